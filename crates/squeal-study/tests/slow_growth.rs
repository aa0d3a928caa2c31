//! A limit cycle reached by slow growth: the two-pad brake's 20.75 kHz mode
//! grows at σ = 14.67 1/s, σT ≈ 7·10⁻⁴ a period, less than settling's
//! default match (10⁻²): two returns agree while the oscillation still
//! grows, and shooting from there fell onto steady sliding ("the oscillation
//! dies out", wrongly: steady sliding is unstable and a simulation settles
//! at 0.708 m/s RMS, 20.751 kHz ± 1 Hz). `cycle` now settles on, to a
//! tighter match, and finds the orbit; `hb` finds the same frequency (the
//! minimal period: the orbit at the settled period's two turns is not
//! tried when the minimal one is not known to be unstable) and either
//! resolves the same stability or says that it does not.

use squeal_study::cycle::{checked_options, of_scenario};
use squeal_study::hb::Guess;
use squeal_study::scenario::{resolve, Source};
use squeal_study::Cancel;

#[test]
fn cycle_and_hb_find_the_limit_cycle_a_slow_growth_leads_to() {
    let sc = resolve(Source::Spec("two-pad-brake"), &[]).unwrap();
    let opts = checked_options(&sc, 20_000_000, 1000.0, 1e-2, None).unwrap();
    let cancel = Cancel::new();
    let c = of_scenario(&sc, &opts, false, &cancel).unwrap();
    // The linear mode is at 20751.27 Hz; the orbit's reversals lower it a little.
    let f = 1.0 / c.period;
    assert!((f - 20751.25).abs() < 0.5, "{f} Hz");
    assert!(c.stable && c.max_multiplier < 1.0, "{}", c.max_multiplier);
    // Four slip reversals a period (each pad reverses twice), nothing else.
    assert_eq!(c.events, [0, 0, 4, 0, 0], "{:?}", c.events);
    // The pads' velocity swings about the sliding speed: ±1.0011 m/s.
    let vp = c.names.iter().position(|n| n == "vx_p1").unwrap();
    assert!(
        (c.amplitude[vp] - 1.0011).abs() < 1e-3,
        "{}",
        c.amplitude[vp]
    );
    // The trivial multiplier is 1 to the shooting's accuracy.
    let trivial = c.multipliers.iter().find(|m| m.2).unwrap();
    assert!(
        (trivial.0.hypot(trivial.1) - 1.0).abs() < 1e-6,
        "{trivial:?}"
    );

    let h = squeal_study::hb::of_scenario(&sc, 20, &opts, Guess::Settle, false, &cancel).unwrap();
    let df = (h.period / c.period - 1.0).abs();
    assert!(
        df < 1e-5,
        "HB {} Hz against shooting {f} Hz",
        1.0 / h.period
    );
    // Newton converges at H = 20 (to the residual's round-off floor, 1e2
    // of its tolerance): where the assembled Jacobian misses a reversal's
    // motion it finishes by differences instead of stalling at ~5e-7.
    assert!(
        h.residual < 1e-8 && h.iterations < 20,
        "{} after {}",
        h.residual,
        h.iterations
    );
    assert!(!h.stability_resolved || h.stable == c.stable);
    if !h.stability_resolved {
        assert!(h
            .warnings
            .iter()
            .any(|w| w.contains("stability is not resolved")));
    }
}

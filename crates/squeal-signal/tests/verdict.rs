//! Run verdicts from synthetic velocity signals.

use crate::common;

use common::{exp_sine, tones, Lcg};
use squeal_signal::*;
use std::f64::consts::TAU;

const FS: f64 = 200_000.0;
const N: usize = 200_000; // 1 s

/// Decaying sines (σ = −20 and −2 1/s) → decays; the tail change is the fitted σ over the
/// tail (within 0.5 dB of σ·T_tail·8.686).
#[test]
fn decaying_signal_decays() {
    for sigma in [-20.0, -2.0] {
        let x = exp_sine(sigma, 3000.0, FS, N);
        let c = classify_with(&x, FS, 0.0, &VerdictOptions::default()).unwrap();
        assert_eq!(c.verdict, Verdict::Decays, "σ={sigma}: {c:?}");
        // tail = last 25 % of the 96 % left after trimming 2 % at each end
        let want = sigma * 0.25 * 0.96 * DB_PER_NEPER;
        assert!((c.tail_change_db - want).abs() < 0.5, "{c:?} want {want}");
        assert!((c.tail_rate - sigma).abs() < 0.02 * sigma.abs(), "{c:?}");
    }
}

/// Growing sines (σ = 8 and 40 1/s) → grows, even with stick events reported.
#[test]
fn growing_signal_grows() {
    for sigma in [8.0, 40.0] {
        let x = exp_sine(sigma, 3000.0, FS, N);
        assert_eq!(classify(&x, FS, 0.0).unwrap(), Verdict::Grows, "σ={sigma}");
        assert_eq!(classify(&x, FS, 0.5).unwrap(), Verdict::Grows, "σ={sigma}");
    }
}

/// Steady oscillation with 1 % noise → limit-cycle; with stick/reversal events in the tail
/// (fraction 0.3) → stick-slip; a tiny fraction (0.005 < 0.01 threshold) stays limit-cycle.
#[test]
fn steady_signal_limit_cycle_or_stick_slip() {
    let mut rng = Lcg(7);
    let x: Vec<f64> = tones(&[(2500.0, 1.0, 0.0), (7500.0, 0.2, 0.4)], FS, N)
        .into_iter()
        .map(|v| v + 0.02 * rng.next())
        .collect();
    let c = classify_with(&x, FS, 0.0, &VerdictOptions::default()).unwrap();
    assert_eq!(c.verdict, Verdict::LimitCycle, "{c:?}");
    assert!(
        c.tail_change_db.abs() < 0.1 && c.drop_from_peak_db < 1.0,
        "{c:?}"
    );
    assert_eq!(classify(&x, FS, 0.3).unwrap(), Verdict::StickSlip);
    assert_eq!(classify(&x, FS, 0.005).unwrap(), Verdict::LimitCycle);
    assert_eq!(Verdict::StickSlip.as_str(), "stick-slip");
    assert_eq!(Verdict::LimitCycle.to_string(), "limit-cycle");
    assert_eq!(Verdict::Decays.as_str(), "decays");
    assert_eq!(Verdict::Grows.as_str(), "grows");
}

/// Growth that saturates at 0.3 s (σ = 30 1/s, 80 dB) then holds: limit-cycle. A sawtooth-like
/// steady stick-slip velocity with an offset and stick fraction 0.4: stick-slip.
#[test]
fn saturated_growth_and_sawtooth() {
    let (sigma, a0) = (30.0, 1e-4);
    let x: Vec<f64> = (0..N)
        .map(|i| {
            let t = i as f64 / FS;
            let a = 1.0 / (1.0 + (1.0 / (a0 * a0) - 1.0) * (-2.0 * sigma * t).exp()).sqrt();
            a * (TAU * 3000.0 * t).sin()
        })
        .collect();
    assert_eq!(classify(&x, FS, 0.0).unwrap(), Verdict::LimitCycle);
    let saw: Vec<f64> = (0..N)
        .map(|i| {
            let ph = (i as f64 / FS * 400.0).fract();
            // stick (constant velocity) for 40 % of the period, then a slip pulse
            if ph < 0.4 {
                1.0
            } else {
                1.0 - (TAU * (ph - 0.4) / 0.6).sin().abs() * 2.0
            }
        })
        .collect();
    assert_eq!(classify(&saw, FS, 0.4).unwrap(), Verdict::StickSlip);
}

/// A signal that dies to exact zeros, and an all-zero signal, both decay.
#[test]
fn dead_signals_decay() {
    let mut x = exp_sine(-50.0, 3000.0, FS, N);
    x[60_000..].iter_mut().for_each(|v| *v = 0.0);
    let c = classify_with(&x, FS, 0.0, &VerdictOptions::default()).unwrap();
    assert_eq!(c.verdict, Verdict::Decays, "{c:?}");
    assert_eq!(
        classify(&vec![0.0; 1000], FS, 0.0).unwrap(),
        Verdict::Decays
    );
    assert_eq!(
        classify(&vec![2.5; 1000], FS, 0.0).unwrap(),
        Verdict::Decays
    );
}

/// Bad input gives typed errors.
#[test]
fn classify_rejects_bad_input() {
    let x = exp_sine(0.0, 3000.0, FS, 1000);
    assert!(classify(&x, FS, 1.5).is_err());
    assert!(classify(&x, FS, f64::NAN).is_err());
    assert!(classify(&x, 0.0, 0.0).is_err());
    assert!(classify(&x[..10], FS, 0.0).is_err());
    assert!(classify(&[], FS, 0.0).is_err());
    let bad = VerdictOptions {
        tail_fraction: 0.0,
        ..Default::default()
    };
    assert!(classify_with(&x, FS, 0.0, &bad).is_err());
}

// ---- judge(): the run's verdict from named coordinates and events ----

/// A one-coordinate record (`x`, `v`) sampled at `fs`.
fn record<'a>(x: &'a [f64], v: &'a [f64], fs: f64, events: Vec<RunEvent<'a>>) -> RunRecord<'a> {
    RunRecord {
        sample_rate: fs,
        t_start: 0.0,
        coordinates: vec![Coordinate {
            name: "x",
            velocity_name: "v",
            position: x,
            velocity: v,
        }],
        events,
        velocity_scale: 1.0,
    }
}

/// `a(t)·sin(2πft)` and its integral-like position `−a(t)·cos(2πft)/(2πf)` over `secs`.
fn osc(a: impl Fn(f64) -> f64, f: f64, fs: f64, secs: f64) -> (Vec<f64>, Vec<f64>) {
    let n = (secs * fs) as usize;
    let w = TAU * f;
    let t = |i: usize| i as f64 / fs;
    let v = (0..n).map(|i| a(t(i)) * (w * t(i)).sin()).collect();
    let x = (0..n).map(|i| -a(t(i)) * (w * t(i)).cos() / w).collect();
    (x, v)
}

fn word(r: &RunRecord) -> RunVerdict {
    judge(r, &JudgeOptions::default()).unwrap().verdict
}

#[test]
fn judge_growth_decay_neutral_and_limit_cycle() {
    let fs = 20_000.0;
    // σ = +1 1/s over 0.2 s: 1.7 dB in all, 0.43 dB over the window → grows.
    let (x, v) = osc(|t| 1e-3 * t.exp(), 500.0, fs, 0.2);
    let j = judge(&record(&x, &v, fs, vec![]), &JudgeOptions::default()).unwrap();
    assert_eq!(j.verdict, RunVerdict::Grows, "{}", j.reason);
    let sq = j.squeal.unwrap();
    assert_eq!((sq.coordinate.as_str(), sq.velocity.as_str()), ("x", "v"));
    assert!((sq.frequency_hz - 500.0).abs() < 2.5, "{}", sq.frequency_hz);
    assert!((j.trends[0].rate - 1.0).abs() < 0.2, "{:?}", j.trends[0]);
    // σ = −1 1/s → decays, no squeal.
    let (x, v) = osc(|t| 1e-3 * (-t).exp(), 500.0, fs, 0.2);
    let j = judge(&record(&x, &v, fs, vec![]), &JudgeOptions::default()).unwrap();
    assert_eq!(j.verdict, RunVerdict::Decays, "{}", j.reason);
    assert!(j.squeal.is_none());
    // Constant amplitude from start to end, no events → neutral.
    let (x, v) = osc(|_| 1e-3, 500.0, fs, 0.2);
    assert_eq!(word(&record(&x, &v, fs, vec![])), RunVerdict::Neutral);
    // Grew (×100) and levelled off → limit-cycle, with its squeal answer.
    let (x, v) = osc(|t| 1e-3 * (1.0 + 99.0 * (t / 0.05).tanh()), 500.0, fs, 1.0);
    let j = judge(&record(&x, &v, fs, vec![]), &JudgeOptions::default()).unwrap();
    assert_eq!(j.verdict, RunVerdict::LimitCycle, "{}", j.reason);
    let rms = j.squeal.unwrap().rms;
    assert!((rms - 0.1 / 2f64.sqrt()).abs() < 1e-3, "{rms}");
    // Two cycles only → too short to tell.
    let (x, v) = osc(|_| 1e-3, 500.0, fs, 0.004);
    assert_eq!(word(&record(&x, &v, fs, vec![])), RunVerdict::TooShort);
}

#[test]
fn judge_stick_slip_is_the_same_at_every_sample_rate() {
    // Sticks and slips every 1/15 s (the integrator's exact times), a bounded
    // oscillation between them: the word and the frequency do not depend on fs.
    let period = 1.0 / 15.0;
    let mut events = Vec::new();
    let mut t = 0.01;
    while t < 2.0 {
        events.push(RunEvent {
            t,
            kind: EventClass::Stick,
            contact: None,
        });
        events.push(RunEvent {
            t: t + 0.3 * period,
            kind: EventClass::Slip,
            contact: None,
        });
        t += period;
    }
    for fs in [100.0, 1000.0, 20_000.0] {
        let (x, v) = osc(|_| 0.1, 15.0, fs, 2.0);
        let j = judge(
            &record(&x, &v, fs, events.clone()),
            &JudgeOptions::default(),
        )
        .unwrap();
        assert_eq!(j.verdict, RunVerdict::StickSlip, "{fs} Hz: {}", j.reason);
        let sq = j.squeal.unwrap();
        assert!(
            (sq.frequency_hz - 15.0).abs() < 1e-9,
            "{fs} Hz: {}",
            sq.frequency_hz
        );
        let c = j.cycle.unwrap();
        assert!((c.sticks_per_cycle - 1.0).abs() < 0.15, "{c:?}");
        assert_eq!(c.reversals, 0);
    }
}

#[test]
fn judge_out_of_range_and_lift_off() {
    let fs = 20_000.0;
    let (mut x, v) = osc(|_| 1e-3, 500.0, fs, 0.2);
    x[3000] = 0.5; // half a metre: beyond the default 0.1 m
    let j = judge(&record(&x, &v, fs, vec![]), &JudgeOptions::default()).unwrap();
    assert_eq!(j.verdict, RunVerdict::OutOfRange);
    assert!(
        j.reason.contains('x') && j.reason.contains("0.150000 s"),
        "{}",
        j.reason
    );
    let wide = JudgeOptions {
        validity: 1.0,
        ..JudgeOptions::default()
    };
    assert_ne!(
        judge(&record(&x, &v, fs, vec![]), &wide).unwrap().verdict,
        RunVerdict::OutOfRange
    );
    // Separations at irregular intervals to the end → lift-off.
    let (x, v) = osc(|_| 1e-3, 500.0, fs, 0.2);
    let mut lcg = 12345u64;
    let mut events = Vec::new();
    let mut t = 0.0;
    while t < 0.2 {
        lcg = lcg.wrapping_mul(6364136223846793005).wrapping_add(1);
        t += 0.002 * (0.5 + (lcg >> 11) as f64 / (1u64 << 53) as f64);
        events.push(RunEvent {
            t,
            kind: EventClass::Separate,
            contact: Some("pad"),
        });
        events.push(RunEvent {
            t: t + 1e-4,
            kind: EventClass::Contact,
            contact: Some("pad"),
        });
    }
    assert_eq!(word(&record(&x, &v, fs, events)), RunVerdict::LiftOff);
}

/// Events `kind` at `contact` every `period` s from `t0` to `end`, with a
/// recontact (for separations) or a slip a third of a period later.
fn periodic(
    kind: EventClass,
    contact: Option<&'static str>,
    t0: f64,
    period: f64,
    end: f64,
) -> Vec<RunEvent<'static>> {
    let mut out = Vec::new();
    let mut t = t0;
    while t < end {
        out.push(RunEvent { t, kind, contact });
        let back = if kind == EventClass::Separate {
            EventClass::Contact
        } else {
            EventClass::Slip
        };
        out.push(RunEvent {
            t: t + period / 3.0,
            kind: back,
            contact,
        });
        t += period;
    }
    out.sort_by(|a, b| a.t.total_cmp(&b.t));
    out
}

#[test]
fn regular_contact_loss_with_reversals_is_a_limit_cycle_not_stick_slip() {
    // A 500 Hz cycle that separates once a period and reverses its slip
    // three times a period (the caliper: 3.3 separations per cycle
    // were called stick-slip): contact loss names the cycle.
    let fs = 20_000.0;
    let (x, v) = osc(|_| 1e-3, 500.0, fs, 0.2);
    let mut events = periodic(EventClass::Separate, Some("pad"), 0.0005, 0.002, 0.2);
    events.extend(periodic(
        EventClass::Reverse,
        Some("pad"),
        0.0007,
        0.002 / 3.0,
        0.2,
    ));
    events.sort_by(|a, b| a.t.total_cmp(&b.t));
    let j = judge(&record(&x, &v, fs, events), &JudgeOptions::default()).unwrap();
    assert_eq!(j.verdict, RunVerdict::LimitCycle, "{}", j.reason);
    assert!(
        j.reason.contains("losing contact regularly at contact pad")
            && j.reason.contains("contact loss, not stick-slip"),
        "{}",
        j.reason
    );
    assert_eq!(j.contacts.len(), 1);
    let c = &j.contacts[0];
    assert_eq!(c.regime(), "contact loss");
    // 0.05 s window: 25 separations, CV ≈ 0 (exactly periodic up to round-off).
    assert_eq!(c.separations, 25);
    assert!(c.separation_cv < 1e-9, "{c:?}");
    let cyc = j.cycle.unwrap();
    assert!((cyc.separations_per_cycle - 1.0).abs() < 0.05, "{cyc:?}");
}

#[test]
fn contacts_are_judged_one_by_one() {
    // Two pads, each losing contact exactly periodically but at different
    // rates (every 2 ms and every 3 ms): their separations together are
    // irregular (the old rule said lift-off); each on its own is regular,
    // so the run is a limit cycle with contact loss at both.
    let fs = 20_000.0;
    let (x, v) = osc(|_| 1e-3, 500.0, fs, 0.2);
    let mut events = periodic(EventClass::Separate, Some("inner"), 0.0005, 0.002, 0.2);
    events.extend(periodic(
        EventClass::Separate,
        Some("outer"),
        0.0011,
        0.003,
        0.2,
    ));
    events.sort_by(|a, b| a.t.total_cmp(&b.t));
    let j = judge(
        &record(&x, &v, fs, events.clone()),
        &JudgeOptions::default(),
    )
    .unwrap();
    assert_eq!(j.verdict, RunVerdict::LimitCycle, "{}", j.reason);
    let names: Vec<&str> = j
        .contacts
        .iter()
        .map(|c| c.name.as_deref().unwrap())
        .collect();
    assert_eq!(names, ["inner", "outer"]);
    assert!(j.contacts.iter().all(|c| c.regime() == "contact loss"));
    // Unnamed, the same events are one contact's, irregular: lift-off.
    let anonymous: Vec<RunEvent> = events
        .iter()
        .map(|e| RunEvent {
            contact: None,
            ..*e
        })
        .collect();
    assert_eq!(word(&record(&x, &v, fs, anonymous)), RunVerdict::LiftOff);
    // A pad that slips back and forth but keeps contact is stick-slip.
    let slips = periodic(EventClass::Reverse, Some("inner"), 0.0005, 0.002, 0.2);
    let j = judge(&record(&x, &v, fs, slips), &JudgeOptions::default()).unwrap();
    assert_eq!(j.verdict, RunVerdict::StickSlip, "{}", j.reason);
    assert_eq!(j.contacts[0].regime(), "stick-slip");
}

//! Harmonic balance against shooting: a smooth orbit (van der Pol:
//! exponential convergence in the harmonics) and the disc–pad's reversal
//! cycle (friction flips sign twice a period: algebraic convergence).

use squeal_core::cycle::{self, find_cycle, CycleOptions};
use squeal_core::hb::{harmonic_balance, Fourier, HbOptions};
use squeal_core::{DiscPad, System};

/// HB with `h` harmonics from the shooting orbit's samples; the relative
/// frequency error against shooting and the largest relative amplitude
/// error of states above 1e-6 of the largest.
fn hb_vs_shooting<S: System<N>, const N: usize>(
    sys: &S,
    cyc: &cycle::Cycle<N>,
    hs: &[usize],
) -> Vec<(usize, f64, Vec<f64>)> {
    let o = cycle::orbit(sys, cyc, &CycleOptions::default()).unwrap();
    // The reference amplitudes from the dense output (the shooting's own
    // are taken at step ends and events, and miss peaks inside a step).
    let k = 100_000;
    let mut rec = squeal_core::sink::Recorder::<N>::new();
    squeal_core::simulate(
        sys,
        0.0,
        cyc.z0,
        cyc.period,
        k as f64 / cyc.period,
        CycleOptions::default().solver,
        &mut rec,
    )
    .unwrap();
    let mut reference = [0.0; N];
    for (i, r) in reference.iter_mut().enumerate() {
        let (lo, hi) = rec
            .z
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), z| {
                (l.min(z[i]), h.max(z[i]))
            });
        *r = 0.5 * (hi - lo);
    }
    let n = sys.norm_states() / 2;
    let mut guess = Fourier::from_orbit(&o, cyc.period, n, hs[0]);
    let mut out = Vec::new();
    for &h in hs {
        let opts = HbOptions {
            harmonics: h,
            ..HbOptions::default()
        };
        let orbit = harmonic_balance(sys, &guess, &opts).unwrap();
        let f = &orbit.fourier;
        let freq_err = (f.omega * cyc.period / std::f64::consts::TAU - 1.0).abs();
        // Half peak-to-peak of every state, from 20000 samples of the series.
        let mut lo = [f64::INFINITY; N];
        let mut hi = [f64::NEG_INFINITY; N];
        for j in 0..20_000 {
            let z: [f64; N] = f.state(std::f64::consts::TAU * j as f64 / 20_000.0);
            for i in 0..N {
                lo[i] = lo[i].min(z[i]);
                hi[i] = hi[i].max(z[i]);
            }
        }
        let mut amp_err = vec![0.0; N];
        for blk in [0..N / 2, N / 2..N] {
            let top = reference[blk.clone()].iter().cloned().fold(0.0, f64::max);
            for i in blk {
                if reference[i] > 1e-6 * top {
                    let a = 0.5 * (hi[i] - lo[i]);
                    amp_err[i] = (a / reference[i] - 1.0).abs();
                }
            }
        }
        eprintln!(
            "H = {h}: frequency {freq_err:.3e}, amplitude {amp_err:?}, {} iterations, residual {:.1e}, {} switches",
            orbit.iterations, orbit.residual, orbit.switches
        );
        out.push((h, freq_err, amp_err));
        guess = orbit.fourier;
    }
    out
}

#[test]
fn disc_pad_reversal_cycle_by_harmonic_balance() {
    let brake = DiscPad::default();
    let cyc = find_cycle(&brake, 0.0, [0.0; 8], &CycleOptions::default()).unwrap();
    let r = hb_vs_shooting(&brake, &cyc, &[10, 40]);
    // Measured: frequency 6.6e-7 (H = 10), 1.6e-7 (40), 8.9e-8 (80),
    // 4.3e-8 (160): first order in 1/H, the kinks of the reversals.
    assert!(r[0].1 <= 1e-6 && r[1].1 <= 2e-7, "{r:?}");
    assert!(r[1].1 < 0.5 * r[0].1, "{r:?}");
    // Amplitudes at H = 40: the pad's tangential displacement and velocity
    // (states 1, 5) to 2e-5; the disc's tangential displacement (0) to
    // 5e-3; its velocity (4), whose peak is the microsecond reversal
    // excursion, to 5 % (0.6 % at H = 160: that spike needs hundreds of
    // harmonics).
    let a = &r[1].2;
    assert!(a[1] <= 2e-5 && a[5] <= 2e-5, "{a:?}");
    assert!(a[0] <= 5e-3, "{a:?}");
    assert!(a[4] <= 5e-2, "{a:?}");
}

/// A smooth orbit: the Fourier series converges exponentially, and so does
/// HB's frequency (van der Pol, ε = 1: T = 6.6632868593…).
#[test]
fn van_der_pol_converges_exponentially_in_the_harmonics() {
    let model = crate::cycle::VanDerPol(1.0);
    let opts = crate::cycle::tight(1e-12, 1e-12);
    let cyc = find_cycle(&model, 0.0, [0.5, 0.0], &opts).unwrap();
    assert!((cyc.period - 6.663_286_859).abs() < 1e-8, "{}", cyc.period);
    let r = hb_vs_shooting(&model, &cyc, &[3, 6, 12, 24]);
    // Measured: 3.3e-4, 1.4e-5, 1.5e-10, 1.6e-13 at H = 3, 6, 12, 24
    // (exponential: the error's logarithm halves, not the error, per
    // doubling); amplitudes at H = 24 to 1.4e-8 (the peak's sampling).
    let e: Vec<f64> = r.iter().map(|x| x.1).collect();
    assert!(e[1] < 0.1 * e[0] && e[2] < 1e-4 * e[1], "{e:?}");
    assert!(e[3] <= 1e-12, "{e:?}");
    assert!(r[3].2[0] <= 1e-7 && r[3].2[1] <= 1e-7, "{:?}", r[3].2);
}

/// Contact loss, no stick: Hoffmann's model sliding at 1 m/s on its belt
/// loses contact for about a third of each period; HB's frequency equals
/// shooting's to 1e-9 at H = 10 (measured 1.5e-10, the shooting's own
/// accuracy), amplitudes to 1e-3 at H = 20 (measured 7.9e-6, the kink of
/// the normal force at the loss of contact: algebraic convergence).
#[test]
fn hoffmann_with_contact_loss_by_harmonic_balance() {
    let model = squeal_core::Hoffmann::default();
    let mut z = model.steady_sliding().unwrap();
    z[0] += 1e-4;
    let cyc = find_cycle(&model, 0.0, z, &CycleOptions::default()).unwrap();
    let r = hb_vs_shooting(&model, &cyc, &[10, 20]);
    assert!(r[0].1 <= 1e-9 && r[1].1 <= 1e-9, "{r:?}");
    for i in 0..4 {
        assert!(r[1].2[i] <= 1e-3, "{:?}", r[1].2);
    }
}

//! Eigenvalue sweeps with mode tracking (`stability::sweep`) against the
//! closed-form Hoffmann model: the coalescence at the analytic critical μ,
//! continuity of both branches on both sides, the analytic eigenvalues at
//! every point, the damped (Routh–Hurwitz) threshold, and a frequency
//! crossing that sorting would get wrong.

use nalgebra::{Complex, DMatrix};
use squeal_core::model::hoffmann::Hoffmann;
use squeal_core::stability::sweep::{hungarian, mac, sweep, Sweep, SweepOptions};
use squeal_core::stability::{state_matrix, Direction, StabilityError};
use squeal_core::Parameters;

fn hoffmann_at(base: &Hoffmann, mu: f64) -> Result<(DMatrix<f64>, Vec<f64>), StabilityError> {
    let mut h = *base;
    h.set("mu", mu)?;
    let (z, a) = state_matrix(&h)?;
    Ok((DMatrix::from_fn(4, 4, |i, j| a[i][j]), z.to_vec()))
}

fn linspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Undamped Hoffmann: `m s²` solves `x² + (k11 + k22) x + a0(μ) = 0` with
/// `a0 = k11 k22 − k12 (k12 − μ k3)`; the discriminant
/// `(k11 − k22)² + 4 k12² − 4 μ k12 k3` vanishes at
/// `μ_c = ((k11 − k22)² + 4 k12²)/(4 k12 k3)` (= 0.25 for the defaults),
/// where the two frequencies coalesce at `ω² = (k11 + k22)/(2m)`.
fn undamped() -> (Hoffmann, f64) {
    let mut h = Hoffmann::default();
    h.set("c1", 0.0).unwrap();
    h.set("c2", 0.0).unwrap();
    let p = &h.p;
    let mu_c = ((p.k11 - p.k22).powi(2) + 4.0 * p.k12 * p.k12) / (4.0 * p.k12 * p.k3);
    (h, mu_c)
}

/// The four exact eigenvalues of undamped Hoffmann at μ.
fn exact(h: &Hoffmann, mu: f64) -> Vec<Complex<f64>> {
    let p = &h.p;
    let a0 = p.k11 * p.k22 - p.k12 * (p.k12 - mu * p.k3);
    let b = p.k11 + p.k22;
    let disc = Complex::new(b * b - 4.0 * a0, 0.0).sqrt();
    let mut out = Vec::new();
    for x in [(-b + disc) / 2.0, (-b - disc) / 2.0] {
        let s = (x / p.m).sqrt();
        out.push(s);
        out.push(-s);
    }
    out
}

fn mode(sw: &Sweep, m: usize, k: usize) -> Complex<f64> {
    sw.lambda[k][sw.listed[m]]
}

#[test]
fn hoffmann_modes_coalesce_at_the_analytic_mu_and_do_not_swap() {
    let (h, mu_c) = undamped();
    assert!((mu_c - 0.25).abs() < 1e-15);
    // Two grids: one that straddles μ_c, one that has it as a grid point.
    for values in [linspace(0.02, 0.5, 37), linspace(0.05, 0.45, 41)] {
        let sw = sweep(&values, |mu| hoffmann_at(&h, mu), &SweepOptions::default()).unwrap();
        // Two modes listed (the lower-half-plane conjugates are twins).
        assert_eq!(sw.listed.len(), 2, "{:?}", sw.lambda[0]);
        // Every point: the tracked eigenvalues are the exact ones (as a set).
        for (k, &mu) in values.iter().enumerate() {
            let mut want = exact(&h, mu);
            for l in &sw.lambda[k] {
                let (i, d) = want
                    .iter()
                    .enumerate()
                    .map(|(i, w)| (i, (w - l).norm()))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .unwrap();
                // Near the double eigenvalue at μ_c the error is ≈ √(ε)·|λ|.
                let tol = if (mu - mu_c).abs() < 1e-3 {
                    1e-6
                } else {
                    1e-10
                };
                assert!(d <= tol * l.norm(), "μ = {mu}: {l} vs {}", want[i]);
                want.swap_remove(i);
            }
        }
        // One onset: the coalescence, at μ_c to 1e-6 (in fact ~1e-10).
        assert_eq!(sw.onsets.len(), 1, "{:?}", sw.onsets);
        let o = sw.onsets[0];
        assert!(o.coalescence && o.direction == Direction::Destabilising);
        assert!(
            (o.value - mu_c).abs() <= 1e-6 * mu_c,
            "onset at {} vs {mu_c}",
            o.value
        );
        let p = &h.p;
        let f_c = ((p.k11 + p.k22) / (2.0 * p.m)).sqrt() / (2.0 * std::f64::consts::PI);
        assert!(
            (o.freq_hz - f_c).abs() <= 1e-4 * f_c,
            "{} vs {f_c}",
            o.freq_hz
        );
        // Continuity below μ_c: mode 1 stays the lower frequency, both neutral,
        // each frequency moves less than the gap between them.
        let below: Vec<usize> = (0..values.len())
            .filter(|&k| values[k] < mu_c - 1e-3)
            .collect();
        let above: Vec<usize> = (0..values.len())
            .filter(|&k| values[k] > mu_c + 1e-3)
            .collect();
        assert!(below.len() > 5 && above.len() > 5);
        for &k in &below {
            let (a, b) = (mode(&sw, 0, k), mode(&sw, 1, k));
            assert!(a.im > 0.0 && b.im > a.im, "μ = {}: {a} {b}", values[k]);
            assert!(a.re.abs() <= 1e-9 * a.norm() && b.re.abs() <= 1e-9 * b.norm());
        }
        for w in below.windows(2) {
            for m in 0..2 {
                let (x, y) = (mode(&sw, m, w[0]), mode(&sw, m, w[1]));
                let gap = (mode(&sw, 1, w[1]).im - mode(&sw, 0, w[1]).im).abs();
                assert!(
                    (x - y).norm() < gap,
                    "mode {m} jumps at μ = {}",
                    values[w[1]]
                );
            }
        }
        // Above μ_c: same frequency, opposite growth rates, and each mode keeps
        // the sign of its growth rate at every point (no swap).
        let s0 = mode(&sw, 0, above[0]).re.signum();
        for &k in &above {
            let (a, b) = (mode(&sw, 0, k), mode(&sw, 1, k));
            assert!(
                (a.im - b.im).abs() <= 1e-9 * a.norm(),
                "μ = {}: {a} {b}",
                values[k]
            );
            assert!(a.re.abs() > 1e-6 * a.norm(), "μ = {}: {a}", values[k]);
            assert_eq!(a.re.signum(), s0, "mode 1 swapped at μ = {}", values[k]);
            assert_eq!(b.re.signum(), -s0, "mode 2 swapped at μ = {}", values[k]);
            assert!((a.re + b.re).abs() <= 1e-9 * a.norm());
        }
        // Tracking quality: every match away from μ_c has MAC ≈ 1.
        for k in below.iter().chain(&above).skip(1) {
            for &b in &sw.listed {
                assert!(
                    sw.mac[*k][b] > 0.9,
                    "μ = {}: MAC {}",
                    values[*k],
                    sw.mac[*k][b]
                );
            }
        }
    }
}

#[test]
fn damped_hoffmann_onset_is_the_routh_hurwitz_threshold() {
    // Routh–Hurwitz on det(m s² + C s + K(μ)) = a4 s⁴ + a3 s³ + a2 s² + a1 s + a0:
    // H = a3 a2 a1 − a4 a1² − a3² a0 changes sign at
    // μ* = (a3 a2 a1 − a4 a1² − a3² a00)/(a3² k12 k3), with a0 = a00 + μ k12 k3.
    let h = Hoffmann::default();
    let p = &h.p;
    let (a4, a3) = (p.m * p.m, p.m * (p.c1 + p.c2));
    let a2 = p.m * (p.k11 + p.k22) + p.c1 * p.c2;
    let a1 = p.c1 * p.k22 + p.c2 * p.k11;
    let a00 = p.k11 * p.k22 - p.k12 * p.k12;
    let mu_star = (a3 * a2 * a1 - a4 * a1 * a1 - a3 * a3 * a00) / (a3 * a3 * p.k12 * p.k3);
    let values = linspace(0.1, 0.4, 31);
    let sw = sweep(&values, |mu| hoffmann_at(&h, mu), &SweepOptions::default()).unwrap();
    assert_eq!(sw.onsets.len(), 1, "{:?}", sw.onsets);
    let o = sw.onsets[0];
    assert!(
        (o.value - mu_star).abs() <= 1e-8 * mu_star,
        "{} vs {mu_star}",
        o.value
    );
    assert_eq!(o.direction, Direction::Destabilising);
    assert!(o.mode.is_some());
}

/// Two uncoupled oscillators whose frequencies cross: ω₁ = 10 fixed,
/// ω₂ = p sweeping 5 → 15. Sorting by frequency would swap the modes at
/// p = 10; tracking by shape keeps mode 1 = coordinate x throughout.
#[test]
fn crossing_frequencies_are_tracked_by_shape_not_by_order() {
    let f = |p: f64| -> Result<(DMatrix<f64>, Vec<f64>), StabilityError> {
        let mut a = DMatrix::<f64>::zeros(4, 4);
        a[(0, 2)] = 1.0;
        a[(1, 3)] = 1.0;
        a[(2, 0)] = -100.0;
        a[(3, 1)] = -p * p;
        a[(2, 2)] = -0.1;
        a[(3, 3)] = -0.1;
        Ok((a, vec![0.0; 4]))
    };
    let values = linspace(5.0, 15.0, 21); // p = 10 is a grid point: a double eigenvalue
    let sw = sweep(&values, f, &SweepOptions::default()).unwrap();
    assert_eq!(sw.listed.len(), 2);
    // At the start, mode 1 (lower frequency) is y (ω = 5), mode 2 is x (ω = 10).
    for (k, &p) in values.iter().enumerate() {
        let (y, x) = (mode(&sw, 0, k), mode(&sw, 1, k));
        let wd = |w: f64| (w * w - 0.0025).sqrt();
        assert!((y.im - wd(p)).abs() < 1e-9 * p, "p = {p}: mode 1 {y}");
        assert!((x.im - wd(10.0)).abs() < 1e-9 * 10.0, "p = {p}: mode 2 {x}");
    }
    assert!(sw.onsets.is_empty());
}

#[test]
fn hungarian_finds_the_optimal_assignment() {
    // Brute force over all permutations of 5.
    let mut seed = 1u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..50 {
        let n = 5;
        let c: Vec<f64> = (0..n * n).map(|_| rnd()).collect();
        let got = hungarian(&c, n);
        let total = |a: &[usize]| {
            a.iter()
                .enumerate()
                .map(|(i, &j)| c[i * n + j])
                .sum::<f64>()
        };
        let mut best = f64::INFINITY;
        let mut perm: Vec<usize> = (0..n).collect();
        permute(&mut perm, 0, &mut |p| best = best.min(total(p)));
        let mut sorted = got.clone();
        sorted.sort();
        assert_eq!(sorted, (0..n).collect::<Vec<_>>());
        assert!(
            (total(&got) - best).abs() < 1e-12,
            "{} vs {best}",
            total(&got)
        );
    }
    assert!(mac(&[Complex::new(1.0, 0.0)], &[Complex::new(0.0, 2.0)]) == 1.0);
    assert_eq!(
        mac(
            &[Complex::new(1.0, 0.0), Complex::new(0.0, 0.0)],
            &[Complex::new(0.0, 0.0), Complex::new(1.0, 0.0)]
        ),
        0.0
    );
}

fn permute(p: &mut Vec<usize>, k: usize, f: &mut dyn FnMut(&[usize])) {
    if k == p.len() {
        f(p);
        return;
    }
    for i in k..p.len() {
        p.swap(k, i);
        permute(p, k + 1, f);
        p.swap(k, i);
    }
}

#[test]
fn bad_sweeps_are_refused() {
    let (h, _) = undamped();
    let o = SweepOptions::default();
    assert!(sweep(&[], |mu| hoffmann_at(&h, mu), &o).is_err());
    assert!(sweep(&[0.1, 0.1], |mu| hoffmann_at(&h, mu), &o).is_err());
    assert!(sweep(&[0.1, f64::NAN], |mu| hoffmann_at(&h, mu), &o).is_err());
    // The closure's error passes through.
    let r = sweep(&[0.1, 0.2], |mu| hoffmann_at(&h, -mu - 1.0), &o);
    assert!(matches!(r, Err(StabilityError::Param(_))), "{r:?}");
}

/// Ten uncoupled oscillators (20 states, more than `CANDIDATES`): ω_i = i + 1
/// for the first nine, and the tenth sweeps ω = p across all of them. Every
/// branch keeps its oscillator (identified by its shape, a unit vector).
#[test]
fn a_mode_sweeping_through_nine_others_keeps_every_identity() {
    let n = 10;
    let f = |p: f64| -> Result<(DMatrix<f64>, Vec<f64>), StabilityError> {
        let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for i in 0..n {
            let w = if i + 1 == n { p } else { (i + 1) as f64 };
            a[(i, n + i)] = 1.0;
            a[(n + i, i)] = -w * w;
            a[(n + i, n + i)] = -0.02 * w;
        }
        Ok((a, vec![0.0; 2 * n]))
    };
    let values = linspace(0.55, 10.45, 67);
    let sw = sweep(&values, f, &SweepOptions::default()).unwrap();
    assert_eq!(sw.listed.len(), n);
    // Mode order at the first point: the sweeping oscillator (ω = 0.55) first.
    for (k, &p) in values.iter().enumerate() {
        for m in 0..n {
            let w = if m == 0 { p } else { m as f64 };
            let want = w * (1.0 - 0.0001f64).sqrt();
            let got = mode(&sw, m, k).im;
            assert!(
                (got - want).abs() < 1e-9 * w,
                "p = {p}: mode {} at {got}, want {want}",
                m + 1
            );
        }
    }
}

/// A state-matrix function of the swept parameter.
type StateAt<'a> = &'a dyn Fn(f64) -> Result<(DMatrix<f64>, Vec<f64>), StabilityError>;

/// A sweep restarted from any value `t` (its own branch numbering) pairs
/// the modes exactly as the whole sweep once its first step agrees with the
/// whole sweep's: the assignment does not depend on how branches are
/// numbered. This is what `sweep --shard` and `merge` rely on.
#[test]
fn a_sweep_resumed_from_a_slice_tracks_bit_for_bit() {
    let (h, _) = undamped();
    let crossing = |p: f64| -> Result<(DMatrix<f64>, Vec<f64>), StabilityError> {
        let mut a = DMatrix::<f64>::zeros(4, 4);
        a[(0, 2)] = 1.0;
        a[(1, 3)] = 1.0;
        a[(2, 0)] = -100.0;
        a[(3, 1)] = -p * p;
        a[(2, 2)] = -0.1;
        a[(3, 3)] = -0.1;
        Ok((a, vec![0.0; 4]))
    };
    let hoff = |mu: f64| hoffmann_at(&h, mu);
    let cases: Vec<(Vec<f64>, StateAt)> = vec![
        (linspace(0.02, 0.5, 37), &hoff),
        (linspace(5.0, 15.0, 21), &crossing),
    ];
    let bits = |l: Complex<f64>| (l.re.to_bits(), l.im.to_bits());
    let mut checked = 0;
    for (values, f) in cases {
        let o = SweepOptions::default();
        let full = sweep(&values, f, &o).unwrap();
        for t in 0..values.len() - 2 {
            let part = sweep(&values[t..], f, &o).unwrap();
            // π: part branch → whole-sweep branch, by the eigenvalues' bits at t.
            let at = &full.lambda[t];
            let pi: Option<Vec<usize>> = part.lambda[0]
                .iter()
                .map(|l| {
                    let m: Vec<usize> =
                        (0..at.len()).filter(|&b| bits(at[b]) == bits(*l)).collect();
                    (m.len() == 1).then(|| m[0])
                })
                .collect();
            let Some(pi) = pi else { continue }; // a double eigenvalue at t
            let same_at = |i: usize| {
                (0..pi.len()).all(|b| bits(part.lambda[i - t][b]) == bits(full.lambda[i][pi[b]]))
            };
            assert!(same_at(t + 1), "t = {t}: the first step pairs differently");
            for i in t + 2..values.len() {
                assert!(same_at(i), "t = {t}: differs at value {i}");
            }
            checked += 1;
        }
    }
    assert!(checked >= 40, "{checked}");
}

//! Linear stability of steady sliding against exact results: analytic
//! Jacobians vs finite differences, eigenvalues vs a 50-digit reference,
//! Hopf and flutter thresholds vs closed forms, and growth of simulated
//! transients at the predicted rate.

use squeal_core::model::disc_pad::Contact;
use squeal_core::model::hoffmann::Hoffmann;
use squeal_core::sink::Recorder;
use squeal_core::stability::{
    analyse, analyse_with_masses, critical, max_growth_rate, CriticalOptions, Direction, Inertia,
    StabilityError,
};
use squeal_core::{simulate, Belt, DiscPad, FrictionLaw, Mode, Model, Parameters, SolverOptions};
use std::f64::consts::PI;

// ---------------------------------------------------------------------------
// Jacobians
// ---------------------------------------------------------------------------

/// Compare `model.jacobian(z)` with central differences of `rhs` in mode
/// SlipPos. Column `j` is differenced with step `1e-3·scale[j]`; in the
/// scaled matrix `J̃_ij = J_ij·scale_j` (the change of `ż_i` caused by a
/// typical change of `z_j`) every entry must agree to
/// `1e-6·|J̃_ij| + 1e-9·max_k |J̃_ik|`: 1e-6 relative on each entry, plus an
/// absolute floor of 1e-9 of the row's largest term for entries that are
/// zero or negligible. Round-off of the differences is ≈ ε·(row term)/1e-3
/// ≈ 2e-13 of the row's largest term; truncation is zero for the quadratic
/// thesis law and ≈ 1e-7 relative for the exponential Stribeck law.
fn check_jacobian<M: Model<N>, const N: usize>(
    model: &M,
    z: &[f64; N],
    scale: &[f64; N],
    label: &str,
) {
    let an = model.jacobian(z);
    let mut fd = [[0.0; N]; N];
    for j in 0..N {
        let h = 1e-3 * scale[j];
        let (mut zp, mut zm) = (*z, *z);
        zp[j] += h;
        zm[j] -= h;
        let (mut fp, mut fm) = ([0.0; N], [0.0; N]);
        model.rhs(0.0, Mode::SlipPos, &zp, &mut fp);
        model.rhs(0.0, Mode::SlipPos, &zm, &mut fm);
        for i in 0..N {
            fd[i][j] = (fp[i] - fm[i]) / (zp[j] - zm[j]);
        }
    }
    for i in 0..N {
        let row_max = (0..N)
            .map(|k| (an[i][k] * scale[k]).abs())
            .fold(0.0, f64::max);
        for j in 0..N {
            let a = an[i][j] * scale[j];
            let f = fd[i][j] * scale[j];
            let tol = 1e-6 * a.abs() + 1e-9 * row_max;
            assert!(
                (a - f).abs() <= tol,
                "{label}: J[{i}][{j}] analytic {:e} vs finite differences {:e} (scaled diff {:e} > {tol:e})",
                an[i][j],
                fd[i][j],
                (a - f).abs()
            );
        }
    }
}

fn perturbed<const N: usize>(z: &[f64; N], d: &[f64; N]) -> [f64; N] {
    let mut out = *z;
    for i in 0..N {
        out[i] += d[i];
    }
    out
}

#[test]
fn jacobians_match_central_differences() {
    // Disc–pad: positions scaled by the static deflections (x ≈ 3–5e-8 m,
    // layer compression ≈ 1.2e-7 m), velocities by 1 mm/s.
    let s_dp = [1e-7, 1e-7, 1e-7, 1e-7, 1e-3, 1e-3, 1e-3, 1e-3];
    let d_dp = [
        3e-8, -2e-8, 5e-8, 1e-8, 5e-4, -7e-4, 2e-4,
        -4e-4, // v stays ≈ 1 m/s, compression > 0
    ];
    let mut variants: Vec<(String, DiscPad)> = vec![("defaults".into(), DiscPad::default())];
    for alpha in [-1.0e4, 3.0e4] {
        let mut m = DiscPad::default();
        m.set("alpha", alpha).unwrap();
        variants.push((format!("alpha = {alpha}"), m));
    }
    let mut m = DiscPad {
        contact: Contact::Bilateral,
        ..DiscPad::default()
    };
    m.set("alpha", -2.0e4).unwrap();
    variants.push(("bilateral, alpha = -2e4".into(), m));
    let mut m = DiscPad {
        friction: FrictionLaw::by_name("stribeck").unwrap(),
        ..DiscPad::default()
    };
    m.set("V", 0.7).unwrap();
    variants.push(("stribeck law, V = 0.7".into(), m));
    let mut m = DiscPad::default();
    m.set("V", 20.0).unwrap();
    m.set("N", 2000.0).unwrap();
    variants.push(("V = 20 > Uc, N = 2000".into(), m));
    for (label, m) in &variants {
        let z = m.equilibrium().unwrap();
        check_jacobian(m, &z, &s_dp, &format!("disc-pad {label}, equilibrium"));
        let zp = perturbed(&z, &d_dp);
        check_jacobian(m, &zp, &s_dp, &format!("disc-pad {label}, perturbed"));
    }

    // Belt: x* = μN/k ≈ 1e-3 m.
    for law in ["thesis", "stribeck", "rational", "tanh"] {
        let mut b = Belt {
            friction: FrictionLaw::by_name(law).unwrap(),
            ..Belt::default()
        };
        b.set("c", 0.3).unwrap();
        b.set("V", 0.8).unwrap();
        let z = b.equilibrium().unwrap();
        let s = [1e-3, 1e-3];
        check_jacobian(&b, &z, &s, &format!("belt {law}, equilibrium"));
        let zp = perturbed(&z, &[2e-4, 3e-4]);
        check_jacobian(&b, &zp, &s, &format!("belt {law}, perturbed"));
    }

    // Hoffmann: x* ≈ 3e-3 m, y* ≈ −5e-4 m.
    let mut thesis = Hoffmann {
        friction: FrictionLaw::default(),
        ..Hoffmann::default()
    };
    thesis.set("V", 2.0).unwrap();
    for (label, h) in [("coulomb", Hoffmann::default()), ("thesis law", thesis)] {
        let z = h.equilibrium().unwrap();
        let s = [1e-3, 1e-3, 1e-3, 1e-3];
        check_jacobian(&h, &z, &s, &format!("hoffmann {label}, equilibrium"));
        let zp = perturbed(&z, &[4e-4, -3e-4, 2e-4, -5e-4]);
        check_jacobian(&h, &zp, &s, &format!("hoffmann {label}, perturbed"));
    }
}

// ---------------------------------------------------------------------------
// Disc–pad eigenvalues
// ---------------------------------------------------------------------------

/// The disc–pad state matrix at the default steady sliding, as printed by
/// `{:?}` and used by `bench/eig_reference.py`.
const REF_J: [[f64; 8]; 8] = [
    [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
    [
        -1000000000.0,
        -0.0,
        -397516666.6666667,
        397516666.6666667,
        2.1333333333332614,
        -3.1333333333332614,
        -0.01870666666666667,
        0.01870666666666667,
    ],
    [
        0.0,
        -17000000000.0,
        3975166666.6666665,
        -3975166666.6666665,
        -31.33333333333261,
        29.33333333333261,
        0.1870666666666667,
        -0.1870666666666667,
    ],
    [
        -0.0,
        -0.0,
        -4258000000.0,
        4250000000.0,
        0.0,
        -0.0,
        -1.2,
        0.2,
    ],
    [0.0, 0.0, 42500000000.0, -42500000000.0, 0.0, 0.0, 2.0, -2.0],
];

/// Eigenvalues of `REF_J` in 50-digit arithmetic, printed by
/// `python3 bench/eig_reference.py` (mpmath 1.3.0), rounded to 17 digits.
#[allow(clippy::excessive_precision)]
const REF_EIG: [(f64, f64); 8] = [
    (14.666666665336814757, 130384.04687911401043),
    (14.666666665336814757, -130384.04687911401043),
    (1.0666666679961213975, 31622.776680714383071),
    (1.0666666679961213975, -31622.776680714383071),
    (-0.45453131184225347359, 2696.7784319682003378),
    (-0.45453131184225347359, -2696.7784319682003378),
    (-1.1454686881577465042, 216219.16516462542378),
    (-1.1454686881577465042, -216219.16516462542378),
];

#[test]
fn disc_pad_default_eigenvalues_match_50_digit_reference() {
    let m = DiscPad::default();
    let z = m.equilibrium().unwrap();
    let j = m.jacobian(&z);
    // The reference was computed for exactly this matrix.
    for r in 0..8 {
        for c in 0..8 {
            assert_eq!(
                j[r][c], REF_J[r][c],
                "J[{r}][{c}] changed: rerun the script"
            );
        }
    }
    let a = analyse(&m).unwrap();
    assert_eq!(a.eigen.len(), 8);
    for (re, im) in REF_EIG {
        let mag = re.hypot(im);
        let e = a
            .eigen
            .iter()
            .min_by(|p, q| {
                let dp = (p.re - re).hypot(p.im - im);
                let dq = (q.re - re).hypot(q.im - im);
                dp.total_cmp(&dq)
            })
            .unwrap();
        let err = (e.re - re).hypot(e.im - im);
        assert!(
            err <= 1e-9 * mag,
            "λ = {re} + {im}i: got {} + {}i, |Δλ|/|λ| = {:e}",
            e.re,
            e.im,
            err / mag
        );
        assert!((e.re - re).abs() < 1e-6, "σ = {re}: got {}", e.re);
    }
    // MODEL.md §5, loosely: disc normal 429 Hz (stable), disc tangential
    // 5.03 kHz (σ ≈ +1.07), pad tangential 20.75 kHz (σ ≈ +14.7), pad normal
    // 34.4 kHz (stable). Attribution weighted by the masses.
    let a = analyse_with_masses(&m, &m.position_masses()).unwrap();
    let expect = [
        (20750.0, 5.0, 14.7, 0.05, "x_p", true),
        (5030.0, 5.0, 1.07, 0.01, "x_d", true),
        (429.0, 0.5, f64::NAN, 0.0, "y_d", false),
        (34400.0, 50.0, f64::NAN, 0.0, "y_p", false),
    ];
    for (k, (f, ftol, s, stol, name, growing)) in expect.into_iter().enumerate() {
        let e = &a.eigen[2 * k];
        assert!((e.freq_hz - f).abs() <= ftol, "mode {k}: {} Hz", e.freq_hz);
        if growing {
            assert!((e.re - s).abs() <= stol, "mode {k}: σ = {}", e.re);
        } else {
            assert!(e.re < 0.0);
        }
        assert_eq!(e.dominant_name, name, "mode {k} at {} Hz", e.freq_hz);
        assert_eq!(e.growing, growing);
        // Conjugate pairs are both listed, +ω first.
        let c = &a.eigen[2 * k + 1];
        assert_eq!((c.re, c.freq_hz), (e.re, e.freq_hz));
        assert!(e.im > 0.0 && c.im < 0.0);
    }
    assert!(!a.stable);
    assert_eq!(a.least_stable, 0);
    assert_eq!(a.max_growth_rate, a.eigen[0].re);
    // The fast path gives the same σ_max and frequency.
    let (s, f) = max_growth_rate(&m).unwrap();
    assert_eq!((s, f), (a.eigen[0].re, a.eigen[0].freq_hz));
    // Eigenvectors: each row's residual |(Au − λu)_i| within 1e-12 of the
    // size of that row's terms Σ_k |A_ik u_k| + |λ u_i|, or 1e-15 of the
    // largest row's (components ~1e-46 of the norm, e.g. the normal
    // coordinates of a tangential mode, carry only absolute accuracy).
    for e in &a.eigen {
        let lam = nalgebra::Complex::new(e.re, e.im);
        let u = &e.vector;
        let unorm = u.iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt();
        assert!((unorm - 1.0).abs() < 1e-12);
        let mut rows = [(0.0, 0.0); 8];
        for i in 0..8 {
            let mut r = -lam * u[i];
            let mut size = (lam * u[i]).norm();
            for k in 0..8 {
                r += j[i][k] * u[k];
                size += (j[i][k] * u[k]).norm();
            }
            rows[i] = (r.norm(), size);
        }
        let biggest = rows.iter().map(|r| r.1).fold(0.0, f64::max);
        for (i, (r, size)) in rows.iter().enumerate() {
            assert!(
                *r <= 1e-12 * size + 1e-15 * biggest,
                "mode {} Hz row {i}: residual {r:e}, row size {size:e}, largest {biggest:e}",
                e.freq_hz
            );
        }
    }
}

#[test]
fn no_steady_sliding_is_an_error_with_the_models_message() {
    let mut m = DiscPad::default();
    m.set("V", 0.0).unwrap();
    match analyse(&m) {
        Err(StabilityError::NoSteadySliding(msg)) => assert!(msg.contains("V = 0"), "{msg}"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        max_growth_rate(&m),
        Err(StabilityError::NoSteadySliding(_))
    ));
    // Follower force: steady sliding needs 1 − α μ(V) y_d* > 0 with y_d* = −N/k_dy,
    // i.e. α > α_c = −k_dy/(μ(V) N) ≈ −1.71e5 1/m with the defaults.
    let m0 = DiscPad::default();
    let alpha_c = -m0.p.k_dy / (m0.friction.mu(m0.p.V) * m0.p.N);
    assert!((alpha_c + 1.7106e5).abs() < 1e2, "{alpha_c}");
    let mut m = m0;
    m.set("alpha", alpha_c * (1.0 + 1e-9)).unwrap();
    match analyse(&m) {
        Err(StabilityError::NoSteadySliding(msg)) => assert!(msg.contains("alpha"), "{msg}"),
        other => panic!("{other:?}"),
    }
    m.set("alpha", -1.72e5).unwrap();
    assert!(max_growth_rate(&m).is_err());
    m.set("alpha", alpha_c * (1.0 - 1e-6)).unwrap();
    assert!(analyse(&m).is_ok());
}

#[test]
fn disc_pad_decoupled_limit_matches_one_dof_criterion() {
    // With α = 0 the normal block does not feel the tangential one, so the
    // tangential eigenvalues are the roots of
    //   P_d(s) P_p(s) − d² s² = 0,  d = N μ'(V),
    //   P_d = m_d s² + (c_dx + d) s + k_dx,  P_p = m_p s² + (c_px + d) s + k_px.
    // At d²→0 the disc root is s_d = σ₀ + iω₀, σ₀ = −(c_dx + N μ'(V))/(2 m_d)
    // (thesis 12.1). First-order perturbation in d² gives the shift
    //   δs = d² s_d² / (P_d'(s_d) P_p(s_d)),  P_d'(s_d) = 2 i m_d ω₀,
    // which is O(d² ω₀ / (m_d |k_px − m_p ω₀²|)). Making the pad heavy and stiff
    // (m_p, k_px, c_px × S: same pad frequency) shrinks it like 1/S.
    for scale in [1.0, 10.0, 1000.0] {
        let mut m = DiscPad::default();
        for key in ["m_p", "k_px", "c_px"] {
            let v = m.get(key).unwrap();
            m.set(key, v * scale).unwrap();
        }
        let p = m.p;
        let d = p.N * m.friction.dmu(p.V);
        let sigma0 = -(p.c_dx + d) / (2.0 * p.m_d);
        let omega0 = (p.k_dx / p.m_d - sigma0 * sigma0).sqrt();
        let s = nalgebra::Complex::new(sigma0, omega0);
        let pp = p.m_p * s * s + (p.c_px + d) * s + p.k_px;
        let ds = d * d * s * s / (nalgebra::Complex::new(0.0, 2.0 * p.m_d * omega0) * pp);
        let a = analyse(&m).unwrap();
        let e = a
            .eigen
            .iter()
            .find(|e| (e.freq_hz - omega0 / (2.0 * PI)).abs() < 10.0 && e.im > 0.0)
            .unwrap();
        // Claim 1: σ equals the one-DOF value to within the coupling's size |δs|.
        assert!(
            (e.re - sigma0).abs() <= ds.norm(),
            "S = {scale}: σ = {} vs σ₀ = {sigma0} (|δs| = {:e})",
            e.re,
            ds.norm()
        );
        // Claim 2: the deviation is the first-order shift, to 1 % of it
        // (the next order is O(|δs|²/ω₀)) plus 1e-12 1/s for round-off.
        let dev = e.re - sigma0;
        assert!(
            (dev - ds.re).abs() <= 1e-2 * ds.re.abs() + 1e-12,
            "S = {scale}: σ − σ₀ = {dev:e}, predicted {:e}",
            ds.re
        );
        assert!(
            (e.im - omega0 - ds.im).abs() <= 1e-2 * ds.im.abs() + 1e-9,
            "S = {scale}: ω − ω₀ = {:e}, predicted {:e}",
            e.im - omega0,
            ds.im
        );
    }
}

// ---------------------------------------------------------------------------
// Critical values
// ---------------------------------------------------------------------------

#[test]
fn belt_critical_speed_is_the_hopf_point() {
    // One DOF: σ = −(c + N μ'(V))/(2m), with μ'(V) = −f0 f1 (1 − V/Uc):
    // zero at V_H = Uc (1 − c/(N f0 f1)) (MODEL.md §5). Unstable below.
    for (c, n) in [(0.2, 100.0), (0.05, 500.0), (1.0, 2000.0)] {
        let mut b = Belt::default();
        b.set("c", c).unwrap();
        b.set("N", n).unwrap();
        let (f0, f1, uc) = (0.1, 1.0 / 15.0, 50.0 / 3.0);
        let v_h = uc * (1.0 - c / (n * f0 * f1));
        let cross = critical(
            |v| {
                let mut m = b;
                m.set("V", v)?;
                max_growth_rate(&m)
            },
            0.1,
            30.0,
            &CriticalOptions::default(),
        )
        .unwrap()
        .unwrap();
        assert!(
            (cross.value - v_h).abs() <= 1e-9 * v_h,
            "c = {c}, N = {n}: {} vs {v_h}",
            cross.value
        );
        assert_eq!(cross.direction, Direction::Stabilising);
        assert!(!cross.from_neutral);
        // At the Hopf point the frequency is the undamped one, √(k/m)/2π.
        let f = (b.p.k / b.p.m).sqrt() / (2.0 * PI);
        assert!((cross.freq_hz - f).abs() <= 1e-9 * f, "{}", cross.freq_hz);
    }
}

/// Coefficients of det(m s² I + C s + K(μ)) = a4 s⁴ + a3 s³ + a2 s² + a1 s + a0
/// for the Hoffmann model, with a0 = a00 + μ k12 k3.
fn hoffmann_quartic(h: &Hoffmann) -> (f64, f64, f64, f64, f64) {
    let p = &h.p;
    let a4 = p.m * p.m;
    let a3 = p.m * (p.c1 + p.c2);
    let a2 = p.m * (p.k11 + p.k22) + p.c1 * p.c2;
    let a1 = p.c1 * p.k22 + p.c2 * p.k11;
    let a00 = p.k11 * p.k22 - p.k12 * p.k12;
    (a4, a3, a2, a1, a00)
}

/// Undamped flutter threshold: `m s²` solves λ² + (k11 + k22) λ + a0(μ) = 0,
/// whose discriminant (k11 − k22)² + 4 k12² − 4 μ k12 k3 vanishes at
/// μ_c = ((k11 − k22)² + 4 k12²)/(4 k12 k3) (coalescence at ω² = (k11 + k22)/(2m)).
fn mu_undamped(h: &Hoffmann) -> f64 {
    let p = &h.p;
    ((p.k11 - p.k22).powi(2) + 4.0 * p.k12 * p.k12) / (4.0 * p.k12 * p.k3)
}

/// Damped threshold (Routh–Hurwitz for a quartic with positive coefficients):
/// stable iff H = a3 a2 a1 − a4 a1² − a3² a0 > 0. H is affine in μ (only a0
/// depends on it), so H = 0 at μ* = (a3 a2 a1 − a4 a1² − a3² a00)/(a3² k12 k3),
/// where s = iω with ω² = a1/a3 is a root.
fn mu_damped(h: &Hoffmann) -> (f64, f64) {
    let (a4, a3, a2, a1, a00) = hoffmann_quartic(h);
    let mu = (a3 * a2 * a1 - a4 * a1 * a1 - a3 * a3 * a00) / (a3 * a3 * h.p.k12 * h.p.k3);
    (mu, (a1 / a3).sqrt() / (2.0 * PI))
}

fn hoffmann_critical_mu(h: &Hoffmann) -> squeal_core::stability::Crossing {
    critical(
        |mu| {
            let mut m = *h;
            m.set("mu", mu)?;
            max_growth_rate(&m)
        },
        0.05,
        0.6,
        &CriticalOptions::default(),
    )
    .unwrap()
    .unwrap()
}

#[test]
fn hoffmann_undamped_flutter_at_coalescence() {
    let mut h = Hoffmann::default();
    h.set("c1", 0.0).unwrap();
    h.set("c2", 0.0).unwrap();
    let mu_c = mu_undamped(&h);
    assert!((mu_c - 0.25).abs() < 1e-15);
    let cross = hoffmann_critical_mu(&h);
    assert!(
        (cross.value - mu_c).abs() <= 1e-9 * mu_c,
        "{} vs {mu_c}",
        cross.value
    );
    assert!(cross.from_neutral);
    assert_eq!(cross.direction, Direction::Destabilising);
    let f = ((h.p.k11 + h.p.k22) / (2.0 * h.p.m)).sqrt() / (2.0 * PI);
    assert!(
        (cross.freq_hz - f).abs() <= 1e-6 * f,
        "{} vs {f}",
        cross.freq_hz
    );
    // Below: neutral (not stable: no mode is damped), both frequencies
    // distinct; above: a ±σ pair.
    let mut below = h;
    below.set("mu", 0.9 * mu_c).unwrap();
    let a = analyse(&below).unwrap();
    assert!(!a.stable && a.neutral);
    assert!(a
        .eigen
        .iter()
        .all(|e| e.neutral && !e.growing && e.re.abs() <= 1e-12 * e.im.abs()));
    let mut above = h;
    above.set("mu", 1.2 * mu_c).unwrap();
    let a = analyse(&above).unwrap();
    assert!(!a.stable);
    let (s0, s3) = (a.eigen[0].re, a.eigen[3].re);
    assert!((s0 + s3).abs() <= 1e-12 * a.eigen[0].im.abs(), "{s0} {s3}");
}

#[test]
fn hoffmann_damped_thresholds_match_routh_hurwitz() {
    let mu_c = mu_undamped(&Hoffmann::default());
    // Equal damping (the defaults, and heavier): the threshold rises above μ_c.
    // Unequal damping with k11 ≠ k22: it drops below μ_c, even for damping
    // tending to zero (the destabilising effect of damping: as c → 0 with
    // c1/c2 fixed, a0* → r (k11 + k22 − r) < (k11 + k22)²/4 with
    // r = (c1 k22 + c2 k11)/(c1 + c2)).
    let cases = [
        (0.5, 0.5, true),
        (5.0, 5.0, true),
        (0.1, 1.0, false),
        (2.0, 0.05, false),
    ];
    for (c1, c2, above) in cases {
        let mut h = Hoffmann::default();
        h.set("c1", c1).unwrap();
        h.set("c2", c2).unwrap();
        let (mu_star, f_star) = mu_damped(&h);
        assert_eq!(mu_star > mu_c, above, "c = ({c1}, {c2}): μ* = {mu_star}");
        let cross = hoffmann_critical_mu(&h);
        assert!(
            (cross.value - mu_star).abs() <= 1e-9 * mu_star,
            "c = ({c1}, {c2}): {} vs {mu_star}",
            cross.value
        );
        assert!(!cross.from_neutral);
        assert_eq!(cross.direction, Direction::Destabilising);
        assert!(
            (cross.freq_hz - f_star).abs() <= 1e-7 * f_star,
            "{} vs {f_star}",
            cross.freq_hz
        );
    }
}

#[test]
fn hoffmann_equal_damping_eigenvalues_are_exact() {
    // C = cI commutes with everything: each eigenvalue κ of K(μ) gives
    // m s² + c s + κ = 0, κ = (k11 + k22)/2 ± √(((k11 − k22)/2)² + k12 (k12 − μ k3)).
    let h = Hoffmann::default();
    let p = h.p;
    let mu = h.get("mu").unwrap();
    let c = p.c1;
    let disc = nalgebra::Complex::new(
        ((p.k11 - p.k22) / 2.0).powi(2) + p.k12 * (p.k12 - mu * p.k3),
        0.0,
    )
    .sqrt();
    let a = analyse(&h).unwrap();
    for sign in [1.0, -1.0] {
        let kappa = nalgebra::Complex::new((p.k11 + p.k22) / 2.0, 0.0) + sign * disc;
        let root = (nalgebra::Complex::new(c * c, 0.0) - 4.0 * p.m * kappa).sqrt();
        for s in [(-c + root) / (2.0 * p.m), (-c - root) / (2.0 * p.m)] {
            let best = a
                .eigen
                .iter()
                .map(|e| (e.re - s.re).hypot(e.im - s.im))
                .fold(f64::INFINITY, f64::min);
            assert!(best <= 1e-12 * s.norm(), "{s}: {best:e}");
        }
    }
    // The default flutters (MODEL-level claim of the module docs): σ ≈ 4.5 at 16.7 Hz.
    assert!(!a.stable);
    assert!((a.eigen[0].re - 4.51).abs() < 0.01, "{}", a.eigen[0].re);
    assert!((a.eigen[0].freq_hz - 16.71).abs() < 0.01);
}

// ---------------------------------------------------------------------------
// Transients grow at σ
// ---------------------------------------------------------------------------

/// Growth rate from the maxima of `x(t) − x*`: for one mode
/// `A e^{σt} cos(ωt + φ)` the maxima are exactly one period apart and grow by
/// `e^{σT}`; each maximum is refined by a parabola through three samples,
/// and σ is the least-squares slope of ln(maximum) against time.
fn fitted_growth(t: &[f64], x: &[f64], x_eq: f64, t_from: f64) -> f64 {
    let mut pts = Vec::new();
    for k in 1..x.len() - 1 {
        let (a, b, c) = (x[k - 1] - x_eq, x[k] - x_eq, x[k + 1] - x_eq);
        if t[k] >= t_from && b > 0.0 && b >= a && b > c {
            let denom = a - 2.0 * b + c;
            let off = 0.5 * (a - c) / denom;
            let peak = b - 0.25 * (a - c) * off;
            let tp = t[k] + off * (t[k + 1] - t[k]);
            pts.push((tp, peak.ln()));
        }
    }
    assert!(pts.len() >= 10, "only {} maxima", pts.len());
    let n = pts.len() as f64;
    let (st, sy) = pts.iter().fold((0.0, 0.0), |(a, b), (t, y)| (a + t, b + y));
    let (mt, my) = (st / n, sy / n);
    let (num, den) = pts.iter().fold((0.0, 0.0), |(a, b), (t, y)| {
        (a + (t - mt) * (y - my), b + (t - mt) * (t - mt))
    });
    num / den
}

#[test]
fn hoffmann_transient_grows_at_the_eigen_growth_rate() {
    let h = Hoffmann::default();
    let a = analyse(&h).unwrap();
    let sigma = a.max_growth_rate;
    let f = a.eigen[0].freq_hz;
    // The partner mode decays at −(c1 + c2)/m − σ (trace of A = 2σ₁ + 2σ₂):
    // after 1 s it is e^{−10} of the growing one; fit from 1 s to 2.5 s, while
    // the amplitude (1e-8 m · e^{4.5·2.5} ≈ 1e-3 m) stays far below both stick
    // (ẋ = V, x ≈ 1e-2 m) and loss of contact (y ≈ −N*/k3 ≈ 1e-2 m).
    let z_eq = h.equilibrium().unwrap();
    let mut z0 = z_eq;
    z0[0] += 1e-8;
    let mut rec = Recorder::<4>::new();
    let opts = SolverOptions {
        rtol: 1e-10,
        atol_pos: Some(1e-16),
        atol_vel: Some(1e-14),
        ..Default::default()
    };
    simulate(&h, 0.0, z0, 2.5, 200.0 * f, opts, &mut rec).unwrap();
    assert!(rec.events.is_empty(), "left the linear slip regime");
    let fit = fitted_growth(&rec.t, &rec.component(0), z_eq[0], 1.0);
    assert!(
        (fit - sigma).abs() <= 0.02 * sigma,
        "fitted σ = {fit} vs eigenvalue σ = {sigma}"
    );
}

#[test]
fn belt_transient_grows_below_the_hopf_speed() {
    // Thesis law, c = 0.2, N = 100, V = 1 < V_H ≈ 11.7 m/s:
    // σ = −(c + N μ'(V))/(2m) ≈ +0.213 1/s at 15.9 Hz.
    let mut b = Belt::default();
    b.set("c", 0.2).unwrap();
    b.set("V", 1.0).unwrap();
    let a = analyse(&b).unwrap();
    let sigma = a.max_growth_rate;
    let exact = -(b.p.c + b.p.N * b.friction.dmu(b.p.V)) / (2.0 * b.p.m);
    assert!((sigma - exact).abs() <= 1e-12 * a.eigen[0].im.abs());
    let z_eq = b.equilibrium().unwrap();
    let mut z0 = z_eq;
    z0[0] += 1e-6; // velocity amplitude ≈ 1e-4 m/s ≪ V: μ stays linear enough
    let mut rec = Recorder::<2>::new();
    let opts = SolverOptions {
        rtol: 1e-10,
        atol_pos: Some(1e-15),
        atol_vel: Some(1e-13),
        ..Default::default()
    };
    let f = a.eigen[0].freq_hz;
    simulate(&b, 0.0, z0, 15.0, 200.0 * f, opts, &mut rec).unwrap();
    assert!(rec.events.is_empty());
    let fit = fitted_growth(&rec.t, &rec.component(0), z_eq[0], 0.0);
    assert!(
        (fit - sigma).abs() <= 0.02 * sigma,
        "fitted σ = {fit} vs eigenvalue σ = {sigma}"
    );
}

// ---------------------------------------------------------------------------
// Hoffmann nonlinear model
// ---------------------------------------------------------------------------

#[test]
fn hoffmann_flutter_saturates_through_friction_events() {
    // Above threshold the linear growth ends in stick-slip and/or loss of
    // contact; the run must go through those events and stay bounded.
    let h = Hoffmann::default();
    let mut z0 = h.equilibrium().unwrap();
    z0[0] += 1e-4;
    let mut rec = Recorder::<4>::new();
    simulate(&h, 0.0, z0, 6.0, 1000.0, SolverOptions::default(), &mut rec).unwrap();
    assert!(!rec.events.is_empty());
    let xmax = rec.z.iter().map(|z| z[0].abs()).fold(0.0, f64::max);
    assert!(xmax < 0.1, "{xmax}");
    // Every event state satisfies its surface: v = 0 for stick/slip/reverse,
    // N = 0 for separate/contact (to 1e-9 of the scales V and N0).
    for e in &rec.events {
        use squeal_core::EventKind::*;
        match e.kind {
            Stick | Reverse => assert!((h.p.V - e.z[2]).abs() <= 1e-9 * h.p.V, "{e:?}"),
            Separate | Contact => {
                assert!(h.normal_force(&e.z).abs() <= 1e-9 * h.p.N0, "{e:?}")
            }
            Slip => {}
        }
    }
}

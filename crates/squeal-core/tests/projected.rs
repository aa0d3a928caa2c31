//! Complex eigenvalue analysis by projection onto undamped modes
//! (`stability::projected`) against the dense solve of the full state
//! matrix: the exact limit (every mode kept: equal to round-off), convergence
//! of the eigenvalues in the band as the basis grows, a consistent (non-
//! diagonal) mass matrix, and the options' keys on a lumped model.

use nalgebra::Complex;
use squeal_core::model::lumped::{disc_pad_spec, LumpedSpec, SpringSpec, Triplets};
use squeal_core::stability::modal::mode_shape;
use squeal_core::stability::projected::{
    analyse_projected, projected_eigenvalues, Basis, Method, SecondOrder,
};
use squeal_core::stability::{lumped as lumped_stability, Analysis};
use squeal_core::{DiscPad, Lumped};

/// The thesis's disc–pad (its friction makes `K` non-symmetric and one mode
/// unstable) with a chain of `extra` masses attached to the disc on both
/// axes: `extra + 4` dofs whose undamped frequencies spread from a few
/// hundred Hz to ≈ 60 kHz. `consistent`: the chain's masses as a consistent
/// (tridiagonal) mass matrix `M` instead of `[masses]`.
fn embedded(extra: usize, consistent: bool) -> Lumped {
    let mut spec: LumpedSpec = disc_pad_spec(&DiscPad::default());
    let mut mm = Triplets {
        rows: extra + 4,
        cols: extra + 4,
        entries: Vec::new(),
    };
    for i in 0..extra {
        let name = format!("c{i}");
        spec.dofs.push(name.clone());
        let m = 0.02 * (1.0 + 0.5 * ((i as f64) * 0.7).sin());
        if consistent {
            // A bar element's consistent mass between neighbours, on top of a lumped part.
            let r = 4 + i;
            mm.entries.push((r, r, m));
            if i + 1 < extra {
                mm.entries.push((r, r + 1, 0.25 * m));
                mm.entries.push((r + 1, r, 0.25 * m));
                mm.entries.push((r + 1, r + 1, 0.5 * m));
            }
        } else {
            spec.masses.push((name.clone(), m));
        }
        let k = 2.0e9 * (1.0 + 0.3 * ((i as f64) * 1.3).cos());
        let on = if i == 0 {
            vec![(name.clone(), 1.0)]
        } else {
            vec![(name.clone(), 1.0), (format!("c{}", i - 1), -1.0)]
        };
        spec.springs.push(SpringSpec {
            name: format!("s{i}"),
            on,
            k,
            c: 2e-8 * k,
            k3: 0.0,
        });
    }
    if consistent {
        // Index the existing dofs in the order of `spec.dofs` (disc–pad first).
        spec.m = Some(mm);
    }
    for (name, dof, tip) in [("link_x", "x_d", 0), ("link_y", "y_d", extra - 1)] {
        spec.springs.push(SpringSpec {
            name: name.into(),
            on: vec![(dof.into(), 1.0), (format!("c{tip}"), -1.0)],
            k: 5.0e6,
            c: 0.5,
            k3: 0.0,
        });
    }
    Lumped::build(&spec).unwrap_or_else(|e| panic!("{e}"))
}

fn dense(l: &Lumped) -> Analysis {
    let mut l = l.clone();
    l.modal.dense_max_dofs = usize::MAX;
    lumped_stability::analyse(&l, Some(&l.diagonal_masses())).unwrap()
}

fn projected(l: &Lumped, modes: usize) -> Analysis {
    let mut l = l.clone();
    l.modal.dense_max_dofs = 0;
    l.modal.modes = modes;
    lumped_stability::analyse(&l, Some(&l.diagonal_masses())).unwrap()
}

/// Largest relative distance from each eigenvalue of `an` with
/// frequency ≤ `band_hz` to the nearest eigenvalue of `reference`.
fn band_error(an: &Analysis, reference: &Analysis, band_hz: f64) -> f64 {
    reference
        .eigen
        .iter()
        .filter(|e| e.freq_hz <= band_hz)
        .map(|e| {
            let l = Complex::new(e.re, e.im);
            an.eigen
                .iter()
                .map(|r| (Complex::new(r.re, r.im) - l).norm() / l.norm())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Every eigenvalue of `a` within `tol·|λ|` of one of `b`'s, and as many.
fn same_spectrum(a: &Analysis, b: &Analysis, tol: f64, label: &str) {
    assert_eq!(a.eigen.len(), b.eigen.len(), "{label}");
    for e in &a.eigen {
        let l = Complex::new(e.re, e.im);
        let best = b
            .eigen
            .iter()
            .map(|r| (Complex::new(r.re, r.im) - l).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(best <= tol * l.norm(), "{label}: {l} off by {best:e}");
    }
}

/// With every undamped mode kept, `Φ` is an invertible change of
/// coordinates: the reduced state matrix is similar to the full one, so the
/// eigenvalues are the dense solve's to round-off (1e-9 relative: both
/// solves' backward error is ≈ 1e-15 of the spectral radius, 1.4e5 Hz, and
/// the smallest eigenvalues are ≈ 1/500 of it) and the mode shapes equal.
/// Diagonal and consistent (non-diagonal) mass matrices.
#[test]
fn every_mode_kept_equals_the_dense_solve() {
    for consistent in [false, true] {
        let l = embedded(200, consistent);
        let n = l.dof_count();
        let d = dense(&l);
        let p = projected(&l, n);
        assert_eq!(d.method, Method::Dense);
        match p.method {
            Method::Projected { modes, dofs, .. } => assert_eq!((modes, dofs), (n, n)),
            Method::Dense => panic!("asked for the projection"),
        }
        let label = format!("consistent mass: {consistent}");
        same_spectrum(&p, &d, 1e-9, &label);
        same_spectrum(&d, &p, 1e-9, &label);
        assert!(d.eigen[0].growing && p.eigen[0].growing, "{label}");
        // The flutter mode's shape (amplitude and phase per dof).
        let (sd, sp) = (mode_shape(&d.eigen[0]), mode_shape(&p.eigen[0]));
        for (x, y) in sd.iter().zip(&sp) {
            assert!((x - y).norm() <= 1e-7, "{label}: shape {x} vs {y}");
        }
        assert_eq!(d.eigen[0].dominant_name, p.eigen[0].dominant_name);
    }
}

/// The eigenvalues in the band (≤ 25 kHz: the flutter mode at 20.75 kHz and
/// everything below) converge as the basis grows. The flutter is the
/// coupling of the pad's tangential mode with the pad's normal (contact)
/// mode at 34.4 kHz: a basis of modes cut at 25 kHz misses it and had the
/// band wrong by 5e-3 relative; the static correction at the contact dofs
/// (`with_static_correction`, 4 vectors) holds the contact's local
/// flexibility, and every cut-off now gives the band to 1e-9 of the dense
/// solve (the flutter mode's growth rate to 1e-9 of |λ|); the error never
/// grows with the basis (nested Ritz spaces; slack for round-off) and
/// vanishes with all modes (1e-10).
#[test]
fn band_eigenvalues_converge_as_the_basis_grows() {
    let l = embedded(200, false);
    let d = dense(&l);
    let band = 25_000.0;
    let mut errors = Vec::new();
    for cutoff in [25e3, 40e3, 60e3, 80e3, 120e3, 1e6] {
        let mut lc = l.clone();
        lc.modal.dense_max_dofs = 0;
        lc.modal.cutoff_hz = cutoff;
        let p = lumped_stability::analyse(&lc, Some(&lc.diagonal_masses())).unwrap();
        let Method::Projected {
            basis_max_hz,
            modes,
            ..
        } = p.method
        else {
            panic!("projected")
        };
        assert!(basis_max_hz <= cutoff && modes <= l.dof_count());
        errors.push((cutoff, modes, band_error(&p, &d, band), p.eigen[0].re));
    }
    let flutter = &d.eigen[0];
    let mag = flutter.re.hypot(flutter.im);
    for w in errors.windows(2) {
        assert!(w[1].2 <= 1.01 * w[0].2 + 1e-10, "{errors:?}");
    }
    for &(cutoff, _, err, sigma) in &errors {
        assert!(err <= 1e-9, "cut-off {cutoff}: {errors:?}");
        assert!(
            (sigma - flutter.re).abs() <= 1e-9 * mag,
            "cut-off {cutoff}: σ {sigma} vs {}",
            flutter.re
        );
    }
    let last = errors.last().unwrap();
    assert_eq!(last.1, l.dof_count());
    assert!(last.2 <= 1e-10, "{errors:?}");
}

/// The eigenvalue-only path (maps, `critical`) gives the analysis's
/// eigenvalues, and the same method.
#[test]
fn projected_eigenvalues_equal_the_analysis() {
    let mut l = embedded(120, true);
    l.modal.dense_max_dofs = 100;
    let an = lumped_stability::analyse(&l, None).unwrap();
    let (ev, method) = lumped_stability::eigenvalues_with_method(&l).unwrap();
    assert_eq!(method, an.method);
    assert!(matches!(method, Method::Projected { .. }));
    assert_eq!(ev.len(), an.eigen.len());
    for e in &an.eigen {
        let l = Complex::new(e.re, e.im);
        let best = ev
            .iter()
            .map(|x| (x - l).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(best <= 1e-12 * l.norm(), "{l}: {best:e}");
    }
    let (sigma, _) = lumped_stability::max_growth_rate(&l).unwrap();
    assert_eq!(sigma, an.max_growth_rate);
    // And the core function on the second-order system directly.
    let z = l.equilibrium_dyn().unwrap();
    let sys: SecondOrder = l.second_order_dyn(&z);
    let (ev2, _) = projected_eigenvalues(&sys, l.modal.basis(), l.modal.kind).unwrap();
    assert_eq!(ev2, ev);
    let an2 = analyse_projected(
        &sys,
        &z,
        l.state_names(),
        None,
        Basis::CutoffHz(l.modal.cutoff_hz),
        l.modal.kind,
    )
    .unwrap();
    assert_eq!(an2.max_growth_rate, an.max_growth_rate);
}

/// The options as keys: read back, checked, unknown ones refused; a
/// cut-off below every mode is an error naming the key; `modal` is not an
/// element name.
#[test]
fn modal_keys_are_checked() {
    let mut l = embedded(20, false);
    assert_eq!(l.get("modal.dense_max_dofs"), Some(500.0));
    assert_eq!(l.get("modal.modes"), Some(0.0));
    assert_eq!(l.get("modal.cutoff_hz"), Some(40_000.0));
    l.set("modal.modes", 12.0).unwrap();
    l.set("modal.dense_max_dofs", 0.0).unwrap();
    l.set("modal.cutoff_hz", 1.0).unwrap();
    assert_eq!(l.modal.modes, 12);
    assert!(!l.keys().iter().any(|(k, _)| k.starts_with("modal.")));
    for (k, v) in [
        ("modal.modes", 1.5),
        ("modal.modes", -1.0),
        ("modal.cutoff_hz", 0.0),
        ("modal.dense_max_dofs", f64::NAN),
    ] {
        let e = l.set(k, v).unwrap_err().to_string();
        assert!(e.contains(k), "{k}={v}: {e}");
    }
    assert!(l.set("modal.shift", 1.0).is_err());
    // 12 modes asked for: the cut-off is not used; the disc–pad contact's
    // 4 dofs add 2 static-correction vectors (x_d, y_d, x_p, y_p: their
    // static responses not already in the 12 modes).
    let an = lumped_stability::analyse(&l, None).unwrap();
    let Method::Projected {
        modes,
        static_vectors,
        ..
    } = an.method
    else {
        panic!("projected")
    };
    assert_eq!(modes, 12);
    assert_eq!(an.eigen.len(), 2 * (modes + static_vectors));
    l.set("modal.modes", 0.0).unwrap();
    let e = lumped_stability::analyse(&l, None).unwrap_err().to_string();
    assert!(e.contains("modal.cutoff_hz = 1 Hz"), "{e}");
    let mut spec = disc_pad_spec(&DiscPad::default());
    spec.springs[0].name = "modal".into();
    let e = Lumped::build(&spec).unwrap_err().to_string();
    assert!(e.contains("'modal'"), "{e}");
}

/// The sparse path (the model's sparse linearisation, its real modes by
/// block shift-invert Lanczos, sparse products and solves) gives the dense
/// path's projected eigenvalues: the same basis size, each eigenvalue below
/// half the cut-off within 1e-10 relative (1e-7 above), the same truncation
/// table, and
/// the same eigenvectors (the growing mode's shape to 1e-7).
#[test]
fn sparse_path_equals_the_dense_projection() {
    use squeal_core::stability::projected::{truncation_table, Structure};
    let mut l = embedded(300, true);
    l.modal.dense_max_dofs = 0;
    l.modal.cutoff_hz = 30_000.0;
    let z = l.equilibrium_dyn().unwrap();
    let dense_sys = l.second_order_dyn(&z);
    let sparse_sys = l.second_order_sparse(&z);
    assert_eq!(sparse_sys.to_dense().k, dense_sys.k);
    assert_eq!(sparse_sys.to_dense().m, dense_sys.m);
    assert_eq!(sparse_sys.coupling_dofs(), dense_sys.coupling_dofs());
    let (basis, kind) = (l.modal.basis(), l.modal.kind);
    let (ev_d, m_d) = projected_eigenvalues(&dense_sys, basis, kind).unwrap();
    let (ev_s, m_s) = projected_eigenvalues(&sparse_sys, basis, kind).unwrap();
    let (
        Method::Projected {
            modes,
            static_vectors,
            basis_max_hz,
            ..
        },
        Method::Projected {
            modes: modes_d,
            static_vectors: static_d,
            basis_max_hz: max_d,
            ..
        },
    ) = (m_s, m_d)
    else {
        panic!("{m_s:?} {m_d:?}")
    };
    assert_eq!((modes, static_vectors), (modes_d, static_d));
    assert!((basis_max_hz - max_d).abs() <= 1e-10 * max_d);
    assert!(modes > 20 && modes < 300, "{modes} modes");
    assert_eq!(ev_d.len(), ev_s.len());
    // Within half the cut-off the modes decide; near it the static
    // correction's vectors (re-orthogonalised against the modes) differ by
    // round-off amplified.
    let tol = |e: &Complex<f64>| {
        if e.norm() <= std::f64::consts::PI * 30_000.0 {
            1e-10
        } else {
            1e-7
        }
    };
    for e in &ev_d {
        let best = ev_s
            .iter()
            .map(|x| (x - e).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(best <= tol(e) * e.norm(), "{e}: {best:e}");
    }
    let (t_d, t_s) = (
        truncation_table(&dense_sys, basis, kind).unwrap(),
        truncation_table(&sparse_sys, basis, kind).unwrap(),
    );
    assert_eq!(t_d.len(), t_s.len());
    for (a, b) in t_d.iter().zip(&t_s) {
        assert_eq!((a.modes, a.static_vectors), (b.modes, b.static_vectors));
        for e in &a.eigenvalues {
            let best = b
                .eigenvalues
                .iter()
                .map(|x| (x - e).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(best <= tol(e) * e.norm(), "row {}: {e}: {best:e}", a.modes);
        }
    }
    let names = l.state_names();
    let a_d = analyse_projected(&dense_sys, &z, names, None, basis, kind).unwrap();
    let a_s = analyse_projected(&sparse_sys, &z, names, None, basis, kind).unwrap();
    assert!(!a_d.stable);
    let (g_d, g_s) = (&a_d.eigen[0], &a_s.eigen[0]);
    assert!(
        (g_d.re - g_s.re).abs() <= 1e-9 * g_d.im.abs(),
        "{} vs {}",
        g_d.re,
        g_s.re
    );
    let (s_d, s_s) = (mode_shape(g_d), mode_shape(g_s));
    let diff = s_d
        .iter()
        .zip(&s_s)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(diff < 1e-7, "shape difference {diff:e}");
}

/// The real modes of the dense path are accurate on a structure whose
/// `ω²` spread over six decades (faer's divide-and-conquer eigen-solver,
/// used before, left the lowest mode of this model with a residual of
/// 3 ω²), and the sparse path's Lanczos modes equal them: residuals
/// `‖K_s φ − ω² M φ‖ / (ω² ‖M φ‖)` below 1e-8, frequencies within 1e-10.
#[test]
fn dense_real_modes_are_accurate() {
    use squeal_core::stability::projected::Structure;
    for consistent in [false, true] {
        let mut l = embedded(300, consistent);
        l.modal.cutoff_hz = 30_000.0;
        let z = l.equilibrium_dyn().unwrap();
        let ds = l.second_order_dyn(&z);
        let d = ds.undamped(l.modal.basis()).unwrap();
        let s = l.second_order_sparse(&z).undamped(l.modal.basis()).unwrap();
        assert_eq!(d.omega2.len(), s.omega2.len(), "consistent {consistent}");
        assert!(d.omega2.len() > 40);
        let ks = (&ds.k + ds.k.transpose()) * 0.5;
        for (i, (a, b)) in d.omega2.iter().zip(&s.omega2).enumerate() {
            assert!((a - b).abs() <= 1e-10 * a, "mode {i}: {a:e} vs {b:e}");
            for basis in [&d, &s] {
                let phi = nalgebra::DVector::from_fn(ds.m.nrows(), |r, _| basis.phi[(r, i)]);
                let mphi = &ds.m * &phi;
                let res =
                    (&ks * &phi - &mphi * basis.omega2[i]).norm() / (basis.omega2[i] * mphi.norm());
                assert!(
                    res < 1e-8,
                    "mode {i}: residual {res:e} (consistent {consistent})"
                );
            }
        }
    }
}

/// The analysis and its truncation table computed together (one Lanczos
/// solve and one set of static responses) equal the two computed apart,
/// on the sparse path and for both bases.
#[test]
fn analysis_with_its_table_equals_the_two_apart() {
    use squeal_core::stability::projected::{
        analyse_projected_with_table, truncation_table, BasisKind,
    };
    let mut l = embedded(300, true);
    l.modal.dense_max_dofs = 0;
    l.modal.cutoff_hz = 30_000.0;
    let z = l.equilibrium_dyn().unwrap();
    let names = l.state_names();
    for (sys_sparse, kind) in [(true, BasisKind::Modes), (false, BasisKind::CraigBampton)] {
        let basis = l.modal.basis();
        let (an, table) = if sys_sparse {
            let sys = l.second_order_sparse(&z);
            let (an, t) = analyse_projected_with_table(&sys, &z, names, None, basis, kind).unwrap();
            let apart = analyse_projected(&sys, &z, names, None, basis, kind).unwrap();
            (
                vec![an, apart],
                vec![t.unwrap(), truncation_table(&sys, basis, kind).unwrap()],
            )
        } else {
            let sys = l.second_order_dyn(&z);
            let (an, t) = analyse_projected_with_table(&sys, &z, names, None, basis, kind).unwrap();
            let apart = analyse_projected(&sys, &z, names, None, basis, kind).unwrap();
            (
                vec![an, apart],
                vec![t.unwrap(), truncation_table(&sys, basis, kind).unwrap()],
            )
        };
        assert_eq!(an[0].eigen.len(), an[1].eigen.len());
        assert!(an[0].eigen.len() > 40, "{} modes", an[0].eigen.len());
        for (a, b) in an[0].eigen.iter().zip(&an[1].eigen) {
            let d = (a.re - b.re).hypot(a.im - b.im);
            assert!(d <= 1e-12 * a.re.hypot(a.im), "{kind:?}: {a:?} vs {b:?}");
        }
        assert_eq!(table[0].len(), table[1].len());
        assert!(table[0].len() >= 3, "{} rows", table[0].len());
        for (a, b) in table[0].iter().zip(&table[1]) {
            assert_eq!((a.modes, a.static_vectors), (b.modes, b.static_vectors));
            assert_eq!(a.eigenvalues.len(), b.eigenvalues.len());
            for (x, y) in a.eigenvalues.iter().zip(&b.eigenvalues) {
                assert!(
                    (x - y).norm() <= 1e-12 * x.norm(),
                    "{kind:?} row {}: {x} vs {y}",
                    a.modes
                );
            }
        }
    }
}

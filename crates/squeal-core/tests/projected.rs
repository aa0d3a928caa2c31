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

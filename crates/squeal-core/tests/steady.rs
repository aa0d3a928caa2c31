//! Steady sliding of lumped models (issue 26 §1) against exact results: the
//! force balance itself (the residual of the equations of motion at the
//! state returned, relative to the forces in the balance), an independent
//! dense solve of the same equations, contacts that must open, a pad that
//! barely touches, friction that lifts a pad off (no consistent contact
//! set), a free dof, and the follower force's quadratic with its fold in
//! closed form. The FE-like models are rings of beam elements with two and
//! four pads: their stiffness spans eight decades, where Newton's method
//! with an absolute tolerance failed from 36 elements on.

use squeal_core::model::lumped::{ContactSpec, ForceSpec, LumpedSpec, SpringSpec, Triplets};
use squeal_core::stability::lumped::analyse;
use squeal_core::{FrictionLaw, Lumped};

fn terms(t: &[(&str, f64)]) -> Vec<(String, f64)> {
    t.iter().map(|(n, v)| (n.to_string(), *v)).collect()
}

fn spring(name: &str, on: &[(&str, f64)], k: f64) -> SpringSpec {
    SpringSpec {
        name: name.into(),
        on: terms(on),
        k,
        c: 0.0,
        k3: 0.0,
    }
}

fn force(name: &str, on: &[(&str, f64)], value: f64) -> ForceSpec {
    ForceSpec {
        name: name.into(),
        on: terms(on),
        value,
        ramp: 0.0,
        amplitude: 0.0,
        freq_hz: 0.0,
    }
}

fn coulomb(mu: f64) -> FrictionLaw {
    FrictionLaw::Coulomb {
        mu_s: 1.2 * mu,
        mu_k: mu,
    }
}

fn contact(
    name: &str,
    normal: &[(&str, f64)],
    tangent: &[(&str, f64)],
    k: f64,
    mu: f64,
) -> ContactSpec {
    ContactSpec {
        name: name.into(),
        normal: Some(terms(normal)),
        k: Some(k),
        c: Some(0.0),
        bilateral: false,
        normal_force: None,
        tangent: Some(terms(tangent)),
        v: 5.0,
        friction: coulomb(mu),
        alpha: 0.0,
        slope: Vec::new(),
    }
}

/// One pad: `(node, side, contact stiffness, μ, brake force)`.
struct Pad {
    node: usize,
    side: f64,
    k: f64,
    mu: f64,
    load: f64,
}

/// A steel ring (mean radius 0.15 m, 20 × 50 mm section) of `ne` beam
/// elements with three dofs per node (`<node>_1` circumferential, `_3`
/// out of plane, `_5` rotation), consistent masses, held by hub springs,
/// and pads of 0.3 kg on inclined abutment springs pressed onto it.
fn ring(ne: usize, pads: &[Pad]) -> LumpedSpec {
    let (e, rho, b, h, r) = (210e9, 7850.0, 0.05, 0.02, 0.15);
    let le = 2.0 * std::f64::consts::PI * r / ne as f64;
    let (a, i) = (b * h, b * h * h * h / 12.0);
    let n = 3 * ne + 2 * pads.len();
    let mut m = Triplets {
        rows: n,
        cols: n,
        entries: Vec::new(),
    };
    let mut k = m.clone();
    let l = le;
    let kb = [[1.0, -1.0], [-1.0, 1.0]].map(|r| r.map(|x| x * e * a / le));
    let mb = [[2.0, 1.0], [1.0, 2.0]].map(|r| r.map(|x| x * rho * a * le / 6.0));
    let kw = [
        [12.0, 6.0 * l, -12.0, 6.0 * l],
        [6.0 * l, 4.0 * l * l, -6.0 * l, 2.0 * l * l],
        [-12.0, -6.0 * l, 12.0, -6.0 * l],
        [6.0 * l, 2.0 * l * l, -6.0 * l, 4.0 * l * l],
    ]
    .map(|r| r.map(|x| x * e * i / (l * l * l)));
    let mw = [
        [156.0, 22.0 * l, 54.0, -13.0 * l],
        [22.0 * l, 4.0 * l * l, 13.0 * l, -3.0 * l * l],
        [54.0, 13.0 * l, 156.0, -22.0 * l],
        [-13.0 * l, -3.0 * l * l, -22.0 * l, 4.0 * l * l],
    ]
    .map(|r| r.map(|x| x * rho * a * l / 420.0));
    for el in 0..ne {
        let (p, q) = (el, (el + 1) % ne);
        let u = [3 * p, 3 * q];
        let w = [3 * p + 1, 3 * p + 2, 3 * q + 1, 3 * q + 2];
        for x in 0..2 {
            for y in 0..2 {
                k.entries.push((u[x], u[y], kb[x][y]));
                m.entries.push((u[x], u[y], mb[x][y]));
            }
        }
        for x in 0..4 {
            for y in 0..4 {
                k.entries.push((w[x], w[y], kw[x][y]));
                m.entries.push((w[x], w[y], mw[x][y]));
            }
        }
    }
    let mut spec = LumpedSpec::default();
    for node in 1..=ne {
        for c in [1, 3, 5] {
            spec.dofs.push(format!("{node}_{c}"));
        }
        k.entries.push((3 * (node - 1), 3 * (node - 1), 1e6));
        k.entries
            .push((3 * (node - 1) + 1, 3 * (node - 1) + 1, 1e6));
    }
    let (ca, sa) = (0.5f64.cos(), 0.5f64.sin());
    for (j, p) in pads.iter().enumerate() {
        let id = 9001 + j;
        let (x, y) = (format!("{id}_1"), format!("{id}_3"));
        spec.dofs.push(x.clone());
        spec.dofs.push(y.clone());
        let ix = 3 * ne + 2 * j;
        m.entries.push((ix, ix, 0.3));
        m.entries.push((ix + 1, ix + 1, 0.3));
        spec.springs.push(spring(
            &format!("abutment{id}"),
            &[(&x, ca), (&y, p.side * sa)],
            4e7,
        ));
        spec.springs
            .push(spring(&format!("piston{id}"), &[(&y, 1.0)], 5e6));
        spec.forces
            .push(force(&format!("brake{id}"), &[(&y, 1.0)], -p.side * p.load));
        let (u, w, t) = (
            format!("{}_1", p.node),
            format!("{}_3", p.node),
            format!("{}_5", p.node),
        );
        let normal = if p.side > 0.0 {
            [(w.as_str(), 1.0), (y.as_str(), -1.0)]
        } else {
            [(y.as_str(), 1.0), (w.as_str(), -1.0)]
        };
        spec.contacts.push(contact(
            &format!("pad{}", j + 1),
            &normal,
            &[(&u, 1.0), (&t, -p.side * h / 2.0), (&x, -1.0)],
            p.k,
            p.mu,
        ));
    }
    spec.m = Some(m);
    spec.k = Some(k);
    spec
}

fn two_pads(ne: usize, symmetric: bool) -> Vec<Pad> {
    let a = ne / 8 + 1;
    let (k2, mu2, load2) = if symmetric {
        (5e7, 0.45, 1000.0)
    } else {
        (3.5e7, 0.38, 900.0)
    };
    vec![
        Pad {
            node: a,
            side: 1.0,
            k: 5e7,
            mu: 0.45,
            load: 1000.0,
        },
        Pad {
            node: a,
            side: -1.0,
            k: k2,
            mu: mu2,
            load: load2,
        },
    ]
}

fn four_pads(ne: usize) -> Vec<Pad> {
    let mut p = two_pads(ne, false);
    let b = ne / 8 + 1 + ne / 2;
    p.push(Pad {
        node: b,
        side: 1.0,
        k: 4.5e7,
        mu: 0.47,
        load: 800.0,
    });
    p.push(Pad {
        node: b + 1,
        side: -1.0,
        k: 3.0e7,
        mu: 0.43,
        load: 850.0,
    });
    p
}

fn build(spec: &LumpedSpec) -> Lumped {
    Lumped::build(spec).unwrap_or_else(|e| panic!("{e}"))
}

/// The largest acceleration's force `M q̈` at `z` against the largest
/// force in the balance, both in newtons (the residual of the equations
/// of motion at steady sliding, relative).
fn relative_residual(l: &Lumped, z: &[f64], spec: &LumpedSpec) -> f64 {
    let n = l.dof_count();
    let modes = l.steady_modes_at(z);
    let acc = l.field_dyn(f64::INFINITY, &modes, z);
    // M q̈ from q̈ (M from the spec).
    let mut f = vec![0.0; n];
    for &(i, j, v) in &spec.m.as_ref().unwrap().entries {
        f[i] += v * acc[n + j];
    }
    let scale = spec
        .forces
        .iter()
        .map(|f| f.value.abs())
        .fold(0.0f64, f64::max);
    f.iter().fold(0.0f64, |m, x| m.max(x.abs())) / scale
}

/// An independent solve of the all-closed balance: `A` assembled densely
/// from the spec (not from the model's operators) and solved by nalgebra's
/// full-pivoting LU.
fn dense_steady(spec: &LumpedSpec) -> Vec<f64> {
    let n = spec.dofs.len();
    let ix = |d: &str| spec.dofs.iter().position(|x| x == d).unwrap();
    let vec_of = |t: &[(String, f64)]| {
        let mut v = nalgebra::DVector::<f64>::zeros(n);
        for (d, c) in t {
            v[ix(d)] += c;
        }
        v
    };
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
    for &(i, j, v) in &spec.k.as_ref().unwrap().entries {
        a[(i, j)] += v;
    }
    let mut b = nalgebra::DVector::<f64>::zeros(n);
    for s in &spec.springs {
        let v = vec_of(&s.on);
        a += s.k * &v * v.transpose();
    }
    for f in &spec.forces {
        b += f.value * vec_of(&f.on);
    }
    for c in &spec.contacts {
        let nv = vec_of(c.normal.as_ref().unwrap());
        let tv = vec_of(c.tangent.as_ref().unwrap());
        let k = c.k.unwrap();
        let mu = c.friction.mu(c.v.abs());
        a += k * &nv * nv.transpose() + mu * k * &tv * nv.transpose();
    }
    a.full_piv_lu().solve(&b).unwrap().as_slice().to_vec()
}

#[test]
fn fe_rings_with_two_and_four_pads_slide_steadily_at_every_size() {
    for ne in [4, 36, 44, 100] {
        for (what, pads) in [
            ("symmetric two-pad", two_pads(ne, true)),
            ("asymmetric two-pad", two_pads(ne, false)),
            ("four-pad", four_pads(ne)),
        ] {
            let spec = ring(ne, &pads);
            let l = build(&spec);
            let z = l
                .equilibrium_dyn()
                .unwrap_or_else(|e| panic!("{ne} elements, {what}: {e}"));
            let res = relative_residual(&l, &z, &spec);
            assert!(res < 1e-10, "{ne} elements, {what}: residual {res:e}");
            // Against the independent dense solve, relative to the
            // largest displacement.
            let q = dense_steady(&spec);
            let size = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let diff = q
                .iter()
                .zip(&z)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                diff <= 1e-9 * size,
                "{ne} elements, {what}: differs by {diff:e} of {size:e}"
            );
            // Every pad pushes.
            for c in &l.contacts {
                let f = c.normal_force(&z[..l.dof_count()], &z[l.dof_count()..]);
                assert!(f > 100.0, "{ne} elements, {what}: {} F_n = {f}", c.name);
            }
        }
    }
}

#[test]
fn the_eigenvalues_of_the_asymmetric_fe_brake_match_an_independent_dense_analysis() {
    let spec = ring(44, &two_pads(44, false));
    let l = build(&spec);
    let an = analyse(&l, None).unwrap();
    let n = spec.dofs.len();
    // Independent: steady sliding by the dense solve, the state matrix of
    // M q̈ + K_eff q = 0 (no damping in this model; Coulomb friction has no
    // velocity term), eigenvalues by nalgebra's real Schur form.
    let ix = |d: &str| spec.dofs.iter().position(|x| x == d).unwrap();
    let vec_of = |t: &[(String, f64)]| {
        let mut v = nalgebra::DVector::<f64>::zeros(n);
        for (d, c) in t {
            v[ix(d)] += c;
        }
        v
    };
    let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
    for &(i, j, v) in &spec.m.as_ref().unwrap().entries {
        m[(i, j)] += v;
    }
    let mut k = nalgebra::DMatrix::<f64>::zeros(n, n);
    for &(i, j, v) in &spec.k.as_ref().unwrap().entries {
        k[(i, j)] += v;
    }
    for s in &spec.springs {
        let v = vec_of(&s.on);
        k += s.k * &v * v.transpose();
    }
    for c in &spec.contacts {
        let nv = vec_of(c.normal.as_ref().unwrap());
        let tv = vec_of(c.tangent.as_ref().unwrap());
        let kc = c.k.unwrap();
        k += kc * &nv * nv.transpose() + c.friction.mu(5.0) * kc * &tv * nv.transpose();
    }
    // M = L Lᵀ; the mass-normalised K̃ = L⁻¹ K_eff L⁻ᵀ has eigenvalues
    // ω² (complex once friction couples modes): λ = ±i √ω².
    let l = m.cholesky().unwrap();
    let lk = l.l().solve_lower_triangular(&k).unwrap();
    let kt = l
        .l()
        .solve_lower_triangular(&lk.transpose())
        .unwrap()
        .transpose();
    let i = nalgebra::Complex::new(0.0, 1.0);
    let mut want: Vec<nalgebra::Complex<f64>> = kt
        .complex_eigenvalues()
        .iter()
        .flat_map(|w2| {
            let r = w2.sqrt();
            [i * r, -i * r]
        })
        .collect();
    let mut got: Vec<nalgebra::Complex<f64>> = an
        .eigen
        .iter()
        .map(|e| nalgebra::Complex::new(e.re, e.im))
        .collect();
    let key = |c: &nalgebra::Complex<f64>| (c.im, c.re);
    want.sort_by(|x, y| key(x).partial_cmp(&key(y)).unwrap());
    got.sort_by(|x, y| key(x).partial_cmp(&key(y)).unwrap());
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!(
            (g - w).norm() <= 1e-8 * w.norm().max(1.0),
            "{g} against {w}"
        );
    }
}

/// A pad on a rigidly held block: `y` (the pad) pressed by `load` against a
/// contact of stiffness `k` on a ground-held dof `w` (spring `kw`), with a
/// tangential dof `x` on a spring.
fn block(load: f64, k: f64) -> LumpedSpec {
    LumpedSpec {
        dofs: ["w", "x", "y"].map(String::from).to_vec(),
        masses: terms(&[("w", 1.0), ("x", 0.1), ("y", 0.1)]),
        springs: vec![
            spring("ground", &[("w", 1.0)], 1e6),
            spring("holder", &[("x", 1.0)], 1e5),
            spring("piston", &[("y", 1.0)], 1e4),
        ],
        forces: vec![force("brake", &[("y", 1.0)], -load)],
        contacts: vec![contact(
            "pad",
            &[("w", 1.0), ("y", -1.0)],
            &[("x", -1.0)],
            k,
            0.5,
        )],
        ..Default::default()
    }
}

#[test]
fn a_pad_pulled_back_is_open_and_one_barely_pressed_is_closed() {
    // Pulled back: the contact opens; the piston alone holds y at
    // −load/k_piston = +0.01 m from the surface, everything else at rest.
    let l = build(&block(-100.0, 1e7));
    let z = l.equilibrium_dyn().unwrap();
    assert!((z[2] - 100.0 / 1e4).abs() < 1e-15, "y = {}", z[2]);
    assert_eq!(z[0], 0.0);
    assert_eq!(z[1], 0.0);
    // Barely pressed (1e-9 N): closed, carrying exactly that load. The
    // closed form: y compresses piston and contact-with-ground in series.
    let load = 1e-9;
    let l = build(&block(load, 1e7));
    let z = l.equilibrium_dyn().unwrap();
    let f_n = l.contacts[0].normal_force(&z[..3], &z[3..]);
    assert!(
        (f_n - load * 1e7 * 1e6 / (1e7 * 1e6 + 1e4 * (1e7 + 1e6))).abs() < 1e-22 + 1e-12 * load
    );
    assert!(f_n > 0.0);
}

/// A pad on an abutment spring inclined by β (Hoffmann's sprag): closed,
/// its normal force is `P / (1 − μ tan β + k_p/k)`, negative once
/// `μ tan β > 1 + k_p/k`; open, the brake force drives it into the disc.
#[test]
fn a_contact_that_must_open_but_cannot_is_named() {
    let (beta, k, k_p, load) = (60f64.to_radians(), 1e7, 1e4, 100.0);
    let spec = |mu: f64| LumpedSpec {
        dofs: ["x", "y"].map(String::from).to_vec(),
        masses: terms(&[("x", 0.1), ("y", 0.1)]),
        springs: vec![
            spring("abutment", &[("x", beta.cos()), ("y", beta.sin())], 1e6),
            spring("piston", &[("y", 1.0)], k_p),
        ],
        forces: vec![force("brake", &[("y", 1.0)], -load)],
        contacts: vec![contact("pad", &[("y", -1.0)], &[("x", -1.0)], k, mu)],
        ..Default::default()
    };
    // Below the sprag: closed, with the closed-form normal force.
    let mu = 0.5;
    let l = build(&spec(mu));
    let z = l.equilibrium_dyn().unwrap();
    let f_n = l.contacts[0].normal_force(&z[..2], &z[2..]);
    let want = load / (1.0 - mu * beta.tan() + k_p / k);
    assert!((f_n - want).abs() <= 1e-10 * want, "{f_n} against {want}");
    // Beyond it (μ tan β = 1.39): no set is consistent, and the message
    // says what each would need.
    let e = build(&spec(0.8)).equilibrium_dyn().unwrap_err().to_string();
    assert!(
        e.contains("no consistent set")
            && e.contains("with every contact closed, 'pad' would pull")
            && e.contains("with 'pad' open, 'pad' would penetrate"),
        "{e}"
    );
}

#[test]
fn a_free_dof_is_named() {
    let mut spec = block(100.0, 1e7);
    spec.dofs.push("loose".into());
    spec.masses.push(("loose".into(), 1.0));
    let e = build(&spec).equilibrium_dyn().unwrap_err().to_string();
    assert!(
        e.contains("singular") && e.contains("dof loose moves freely"),
        "{e}"
    );
    // A free rigid-body mode spread over several dofs: the pad's normal dof
    // held by nothing once the brake pulls it away.
    let mut spec = block(-100.0, 1e7);
    spec.springs.retain(|s| s.name != "piston");
    let e = build(&spec).equilibrium_dyn().unwrap_err().to_string();
    assert!(
        e.contains("'pad' would pull") && e.contains("with 'pad' open: dof y moves freely"),
        "{e}"
    );
}

/// `(k0 + k) y − αμk y² = F` (one pad of stiffness `k` on a ground spring
/// `k0`, follower slope on its own compression): the root continued from
/// α = 0, and the fold at `α* = (k0 + k)² / (4μkF)`.
#[test]
fn the_follower_force_is_followed_to_its_closed_form_root_and_fold() {
    let (k0, k, mu, load) = (1e6, 4e6, 0.5, 1000.0);
    let spec = |alpha: f64| LumpedSpec {
        dofs: ["y", "x"].map(String::from).to_vec(),
        masses: terms(&[("y", 1.0), ("x", 1.0)]),
        springs: vec![
            spring("ground", &[("y", 1.0)], k0),
            spring("holder", &[("x", 1.0)], 1e5),
        ],
        forces: vec![force("brake", &[("y", 1.0)], load)],
        contacts: vec![ContactSpec {
            alpha,
            slope: terms(&[("y", 1.0)]),
            ..contact("pad", &[("y", 1.0)], &[("x", -1.0)], k, mu)
        }],
        ..Default::default()
    };
    let fold = (k0 + k) * (k0 + k) / (4.0 * mu * k * load);
    for frac in [0.1, 0.5, 0.9, 0.999] {
        let alpha = frac * fold;
        let z = build(&spec(alpha)).equilibrium_dyn().unwrap();
        let (a2, a1) = (alpha * mu * k, k0 + k);
        let root = (a1 - (a1 * a1 - 4.0 * a2 * load).sqrt()) / (2.0 * a2);
        assert!(
            (z[0] - root).abs() <= 1e-9 * root,
            "α = {alpha}: {} against {root}",
            z[0]
        );
    }
    let e = build(&spec(1.25 * fold))
        .equilibrium_dyn()
        .unwrap_err()
        .to_string();
    assert!(e.contains("pad.alpha") && e.contains("folds"), "{e}");
    // The fold's λ: it exists up to 1/1.25 = 0.8 of the given alpha.
    assert!(e.contains("up to 0.8000 of"), "{e}");
}

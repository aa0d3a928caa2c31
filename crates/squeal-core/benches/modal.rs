//! Complex eigenvalue analysis cost (`stability::modal`), timed once per size
//! with `std::time::Instant` (a 4000-state solve takes too long for
//! criterion's repeated sampling).
//!
//! `cargo bench -p squeal-core --bench modal` (sizes in dofs: dense
//! `SQUEAL_MODAL_DOFS=500,1000,2000`, default `1000`; projected
//! `SQUEAL_PROJECTED_DOFS`, default `2000`).
//!
//! - the projected complex eigen-analysis (`stability::projected`) of
//!   2000 dofs with mode shapes, default basis (undamped modes ≤ 40 kHz):
//!   (a) `stability::lumped::analyse` of a lumped model — the thesis's
//!   disc–pad with a chain of 1996 masses on the disc (frequencies up to
//!   ≈ 500 kHz), Newton equilibrium and linearisation included; (b)
//!   `analyse_projected` of `n` damped oscillators with frequencies evenly
//!   spread to 500 kHz seen through a random orthogonal change of
//!   coordinates (dense `M`-free `K`, `C`) plus a friction-like
//!   non-symmetric coupling;
//!
//! - `analyse_matrix` + `mode_shape` of every mode for `n` decoupled damped
//!   oscillators seen through a random orthogonal change of coordinates
//!   (dense `2n × 2n` state matrix; faer path);
//! - the small-model path: `analyse` (fixed size) and `analyse_matrix`
//!   (runtime size) on the default disc–pad (8 states), and `analyse_matrix`
//!   on a 6-dof chain (12 states, the size of a two-pad brake).
#![allow(missing_docs)]

use nalgebra::{DMatrix, DVector};
use squeal_core::model::lumped::{disc_pad_spec, SpringSpec};
use squeal_core::stability::modal::{analyse_matrix, mode_shape};
use squeal_core::stability::projected::{analyse_projected, SecondOrder};
use squeal_core::stability::{analyse, state_matrix};
use squeal_core::{DiscPad, Lumped};
use std::hint::black_box;
use std::time::Instant;

fn rng(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *seed;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

fn oscillators(n: usize) -> DMatrix<f64> {
    let mut s = 3u64;
    let w: Vec<f64> = (0..n)
        .map(|i| 10f64.powf(4.0 * i as f64 / (n - 1) as f64))
        .collect();
    let mut q = DMatrix::<f64>::identity(n, n);
    for _ in 0..3 {
        let v = DVector::<f64>::from_fn(n, |_, _| rng(&mut s)).normalize();
        let qv = &q * &v;
        q -= 2.0 * qv * v.transpose();
    }
    let k = &q * DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| w[i] * w[i])) * q.transpose();
    let c = &q * DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| 0.1 * w[i])) * q.transpose();
    let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -k[(i, j)];
            a[(n + i, n + j)] = -c[(i, j)];
        }
    }
    a
}

/// The disc–pad with a chain of `n − 4` masses on the disc (x and y).
fn disc_pad_chain(n: usize) -> Lumped {
    let mut spec = disc_pad_spec(&DiscPad::default());
    let extra = n - 4;
    for i in 0..extra {
        let name = format!("c{i}");
        spec.dofs.push(name.clone());
        spec.masses
            .push((name.clone(), 0.02 * (1.0 + 0.5 * (i as f64 * 0.7).sin())));
        let k = 5.0e10 * (1.0 + 0.3 * (i as f64 * 1.3).cos());
        let mut on = vec![(name, 1.0)];
        if i > 0 {
            on.push((format!("c{}", i - 1), -1.0));
        }
        spec.springs.push(SpringSpec {
            name: format!("s{i}"),
            on,
            k,
            c: 2e-9 * k,
            k3: 0.0,
        });
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
    Lumped::build(&spec).unwrap()
}

/// `n` oscillators, frequencies evenly spread to 500 kHz, damping ratio 1 %,
/// in random orthogonal coordinates, unit masses, plus a friction-like
/// coupling `K[1][0] += 0.3·k_00`.
fn oscillators_second_order(n: usize) -> SecondOrder {
    let mut s = 5u64;
    let w: Vec<f64> = (0..n)
        .map(|i| 2.0 * std::f64::consts::PI * 5.0e5 * (i + 1) as f64 / n as f64)
        .collect();
    let mut q = DMatrix::<f64>::identity(n, n);
    for _ in 0..3 {
        let v = DVector::<f64>::from_fn(n, |_, _| rng(&mut s)).normalize();
        let qv = &q * &v;
        q -= 2.0 * qv * v.transpose();
    }
    let mut k =
        &q * DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| w[i] * w[i])) * q.transpose();
    let c = &q * DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| 0.02 * w[i])) * q.transpose();
    k[(1, 0)] += 0.3 * k[(0, 0)];
    SecondOrder {
        m: DMatrix::identity(n, n),
        k,
        c,
    }
}

fn per_call<F: FnMut()>(mut f: F) -> f64 {
    let mut reps = 1usize;
    loop {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        let dt = t.elapsed().as_secs_f64();
        if dt > 1.0 {
            return dt / reps as f64;
        }
        reps *= 4;
    }
}

fn main() {
    // Small models.
    let disc = DiscPad::default();
    let t = per_call(|| {
        black_box(analyse(black_box(&disc)).unwrap());
    });
    println!(
        "analyse (fixed size), disc-pad, 8 states: {:.2} µs",
        t * 1e6
    );
    let (z, a) = state_matrix(&disc).unwrap();
    let dm = DMatrix::from_fn(8, 8, |i, j| a[i][j]);
    let names: Vec<String> = (0..8).map(|i| format!("s{i}")).collect();
    let t = per_call(|| {
        black_box(analyse_matrix(black_box(&dm), &z, &names, None).unwrap());
    });
    println!("analyse_matrix, disc-pad, 8 states: {:.2} µs", t * 1e6);
    // A 6-dof chain of masses and springs with a friction-like non-symmetric coupling.
    let n = 6;
    let mut m12 = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        m12[(i, n + i)] = 1.0;
        m12[(n + i, i)] = -2.0e8 * (1.0 + i as f64 * 0.1);
        m12[(n + i, n + i)] = -5.0;
        if i + 1 < n {
            m12[(n + i, i + 1)] = 1.0e8 * (1.0 + 0.3 * (i % 2) as f64);
            m12[(n + i + 1, i)] = 1.0e8;
        }
    }
    let names12: Vec<String> = (0..2 * n).map(|i| format!("s{i}")).collect();
    let t = per_call(|| {
        black_box(analyse_matrix(black_box(&m12), &[0.0; 12], &names12, None).unwrap());
    });
    println!(
        "analyse_matrix, 6-dof chain, 12 states: {:.2} µs ({:.0} /s)",
        t * 1e6,
        1.0 / t
    );
    // Large models.
    let sizes: Vec<usize> = std::env::var("SQUEAL_MODAL_DOFS")
        .unwrap_or_else(|_| "1000".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    for n in sizes {
        let a = oscillators(n);
        let names: Vec<String> = (0..2 * n).map(|i| format!("s{i}")).collect();
        let t = Instant::now();
        let an = analyse_matrix(&a, &vec![0.0; 2 * n], &names, None).unwrap();
        let shapes: usize = an.eigen.iter().map(|e| mode_shape(e).len()).sum();
        let dt = t.elapsed().as_secs_f64();
        black_box(shapes);
        println!(
            "analyse_matrix + mode shapes, {n} dofs ({} states), dense, one thread: {dt:.2} s",
            2 * n
        );
    }
    let sizes: Vec<usize> = std::env::var("SQUEAL_PROJECTED_DOFS")
        .unwrap_or_else(|_| "2000".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    for n in sizes {
        let l = disc_pad_chain(n);
        let t = Instant::now();
        let an = squeal_core::stability::lumped::analyse(&l, Some(&l.diagonal_masses())).unwrap();
        let shapes: usize = an.eigen.iter().map(|e| mode_shape(e).len()).sum();
        let dt = t.elapsed().as_secs_f64();
        black_box(shapes);
        println!(
            "lumped::analyse + mode shapes, disc-pad + chain, {n} dofs, {:?}, one thread: {dt:.2} s (sigma_max {:.6})",
            an.method, an.max_growth_rate
        );
        // What simulating it would cost: the fastest mode bounds an explicit
        // method's step (integrate::budget).
        let z = l.equilibrium_dyn().unwrap();
        let all = squeal_core::stability::projected::undamped_basis(
            &l.second_order_dyn(&z),
            squeal_core::stability::projected::Basis::Modes(n),
        )
        .unwrap();
        let w_max = all.omega2.last().unwrap().sqrt();
        println!(
            "  highest undamped frequency {:.0} Hz: an explicit run of 1 s needs at least {:.3e} DOP853 steps (integrate::budget::min_steps)",
            w_max / (2.0 * std::f64::consts::PI),
            squeal_core::integrate::budget::min_steps(w_max, 1.0, f64::INFINITY)
        );
        let sys = oscillators_second_order(n);
        let names: Vec<String> = (0..2 * n).map(|i| format!("s{i}")).collect();
        let t = Instant::now();
        let an = analyse_projected(
            &sys,
            &vec![0.0; 2 * n],
            &names,
            None,
            squeal_core::stability::projected::ModalOptions::default().basis(),
            squeal_core::stability::projected::BasisKind::Modes,
        )
        .unwrap();
        let shapes: usize = an.eigen.iter().map(|e| mode_shape(e).len()).sum();
        let dt = t.elapsed().as_secs_f64();
        black_box(shapes);
        println!(
            "analyse_projected + mode shapes, {n} dense oscillators, {:?}, one thread: {dt:.2} s",
            an.method
        );
    }
}

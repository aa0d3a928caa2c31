//! Complex eigenvalue analysis cost (`stability::modal`), timed once per size
//! with `std::time::Instant` (a 4000-state solve takes too long for
//! criterion's repeated sampling).
//!
//! `cargo bench -p squeal-core --bench modal` (sizes in dofs:
//! `SQUEAL_MODAL_DOFS=500,1000,2000`, default `1000,2000`).
//!
//! - `analyse_matrix` + `mode_shape` of every mode for `n` decoupled damped
//!   oscillators seen through a random orthogonal change of coordinates
//!   (dense `2n × 2n` state matrix; faer path);
//! - the small-model path: `analyse` (fixed size) and `analyse_matrix`
//!   (runtime size) on the default disc–pad (8 states), and `analyse_matrix`
//!   on a 6-dof chain (12 states, the size of a two-pad brake).
#![allow(missing_docs)]

use nalgebra::{DMatrix, DVector};
use squeal_core::stability::modal::{analyse_matrix, mode_shape};
use squeal_core::stability::{analyse, state_matrix};
use squeal_core::DiscPad;
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
        .unwrap_or_else(|_| "1000,2000".into())
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
}

//! Eigenvalues and eigenvectors of small real non-symmetric matrices held in
//! fixed-size arrays (`[[f64; N]; N]`, no heap allocation).
//!
//! The classic EISPACK pipeline (Smith et al., *Matrix Eigensystem Routines —
//! EISPACK Guide*, 1976; Press et al., *Numerical Recipes*, 2nd ed., §11.5–11.6):
//!
//! 1. [`balance`]: Parlett–Reinsch balancing (Parlett & Reinsch 1969, Numer.
//!    Math. 13, "Balancing a matrix for calculation of eigenvalues and
//!    eigenvectors"): a diagonal similarity `D⁻¹AD` by powers of 2 (so it is
//!    exact in floating point) that equalises row and column norms. The
//!    state matrices of this crate have entries from ~1 to ~4e10 (MODEL.md
//!    §8); without balancing, QR's backward error `ε‖A‖` is set by the
//!    largest entry and the slow modes lose digits.
//! 2. [`hessenberg`]: Householder reduction to upper Hessenberg form (EISPACK
//!    `orthes`, without accumulating the transformation).
//! 3. [`hqr`]: the Francis implicit double-shift QR iteration (EISPACK `hqr`)
//!    with exceptional shifts, eigenvalues only.
//! 4. [`eigenvector`]: inverse iteration with a complex LU factorisation with
//!    partial pivoting of `A − λI` (Wilkinson, *The Algebraic Eigenvalue
//!    Problem*, 1965, §9.48).
//!
//! Why not nalgebra: nalgebra 0.33 has a Parlett–Reinsch balancing and a
//! Francis QR (`Schur`), but (a) `complex_eigenvalues` iterates without a cap
//! (`max_niter = 0`), so a matrix on which the shifts stall would hang the
//! caller, while the capped `Schur::try_new` always accumulates the Schur
//! vectors (wasted work on the fast path); (b) in code generic over
//! `const N` its Hessenberg/Schur need `Const<N>: DimSub<U1>` plus allocator
//! bounds on every public signature; (c) it does not balance by itself: on
//! the unbalanced default disc–pad matrix it misses σ of the 20.75 kHz mode
//! by 6e-7 1/s and ω of the 34.4 kHz mode by 0.07 rad/s (after balancing,
//! 3e-12 1/s). The hand-written version below is bounded, allocation-free,
//! and matches the 50-digit reference to 4e-14 relative (`tests/stability.rs`).

use nalgebra::Complex;

/// Most sweeps of [`balance`] (it converges in a handful; this only bounds
/// the loop on pathological input).
pub const MAX_BALANCE_SWEEPS: usize = 200;

/// QR iterations allowed per eigenvalue in [`hqr`] before it gives up.
pub const MAX_QR_ITERATIONS: usize = 60;

// Every algorithm below is written once, on a row-major `n × n` slice
// (`a[i * n + j]`), and used twice: by the fixed-size wrappers (`N` known at
// compile time, stack arrays, no heap allocation; `#[inline(always)]` lets the
// compiler fold `n = N`) and by the runtime-sized [`Workspace`] used for
// models whose size is known only at run time
// ([`analyse_matrix`](super::modal::analyse_matrix)). Both paths perform the
// same floating-point operations in the same order, so they agree bit for bit.

/// Parlett–Reinsch balancing with radix 2 (EISPACK `balanc`, 1-norms of the
/// off-diagonal parts of row and column `i`): overwrites `a` by `D⁻¹ a D` and
/// returns the diagonal of `D`. Eigenvalues are unchanged; an eigenvector `x̃`
/// of the balanced matrix is `x = D x̃` for the original one. Every scale is
/// a power of two, so the similarity is exact. `a` must be finite.
pub fn balance<const N: usize>(a: &mut [[f64; N]; N]) -> [f64; N] {
    let mut d = [1.0; N];
    balance_flat(a.as_flattened_mut(), N, &mut d);
    d
}

/// [`balance`] on a row-major `n × n` slice; `d` (length `n`) receives the
/// diagonal of `D`.
#[inline(always)]
pub fn balance_flat(a: &mut [f64], n: usize, d: &mut [f64]) {
    const RADIX: f64 = 2.0;
    const SQRDX: f64 = RADIX * RADIX;
    assert!(a.len() == n * n && d.len() == n);
    d.fill(1.0);
    for _ in 0..MAX_BALANCE_SWEEPS {
        let mut done = true;
        for i in 0..n {
            let mut c = 0.0;
            let mut r = 0.0;
            for j in 0..n {
                if j != i {
                    c += a[j * n + i].abs();
                    r += a[i * n + j].abs();
                }
            }
            // A zero row or column needs no scaling; a non-finite sum (an
            // infinite or NaN entry, or 1-norms that overflow) cannot be
            // balanced: the scaling loops below would never end on it.
            if c == 0.0 || r == 0.0 || !(c + r).is_finite() {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut g = r / RADIX;
            while c < g {
                f *= RADIX;
                c *= SQRDX;
            }
            g = r * RADIX;
            while c > g {
                f /= RADIX;
                c /= SQRDX;
            }
            if (c + r) / f < 0.95 * s {
                done = false;
                let gi = 1.0 / f;
                d[i] *= f;
                for j in 0..n {
                    a[i * n + j] *= gi;
                }
                for j in 0..n {
                    a[j * n + i] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
}

/// Householder reduction of `a` to upper Hessenberg form in place (EISPACK
/// `orthes`; the orthogonal transformation is not kept). Entries below the
/// first subdiagonal are set to exactly zero.
pub fn hessenberg<const N: usize>(a: &mut [[f64; N]; N]) {
    let mut v = [0.0; N];
    hessenberg_flat(a.as_flattened_mut(), N, &mut v);
}

/// [`hessenberg`] on a row-major `n × n` slice, with scratch `v` (length `n`).
#[inline(always)]
pub fn hessenberg_flat(a: &mut [f64], n: usize, v: &mut [f64]) {
    assert!(a.len() == n * n && v.len() == n);
    for k in 0..n.saturating_sub(2) {
        let scale: f64 = (k + 1..n).map(|i| a[i * n + k].abs()).sum();
        if scale == 0.0 {
            continue;
        }
        let mut h = 0.0;
        for i in k + 1..n {
            v[i] = a[i * n + k] / scale;
            h += v[i] * v[i];
        }
        let g = -v[k + 1].signum() * h.sqrt();
        h -= v[k + 1] * g;
        v[k + 1] -= g;
        // P = I − v vᵀ / h, applied from the left (rows k+1..) ...
        for j in k + 1..n {
            let mut f = 0.0;
            for i in k + 1..n {
                f += v[i] * a[i * n + j];
            }
            f /= h;
            for i in k + 1..n {
                a[i * n + j] -= f * v[i];
            }
        }
        // ... and from the right (columns k+1..).
        for row in a.chunks_exact_mut(n) {
            let mut f = 0.0;
            for j in k + 1..n {
                f += row[j] * v[j];
            }
            f /= h;
            for j in k + 1..n {
                row[j] -= f * v[j];
            }
        }
        a[(k + 1) * n + k] = scale * g;
        for row in a.chunks_exact_mut(n).skip(k + 2) {
            row[k] = 0.0;
        }
    }
}

/// `|a|` with the sign of `b` (Fortran `SIGN`).
#[inline]
fn sign(a: f64, b: f64) -> f64 {
    if b >= 0.0 {
        a.abs()
    } else {
        -a.abs()
    }
}

/// Eigenvalues of an upper Hessenberg matrix by the Francis double-shift QR
/// iteration (EISPACK `hqr`, as in Numerical Recipes 2nd ed. §11.6), with
/// exceptional shifts every 10 iterations. `h` is destroyed. A subdiagonal
/// entry is neglected when it is below `ε·(|h_{l−1,l−1}| + |h_{l,l}|)` (or
/// `ε‖H‖₁` if both are zero). Complex eigenvalues come in adjacent conjugate
/// pairs, the one with positive imaginary part last.
///
/// Returns `None` if an eigenvalue needs more than [`MAX_QR_ITERATIONS`]
/// iterations (or the input is not finite).
pub fn hqr<const N: usize>(h: &mut [[f64; N]; N]) -> Option<[Complex<f64>; N]> {
    let mut out = [Complex::new(0.0, 0.0); N];
    hqr_flat(h.as_flattened_mut(), N, &mut out).then_some(out)
}

/// [`hqr`] on a row-major `n × n` slice; the eigenvalues go to `out` (length
/// `n`). Returns `false` where [`hqr`] returns `None`.
#[inline(always)]
pub fn hqr_flat(h: &mut [f64], n: usize, out: &mut [Complex<f64>]) -> bool {
    assert!(h.len() == n * n && out.len() == n);
    // 1-based indexing as in the reference, to keep the translation literal.
    macro_rules! a {
        ($i:expr, $j:expr) => {
            h[(($i) - 1) * n + ($j) - 1]
        };
    }
    let eps = f64::EPSILON;
    out.fill(Complex::new(0.0, 0.0));
    let mut anorm = 0.0;
    for i in 1..=n {
        for j in i.saturating_sub(1).max(1)..=n {
            anorm += a!(i, j).abs();
        }
    }
    if !anorm.is_finite() {
        return false;
    }
    let mut nn = n;
    let mut t = 0.0;
    let (mut p, mut q, mut r, mut x, mut y, mut z, mut w);
    while nn >= 1 {
        let mut its = 0;
        loop {
            // Look for a single small subdiagonal element.
            let mut l = nn;
            while l >= 2 {
                let mut s = a!(l - 1, l - 1).abs() + a!(l, l).abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a!(l, l - 1).abs() <= eps * s {
                    a!(l, l - 1) = 0.0;
                    break;
                }
                l -= 1;
            }
            x = a!(nn, nn);
            if l == nn {
                // One root found.
                out[nn - 1] = Complex::new(x + t, 0.0);
                nn -= 1;
                break;
            }
            y = a!(nn - 1, nn - 1);
            w = a!(nn, nn - 1) * a!(nn - 1, nn);
            if l == nn - 1 {
                // Two roots found.
                p = 0.5 * (y - x);
                q = p * p + w;
                z = q.abs().sqrt();
                x += t;
                if q >= 0.0 {
                    z = p + sign(z, p);
                    let hi = x + z;
                    let lo = if z != 0.0 { x - w / z } else { hi };
                    out[nn - 2] = Complex::new(hi, 0.0);
                    out[nn - 1] = Complex::new(lo, 0.0);
                } else {
                    out[nn - 2] = Complex::new(x + p, -z);
                    out[nn - 1] = Complex::new(x + p, z);
                }
                nn = nn.saturating_sub(2);
                break;
            }
            // No roots yet: a QR step on rows/columns l..=nn.
            if its == MAX_QR_ITERATIONS {
                return false;
            }
            if its > 0 && its % 10 == 0 {
                // Exceptional shift.
                t += x;
                for i in 1..=nn {
                    a!(i, i) -= x;
                }
                let s = a!(nn, nn - 1).abs() + a!(nn - 1, nn - 2).abs();
                x = 0.75 * s;
                y = x;
                w = -0.4375 * s * s;
            }
            its += 1;
            // Form the shift and look for two consecutive small subdiagonals.
            let mut m = nn - 2;
            loop {
                z = a!(m, m);
                r = x - z;
                let s = y - z;
                p = (r * s - w) / a!(m + 1, m) + a!(m, m + 1);
                q = a!(m + 1, m + 1) - z - r - s;
                r = a!(m + 2, m + 1);
                let s = p.abs() + q.abs() + r.abs();
                p /= s;
                q /= s;
                r /= s;
                if m == l {
                    break;
                }
                let u = a!(m, m - 1).abs() * (q.abs() + r.abs());
                let v = p.abs() * (a!(m - 1, m - 1).abs() + z.abs() + a!(m + 1, m + 1).abs());
                if u <= eps * v {
                    break;
                }
                m -= 1;
            }
            for i in m + 2..=nn {
                a!(i, i - 2) = 0.0;
                if i != m + 2 {
                    a!(i, i - 3) = 0.0;
                }
            }
            // Double QR step on rows l..=nn and columns m..=nn.
            for k in m..nn {
                if k != m {
                    p = a!(k, k - 1);
                    q = a!(k + 1, k - 1);
                    r = 0.0;
                    if k != nn - 1 {
                        r = a!(k + 2, k - 1);
                    }
                    x = p.abs() + q.abs() + r.abs();
                    if x != 0.0 {
                        p /= x;
                        q /= x;
                        r /= x;
                    }
                }
                let s = sign((p * p + q * q + r * r).sqrt(), p);
                if s != 0.0 {
                    if k == m {
                        if l != m {
                            a!(k, k - 1) = -a!(k, k - 1);
                        }
                    } else {
                        a!(k, k - 1) = -s * x;
                    }
                    p += s;
                    x = p / s;
                    y = q / s;
                    z = r / s;
                    q /= p;
                    r /= p;
                    for j in k..=nn {
                        p = a!(k, j) + q * a!(k + 1, j);
                        if k != nn - 1 {
                            p += r * a!(k + 2, j);
                            a!(k + 2, j) -= p * z;
                        }
                        a!(k + 1, j) -= p * y;
                        a!(k, j) -= p * x;
                    }
                    let mmin = nn.min(k + 3);
                    for i in l..=mmin {
                        p = x * a!(i, k) + y * a!(i, k + 1);
                        if k != nn - 1 {
                            p += z * a!(i, k + 2);
                            a!(i, k + 2) -= p * r;
                        }
                        a!(i, k + 1) -= p * q;
                        a!(i, k) -= p;
                    }
                }
            }
        }
    }
    true
}

/// All eigenvalues of `a` ([`balance`], [`hessenberg`], [`hqr`]), and the
/// balanced matrix with its scaling `D` (for [`eigenvector`]). `None` if `a`
/// is not finite or the QR iteration does not converge.
#[allow(clippy::type_complexity)]
pub fn eigenvalues_balanced<const N: usize>(
    a: &[[f64; N]; N],
) -> Option<([Complex<f64>; N], [[f64; N]; N], [f64; N])> {
    if a.iter().flatten().any(|x| !x.is_finite()) {
        return None;
    }
    let mut b = *a;
    let d = balance(&mut b);
    let mut h = b;
    hessenberg(&mut h);
    let ev = hqr(&mut h)?;
    Some((ev, b, d))
}

/// All eigenvalues of `a` (see [`eigenvalues_balanced`]); no heap allocation.
pub fn eigenvalues<const N: usize>(a: &[[f64; N]; N]) -> Option<[Complex<f64>; N]> {
    eigenvalues_balanced(a).map(|(ev, _, _)| ev)
}

/// Eigenvector of `a` for the (computed) eigenvalue `lambda`, by three steps
/// of inverse iteration `(a − λI) x_{k+1} = x_k` with a complex LU
/// factorisation with partial pivoting; a pivot below `ε‖a‖∞` is replaced by
/// `ε‖a‖∞` (the matrix is singular to working precision by construction).
/// That threshold presumes rows and columns of comparable size: pass the
/// balanced matrix ([`balance`]) and map the result back with `x = D x̃`.
/// Returned with unit 2-norm and its largest component real and positive.
pub fn eigenvector<const N: usize>(a: &[[f64; N]; N], lambda: Complex<f64>) -> [Complex<f64>; N] {
    let zero = Complex::new(0.0, 0.0);
    let mut lu = [[zero; N]; N];
    let mut perm = [0usize; N];
    let mut x = [zero; N];
    eigenvector_flat(
        a.as_flattened(),
        N,
        lambda,
        lu.as_flattened_mut(),
        &mut perm,
        &mut x,
    );
    x
}

/// [`eigenvector`] on a row-major `n × n` slice, with scratch `lu` (`n²`) and
/// `perm` (`n`); the eigenvector goes to `x` (length `n`).
#[inline(always)]
pub fn eigenvector_flat(
    a: &[f64],
    n: usize,
    lambda: Complex<f64>,
    lu: &mut [Complex<f64>],
    perm: &mut [usize],
    x: &mut [Complex<f64>],
) {
    assert!(a.len() == n * n && lu.len() == n * n && perm.len() == n && x.len() == n);
    let zero = Complex::new(0.0, 0.0);
    let mut norm: f64 = 0.0;
    for i in 0..n {
        let mut row = 0.0;
        for j in 0..n {
            lu[i * n + j] = Complex::new(a[i * n + j], 0.0);
            row += a[i * n + j].abs();
        }
        lu[i * n + i] -= lambda;
        norm = norm.max(row);
    }
    // (For a zero matrix, √MIN_POSITIVE: its square, compared with |pivot|²
    // below, must not underflow to 0.)
    let tiny = if norm > 0.0 {
        f64::EPSILON * norm
    } else {
        f64::MIN_POSITIVE.sqrt()
    };
    for k in 0..n {
        // Pivot by |·|² (the same order as |·|, without a hypot per entry).
        let mut piv = k;
        let mut best = lu[k * n + k].norm_sqr();
        for i in k + 1..n {
            let v = lu[i * n + k].norm_sqr();
            if v > best {
                best = v;
                piv = i;
            }
        }
        perm[k] = piv;
        if piv != k {
            for j in 0..n {
                lu.swap(k * n + j, piv * n + j);
            }
        }
        if lu[k * n + k].norm_sqr() < tiny * tiny {
            lu[k * n + k] = Complex::new(tiny, 0.0);
        }
        let pivot = lu[k * n + k];
        // Row slices instead of indices: same operations, no bounds checks.
        let (top, below) = lu.split_at_mut((k + 1) * n);
        let row_k = &top[k * n + k + 1..(k + 1) * n];
        for row_i in below.chunks_exact_mut(n) {
            let f = row_i[k] / pivot;
            row_i[k] = f;
            if f != zero {
                for (a, &u) in row_i[k + 1..].iter_mut().zip(row_k) {
                    *a -= f * u;
                }
            }
        }
    }
    // Start from a vector with no special structure.
    for (i, xi) in x.iter_mut().enumerate() {
        *xi = Complex::new(1.0, 0.5 * (i as f64 + 1.0) / n as f64);
    }
    for _ in 0..3 {
        for k in 0..n {
            x.swap(k, perm[k]);
        }
        for (i, row) in lu.chunks_exact(n).enumerate() {
            let mut s = x[i];
            for (l, xj) in row[..i].iter().zip(&x[..i]) {
                s -= l * xj;
            }
            x[i] = s;
        }
        for (i, row) in lu.chunks_exact(n).enumerate().rev() {
            let mut s = x[i];
            for (u, xj) in row[i + 1..].iter().zip(&x[i + 1..]) {
                s -= u * xj;
            }
            x[i] = s / row[i];
        }
        let m = x.iter().map(|c| c.norm_sqr()).fold(0.0, f64::max).sqrt();
        if !(m > 0.0 && m.is_finite()) {
            break;
        }
        for xi in x.iter_mut() {
            *xi /= m;
        }
    }
    normalise(x);
}

/// Scale `x` to unit 2-norm with its largest component real and positive
/// (the first largest, on ties).
pub fn normalise(x: &mut [Complex<f64>]) {
    let mut big = 0;
    for i in 0..x.len() {
        if x[i].norm_sqr() > x[big].norm_sqr() {
            big = i;
        }
    }
    let n2 = x.iter().map(|c| c.norm_sqr()).sum::<f64>().sqrt();
    if !(n2 > 0.0 && n2.is_finite()) {
        return;
    }
    let phase = x[big] / x[big].norm();
    for xi in x.iter_mut() {
        *xi /= phase * n2;
    }
}

/// Heap workspace for the runtime-sized path: the same balancing, Hessenberg
/// reduction, Francis QR and inverse iteration as the fixed-size functions,
/// on an `n × n` matrix given at run time.
#[derive(Debug, Clone)]
pub struct Workspace {
    n: usize,
    /// The balanced matrix `D⁻¹ A D` (row-major).
    balanced: Vec<f64>,
    /// The balancing scales `D`.
    d: Vec<f64>,
    h: Vec<f64>,
    v: Vec<f64>,
    lu: Vec<Complex<f64>>,
    perm: Vec<usize>,
}

impl Workspace {
    /// The eigenvalues of the row-major `n × n` matrix `a` (the order of
    /// [`hqr`]); keeps the balanced matrix for [`Workspace::eigenvector`].
    /// `None` if `a` is not finite or QR does not converge.
    pub fn eigenvalues(a: &[f64], n: usize) -> Option<(Self, Vec<Complex<f64>>)> {
        assert_eq!(a.len(), n * n, "eigenvalues: matrix is not {n} × {n}");
        if a.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let mut ws = Workspace {
            n,
            balanced: a.to_vec(),
            d: vec![1.0; n],
            h: vec![0.0; n * n],
            v: vec![0.0; n],
            lu: vec![Complex::new(0.0, 0.0); n * n],
            perm: vec![0; n],
        };
        balance_flat(&mut ws.balanced, n, &mut ws.d);
        ws.h.copy_from_slice(&ws.balanced);
        hessenberg_flat(&mut ws.h, n, &mut ws.v);
        let mut ev = vec![Complex::new(0.0, 0.0); n];
        hqr_flat(&mut ws.h, n, &mut ev).then_some((ws, ev))
    }

    /// Eigenvector of the original matrix for `lambda`: inverse iteration on
    /// the balanced matrix ([`eigenvector`]), mapped back `x = D x̃`, unit
    /// 2-norm, largest component real positive.
    pub fn eigenvector(&mut self, lambda: Complex<f64>) -> Vec<Complex<f64>> {
        let mut x = vec![Complex::new(0.0, 0.0); self.n];
        eigenvector_flat(
            &self.balanced,
            self.n,
            lambda,
            &mut self.lu,
            &mut self.perm,
            &mut x,
        );
        for (xi, di) in x.iter_mut().zip(&self.d) {
            *xi *= *di;
        }
        normalise(&mut x);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (SplitMix64) for test matrices.
    fn rng(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn residual<const N: usize>(a: &[[f64; N]; N], l: Complex<f64>, x: &[Complex<f64>; N]) -> f64 {
        let mut r: f64 = 0.0;
        for i in 0..N {
            let mut s = -l * x[i];
            for j in 0..N {
                s += a[i][j] * x[j];
            }
            r = r.max(s.norm());
        }
        r
    }

    #[test]
    fn companion_matrix_of_known_roots() {
        // Roots 1, 2, −3, 1 ± 2i, −0.5 ± 4i: monic polynomial coefficients
        // from the product, companion matrix, eigenvalues to 1e-12 relative.
        let roots = [
            Complex::new(1.0, 0.0),
            Complex::new(2.0, 0.0),
            Complex::new(-3.0, 0.0),
            Complex::new(1.0, 2.0),
            Complex::new(1.0, -2.0),
            Complex::new(-0.5, 4.0),
            Complex::new(-0.5, -4.0),
        ];
        let mut c = vec![Complex::new(1.0, 0.0)];
        for r in roots {
            let mut n = vec![Complex::new(0.0, 0.0); c.len() + 1];
            for (k, ck) in c.iter().enumerate() {
                n[k] += *ck;
                n[k + 1] -= *ck * r;
            }
            c = n;
        }
        let mut a = [[0.0; 7]; 7];
        for j in 0..7 {
            a[0][j] = -c[j + 1].re;
        }
        for i in 1..7 {
            a[i][i - 1] = 1.0;
        }
        let ev = eigenvalues(&a).unwrap();
        for r in roots {
            let best = ev
                .iter()
                .map(|e| (e - r).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(best < 1e-12 * r.norm().max(1.0), "root {r}: {best:e}");
        }
    }

    #[test]
    fn random_matrices_match_nalgebra_and_residuals_are_small() {
        let mut seed = 7u64;
        for trial in 0..200 {
            let mut a = [[0.0; 8]; 8];
            for row in a.iter_mut() {
                for x in row.iter_mut() {
                    *x = rng(&mut seed);
                }
            }
            // Graded scales on some trials, as in the brake matrices.
            if trial % 2 == 1 {
                for i in 0..8 {
                    for j in 0..8 {
                        a[i][j] *= 10f64.powi(i as i32 - j as i32);
                    }
                }
            }
            let ev = eigenvalues(&a).unwrap();
            let norm = a.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max);
            // Trace and determinant-free check: sum of eigenvalues = trace.
            let tr: f64 = (0..8).map(|i| a[i][i]).sum();
            let sum: Complex<f64> = ev.iter().sum();
            assert!((sum.re - tr).abs() < 1e-10 * norm, "trial {trial}");
            assert!(sum.im.abs() < 1e-10 * norm, "trial {trial}");
            // Against nalgebra's Schur (unbalanced, so a looser bound).
            let m = nalgebra::SMatrix::<f64, 8, 8>::from_fn(|i, j| a[i][j]);
            let nev = nalgebra::Schur::try_new(m, f64::EPSILON, 10_000)
                .unwrap()
                .complex_eigenvalues();
            for e in ev.iter() {
                let best = nev
                    .iter()
                    .map(|f| (f - e).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    best < 1e-7 * norm.max(e.norm()),
                    "trial {trial}: {e} {best:e}"
                );
            }
            // Eigenvectors of the balanced matrix B: backward residual
            // ‖Bx − λx‖∞ ≤ 1e-13 ‖B‖∞ (‖x‖₂ = 1).
            let (_, b, _) = eigenvalues_balanced(&a).unwrap();
            let rownorm = b
                .iter()
                .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
                .fold(0.0, f64::max);
            for e in ev.iter() {
                let x = eigenvector(&b, *e);
                let r = residual(&b, *e, &x);
                assert!(r < 1e-13 * rownorm, "trial {trial}: residual {r:e}");
            }
        }
    }

    #[test]
    fn undamped_oscillator_deflates_with_zero_diagonal() {
        // ż = [[0, I], [−K, 0]] z with K = diag(1, 4, 9): eigenvalues ±i, ±2i, ±3i exactly.
        let mut a = [[0.0; 6]; 6];
        for i in 0..3 {
            a[i][i + 3] = 1.0;
            a[i + 3][i] = -(((i + 1) * (i + 1)) as f64);
        }
        let ev = eigenvalues(&a).unwrap();
        let mut im: Vec<f64> = ev.iter().map(|e| e.im).collect();
        im.sort_by(f64::total_cmp);
        for (got, want) in im.iter().zip([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
        assert!(ev.iter().all(|e| e.re.abs() < 1e-14));
    }

    #[test]
    fn balancing_is_an_exact_power_of_two_similarity() {
        let mut a = [[1.0, 1e10, 0.0], [1e-10, 2.0, 3e9], [0.0, 1e-9, 3.0]];
        let orig = a;
        let d = balance(&mut a);
        for i in 0..3 {
            assert_eq!(d[i].log2().fract(), 0.0);
            for j in 0..3 {
                assert_eq!(a[i][j], orig[i][j] * d[j] / d[i]);
            }
        }
        let amax = a.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(amax < 1e3, "balanced max entry {amax}");
    }

    #[test]
    fn rejects_non_finite_input() {
        let a = [[1.0, f64::NAN], [0.0, 1.0]];
        assert!(eigenvalues(&a).is_none());
        let a = [[1.0, f64::INFINITY], [0.0, 1.0]];
        assert!(eigenvalues(&a).is_none());
    }
}

//! One-parameter eigenvalue sweeps with continuous mode tracking: the data of
//! the mode-coupling diagram (frequency and growth rate of every mode against
//! a parameter; Hoffmann et al. 2002, Fig. 2; Kinkaid, O'Reilly & Papadopoulos
//! 2003, "Automotive disc brake squeal", §4).
//!
//! At each parameter value `p_k` a caller-supplied closure gives the state
//! matrix (and equilibrium); [`modal::eigenpairs`] solves it. The eigenvalues
//! of consecutive points are matched as an assignment problem, not by
//! sorting: branch `b` (eigenvalue `λ_b`, eigenvector `u_b` at `p_{k−1}`)
//! goes to the new eigenpair `j` minimising the total cost
//!
//! ```text
//! cost(b, j) = (1 − MAC(q_b, q_j)) + |λ̂_b − λ_j| / max(|λ̂_b|, |λ_j|)
//! MAC(x, y)  = |xᴴy|² / (xᴴx · yᴴy)       (modal assurance criterion)
//! ```
//!
//! with `q` the position half of the eigenvector (the mode shape) and `λ̂_b`
//! the linear extrapolation of the branch from its last two points. The MAC
//! term follows a mode shape through frequency crossings and veerings; the
//! eigenvalue term separates a mode from its complex conjugate (same shape,
//! MAC = 1) and the two modes born at a coalescence (nearly the same shape,
//! eigenvalues `±σ + iω`, the extrapolation keeps each on its side). The
//! assignment is solved exactly by the Hungarian method ([`hungarian`]);
//! MAC is evaluated for the [`CANDIDATES`] eigenvalues nearest each
//! prediction and taken as 0 for the others (their cost ≥ 1 anyway).
//!
//! **Onsets and coalescences.** Where the number of growing eigenvalues
//! ([`super::is_growing`]) changes between two points, the change is located
//! by bisection on that count to `rtol` relative ([`SweepOptions`]). For an
//! undamped pair this is the coalescence itself: below it the pair is neutral
//! (σ = 0), above it σ grows like `√(p − p_c)` (see [`super::critical`]). An
//! onset is a **coalescence** when, just past it, another eigenvalue (not the
//! conjugate) lies within 1 % in frequency of the one that grows.

use super::modal::{self, EigenPair};
use super::{is_growing, Direction, StabilityError};
use nalgebra::{Complex, DMatrix};
use serde::Serialize;

/// Eigenvalues nearest each branch's prediction for which the MAC is computed.
pub const CANDIDATES: usize = 8;

/// Options of [`sweep`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepOptions {
    /// Relative tolerance of the located onsets (default 1e-10).
    pub rtol: f64,
    /// Most bisection steps per onset (default 200).
    pub max_bisect: usize,
}

impl Default for SweepOptions {
    fn default() -> Self {
        SweepOptions {
            rtol: 1e-10,
            max_bisect: 200,
        }
    }
}

/// A change of the number of growing eigenvalues along the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Onset {
    /// Parameter value where it happens (bisection to `rtol`).
    pub value: f64,
    /// Frequency (Hz) of the eigenvalue that starts (or stops) growing.
    pub freq_hz: f64,
    /// Index into [`Sweep::listed`] of the branch that changes, if one of
    /// the listed branches changes its verdict between the two grid points.
    pub mode: Option<usize>,
    /// Destabilising (more growing eigenvalues above) or stabilising.
    pub direction: Direction,
    /// Another eigenvalue within 1 % in frequency on the growing side: two
    /// modes coalesce (mode-coupling flutter) rather than one mode crossing
    /// alone (a Hopf point).
    pub coalescence: bool,
}

/// Result of [`sweep`].
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// The parameter values, as given.
    pub values: Vec<f64>,
    /// `lambda[k][b]`: eigenvalue of branch `b` at `values[k]`; every branch
    /// is one continuously tracked eigenvalue (all `dim` of them).
    pub lambda: Vec<Vec<Complex<f64>>>,
    /// `mac[k][b]`: MAC between branch `b`'s shapes at `values[k−1]` and
    /// `values[k]` (1 at `k = 0`): a tracking-quality indicator.
    pub mac: Vec<Vec<f64>>,
    /// The branches reported as modes, in mode order: every branch except
    /// the lower-half-plane twin of a complex-conjugate pair (a branch that is
    /// at every point the conjugate of another branch, with `Im λ ≤ 0`).
    /// Sorted by frequency, then growth rate (descending), at the first point.
    pub listed: Vec<usize>,
    /// Changes of stability along the sweep, in parameter order.
    pub onsets: Vec<Onset>,
}

/// Sweep `values` (strictly monotonic) with `f(p) → (state matrix, z)`, and
/// track every eigenvalue continuously (see the module docs). Errors of `f`
/// and of the eigen-solver pass through; the matrices must all have the same
/// size.
pub fn sweep<F, E>(values: &[f64], mut f: F, opts: &SweepOptions) -> Result<Sweep, E>
where
    F: FnMut(f64) -> Result<(DMatrix<f64>, Vec<f64>), E>,
    E: From<StabilityError>,
{
    if values.is_empty()
        || values.iter().any(|v| !v.is_finite())
        || !(values.windows(2).all(|w| w[0] < w[1]) || values.windows(2).all(|w| w[0] > w[1]))
    {
        return Err(StabilityError::BadInput(
            "sweep: need finite, strictly monotonic parameter values".into(),
        )
        .into());
    }
    if !(opts.rtol > 0.0 && opts.rtol < 1.0) || opts.max_bisect == 0 {
        return Err(StabilityError::BadInput(format!(
            "sweep: rtol = {} (in (0, 1)), max_bisect = {} (≥ 1)",
            opts.rtol, opts.max_bisect
        ))
        .into());
    }
    let mut lambda: Vec<Vec<Complex<f64>>> = Vec::with_capacity(values.len());
    let mut mac: Vec<Vec<f64>> = Vec::with_capacity(values.len());
    let mut growing_count: Vec<usize> = Vec::with_capacity(values.len());
    // Branch state at the previous point: eigenvalue and shape.
    let mut prev: Vec<EigenPair> = Vec::new();
    // prev_idx[b]: the solver's index of branch b's eigenpair at the previous
    // value (the assignment reads the branches in that order, so that it
    // does not depend on how the branches are numbered).
    let mut prev_idx: Vec<usize> = Vec::new();
    let mut dim = 0;
    for (k, &p) in values.iter().enumerate() {
        let (a, _) = f(p)?;
        let pairs = modal::eigenpairs(&a)?;
        growing_count.push(pairs.iter().filter(|(l, _)| is_growing(l.re, l.im)).count());
        if k == 0 {
            dim = pairs.len();
            // Initial order: frequency ascending, growth descending, +ω first
            // (a stable sort: equal eigenvalues keep the solver's order).
            let mut order: Vec<usize> = (0..dim).collect();
            order.sort_by(|&a, &b| {
                let (x, y) = (pairs[a].0, pairs[b].0);
                x.im.abs()
                    .total_cmp(&y.im.abs())
                    .then(y.re.total_cmp(&x.re))
                    .then(y.im.total_cmp(&x.im))
            });
            let mut slots: Vec<Option<EigenPair>> = pairs.into_iter().map(Some).collect();
            let pairs: Vec<EigenPair> = order
                .iter()
                .map(|&j| slots[j].take().expect("a sort is a permutation"))
                .collect();
            lambda.push(pairs.iter().map(|(l, _)| *l).collect());
            mac.push(vec![1.0; dim]);
            prev = pairs;
            prev_idx = order;
            continue;
        }
        if pairs.len() != dim {
            return Err(StabilityError::BadInput(format!(
                "sweep: the state matrix changed size from {dim} to {} at {p}",
                pairs.len()
            ))
            .into());
        }
        let predicted: Vec<Complex<f64>> = (0..dim)
            .map(|b| {
                let l1 = lambda[k - 1][b];
                if k >= 2 {
                    let l0 = lambda[k - 2][b];
                    let h = (p - values[k - 1]) / (values[k - 1] - values[k - 2]);
                    l1 + (l1 - l0) * h
                } else {
                    l1
                }
            })
            .collect();
        let (assign, macs) = match_branches(&prev, &prev_idx, &predicted, &pairs);
        let mut next: Vec<EigenPair> = Vec::with_capacity(dim);
        let mut pairs: Vec<Option<EigenPair>> = pairs.into_iter().map(Some).collect();
        for &j in &assign {
            next.push(pairs[j].take().expect("an assignment is a permutation"));
        }
        lambda.push(next.iter().map(|(l, _)| *l).collect());
        mac.push(macs);
        prev = next;
        prev_idx = assign;
    }
    let listed = listed_branches(&lambda);
    let mut onsets = Vec::new();
    for k in 1..values.len() {
        let (c0, c1) = (growing_count[k - 1], growing_count[k]);
        if c0 == c1 {
            continue;
        }
        onsets.push(locate_onset(
            &mut f,
            (values[k - 1], c0),
            (values[k], c1),
            opts,
            &lambda[k - 1],
            &lambda[k],
            &listed,
        )?);
    }
    Ok(Sweep {
        values: values.to_vec(),
        lambda,
        mac,
        listed,
        onsets,
    })
}

/// The position half of an eigenvector (the whole vector if its length is odd).
fn shape(u: &[Complex<f64>]) -> &[Complex<f64>] {
    if u.len().is_multiple_of(2) && !u.is_empty() {
        &u[..u.len() / 2]
    } else {
        u
    }
}

/// Modal assurance criterion `|xᴴy|² / (xᴴx · yᴴy)` (0 if either vanishes).
pub fn mac(x: &[Complex<f64>], y: &[Complex<f64>]) -> f64 {
    let mut xy = Complex::new(0.0, 0.0);
    let (mut xx, mut yy) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        xy += a.conj() * b;
        xx += a.norm_sqr();
        yy += b.norm_sqr();
    }
    if xx > 0.0 && yy > 0.0 {
        (xy.norm_sqr() / (xx * yy)).min(1.0)
    } else {
        0.0
    }
}

/// The assignment of branches (previous eigenpairs `prev`, the solver's
/// index `prev_idx` of each, predictions `predicted`) to the new eigenpairs
/// `new`: `assign[b] = j`, and the MAC of each match. The cost matrix's rows
/// are the branches in the order of `prev_idx`, not of their numbers: the
/// result is the same however the branches are numbered (a sweep resumed
/// from a slice of the values, with branches numbered its own way, pairs
/// the modes exactly as the whole sweep does — what sharded sweeps rely on).
fn match_branches(
    prev: &[EigenPair],
    prev_idx: &[usize],
    predicted: &[Complex<f64>],
    new: &[EigenPair],
) -> (Vec<usize>, Vec<f64>) {
    let n = new.len();
    // rows[r] = the branch whose previous eigenpair the solver gave r-th.
    let mut rows = vec![0; n];
    for (b, &i) in prev_idx.iter().enumerate() {
        rows[i] = b;
    }
    let dist = |b: usize, j: usize| {
        let (x, y) = (predicted[b], new[j].0);
        let scale = x.norm().max(y.norm());
        if scale > 0.0 {
            (x - y).norm() / scale
        } else {
            0.0
        }
    };
    let mut cost = vec![0.0; n * n];
    let mut macs = vec![0.0; n * n];
    let mut order: Vec<usize> = (0..n).collect();
    let mut d = vec![0.0; n];
    let k = CANDIDATES.min(n);
    for (r, &b) in rows.iter().enumerate() {
        for j in 0..n {
            d[j] = dist(b, j);
            cost[r * n + j] = 1.0 + d[j];
        }
        // The k nearest (ties by index: deterministic), in O(n).
        order.iter_mut().enumerate().for_each(|(i, o)| *o = i);
        if k < n {
            order.select_nth_unstable_by(k - 1, |&i, &j| d[i].total_cmp(&d[j]).then(i.cmp(&j)));
        }
        for &j in &order[..k] {
            let m = mac(shape(&prev[b].1), shape(&new[j].1));
            macs[r * n + j] = m;
            cost[r * n + j] = (1.0 - m) + d[j];
        }
    }
    let by_row = hungarian(&cost, n);
    let mut assign = vec![0; n];
    let mut m = vec![0.0; n];
    for (r, &j) in by_row.iter().enumerate() {
        assign[rows[r]] = j;
        m[rows[r]] = macs[r * n + j];
    }
    (assign, m)
}

/// Minimum-cost perfect assignment on a square `n × n` cost matrix
/// (row-major): `result[row] = column`. The Hungarian method with
/// potentials (Kuhn 1955, Munkres 1957; the O(n³) shortest-augmenting-path
/// form of Jonker & Volgenant 1987). Ties go to the lowest column index, so
/// the result is deterministic.
pub fn hungarian(cost: &[f64], n: usize) -> Vec<usize> {
    assert_eq!(cost.len(), n * n);
    // 1-based arrays as in the classic formulation: column 0 is a sentinel.
    let mut u = vec![0.0; n + 1];
    let mut v = vec![0.0; n + 1];
    let mut p = vec![0usize; n + 1]; // p[col] = row matched to col
    let mut way = vec![0usize; n + 1];
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0;
        let mut minv = vec![f64::INFINITY; n + 1];
        let mut used = vec![false; n + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0;
            for j in 1..=n {
                if !used[j] {
                    let cur = cost[(i0 - 1) * n + (j - 1)] - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=n {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut out = vec![0; n];
    for j in 1..=n {
        if p[j] > 0 {
            out[p[j] - 1] = j - 1;
        }
    }
    out
}

/// Branches to report (see [`Sweep::listed`]), ordered by frequency then
/// growth rate (descending) at the first point; `lambda[k][b]` as in
/// [`Sweep::lambda`]. Public so that a sweep merged from slices lists its
/// modes as the whole sweep does.
pub fn listed_branches(lambda: &[Vec<Complex<f64>>]) -> Vec<usize> {
    let dim = lambda.first().map_or(0, |l| l.len());
    let conj_of = |a: usize, b: usize| {
        lambda.iter().all(|l| {
            let (x, y) = (l[a], l[b].conj());
            (x - y).norm() <= 1e-9 * x.norm().max(y.norm())
        })
    };
    let mut twin = vec![false; dim];
    for b in 0..dim {
        let lower = lambda.iter().all(|l| l[b].im <= 0.0) && lambda.iter().any(|l| l[b].im < 0.0);
        if lower && (0..dim).any(|c| c != b && !twin[c] && conj_of(c, b)) {
            twin[b] = true;
        }
    }
    let mut out: Vec<usize> = (0..dim).filter(|&b| !twin[b]).collect();
    let l0 = &lambda[0];
    out.sort_by(|&a, &b| {
        l0[a]
            .im
            .abs()
            .total_cmp(&l0[b].im.abs())
            .then(l0[b].re.total_cmp(&l0[a].re))
            .then(a.cmp(&b))
    });
    out
}

/// [`Onset::mode`]: the first listed branch (an index into `listed`) whose
/// verdict differs between the eigenvalues `lam_lo` and `lam_hi` of the
/// interval's two grid values (branch order of [`Sweep::lambda`]).
pub fn onset_mode(
    listed: &[usize],
    lam_lo: &[Complex<f64>],
    lam_hi: &[Complex<f64>],
) -> Option<usize> {
    listed.iter().position(|&b| {
        let (a, c) = (lam_lo[b], lam_hi[b]);
        is_growing(a.re, a.im) != is_growing(c.re, c.im)
    })
}

/// Bisection on the number of growing eigenvalues between `(lo, c_lo)` and
/// `(hi, c_hi)` (`c_lo ≠ c_hi`).
#[allow(clippy::type_complexity)]
fn locate_onset<F, E>(
    f: &mut F,
    (mut lo, c_lo): (f64, usize),
    (mut hi, c_hi): (f64, usize),
    opts: &SweepOptions,
    lam_lo: &[Complex<f64>],
    lam_hi: &[Complex<f64>],
    listed: &[usize],
) -> Result<Onset, E>
where
    F: FnMut(f64) -> Result<(DMatrix<f64>, Vec<f64>), E>,
    E: From<StabilityError>,
{
    let count = |f: &mut F, p: f64| -> Result<(usize, Vec<Complex<f64>>), E> {
        let (a, _) = f(p)?;
        let ev = modal::eigenvalues(&a)?;
        Ok((ev.iter().filter(|l| is_growing(l.re, l.im)).count(), ev))
    };
    let mut ev_hi = Vec::new();
    for _ in 0..opts.max_bisect {
        if (hi - lo).abs() <= opts.rtol * lo.abs().max(hi.abs()) {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if mid == lo || mid == hi {
            break;
        }
        let (c, ev) = count(f, mid)?;
        if c == c_lo {
            lo = mid;
        } else {
            hi = mid;
            if c == c_hi {
                ev_hi = ev;
            }
        }
    }
    let value = 0.5 * (lo + hi);
    // The growing side: `hi` when the count rises, `lo` when it falls.
    let destab = c_hi > c_lo;
    let growing_side = if destab { hi } else { lo };
    let ev = if destab && !ev_hi.is_empty() {
        ev_hi
    } else {
        count(f, growing_side)?.1
    };
    // The newly growing eigenvalue: the growing one with the smallest σ/|λ|
    // (it has just crossed), +ω first.
    let g = ev
        .iter()
        .filter(|l| is_growing(l.re, l.im))
        .min_by(|x, y| {
            (x.re / x.norm())
                .total_cmp(&(y.re / y.norm()))
                .then(y.im.total_cmp(&x.im))
        })
        .copied()
        .unwrap_or(Complex::new(0.0, 0.0));
    let coalescence = g.im != 0.0
        && ev.iter().any(|o| {
            (o - g).norm() > 0.0
                && (o - g.conj()).norm() > 0.0
                && o.im.signum() == g.im.signum()
                && (o.im - g.im).abs() <= 0.01 * g.im.abs()
        });
    let mode = onset_mode(listed, lam_lo, lam_hi);
    Ok(Onset {
        value,
        freq_hz: g.im.abs() / (2.0 * std::f64::consts::PI),
        mode,
        direction: if destab {
            Direction::Destabilising
        } else {
            Direction::Stabilising
        },
        coalescence,
    })
}

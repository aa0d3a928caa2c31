//! Eigenvalues followed along a parameter path (numerical continuation).
//!
//! Sorting eigenvalues by frequency at every point of a sweep swaps modes
//! where their frequencies cross; here each mode is followed from its value
//! at the previous point instead: the new eigenvalues are assigned to the
//! tracks greedily, nearest first, by the relative distance
//! `|λ_new − λ_pred| / |λ_pred|`, where `λ_pred` is the track's linear
//! extrapolation from its last two points (its last point at the start).
//! Steps must be small enough that a mode moves by less than half its
//! distance to any other — the caller's choice of path.

pub use nalgebra::Complex;

/// Modes followed along a path: `lambdas[mode][point]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracks {
    /// The parameter values, in path order.
    pub params: Vec<f64>,
    /// Eigenvalue of each mode at each point (mode order = the first point's order).
    pub lambdas: Vec<Vec<Complex<f64>>>,
}

/// Relative distance between two eigenvalues, `|a − b| / max(|a|, |b|)` (0 for two zeros).
pub fn rel_distance(a: Complex<f64>, b: Complex<f64>) -> f64 {
    let scale = a.norm().max(b.norm());
    if scale == 0.0 {
        0.0
    } else {
        (a - b).norm() / scale
    }
}

/// Assign `new` eigenvalues to predicted values `pred`, nearest pairs first.
/// Returns `new` reordered so that entry `i` belongs to `pred[i]`.
pub fn assign(pred: &[Complex<f64>], new: &[Complex<f64>]) -> Vec<Complex<f64>> {
    let n = pred.len().min(new.len());
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(pred.len() * new.len());
    for (i, p) in pred.iter().enumerate() {
        for (j, q) in new.iter().enumerate() {
            pairs.push((rel_distance(*p, *q), i, j));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut out = vec![Complex::new(f64::NAN, f64::NAN); pred.len()];
    let (mut used_p, mut used_q) = (vec![false; pred.len()], vec![false; new.len()]);
    let mut done = 0;
    for (_, i, j) in pairs {
        if done == n {
            break;
        }
        if !used_p[i] && !used_q[j] {
            out[i] = new[j];
            used_p[i] = true;
            used_q[j] = true;
            done += 1;
        }
    }
    out
}

/// Follow the eigenvalues returned by `eig` along `path`. `eig(p)` returns
/// the eigenvalues at `p` (e.g. those with `Im λ ≥ 0`), the same number at
/// every point; `None` ends the path early (e.g. no steady state there).
/// Returns `None` if the first point has no eigenvalues.
pub fn track<F>(eig: F, path: &[f64]) -> Option<Tracks>
where
    F: Fn(f64) -> Option<Vec<Complex<f64>>>,
{
    let first = eig(*path.first()?)?;
    let mut params = vec![path[0]];
    let mut lambdas: Vec<Vec<Complex<f64>>> = first.iter().map(|l| vec![*l]).collect();
    for &p in &path[1..] {
        let Some(new) = eig(p) else { break };
        if new.len() != first.len() {
            break;
        }
        let k = params.len();
        let pred: Vec<Complex<f64>> = lambdas
            .iter()
            .map(|tr| {
                if k >= 2 {
                    let (p1, p0) = (params[k - 1], params[k - 2]);
                    let s = if p1 != p0 { (p - p1) / (p1 - p0) } else { 0.0 };
                    tr[k - 1] + (tr[k - 1] - tr[k - 2]) * s
                } else {
                    tr[k - 1]
                }
            })
            .collect();
        for (tr, l) in lambdas.iter_mut().zip(assign(&pred, &new)) {
            tr.push(l);
        }
        params.push(p);
    }
    Some(Tracks { params, lambdas })
}

/// The first parameter along a path at which `change(p)` reaches `level`,
/// given the last point `lo` where it is below and the first point `hi`
/// where it is at or above: bisection, geometric when both ends have the
/// same sign and are non-zero (log-spaced sweeps), to `rtol` relative.
pub fn first_reach<C>(change: C, mut lo: f64, mut hi: f64, level: f64, rtol: f64) -> f64
where
    C: Fn(f64) -> f64,
{
    for _ in 0..200 {
        if (hi - lo).abs() <= rtol * hi.abs().max(lo.abs()) {
            break;
        }
        let mid = if lo * hi > 0.0 {
            lo.signum() * (lo.abs() * hi.abs()).sqrt()
        } else {
            0.5 * (lo + hi)
        };
        if change(mid) >= level {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two modes whose frequencies cross linearly: sorting by frequency would
    /// swap them at the crossing, tracking must not.
    #[test]
    fn crossing_modes_keep_their_identity() {
        let eig = |p: f64| {
            Some(vec![
                Complex::new(-1.0, 100.0 + p),
                Complex::new(-2.0, 200.0 - p),
            ])
        };
        let path: Vec<f64> = (0..=40).map(|i| i as f64 * 5.0).collect();
        let t = track(eig, &path).unwrap();
        assert_eq!(t.params.len(), 41);
        for (k, p) in path.iter().enumerate() {
            assert_eq!(t.lambdas[0][k], Complex::new(-1.0, 100.0 + p));
            assert_eq!(t.lambdas[1][k], Complex::new(-2.0, 200.0 - p));
        }
    }

    #[test]
    fn first_reach_finds_a_power_law_threshold() {
        // change = (|p| / 80)²: reaches 1 % at |p| = 8.
        let c = |p: f64| (p.abs() / 80.0).powi(2);
        let p = first_reach(c, -1.0, -100.0, 0.01, 1e-12);
        assert!((p + 8.0).abs() < 1e-9, "{p}");
    }

    #[test]
    fn a_path_ends_where_the_eigenvalues_end() {
        let eig = |p: f64| (p < 3.0).then(|| vec![Complex::new(p, 1.0)]);
        let t = track(eig, &[0.0, 1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(t.params, vec![0.0, 1.0, 2.0]);
    }
}

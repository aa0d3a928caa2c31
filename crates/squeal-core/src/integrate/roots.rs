//! All roots of an event polynomial on a step: the first upward zero
//! crossing of a degree-7 polynomial on [0, 1].
//!
//! Written by hand because no crate isolates polynomial roots without
//! allocating: the polynomial is converted to the Bernstein basis, where the
//! number of sign changes of the coefficients bounds the number of roots
//! (Descartes' rule for the Bernstein basis), and intervals with more than one
//! change are halved by de Casteljau's algorithm. An isolated root is then
//! refined by the Illinois variant of regula falsi. Every root is seen, however
//! close to another or to an end of the step: this is what finds the brief
//! reversal excursions of the sliding velocity inside one step (MODEL.md §8).

/// Degree of the DOP853 dense output and so of every event polynomial.
pub const DEGREE: usize = 7;
const NC: usize = DEGREE + 1;

/// `T[j][i] = C(j, i) / C(7, i)` for i ≤ j: power → Bernstein coefficients.
const BERN: [[f64; NC]; NC] = {
    let mut t = [[0.0; NC]; NC];
    let mut j = 0;
    while j < NC {
        let mut i = 0;
        while i <= j {
            t[j][i] = binom(j, i) as f64 / binom(DEGREE, i) as f64;
            i += 1;
        }
        j += 1;
    }
    t
};

const fn binom(n: usize, k: usize) -> u64 {
    let mut r: u64 = 1;
    let mut i = 0;
    while i < k {
        r = r * (n - i) as u64 / (i + 1) as u64;
        i += 1;
    }
    r
}

/// Evaluate a power-basis polynomial `Σ a_i θ^i` (Horner).
#[inline]
pub fn horner(a: &[f64; NC], x: f64) -> f64 {
    let mut s = a[DEGREE];
    for i in (0..DEGREE).rev() {
        s = s * x + a[i];
    }
    s
}

/// An enclosure `[lo, hi]` of a power-basis polynomial's values on
/// `θ ∈ [0, 1]`: the extreme Bernstein coefficients (the polynomial lies in
/// their convex hull).
pub fn range(a: &[f64; NC]) -> (f64, f64) {
    let b = to_bernstein(a);
    b.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(*x), hi.max(*x))
        })
}

/// Bernstein coefficients on [0, 1] of a power-basis polynomial.
#[inline]
pub fn to_bernstein(a: &[f64; NC]) -> [f64; NC] {
    let mut b = [0.0; NC];
    for j in 0..NC {
        let mut s = 0.0;
        for i in 0..=j {
            s += BERN[j][i] * a[i];
        }
        b[j] = s;
    }
    b
}

/// Number of sign changes in the coefficient sequence, zero counted as non-negative.
#[inline]
fn sign_changes(b: &[f64; NC]) -> usize {
    let mut n = 0;
    let mut prev = b[0] < 0.0;
    for &x in &b[1..] {
        let neg = x < 0.0;
        if neg != prev {
            n += 1;
        }
        prev = neg;
    }
    n
}

/// Split Bernstein coefficients at the midpoint (de Casteljau).
#[inline]
fn split(b: &[f64; NC]) -> ([f64; NC], [f64; NC]) {
    let mut w = *b;
    let mut left = [0.0; NC];
    let mut right = [0.0; NC];
    left[0] = w[0];
    right[DEGREE] = w[DEGREE];
    for r in 1..NC {
        for i in 0..NC - r {
            w[i] = 0.5 * (w[i] + w[i + 1]);
        }
        left[r] = w[0];
        right[DEGREE - r] = w[NC - r - 1];
    }
    (left, right)
}

/// The first θ in (0, 1] where the polynomial (power basis `a`) crosses
/// from negative to non-negative, to within `tol` in θ; `None` if it never
/// does. Tangential touches (even-multiplicity roots) are not crossings.
/// A polynomial that starts at or above zero fires only after it has been
/// negative: this is what keeps a restart on a switching surface from
/// re-triggering the event that just fired.
pub fn first_upcrossing(a: &[f64; NC], tol: f64) -> Option<f64> {
    let b = to_bernstein(a);
    // Quick exit, the common case: all coefficients negative (g < 0 on the step)
    // or all non-negative (never negative, so never crossing upwards).
    let changes = sign_changes(&b);
    if changes == 0 {
        return None;
    }
    // Depth-first, left interval first, on an explicit fixed-size stack.
    const MAX_DEPTH: usize = 60;
    let mut stack: [(f64, f64, [f64; NC]); MAX_DEPTH + 2] = [(0.0, 0.0, [0.0; NC]); MAX_DEPTH + 2];
    let mut depth = [0usize; MAX_DEPTH + 2];
    let mut top = 1;
    stack[0] = (0.0, 1.0, b);
    depth[0] = 0;
    while top > 0 {
        top -= 1;
        let (lo, hi, c) = stack[top];
        let d = depth[top];
        let v = sign_changes(&c);
        if v == 0 {
            continue;
        }
        let up = c[0] < 0.0 && c[DEGREE] >= 0.0;
        if v == 1 || d >= MAX_DEPTH || hi - lo <= tol * 0.5 {
            if up {
                return Some(refine(a, lo, hi, tol));
            }
            continue;
        }
        let (l, r) = split(&c);
        let mid = 0.5 * (lo + hi);
        // Push right first so that the left half is examined first.
        stack[top] = (mid, hi, r);
        depth[top] = d + 1;
        stack[top + 1] = (lo, mid, l);
        depth[top + 1] = d + 1;
        top += 2;
    }
    None
}

/// Refine a bracketed upward crossing (p(lo) < 0 ≤ p(hi)) by the Illinois
/// method; returns a θ on the non-negative side, within `tol` of the root.
fn refine(a: &[f64; NC], mut lo: f64, mut hi: f64, tol: f64) -> f64 {
    let mut flo = horner(a, lo);
    let mut fhi = horner(a, hi);
    if flo >= 0.0 {
        return lo;
    }
    if fhi < 0.0 {
        // Round-off disagreement between bases at a near-tangency: bisect on values.
        return hi;
    }
    let mut side = 0i8;
    for _ in 0..200 {
        if hi - lo <= tol {
            break;
        }
        let mut x = (lo * fhi - hi * flo) / (fhi - flo);
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let fx = horner(a, x);
        if fx < 0.0 {
            lo = x;
            flo = fx;
            if side == -1 {
                fhi *= 0.5;
            }
            side = -1;
        } else {
            hi = x;
            fhi = fx;
            if side == 1 {
                flo *= 0.5;
            }
            side = 1;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Power coefficients of Π (θ − r_i) · scale, padded to degree 7.
    fn from_roots(roots: &[f64], scale: f64) -> [f64; NC] {
        let mut a = [0.0; NC];
        a[0] = scale;
        for &r in roots {
            let mut n = [0.0; NC];
            for i in 0..DEGREE {
                n[i + 1] += a[i];
                n[i] -= r * a[i];
            }
            a = n;
        }
        a
    }

    #[test]
    fn bernstein_reproduces_values() {
        let a = [0.3, -1.2, 2.0, 0.5, -0.7, 0.1, 0.9, -0.4];
        let b = to_bernstein(&a);
        assert!((b[0] - horner(&a, 0.0)).abs() < 1e-15);
        assert!((b[7] - horner(&a, 1.0)).abs() < 1e-14);
        let (l, r) = split(&b);
        assert!((l[7] - horner(&a, 0.5)).abs() < 1e-14);
        assert!((r[0] - horner(&a, 0.5)).abs() < 1e-14);
    }

    #[test]
    fn finds_a_short_excursion_between_two_close_roots() {
        // Negative outside, positive on (0.4, 0.4 + 1e-7): an excursion a
        // sign test at the ends of the step cannot see.
        let a = from_roots(&[0.4, 0.4 + 1e-7], -1.0);
        assert!(horner(&a, 0.0) < 0.0 && horner(&a, 1.0) < 0.0);
        let t = first_upcrossing(&a, 1e-15).expect("excursion found");
        // Two roots 1e-7 apart are ill-conditioned: ~1e-16/1e-7 in θ.
        assert!((t - 0.4).abs() < 1e-9, "{t}");
    }

    #[test]
    fn picks_the_first_of_several_upcrossings() {
        // p = (θ−0.1)(θ−0.2)(θ−0.7)(θ−0.8)(θ−0.95): negative at 0, up at 0.1.
        let a = from_roots(&[0.1, 0.2, 0.7, 0.8, 0.95], 1.0);
        assert!(horner(&a, 0.0) < 0.0);
        let t = first_upcrossing(&a, 1e-15).unwrap();
        assert!((t - 0.1).abs() < 1e-13, "{t}");
        // Starting on the surface and going down: the first *upward* crossing is 0.2.
        let c = from_roots(&[0.0, 0.2, 0.7], -1.0); // root at the start, then negative
        let t = first_upcrossing(&c, 1e-15).unwrap();
        assert!((t - 0.2).abs() < 1e-13, "{t}");
    }

    #[test]
    fn restart_on_the_surface_does_not_refire() {
        // g(0) = 0 exactly and decreasing: no event.
        let a = from_roots(&[0.0], -1.0);
        assert_eq!(first_upcrossing(&a, 1e-15), None);
        // g(0) = +1e-20 (round-off above) and decreasing: no event.
        let mut b = a;
        b[0] = 1e-20;
        assert_eq!(first_upcrossing(&b, 1e-15), None);
    }

    #[test]
    fn tangency_is_not_a_crossing() {
        // −(θ − 0.5)² − 1e-12: comes within 1e-12 of zero from below.
        let mut a = from_roots(&[0.5, 0.5], -1.0);
        a[0] -= 1e-12;
        assert_eq!(first_upcrossing(&a, 1e-15), None);
        // A negative polynomial: nothing.
        assert_eq!(
            first_upcrossing(&[-1.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 1e-15),
            None
        );
    }
}

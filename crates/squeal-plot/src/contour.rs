//! Zero contour of a gridded field by marching squares.
//!
//! Hand-written rather than taken from a crate: we need only the single level 0 on a
//! rectilinear grid (possibly in log-transformed coordinates), with NaN cells skipped
//! and saddles resolved consistently; that is ~60 lines, while plotters has no contour
//! support and contour crates bring geometry stacks we do not otherwise need.

/// A straight piece of contour: two `(x, y)` end points in data coordinates.
pub type Segment = [(f64, f64); 2];

/// Segments of the zero level set of `values` sampled at the grid nodes
/// `(xs[i], ys[j])`, with `values` row-major `ys.len() × xs.len()`
/// (`values[j * xs.len() + i]`).
///
/// Positions along cell edges are linearly interpolated, so a field that is linear
/// in x and y gives its zero line exactly. Cells with any non-finite corner are
/// skipped; a node that is exactly 0 counts as positive. Saddle cells (signs
/// alternating around the cell) are disambiguated by the mean of the four corners.
/// Mismatched lengths or fewer than 2×2 nodes give no segments.
pub fn zero_contour(xs: &[f64], ys: &[f64], values: &[f64]) -> Vec<Segment> {
    let (nx, ny) = (xs.len(), ys.len());
    let mut out = Vec::new();
    if nx < 2 || ny < 2 || values.len() != nx * ny {
        return out;
    }
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            // Corners counter-clockwise from bottom-left: 0 (i,j), 1 (i+1,j),
            // 2 (i+1,j+1), 3 (i,j+1).
            let p = [
                (xs[i], ys[j]),
                (xs[i + 1], ys[j]),
                (xs[i + 1], ys[j + 1]),
                (xs[i], ys[j + 1]),
            ];
            let v = [
                values[j * nx + i],
                values[j * nx + i + 1],
                values[(j + 1) * nx + i + 1],
                values[(j + 1) * nx + i],
            ];
            if v.iter()
                .chain(p.iter().flat_map(|q| [&q.0, &q.1]))
                .any(|a| !a.is_finite())
            {
                continue;
            }
            let pos = v.map(|a| a >= 0.0);
            // Crossing on edge k (between corner k and corner k+1), if any.
            let cross = |k: usize| -> Option<(f64, f64)> {
                let l = (k + 1) % 4;
                if pos[k] == pos[l] {
                    return None;
                }
                let t = v[k] / (v[k] - v[l]);
                Some((
                    p[k].0 + t * (p[l].0 - p[k].0),
                    p[k].1 + t * (p[l].1 - p[k].1),
                ))
            };
            let e: [Option<(f64, f64)>; 4] = [cross(0), cross(1), cross(2), cross(3)];
            let found: Vec<(f64, f64)> = e.iter().flatten().copied().collect();
            match found.len() {
                2 => push(&mut out, found[0], found[1]),
                4 => {
                    // Saddle: corners 0 and 2 share a sign. If the centre has that sign
                    // too, 0 and 2 are connected and corners 1 and 3 are cut off.
                    let centre = (v[0] + v[1] + v[2] + v[3]) / 4.0;
                    let (a, b, c, d) = (
                        e[0].unwrap_or_default(),
                        e[1].unwrap_or_default(),
                        e[2].unwrap_or_default(),
                        e[3].unwrap_or_default(),
                    );
                    if (centre >= 0.0) == pos[0] {
                        push(&mut out, a, b); // around corner 1
                        push(&mut out, c, d); // around corner 3
                    } else {
                        push(&mut out, d, a); // around corner 0
                        push(&mut out, b, c); // around corner 2
                    }
                }
                _ => {}
            }
        }
    }
    out
}

fn push(out: &mut Vec<Segment>, a: (f64, f64), b: (f64, f64)) {
    if a != b {
        out.push([a, b]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect()
    }

    fn field(xs: &[f64], ys: &[f64], f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        ys.iter()
            .flat_map(|&y| xs.iter().map(move |&x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect()
    }

    #[test]
    fn circle_endpoints_lie_on_circle() {
        let xs = grid(81, -2.0, 2.0);
        let ys = grid(61, -1.5, 1.5);
        let r = 1.0;
        let v = field(&xs, &ys, |x, y| x * x + y * y - r * r);
        let segs = zero_contour(&xs, &ys, &v);
        assert!(segs.len() > 50, "only {} segments", segs.len());
        // grid step 0.05: linear interpolation error is O(h²) ≈ 2.5e-3
        for s in &segs {
            for (x, y) in s {
                assert!(((x * x + y * y).sqrt() - r).abs() < 3e-3, "({x},{y})");
            }
        }
        // the contour closes: total length ≈ 2πr
        let len: f64 = segs
            .iter()
            .map(|[a, b]| ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt())
            .sum();
        assert!(
            (len - 2.0 * std::f64::consts::PI * r).abs() < 0.01,
            "len {len}"
        );
    }

    #[test]
    fn linear_field_is_exact() {
        let xs = grid(17, 0.0, 4.0);
        let ys = grid(9, -1.0, 1.0);
        let v = field(&xs, &ys, |x, y| 0.5 * x - y - 1.0); // zero on y = x/2 - 1
        let segs = zero_contour(&xs, &ys, &v);
        assert!(!segs.is_empty());
        for s in &segs {
            for (x, y) in s {
                assert!((y - (0.5 * x - 1.0)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn nan_and_degenerate_inputs() {
        let xs = grid(5, 0.0, 1.0);
        let ys = grid(5, 0.0, 1.0);
        let mut v = field(&xs, &ys, |x, _| x - 0.5);
        v[7] = f64::NAN;
        let segs = zero_contour(&xs, &ys, &v);
        assert!(!segs.is_empty());
        assert!(segs.iter().all(|s| s.iter().all(|p| p.0.is_finite())));
        assert!(zero_contour(&xs, &ys, &[f64::NAN; 25]).is_empty());
        assert!(zero_contour(&xs, &ys, &[1.0; 24]).is_empty());
        assert!(zero_contour(&[], &[], &[]).is_empty());
        assert!(zero_contour(&xs, &ys, &[0.0; 25]).is_empty());
    }

    #[test]
    fn saddle_gives_two_segments() {
        let xs = [0.0, 1.0];
        let ys = [0.0, 1.0];
        let segs = zero_contour(&xs, &ys, &[1.0, -1.0, 1.0, -1.0]);
        // rows: y=0: [1, -1]; y=1: [1, -1] -> not a saddle, a vertical line
        assert_eq!(segs.len(), 1);
        let segs = zero_contour(&xs, &ys, &[1.0, -1.0, -1.0, 1.0]);
        assert_eq!(segs.len(), 2);
    }
}

//! Reducing long series to what can be seen at the output resolution.
//!
//! Hand-written on purpose: a 200 000-point velocity signal drawn into ~1000 pixel
//! columns would otherwise push every point through plotters' path rasteriser (and
//! into the SVG file). Plain stride decimation would alias away the squeal envelope,
//! so for x-sorted data we keep, per pixel column, the first, last, minimum and
//! maximum points (the "M4" scheme), in their original order. The polyline through
//! those points covers exactly the same pixels vertically in every column as the full
//! polyline, so the envelope and the extremes stay visible, at ≤ 4 points per column.

/// M4 decimation of x-sorted points. `column` maps an x value to its pixel column.
/// Returns `None` if the columns are not non-decreasing (the caller then falls back
/// to [`dedupe_pixels`]).
pub(crate) fn min_max_per_column(
    points: &[(f64, f64)],
    column: impl Fn(f64) -> i32,
) -> Option<Vec<(f64, f64)>> {
    let cols: Vec<i32> = points.iter().map(|p| column(p.0)).collect();
    if cols.windows(2).any(|w| w[1] < w[0]) {
        return None;
    }
    let n = points.len();
    let mut out = Vec::new();
    let mut start = 0;
    while start < n {
        let c = cols[start];
        let (mut imin, mut imax) = (start, start);
        let mut end = start + 1;
        while end < n && cols[end] == c {
            if points[end].1 < points[imin].1 {
                imin = end;
            }
            if points[end].1 > points[imax].1 {
                imax = end;
            }
            end += 1;
        }
        let mut idx = [start, imin, imax, end - 1];
        idx.sort_unstable();
        let mut last = usize::MAX;
        for i in idx {
            if i != last {
                out.push(points[i]);
                last = i;
            }
        }
        start = end;
    }
    Some(out)
}

/// Path simplification for curves that are not functions of x (phase portraits):
/// drop consecutive points that land on the same pixel as the last kept point.
/// Everything dropped lies within one pixel of the kept polyline.
pub(crate) fn dedupe_pixels(
    points: &[(f64, f64)],
    pixel: impl Fn(f64, f64) -> (i32, i32),
) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut last_px = None;
    for (k, &(x, y)) in points.iter().enumerate() {
        let px = pixel(x, y);
        if last_px != Some(px) || k + 1 == points.len() {
            out.push((x, y));
            last_px = Some(px);
        }
    }
    out
}

/// Split a pixel-simplified path into polylines that never retrace a pixel-level
/// segment already drawn. A phase-portrait trajectory that has settled on a limit
/// cycle goes round the same pixels thousands of times; drawing each pixel segment
/// once gives the same picture with a fraction of the strokes (and SVG size).
pub(crate) fn unique_polylines(
    points: &[(f64, f64)],
    pixel: impl Fn(f64, f64) -> (i32, i32),
) -> Vec<Vec<(f64, f64)>> {
    let mut seen = std::collections::HashSet::new();
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let mut prev: Option<((f64, f64), (i32, i32))> = None;
    for &(x, y) in points {
        let px = pixel(x, y);
        if let Some((pp, ppx)) = prev {
            let key = if ppx <= px { (ppx, px) } else { (px, ppx) };
            if seen.insert(key) {
                if current.is_empty() {
                    current.push(pp);
                }
                current.push((x, y));
            } else if !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
        }
        prev = Some(((x, y), px));
    }
    if !current.is_empty() {
        out.push(current);
    }
    if out.is_empty() && !points.is_empty() {
        out.push(vec![points[0]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn m4_keeps_envelope_and_bounds_size() {
        let n = 200_000;
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let t = k as f64 / n as f64;
                (t, (t * 2000.0 * std::f64::consts::TAU).sin() * t)
            })
            .collect();
        let width = 900;
        let col = |x: f64| (x * width as f64) as i32;
        let d = min_max_per_column(&pts, col).unwrap();
        assert!(d.len() <= 4 * (width + 1), "{}", d.len());
        assert!(d.len() >= 2 * width);
        // global extremes survive
        let max_full = pts.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let max_dec = d.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        assert_eq!(max_full, max_dec);
        // per-column extremes survive
        for c in [10, 450, 899] {
            let in_col = |p: &&(f64, f64)| col(p.0) == c;
            let a = pts
                .iter()
                .filter(in_col)
                .map(|p| p.1)
                .fold(f64::MIN, f64::max);
            let b = d
                .iter()
                .filter(in_col)
                .map(|p| p.1)
                .fold(f64::MIN, f64::max);
            assert_eq!(a, b);
        }
        assert_eq!(d.first(), pts.first());
        assert_eq!(d.last(), pts.last());
    }

    #[test]
    fn unsorted_x_is_rejected_and_dedupe_works() {
        let pts = [(0.0, 0.0), (1.0, 1.0), (0.5, 0.0)];
        assert!(min_max_per_column(&pts, |x| (x * 10.0) as i32).is_none());
        let circle: Vec<(f64, f64)> = (0..10_000)
            .map(|k| {
                let a = k as f64 * 0.001;
                (a.cos(), a.sin())
            })
            .collect();
        let px = |x: f64, y: f64| ((x * 100.0).round() as i32, (y * 100.0).round() as i32);
        let d = dedupe_pixels(&circle, px);
        assert!(d.len() < circle.len() / 2);
        assert_eq!(d.last(), circle.last());
        assert!(min_max_per_column(&[], |x| x as i32).unwrap().is_empty());
        assert!(dedupe_pixels(&[], px).is_empty());
        // ten laps of the same circle collapse to about one lap of strokes
        let laps: Vec<(f64, f64)> = (0..62_832)
            .map(|k| {
                let a = k as f64 * 0.001;
                (a.cos(), a.sin())
            })
            .collect();
        let one_lap = dedupe_pixels(&laps[..6284], px).len();
        let lines = unique_polylines(&dedupe_pixels(&laps, px), px);
        let total: usize = lines.iter().map(|l| l.len()).sum();
        assert!(total < 2 * one_lap, "{total} vs {one_lap}");
        assert_eq!(unique_polylines(&[(0.0, 0.0)], px), vec![vec![(0.0, 0.0)]]);
        assert!(unique_polylines(&[], px).is_empty());
    }
}

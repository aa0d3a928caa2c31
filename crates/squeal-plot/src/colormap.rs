//! Colormaps written as a few control points with linear interpolation in sRGB.

/// Approximation of matplotlib's perceptually uniform "viridis" (11 samples).
const VIRIDIS: [[u8; 3]; 11] = [
    [0x44, 0x01, 0x54],
    [0x48, 0x24, 0x75],
    [0x41, 0x44, 0x87],
    [0x35, 0x5F, 0x8D],
    [0x2A, 0x78, 0x8E],
    [0x21, 0x91, 0x8C],
    [0x22, 0xA8, 0x84],
    [0x44, 0xBF, 0x70],
    [0x7A, 0xD1, 0x51],
    [0xBD, 0xDF, 0x26],
    [0xFD, 0xE7, 0x25],
];

/// The stable half of the diverging map: ColorBrewer "RdBu"'s blues, dark
/// (most negative) to light (just below 0) — never white.
const BLUES: [[u8; 3]; 3] = [[0x21, 0x66, 0xAC], [0x43, 0x93, 0xC3], [0x92, 0xC5, 0xDE]];

/// The unstable half: its reds, light (0 and just above) to dark.
const REDS: [[u8; 3]; 3] = [[0xF4, 0xA5, 0x82], [0xD6, 0x60, 0x4D], [0xB2, 0x18, 0x2B]];

fn interpolate(points: &[[u8; 3]], t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let n = points.len() - 1;
    let pos = t * n as f64;
    let i = (pos.floor() as usize).min(n - 1);
    let f = pos - i as f64;
    let (a, b) = (points[i], points[i + 1]);
    let mut out = [0u8; 3];
    for c in 0..3 {
        out[c] = (a[c] as f64 + f * (b[c] as f64 - a[c] as f64)).round() as u8;
    }
    out
}

/// Sequential map, `t` in `[0, 1]` (clamped).
pub(crate) fn sequential(t: f64) -> [u8; 3] {
    interpolate(&VIRIDIS, t)
}

/// Diverging map, `t` in `[0, 1]` (clamped), centred at 0.5: blues below
/// (stable), reds from 0.5 up (unstable), both sides coloured — no white
/// that a stable cell would share with the background — and the sign
/// change a visible step.
pub(crate) fn diverging(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    if t < 0.5 {
        interpolate(&BLUES, 2.0 * t)
    } else {
        interpolate(&REDS, 2.0 * t - 1.0)
    }
}

/// Qualitative palette for categories (ColorBrewer "Set1" without yellow, then "Dark2"):
/// colour of class `i` (cycled after 12).
pub fn qualitative(i: usize) -> [u8; 3] {
    const SET: [[u8; 3]; 12] = [
        [0x37, 0x7E, 0xB8], // blue
        [0xE4, 0x1A, 0x1C], // red
        [0x4D, 0xAF, 0x4A], // green
        [0x98, 0x4E, 0xA3], // purple
        [0xFF, 0x7F, 0x00], // orange
        [0xA6, 0x56, 0x28], // brown
        [0xF7, 0x81, 0xBF], // pink
        [0x1B, 0x9E, 0x77], // teal
        [0x66, 0x66, 0x66], // dark grey
        [0xE6, 0xAB, 0x02], // mustard
        [0x75, 0x70, 0xB3], // slate
        [0x00, 0x00, 0x00], // black
    ];
    SET[i % SET.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_and_centre() {
        assert_eq!(sequential(0.0), VIRIDIS[0]);
        assert_eq!(sequential(1.0), VIRIDIS[10]);
        assert_eq!(sequential(7.0), VIRIDIS[10]);
        assert_eq!(diverging(0.5), REDS[0]);
        assert_eq!(diverging(0.4999), [0x92, 0xC5, 0xDE]);
        assert_eq!(diverging(-1.0), BLUES[0]);
        assert_eq!(diverging(1.0), REDS[2]);
        let _ = sequential(f64::NAN);
    }

    /// Neither side of σ = 0 is white or near the white background: every
    /// colour of the map is at least 60 (of 255) from white in some channel
    /// sum sense, and the two sides of 0 differ clearly.
    #[test]
    fn diverging_is_coloured_on_both_sides_of_zero() {
        let dist = |a: [u8; 3], b: [u8; 3]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (*x as f64 - y as f64).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        for k in 0..=1000 {
            let c = diverging(k as f64 / 1000.0);
            assert!(dist(c, [255, 255, 255]) > 90.0, "{k}: {c:?} is near white");
        }
        assert!(dist(diverging(0.4999), diverging(0.5)) > 100.0);
    }
}

//! The shared look: bundled font, palette, font sizes, tick formatting, notes.

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

use crate::PlotError;

/// Font family used for all text (bundled DejaVu Sans; SVG `<text>` elements name it).
pub const FONT_FAMILY: &str = "DejaVu Sans";

static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static FONT_OK: OnceLock<bool> = OnceLock::new();

/// Register the bundled font with plotters (once per process). It is registered as
/// [`FONT_FAMILY`] and also as `"sans-serif"`, so any plotters default text finds it.
pub(crate) fn ensure_font() -> Result<(), PlotError> {
    let ok = *FONT_OK.get_or_init(|| {
        [FONT_FAMILY, "sans-serif"]
            .iter()
            .all(|name| plotters::style::register_font(name, FontStyle::Normal, FONT_BYTES).is_ok())
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// Text colour.
pub(crate) const INK: RGBColor = RGBColor(20, 20, 20);
/// Grid lines.
pub(crate) const GRID: RGBColor = RGBColor(225, 225, 225);
/// Coarse grid lines.
pub(crate) const GRID_BOLD: RGBColor = RGBColor(200, 200, 200);
/// Peak marker lines and labels.
pub(crate) const MARKER: RGBColor = RGBColor(180, 30, 30);
/// Heatmap cells whose value is NaN.
pub(crate) const NAN_GREY: RGBColor = RGBColor(176, 176, 176);

/// Line colours (the matplotlib "tab10" set), cycled over series.
pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    // Teal, not the category palette's red: red is the highlight (MARKER).
    RGBColor(23, 190, 207),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Font sizes and spacings scaled from the image size, so that the default sizes
/// (1000×600, 1200×900) get readable text and other sizes look proportionate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Theme {
    pub scale: f64,
    pub title: f64,
    pub label: f64,
    pub tick: f64,
    pub note: f64,
}

impl Theme {
    pub fn for_size((w, h): (u32, u32)) -> Self {
        let scale = (w as f64 / 1000.0).min(h as f64 / 600.0).clamp(0.6, 3.0);
        Theme {
            scale,
            title: 24.0 * scale,
            label: 19.0 * scale,
            tick: 15.0 * scale,
            note: 20.0 * scale,
        }
    }

    /// A length in pixels scaled with the image.
    pub fn px(&self, v: f64) -> i32 {
        (v * self.scale).round() as i32
    }

    pub fn px_u(&self, v: f64) -> u32 {
        self.px(v).max(1) as u32
    }
}

/// Text style in the bundled font.
pub(crate) fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from((FONT_FAMILY, size).into_font()).color(&INK)
}

/// Tick label for a "nice" tick value: plain decimals for moderate magnitudes,
/// short scientific notation for very large or small ones, no float noise.
pub(crate) fn fmt_tick(v: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    let a = v.abs();
    if a < 1e-12 {
        return "0".to_string();
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{:.3e}", v);
        // "1.500e-4" -> "1.5e-4"
        return match s.split_once('e') {
            Some((m, e)) => format!("{}e{}", trim_zeros(m), e),
            None => s,
        };
    }
    trim_zeros(&format!("{:.6}", v)).to_string()
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// A value in engineering notation with an SI prefix and three significant
/// digits, for colourbars: `1134.263806` → `"1.13 k"`, `0.25` → `"250 m"`,
/// `-40` → `"-40"`, `3.2e-6` → `"3.2 µ"`; `"0"` at zero.
pub(crate) fn fmt_eng(v: f64) -> String {
    const PREFIXES: [&str; 9] = ["f", "p", "n", "µ", "m", "", "k", "M", "G"];
    if !v.is_finite() {
        return String::new();
    }
    let a = v.abs();
    if a < 1e-15 {
        return "0".to_string();
    }
    let mut e = ((a.log10() / 3.0).floor() as i32).clamp(-5, 3);
    let mut m = a / 10f64.powi(3 * e);
    let digits = |m: f64| {
        if m >= 100.0 {
            0
        } else if m >= 10.0 {
            1
        } else {
            2
        }
    };
    let mut text = format!("{:.*}", digits(m), m);
    // Rounding may reach the next prefix: 999.7 → "1000" → "1 k".
    if text.parse::<f64>().unwrap_or(0.0) >= 1000.0 && e < 3 {
        e += 1;
        m /= 1000.0;
        text = format!("{:.*}", digits(m), m);
    }
    let sign = if v < 0.0 { "-" } else { "" };
    let prefix = PREFIXES[(e + 5) as usize];
    let number = trim_zeros(&text);
    if prefix.is_empty() {
        format!("{sign}{number}")
    } else {
        format!("{sign}{number} {prefix}")
    }
}

/// Format a data value for a note ("constant at …").
pub(crate) fn fmt_value(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{:.4e}", v)
    } else {
        trim_zeros(&format!("{:.6}", v)).to_string()
    }
}

/// About `target` round-numbered ticks (1, 2, 5 × 10^k) covering `[lo, hi]`.
pub(crate) fn nice_ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Vec::new();
    }
    let raw = (hi - lo) / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let step = mag
        * if f < 1.5 {
            1.0
        } else if f < 3.0 {
            2.0
        } else if f < 7.0 {
            5.0
        } else {
            10.0
        };
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|k| {
            let t = k as f64 * step;
            // snap tiny float noise around zero
            if t.abs() < step * 1e-9 {
                0.0
            } else {
                t
            }
        })
        .collect()
}

/// Draw text at pixel `pos` (anchor centre) on a light box, e.g. "signal is identically zero".
pub(crate) fn draw_note<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pos: (i32, i32),
    text: &str,
    size: f64,
) -> Result<(), PlotError> {
    let style = font(size).pos(Pos::new(HPos::Center, VPos::Center));
    let (tw, th) = root.estimate_text_size(text, &style)?;
    let (tw, th) = (tw as i32, th as i32);
    let pad = (size * 0.5) as i32;
    root.draw(&Rectangle::new(
        [
            (pos.0 - tw / 2 - pad, pos.1 - th / 2 - pad),
            (pos.0 + tw / 2 + pad, pos.1 + th / 2 + pad),
        ],
        ShapeStyle::from(&RGBColor(255, 250, 235)).filled(),
    ))?;
    root.draw(&Rectangle::new(
        [
            (pos.0 - tw / 2 - pad, pos.1 - th / 2 - pad),
            (pos.0 + tw / 2 + pad, pos.1 + th / 2 + pad),
        ],
        ShapeStyle::from(&RGBColor(160, 140, 90)).stroke_width(1),
    ))?;
    root.draw(&Text::new(text.to_string(), pos, style))?;
    Ok(())
}

/// Draw left-anchored text at pixel `pos` on a translucent white box (labels over data).
pub(crate) fn draw_label<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pos: (i32, i32),
    text: &str,
    size: f64,
    color: RGBColor,
) -> Result<(), PlotError> {
    let style = font(size)
        .color(&color)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let (tw, th) = root.estimate_text_size(text, &style)?;
    let (tw, th) = (tw as i32, th as i32);
    let pad = (size * 0.25).ceil() as i32;
    root.draw(&Rectangle::new(
        [
            (pos.0 - pad, pos.1 - th / 2 - pad),
            (pos.0 + tw + pad, pos.1 + th / 2 + pad),
        ],
        ShapeStyle::from(&WHITE.mix(0.8)).filled(),
    ))?;
    root.draw(&Text::new(text.to_string(), pos, style))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_format_is_clean() {
        assert_eq!(fmt_tick(0.30000000000000004), "0.3");
        assert_eq!(fmt_tick(2000.0), "2000");
        assert_eq!(fmt_tick(-1.5), "-1.5");
        assert_eq!(fmt_tick(0.0002), "2e-4");
        assert_eq!(fmt_tick(250000.0), "2.5e5");
        assert_eq!(fmt_tick(1e-17), "0");
    }

    #[test]
    fn engineering_notation() {
        assert_eq!(fmt_eng(1134.263806), "1.13 k");
        assert_eq!(fmt_eng(0.25), "250 m");
        assert_eq!(fmt_eng(-40.0), "-40");
        assert_eq!(fmt_eng(3.2e-6), "3.2 µ");
        assert_eq!(fmt_eng(0.0), "0");
        assert_eq!(fmt_eng(999.7), "1 k");
        assert_eq!(fmt_eng(118.0), "118");
        assert_eq!(fmt_eng(-80.0), "-80");
        assert_eq!(fmt_eng(2.5e7), "25 M");
        assert_eq!(fmt_eng(1.0), "1");
    }

    #[test]
    fn the_palette_never_uses_the_highlight_red() {
        let d = |a: RGBColor, b: RGBColor| {
            ((a.0 as f64 - b.0 as f64).powi(2)
                + (a.1 as f64 - b.1 as f64).powi(2)
                + (a.2 as f64 - b.2 as f64).powi(2))
            .sqrt()
        };
        for c in PALETTE {
            assert!(d(c, MARKER) >= 80.0, "{c:?} is too close to the highlight");
        }
    }

    #[test]
    fn nice_ticks_cover_range() {
        let t = nice_ticks(-3.2, 7.9, 5);
        assert_eq!(t, vec![-2.0, 0.0, 2.0, 4.0, 6.0]);
        assert!(nice_ticks(1.0, 1.0, 5).is_empty());
        assert!(nice_ticks(f64::NAN, 1.0, 5).is_empty());
    }
}

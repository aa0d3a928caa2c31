//! Heatmaps: spectrograms (sequential colormap) and stability maps (diverging
//! colormap centred on 0, zero contour, labelled parameter markers).

use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::BitMapElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::colormap;
use crate::contour::{zero_contour, Segment};
use crate::lines::axis_range;
use crate::output::{emit, Figure, Raster, RasterMode, PLACEHOLDER};
use crate::style::{
    draw_label, draw_note, fmt_eng, fmt_tick, font, nice_ticks, Theme, INK, NAN_GREY,
};
use crate::{Format, PlotError};

/// Colour scheme of a [`heatmap`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Colormap {
    /// Dark-to-bright (viridis approximation), for magnitudes such as dB.
    #[default]
    Sequential,
    /// Blues below 0, reds from 0 up (both sides coloured, never white), centred on 0, for signed
    /// quantities such as the growth rate σ.
    Diverging,
}

/// What to draw in a [`heatmap`]. Build with [`HeatmapSpec::new`] and override
/// fields with struct-update syntax:
/// `HeatmapSpec { log_y: true, ..HeatmapSpec::new(...) }`.
#[derive(Debug, Clone, Copy)]
pub struct HeatmapSpec<'a> {
    /// Title above the plot (empty: none).
    pub title: &'a str,
    /// x axis label with units.
    pub x_label: &'a str,
    /// y axis label with units.
    pub y_label: &'a str,
    /// Colorbar label with units, e.g. `"PSD (dB re 1 (m/s)²/Hz)"` or `"σ_max (1/s)"`.
    pub colorbar_label: &'a str,
    /// Cell-centre x coordinates, strictly increasing (`nx` values).
    pub xs: &'a [f64],
    /// Cell-centre y coordinates, strictly increasing (`ny` values).
    pub ys: &'a [f64],
    /// Row-major `ny × nx` values: `values[j * nx + i]` is at `(xs[i], ys[j])`.
    /// NaN cells are drawn grey; ±∞ saturate the colormap.
    pub values: &'a [f64],
    /// Logarithmic x axis (columns with x ≤ 0 are dropped).
    pub log_x: bool,
    /// Logarithmic y axis (rows with y ≤ 0, e.g. the 0 Hz bin, are dropped).
    pub log_y: bool,
    /// Colour scheme.
    pub colormap: Colormap,
    /// Colour scale limits; values outside saturate. `None`: the finite data range
    /// (symmetrised about 0 for [`Colormap::Diverging`]). E.g. `Some((max - 80.0, max))`
    /// for an 80 dB spectrogram.
    pub value_range: Option<(f64, f64)>,
    /// Draw the zero level set (marching squares on the cell centres) as a black line,
    /// and mark 0 on the colorbar.
    pub contour_zero: bool,
    /// Labelled points `(x, y, label)`, e.g. named parameter sets.
    pub markers: &'a [(f64, f64, &'a str)],
    /// Legend text for grey NaN cells, e.g. `"no steady sliding"`; empty: `"no data"`.
    /// Shown only when NaN cells are present.
    pub nan_label: &'a str,
    /// Categories instead of a colour scale: when not empty, `values` are class
    /// indices (0, 1, …; NaN grey), drawn in a qualitative palette
    /// (ColorBrewer Set1, then Dark2) with a legend of these names in place of the colorbar.
    pub classes: &'a [&'a str],
}

impl<'a> HeatmapSpec<'a> {
    /// A sequential, linear-axes heatmap without contour or markers.
    pub fn new(
        title: &'a str,
        x_label: &'a str,
        y_label: &'a str,
        colorbar_label: &'a str,
        xs: &'a [f64],
        ys: &'a [f64],
        values: &'a [f64],
    ) -> Self {
        HeatmapSpec {
            title,
            x_label,
            y_label,
            colorbar_label,
            xs,
            ys,
            values,
            log_x: false,
            log_y: false,
            colormap: Colormap::Sequential,
            value_range: None,
            contour_zero: false,
            markers: &[],
            nan_label: "",
            classes: &[],
        }
    }
}

/// Draw a heatmap with a colorbar and write `stem.png` / `stem.svg`.
///
/// Cells are rasterised straight into a pixel buffer (one lookup per output pixel),
/// so 1000×1000 grids render as fast as small ones; SVG output embeds that raster
/// as a PNG `<image>` under vector axes, contour and markers. Returns the paths written.
pub fn heatmap(
    stem: impl AsRef<Path>,
    formats: &[Format],
    size: (u32, u32),
    spec: &HeatmapSpec<'_>,
) -> Result<Vec<PathBuf>, PlotError> {
    let fig = HeatFigure::prepare(spec, Theme::for_size(size))?;
    emit(stem.as_ref(), formats, size, &fig)
}

struct HeatFigure<'a> {
    spec: &'a HeatmapSpec<'a>,
    theme: Theme,
    nx: usize,
    ny: usize,
    /// Cell edges in data coordinates (nx + 1, ny + 1 values).
    edges_x: Vec<f64>,
    edges_y: Vec<f64>,
    /// Colour per kept cell, row-major ny × nx.
    colors: Vec<[u8; 3]>,
    range: (f64, f64),
    /// Finite values below / above `range`: the colour scale saturates there.
    clipped: (bool, bool),
    has_nan: bool,
    segments: Vec<Segment>,
    note: Option<String>,
}

fn check_axis(name: &str, v: &[f64]) -> Result<(), PlotError> {
    if v.is_empty() {
        return Err(PlotError::Input(format!("heatmap {name} is empty")));
    }
    if v.iter().any(|a| !a.is_finite()) || v.windows(2).any(|w| w[1] <= w[0]) {
        return Err(PlotError::Input(format!(
            "heatmap {name} must be finite and strictly increasing"
        )));
    }
    Ok(())
}

/// Cell edges from centres, in the axis' own (linear or log10) space. The
/// outer cells end at the first and last centres (half cells), so the picture
/// stays inside the data's range (a parameter's LO:HI, a spectrogram's times).
fn edges(centres_t: &[f64]) -> Vec<f64> {
    let n = centres_t.len();
    if n == 1 {
        let c = centres_t[0];
        let d = if c == 0.0 { 0.5 } else { c.abs() * 0.5 };
        return vec![c - d, c + d];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(centres_t[0]);
    for w in centres_t.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    e.push(centres_t[n - 1]);
    e
}

impl<'a> HeatFigure<'a> {
    fn prepare(spec: &'a HeatmapSpec<'a>, theme: Theme) -> Result<Self, PlotError> {
        check_axis("xs", spec.xs)?;
        check_axis("ys", spec.ys)?;
        let (nx0, ny0) = (spec.xs.len(), spec.ys.len());
        if spec.values.len() != nx0 * ny0 {
            return Err(PlotError::Input(format!(
                "heatmap values has {} entries, expected ny × nx = {ny0} × {nx0}",
                spec.values.len()
            )));
        }
        // On log axes keep only positive coordinates (e.g. drop the 0 Hz row).
        let keep_x: Vec<usize> = (0..nx0)
            .filter(|&i| !spec.log_x || spec.xs[i] > 0.0)
            .collect();
        let keep_y: Vec<usize> = (0..ny0)
            .filter(|&j| !spec.log_y || spec.ys[j] > 0.0)
            .collect();
        if keep_x.is_empty() || keep_y.is_empty() {
            return Err(PlotError::Input(
                "heatmap has no positive coordinates on a log axis".into(),
            ));
        }
        let t = |v: f64, log: bool| if log { v.log10() } else { v };
        let inv = |v: f64, log: bool| if log { 10f64.powf(v) } else { v };
        let tx: Vec<f64> = keep_x.iter().map(|&i| t(spec.xs[i], spec.log_x)).collect();
        let ty: Vec<f64> = keep_y.iter().map(|&j| t(spec.ys[j], spec.log_y)).collect();
        let edges_x = edges(&tx).into_iter().map(|e| inv(e, spec.log_x)).collect();
        let edges_y = edges(&ty).into_iter().map(|e| inv(e, spec.log_y)).collect();
        let (nx, ny) = (keep_x.len(), keep_y.len());
        let vals: Vec<f64> = keep_y
            .iter()
            .flat_map(|&j| keep_x.iter().map(move |&i| spec.values[j * nx0 + i]))
            .collect();

        let finite = vals.iter().copied().filter(|v| v.is_finite());
        let data_range = finite.fold(None, |acc: Option<(f64, f64)>, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        });
        let mut note = None;
        let range = match (spec.value_range, data_range) {
            (Some((lo, hi)), _) if lo.is_finite() && hi.is_finite() && hi > lo => (lo, hi),
            (_, None) => {
                note = Some("no finite values".to_string());
                (-1.0, 1.0)
            }
            (_, Some((lo, hi))) => match spec.colormap {
                Colormap::Diverging => {
                    let m = lo.abs().max(hi.abs());
                    if m > 0.0 {
                        (-m, m)
                    } else {
                        (-1.0, 1.0)
                    }
                }
                Colormap::Sequential => axis_range(lo, hi, false, 0.0).0,
            },
        };
        let map: fn(f64) -> [u8; 3] = match spec.colormap {
            Colormap::Sequential => colormap::sequential,
            Colormap::Diverging => colormap::diverging,
        };
        let g = [NAN_GREY.0, NAN_GREY.1, NAN_GREY.2];
        let categorical = !spec.classes.is_empty();
        let colors = vals
            .iter()
            .map(|&v| {
                if v.is_nan() {
                    g
                } else if categorical {
                    colormap::qualitative(v.max(0.0).round() as usize)
                } else {
                    map((v - range.0) / (range.1 - range.0))
                }
            })
            .collect();
        let clipped = if categorical {
            (false, false)
        } else {
            (
                vals.iter().any(|&v| v < range.0),
                vals.iter().any(|&v| v > range.1),
            )
        };
        let has_nan = vals.iter().any(|v| v.is_nan());
        let segments = if spec.contour_zero {
            // Contour in the axes' display space so that it is straight where the
            // field is linear on screen, then mapped back to data coordinates.
            zero_contour(&tx, &ty, &vals)
                .into_iter()
                .map(|s| s.map(|(x, y)| (inv(x, spec.log_x), inv(y, spec.log_y))))
                .collect()
        } else {
            Vec::new()
        };
        Ok(HeatFigure {
            spec,
            theme,
            nx,
            ny,
            edges_x,
            edges_y,
            colors,
            range,
            clipped,
            has_nan,
            segments,
            note,
        })
    }
}

impl Figure for HeatFigure<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        mode: RasterMode,
    ) -> Result<Option<Raster>, PlotError> {
        root.fill(&WHITE)?;
        let (x0, x1) = (self.edges_x[0], self.edges_x[self.nx]);
        let (y0, y1) = (self.edges_y[0], self.edges_y[self.ny]);
        let lin = |a: f64, b: f64| RangedCoordf64::from(a..b);
        let log = |a: f64, b: f64| -> LogCoord<f64> { (a..b).log_scale().into() };
        match (self.spec.log_x, self.spec.log_y) {
            (false, false) => self.draw_on(root, mode, lin(x0, x1), lin(y0, y1)),
            (true, false) => self.draw_on(root, mode, log(x0, x1), lin(y0, y1)),
            (false, true) => self.draw_on(root, mode, lin(x0, x1), log(y0, y1)),
            (true, true) => self.draw_on(root, mode, log(x0, x1), log(y0, y1)),
        }
    }
}

/// Index of the cell containing pixel `p`, given the cells' edge pixels in either
/// increasing (x) or decreasing (y) order.
fn cell_index(edge_px: &[i32], p: i32) -> Option<usize> {
    let n = edge_px.len() - 1;
    let k = if edge_px[n] >= edge_px[0] {
        edge_px.partition_point(|&e| e <= p)
    } else {
        edge_px.partition_point(|&e| e > p)
    };
    if k == 0 {
        None
    } else {
        Some((k - 1).min(n - 1))
    }
}

impl HeatFigure<'_> {
    fn draw_on<DB, X, Y>(
        &self,
        root: &DrawingArea<DB, Shift>,
        mode: RasterMode,
        xc: X,
        yc: Y,
    ) -> Result<Option<Raster>, PlotError>
    where
        DB: DrawingBackend,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let th = self.theme;
        let spec = self.spec;
        let (w, _h) = root.dim_in_pixel();
        let cb_width = th.px(175.0).min(w as i32 / 3) as u32;
        let (left, _right) = root.split_horizontally(w - cb_width);

        let mut builder = ChartBuilder::on(&left);
        builder
            .margin(th.px(12.0))
            .margin_right(th.px(20.0))
            .x_label_area_size(th.px(52.0))
            .y_label_area_size(th.px(96.0));
        if !spec.title.is_empty() {
            builder.caption(spec.title, font(th.title));
        }
        let mut chart = builder.build_cartesian_2d(xc, yc)?;
        let fmt = |v: &f64| fmt_tick(*v);
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(spec.x_label)
            .y_desc(spec.y_label)
            .x_labels(10)
            .y_labels(8)
            .x_label_formatter(&fmt)
            .y_label_formatter(&fmt)
            .label_style(font(th.tick))
            .axis_desc_style(font(th.label))
            .axis_style(INK)
            .draw()?;

        // Raster of the cells at output resolution.
        let (px, py) = chart.plotting_area().get_pixel_range();
        let (rw, rh) = (
            (px.end - px.start).max(1) as u32,
            (py.end - py.start).max(1) as u32,
        );
        let ex: Vec<i32> = self
            .edges_x
            .iter()
            .map(|&x| chart.backend_coord(&(x, self.edges_y[0])).0)
            .collect();
        let ey: Vec<i32> = self
            .edges_y
            .iter()
            .map(|&y| chart.backend_coord(&(self.edges_x[0], y)).1)
            .collect();
        let cols: Vec<Option<usize>> = (px.start..px.start + rw as i32)
            .map(|p| cell_index(&ex, p))
            .collect();
        let mut rgb = vec![255u8; rw as usize * rh as usize * 3];
        for (r, q) in (py.start..py.start + rh as i32).enumerate() {
            let Some(iy) = cell_index(&ey, q) else {
                continue;
            };
            let row = &self.colors[iy * self.nx..(iy + 1) * self.nx];
            let line = &mut rgb[r * rw as usize * 3..(r + 1) * rw as usize * 3];
            for (c, ix) in cols.iter().enumerate() {
                if let Some(ix) = ix {
                    line[c * 3..c * 3 + 3].copy_from_slice(&row[*ix]);
                }
            }
        }
        let raster = match mode {
            RasterMode::Blit => {
                let elem = BitMapElement::<(i32, i32)>::with_owned_buffer(
                    (px.start, py.start),
                    (rw, rh),
                    rgb,
                )
                .ok_or_else(|| PlotError::Draw("raster size mismatch".into()))?;
                root.draw(&elem)?;
                None
            }
            RasterMode::Placeholder => {
                root.draw(&Rectangle::new(
                    [
                        (px.start, py.start),
                        (px.start + rw as i32, py.start + rh as i32),
                    ],
                    PLACEHOLDER.filled(),
                ))?;
                Some(Raster {
                    x: px.start,
                    y: py.start,
                    w: rw,
                    h: rh,
                    rgb,
                })
            }
        };
        root.draw(&Rectangle::new(
            [(px.start, py.start), (px.end, py.end)],
            INK.stroke_width(1),
        ))?;

        if !self.segments.is_empty() {
            let lw = th.px_u(2.0);
            chart.draw_series(
                self.segments
                    .iter()
                    .map(|s| PathElement::new(vec![s[0], s[1]], INK.stroke_width(lw))),
            )?;
        }

        let (x_lo, x_hi) = (self.edges_x[0], self.edges_x[self.nx]);
        let (y_lo, y_hi) = (self.edges_y[0], self.edges_y[self.ny]);
        for &(mx, my, label) in spec.markers {
            if !(mx.is_finite() && my.is_finite())
                || mx < x_lo
                || mx > x_hi
                || my < y_lo
                || my > y_hi
            {
                continue;
            }
            let (qx, qy) = chart.backend_coord(&(mx, my));
            let r = th.px(6.0);
            root.draw(&Circle::new((qx, qy), r, WHITE.filled()))?;
            root.draw(&Circle::new((qx, qy), r, INK.stroke_width(th.px_u(2.0))))?;
            if !label.is_empty() {
                draw_label(root, (qx + r + th.px(4.0), qy), label, th.tick, INK)?;
            }
        }

        if let Some(note) = &self.note {
            let centre = ((px.start + px.end) / 2, (py.start + py.end) / 2);
            draw_note(root, centre, note, th.note)?;
        }

        if spec.classes.is_empty() {
            self.draw_colorbar(root, px.end + th.px(34.0), py.start, py.end)?;
        } else {
            self.draw_class_legend(root, px.end + th.px(20.0), py.start)?;
        }
        if self.has_nan {
            self.draw_nan_legend(root)?;
        }
        Ok(raster)
    }

    fn draw_colorbar<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        x: i32,
        top: i32,
        bottom: i32,
    ) -> Result<(), PlotError> {
        let th = self.theme;
        let bar_w = th.px(24.0);
        let (lo, hi) = self.range;
        let h = (bottom - top).max(1);
        let map: fn(f64) -> [u8; 3] = match self.spec.colormap {
            Colormap::Sequential => colormap::sequential,
            Colormap::Diverging => colormap::diverging,
        };
        // One rectangle per pixel row of the bar.
        for q in top..bottom {
            let t = 1.0 - ((q - top) as f64 + 0.5) / h as f64;
            let [r, g, b] = map(t);
            root.draw(&Rectangle::new(
                [(x, q), (x + bar_w, q + 1)],
                RGBColor(r, g, b).filled(),
            ))?;
        }
        root.draw(&Rectangle::new(
            [(x, top), (x + bar_w, bottom)],
            INK.stroke_width(1),
        ))?;
        // Saturation: an extension triangle in the end colour, and the end's
        // value marked "≥" / "≤", where the data go beyond the scale.
        let tri = th.px(14.0);
        for (on, tip, base, t) in [
            (self.clipped.1, top - tri, top, 1.0),
            (self.clipped.0, bottom + tri, bottom, 0.0),
        ] {
            if on {
                let [r, g, b] = map(t);
                let pts = vec![(x, base), (x + bar_w, base), (x + bar_w / 2, tip)];
                root.draw(&Polygon::new(pts.clone(), RGBColor(r, g, b).filled()))?;
                let mut outline = pts;
                outline.push((x, base));
                root.draw(&PathElement::new(outline, INK.stroke_width(1)))?;
            }
        }
        let to_px = |v: f64| bottom - ((v - lo) / (hi - lo) * h as f64).round() as i32;
        let tick_len = th.px(6.0);
        let style = font(th.tick).pos(Pos::new(HPos::Left, VPos::Center));
        let mut max_w = 0;
        let mut ticks: Vec<(f64, String)> = nice_ticks(lo, hi, 6)
            .into_iter()
            .map(|v| (v, fmt_eng(v)))
            .collect();
        // The saturated ends are labelled with their value, marked ≥ / ≤.
        let near = |v: f64, end: f64| (v - end).abs() < 0.06 * (hi - lo);
        if self.clipped.1 {
            ticks.retain(|(v, _)| !near(*v, hi));
            ticks.push((hi, format!("≥ {}", fmt_eng(hi))));
        }
        if self.clipped.0 {
            ticks.retain(|(v, _)| !near(*v, lo));
            ticks.push((lo, format!("≤ {}", fmt_eng(lo))));
        }
        for (v, text) in ticks {
            let q = to_px(v);
            root.draw(&PathElement::new(
                vec![(x + bar_w, q), (x + bar_w + tick_len, q)],
                INK.stroke_width(1),
            ))?;
            max_w = max_w.max(root.estimate_text_size(&text, &style)?.0 as i32);
            root.draw(&Text::new(
                text,
                (x + bar_w + tick_len + th.px(4.0), q),
                style.clone(),
            ))?;
        }
        if self.spec.contour_zero && lo < 0.0 && hi > 0.0 {
            let q = to_px(0.0);
            root.draw(&PathElement::new(
                vec![(x - th.px(4.0), q), (x + bar_w + th.px(4.0), q)],
                INK.stroke_width(th.px_u(2.0)),
            ))?;
        }
        if !self.spec.colorbar_label.is_empty() {
            let lx = x + bar_w + tick_len + th.px(10.0) + max_w + (th.label * 0.6) as i32;
            let style = font(th.label)
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Center, VPos::Center));
            root.draw(&Text::new(
                self.spec.colorbar_label.to_string(),
                (lx, (top + bottom) / 2),
                style,
            ))?;
        }
        Ok(())
    }

    /// One swatch and name per class, top down, in place of the colorbar.
    fn draw_class_legend<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        x: i32,
        top: i32,
    ) -> Result<(), PlotError> {
        let th = self.theme;
        let s = th.px(16.0);
        let step = th.px(26.0);
        let style = font(th.tick).pos(Pos::new(HPos::Left, VPos::Center));
        for (i, name) in self.spec.classes.iter().enumerate() {
            let y = top + th.px(10.0) + i as i32 * step;
            let [r, g, b] = colormap::qualitative(i);
            root.draw(&Rectangle::new(
                [(x, y - s / 2), (x + s, y + s / 2)],
                RGBColor(r, g, b).filled(),
            ))?;
            root.draw(&Rectangle::new(
                [(x, y - s / 2), (x + s, y + s / 2)],
                INK.stroke_width(1),
            ))?;
            root.draw(&Text::new(
                name.to_string(),
                (x + s + th.px(6.0), y),
                style.clone(),
            ))?;
        }
        Ok(())
    }

    /// Grey swatch and its meaning in the top-right corner.
    fn draw_nan_legend<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        let th = self.theme;
        let (w, _) = root.dim_in_pixel();
        let text = if self.spec.nan_label.is_empty() {
            "no data"
        } else {
            self.spec.nan_label
        };
        let style = font(th.tick).pos(Pos::new(HPos::Left, VPos::Center));
        let (tw, _) = root.estimate_text_size(text, &style)?;
        let s = th.px(16.0);
        let y = th.px(26.0);
        let tx = w as i32 - th.px(12.0) - tw as i32;
        let sx = tx - th.px(6.0) - s;
        root.draw(&Rectangle::new(
            [(sx, y - s / 2), (sx + s, y + s / 2)],
            NAN_GREY.filled(),
        ))?;
        root.draw(&Rectangle::new(
            [(sx, y - s / 2), (sx + s, y + s / 2)],
            INK.stroke_width(1),
        ))?;
        root.draw(&Text::new(text.to_string(), (tx, y), style))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_lookup_both_directions() {
        let inc = [10, 20, 30];
        assert_eq!(cell_index(&inc, 9), None);
        assert_eq!(cell_index(&inc, 10), Some(0));
        assert_eq!(cell_index(&inc, 25), Some(1));
        assert_eq!(cell_index(&inc, 30), Some(1));
        let dec = [30, 20, 10];
        assert_eq!(cell_index(&dec, 30), None);
        assert_eq!(cell_index(&dec, 29), Some(0));
        assert_eq!(cell_index(&dec, 15), Some(1));
        assert_eq!(cell_index(&dec, 5), Some(1));
    }

    #[test]
    fn edges_from_centres() {
        assert_eq!(edges(&[1.0, 2.0, 4.0]), vec![1.0, 1.5, 3.0, 4.0]);
        assert_eq!(edges(&[2.0]), vec![1.0, 3.0]);
    }
}

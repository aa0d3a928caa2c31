//! The mode-coupling diagram: frequency (top) and growth rate (bottom) of
//! every tracked mode against a swept parameter. Each mode keeps its colour
//! in both panels; where a mode grows its line is drawn thick, with a red
//! outline, and coalescences are marked by a dashed vertical line and a ring
//! on the frequency branch.

use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::lines::axis_range;
use crate::output::{emit, Figure, Raster, RasterMode};
use crate::style::{draw_note, fmt_tick, font, Theme, GRID, GRID_BOLD, INK, MARKER, PALETTE};
use crate::{Format, PlotError};

/// One mode of the diagram: its values at each parameter value.
#[derive(Debug, Clone, Copy)]
pub struct BranchSeries<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Frequency (Hz) at each parameter value.
    pub freq: &'a [f64],
    /// Growth rate σ (1/s) at each parameter value.
    pub growth: &'a [f64],
    /// Whether the mode grows at each parameter value (drawn highlighted).
    pub growing: &'a [bool],
}

/// What [`mode_coupling`] draws.
#[derive(Debug, Clone, Copy)]
pub struct ModeCouplingSpec<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Parameter axis label (with unit).
    pub x_label: &'a str,
    /// Parameter values.
    pub x: &'a [f64],
    /// The modes; every slice as long as `x`.
    pub branches: &'a [BranchSeries<'a>],
    /// Coalescences: (parameter value, frequency in Hz).
    pub coalescences: &'a [(f64, f64)],
}

/// Draw the mode-coupling diagram and write `stem.png` / `stem.svg`.
/// Returns the paths written.
pub fn mode_coupling(
    stem: impl AsRef<Path>,
    formats: &[Format],
    size: (u32, u32),
    spec: &ModeCouplingSpec<'_>,
) -> Result<Vec<PathBuf>, PlotError> {
    for b in spec.branches {
        if b.freq.len() != spec.x.len()
            || b.growth.len() != spec.x.len()
            || b.growing.len() != spec.x.len()
        {
            return Err(PlotError::Input(format!(
                "mode \"{}\": {} parameter values but {} frequencies, {} growth rates, {} flags",
                b.label,
                spec.x.len(),
                b.freq.len(),
                b.growth.len(),
                b.growing.len()
            )));
        }
    }
    let fig = Diagram {
        spec: *spec,
        theme: Theme::for_size(size),
    };
    emit(stem.as_ref(), formats, size, &fig)
}

struct Diagram<'a> {
    spec: ModeCouplingSpec<'a>,
    theme: Theme,
}

fn range(vals: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = vals
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return (0.0, 1.0);
    }
    axis_range(lo, hi, false, pad).0
}

impl Figure for Diagram<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _mode: RasterMode,
    ) -> Result<Option<Raster>, PlotError> {
        root.fill(&WHITE)?;
        let s = &self.spec;
        let t = self.theme;
        let (top, bottom) = root.split_vertically(root.dim_in_pixel().1 / 2);
        let xr = range(s.x.iter().copied(), 0.0);
        let fr = range(s.branches.iter().flat_map(|b| b.freq.iter().copied()), 0.05);
        let gr = {
            let (lo, hi) = range(
                s.branches.iter().flat_map(|b| b.growth.iter().copied()),
                0.05,
            );
            // Keep σ = 0 in view: it is the stability boundary.
            (lo.min(0.0), hi.max(0.0))
        };
        for (panel, area, yr, ylab) in [
            (0, &top, fr, "frequency (Hz)"),
            (1, &bottom, gr, "growth rate σ (1/s)"),
        ] {
            let mut builder = ChartBuilder::on(area);
            builder
                .margin(t.px(12.0))
                .margin_right(t.px(28.0))
                .x_label_area_size(t.px(48.0))
                .y_label_area_size(t.px(96.0));
            if panel == 0 && !s.title.is_empty() {
                builder.caption(s.title, font(t.title));
            }
            let mut chart = builder.build_cartesian_2d(
                RangedCoordf64::from(xr.0..xr.1),
                RangedCoordf64::from(yr.0..yr.1),
            )?;
            let fmt = |v: &f64| fmt_tick(*v);
            chart
                .configure_mesh()
                .x_desc(s.x_label)
                .y_desc(ylab)
                .x_labels(10)
                .y_labels(7)
                .x_label_formatter(&fmt)
                .y_label_formatter(&fmt)
                .label_style(font(t.tick))
                .axis_desc_style(font(t.label))
                .light_line_style(GRID)
                .bold_line_style(GRID_BOLD)
                .x_max_light_lines(1)
                .y_max_light_lines(1)
                .axis_style(INK)
                .draw()?;
            if panel == 1 {
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(xr.0, 0.0), (xr.1, 0.0)],
                    INK.stroke_width(1),
                )))?;
            }
            for (k, b) in s.branches.iter().enumerate() {
                let color = PALETTE[k % PALETTE.len()];
                let y = if panel == 0 { b.freq } else { b.growth };
                // Unstable stretches first (thick red underlay), then the line.
                for i in 1..s.x.len() {
                    if b.growing[i - 1] && b.growing[i] {
                        chart.draw_series(std::iter::once(PathElement::new(
                            vec![(s.x[i - 1], y[i - 1]), (s.x[i], y[i])],
                            MARKER.stroke_width(t.px_u(7.0)),
                        )))?;
                    }
                }
                let pts: Vec<(f64, f64)> =
                    s.x.iter()
                        .zip(y)
                        .map(|(&x, &y)| (x, y))
                        .filter(|(x, y)| x.is_finite() && y.is_finite())
                        .collect();
                if pts.len() == 1 {
                    chart.draw_series(std::iter::once(Circle::new(
                        pts[0],
                        t.px(4.0),
                        color.filled(),
                    )))?;
                }
                let lw = t.px_u(2.0);
                let anno = chart.draw_series(std::iter::once(PathElement::new(
                    pts,
                    color.stroke_width(lw),
                )))?;
                if panel == 0 && !b.label.is_empty() {
                    let leg = t.px(22.0);
                    let w = t.px_u(3.0);
                    anno.label(b.label).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + leg, y)], color.stroke_width(w))
                    });
                }
            }
            // Coalescences: dashed vertical line in both panels, ring on the frequency.
            let (_, py) = chart.plotting_area().get_pixel_range();
            for &(xc, fc) in s.coalescences {
                if !(xc.is_finite() && xc >= xr.0 && xc <= xr.1) {
                    continue;
                }
                let xp = chart.backend_coord(&(xc, yr.0)).0;
                root.draw(&DashedPathElement::new(
                    vec![(xp, py.start), (xp, py.end)],
                    t.px(6.0),
                    t.px(4.0),
                    MARKER.stroke_width(t.px_u(1.5)),
                ))?;
                if panel == 0 && fc.is_finite() {
                    chart.draw_series(std::iter::once(Circle::new(
                        (xc, fc),
                        t.px(8.0),
                        MARKER.stroke_width(t.px_u(2.5)),
                    )))?;
                }
            }
            if panel == 0 && !s.branches.is_empty() {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .margin(t.px(8.0))
                    .legend_area_size(t.px(30.0))
                    .label_font(font(t.tick))
                    .background_style(WHITE.mix(0.85))
                    .border_style(INK)
                    .draw()?;
            }
            if s.branches.is_empty() || s.x.is_empty() {
                let (px, py) = chart.plotting_area().get_pixel_range();
                draw_note(
                    root,
                    ((px.start + px.end) / 2, (py.start + py.end) / 2),
                    "no data",
                    t.note,
                )?;
            }
        }
        Ok(None)
    }
}

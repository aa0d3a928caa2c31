//! Stacked line panels (time series, spectra with peak markers) and phase portraits.

use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use crate::decimate::{dedupe_pixels, min_max_per_column, unique_polylines};
use crate::output::{emit, Figure, Raster, RasterMode};
use crate::style::{
    draw_label, draw_note, fmt_tick, fmt_value, font, Theme, GRID, GRID_BOLD, INK, MARKER, PALETTE,
};
use crate::{Format, PlotError};

/// One line of a panel. `x` and `y` must have equal lengths; non-finite points
/// (and points with x ≤ 0 on a log-x panel) are skipped.
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// Legend text; panels where every label is empty get no legend.
    pub label: &'a str,
    /// Abscissae (need not be sorted, but sorted data decimates best).
    pub x: &'a [f64],
    /// Ordinates.
    pub y: &'a [f64],
    /// Drawn dashed (e.g. the unstable part of a bifurcation diagram).
    pub dashed: bool,
    /// Colour: index into the palette; `None` is the series' own position.
    pub colour: Option<usize>,
    /// A non-finite point breaks the line (instead of being skipped).
    pub gaps: bool,
}

impl<'a> Series<'a> {
    /// A labelled series.
    pub fn new(label: &'a str, x: &'a [f64], y: &'a [f64]) -> Self {
        Series {
            label,
            x,
            y,
            dashed: false,
            colour: None,
            gaps: false,
        }
    }
    /// Drawn dashed.
    pub fn dashed(mut self, on: bool) -> Self {
        self.dashed = on;
        self
    }
    /// In the palette's colour `k` (several series can share one).
    pub fn colour(mut self, k: usize) -> Self {
        self.colour = Some(k);
        self
    }
    /// Non-finite points break the line into pieces.
    pub fn with_gaps(mut self) -> Self {
        self.gaps = true;
        self
    }
}

/// A labelled vertical marker on a panel, e.g. a spectral peak at 5030 Hz, "5.03 kHz".
#[derive(Debug, Clone, Copy)]
pub struct Peak<'a> {
    /// Position on the x axis (markers outside the axis range are not drawn).
    pub x: f64,
    /// Text drawn next to the marker at the top of the panel.
    pub label: &'a str,
}

/// One panel of [`line_panels`]: axes with one or more series.
#[derive(Debug, Clone, Default)]
pub struct Panel<'a> {
    /// Title above the panel (empty: none).
    pub title: &'a str,
    /// x axis label with units, e.g. `"time (s)"`.
    pub x_label: &'a str,
    /// y axis label with units, e.g. `"v (m/s)"`.
    pub y_label: &'a str,
    /// Logarithmic x axis (for spectra).
    pub log_x: bool,
    /// The lines, coloured from a fixed palette in order.
    pub series: Vec<Series<'a>>,
    /// Vertical peak markers with labels.
    pub peaks: Vec<Peak<'a>>,
}

impl<'a> Panel<'a> {
    /// An empty linear-axis panel.
    pub fn new(title: &'a str, x_label: &'a str, y_label: &'a str) -> Self {
        Panel {
            title,
            x_label,
            y_label,
            ..Panel::default()
        }
    }

    /// Set the log-x option.
    pub fn log_x(mut self, on: bool) -> Self {
        self.log_x = on;
        self
    }

    /// Add a series.
    pub fn with_series(mut self, series: Series<'a>) -> Self {
        self.series.push(series);
        self
    }

    /// Add a peak marker.
    pub fn with_peak(mut self, x: f64, label: &'a str) -> Self {
        self.peaks.push(Peak { x, label });
        self
    }
}

/// Title and axis labels of a single-axes figure.
#[derive(Debug, Clone, Copy, Default)]
pub struct Labels<'a> {
    /// Title above the plot (empty: none).
    pub title: &'a str,
    /// x axis label with units.
    pub x_label: &'a str,
    /// y axis label with units.
    pub y_label: &'a str,
}

/// Draw `panels` stacked vertically in one image and write `stem.png` / `stem.svg`.
///
/// Long series are decimated per pixel column (min/max envelope), so 10⁵–10⁶ points
/// render quickly and the SVG stays small. Returns the paths written.
pub fn line_panels(
    stem: impl AsRef<Path>,
    formats: &[Format],
    size: (u32, u32),
    panels: &[Panel<'_>],
) -> Result<Vec<PathBuf>, PlotError> {
    if panels.is_empty() {
        return Err(PlotError::Input(
            "line_panels needs at least one panel".into(),
        ));
    }
    let prepared = panels
        .iter()
        .map(|p| Prepared::from_panel(p, 0.0))
        .collect::<Result<Vec<_>, _>>()?;
    let fig = XyFigure {
        panels: prepared,
        theme: Theme::for_size(size),
    };
    emit(stem.as_ref(), formats, size, &fig)
}

/// Phase portrait: velocity `v` against displacement `x` as a line (sticking shows as
/// a flat segment at the belt velocity). Long trajectories are simplified to the
/// pixel grid. Returns the paths written.
pub fn phase_portrait(
    stem: impl AsRef<Path>,
    formats: &[Format],
    size: (u32, u32),
    x: &[f64],
    v: &[f64],
    labels: &Labels<'_>,
) -> Result<Vec<PathBuf>, PlotError> {
    let panel =
        Panel::new(labels.title, labels.x_label, labels.y_label).with_series(Series::new("", x, v));
    let mut p = Prepared::from_panel(&panel, 0.05)?;
    p.path_mode = true;
    let all_zero = p
        .series
        .iter()
        .all(|(_, pts)| pts.iter().all(|q| *q == (0.0, 0.0)));
    if p.x_constant && p.y_constant && !all_zero {
        p.note = Some("trajectory stays at a single point".to_string());
    }
    let fig = XyFigure {
        panels: vec![p],
        theme: Theme::for_size(size),
    };
    emit(stem.as_ref(), formats, size, &fig)
}

/// A panel with its data filtered and its axis ranges and note decided.
struct Prepared<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    log_x: bool,
    /// label, finite points
    series: Vec<(&'a str, Vec<(f64, f64)>)>,
    /// Per series: dashed, colour, and the indices in its points where a
    /// new piece starts (gapped series).
    looks: Vec<(bool, Option<usize>, Vec<usize>)>,
    peaks: Vec<Peak<'a>>,
    x_range: (f64, f64),
    y_range: (f64, f64),
    x_constant: bool,
    y_constant: bool,
    note: Option<String>,
    /// Curve is not a function of x (phase portrait): simplify by pixel, not column.
    path_mode: bool,
}

impl<'a> Prepared<'a> {
    /// `x_pad`: fractional padding of the x range (0 for signals and spectra).
    fn from_panel(p: &Panel<'a>, x_pad: f64) -> Result<Self, PlotError> {
        let mut series = Vec::with_capacity(p.series.len());
        let mut looks = Vec::with_capacity(p.series.len());
        for s in &p.series {
            if s.x.len() != s.y.len() {
                return Err(PlotError::Input(format!(
                    "series \"{}\" has {} x values but {} y values",
                    s.label,
                    s.x.len(),
                    s.y.len()
                )));
            }
            let mut pts: Vec<(f64, f64)> = Vec::with_capacity(s.x.len());
            let mut breaks = Vec::new();
            for (&x, &y) in s.x.iter().zip(s.y) {
                if x.is_finite() && y.is_finite() && (!p.log_x || x > 0.0) {
                    pts.push((x, y));
                } else if s.gaps && breaks.last() != Some(&pts.len()) {
                    breaks.push(pts.len());
                }
            }
            series.push((s.label, pts));
            looks.push((s.dashed, s.colour, breaks));
        }
        let all = || series.iter().flat_map(|(_, pts)| pts.iter());
        let xr = min_max(all().map(|p| p.0));
        let yr = min_max(all().map(|p| p.1));
        let mut note = None;
        let (x_range, x_constant) = match xr {
            Some((lo, hi)) => axis_range(lo, hi, p.log_x, x_pad),
            None => (if p.log_x { (1.0, 10.0) } else { (0.0, 1.0) }, false),
        };
        let (y_range, y_constant) = match yr {
            Some((lo, hi)) => axis_range(lo, hi, false, 0.05),
            None => ((0.0, 1.0), false),
        };
        // Spans beyond the largest float (1.7e308 against −1.7e308) or
        // near it leave nothing to draw: an error, not an endless tick search.
        for (axis, (a, b)) in [("x", x_range), ("y", y_range)] {
            if !(b - a).is_finite() || a.abs() > 1e300 || b.abs() > 1e300 {
                return Err(PlotError::Input(format!(
                    "panel \"{}\": {axis} values from {a:e} to {b:e} are too large to draw",
                    p.title
                )));
            }
        }
        match yr {
            None => {
                note = Some(if p.series.iter().all(|s| s.x.is_empty()) {
                    "no data".to_string()
                } else {
                    "no finite data".to_string()
                })
            }
            Some((lo, _)) if y_constant && lo == 0.0 => {
                note = Some("signal is identically zero".to_string())
            }
            Some((lo, _)) if y_constant => {
                note = Some(format!("signal is constant at {}", fmt_value(lo)))
            }
            _ => {}
        }
        Ok(Prepared {
            title: p.title,
            x_label: p.x_label,
            y_label: p.y_label,
            log_x: p.log_x,
            series,
            looks,
            peaks: p.peaks.clone(),
            x_range,
            y_range,
            x_constant,
            y_constant,
            note,
            path_mode: false,
        })
    }
}

fn min_max(vals: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    vals.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Axis range for data in `[lo, hi]` with fractional padding `pad`; degenerate
/// (constant) data gets a symmetric range around the value. Returns (range, constant).
pub(crate) fn axis_range(lo: f64, hi: f64, log: bool, pad: f64) -> ((f64, f64), bool) {
    if log {
        let (a, b) = (lo.log10(), hi.log10());
        if b - a < 1e-9 {
            return ((lo / 2.0, lo * 2.0), true);
        }
        let d = (b - a) * pad;
        return ((10f64.powf(a - d), 10f64.powf(b + d)), false);
    }
    let scale = lo.abs().max(hi.abs());
    if hi - lo <= scale * 1e-12 {
        let c = 0.5 * (lo + hi);
        let d = if c == 0.0 { 1.0 } else { c.abs() * 0.5 };
        return ((c - d, c + d), true);
    }
    let d = (hi - lo) * pad;
    ((lo - d, hi + d), false)
}

struct XyFigure<'a> {
    panels: Vec<Prepared<'a>>,
    theme: Theme,
}

impl Figure for XyFigure<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _mode: RasterMode,
    ) -> Result<Option<Raster>, PlotError> {
        root.fill(&WHITE)?;
        let areas = root.split_evenly((self.panels.len(), 1));
        for (p, area) in self.panels.iter().zip(&areas) {
            let (x0, x1) = p.x_range;
            if p.log_x {
                let xc: LogCoord<f64> = (x0..x1).log_scale().into();
                draw_panel(root, area, p, self.theme, xc)?;
            } else {
                draw_panel(root, area, p, self.theme, RangedCoordf64::from(x0..x1))?;
            }
        }
        Ok(None)
    }
}

fn draw_panel<DB, X>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    p: &Prepared<'_>,
    theme: Theme,
    xc: X,
) -> Result<(), PlotError>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let (y0, y1) = p.y_range;
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(theme.px(12.0))
        .margin_right(theme.px(28.0))
        .x_label_area_size(theme.px(48.0))
        .y_label_area_size(theme.px(96.0));
    if !p.title.is_empty() {
        builder.caption(p.title, font(theme.title));
    }
    let mut chart = builder.build_cartesian_2d(xc, RangedCoordf64::from(y0..y1))?;
    let fmt = |v: &f64| fmt_tick(*v);
    chart
        .configure_mesh()
        .x_desc(p.x_label)
        .y_desc(p.y_label)
        .x_labels(10)
        .y_labels(7)
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .label_style(font(theme.tick))
        .axis_desc_style(font(theme.label))
        .light_line_style(GRID)
        .bold_line_style(GRID_BOLD)
        .x_max_light_lines(if p.log_x { 9 } else { 1 })
        .y_max_light_lines(1)
        .axis_style(INK)
        .draw()?;

    let (px_range, py_range) = chart.plotting_area().get_pixel_range();
    let plot_w = (px_range.end - px_range.start).max(1) as usize;
    let mut any_label = false;
    for (k, (label, pts)) in p.series.iter().enumerate() {
        let (dashed, colour, breaks) = &p.looks[k];
        let color = PALETTE[colour.unwrap_or(k) % PALETTE.len()];
        let dense = pts.len() > 3 * plot_w;
        // Polylines to draw: the data itself when short or broken into
        // pieces, else simplified to the output resolution (see `decimate`).
        let polylines: Vec<Vec<(f64, f64)>> = if !breaks.is_empty() {
            let mut cuts = vec![0];
            cuts.extend(breaks.iter().copied());
            cuts.push(pts.len());
            cuts.windows(2)
                .filter(|w| w[1] > w[0])
                .map(|w| pts[w[0]..w[1]].to_vec())
                .collect()
        } else if pts.len() > 2 * plot_w {
            let to_px = |x: f64, y: f64| chart.backend_coord(&(x, y));
            let by_column = if p.path_mode {
                None
            } else {
                min_max_per_column(pts, |x| to_px(x, y0).0)
            };
            match by_column {
                Some(d) => vec![d],
                None => unique_polylines(&dedupe_pixels(pts, to_px), to_px),
            }
        } else {
            vec![pts.clone()]
        };
        let stroke = color.stroke_width(if dense { 1 } else { theme.px_u(2.0) });
        // A lone point (a piece of one, or a one-point series) is a dot.
        let (dots, lines): (Vec<_>, Vec<_>) = polylines.into_iter().partition(|l| l.len() == 1);
        let dot = |l: Vec<(f64, f64)>| Circle::new(l[0], theme.px(4.0), color.filled());
        let (dash, gap) = (theme.px(8.0), theme.px(5.0));
        let anno = if *dashed {
            chart.draw_series(
                lines
                    .into_iter()
                    .map(|line| DashedPathElement::new(line, dash, gap, stroke)),
            )?
        } else {
            chart.draw_series(lines.into_iter().map(|line| PathElement::new(line, stroke)))?
        };
        if !label.is_empty() {
            any_label = true;
            let leg = theme.px(22.0);
            let lw = theme.px_u(3.0);
            let style = color.stroke_width(lw);
            if *dashed {
                anno.label(*label).legend(move |(x, y)| {
                    DashedPathElement::new(
                        vec![(x, y), (x + leg, y)],
                        theme.px(6.0),
                        theme.px(4.0),
                        style,
                    )
                    .into_dyn()
                });
            } else {
                anno.label(*label).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + leg, y)], style).into_dyn()
                });
            }
        }
        chart.draw_series(dots.into_iter().map(dot))?;
    }
    if any_label {
        chart
            .configure_series_labels() // upper left: squeal grows to the right
            .position(SeriesLabelPosition::UpperLeft)
            .margin(theme.px(8.0))
            .legend_area_size(theme.px(30.0))
            .label_font(font(theme.tick))
            .background_style(WHITE.mix(0.85))
            .border_style(INK)
            .draw()?;
    }

    // Peak markers: dashed vertical line plus a label near the top, staggered so
    // neighbouring peaks do not overprint each other.
    let (x0, x1) = p.x_range;
    let mut shown = 0;
    for peak in &p.peaks {
        if !peak.x.is_finite() || peak.x < x0.min(x1) || peak.x > x0.max(x1) {
            continue;
        }
        let xp = chart.backend_coord(&(peak.x, y0)).0;
        root.draw(&DashedPathElement::new(
            vec![(xp, py_range.start), (xp, py_range.end)],
            theme.px(6.0),
            theme.px(4.0),
            MARKER.stroke_width(theme.px_u(1.5)),
        ))?;
        if !peak.label.is_empty() {
            let size = theme.tick;
            let (tw, _) = root.estimate_text_size(peak.label, &font(size))?;
            let gap = theme.px(5.0);
            let lx = if xp + gap + tw as i32 > px_range.end {
                xp - gap - tw as i32
            } else {
                xp + gap
            };
            let ly = py_range.start + (size * (0.9 + 1.3 * (shown % 3) as f64)) as i32;
            draw_label(root, (lx, ly), peak.label, size, MARKER)?;
        }
        shown += 1;
    }

    if let Some(note) = &p.note {
        let centre = (
            (px_range.start + px_range.end) / 2,
            (py_range.start + py_range.end) / 2,
        );
        draw_note(root, centre, note, theme.note)?;
    }
    Ok(())
}

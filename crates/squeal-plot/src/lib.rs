//! Pictures for squeal: stacked line panels (time series, spectra), heatmaps
//! (spectrograms, stability maps), phase portraits and mode-coupling diagrams, written as PNG and/or SVG.
//!
//! The crate takes plain data (slices) and knows nothing of the physics. Every plot
//! function takes an output path *stem* and a list of [`Format`]s and writes
//! `stem.png` / `stem.svg`, returning the paths written.
//!
//! Rendering is self-contained: the DejaVu Sans font is bundled (see
//! `assets/LICENSE-DejaVu.txt`, Bitstream Vera license) and registered with plotters'
//! `ab_glyph` text support, so no system fonts or font libraries are needed. SVG
//! output names the family `"DejaVu Sans"` in its `<text>` elements.
//!
//! Bad data never panics: non-finite values are dropped (NaN heatmap cells are drawn
//! grey), and constant or empty signals still get axes plus a centred note.

mod colormap;
mod contour;
mod decimate;
mod heatmap;
mod lines;
mod modes;
mod output;
mod style;

use std::path::PathBuf;

pub use contour::{zero_contour, Segment};
pub use heatmap::{heatmap, Colormap, HeatmapSpec};
pub use lines::{line_panels, phase_portrait, Labels, Panel, Peak, Series};
pub use modes::{mode_coupling, BranchSeries, ModeCouplingSpec};
pub use style::FONT_FAMILY;

/// Default size (pixels) for multi-panel figures such as the velocity/PSD triplet.
pub const SIZE_MULTI: (u32, u32) = (1200, 900);
/// Default size (pixels) for single-panel figures.
pub const SIZE_SINGLE: (u32, u32) = (1000, 600);

/// Output file format. The file name is the stem plus [`Format::extension`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// Raster PNG (8-bit RGB).
    Png,
    /// Vector SVG (heatmap cells are embedded as a PNG image).
    Svg,
}

impl Format {
    /// File extension without the dot: `"png"` or `"svg"`.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Svg => "svg",
        }
    }
}

/// Errors from writing a plot.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Creating or writing an output file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file that could not be written.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The drawing library or the PNG encoder reported an error.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// The input is structurally unusable (mismatched lengths, bad grid, tiny size).
    #[error("invalid plot input: {0}")]
    Input(String),
    /// The bundled font could not be parsed (should never happen).
    #[error("the bundled DejaVu Sans font could not be loaded")]
    Font,
}

impl<E> From<plotters::drawing::DrawingAreaErrorKind<E>> for PlotError
where
    E: std::error::Error + Send + Sync,
{
    fn from(e: plotters::drawing::DrawingAreaErrorKind<E>) -> Self {
        PlotError::Draw(e.to_string())
    }
}

//! Running one figure description against the PNG and SVG backends and writing files.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::{style, Format, PlotError};

/// How a figure should put a pre-rendered RGB raster (heatmap cells) on the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RasterMode {
    /// Blit it into the bitmap directly.
    Blit,
    /// Draw a placeholder rectangle in [`PLACEHOLDER`] colour and return the raster;
    /// the SVG writer swaps the placeholder for an embedded `<image>`.
    Placeholder,
}

/// Colour of the SVG placeholder rectangle (never used otherwise).
pub(crate) const PLACEHOLDER: RGBColor = RGBColor(1, 2, 3);

/// An RGB8 raster covering pixels `[x, x + w) × [y, y + h)`.
pub(crate) struct Raster {
    pub x: i32,
    pub y: i32,
    pub w: u32,
    pub h: u32,
    pub rgb: Vec<u8>,
}

/// Something that can draw itself on any plotters backend.
pub(crate) trait Figure {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        mode: RasterMode,
    ) -> Result<Option<Raster>, PlotError>;
}

/// `stem` + `.` + extension (appended, so a stem like `run_0.5` keeps its dot).
fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Render `fig` once per requested format and write the files.
pub(crate) fn emit(
    stem: &Path,
    formats: &[Format],
    size: (u32, u32),
    fig: &impl Figure,
) -> Result<Vec<PathBuf>, PlotError> {
    let (w, h) = size;
    if !(64..=16384).contains(&w) || !(64..=16384).contains(&h) {
        return Err(PlotError::Input(format!(
            "image size {w}×{h} outside 64..=16384 pixels"
        )));
    }
    style::ensure_font()?;
    let mut written = Vec::new();
    let mut seen = Vec::new();
    for &format in formats {
        if seen.contains(&format) {
            continue;
        }
        seen.push(format);
        let path = with_ext(stem, format.extension());
        match format {
            Format::Png => write_png(&path, size, fig)?,
            Format::Svg => write_svg(&path, size, fig)?,
        }
        written.push(path);
    }
    Ok(written)
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> PlotError + '_ {
    move |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn write_png(path: &Path, (w, h): (u32, u32), fig: &impl Figure) -> Result<(), PlotError> {
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        fig.draw(&root, RasterMode::Blit)?;
        root.present()?;
    }
    let file = File::create(path).map_err(io_err(path))?;
    let mut out = BufWriter::new(file);
    encode_png(&mut out, w, h, &buf).map_err(|e| png_err(path, e))?;
    out.flush().map_err(io_err(path))
}

fn png_err(path: &Path, e: png::EncodingError) -> PlotError {
    match e {
        png::EncodingError::IoError(source) => PlotError::Io {
            path: path.to_path_buf(),
            source,
        },
        other => PlotError::Draw(format!("PNG encoding: {other}")),
    }
}

fn encode_png<W: Write>(out: W, w: u32, h: u32, rgb: &[u8]) -> Result<(), png::EncodingError> {
    let mut enc = png::Encoder::new(out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()
}

fn write_svg(path: &Path, size: (u32, u32), fig: &impl Figure) -> Result<(), PlotError> {
    let mut svg = String::new();
    let raster = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let raster = fig.draw(&root, RasterMode::Placeholder)?;
        root.present()?;
        raster
    };
    if let Some(r) = raster {
        svg = embed_raster(&svg, &r)?;
    }
    std::fs::write(path, svg).map_err(io_err(path))
}

/// Replace the placeholder `<rect … fill="#010203" …/>` with an `<image>` holding the
/// raster as a base64 PNG. (plotters' own SVG bitmap support writes a malformed
/// `data:png` URI and needs the `image` crate, so we do it here.)
fn embed_raster(svg: &str, r: &Raster) -> Result<String, PlotError> {
    let fill = format!(
        "fill=\"#{:02X}{:02X}{:02X}\"",
        PLACEHOLDER.0, PLACEHOLDER.1, PLACEHOLDER.2
    );
    let Some(at) = svg.find(&fill) else {
        return Err(PlotError::Draw("SVG raster placeholder not found".into()));
    };
    let start = svg[..at].rfind("<rect").unwrap_or(at);
    let end = svg[at..].find("/>").map(|k| at + k + 2).unwrap_or(at);
    let mut png_bytes = Vec::new();
    encode_png(&mut png_bytes, r.w, r.h, &r.rgb)
        .map_err(|e| PlotError::Draw(format!("PNG encoding: {e}")))?;
    let image = format!(
        "<image x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" preserveAspectRatio=\"none\" \
         style=\"image-rendering:pixelated\" xlink:href=\"data:image/png;base64,{}\"/>",
        r.x,
        r.y,
        r.w,
        r.h,
        base64(&png_bytes)
    );
    // xlink:href (with its namespace) is understood by SVG 1.1 tools and browsers alike.
    let head = svg[..start].replacen(
        "<svg ",
        "<svg xmlns:xlink=\"http://www.w3.org/1999/xlink\" ",
        1,
    );
    Ok(format!("{}{}{}", head, image, &svg[end..]))
}

/// Standard base64 with padding (RFC 4648); tiny, so not worth a dependency.
fn base64(data: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_known_vectors() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn extension_is_appended() {
        assert_eq!(
            with_ext(Path::new("/tmp/run_0.5"), "png"),
            PathBuf::from("/tmp/run_0.5.png")
        );
    }
}

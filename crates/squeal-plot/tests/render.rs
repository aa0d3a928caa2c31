//! End-to-end rendering: files exist with the right size, are not blank, and the SVG
//! carries the label text; degenerate inputs never panic.

use std::collections::HashSet;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use squeal_plot::{
    heatmap, line_panels, phase_portrait, Colormap, Format, HeatmapSpec, Labels, Panel, PlotError,
    Series, SIZE_MULTI, SIZE_SINGLE,
};

const BOTH: [Format; 2] = [Format::Png, Format::Svg];

struct Image {
    w: u32,
    h: u32,
    rgb: Vec<u8>,
}

impl Image {
    fn pixels(&self) -> impl Iterator<Item = [u8; 3]> + '_ {
        self.rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]])
    }
    fn non_white_fraction(&self) -> f64 {
        let n = self.pixels().filter(|p| *p != [255, 255, 255]).count();
        n as f64 / (self.w as f64 * self.h as f64)
    }
    fn distinct_colours(&self) -> usize {
        self.pixels().collect::<HashSet<_>>().len()
    }
    fn count(&self, pred: impl Fn([u8; 3]) -> bool) -> usize {
        self.pixels().filter(|p| pred(*p)).count()
    }
}

fn read_png(path: &Path) -> Image {
    let decoder = png::Decoder::new(std::fs::File::open(path).expect("png exists"));
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png data");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    Image {
        w: info.width,
        h: info.height,
        rgb: buf,
    }
}

fn check_png(path: &Path, size: (u32, u32)) -> Image {
    let img = read_png(path);
    assert_eq!((img.w, img.h), size, "{}", path.display());
    let nw = img.non_white_fraction();
    assert!(nw > 0.01, "{} nearly blank: {nw}", path.display());
    assert!(img.distinct_colours() > 8, "{}", path.display());
    img
}

fn read_svg(path: &Path) -> String {
    let s = std::fs::read_to_string(path).expect("svg exists");
    assert!(s.starts_with("<svg"), "{}", &s[..s.len().min(80)]);
    assert!(s.trim_end().ends_with("</svg>"));
    assert!(s.contains("font-family=\"DejaVu Sans\""));
    s
}

fn paths(stem: &Path) -> (PathBuf, PathBuf) {
    let s = stem.display().to_string();
    (PathBuf::from(s.clone() + ".png"), PathBuf::from(s + ".svg"))
}

#[test]
fn triplet_with_200k_points() {
    let dir = tempfile::tempdir().unwrap();
    let n = 200_000;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-6).collect();
    let vt: Vec<f64> = t
        .iter()
        .map(|&t| (t * 20.0).exp() * 1e-3 * (TAU * 5030.0 * t).sin())
        .collect();
    let vn: Vec<f64> = vt.iter().map(|v| 0.3 * v).collect();
    let f: Vec<f64> = (0..2049).map(|k| k as f64 * 24.4).collect(); // includes 0 Hz
    let db: Vec<f64> = f
        .iter()
        .map(|&f| -100.0 + 60.0 / (1.0 + ((f - 5030.0) / 50.0).powi(2)))
        .collect();
    let panels = [
        Panel::new("velocities", "time (s)", "v (m/s)")
            .with_series(Series::new("tangential", &t, &vt))
            .with_series(Series::new("normal", &t, &vn)),
        Panel::new(
            "tangential PSD",
            "frequency (Hz)",
            "PSD (dB re 1 (m/s)²/Hz)",
        )
        .log_x(true)
        .with_series(Series::new("", &f, &db))
        .with_peak(5030.0, "5.03 kHz"),
        Panel::new("normal PSD", "frequency (Hz)", "PSD (dB re 1 (m/s)²/Hz)")
            .with_series(Series::new("", &f, &db))
            .with_peak(5030.0, "5.03 kHz")
            .with_peak(1e9, "off the axis"),
    ];
    let stem = dir.path().join("triplet");
    let written = line_panels(&stem, &BOTH, SIZE_MULTI, &panels).unwrap();
    let (png, svg) = paths(&stem);
    assert_eq!(written, vec![png.clone(), svg.clone()]);
    let img = check_png(&png, SIZE_MULTI);
    // series colours are present: tab10 blue and orange
    assert!(img.count(|p| p == [31, 119, 180]) > 1000);
    assert!(img.count(|p| p == [255, 127, 14]) > 1000);
    let s = read_svg(&svg);
    for text in [
        "time (s)",
        "v (m/s)",
        "PSD (dB re 1 (m/s)²/Hz)",
        "5.03 kHz",
        "tangential",
    ] {
        assert!(s.contains(text), "svg lacks {text:?}");
    }
    assert!(!s.contains("off the axis"));
    // decimation keeps the SVG small (400 000 raw points)
    assert!(s.len() < 1_000_000, "svg is {} bytes", s.len());
}

#[test]
fn zero_and_constant_signals_get_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let t: Vec<f64> = (0..500).map(|k| k as f64 * 1e-3).collect();
    let zero = vec![0.0; 500];
    let three = vec![3.5; 500];
    let stem = dir.path().join("zero");
    line_panels(
        &stem,
        &BOTH,
        SIZE_SINGLE,
        &[Panel::new("normal velocity", "time (s)", "v (m/s)")
            .with_series(Series::new("normal", &t, &zero))],
    )
    .unwrap();
    let (png, svg) = paths(&stem);
    check_png(&png, SIZE_SINGLE);
    let s = read_svg(&svg);
    assert!(s.contains("signal is identically zero"));
    assert!(s.contains("v (m/s)"));

    let stem = dir.path().join("constant");
    line_panels(
        &stem,
        &[Format::Svg],
        SIZE_SINGLE,
        &[Panel::new("", "time (s)", "F (N)").with_series(Series::new("", &t, &three))],
    )
    .unwrap();
    let s = read_svg(&paths(&stem).1);
    assert!(s.contains("signal is constant at 3.5"), "{s}");
}

#[test]
fn nan_and_empty_inputs_do_not_panic() {
    let dir = tempfile::tempdir().unwrap();
    let nan = vec![f64::NAN; 100];
    let t: Vec<f64> = (0..100).map(f64::from).collect();
    let mut mixed: Vec<f64> = t.iter().map(|x| x.sin()).collect();
    mixed[10] = f64::NAN;
    mixed[20] = f64::INFINITY;
    let neg: Vec<f64> = t.iter().map(|x| x - 50.0).collect();
    let one = [1.0];
    let panels = [
        Panel::new("all NaN", "time (s)", "v (m/s)").with_series(Series::new("a", &t, &nan)),
        Panel::new("mixed", "time (s)", "v (m/s)")
            .with_series(Series::new("b", &t, &mixed))
            .with_peak(f64::NAN, "nan peak"),
        Panel::new("empty", "time (s)", "v (m/s)").with_series(Series::new("c", &[], &[])),
        Panel::new("no series", "time (s)", "v (m/s)"),
        Panel::new("log of negatives", "f (Hz)", "dB")
            .log_x(true)
            .with_series(Series::new("", &neg, &t)),
        Panel::new("single point", "x", "y").with_series(Series::new("", &one, &one)),
    ];
    let stem = dir.path().join("nan");
    line_panels(&stem, &BOTH, SIZE_MULTI, &panels).unwrap();
    let (png, svg) = paths(&stem);
    check_png(&png, SIZE_MULTI);
    let s = read_svg(&svg);
    assert!(s.contains("no finite data"));
    assert!(s.contains("no data"));

    // structural errors are errors, not panics
    let e = line_panels(&stem, &BOTH, SIZE_SINGLE, &[]).unwrap_err();
    assert!(matches!(e, PlotError::Input(_)));
    let bad = [Panel::new("", "", "").with_series(Series::new("s", &t, &one))];
    let e = line_panels(&stem, &BOTH, SIZE_SINGLE, &bad).unwrap_err();
    assert!(matches!(e, PlotError::Input(_)), "{e}");
    let e = line_panels(&stem, &BOTH, (10, 10), &panels).unwrap_err();
    assert!(matches!(e, PlotError::Input(_)));
    // unwritable location is an I/O error
    let e = line_panels(
        dir.path().join("missing/dir/x"),
        &[Format::Png],
        SIZE_SINGLE,
        &panels,
    )
    .unwrap_err();
    assert!(matches!(e, PlotError::Io { .. }), "{e}");
    // no formats: nothing written
    assert!(line_panels(&stem, &[], SIZE_SINGLE, &panels)
        .unwrap()
        .is_empty());
}

fn grid(n: usize, lo: f64, hi: f64) -> Vec<f64> {
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

#[test]
fn spectrogram_heatmap() {
    let dir = tempfile::tempdir().unwrap();
    let xs = grid(200, 0.0, 0.2);
    let ys = grid(129, 0.0, 20_000.0); // 0 Hz row dropped on the log axis
    let vals: Vec<f64> = ys
        .iter()
        .flat_map(|&f| {
            xs.iter()
                .map(move |&t| -120.0 + 80.0 * t / 0.2 / (1.0 + ((f - 5000.0) / 300.0).powi(2)))
        })
        .collect();
    let spec = HeatmapSpec {
        log_y: true,
        value_range: Some((-120.0, -40.0)),
        ..HeatmapSpec::new(
            "spectrogram",
            "time (s)",
            "frequency (Hz)",
            "PSD (dB re 1 (m/s)²/Hz)",
            &xs,
            &ys,
            &vals,
        )
    };
    let stem = dir.path().join("spectrogram");
    heatmap(&stem, &BOTH, SIZE_SINGLE, &spec).unwrap();
    let (png, svg) = paths(&stem);
    let img = check_png(&png, SIZE_SINGLE);
    assert!(img.non_white_fraction() > 0.4);
    assert!(img.distinct_colours() > 50);
    let s = read_svg(&svg);
    for text in ["time (s)", "frequency (Hz)", "PSD (dB re 1 (m/s)²/Hz)"] {
        assert!(s.contains(text), "svg lacks {text:?}");
    }
    assert!(s.contains("<image") && s.contains("xlink:href=\"data:image/png;base64,"));
    assert!(!s.contains("#010203"), "placeholder left in svg");
    assert!(!s.contains("no data"), "no NaN legend without NaN cells");
}

fn dark(p: [u8; 3]) -> bool {
    p.iter().all(|&c| c < 60)
}

#[test]
fn stability_map_has_contour_markers_and_nan_cells() {
    let dir = tempfile::tempdir().unwrap();
    let mu = grid(60, 0.1, 0.7);
    let k = grid(40, 1e5, 1e7);
    // sign change on the circle (μ - 0.4)² + ((k - 5e6)/1e7)² = 0.15², NaN corner
    let sigma: Vec<f64> = k
        .iter()
        .flat_map(|&k| {
            mu.iter().map(move |&m| {
                if m > 0.65 && k < 1e6 {
                    f64::NAN
                } else {
                    1000.0 * (0.15f64.powi(2) - (m - 0.4).powi(2) - ((k - 5e6) / 1e7).powi(2))
                }
            })
        })
        .collect();
    let markers = [(0.4, 5e6, "baseline"), (0.2, 2e6, "damped shim")];
    let base = HeatmapSpec {
        colormap: Colormap::Diverging,
        markers: &markers,
        nan_label: "no steady sliding",
        ..HeatmapSpec::new(
            "stability map",
            "friction coefficient μ (–)",
            "contact stiffness (N/m)",
            "σ_max (1/s)",
            &mu,
            &k,
            &sigma,
        )
    };
    let with = HeatmapSpec {
        contour_zero: true,
        ..base
    };
    let stem_a = dir.path().join("with");
    let stem_b = dir.path().join("without");
    heatmap(&stem_a, &BOTH, SIZE_SINGLE, &with).unwrap();
    heatmap(&stem_b, &[Format::Png], SIZE_SINGLE, &base).unwrap();
    let a = check_png(&paths(&stem_a).0, SIZE_SINGLE);
    let b = check_png(&paths(&stem_b).0, SIZE_SINGLE);
    // the contour is a closed curve of ~0.94 in μ units on a ~700 px wide axis
    let extra = a.count(dark) as i64 - b.count(dark) as i64;
    assert!(extra > 800, "contour adds only {extra} dark pixels");
    // grey NaN cells and red (positive σ) cells present
    assert!(a.count(|p| p == [176, 176, 176]) > 1000);
    assert!(a.count(|p| p[0] > 150 && p[1] < 100 && p[2] < 100) > 100);
    let s = read_svg(&paths(&stem_a).1);
    for text in [
        "no steady sliding",
        "baseline",
        "damped shim",
        "σ_max (1/s)",
        "friction coefficient μ (–)",
    ] {
        assert!(s.contains(text), "svg lacks {text:?}");
    }
}

#[test]
fn heatmap_degenerate_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let xs = grid(5, 0.0, 1.0);
    let ys = grid(4, 0.0, 1.0);
    let stem = dir.path().join("h");
    // all NaN
    let nan = vec![f64::NAN; 20];
    let spec = HeatmapSpec {
        contour_zero: true,
        colormap: Colormap::Diverging,
        ..HeatmapSpec::new("", "x", "y", "z", &xs, &ys, &nan)
    };
    heatmap(&stem, &BOTH, SIZE_SINGLE, &spec).unwrap();
    check_png(&paths(&stem).0, SIZE_SINGLE);
    assert!(read_svg(&paths(&stem).1).contains("no finite values"));
    // constant, identically zero, single cell, markers out of range / NaN
    let zero = vec![0.0; 20];
    let markers = [(f64::NAN, 0.5, "nan"), (5.0, 5.0, "outside")];
    for (x, y, v) in [
        (&xs[..], &ys[..], &zero[..]),
        (&xs[..], &ys[..], &[2.0; 20][..]),
        (&[1.0][..], &[1.0][..], &[3.0][..]),
    ] {
        for colormap in [Colormap::Sequential, Colormap::Diverging] {
            let spec = HeatmapSpec {
                colormap,
                contour_zero: true,
                markers: &markers,
                log_x: true,
                ..HeatmapSpec::new("t", "x", "y", "z", x, y, v)
            };
            // log_x with x = 0 drops that column; all-zero x would be an error
            let r = heatmap(&stem, &BOTH, (400, 300), &spec);
            assert!(r.is_ok(), "{r:?}");
        }
    }
    // structural errors
    let short = vec![0.0; 19];
    let e = heatmap(
        &stem,
        &BOTH,
        SIZE_SINGLE,
        &HeatmapSpec::new("", "", "", "", &xs, &ys, &short),
    );
    assert!(matches!(e, Err(PlotError::Input(_))));
    let unsorted = [0.0, 2.0, 1.0, 3.0, 4.0];
    let e = heatmap(
        &stem,
        &BOTH,
        SIZE_SINGLE,
        &HeatmapSpec::new("", "", "", "", &unsorted, &ys, &zero),
    );
    assert!(matches!(e, Err(PlotError::Input(_))));
    let e = heatmap(
        &stem,
        &BOTH,
        SIZE_SINGLE,
        &HeatmapSpec::new("", "", "", "", &[], &[], &[]),
    );
    assert!(matches!(e, Err(PlotError::Input(_))));
    let neg = [-2.0, -1.0];
    let spec = HeatmapSpec {
        log_y: true,
        ..HeatmapSpec::new("", "", "", "", &xs, &neg, &[0.0; 10])
    };
    assert!(matches!(
        heatmap(&stem, &BOTH, SIZE_SINGLE, &spec),
        Err(PlotError::Input(_))
    ));
}

#[test]
fn large_heatmap_renders() {
    let dir = tempfile::tempdir().unwrap();
    let xs = grid(1000, 0.0, 1.0);
    let ys = grid(1000, 0.0, 1.0);
    let vals: Vec<f64> = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| (x * 30.0).sin() * (y * 20.0).cos()))
        .collect();
    let spec = HeatmapSpec {
        colormap: Colormap::Diverging,
        contour_zero: true,
        ..HeatmapSpec::new("big", "x (m)", "y (m)", "w (m)", &xs, &ys, &vals)
    };
    let stem = dir.path().join("big");
    heatmap(&stem, &BOTH, SIZE_MULTI, &spec).unwrap();
    check_png(&paths(&stem).0, SIZE_MULTI);
    assert!(read_svg(&paths(&stem).1).contains("x (m)"));
}

#[test]
fn phase_portrait_renders() {
    let dir = tempfile::tempdir().unwrap();
    let n = 50_000;
    let x: Vec<f64> = (0..n).map(|k| (k as f64 * 0.01).cos() * 1e-4).collect();
    let v: Vec<f64> = (0..n)
        .map(|k| (-(k as f64 * 0.01).sin() * 0.2).min(0.1))
        .collect();
    let labels = Labels {
        title: "phase portrait",
        x_label: "x (m)",
        y_label: "v (m/s)",
    };
    let stem = dir.path().join("phase");
    phase_portrait(&stem, &BOTH, SIZE_SINGLE, &x, &v, &labels).unwrap();
    check_png(&paths(&stem).0, SIZE_SINGLE);
    let s = read_svg(&paths(&stem).1);
    assert!(s.contains("x (m)") && s.contains("v (m/s)"));
    // ~80 laps of one cycle: retraced pixel segments are drawn once
    assert!(s.len() < 300_000, "svg is {} bytes", s.len());

    let stem = dir.path().join("still");
    phase_portrait(
        &stem,
        &[Format::Svg],
        SIZE_SINGLE,
        &[0.0; 10],
        &[0.0; 10],
        &labels,
    )
    .unwrap();
    assert!(read_svg(&paths(&stem).1).contains("signal is identically zero"));
    let stem = dir.path().join("point");
    phase_portrait(
        &stem,
        &[Format::Svg],
        SIZE_SINGLE,
        &[1e-3; 10],
        &[0.1; 10],
        &labels,
    )
    .unwrap();
    assert!(read_svg(&paths(&stem).1).contains("single point"));
    let e = phase_portrait(&stem, &BOTH, SIZE_SINGLE, &x, &v[..10], &labels);
    assert!(matches!(e, Err(PlotError::Input(_))));
}

/// A colour scale that clips says so: "≥"/"≤" at the saturated ends (and an
/// extension triangle); one that does not clip has no such marks.
#[test]
fn saturated_colour_scales_are_marked() {
    let xs = [0.0, 1.0, 2.0];
    let ys = [0.0, 1.0];
    let vals = [-50.0, 0.0, 10.0, 20.0, 30.0, 500.0];
    let dir = tempfile::tempdir().unwrap();
    let clipped = squeal_plot::HeatmapSpec {
        value_range: Some((0.0, 100.0)),
        ..squeal_plot::HeatmapSpec::new("t", "x", "y", "v", &xs, &ys, &vals)
    };
    squeal_plot::heatmap(
        dir.path().join("c"),
        &[squeal_plot::Format::Svg],
        (800, 500),
        &clipped,
    )
    .unwrap();
    let svg = std::fs::read_to_string(dir.path().join("c.svg")).unwrap();
    assert!(
        svg.contains("≥ 100") && svg.contains("≤ 0"),
        "saturation marks"
    );
    let free = squeal_plot::HeatmapSpec {
        value_range: Some((-100.0, 600.0)),
        ..clipped
    };
    squeal_plot::heatmap(
        dir.path().join("f"),
        &[squeal_plot::Format::Svg],
        (800, 500),
        &free,
    )
    .unwrap();
    let svg = std::fs::read_to_string(dir.path().join("f.svg")).unwrap();
    assert!(!svg.contains('≥') && !svg.contains('≤'));
}

//! Renders one sample of each plot kind from synthetic data and prints timings.
//!
//! `cargo run --release -p squeal-plot --example samples [-- OUT_DIR]`
//! (default OUT_DIR: /tmp/squeal-plot-samples)

use std::f64::consts::TAU;
use std::path::PathBuf;
use std::time::Instant;

use squeal_plot::{
    heatmap, line_panels, phase_portrait, Colormap, Format, HeatmapSpec, Labels, Panel, Series,
    SIZE_MULTI, SIZE_SINGLE,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "/tmp/squeal-plot-samples".into()),
    );
    std::fs::create_dir_all(&dir)?;
    let both = [Format::Png, Format::Svg];

    // Thesis triplet: 200 000-point velocities, growing 5 kHz squeal, and two PSDs.
    let n = 200_000;
    let fs = 1.0e6;
    let t: Vec<f64> = (0..n).map(|k| k as f64 / fs).collect();
    let env = |t: f64| 1e-3 * (t / 0.05).exp().min(40.0);
    let vt: Vec<f64> = t
        .iter()
        .map(|&t| env(t) * (TAU * 5030.0 * t).sin() + 2e-4 * (TAU * 15090.0 * t).sin())
        .collect();
    let vn: Vec<f64> = t
        .iter()
        .map(|&t| 0.4 * env(t) * (TAU * 5030.0 * t + 1.0).sin())
        .collect();
    let f: Vec<f64> = (1..=4096).map(|k| k as f64 * 12.2).collect();
    let lorentz = |f: f64, f0: f64, g: f64| 1.0 / (1.0 + ((f - f0) / g).powi(2));
    let psd = |scale: f64| -> Vec<f64> {
        f.iter()
            .map(|&f| {
                let p =
                    1e-12 + scale * (lorentz(f, 5030.0, 40.0) + 1e-2 * lorentz(f, 15090.0, 60.0));
                10.0 * p.log10()
            })
            .collect()
    };
    let (pt, pn) = (psd(1e-4), psd(2e-5));
    let panels = [
        Panel::new("Disc velocity at the contact", "time (s)", "v (m/s)")
            .with_series(Series::new("tangential", &t, &vt))
            .with_series(Series::new("normal", &t, &vn)),
        Panel::new(
            "Tangential velocity PSD",
            "frequency (Hz)",
            "PSD (dB re 1 (m/s)²/Hz)",
        )
        .log_x(true)
        .with_series(Series::new("", &f, &pt))
        .with_peak(5030.0, "5.03 kHz")
        .with_peak(15090.0, "15.09 kHz"),
        Panel::new(
            "Normal velocity PSD",
            "frequency (Hz)",
            "PSD (dB re 1 (m/s)²/Hz)",
        )
        .log_x(true)
        .with_series(Series::new("", &f, &pn))
        .with_peak(5030.0, "5.03 kHz"),
    ];
    let t0 = Instant::now();
    line_panels(dir.join("triplet"), &[Format::Png], SIZE_MULTI, &panels)?;
    let png_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    line_panels(dir.join("triplet"), &[Format::Svg], SIZE_MULTI, &panels)?;
    let svg_ms = t0.elapsed().as_secs_f64() * 1e3;
    println!("triplet, 2×{n} + 2×4096 points: PNG {png_ms:.0} ms, SVG {svg_ms:.0} ms");

    // Zero signal.
    let zeros = vec![0.0; 1000];
    let tz: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-4).collect();
    line_panels(
        dir.join("zero_signal"),
        &both,
        SIZE_SINGLE,
        &[Panel::new("Normal velocity", "time (s)", "v (m/s)")
            .with_series(Series::new("normal", &tz, &zeros))],
    )?;

    // Spectrogram 500 × 500.
    let (nx, ny) = (500, 500);
    let xs: Vec<f64> = (0..nx).map(|i| i as f64 * 0.2 / nx as f64).collect();
    let ys: Vec<f64> = (0..ny).map(|j| j as f64 * 20_000.0 / ny as f64).collect();
    let mut spec_db = Vec::with_capacity(nx * ny);
    for &fq in &ys {
        for &tt in &xs {
            let a =
                env(tt).powi(2) * (lorentz(fq, 5030.0, 150.0) + 0.01 * lorentz(fq, 15090.0, 200.0));
            spec_db.push(10.0 * (a + 1e-13 * (1.0 + (fq * 0.01 + tt * 100.0).sin().abs())).log10());
        }
    }
    let top = spec_db.iter().cloned().fold(f64::MIN, f64::max);
    let spec = HeatmapSpec {
        value_range: Some((top - 80.0, top)),
        log_y: true,
        ..HeatmapSpec::new(
            "Spectrogram of tangential velocity",
            "time (s)",
            "frequency (Hz)",
            "PSD (dB re 1 (m/s)²/Hz)",
            &xs,
            &ys,
            &spec_db,
        )
    };
    let t0 = Instant::now();
    heatmap(dir.join("spectrogram"), &[Format::Png], SIZE_SINGLE, &spec)?;
    let png_ms = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    heatmap(dir.join("spectrogram"), &[Format::Svg], SIZE_SINGLE, &spec)?;
    let svg_ms = t0.elapsed().as_secs_f64() * 1e3;
    println!("heatmap 500×500: PNG {png_ms:.0} ms, SVG {svg_ms:.0} ms");

    // Stability map: σ(μ, k) with a NaN corner.
    let (nx, ny) = (120, 90);
    let mu: Vec<f64> = (0..nx)
        .map(|i| 0.1 + 0.6 * i as f64 / (nx - 1) as f64)
        .collect();
    let kc: Vec<f64> = (0..ny)
        .map(|j| 10f64.powf(5.0 + 2.0 * j as f64 / (ny - 1) as f64))
        .collect();
    let mut sigma = Vec::with_capacity(nx * ny);
    for &k in &kc {
        for &m in &mu {
            let s = 400.0
                * ((m - 0.35) * 4.0 - 0.6 * (k.log10() - 6.0).powi(2) + 0.3 * (k.log10() - 6.0));
            sigma.push(if m > 0.62 && k < 3e5 { f64::NAN } else { s });
        }
    }
    let markers = [(0.3, 1e6, "baseline pad"), (0.55, 3e6, "stiff shim")];
    let stab = HeatmapSpec {
        log_y: true,
        colormap: Colormap::Diverging,
        contour_zero: true,
        markers: &markers,
        nan_label: "no steady sliding",
        ..HeatmapSpec::new(
            "Stability map",
            "friction coefficient μ (–)",
            "contact stiffness k (N/m)",
            "max growth rate σ (1/s)",
            &mu,
            &kc,
            &sigma,
        )
    };
    heatmap(dir.join("stability_map"), &both, SIZE_SINGLE, &stab)?;

    // Phase portrait: stick-slip-like limit cycle, 200 000 points.
    let n = 200_000;
    let (mut x, mut v) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let vb = 0.1;
    for k in 0..n {
        let ph = (k as f64 / 2000.0) % 1.0;
        if ph < 0.4 {
            // stick: pad moves with the belt
            x.push(-1e-4 + 2e-4 * ph / 0.4);
            v.push(vb);
        } else {
            let a = (ph - 0.4) / 0.6 * TAU;
            x.push(1e-4 * a.cos() + 1e-6 * (k as f64 * 1e-3).sin());
            v.push(
                vb - 0.25 * a.sin().abs() * (1.0 - (ph - 0.4) / 0.6).min(1.0)
                    - 0.02 * (a / 2.0).sin(),
            );
        }
    }
    let t0 = Instant::now();
    phase_portrait(
        dir.join("phase_portrait"),
        &both,
        SIZE_SINGLE,
        &x,
        &v,
        &Labels {
            title: "Pad phase portrait",
            x_label: "tangential displacement x (m)",
            y_label: "velocity v (m/s)",
        },
    )?;
    println!(
        "phase portrait, {n} points, PNG+SVG: {:.0} ms",
        t0.elapsed().as_secs_f64() * 1e3
    );
    println!("wrote samples to {}", dir.display());
    Ok(())
}

//! Spectra, verdicts, pictures and sound of `squeal simulate`, `plot` and `listen`.

use std::path::Path;
use std::process::{Command, Output};

fn squeal(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("squeal runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// PNG size and number of distinct colours.
fn png_stats(path: &Path) -> (u32, u32, usize) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bytes = &buf[..info.buffer_size()];
    let px = info.color_type.samples();
    let mut colours: Vec<&[u8]> = bytes.chunks(px).collect();
    colours.sort();
    colours.dedup();
    (info.width, info.height, colours.len())
}

/// Lower eigenfrequency of the disc–pad normal pair (masses m_d, m_p; springs
/// k_dy to ground and k_py between): ω² = eigenvalues of M⁻¹K.
fn normal_frequency(m_d: f64, m_p: f64, k_dy: f64, k_py: f64) -> f64 {
    let (a, b, d) = ((k_dy + k_py) / m_d, -k_py / m_d, k_py / m_p);
    let c = -k_py / m_p;
    let tr = a + d;
    let det = a * d - b * c;
    let w2 = 0.5 * (tr - (tr * tr - 4.0 * det).sqrt());
    w2.sqrt() / (2.0 * std::f64::consts::PI)
}

#[test]
fn thesis_first_run_rings_at_the_normal_frequency_and_has_no_tangential_motion() {
    let d = tempfile::tempdir().unwrap();
    let mut args = vec!["simulate", "--out", "run1", "--duration", "0.5"];
    let sets = [
        "V=0", "N=500", "f1=0", "alpha=0", "c_dx=0", "c_dy=0", "c_px=0", "c_py=0",
    ];
    for s in &sets {
        args.extend(["--set", s]);
    }
    squeal(d.path(), &args);
    let dir = d.path().join("run1");
    let s = summary(&dir);
    let f = s["spectrum"]["normal"]["dominant_hz"].as_f64().unwrap();
    let bin = s["spectrum"]["resolution_hz"].as_f64().unwrap();
    let want = normal_frequency(1.0, 0.1, 8.0e6, 4.25e9);
    assert!((want - 429.0).abs() < 1.0, "MODEL.md: ≈ 429 Hz, got {want}");
    assert!(
        (f - want).abs() <= bin,
        "normal peak {f} Hz vs {want} Hz (bin {bin} Hz)"
    );
    // No friction at V = 0: the tangential velocity is identically zero…
    let csv = std::fs::read_to_string(dir.join("series.csv")).unwrap();
    assert!(
        csv.lines()
            .skip(1)
            .all(|l| l.split(',').nth(5) == Some("0e0")),
        "vx_d ≡ 0"
    );
    // …and still gets its picture, with a note.
    let svg = std::fs::read_to_string(dir.join("triplet.svg")).unwrap();
    assert!(svg.contains("identically zero"), "zero-signal note");
    assert_eq!(
        s["verdict"], "neutral",
        "undamped normal ringing persists, neither growing nor decaying"
    );
}

#[test]
fn default_run_has_spectrum_verdict_and_pictures() {
    let d = tempfile::tempdir().unwrap();
    squeal(d.path(), &["simulate", "--out", "r", "--wav"]);
    let dir = d.path().join("r");
    let s = summary(&dir);
    // MODEL.md §5: disc tangential 5.03 kHz, disc normal 429 Hz.
    let ft = s["spectrum"]["tangential"]["dominant_hz"].as_f64().unwrap();
    let fnorm = s["spectrum"]["normal"]["dominant_hz"].as_f64().unwrap();
    assert!((ft - 5030.0).abs() < 15.0, "{ft}");
    assert!((fnorm - 429.0).abs() < 13.0, "{fnorm}");
    // The pad's tangential mode grows at σ ≈ 14.7 1/s before it saturates.
    let g = s["growth_rate"]["vx_p"]["rate"].as_f64().unwrap();
    assert!((g - 14.7).abs() < 0.3, "pad growth rate {g}");
    assert_eq!(s["verdict"], "stick-slip");
    for (stem, w, h) in [
        ("triplet", 1200, 2400),
        ("spectrogram", 1000, 600),
        ("phase", 1000, 600),
    ] {
        let (pw, ph, colours) = png_stats(&dir.join(format!("{stem}.png")));
        assert_eq!((pw, ph), (w, h), "{stem}.png size");
        assert!(colours > 20, "{stem}.png looks blank ({colours} colours)");
        assert!(dir.join(format!("{stem}.svg")).is_file());
    }
    let wav = hound::WavReader::open(dir.join("squeal.wav")).unwrap();
    let spec = wav.spec();
    assert_eq!(
        (spec.sample_rate, spec.channels, spec.bits_per_sample),
        (48_000, 1, 16)
    );
    let samples: Vec<i16> = wav.into_samples::<i16>().map(Result::unwrap).collect();
    assert!(samples.len() >= 96_000, "{} samples", samples.len());
    assert!(
        samples.iter().all(|&x| x > i16::MIN),
        "no sample beyond full scale"
    );
    // No normalisation: full scale is 2 m/s, and the pad's squeal (≈ 1 m/s
    // peak) fills about half of it.
    let peak = samples.iter().map(|x| x.unsigned_abs()).max().unwrap();
    assert!((12_000..24_000).contains(&peak), "peak {peak}");
    assert_eq!(s["audio"]["signal"], "vx_p");
    assert_eq!(s["audio"]["full_scale_m_per_s"], 2.0);
    let spec = std::fs::read_to_string(dir.join("spectrum.csv")).unwrap();
    assert_eq!(
        spec.lines().next().unwrap(),
        "freq_hz,vx_d_psd,vx_d_db,vx_p_psd,vx_p_db,vy_d_psd,vy_d_db,vy_p_psd,vy_p_db"
    );
    assert_eq!(
        spec.lines().count(),
        1 + 16384 / 2 + 1,
        "one row per bin of a 16384-point segment"
    );
    assert_eq!(s["spectrum"]["window"], "hann");
    // Redraw from the saved output, with other analyser settings.
    for stem in ["triplet", "spectrogram", "phase"] {
        std::fs::remove_file(dir.join(format!("{stem}.png"))).unwrap();
    }
    squeal(
        d.path(),
        &[
            "plot",
            "r",
            "--window",
            "flattop",
            "--segment",
            "4096",
            "--amplitude",
        ],
    );
    assert!(dir.join("triplet.png").is_file() && dir.join("phase.png").is_file());
    let spec = std::fs::read_to_string(dir.join("spectrum.csv")).unwrap();
    assert_eq!(
        spec.lines().next().unwrap(),
        "freq_hz,vx_d_amp2,vx_d_db,vx_p_amp2,vx_p_db,vy_d_amp2,vy_d_db,vy_p_amp2,vy_p_db"
    );
    assert_eq!(spec.lines().count(), 1 + 4096 / 2 + 1);
    let bad = Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(d.path())
        .args(["plot", "r", "--overlap", "0.99"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--overlap 0.99"));
}

#[test]
fn listen_renders_a_chosen_signal_from_a_run_or_a_scenario() {
    let d = tempfile::tempdir().unwrap();
    squeal(
        d.path(),
        &["simulate", "--out", "r", "--duration", "0.05", "--no-plots"],
    );
    let out = squeal(
        d.path(),
        &[
            "listen", "r", "--signal", "vy_d", "--out", "n.wav", "--float",
        ],
    );
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("looped"),
        "a short run is looped, and says so"
    );
    let wav = hound::WavReader::open(d.path().join("n.wav")).unwrap();
    assert_eq!(wav.spec().sample_format, hound::SampleFormat::Float);
    let n = wav.len();
    let peak = wav
        .into_samples::<f32>()
        .map(Result::unwrap)
        .fold(0.0f32, |m, x| m.max(x.abs()));
    // Not normalised: the disc's normal velocity (≈ 0.17 m/s peak) against
    // the 2 m/s full scale.
    assert!(
        n >= 96_000 && peak > 0.06 && peak < 0.12,
        "{n} samples, peak {peak}"
    );
    squeal(
        d.path(),
        &["listen", "belt", "--out", "belt.wav", "--set", "N=120"],
    );
    assert!(d.path().join("belt.wav").is_file());
    let bad = Command::new(env!("CARGO_BIN_EXE_squeal"))
        .current_dir(d.path())
        .args(["listen", "r", "--signal", "vz"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("vz"));
}

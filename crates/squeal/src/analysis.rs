//! What a run means: spectra of the tangential and normal velocities (as the
//! thesis's spectral analyser showed them), growth rate, and a one-word
//! verdict; and the pictures and sound made from them.

use crate::model::Channels;
use crate::run::{Run, RunError};
use crate::scenario::InputError;
use serde_json::{json, Map, Value};
use squeal_core::EventKind;
use squeal_plot::{Format, HeatmapSpec, Labels, Panel, Series};
use squeal_signal::spectrum::Scaling;
use squeal_signal::window::Window;
use squeal_signal::{
    amplitude_spectrum, find_peaks, growth_rate_linear_part, spectrogram, welch, GrowthOptions,
    Peak, PeakOptions, Spectrum, Verdict, VerdictOptions, WelchOptions,
};
use std::fmt::Write as _;
use std::path::Path;

/// Velocities below this fraction of the sliding speed (or of 1 mm/s when
/// the run does not slide) everywhere in a run are integration noise around
/// an equilibrium, not motion to classify.
pub const STILL: f64 = 1e-8;

/// Longest Welch segment (samples): 16384 at 200 kHz resolves 12.2 Hz.
pub const SEGMENT: usize = 16384;

/// The spectrum of one signal with its strongest peaks.
#[derive(Debug, Clone)]
pub struct ChannelSpectrum {
    /// Column name.
    pub signal: String,
    /// One-sided Welch PSD, (m/s)²/Hz.
    pub spectrum: Spectrum,
    /// Strongest peaks, strongest first.
    pub peaks: Vec<Peak>,
    /// Segment (FFT) length used, samples.
    pub segment: usize,
}

/// Spectra, growth and verdict of a run.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// Tangential velocity spectrum.
    pub tangential: Option<ChannelSpectrum>,
    /// Normal velocity spectrum.
    pub normal: Option<ChannelSpectrum>,
    /// Growth rate of each velocity over its exponential part: (signal, rate 1/s, t0, t1, R²).
    pub growth: Vec<(String, f64, f64, f64, f64)>,
    /// One word: decays, grows, limit-cycle, stick-slip.
    pub verdict: Verdict,
}

/// The spectral analyser's settings (the thesis's analyser had a sample time,
/// an FFT length, a hop and a buffer; here: window, segment, overlap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumSettings {
    /// Window of every segment.
    pub window: Window,
    /// Longest segment (FFT length) in samples; shorter runs use their length.
    pub segment: usize,
    /// Overlap of consecutive segments, in [0, 0.95].
    pub overlap: f64,
    /// Peak-amplitude spectrum ((m/s)², read as amplitude in dB) instead of the PSD.
    pub amplitude: bool,
}

impl Default for SpectrumSettings {
    fn default() -> Self {
        SpectrumSettings {
            window: Window::Hann,
            segment: SEGMENT,
            overlap: 0.5,
            amplitude: false,
        }
    }
}

impl SpectrumSettings {
    /// From command-line flags, checked.
    pub fn from_flags(
        window: &str,
        segment: usize,
        overlap: f64,
        amplitude: bool,
    ) -> Result<Self, InputError> {
        let window = window.parse::<Window>().map_err(|_| {
            InputError(format!("--window {window}: expected hann, flattop or rect"))
        })?;
        if !(16..=1 << 22).contains(&segment) {
            return Err(InputError(format!(
                "--segment {segment}: must be between 16 and 4194304 samples"
            )));
        }
        if !(0.0..=0.95).contains(&overlap) {
            return Err(InputError(format!(
                "--overlap {overlap}: must be between 0 and 0.95"
            )));
        }
        Ok(SpectrumSettings {
            window,
            segment,
            overlap,
            amplitude,
        })
    }
}

fn spectrum_of(name: &str, x: &[f64], fs: f64, set: &SpectrumSettings) -> Option<ChannelSpectrum> {
    if x.len() < 16 {
        return None;
    }
    let opts = WelchOptions {
        seg_len: Some(set.segment.min(x.len())),
        overlap: set.overlap,
        window: set.window,
        ..WelchOptions::default()
    };
    let spectrum = if set.amplitude {
        amplitude_spectrum(x, fs, &opts).ok()?
    } else {
        welch(x, fs, &opts).ok()?
    };
    // Peaks within 60 dB of the strongest: below that lies the numerical noise floor.
    let peaks = find_peaks(
        &spectrum,
        5,
        &PeakOptions {
            max_below_strongest_db: 60.0,
            ..PeakOptions::default()
        },
    );
    Some(ChannelSpectrum {
        signal: name.to_string(),
        spectrum,
        peaks,
        segment: set.segment.min(x.len()),
    })
}

/// Analyse a run. Velocities are the columns whose names start with `v`.
pub fn analyse(run: &Run, ch: &Channels, set: &SpectrumSettings) -> Analysis {
    let fs = run.sample_rate;
    let tangential = run
        .column(&ch.tangential)
        .and_then(|x| spectrum_of(&ch.tangential, x, fs, set));
    let normal = ch
        .normal
        .as_deref()
        .and_then(|n| run.column(n).and_then(|x| spectrum_of(n, x, fs, set)));
    let t_end = run
        .column("t")
        .and_then(|t| t.last().copied())
        .unwrap_or(0.0);
    let tail_start = 0.75 * t_end;
    let stick_slip_in_tail = run
        .events
        .iter()
        .any(|(t, k)| *t >= tail_start && matches!(k, EventKind::Stick | EventKind::Reverse));
    let stick_flag = if stick_slip_in_tail { 1.0 } else { 0.0 };
    let mut growth = Vec::new();
    for (name, col) in run.columns.iter().zip(&run.data) {
        if !name.starts_with('v') || name == "v_rel" {
            continue;
        }
        if let Ok(g) = growth_rate_linear_part(col, fs, &GrowthOptions::default()) {
            if g.fit.rate.is_finite() {
                growth.push((
                    name.clone(),
                    g.fit.rate,
                    g.fit.t_start,
                    g.fit.t_end,
                    g.fit.r_squared,
                ));
            }
        }
    }
    // The verdict is about the friction-excited (tangential) motion; only when
    // there is none (a disc at rest) does it describe the normal motion; when
    // nothing moves by more than STILL·V (a run started exactly at a stable
    // equilibrium, where only integration noise remains) it decays. A
    // steady tail is one whose level changes by less than 0.25 dB: slow decays
    // (the disc's ≈ 0.5 1/s) must not pass for limit cycles.
    let opts = VerdictOptions {
        steady_tol_db: 0.25,
        ..VerdictOptions::default()
    };
    let speed = run
        .column("v_rel")
        .map_or(0.0, |v| v.iter().fold(0.0f64, |m, x| m.max(x.abs())));
    let still = STILL * speed.max(1e-3);
    let moving = |name: &str| {
        run.column(name)
            .is_some_and(|x| x.iter().any(|v| v.abs() > still))
    };
    let velocity = |name: &str| name.starts_with('v') && name != "v_rel";
    let tangential_cols: Vec<&String> = run
        .columns
        .iter()
        .filter(|n| velocity(n) && (n.starts_with("vx") || n.as_str() == "v") && moving(n))
        .collect();
    let chosen: Vec<&String> = if tangential_cols.is_empty() {
        run.columns
            .iter()
            .filter(|n| velocity(n) && moving(n))
            .collect()
    } else {
        tangential_cols
    };
    let verdicts: Vec<Verdict> = chosen
        .iter()
        .filter_map(|n| run.column(n))
        .filter_map(|x| squeal_signal::classify_with(x, fs, stick_flag, &opts).ok())
        .map(|c| c.verdict)
        .collect();
    // The system's verdict: growing anywhere beats a steady oscillation, which beats decay.
    let verdict = if verdicts.contains(&Verdict::Grows) {
        Verdict::Grows
    } else if verdicts.contains(&Verdict::StickSlip)
        || (stick_slip_in_tail && verdicts.contains(&Verdict::LimitCycle))
    {
        Verdict::StickSlip
    } else if verdicts.contains(&Verdict::LimitCycle) {
        Verdict::LimitCycle
    } else {
        Verdict::Decays
    };
    Analysis {
        tangential,
        normal,
        growth,
        verdict,
    }
}

fn channel_json(c: &Option<ChannelSpectrum>) -> Value {
    match c {
        None => Value::Null,
        Some(c) => {
            let peaks: Vec<Value> = c
                .peaks
                .iter()
                .map(|p| json!({ "freq_hz": p.freq, "level_db": p.level_db }))
                .collect();
            json!({
                "signal": c.signal,
                "dominant_hz": c.peaks.first().map(|p| p.freq),
                "peaks": peaks,
            })
        }
    }
}

impl Analysis {
    /// The `spectrum` key of summary.json.
    pub fn spectrum_json(&self) -> Value {
        let df = self
            .tangential
            .as_ref()
            .or(self.normal.as_ref())
            .map(|c| c.spectrum.df);
        let first = self.tangential.as_ref().or(self.normal.as_ref());
        json!({
            "window": first.map(|c| c.spectrum.window.name()),
            "segment": first.map(|c| c.segment),
            "segments": first.map(|c| c.spectrum.segments),
            "scaling": first.map(|c| if c.spectrum.scaling == Scaling::Amplitude { "amplitude" } else { "psd" }),
            "resolution_hz": df,
            "tangential": self.with_growth(channel_json(&self.tangential), &self.tangential),
            "normal": self.with_growth(channel_json(&self.normal), &self.normal),
        })
    }
    /// A channel's JSON with the growth rate (1/s) of its signal added.
    fn with_growth(&self, mut v: Value, c: &Option<ChannelSpectrum>) -> Value {
        if let (Some(c), Some(obj)) = (c, v.as_object_mut()) {
            let g = self.growth.iter().find(|g| g.0 == c.signal).map(|g| g.1);
            obj.insert("growth_rate".into(), json!(g));
        }
        v
    }

    /// The `growth_rate` key of summary.json: per velocity, rate (1/s) and window (s).
    pub fn growth_json(&self) -> Value {
        let mut m = Map::new();
        for (name, rate, t0, t1, r2) in &self.growth {
            m.insert(
                name.clone(),
                json!({ "rate": rate, "t_start": t0, "t_end": t1, "r_squared": r2 }),
            );
        }
        Value::Object(m)
    }
}

/// Write `spectrum.csv`: `freq_hz`, then for each analysed signal its
/// spectrum (`<signal>_psd` in (m/s)²/Hz, or `<signal>_amp2` in (m/s)² with
/// `--amplitude`) and the same in dB (`<signal>_db`).
pub fn write_spectrum_csv(an: &Analysis, path: &Path) -> Result<(), RunError> {
    let chans: Vec<&ChannelSpectrum> = [&an.tangential, &an.normal].into_iter().flatten().collect();
    let Some(first) = chans.first() else {
        return Ok(());
    };
    let unit = if first.spectrum.scaling == Scaling::Amplitude {
        "amp2"
    } else {
        "psd"
    };
    let mut t = String::from("freq_hz");
    for c in &chans {
        let _ = write!(t, ",{0}_{unit},{0}_db", c.signal);
    }
    t.push('\n');
    let dbs: Vec<Vec<f64>> = chans.iter().map(|c| c.spectrum.to_db()).collect();
    for k in 0..first.spectrum.freq.len() {
        let _ = write!(t, "{:e}", first.spectrum.freq[k]);
        for (c, d) in chans.iter().zip(&dbs) {
            let _ = write!(
                t,
                ",{:e},{:e}",
                c.spectrum.psd.get(k).copied().unwrap_or(f64::NAN),
                d.get(k).copied().unwrap_or(f64::NAN)
            );
        }
        t.push('\n');
    }
    std::fs::write(path, t)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
}

/// Write the pictures of a run into `dir`: `triplet` (the thesis's three
/// pictures), `spectrogram` and `phase` (pad tangential phase portrait), as
/// PNG and SVG.
pub fn draw(
    run: &Run,
    an: &Analysis,
    ch: &Channels,
    title: &str,
    dir: &Path,
) -> Result<(), RunError> {
    let plot_err = |e: squeal_plot::PlotError| RunError::Io(format!("drawing failed: {e}"));
    let formats = [Format::Png, Format::Svg];
    let t = run.column("t").unwrap_or(&[]);
    // The thesis's pictures: each velocity against time on its own axis (their
    // sizes differ by orders of magnitude), then the spectrum of each.
    let tan_title = format!("{title}: tangential velocity {}", ch.tangential);
    let nor_title = format!(
        "{title}: normal velocity {}",
        ch.normal.as_deref().unwrap_or("")
    );
    let mut panels = Vec::new();
    if let Some(x) = run.column(&ch.tangential) {
        panels.push(
            // One series per panel, named in its title: no legend to cover the data.
            Panel::new(&tan_title, "time (s)", "velocity (m/s)").with_series(Series::new("", t, x)),
        );
    }
    if let Some(x) = ch.normal.as_deref().and_then(|n| run.column(n)) {
        panels.push(
            Panel::new(&nor_title, "time (s)", "velocity (m/s)").with_series(Series::new("", t, x)),
        );
    }
    let chans: Vec<(&ChannelSpectrum, &str)> =
        [(&an.tangential, "tangential"), (&an.normal, "normal")]
            .into_iter()
            .filter_map(|(c, w)| c.as_ref().map(|c| (c, w)))
            .collect();
    let db: Vec<Vec<f64>> = chans.iter().map(|(c, _)| c.spectrum.to_db()).collect();
    let titles: Vec<String> = chans
        .iter()
        .map(|(c, w)| {
            let what = if c.spectrum.scaling == Scaling::Amplitude {
                "amplitude spectrum"
            } else {
                "power spectral density"
            };
            format!(
                "{what} of {} ({w}, {} window)",
                c.signal,
                c.spectrum.window.name()
            )
        })
        .collect();
    let labels: Vec<Vec<String>> = chans
        .iter()
        .map(|(c, _)| {
            c.peaks
                .iter()
                .take(2)
                .map(|p| format!("{:.1} Hz", p.freq))
                .collect()
        })
        .collect();
    for (k, (c, _)) in chans.iter().enumerate() {
        let y_label = if c.spectrum.scaling == Scaling::Amplitude {
            "amplitude (dB re 1 m/s)"
        } else {
            "PSD (dB re 1 (m/s)²/Hz)"
        };
        let mut p = Panel::new(&titles[k], "frequency (Hz)", y_label).with_series(Series::new(
            "",
            &c.spectrum.freq,
            &db[k],
        ));
        for (peak, label) in c.peaks.iter().zip(&labels[k]) {
            p = p.with_peak(peak.freq, label);
        }
        panels.push(p);
    }
    let size = (1200, 300 * panels.len() as u32);
    squeal_plot::line_panels(dir.join("triplet"), &formats, size, &panels).map_err(plot_err)?;

    if let Some(x) = run.column(&ch.tangential) {
        let seg = 2048.min(x.len().max(2));
        if let Ok(sg) = spectrogram(
            x,
            run.sample_rate,
            seg,
            (seg / 4).max(1),
            squeal_signal::window::Window::Hann,
        ) {
            let title = format!("{title}: spectrogram of {}", ch.tangential);
            let values = transpose(&sg.psd_db, sg.n_times(), sg.n_freqs());
            let spec = HeatmapSpec {
                value_range: Some((sg.max_db() - 100.0, sg.max_db())),
                ..HeatmapSpec::new(
                    &title,
                    "time (s)",
                    "frequency (Hz)",
                    "PSD (dB re 1 (m/s)²/Hz)",
                    &sg.times,
                    &sg.freqs,
                    &values,
                )
            };
            squeal_plot::heatmap(
                dir.join("spectrogram"),
                &formats,
                squeal_plot::SIZE_SINGLE,
                &spec,
            )
            .map_err(plot_err)?;
        }
    }
    if let (Some(x), Some(v)) = (run.column(&ch.phase.0), run.column(&ch.phase.1)) {
        // The last fifth of the run: the settled motion (a stick line, if any, is flat at v = V).
        let from = x.len() - x.len() / 5;
        let (x, v) = (&x[from..], &v[from..]);
        let t_from = t.get(from).copied().unwrap_or(0.0);
        let title = format!(
            "{title}: phase portrait {} – {}, t ≥ {t_from:.3} s",
            ch.phase.0, ch.phase.1
        );
        let x_label = format!("{} (m)", ch.phase.0);
        let y_label = format!("{} (m/s)", ch.phase.1);
        let labels = Labels {
            title: &title,
            x_label: &x_label,
            y_label: &y_label,
        };
        squeal_plot::phase_portrait(
            dir.join("phase"),
            &formats,
            squeal_plot::SIZE_SINGLE,
            x,
            v,
            &labels,
        )
        .map_err(plot_err)?;
    }
    Ok(())
}

/// Row-major (time, freq) → row-major (freq, time): heatmap rows are y.
fn transpose(a: &[f64], n_rows: usize, n_cols: usize) -> Vec<f64> {
    let mut out = vec![0.0; a.len()];
    for r in 0..n_rows {
        for c in 0..n_cols {
            out[c * n_rows + r] = a[r * n_cols + c];
        }
    }
    out
}

/// Render a velocity column as a WAV file (16-bit PCM or 32-bit float, 48 kHz).
/// Returns whether the run was looped to reach the minimum length.
pub fn write_wav(
    x: &[f64],
    fs: f64,
    path: &Path,
    float: bool,
) -> Result<squeal_signal::AudioClip, RunError> {
    // Loop the last fifth: the part the verdict judges steady (the last half of
    // a squeal run often still holds its growth or the pad's saturation).
    let opts = squeal_signal::AudioOptions {
        loop_fraction: 0.2,
        ..squeal_signal::AudioOptions::default()
    };
    let clip = squeal_signal::render_audio(x, fs, &opts)
        .map_err(|e| RunError::Io(format!("audio rendering failed: {e}")))?;
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: clip.sample_rate,
        bits_per_sample: if float { 32 } else { 16 },
        sample_format: if float {
            hound::SampleFormat::Float
        } else {
            hound::SampleFormat::Int
        },
    };
    let io = |e: hound::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = hound::WavWriter::create(path, spec).map_err(io)?;
    for &s in &clip.samples {
        if float {
            w.write_sample(s).map_err(io)?;
        } else {
            w.write_sample((s.clamp(-1.0, 1.0) * 32767.0).round() as i16)
                .map_err(io)?;
        }
    }
    w.finalize().map_err(io)?;
    Ok(clip)
}

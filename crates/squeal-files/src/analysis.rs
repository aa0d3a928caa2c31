//! The pictures, `spectrum.csv` and sound made from a run's analysis (the
//! analysis itself — spectra, growth, verdict, its JSON — is
//! `squeal_study::analysis`, re-exported here).

pub use squeal_study::analysis::*;

use crate::RunError;
use squeal_plot::{Format, HeatmapSpec, Labels, Panel, Series};
use squeal_signal::spectrogram;
use squeal_signal::spectrum::Scaling;
use squeal_study::model::Channels;
use squeal_study::run::Run;
use squeal_study::scenario::InputError;
use std::fmt::Write as _;
use std::path::Path;

/// Write `spectrum.csv`: `freq_hz`, then for each analysed signal its
/// spectrum (`<signal>_psd` in (m/s)²/Hz, or `<signal>_amp2` in (m/s)² with
/// `--amplitude`) and the same in dB (`<signal>_db`).
pub fn write_spectrum_csv(an: &Analysis, path: &Path) -> Result<(), RunError> {
    let chans: Vec<&ChannelSpectrum> = an.spectra.iter().collect();
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

/// What the pictures show beyond the analyser's settings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlotSettings {
    /// Frequency range (Hz) of the spectra and the spectrogram; `None`: all.
    pub f_range: Option<(f64, f64)>,
    /// Logarithmic frequency axes.
    pub log_f: bool,
}

impl PlotSettings {
    /// From `--fmax F`, `--frange LO:HI` and `--log-f`, checked (at most one range).
    pub fn from_flags(
        fmax: Option<f64>,
        frange: Option<&str>,
        log_f: bool,
    ) -> Result<Self, InputError> {
        let f_range = match (fmax, frange) {
            (Some(_), Some(_)) => {
                return Err(InputError(
                    "--fmax and --frange: give one frequency range, not both".into(),
                ))
            }
            (Some(f), None) => {
                if !(f.is_finite() && f > 0.0) {
                    return Err(InputError(format!("--fmax {f}: must be a number > 0 (Hz)")));
                }
                Some((0.0, f))
            }
            (None, Some(r)) => {
                let bad = || {
                    InputError(format!(
                        "--frange {r}: expected LO:HI in Hz with 0 <= LO < HI"
                    ))
                };
                let (lo, hi) = r.split_once(':').ok_or_else(bad)?;
                let lo: f64 = lo.trim().parse().map_err(|_| bad())?;
                let hi: f64 = hi.trim().parse().map_err(|_| bad())?;
                if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && lo < hi) {
                    return Err(bad());
                }
                Some((lo, hi))
            }
            (None, None) => None,
        };
        Ok(PlotSettings { f_range, log_f })
    }

    /// Without `--fmax`/`--frange`, the band that shows a squeal at
    /// `squeal_hz` and its first two harmonics: 0 to the next 1–2–5 step
    /// above 3.5 × the squeal, at most the Nyquist frequency `fs/2` (issue
    /// 28 §5: a 2.25 kHz squeal is not squeezed into a few pixels of
    /// 0–50 kHz). A range given by flag is kept.
    pub fn around_squeal(self, squeal_hz: Option<f64>, fs: f64) -> Self {
        let nyquist = 0.5 * fs;
        match (self.f_range, squeal_hz) {
            (None, Some(f)) if f.is_finite() && f > 0.0 => {
                let want = 3.5 * f;
                let decade = 10f64.powf(want.log10().floor());
                let step = [1.0, 2.0, 5.0, 10.0]
                    .iter()
                    .map(|k| k * decade)
                    .find(|&s| s >= want)
                    .unwrap_or(10.0 * decade);
                if step >= nyquist {
                    self
                } else {
                    PlotSettings {
                        f_range: Some((0.0, step)),
                        ..self
                    }
                }
            }
            _ => self,
        }
    }
}

/// A prefix scale for values up to `max_abs`: (divisor, prefix) such that the
/// scaled values lie in [1, 1000) — "µ" for 3e-6.
pub fn si_scale(max_abs: f64) -> (f64, &'static str) {
    if !(max_abs.is_finite() && max_abs > 0.0) {
        return (1.0, "");
    }
    squeal_study::analysis::SI_PREFIXES
        .iter()
        .copied()
        .find(|(s, _)| max_abs >= *s)
        .unwrap_or((1e-15, "f"))
}

/// Words for a velocity column: "pad tangential" for `vx_p`.
fn velocity_words(v: &str) -> Option<&'static str> {
    let pos = if v == "v" {
        "x"
    } else {
        v.strip_prefix('v').unwrap_or(v)
    };
    squeal_study::model::coordinate_words(pos)
}

/// `" (words)"` for a velocity with known words (`" (disc tangential)"`), else
/// nothing: a lumped model's dof names are already the user's own words.
fn velocity_words_paren(v: &str) -> String {
    velocity_words(v).map_or(String::new(), |w| format!(" ({w})"))
}

/// Frequencies shown: (divisor, unit) — kHz when the shown range reaches 2 kHz.
fn freq_unit(f_hi: f64) -> (f64, &'static str) {
    if f_hi >= 2000.0 {
        (1000.0, "kHz")
    } else {
        (1.0, "Hz")
    }
}

/// Most velocities the triplet shows unless `--signals` names them (two
/// panels each: 8 panels, 2400 pixels high).
pub const MAX_SHOWN_SIGNALS: usize = 4;

/// The velocities the triplet shows, in the order shown: all analysed ones
/// when `explicit` (`--signals`) or when there are at most
/// [`MAX_SHOWN_SIGNALS`]; otherwise the squealing velocity first, then the
/// contact's tangential and normal ones (when they move), then the others
/// by RMS over the run.
pub fn shown_signals<'a>(
    run: &Run,
    an: &'a Analysis,
    ch: &Channels,
    explicit: bool,
) -> Vec<&'a ChannelSpectrum> {
    let all: Vec<&ChannelSpectrum> = an.spectra.iter().collect();
    if explicit || all.len() <= MAX_SHOWN_SIGNALS {
        return all;
    }
    let rms = |s: &str| {
        run.column(s).map_or(0.0, |x| {
            (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
        })
    };
    let mut first: Vec<&str> = Vec::new();
    if let Some(q) = &an.judgement.squeal {
        first.push(q.velocity.as_str());
    }
    first.push(ch.tangential.as_str());
    if let Some(n) = &ch.normal {
        first.push(n.as_str());
    }
    let mut order: Vec<&ChannelSpectrum> = Vec::new();
    // A contact velocity that never moves (a symmetric two-pad disc's
    // normal one) gives its place to one that does.
    for f in first.into_iter().filter(|f| rms(f) > 0.0) {
        if let Some(c) = all.iter().find(|c| c.signal == f) {
            if !order.iter().any(|o| o.signal == c.signal) {
                order.push(c);
            }
        }
    }
    let mut rest: Vec<(f64, &ChannelSpectrum)> = all
        .iter()
        .filter(|c| !order.iter().any(|o| o.signal == c.signal))
        .map(|c| (rms(&c.signal), *c))
        .collect();
    rest.sort_by(|a, b| b.0.total_cmp(&a.0));
    order.extend(rest.into_iter().map(|(_, c)| c));
    order.truncate(MAX_SHOWN_SIGNALS);
    order
}

/// Write the pictures of a run into `dir`: `triplet` (each shown velocity
/// against time, then its spectrum: the thesis's pictures, with the pad's
/// velocities too; [`shown_signals`]), `spectrogram` (of the squealing
/// velocity) and `phase` (phase portrait of the squealing coordinate), as
/// PNG and SVG. Axes carry SI prefixes (µm/s, kHz); `plot` limits and scales
/// the frequency axes; `squeal` (the run's answer in words, e.g. "squeal
/// 2.2508 kHz ± 4.0 Hz") titles the spectrogram and the squealing
/// velocity's spectrum. Returns a note when velocities were left out.
pub fn draw(
    run: &Run,
    an: &Analysis,
    ch: &Channels,
    title: &str,
    dir: &Path,
    plot: &PlotSettings,
    squeal: Option<&str>,
    explicit_signals: bool,
) -> Result<Option<String>, RunError> {
    let plot_err = |e: squeal_plot::PlotError| RunError::Io(format!("drawing failed: {e}"));
    let formats = [Format::Png, Format::Svg];
    let t = run.column("t").unwrap_or(&[]);
    let chans = shown_signals(run, an, ch, explicit_signals);
    let left_out = (chans.len() < an.spectra.len()).then(|| {
        format!(
            "triplet: {} of the {} velocities ({}); --signals draws others",
            chans.len(),
            an.spectra.len(),
            chans
                .iter()
                .map(|c| c.signal.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )
    });
    let squeal_velocity = an.judgement.squeal.as_ref().map(|q| q.velocity.as_str());
    let marked = |signal: &str, text: String| match squeal {
        Some(s) if Some(signal) == squeal_velocity => format!("{text} — {s}"),
        _ => text,
    };
    // Each velocity against time on its own axis (their sizes differ by orders
    // of magnitude), scaled to an SI prefix.
    struct Shown {
        title: String,
        y_label: String,
        y: Vec<f64>,
    }
    let time: Vec<Shown> = chans
        .iter()
        .filter_map(|c| {
            let x = run.column(&c.signal)?;
            let m = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let (k, p) = si_scale(m);
            Some(Shown {
                title: match velocity_words(&c.signal) {
                    Some(w) => format!("{title}: {w} velocity {}", c.signal),
                    None => format!("{title}: velocity {}", c.signal),
                },
                y_label: format!("velocity ({p}m/s)"),
                y: x.iter().map(|v| v / k).collect(),
            })
        })
        .collect();
    // Spectra over the chosen frequency range.
    let f_hi_all = chans
        .first()
        .and_then(|c| c.spectrum.freq.last().copied())
        .unwrap_or(1.0);
    let (f_lo, f_hi) = plot.f_range.unwrap_or((0.0, f_hi_all));
    let (fdiv, funit) = freq_unit(f_hi.min(f_hi_all));
    struct Spec {
        title: String,
        y_label: &'static str,
        f: Vec<f64>,
        db: Vec<f64>,
        peaks: Vec<(f64, String)>,
    }
    let specs: Vec<Spec> = chans
        .iter()
        .map(|c| {
            let what = if c.spectrum.scaling == Scaling::Amplitude {
                "amplitude spectrum"
            } else {
                "power spectral density"
            };
            let db = c.spectrum.to_db();
            let keep: Vec<usize> = (0..c.spectrum.freq.len())
                .filter(|&k| {
                    let f = c.spectrum.freq[k];
                    f >= f_lo && f <= f_hi && (!plot.log_f || f > 0.0)
                })
                .collect();
            // The squealing velocity's title carries the squeal instead of
            // the window's name (the other panels say it), so that it fits.
            let window = if squeal.is_some() && Some(c.signal.as_str()) == squeal_velocity {
                String::new()
            } else {
                format!("{} window", c.spectrum.window.name())
            };
            let words = match (velocity_words(&c.signal), window.is_empty()) {
                (Some(w), false) => format!(" ({w}, {window})"),
                (Some(w), true) => format!(" ({w})"),
                (None, false) => format!(" ({window})"),
                (None, true) => String::new(),
            };
            Spec {
                title: marked(&c.signal, format!("{what} of {}{words}", c.signal)),
                y_label: if c.spectrum.scaling == Scaling::Amplitude {
                    "amplitude (dB re 1 m/s)"
                } else {
                    "PSD (dB re 1 (m/s)²/Hz)"
                },
                f: keep.iter().map(|&k| c.spectrum.freq[k] / fdiv).collect(),
                db: keep.iter().map(|&k| db[k]).collect(),
                peaks: c
                    .peaks
                    .iter()
                    .filter(|p| p.freq >= f_lo && p.freq <= f_hi)
                    .take(2)
                    .map(|p| (p.freq / fdiv, si(p.freq, "Hz", 4)))
                    .collect(),
            }
        })
        .collect();
    let f_label = format!("frequency ({funit})");
    let mut panels = Vec::new();
    for s in &time {
        // One series per panel, named in its title: no legend to cover the data.
        panels.push(
            Panel::new(&s.title, "time (s)", &s.y_label).with_series(Series::new("", t, &s.y)),
        );
    }
    for s in &specs {
        let mut p = Panel::new(&s.title, &f_label, s.y_label)
            .log_x(plot.log_f)
            .with_series(Series::new("", &s.f, &s.db));
        for (f, label) in &s.peaks {
            p = p.with_peak(*f, label);
        }
        panels.push(p);
    }
    if !panels.is_empty() {
        let size = (1200, 300 * panels.len() as u32);
        squeal_plot::line_panels(dir.join("triplet"), &formats, size, &panels).map_err(plot_err)?;
    }

    // The spectrogram of the velocity that squeals (else the tangential one).
    let sg_signal = an
        .judgement
        .squeal
        .as_ref()
        .map_or(ch.tangential.to_string(), |q| q.velocity.clone());
    if let Some(x) = run.column(&sg_signal) {
        let seg = 2048.min(x.len().max(2));
        if let Ok(sg) = spectrogram(
            x,
            run.sample_rate,
            seg,
            (seg / 4).max(1),
            squeal_signal::window::Window::Hann,
        ) {
            let title = marked(
                &sg_signal,
                format!(
                    "{title}: spectrogram of {sg_signal}{}",
                    velocity_words_paren(&sg_signal)
                ),
            );
            let rows: Vec<usize> = (0..sg.n_freqs())
                .filter(|&k| {
                    let f = sg.freqs[k];
                    f >= f_lo && f <= f_hi && (!plot.log_f || f > 0.0)
                })
                .collect();
            if rows.len() >= 2 {
                let nt = sg.n_times();
                let nf = sg.n_freqs();
                let ys: Vec<f64> = rows.iter().map(|&k| sg.freqs[k] / fdiv).collect();
                let mut values = Vec::with_capacity(rows.len() * nt);
                for &k in &rows {
                    for i in 0..nt {
                        values.push(sg.psd_db[i * nf + k]);
                    }
                }
                // An 80 dB scale ending at the next 10 dB above the
                // maximum: the squeal and what stands within 80 dB of it,
                // not the integration's noise floor.
                let top = (sg.max_db() / 10.0).ceil() * 10.0;
                let spec = HeatmapSpec {
                    value_range: Some((top - 80.0, top)),
                    log_y: plot.log_f,
                    ..HeatmapSpec::new(
                        &title,
                        "time (s)",
                        &f_label,
                        "PSD (dB re 1 (m/s)²/Hz)",
                        &sg.times,
                        &ys,
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
    }
    // The phase portrait of the squealing coordinate (else the model's default).
    let (px, pv) = an
        .judgement
        .squeal
        .as_ref()
        .map_or((ch.phase.0.to_string(), ch.phase.1.to_string()), |q| {
            (q.coordinate.clone(), q.velocity.clone())
        });
    if let (Some(x), Some(v)) = (run.column(&px), run.column(&pv)) {
        // The last fifth of the run: the settled motion (a stick line, if any, is flat at v = V).
        let from = x.len() - x.len() / 5;
        let (x, v) = (&x[from..], &v[from..]);
        let t_from = t.get(from).copied().unwrap_or(0.0);
        // Positions about their mean, both axes with SI prefixes.
        let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
        let xm = x.iter().fold(0.0f64, |m, a| m.max((a - mean).abs()));
        let vm = v.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        let (kx, ppx) = si_scale(xm);
        let (kv, ppv) = si_scale(vm);
        let xs: Vec<f64> = x.iter().map(|a| (a - mean) / kx).collect();
        let vs: Vec<f64> = v.iter().map(|a| a / kv).collect();
        let title = match velocity_words(&pv) {
            Some(w) => format!("{title}: phase portrait of {w} ({px} – {pv}), t ≥ {t_from:.3} s"),
            None => format!("{title}: phase portrait of {px} – {pv}, t ≥ {t_from:.3} s"),
        };
        let x_label = format!(
            "{px} − mean ({}, mean {})",
            format_args!("{ppx}m"),
            si(mean, "m", 4)
        );
        let y_label = format!("{pv} ({ppv}m/s)");
        let labels = Labels {
            title: &title,
            x_label: &x_label,
            y_label: &y_label,
        };
        squeal_plot::phase_portrait(
            dir.join("phase"),
            &formats,
            squeal_plot::SIZE_SINGLE,
            &xs,
            &vs,
            &labels,
        )
        .map_err(plot_err)?;
    }
    Ok(left_out)
}

pub use squeal_study::audio::{default_sound_signal, hearing_note, SoundSettings};

/// Render a velocity column as a WAV file at `path`
/// ([`squeal_study::audio::render`] and [`squeal_study::audio::wav_bytes`]).
pub fn write_wav(
    x: &[f64],
    fs: f64,
    path: &Path,
    float: bool,
    sound: &SoundSettings,
) -> Result<squeal_signal::AudioClip, RunError> {
    let clip = squeal_study::audio::render(x, fs, sound).map_err(RunError::Io)?;
    let name = path
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let bytes = squeal_study::audio::wav_bytes(&clip, float, &name, sound);
    std::fs::write(path, bytes)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))?;
    Ok(clip)
}

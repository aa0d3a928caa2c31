//! What a run means: spectra of the tangential and normal velocities (as the
//! thesis's spectral analyser showed them), growth rate, and a one-word
//! verdict (`squeal_signal::judge`), and their JSON for `summary.json`.
//! The pictures and sound made from them are the CLI's.

use crate::error::InputError;
use crate::model::Channels;
use crate::run::Run;
use serde_json::{json, Map, Value};
use squeal_core::EventKind;
use squeal_signal::spectrum::Scaling;
use squeal_signal::window::Window;
use squeal_signal::{
    amplitude_spectrum, find_peaks, growth_rate_linear_part, welch, Coordinate, EventClass,
    GrowthOptions, JudgeOptions, Judgement, Peak, PeakOptions, RunEvent, RunRecord, RunVerdict,
    Spectrum, WelchOptions,
};

/// Velocities below this fraction of the sliding speed (or of 1 mm/s when
/// the run does not slide) everywhere in a run are integration noise around
/// an equilibrium, not motion to classify.
pub const STILL: f64 = 1e-8;

/// How many of the integrator's tolerances a position must move from its
/// start to count as motion ([`position_noise`]).
///
/// DOP853 holds each step's local error to `atol + rtol·|q|`; started at
/// equilibrium with no offset, the positions wander by a few of those from
/// their static deflection (the reduced FE disc of
/// `examples/fe-brake/disc-reduced`: 3–5·10⁻¹² m in 0.05 s around
/// 2.6·10⁻⁵ m with rtol 1e-8, 1.2·10⁻¹¹ m in 1 s), and a stiff contact
/// mode turns that into µm/s, above [`STILL`]: a velocity threshold cannot
/// tell noise from motion. A hundred tolerances can.
pub const STILL_TOLERANCES: f64 = 100.0;

/// The integration noise of positions starting at most `deflection` (m)
/// from 0 under `solver`: `STILL_TOLERANCES · max(rtol · deflection,
/// atol_pos)`. A run none of whose positions leaves its start by more has
/// not moved.
pub fn position_noise(deflection: f64, solver: &squeal_core::SolverOptions) -> f64 {
    let atol = solver
        .atol_pos
        .unwrap_or(squeal_core::integrate::DEFAULT_ATOL_POS);
    STILL_TOLERANCES * (solver.rtol * deflection).max(atol)
}

/// Whether some position of `run` (every state coordinate with a velocity
/// column) leaves its first sample by more than [`position_noise`] under
/// `solver`.
pub fn moved_beyond_noise(run: &Run, solver: &squeal_core::SolverOptions) -> bool {
    let positions: Vec<&[f64]> = state_pairs(run)
        .iter()
        .filter_map(|(p, _)| run.column(p))
        .collect();
    let q0 = |c: &[f64]| c.first().copied().unwrap_or(0.0);
    let deflection = positions.iter().fold(0.0f64, |m, c| m.max(q0(c).abs()));
    let bound = position_noise(deflection, solver);
    positions
        .iter()
        .any(|c| c.iter().any(|q| q.is_nan() || (q - q0(c)).abs() > bound))
}

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
    /// Spectrum of every analysed velocity (all of the state's, or `--signals`), column order.
    pub spectra: Vec<ChannelSpectrum>,
    /// Tangential velocity spectrum.
    pub tangential: Option<ChannelSpectrum>,
    /// Normal velocity spectrum.
    pub normal: Option<ChannelSpectrum>,
    /// Growth rate of each velocity over its exponential part: (signal, rate 1/s, t0, t1, R²).
    pub growth: Vec<(String, f64, f64, f64, f64)>,
    /// The run's word ([`RunVerdict`]); the same as `judgement.verdict`.
    pub verdict: RunVerdict,
    /// The verdict with its reasons, trends, squeal answer and events per cycle.
    pub judgement: Judgement,
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
    Some(ChannelSpectrum {
        signal: name.to_string(),
        spectrum,
        peaks: Vec::new(),
        segment: set.segment.min(x.len()),
    })
}

/// How far (dB) below the run's strongest spectral line the numerical noise
/// floor lies: the integrator's relative accuracy (rtol ≈ 1e-8) is 160 dB in
/// power. Nothing below it is labelled a peak.
pub const NOISE_DB: f64 = 160.0;

/// A peak must stand this many dB above its own spectrum's median level.
pub const PROMINENCE_DB: f64 = 20.0;

/// The strongest peaks (at most 5, within 60 dB of the spectrum's strongest)
/// that are lines, not noise: above the run's noise floor (`run_max_db −
/// NOISE_DB`) and [`PROMINENCE_DB`] above the spectrum's median level.
fn real_peaks(c: &ChannelSpectrum, run_max_db: f64) -> Vec<Peak> {
    let db = c.spectrum.to_db();
    let mut sorted: Vec<f64> = db.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return Vec::new();
    }
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    find_peaks(
        &c.spectrum,
        5,
        &PeakOptions {
            max_below_strongest_db: 60.0,
            ..PeakOptions::default()
        },
    )
    .into_iter()
    .filter(|p| p.level_db >= run_max_db - NOISE_DB && p.level_db >= median + PROMINENCE_DB)
    .collect()
}

/// The state's velocity columns of a run (`vx_d, vx_p, vy_d, vy_p`; the belt's `v`).
pub fn velocity_columns(run: &Run) -> Vec<String> {
    let mut v: Vec<String> = state_pairs(run).into_iter().map(|p| p.1).collect();
    // Column order (velocities as the run lists them).
    v.sort_by_key(|n| run.columns.iter().position(|c| c == n));
    v
}

/// Check a `--signals` list against a run's velocities (one line naming the bad one).
pub fn check_signals(signals: &[String], velocities: &[String]) -> Result<(), InputError> {
    for s in signals {
        if !velocities.contains(s) {
            return Err(InputError(format!(
                "--signals {s}: no such velocity (velocities: {})",
                velocities.join(", ")
            )));
        }
    }
    Ok(())
}

/// Analyse a run. Velocities are the columns whose names start with `v`.
///
/// `validity` is the scenario's displacement bound (m) for `out-of-range`.
pub fn analyse(
    run: &Run,
    ch: &Channels,
    set: &SpectrumSettings,
    validity: f64,
    signals: &[String],
) -> Analysis {
    let fs = run.sample_rate;
    let names: Vec<String> = if signals.is_empty() {
        velocity_columns(run)
    } else {
        signals.to_vec()
    };
    let mut spectra: Vec<ChannelSpectrum> = names
        .iter()
        .filter_map(|n| run.column(n).and_then(|x| spectrum_of(n, x, fs, set)))
        .collect();
    let run_max_db = spectra
        .iter()
        .flat_map(|c| c.spectrum.to_db())
        .fold(f64::NEG_INFINITY, f64::max);
    for c in &mut spectra {
        c.peaks = real_peaks(c, run_max_db);
    }
    let named = |n: Option<&str>| {
        n.and_then(|n| {
            spectra.iter().find(|c| c.signal == n).cloned().or_else(|| {
                run.column(n).and_then(|x| {
                    spectrum_of(n, x, fs, set).map(|mut c| {
                        c.peaks = real_peaks(&c, run_max_db);
                        c
                    })
                })
            })
        })
    };
    let tangential = named(Some(ch.tangential.as_str()));
    let normal = named(ch.normal.as_deref());
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
    let judgement = judge_run(run, validity);
    let verdict = judgement.verdict;
    Analysis {
        spectra,
        tangential,
        normal,
        growth,
        verdict,
        judgement,
    }
}

/// The state's coordinates of a run by name: every column `q` with a velocity
/// column `vq` (`x_p` and `vx_p`; the belt's `x` has `v`), in column order.
pub fn state_pairs(run: &Run) -> Vec<(String, String)> {
    let has = |n: &str| run.columns.iter().any(|c| c == n);
    run.columns
        .iter()
        .skip(1)
        .filter_map(|c| {
            let v = format!("v{c}");
            if has(&v) {
                Some((c.clone(), v))
            } else if c == "x" && has("v") {
                Some((c.clone(), "v".to_string()))
            } else {
                None
            }
        })
        .collect()
}

/// The run's events as the verdict sees them.
pub fn run_events(run: &Run) -> Vec<RunEvent<'_>> {
    run.events
        .iter()
        .enumerate()
        .filter_map(|(i, (t, k))| {
            EventClass::from_name(k.as_str()).map(|kind| RunEvent {
                t: *t,
                kind,
                contact: run
                    .event_contacts
                    .get(i)
                    .and_then(|&c| run.contact_names.get(c))
                    .map(String::as_str),
            })
        })
        .collect()
}

/// [`squeal_signal::judge`] on a run: every coordinate, every event, the
/// scenario's validity bound; the velocity scale is the largest sliding speed
/// of any contact.
pub fn judge_run(run: &Run, validity: f64) -> Judgement {
    let pairs = state_pairs(run);
    let coordinates: Vec<Coordinate> = pairs
        .iter()
        .filter_map(|(p, v)| {
            Some(Coordinate {
                name: p,
                velocity_name: v,
                position: run.column(p)?,
                velocity: run.column(v)?,
            })
        })
        .collect();
    // `v_rel` of a built-in, `<contact>.v_rel` of each of a lumped model's
    // contacts.
    let speed = run
        .columns
        .iter()
        .zip(&run.data)
        .filter(|(c, _)| *c == "v_rel" || c.ends_with(".v_rel"))
        .flat_map(|(_, v)| v.iter())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let record = RunRecord {
        sample_rate: run.sample_rate,
        t_start: run
            .column("t")
            .and_then(|t| t.first().copied())
            .unwrap_or(0.0),
        coordinates,
        events: run_events(run),
        velocity_scale: speed,
    };
    let opts = JudgeOptions {
        validity,
        still: STILL,
        ..JudgeOptions::default()
    };
    squeal_signal::judge(&record, &opts).unwrap_or_else(|e| Judgement {
        verdict: RunVerdict::TooShort,
        reason: e.to_string(),
        window: (0.0, 0.0),
        trends: Vec::new(),
        squeal: None,
        cycle: None,
        contacts: Vec::new(),
    })
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
        let first = self
            .spectra
            .first()
            .or(self.tangential.as_ref())
            .or(self.normal.as_ref());
        let df = first.map(|c| c.spectrum.df);
        let mut signals = Map::new();
        for c in &self.spectra {
            let v = self.with_growth(channel_json(&Some(c.clone())), &Some(c.clone()));
            signals.insert(c.signal.clone(), v);
        }
        json!({
            "window": first.map(|c| c.spectrum.window.name()),
            "segment": first.map(|c| c.segment),
            "segments": first.map(|c| c.spectrum.segments),
            "scaling": first.map(|c| if c.spectrum.scaling == Scaling::Amplitude { "amplitude" } else { "psd" }),
            "resolution_hz": df,
            "tangential": self.with_growth(channel_json(&self.tangential), &self.tangential),
            "normal": self.with_growth(channel_json(&self.normal), &self.normal),
            "signals": signals,
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

    /// The `squeal` key of summary.json: `{coordinate, frequency_hz, rms,
    /// level_db}` (position name, Hz, velocity RMS in m/s over the judged
    /// window, dB re 1 m/s), or `null` when nothing squeals.
    pub fn squeal_json(&self) -> Value {
        match &self.judgement.squeal {
            None => Value::Null,
            Some(s) => json!({
                "coordinate": s.coordinate,
                "velocity": s.velocity,
                "frequency_hz": s.frequency_hz,
                "rms": s.rms,
                "level_db": s.level_db,
            }),
        }
    }

    /// The `verdict_detail` key of summary.json: why the verdict, over which
    /// window, and (when the run squeals) its events per cycle: true sticks,
    /// slip reversals, separations.
    pub fn verdict_detail_json(&self) -> Value {
        let j = &self.judgement;
        let trends: Map<String, Value> = j
            .trends
            .iter()
            .map(|t| {
                (
                    t.name.clone(),
                    json!({
                        "rms": t.rms,
                        "rate": if t.rate_se.is_finite() { json!(t.rate) } else { Value::Null },
                        "rate_se": if t.rate_se.is_finite() { json!(t.rate_se) } else { Value::Null },
                        "change_db": if t.rate_se.is_finite() { json!(t.change_db) } else { Value::Null },
                        "below_peak_db": t.below_peak_db,
                        "moving": t.moving,
                    }),
                )
            })
            .collect();
        let cycle = j.cycle.map_or(Value::Null, |c| {
            json!({
                "cycles": c.cycles,
                "sticks": c.sticks,
                "reversals": c.reversals,
                "separations": c.separations,
                "sticks_per_cycle": c.sticks_per_cycle,
                "reversals_per_cycle": c.reversals_per_cycle,
                "separations_per_cycle": c.separations_per_cycle,
            })
        });
        // Each contact's events over the window, per cycle of the squeal
        // when there is one, and its regime.
        let cycles = j.cycle.map(|c| c.cycles).filter(|c| *c > 0.0);
        let per = |n: usize| cycles.map_or(Value::Null, |c| json!(n as f64 / c));
        let contacts: Map<String, Value> = j
            .contacts
            .iter()
            .map(|c| {
                (
                    c.name.clone().unwrap_or_else(|| "contact".into()),
                    json!({
                        "regime": c.regime(),
                        "sticks": c.sticks,
                        "reversals": c.reversals,
                        "separations": c.separations,
                        "sticks_per_cycle": per(c.sticks),
                        "reversals_per_cycle": per(c.reversals),
                        "separations_per_cycle": per(c.separations),
                        "separation_interval_cv": if c.separation_cv.is_finite() { json!(c.separation_cv) } else { Value::Null },
                    }),
                )
            })
            .collect();
        json!({
            "verdict": j.verdict.as_str(),
            "reason": j.reason,
            "window_s": [j.window.0, j.window.1],
            "per_cycle": cycle,
            "contacts": contacts,
            "trends": trends,
        })
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

/// The SI prefixes squeal writes, largest first: (scale, prefix).
pub const SI_PREFIXES: [(f64, &str); 9] = [
    (1e9, "G"),
    (1e6, "M"),
    (1e3, "k"),
    (1.0, ""),
    (1e-3, "m"),
    (1e-6, "µ"),
    (1e-9, "n"),
    (1e-12, "p"),
    (1e-15, "f"),
];

/// `x` with an SI prefix and `digits` significant digits: `si(20751.3, "Hz", 4)`
/// = "20.75 kHz", `si(3.2e-6, "m/s", 3)` = "3.20 µm/s".
pub fn si(x: f64, unit: &str, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x} {unit}");
    }
    let a = x.abs();
    let (scale, prefix) = SI_PREFIXES
        .iter()
        .copied()
        .find(|(s, _)| a >= *s * 0.999_95)
        .unwrap_or((1e-15, "f"));
    let v = x / scale;
    let int_digits = if v.abs() >= 100.0 {
        3
    } else if v.abs() >= 10.0 {
        2
    } else {
        1
    };
    let dec = digits.saturating_sub(int_digits);
    format!("{v:.dec$} {prefix}{unit}")
}

/// RMS of each velocity column over the last 20 % of the run.
pub fn tail_rms(run: &Run, velocity_columns: &[String]) -> Map<String, Value> {
    let n = run.len();
    let start = n - n / 5;
    let mut out = Map::new();
    for name in velocity_columns {
        if let Some(col) = run.column(name) {
            let tail = &col[start.min(n)..];
            let rms = if tail.is_empty() {
                0.0
            } else {
                (tail.iter().map(|x| x * x).sum::<f64>() / tail.len() as f64).sqrt()
            };
            out.insert(name.clone(), json!(rms));
        }
    }
    out
}

/// The parts of summary.json that describe the integration.
pub fn integrator_json(run: &Run) -> Value {
    let s = &run.info.stats;
    let mut events = Map::new();
    for k in EventKind::ALL {
        events.insert(k.as_str().into(), json!(s.event_count(k)));
    }
    json!({
        "integrator": {
            "method": "DOP853 with dense-output event location",
            "accepted_steps": s.accepted,
            "rejected_steps": s.rejected,
            "rhs_evaluations": s.rhs_evals,
            "rhs_per_step": if s.accepted > 0 { s.rhs_evals as f64 / s.accepted as f64 } else { 0.0 },
        },
        "events": events,
        "stick_fraction": s.stick_fraction(),
        "t_final": run.info.t_final,
    })
}

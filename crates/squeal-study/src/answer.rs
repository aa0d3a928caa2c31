//! One answer for a run (issue 28 §1–§2): the squeal frequency from the
//! settled part of the run with its uncertainty, the linear prediction
//! beside it, and the growth rate measured on the unstable mode's own modal
//! coordinate against its eigenvalue.
//!
//! **Linear prediction.** The eigenvalues of steady sliding
//! ([`AnyModel::eigenvalues`]); the prediction is the most unstable one,
//! `λ = σ + iω` (the least stable one when none grows).
//!
//! **Growth on the modal coordinate** (docs/physics.md §5e). With `y` the
//! left eigenvector of the state matrix `A` for `λ` and `z_s` the steady
//! sliding state, the modal coordinate `q(t) = yᴴ (z(t) − z_s)` obeys
//! `q̇ = λ q` exactly while the motion is linear (every other mode's right
//! eigenvector is orthogonal to `y`), so `ln |q|` is a straight line of
//! slope `σ`, whatever the other modes do. The linear phase searched is the
//! longest event-free stretch of the run after any force ramp; within it the
//! longest run of eighths on which every eighth's slope agrees with the fit
//! to [`LINEAR_TOLERANCE`] is fitted. No number is given (with the reason)
//! when there is no such stretch of two periods, or when the fitted slope
//! differs from `σ` by more than [`AGREEMENT`]: the motion was not linear.
//!
//! **Squeal frequency.** The strongest line of the squealing velocity over
//! the judged window (`squeal_signal::judge`), one Hann segment zero-padded
//! ([`LineSpectrum`]), with the uncertainty `1/(2T)` of a window of `T`
//! seconds (a strictly periodic stick cycle with one stick a period: the
//! integrator's stick times). Where steady sliding is unstable it is
//! *established* when that line is a growing eigenvalue's frequency: within
//! three uncertainties or 1 % while the run grows, within 10 % for a settled
//! cycle (limit cycle, stick–slip, lift-off). Otherwise — another mode's
//! transient or round-off still dominates, or nothing squeals yet — the
//! answer is the linear prediction, labelled so; when the run ends in its
//! linear phase, with an estimate of how much longer it must be for the
//! unstable mode to stand 20 dB above what dominates now:
//! `Δt = (ln(A_other/A_mode) + ln 10)/σ`.

use nalgebra::Complex;
use serde_json::{json, Map, Value};
use squeal_core::stability::is_growing;
use squeal_core::stability::sensitivity::Eigenvectors;
use squeal_signal::{LineSpectrum, RunVerdict, DB_PER_NEPER};

use crate::analysis::{si, state_pairs, Analysis};
use crate::model::AnyModel;
use crate::run::Run;
use crate::scenario::Scenario;
use crate::sound::Sound;

/// Eighths of a linear stretch must each have a slope within this fraction
/// of the fitted slope (or of `|σ|`, whichever is larger), plus
/// [`SLOPE_FLOOR`].
pub const LINEAR_TOLERANCE: f64 = 0.02;

/// Absolute part of the linearity test (1/s), for modes with `σ` near zero.
pub const SLOPE_FLOOR: f64 = 1e-4;

/// A measured growth rate more than this fraction away from the eigenvalue's
/// is not reported as a measurement of it.
pub const AGREEMENT: f64 = 0.05;

/// A per-velocity envelope fit more than this fraction away from the
/// eigenvalue's growth rate is not reported (it mixes modes or spans the
/// nonlinear part).
pub const SIGNAL_AGREEMENT: f64 = 0.10;

/// The linear prediction: steady sliding's most unstable eigenvalue.
#[derive(Debug, Clone, PartialEq)]
pub struct Linear {
    /// `λ = σ + iω` with `ω ≥ 0`.
    pub lambda: Complex<f64>,
    /// The state coordinate where the mode's velocity is largest (`vx_p`).
    pub velocity: Option<String>,
    /// Every eigenvalue with `ω ≥ 0`.
    pub all: Vec<Complex<f64>>,
}

impl Linear {
    /// `σ` (1/s).
    pub fn growth_rate(&self) -> f64 {
        self.lambda.re
    }
    /// `ω/2π` (Hz).
    pub fn freq_hz(&self) -> f64 {
        self.lambda.im / std::f64::consts::TAU
    }
    /// Whether the prediction grows: `σ > 0` beyond the eigen-solver's
    /// round-off ([`is_growing`]; an undamped mode's `σ = 1e-11` is neutral).
    pub fn grows(&self) -> bool {
        is_growing(self.lambda.re, self.lambda.im)
    }
    /// The frequencies (Hz) of every growing eigenvalue (each conjugate
    /// pair once, round-off excluded), most unstable first.
    pub fn growing_hz(&self) -> Vec<f64> {
        let mut g: Vec<Complex<f64>> = self
            .all
            .iter()
            .copied()
            .filter(|e| is_growing(e.re, e.im))
            .collect();
        g.sort_by(|a, b| b.re.total_cmp(&a.re));
        g.iter().map(|e| e.im / std::f64::consts::TAU).collect()
    }
}

/// The growth rate measured on the modal coordinate.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalGrowth {
    /// The fitted rate (1/s), `None` with a reason when it is not a measurement of `σ`.
    pub rate: Option<f64>,
    /// The fitted stretch (s), when one was fitted.
    pub window: Option<(f64, f64)>,
    /// `(rate − σ)/|σ|`, when a rate is given.
    pub relative_difference: Option<f64>,
    /// Why no rate is given.
    pub reason: Option<String>,
}

impl ModalGrowth {
    /// Whether the measured linear phase lasts to the run's last sample
    /// (within two samples).
    pub fn reaches_end(&self, run: &Run) -> bool {
        let end = run.column("t").and_then(|t| t.last().copied());
        match (self.rate, self.window, end) {
            (Some(_), Some((_, t1)), Some(end)) => end - t1 <= 2.0 / run.sample_rate,
            _ => false,
        }
    }
}

/// Where the squeal frequency comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Measured on the run.
    Run,
    /// The linear prediction (the run ended before the squeal was established).
    Linear,
}

impl Source {
    /// `run` or `linear`.
    pub fn as_str(self) -> &'static str {
        match self {
            Source::Run => "run",
            Source::Linear => "linear",
        }
    }
}

/// The squeal answer: one frequency, everywhere.
#[derive(Debug, Clone, PartialEq)]
pub struct SquealAnswer {
    /// Position name of the coordinate that carries it.
    pub coordinate: String,
    /// Its velocity column.
    pub velocity: String,
    /// The squeal frequency (Hz).
    pub frequency_hz: f64,
    /// Its uncertainty (Hz): half the judged window's resolution; `None` for a linear prediction.
    pub uncertainty_hz: Option<f64>,
    /// Whether the run shows the squeal itself (settled, or its growing mode dominating).
    pub established: bool,
    /// Where `frequency_hz` comes from.
    pub source: Source,
    /// Velocity RMS over the judged window (m/s), when measured.
    pub rms: Option<f64>,
    /// `20·log10(rms / 1 m/s)`, when measured.
    pub level_db: Option<f64>,
    /// The linear prediction's frequency (Hz), when there is one.
    pub linear_hz: Option<f64>,
    /// The run's strongest line in the judged window when it is not the squeal (Hz).
    pub dominant_hz: Option<f64>,
    /// About how much longer (s) the run must be for the squeal to be established.
    pub lengthen_s: Option<f64>,
    /// One line saying what the number is.
    pub note: String,
}

/// The squeal in a few words, for the pictures' titles: "squeal 2.2508 kHz
/// ± 4.0 Hz" (measured), or "squeal not established: linear prediction
/// 2.25076 kHz" (`source` = `linear`).
pub fn squeal_words(frequency_hz: f64, uncertainty_hz: Option<f64>, source: &str) -> String {
    if source == Source::Linear.as_str() {
        return format!(
            "squeal not established: linear prediction {}",
            si(frequency_hz, "Hz", 6)
        );
    }
    match uncertainty_hz {
        Some(u) => format!("squeal {} ± {}", si(frequency_hz, "Hz", 5), si(u, "Hz", 2)),
        None => format!("squeal {}", si(frequency_hz, "Hz", 5)),
    }
}

/// [`squeal_words`], or for a forced model's line (`forced`: the forcing
/// frequency it is a multiple of) "forced response 15.000 Hz ± 500 mHz".
pub fn line_words(
    frequency_hz: f64,
    uncertainty_hz: Option<f64>,
    source: &str,
    forced: Option<f64>,
) -> String {
    match (forced, uncertainty_hz) {
        (Some(_), Some(u)) => format!(
            "forced response {} ± {}",
            si(frequency_hz, "Hz", 5),
            si(u, "Hz", 2)
        ),
        (Some(_), None) => format!("forced response {}", si(frequency_hz, "Hz", 5)),
        (None, _) => squeal_words(frequency_hz, uncertainty_hz, source),
    }
}

impl SquealAnswer {
    /// [`squeal_words`] of this answer.
    pub fn words(&self) -> String {
        squeal_words(self.frequency_hz, self.uncertainty_hz, self.source.as_str())
    }
}

/// The answer of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Answer {
    /// The linear prediction, when steady sliding has one.
    pub linear: Option<Linear>,
    /// Why there is no linear prediction.
    pub linear_reason: Option<String>,
    /// The growth measured on the modal coordinate (when there is a linear prediction).
    pub growth: Option<ModalGrowth>,
    /// The squeal, `None` when nothing squeals and nothing is predicted to.
    pub squeal: Option<SquealAnswer>,
    /// A corrected verdict with its reason: `grows` for a run whose
    /// unstable mode is measured growing at its eigenvalue's rate to the
    /// end (its linear phase), which the signal's level alone cannot
    /// resolve over the judged window.
    pub verdict: Option<(RunVerdict, String)>,
    /// The run's sound over the judged window, from the scenario's
    /// radiating surfaces ([`crate::radiation`]); the reason when there is none.
    pub sound: Result<Sound, String>,
    /// The forcing frequency (Hz) whose multiple the measured line is,
    /// within its uncertainty, for a model with harmonic forces: the line is
    /// then (at least in part) the forced response, not self-excited squeal.
    pub forced_hz: Option<f64>,
}

/// The most unstable eigenvalue with `ω ≥ 0` (largest real part; among
/// equals, the lowest frequency).
fn leading(ev: &[Complex<f64>]) -> Option<Complex<f64>> {
    ev.iter()
        .copied()
        .filter(|e| e.im >= 0.0)
        .max_by(|a, b| a.re.total_cmp(&b.re).then(b.im.total_cmp(&a.im)))
}

/// The forcing frequency of `model` (Hz) of which `hz` is a whole multiple
/// (1 to 10), within `uncertainty` (or 10⁻³ of `hz`), if any.
fn forcing_match(model: &AnyModel, hz: f64, uncertainty: Option<f64>) -> Option<f64> {
    let AnyModel::Lumped(l) = model else {
        return None;
    };
    let tol = uncertainty.unwrap_or(0.0).max(1e-3 * hz);
    l.forcing_hz().into_iter().find(|&f| {
        let k = (hz / f).round();
        (1.0..=10.0).contains(&k) && (hz - k * f).abs() <= tol
    })
}

/// The time the last force ramp of a lumped model ends (0 for none).
fn ramps_end(model: &AnyModel) -> f64 {
    match model {
        AnyModel::Lumped(l) => l.forces.iter().map(|f| f.ramp).fold(0.0, f64::max),
        _ => 0.0,
    }
}

impl Answer {
    /// The answer of `run` of `sc`, analysed as `an`.
    pub fn of(sc: &Scenario, run: &Run, an: &Analysis) -> Answer {
        let mut answer = Answer {
            linear: None,
            linear_reason: None,
            growth: None,
            squeal: None,
            verdict: None,
            sound: Sound::of(&sc.radiation, run, an.judgement.window),
            forced_hz: None,
        };
        let names = sc.model.state_names();
        // One steady-sliding solve and one state matrix: its eigenvalues
        // and the leading one's eigenvectors.
        let eig = sc.model.state_matrix().map(|r| {
            r.and_then(|(z, a)| {
                let ev = squeal_core::stability::modal::eigenvalues(&a)?;
                Ok((z, a, ev))
            })
        });
        let vectors = match eig {
            None => {
                answer.linear_reason = Some(
                    "the model is analysed by projection: no full state matrix to project the run with".into(),
                );
                None
            }
            Some(Err(e)) => {
                answer.linear_reason = Some(format!("no linear analysis: {e}"));
                None
            }
            Some(Ok((z, a, ev))) => leading(&ev).map(|lambda| {
                let vectors = Eigenvectors::of(&a, lambda);
                let n = names.len() / 2;
                let velocity = vectors.as_ref().and_then(|v| {
                    (n..2 * n)
                        .max_by(|&i, &j| v.right[i].norm().total_cmp(&v.right[j].norm()))
                        .map(|i| names[i].clone())
                });
                answer.linear = Some(Linear {
                    lambda,
                    velocity,
                    all: ev.iter().copied().filter(|e| e.im >= 0.0).collect(),
                });
                (z, vectors)
            }),
        };
        if let (Some(lin), Some((z, vectors))) = (&answer.linear, &vectors) {
            answer.growth = Some(match vectors {
                Some(v) => modal_growth(sc, run, &names, z, v, lin),
                None => ModalGrowth {
                    rate: None,
                    window: None,
                    relative_difference: None,
                    reason: Some(
                        "the eigenvectors of the leading eigenvalue could not be computed".into(),
                    ),
                },
            });
        }
        let linear_to_end = answer.growth.as_ref().is_some_and(|g| g.reaches_end(run));
        answer.verdict = still_linear(
            an,
            answer.linear.as_ref(),
            answer.growth.as_ref(),
            linear_to_end,
        );
        // Steady sliding is stable and no position left its start by more
        // than the integration's noise: whatever steady line the judge saw
        // (a stiff contact mode turns the noise into µm/s) is not a squeal.
        let noise = answer.linear.as_ref().is_some_and(|l| !l.grows())
            && an.judgement.verdict != RunVerdict::Decays
            && !crate::analysis::moved_beyond_noise(run, &sc.solver);
        if noise {
            answer.verdict = Some((
                RunVerdict::Decays,
                format!(
                    "nothing moves: steady sliding is stable and no position leaves its start by more than {} tolerances of the integrator (integration noise; judged {})",
                    crate::analysis::STILL_TOLERANCES,
                    an.judgement.verdict
                ),
            ));
        }
        let verdict = answer.verdict(an);
        answer.squeal = squeal_answer(run, an, verdict, answer.linear.as_ref(), linear_to_end)
            .filter(|_| !noise);
        // A steady run whose steady line is not the unstable mode's: the
        // run ended before the squeal showed.
        if let Some(s) = answer
            .squeal
            .as_ref()
            .filter(|s| s.source == Source::Linear)
        {
            if matches!(verdict, RunVerdict::LimitCycle | RunVerdict::Neutral) {
                answer.verdict = Some((
                    RunVerdict::TooShort,
                    format!(
                        "the run ends before its unstable mode ({}) shows: the steady line of the judged window{} is not a growing mode's (judged {verdict})",
                        si(s.frequency_hz, "Hz", 5),
                        s.dominant_hz
                            .map_or(String::new(), |d| format!(" ({})", si(d, "Hz", 4)))
                    ),
                ));
            }
        }
        answer.forced_hz = answer
            .squeal
            .as_ref()
            .filter(|s| s.source == Source::Run)
            .and_then(|s| forcing_match(&sc.model, s.frequency_hz, s.uncertainty_hz));
        answer
    }

    /// The line in a few words for the pictures' titles ([`line_words`]).
    pub fn words(&self) -> Option<String> {
        self.squeal.as_ref().map(|s| {
            line_words(
                s.frequency_hz,
                s.uncertainty_hz,
                s.source.as_str(),
                self.forced_hz,
            )
        })
    }

    /// The run's verdict: the judge's, or `grows` where the answer knows better.
    pub fn verdict(&self, an: &Analysis) -> RunVerdict {
        self.verdict.as_ref().map_or(an.judgement.verdict, |v| v.0)
    }

    /// The `verdict_detail` key of summary.json: the judge's, with the
    /// verdict and reason the answer corrected (and `judged` keeping the
    /// judge's own word).
    pub fn verdict_detail_json(&self, an: &Analysis) -> Value {
        let mut v = an.verdict_detail_json();
        if let Some((word, reason)) = &self.verdict {
            v["judged"] = v["verdict"].clone();
            v["verdict"] = json!(word.as_str());
            v["reason"] = json!(reason);
        }
        v
    }

    /// The `squeal` key of summary.json: the judge's keys (`coordinate`,
    /// `velocity`, `frequency_hz`, `rms`, `level_db`) and `established`,
    /// `uncertainty_hz`, `source`, `linear_hz`, `difference_hz`,
    /// `dominant_hz`, `lengthen_s`, `note`; `null` when nothing squeals.
    pub fn squeal_json(&self) -> Value {
        let Some(s) = &self.squeal else {
            return Value::Null;
        };
        json!({
            "coordinate": s.coordinate,
            "velocity": s.velocity,
            "frequency_hz": s.frequency_hz,
            "uncertainty_hz": s.uncertainty_hz,
            "established": s.established,
            "source": s.source.as_str(),
            "rms": s.rms,
            "level_db": s.level_db,
            "linear_hz": s.linear_hz,
            "difference_hz": s.linear_hz.filter(|_| s.source == Source::Run).map(|l| s.frequency_hz - l),
            "dominant_hz": s.dominant_hz,
            "lengthen_s": s.lengthen_s,
            "note": s.note,
            "forced_hz": self.forced_hz,
        })
    }

    /// The `linear` key of summary.json: the linear prediction and the
    /// growth measured on its modal coordinate; `null` with `reason` when
    /// the model has none.
    pub fn linear_json(&self) -> Value {
        let Some(l) = &self.linear else {
            return json!({ "eigenvalue": null, "reason": self.linear_reason });
        };
        let g = self.growth.as_ref();
        let growing_hz = l.growing_hz();
        json!({
            "eigenvalue": { "re": l.lambda.re, "im": l.lambda.im },
            "growth_rate": l.growth_rate(),
            "freq_hz": l.freq_hz(),
            "growing_modes": growing_hz.len(),
            "growing_hz": growing_hz,
            "velocity": l.velocity,
            "measured_growth": g.map_or(Value::Null, |g| json!({
                "rate": g.rate,
                "t_start": g.window.map(|w| w.0),
                "t_end": g.window.map(|w| w.1),
                "relative_difference": g.relative_difference,
                "method": "ln|yᴴ(z − z_s)| on the mode's modal coordinate (left eigenvector y), linear phase only",
                "reason": g.reason,
            })),
        })
    }

    /// The `growth_rate` key of summary.json: per velocity, the envelope
    /// fit (`rate`, `t_start`, `t_end`, `r_squared`) and `reason`. A fit is
    /// a measurement of a mode when some eigenvalue of steady sliding has
    /// its rate (within [`SIGNAL_AGREEMENT`]) at the velocity's strongest
    /// spectral line (within 2 % or two bins); otherwise `rate` is `null`
    /// and `reason` says why (the envelope mixes modes or spans the
    /// nonlinear part).
    pub fn growth_rate_json(&self, an: &Analysis) -> Value {
        let mut m = Map::new();
        for (name, rate, t0, t1, r2) in &an.growth {
            let reason = self.linear.as_ref().and_then(|l| {
                let spectrum = an.spectra.iter().find(|c| &c.signal == name);
                let line = spectrum.and_then(|c| c.peaks.first().map(|p| (p.freq, c.spectrum.df)));
                let at_line = |e: &Complex<f64>| {
                    let f = e.im / std::f64::consts::TAU;
                    line.is_none_or(|(fl, df)| (fl - f).abs() <= (0.02 * f).max(2.0 * df))
                };
                let agrees = |e: &Complex<f64>| {
                    (rate - e.re).abs() <= SIGNAL_AGREEMENT * e.re.abs().max(SLOPE_FLOOR)
                };
                let ok = l.all.iter().any(|e| at_line(e) && agrees(e));
                (!ok).then(|| {
                    let line_words = line.map_or(String::new(), |(f, _)| {
                        format!(" at its strongest line ({})", si(f, "Hz", 4))
                    });
                    format!(
                        "the envelope of {name} fits {rate:+.4e} 1/s over {t0:.4}–{t1:.4} s (R² {r2:.3}), but no eigenvalue of steady sliding{line_words} changes at that rate (the leading mode: {:+.4e} 1/s at {}): the envelope mixes modes or spans the nonlinear part; see linear.measured_growth",
                        l.growth_rate(),
                        si(l.freq_hz(), "Hz", 5)
                    )
                })
            });
            m.insert(
                name.clone(),
                json!({
                    "rate": if reason.is_some() { Value::Null } else { json!(rate) },
                    "t_start": t0, "t_end": t1, "r_squared": r2,
                    "reason": reason,
                }),
            );
        }
        Value::Object(m)
    }

    /// The squeal answer in words, for the terminal.
    pub fn squeal_line(
        &self,
        an: &Analysis,
        coordinate_words: impl Fn(&str) -> Option<&'static str>,
    ) -> String {
        let j = &an.judgement;
        let Some(s) = &self.squeal else {
            return format!(
                "does not squeal: verdict {} ({})",
                self.verdict(an),
                self.verdict
                    .as_ref()
                    .map_or(j.reason.as_str(), |v| v.1.as_str())
            );
        };
        let what = coordinate_words(&s.coordinate)
            .map_or(s.coordinate.clone(), |w| format!("{w}, {}", s.coordinate));
        let verdict = self.verdict(an);
        if s.source == Source::Linear {
            return format!("{} ({what}); verdict {verdict}", s.note);
        }
        if let Some(f) = self.forced_hz {
            return format!(
                "responds at {} ± {} ({what}), a multiple of the forcing frequency {} (a forced response, not self-excited squeal; `squeal hb` computes it): {} RMS = {:.1} dB re 1 m/s; verdict {verdict}",
                si(s.frequency_hz, "Hz", 5),
                si(s.uncertainty_hz.unwrap_or(0.0), "Hz", 2),
                si(f, "Hz", 6),
                si(s.rms.unwrap_or(0.0), "m/s", 3),
                s.level_db.unwrap_or(f64::NAN),
            );
        }
        let verb = if verdict == RunVerdict::Grows {
            "squeals (still growing)"
        } else {
            "squeals"
        };
        let linear = s.linear_hz.map_or(String::new(), |l| {
            format!(
                "; linear prediction {} (difference {:+.3} Hz)",
                si(l, "Hz", 6),
                s.frequency_hz - l
            )
        });
        format!(
            "{verb} at {} ± {} ({what}): {} RMS = {:.1} dB re 1 m/s; verdict {verdict}{linear}",
            si(s.frequency_hz, "Hz", 5),
            si(s.uncertainty_hz.unwrap_or(0.0), "Hz", 2),
            si(s.rms.unwrap_or(0.0), "m/s", 3),
            s.level_db.unwrap_or(f64::NAN),
        )
    }

    /// The growth in words, for the terminal.
    pub fn growth_line(&self) -> Option<String> {
        let l = self.linear.as_ref()?;
        let g = self.growth.as_ref()?;
        let mode = format!("the {} mode", si(l.freq_hz(), "Hz", 5));
        Some(match (g.rate, g.window) {
            (Some(r), Some((t0, t1))) => format!(
                "growth: {r:+.6e} 1/s measured on {mode}'s own coordinate over {t0:.4}–{t1:.4} s; its eigenvalue gives {:+.6e} 1/s (relative difference {:+.1e})",
                l.growth_rate(),
                g.relative_difference.unwrap_or(0.0)
            ),
            _ => format!(
                "growth of {mode} (eigenvalue {:+.4e} 1/s) not measured: {}",
                l.growth_rate(),
                g.reason.as_deref().unwrap_or("")
            ),
        })
    }
}

/// Least-squares slope of `y` against `t` (both the same length ≥ 2).
fn slope(t: &[f64], y: &[f64]) -> f64 {
    let n = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in t.iter().zip(y) {
        sxy += (a - tm) * (b - ym);
        sxx += (a - tm) * (a - tm);
    }
    sxy / sxx
}

/// The growth measured on the modal coordinate of `v` (see the module docs).
fn modal_growth(
    sc: &Scenario,
    run: &Run,
    names: &[String],
    z_s: &[f64],
    v: &Eigenvectors,
    lin: &Linear,
) -> ModalGrowth {
    let none = |reason: String, window: Option<(f64, f64)>| ModalGrowth {
        rate: None,
        window,
        relative_difference: None,
        reason: Some(reason),
    };
    let cols: Option<Vec<&[f64]>> = names.iter().map(|n| run.column(n)).collect();
    let (Some(cols), Some(t)) = (cols, run.column("t")) else {
        return none("the run does not hold every state column".into(), None);
    };
    if z_s.len() != cols.len() || v.left.len() != cols.len() {
        return none(
            "the run's state and the linear analysis differ in size".into(),
            None,
        );
    }
    // The longest event-free stretch after the ramps.
    let start = ramps_end(&sc.model);
    let t_end = t.last().copied().unwrap_or(0.0);
    let mut cuts: Vec<f64> = vec![start];
    cuts.extend(run.events.iter().map(|e| e.0).filter(|&te| te > start));
    cuts.push(t_end);
    let (a, b) = cuts
        .windows(2)
        .map(|w| (w[0], w[1]))
        .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
        .unwrap_or((start, t_end));
    let period = if lin.lambda.im > 0.0 {
        std::f64::consts::TAU / lin.lambda.im
    } else {
        0.0
    };
    let i0 = t.partition_point(|&x| x <= a);
    let i1 = t.partition_point(|&x| x < b);
    if i1 <= i0 + 64 || b - a < 2.0 * period {
        return none(
            format!(
                "the run has no event-free stretch of two periods ({:.3e} s) and 64 samples after {start:.4} s (longest: {a:.4}–{b:.4} s); it is nonlinear from the start",
                2.0 * period
            ),
            None,
        );
    }
    // q = yᴴ (z − z_s), ln |q| sample by sample.
    let mut lnq = Vec::with_capacity(i1 - i0);
    for k in i0..i1 {
        let mut q = Complex::new(0.0, 0.0);
        for (j, c) in cols.iter().enumerate() {
            q += v.left[j].conj() * (c[k] - z_s[j]);
        }
        lnq.push(q.norm().max(1e-300).ln());
    }
    let ts = &t[i0..i1];
    let sigma = lin.growth_rate();
    let m = lnq.len();
    // The longest run of eighths that is a straight line, earliest first.
    let eighth = |k: usize| k * m / 8;
    let mut fit = None;
    'len: for len in (2..=8).rev() {
        for s in 0..=(8 - len) {
            let (lo, hi) = (eighth(s), eighth(s + len));
            if (ts[hi - 1] - ts[lo]) < 2.0 * period || hi - lo < 64 {
                continue;
            }
            let r = slope(&ts[lo..hi], &lnq[lo..hi]);
            let tol = LINEAR_TOLERANCE * r.abs().max(sigma.abs()) + SLOPE_FLOOR;
            let straight = (s..s + len).all(|e| {
                let (p, q) = (eighth(e), eighth(e + 1));
                q - p >= 3 && (slope(&ts[p..q], &lnq[p..q]) - r).abs() <= tol
            });
            if straight {
                fit = Some((r, (ts[lo], ts[hi - 1])));
                break 'len;
            }
        }
    }
    let Some((rate, window)) = fit else {
        let q_max = lnq.iter().copied().fold(f64::NEG_INFINITY, f64::max).exp();
        let z_max = (i0..i1)
            .flat_map(|k| cols.iter().zip(z_s).map(move |(c, zs)| (c[k] - zs).abs()))
            .fold(0.0f64, f64::max);
        return none(
            format!(
                "ln|q| of the mode's modal coordinate is not a straight line over any quarter of the event-free stretch {a:.4}–{b:.4} s (|q| ≤ {q_max:.2e} while the state moves by up to {z_max:.2e} from steady sliding): the motion is not linear there, or the mode is too weakly excited to stand above the integration error"
            ),
            None,
        );
    };
    let diff = (rate - sigma) / sigma.abs().max(SLOPE_FLOOR);
    if diff.abs() > AGREEMENT {
        return none(
            format!(
                "the modal coordinate changes at {rate:+.4e} 1/s over {:.4}–{:.4} s, {:+.1} % from the eigenvalue's {sigma:+.4e} 1/s: not the linear phase (nonlinear friction or contact at this amplitude)",
                window.0,
                window.1,
                100.0 * diff
            ),
            Some(window),
        );
    }
    ModalGrowth {
        rate: Some(rate),
        window: Some(window),
        relative_difference: Some(diff),
        reason: None,
    }
}

/// `grows` when the judge called a run steady, neutral, decaying or too
/// short while its unstable mode's own coordinate grows at the eigenvalue's
/// rate to the end of the run.
fn still_linear(
    an: &Analysis,
    lin: Option<&Linear>,
    growth: Option<&ModalGrowth>,
    to_end: bool,
) -> Option<(RunVerdict, String)> {
    let l = lin.filter(|l| l.grows())?;
    let g = growth?;
    let (rate, (t0, t1)) = (g.rate?, g.window?);
    let j = &an.judgement;
    let contradicted = matches!(
        j.verdict,
        RunVerdict::LimitCycle | RunVerdict::Neutral | RunVerdict::TooShort | RunVerdict::Decays
    );
    (to_end && contradicted).then(|| {
        let span = j.window.1 - j.window.0;
        (
            RunVerdict::Grows,
            format!(
                "still growing, in its linear phase: the {} mode's own coordinate grows at {rate:+.4e} 1/s over {t0:.4}–{t1:.4} s, as its eigenvalue ({:+.4e} 1/s) says; {:+.3} dB over the judged {span:.4} s, which the levels alone did not resolve (judged {})",
                si(l.freq_hz(), "Hz", 5),
                l.growth_rate(),
                rate * span * DB_PER_NEPER,
                j.verdict
            ),
        )
    })
}

/// The squeal answer (see the module docs).
fn squeal_answer(
    run: &Run,
    an: &Analysis,
    verdict: RunVerdict,
    lin: Option<&Linear>,
    linear_to_end: bool,
) -> Option<SquealAnswer> {
    let j = &an.judgement;
    // σ says how much longer to run only while the run is still linear at
    // its end: no event in the judged window, the modal coordinate measured
    // to the last sample.
    let quiet = !run
        .events
        .iter()
        .any(|e| e.0 >= j.window.0 && e.0 <= j.window.1);
    let end = if quiet && linear_to_end {
        RunEnd::Linear
    } else if quiet {
        RunEnd::Unmeasured
    } else {
        RunEnd::Nonlinear
    };
    let fs = run.sample_rate;
    let n = run.len();
    let i0 = n
        .saturating_sub(((j.window.1 - j.window.0) * fs).round() as usize + 1)
        .min(n);
    let spectrum_of = |velocity: &str| {
        run.column(velocity)
            .and_then(|x| LineSpectrum::of(&x[i0..], fs).ok())
    };
    let settled = matches!(
        verdict,
        RunVerdict::LimitCycle | RunVerdict::StickSlip | RunVerdict::LiftOff
    );
    let unstable = lin.filter(|l| l.grows());
    if let Some(s) = &j.squeal {
        // The strongest line; for a strictly periodic stick–slip cycle
        // with one stick a period (the stick frequency within the line's
        // uncertainty), the integrator's stick times give it far more
        // precisely, uncertain by the spread of the periods over their
        // number.
        let line = spectrum_of(&s.velocity)
            .and_then(|sp| sp.strongest(None))
            .map_or((s.frequency_hz, None), |l| (l.freq, Some(l.uncertainty)));
        let sticks = stick_frequency(run, j.window).filter(|&(f_stick, _)| {
            verdict == RunVerdict::StickSlip
                && line.1.is_some_and(|u| (f_stick - line.0).abs() <= u)
        });
        let (f, u) = sticks.map_or(line, |(f_stick, u_stick)| (f_stick, Some(u_stick)));
        // A settled cycle's frequency may drift from its mode's linear one
        // (10 %); a growing run's line is the mode's (three uncertainties
        // or 1 %).
        let tol = |g: f64| {
            if settled {
                0.1 * g
            } else {
                (3.0 * u.unwrap_or(0.0)).max(0.01 * g)
            }
        };
        let matched = unstable.and_then(|l| {
            l.growing_hz()
                .into_iter()
                .find(|&g| (f - g).abs() <= tol(g))
        });
        let established = unstable.is_none() || matched.is_some();
        if established {
            let linear_hz = matched.or(unstable.map(|l| l.freq_hz()));
            return Some(SquealAnswer {
                coordinate: s.coordinate.clone(),
                velocity: s.velocity.clone(),
                frequency_hz: f,
                uncertainty_hz: u,
                established: true,
                source: Source::Run,
                rms: Some(s.rms),
                level_db: Some(s.level_db),
                linear_hz,
                dominant_hz: None,
                lengthen_s: None,
                note: format!(
                    "measured over the judged window {:.4}–{:.4} s ({verdict}); ± half its resolution",
                    j.window.0, j.window.1
                ),
            });
        }
        // The line is not a growing mode's: another mode's transient (or
        // the integration's noise) still dominates the window.
        return unstable.map(|l| not_yet(run, an, l, spectrum_of, end));
    }
    // Nothing squeals in the run although steady sliding is unstable: the
    // squeal is not there yet.
    let l = unstable?;
    if !matches!(
        verdict,
        RunVerdict::TooShort | RunVerdict::Decays | RunVerdict::Neutral
    ) {
        return None;
    }
    Some(not_yet(run, an, l, spectrum_of, end))
}

/// How a run that has not shown its squeal ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RunEnd {
    /// In its linear phase, the mode's growth measured to the end: σ says
    /// how much longer to run.
    Linear,
    /// No contact event at its end, but the mode's coordinate not
    /// measurable (unexcited, at round-off).
    Unmeasured,
    /// Contact events at its end: nonlinear and not settled.
    Nonlinear,
}

/// The frequency of a strictly periodic stick cycle over `window` (the
/// judge's rule, [`squeal_signal::gaps`]: gaps between true sticks with a
/// coefficient of variation below 2 %) and its standard error
/// `f²·sd(T)/√n`.
fn stick_frequency(run: &Run, window: (f64, f64)) -> Option<(f64, f64)> {
    let times: Vec<f64> = run
        .events
        .iter()
        .filter(|e| {
            e.1 == squeal_core::EventKind::Stick && e.0 >= window.0 && e.0 <= window.1 + 1e-12
        })
        .map(|e| e.0)
        .collect();
    let (mean, cv) = squeal_signal::gaps(&times).filter(|g| g.1 < 0.02)?;
    let n = (times.len() - 1) as f64;
    Some((1.0 / mean, cv / mean / n.sqrt()))
}

/// The linear prediction, labelled so, with how much longer to run when
/// the run is still linear at its end (otherwise that cannot be told from
/// `σ`).
fn not_yet(
    run: &Run,
    an: &Analysis,
    l: &Linear,
    spectrum_of: impl Fn(&str) -> Option<LineSpectrum>,
    end: RunEnd,
) -> SquealAnswer {
    let pairs = state_pairs(run);
    let velocity = l.velocity.clone().unwrap_or_default();
    let coordinate = pairs
        .iter()
        .find(|p| p.1 == velocity)
        .map_or(velocity.clone(), |p| p.0.clone());
    let f_lin = l.freq_hz();
    let sigma = l.growth_rate();
    let sp = spectrum_of(&velocity);
    let dominant = sp
        .as_ref()
        .and_then(|s| s.strongest(None))
        .map(|x| (x.freq, x.amplitude));
    let mode = sp
        .as_ref()
        .map_or(0.0, |s| s.level_near(f_lin, 2.0 * s.uncertainty()));
    let nepers = match dominant {
        Some((_, a)) if mode > 0.0 && a > mode => (a / mode).ln() + 10f64.ln(),
        _ => 10f64.ln(),
    };
    let lengthen = nepers / sigma;
    // What the run shows instead: the strongest line of its loudest
    // velocity over the judged window.
    let loudest = an
        .judgement
        .trends
        .iter()
        .filter(|t| t.moving)
        .max_by(|a, b| a.rms.total_cmp(&b.rms))
        .and_then(|t| pairs.iter().find(|p| p.0 == t.name).map(|p| p.1.clone()));
    let dominant_hz = loudest
        .and_then(|v| spectrum_of(&v))
        .and_then(|s| s.strongest(None))
        .map(|x| x.freq)
        .or(dominant.map(|d| d.0));
    let duration = run
        .column("t")
        .and_then(|t| t.last().copied())
        .unwrap_or(0.0);
    let advice = match end {
        RunEnd::Linear => format!(
            "lengthen the run by about {} ({:.1} dB more growth, estimated from σ and the levels at the end of the run) to hear it",
            si(lengthen, "s", 3),
            nepers * DB_PER_NEPER
        ),
        RunEnd::Unmeasured => format!(
            "the mode is too weakly excited to measure here (unexcited, or at the integration's round-off): give it a start (an offset on {coordinate}) or lengthen the run; how much longer cannot be told from so weak a start"
        ),
        RunEnd::Nonlinear => "the run is not in its linear phase at its end and has not settled: lengthen it until its last quarter is steady (how much cannot be told from σ once the motion is nonlinear)".to_string(),
    };
    let note = format!(
        "the squeal is not established by the end of the run ({duration:.4} s): the linear prediction is {} (σ = {sigma:+.4e} 1/s, e-fold time {:.3} s){}; {advice}",
        si(f_lin, "Hz", 6),
        1.0 / sigma,
        dominant_hz.map_or(String::new(), |d| format!(
            ", while the run's strongest line at its end is {}",
            si(d, "Hz", 4)
        )),
    );
    SquealAnswer {
        coordinate,
        velocity,
        frequency_hz: f_lin,
        uncertainty_hz: None,
        established: false,
        source: Source::Linear,
        rms: None,
        level_db: None,
        linear_hz: Some(f_lin),
        dominant_hz,
        lengthen_s: (end == RunEnd::Linear).then_some(lengthen),
        note,
    }
}

/// The document `summary.json` holds for a run of `sc` analysed as `an`:
/// the integration (`integrator`, `events`, `stick_fraction`, `t_final`),
/// `scenario`, `columns`, the tail `rms` of every velocity, `spectrum`,
/// `growth_rate`, `verdict`, `verdict_detail`, `squeal` and `linear` (the
/// [`Answer`] of the run), and `radiation` (its
/// sound over the judged window, [`crate::sound`]). The CLI adds `audio` and
/// `timing`.
pub fn summary_json(sc: &Scenario, run: &Run, an: &Analysis) -> Value {
    summary_json_with(sc, run, an, &Answer::of(sc, run, an))
}

/// [`summary_json`] with the run's answer already computed.
pub fn summary_json_with(sc: &Scenario, run: &Run, an: &Analysis, answer: &Answer) -> Value {
    let velocity_names: Vec<String> = {
        let names = sc.model.state_names();
        names[names.len() / 2..].to_vec()
    };
    let mut summary = crate::analysis::integrator_json(run);
    summary["scenario"] = sc.to_json();
    summary["columns"] = json!(run.columns);
    summary["rms"] = json!(crate::analysis::tail_rms(run, &velocity_names));
    summary["spectrum"] = an.spectrum_json();
    summary["growth_rate"] = answer.growth_rate_json(an);
    summary["verdict"] = json!(answer.verdict(an).as_str());
    summary["verdict_detail"] = answer.verdict_detail_json(an);
    summary["squeal"] = answer.squeal_json();
    summary["linear"] = answer.linear_json();
    summary["radiation"] = crate::sound::radiation_json(
        &answer.sound,
        answer.squeal.as_ref().map(|s| s.coordinate.as_str()),
    );
    summary
}

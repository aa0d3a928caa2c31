//! The thesis re-done: each of the 40 sets of Table 11.1 measured (linear
//! stability, a run, its analysis and the numbers the conclusions need),
//! the extra sweeps around set 15, and the seven conclusions of
//! docs/physics.md §6 graded on them. The report text and the pictures are
//! the CLI's (`squeal reproduce`).

use crate::analysis::{self, Analysis};
use crate::error::{Cancel, NoProgress, StudyError};
use crate::model::AnyModel;
use crate::run::Run;
use crate::scenario::Scenario;
use crate::stability::analyse as eigen_analyse;
use crate::study::{self, AboveUc, AlphaSweep, CpxSweep, StickStats};
use serde_json::{json, Value};
use squeal_core::stability;
use squeal_core::{EventKind, Model};
use squeal_signal::Spectrum;
use std::fmt::Write as _;

/// Linear stability of one set (sets at V = 0 have no steady sliding).
#[derive(Debug, Clone)]
pub struct Linear {
    /// Largest growth rate σ (1/s).
    pub max_growth: f64,
    /// Frequency of the least stable mode (Hz).
    pub freq_hz: f64,
    /// Whether a mode grows.
    pub growing: bool,
    /// Whether the least stable mode is neutral (σ = 0 within round-off).
    pub neutral: bool,
    /// (σ, ω, dominant) of every eigenvalue with ω ≥ 0, sorted by σ.
    pub modes: Vec<(f64, f64, String)>,
}

/// Everything measured on one set.
#[derive(Debug, Clone)]
pub struct SetResult {
    /// Set number (1–40), or conclusion number (1–7).
    pub id: usize,
    /// The scenario as run.
    pub sc: Scenario,
    /// Its linear stability (None without steady sliding).
    pub linear: Option<Linear>,
    /// Why there is none.
    pub linear_note: String,
    /// The run's verdict word.
    pub verdict: String,
    /// Strongest tangential frequency (Hz).
    pub f_t: Option<f64>,
    /// Strongest normal frequency (Hz).
    pub f_n: Option<f64>,
    /// Growth rate (1/s) of each velocity.
    pub growth: Vec<(String, f64)>,
    /// Fraction of the time in stick.
    pub stick_fraction: f64,
    /// Event counts by kind (order of `EventKind::ALL`).
    pub events: [u64; 5],
    /// Time of the first reversal or stick (s).
    pub first_reversal: Option<f64>,
    /// Peak |vx_d| (m/s).
    pub vxd_peak: f64,
    /// Peak |vx_d| over the last fifth of the run (m/s).
    pub vxd_tail_peak: f64,
    /// Peak |vx_p| (m/s).
    pub vxp_max: f64,
    /// Whether vx_d is zero throughout.
    pub tangential_zero: bool,
    /// Prominence (dB) of the tangential spectrum at the normal frequency.
    pub tan_prom_at_fn: Option<f64>,
    /// Prominence (dB) of the normal spectrum at the disc tangential frequency.
    pub nor_prom_at_ft: Option<f64>,
    /// True sticks, reversals and stick durations.
    pub stick: StickStats,
    /// Fraction of the run without contact.
    pub free_fraction: f64,
    /// The squeal: the coordinate that carries it, its frequency and level.
    pub squeal: Option<SquealAnswer>,
    /// Squared peak amplitude A² ((m/s)² = J/kg) of the disc's normal velocity
    /// at its spectral peak (flat-top window), and the frequency of that peak.
    pub normal_power: Option<(f64, f64)>,
    /// Envelope rate (1/s) of the disc's normal velocity at its peak frequency.
    pub normal_rate: Option<f64>,
    /// The equivalent radiated power (dB re 1 pW) over the judged window,
    /// from the scenario's radiating surfaces ([`crate::radiation`]); `None`
    /// when there are none or nothing moves them.
    pub erp_db: Option<f64>,
    /// The A-weighted sound pressure level (dB(A) re 20 µPa) at the
    /// scenario's distance, likewise.
    pub spl_dba: Option<f64>,
}

/// The answer to "does it squeal, at which frequency, how loud".
#[derive(Debug, Clone, PartialEq)]
pub struct SquealAnswer {
    /// The coordinate that carries it.
    pub coordinate: String,
    /// Its frequency (Hz).
    pub frequency_hz: f64,
    /// Its level (dB).
    pub level_db: f64,
}

impl SetResult {
    /// The value of parameter `k` in this set (NaN if the model has none).
    pub fn p(&self, k: &str) -> f64 {
        self.sc.model.get(k).unwrap_or(f64::NAN)
    }
    /// The verdict word when the run left the model's range of validity
    /// (`lift-off`, `out-of-range`): such runs are no evidence for other claims.
    pub fn outside(&self) -> Option<&str> {
        matches!(self.verdict.as_str(), "lift-off" | "out-of-range")
            .then_some(self.verdict.as_str())
    }
    /// The growth rate of velocity `s`.
    pub fn growth_of(&self, s: &str) -> Option<f64> {
        self.growth.iter().find(|(n, _)| n == s).map(|g| g.1)
    }
    /// `none`, `unstable`, `neutral` or `stable`.
    pub fn linear_word(&self) -> &'static str {
        match &self.linear {
            None => "none",
            Some(l) if l.growing => "unstable",
            Some(l) if l.neutral => "neutral",
            Some(_) => "stable",
        }
    }
    /// Do the eigenvalues and the simulation tell the same story?
    pub fn agrees(&self) -> Option<bool> {
        let word = self.linear_word();
        let v = self.verdict.as_str();
        if self.outside().is_some() || v == "too-short" {
            return None;
        }
        match word {
            "none" => None,
            "unstable" => Some(matches!(v, "grows" | "stick-slip" | "limit-cycle")),
            "stable" => Some(v == "decays"),
            _ => Some(matches!(v, "neutral" | "limit-cycle" | "decays")),
        }
    }
}

/// Prominence (dB) of a spectrum at frequency `f`: the highest level within
/// ±1 bin minus the median level of the bins 4–40 away on either side.
pub fn prominence(s: &Spectrum, f: f64) -> Option<f64> {
    let db = s.to_db();
    let k = (f / s.df).round() as usize;
    if k < 2 || k + 2 >= db.len() {
        return None;
    }
    let level = db[k - 1..=k + 1].iter().copied().fold(f64::MIN, f64::max);
    let mut around: Vec<f64> = (k.saturating_sub(40)..k.saturating_sub(3))
        .chain(k + 4..(k + 41).min(db.len()))
        .map(|i| db[i])
        .collect();
    if around.is_empty() {
        return None;
    }
    around.sort_by(f64::total_cmp);
    Some(level - around[around.len() / 2])
}

/// The linear stability of a model (the message when it has no steady sliding).
pub fn linear_of(model: &AnyModel) -> Result<Linear, String> {
    let an = eigen_analyse(model).map_err(|e| e.to_string())?;
    let ls = an.least_stable_mode();
    let neutral = an.neutral;
    Ok(Linear {
        max_growth: an.max_growth_rate,
        freq_hz: ls.freq_hz,
        growing: an.eigen.iter().any(|e| e.growing),
        neutral,
        modes: an
            .eigen
            .iter()
            .filter(|e| e.im >= 0.0)
            .map(|e| (e.re, e.im, e.dominant_name.clone()))
            .collect(),
    })
}

/// The squeal a run shows, as its [`Answer`](crate::answer::Answer) gives
/// it (the number `simulate` prints and writes): `None` when nothing
/// squeals, or the run ended before the squeal was established (the
/// answer is then a linear prediction, not something the run shows).
pub fn squeal_answer(answer: &crate::answer::Answer) -> Option<SquealAnswer> {
    answer
        .squeal
        .as_ref()
        .filter(|s| s.source == crate::answer::Source::Run)
        .map(|s| SquealAnswer {
            coordinate: s.coordinate.clone(),
            frequency_hz: s.frequency_hz,
            level_db: s.level_db.unwrap_or(f64::NAN),
        })
}

/// Measure one set: its eigenvalues, a run and its analysis, and the
/// numbers the conclusions need. `after` sees the run, its analysis and
/// its answer before they are dropped (the CLI draws Appendix A's pictures
/// there).
/// [`measure_run`] of [`run::run`](crate::run::run)'s run of `sc`.
pub fn measure<E: From<StudyError>>(
    id: usize,
    sc: Scenario,
    cancel: &Cancel,
    after: impl Fn(&Run, &Analysis, &crate::answer::Answer) -> Result<(), E>,
) -> Result<SetResult, E> {
    let run: Run = crate::run::run(&sc, &NoProgress, cancel)?;
    measure_run(id, sc, run, after)
}

/// [`measure`] with the set's run already done (e.g. by
/// [`run_many`](crate::run::run_many) with other sets): its eigenvalues,
/// the run's analysis, and the numbers the conclusions need.
pub fn measure_run<E: From<StudyError>>(
    id: usize,
    sc: Scenario,
    run: Run,
    after: impl Fn(&Run, &Analysis, &crate::answer::Answer) -> Result<(), E>,
) -> Result<SetResult, E> {
    let (linear, linear_note) = match linear_of(&sc.model) {
        Ok(l) => (Some(l), String::new()),
        Err(e) => (None, e),
    };
    let ch = sc.model.channels();
    let an: Analysis = analysis::analyse(
        &run,
        &ch,
        &analysis::SpectrumSettings::default(),
        sc.validity,
        &[],
    );
    // One answer: the verdict and squeal `simulate` gives for this run.
    let answer = crate::answer::Answer::of(&sc, &run, &an);
    after(&run, &an, &answer)?;
    let col = |n: &str| run.column(n).unwrap_or(&[]);
    let vxd = col("vx_d");
    let n = vxd.len();
    let tail = &vxd[n - n / 5..];
    let absmax = |x: &[f64]| x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let f_t = an
        .tangential
        .as_ref()
        .and_then(|c| c.peaks.first().map(|p| p.freq));
    let f_n = an
        .normal
        .as_ref()
        .and_then(|c| c.peaks.first().map(|p| p.freq));
    // The model's own frequencies (from its eigenvalues) to look for in the spectra.
    let (mode_n, mode_t) = match &linear {
        Some(l) => (
            l.modes
                .iter()
                .find(|m| m.2 == "y_d")
                .map(|m| m.1 / (2.0 * std::f64::consts::PI)),
            l.modes
                .iter()
                .find(|m| m.2 == "x_d")
                .map(|m| m.1 / (2.0 * std::f64::consts::PI)),
        ),
        None => (None, None),
    };
    let tan_prom_at_fn = match (&an.tangential, mode_n) {
        (Some(c), Some(f)) => prominence(&c.spectrum, f),
        _ => None,
    };
    let nor_prom_at_ft = match (&an.normal, mode_t) {
        (Some(c), Some(f)) => prominence(&c.spectrum, f),
        _ => None,
    };
    let stats = run.info.stats;
    let fs = run.sample_rate;
    let vyd = col("vy_d");
    let normal_power = f_n.and_then(|f| {
        let opts = squeal_signal::WelchOptions {
            window: squeal_signal::Window::FlatTop,
            ..Default::default()
        };
        let s = squeal_signal::amplitude_spectrum(vyd, fs, &opts).ok()?;
        let k = s.bin_of(f);
        let (lo, hi) = (k.saturating_sub(3), (k + 4).min(s.len()));
        (lo..hi)
            .map(|i| (s.psd[i], s.freq[i]))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    });
    let normal_rate = f_n.and_then(|f| {
        let b = study::demodulate(vyd, fs, f, 20.0);
        study::envelope_rate(&b, 0.0, sc.duration)
    });
    let total: f64 = stats.mode_time.iter().sum();
    let sound = answer.sound.as_ref().ok();
    let finite = |x: f64| x.is_finite().then_some(x);
    Ok(SetResult {
        erp_db: sound.as_ref().and_then(|s| finite(s.levels.erp_db)),
        spl_dba: sound.as_ref().and_then(|s| finite(s.levels.spl_dba)),
        id,
        linear,
        linear_note,
        verdict: answer.verdict(&an).as_str().to_string(),
        f_t,
        f_n,
        growth: an.growth.iter().map(|g| (g.0.clone(), g.1)).collect(),
        stick_fraction: stats.stick_fraction(),
        events: stats.events,
        first_reversal: run
            .events
            .iter()
            .find(|(_, k)| matches!(k, EventKind::Reverse | EventKind::Stick))
            .map(|e| e.0),
        vxd_peak: absmax(vxd),
        vxd_tail_peak: absmax(tail),
        vxp_max: absmax(col("vx_p")),
        tangential_zero: vxd.iter().all(|v| *v == 0.0),
        tan_prom_at_fn,
        nor_prom_at_ft,
        stick: StickStats::of(&run.events),
        free_fraction: if total > 0.0 {
            stats.mode_time[squeal_core::Mode::Free.index()] / total
        } else {
            0.0
        },
        squeal: squeal_answer(&answer),
        normal_power,
        normal_rate,
        sc,
    })
}

/// How far a thesis conclusion survives the runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grade {
    /// The claim holds as stated, quantitatively.
    Held,
    /// The trend holds, a number or magnitude the thesis gave does not.
    Qualitatively,
    /// The observation holds, but the runs show another cause than the thesis named.
    AnotherMechanism,
    /// The runs contradict the claim.
    Refuted,
    /// The evidence the claim needs lies outside the model's range of validity.
    Outside,
}

impl Grade {
    /// Every grade, in the report's order.
    pub const ALL: [Grade; 5] = [
        Grade::Held,
        Grade::Qualitatively,
        Grade::AnotherMechanism,
        Grade::Refuted,
        Grade::Outside,
    ];
    /// The grade in words.
    pub fn as_str(self) -> &'static str {
        match self {
            Grade::Held => "held",
            Grade::Qualitatively => "held qualitatively",
            Grade::AnotherMechanism => "held by another mechanism",
            Grade::Refuted => "refuted",
            Grade::Outside => "outside the model",
        }
    }
    /// What the grade means.
    pub fn meaning(self) -> &'static str {
        match self {
            Grade::Held => "the claim holds as stated, with the numbers the thesis gave or implied",
            Grade::Qualitatively => "the trend the thesis describes holds, but a number or magnitude it gave is wrong",
            Grade::AnotherMechanism => "what the thesis observed happens, but the runs show a different cause than the one it named",
            Grade::Refuted => "the runs contradict the claim",
            Grade::Outside => "the runs the claim rests on leave the model's range of validity, so the model cannot judge it",
        }
    }
    /// `held` in conclusions.json: every grade that keeps the observation.
    pub fn held(self) -> bool {
        matches!(
            self,
            Grade::Held | Grade::Qualitatively | Grade::AnotherMechanism
        )
    }
}

/// One conclusion, evaluated.
#[derive(Debug, Clone)]
pub struct Conclusion {
    /// Set number (1–40), or conclusion number (1–7).
    pub id: usize,
    /// The thesis's words.
    pub thesis: &'static str,
    /// The claim as measured.
    pub claim: String,
    /// How far it survives.
    pub grade: Grade,
    /// One line for the headline: why this grade.
    pub caveat: String,
    /// The evidence, in words.
    pub evidence: String,
    /// The evidence's numbers, machine-readable (conclusions.json `data`).
    pub data: Value,
}

/// The sets of `v` for which `keep` holds.
pub fn pick<'a>(v: &[&'a SetResult], keep: impl Fn(&SetResult) -> bool) -> Vec<&'a SetResult> {
    v.iter().copied().filter(|r| keep(r)).collect()
}

/// The set numbers of `v`, comma-separated (`none` if empty).
pub fn ids(v: &[&SetResult]) -> String {
    let list: Vec<String> = v.iter().map(|r| r.id.to_string()).collect();
    if list.is_empty() {
        "none".into()
    } else {
        list.join(", ")
    }
}

/// `x` in decibels (20 log10).
pub fn db(x: f64) -> f64 {
    20.0 * x.max(1e-300).log10()
}

/// A run squeals when its vibration grows or is sustained (the verdict
/// vocabulary's squealing words; lift-off is outside the model, not evidence).
pub fn squeals(r: &SetResult) -> bool {
    matches!(r.verdict.as_str(), "grows" | "stick-slip" | "limit-cycle")
}

/// Follower-force sweep: negative α values (log-spaced −1 … −1e5) and positive ones.
pub const ALPHA_SWEEP: (usize, usize, f64) = (41, 21, -1e5);
/// Pad-damping sweep: c_px as multiples of the pad's Hopf damping c_px*.
pub const CPX_FACTORS: [f64; 6] = [0.064, 0.3, 0.6, 1.2, 1.5, 2.0];
/// Simulated time of each pad-damping run (s).
pub const CPX_DURATION: f64 = 0.6;
/// Simulated time of the kicked run above U_c (s).
pub const KICK_DURATION: f64 = 1.0;

/// Extra computations the conclusions need, linear and simulated.
pub struct Sweeps {
    /// (points, max σ, at V, at N) over V ∈ (Uc, 3Uc], N ∈ {100, 500, 2000, 5000}, c_dx = c_px = 0.
    pub above_uc: (usize, f64, f64, f64),
    /// Max σ just below Uc (V = 0.9 Uc, N = 500, default damping).
    pub below_uc: f64,
    /// Critical common tangential damping c (c_dx = c_px = c) at N = 500 and N = 2000, V = 1.
    pub c_crit: (Option<f64>, Option<f64>),
    /// The destabilising term −F_y*·μ′(V) of the model at N = 500 and N = 2000, V = 1 (kg/s).
    pub destab: (f64, f64),
    /// The follower-force sweep.
    pub alpha: Option<AlphaSweep>,
    /// The pad-damping sweep.
    pub cpx: CpxSweep,
    /// The kicked run above U_c, and its verdict.
    pub kicked: AboveUc,
    /// The verdict of the kicked run.
    pub kicked_verdict: String,
}

/// The extra computations of [`Sweeps`], around set 15 (the thesis's
/// reference set). `cancel` is looked at between them.
pub fn sweeps(set15: &Scenario, cancel: &Cancel) -> Result<Sweeps, StudyError> {
    let base = &set15.model;
    let uc = base.get("Uc").unwrap_or(50.0 / 3.0);
    let mut worst = (0usize, f64::NEG_INFINITY, f64::NAN, f64::NAN);
    for &n in &[100.0, 500.0, 2000.0, 5000.0] {
        for i in 1..=200 {
            let v = uc * (1.0 + 2.0 * i as f64 / 200.0);
            let mut m = base.clone();
            let ok = m
                .set("V", v)
                .and(m.set("N", n))
                .and(m.set("c_dx", 0.0))
                .and(m.set("c_px", 0.0));
            if ok.is_err() {
                continue;
            }
            if let Ok((s, _)) = m.max_growth_rate() {
                worst.0 += 1;
                if s > worst.1 {
                    worst = (worst.0, s, v, n);
                }
            }
        }
    }
    cancel.check()?;
    let mut m = base.clone();
    let _ = m.set("V", 0.9 * uc);
    let below = m.max_growth_rate().map(|r| r.0).unwrap_or(f64::NAN);
    let at_n = |n: f64| {
        let mut m = base.clone();
        m.set("N", n).ok()?;
        m.set("V", 1.0).ok()?;
        Some(m)
    };
    let crit = |n: f64| {
        let m = at_n(n)?;
        let f = |c: f64| {
            let mut mm = m.clone();
            mm.set("c_dx", c)?;
            mm.set("c_px", c)?;
            mm.max_growth_rate()
        };
        stability::critical(f, 0.0, 100.0, &stability::CriticalOptions::default())
            .ok()
            .flatten()
            .map(|c| c.value)
    };
    let destab = |n: f64| -> f64 {
        match at_n(n) {
            Some(AnyModel::DiscPad(dp)) => dp.equilibrium().map_or(f64::NAN, |z| {
                -dp.p.k_py * (z[2] - z[3]) * dp.friction.dmu(dp.p.V)
            }),
            _ => f64::NAN,
        }
    };
    let alpha = match base {
        AnyModel::DiscPad(dp) => {
            study::alpha_sweep(dp, ALPHA_SWEEP.0, ALPHA_SWEEP.1, ALPHA_SWEEP.2)
        }
        _ => None,
    };
    let (cpx, kicked) = rayon::join(
        || study::cpx_sweep(set15, &CPX_FACTORS, CPX_DURATION, cancel),
        || study::above_uc(set15, KICK_DURATION, cancel),
    );
    let (cpx, kicked) = (cpx?, kicked?);
    let ch = base.channels();
    let kicked_verdict = analysis::analyse(
        &kicked.run,
        &ch,
        &analysis::SpectrumSettings::default(),
        set15.validity,
        &[],
    )
    .verdict
    .as_str()
    .to_string();
    Ok(Sweeps {
        above_uc: worst,
        below_uc: below,
        c_crit: (crit(500.0), crit(2000.0)),
        destab: (destab(500.0), destab(2000.0)),
        alpha,
        cpx,
        kicked,
        kicked_verdict,
    })
}

/// A short time in nanoseconds, with three significant digits below 10 ns.
pub fn ns(t: f64) -> String {
    let x = t * 1e9;
    if x < 10.0 {
        format!("{x:.3} ns")
    } else {
        format!("{x:.0} ns")
    }
}

/// A threshold in words (`beyond the sweep` if none).
pub fn thr(x: Option<f64>) -> String {
    x.map_or("beyond the sweep".into(), |a| format!("{a:.0}"))
}

/// The seven conclusions, graded on the sets `rs` and the sweeps `sw`.
pub fn conclusions(rs: &[SetResult], sw: &Sweeps) -> Vec<Conclusion> {
    let uc = rs[0].sc.model.get("Uc").unwrap_or(50.0 / 3.0);
    let outside: Vec<&SetResult> = rs.iter().filter(|r| r.outside().is_some()).collect();
    let excluded = if outside.is_empty() {
        String::new()
    } else {
        format!(
            " Excluded as outside the model: {}.",
            outside
                .iter()
                .map(|r| format!("set {} ({})", r.id, r.verdict))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    // Evidence comes only from runs that stay inside the model.
    let sliding: Vec<&SetResult> = rs
        .iter()
        .filter(|r| r.p("V") > 0.0 && r.outside().is_none())
        .collect();
    let find = |id: usize| rs.iter().find(|r| r.id == id);
    let mut out = Vec::new();

    // 1. Stribeck effect.
    let no_stribeck: Vec<&SetResult> = pick(&sliding, |r| r.p("f1") == 0.0);
    let bad: Vec<&SetResult> = pick(&no_stribeck, |r| {
        r.linear.as_ref().is_some_and(|l| l.growing) || squeals(r)
    });
    let squealing: Vec<&SetResult> = pick(&sliding, squeals);
    let elsewhere: Vec<&SetResult> = pick(&squealing, |r| !(r.p("f1") > 0.0 && r.p("V") < uc));
    let quiet: Vec<&SetResult> = pick(&sliding, |r| {
        r.p("f1") > 0.0 && r.p("V") < uc && !squeals(r)
    });
    let quiet_text: Vec<String> = quiet
        .iter()
        .map(|r| {
            format!(
                "{} ({}, σ_max {})",
                r.id,
                r.linear_word(),
                r.linear
                    .as_ref()
                    .map_or("n/a".into(), |l| format!("{:+.3}", l.max_growth))
            )
        })
        .collect();
    let worst = no_stribeck
        .iter()
        .filter_map(|r| r.linear.as_ref().map(|l| (l.max_growth, r.id)))
        .fold((f64::NEG_INFINITY, 0), |a, b| if b.0 > a.0 { b } else { a });
    let ok1 =
        !no_stribeck.is_empty() && bad.is_empty() && elsewhere.is_empty() && !squealing.is_empty();
    out.push(Conclusion {
        data: Value::Null,
        id: 1,
        thesis: "Unstable tangential oscillations develop through the Stribeck effect.",
        claim: "The Stribeck effect is necessary, not sufficient: no sliding run without it (f1 = 0) has a growing mode or squeals, and every run that squeals has f1 > 0 and V < Uc; with it, a run squeals only where its damping is below the critical damping.".into(),
        grade: if ok1 { Grade::Held } else { Grade::Refuted },
        caveat: format!("necessary, not sufficient: {} sets with the Stribeck effect below Uc are quiet, all linearly stable", quiet.len()),
        evidence: format!(
            "f1 = 0 sets {}: largest σ_max {:+.3e} 1/s (set {}), growing or squealing: {}. Squealing sets: {} (outside f1 > 0, V < Uc: {}). Quiet sets with f1 > 0 and V < Uc, and why: {}.{excluded}",
            ids(&no_stribeck), worst.0, worst.1, ids(&bad), ids(&squealing), ids(&elsewhere),
            if quiet_text.is_empty() { "none".into() } else { quiet_text.join(", ") }
        ),
    });

    // 2. Normal → tangential spectrum, not the reverse.
    let a0: Vec<&SetResult> = pick(&sliding, |r| r.p("alpha") == 0.0);
    let present: Vec<&SetResult> = pick(&a0, |r| r.tan_prom_at_fn.is_some_and(|p| p >= 10.0));
    let leak: Vec<&SetResult> = pick(&a0, |r| r.nor_prom_at_ft.is_some_and(|p| p > 3.0));
    let minmax = |f: &dyn Fn(&SetResult) -> Option<f64>| {
        let v: Vec<f64> = a0.iter().filter_map(|r| f(r)).collect();
        (
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let (tp_lo, tp_hi) = minmax(&|r| r.tan_prom_at_fn);
    let (np_lo, np_hi) = minmax(&|r| r.nor_prom_at_ft);
    let ok2 = !a0.is_empty() && present.len() == a0.len() && leak.is_empty();
    out.push(Conclusion {
        data: Value::Null,
        id: 2,
        thesis: "Normal oscillations show up in the tangential spectrum through F_y; not the other way round (without follower force).",
        claim: "In every sliding run with α = 0 the tangential velocity spectrum has a peak (≥ 10 dB above its neighbourhood) at the disc's normal frequency, while the normal spectrum has none (≤ 3 dB) at the disc's tangential frequency.".into(),
        grade: if ok2 { Grade::Held } else { Grade::Refuted },
        caveat: "exact by construction: with α = 0 the normal equations contain no tangential state".into(),
        evidence: format!(
            "{} sliding sets with α = 0; tangential prominence at the normal frequency {:.1} to {:.1} dB (sets with ≥ 10 dB: {} of {}); normal prominence at the tangential frequency {:.1} to {:.1} dB (sets above 3 dB: {}). With α = 0 the normal equations do not involve the tangential states at all.",
            a0.len(), tp_lo, tp_hi, present.len(), a0.len(), np_lo, np_hi, ids(&leak)
        ),
    });

    // 3. Nothing grows above Uc — from rest and after a large kick.
    let above: Vec<&SetResult> = pick(&sliding, |r| r.p("V") > uc);
    let above_bad: Vec<&SetResult> = pick(&above, |r| {
        squeals(r) || r.linear.as_ref().is_some_and(|l| l.growing)
    });
    let (npts, smax, sv, sn) = sw.above_uc;
    let k = &sw.kicked;
    let kick_ok = sw.kicked_verdict == "decays"
        && k.rate.0.is_some_and(|r| r < 0.0)
        && k.rate.1.is_some_and(|r| r < 0.0)
        && k.last_event.is_none_or(|t| t < 0.5 * k.duration);
    let rate = |x: Option<f64>| x.map_or("n/a".into(), |r| format!("{r:+.3}"));
    out.push(Conclusion {
        data: json!({
            "sets_above_uc_squealing": above_bad.iter().map(|r| r.id).collect::<Vec<_>>(),
            "sweep_points": npts, "sweep_max_growth_rate": smax,
            "kick": {"V": k.v, "vx_p0": k.kick.0, "vx_d0": k.kick.1, "reversals": k.reversals, "sticks": k.sticks,
                     "last_event_s": k.last_event, "disc_rate": k.rate.0, "pad_rate": k.rate.1,
                     "disc_sigma": k.sigma.0, "pad_sigma": k.sigma.1, "verdict": sw.kicked_verdict},
        }),
        id: 3,
        thesis: "No tangential instability above the critical speed Uc.",
        claim: format!("No run with V > Uc = {uc:.2} m/s grows or squeals; an eigenvalue sweep of V over (Uc, 3Uc] at N = 100–5000 N without tangential damping finds no growing mode; and a large kick above Uc (pad and disc thrown far past the disc speed, so that the slip reverses) dies away too."),
        grade: if !above.is_empty() && above_bad.is_empty() && smax < 0.0 && kick_ok { Grade::Held } else { Grade::Refuted },
        caveat: "also after a large kick, not only from rest".into(),
        evidence: format!(
            "Sets above Uc: {} (growing or squealing: {}). Sweep: {npts} points, largest σ_max {smax:+.3e} 1/s at V = {sv:.2} m/s, N = {sn} N. For contrast, at V = 0.9·Uc (N = 500, default damping) σ_max = {:+.3e} 1/s. Kick at V = {:.2} m/s without tangential damping (c_dx = c_px = 0), from steady sliding with ẋ_p = {:.1} m/s and ẋ_d = {:.1} m/s: {} reversals and {} sticks, the last at {}; envelope rates over the second half: disc {} 1/s (eigenvalue {:+.3}), pad {} 1/s (eigenvalue {:+.3}); pad speed peak {:.3} m/s in the first 10 %, {:.2e} m/s in the last; verdict {}.",
            ids(&above), ids(&above_bad), sw.below_uc,
            k.v, k.kick.0, k.kick.1, k.reversals, k.sticks,
            k.last_event.map_or("never".into(), |t| format!("t = {t:.4} s")),
            rate(k.rate.0), k.sigma.0, rate(k.rate.1), k.sigma.1,
            k.pad_peak.0, k.pad_peak.1, sw.kicked_verdict
        ),
    });

    // 4. Damping and N; the thesis's estimate of the destabilising term.
    let (c500, c2000) = sw.c_crit;
    let (d500, d2000) = sw.destab;
    let s28 = find(28);
    let s31 = find(31);
    let runs_ok = s28.is_some_and(|r| !squeals(r)) && s31.is_some_and(squeals);
    let trend = matches!((c500, c2000), (Some(a), Some(b)) if b > a) && runs_ok;
    let f0 = rs[14].p("f0");
    let f1 = rs[14].p("f1");
    out.push(Conclusion {
        data: json!({
            "thesis_estimate_kg_s": [30.0, 100.0],
            "thesis_formula_N_f1_kg_s": [500.0 * f1, 2000.0 * f1],
            "destabilising_term_kg_s": {"N500_V1": d500, "N2000_V1": d2000},
            "missing_factor_f0": f0,
            "critical_damping_kg_s": {"N500": c500, "N2000": c2000},
        }),
        id: 4,
        thesis: "Below Uc, instability appears when damping is small, more readily at high N.",
        claim: "At V = 1 m/s the tangential damping needed to silence the brake (c = c_dx = c_px) rises with the pad force, and the damping that silences it at N = 500 N (set 28) does not at N = 2000 N (set 31). The thesis's size of the destabilising term, 30–100 kg/s, is confronted with the model's.".into(),
        grade: if !trend { Grade::Refuted } else { Grade::Qualitatively },
        caveat: format!("the trend holds; the thesis's 30–100 kg/s is the model's {d500:.2} kg/s without the factor f0"),
        evidence: format!(
            "Critical c: {} kg/s at N = 500 N, {} kg/s at N = 2000 N (ratio {}); set 28: {} (σ_max {}), set 31: {} (σ_max {}). \
             The thesis (Ch. 13) puts the destabilising term N·f′(0) at 30–100 kg/s for N = 500–2000 N, taking f′(0) = −f1 (N·f1 = {:.1} and {:.1} kg/s), and concludes that it \"considerably exceeds\" its physical damping estimates (1–5 kg/s). \
             With the law it uses the term is F_y·μ′(V) = −N·f0·f1·(1 − V/Uc): the model gives {d500:.4} kg/s at N = 500 N and {d2000:.4} kg/s at N = 2000 N, V = 1 m/s. The thesis dropped the factor f0 = {f0}, which makes its estimate ten times too large (another 6 % comes from evaluating the slope at v = 0 instead of V = 1 m/s). \
             The coupled eigenvalues agree with the corrected term: the critical damping at 500 N differs from it by {}. \
             Consequence: the brake at 500 N is marginal, not far beyond help — the thesis's own damping range (1–5 kg/s) straddles the critical {d500:.2} kg/s, and its conclusion that \"a considerable addition may be required\" is refuted at 500 N; only at 2000 N ({d2000:.1} kg/s) does the critical damping exceed its range.",
            c500.map_or("none".into(), |c| format!("{c:.4}")),
            c2000.map_or("none".into(), |c| format!("{c:.4}")),
            match (c500, c2000) { (Some(a), Some(b)) => format!("{:.3}", b / a), _ => "n/a".into() },
            s28.map_or("missing", |r| r.verdict.as_str()),
            s28.and_then(|r| r.linear.as_ref()).map_or("n/a".into(), |l| format!("{:+.3}", l.max_growth)),
            s31.map_or("missing", |r| r.verdict.as_str()),
            s31.and_then(|r| r.linear.as_ref()).map_or("n/a".into(), |l| format!("{:+.3}", l.max_growth)),
            500.0 * f1, 2000.0 * f1,
            c500.map_or("n/a".into(), |c| format!("{:.1e} relative", ((c - d500) / d500).abs())),
        ),
    });

    // 5. What limits the amplitude: sticks or reversals.
    let unstable: Vec<&SetResult> =
        pick(&sliding, |r| r.linear.as_ref().is_some_and(|l| l.growing));
    let saturated: Vec<&SetResult> = pick(&unstable, |r| {
        r.p("alpha") == 0.0 && r.first_reversal.is_some_and(|t| t < 0.6 * r.sc.duration)
    });
    let late: Vec<&SetResult> = pick(&unstable, |r| {
        r.p("alpha") == 0.0 && r.first_reversal.is_some_and(|t| t >= 0.6 * r.sc.duration)
    });
    let bounded: Vec<&SetResult> = pick(&saturated, |r| {
        matches!(r.verdict.as_str(), "stick-slip" | "limit-cycle") && r.vxp_max <= 2.0 * r.p("V")
    });
    let unsat: Vec<&SetResult> = pick(&unstable, |r| r.first_reversal.is_none());
    let ratio = saturated
        .iter()
        .map(|r| r.vxp_max / r.p("V"))
        .fold(0.0, f64::max);
    let (sticks, reversals) = saturated.iter().fold((0u64, 0u64), |a, r| {
        (a.0 + r.stick.sticks, a.1 + r.stick.reversals)
    });
    let per_set: Vec<String> = saturated
        .iter()
        .map(|r| {
            let d = r.sc.duration;
            format!(
                "set {}: {} sticks ({:.0}/s), {} reversals ({:.0}/s){}",
                r.id,
                r.stick.sticks,
                r.stick.sticks as f64 / d,
                r.stick.reversals,
                r.stick.reversals as f64 / d,
                r.stick
                    .durations
                    .map_or(String::new(), |(med, lo, hi)| format!(
                        ", sticks last {} (median; {}–{})",
                        ns(med),
                        ns(lo),
                        ns(hi)
                    ))
            )
        })
        .collect();
    let window = match &rs[14].sc.model {
        AnyModel::DiscPad(dp) => dp.friction.mu_static() * dp.p.N / dp.p.k_px,
        _ => f64::NAN,
    };
    let flagged: Vec<&SetResult> = pick(&sliding, |r| r.stick.sticks + r.stick.reversals > 0);
    let flagged_no_stick: Vec<&SetResult> = pick(&flagged, |r| r.stick.sticks == 0);
    let by_reversal = reversals > 10 * sticks;
    let ok5 = !saturated.is_empty() && bounded.len() == saturated.len();
    out.push(Conclusion {
        data: json!({
            "sticks": sticks, "reversals": reversals,
            "stick_window_m": window,
            "sets": saturated.iter().map(|r| json!({
                "set": r.id, "sticks": r.stick.sticks, "reversals": r.stick.reversals,
                "sticks_per_s": r.stick.sticks as f64 / r.sc.duration,
                "reversals_per_s": r.stick.reversals as f64 / r.sc.duration,
                "stick_duration_s": r.stick.durations.map(|d| json!({"median": d.0, "min": d.1, "max": d.2})),
            })).collect::<Vec<_>>(),
            "thesis_flag_stick_slip_sets": flagged.iter().map(|r| r.id).collect::<Vec<_>>(),
            "thesis_flag_sets_without_true_stick": flagged_no_stick.iter().map(|r| r.id).collect::<Vec<_>>(),
        }),
        id: 5,
        thesis: "Stick-slip limits the amplitude of the growing oscillation.",
        claim: "Every linearly unstable run without follower force that reaches the disc speed in the first 60 % of its duration settles on a bounded friction-limited cycle (pad speed below 2V) instead of growing without bound; the events say whether true sticks or slip reversals limit it.".into(),
        grade: if !ok5 { Grade::Refuted } else if by_reversal { Grade::AnotherMechanism } else { Grade::Held },
        caveat: format!("the amplitude is bounded, but by slip reversals ({reversals}) far more than by true sticks ({sticks})"),
        evidence: format!(
            "Unstable sets: {}; reached the disc speed early: {} (bounded: {} of them; largest pad speed {:.3}·V); late, still settling: {}; still growing when the run ended: {}. \
             Events in the saturated runs: {}. In total {sticks} true sticks against {reversals} slip reversals. \
             The pad can stick only while |x_p| ≤ μ_s·F_y/k_px = {:.1} nm (set 15), while its cycle at the disc speed has an amplitude of order V/ω_p ≈ {:.2} µm: the pad's velocity dips below the disc's for about a microsecond per cycle and reverses without sticking, and the rare true sticks last nanoseconds. \
             The thesis's flag, which switched to stick at every zero of v, would have called every set with a reversal or a stick stick-slip: sets {} — of which {} have no true stick at all.{excluded}",
            ids(&unstable), ids(&saturated), bounded.len(), ratio, ids(&late), ids(&unsat),
            if per_set.is_empty() { "none".into() } else { per_set.join("; ") },
            window * 1e9,
            rs[14].p("V") / (std::f64::consts::TAU * rs[14].linear.as_ref().and_then(|l| l.modes.iter().find(|m| m.2 == "x_p").map(|m| m.1 / std::f64::consts::TAU)).unwrap_or(f64::NAN)) * 1e6,
            ids(&flagged), ids(&flagged_no_stick),
        ),
    });

    // 6. The pad saturates first and holds the disc back; pad damping frees the disc.
    let (s15, s27) = (find(15), find(27));
    let cp = &sw.cpx;
    let below: Vec<&study::CpxPoint> = cp.points.iter().filter(|p| p.c_px < cp.c_star).collect();
    let above_c: Vec<&study::CpxPoint> = cp.points.iter().filter(|p| p.c_px > cp.c_star).collect();
    let sweep_ok = !below.is_empty()
        && !above_c.is_empty()
        && below
            .iter()
            .all(|p| p.saturated_at.is_some() && p.disc_rate.is_some_and(|r| r < 0.0))
        && above_c.iter().all(|p| {
            p.saturated_at.is_none()
                && p.disc_rate.is_some_and(|r| {
                    p.sigma_disc > 0.0 && (r - p.sigma_disc).abs() <= 0.1 * p.sigma_disc
                })
        })
        && cp.disc_eig_change < 1e-6;
    let mut held6 = false;
    let mut ev6 = String::from("sets 15 and 27 are needed");
    if let (Some(a), Some(b)) = (s15, s27) {
        let mode = |r: &SetResult, d: &str| {
            r.linear
                .as_ref()
                .and_then(|l| l.modes.iter().find(|m| m.2 == d).map(|m| m.0))
        };
        let (pad15, disc15) = (mode(a, "x_p"), mode(a, "x_d"));
        let disc27 = mode(b, "x_d");
        let collapse_db = db(a.vxd_peak) - db(a.vxd_tail_peak);
        let g27 = b.growth_of("vx_d");
        held6 = matches!((pad15, disc15), (Some(p), Some(d)) if p > d && d > 0.0)
            && a.first_reversal.is_some()
            && b.first_reversal.is_none()
            && sweep_ok;
        let pts: Vec<String> = cp
            .points
            .iter()
            .map(|p| {
                format!(
                    "c_px = {:.2} kg/s (σ_pad {:+.2}, σ_disc {:+.4} 1/s): {}, disc envelope {} 1/s",
                    p.c_px,
                    p.sigma_pad,
                    p.sigma_disc,
                    p.saturated_at
                        .map_or("the pad stays linear (no reversal)".into(), |t| format!(
                            "the pad saturates at t = {t:.3} s"
                        )),
                    p.disc_rate.map_or("n/a".into(), |r| format!("{r:+.3}")),
                )
            })
            .collect();
        ev6 = format!(
            "Set 15: σ_pad {} > σ_disc {} 1/s; first reversal at {}; disc tangential amplitude falls {collapse_db:.1} dB from its peak ({:.3e} m/s) to the last 20 % ({:.3e} m/s). Set 27 (c_px = 4 kg/s): reversals {}, verdict {}, disc growth rate fitted {} vs eigenvalue {} 1/s. \
             Sweep across the pad's Hopf damping c_px* = −F_y*·μ′(V) = {:.4} kg/s, each run {} s from steady sliding with the pad kicked to {} m/s and the disc to {} m/s; the disc's envelope is demodulated at its eigenfrequency and fitted from 20 ms after the first reversal over 0.2 s (or over the whole run when the pad stays linear): {}. \
             The disc's eigenvalue does not depend on c_px: over c_px ∈ [0, 3·c_px*] its growth rate changes by at most {:.1e} relative. So no linear mechanism makes pad damping destabilise the disc; the effect is nonlinear: the pad's saturated reversal cycle collapses the disc's mode, and a pad damped past c_px* stays linear and lets the disc grow at its own eigenvalue rate.",
            pad15.map_or("n/a".into(), |x| format!("{x:+.3}")),
            disc15.map_or("n/a".into(), |x| format!("{x:+.3}")),
            a.first_reversal.map_or("never".into(), |t| format!("t = {t:.4} s")),
            a.vxd_peak, a.vxd_tail_peak,
            b.events[EventKind::Reverse.index()],
            b.verdict,
            g27.map_or("n/a".into(), |x| format!("{x:+.3}")),
            disc27.map_or("n/a".into(), |x| format!("{x:+.3}")),
            cp.c_star, cp.duration, cp.kick.0, cp.kick.1,
            pts.join("; "),
            cp.disc_eig_change,
        );
    }
    out.push(Conclusion {
        data: json!({
            "c_px_star": cp.c_star,
            "disc_eigenvalue_max_relative_change": cp.disc_eig_change,
            "sweep": cp.points.iter().map(|p| json!({
                "c_px": p.c_px, "sigma_pad": p.sigma_pad, "sigma_disc": p.sigma_disc,
                "saturated_at_s": p.saturated_at, "reversals": p.reversals, "disc_envelope_rate": p.disc_rate,
            })).collect::<Vec<_>>(),
        }),
        id: 6,
        thesis: "The pad, which grows faster (smaller inertia), reaches stick-slip first, and its stick-slip suppresses the disc's growth; adding pad damping can destabilise the disc.",
        claim: "In the default brake the pad's mode grows faster than the disc's and reaches reversals first; across a sweep of c_px through the pad's Hopf damping c_px*, the disc collapses wherever the pad saturates and grows at its eigenvalue rate (within 10 %) wherever the pad stays linear, while the disc's eigenvalue does not change with c_px.".into(),
        grade: if held6 { Grade::Held } else { Grade::Refuted },
        caveat: "a purely nonlinear effect: the disc's eigenvalue does not depend on c_px".into(),
        evidence: ev6,
    });

    // 7. Follower force.
    let (s38, s39, s40) = (find(38), find(39), find(40));
    let same = match (s15, s38) {
        (Some(a), Some(b)) => {
            a.verdict == b.verdict
                && matches!((a.f_t, b.f_t), (Some(x), Some(y)) if (x - y).abs() < 1.0)
        }
        _ => false,
    };
    let (grade7, caveat7, claim7, ev7) = match &sw.alpha {
        None => (
            Grade::Refuted,
            "no sweep".to_string(),
            "The follower-force sweep could not be computed.".to_string(),
            "The steady sliding of set 15 has no eigenvalues.".to_string(),
        ),
        Some(a) => {
            // The smallest |α| at which any mode's growth rate or frequency changes by 1 %.
            let first = a
                .modes
                .iter()
                .flat_map(|m| {
                    [
                        (m.sigma_at[0], m.name, "growth rate"),
                        (m.freq_at[0], m.name, "frequency"),
                    ]
                })
                .filter_map(|(x, n, q)| x.map(|x| (x, n, q)))
                .fold(
                    (f64::INFINITY, "", ""),
                    |b, c| if c.0 < b.0 { c } else { b },
                );
            let lines: Vec<String> = a
                .modes
                .iter()
                .map(|m| {
                    format!(
                        "{} ({:.1} Hz, σ {:+.3}): σ changes 1 % / 10 % at |α| = {} / {} (α > 0: {} / {}), frequency at {} / {}; at α = {:.0e}: σ {:+.3}, {:.1} Hz",
                        m.name, m.freq0, m.sigma0,
                        thr(m.sigma_at[0]), thr(m.sigma_at[1]), thr(m.sigma_at_pos[0]), thr(m.sigma_at_pos[1]),
                        thr(m.freq_at[0]), thr(m.freq_at[1]),
                        a.alpha_end, m.at_end.0, m.at_end.1,
                    )
                })
                .collect();
            let (ca, cb, cd, cal) = a.closest;
            let coupling = if cd < 1e-3 {
                format!("modes {ca} and {cb} coalesce (relative distance {cd:.1e}) at α = {cal:.3e} 1/m")
            } else {
                format!("no two modes coalesce; the closest approach is {ca} and {cb}, {:.1} % apart at α = {cal:.3e} 1/m (the pad's normal frequency falls towards its tangential one: the start of mode coupling)", 100.0 * cd)
            };
            let lift = |r: Option<&SetResult>| {
                r.map_or("missing".into(), |r| {
                    format!(
                        "verdict {}, {} separations ({:.0}/s), {:.1} % of the time without contact",
                        r.verdict,
                        r.events[EventKind::Separate.index()],
                        r.events[EventKind::Separate.index()] as f64 / r.sc.duration,
                        100.0 * r.free_fraction
                    )
                })
            };
            let small = first.0 >= 10.0 && same;
            (
                if small { Grade::Qualitatively } else { Grade::Refuted },
                format!(
                    "weak only for |α| below about {:.0} 1/m; at α = −1000 (set 39) the pad lifts off",
                    first.0
                ),
                format!(
                    "The follower force leaves every mode's growth rate and frequency within 1 % up to |α| ≈ {:.0} 1/m, and set 38 (α = −10) tells the same story as set 15. The thesis gave no realistic value of α; larger |α| does change the brake.",
                    first.0
                ),
                format!(
                    "Sweep of steady sliding over {} values of α log-spaced from −1 to {:.0e} 1/m and {} from +1 to {:.0e} 1/m, each mode followed from α = 0 (thresholds refined between sweep points). First 1 % change: the {} of {} at |α| = {:.1} 1/m. Per mode: {}. {}. Steady sliding ceases to exist at α = {:.4e} 1/m. \
                     Set 38: {} (tangential {}), set 15: {} (tangential {}). Set 39 (α = −1000): {} — the follower force is not too weak there: the pad leaves the disc over and over, a lift-off regime that the linearisation about steady sliding cannot describe. Set 40 (α = −1e5): {}{}.",
                    a.n_neg, a.alpha_end, a.n_pos, -a.alpha_end,
                    first.2, first.1, first.0,
                    lines.join("; "),
                    coupling,
                    a.limit,
                    s38.map_or("missing", |r| r.verdict.as_str()),
                    s38.and_then(|r| r.f_t).map_or("n/a".into(), |f| format!("{f:.1} Hz")),
                    s15.map_or("missing", |r| r.verdict.as_str()),
                    s15.and_then(|r| r.f_t).map_or("n/a".into(), |f| format!("{f:.1} Hz")),
                    lift(s39),
                    lift(s40),
                    if s40.is_some_and(|r| r.outside().is_some()) { "; outside the model, no evidence either way" } else { "" },
                ),
            )
        }
    };
    out.push(Conclusion {
        data: sw.alpha.as_ref().map_or(Value::Null, |a| json!({
            "alpha_values_negative": a.n_neg, "alpha_values_positive": a.n_pos,
            "alpha_end": a.alpha_end, "steady_sliding_limit": a.limit,
            "closest_modes": {"a": a.closest.0, "b": a.closest.1, "relative_distance": a.closest.2, "alpha": a.closest.3},
            "modes": a.modes.iter().map(|m| json!({
                "mode": m.name, "freq_hz": m.freq0, "sigma": m.sigma0,
                "sigma_1pct_abs_alpha": m.sigma_at[0], "sigma_10pct_abs_alpha": m.sigma_at[1],
                "freq_1pct_abs_alpha": m.freq_at[0], "freq_10pct_abs_alpha": m.freq_at[1],
                "sigma_1pct_positive_alpha": m.sigma_at_pos[0], "freq_1pct_positive_alpha": m.freq_at_pos[0],
            })).collect::<Vec<_>>(),
        })),
        id: 7,
        thesis: "The follower force, at realistic α, is too weak to couple tangential and normal motion.",
        claim: claim7,
        grade: grade7,
        caveat: caveat7,
        evidence: ev7,
    });
    out
}

/// The 40 sets as `reproduce` runs them: [`crate::scenario::thesis_sets`]
/// with every duration multiplied by `duration_scale` (in (0, 10]) and
/// each checked by [`crate::feasible::prepare`]. An unsharded run, every
/// shard and the merge all start from this, so they run the same scenarios.
pub fn prepared_sets(duration_scale: f64) -> Result<Vec<Scenario>, StudyError> {
    if !(duration_scale.is_finite() && duration_scale > 0.0 && duration_scale <= 10.0) {
        return Err(crate::scenario::InputError(format!(
            "--duration-scale {duration_scale}: must be in (0, 10]"
        ))
        .into());
    }
    let mut sets = crate::scenario::thesis_sets();
    for s in &mut sets {
        let d = s.duration * duration_scale;
        s.apply("duration", &crate::scenario::Setting::Number(d))?;
        crate::feasible::prepare(s)?;
    }
    Ok(sets)
}

/// Shards of `reproduce`: a [`SetResult`] written as JSON and read back bit
/// for bit. Every `f64` is the text `{:e}` (the shortest decimal that
/// parses back to the same bits, `NaN` and `inf` included), never a JSON
/// number, so a merged report is the unsharded one byte for byte. The
/// scenario is not written: the merge rebuilds it with [`prepared_sets`].
pub mod exact {
    use super::{Linear, SetResult, SquealAnswer};
    use crate::scenario::Scenario;
    use crate::study::StickStats;
    use serde_json::{json, Value};

    fn x(v: f64) -> Value {
        Value::String(format!("{v:e}"))
    }
    fn ox(v: Option<f64>) -> Value {
        v.map_or(Value::Null, x)
    }

    /// One set's result as JSON (see the module docs).
    pub fn to_json(r: &SetResult) -> Value {
        json!({
            "id": r.id,
            "linear": r.linear.as_ref().map_or(Value::Null, |l| json!({
                "max_growth": x(l.max_growth),
                "freq_hz": x(l.freq_hz),
                "growing": l.growing,
                "neutral": l.neutral,
                "modes": l.modes.iter().map(|(s, w, d)| json!([x(*s), x(*w), d])).collect::<Vec<_>>(),
            })),
            "linear_note": r.linear_note,
            "verdict": r.verdict,
            "f_t": ox(r.f_t),
            "f_n": ox(r.f_n),
            "growth": r.growth.iter().map(|(n, g)| json!([n, x(*g)])).collect::<Vec<_>>(),
            "stick_fraction": x(r.stick_fraction),
            "events": r.events,
            "first_reversal": ox(r.first_reversal),
            "vxd_peak": x(r.vxd_peak),
            "vxd_tail_peak": x(r.vxd_tail_peak),
            "vxp_max": x(r.vxp_max),
            "tangential_zero": r.tangential_zero,
            "tan_prom_at_fn": ox(r.tan_prom_at_fn),
            "nor_prom_at_ft": ox(r.nor_prom_at_ft),
            "stick": {
                "sticks": r.stick.sticks,
                "reversals": r.stick.reversals,
                "durations": r.stick.durations.map_or(Value::Null, |(a, b, c)| json!([x(a), x(b), x(c)])),
            },
            "free_fraction": x(r.free_fraction),
            "squeal": r.squeal.as_ref().map_or(Value::Null, |s| json!({
                "coordinate": s.coordinate,
                "frequency_hz": x(s.frequency_hz),
                "level_db": x(s.level_db),
            })),
            "normal_power": r.normal_power.map_or(Value::Null, |(a, b)| json!([x(a), x(b)])),
            "normal_rate": ox(r.normal_rate),
            "erp_db": ox(r.erp_db),
            "spl_dba": ox(r.spl_dba),
        })
    }

    fn gx(v: &Value, what: &str) -> Result<f64, String> {
        v.as_str()
            .and_then(|s| s.parse::<f64>().ok())
            .ok_or_else(|| format!("{what}: not a number"))
    }
    fn gox(v: &Value, what: &str) -> Result<Option<f64>, String> {
        if v.is_null() {
            Ok(None)
        } else {
            gx(v, what).map(Some)
        }
    }
    fn gs(v: &Value, what: &str) -> Result<String, String> {
        v.as_str()
            .map(str::to_string)
            .ok_or_else(|| format!("{what}: not text"))
    }
    fn gb(v: &Value, what: &str) -> Result<bool, String> {
        v.as_bool().ok_or_else(|| format!("{what}: not true/false"))
    }
    fn gu(v: &Value, what: &str) -> Result<u64, String> {
        v.as_u64()
            .ok_or_else(|| format!("{what}: not a whole number"))
    }
    fn arr<'a>(v: &'a Value, what: &str) -> Result<&'a Vec<Value>, String> {
        v.as_array().ok_or_else(|| format!("{what}: not a list"))
    }

    /// Read back what [`to_json`] wrote, for the scenario `sc` it was
    /// measured on; the error names the field.
    pub fn from_json(v: &Value, sc: Scenario) -> Result<SetResult, String> {
        let id = gu(&v["id"], "id")? as usize;
        let linear = match &v["linear"] {
            Value::Null => None,
            l => Some(Linear {
                max_growth: gx(&l["max_growth"], "linear.max_growth")?,
                freq_hz: gx(&l["freq_hz"], "linear.freq_hz")?,
                growing: gb(&l["growing"], "linear.growing")?,
                neutral: gb(&l["neutral"], "linear.neutral")?,
                modes: arr(&l["modes"], "linear.modes")?
                    .iter()
                    .map(|m| {
                        Ok((
                            gx(&m[0], "linear.modes")?,
                            gx(&m[1], "linear.modes")?,
                            gs(&m[2], "linear.modes")?,
                        ))
                    })
                    .collect::<Result<_, String>>()?,
            }),
        };
        let ev = arr(&v["events"], "events")?;
        let mut events = [0u64; 5];
        if ev.len() != events.len() {
            return Err("events: expected 5 counts".into());
        }
        for (e, j) in events.iter_mut().zip(ev) {
            *e = gu(j, "events")?;
        }
        let st = &v["stick"];
        let durations = match &st["durations"] {
            Value::Null => None,
            d => Some((
                gx(&d[0], "stick.durations")?,
                gx(&d[1], "stick.durations")?,
                gx(&d[2], "stick.durations")?,
            )),
        };
        Ok(SetResult {
            id,
            linear,
            linear_note: gs(&v["linear_note"], "linear_note")?,
            verdict: gs(&v["verdict"], "verdict")?,
            f_t: gox(&v["f_t"], "f_t")?,
            f_n: gox(&v["f_n"], "f_n")?,
            growth: arr(&v["growth"], "growth")?
                .iter()
                .map(|g| Ok((gs(&g[0], "growth")?, gx(&g[1], "growth")?)))
                .collect::<Result<_, String>>()?,
            stick_fraction: gx(&v["stick_fraction"], "stick_fraction")?,
            events,
            first_reversal: gox(&v["first_reversal"], "first_reversal")?,
            vxd_peak: gx(&v["vxd_peak"], "vxd_peak")?,
            vxd_tail_peak: gx(&v["vxd_tail_peak"], "vxd_tail_peak")?,
            vxp_max: gx(&v["vxp_max"], "vxp_max")?,
            tangential_zero: gb(&v["tangential_zero"], "tangential_zero")?,
            tan_prom_at_fn: gox(&v["tan_prom_at_fn"], "tan_prom_at_fn")?,
            nor_prom_at_ft: gox(&v["nor_prom_at_ft"], "nor_prom_at_ft")?,
            stick: StickStats {
                sticks: gu(&st["sticks"], "stick.sticks")?,
                reversals: gu(&st["reversals"], "stick.reversals")?,
                durations,
            },
            free_fraction: gx(&v["free_fraction"], "free_fraction")?,
            squeal: match &v["squeal"] {
                Value::Null => None,
                s => Some(SquealAnswer {
                    coordinate: gs(&s["coordinate"], "squeal.coordinate")?,
                    frequency_hz: gx(&s["frequency_hz"], "squeal.frequency_hz")?,
                    level_db: gx(&s["level_db"], "squeal.level_db")?,
                }),
            },
            normal_power: match &v["normal_power"] {
                Value::Null => None,
                p => Some((gx(&p[0], "normal_power")?, gx(&p[1], "normal_power")?)),
            },
            normal_rate: gox(&v["normal_rate"], "normal_rate")?,
            erp_db: gox(&v["erp_db"], "erp_db")?,
            spl_dba: gox(&v["spl_dba"], "spl_dba")?,
            sc,
        })
    }
}

/// `x` with `prec` decimals, empty when missing or not finite (a table cell).
pub fn opt(x: Option<f64>, prec: usize) -> String {
    x.filter(|v| v.is_finite())
        .map_or(String::new(), |v| format!("{v:.prec$}"))
}

/// The parameters the table shows for every set (the ones the sets vary).
pub const TABLE_PARAMS: [&str; 8] = ["V", "N", "f1", "alpha", "c_dx", "c_dy", "c_px", "c_py"];

/// `table.csv`'s header.
pub const TABLE_HEADER: &str = "set,question,V,N,f1,alpha,c_dx,c_dy,c_px,c_py,duration,linear,max_growth_rate,least_stable_hz,verdict,tangential_hz,normal_hz,growth_rate_vx_p,growth_rate_vx_d,stick_fraction,reversals,sticks,tangential_zero,agree,squeal_coordinate,squeal_frequency_hz,squeal_level_db,separations,valid,erp_db,spl_dba";

/// `table.csv`: one row per set (its parameters, linear and measured
/// answers), the same bytes from `reproduce`, `merge` and Python.
pub fn table_csv(rs: &[SetResult]) -> String {
    let mut t = String::from(TABLE_HEADER);
    t.push('\n');
    for r in rs {
        let q = r.sc.description.replace('"', "'");
        let params: Vec<String> = TABLE_PARAMS.iter().map(|k| r.p(k).to_string()).collect();
        let _ = writeln!(
            t,
            "{},\"{}\",{},{},{},{},{},{},{},{},{},{},{:e},{},{},{},{},{},{},{},{},{},{},{}",
            r.id,
            q,
            params.join(","),
            r.sc.duration,
            r.linear_word(),
            r.linear
                .as_ref()
                .map_or(String::new(), |l| format!("{:e}", l.max_growth)),
            r.linear
                .as_ref()
                .map_or(String::new(), |l| format!("{:.2}", l.freq_hz)),
            r.verdict,
            opt(r.f_t, 2),
            opt(r.f_n, 2),
            opt(r.growth_of("vx_p"), 4),
            opt(r.growth_of("vx_d"), 4),
            r.stick_fraction,
            r.events[EventKind::Reverse.index()],
            r.events[EventKind::Stick.index()],
            r.tangential_zero,
            r.agrees().map_or("", |a| if a { "yes" } else { "no" }),
            r.squeal.as_ref().map_or("", |s| s.coordinate.as_str()),
            opt(r.squeal.as_ref().map(|s| s.frequency_hz), 2),
            opt(r.squeal.as_ref().map(|s| s.level_db), 2),
            r.events[EventKind::Separate.index()],
            r.outside().is_none(),
            opt(r.erp_db, 2),
            opt(r.spl_dba, 2),
        );
    }
    t
}

/// `conclusions.json`: each conclusion's `id`, `thesis`, `claim`, `held`,
/// `grade`, `caveat`, `evidence` and `data`.
pub fn conclusions_json(cs: &[Conclusion]) -> Vec<Value> {
    cs.iter()
        .map(|c| json!({ "id": c.id, "thesis": c.thesis, "claim": c.claim, "held": c.grade.held(), "grade": c.grade.as_str(), "caveat": c.caveat, "evidence": c.evidence, "data": c.data }))
        .collect()
}

/// Measure the sets `ids` (indices into `sets`, set `i + 1`) in parallel,
/// calling `after` on each set's run, analysis and answer (the CLI draws
/// Appendix A's pictures there); results in the order of `ids`, whatever
/// the number of threads. Each task takes up to four sets
/// ([`tasks`](crate::run::tasks): fewer when their series would take too
/// much memory together) and runs them together on its core
/// ([`run_many`](crate::run::run_many): the disc–pads as one ensemble, bit
/// for bit their single runs), then analyses each. `progress` counts sets.
pub fn measure_sets<E, F>(
    sets: &[Scenario],
    ids: &[usize],
    after: F,
    progress: &dyn crate::error::Progress,
    cancel: &Cancel,
) -> Vec<Result<SetResult, E>>
where
    E: From<StudyError> + Send,
    F: Fn(usize, &Run, &Analysis, &crate::answer::Answer) -> Result<(), E> + Sync,
{
    use rayon::prelude::*;
    let all: Vec<&Scenario> = ids.iter().map(|&i| &sets[i]).collect();
    let results: Vec<Vec<Result<SetResult, E>>> = crate::run::tasks(&all)
        .into_par_iter()
        .map(|task| {
            let chunk = &ids[task.clone()];
            let scs = &all[task];
            let runs = crate::run::run_many(scs, &NoProgress, cancel);
            chunk
                .iter()
                .zip(runs)
                .map(|(&i, run)| {
                    let sc = sets[i].clone();
                    let r = run.map_err(E::from).and_then(|run| {
                        measure_run(i + 1, sc, run, |run, an, answer| {
                            after(i + 1, run, an, answer)
                        })
                    });
                    progress.inc(1);
                    r
                })
                .collect()
        })
        .collect();
    progress.finish();
    results.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bits of every f64 in a result's Debug text agree when the texts do
    /// (Debug prints the shortest round-trip decimal).
    fn same(a: &SetResult, b: &SetResult) -> bool {
        format!("{a:?}") == format!("{b:?}")
    }

    #[test]
    fn a_measured_set_round_trips_bit_for_bit() {
        // Set 1 (no steady sliding) and set 15 (sliding, with modes), short runs.
        let sets = prepared_sets(0.02).unwrap();
        for i in [0usize, 14, 36] {
            let r = measure(i + 1, sets[i].clone(), &Cancel::new(), |_, _, _| {
                Ok::<(), StudyError>(())
            })
            .unwrap();
            let text = serde_json::to_string(&exact::to_json(&r)).unwrap();
            let back: Value = serde_json::from_str(&text).unwrap();
            let b = exact::from_json(&back, sets[i].clone()).unwrap();
            assert!(same(&r, &b), "set {}:\n{r:?}\n{b:?}", i + 1);
        }
    }

    #[test]
    fn awkward_values_round_trip_and_bad_fields_are_named() {
        let sc = prepared_sets(0.02).unwrap().remove(0);
        let r = SetResult {
            id: 1,
            sc: sc.clone(),
            linear: Some(Linear {
                max_growth: -0.0,
                freq_hz: 1.0 / 3.0,
                growing: false,
                neutral: true,
                modes: vec![(f64::MIN_POSITIVE / 4.0, f64::INFINITY, "x_d".into())],
            }),
            linear_note: "n\"ote".into(),
            verdict: "decays".into(),
            f_t: None,
            f_n: Some(f64::NEG_INFINITY),
            growth: vec![("vx_d".into(), 6.02e23)],
            stick_fraction: 0.1 + 0.2,
            events: [1, 2, 3, 4, u64::MAX],
            first_reversal: Some(1e-300),
            vxd_peak: f64::MAX,
            vxd_tail_peak: 0.0,
            vxp_max: 5e-324,
            tangential_zero: true,
            tan_prom_at_fn: None,
            nor_prom_at_ft: Some(-1.5),
            stick: StickStats {
                sticks: 3,
                reversals: 0,
                durations: Some((0.1, 0.2, 0.3)),
            },
            free_fraction: 1.0 - 1e-16,
            squeal: Some(SquealAnswer {
                coordinate: "vx_p".into(),
                frequency_hz: 1234.5678901234,
                level_db: -3.0,
            }),
            normal_power: Some((7.0, 8.0)),
            normal_rate: None,
            erp_db: Some(61.25),
            spl_dba: None,
        };
        let j = exact::to_json(&r);
        let b = exact::from_json(&j, sc.clone()).unwrap();
        assert!(same(&r, &b), "{r:?}\n{b:?}");
        assert_eq!(b.linear.unwrap().max_growth.to_bits(), (-0.0f64).to_bits());
        let mut bad = j.clone();
        bad["vxp_max"] = json!("x");
        assert_eq!(
            exact::from_json(&bad, sc.clone()).unwrap_err(),
            "vxp_max: not a number"
        );
        bad = j;
        bad["events"] = json!([1, 2]);
        assert!(exact::from_json(&bad, sc)
            .unwrap_err()
            .starts_with("events"));
    }

    #[test]
    fn duration_scale_is_checked() {
        for bad in [0.0, -1.0, 10.5, f64::NAN] {
            let e = prepared_sets(bad).unwrap_err().to_string();
            assert!(e.starts_with("--duration-scale"), "{e}");
        }
        let a = prepared_sets(0.5).unwrap();
        let b = crate::scenario::thesis_sets();
        assert_eq!(a.len(), 40);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.duration, y.duration * 0.5);
        }
    }
}

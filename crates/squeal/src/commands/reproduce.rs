//! `squeal reproduce [--out DIR]`: the thesis's study re-done, checked and
//! extended in one command — the 40 parameter sets of Table 11.1
//! (reconstructed, `scenarios/thesis/`), Appendix A's pictures for each set
//! (the disc as the thesis drew it, the pad beside it) plus its eigenvalues,
//! the seven conclusions of docs/physics.md §6 turned into measurable claims,
//! evaluated on this invocation's runs and on the studies of [`squeal_study::study`]
//! (α sweep, c_px sweep, a kick above Uc), each graded `held`, `held
//! qualitatively`, `held by another mechanism`, `refuted` or `outside the
//! model`; runs that leave the model (`lift-off`, `out-of-range`) are flagged
//! and are evidence for nothing. Also a V × N stability map with the sets that
//! share its parameters, and the thesis's numbers confronted (450 Hz, the
//! spectral levels of its Figs. 1–2, its 30–100 kg/s). The report holds no
//! wall-clock time: the same input gives byte-identical files.

use crate::analysis::{self, Analysis};
use crate::run::{self, progress_bar, Run, RunError, Staging};
use clap::Args;
use rayon::prelude::*;
use serde_json::{json, Value};
use squeal_core::stability;
use squeal_core::{EventKind, Model};
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_signal::Spectrum;
use squeal_study::model::AnyModel;
use squeal_study::scenario::{InputError, Scenario, Setting};
use squeal_study::stability::analyse as eigen_analyse;
use squeal_study::study::{self, AboveUc, AlphaSweep, CpxSweep, StickStats};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `squeal reproduce`.
#[derive(Args, Debug)]
pub struct ReproduceArgs {
    /// Output folder.
    #[arg(long, default_value = "out/reproduce")]
    out: PathBuf,
    /// Multiply every set's simulated duration by this factor (e.g. 0.1 for a
    /// quick look; the conclusions need the full durations).
    #[arg(long, default_value_t = 1.0)]
    duration_scale: f64,
    /// Skip the per-set pictures (Appendix A).
    #[arg(long)]
    no_figures: bool,
}

use squeal_study::scenario::thesis_sets;

/// Linear stability of one set (sets at V = 0 have no steady sliding).
#[derive(Debug, Clone)]
struct Linear {
    max_growth: f64,
    freq_hz: f64,
    growing: bool,
    neutral: bool,
    /// (σ, ω, dominant) of every eigenvalue with ω ≥ 0, sorted by σ.
    modes: Vec<(f64, f64, String)>,
}

/// Everything measured on one set.
#[derive(Debug, Clone)]
struct SetResult {
    id: usize,
    sc: Scenario,
    linear: Option<Linear>,
    linear_note: String,
    verdict: String,
    f_t: Option<f64>,
    f_n: Option<f64>,
    growth: Vec<(String, f64)>,
    stick_fraction: f64,
    events: [u64; 5],
    first_reversal: Option<f64>,
    vxd_peak: f64,
    vxd_tail_peak: f64,
    vxp_max: f64,
    tangential_zero: bool,
    /// Prominence (dB) of the tangential spectrum at the normal frequency.
    tan_prom_at_fn: Option<f64>,
    /// Prominence (dB) of the normal spectrum at the disc tangential frequency.
    nor_prom_at_ft: Option<f64>,
    /// True sticks, reversals and stick durations.
    stick: StickStats,
    /// Fraction of the run without contact.
    free_fraction: f64,
    /// The squeal: the coordinate that carries it, its frequency and level.
    squeal: Option<SquealAnswer>,
    /// Squared peak amplitude A² ((m/s)² = J/kg) of the disc's normal velocity
    /// at its spectral peak (flat-top window), and the frequency of that peak.
    normal_power: Option<(f64, f64)>,
    /// Envelope rate (1/s) of the disc's normal velocity at its peak frequency.
    normal_rate: Option<f64>,
}

/// The answer to "does it squeal, at which frequency, how loud".
#[derive(Debug, Clone, PartialEq)]
struct SquealAnswer {
    coordinate: String,
    frequency_hz: f64,
    level_db: f64,
}

impl SetResult {
    fn p(&self, k: &str) -> f64 {
        self.sc.model.get(k).unwrap_or(f64::NAN)
    }
    /// The verdict word when the run left the model's range of validity
    /// (`lift-off`, `out-of-range`): such runs are no evidence for other claims.
    fn outside(&self) -> Option<&str> {
        matches!(self.verdict.as_str(), "lift-off" | "out-of-range")
            .then_some(self.verdict.as_str())
    }
    fn growth_of(&self, s: &str) -> Option<f64> {
        self.growth.iter().find(|(n, _)| n == s).map(|g| g.1)
    }
    fn linear_word(&self) -> &'static str {
        match &self.linear {
            None => "none",
            Some(l) if l.growing => "unstable",
            Some(l) if l.neutral => "neutral",
            Some(_) => "stable",
        }
    }
    /// Do the eigenvalues and the simulation tell the same story?
    fn agrees(&self) -> Option<bool> {
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
fn prominence(s: &Spectrum, f: f64) -> Option<f64> {
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

fn linear_of(model: &AnyModel) -> Result<Linear, String> {
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

/// The squeal of a run, as the analysis answers it.
fn squeal_answer(an: &Analysis) -> Option<SquealAnswer> {
    an.judgement.squeal.as_ref().map(|s| SquealAnswer {
        coordinate: s.coordinate.clone(),
        frequency_hz: s.frequency_hz,
        level_db: s.level_db,
    })
}

fn measure(id: usize, sc: Scenario, figures: Option<&Path>) -> Result<SetResult, RunError> {
    let (linear, linear_note) = match linear_of(&sc.model) {
        Ok(l) => (Some(l), String::new()),
        Err(e) => (None, e),
    };
    let run: Run = squeal_study::run::run(&sc, &squeal_study::NoProgress, &run::NEVER)?;
    let ch = sc.model.channels();
    let an: Analysis = analysis::analyse(
        &run,
        &ch,
        &analysis::SpectrumSettings::default(),
        sc.validity,
        &[],
    );
    if let Some(dir) = figures {
        let d = dir.join(format!("set{id:02}"));
        std::fs::create_dir_all(&d)
            .map_err(|e| RunError::Io(format!("cannot create {}: {e}", d.display())))?;
        analysis::draw(
            &run,
            &an,
            &ch,
            &format!("set {id}"),
            &d,
            &analysis::PlotSettings::default(),
        )?;
    }
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
    Ok(SetResult {
        id,
        linear,
        linear_note,
        verdict: an.verdict.as_str().to_string(),
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
        squeal: squeal_answer(&an),
        normal_power,
        normal_rate,
        sc,
    })
}

/// How far a thesis conclusion survives the runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Grade {
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
    const ALL: [Grade; 5] = [
        Grade::Held,
        Grade::Qualitatively,
        Grade::AnotherMechanism,
        Grade::Refuted,
        Grade::Outside,
    ];
    fn as_str(self) -> &'static str {
        match self {
            Grade::Held => "held",
            Grade::Qualitatively => "held qualitatively",
            Grade::AnotherMechanism => "held by another mechanism",
            Grade::Refuted => "refuted",
            Grade::Outside => "outside the model",
        }
    }
    fn meaning(self) -> &'static str {
        match self {
            Grade::Held => "the claim holds as stated, with the numbers the thesis gave or implied",
            Grade::Qualitatively => "the trend the thesis describes holds, but a number or magnitude it gave is wrong",
            Grade::AnotherMechanism => "what the thesis observed happens, but the runs show a different cause than the one it named",
            Grade::Refuted => "the runs contradict the claim",
            Grade::Outside => "the runs the claim rests on leave the model's range of validity, so the model cannot judge it",
        }
    }
    /// `held` in conclusions.json: every grade that keeps the observation.
    fn held(self) -> bool {
        matches!(
            self,
            Grade::Held | Grade::Qualitatively | Grade::AnotherMechanism
        )
    }
}

/// One conclusion, evaluated.
#[derive(Debug, Clone)]
struct Conclusion {
    id: usize,
    thesis: &'static str,
    claim: String,
    grade: Grade,
    /// One line for the headline: why this grade.
    caveat: String,
    evidence: String,
    /// The evidence's numbers, machine-readable (conclusions.json `data`).
    data: Value,
}

/// The sets of `v` for which `keep` holds.
fn pick<'a>(v: &[&'a SetResult], keep: impl Fn(&SetResult) -> bool) -> Vec<&'a SetResult> {
    v.iter().copied().filter(|r| keep(r)).collect()
}

fn ids(v: &[&SetResult]) -> String {
    let list: Vec<String> = v.iter().map(|r| r.id.to_string()).collect();
    if list.is_empty() {
        "none".into()
    } else {
        list.join(", ")
    }
}

fn db(x: f64) -> f64 {
    20.0 * x.max(1e-300).log10()
}

/// A run squeals when its vibration grows or is sustained (the verdict
/// vocabulary's squealing words; lift-off is outside the model, not evidence).
fn squeals(r: &SetResult) -> bool {
    matches!(r.verdict.as_str(), "grows" | "stick-slip" | "limit-cycle")
}

/// Follower-force sweep: negative α values (log-spaced −1 … −1e5) and positive ones.
const ALPHA_SWEEP: (usize, usize, f64) = (41, 21, -1e5);
/// Pad-damping sweep: c_px as multiples of the pad's Hopf damping c_px*.
const CPX_FACTORS: [f64; 6] = [0.064, 0.3, 0.6, 1.2, 1.5, 2.0];
/// Simulated time of each pad-damping run (s).
const CPX_DURATION: f64 = 0.6;
/// Simulated time of the kicked run above U_c (s).
const KICK_DURATION: f64 = 1.0;

/// Extra computations the conclusions need, linear and simulated.
struct Sweeps {
    /// (points, max σ, at V, at N) over V ∈ (Uc, 3Uc], N ∈ {100, 500, 2000, 5000}, c_dx = c_px = 0.
    above_uc: (usize, f64, f64, f64),
    /// Max σ just below Uc (V = 0.9 Uc, N = 500, default damping).
    below_uc: f64,
    /// Critical common tangential damping c (c_dx = c_px = c) at N = 500 and N = 2000, V = 1.
    c_crit: (Option<f64>, Option<f64>),
    /// The destabilising term −F_y*·μ′(V) of the model at N = 500 and N = 2000, V = 1 (kg/s).
    destab: (f64, f64),
    /// The follower-force sweep.
    alpha: Option<AlphaSweep>,
    /// The pad-damping sweep.
    cpx: CpxSweep,
    /// The kicked run above U_c, and its verdict.
    kicked: AboveUc,
    kicked_verdict: String,
}

fn sweeps(set15: &Scenario) -> Result<Sweeps, RunError> {
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
        || study::cpx_sweep(set15, &CPX_FACTORS, CPX_DURATION, &run::NEVER),
        || study::above_uc(set15, KICK_DURATION, &run::NEVER),
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
fn ns(t: f64) -> String {
    let x = t * 1e9;
    if x < 10.0 {
        format!("{x:.3} ns")
    } else {
        format!("{x:.0} ns")
    }
}

fn thr(x: Option<f64>) -> String {
    x.map_or("beyond the sweep".into(), |a| format!("{a:.0}"))
}

fn conclusions(rs: &[SetResult], sw: &Sweeps) -> Vec<Conclusion> {
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

fn opt(x: Option<f64>, prec: usize) -> String {
    x.filter(|v| v.is_finite())
        .map_or(String::new(), |v| format!("{v:.prec$}"))
}

/// The parameters the table shows for every set (the ones the sets vary).
const TABLE_PARAMS: [&str; 8] = ["V", "N", "f1", "alpha", "c_dx", "c_dy", "c_px", "c_py"];

const TABLE_HEADER: &str = "set,question,V,N,f1,alpha,c_dx,c_dy,c_px,c_py,duration,linear,max_growth_rate,least_stable_hz,verdict,tangential_hz,normal_hz,growth_rate_vx_p,growth_rate_vx_d,stick_fraction,reversals,sticks,tangential_zero,agree,squeal_coordinate,squeal_frequency_hz,squeal_level_db,separations,valid";

fn table_csv(rs: &[SetResult]) -> String {
    let mut t = String::from(TABLE_HEADER);
    t.push('\n');
    for r in rs {
        let q = r.sc.description.replace('"', "'");
        let params: Vec<String> = TABLE_PARAMS.iter().map(|k| r.p(k).to_string()).collect();
        let _ = writeln!(
            t,
            "{},\"{}\",{},{},{},{},{},{},{},{},{},{},{:e},{},{},{},{},{},{},{},{},{}",
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
        );
    }
    t
}

/// "0.5 s (sets 1–14), 1 s (…)": the durations used, grouped.
fn durations(rs: &[SetResult]) -> String {
    let mut groups: Vec<(f64, Vec<usize>)> = Vec::new();
    for r in rs {
        match groups.iter_mut().find(|g| g.0 == r.sc.duration) {
            Some(g) => g.1.push(r.id),
            None => groups.push((r.sc.duration, vec![r.id])),
        }
    }
    groups
        .iter()
        .map(|(d, v)| {
            let list: Vec<String> = v.iter().map(|i| i.to_string()).collect();
            format!("{d} s (sets {})", list.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// "3 held, 2 held qualitatively, …": the grades that occur, in order.
fn grade_counts(cs: &[Conclusion]) -> String {
    Grade::ALL
        .iter()
        .filter_map(|g| {
            let n = cs.iter().filter(|c| c.grade == *g).count();
            (n > 0).then(|| format!("{n} {}", g.as_str()))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The verdict words of the simulated runs and what each means.
const VERDICT_WORDS: [(&str, &str); 8] = [
    ("decays", "the vibration dies away"),
    ("grows", "the vibration is still growing when the run ends"),
    ("limit-cycle", "a bounded, sustained, smooth oscillation (no friction events keep it bounded)"),
    ("stick-slip", "a sustained cycle bounded by friction events: true sticks and/or slip reversals (counted separately in the table)"),
    ("neutral", "an undamped linear oscillation that neither grows nor decays"),
    ("lift-off", "the pad loses contact with the disc repeatedly; the run is outside the model's range of validity"),
    ("out-of-range", "the run leaves the model's range of validity (displacements far beyond what a lumped linear-elastic model means)"),
    ("too-short", "the run is too short to tell growth from decay"),
];

/// The window length T over which the mean of `exp(2·rate·t)`, t ∈ [0, T],
/// equals `ratio` (< 1, rate < 0): how long a power average of a decaying
/// tone must be to lose that much against an undamped one.
fn window_for_ratio(rate: f64, ratio: f64) -> Option<f64> {
    if !(rate < 0.0 && ratio > 0.0 && ratio < 1.0) {
        return None;
    }
    let mean = |t: f64| {
        let x = -2.0 * rate * t;
        (1.0 - (-x).exp()) / x
    };
    let (mut lo, mut hi) = (1e-9f64, 1e3f64);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if mean(mid) > ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

fn report_md(
    rs: &[SetResult],
    cs: &[Conclusion],
    sw: &Sweeps,
    scale: f64,
    figures: bool,
    map_note: &str,
) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "# The thesis re-done: Table 11.1, Appendix A and its conclusions\n"
    );
    let _ = writeln!(
        m,
        "Produced by `squeal reproduce`. The 40 parameter sets reconstruct Table 11.1 of V. Milovs, \
         *Computer Simulation of Automotive Disc Brake Noise* (its numbers were lost to OCR; see docs/physics.md §2 and §6, and \
         `scenarios/thesis/`). Every run starts from rest with N applied as a step at t = 0, as the thesis did. The integrator \
         (DOP853 with per-state tolerances) locates every stick, slip, slip reversal, separation and recontact in time on its \
         dense output instead of smoothing the friction law or stepping over the switches. Simulated durations: {}{}: \
         long enough for the pad to reach its reversal cycle where it grows fast, shorter where nothing grows. \
         Every number below was computed by this invocation.\n",
        durations(rs),
        if scale != 1.0 { format!(" (the shipped durations scaled by {scale})") } else { String::new() }
    );
    let _ = writeln!(m, "## Conclusions: {}\n", grade_counts(cs));
    for c in cs {
        let _ = writeln!(
            m,
            "{}. **{}** — {} *({})*\n",
            c.id,
            c.grade.as_str(),
            c.thesis,
            c.caveat
        );
    }
    let _ = writeln!(m, "### What the words mean\n");
    let _ = writeln!(m, "Grades of the conclusions:\n");
    for g in Grade::ALL {
        let _ = writeln!(m, "- **{}**: {}.", g.as_str(), g.meaning());
    }
    let _ = writeln!(
        m,
        "\nVerdicts of the simulated runs (table column *verdict*):\n"
    );
    for (w, d) in VERDICT_WORDS {
        let _ = writeln!(m, "- **{w}**: {d}.");
    }
    let _ = writeln!(
        m,
        "\nLinear verdicts (column *linear*), from the eigenvalues of steady sliding: **unstable** (some mode's growth rate σ > 0), \
         **stable** (every σ < 0), **neutral** (no mode grows and some σ is zero within round-off), **none** (no steady sliding: V = 0, \
         or a follower force past the limit). A *reversal* is a zero of the sliding velocity v at which the pad cannot stick and \
         slips the other way; a *stick* is a true stick (v ≡ 0 for a while). The *squeal* of a run is the coordinate that carries \
         its sustained or growing vibration, with that vibration's frequency and level (velocity RMS in dB re 1 m/s); runs outside \
         the model (lift-off, out-of-range) are marked ⚠ and are evidence for no conclusion.\n"
    );
    let _ = writeln!(m, "## The conclusions in detail\n");
    for c in cs {
        let _ = writeln!(
            m,
            "**{}. {}** — **{}**\n\n*Claim:* {}\n\n*Evidence:* {}\n",
            c.id,
            c.thesis,
            c.grade.as_str(),
            c.claim,
            c.evidence
        );
    }
    squeal_section(&mut m, rs);
    alpha_section(&mut m, sw);
    cpx_section(&mut m, sw);
    frequency_section(&mut m, rs);
    levels_section(&mut m, rs);
    let dis: Vec<&SetResult> = rs.iter().filter(|r| r.agrees() == Some(false)).collect();
    let _ = writeln!(m, "## Eigenvalues against simulation\n");
    let _ = writeln!(
        m,
        "The thesis judged stability from runs alone. For every sliding set the eigenvalues of the steady-sliding \
         state (docs/physics.md §5) give a linear verdict; it agrees with the simulated outcome in {} of {} sets{}. Where they \
         differ: {}.\n",
        rs.iter().filter(|r| r.agrees() == Some(true)).count(),
        rs.iter().filter(|r| r.agrees().is_some()).count(),
        {
            let out: Vec<String> = rs
                .iter()
                .filter(|r| r.p("V") > 0.0 && r.agrees().is_none())
                .map(|r| format!("{} ({})", r.id, r.verdict))
                .collect();
            if out.is_empty() {
                String::new()
            } else {
                format!(
                    " (not compared: sets {} — contact loss or a run outside the model's validity is beyond what a \
                     linearisation about steady sliding describes, and a run too short to tell has no outcome)",
                    out.join(", ")
                )
            }
        },
        if dis.is_empty() {
            "nowhere".to_string()
        } else {
            dis.iter()
                .map(|r| {
                    let l = r.linear.as_ref();
                    let growth_time = l.map(|l| r.sc.duration * l.max_growth).filter(|g| g.abs() < 1.0);
                    format!(
                        "set {} (linear {}, σ_max {}, simulated {}{})",
                        r.id,
                        r.linear_word(),
                        l.map_or("n/a".into(), |l| format!("{:+.3e}", l.max_growth)),
                        r.verdict,
                        growth_time.map_or(String::new(), |g| {
                            format!("; σ·T = {g:+.3}: the run is too short to see that much growth or decay")
                        }) + &{
                            let sep = r.events[EventKind::Separate.index()];
                            if sep > 0 {
                                format!("; the pad lifts off the disc {sep} times: contact loss, which the linearisation about steady sliding cannot see, decides the outcome")
                            } else {
                                String::new()
                            }
                        }
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
        }
    );
    let _ = writeln!(m, "![V × N stability map](map.png)\n");
    let _ = writeln!(m, "{map_note}\n");
    let _ = writeln!(m, "## Table 11.1, reconstructed, with results\n");
    let _ = writeln!(
        m,
        "| set | question | V | N | f1 | α | c_dx | c_dy | c_px | c_py | linear | σ_max (1/s) | verdict | squeal | f_t (Hz) | f_n (Hz) | σ fit pad (1/s) | sticks | reversals |"
    );
    let _ = writeln!(
        m,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in rs {
        let params: Vec<String> = TABLE_PARAMS
            .iter()
            .map(|k| {
                if *k == "f1" {
                    format!("{:.4}", r.p(k))
                } else {
                    r.p(k).to_string()
                }
            })
            .collect();
        let _ = writeln!(
            m,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.id,
            r.sc.description,
            params.join(" | "),
            r.linear_word(),
            r.linear
                .as_ref()
                .map_or("—".into(), |l| format!("{:+.3}", l.max_growth)),
            match r.outside() {
                Some(v) => format!("⚠ {v} (outside the model)"),
                None => r.verdict.clone(),
            },
            squeal_cell(r),
            opt(r.f_t, 1),
            opt(r.f_n, 1),
            opt(r.growth_of("vx_p"), 3),
            r.events[EventKind::Stick.index()],
            r.events[EventKind::Reverse.index()],
        );
    }
    let _ = writeln!(m, "\n## Appendix A, regenerated\n");
    for r in rs {
        let _ = writeln!(m, "### Set {}: {}\n", r.id, r.sc.description);
        match &r.linear {
            Some(l) => {
                let modes: Vec<String> = l
                    .modes
                    .iter()
                    .map(|(s, w, d)| {
                        format!(
                            "{:.1} Hz ({d}) σ = {s:+.3}",
                            w / (2.0 * std::f64::consts::PI)
                        )
                    })
                    .collect();
                let _ = writeln!(
                    m,
                    "Eigenvalues: {}. Linear verdict: {}.\n",
                    modes.join("; "),
                    r.linear_word()
                );
            }
            None => {
                let _ = writeln!(m, "No eigenvalues: {}.\n", r.linear_note);
            }
        }
        let _ = writeln!(
            m,
            "Simulated: {}{}; squeal: {}; {} reversals, {} sticks, {} separations.\n",
            r.verdict,
            if r.tangential_zero {
                " (tangential motion identically zero)"
            } else {
                ""
            },
            squeal_cell(r),
            r.events[EventKind::Reverse.index()],
            r.events[EventKind::Stick.index()],
            r.events[EventKind::Separate.index()]
        );
        if figures {
            let _ = writeln!(
                m,
                "![set {0}: disc and pad velocities and their spectra](figures/set{0:02}/triplet.png)\n",
                r.id
            );
        }
    }
    m
}

/// "pad tangential (x_p) 20751.3 Hz, −3.0 dB" or "none".
fn squeal_cell(r: &SetResult) -> String {
    match &r.squeal {
        Some(s) => format!(
            "{} {:.1} Hz, {:.1} dB",
            s.coordinate, s.frequency_hz, s.level_db
        ),
        None => "none".into(),
    }
}

fn squeal_section(m: &mut String, rs: &[SetResult]) {
    let _ = writeln!(m, "## Does it squeal, and at which frequency?\n");
    let loud: Vec<&SetResult> = rs
        .iter()
        .filter(|r| r.squeal.is_some() && r.outside().is_none())
        .collect();
    let _ = writeln!(
        m,
        "The squeal is read from every coordinate, not only the disc's (the thesis plotted disc velocities only). \
         Sets that squeal: {}. The others do not squeal{}. The frequency is that of the coordinate that carries the \
         vibration; in the default brake it is the pad's tangential mode, not the disc's 5 kHz mode, whose transient \
         dominates the disc's own spectrum before it collapses.\n",
        if loud.is_empty() {
            "none".to_string()
        } else {
            loud.iter()
                .map(|r| format!("{} ({})", r.id, squeal_cell(r)))
                .collect::<Vec<_>>()
                .join(", ")
        },
        {
            let out: Vec<String> = rs
                .iter()
                .filter(|r| r.outside().is_some())
                .map(|r| format!("{} ({})", r.id, r.verdict))
                .collect();
            if out.is_empty() {
                String::new()
            } else {
                format!(
                    ", or left the model so that no answer is meaningful: sets {}",
                    out.join(", ")
                )
            }
        }
    );
}

fn alpha_section(m: &mut String, sw: &Sweeps) {
    let Some(a) = &sw.alpha else { return };
    let _ = writeln!(
        m,
        "## Conclusion 7 in detail: every mode against the follower force\n"
    );
    let _ = writeln!(
        m,
        "Steady sliding of the default brake (set 15) with α swept over {} log-spaced values from −1 to {:.0e} 1/m and {} \
         from +1 to {:.0e} 1/m; each mode is followed from α = 0 by continuation, and each threshold is the smallest |α| at \
         which the mode's growth rate σ (relative to |σ(0)|) or its frequency has changed by 1 % or 10 %, refined between \
         sweep points. Steady sliding ends at α = {:.4e} 1/m.\n",
        a.n_neg, a.alpha_end, a.n_pos, -a.alpha_end, a.limit
    );
    let _ = writeln!(
        m,
        "| mode | f (Hz) | σ (1/s) | σ ±1 % at \\|α\\| | σ ±10 % at \\|α\\| | σ ±1 % at α > 0 | f ±1 % at \\|α\\| | f ±10 % at \\|α\\| | f ±1 % at α > 0 | σ at α = {:.0e} | f at α = {:.0e} (Hz) |",
        a.alpha_end, a.alpha_end
    );
    let _ = writeln!(m, "|---|---|---|---|---|---|---|---|---|---|---|");
    for md in &a.modes {
        let _ = writeln!(
            m,
            "| {} | {:.1} | {:+.4} | {} | {} | {} | {} | {} | {} | {:+.3} | {:.1} |",
            md.name,
            md.freq0,
            md.sigma0,
            thr(md.sigma_at[0]),
            thr(md.sigma_at[1]),
            thr(md.sigma_at_pos[0]),
            thr(md.freq_at[0]),
            thr(md.freq_at[1]),
            thr(md.freq_at_pos[0]),
            md.at_end.0,
            md.at_end.1
        );
    }
    let _ = writeln!(m);
}

fn cpx_section(m: &mut String, sw: &Sweeps) {
    let cp = &sw.cpx;
    let _ = writeln!(m, "## Conclusion 6 in detail: pad damping across c_px*\n");
    let _ = writeln!(
        m,
        "Runs of {} s from steady sliding with the pad kicked to {} m/s and the disc to {} m/s; c_px* = {:.4} kg/s. \
         The disc's envelope is demodulated at its eigenfrequency.\n",
        cp.duration, cp.kick.0, cp.kick.1, cp.c_star
    );
    let _ = writeln!(
        m,
        "| c_px (kg/s) | c_px / c_px* | σ pad (1/s) | σ disc (1/s) | pad saturates at (s) | reversals | disc envelope rate (1/s) |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|---|---|");
    for p in &cp.points {
        let _ = writeln!(
            m,
            "| {:.3} | {:.2} | {:+.3} | {:+.6} | {} | {} | {} |",
            p.c_px,
            p.c_px / cp.c_star,
            p.sigma_pad,
            p.sigma_disc,
            p.saturated_at.map_or("never".into(), |t| format!("{t:.4}")),
            p.reversals,
            p.disc_rate.map_or("n/a".into(), |r| format!("{r:+.3}"))
        );
    }
    let _ = writeln!(m);
}

fn frequency_section(m: &mut String, rs: &[SetResult]) {
    let AnyModel::DiscPad(dp) = rs[14].sc.model else {
        return;
    };
    let p = &dp.p;
    let alone = (p.k_dy / p.m_d).sqrt() / std::f64::consts::TAU;
    let riding = (p.k_dy / (p.m_d + p.m_p)).sqrt() / std::f64::consts::TAU;
    let eig = rs[14]
        .linear
        .as_ref()
        .and_then(|l| l.modes.iter().find(|x| x.2 == "y_d"))
        .map(|x| x.1 / std::f64::consts::TAU);
    let _ = writeln!(
        m,
        "## The normal frequency: 429 Hz against the thesis's \"around 450 Hz\"\n"
    );
    let _ = writeln!(
        m,
        "The thesis's first simulation shows the disc's normal peak \"around 450 Hz\"; its stiffness was lost, so the \
         reconstruction chose k_dy = {:.3e} N/m, which puts the disc *alone* at √(k_dy/m_d)/2π = {alone:.1} Hz. But the pad \
         rides on the disc through a contact layer {:.0} times stiffer than the disc's bending, so the two move as one body \
         of mass m_d + m_p in this mode: √(k_dy/(m_d + m_p))/2π = {riding:.1} Hz, and the exact eigenvalue gives {} Hz; the \
         runs at V = 0 (set 1) peak at {} Hz. The 5 % difference is the pad's mass. Either the thesis quoted the disc's own \
         frequency, or it read its peak coarsely (its FFT length is lost); to put the coupled mode at 450 Hz the \
         reconstruction would need k_dy = {:.3e} N/m.\n",
        p.k_dy,
        p.k_py / p.k_dy,
        eig.map_or("n/a".into(), |f| format!("{f:.2}")),
        opt(rs[0].f_n, 1),
        p.k_dy * (450.0 / riding).powi(2),
    );
}

fn levels_section(m: &mut String, rs: &[SetResult]) {
    let (Some(r1), Some(r2)) = (rs.first(), rs.get(1)) else {
        return;
    };
    let (Some((p1, _)), Some((p2, _)), Some(f1)) = (r1.normal_power, r2.normal_power, r1.f_n)
    else {
        return;
    };
    let thesis: f64 = 0.4 / 0.7;
    let ratio = p2 / p1;
    let _ = writeln!(
        m,
        "## Spectral levels against the thesis's Figures 1 and 2\n"
    );
    let _ = writeln!(
        m,
        "The thesis's analyser plotted the power spectrum of the disc's normal velocity \"in meters per second square units, \
         or Joule per kilogram\" (Ch. 10), i.e. (m/s)² = J/kg, and quotes its peaks: 0.7 J/kg at about 450 Hz for the undamped \
         disc (Fig. 1, set 1) and 0.4 J/kg with c_dy = 10 kg/s (Fig. 2, set 2). The same quantity from squeal — the squared \
         peak amplitude A² of the disc's normal velocity at its spectral peak, flat-top window, averaged over the run's \
         Welch segments — is {p1:.4} J/kg at {f1:.1} Hz for set 1 and {p2:.4} J/kg for set 2 (mean square A²/2: {:.4} and \
         {:.4} J/kg). The absolute levels differ by a factor {:.0} ({:.1} dB): the thesis's normalisation (an FFT length and \
         scaling that were lost; an unnormalised |FFT|² grows with the FFT length) cannot be recovered. Read as A², the \
         thesis's 0.7 J/kg would mean a velocity amplitude of {:.3} m/s; the pad's step load N gives the coupled normal mode \
         an amplitude N/(ω·M), so that would need a moving mass M = {:.3} kg instead of the reconstruction's \
         m_d + m_p = {:.1} kg (the disc's modal mass, itself a reconstruction). Only the ratio is free of the \
         normalisation. The thesis's damped/undamped ratio is 0.4/0.7 = {thesis:.3} ({:.1} dB); squeal's is {ratio:.3} \
         ({:.1} dB) over {} s runs. Set 2's normal vibration decays at {} 1/s, so the ratio depends on how long the \
         analysed window is: a power average from t = 0 over {} reproduces the thesis's ratio.\n",
        p1 / 2.0,
        p2 / 2.0,
        0.7 / p1,
        10.0 * (0.7 / p1).log10(),
        0.7f64.sqrt(),
        r1.p("N") / (std::f64::consts::TAU * f1 * 0.7f64.sqrt()),
        r1.p("m_d") + r1.p("m_p"),
        10.0 * thesis.log10(),
        10.0 * ratio.log10(),
        r2.sc.duration,
        opt(r2.normal_rate, 3),
        r2.normal_rate
            .and_then(|r| window_for_ratio(r, thesis))
            .map_or("no window".into(), |t| format!("{:.3} s", t)),
    );
}

/// A minimal Markdown → HTML rendering of the report: headings, paragraphs,
/// tables and images are all it uses.
fn report_html(md: &str) -> String {
    fn esc(s: &str) -> String {
        s.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
    }
    /// `code`, **bold** and *italic*; a `*` counts as emphasis only at a word
    /// boundary (so `F_t*` stays a star) and open tags close at the line's end.
    fn inline(s: &str) -> String {
        let chars: Vec<char> = esc(s).chars().collect();
        let at = |i: usize| chars.get(i).copied();
        let opens = |i: usize, len: usize| {
            (i == 0 || at(i - 1).is_some_and(|c| c.is_whitespace() || c == '('))
                && at(i + len).is_some_and(|c| !c.is_whitespace())
        };
        let closes = |i: usize| i > 0 && at(i - 1).is_some_and(|c| !c.is_whitespace());
        let (mut out, mut bold, mut ital, mut code) = (String::new(), false, false, false);
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            if c == '`' {
                out.push_str(if code { "</code>" } else { "<code>" });
                code = !code;
            } else if !code
                && c == '*'
                && at(i + 1) == Some('*')
                && (if bold { closes(i) } else { opens(i, 2) })
            {
                out.push_str(if bold { "</strong>" } else { "<strong>" });
                bold = !bold;
                i += 1;
            } else if !code && c == '*' && (if ital { closes(i) } else { opens(i, 1) }) {
                out.push_str(if ital { "</em>" } else { "<em>" });
                ital = !ital;
            } else {
                out.push(c);
            }
            i += 1;
        }
        for (open, tag) in [(ital, "</em>"), (bold, "</strong>"), (code, "</code>")] {
            if open {
                out.push_str(tag);
            }
        }
        out
    }
    let mut h = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>squeal: the thesis re-done</title>\n<style>body{font-family:sans-serif;max-width:75em;margin:2em auto;padding:0 1em;line-height:1.45}table{border-collapse:collapse;font-size:85%}td,th{border:1px solid #ccc;padding:2px 6px}img{max-width:100%}code{background:#f4f4f4}</style></head><body>\n",
    );
    let (mut in_table, mut in_list) = (false, false);
    for line in md.lines() {
        if line.starts_with('|') {
            if line.starts_with("|---") {
                continue;
            }
            if !in_table {
                h.push_str("<table>\n");
                in_table = true;
            }
            let cells: Vec<&str> = line.trim_matches('|').split(" | ").collect();
            h.push_str("<tr>");
            for c in cells {
                let _ = write!(h, "<td>{}</td>", inline(&c.trim().replace("\\|", "|")));
            }
            h.push_str("</tr>\n");
            continue;
        } else if in_table {
            h.push_str("</table>\n");
            in_table = false;
        }
        if let Some(item) = line.strip_prefix("- ") {
            if !in_list {
                h.push_str("<ul>\n");
                in_list = true;
            }
            let _ = writeln!(h, "<li>{}</li>", inline(item));
            continue;
        } else if in_list {
            h.push_str("</ul>\n");
            in_list = false;
        }
        if let Some(t) = line.strip_prefix("### ") {
            let _ = writeln!(h, "<h3>{}</h3>", inline(t));
        } else if let Some(t) = line.strip_prefix("## ") {
            let _ = writeln!(h, "<h2>{}</h2>", inline(t));
        } else if let Some(t) = line.strip_prefix("# ") {
            let _ = writeln!(h, "<h1>{}</h1>", inline(t));
        } else if line.starts_with("![") {
            // One or more images on a line: side by side.
            let imgs: Vec<(&str, &str)> = line
                .split("![")
                .filter_map(|part| {
                    let (alt, rest) = part.split_once("](")?;
                    Some((alt, rest.split_once(')')?.0))
                })
                .collect();
            let width = if imgs.len() > 1 {
                " style=\"max-width:49%\""
            } else {
                ""
            };
            h.push_str("<p>");
            for (alt, src) in imgs {
                let _ = write!(h, "<img alt=\"{}\" src=\"{}\"{width}>", esc(alt), esc(src));
            }
            h.push_str("</p>\n");
        } else if !line.trim().is_empty() {
            let _ = writeln!(h, "<p>{}</p>", inline(line));
        }
    }
    if in_table {
        h.push_str("</table>\n");
    }
    if in_list {
        h.push_str("</ul>\n");
    }
    h.push_str("</body></html>\n");
    h
}

/// The sets the V × N map can show: sliding sets whose every other
/// parameter is the map's (the disc–pad defaults).
fn on_map<'a>(rs: &'a [SetResult], base: &AnyModel) -> Vec<&'a SetResult> {
    rs.iter()
        .filter(|r| {
            let mut m = r.sc.model.clone();
            r.p("V") > 0.0
                && m.set("V", base.get("V").unwrap_or(f64::NAN)).is_ok()
                && m.set("N", base.get("N").unwrap_or(f64::NAN)).is_ok()
                && m == *base
        })
        .collect()
}

/// Draw the V × N map with the sets that share its other parameters, and
/// say in words which sets it shows and which it leaves out.
fn draw_map(rs: &[SetResult], dir: &Path) -> Result<String, RunError> {
    let base = AnyModel::by_name("disc-pad").expect("built-in model");
    let shown = on_map(rs, &base);
    let left_out: Vec<&SetResult> = rs
        .iter()
        .filter(|r| r.p("V") > 0.0 && !shown.iter().any(|s| s.id == r.id))
        .collect();
    let note = format!(
        "The map shows the largest growth rate of steady sliding over V × N with every other parameter at its default \
         (the default damping, f1 = 1/15, α = 0); the black line is σ = 0. Only the sets that share those parameters are \
         marked, at their (V, N): {}. The other sliding sets differ in damping, f1 or α, so this map's colours do not \
         describe them; their linear verdicts are in the table (sets {}). Sets 1–5 (V = 0) have no steady sliding.",
        ids(&shown),
        ids(&left_out)
    );
    let xs: Vec<f64> = (0..160).map(|i| 0.25 + 24.75 * i as f64 / 159.0).collect();
    let ys: Vec<f64> = (0..120).map(|j| 50.0 + 2950.0 * j as f64 / 119.0).collect();
    let vals: Vec<f64> = (0..xs.len() * ys.len())
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % xs.len(), k / xs.len());
            let mut m = base.clone();
            if m.set("V", xs[i]).and(m.set("N", ys[j])).is_err() {
                return f64::NAN;
            }
            m.max_growth_rate().map(|r| r.0).unwrap_or(f64::NAN)
        })
        .collect();
    // Group the sets by position so that coincident sets share one label.
    let mut spots: Vec<(f64, f64, Vec<usize>)> = Vec::new();
    for r in &shown {
        let (v, n) = (r.p("V"), r.p("N"));
        match spots.iter_mut().find(|s| s.0 == v && s.1 == n) {
            Some(s) => s.2.push(r.id),
            None => spots.push((v, n, vec![r.id])),
        }
    }
    let labels: Vec<String> = spots
        .iter()
        .map(|s| {
            s.2.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    let markers: Vec<(f64, f64, &str)> = spots
        .iter()
        .zip(&labels)
        .map(|(s, l)| (s.0, s.1, l.as_str()))
        .collect();
    let spec = HeatmapSpec {
        colormap: Colormap::Diverging,
        contour_zero: true,
        markers: &markers,
        value_range: crate::commands::map::robust_range(&vals),
        nan_label: "no steady sliding",
        ..HeatmapSpec::new(
            "Steady sliding at the defaults, with the sets that share them",
            "V (m/s)",
            "N (N)",
            "max growth rate σ (1/s)",
            &xs,
            &ys,
            &vals,
        )
    };
    squeal_plot::heatmap(
        dir.join("map"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &spec,
    )
    .map_err(|e| RunError::Io(format!("drawing failed: {e}")))?;
    Ok(note)
}

/// Run the command.
pub fn run(a: ReproduceArgs) -> Result<(), RunError> {
    if !(a.duration_scale.is_finite() && a.duration_scale > 0.0 && a.duration_scale <= 10.0) {
        return Err(InputError(format!(
            "--duration-scale {}: must be in (0, 10]",
            a.duration_scale
        ))
        .into());
    }
    let start = Instant::now();
    let mut sets = thesis_sets();
    for s in &mut sets {
        let d = s.duration * a.duration_scale;
        s.apply("duration", &Setting::Number(d))?;
        squeal_study::feasible::prepare(s)?;
    }
    let stage = Staging::new(&a.out)?;
    let figures = stage.dir().join("figures");
    let pb = progress_bar(sets.len() as u64, "reproducing the thesis");
    let results: Vec<Result<SetResult, RunError>> = sets
        .into_par_iter()
        .enumerate()
        .map(|(i, sc)| {
            let r = measure(i + 1, sc, (!a.no_figures).then_some(figures.as_path()));
            squeal_study::Progress::inc(&pb, 1);
            r
        })
        .collect();
    squeal_study::Progress::finish(&pb);
    let mut rs = Vec::new();
    for (i, r) in results.into_iter().enumerate() {
        rs.push(r.map_err(|e| RunError::Numerical(format!("set {}: {e}", i + 1)))?);
    }
    let sw = sweeps(&rs[14].sc)?;
    let cs = conclusions(&rs, &sw);
    let map_note = draw_map(&rs, stage.dir())?;
    let wall = start.elapsed().as_secs_f64();
    let write = |name: &str, text: &str| {
        let p = stage.path(name);
        std::fs::write(&p, text)
            .map_err(|e| RunError::Io(format!("cannot write {}: {e}", p.display())))
    };
    write("table.csv", &table_csv(&rs))?;
    let cj: Vec<Value> = cs
        .iter()
        .map(|c| json!({ "id": c.id, "thesis": c.thesis, "claim": c.claim, "held": c.grade.held(), "grade": c.grade.as_str(), "caveat": c.caveat, "evidence": c.evidence, "data": c.data }))
        .collect();
    write(
        "conclusions.json",
        &(serde_json::to_string_pretty(&cj).map_err(|e| RunError::Io(e.to_string()))? + "\n"),
    )?;
    let md = report_md(&rs, &cs, &sw, a.duration_scale, !a.no_figures, &map_note);
    write("report.md", &md)?;
    write("report.html", &report_html(&md))?;
    let dest = stage.commit()?;
    crate::outln!("reproduced 40 sets in {wall:.1} s: {}", grade_counts(&cs));
    for c in &cs {
        crate::outln!("  {}. {:<26} {}", c.id, c.grade.as_str(), c.thesis);
    }
    crate::outln!("report: {}", dest.join("report.html").display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn html_emphasis_stays_balanced() {
        let h = report_html("**1. Claim** — *Evidence:* the terms α·F_t* ≈ α·μ·N, `a*b` and 2 * 3.\n\n| a | b |\n|---|---|\n| 1 | 2 |\n");
        assert!(h.contains("<strong>1. Claim</strong>"), "{h}");
        assert!(h.contains("<em>Evidence:</em>"), "{h}");
        assert!(
            h.contains("F_t* ≈") && h.contains("<code>a*b</code>") && h.contains("2 * 3"),
            "{h}"
        );
        assert_eq!(h.matches("<em>").count(), h.matches("</em>").count());
        assert!(h.contains("<table>") && h.contains("<td>1</td>"));
        let list = report_html("- **held**: as stated.\n- **refuted**: no.\n\nafter\n");
        assert!(
            list.contains("<ul>\n<li><strong>held</strong>: as stated.</li>\n<li><strong>refuted</strong>: no.</li>\n</ul>\n<p>after</p>"),
            "{list}"
        );
        let esc = report_html("| σ at \\|α\\| | x |\n|---|---|\n");
        assert!(esc.contains("<td>σ at |α|</td>"), "{esc}");
        let two = report_html("![disc](a/triplet.png) ![pad](a/pad.png)\n");
        assert_eq!(
            two,
            report_html("")
                .replace("</body>", "<p><img alt=\"disc\" src=\"a/triplet.png\" style=\"max-width:49%\"><img alt=\"pad\" src=\"a/pad.png\" style=\"max-width:49%\"></p>\n</body>")
        );
    }

    #[test]
    fn grades_and_power_window() {
        assert!(Grade::Qualitatively.held() && Grade::AnotherMechanism.held());
        assert!(!Grade::Refuted.held() && !Grade::Outside.held());
        // mean of exp(2·rate·t) over [0, T] = ratio: check by the closed form.
        let t = window_for_ratio(-4.5, 0.5).unwrap();
        let x = 9.0 * t;
        assert!(((1.0 - (-x).exp()) / x - 0.5).abs() < 1e-9, "{t}");
        assert!(window_for_ratio(1.0, 0.5).is_none());
    }
}

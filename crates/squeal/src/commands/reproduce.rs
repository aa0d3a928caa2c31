//! `squeal reproduce [--out DIR]`: the thesis's study re-done, checked and
//! extended in one command — the 40 parameter sets of Table 11.1
//! (reconstructed, `scenarios/thesis/`), Appendix A's pictures for each set
//! plus its eigenvalues, the seven conclusions of MODEL.md §6 turned into
//! measurable claims and evaluated on this invocation's runs, and a V × N
//! stability map with the sets marked.

use crate::analysis::{self, Analysis};
use crate::commands::stability::analyse as eigen_analyse;
use crate::model::AnyModel;
use crate::run::{self, progress_bar, Run, RunError, Staging};
use crate::scenario::{InputError, Scenario, Setting};
use clap::Args;
use rayon::prelude::*;
use serde_json::{json, Value};
use squeal_core::stability::{self, NEUTRAL_TOL};
use squeal_core::EventKind;
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_signal::Spectrum;
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

use crate::scenario::thesis_sets;

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
}

impl SetResult {
    fn p(&self, k: &str) -> f64 {
        self.sc.model.get(k).unwrap_or(f64::NAN)
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
        match word {
            "none" => None,
            "unstable" => Some(v == "grows" || v == "stick-slip"),
            "stable" => Some(v == "decays"),
            _ => Some(v == "limit-cycle" || v == "decays"),
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
    let neutral = !an.eigen.iter().any(|e| e.growing)
        && an
            .eigen
            .iter()
            .any(|e| e.re.abs() <= NEUTRAL_TOL * e.re.hypot(e.im));
    Ok(Linear {
        max_growth: an.max_growth_rate,
        freq_hz: ls.freq_hz,
        growing: !an.stable,
        neutral,
        modes: an
            .eigen
            .iter()
            .filter(|e| e.im >= 0.0)
            .map(|e| (e.re, e.im, e.dominant_name.clone()))
            .collect(),
    })
}

fn measure(id: usize, sc: Scenario, figures: Option<&Path>) -> Result<SetResult, RunError> {
    let (linear, linear_note) = match linear_of(&sc.model) {
        Ok(l) => (Some(l), String::new()),
        Err(e) => (None, e),
    };
    let run: Run = run::run_with(&sc, &indicatif::ProgressBar::hidden())?;
    let ch = sc.model.channels();
    let an: Analysis = analysis::analyse(&run, &ch, &analysis::SpectrumSettings::default());
    if let Some(dir) = figures {
        let d = dir.join(format!("set{id:02}"));
        std::fs::create_dir_all(&d)
            .map_err(|e| RunError::Io(format!("cannot create {}: {e}", d.display())))?;
        analysis::draw(&run, &an, &ch, &format!("set {id}"), &d)?;
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
        sc,
    })
}

/// One conclusion, evaluated.
#[derive(Debug, Clone)]
struct Conclusion {
    id: usize,
    thesis: &'static str,
    claim: String,
    held: bool,
    evidence: String,
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

/// Extra linear computations the conclusions need.
struct Sweeps {
    /// (points, max σ, at V, at N) over V ∈ (Uc, 3Uc], N ∈ {100, 500, 2000, 5000}, c_dx = c_px = 0.
    above_uc: (usize, f64, f64, f64),
    /// Max σ just below Uc (V = 0.9 Uc, N = 500, default damping).
    below_uc: f64,
    /// Critical common tangential damping c (c_dx = c_px = c) at N = 500 and N = 2000, V = 1.
    c_crit: (Option<f64>, Option<f64>),
    /// Largest relative eigenvalue shift from α = 0 at α = −10 and α = −1e5.
    alpha_shift: (f64, f64),
}

fn sweeps(base: &AnyModel) -> Sweeps {
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
    let crit = |n: f64| {
        let mut m = base.clone();
        m.set("N", n).ok()?;
        m.set("V", 1.0).ok()?;
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
    let shift = |alpha: f64| -> f64 {
        let mut m = base.clone();
        let _ = m.set("alpha", alpha);
        let (a0, a1) = (eigen_analyse(base), eigen_analyse(&m));
        match (a0, a1) {
            (Ok(a0), Ok(a1)) => {
                let mut l0: Vec<(f64, f64)> = a0.eigen.iter().map(|e| (e.re, e.im)).collect();
                let mut l1: Vec<(f64, f64)> = a1.eigen.iter().map(|e| (e.re, e.im)).collect();
                l0.sort_by(|a, b| a.1.total_cmp(&b.1));
                l1.sort_by(|a, b| a.1.total_cmp(&b.1));
                l0.iter()
                    .zip(&l1)
                    .map(|(a, b)| (a.0 - b.0).hypot(a.1 - b.1) / a.0.hypot(a.1))
                    .fold(0.0, f64::max)
            }
            _ => f64::NAN,
        }
    };
    Sweeps {
        above_uc: worst,
        below_uc: below,
        c_crit: (crit(500.0), crit(2000.0)),
        alpha_shift: (shift(-10.0), shift(-1e5)),
    }
}

fn conclusions(rs: &[SetResult], sw: &Sweeps) -> Vec<Conclusion> {
    let uc = rs[0].sc.model.get("Uc").unwrap_or(50.0 / 3.0);
    let sliding: Vec<&SetResult> = rs.iter().filter(|r| r.p("V") > 0.0).collect();
    let squeals = |r: &SetResult| r.verdict == "grows" || r.verdict == "stick-slip";
    let mut out = Vec::new();

    // 1. Stribeck effect.
    let no_stribeck: Vec<&SetResult> = pick(&sliding, |r| r.p("f1") == 0.0);
    let bad: Vec<&SetResult> = pick(&no_stribeck, |r| {
        r.linear.as_ref().is_some_and(|l| l.growing) || squeals(r)
    });
    let with: Vec<&SetResult> = pick(&sliding, |r| {
        r.p("f1") > 0.0
            && r.p("V") < uc
            && r.linear.as_ref().is_some_and(|l| l.growing)
            && squeals(r)
    });
    let worst = no_stribeck
        .iter()
        .filter_map(|r| r.linear.as_ref().map(|l| (l.max_growth, r.id)))
        .fold((f64::NEG_INFINITY, 0), |a, b| if b.0 > a.0 { b } else { a });
    out.push(Conclusion {
        id: 1,
        thesis: "Unstable tangential oscillations develop through the Stribeck effect.",
        claim: "No sliding run without the Stribeck effect (f1 = 0) has a growing mode or ends growing or in stick-slip, while runs with it (f1 > 0, V < Uc) do.".into(),
        held: !no_stribeck.is_empty() && bad.is_empty() && !with.is_empty(),
        evidence: format!(
            "f1 = 0 sets {}: largest σ_max {:+.3e} 1/s (set {}), growing or squealing: {}; f1 > 0 sets below Uc that are unstable and squeal: {}.",
            ids(&no_stribeck), worst.0, worst.1, ids(&bad), ids(&with)
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
    out.push(Conclusion {
        id: 2,
        thesis: "Normal oscillations show up in the tangential spectrum through F_y; not the other way round (without follower force).",
        claim: "In every sliding run with α = 0 the tangential velocity spectrum has a peak (≥ 10 dB above its neighbourhood) at the disc's normal frequency, while the normal spectrum has none (≤ 3 dB) at the disc's tangential frequency.".into(),
        held: !a0.is_empty() && present.len() == a0.len() && leak.is_empty(),
        evidence: format!(
            "{} sliding sets with α = 0; tangential prominence at the normal frequency {:.1} to {:.1} dB (sets with ≥ 10 dB: {} of {}); normal prominence at the tangential frequency {:.1} to {:.1} dB (sets above 3 dB: {}). With α = 0 the normal equations do not involve the tangential states at all.",
            a0.len(), tp_lo, tp_hi, present.len(), a0.len(), np_lo, np_hi, ids(&leak)
        ),
    });

    // 3. Nothing grows above Uc.
    let above: Vec<&SetResult> = pick(&sliding, |r| r.p("V") > uc);
    let above_bad: Vec<&SetResult> = pick(&above, |r| {
        squeals(r) || r.linear.as_ref().is_some_and(|l| l.growing)
    });
    let (npts, smax, sv, sn) = sw.above_uc;
    out.push(Conclusion {
        id: 3,
        thesis: "No tangential instability above the critical speed Uc.",
        claim: format!("No run with V > Uc = {uc:.2} m/s grows or ends in stick-slip, and an eigenvalue sweep of V over (Uc, 3Uc] at N = 100–5000 N without tangential damping finds no growing mode."),
        held: !above.is_empty() && above_bad.is_empty() && smax < 0.0,
        evidence: format!(
            "Sets above Uc: {} (growing or squealing: {}). Sweep: {npts} points, largest σ_max {smax:+.3e} 1/s at V = {sv:.2} m/s, N = {sn} N. For contrast, at V = 0.9·Uc (N = 500, default damping) σ_max = {:+.3e} 1/s.",
            ids(&above), ids(&above_bad), sw.below_uc
        ),
    });

    // 4. Damping and N.
    let find = |id: usize| rs.iter().find(|r| r.id == id);
    let (c500, c2000) = sw.c_crit;
    let s28 = find(28);
    let s31 = find(31);
    let runs_ok = s28.is_some_and(|r| !squeals(r)) && s31.is_some_and(squeals);
    out.push(Conclusion {
        id: 4,
        thesis: "Below Uc, instability appears when damping is small, more readily at high N.",
        claim: "At V = 1 m/s the tangential damping needed to silence the brake (c = c_dx = c_px) rises with the pad force, and the damping that silences it at N = 500 N (set 28) does not at N = 2000 N (set 31).".into(),
        held: matches!((c500, c2000), (Some(a), Some(b)) if b > a) && runs_ok,
        evidence: format!(
            "Critical c: {} kg/s at N = 500 N, {} kg/s at N = 2000 N (ratio {}); set 28: {} (σ_max {}), set 31: {} (σ_max {}).",
            c500.map_or("none".into(), |c| format!("{c:.4}")),
            c2000.map_or("none".into(), |c| format!("{c:.4}")),
            match (c500, c2000) { (Some(a), Some(b)) => format!("{:.3}", b / a), _ => "n/a".into() },
            s28.map_or("missing", |r| r.verdict.as_str()),
            s28.and_then(|r| r.linear.as_ref()).map_or("n/a".into(), |l| format!("{:+.3}", l.max_growth)),
            s31.map_or("missing", |r| r.verdict.as_str()),
            s31.and_then(|r| r.linear.as_ref()).map_or("n/a".into(), |l| format!("{:+.3}", l.max_growth)),
        ),
    });

    // 5. Stick-slip bounds the growth.
    let unstable: Vec<&SetResult> =
        pick(&sliding, |r| r.linear.as_ref().is_some_and(|l| l.growing));
    // The Stribeck-driven growth of the thesis: no follower force, and the first
    // reversal early enough (before 60 % of the run) for the cycle to settle.
    let saturated: Vec<&SetResult> = pick(&unstable, |r| {
        r.p("alpha") == 0.0 && r.first_reversal.is_some_and(|t| t < 0.6 * r.sc.duration)
    });
    let late: Vec<&SetResult> = pick(&unstable, |r| {
        r.p("alpha") == 0.0 && r.first_reversal.is_some_and(|t| t >= 0.6 * r.sc.duration)
    });
    let follower: Vec<String> = unstable
        .iter()
        .filter(|r| r.p("alpha") != 0.0)
        .map(|r| {
            format!(
                "{} ({}, pad speed {:.2}·V)",
                r.id,
                r.verdict,
                r.vxp_max / r.p("V")
            )
        })
        .collect();
    let bounded: Vec<&SetResult> = pick(&saturated, |r| {
        r.verdict == "stick-slip" && r.vxp_max <= 2.0 * r.p("V")
    });
    let unsat: Vec<&SetResult> = pick(&unstable, |r| r.first_reversal.is_none());
    let ratio = saturated
        .iter()
        .map(|r| r.vxp_max / r.p("V"))
        .fold(0.0, f64::max);
    out.push(Conclusion {
        id: 5,
        thesis: "Stick-slip limits the amplitude of the growing oscillation.",
        claim: "Every linearly unstable run without follower force that reaches the disc speed in the first 60 % of its duration settles on a bounded stick-slip/reversal cycle (verdict stick-slip, pad speed below 2V) instead of growing without bound.".into(),
        held: !saturated.is_empty() && bounded.len() == saturated.len(),
        evidence: format!(
            "Unstable sets: {}; reached reversals early: {} (bounded: {} of them; largest pad speed {:.3}·V); reached reversals late, still settling: {}; still growing when the run ended (too slow to saturate in the simulated time): {}; with follower force (outside the claim): {}.",
            ids(&unstable), ids(&saturated), bounded.len(), ratio, ids(&late), ids(&unsat),
            if follower.is_empty() { "none".into() } else { follower.join(", ") }
        ),
    });

    // 6. The pad saturates first and holds the disc back; pad damping frees the disc.
    let (s15, s27) = (find(15), find(27));
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
        let rate_ok =
            matches!((g27, disc27), (Some(g), Some(s)) if s > 0.0 && (g - s).abs() <= 0.1 * s);
        held6 = matches!((pad15, disc15), (Some(p), Some(d)) if p > d && d > 0.0)
            && a.first_reversal.is_some()
            && collapse_db >= 10.0
            && b.first_reversal.is_none()
            && b.verdict == "grows"
            && rate_ok;
        ev6 = format!(
            "Set 15: σ_pad {} > σ_disc {} 1/s; first reversal at {}; disc tangential amplitude falls {collapse_db:.1} dB from its peak ({:.3e} m/s) to the last 20 % ({:.3e} m/s). Set 27 (c_px = 4 kg/s, pad stable): reversals {}, verdict {}, disc growth rate fitted {} vs eigenvalue {} 1/s over {} s.",
            pad15.map_or("n/a".into(), |x| format!("{x:+.3}")),
            disc15.map_or("n/a".into(), |x| format!("{x:+.3}")),
            a.first_reversal.map_or("never".into(), |t| format!("t = {t:.4} s")),
            a.vxd_peak, a.vxd_tail_peak,
            b.events[EventKind::Reverse.index()],
            b.verdict,
            g27.map_or("n/a".into(), |x| format!("{x:+.3}")),
            disc27.map_or("n/a".into(), |x| format!("{x:+.3}")),
            b.sc.duration,
        );
    }
    out.push(Conclusion {
        id: 6,
        thesis: "The pad, which grows faster (smaller inertia), reaches stick-slip first, and its stick-slip suppresses the disc's growth; adding pad damping can destabilise the disc.",
        claim: "In the default brake (set 15) the pad's mode grows faster than the disc's, reaches reversals first, and the disc's tangential vibration then collapses (≥ 10 dB); with the pad damped above its own threshold (set 27) no reversals occur and the disc keeps growing at its eigenvalue rate (within 10 %) to the end of the run.".into(),
        held: held6,
        evidence: ev6,
    });

    // 7. Follower force.
    let (s38, s40) = (find(38), find(40));
    let same = match (s15, s38) {
        (Some(a), Some(b)) => {
            a.verdict == b.verdict
                && matches!((a.f_t, b.f_t), (Some(x), Some(y)) if (x - y).abs() < 1.0)
        }
        _ => false,
    };
    let (small, large) = sw.alpha_shift;
    out.push(Conclusion {
        id: 7,
        thesis: "The follower force, at realistic α, is too weak to couple tangential and normal motion.",
        claim: "At a realistic α = −10 1/m every eigenvalue moves by less than 1e-4 relative from α = 0 and the run (set 38) tells the same story as set 15; only near the limit of steady sliding (α = −1e5 1/m) do the modes change noticeably (> 1 %).".into(),
        held: small < 1e-4 && large > 1e-2 && same,
        evidence: format!(
            "Largest relative eigenvalue shift: {small:.2e} at α = −10 (the follower terms α·F_t* ≈ α·μ·N are ~1e-5 of the normal stiffness), {large:.2e} at α = −1e5. Set 38: {} (tangential {}), set 15: {} (tangential {}); set 40: {} with {} separations.",
            s38.map_or("missing", |r| r.verdict.as_str()),
            s38.and_then(|r| r.f_t).map_or("n/a".into(), |f| format!("{f:.1} Hz")),
            s15.map_or("missing", |r| r.verdict.as_str()),
            s15.and_then(|r| r.f_t).map_or("n/a".into(), |f| format!("{f:.1} Hz")),
            s40.map_or("missing", |r| r.verdict.as_str()),
            s40.map_or(0, |r| r.events[EventKind::Separate.index()]),
        ),
    });
    out
}

fn opt(x: Option<f64>, prec: usize) -> String {
    x.filter(|v| v.is_finite())
        .map_or(String::new(), |v| format!("{v:.prec$}"))
}

/// The parameters the table shows for every set (the ones the sets vary).
const TABLE_PARAMS: [&str; 8] = ["V", "N", "f1", "alpha", "c_dx", "c_dy", "c_px", "c_py"];

const TABLE_HEADER: &str = "set,question,V,N,f1,alpha,c_dx,c_dy,c_px,c_py,duration,linear,max_growth_rate,least_stable_hz,verdict,tangential_hz,normal_hz,growth_rate_vx_p,growth_rate_vx_d,stick_fraction,reversals,sticks,tangential_zero,agree";

fn table_csv(rs: &[SetResult]) -> String {
    let mut t = String::from(TABLE_HEADER);
    t.push('\n');
    for r in rs {
        let q = r.sc.description.replace('"', "'");
        let params: Vec<String> = TABLE_PARAMS.iter().map(|k| r.p(k).to_string()).collect();
        let _ = writeln!(
            t,
            "{},\"{}\",{},{},{},{},{},{},{},{},{},{},{:e},{},{},{},{}",
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

fn report_md(rs: &[SetResult], cs: &[Conclusion], scale: f64, figures: bool) -> String {
    let mut m = String::new();
    let _ = writeln!(
        m,
        "# The thesis re-done: Table 11.1, Appendix A and its conclusions\n"
    );
    let _ = writeln!(
        m,
        "Produced by `squeal reproduce`. The 40 parameter sets reconstruct Table 11.1 of V. Milovs, \
         *Computer Simulation of Automotive Disc Brake Noise* (its numbers were lost to OCR; see MODEL.md §6 and \
         `scenarios/thesis/`). Every run starts from rest with N applied as a step at t = 0, as the thesis did, and \
         is integrated exactly (event-located stick, slip, reversal, separation). Simulated durations: {}{}: \
         long enough for the pad to reach its reversal cycle where it grows fast, shorter where nothing grows. \
         Every number below was computed by this invocation.\n",
        durations(rs),
        if scale != 1.0 { format!(" (the shipped durations scaled by {scale})") } else { String::new() }
    );
    let held = cs.iter().filter(|c| c.held).count();
    let _ = writeln!(m, "## Conclusions: {held} of {} held\n", cs.len());
    for c in cs {
        let _ = writeln!(
            m,
            "**{}. {}** — {}\n\n*Claim:* {}\n\n*Evidence:* {}\n",
            c.id,
            c.thesis,
            if c.held { "**held**" } else { "**not held**" },
            c.claim,
            c.evidence
        );
    }
    let dis: Vec<&SetResult> = rs.iter().filter(|r| r.agrees() == Some(false)).collect();
    let _ = writeln!(m, "## Eigenvalues against simulation\n");
    let _ = writeln!(
        m,
        "The thesis judged stability from runs alone. For every sliding set the eigenvalues of the steady-sliding \
         state (MODEL.md §5) give a linear verdict; it agrees with the simulated outcome in {} of {} sets. Where they \
         differ: {}.\n",
        rs.iter().filter(|r| r.agrees() == Some(true)).count(),
        rs.iter().filter(|r| r.agrees().is_some()).count(),
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
    let _ = writeln!(
        m,
        "The map shows the largest growth rate of steady sliding over V × N with the default damping; the black line \
         is σ = 0. Sets are marked by number at their (V, N); sets 1–5 (V = 0) have no steady sliding and lie off it.\n"
    );
    let _ = writeln!(m, "## Table 11.1, reconstructed, with results\n");
    let _ = writeln!(
        m,
        "| set | question | V | N | f1 | α | c_dx | c_dy | c_px | c_py | linear | σ_max (1/s) | verdict | f_t (Hz) | f_n (Hz) | σ fit pad (1/s) | stick fraction | reversals |"
    );
    let _ = writeln!(
        m,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
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
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2e} | {} |",
            r.id,
            r.sc.description,
            params.join(" | "),
            r.linear_word(),
            r.linear
                .as_ref()
                .map_or("—".into(), |l| format!("{:+.3}", l.max_growth)),
            r.verdict,
            opt(r.f_t, 1),
            opt(r.f_n, 1),
            opt(r.growth_of("vx_p"), 3),
            r.stick_fraction,
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
            "Simulated: {}{}; {} reversals, {} sticks, {} separations.\n",
            r.verdict,
            if r.tangential_zero {
                " (tangential motion identically zero)"
            } else {
                ""
            },
            r.events[EventKind::Reverse.index()],
            r.events[EventKind::Stick.index()],
            r.events[EventKind::Separate.index()]
        );
        if figures {
            let _ = writeln!(m, "![set {0}](figures/set{0:02}/triplet.png)\n", r.id);
        }
    }
    m
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
    let mut in_table = false;
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
                let _ = write!(h, "<td>{}</td>", inline(c.trim()));
            }
            h.push_str("</tr>\n");
            continue;
        } else if in_table {
            h.push_str("</table>\n");
            in_table = false;
        }
        if let Some(t) = line.strip_prefix("### ") {
            let _ = writeln!(h, "<h3>{}</h3>", inline(t));
        } else if let Some(t) = line.strip_prefix("## ") {
            let _ = writeln!(h, "<h2>{}</h2>", inline(t));
        } else if let Some(t) = line.strip_prefix("# ") {
            let _ = writeln!(h, "<h1>{}</h1>", inline(t));
        } else if let Some(rest) = line.strip_prefix("![") {
            if let Some((alt, src)) = rest.split_once("](") {
                let _ = writeln!(
                    h,
                    "<p><img alt=\"{}\" src=\"{}\"></p>",
                    esc(alt),
                    esc(src.trim_end_matches(')'))
                );
            }
        } else if !line.trim().is_empty() {
            let _ = writeln!(h, "<p>{}</p>", inline(line));
        }
    }
    if in_table {
        h.push_str("</table>\n");
    }
    h.push_str("</body></html>\n");
    h
}

fn draw_map(rs: &[SetResult], dir: &Path) -> Result<(), RunError> {
    let base = AnyModel::by_name("disc-pad").expect("built-in model");
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
    for r in rs.iter().filter(|r| r.p("V") > 0.0) {
        let (v, n) = (r.p("V"), r.p("N"));
        match spots.iter_mut().find(|s| s.0 == v && s.1 == n) {
            Some(s) => s.2.push(r.id),
            None => spots.push((v, n, vec![r.id])),
        }
    }
    let labels: Vec<String> = spots
        .iter()
        .map(|s| {
            if s.2.len() > 4 {
                format!(
                    "{} sets ({}…)",
                    s.2.len(),
                    s.2[..3]
                        .iter()
                        .map(|i| i.to_string())
                        .collect::<Vec<_>>()
                        .join(",")
                )
            } else {
                s.2.iter()
                    .map(|i| i.to_string())
                    .collect::<Vec<_>>()
                    .join(",")
            }
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
            "Stability of steady sliding (default damping) with the thesis's sets",
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
    Ok(())
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
        crate::feasible::prepare(s)?;
    }
    let stage = Staging::new(&a.out)?;
    let figures = stage.dir().join("figures");
    let pb = progress_bar(sets.len() as u64, "reproducing the thesis");
    let results: Vec<Result<SetResult, RunError>> = sets
        .into_par_iter()
        .enumerate()
        .map(|(i, sc)| {
            let r = measure(i + 1, sc, (!a.no_figures).then_some(figures.as_path()));
            pb.inc(1);
            r
        })
        .collect();
    pb.finish_and_clear();
    let mut rs = Vec::new();
    for (i, r) in results.into_iter().enumerate() {
        rs.push(r.map_err(|e| RunError::Numerical(format!("set {}: {e}", i + 1)))?);
    }
    let sw = sweeps(&rs[14].sc.model);
    let cs = conclusions(&rs, &sw);
    draw_map(&rs, stage.dir())?;
    let wall = start.elapsed().as_secs_f64();
    let write = |name: &str, text: &str| {
        let p = stage.path(name);
        std::fs::write(&p, text)
            .map_err(|e| RunError::Io(format!("cannot write {}: {e}", p.display())))
    };
    write("table.csv", &table_csv(&rs))?;
    let cj: Vec<Value> = cs
        .iter()
        .map(|c| json!({ "id": c.id, "thesis": c.thesis, "claim": c.claim, "held": c.held, "evidence": c.evidence }))
        .collect();
    write(
        "conclusions.json",
        &(serde_json::to_string_pretty(&cj).map_err(|e| RunError::Io(e.to_string()))? + "\n"),
    )?;
    let md = report_md(&rs, &cs, a.duration_scale, !a.no_figures);
    write("report.md", &md)?;
    write("report.html", &report_html(&md))?;
    let dest = stage.commit()?;
    let held = cs.iter().filter(|c| c.held).count();
    crate::outln!("reproduced 40 sets in {wall:.1} s: {held} of 7 conclusions held");
    for c in &cs {
        crate::outln!(
            "  {}. {} {}",
            c.id,
            if c.held { "held    " } else { "NOT held" },
            c.thesis
        );
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
    }
}

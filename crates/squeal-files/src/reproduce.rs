//! The thesis reproduced (`squeal reproduce [--out DIR]`) and its report: the thesis's study re-done, checked and
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
use crate::shard::{fnv1a, write_file, Shard, FORMAT, SETS_FILE, SHARD_FILE};
use crate::{Bars, RunError, Staging};
use rayon::prelude::*;
use serde_json::{json, Value};
use squeal_core::EventKind;
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_study::input::{read_regular, MAX_TABLE_BYTES};
use squeal_study::model::AnyModel;
use squeal_study::reproduce::*;
use squeal_study::run::Run;
use squeal_study::{Cancel, Scenario};
use std::fmt::Write as _;
use std::path::Path;

/// Appendix A's pictures of set `id` in `figures/setNN`, if asked for.
fn draw_set(
    id: usize,
    run: &Run,
    an: &Analysis,
    answer: &squeal_study::answer::Answer,
    ch: &squeal_study::model::Channels,
    figures: Option<&Path>,
) -> Result<(), RunError> {
    let Some(dir) = figures else {
        return Ok(());
    };
    let d = dir.join(format!("set{id:02}"));
    std::fs::create_dir_all(&d)
        .map_err(|e| RunError::Io(format!("cannot create {}: {e}", d.display())))?;
    let words = answer.words();
    analysis::draw(
        run,
        an,
        ch,
        &format!("set {id}"),
        &d,
        &analysis::PlotSettings::default(),
        words.as_deref(),
        false,
    )
    .map(|_| ())
}

/// "7 (lift-off)" for every set that `keep` keeps: its number and verdict.
fn sets_with(rs: &[SetResult], keep: impl Fn(&SetResult) -> bool) -> Vec<String> {
    rs.iter()
        .filter(|r| keep(r))
        .map(|r| format!("{} ({})", r.id, r.verdict))
        .collect()
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
pub fn grade_counts(cs: &[Conclusion]) -> String {
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
            let out = sets_with(rs, |r| r.p("V") > 0.0 && r.agrees().is_none());
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
            let out = sets_with(rs, |r| r.outside().is_some());
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
        value_range: crate::map::robust_range(&vals),
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

/// Measure the sets `ids` (indices into `sets`, set `i + 1`) in parallel
/// ([`squeal_study::reproduce::measure_sets`]), drawing Appendix A's
/// pictures into `figures` if given; results in the order of `ids`.
fn measure_sets(
    sets: &[Scenario],
    ids: &[usize],
    figures: Option<&Path>,
    label: &str,
    bars: Bars,
    cancel: &Cancel,
) -> Result<Vec<SetResult>, RunError> {
    let pb = bars(ids.len() as u64, label);
    let results = squeal_study::reproduce::measure_sets(
        sets,
        ids,
        |id, run, an, answer| {
            let ch = sets[id - 1].model.channels();
            draw_set(id, run, an, answer, &ch, figures)
        },
        &*pb,
        cancel,
    );
    pb.finish();
    let mut rs = Vec::with_capacity(ids.len());
    for (i, r) in ids.iter().zip(results) {
        rs.push(r.map_err(|e: RunError| RunError::Numerical(format!("set {}: {e}", i + 1)))?);
    }
    Ok(rs)
}

/// Everything after the 40 sets: the sweeps around set 15, the
/// conclusions, the V × N map and the report (`table.csv`,
/// `conclusions.json`, `report.md`, `report.html`, `map.png`/`.svg`),
/// written into `stage`. `reproduce` and `merge` both end here, so a merged
/// report is the unsharded one byte for byte.
pub fn finish(
    stage: &Staging,
    rs: &[SetResult],
    duration_scale: f64,
    figures: bool,
    cancel: &Cancel,
) -> Result<Vec<Conclusion>, RunError> {
    let sw = sweeps(&rs[14].sc, cancel)?;
    let cs = conclusions(rs, &sw);
    let map_note = draw_map(rs, stage.dir())?;
    let write = |name: &str, text: &str| {
        let p = stage.path(name);
        std::fs::write(&p, text)
            .map_err(|e| RunError::Io(format!("cannot write {}: {e}", p.display())))
    };
    write("table.csv", &table_csv(rs))?;
    let cj = conclusions_json(&cs);
    write(
        "conclusions.json",
        &(serde_json::to_string_pretty(&cj).map_err(|e| RunError::Io(e.to_string()))? + "\n"),
    )?;
    let md = report_md(rs, &cs, &sw, duration_scale, figures, &map_note);
    write("report.md", &md)?;
    write("report.html", &report_html(&md))?;
    Ok(cs)
}

/// The study a `reproduce` shard belongs to: the squeal version, the
/// duration scale, whether it draws figures, and a hash of the 40 prepared
/// scenarios (their resolved content).
pub fn reproduce_study(sets: &[Scenario], duration_scale: f64, figures: bool) -> Value {
    let content: Vec<Value> = sets.iter().map(Scenario::to_json).collect();
    let text = serde_json::to_string(&content).unwrap_or_default();
    json!({
        "command": "reproduce",
        "squeal_version": env!("CARGO_PKG_VERSION"),
        "duration_scale": format!("{duration_scale:e}"),
        "figures": figures,
        "sets": { "count": sets.len(), "hash": fnv1a(text.as_bytes()) },
    })
}

/// Every file under `dir/figures`, as paths relative to `dir` with `/`,
/// sorted.
fn figure_files(dir: &Path) -> Result<Vec<String>, RunError> {
    let mut out = Vec::new();
    let mut todo = vec![dir.join("figures")];
    while let Some(d) = todo.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries {
            let e = e.map_err(|e| RunError::Io(format!("cannot read {}: {e}", d.display())))?;
            let p = e.path();
            if p.is_dir() {
                todo.push(p);
            } else if let Ok(rel) = p.strip_prefix(dir) {
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(parts.join("/"));
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Write a `reproduce` shard (`part.json`, then `shard.json` listing
/// `part.json` and every picture under `figures/` with its length and
/// hash) into `stage`, whose `figures/` the sets have drawn into.
pub fn write_reproduce_part(
    stage: &Staging,
    study: &Value,
    s: Shard,
    rs: &[SetResult],
) -> Result<(), RunError> {
    let sets: Vec<Value> = rs
        .iter()
        .map(squeal_study::reproduce::exact::to_json)
        .collect();
    let bytes =
        serde_json::to_string_pretty(&sets).map_err(|e| RunError::Io(e.to_string()))? + "\n";
    write_file(&stage.path(SETS_FILE), bytes.as_bytes())?;
    let mut figures = Vec::new();
    for f in figure_files(stage.dir())? {
        let p = stage.dir().join(&f);
        let b = read_regular(&p, MAX_TABLE_BYTES).map_err(RunError::Io)?;
        figures.push(json!({ "file": f, "bytes": b.len(), "fnv1a": fnv1a(&b) }));
    }
    let doc = json!({
        "format": FORMAT,
        "study": study,
        "k": s.k,
        "n": s.n,
        "slicing": "interleaved: set index i (set i + 1) belongs to shard i mod n",
        "points": rs.len(),
        "part": { "file": SETS_FILE, "rows": rs.len(), "bytes": bytes.len(), "fnv1a": fnv1a(bytes.as_bytes()) },
        "figures": figures,
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    write_file(&stage.path(SHARD_FILE), (text + "\n").as_bytes())
}

/// The thesis reproduced: the 40 sets (durations scaled), with or without
/// Appendix A's pictures; all of it, or one shard of the sets.
pub struct ReproduceStudy {
    /// The 40 prepared scenarios ([`prepared_sets`]).
    pub sets: Vec<Scenario>,
    /// The factor on every set's simulated duration.
    pub duration_scale: f64,
    /// Draw each set's pictures under `figures/`.
    pub figures: bool,
    /// Only this shard's sets (`--shard K/N`).
    pub shard: Option<Shard>,
}

/// What [`ReproduceStudy::run`] measured and concluded.
pub struct Reproduced {
    /// The indices of the sets measured (set `i + 1`).
    pub ids: Vec<usize>,
    /// Their results, in the order of `ids`.
    pub results: Vec<SetResult>,
    /// The graded conclusions (the whole study only).
    pub conclusions: Option<Vec<Conclusion>>,
}

impl ReproduceStudy {
    /// The study at `duration_scale` (bad input if it is not a positive number).
    pub fn new(
        duration_scale: f64,
        figures: bool,
        shard: Option<Shard>,
    ) -> Result<ReproduceStudy, squeal_study::StudyError> {
        Ok(ReproduceStudy {
            sets: prepared_sets(duration_scale)?,
            duration_scale,
            figures,
            shard,
        })
    }

    /// The default output folder's name: `reproduce`, a shard's
    /// `reproduce-shard-K-of-N`.
    pub fn folder(&self) -> String {
        Shard::folder("reproduce", self.shard)
    }

    /// Measure the sets (in parallel) into `stage`, drawing their pictures,
    /// then write the shard's part or the whole report ([`finish`]).
    pub fn run(
        &self,
        stage: &Staging,
        bars: Bars,
        cancel: &Cancel,
    ) -> Result<Reproduced, RunError> {
        let figures = stage.dir().join("figures");
        let figures = self.figures.then_some(figures.as_path());
        if let Some(s) = self.shard {
            let ids = s.points(self.sets.len());
            let label = format!("shard {}/{}: reproducing the thesis", s.k, s.n);
            let results = measure_sets(&self.sets, &ids, figures, &label, bars, cancel)?;
            let study = reproduce_study(&self.sets, self.duration_scale, self.figures);
            write_reproduce_part(stage, &study, s, &results)?;
            return Ok(Reproduced {
                ids,
                results,
                conclusions: None,
            });
        }
        let ids: Vec<usize> = (0..self.sets.len()).collect();
        let label = "reproducing the thesis";
        let results = measure_sets(&self.sets, &ids, figures, label, bars, cancel)?;
        let cs = finish(stage, &results, self.duration_scale, self.figures, cancel)?;
        Ok(Reproduced {
            ids,
            results,
            conclusions: Some(cs),
        })
    }
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

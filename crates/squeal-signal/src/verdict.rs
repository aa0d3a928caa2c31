//! The verdict of a whole run and its squeal answer: does it squeal, at which
//! frequency, how loud.
//!
//! [`judge`] looks at *every* coordinate of the state (each position and its
//! velocity, by name) and at the integrator's own events (stick, slip,
//! reverse, separate, contact; optionally per contact), never at one signal
//! alone, and decides with rules that do not depend on the run's length
//! (beyond needing enough of it) or on the output sample rate:
//!
//! | word | rule (checked in this order) |
//! | --- | --- |
//! | `out-of-range` | some position leaves `±validity` (m), or a value is not finite: the run left the model's range of validity |
//! | `lift-off` | some contact is lost at least `min_events` times in the judged window, to its end, irregularly (intervals between its separations vary by more than `regular_cv`) |
//! | `grows` | some moving velocity's level still rises across the judged window: fitted rate `σ > k_se·SE(σ)` and `σ·T > min_change_db` |
//! | `limit-cycle` (contact loss) | some contact loses contact at least `min_events` times through the window, to its end, at regular intervals (coefficient of variation ≤ `regular_cv`), and nothing grows: a cycle with contact loss every period, whatever sticks or reversals come with it — never `stick-slip` |
//! | `stick-slip` | true sticks or slip reversals recur through the judged window (at least `min_events` of them, the last within two typical gaps of the end), no contact is lost recurrently and nothing grows: a friction-limited cycle |
//! | `limit-cycle` | the motion neither grows nor decays across the window (within `k_se`·SE or `min_change_db`), after the run's level changed by more than `neutral_db` or with contact events (a cycle the motion was attracted to) |
//!
//! Contact loss is decided contact by contact ([`ContactRegime`]): each
//! contact's own separations, their count and the regularity of their
//! intervals (two pads' separations interleave).
//! | `decays` | every moving velocity falls significantly across the window, or has fallen `decayed_db` below its peak, or nothing moves |
//! | `neutral` | steady, no events at all, and the level at the start of the run equals that at its end within `neutral_db`: undamped linear ringing |
//! | `too-short` | the judged window holds fewer than `min_cycles` cycles of the motion or too few samples, and the events do not decide: too short to tell |
//!
//! The judged window is the last `tail_fraction` of the run. Levels are block
//! RMS values (blocks of at least one cycle of the dominant motion): an RMS is
//! insensitive to where the samples fall in a cycle, so a run sampled below
//! the oscillation's Nyquist rate gives the same trend as one sampled finely.
//! Event counts and times come from the integrator, exact to its event
//! tolerance, whatever the sample rate.
//!
//! The squeal answer ([`Squeal`]): for `grows`, `limit-cycle`, `stick-slip`
//! and `lift-off`, the coordinate whose velocity carries the most energy
//! (RMS over the window) among those that grow (for `grows`) or are sustained
//! (otherwise), the frequency of its strongest spectral line over the window
//! (or, for a strictly periodic stick-slip cycle, `1/period` of its sticks,
//! which the integrator times exactly), its velocity RMS (m/s) and level
//! (dB re 1 m/s). `None` when nothing squeals.

use std::fmt;

use crate::growth::DB_PER_NEPER;
use crate::peaks::{find_peaks, PeakOptions};
use crate::spectrum::{welch, WelchOptions};

/// What the integrator reports as an event (the `kind` column of `events.csv`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EventClass {
    /// Slip → stick (a true stick).
    Stick,
    /// Stick → slip.
    Slip,
    /// Slip reversal: the sliding velocity crosses zero without sticking.
    Reverse,
    /// Loss of contact.
    Separate,
    /// Recontact.
    Contact,
}

impl EventClass {
    /// The class named as in `events.csv` (`stick`, `slip`, `reverse`, `separate`, `contact`).
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "stick" => EventClass::Stick,
            "slip" => EventClass::Slip,
            "reverse" => EventClass::Reverse,
            "separate" => EventClass::Separate,
            "contact" => EventClass::Contact,
            _ => return None,
        })
    }
}

/// One event of a run: its time, its class and (for models with several
/// contacts) the contact's name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunEvent<'a> {
    /// Time (s).
    pub t: f64,
    /// What happened.
    pub kind: EventClass,
    /// The contact's name, if the model names its contacts.
    pub contact: Option<&'a str>,
}

/// One coordinate of the state: a position and its velocity, by name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coordinate<'a> {
    /// Position name (`x_p`), used in the squeal answer.
    pub name: &'a str,
    /// Name of its velocity column (`vx_p`).
    pub velocity_name: &'a str,
    /// Position samples (m, or rad for a rotation).
    pub position: &'a [f64],
    /// Velocity samples (m/s).
    pub velocity: &'a [f64],
}

/// A run as [`judge`] sees it: uniformly sampled coordinates and the event list.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord<'a> {
    /// Sample rate (Hz) of every coordinate.
    pub sample_rate: f64,
    /// Time of the first sample (s).
    pub t_start: f64,
    /// The state, coordinate by coordinate (all of equal length).
    pub coordinates: Vec<Coordinate<'a>>,
    /// The integrator's events, in time order.
    pub events: Vec<RunEvent<'a>>,
    /// A velocity scale of the run (e.g. the sliding speed), m/s: velocities
    /// that never exceed `still·scale` are integration noise, not motion.
    pub velocity_scale: f64,
}

/// Thresholds of [`judge`] (see the module table for where each enters).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JudgeOptions {
    /// Largest displacement (m) the model means anything at; default 0.1 m.
    pub validity: f64,
    /// The judged window is this last fraction of the run; default 0.25.
    pub tail_fraction: f64,
    /// Fewest events (sticks + reversals, or separations) that make a regime; default 4.
    pub min_events: usize,
    /// Fewest cycles of the motion in the window for a trend; default 4.
    pub min_cycles: f64,
    /// Significance of a trend, in standard errors of the fitted rate; default 3.
    pub k_se: f64,
    /// Smallest level change across the window (dB) that counts as a trend; default 0.05 dB.
    pub min_change_db: f64,
    /// A tail this far below the run's peak level (dB) has decayed; default 40 dB.
    pub decayed_db: f64,
    /// Largest start-to-end level change (dB) of a neutral run; default 1 dB.
    pub neutral_db: f64,
    /// Separations whose intervals have a coefficient of variation below this are regular
    /// (a strictly periodic cycle that lifts off, not erratic lift-off); default 0.01.
    pub regular_cv: f64,
    /// Velocities that never exceed `still·velocity_scale` do not move; default 1e-8.
    pub still: f64,
}

impl Default for JudgeOptions {
    fn default() -> Self {
        JudgeOptions {
            validity: 0.1,
            tail_fraction: 0.25,
            min_events: 4,
            min_cycles: 4.0,
            k_se: 3.0,
            min_change_db: 0.05,
            decayed_db: 40.0,
            neutral_db: 1.0,
            regular_cv: 0.01,
            still: 1e-8,
        }
    }
}

/// The word of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RunVerdict {
    /// The vibration dies out.
    Decays,
    /// Still growing when the run ends.
    Grows,
    /// Bounded, sustained, smooth oscillation the motion settled on.
    LimitCycle,
    /// A friction-limited cycle: true sticks or slip reversals recur.
    StickSlip,
    /// Undamped linear oscillation: neither grows nor decays, never did.
    Neutral,
    /// Contact is lost repeatedly and irregularly.
    LiftOff,
    /// The run left the model's range of validity.
    OutOfRange,
    /// Too short to tell.
    TooShort,
}

impl RunVerdict {
    /// All words, in the README's order.
    pub const ALL: [RunVerdict; 8] = [
        RunVerdict::Decays,
        RunVerdict::Grows,
        RunVerdict::LimitCycle,
        RunVerdict::StickSlip,
        RunVerdict::Neutral,
        RunVerdict::LiftOff,
        RunVerdict::OutOfRange,
        RunVerdict::TooShort,
    ];

    /// The word: `decays`, `grows`, `limit-cycle`, `stick-slip`, `neutral`,
    /// `lift-off`, `out-of-range`, `too-short`.
    pub fn as_str(self) -> &'static str {
        match self {
            RunVerdict::Decays => "decays",
            RunVerdict::Grows => "grows",
            RunVerdict::LimitCycle => "limit-cycle",
            RunVerdict::StickSlip => "stick-slip",
            RunVerdict::Neutral => "neutral",
            RunVerdict::LiftOff => "lift-off",
            RunVerdict::OutOfRange => "out-of-range",
            RunVerdict::TooShort => "too-short",
        }
    }

    /// Whether the run makes noise that a squeal answer describes.
    pub fn squeals(self) -> bool {
        matches!(
            self,
            RunVerdict::Grows
                | RunVerdict::LimitCycle
                | RunVerdict::StickSlip
                | RunVerdict::LiftOff
        )
    }
}

impl fmt::Display for RunVerdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How one velocity behaves over the judged window.
#[derive(Debug, Clone, PartialEq)]
pub struct Trend {
    /// Position name of the coordinate.
    pub name: String,
    /// Velocity RMS over the window (m/s).
    pub rms: f64,
    /// Fitted exponential rate of its block RMS over the window (1/s); 0 when not fitted.
    pub rate: f64,
    /// Standard error of `rate` (1/s); infinite when not fitted.
    pub rate_se: f64,
    /// Level change across the window from the fit, dB.
    pub change_db: f64,
    /// Peak block level over the whole run minus the window's level, dB (≥ 0).
    pub below_peak_db: f64,
    /// Level change from the run's first block to its last, dB.
    pub run_change_db: f64,
    /// Whether the velocity moves at all (above the noise threshold).
    pub moving: bool,
}

impl Trend {
    fn grows(&self, o: &JudgeOptions, span: f64) -> bool {
        self.moving
            && self.rate > o.k_se * self.rate_se
            && self.rate * span * DB_PER_NEPER > o.min_change_db
    }
    fn decays(&self, o: &JudgeOptions, span: f64) -> bool {
        !self.moving
            || self.below_peak_db >= o.decayed_db
            || (-self.rate > o.k_se * self.rate_se
                && -self.rate * span * DB_PER_NEPER > o.min_change_db)
    }
}

/// Friction events over the judged window, per cycle of the squeal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleEvents {
    /// True sticks in the window.
    pub sticks: usize,
    /// Slip reversals in the window.
    pub reversals: usize,
    /// Separations in the window.
    pub separations: usize,
    /// Cycles of the squeal in the window (`frequency × window length`).
    pub cycles: f64,
    /// `sticks / cycles`.
    pub sticks_per_cycle: f64,
    /// `reversals / cycles`.
    pub reversals_per_cycle: f64,
    /// `separations / cycles`.
    pub separations_per_cycle: f64,
}

/// The squeal answer: which coordinate, at which frequency, how loud.
#[derive(Debug, Clone, PartialEq)]
pub struct Squeal {
    /// Position name of the coordinate that carries it (`x_p`).
    pub coordinate: String,
    /// Its velocity column (`vx_p`).
    pub velocity: String,
    /// Frequency (Hz).
    pub frequency_hz: f64,
    /// Velocity RMS over the judged window (m/s).
    pub rms: f64,
    /// `20·log10(rms / 1 m/s)`, dB re 1 m/s.
    pub level_db: f64,
}

/// The verdict of a run with the numbers it was decided from.
#[derive(Debug, Clone, PartialEq)]
pub struct Judgement {
    /// The word.
    pub verdict: RunVerdict,
    /// One line: why this word (the deciding numbers).
    pub reason: String,
    /// The judged window (s).
    pub window: (f64, f64),
    /// Every coordinate's trend over the window.
    pub trends: Vec<Trend>,
    /// The squeal answer, `None` when nothing squeals.
    pub squeal: Option<Squeal>,
    /// Friction events per cycle over the window (when there is a squeal frequency).
    pub cycle: Option<CycleEvents>,
    /// Each contact's events over the window and its regime (one entry,
    /// unnamed, when the events name no contact).
    pub contacts: Vec<ContactRegime>,
}

/// One contact's events over the judged window and what they make of it.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRegime {
    /// The contact's name (`None` when the events name no contact).
    pub name: Option<String>,
    /// True sticks in the window.
    pub sticks: usize,
    /// Slip reversals in the window.
    pub reversals: usize,
    /// Separations in the window.
    pub separations: usize,
    /// Coefficient of variation of the intervals between its separations
    /// (infinite with fewer than three).
    pub separation_cv: f64,
    /// Separations recur to the end of the window (at least `min_events`,
    /// the last within two typical intervals of the end): contact loss.
    pub loses_contact: bool,
    /// Sticks or reversals (at least `min_events`) recur to the end of the
    /// window: the last within two of its longest gaps of the end.
    pub friction_cycle: bool,
}

impl ContactRegime {
    /// `contact loss` (separations recur), `stick-slip` (sticks or
    /// reversals recur, contact kept), or `sliding`.
    pub fn regime(&self) -> &'static str {
        if self.loses_contact {
            "contact loss"
        } else if self.friction_cycle {
            "stick-slip"
        } else {
            "sliding"
        }
    }
}

/// Errors of [`judge`]: inputs that cannot describe a run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JudgeError {
    /// Coordinates of different lengths, none at all, or a bad rate.
    #[error("invalid run record: {0}")]
    Invalid(String),
}

/// Block RMS levels of `x` (natural log), blocks of `bs` samples from `start`.
fn block_levels(x: &[f64], bs: usize) -> Vec<f64> {
    x.chunks_exact(bs.max(1))
        .map(|c| {
            let ms = c.iter().map(|v| v * v).sum::<f64>() / c.len() as f64;
            0.5 * ms.max(1e-300).ln()
        })
        .collect()
}

/// Least-squares slope (per block) of `y` and its standard error.
fn slope_se(y: &[f64]) -> Option<(f64, f64)> {
    let n = y.len();
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let ic = (nf - 1.0) / 2.0;
    let ybar = y.iter().sum::<f64>() / nf;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in y.iter().enumerate() {
        let dx = i as f64 - ic;
        sxy += dx * (v - ybar);
        sxx += dx * dx;
    }
    let b = sxy / sxx;
    let ss: f64 = y
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let r = v - ybar - b * (i as f64 - ic);
            r * r
        })
        .sum();
    Some((b, (ss / (nf - 2.0) / sxx).sqrt()))
}

fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
}

/// Frequency (Hz) of the strongest spectral line of `x` (mean removed), if any.
pub fn strongest_line(x: &[f64], fs: f64) -> Option<f64> {
    if x.len() < 16 {
        return None;
    }
    let opts = WelchOptions {
        seg_len: Some(x.len().min(1 << 15)),
        ..WelchOptions::default()
    };
    let s = welch(x, fs, &opts).ok()?;
    find_peaks(&s, 1, &PeakOptions::default())
        .first()
        .map(|p| p.freq)
}

/// Mean and coefficient of variation of the gaps between consecutive
/// times (at least three times, a positive mean): the judge's test of a
/// periodic regime (sticks with CV below 2 % are a strictly periodic stick
/// cycle; separations with CV above `regular_cv` are irregular).
pub fn gaps(times: &[f64]) -> Option<(f64, f64)> {
    if times.len() < 3 {
        return None;
    }
    let g: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    let mean = g.iter().sum::<f64>() / g.len() as f64;
    let var = g.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / g.len() as f64;
    (mean > 0.0).then(|| (mean, var.sqrt() / mean))
}

/// Fewest blocks (each at least one cycle of the run's dominant motion) a
/// trend is fitted on.
const MIN_BLOCKS: usize = 8;

/// Longest judged window, as a fraction of the run: when the last
/// `tail_fraction` is too short to tell, the window grows to this.
pub const MAX_TAIL_FRACTION: f64 = 0.5;

/// The verdict of a run (see the module docs for the rules). The window is
/// the last `tail_fraction` of the run; when that is too short to tell, the
/// last [`MAX_TAIL_FRACTION`].
///
/// Errors: no coordinates, coordinates of different lengths, a non-positive
/// rate or options out of range.
pub fn judge(run: &RunRecord<'_>, o: &JudgeOptions) -> Result<Judgement, JudgeError> {
    let j = judge_window(run, o)?;
    if j.verdict == RunVerdict::TooShort && o.tail_fraction < MAX_TAIL_FRACTION {
        let wider = JudgeOptions {
            tail_fraction: MAX_TAIL_FRACTION,
            ..*o
        };
        return judge_window(run, &wider);
    }
    Ok(j)
}

fn judge_window(run: &RunRecord<'_>, o: &JudgeOptions) -> Result<Judgement, JudgeError> {
    let bad = |m: String| Err(JudgeError::Invalid(m));
    let fs = run.sample_rate;
    if !(fs.is_finite() && fs > 0.0) {
        return bad(format!("sample_rate = {fs}"));
    }
    let Some(first) = run.coordinates.first() else {
        return bad("no coordinates".into());
    };
    let n = first.velocity.len();
    if run
        .coordinates
        .iter()
        .any(|c| c.velocity.len() != n || c.position.len() != n)
    {
        return bad("coordinates of different lengths".into());
    }
    if !(o.validity > 0.0 && o.tail_fraction > 0.0 && o.tail_fraction <= 1.0) {
        return bad(format!(
            "validity = {}, tail_fraction = {}",
            o.validity, o.tail_fraction
        ));
    }
    let t_end = run.t_start + n.saturating_sub(1) as f64 / fs;
    let i0 = n - ((o.tail_fraction * n as f64).ceil() as usize).min(n);
    let window = (run.t_start + i0 as f64 / fs, t_end);
    let span = window.1 - window.0;
    let mut j = Judgement {
        verdict: RunVerdict::TooShort,
        reason: String::new(),
        window,
        trends: Vec::new(),
        squeal: None,
        cycle: None,
        contacts: Vec::new(),
    };

    // 1. Out of range: any position beyond ±validity, or anything non-finite.
    for c in &run.coordinates {
        let worst = c.position.iter().copied().fold(0.0f64, |m, v| {
            if v.is_finite() {
                m.max(v.abs())
            } else {
                f64::INFINITY
            }
        });
        let vel_ok = c.velocity.iter().all(|v| v.is_finite());
        if worst > o.validity || !vel_ok {
            let at = c
                .position
                .iter()
                .position(|v| v.is_nan() || v.abs() > o.validity)
                .map(|i| run.t_start + i as f64 / fs);
            j.verdict = RunVerdict::OutOfRange;
            j.reason = format!(
                "{} reaches {worst:.3e} m, beyond the validity bound {:.3e} m{}",
                c.name,
                o.validity,
                at.map_or(String::new(), |t| format!(" at t = {t:.6} s"))
            );
            return Ok(j);
        }
    }

    // Events in the window.
    let in_win: Vec<&RunEvent> = run
        .events
        .iter()
        .filter(|e| e.t >= window.0 && e.t <= window.1 + 1e-12)
        .collect();
    let count = |k: EventClass| in_win.iter().filter(|e| e.kind == k).count();
    let (sticks, reversals, separations) = (
        count(EventClass::Stick),
        count(EventClass::Reverse),
        count(EventClass::Separate),
    );
    let friction_times: Vec<f64> = in_win
        .iter()
        .filter(|e| {
            matches!(
                e.kind,
                EventClass::Stick | EventClass::Slip | EventClass::Reverse
            )
        })
        .map(|e| e.t)
        .collect();
    // A regime recurs when there are enough events and the last one is within
    // two typical gaps of the end (the regime has not stopped).
    let recurs = |times: &[f64], count: usize| {
        count >= o.min_events
            && gaps(times).is_some_and(|(mean, _)| {
                let last = times.last().copied().unwrap_or(f64::NEG_INFINITY);
                window.1 - last <= 2.0 * mean.max(span / count as f64)
            })
    };
    let friction_cycle = recurs(&friction_times, sticks + reversals);
    // Each contact on its own: separations of two pads interleave, and only
    // one contact's own intervals say whether it loses contact regularly.
    let mut names: Vec<Option<&str>> = in_win.iter().map(|e| e.contact).collect();
    names.sort_unstable();
    names.dedup();
    j.contacts = names
        .iter()
        .map(|&name| {
            let of = |pick: &dyn Fn(EventClass) -> bool| -> Vec<f64> {
                in_win
                    .iter()
                    .filter(|e| e.contact == name && pick(e.kind))
                    .map(|e| e.t)
                    .collect()
            };
            let seps = of(&|k| k == EventClass::Separate);
            let friction = of(&|k| {
                matches!(
                    k,
                    EventClass::Stick | EventClass::Slip | EventClass::Reverse
                )
            });
            let n_sticks = of(&|k| k == EventClass::Stick).len();
            let n_reversals = of(&|k| k == EventClass::Reverse).len();
            ContactRegime {
                name: name.map(str::to_string),
                sticks: n_sticks,
                reversals: n_reversals,
                separations: seps.len(),
                separation_cv: gaps(&seps).map_or(f64::INFINITY, |g| g.1),
                loses_contact: recurs(&seps, seps.len()),
                // Descriptive only (the verdict reads all contacts' friction
                // events together): one pad's reversals come in bursts, so
                // its regime has not stopped while the silence at the end
                // is shorter than two of its longest gaps.
                friction_cycle: n_sticks + n_reversals >= o.min_events && friction.len() >= 2 && {
                    let longest = friction
                        .windows(2)
                        .map(|w| w[1] - w[0])
                        .fold(0.0f64, f64::max);
                    window.1 - friction[friction.len() - 1] <= 2.0 * longest
                },
            }
        })
        .collect();
    let lifting_contacts: Vec<&ContactRegime> =
        j.contacts.iter().filter(|c| c.loses_contact).collect();
    let lifting = !lifting_contacts.is_empty();
    // The least regular of the contacts that lose contact.
    let worst = lifting_contacts
        .iter()
        .copied()
        .max_by(|a, b| a.separation_cv.total_cmp(&b.separation_cv));
    let sep_cv = worst.map_or(f64::INFINITY, |c| c.separation_cv);
    let who = |c: Option<&ContactRegime>| {
        c.and_then(|c| c.name.as_deref())
            .map_or(String::new(), |n| format!(" at contact {n}"))
    };
    let stick_times: Vec<f64> = in_win
        .iter()
        .filter(|e| e.kind == EventClass::Stick)
        .map(|e| e.t)
        .collect();
    // A strictly periodic stick cycle: the integrator's stick times give its frequency.
    let stick_period = gaps(&stick_times).filter(|g| g.1 < 0.02).map(|g| g.0);

    // Trends. Blocks span whole cycles of the run's dominant motion: the
    // strongest line of the largest velocity over the window (or the stick
    // period); at least 8 samples and at most a tenth of the window.
    let scale = run.velocity_scale.abs().max(1e-3);
    let tail_rms: Vec<f64> = run
        .coordinates
        .iter()
        .map(|c| rms(&c.velocity[i0..]))
        .collect();
    let loudest = (0..tail_rms.len())
        .max_by(|&a, &b| tail_rms[a].total_cmp(&tail_rms[b]))
        .unwrap_or(0);
    let f_dom = stick_period
        .map(|p| 1.0 / p)
        .or_else(|| strongest_line(&run.coordinates[loudest].velocity[i0..], fs))
        .filter(|f| *f > 0.0);
    let win_len = n - i0;
    let cycles_in_window = f_dom.map_or(0.0, |f| f * span);
    let block = |f: Option<f64>| {
        let per_cycle = f.map_or(8.0, |f| (fs / f).ceil());
        (per_cycle.max(8.0) as usize).max(win_len / 20)
    };
    let bs = block(f_dom);
    let trend_ok = win_len >= MIN_BLOCKS * bs && cycles_in_window >= o.min_cycles;
    for (k, c) in run.coordinates.iter().enumerate() {
        let peak_abs = c.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let moving = peak_abs > o.still * scale;
        let win = &c.velocity[i0..];
        // Blocks of whole cycles of this coordinate's own strongest line.
        let f_own = stick_period
            .map(|p| 1.0 / p)
            .or_else(|| strongest_line(win, fs))
            .filter(|f| *f > 0.0);
        let bs_own = block(f_own).max(bs);
        let own_ok =
            win_len >= MIN_BLOCKS * bs_own && f_own.map_or(0.0, |f| f * span) >= o.min_cycles;
        let (rate, rate_se) = if trend_ok && own_ok && moving {
            let y = block_levels(win, bs_own);
            slope_se(&y).map_or((0.0, f64::INFINITY), |(b, se)| {
                let per_s = fs / bs_own as f64;
                (b * per_s, se * per_s)
            })
        } else {
            (0.0, f64::INFINITY)
        };
        let all = block_levels(c.velocity, bs.min(n.max(1)));
        let peak = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let tail_level = tail_rms[k].max(1e-300).ln();
        let run_change = match (all.first(), all.last()) {
            (Some(a), Some(b)) if all.len() >= 2 => (b - a) * DB_PER_NEPER,
            _ => 0.0,
        };
        j.trends.push(Trend {
            name: c.name.to_string(),
            rms: tail_rms[k],
            rate,
            rate_se,
            change_db: rate * span * DB_PER_NEPER,
            below_peak_db: ((peak - tail_level) * DB_PER_NEPER).max(0.0),
            run_change_db: run_change,
            moving,
        });
    }
    let moving: Vec<&Trend> = j.trends.iter().filter(|t| t.moving).collect();
    let growing: Vec<&Trend> = moving
        .iter()
        .copied()
        .filter(|t| trend_ok && t.grows(o, span))
        .collect();
    let all_decay = moving.iter().all(|t| t.decays(o, span));
    let fmt_rate = |t: &Trend| {
        format!(
            "{} at {:+.3e} ± {:.1e} 1/s ({:+.2} dB over the last {:.4} s)",
            t.name, t.rate, t.rate_se, t.change_db, span
        )
    };

    // 2.–8. The regimes, in order.
    let (verdict, reason) = if lifting && sep_cv > o.regular_cv {
        (
            RunVerdict::LiftOff,
            format!(
                "contact lost {} times{} in the last {span:.4} s, irregularly (interval CV {sep_cv:.2})",
                worst.map_or(separations, |c| c.separations),
                who(worst)
            ),
        )
    } else if let Some(g) = growing.first() {
        (RunVerdict::Grows, format!("still growing: {}", fmt_rate(g)))
    } else if lifting {
        // A contact that separates and recloses every cycle, regularly: a
        // cycle with contact loss, whatever sticks or reversals come with it.
        (
            RunVerdict::LimitCycle,
            format!(
                "steady over the last {span:.4} s, losing contact regularly{} ({} times, interval CV {sep_cv:.4}){}: contact loss, not stick-slip",
                who(worst),
                worst.map_or(separations, |c| c.separations),
                if sticks + reversals > 0 {
                    format!(", with {sticks} true sticks and {reversals} slip reversals")
                } else {
                    String::new()
                }
            ),
        )
    } else if friction_cycle {
        (
            RunVerdict::StickSlip,
            format!(
                "{sticks} true sticks and {reversals} slip reversals in the last {span:.4} s, recurring to the end; nothing grows"
            ),
        )
    } else if moving.is_empty() {
        (RunVerdict::Decays, "nothing moves".to_string())
    } else if all_decay {
        let t = moving
            .iter()
            .max_by(|a, b| a.rms.total_cmp(&b.rms))
            .copied()
            .expect("moving is not empty");
        (
            RunVerdict::Decays,
            if t.below_peak_db >= o.decayed_db {
                format!("{} fell {:.0} dB below its peak", t.name, t.below_peak_db)
            } else {
                format!("decaying: {}", fmt_rate(t))
            },
        )
    } else if !trend_ok {
        (
            RunVerdict::TooShort,
            format!(
                "the last {span:.4} s hold {cycles_in_window:.1} cycles ({win_len} samples): too short to tell"
            ),
        )
    } else if run.events.is_empty() && moving.iter().all(|t| t.run_change_db.abs() <= o.neutral_db)
    {
        (
            RunVerdict::Neutral,
            "steady from start to end, no events: undamped linear oscillation".to_string(),
        )
    } else {
        (
            RunVerdict::LimitCycle,
            format!("steady over the last {span:.4} s"),
        )
    };
    j.verdict = verdict;
    j.reason = reason;

    // The squeal answer.
    if verdict.squeals() {
        let candidates: Vec<usize> = (0..j.trends.len())
            .filter(|&k| {
                let t = &j.trends[k];
                t.moving
                    && if verdict == RunVerdict::Grows {
                        t.grows(o, span)
                    } else {
                        !t.decays(o, span)
                    }
            })
            .collect();
        let pick = candidates
            .iter()
            .copied()
            .max_by(|&a, &b| j.trends[a].rms.total_cmp(&j.trends[b].rms))
            .unwrap_or(loudest);
        let c = &run.coordinates[pick];
        let f = if verdict == RunVerdict::StickSlip {
            stick_period.map(|p| 1.0 / p)
        } else {
            None
        }
        .or_else(|| strongest_line(&c.velocity[i0..], fs));
        if let Some(f) = f {
            let r = j.trends[pick].rms;
            j.squeal = Some(Squeal {
                coordinate: c.name.to_string(),
                velocity: c.velocity_name.to_string(),
                frequency_hz: f,
                rms: r,
                level_db: 20.0 * r.max(1e-300).log10(),
            });
            let cycles = f * span;
            if cycles > 0.0 {
                j.cycle = Some(CycleEvents {
                    sticks,
                    reversals,
                    separations,
                    cycles,
                    sticks_per_cycle: sticks as f64 / cycles,
                    reversals_per_cycle: reversals as f64 / cycles,
                    separations_per_cycle: separations as f64 / cycles,
                });
            }
        }
    }
    Ok(j)
}

//! "What would stop it" for any model and any parameter (issue 26 §4;
//! docs/physics.md §5d): for every parameter of steady sliding,
//!
//! - the **sensitivity** of the most unstable eigenvalue,
//!   `dλ/dp = yᴴ (dA/dp) x / yᴴ x` from its left and right eigenvectors
//!   ([`squeal_core::stability::sensitivity`]), where `dA/dp` is the change
//!   of the state matrix at steady sliding, the steady state re-solved (a
//!   central difference of the linearisation, step `1e-5·|p|`: exact for
//!   the parameters the matrix is linear in, `O(1e-10)` relative else); at a
//!   coalescence, where `λ` is not differentiable, a one-sided difference of
//!   the eigenvalue itself, said so; for a model analysed by projection
//!   (above `modal.dense_max_dofs` dofs) a central difference of the
//!   projected eigenvalue, said so;
//! - in each direction, the **smallest change** that stops every growing
//!   mode growing (or, for a quiet brake, that starts one), the **stable
//!   window** beyond it (how far the parameter may drift before a mode
//!   grows again) and whether the change only **moves the squeal** to
//!   another mode (the growing mode stops growing while another starts);
//! - within the parameter's physical range: masses and stiffnesses stay
//!   positive, dampings non-negative, and a signed value (a speed, a force,
//!   a follower slope) keeps its sign — a lever never reverses the disc.
//!
//! The search scans outward on relative changes of 0.1 % to ×1000 (three
//! points a decade), then locates each change of the verdict with
//! [`stability::critical`] (Brent's method, `1e-10` relative: a lever equals
//! `squeal critical` on that bracket). Crossings closer together than the
//! scan's spacing may be missed. Parameters run in parallel, results in
//! their order: the same input gives the same output.

use crate::error::{Cancel, Progress, StudyError};
use crate::model::AnyModel;
use nalgebra::{Complex, DMatrix};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::{json, Value};
use squeal_core::params::ParamKind;
use squeal_core::stability::sensitivity::Eigenvectors;
use squeal_core::stability::track::rel_distance;
use squeal_core::stability::{self, is_growing, CriticalOptions, StabilityError};
use std::sync::atomic::{AtomicUsize, Ordering};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// Relative step of the central difference of the state matrix.
const MATRIX_STEP: f64 = 1e-5;
/// Relative step of the one-sided difference of an eigenvalue (coalescence,
/// projected models).
const EIGEN_STEP: f64 = 1e-6;
/// Scan points per decade of relative change.
const PER_DECADE: i32 = 3;
/// The scan's reach: relative changes up to ×1000 (and down to ÷1000).
const DECADES: i32 = 3;

/// Which way a lever moves its parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Way {
    /// To a larger value.
    Raise,
    /// To a smaller value.
    Lower,
}

impl Way {
    /// `raise` or `lower`.
    pub fn word(self) -> &'static str {
        match self {
            Way::Raise => "raise",
            Way::Lower => "lower",
        }
    }
}

/// A parameter value where the verdict changes, and the frequency of the
/// mode that crosses there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bound {
    /// The parameter value.
    pub value: f64,
    /// Frequency (Hz) of the mode that crosses.
    pub freq_hz: f64,
}

/// One parameter change that alone flips the verdict (all else as is).
#[derive(Debug, Clone, PartialEq)]
pub struct Lever {
    /// Parameter name.
    pub param: String,
    /// Its unit.
    pub unit: &'static str,
    /// Its current value.
    pub from: f64,
    /// A value in this direction where the verdict flips: for a squealing
    /// model, where a stable window begins (every window is a lever, the
    /// nearest first); for a quiet one, the nearest value where a mode grows.
    pub to: f64,
    /// Frequency (Hz) of the mode that crosses there.
    pub freq_hz: f64,
    /// Which way.
    pub way: Way,
    /// From squealing to stable (`true`: what would stop it), or from stable
    /// to squealing (`false`: what would start it).
    pub stops: bool,
    /// Beyond `to`, where the verdict flips back (the end of the stable
    /// window of a lever that stops the squeal); `None` if it does not
    /// within the search.
    pub until: Option<Bound>,
    /// How far the search went in this direction.
    pub searched_to: f64,
    /// Why the search ended before ×1000 (÷1000), if it did.
    pub search_ended: Option<String>,
}

impl Lever {
    /// `to − from`.
    pub fn change(&self) -> f64 {
        self.to - self.from
    }
    /// `(to − from)/|from|` (infinite for a parameter at 0).
    pub fn relative_change(&self) -> f64 {
        if self.from == 0.0 {
            f64::INFINITY * self.change().signum()
        } else {
            self.change() / self.from.abs()
        }
    }
}

/// A change that stops the growing mode but makes another grow: it only
/// moves the squeal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeMove {
    /// Parameter name.
    pub param: String,
    /// Its unit.
    pub unit: &'static str,
    /// Its current value.
    pub from: f64,
    /// Which way.
    pub way: Way,
    /// Where the growing mode stops growing (located to 1e-6 of the scan
    /// step by bisection on that mode's growth rate).
    pub at: f64,
    /// Frequency (Hz) of the mode that stops growing there.
    pub stops_hz: f64,
    /// Frequency (Hz) of the mode that grows there instead.
    pub grows_hz: f64,
    /// Its growth rate (1/s) there.
    pub growth_rate: f64,
    /// A mode within 5 % of that frequency was growing at the start already:
    /// the change stops one growing mode, not the squeal (else it moves the
    /// squeal to a mode that did not grow).
    pub already_growing: bool,
}

/// How a sensitivity was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Method {
    /// `yᴴ (dA/dp) x / yᴴ x` (first-order perturbation; exact).
    #[serde(rename = "eigenvectors")]
    Eigenvectors,
    /// The eigenvalue is at a coalescence (defective, no derivative): a
    /// one-sided difference of the eigenvalue, step `1e-6·|p|`.
    #[serde(rename = "one-sided difference at a coalescence")]
    Coalescence,
    /// The model is analysed by projection: a central difference of the
    /// projected eigenvalue, step `1e-6·|p|`.
    #[serde(rename = "difference of the projected eigenvalue")]
    Projected,
}

/// How the most unstable eigenvalue moves with one parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitivity {
    /// Parameter name.
    pub param: String,
    /// Its unit.
    pub unit: &'static str,
    /// Its current value.
    pub value: f64,
    /// `dσ/dp` (1/s per unit of the parameter).
    pub d_growth_rate: f64,
    /// `d(freq)/dp` (Hz per unit).
    pub d_freq_hz: f64,
    /// `p·dσ/dp` (1/s): the change of σ per unit relative change of `p`
    /// (a 1 % change moves σ by a hundredth of it).
    pub relative: f64,
    /// How it was computed.
    pub method: Method,
}

/// Everything [`search`] finds.
#[derive(Debug, Clone, PartialEq)]
pub struct Levers {
    /// The eigenvalue the sensitivities are of: the most unstable one
    /// (largest σ; `Im λ ≥ 0`).
    pub eigenvalue: Complex<f64>,
    /// Sensitivities, in parameter order.
    pub sensitivities: Vec<Sensitivity>,
    /// Levers, ranked by the relative change they need.
    pub levers: Vec<Lever>,
    /// Changes that only move the squeal to another mode.
    pub moves: Vec<ModeMove>,
    /// Parameters that do not enter steady sliding's linearisation (its
    /// state and matrix do not change with them: no lever, no sensitivity).
    pub inert: Vec<String>,
    /// How many eigen-analyses of steady sliding the search made (values
    /// whose state matrix is the operating point's reuse its eigenvalues;
    /// the state matrices of the sensitivities are not counted).
    pub analyses: usize,
}

impl Levers {
    /// No levers searched (`--no-levers`, Python's `levers=False`).
    pub fn none() -> Self {
        Levers {
            analyses: 0,
            eigenvalue: Complex::new(f64::NAN, f64::NAN),
            sensitivities: Vec::new(),
            levers: Vec::new(),
            moves: Vec::new(),
            inert: Vec::new(),
        }
    }

    /// The JSON of the search: `levers` (each with `param`, `from`, `to`,
    /// `freq_hz`, `unit`, `way`, `stops`, `change`, `relative_change`,
    /// `stable_until`, `searched_to`, `search_ended`), `sensitivities`,
    /// `sensitivity_of` (the eigenvalue), `mode_moves`, `inert_params` and
    /// `lever_analyses` (how many eigen-analyses the search made).
    pub fn to_json(&self) -> Value {
        let finite = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
        json!({
            "levers": self.levers.iter().map(|l| json!({
                "param": l.param, "from": l.from, "to": l.to, "freq_hz": l.freq_hz,
                "unit": l.unit, "way": l.way, "stops": l.stops,
                "change": l.change(), "relative_change": finite(l.relative_change()),
                "stable_until": l.until.map(|b| json!({ "value": b.value, "freq_hz": b.freq_hz })),
                "searched_to": l.searched_to, "search_ended": l.search_ended,
            })).collect::<Vec<_>>(),
            "sensitivity_of": if self.eigenvalue.re.is_finite() {
                json!({ "re": self.eigenvalue.re, "im": self.eigenvalue.im, "freq_hz": self.eigenvalue.im.abs() / TWO_PI })
            } else { Value::Null },
            "sensitivities": self.sensitivities,
            "mode_moves": self.moves,
            "inert_params": self.inert,
            "lever_analyses": self.analyses,
        })
    }
}

/// The parameters a lever may move: every key but start-up settings
/// (`t_ramp`, `*.ramp`) and numerical ones (`modal.*`).
pub fn lever_keys(model: &AnyModel) -> Vec<(String, &'static str, ParamKind)> {
    model
        .keys()
        .into_iter()
        .filter(|(k, ..)| k != "t_ramp" && !k.ends_with(".ramp") && !k.starts_with("modal."))
        .map(|(k, unit, _, kind)| (k, unit, kind))
        .collect()
}

/// One evaluation: the largest growth rate and its frequency (as
/// `squeal critical` computes them) and every eigenvalue with `Im λ ≥ 0`.
#[derive(Debug, Clone)]
struct Point {
    p: f64,
    sigma: f64,
    freq: f64,
    ev: Vec<Complex<f64>>,
}

impl Point {
    fn growing(&self) -> bool {
        is_growing(self.sigma, TWO_PI * self.freq)
    }
}

fn with_value(model: &AnyModel, name: &str, p: f64) -> Result<AnyModel, StabilityError> {
    let mut m = model.clone();
    m.set(name, p)?;
    m.validate()?;
    Ok(m)
}

/// Why an evaluation failed: cancelled, or no analysis at that value.
enum Failed {
    Interrupted,
    At(StabilityError),
}

impl From<Failed> for StudyError {
    fn from(f: Failed) -> Self {
        match f {
            Failed::Interrupted => StudyError::Interrupted,
            Failed::At(e) => crate::feasible::stability_error(e),
        }
    }
}

/// One parameter's search: the model, the parameter, and the state matrix
/// and eigenvalues at the operating point (a value whose state matrix is
/// bitwise that one has those eigenvalues: no eigen-solve).
struct Ctx<'a> {
    model: &'a AnyModel,
    name: &'a str,
    cancel: &'a Cancel,
    base: Option<&'a (DMatrix<f64>, Vec<Complex<f64>>)>,
    /// Analyses made (the steady state and every eigenvalue).
    count: &'a AtomicUsize,
    /// Extra analyses left for halving steps while following a mode.
    halvings: std::cell::Cell<u32>,
}

impl Ctx<'_> {
    fn eval(&self, p: f64) -> Result<Point, Failed> {
        if self.cancel.is_cancelled() {
            return Err(Failed::Interrupted);
        }
        let m = with_value(self.model, self.name, p).map_err(Failed::At)?;
        if let Some((a0, ev0)) = self.base {
            if let Some(r) = m.state_matrix() {
                let (_, a) = r.map_err(Failed::At)?;
                if a == *a0 {
                    return Ok(point(p, ev0.clone()));
                }
                self.count.fetch_add(1, Ordering::Relaxed);
                // What `eigenvalues` computes for this model, from the matrix at hand.
                let ev = squeal_core::stability::modal::eigenvalues(&a).map_err(Failed::At)?;
                return Ok(point(p, ev));
            }
        }
        self.count.fetch_add(1, Ordering::Relaxed);
        Ok(point(p, m.eigenvalues().map_err(Failed::At)?))
    }
}

fn point(p: f64, ev: Vec<Complex<f64>>) -> Point {
    let mut best = Complex::new(f64::NEG_INFINITY, 0.0);
    for e in &ev {
        if e.re > best.re || (e.re == best.re && e.im > best.im) {
            best = *e;
        }
    }
    Point {
        p,
        sigma: best.re,
        freq: best.im.abs() / TWO_PI,
        ev: ev.into_iter().filter(|e| e.im >= 0.0).collect(),
    }
}

/// The most unstable eigenvalue (largest σ, `Im λ ≥ 0`).
fn leading(ev: &[Complex<f64>]) -> Complex<f64> {
    let mut best = Complex::new(f64::NEG_INFINITY, 0.0);
    for e in ev.iter().filter(|e| e.im >= 0.0) {
        if e.re > best.re || (e.re == best.re && e.im > best.im) {
            best = *e;
        }
    }
    best
}

/// The eigenvalue of `ev` nearest `to` (relative distance), and whether it
/// is unambiguous (at most half as far as the next nearest).
fn nearest(ev: &[Complex<f64>], to: Complex<f64>) -> Option<(Complex<f64>, bool)> {
    let mut d: Vec<(f64, Complex<f64>)> = ev.iter().map(|e| (rel_distance(*e, to), *e)).collect();
    d.sort_by(|a, b| a.0.total_cmp(&b.0));
    let first = d.first()?;
    let clear = d.get(1).is_none_or(|second| first.0 <= 0.5 * second.0);
    Some((first.1, clear))
}

/// Scan values outward from `cur` in one direction, within the parameter's
/// physical range: relative changes 10^(−3 + k/3) up to ×1000 away from 0;
/// towards 0, down to `cur`/1000 (and 0 itself for a non-negative
/// parameter). A parameter at 0 moves by 1e-6 … 1e3 (absolute).
fn scan_points(cur: f64, kind: ParamKind, way: Way) -> Vec<f64> {
    let steps = |lo: i32, hi: i32| (lo..=hi).map(|k| 10f64.powf(k as f64 / PER_DECADE as f64));
    if cur == 0.0 {
        let up: Vec<f64> = steps(-6 * PER_DECADE, DECADES * PER_DECADE).collect();
        return match (way, kind) {
            (Way::Raise, _) => up,
            (Way::Lower, ParamKind::Any) => up.into_iter().map(|v| -v).collect(),
            (Way::Lower, _) => Vec::new(),
        };
    }
    let away = (way == Way::Raise) == (cur > 0.0);
    if away {
        return steps(-DECADES * PER_DECADE, DECADES * PER_DECADE)
            .map(|d| cur * (1.0 + d))
            .collect();
    }
    let mut out: Vec<f64> = steps(-DECADES * PER_DECADE, -1)
        .take_while(|d| *d < 0.5)
        .map(|d| cur * (1.0 - d))
        .collect();
    out.extend(steps(-DECADES * PER_DECADE, -2).rev().map(|f| cur * f));
    if kind == ParamKind::NonNegative {
        out.push(0.0);
    }
    out
}

/// The crossing between two scan points of different verdicts, located by
/// [`stability::critical`] on that bracket (the growth rate as `squeal
/// critical` computes it); the midpoint if that fails.
fn locate(ctx: &Ctx, a: &Point, b: &Point) -> Bound {
    let (model, name) = (ctx.model, ctx.name);
    let (lo, hi) = if a.p < b.p { (a.p, b.p) } else { (b.p, a.p) };
    let opts = CriticalOptions {
        grid: 2,
        ..CriticalOptions::default()
    };
    let f = |p: f64| {
        ctx.count.fetch_add(1, Ordering::Relaxed);
        crate::critical::growth_at(model, name, p)
    };
    match stability::critical(f, lo, hi, &opts) {
        Ok(Some(c)) => Bound {
            value: c.value,
            freq_hz: c.freq_hz,
        },
        _ => {
            let g = if a.growing() { a } else { b };
            Bound {
                value: 0.5 * (a.p + b.p),
                freq_hz: g.freq,
            }
        }
    }
}

/// What one direction of one parameter holds.
struct Direction {
    levers: Vec<Lever>,
    moved: Option<ModeMove>,
}

/// Most stable windows reported per direction.
const MAX_WINDOWS: usize = 4;

/// Scan one direction. From a squealing start: every stable window (up to
/// [`MAX_WINDOWS`]), each a lever — where it begins and where it ends. From
/// a quiet start: the first value where a mode grows. From a squealing
/// start without a window this way, follow the growing mode along the scan
/// until it stops growing: a mode move if another mode grows there.
fn scan_direction(
    ctx: &Ctx,
    unit: &'static str,
    kind: ParamKind,
    way: Way,
    start: &Point,
) -> Result<Direction, StudyError> {
    let name = ctx.name;
    let mut seen: Vec<Point> = vec![start.clone()];
    // (entry, exit) of each window; for a quiet start, the one crossing.
    let mut windows: Vec<(Bound, Option<Bound>)> = Vec::new();
    let mut search_ended = None;
    let full = |w: &Vec<(Bound, Option<Bound>)>| {
        if start.growing() {
            w.len() >= MAX_WINDOWS && w.last().is_some_and(|x| x.1.is_some())
        } else {
            !w.is_empty()
        }
    };
    let mut probed = 0;
    'scan: for p in scan_points(start.p, kind, way) {
        let next = match ctx.eval(p) {
            Ok(pt) => pt,
            Err(Failed::Interrupted) => return Err(StudyError::Interrupted),
            Err(Failed::At(e)) => {
                search_ended = Some(crate::error::for_terminal(&format!(
                    "at {name} = {}: {e}",
                    squeal_core::params::short(p)
                )));
                break;
            }
        };
        let prev = seen.last().expect("the start is seen");
        // The nearest gaps first: at most PROBED_GAPS per direction.
        let mut between = if probed < PROBED_GAPS {
            probe(ctx, prev, &next, PROBE_DEPTH)?
        } else {
            Vec::new()
        };
        if !between.is_empty() {
            probed += 1;
        }
        between.push(next);
        for next in between {
            let prev = seen.last().expect("the start is seen");
            if next.growing() != prev.growing() {
                let b = locate(ctx, prev, &next);
                if next.growing() && start.growing() {
                    if let Some(w) = windows.last_mut() {
                        w.1 = Some(b);
                    }
                } else {
                    windows.push((b, None));
                }
            }
            seen.push(next);
            if full(&windows) {
                break 'scan;
            }
        }
    }
    let searched_to = seen.last().map_or(start.p, |p| p.p);
    ctx.halvings.set(FOLLOW_HALVINGS);
    let moved = if windows.is_empty() && start.growing() {
        follow_along(ctx, unit, way, &seen)?
    } else {
        None
    };
    let levers = windows
        .into_iter()
        .map(|(b, until)| Lever {
            param: name.to_string(),
            unit,
            from: start.p,
            to: b.value,
            freq_hz: b.freq_hz,
            way,
            stops: start.growing(),
            until,
            searched_to,
            search_ended: if until.is_some() {
                None
            } else {
                search_ended.clone()
            },
        })
        .collect();
    Ok(Direction { levers, moved })
}

/// How many times [`probe`] halves a scan step.
const PROBE_DEPTH: u32 = 4;
/// How many gaps between scan points [`probe`] looks into per direction
/// (the nearest ones: the windows that need the smallest change).
const PROBED_GAPS: u32 = 2;
/// Most step halvings while following a mode along one direction.
const FOLLOW_HALVINGS: u32 = 16;

/// Between two scan points that both squeal but through different modes
/// (leading frequencies more than 2 % apart), one mode's growth falls as
/// another's rises, and a stable window may lie between them, narrower than
/// the step: probe the midpoint, recursively (`depth` halvings at most),
/// and return the points evaluated, in order. Elsewhere nothing.
fn probe(ctx: &Ctx, a: &Point, b: &Point, depth: u32) -> Result<Vec<Point>, StudyError> {
    let same_mode = (a.freq - b.freq).abs() <= 0.02 * a.freq.max(b.freq);
    if depth == 0 || !a.growing() || !b.growing() || same_mode {
        return Ok(Vec::new());
    }
    let m = match ctx.eval(midpoint(a.p, b.p)) {
        Ok(m) => m,
        Err(Failed::Interrupted) => return Err(StudyError::Interrupted),
        Err(Failed::At(_)) => return Ok(Vec::new()),
    };
    let mut out = probe(ctx, a, &m, depth - 1)?;
    let rest = probe(ctx, &m, b, depth - 1)?;
    out.push(m);
    out.extend(rest);
    Ok(out)
}

/// Follow the growing mode of `seen[0]` along the scanned points `seen`
/// (every one of them squealing) until it stops growing; where it does, the
/// mode that grows instead, unless the two are one mode veering past
/// another (then follow that one on).
fn follow_along(
    ctx: &Ctx,
    unit: &'static str,
    way: Way,
    seen: &[Point],
) -> Result<Option<ModeMove>, StudyError> {
    let start = &seen[0];
    let lam0 = leading(&start.ev);
    let mut tr = Track {
        p: start.p,
        lam: lam0,
        before: None,
    };
    for next in &seen[1..] {
        loop {
            match follow(ctx, &tr, next, 0)? {
                Followed::Growing(t) => tr = t,
                Followed::Lost => return Ok(None),
                Followed::Stops { at, lambda } => {
                    let there = match ctx.eval(at) {
                        Ok(t) => t,
                        Err(Failed::Interrupted) => return Err(StudyError::Interrupted),
                        Err(Failed::At(_)) => return Ok(None),
                    };
                    if !there.growing() {
                        return Ok(None);
                    }
                    let g = leading(&there.ev);
                    if rel_distance(g, lambda) < VEERING {
                        // Two modes veer past each other: the growth goes on
                        // in the other branch; follow it from here.
                        tr = Track {
                            p: at,
                            lam: g,
                            before: None,
                        };
                        if at == next.p {
                            break;
                        }
                        continue;
                    }
                    return Ok(Some(ModeMove {
                        param: ctx.name.to_string(),
                        unit,
                        from: start.p,
                        way,
                        at,
                        stops_hz: lambda.im / TWO_PI,
                        grows_hz: there.freq,
                        growth_rate: there.sigma,
                        already_growing: start.ev.iter().any(|e| {
                            *e != lam0
                                && is_growing(e.re, e.im)
                                && (e.im - g.im).abs() <= 0.05 * g.im.abs()
                        }),
                    }));
                }
            }
            break;
        }
    }
    Ok(None)
}

/// Two eigenvalues closer than this (relative) where the followed mode
/// stops growing are one mode veering past another, not a new mode.
const VEERING: f64 = 0.02;

/// A mode followed along the scan: its last two values, for a linear
/// prediction of the next.
#[derive(Debug, Clone, Copy)]
struct Track {
    p: f64,
    lam: Complex<f64>,
    before: Option<(f64, Complex<f64>)>,
}

impl Track {
    fn predict(&self, p: f64) -> Complex<f64> {
        match self.before {
            Some((p0, l0)) if p0 != self.p => {
                self.lam + (self.lam - l0) * ((p - self.p) / (self.p - p0))
            }
            _ => self.lam,
        }
    }
    fn step(&self, p: f64, lam: Complex<f64>) -> Track {
        Track {
            p,
            lam,
            before: Some((self.p, self.lam)),
        }
    }
}

enum Followed {
    Growing(Track),
    Lost,
    Stops { at: f64, lambda: Complex<f64> },
}

/// Follow the mode `tr` to the point `b`: the eigenvalue of `b` nearest its
/// prediction, halving the step (at most 3 times, and at most
/// [`FOLLOW_HALVINGS`] times along a direction) where that is not clearly
/// the nearest. Where it stops growing, bisect (on log scale when both ends
/// have one sign) twenty times for the value where it does (to 1e-6 of
/// the step).
fn follow(ctx: &Ctx, tr: &Track, b: &Point, depth: u32) -> Result<Followed, StudyError> {
    let Some((l, clear)) = nearest(&b.ev, tr.predict(b.p)) else {
        return Ok(Followed::Lost);
    };
    if !clear && depth < 3 && ctx.halvings.get() > 0 {
        ctx.halvings.set(ctx.halvings.get() - 1);
        let m = match ctx.eval(midpoint(tr.p, b.p)) {
            Ok(m) => m,
            Err(Failed::Interrupted) => return Err(StudyError::Interrupted),
            Err(Failed::At(_)) => return Ok(Followed::Lost),
        };
        return match follow(ctx, tr, &m, depth + 1)? {
            Followed::Growing(t) => follow(ctx, &t, b, depth + 1),
            other => Ok(other),
        };
    }
    if is_growing(l.re, l.im) {
        return Ok(Followed::Growing(tr.step(b.p, l)));
    }
    let (mut lo, mut hi, mut hi_ev) = (*tr, (b.p, l), b.ev.clone());
    for _ in 0..20 {
        let mid = midpoint(lo.p, hi.0);
        let m = match ctx.eval(mid) {
            Ok(m) => m,
            Err(Failed::Interrupted) => return Err(StudyError::Interrupted),
            Err(Failed::At(_)) => break,
        };
        let Some((lm, _)) = nearest(&m.ev, lo.predict(mid)) else {
            break;
        };
        if is_growing(lm.re, lm.im) {
            lo = lo.step(mid, lm);
        } else {
            (hi, hi_ev) = ((mid, lm), m.ev);
        }
    }
    // A mode that stops growing does so continuously: its eigenvalue on
    // both sides of the bracket agrees. If it does not, the following
    // jumped to another mode (two frequencies crossing): go on with the
    // growing eigenvalue nearest the followed one, if any.
    if rel_distance(lo.lam, hi.1) > CONTINUITY {
        let growing: Vec<Complex<f64>> = hi_ev
            .into_iter()
            .filter(|e| is_growing(e.re, e.im))
            .collect();
        return Ok(match nearest(&growing, lo.lam) {
            Some((g, _)) if rel_distance(g, lo.lam) <= CONTINUITY => Followed::Growing(Track {
                p: hi.0,
                lam: g,
                before: None,
            }),
            _ => Followed::Lost,
        });
    }
    Ok(Followed::Stops {
        at: hi.0,
        lambda: hi.1,
    })
}

/// Largest relative jump of a followed eigenvalue across a bracket of 1e-6
/// of a scan step (a continuous change there is ~1e-6 relative).
const CONTINUITY: f64 = 1e-4;

/// The middle of `[a, b]`: geometric when both have one sign.
fn midpoint(a: f64, b: f64) -> f64 {
    if a * b > 0.0 {
        a.signum() * (a.abs() * b.abs()).sqrt()
    } else {
        0.5 * (a + b)
    }
}

/// The sensitivity of `lam` to `name`, or `None` when the linearisation
/// does not change with it (inert).
fn sensitivity(
    model: &AnyModel,
    name: &str,
    unit: &'static str,
    cur: f64,
    dense: Option<&(Vec<f64>, DMatrix<f64>, Eigenvectors)>,
    lam: Complex<f64>,
    cancel: &Cancel,
) -> Result<Option<Sensitivity>, StudyError> {
    cancel.check()?;
    let step = |rel: f64| if cur == 0.0 { rel } else { rel * cur.abs() };
    let make = |d: Complex<f64>, method| Sensitivity {
        param: name.to_string(),
        unit,
        value: cur,
        d_growth_rate: d.re,
        d_freq_hz: d.im / TWO_PI,
        relative: cur * d.re,
        method,
    };
    // The eigenvalue nearest `lam` at p (one-sided and projected differences).
    let eig_at = |p: f64| -> Option<Complex<f64>> {
        let ev = with_value(model, name, p).ok()?.eigenvalues().ok()?;
        let ev: Vec<Complex<f64>> = ev.into_iter().filter(|e| e.im >= 0.0).collect();
        nearest(&ev, lam).map(|(l, _)| l)
    };
    let Some((z0, a0, vecs)) = dense else {
        // Projected: a central (one-sided at a range end) difference of the eigenvalue.
        let h = step(EIGEN_STEP);
        let (up, down) = (eig_at(cur + h), eig_at(cur - h));
        let d = match (up, down) {
            (Some(u), Some(d)) if u == d => return Ok(None),
            (Some(u), Some(d)) => (u - d) / (2.0 * h),
            (Some(u), None) => (u - lam) / h,
            (None, Some(d)) => (lam - d) / h,
            (None, None) => return Ok(None),
        };
        return Ok(Some(make(d, Method::Projected)));
    };
    let h = step(MATRIX_STEP);
    let at = |p: f64| with_value(model, name, p).ok()?.state_matrix()?.ok();
    let (up, down) = (at(cur + h), at(cur - h));
    let (da, inert) = match (&up, &down) {
        (Some((zu, au)), Some((zd, ad))) => ((au - ad) / (2.0 * h), zu == zd && au == ad),
        (Some((zu, au)), None) => ((au - a0) / h, zu == z0 && au == a0),
        (None, Some((zd, ad))) => ((a0 - ad) / h, zd == z0 && ad == a0),
        (None, None) => return Ok(None),
    };
    if inert {
        return Ok(None);
    }
    if vecs.defective() {
        let h = step(EIGEN_STEP);
        let (d, h) = match eig_at(cur + h) {
            Some(u) => (u, h),
            None => match eig_at(cur - h) {
                Some(d) => (d, -h),
                None => return Ok(None),
            },
        };
        return Ok(Some(make((d - lam) / h, Method::Coalescence)));
    }
    Ok(Some(make(vecs.derivative(&da), Method::Eigenvectors)))
}

/// What one parameter holds.
struct OneParam {
    sensitivity: Option<Sensitivity>,
    levers: Vec<Lever>,
    moves: Vec<ModeMove>,
    inert: bool,
}

/// Every lever, sensitivity and mode move of `model` ([module docs](self)).
/// `progress` counts parameters; `cancel` stops the search.
pub fn search(
    model: &AnyModel,
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<Levers, StudyError> {
    let ev = model
        .eigenvalues()
        .map_err(crate::feasible::stability_error)?;
    let start_ev = ev.clone();
    let start = point(f64::NAN, ev);
    let lam = leading(&start.ev);
    let dense = match model.state_matrix() {
        Some(r) => {
            let (z, a) = r.map_err(crate::feasible::stability_error)?;
            Eigenvectors::of(&a, lam).map(|v| (z, a, v))
        }
        None => None,
    };
    // The operating point's state matrix and eigenvalues, for the dense
    // analyses of models of no fixed size (where an eigen-solve costs).
    let base = match (&dense, model) {
        (Some((_, a, _)), AnyModel::Lumped(l))
            if l.dof_count() > squeal_core::model::lumped::MAX_EXACT_DOFS =>
        {
            Some((a.clone(), start_ev.clone()))
        }
        _ => None,
    };
    let keys = lever_keys(model);
    let count = AtomicUsize::new(0);
    let per: Vec<OneParam> = keys
        .par_iter()
        .map(|(name, unit, kind)| {
            let Some(cur) = model.get(name) else {
                return Ok(OneParam {
                    sensitivity: None,
                    levers: Vec::new(),
                    moves: Vec::new(),
                    inert: false,
                });
            };
            let s = sensitivity(model, name, unit, cur, dense.as_ref(), lam, cancel)?;
            let mut one = OneParam {
                inert: s.is_none(),
                sensitivity: s,
                levers: Vec::new(),
                moves: Vec::new(),
            };
            if !one.inert {
                let start = Point {
                    p: cur,
                    ..start.clone()
                };
                let ctx = Ctx {
                    model,
                    name,
                    cancel,
                    base: base.as_ref(),
                    count: &count,
                    halvings: std::cell::Cell::new(0),
                };
                for way in [Way::Raise, Way::Lower] {
                    let d = scan_direction(&ctx, unit, *kind, way, &start)?;
                    one.levers.extend(d.levers);
                    one.moves.extend(d.moved);
                }
            }
            progress.inc(1);
            Ok(one)
        })
        .collect::<Result<_, StudyError>>()?;
    progress.finish();
    let mut out = Levers {
        analyses: count.into_inner(),
        eigenvalue: lam,
        sensitivities: Vec::new(),
        levers: Vec::new(),
        moves: Vec::new(),
        inert: Vec::new(),
    };
    for ((name, ..), one) in keys.iter().zip(per) {
        if one.inert {
            out.inert.push(name.clone());
        }
        out.sensitivities.extend(one.sensitivity);
        out.levers.extend(one.levers);
        out.moves.extend(one.moves);
    }
    out.levers.sort_by(|a, b| {
        a.relative_change()
            .abs()
            .total_cmp(&b.relative_change().abs())
            .then_with(|| a.param.cmp(&b.param))
    });
    Ok(out)
}

//! Stability over a grid of any two parameters: linear (the largest growth
//! rate of steady sliding) or transient (one simulation per point, stopped
//! once its outcome is certain), in parallel and deterministic.
//!
//! A grid of `nx × ny` points is numbered row-major over y then x: point
//! `k` is `(x[k % nx], y[k / nx])` ([`point`]). The grid functions compute
//! the points they are given (all of them, or a shard's share) and return
//! one row per point in the order given; a point's result does not depend
//! on which others are computed with it, so shards merge bit for bit.

use crate::analysis::position_noise;
use crate::critical::growth_at;
use crate::error::{Cancel, Progress, StudyError};
use crate::model::AnyModel;
use crate::scenario::{InputError, Scenario};
use rayon::prelude::*;
use squeal_core::integrate::ensemble::{simulate_ensemble_lanes, Job, LaneField};
use squeal_core::integrate::{Flow, Sink};
use squeal_core::model::lumped::{Fixed, MAX_EXACT_DOFS};
use squeal_core::stability::StabilityError;
use squeal_core::{simulate, EventKind, IntegrateError, Mode, RunInfo};
use squeal_core::{DiscPad, System};

/// Points per progress report of a linear grid.
const CHUNK: usize = 256;

/// Points per task of a transient grid: a task's disc–pad and small lumped
/// points run four at a time on its core ([`simulate_ensemble_lanes`]; a
/// lane whose point is decided takes the task's next point), the others
/// one by one.
const TRANSIENT_CHUNK: usize = 16;

/// One grid axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Parameter name.
    pub name: String,
    /// Grid values.
    pub values: Vec<f64>,
    /// Logarithmic spacing.
    pub log: bool,
}

/// The two axes of a map must vary different parameters.
pub fn check_distinct(x: &Axis, y: &Axis) -> Result<(), InputError> {
    if x.name == y.name {
        return Err(InputError(format!(
            "--x and --y both vary {}: choose two parameters",
            x.name
        )));
    }
    Ok(())
}

/// Parse `NAME=LO:HI:N` into grid values.
pub fn parse_axis(spec: &str, flag: &str, log: bool, model: &AnyModel) -> Result<Axis, InputError> {
    let bad = |why: &str| InputError(format!("{flag} {spec}: {why}"));
    let (name, range) = spec
        .split_once('=')
        .ok_or_else(|| bad("expected NAME=LO:HI:N"))?;
    let parts: Vec<&str> = range.split(':').collect();
    if parts.len() != 3 {
        return Err(bad("expected NAME=LO:HI:N"));
    }
    let lo: f64 = parts[0]
        .trim()
        .parse()
        .map_err(|_| bad("LO is not a number"))?;
    let hi: f64 = parts[1]
        .trim()
        .parse()
        .map_err(|_| bad("HI is not a number"))?;
    let n: usize = parts[2]
        .trim()
        .parse()
        .map_err(|_| bad("N is not a whole number"))?;
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad("need finite LO < HI"));
    }
    if !(2..=4000).contains(&n) {
        return Err(bad("N must be between 2 and 4000"));
    }
    if log && lo <= 0.0 {
        return Err(bad("a logarithmic axis needs LO > 0"));
    }
    let name = name.trim().to_string();
    if model.get(&name).is_none() {
        return Err(bad(&format!(
            "unknown parameter '{name}' for model {}",
            model.name()
        )));
    }
    crate::critical::check_endpoints(model, &name, lo, hi).map_err(|why| bad(&why))?;
    let values = (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            if i + 1 == n {
                hi
            } else if log {
                (lo.ln() + s * (hi.ln() - lo.ln())).exp()
            } else {
                lo + s * (hi - lo)
            }
        })
        .collect();
    Ok(Axis { name, values, log })
}

/// Unit of a parameter, for axis labels.
pub fn unit_of(model: &AnyModel, name: &str) -> &'static str {
    model
        .keys()
        .into_iter()
        .find(|k| k.0 == name)
        .map(|k| k.1)
        .unwrap_or("")
}

/// The grid indices `(i, j)` of flat point `k` (`x[i]`, `y[j]`).
pub fn point(x: &Axis, k: usize) -> (usize, usize) {
    let nx = x.values.len();
    (k % nx, k / nx)
}

/// Every flat point index of the grid, in order.
pub fn all_points(x: &Axis, y: &Axis) -> Vec<usize> {
    (0..x.values.len() * y.values.len()).collect()
}

/// Linear map over `points` (flat indices, see [`point`]): `(σ_max,
/// freq_hz)` per point, in the order given; NaN where steady sliding does
/// not exist or the parameters are invalid. A point whose state matrix is
/// not finite is an error (naming the point and the parameter to blame),
/// not a blank; the first such point in `points`' order is reported.
/// `progress` counts points; `cancel` is looked at before every point.
pub fn linear_grid(
    model: &AnyModel,
    x: &Axis,
    y: &Axis,
    points: &[usize],
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<Vec<(f64, f64)>, StudyError> {
    let rows: Vec<Result<(f64, f64), StudyError>> = points
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let out: Vec<_> = chunk
                .iter()
                .map(|&k| linear_point(model, x, y, k, cancel))
                .collect();
            progress.inc(chunk.len() as u64);
            out
        })
        .collect();
    cancel.check()?;
    rows.into_iter().collect()
}

/// One point of [`linear_grid`].
fn linear_point(
    model: &AnyModel,
    x: &Axis,
    y: &Axis,
    k: usize,
    cancel: &Cancel,
) -> Result<(f64, f64), StudyError> {
    cancel.check()?;
    let (i, j) = point(x, k);
    let mut m = model.clone();
    let r = m
        .set(&y.name, y.values[j])
        .map_err(StabilityError::from)
        .and_then(|_| growth_at(&m, &x.name, x.values[i]));
    match r {
        Ok(p) => Ok(p),
        Err(e @ StabilityError::NonFinite { .. }) => {
            let _ = m.set(&x.name, x.values[i]);
            let why = crate::feasible::stability_failure(&m, e);
            Err(StudyError::Input(InputError(format!(
                "at {} = {:e}, {} = {:e}: {why}",
                x.name, x.values[i], y.name, y.values[j]
            ))))
        }
        Err(_) => Ok((f64::NAN, f64::NAN)),
    }
}

/// Outcome of one transient run.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// decays, grows, stick-slip, steady, out-of-range, failed, or
    /// too-short (see [`CLASSES`]).
    pub class: &'static str,
    /// RMS of the tangential velocity over the last window (m/s).
    pub rms: f64,
    /// Fraction of the time in true stick.
    pub stick_fraction: f64,
    /// Time the run ended (early once the class is certain).
    pub t_end: f64,
    /// A-weighted sound pressure level (dB(A) re 20 µPa) over the last
    /// window, from the scenario's radiating surfaces ([`crate::radiation`]);
    /// NaN without surfaces or motion.
    pub spl_dba: f64,
}

impl Outcome {
    /// The outcome of a point that could not run.
    pub const FAILED: Outcome = Outcome {
        class: "failed",
        rms: f64::NAN,
        stick_fraction: f64::NAN,
        t_end: f64::NAN,
        spl_dba: f64::NAN,
    };
}

/// Watches the tangential velocities in windows and stops the run once its
/// class is certain: decayed by 60 dB from its peak in a run that moved
/// (some position beyond [`Watch::still`] from its start), or
/// stick-slip/reversals with a steady amplitude (±2 % over three windows).
struct Watch {
    idx: Vec<usize>,
    v_idx: usize,
    window: f64,
    next: f64,
    cur_max: f64,
    sum2: f64,
    count: usize,
    amps: Vec<f64>,
    last_rms: f64,
    events_in_window: usize,
    event_windows: Vec<usize>,
    peak: f64,
    /// Integration noise (m) of the positions ([`position_noise`] of the
    /// largest at the start).
    still: f64,
    /// Every position at the start.
    q0: Vec<f64>,
    /// Whether some position has moved further than `still` from its start.
    moved: bool,
    decided: Option<&'static str>,
    /// The scenario's validity bound (m): a position beyond it ends the run `out-of-range`.
    validity: f64,
    /// The radiating surfaces: their velocities' state indices and areas (m²).
    surfaces: Vec<(usize, f64)>,
    /// Their velocities over the current window, interleaved (capacity
    /// reserved for a whole window: no allocation while running).
    current: Vec<f64>,
    /// The same over the last complete window.
    last: Vec<f64>,
}

impl<const N: usize> Sink<N> for Watch {
    fn sample(&mut self, t: f64, z: &[f64; N], _mode: Mode) -> Flow {
        if z[..N / 2]
            .iter()
            .any(|q| q.is_nan() || q.abs() > self.validity)
        {
            self.decided = Some("out-of-range");
            return Flow::Stop;
        }
        if !self.moved {
            self.moved = z[..N / 2]
                .iter()
                .zip(&self.q0)
                .any(|(q, q0)| (q - q0).abs() > self.still);
        }
        let a = self.idx.iter().map(|&i| z[i].abs()).fold(0.0, f64::max);
        self.cur_max = self.cur_max.max(a);
        self.sum2 += z[self.v_idx] * z[self.v_idx];
        self.count += 1;
        if self.current.len() + self.surfaces.len() <= self.current.capacity() {
            for &(i, _) in &self.surfaces {
                self.current.push(z[i]);
            }
        }
        if t < self.next {
            return Flow::Continue;
        }
        self.next = t + self.window;
        std::mem::swap(&mut self.current, &mut self.last);
        self.current.clear();
        let amp = self.cur_max;
        self.last_rms = (self.sum2 / self.count.max(1) as f64).sqrt();
        self.amps.push(amp);
        self.event_windows.push(self.events_in_window);
        self.peak = self.peak.max(amp);
        (self.cur_max, self.sum2, self.count, self.events_in_window) = (0.0, 0.0, 0, 0);
        let n = self.amps.len();
        if n >= 4 {
            let recent = &self.amps[n - 4..];
            let steady = recent
                .windows(2)
                .all(|w| (w[1] - w[0]).abs() <= 0.02 * w[1].max(1e-300));
            if self.event_windows[n - 3..].iter().all(|&e| e > 0) && steady {
                self.decided = Some("stick-slip");
                return Flow::Stop;
            }
            if self.moved && amp < 1e-3 * self.peak && recent.windows(2).all(|w| w[1] <= w[0]) {
                self.decided = Some("decays");
                return Flow::Stop;
            }
        }
        Flow::Continue
    }
    fn event(&mut self, _t: f64, kind: EventKind, _z: &[f64; N], _mode: Mode) {
        if matches!(kind, EventKind::Stick | EventKind::Reverse) {
            self.events_in_window += 1;
        }
    }
}

/// The sink that watches a transient run of `model`, and its start.
fn watch_for<M: System<N>, const N: usize>(
    model: &M,
    sc: &Scenario,
) -> Result<(Watch, [f64; N]), String> {
    let names = model.names();
    // The tangential velocities: a lumped model's are those of its
    // contacts' tangential dofs (whatever the dofs are called: `x_d`, or an
    // FE model's `6_1`); a built-in's are named `vx…` (`v` for the belt).
    let idx: Vec<usize> = match &sc.model {
        AnyModel::Lumped(l) => {
            let mut idx = Vec::new();
            for c in &l.contacts {
                for &i in &c.tangent.idx {
                    if N / 2 + i < N && !idx.contains(&(N / 2 + i)) {
                        idx.push(N / 2 + i);
                    }
                }
            }
            idx
        }
        _ => (N / 2..N)
            .filter(|&i| names[i].starts_with("vx") || names[i] == "v")
            .collect(),
    };
    let v_idx = *idx.first().ok_or("no tangential velocity")?;
    let z0 = crate::run::initial_of(model, sc).map_err(|e| e.to_string())?;
    let window = sc.duration / 50.0;
    let surfaces: Vec<(usize, f64)> = sc
        .radiation
        .areas
        .iter()
        .filter_map(|(dof, a)| {
            names[..N / 2]
                .iter()
                .position(|n| n == dof)
                .map(|i| (i + N / 2, *a))
        })
        .collect();
    // A window's samples, and a few more for the sample that closes it.
    let room = ((window * sc.sample_rate).ceil() as usize + 4) * surfaces.len();
    let w = Watch {
        idx,
        v_idx,
        window,
        next: window,
        cur_max: 0.0,
        sum2: 0.0,
        count: 0,
        amps: Vec::new(),
        last_rms: 0.0,
        events_in_window: 0,
        event_windows: Vec::new(),
        peak: 0.0,
        still: position_noise(
            z0[..N / 2].iter().fold(0.0, |m: f64, q| m.max(q.abs())),
            &sc.solver,
        ),
        q0: z0[..N / 2].to_vec(),
        moved: false,
        decided: None,
        validity: sc.validity,
        surfaces,
        current: Vec::with_capacity(room),
        last: Vec::with_capacity(room),
    };
    Ok((w, z0))
}

/// The A-weighted level of the last complete window of `w`'s surfaces
/// (NaN when there is none, or it is silent).
fn last_window_dba(w: &Watch, sc: &Scenario) -> f64 {
    let k = w.surfaces.len();
    if k == 0 || w.last.len() < 2 * k {
        return f64::NAN;
    }
    let columns: Vec<Vec<f64>> = (0..k)
        .map(|j| w.last.iter().skip(j).step_by(k).copied().collect())
        .collect();
    let surfaces: Vec<(f64, &[f64])> = w
        .surfaces
        .iter()
        .zip(&columns)
        .map(|(&(_, a), c)| (a, c.as_slice()))
        .collect();
    let l = sc.radiation.listener().levels(&surfaces, sc.sample_rate);
    if l.spl_dba.is_finite() {
        l.spl_dba
    } else {
        f64::NAN
    }
}

/// The outcome of a watched run that ended with `info`.
fn classify(
    w: &Watch,
    sc: &Scenario,
    info: Result<RunInfo, IntegrateError>,
) -> Result<Outcome, String> {
    let info = info.map_err(|e| e.to_string())?;
    let class = w.decided.unwrap_or_else(|| {
        // From a start at round-off (an FE brake at its equilibrium, no
        // offset) a growing mode can stay under the fast modes' decaying
        // transient for the whole run: a trend of noise tells nothing.
        if !w.moved {
            return "too-short";
        }
        let n = w.amps.len();
        if n < 6 {
            return "steady";
        }
        // Trend over the second half of the run: ±5 % decides.
        let (early, late) = (w.amps[n / 2], w.amps[n - 1]);
        if late > 1.05 * early {
            "grows"
        } else if late < 0.95 * early {
            "decays"
        } else if w.event_windows[n - 3..].iter().any(|&e| e > 0) {
            "stick-slip"
        } else {
            "steady"
        }
    });
    Ok(Outcome {
        class,
        rms: w.last_rms,
        stick_fraction: info.stats.stick_fraction(),
        t_end: info.t_final,
        spl_dba: last_window_dba(w, sc),
    })
}

fn transient_point<M: System<N>, const N: usize>(
    model: &M,
    sc: &Scenario,
) -> Result<Outcome, String> {
    let (mut w, z0) = watch_for(model, sc)?;
    // Each window's peak is taken over the scenario's samples: at 200 kHz it is
    // within a few % of the envelope, which is all a class needs.
    let info = simulate(
        model,
        0.0,
        z0,
        sc.duration,
        sc.sample_rate,
        crate::run::sim_options::<N>(sc),
        &mut w,
    );
    classify(&w, sc, info)
}

/// Transient map over `points` (flat indices, see [`point`]): one
/// simulation per point, stopped early once its class is certain; one
/// [`Outcome`] per point in the order given (`failed` where the point
/// cannot run). The points go in tasks of 16, whose disc–pads and small
/// lumped models run as an ensemble on one core (the same bits as one at a
/// time). `progress` counts points; `cancel` is looked at before every
/// task and ends the map with [`StudyError::Interrupted`].
pub fn transient_grid(
    sc: &Scenario,
    x: &Axis,
    y: &Axis,
    points: &[usize],
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<Vec<Outcome>, StudyError> {
    let out: Vec<Vec<Outcome>> = points
        .par_chunks(TRANSIENT_CHUNK)
        .map(|chunk| {
            if cancel.is_cancelled() {
                return vec![Outcome::FAILED; chunk.len()];
            }
            let o = transient_chunk(sc, x, y, chunk);
            progress.inc(chunk.len() as u64);
            o
        })
        .collect();
    cancel.check()?;
    Ok(out.concat())
}

/// The points of one task of [`transient_grid`]: each exactly as
/// [`transient_at`] computes it (the ensemble's runs are bit for bit the
/// single runs). Disc–pads and lumped models of at most
/// [`MAX_EXACT_DOFS`](squeal_core::model::lumped::MAX_EXACT_DOFS) dofs run
/// [`LANES`](squeal_core::integrate::ensemble::LANES) at a time, the others
/// one by one.
fn transient_chunk(sc: &Scenario, x: &Axis, y: &Axis, chunk: &[usize]) -> Vec<Outcome> {
    let mut out = vec![Outcome::FAILED; chunk.len()];
    let mut discs: Vec<(usize, Scenario)> = Vec::new();
    let mut lumped: Vec<(usize, Scenario)> = Vec::new();
    for (n, &k) in chunk.iter().enumerate() {
        match prepared(sc, x, y, k) {
            Ok(s) if s.sample_rate != sc.sample_rate => {
                out[n] = run_prepared(&s).unwrap_or(Outcome::FAILED)
            }
            Ok(s) if matches!(s.model, AnyModel::DiscPad(_)) => discs.push((n, s)),
            Ok(s) if matches!(&s.model, AnyModel::Lumped(l) if l.dof_count() <= MAX_EXACT_DOFS) => {
                lumped.push((n, s))
            }
            Ok(s) => out[n] = run_prepared(&s).unwrap_or(Outcome::FAILED),
            Err(_) => {}
        }
    }
    let discs: Vec<(usize, &Scenario, &DiscPad)> = discs
        .iter()
        .filter_map(|(n, s)| match &s.model {
            AnyModel::DiscPad(m) => Some((*n, s, m)),
            _ => None,
        })
        .collect();
    run_lanes(&discs, sc.sample_rate, &mut out);
    // A map's lumped points share their model's structure, so one size.
    if let Some((_, first)) = lumped.first() {
        if let AnyModel::Lumped(l) = &first.model {
            squeal_core::with_lumped_size!(&**l, m => lumped_lanes(m, &lumped, sc.sample_rate, &mut out),
            else => for (n, s) in &lumped {
                out[*n] = run_prepared(s).unwrap_or(Outcome::FAILED);
            });
        }
    }
    out
}

/// [`run_lanes`] for lumped models of the size of `_size` (any of
/// another size runs one by one).
fn lumped_lanes<const N: usize>(
    _size: &Fixed<'_, N>,
    points: &[(usize, Scenario)],
    sample_rate: f64,
    out: &mut [Outcome],
) {
    let mut fixed = Vec::new();
    for (n, s) in points {
        match &s.model {
            AnyModel::Lumped(l) if 2 * l.dof_count() == N => fixed.push((*n, s, Fixed::<N>(l))),
            _ => out[*n] = run_prepared(s).unwrap_or(Outcome::FAILED),
        }
    }
    let fixed: Vec<(usize, &Scenario, &Fixed<'_, N>)> =
        fixed.iter().map(|(n, s, m)| (*n, *s, m)).collect();
    run_lanes(&fixed, sample_rate, out);
}

/// The transient runs of `points` (slot in `out`, prepared scenario, its
/// model) as one ensemble ([`simulate_ensemble_lanes`]): each outcome
/// exactly as [`transient_at`]'s.
fn run_lanes<M: LaneField<N>, const N: usize>(
    points: &[(usize, &Scenario, &M)],
    sample_rate: f64,
    out: &mut [Outcome],
) {
    let mut jobs: Vec<Job<'_, M, Watch, N>> = Vec::new();
    let mut slots = Vec::new();
    for &(n, s, m) in points {
        if let Ok((sink, z0)) = watch_for(m, s) {
            jobs.push(Job {
                model: m,
                t0: 0.0,
                z0,
                t_end: s.duration,
                opts: crate::run::sim_options::<N>(s),
                sink,
            });
            slots.push((n, s));
        }
    }
    let results = simulate_ensemble_lanes(&mut jobs, sample_rate);
    for ((job, r), (n, s)) in jobs.iter().zip(results).zip(slots) {
        out[n] = classify(&job.sink, s, r).unwrap_or(Outcome::FAILED);
    }
}

/// The scenario of point `k`: both parameters set, validated, and checked
/// for a simulated run (its own step budget).
fn prepared(sc: &Scenario, x: &Axis, y: &Axis, k: usize) -> Result<Scenario, String> {
    let (i, j) = point(x, k);
    let mut s = sc.clone();
    s.model
        .set(&x.name, x.values[i])
        .and_then(|_| s.model.set(&y.name, y.values[j]))
        .and_then(|_| s.model.validate())
        .map_err(|e| e.to_string())
        // Each point gets its own step budget (its stiffness differs).
        .and_then(|_| crate::feasible::prepare(&mut s).map_err(|e| e.to_string()))?;
    Ok(s)
}

/// The transient run of a prepared point, one at a time.
fn run_prepared(s: &Scenario) -> Result<Outcome, String> {
    crate::with_transient_system!(&s.model, m => transient_point(m, s),
        else => Err(s.model.check_simulable().err().unwrap_or_default()))
}

/// One point of [`transient_grid`].
pub fn transient_at(sc: &Scenario, x: &Axis, y: &Axis, k: usize) -> Outcome {
    prepared(sc, x, y, k)
        .and_then(|s| run_prepared(&s))
        .unwrap_or(Outcome::FAILED)
}

/// Do the linear verdict (σ) and the simulated outcome tell the same story?
/// `yes` or `no`; `n/a` where there is no linear verdict (no steady sliding)
/// or no outcome (the run failed, or was too short to tell). Never empty.
pub fn agree(sigma: f64, o: &Outcome) -> &'static str {
    if !sigma.is_finite() || matches!(o.class, "failed" | "too-short") {
        return "n/a";
    }
    let unstable = sigma > 0.0;
    // A growing, friction-limited, sustained or runaway outcome is what an
    // unstable equilibrium predicts; decay is what a stable one predicts.
    let sustained = matches!(o.class, "grows" | "stick-slip" | "steady" | "out-of-range");
    if unstable == sustained {
        "yes"
    } else {
        "no"
    }
}

/// The outcome classes of a transient map, in legend order.
///
/// `too-short`: no position moved further from its start than integration
/// noise ([`STILL_TOLERANCES`](crate::analysis::STILL_TOLERANCES)
/// tolerances of the integrator, [`position_noise`]) in the whole
/// run: from a start at round-off, the run cannot tell growth from decay
/// (give the scenario an offset, or a longer duration).
pub const CLASSES: [&str; 7] = [
    "decays",
    "grows",
    "stick-slip",
    "steady",
    "out-of-range",
    "failed",
    "too-short",
];

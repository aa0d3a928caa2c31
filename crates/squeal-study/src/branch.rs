//! The limit cycle followed in one parameter by
//! `squeal_core::cycle::continuation` (pseudo-arclength through folds; grid
//! values the branch does not reach are settled afresh by simulation), with
//! the bifurcations along it (folds, period doubling, Neimark–Sacker,
//! grazing/sliding) and where it meets steady sliding, compared with
//! `critical`'s Hopf point.

use crate::cycle::{self, Found};
use crate::error::{Cancel, Progress, StudyError};
use crate::scenario::{InputError, Scenario};
use serde_json::{json, Value};
use squeal_core::cycle::continuation::{
    self as cont, BranchOptions, PointKind, Reparametrise, SegmentEnd, Varied,
};
use squeal_core::cycle::{find_cycle, CycleError};
use squeal_core::stability::Crossing;

/// `n` evenly spaced values from `lo` to `hi`.
pub fn values(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Every check before any work: a known parameter, a simulable model whose
/// linearisation is finite, and every value acceptable (messages name
/// `--param`).
pub fn check(sc: &Scenario, name: &str, values: &[f64]) -> Result<(), StudyError> {
    if let Some(f) = sc.model.forcing_hz().first() {
        return Err(InputError(format!(
            "{}: the model is forced (a harmonic force at {f} Hz): branch follows self-excited orbits by shooting; `squeal hb --param {name}=…` follows a forced response",
            sc.name
        ))
        .into());
    }
    check_param(sc, name, values)
}

/// [`check`] without the refusal of forced models (`hb --param` takes them).
pub fn check_param(sc: &Scenario, name: &str, values: &[f64]) -> Result<(), StudyError> {
    if sc.model.get(name).is_none() {
        return Err(InputError(format!(
            "--param {name}: unknown parameter for model {}",
            sc.model.name()
        ))
        .into());
    }
    sc.model.check_cycle_size().map_err(InputError)?;
    // i9's validation path, the part that applies to a cycle (which budgets
    // its own settling): a linearisation that overflows is named by parameter.
    crate::feasible::scales(&sc.model, Some(sc))
        .map_err(|e| crate::feasible::stability_failure(&sc.model, e))?;
    for &v in values {
        let mut m = sc.model.clone();
        m.set(name, v)
            .and_then(|_| m.validate())
            .map_err(|e| InputError(format!("--param {name}={v}: {e}")))?;
    }
    Ok(())
}

/// A followed branch.
#[derive(Debug, Clone)]
pub struct Branch {
    /// The rows: each grid value the branch passes (twice or more where it
    /// folds back over it) and each fold, segment by segment in the order
    /// followed.
    pub points: Vec<BranchPoint>,
    /// Every computed point, intermediate steps included, for the diagram:
    /// `(segment, value, amplitude of every state, stable)`.
    pub curve: Vec<(usize, f64, Vec<f64>, bool)>,
    /// `(value, why)` where no cycle was found.
    pub failures: Vec<(f64, String)>,
    /// The bifurcations along the segments.
    pub bifurcations: Vec<cont::Bifurcation>,
    /// How each segment (continuation run) ended.
    pub ends: Vec<SegmentEnd>,
    /// Where steady sliding changes stability in the range (`critical`'s
    /// Hopf point, scanned on 64 points), if it does.
    pub hopf: Option<Crossing>,
}

/// Follow the cycle of `sc` over `values` of `name` (checked by [`check`]);
/// `range` is the interval searched for the Hopf point. `progress` counts
/// values settled afresh and, at the end, the rest; `cancel` is looked at
/// before every settling and every system the continuation builds.
pub fn follow(
    sc: &Scenario,
    name: &str,
    values: &[f64],
    range: (f64, f64),
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<Branch, StudyError> {
    let opts = cycle::options(sc, 20_000_000, 1000.0);
    let names = sc.model.state_names();
    let bopts = BranchOptions {
        cycle: opts,
        ..BranchOptions::default()
    };
    let mut settled = 0;
    let out = crate::with_sim_system!(&sc.model, m => {
        // The family checks the cancel token each time it builds a system,
        // so an interrupted continuation fails every step at once.
        let family = Varied { model: m, name };
        let guarded = Guarded { inner: &family, cancel };
        let mut settle = |v: f64| {
            if cancel.is_cancelled() {
                return Err(CycleError::Bad("interrupted".into()));
            }
            settled += 1;
            progress.inc(1);
            let mut out = Err(CycleError::Bad(format!("{name} = {v}: no system")));
            m.with_param(name, v, &mut |sys| {
                out = crate::run::initial_of(sys, sc)
                    .map_err(|e| CycleError::Bad(e.to_string()))
                    .and_then(|z0| find_cycle(sys, 0.0, z0, &opts));
            })
            .map_err(CycleError::Bad)?;
            out
        };
        let b = cont::branch(&guarded, values, &mut settle, &bopts);
        Ok(collect(&b, &names))
    }, else => Err(StudyError::Input(InputError(sc.model.check_cycle_size().err().unwrap_or_default()))));
    cancel.check()?;
    progress.inc(values.len().saturating_sub(settled) as u64);
    let (points, curve, failures, bifurcations, ends) = out?;
    let hopf = crate::critical::locate(&sc.model, name, range.0, range.1, 64, cancel)
        .ok()
        .flatten();
    cancel.check()?;
    Ok(Branch {
        points,
        curve,
        failures,
        bifurcations,
        ends,
        hopf,
    })
}

/// A family that fails once `cancel` is set.
pub(crate) struct Guarded<'a, F: ?Sized> {
    pub(crate) inner: &'a F,
    pub(crate) cancel: &'a Cancel,
}

impl<F: cont::Family<N> + ?Sized, const N: usize> cont::Family<N> for Guarded<'_, F> {
    fn visit(&self, p: f64, f: &mut dyn FnMut(&dyn squeal_core::System<N>)) -> Result<(), String> {
        if self.cancel.is_cancelled() {
            return Err("interrupted".into());
        }
        self.inner.visit(p, f)
    }
}

type Collected = (
    Vec<BranchPoint>,
    Vec<(usize, f64, Vec<f64>, bool)>,
    Vec<(f64, String)>,
    Vec<cont::Bifurcation>,
    Vec<SegmentEnd>,
);

fn collect<const N: usize>(b: &cont::Branch<N>, names: &[String]) -> Collected {
    let mut points = Vec::new();
    let mut curve = Vec::new();
    let real = cycle::real_states::<N>(names.len());
    for p in &b.points {
        curve.push((
            p.segment,
            p.value,
            real.iter().map(|&i| p.cycle.amplitude[i]).collect(),
            p.cycle.stable,
        ));
        let kind = match p.kind {
            PointKind::Grid(_) => "grid",
            PointKind::Fold => "fold",
            PointKind::Step => continue,
        };
        points.push(BranchPoint {
            value: p.value,
            found: cycle::found_of(&p.cycle, names.to_vec()),
            kind,
            segment: p.segment,
        });
    }
    let failures = b
        .failures
        .iter()
        .map(|(v, e)| (*v, format!("cycle: {e}")))
        .collect();
    (
        points,
        curve,
        failures,
        b.bifurcations.clone(),
        b.ends.clone(),
    )
}

impl Branch {
    /// Where segments shrink onto steady sliding: `(value, frequency in Hz)`
    /// extrapolated in the squared amplitude.
    pub fn steady_sliding(&self) -> Vec<(f64, f64)> {
        self.ends
            .iter()
            .filter_map(|e| match e {
                SegmentEnd::SteadySliding { value, freq_hz } => Some((*value, *freq_hz)),
                _ => None,
            })
            .collect()
    }

    /// The document `summary.json` holds: `param`, `points` (each cycle's
    /// JSON with its `value`, `point` (`grid` or `fold`) and `segment`),
    /// `bifurcations` (`kind`, `between`, `value`, `detail`), `segments` (how
    /// each ended), `failed`, `hopf` (with the branch's point nearest to it
    /// and the branch's own end on steady sliding, `branch_end`) and the
    /// `scenario`.
    pub fn to_json(&self, name: &str, sc: &Scenario) -> Value {
        let steady = self.steady_sliding();
        let hopf = self.hopf.as_ref().map(|c| {
            let near = self.points.iter().min_by(|p, q| {
                (p.value - c.value)
                    .abs()
                    .total_cmp(&(q.value - c.value).abs())
            });
            let end = steady
                .iter()
                .min_by(|a, b| (a.0 - c.value).abs().total_cmp(&(b.0 - c.value).abs()));
            json!({
                "value": c.value,
                "freq_hz": c.freq_hz,
                "nearest_point": near.map(|p| json!({
                    "value": p.value,
                    "cycle_freq_hz": 1.0 / p.found.period,
                    "max_multiplier": p.found.max_multiplier,
                })),
                "branch_end": end.map(|&(v, f)| json!({
                    "value": v,
                    "freq_hz": f,
                    "value_difference": v - c.value,
                    "freq_difference_hz": f - c.freq_hz,
                })),
            })
        });
        let segments: Vec<Value> = self
            .ends
            .iter()
            .map(|e| match e {
                SegmentEnd::LeftRange => json!({ "end": "left_range" }),
                SegmentEnd::Steps => json!({ "end": "steps" }),
                SegmentEnd::Stalled { value, cause } => {
                    json!({ "end": "stalled", "value": value, "cause": cause })
                }
                SegmentEnd::SteadySliding { value, freq_hz } => {
                    json!({ "end": "steady_sliding", "value": value, "freq_hz": freq_hz })
                }
            })
            .collect();
        json!({
            "param": name,
            "points": self.points.iter().map(|p| {
                let mut v = p.found.to_json();
                v["value"] = json!(p.value);
                v["point"] = json!(p.kind);
                v["segment"] = json!(p.segment);
                v
            }).collect::<Vec<_>>(),
            "bifurcations": self.bifurcations.iter().map(|x| json!({
                "kind": x.kind.as_str(),
                "between": [x.between.0, x.between.1],
                "value": x.value,
                "detail": x.detail,
            })).collect::<Vec<_>>(),
            "segments": segments,
            "failed": self.failures.iter().map(|(v, e)| json!({ "value": v, "error": e })).collect::<Vec<_>>(),
            "hopf": hopf,
            "scenario": sc.to_json(),
        })
    }
}

/// One row of the branch.
#[derive(Debug, Clone)]
pub struct BranchPoint {
    /// The parameter's value.
    pub value: f64,
    /// The cycle there.
    pub found: Found,
    /// `grid` (one of the evenly spaced values) or `fold`.
    pub kind: &'static str,
    /// The continuation run it belongs to.
    pub segment: usize,
}

/// Most grid values of a branch (each one a limit cycle found by
/// continuation: up to seconds of work; 10 000 is hours at most).
pub const MAX_BRANCH_POINTS: usize = 10_000;

/// Parse `NAME=LO:HI:N` (`squeal branch --param`): N evenly spaced
/// values of NAME from LO to HI, LO < HI finite, 2 ≤ N ≤ [`MAX_BRANCH_POINTS`].
pub fn parse_range(spec: &str) -> Result<(String, f64, f64, usize), InputError> {
    let bad = || {
        InputError(format!(
            "--param {spec}: expected NAME=LO:HI:N with numbers LO < HI and N ≥ 2"
        ))
    };
    let (name, range) = spec.split_once('=').ok_or_else(bad)?;
    let parts: Vec<&str> = range.split(':').collect();
    if parts.len() != 3 {
        return Err(bad());
    }
    let lo: f64 = parts[0].trim().parse().map_err(|_| bad())?;
    let hi: f64 = parts[1].trim().parse().map_err(|_| bad())?;
    let n: usize = parts[2].trim().parse().map_err(|_| bad())?;
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad());
    }
    if !(2..=MAX_BRANCH_POINTS).contains(&n) {
        return Err(InputError(format!(
            "--param {spec}: N = {n}: a branch has from 2 to {MAX_BRANCH_POINTS} grid values (each is a limit cycle: seconds of work)"
        )));
    }
    Ok((name.trim().to_string(), lo, hi, n))
}

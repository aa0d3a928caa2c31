//! The limit cycle followed in one parameter by natural-parameter
//! continuation (each point's Newton shooting starts from the previous
//! cycle; a point where that fails is settled afresh by simulation), with
//! the changes of stability and of the event structure along the branch.

use crate::cycle::{self, Found};
use crate::error::{Cancel, Progress, StudyError};
use crate::scenario::{InputError, Scenario};
use serde_json::{json, Value};
use squeal_core::cycle::Section;
use squeal_core::stability::Crossing;
use squeal_core::EventKind;

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
    if sc.model.get(name).is_none() {
        return Err(InputError(format!(
            "--param {name}: unknown parameter for model {}",
            sc.model.name()
        ))
        .into());
    }
    sc.model.check_simulable().map_err(InputError)?;
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
    /// The points where a cycle was found, in parameter order.
    pub points: Vec<BranchPoint>,
    /// `(value, why)` where none was.
    pub failures: Vec<(f64, String)>,
    /// `(value, next value, what changes)` between neighbouring points.
    pub bifurcations: Vec<(f64, f64, String)>,
    /// Where steady sliding changes stability in the range (`critical`'s
    /// Hopf point, scanned on 64 points), if it does.
    pub hopf: Option<Crossing>,
}

/// Follow the cycle of `sc` over `values` of `name` (checked by [`check`]);
/// `range` is the interval searched for the Hopf point. `progress` counts
/// values; `cancel` is looked at between points.
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
    let mut points: Vec<BranchPoint> = Vec::with_capacity(values.len());
    let mut failures = Vec::new();
    for &v in values {
        cancel.check()?;
        let mut p = sc.clone();
        p.model
            .set(name, v)
            .map_err(|e| InputError(e.to_string()))?;
        let prev = points.last().map(|q| &q.found);
        let found = continue_from(&p, prev, &names, &opts)
            .or_else(|_| cycle::of_scenario(&p, &opts, false, cancel));
        cancel.check()?;
        match found {
            Ok(f) => points.push(BranchPoint { value: v, found: f }),
            Err(e) => failures.push((v, e.to_string())),
        }
        progress.inc(1);
    }
    let mut bifurcations = Vec::new();
    for w in points.windows(2) {
        for what in transition(&w[0].found, &w[1].found) {
            bifurcations.push((w[0].value, w[1].value, what));
        }
    }
    let hopf = crate::critical::locate(&sc.model, name, range.0, range.1, 64, cancel)
        .ok()
        .flatten();
    cancel.check()?;
    Ok(Branch {
        points,
        failures,
        bifurcations,
        hopf,
    })
}

impl Branch {
    /// The document `summary.json` holds: `param`, `points` (each cycle's
    /// JSON with its `value`), `bifurcations`, `failed`, `hopf` (with the
    /// branch's point nearest to it) and the `scenario`.
    pub fn to_json(&self, name: &str, sc: &Scenario) -> Value {
        let hopf = self.hopf.as_ref().map(|c| {
            let near = self.points.iter().min_by(|p, q| {
                (p.value - c.value)
                    .abs()
                    .total_cmp(&(q.value - c.value).abs())
            });
            json!({
                "value": c.value,
                "freq_hz": c.freq_hz,
                "nearest_point": near.map(|p| json!({
                    "value": p.value,
                    "cycle_freq_hz": 1.0 / p.found.period,
                    "max_multiplier": p.found.max_multiplier,
                })),
            })
        });
        json!({
            "param": name,
            "points": self.points.iter().map(|p| {
                let mut v = p.found.to_json();
                v["value"] = json!(p.value);
                v
            }).collect::<Vec<_>>(),
            "bifurcations": self.bifurcations.iter().map(|(a, b, what)| json!({ "between": [a, b], "kind": what })).collect::<Vec<_>>(),
            "failed": self.failures.iter().map(|(v, e)| json!({ "value": v, "error": e })).collect::<Vec<_>>(),
            "hopf": hopf,
            "scenario": sc.to_json(),
        })
    }
}

/// One point of the branch.
#[derive(Debug, Clone)]
pub struct BranchPoint {
    /// The parameter's value.
    pub value: f64,
    /// The cycle there.
    pub found: Found,
}

/// What changes between two neighbouring points: a bifurcation's name.
pub fn transition(a: &Found, b: &Found) -> Vec<String> {
    let mut out = Vec::new();
    if a.events != b.events {
        let show = |e: &[u64; 5]| {
            EventKind::ALL
                .iter()
                .filter(|k| e[k.index()] > 0)
                .map(|k| format!("{} {}", e[k.index()], k.as_str()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        out.push(format!(
            "grazing/sliding: the events per period change ({} → {})",
            show(&a.events),
            show(&b.events)
        ));
    }
    if a.stable != b.stable {
        // The multiplier that crossed the unit circle: the largest non-trivial
        // one on the unstable side.
        let side = if a.stable { b } else { a };
        let crit = side
            .multipliers
            .iter()
            .filter(|m| !m.2)
            .max_by(|x, y| x.0.hypot(x.1).total_cmp(&y.0.hypot(y.1)));
        let kind = match crit {
            Some(&(re, im, _)) if im.abs() > 1e-9 * re.hypot(im) => "Neimark–Sacker",
            Some(&(re, _, _)) if re < 0.0 => "period doubling",
            _ => "fold (a real multiplier through +1)",
        };
        out.push(format!(
            "{kind}: stability {} → {}",
            if a.stable { "stable" } else { "unstable" },
            if b.stable { "stable" } else { "unstable" }
        ));
    }
    if (b.period / a.period - 1.0).abs() > 0.5 {
        out.push(format!(
            "the period jumps ({:.6e} → {:.6e} s): another cycle",
            a.period, b.period
        ));
    }
    out
}

/// Newton shooting from the previous point's cycle.
fn continue_from(
    sc: &Scenario,
    prev: Option<&Found>,
    names: &[String],
    opts: &squeal_core::cycle::CycleOptions,
) -> Result<Found, StudyError> {
    let Some(prev) = prev else {
        return Err(StudyError::Numerical("no previous point".into()));
    };
    let index = names
        .iter()
        .position(|n| *n == prev.section.0)
        .ok_or_else(|| StudyError::Numerical("section lost".into()))?;
    let section = Section {
        index,
        level: prev.section.1,
    };
    crate::with_system!(&sc.model, m => {
        cycle::find(m, &sc.model, &prev.z0, Some((&prev.z0, prev.period, section)), opts, false)
    }, else => Err(StudyError::Numerical("not simulable".into())))
}

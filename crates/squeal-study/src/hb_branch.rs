//! `squeal hb SCENARIO --param NAME=LO:HI:N`: the harmonic-balance solution
//! followed in one parameter (`squeal_core::hb::hb_branch`, pseudo-arclength
//! through folds). For a forced model with `NAME` its forcing frequency
//! (`<force>.freq_hz`) this is the frequency-response curve through
//! resonance; for a self-excited one, the branch of its periodic orbit (as
//! `squeal branch` follows it by shooting). The first point is `squeal hb`
//! at `NAME = LO` (settled by simulation); every point's stability is one
//! exact period from its HB state (Floquet multipliers with saltation).

use crate::branch::Guarded;
use crate::cycle::real_states;
use crate::error::{Cancel, StudyError};
use crate::hb::{amplitudes, of_scenario, Guess, HbFound, Stability};
use crate::scenario::{InputError, Scenario};
use rayon::prelude::*;
use serde_json::{json, Value};
use squeal_core::cycle::continuation::{Reparametrise, Varied};
use squeal_core::cycle::{self, CycleOptions};
use squeal_core::hb::continuation::{
    hb_branch_from, BranchStart, HbBranch, HbBranchEnd, HbBranchOptions,
};
use squeal_core::hb::{forced_response, harmonic_balance, HbError, HbOptions};
use squeal_core::stability::Crossing;
use squeal_core::System;

/// One point of an HB branch.
#[derive(Debug, Clone, PartialEq)]
pub struct HbBranchRow {
    /// The parameter's value.
    pub value: f64,
    /// Period (s).
    pub period: f64,
    /// Half peak-to-peak of each state over the period (from the series).
    pub amplitude: Vec<f64>,
    /// Largest multiplier modulus (non-trivial, for an autonomous orbit).
    pub max_multiplier: f64,
    /// Whether it is stable.
    pub stable: bool,
    /// Whether the multipliers resolve that verdict (farther from the unit
    /// circle than their error).
    pub resolved: bool,
    /// Scaled HB residual.
    pub residual: f64,
    /// Whether stick was imposed as a constraint (the dynamic Lagrangian
    /// step) at this point, rather than friction balanced as slip.
    pub stick_constraint: bool,
    /// `step`, or `fold` for the point nearest a fold.
    pub kind: &'static str,
}

/// A followed HB branch.
#[derive(Debug, Clone)]
pub struct HbBranchFound {
    /// The parameter.
    pub name: String,
    /// Whether the model is forced (the curve is a frequency response).
    pub forced: bool,
    /// Harmonics.
    pub harmonics: usize,
    /// State names.
    pub names: Vec<String>,
    /// The points in the order followed.
    pub rows: Vec<HbBranchRow>,
    /// Folds: the parameter at each (on the parabola through its neighbours).
    pub folds: Vec<f64>,
    /// Why the branch ended.
    pub end: String,
    /// `squeal hb` at the first value (`None`: no orbit there; the branch
    /// then starts at the Hopf point `hopf`).
    pub start: Option<HbFound>,
    /// Where the branch was born from steady sliding, when it was started
    /// there (`critical`'s Hopf point in the range).
    pub hopf: Option<Crossing>,
    /// What the numbers do not support.
    pub warnings: Vec<String>,
}

fn why_end(e: &HbBranchEnd, lo: f64, hi: f64, from_hopf: bool) -> String {
    match e {
        HbBranchEnd::Reached => format!("reached the range's end ({hi})"),
        HbBranchEnd::LeftRange if from_hopf => {
            format!("left the range at its start ({lo}): the orbit grows towards it")
        }
        HbBranchEnd::LeftRange => "turned back and left the range at its start".into(),
        HbBranchEnd::Collapsed(p) => {
            format!("the orbit shrank onto steady sliding near {p} (a Hopf point)")
        }
        HbBranchEnd::Stalled(p, why) => format!(
            "no continuation step converged at {p}: {why} (where a switch appears on the orbit — grazing, or a contact beginning to stick — the HB residual is not smooth, and stick is not balanced here; `squeal branch` follows the orbit by shooting)"
        ),
        HbBranchEnd::MaxPoints => "the most points a branch may have".into(),
    }
}

/// Follow the HB solution of `sc` from `name = lo` to `hi`, the grid
/// spacing `(hi − lo)/(steps − 1)` the largest step (`--param`, checked by
/// `crate::branch::parse_range`), with `harmonics` harmonics; `opts` are
/// `squeal cycle`'s (the first point's settling, the Floquet periods).
///
/// A self-excited model with no orbit at `lo` that HB takes (its
/// oscillation dies out there, or its orbit there sticks) whose steady
/// sliding changes stability inside the range
/// (`critical`'s Hopf point, scanned on 64 points) has its branch started
/// at that Hopf point instead, from the critical mode's small orbit
/// ([`BranchStart::Hopf`]), and followed in the direction the orbit grows.
pub fn follow(
    sc: &Scenario,
    name: &str,
    lo: f64,
    hi: f64,
    steps: usize,
    harmonics: usize,
    opts: &CycleOptions,
    cancel: &Cancel,
) -> Result<HbBranchFound, StudyError> {
    crate::branch::check_param(sc, name, &[lo, hi])?;
    crate::hb::check_harmonics(harmonics)?;
    let mut first = sc.clone();
    first
        .model
        .set(name, lo)
        .map_err(|e| InputError(format!("--param {name}={lo}: {e}")))?;
    let (start, hopf) = match of_scenario(&first, harmonics, opts, Guess::Settle, false, cancel) {
        Ok(s) => (Some(s), None),
        Err(e @ StudyError::Interrupted) => return Err(e),
        Err(e) if !sc.model.forcing_hz().is_empty() => return Err(e),
        Err(e) => match crate::critical::locate(&sc.model, name, lo, hi, 64, cancel) {
            Ok(Some(c)) if !c.from_neutral && c.value > lo.min(hi) && c.value < lo.max(hi) => {
                (None, Some(c))
            }
            _ => return Err(e),
        },
    };
    cancel.check()?;
    // An orbit at `lo` that sticks was solved with stick as a constraint: it
    // is not a solution of the balance with friction as slip, so the whole
    // branch goes on that way.
    let bopts = HbBranchOptions {
        hb: HbOptions {
            harmonics,
            lagrangian: start.as_ref().is_some_and(|s| s.stick_constraint),
            ..HbOptions::default()
        },
        ..HbBranchOptions::default()
    };
    let names = sc.model.state_names();
    crate::with_sim_system!(&sc.model, m => {
        follow_in(m, name, lo, hi, steps, harmonics, opts, (start, hopf), names, &bopts, cancel)
    }, else => Err(StudyError::Input(InputError(sc.model.check_cycle_size().err().unwrap_or_default()))))
}

#[allow(clippy::too_many_arguments)]
fn follow_in<M: System<N> + Reparametrise<N> + ?Sized, const N: usize>(
    m: &M,
    name: &str,
    lo: f64,
    hi: f64,
    steps: usize,
    harmonics: usize,
    opts: &CycleOptions,
    (start, hopf): (Option<HbFound>, Option<Crossing>),
    names: Vec<String>,
    bopts: &HbBranchOptions,
    cancel: &Cancel,
) -> Result<HbBranchFound, StudyError> {
    {
        let family = Varied { model: m, name };
        let guarded = Guarded {
            inner: &family,
            cancel,
        };
        let real = real_states::<N>(m.norm_states());
        let (series, from) = match (&start, &hopf) {
            (Some(s), _) => (s.series.clone(), BranchStart::Lo),
            (None, Some(c)) => {
                // The critical mode's orbit at 5 % of the amplitude where its
                // motion first meets a nonlinearity, measured in that amplitude.
                let mut guess = Err(StudyError::Numerical(format!(
                    "hb --param: {name} = {}: no system",
                    c.value
                )));
                m.with_param(name, c.value, &mut |sys| {
                    guess = crate::hb::hopf_guess(sys, &real, 1.0, false);
                })
                .map_err(|e| StudyError::Numerical(format!("hb --param: {e}")))?;
                let Some(full) = guess? else {
                    return Err(StudyError::Numerical(format!(
                        "hb --param: no orbit at {name} = {lo}, and at the Hopf point {name} = {} the critical mode meets no nonlinearity to bound its orbit",
                        c.value
                    )));
                };
                let top = (0..full.coeffs.len())
                    .map(|i| full.amplitude(i, 1))
                    .fold(0.0, f64::max);
                let mut small = full.clone();
                for cf in &mut small.coeffs {
                    cf[1] *= 0.05;
                    cf[2] *= 0.05;
                }
                (
                    small,
                    BranchStart::Hopf {
                        p_h: c.value,
                        scale: top,
                    },
                )
            }
            (None, None) => unreachable!("follow gives a start or a Hopf point"),
        };
        let mut br =
            hb_branch_from(&guarded, lo, hi, steps, &series, from, bopts).map_err(|e| match e {
                HbError::Bad(m) => StudyError::Input(InputError(format!("hb --param: {m}"))),
                other => StudyError::Numerical(format!("hb --param: {other}")),
            })?;
        cancel.check()?;
        let stick_from = if bopts.hb.lagrangian {
            None
        } else {
            with_stick(&guarded, &mut br, lo, hi, steps, bopts)
        };
        cancel.check()?;
        let forced = start.as_ref().is_some_and(|s| s.forcing_hz.is_some());
        // Each point's stability by one exact period (independent, in
        // parallel; the order of the results is the points').
        let stab: Vec<Result<(f64, bool, bool), String>> = br
            .points
            .par_iter()
            .map(|pt| {
                let period = pt.orbit.period();
                let mut out = Err(format!("{name} = {}: no system", pt.p));
                m.with_param(name, pt.p, &mut |sys| {
                    let z: [f64; N] = pt.orbit.fourier.state(0.0);
                    let st = if forced {
                        cycle::forced_floquet(sys, &z, period, opts)
                            .map(|(l, defect, events)| Stability::forced(&l, defect, events))
                    } else {
                        cycle::floquet_from(sys, &z, period, opts).map(|c| Stability::of_cycle(&c))
                    };
                    out = st
                        .map(|s| (s.max, s.stable, s.resolved))
                        .map_err(|e| e.to_string());
                })
                .map_err(|e| e.to_string())?;
                out
            })
            .collect();
        cancel.check()?;
        let fold_at: Vec<usize> = br
            .folds
            .iter()
            .map(|&(k, _)| {
                // The neighbour with the smaller |dp/ds| is nearer the fold.
                if br.points[k].dp_ds.abs() <= br.points[k + 1].dp_ds.abs() {
                    k
                } else {
                    k + 1
                }
            })
            .collect();
        let mut warnings = start.as_ref().map_or_else(Vec::new, |s| s.warnings.clone());
        if let Some(p) = stick_from {
            warnings.push(format!(
                "from {name} = {p} on (where the branch stalled with friction as slip) the branch was continued with stick as a constraint (dynamic Lagrangian step); its convergence in the harmonics is algebraic"
            ));
        }
        let mut rows = Vec::with_capacity(br.points.len());
        for (k, (pt, st)) in br.points.iter().zip(stab).enumerate() {
            let (max, stable, resolved) = match st {
                Ok(v) => v,
                Err(e) => {
                    warnings.push(format!("{name} = {}: no stability ({e})", pt.p));
                    (f64::NAN, false, false)
                }
            };
            let amp = amplitudes::<N>(&pt.orbit.fourier);
            rows.push(HbBranchRow {
                value: pt.p,
                period: pt.orbit.period(),
                amplitude: real.iter().map(|&i| amp[i]).collect(),
                max_multiplier: max,
                stable,
                resolved,
                residual: pt.orbit.residual,
                stick_constraint: pt.orbit.lagrangian,
                kind: if fold_at.contains(&k) { "fold" } else { "step" },
            });
            if pt.orbit.sticks && !pt.orbit.lagrangian {
                warnings.push(format!(
                    "{name} = {}: a contact sticks on the orbit (harmonic balance treats stick as slip at zero speed)",
                    pt.p
                ));
            }
        }
        warnings.dedup();
        Ok(HbBranchFound {
            name: name.to_string(),
            forced,
            harmonics,
            names,
            rows,
            folds: br.folds.iter().map(|&(_, p)| p).collect(),
            end: why_end(&br.end, lo, hi, hopf.is_some()),
            start,
            hopf,
            warnings,
        })
    }
}

/// A branch that stalled with friction as slip (an orbit beginning to
/// stick, say), continued from its last point to `hi` with stick as a
/// constraint (`HbOptions::lagrangian`), at the same largest step; the
/// value it was continued from, if the second leg added a point.
fn with_stick<const N: usize>(
    family: &(dyn squeal_core::cycle::continuation::Family<N> + Sync),
    br: &mut HbBranch,
    lo: f64,
    hi: f64,
    steps: usize,
    bopts: &HbBranchOptions,
) -> Option<f64> {
    if !matches!(br.end, HbBranchEnd::Stalled(..)) {
        return None;
    }
    let last = br.points.last()?;
    let dp = (hi - lo) / (steps - 1) as f64;
    let rest = (hi - last.p) / dp;
    if rest.is_nan() || rest <= 0.5 {
        return None;
    }
    let steps2 = (rest.ceil() as usize + 1).max(2);
    let mut b2 = *bopts;
    b2.hb.lagrangian = true;
    // The slip and stick-slip branches meet at a corner: the start's
    // tangent is the slip branch's, so the leg starts with a small step
    // (then grows it by half at each easy step) rather than jumping along
    // that tangent past the first part of the stick-slip branch.
    b2.first_step = 0.05 * bopts.max_step;
    // The last orbit solved again with stick as a constraint: the start.
    let mut solved = None;
    family
        .visit(last.p, &mut |sys| {
            solved = Some(if sys.forcing_hz().is_empty() {
                harmonic_balance(sys, &last.orbit.fourier, &b2.hb)
            } else {
                forced_response(sys, &last.orbit.fourier, &b2.hb)
            });
        })
        .ok()?;
    let start = solved?.ok()?.fourier;
    let leg = hb_branch_from(family, last.p, hi, steps2, &start, BranchStart::Lo, &b2).ok()?;
    if leg.points.len() < 2 {
        return None;
    }
    let from = last.p;
    let off = br.points.len() - 1;
    br.folds
        .extend(leg.folds.iter().map(|&(k, p)| (k + off, p)));
    br.points.extend(leg.points.into_iter().skip(1));
    br.end = leg.end;
    Some(from)
}

impl HbBranchFound {
    /// The JSON document: `param`, `forced`, `harmonic_count`, `points`
    /// (per point `value`, `period`, `freq_hz`, `amplitude` per state,
    /// `max_multiplier`, `stable`, `stability_resolved`, `residual`,
    /// `stick_constraint`, `point`), `folds`, `end`, `start` (`squeal hb`'s document at the
    /// first value; null when there is no orbit there), `hopf` (`value`,
    /// `freq_hz` of the Hopf point the branch started at, or null) and
    /// `warnings`.
    pub fn to_json(&self) -> Value {
        let points: Vec<Value> = self
            .rows
            .iter()
            .map(|r| {
                json!({
                    "value": r.value,
                    "period": r.period,
                    "freq_hz": 1.0 / r.period,
                    "amplitude": crate::cycle::named_json(&self.names, &r.amplitude),
                    "max_multiplier": if r.max_multiplier.is_finite() { json!(r.max_multiplier) } else { Value::Null },
                    "stable": r.stable,
                    "stability_resolved": r.resolved,
                    "residual": r.residual,
                    "stick_constraint": r.stick_constraint,
                    "point": r.kind,
                })
            })
            .collect();
        json!({
            "method": "harmonic balance continuation",
            "param": self.name,
            "forced": self.forced,
            "harmonic_count": self.harmonics,
            "points": points,
            "folds": self.folds,
            "end": self.end,
            "start": self.start.as_ref().map_or(Value::Null, HbFound::to_json),
            "hopf": self.hopf.as_ref().map_or(Value::Null, |c| json!({"value": c.value, "freq_hz": c.freq_hz})),
            "warnings": self.warnings,
        })
    }
}

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
use squeal_core::hb::continuation::{hb_branch, HbBranchEnd, HbBranchOptions};
use squeal_core::hb::{HbError, HbOptions};
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
    /// `squeal hb` at the first value.
    pub start: HbFound,
    /// What the numbers do not support.
    pub warnings: Vec<String>,
}

fn why_end(e: &HbBranchEnd, hi: f64) -> String {
    match e {
        HbBranchEnd::Reached => format!("reached the range's end ({hi})"),
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
    let start = of_scenario(&first, harmonics, opts, Guess::Settle, false, cancel)?;
    let bopts = HbBranchOptions {
        hb: HbOptions {
            harmonics,
            ..HbOptions::default()
        },
        ..HbBranchOptions::default()
    };
    let names = sc.model.state_names();
    crate::with_sim_system!(&sc.model, m => {
        follow_in(m, name, lo, hi, steps, harmonics, opts, start, names, &bopts, cancel)
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
    start: HbFound,
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
        let br = hb_branch(&guarded, lo, hi, steps, &start.series, bopts).map_err(|e| match e {
            HbError::Bad(m) => StudyError::Input(InputError(format!("hb --param: {m}"))),
            other => StudyError::Numerical(format!("hb --param: {other}")),
        })?;
        cancel.check()?;
        let real = real_states::<N>(m.norm_states());
        let forced = start.forcing_hz.is_some();
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
        let mut warnings = start.warnings.clone();
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
                kind: if fold_at.contains(&k) { "fold" } else { "step" },
            });
            if pt.orbit.sticks {
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
            end: why_end(&br.end, hi),
            start,
            warnings,
        })
    }
}

impl HbBranchFound {
    /// The JSON document: `param`, `forced`, `harmonic_count`, `points`
    /// (per point `value`, `period`, `freq_hz`, `amplitude` per state,
    /// `max_multiplier`, `stable`, `stability_resolved`, `residual`,
    /// `point`), `folds`, `end`, `start` (`squeal hb`'s document at the
    /// first value) and `warnings`.
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
            "start": self.start.to_json(),
            "warnings": self.warnings,
        })
    }
}

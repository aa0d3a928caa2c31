//! The parameter value where steady sliding changes stability (a Hopf
//! point, or the onset of undamped mode coupling), by bracketing and
//! Brent's method.

use crate::error::{Cancel, StudyError};
use crate::feasible::stability_error;
use crate::model::AnyModel;
use crate::scenario::InputError;
use squeal_core::stability::{self, CriticalOptions, Crossing, StabilityError};

/// Most points of `critical`'s initial scan (about a second of eigen-analyses).
pub const MAX_GRID: usize = 100_000;

/// Both ends of a range must be values the parameter may take: the reason
/// the one that is not cannot, naming it (LO or HI).
pub fn check_endpoints(model: &AnyModel, name: &str, lo: f64, hi: f64) -> Result<(), String> {
    for (end, v) in [("LO", lo), ("HI", hi)] {
        let mut m = model.clone();
        if let Err(e) = m.set(name, v) {
            return Err(format!("{end} = {v}: {e}"));
        }
    }
    Ok(())
}

/// Least stable growth rate and its frequency with `name` set to `value`.
pub fn growth_at(model: &AnyModel, name: &str, value: f64) -> Result<(f64, f64), StabilityError> {
    let mut m = model.clone();
    m.set(name, value)?;
    m.validate()?;
    m.max_growth_rate()
}

/// Locate the crossing of `name` in `[lo, hi]`: a scan of `grid` points,
/// then Brent's method to 1e-10 ([`stability::critical`]); `None` when the
/// verdict is the same across the interval. Messages name `--param`.
pub fn locate(
    model: &AnyModel,
    name: &str,
    lo: f64,
    hi: f64,
    grid: usize,
    cancel: &Cancel,
) -> Result<Option<Crossing>, StudyError> {
    if !(2..=MAX_GRID).contains(&grid) {
        return Err(InputError(format!(
            "--grid {grid}: must be between 2 and {MAX_GRID} (the scan, then Brent's method, locates the crossing to 1e-10 whatever the grid)"
        ))
        .into());
    }
    if model.get(name).is_none() {
        return Err(InputError(format!(
            "--param {name}: unknown parameter for model {}",
            model.name()
        ))
        .into());
    }
    check_endpoints(model, name, lo, hi).map_err(|why| {
        InputError(format!(
            "--param {name}={}:{}: {why}",
            squeal_core::params::short(lo),
            squeal_core::params::short(hi)
        ))
    })?;
    let opts = CriticalOptions {
        grid,
        ..CriticalOptions::default()
    };
    // A range that starts where there is no steady sliding (V = 0, say) starts
    // just inside, where there is.
    let mut lo = lo;
    if let Err(StabilityError::NoSteadySliding(_)) = growth_at(model, name, lo) {
        let nudged = lo + (hi - lo) * 1e-9;
        if growth_at(model, name, nudged).is_ok() {
            lo = nudged;
        }
    }
    let at = |p: f64| {
        if cancel.is_cancelled() {
            return Err(StabilityError::BadInput(String::new()));
        }
        growth_at(model, name, p).map_err(|e| match e {
            StabilityError::NonFinite { what } => StabilityError::BadInput(format!(
                "--param {name}={}:{}: at {name} = {p:e} the {what} at steady sliding is not finite (it overflows)",
                squeal_core::params::short(lo),
                squeal_core::params::short(hi)
            )),
            other => other,
        })
    };
    let found = stability::critical(at, lo, hi, &opts);
    cancel.check()?;
    found.map_err(|e| match e {
        StabilityError::BadInput(msg) => StudyError::Input(InputError(msg)),
        other => stability_error(other),
    })
}

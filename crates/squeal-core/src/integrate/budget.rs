//! The work a run must do, known before it starts.
//!
//! An explicit Runge–Kutta method is stable on `y' = λy` only while `h·λ`
//! lies in its stability region; for DOP853 that region reaches about
//! [`STABILITY_REACH`] from the origin (Hairer & Wanner, *Solving Ordinary
//! Differential Equations II*, §IV.2, Fig. 2.1). However small the wanted
//! accuracy, a run of length `T` whose fastest eigenvalue has modulus `|λ|`
//! therefore needs at least `T·|λ|/STABILITY_REACH` steps. Stiff parameter
//! sets (a damper of 1e15 N·s/m on a 1 kg mass: `|λ| = c/m = 1e15 1/s`) need
//! billions of steps; the budget below lets a caller refuse them up front and
//! bounds every run, however it goes, by [`step_budget`] steps.

/// Radius (in `h·|λ|`) of DOP853's stability region along the real and
/// imaginary axes, rounded up: the step controller never sustains a larger
/// stable step, so `T·|λ|/STABILITY_REACH` is a lower bound on the steps.
pub const STABILITY_REACH: f64 = 6.5;

/// Least number of steps an explicit DOP853 run of `duration` seconds needs
/// when its fastest eigenvalue has modulus `lambda_max` (1/s) and its steps
/// are at most `h_max` seconds: `max(T·|λ|/STABILITY_REACH, T/h_max)`.
pub fn min_steps(lambda_max: f64, duration: f64, h_max: f64) -> f64 {
    let by_stability = duration * lambda_max.abs() / STABILITY_REACH;
    let by_h_max = if h_max > 0.0 {
        duration / h_max
    } else {
        f64::INFINITY
    };
    by_stability.max(by_h_max)
}

/// Steps a run is allowed before it is abandoned: [`BUDGET_BASE`] plus
/// [`BUDGET_FACTOR`] times [`min_steps`]. The factor covers what the bound
/// leaves out — accuracy (about ten steps per period of the fastest
/// oscillation), steps cut at events, start-up transients — with a wide
/// margin: the default disc–pad run takes 9.3 times its bound, the most
/// demanding of the thesis's 40 sets 11.2 times.
pub fn step_budget(min_steps: f64) -> u64 {
    let b = BUDGET_BASE + BUDGET_FACTOR * min_steps;
    if b.is_finite() && b < u64::MAX as f64 {
        b as u64
    } else {
        u64::MAX
    }
}

/// Steps every run may take whatever its bound (a few seconds of work).
pub const BUDGET_BASE: f64 = 2.0e6;
/// Multiple of [`min_steps`] a run may take.
pub const BUDGET_FACTOR: f64 = 50.0;

//! The integrator's tuning knobs, shared by the models (a padded model
//! adapts them to its size) and the integrator below them.

/// Most states a per-state tolerance can be given for.
pub const MAX_STATES: usize = 16;

/// Tuning knobs of the integrator. Times in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Relative tolerance (default 1e-8).
    pub rtol: f64,
    /// Absolute tolerance of position states (m); `None`: the model's default.
    pub atol_pos: Option<f64>,
    /// Absolute tolerance of velocity states (m/s); `None`: the model's default.
    pub atol_vel: Option<f64>,
    /// Per-state absolute tolerances, overriding `atol_pos`/`atol_vel` for
    /// the states that have one (index = state index; at most [`MAX_STATES`]).
    pub atol_state: [Option<f64>; MAX_STATES],
    /// Largest step (s).
    pub h_max: f64,
    /// First step (s); `None`: chosen automatically (Hairer's rule).
    pub h_init: Option<f64>,
    /// Most accepted steps before the run is abandoned.
    pub max_steps: u64,
    /// Event location tolerance (s): roots are located to within
    /// `max(event_tol, 1e-9·h)`; they are in practice refined to round-off.
    pub event_tol: f64,
    /// Two events closer than this (s) count as chatter…
    pub zeno_gap: f64,
    /// …and this many such events in a row end the run with `IntegrateError::Chatter`.
    pub zeno_count: u32,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            rtol: 1e-8,
            atol_pos: None,
            atol_vel: None,
            atol_state: [None; MAX_STATES],
            h_max: f64::INFINITY,
            h_init: None,
            max_steps: 500_000_000,
            event_tol: 1e-12,
            zeno_gap: 1e-13,
            zeno_count: 100,
        }
    }
}

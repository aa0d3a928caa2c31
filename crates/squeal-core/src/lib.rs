//! # squeal-core
//!
//! The physics and numerics of squeal, a toolkit for friction-induced
//! vibration (disc-brake squeal first of all). It is the clean specification
//! of `MODEL.md` made executable:
//!
//! - [`friction`]: friction laws μ(v) (thesis, Coulomb, Stribeck, rational);
//! - [`model`]: the disc–pad model of the thesis, the mass on a belt and the
//!   Hoffmann et al. (2002) mode-coupling model, as
//!   plug-ins (a vector field per contact mode, guards, transition rules);
//! - [`integrate`]: an event-driven DOP853 integrator that locates every
//!   stick, slip, reversal, separation and contact on the dense output;
//! - [`sink`]: where a run's samples and events go;
//! - [`initial`]: initial states (`rest`, `equilibrium`, offsets);
//! - [`stability`]: linear stability of steady sliding (eigenvalues of the
//!   state matrix, critical parameter values).
//!
//! The crate is pure computation: no files, no threads, no clocks.
//!
//! ```
//! use squeal_core::sink::Recorder;
//! use squeal_core::{simulate, stability, DiscPad, EventKind, SolverOptions};
//!
//! // The thesis's brake with MODEL.md's defaults: linearly unstable…
//! let brake = DiscPad::default();
//! let linear = stability::analyse(&brake).unwrap();
//! assert!(!linear.stable);
//! assert!((linear.max_growth_rate - 14.667).abs() < 1e-3); // the pad's 20.75 kHz mode
//!
//! // …and 10 ms of it from rest, sampled at 20 kHz, every event located.
//! let mut rec = Recorder::<8>::new();
//! let run = simulate(&brake, 0.0, [0.0; 8], 0.01, 20_000.0, SolverOptions::default(), &mut rec).unwrap();
//! assert_eq!(rec.t.len(), 201);
//! assert_eq!(run.stats.event_count(EventKind::Reverse), 0); // too early for stick-slip
//! ```

pub mod abaqus;
pub mod cycle;
pub mod dmig;
pub mod friction;
pub mod harwell_boeing;
pub mod hb;
pub mod initial;
pub mod integrate;
pub mod labelled;
pub mod lanes;
pub mod linear;
pub mod matrix_market;
pub mod model;
pub mod params;
pub mod sink;
pub mod solver_options;
pub mod stability;

pub use friction::FrictionLaw;
pub use integrate::{simulate, Flow, IntegrateError, RunInfo, Sink, Solver, SolverOptions, Stats};
pub use model::{
    belt::Belt, disc_pad::DiscPad, hoffmann::Hoffmann, lumped::Lumped, EventKind, Mode, Model,
    ModelError, Modes, Parameters, System,
};
pub use params::{ParamError, ParamSpec};
pub use stability::{analyse, critical, max_growth_rate, Analysis, StabilityError};

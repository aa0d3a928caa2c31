//! Initial states: `rest` or `equilibrium`, plus per-state offsets.

use crate::model::{ModelError, System};

/// How a run starts (before offsets).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Initial {
    /// All states zero: the pad touches the disc with zero compression and
    /// N is switched on at t = 0, as the thesis does.
    #[default]
    Rest,
    /// The steady-sliding equilibrium of MODEL.md §5.
    Equilibrium,
}

impl Initial {
    /// Name as typed by users.
    pub fn as_str(self) -> &'static str {
        match self {
            Initial::Rest => "rest",
            Initial::Equilibrium => "equilibrium",
        }
    }
    /// Parse `rest` / `equilibrium`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "rest" => Some(Initial::Rest),
            "equilibrium" => Some(Initial::Equilibrium),
            _ => None,
        }
    }
}

/// The initial state `base + offsets`.
pub fn initial_state<M: System<N> + ?Sized, const N: usize>(
    model: &M,
    initial: Initial,
    offsets: &[f64; N],
) -> Result<[f64; N], ModelError> {
    let mut z = match initial {
        Initial::Rest => [0.0; N],
        Initial::Equilibrium => model.steady_sliding()?,
    };
    for i in 0..N {
        z[i] += offsets[i];
    }
    Ok(z)
}

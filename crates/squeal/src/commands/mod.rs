//! One module per command.

pub mod listen;
pub mod plot;
pub mod scenario;
pub mod simulate;

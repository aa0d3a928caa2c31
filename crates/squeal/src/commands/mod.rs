//! One module per command.

pub mod scenario;
pub mod simulate;

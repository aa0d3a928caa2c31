//! `squeal scenario list | show NAME`.

use crate::run::RunError;
use clap::Subcommand;
use squeal_study::scenario::{InputError, Scenario, BUILTINS};

/// What to do with scenarios.
#[derive(Subcommand, Debug)]
pub enum ScenarioCmd {
    /// List the built-in scenarios.
    List,
    /// Print a built-in scenario (or a thesis set, thesis-01 … thesis-40) as a documented TOML file.
    Show {
        /// Built-in scenario name.
        name: String,
    },
}

/// Run the command.
pub fn run(cmd: ScenarioCmd) -> Result<(), RunError> {
    match cmd {
        ScenarioCmd::List => {
            for name in BUILTINS {
                let s = Scenario::builtin(name).expect("listed built-ins exist");
                crate::outln!("{name:<14} {}", s.description);
            }
            for (i, s) in squeal_study::scenario::thesis_sets().iter().enumerate() {
                crate::outln!("thesis-{:02}      {}", i + 1, s.description);
            }
        }
        ScenarioCmd::Show { name } => {
            let s = Scenario::builtin(&name).ok_or_else(|| {
                InputError(format!(
                    "scenario '{name}': no built-in of that name (built-ins: {})",
                    BUILTINS.join(", ")
                ))
            })?;
            crate::out::text(&s.to_toml());
        }
    }
    Ok(())
}

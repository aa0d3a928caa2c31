//! `squeal scenario list | show NAME|FILE`.

use crate::run::RunError;
use clap::Subcommand;
use squeal_study::scenario::{InputError, Scenario, BUILTINS};

/// What to do with scenarios.
#[derive(Subcommand, Debug)]
pub enum ScenarioCmd {
    /// List the built-in scenarios.
    List,
    /// Print a built-in scenario (or a thesis set, thesis-01 … thesis-40, or a
    /// scenario file, resolved: a lumped file's expressions with their values) as a
    /// documented TOML file.
    Show {
        /// Built-in scenario name, or a scenario file.
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
            let s = match Scenario::builtin(&name) {
                Some(s) => s,
                None if name.ends_with(".toml") || std::path::Path::new(&name).is_file() => {
                    Scenario::load(&name)?
                }
                None => {
                    return Err(InputError(format!(
                        "scenario '{name}': no built-in of that name (built-ins: {})",
                        BUILTINS.join(", ")
                    ))
                    .into())
                }
            };
            crate::out::text(&s.to_toml());
        }
    }
    Ok(())
}

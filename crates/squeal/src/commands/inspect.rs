//! `squeal inspect [SCENARIO] [--json]`: what was read — each matrix's
//! format, file, size, nonzeros and symmetry, the dofs, the lowest natural
//! frequencies without friction, each contact with its dofs
//! ([`squeal_study::inspect`]).

use crate::commands::simulate::resolve;
use crate::run::RunError;
use crate::ScenarioArgs;
use clap::Args;

/// Arguments of `squeal inspect`.
#[derive(Args, Debug)]
pub struct InspectArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Run the command.
pub fn run(a: InspectArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let report = squeal_study::inspect::inspect(&sc);
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::out::text(&report.to_text());
    }
    Ok(())
}

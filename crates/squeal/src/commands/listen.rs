//! `squeal listen RUN_DIR|SCENARIO [--signal vy_d] [--out squeal.wav] [--float]`:
//! a velocity as sound, at true pitch, band-limited to the audible range.

use crate::model::channels_for;
use crate::run::{self, RunError};
use crate::scenario::InputError;
use crate::{analysis, output, ScenarioArgs};
use clap::Args;
use std::path::{Path, PathBuf};

/// Arguments of `squeal listen`.
#[derive(Args, Debug)]
pub struct ListenArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The velocity to hear (default: the disc's tangential velocity).
    #[arg(long)]
    signal: Option<String>,
    /// Output WAV file (never an existing file, unless --force).
    #[arg(long, default_value = "squeal.wav")]
    out: PathBuf,
    /// Replace an existing --out file.
    #[arg(long)]
    force: bool,
    /// 32-bit float samples instead of 16-bit PCM.
    #[arg(long)]
    float: bool,
}

/// Run the command.
pub fn run(a: ListenArgs) -> Result<(), RunError> {
    // Written beside the target and renamed into place: a failure or an
    // interrupt leaves no partial file, and no file is replaced unasked.
    // Staged before the work, so an unwritable place is found at once.
    let staged = crate::staging::StagedFile::new("--out", &a.out, a.force)?;
    let dir = Path::new(&a.scenario.scenario);
    let (run, model) = if dir.is_dir() {
        if !a.scenario.sets.is_empty() {
            return Err(
                InputError("--set applies to scenarios, not to a saved run folder".into()).into(),
            );
        }
        let (run, summary) = output::read_run_dir(dir)?;
        let model = summary["scenario"]["model"]
            .as_str()
            .unwrap_or("disc-pad")
            .to_string();
        (run, model)
    } else {
        let sc = crate::commands::simulate::resolve_run(&a.scenario, None)?;
        (run::run(&sc)?, sc.model.name().to_string())
    };
    let name = a
        .signal
        .clone()
        .unwrap_or_else(|| channels_for(&model).tangential.to_string());
    let x = run.column(&name).ok_or_else(|| {
        let vels: Vec<&str> = run
            .columns
            .iter()
            .filter(|c| c.starts_with('v') && *c != "v_rel")
            .map(String::as_str)
            .collect();
        InputError(format!(
            "--signal {name}: no such signal (velocities: {})",
            vels.join(", ")
        ))
    })?;
    let clip = analysis::write_wav(x, run.sample_rate, staged.path(), a.float)?;
    staged.commit("--out")?;
    if clip.looped {
        eprintln!(
            "note: the run ({:.3} s) is shorter than {:.1} s of sound: its last steady part is looped",
            clip.source_seconds,
            clip.duration()
        );
    }
    crate::outln!(
        "{}: {name} at true pitch, {:.2} s, {} Hz, {}",
        a.out.display(),
        clip.duration(),
        clip.sample_rate,
        if a.float {
            "32-bit float"
        } else {
            "16-bit PCM"
        }
    );
    Ok(())
}

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
    /// Output WAV file.
    #[arg(long, default_value = "squeal.wav")]
    out: PathBuf,
    /// 32-bit float samples instead of 16-bit PCM.
    #[arg(long)]
    float: bool,
}

/// Run the command.
pub fn run(a: ListenArgs) -> Result<(), RunError> {
    if a.out.is_dir() {
        return Err(InputError(format!(
            "--out {}: is a folder; name a .wav file",
            a.out.display()
        ))
        .into());
    }
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
        let sc = crate::commands::simulate::resolve(&a.scenario)?;
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
    if let Some(parent) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .map_err(|e| RunError::Io(format!("cannot create {}: {e}", parent.display())))?;
    }
    // Write beside the target and rename, so a failure leaves no partial file.
    let tmp = a.out.with_extension("wav.partial");
    let clip = analysis::write_wav(x, run.sample_rate, &tmp, a.float);
    let clip = match clip {
        Ok(c) => c,
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            return Err(e);
        }
    };
    std::fs::rename(&tmp, &a.out)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", a.out.display())))?;
    if clip.looped {
        eprintln!(
            "note: the run ({:.3} s) is shorter than {:.1} s of sound: its last steady part is looped",
            clip.source_seconds,
            clip.duration()
        );
    }
    println!(
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

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
    /// The velocity to hear (default: the one that squeals, else the one with the most energy).
    #[arg(long)]
    signal: Option<String>,
    /// Gain in dB on top of the fixed reference (full scale = 2 m/s at 0 dB).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    gain: f64,
    /// Transpose by this many octaves (e.g. -2: a 20 kHz squeal at 5 kHz), a listening aid;
    /// resampled, duration kept.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    transpose: f64,
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
    let sound = analysis::SoundSettings::from_flags(a.gain, a.transpose)?;
    let dir = Path::new(&a.scenario.scenario);
    let (run, model, validity) = if dir.is_dir() {
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
        let validity = summary["scenario"]["validity"]
            .as_f64()
            .unwrap_or(crate::scenario::VALIDITY);
        (run, model, validity)
    } else {
        let sc = crate::commands::simulate::resolve(&a.scenario)?;
        (run::run(&sc)?, sc.model.name().to_string(), sc.validity)
    };
    let judgement = analysis::judge_run(&run, validity);
    let name = a.signal.clone().unwrap_or_else(|| {
        analysis::default_sound_signal(&run, &judgement)
            .unwrap_or_else(|| channels_for(&model).tangential.to_string())
    });
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
    let clip = analysis::write_wav(x, run.sample_rate, &tmp, a.float, &sound);
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
    let what = match &judgement.squeal {
        Some(q) if q.velocity == name => {
            format!("the squeal, {}", analysis::si(q.frequency_hz, "Hz", 4))
        }
        _ => format!("verdict {}", judgement.verdict),
    };
    println!(
        "{}: {name} ({what}) {}, {:.2} s, {} Hz, {}",
        a.out.display(),
        if sound.transpose_octaves == 0.0 {
            "at true pitch".to_string()
        } else {
            format!("TRANSPOSED {:+} octaves", sound.transpose_octaves)
        },
        clip.duration(),
        clip.sample_rate,
        if a.float {
            "32-bit float"
        } else {
            "16-bit PCM"
        }
    );
    println!("{}", sound.describe(&clip));
    if let Some(note) = analysis::hearing_note(&judgement, &sound) {
        eprintln!("{note}");
    }
    Ok(())
}

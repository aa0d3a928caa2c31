//! `squeal listen RUN_DIR|SCENARIO [--signal vy_d] [--out squeal.wav] [--float]`:
//! a velocity as sound, at true pitch, band-limited to the audible range.

use crate::run::{self, RunError};
use crate::{analysis, output, ScenarioArgs};
use clap::Args;
use squeal_study::model::channels_for;
use squeal_study::scenario::InputError;
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
            .unwrap_or(squeal_study::scenario::VALIDITY);
        (run, model, validity)
    } else {
        let sc = crate::commands::simulate::resolve_run(&a.scenario, None)?;
        (run::run(&sc)?, sc.model.name().to_string(), sc.validity)
    };
    let (name, clip, judgement) = squeal_study::audio::listen(
        &run,
        validity,
        a.signal.as_deref(),
        &channels_for(&model).tangential,
        &sound,
        "--signal ",
    )?;
    let file_name = a
        .out
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let bytes = squeal_study::audio::wav_bytes(&clip, a.float, &file_name, &sound);
    std::fs::write(staged.path(), bytes)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", staged.path().display())))?;
    staged.commit("--out")?;
    if clip.looped {
        crate::errln!(
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
    crate::outln!(
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
    crate::outln!("{}", sound.describe(&clip));
    if let Some(note) = analysis::hearing_note(&judgement, &sound) {
        crate::errln!("{note}");
    }
    Ok(())
}

//! A simulated run's folder (`simulate --out`) written whole, and its
//! pictures redrawn (`plot RUN_DIR`).

use crate::output::{
    read_run_dir, write_events_csv, write_json, write_series_csv, write_series_npy,
};
use crate::RunError;
use serde_json::Value;
use squeal_study::run::Run;
use std::path::Path;

/// What a run's folder holds besides its series: which files, and how the
/// spectra and pictures are made (`simulate`'s flags).
pub struct RunFiles<'a> {
    /// Write `series.csv`.
    pub csv: bool,
    /// Write `series.npy`.
    pub npy: bool,
    /// Draw the pictures.
    pub plots: bool,
    /// Write `squeal.wav` (the default sound signal, 2 s).
    pub wav: bool,
    /// How spectra are computed.
    pub spectrum: &'a crate::analysis::SpectrumSettings,
    /// The frequency band of the pictures.
    pub plot: &'a crate::analysis::PlotSettings,
    /// The velocities whose spectra the user asked for (none: the default).
    pub signals: &'a [String],
}

/// What [`write_run`] analysed and wrote, and the notes for the terminal.
pub struct RunWritten {
    /// The run's spectra and judgement.
    pub analysis: crate::analysis::Analysis,
    /// The run's one answer (frequency, growth, sound).
    pub answer: squeal_study::answer::Answer,
    /// `summary.json`'s document, without `timing` (the caller's clock),
    /// not yet written.
    pub summary: Value,
    /// Lines for standard error (a picture's or the sound's caveats).
    pub notes: Vec<String>,
    /// What a listener should know about the sound, said after the summary.
    pub hearing: Option<String>,
}

/// Write a simulated run's folder into `stage` (`simulate`): the series
/// asked for, `events.csv`, `spectrum.csv`, the pictures and the sound; the
/// caller adds its timing to the summary and writes `summary.json`.
pub fn write_run(
    stage: &crate::Staging,
    sc: &squeal_study::Scenario,
    run: &Run,
    f: &RunFiles,
) -> Result<RunWritten, RunError> {
    use crate::analysis;
    if f.csv {
        write_series_csv(run, &stage.path("series.csv"))?;
    }
    if f.npy {
        write_series_npy(run, &stage.path("series.npy"))?;
    }
    write_events_csv(run, &stage.path("events.csv"))?;
    let channels = sc.model.channels();
    let an = analysis::analyse(run, &channels, f.spectrum, sc.validity, f.signals);
    analysis::write_spectrum_csv(&an, &stage.path("spectrum.csv"))?;
    let answer = squeal_study::answer::Answer::of(sc, run, &an);
    let mut summary = squeal_study::answer::summary_json_with(sc, run, &an, &answer);
    let mut notes = Vec::new();
    if f.plots {
        let squeal_hz = answer.squeal.as_ref().map(|s| s.frequency_hz);
        let band = f.plot.around_squeal(squeal_hz, run.sample_rate);
        let words = answer.words();
        let explicit = !f.signals.is_empty();
        let (name, dir) = (&sc.name, stage.dir());
        let drawn = analysis::draw(
            run,
            &an,
            &channels,
            name,
            dir,
            &band,
            words.as_deref(),
            explicit,
        );
        notes.extend(drawn?);
    }
    let mut hearing = None;
    if f.wav {
        let sound = analysis::SoundSettings::default();
        let signal = analysis::default_sound_signal(run, &an.judgement)
            .unwrap_or_else(|| channels.tangential.to_string());
        if let Some(x) = run.column(&signal) {
            let path = stage.path("squeal.wav");
            let clip = analysis::write_wav(x, run.sample_rate, &path, false, &sound)?;
            if clip.looped {
                notes.push(format!(
                    "note: the run ({:.3} s) is shorter than the 2 s of sound: its last steady part is looped",
                    clip.source_seconds
                ));
            }
            summary["audio"] = sound.json(&signal, &clip);
            notes.push(format!("squeal.wav: {signal}, {}", sound.describe(&clip)));
            hearing = analysis::hearing_note(&an.judgement, &sound);
        }
    }
    Ok(RunWritten {
        analysis: an,
        answer,
        summary,
        notes,
        hearing,
    })
}

/// Redraw the pictures of the saved run in `run_dir` (`squeal plot`) with
/// new spectrum and picture settings, without re-simulating: drawn into a
/// scratch folder, then each file replaces only a file squeal wrote there
/// (`spectrum.csv` and `summary.json` say what the new pictures show).
/// Returns the notes for standard error.
pub fn redraw(
    run_dir: &Path,
    settings: &crate::analysis::SpectrumSettings,
    plot: &crate::analysis::PlotSettings,
    signals: &[String],
) -> Result<Vec<String>, RunError> {
    // Checked before any work: plot writes into the run folder.
    crate::staging::check_not_a_link("run folder", run_dir)?;
    let (run, mut summary) = read_run_dir(run_dir)?;
    crate::analysis::check_signals(signals, &crate::analysis::velocity_columns(&run))?;
    let model = summary["scenario"]["model"].as_str().unwrap_or("disc-pad");
    let name = summary["scenario"]["name"]
        .as_str()
        .unwrap_or("run")
        .to_string();
    let channels = squeal_study::model::channels_for(model);
    let validity = summary["scenario"]["validity"]
        .as_f64()
        .unwrap_or(squeal_study::scenario::VALIDITY);
    let an = crate::analysis::analyse(&run, &channels, settings, validity, signals);
    // Drawn into a scratch folder first; each file then replaces only a file
    // squeal wrote (or none) in the run folder.
    let scratch = crate::staging::Staging::scratch(run_dir)?;
    let plot = plot.around_squeal(summary["squeal"]["frequency_hz"].as_f64(), run.sample_rate);
    let q = &summary["squeal"];
    let words = q["frequency_hz"].as_f64().map(|f| {
        squeal_study::answer::line_words(
            f,
            q["uncertainty_hz"].as_f64(),
            q["source"].as_str().unwrap_or("run"),
            q["forced_hz"].as_f64(),
        )
    });
    let note = crate::analysis::draw(
        &run,
        &an,
        &channels,
        &name,
        scratch.dir(),
        &plot,
        words.as_deref(),
        !signals.is_empty(),
    )?;
    crate::analysis::write_spectrum_csv(&an, &scratch.path("spectrum.csv"))?;
    // summary.json says what the redrawn pictures and spectrum.csv show.
    summary["spectrum"] = an.spectrum_json();
    // The squeal answer and the growth rates were made with the model's
    // linear analysis (squeal_study::answer), which a saved run does not
    // hold: a summary that has them keeps them (the run is the same).
    if summary.get("linear").is_none() {
        summary["growth_rate"] = an.growth_json();
        summary["squeal"] = an.squeal_json();
    }
    summary["verdict"] = serde_json::json!(an.verdict.as_str());
    summary["verdict_detail"] = an.verdict_detail_json();
    write_json(&summary, &scratch.path("summary.json"))?;
    crate::staging::replace_files(run_dir, scratch.dir())?;
    Ok(note.into_iter().collect())
}

//! `squeal plot RUN_DIR`: redraw the pictures of a saved run without re-simulating.

use crate::analysis;
use crate::output;
use crate::run::RunError;
use clap::Args;
use squeal_study::model::channels_for;
use std::path::PathBuf;

/// Arguments of `squeal plot`.
#[derive(Args, Debug)]
pub struct PlotArgs {
    /// A folder written by `squeal simulate`.
    run_dir: PathBuf,
    #[command(flatten)]
    spectrum: crate::commands::simulate::SpectrumArgs,
}

/// Run the command.
pub fn run(a: PlotArgs) -> Result<(), RunError> {
    let settings = a.spectrum.settings()?;
    let plot = a.spectrum.plot_settings()?;
    // Checked before any work: plot writes into the run folder.
    crate::staging::check_not_a_link("run folder", &a.run_dir)?;
    let (run, mut summary) = output::read_run_dir(&a.run_dir)?;
    analysis::check_signals(a.spectrum.signals(), &analysis::velocity_columns(&run))?;
    let model = summary["scenario"]["model"].as_str().unwrap_or("disc-pad");
    let name = summary["scenario"]["name"]
        .as_str()
        .unwrap_or("run")
        .to_string();
    let channels = channels_for(model);
    let validity = summary["scenario"]["validity"]
        .as_f64()
        .unwrap_or(squeal_study::scenario::VALIDITY);
    let an = analysis::analyse(&run, &channels, &settings, validity, a.spectrum.signals());
    // Drawn into a scratch folder first; each file then replaces only a file
    // squeal wrote (or none) in the run folder.
    let scratch = crate::staging::Staging::scratch(&a.run_dir)?;
    let plot = plot.around_squeal(summary["squeal"]["frequency_hz"].as_f64(), run.sample_rate);
    let q = &summary["squeal"];
    let words = q["frequency_hz"].as_f64().map(|f| {
        squeal_study::answer::squeal_words(
            f,
            q["uncertainty_hz"].as_f64(),
            q["source"].as_str().unwrap_or("run"),
        )
    });
    if let Some(note) = analysis::draw(
        &run,
        &an,
        &channels,
        &name,
        scratch.dir(),
        &plot,
        words.as_deref(),
        !a.spectrum.signals().is_empty(),
    )? {
        crate::errln!("{note}");
    }
    analysis::write_spectrum_csv(&an, &scratch.path("spectrum.csv"))?;
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
    output::write_json(&summary, &scratch.path("summary.json"))?;
    crate::staging::replace_files(&a.run_dir, scratch.dir())?;
    crate::outln!(
        "pictures redrawn in {} (triplet, spectrogram, phase; PNG and SVG)",
        a.run_dir.display()
    );
    Ok(())
}

//! `squeal plot RUN_DIR`: redraw the pictures of a saved run without re-simulating.

use crate::analysis;
use crate::model::channels_for;
use crate::output;
use crate::run::RunError;
use clap::Args;
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
    let (run, summary) = output::read_run_dir(&a.run_dir)?;
    let model = summary["scenario"]["model"].as_str().unwrap_or("disc-pad");
    let name = summary["scenario"]["name"]
        .as_str()
        .unwrap_or("run")
        .to_string();
    let channels = channels_for(model);
    let an = analysis::analyse(&run, &channels, &settings);
    // Drawn into a scratch folder first; each file then replaces only a file
    // squeal wrote (or none) in the run folder.
    let scratch = crate::staging::Staging::scratch(&a.run_dir)?;
    analysis::draw(&run, &an, &channels, &name, scratch.dir())?;
    analysis::write_spectrum_csv(&an, &scratch.path("spectrum.csv"))?;
    crate::staging::replace_files(&a.run_dir, scratch.dir())?;
    crate::outln!(
        "pictures redrawn in {} (triplet, spectrogram, phase; PNG and SVG)",
        a.run_dir.display()
    );
    Ok(())
}

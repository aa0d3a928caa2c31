//! `squeal plot RUN_DIR`: redraw the pictures of a saved run without re-simulating.

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
    let plot = a.spectrum.plot_settings()?;
    let notes = squeal_files::run_dir::redraw(&a.run_dir, &settings, &plot, a.spectrum.signals())?;
    for note in notes {
        crate::errln!("{note}");
    }
    crate::outln!(
        "pictures redrawn in {} (triplet, spectrogram, phase; PNG and SVG)",
        a.run_dir.display()
    );
    Ok(())
}

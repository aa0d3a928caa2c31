//! `squeal reproduce [--out DIR]`: the thesis's study re-done, checked and
//! extended in one command — the 40 parameter sets of Table 11.1
//! (reconstructed, `scenarios/thesis/`), Appendix A's pictures for each set
//! (the disc as the thesis drew it, the pad beside it) plus its eigenvalues,
//! the seven conclusions of docs/physics.md §6 turned into measurable claims,
//! evaluated on this invocation's runs and on the studies of [`squeal_study::study`]
//! (α sweep, c_px sweep, a kick above Uc), each graded `held`, `held
//! qualitatively`, `held by another mechanism`, `refuted` or `outside the
//! model`; runs that leave the model (`lift-off`, `out-of-range`) are flagged
//! and are evidence for nothing. Also a V × N stability map with the sets that
//! share its parameters, and the thesis's numbers confronted (450 Hz, the
//! spectral levels of its Figs. 1–2, its 30–100 kg/s). The report holds no
//! wall-clock time: the same input gives byte-identical files.

use crate::run::{bars, RunError, Staging, NEVER};
use clap::Args;
use squeal_files::reproduce::{grade_counts, ReproduceStudy};
use squeal_files::shard::Shard;
use squeal_study::reproduce::Conclusion;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `squeal reproduce`.
#[derive(Args, Debug)]
pub struct ReproduceArgs {
    /// Output folder (default: out/reproduce; a shard's: out/reproduce-shard-K-of-N).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Multiply every set's simulated duration by this factor (e.g. 0.1 for a
    /// quick look; the conclusions need the full durations).
    #[arg(long, default_value_t = 1.0)]
    pub duration_scale: f64,
    /// Skip the per-set pictures (Appendix A).
    #[arg(long)]
    pub no_figures: bool,
    /// Compute only shard K of N (K from 0): the sets whose index i (set
    /// i + 1) has i mod N = K, written as `shard.json` + `part.json` (and
    /// their Appendix A pictures) for `squeal merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
}

/// The terminal lines after a report: the grades, each conclusion, where
/// the report is.
pub fn print_summary(head: &str, cs: &[Conclusion], dest: &Path) {
    crate::outln!("{head}: {}", grade_counts(cs));
    for c in cs {
        crate::outln!("  {}. {:<26} {}", c.id, c.grade.as_str(), c.thesis);
    }
    crate::outln!("report: {}", dest.join("report.html").display());
}

/// Run the command.
pub fn run(a: ReproduceArgs) -> Result<(), RunError> {
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    let study = ReproduceStudy::new(a.duration_scale, !a.no_figures, shard)?;
    let start = Instant::now();
    let stage = Staging::for_out(a.out.as_deref(), &study.folder())?;
    let r = study.run(&stage, &bars, &NEVER)?;
    if let Some(s) = shard {
        let dest = stage.commit()?;
        let list: Vec<String> = r.ids.iter().map(|i| (i + 1).to_string()).collect();
        crate::outln!(
            "reproduce: shard {}/{} — sets {} of 40; output: {} (shard.json, part.json{}); gather with `squeal merge`",
            s.k,
            s.n,
            if list.is_empty() { "none".into() } else { list.join(", ") },
            dest.display(),
            if a.no_figures { "" } else { ", figures" }
        );
        return Ok(());
    }
    let cs = r.conclusions.unwrap_or_default();
    let wall = start.elapsed().as_secs_f64();
    let dest = stage.commit()?;
    print_summary(&format!("reproduced 40 sets in {wall:.1} s"), &cs, &dest);
    Ok(())
}

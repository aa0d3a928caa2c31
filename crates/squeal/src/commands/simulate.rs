//! `squeal simulate [SCENARIO] [--set NAME=VALUE]... [--duration S] [--out DIR]`.

use crate::run::{self, RunError, Staging};
use crate::ScenarioArgs;
use crate::{analysis, output};
use clap::Args;
use serde_json::json;
use squeal_study::scenario::{InputError, Scenario, Source};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `squeal simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Simulated time in seconds (overrides the scenario's).
    #[arg(long, allow_negative_numbers = true)]
    duration: Option<f64>,
    /// Output folder (default: out/SCENARIO, the scenario's name).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Series formats, comma-separated: csv, npy.
    #[arg(long, default_value = "csv", value_delimiter = ',')]
    format: Vec<String>,
    /// Print summary.json on stdout instead of the human summary.
    #[arg(long)]
    json: bool,
    /// Also write the squealing velocity as sound (squeal.wav, 48 kHz, full scale = 2 m/s).
    #[arg(long)]
    wav: bool,
    /// Skip the pictures (triplet, spectrogram, phase portrait).
    #[arg(long)]
    no_plots: bool,
    #[command(flatten)]
    spectrum: SpectrumArgs,
}

/// The spectral analyser's flags, shared by `simulate` and `plot`.
#[derive(Args, Debug, Clone)]
pub struct SpectrumArgs {
    /// Window of the Welch segments: hann, flattop or rect.
    #[arg(long, default_value = "hann")]
    window: String,
    /// Segment (FFT) length in samples; the resolution is sample_rate / segment.
    #[arg(long, default_value_t = crate::analysis::SEGMENT)]
    segment: usize,
    /// Overlap of consecutive segments (0 to 0.95).
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    overlap: f64,
    /// Peak-amplitude spectrum instead of the power spectral density.
    #[arg(long)]
    amplitude: bool,
    /// Velocities to analyse and draw, comma-separated (default: every velocity of the state).
    #[arg(long, value_delimiter = ',', value_name = "NAME,…")]
    signals: Vec<String>,
    /// Highest frequency (Hz) shown in the spectra and the spectrogram.
    #[arg(long)]
    fmax: Option<f64>,
    /// Frequency range LO:HI (Hz) shown in the spectra and the spectrogram.
    #[arg(long, value_name = "LO:HI")]
    frange: Option<String>,
    /// Logarithmic frequency axes.
    #[arg(long)]
    log_f: bool,
}

impl SpectrumArgs {
    /// Checked settings.
    pub fn settings(&self) -> Result<analysis::SpectrumSettings, InputError> {
        analysis::SpectrumSettings::from_flags(
            &self.window,
            self.segment,
            self.overlap,
            self.amplitude,
        )
    }
    /// Checked picture settings.
    pub fn plot_settings(&self) -> Result<analysis::PlotSettings, InputError> {
        analysis::PlotSettings::from_flags(self.fmax, self.frange.as_deref(), self.log_f)
    }
    /// The `--signals` list (empty: all velocities).
    pub fn signals(&self) -> &[String] {
        &self.signals
    }
}

/// Resolve the scenario named on the command line, with its overrides.
pub fn resolve(args: &ScenarioArgs) -> Result<Scenario, InputError> {
    squeal_study::scenario::resolve(Source::Spec(&args.scenario), &args.sets)
}

/// Resolve a scenario for a run — with `--duration` if given — and check it
/// the one way every simulating command does ([`squeal_study::feasible::prepare`]).
pub fn resolve_run(args: &ScenarioArgs, duration: Option<f64>) -> Result<Scenario, RunError> {
    Ok(squeal_study::feasible::resolve_run(
        Source::Spec(&args.scenario),
        &args.sets,
        duration,
    )?)
}

/// Run the command.
pub fn run(a: SimulateArgs) -> Result<(), RunError> {
    let sc = resolve_run(&a.scenario, a.duration)?;
    let spectrum_settings = a.spectrum.settings()?;
    let plot_settings = a.spectrum.plot_settings()?;
    {
        let names = sc.model.state_names();
        let velocities: Vec<String> = names[names.len() / 2..]
            .iter()
            .map(|s| s.to_string())
            .collect();
        analysis::check_signals(a.spectrum.signals(), &velocities)?;
    }
    let (mut csv, mut npy) = (false, false);
    for f in &a.format {
        match f.as_str() {
            "csv" => csv = true,
            "npy" => npy = true,
            other => {
                return Err(InputError(format!("--format {other}: expected csv or npy")).into())
            }
        }
    }
    let stage = Staging::for_out(a.out.as_deref(), &sc.name)?;
    let run = run::run(&sc)?;
    let t0 = Instant::now();
    let files = squeal_files::run_dir::RunFiles {
        csv,
        npy,
        plots: !a.no_plots,
        wav: a.wav,
        spectrum: &spectrum_settings,
        plot: &plot_settings,
        signals: a.spectrum.signals(),
    };
    let squeal_files::run_dir::RunWritten {
        analysis: an,
        answer,
        mut summary,
        notes,
        hearing,
    } = squeal_files::run_dir::write_run(&stage, &sc, &run, &files)?;
    for note in notes {
        crate::errln!("{note}");
    }
    let output_s = t0.elapsed().as_secs_f64();
    summary["timing"] = json!({ "integrate_s": run.integrate_s, "output_s": output_s });
    output::write_json(&summary, &stage.path("summary.json"))?;
    let dest = stage.commit()?;
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{}",
            answer.squeal_line(&an, squeal_study::model::coordinate_words)
        );
        if let Some(g) = answer.growth_line() {
            crate::outln!("{g}");
        }
        crate::outln!("{}", squeal_study::sound::sound_line(&answer.sound));
        if let Some(note) = answer
            .sound
            .as_ref()
            .ok()
            .and_then(|s| s.squeal_note(answer.squeal.as_ref().map(|q| q.coordinate.as_str())))
        {
            crate::outln!("  note: {note}");
        }
        print_human(&sc, &run, &summary, &dest);
    }
    if let Some(note) = hearing {
        crate::errln!("{note}");
    }
    Ok(())
}

/// Most velocities the human summary lists (the largest by RMS).
const SHOWN_SIGNALS: usize = 12;

fn print_human(sc: &Scenario, run: &run::Run, summary: &serde_json::Value, dest: &std::path::Path) {
    let s = &run.info.stats;
    crate::outln!(
        "{} ({}): {} s simulated in {:.2} s — {} steps ({} rejected), {} RHS evaluations",
        sc.name,
        sc.model.name(),
        sc.duration,
        run.integrate_s,
        s.accepted,
        s.rejected,
        s.rhs_evals
    );
    let ev: Vec<String> = squeal_core::EventKind::ALL
        .iter()
        .map(|k| format!("{} {}", s.event_count(*k), k.as_str()))
        .collect();
    crate::outln!(
        "events: {}; stick fraction {:.3e}",
        ev.join(", "),
        s.stick_fraction()
    );
    // A large model (an FE brake's hundreds of velocities) lists its
    // SHOWN_SIGNALS largest by RMS; summary.json has every one.
    let rms = summary["rms"].as_object();
    let shown: Option<Vec<&String>> = rms.map(|r| {
        let mut keys: Vec<&String> = r.keys().collect();
        if keys.len() > SHOWN_SIGNALS {
            let v = |k: &String| r[k.as_str()].as_f64().unwrap_or(0.0);
            keys.sort_by(|a, b| v(b).total_cmp(&v(a)));
            keys.truncate(SHOWN_SIGNALS);
        }
        keys
    });
    let truncated = rms.is_some_and(|r| r.len() > SHOWN_SIGNALS);
    let more = |total: usize, listed: usize| {
        if truncated && total > listed {
            format!(" … and {} more in summary.json", total - listed)
        } else {
            String::new()
        }
    };
    if let (Some(rms), Some(shown)) = (rms, &shown) {
        let parts: Vec<String> = shown
            .iter()
            .map(|k| format!("{k} {:.3e}", rms[k.as_str()].as_f64().unwrap_or(0.0)))
            .collect();
        crate::outln!(
            "RMS velocity over the last 20 % (m/s){}: {}{}",
            if truncated { ", the largest" } else { "" },
            parts.join(", "),
            more(rms.len(), parts.len())
        );
    }
    if let Some(sig) = summary["spectrum"]["signals"].as_object() {
        let listed = |k: &String| shown.as_ref().is_none_or(|s| s.contains(&k));
        let dom: Vec<String> = sig
            .iter()
            .filter(|(k, _)| listed(k))
            .filter_map(|(k, v)| {
                v["dominant_hz"]
                    .as_f64()
                    .map(|f| format!("{k} {}", crate::analysis::si(f, "Hz", 4)))
            })
            .collect();
        if !dom.is_empty() {
            crate::outln!(
                "spectral peaks (the strongest line of each velocity, not the squeal answer): {}{}",
                dom.join(", "),
                more(sig.len(), dom.len())
            );
        }
    }
    crate::outln!(
        "verdict: {} — {}",
        summary["verdict"].as_str().unwrap_or("?"),
        summary["verdict_detail"]["reason"].as_str().unwrap_or("")
    );
    // Per cycle of a line the run shows (not of noise, nor of a prediction).
    if let Some(c) = summary["verdict_detail"]["per_cycle"]
        .as_object()
        .filter(|_| summary["squeal"]["source"] == "run")
    {
        let g = |k: &str| c.get(k).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
        crate::outln!(
            "per cycle of the squeal ({:.0} cycles in the judged window): {:.3} true sticks, {:.3} slip reversals, {:.3} separations",
            g("cycles"),
            g("sticks_per_cycle"),
            g("reversals_per_cycle"),
            g("separations_per_cycle")
        );
    }
    crate::outln!("output: {}", dest.display());
}

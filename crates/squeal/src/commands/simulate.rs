//! `squeal simulate [SCENARIO] [--set NAME=VALUE]... [--duration S] [--out DIR]`.

use crate::run::{self, RunError, Staging};
use crate::scenario::{InputError, Scenario, Setting};
use crate::ScenarioArgs;
use crate::{analysis, output};
use clap::Args;
use serde_json::json;
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
    /// Also write the tangential disc velocity as sound (squeal.wav, 48 kHz).
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
}

/// Resolve the scenario named on the command line, with its overrides.
pub fn resolve(args: &ScenarioArgs) -> Result<Scenario, InputError> {
    crate::scenario::check_set_syntax(&args.sets, &args.scenario)?;
    let mut sc = Scenario::load(&args.scenario)?;
    sc.apply_overrides(&args.sets)?;
    Ok(sc)
}

/// Resolve a scenario for a run — with `--duration` if given — and check it
/// the one way every simulating command does ([`crate::feasible::prepare`]).
pub fn resolve_run(args: &ScenarioArgs, duration: Option<f64>) -> Result<Scenario, RunError> {
    let mut sc = resolve(args)?;
    if let Some(d) = duration {
        sc.apply("duration", &Setting::Number(d))
            .map_err(|e| InputError(format!("--duration: {}", e.0)))?;
    }
    crate::feasible::prepare(&mut sc)?;
    Ok(sc)
}

/// Run the command.
pub fn run(a: SimulateArgs) -> Result<(), RunError> {
    let sc = resolve_run(&a.scenario, a.duration)?;
    let spectrum_settings = a.spectrum.settings()?;
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
    let dest = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&sc.name));
    let flag = if a.out.is_some() {
        "--out"
    } else {
        "output folder (default --out)"
    };
    let stage = Staging::new_as(flag, &dest)?;
    let run = run::run(&sc)?;
    let t0 = Instant::now();
    if csv {
        output::write_series_csv(&run, &stage.path("series.csv"))?;
    }
    if npy {
        output::write_series_npy(&run, &stage.path("series.npy"))?;
    }
    output::write_events_csv(&run, &stage.path("events.csv"))?;
    let velocity_names: Vec<String> = {
        let names = sc.model.state_names();
        names[names.len() / 2..]
            .iter()
            .map(|s| s.to_string())
            .collect()
    };
    let mut summary = output::integrator_json(&run);
    summary["scenario"] = sc.to_json();
    summary["columns"] = json!(run.columns);
    summary["rms"] = json!(output::tail_rms(&run, &velocity_names));
    let channels = sc.model.channels();
    let an = analysis::analyse(&run, &channels, &spectrum_settings);
    analysis::write_spectrum_csv(&an, &stage.path("spectrum.csv"))?;
    summary["spectrum"] = an.spectrum_json();
    summary["growth_rate"] = an.growth_json();
    summary["verdict"] = json!(an.verdict.as_str());
    if !a.no_plots {
        analysis::draw(&run, &an, &channels, &sc.name, stage.dir())?;
    }
    if a.wav {
        if let Some(x) = run.column(&channels.tangential) {
            let clip = analysis::write_wav(x, run.sample_rate, &stage.path("squeal.wav"), false)?;
            if clip.looped {
                eprintln!(
                    "note: the run ({:.3} s) is shorter than the 2 s of sound: its last steady part is looped",
                    clip.source_seconds
                );
            }
        }
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
        print_human(&sc, &run, &summary, &dest);
    }
    Ok(())
}

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
    if let Some(rms) = summary["rms"].as_object() {
        let parts: Vec<String> = rms
            .iter()
            .map(|(k, v)| format!("{k} {:.3e}", v.as_f64().unwrap_or(0.0)))
            .collect();
        crate::outln!(
            "RMS velocity over the last 20 % (m/s): {}",
            parts.join(", ")
        );
    }
    let fmt = |k: &str| {
        summary["spectrum"][k]["dominant_hz"]
            .as_f64()
            .map(|f| format!("{k} {f:.1} Hz"))
    };
    let dom: Vec<String> = ["tangential", "normal"]
        .iter()
        .filter_map(|k| fmt(k))
        .collect();
    if !dom.is_empty() {
        crate::outln!("dominant frequencies: {}", dom.join(", "));
    }
    crate::outln!("verdict: {}", summary["verdict"].as_str().unwrap_or("?"));
    crate::outln!("output: {}", dest.display());
}

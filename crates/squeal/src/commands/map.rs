//! `squeal map [SCENARIO] --x NAME=LO:HI:N --y NAME=LO:HI:N [--log-x] [--log-y] --out DIR [--transient]`:
//! stability over a grid of any two parameters, linear (eigenvalues) or
//! nonlinear (simulation), in parallel and deterministic.

use crate::commands::simulate::{resolve, resolve_run};
use crate::run::{progress_bar, RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_study::map::{
    agree, all_points, check_distinct, linear_grid, parse_axis, transient_grid, unit_of, CLASSES,
};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `squeal map`.
#[derive(Args, Debug)]
pub struct MapArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// First parameter and its range: NAME=LO:HI:N.
    #[arg(long = "x", value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    x: String,
    /// Second parameter and its range: NAME=LO:HI:N.
    #[arg(long = "y", value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    y: String,
    /// Space the x values logarithmically.
    #[arg(long)]
    log_x: bool,
    /// Space the y values logarithmically.
    #[arg(long)]
    log_y: bool,
    /// Output folder (default: out/SCENARIO-map).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Classify every point by simulation too (decays / grows / stick-slip / steady / out-of-range).
    #[arg(long)]
    transient: bool,
    /// Simulated time per point for --transient (default: the scenario's).
    #[arg(long)]
    duration: Option<f64>,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

/// A colour range for growth rates, symmetric about σ = 0, that a few
/// extreme points (near the edge of steady sliding σ can reach 1e6 1/s) do
/// not flatten: ± the 98th percentile of |σ|. The contour and the CSV keep
/// the exact values.
pub fn robust_range(values: &[f64]) -> Option<(f64, f64)> {
    let mut a: Vec<f64> = values
        .iter()
        .filter(|v| v.is_finite())
        .map(|v| v.abs())
        .collect();
    if a.is_empty() {
        return None;
    }
    a.sort_by(f64::total_cmp);
    let lim = a[((a.len() - 1) as f64 * 0.98).round() as usize];
    (lim > 0.0).then_some((-lim, lim))
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        "nan".into()
    }
}

/// Run the command.
pub fn run(a: MapArgs) -> Result<(), RunError> {
    // The same checks as `simulate` whenever the map simulates.
    let sc = if a.transient || a.duration.is_some() {
        resolve_run(&a.scenario, a.duration)?
    } else {
        resolve(&a.scenario)?
    };
    let x = parse_axis(&a.x, "--x", a.log_x, &sc.model)?;
    let y = parse_axis(&a.y, "--y", a.log_y, &sc.model)?;
    check_distinct(&x, &y)?;
    let dest = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-map", sc.name)));
    let flag = if a.out.is_some() {
        "--out"
    } else {
        "output folder (default --out)"
    };
    let stage = Staging::new_as(flag, &dest)?;
    let n = x.values.len() * y.values.len();
    let pb = progress_bar(n as u64, "eigen-analysis");
    let points = all_points(&x, &y);
    let lin = linear_grid(&sc.model, &x, &y, &points, &pb, &NEVER)?;
    squeal_study::Progress::finish(&pb);
    let trans = if a.transient {
        let pb = progress_bar(n as u64, "simulating");
        let t = transient_grid(&sc, &x, &y, &points, &pb, &NEVER)?;
        squeal_study::Progress::finish(&pb);
        Some(t)
    } else {
        None
    };
    let path = stage.path("map.csv");
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io)?);
    let mut header = format!("{},{},max_growth_rate,freq_hz", x.name, y.name);
    if trans.is_some() {
        header.push_str(",outcome,rms_tangential,stick_fraction,t_end,agree");
    }
    writeln!(w, "{header}").map_err(io)?;
    let nx = x.values.len();
    for (k, (s, f)) in lin.iter().enumerate() {
        let (i, j) = (k % nx, k / nx);
        write!(
            w,
            "{},{},{},{}",
            num(x.values[i]),
            num(y.values[j]),
            num(*s),
            num(*f)
        )
        .map_err(io)?;
        if let Some(t) = &trans {
            let o = &t[k];
            write!(
                w,
                ",{},{},{},{},{}",
                o.class,
                num(o.rms),
                num(o.stick_fraction),
                num(o.t_end),
                agree(*s, o)
            )
            .map_err(io)?;
        }
        writeln!(w).map_err(io)?;
    }
    w.flush().map_err(io)?;
    let xl = format!("{} ({})", x.name, unit_of(&sc.model, &x.name));
    let yl = format!("{} ({})", y.name, unit_of(&sc.model, &y.name));
    let sigma: Vec<f64> = lin.iter().map(|p| p.0).collect();
    let title = format!("{}: maximum growth rate of steady sliding", sc.name);
    let spec = HeatmapSpec {
        log_x: x.log,
        log_y: y.log,
        colormap: Colormap::Diverging,
        contour_zero: true,
        nan_label: "no steady sliding",
        value_range: robust_range(&sigma),
        ..HeatmapSpec::new(
            &title,
            &xl,
            &yl,
            "max growth rate σ (1/s)",
            &x.values,
            &y.values,
            &sigma,
        )
    };
    let plot_err = |e: squeal_plot::PlotError| RunError::Io(format!("drawing failed: {e}"));
    squeal_plot::heatmap(
        stage.path("map"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &spec,
    )
    .map_err(plot_err)?;
    let mut disagree = 0;
    if let Some(t) = &trans {
        let cls: Vec<f64> = t
            .iter()
            .map(|o| {
                CLASSES
                    .iter()
                    .position(|c| *c == o.class)
                    .map_or(f64::NAN, |i| i as f64)
            })
            .collect();
        let title = format!("{}: outcome of each simulated run", sc.name);
        let spec = HeatmapSpec {
            log_x: x.log,
            log_y: y.log,
            nan_label: "unclassified",
            classes: &CLASSES,
            ..HeatmapSpec::new(&title, &xl, &yl, "", &x.values, &y.values, &cls)
        };
        squeal_plot::heatmap(
            stage.path("transient"),
            &[Format::Png, Format::Svg],
            squeal_plot::SIZE_SINGLE,
            &spec,
        )
        .map_err(plot_err)?;
        disagree = t
            .iter()
            .zip(&lin)
            .filter(|(o, (s, _))| agree(*s, o) == "no")
            .count();
    }
    let dest = stage.commit()?;
    let unstable = sigma.iter().filter(|s| **s > 0.0).count();
    let nan = sigma.iter().filter(|s| s.is_nan()).count();
    if a.json {
        let doc = json!({
            "x": x.name, "y": y.name, "points": n, "unstable": unstable, "no_steady_sliding": nan,
            "linear_nonlinear_disagree": trans.as_ref().map(|_| disagree), "out": dest,
        });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{}: {n} points ({} × {}), {unstable} unstable, {nan} without steady sliding",
            sc.name,
            x.values.len(),
            y.values.len()
        );
        if trans.is_some() {
            crate::outln!(
                "linear verdict and simulated outcome disagree at {disagree} points (see map.csv)"
            );
        }
        crate::outln!(
            "output: {} (map.csv, map.png{})",
            dest.display(),
            if trans.is_some() {
                ", transient.png"
            } else {
                ""
            }
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_range_ignores_a_few_extremes() {
        let mut v: Vec<f64> = (0..100).map(|i| i as f64 - 50.0).collect();
        v[3] = 2.0e6;
        v[7] = f64::NAN;
        let (lo, hi) = robust_range(&v).unwrap();
        assert_eq!(lo, -hi);
        assert!((48.0..=50.0).contains(&hi), "{hi}");
        assert_eq!(robust_range(&[f64::NAN]), None);
    }
}

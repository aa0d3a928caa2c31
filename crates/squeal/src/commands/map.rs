//! `squeal map [SCENARIO] --x NAME=LO:HI:N --y NAME=LO:HI:N [--log-x] [--log-y] --out DIR [--transient]`:
//! stability over a grid of any two parameters, linear (eigenvalues) or
//! nonlinear (simulation), in parallel and deterministic.

use crate::commands::merge::Shard;
use crate::commands::simulate::{resolve, resolve_run};
use crate::run::{progress_bar, RunError, Staging, NEVER};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::json;
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_study::map::{
    agree, all_points, check_distinct, linear_grid, parse_axis, point, transient_grid, unit_of,
    Axis, Outcome, CLASSES,
};
use squeal_study::Scenario;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `squeal map`.
#[derive(Args, Debug)]
pub struct MapArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// First parameter and its range: NAME=LO:HI:N.
    #[arg(long = "x", value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    pub x: String,
    /// Second parameter and its range: NAME=LO:HI:N.
    #[arg(long = "y", value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    pub y: String,
    /// Space the x values logarithmically.
    #[arg(long)]
    pub log_x: bool,
    /// Space the y values logarithmically.
    #[arg(long)]
    pub log_y: bool,
    /// Output folder (default: out/SCENARIO-map).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Classify every point by simulation too (decays / grows / stick-slip / steady / out-of-range).
    #[arg(long)]
    pub transient: bool,
    /// Simulated time per point for --transient (default: the scenario's).
    #[arg(long)]
    pub duration: Option<f64>,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
    /// Compute only shard K of N (K from 0): the points whose flat index i
    /// has i mod N = K (interleaved), written as `shard.json` + `part.csv`
    /// for `squeal merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
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

/// What a map's pictures and CSV are labelled with: the scenario's name and
/// the two axes with their units.
pub struct Labels {
    /// The scenario's name (titles).
    pub name: String,
    /// x axis label, `NAME (UNIT)`.
    pub xl: String,
    /// y axis label, `NAME (UNIT)`.
    pub yl: String,
}

/// The rows of `map.csv` for `points` (flat indices, see
/// [`squeal_study::map::point`]) with their results in the same order. With
/// `exact`, each row starts with its flat index and numbers keep infinities
/// (the rows of a shard's `part.csv`, which `merge` reads back bit for bit:
/// `{:e}` is the shortest text that parses to the same f64).
pub fn write_rows(
    w: &mut dyn Write,
    x: &Axis,
    y: &Axis,
    points: &[usize],
    lin: &[(f64, f64)],
    trans: Option<&[Outcome]>,
    exact: bool,
) -> std::io::Result<()> {
    let f = |v: f64| if exact { format!("{v:e}") } else { num(v) };
    let mut header = format!("{},{},max_growth_rate,freq_hz", x.name, y.name);
    if trans.is_some() {
        header.push_str(",outcome,rms_tangential,stick_fraction,t_end,agree,spl_dba");
    }
    if exact {
        header.insert_str(0, "index,");
    }
    writeln!(w, "{header}")?;
    for (r, (&k, (s, fr))) in points.iter().zip(lin).enumerate() {
        let (i, j) = point(x, k);
        if exact {
            write!(w, "{k},")?;
        }
        write!(
            w,
            "{},{},{},{}",
            num(x.values[i]),
            num(y.values[j]),
            f(*s),
            f(*fr)
        )?;
        if let Some(t) = trans {
            let o = &t[r];
            write!(
                w,
                ",{},{},{},{},{},{}",
                o.class,
                f(o.rms),
                f(o.stick_fraction),
                f(o.t_end),
                agree(*s, o),
                f(o.spl_dba)
            )?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// Write a whole map — `map.csv`, `map.png`/`.svg` and with `trans`
/// `transient.png`/`.svg` — into `stage`, from every point's result in flat
/// order. `map` and `merge` both write through this, so a merged map is the
/// unsharded one byte for byte. Returns how many points' linear verdict and
/// simulated outcome disagree.
pub fn write_map(
    stage: &Staging,
    labels: &Labels,
    x: &Axis,
    y: &Axis,
    lin: &[(f64, f64)],
    trans: Option<&[Outcome]>,
) -> Result<usize, RunError> {
    let path = stage.path("map.csv");
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io)?);
    let points = all_points(x, y);
    write_rows(&mut w, x, y, &points, lin, trans, false).map_err(io)?;
    w.flush().map_err(io)?;
    let (xl, yl) = (labels.xl.as_str(), labels.yl.as_str());
    let sigma: Vec<f64> = lin.iter().map(|p| p.0).collect();
    let title = format!("{}: maximum growth rate of steady sliding", labels.name);
    let spec = HeatmapSpec {
        log_x: x.log,
        log_y: y.log,
        colormap: Colormap::Diverging,
        contour_zero: true,
        nan_label: "no steady sliding",
        value_range: robust_range(&sigma),
        ..HeatmapSpec::new(
            &title,
            xl,
            yl,
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
    let Some(t) = trans else {
        return Ok(0);
    };
    let cls: Vec<f64> = t
        .iter()
        .map(|o| {
            CLASSES
                .iter()
                .position(|c| *c == o.class)
                .map_or(f64::NAN, |i| i as f64)
        })
        .collect();
    let title = format!("{}: outcome of each simulated run", labels.name);
    let spec = HeatmapSpec {
        log_x: x.log,
        log_y: y.log,
        nan_label: "unclassified",
        classes: &CLASSES,
        ..HeatmapSpec::new(&title, xl, yl, "", &x.values, &y.values, &cls)
    };
    squeal_plot::heatmap(
        stage.path("transient"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &spec,
    )
    .map_err(plot_err)?;
    // How loud each point is, where the scenario names radiating surfaces.
    let dba: Vec<f64> = t.iter().map(|o| o.spl_dba).collect();
    if dba.iter().any(|v| v.is_finite()) {
        let title = format!(
            "{}: A-weighted sound pressure level of each run's last window",
            labels.name
        );
        let spec = HeatmapSpec {
            log_x: x.log,
            log_y: y.log,
            colormap: Colormap::Sequential,
            nan_label: "silent or failed",
            ..HeatmapSpec::new(
                &title,
                xl,
                yl,
                "SPL (dB(A) re 20 µPa)",
                &x.values,
                &y.values,
                &dba,
            )
        };
        squeal_plot::heatmap(
            stage.path("spl_dba"),
            &[Format::Png, Format::Svg],
            squeal_plot::SIZE_SINGLE,
            &spec,
        )
        .map_err(plot_err)?;
    }
    Ok(t.iter()
        .zip(lin)
        .filter(|(o, (s, _))| agree(*s, o) == "no")
        .count())
}

/// The summary `map` and `merge` print (or `--json`).
pub fn report(
    labels: &Labels,
    x: &Axis,
    y: &Axis,
    lin: &[(f64, f64)],
    disagree: Option<usize>,
    dest: &std::path::Path,
    json: bool,
) -> Result<(), RunError> {
    let n = lin.len();
    let unstable = lin.iter().filter(|s| s.0 > 0.0).count();
    let nan = lin.iter().filter(|s| s.0.is_nan()).count();
    if json {
        let doc = json!({
            "x": x.name, "y": y.name, "points": n, "unstable": unstable, "no_steady_sliding": nan,
            "linear_nonlinear_disagree": disagree, "out": dest,
        });
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
        return Ok(());
    }
    crate::outln!(
        "{}: {n} points ({} × {}), {unstable} unstable, {nan} without steady sliding",
        labels.name,
        x.values.len(),
        y.values.len()
    );
    if let Some(d) = disagree {
        crate::outln!("linear verdict and simulated outcome disagree at {d} points (see map.csv)");
    }
    crate::outln!(
        "output: {} (map.csv, map.png{})",
        dest.display(),
        match disagree {
            Some(_) if dest.join("spl_dba.png").exists() => ", transient.png, spl_dba.png",
            Some(_) => ", transient.png",
            None => "",
        }
    );
    Ok(())
}

/// The scenario and both axes of a map, checked (as `simulate` checks
/// whenever the map simulates) before anything is written.
pub fn prepare(a: &MapArgs) -> Result<(Scenario, Axis, Axis), RunError> {
    let sc = if a.transient || a.duration.is_some() {
        resolve_run(&a.scenario, a.duration)?
    } else {
        resolve(&a.scenario)?
    };
    let x = parse_axis(&a.x, "--x", a.log_x, &sc.model)?;
    let y = parse_axis(&a.y, "--y", a.log_y, &sc.model)?;
    check_distinct(&x, &y)?;
    Ok((sc, x, y))
}

/// Run the command.
pub fn run(a: MapArgs) -> Result<(), RunError> {
    let (sc, x, y) = prepare(&a)?;
    let n = x.values.len() * y.values.len();
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    let name = Shard::folder(&format!("{}-map", sc.name), shard);
    let stage = Staging::for_out(a.out.as_deref(), &name)?;
    let points = match shard {
        Some(s) => s.points(n),
        None => all_points(&x, &y),
    };
    let share = |what: &str| match shard {
        Some(s) => format!("shard {}/{}: {what}", s.k, s.n),
        None => what.to_string(),
    };
    if let Some(p) = squeal_study::plan::plan(&sc, "map", points.len()) {
        crate::errln!("{p}");
    }
    let pb = progress_bar(points.len() as u64, &share("eigen-analysis"));
    let lin = linear_grid(&sc.model, &x, &y, &points, &pb, &NEVER)?;
    squeal_study::Progress::finish(&pb);
    let trans = if a.transient {
        let pb = progress_bar(points.len() as u64, &share("simulating"));
        let t = transient_grid(&sc, &x, &y, &points, &pb, &NEVER)?;
        squeal_study::Progress::finish(&pb);
        Some(t)
    } else {
        None
    };
    let labels = Labels {
        name: sc.name.clone(),
        xl: format!("{} ({})", x.name, unit_of(&sc.model, &x.name)),
        yl: format!("{} ({})", y.name, unit_of(&sc.model, &y.name)),
    };
    if let Some(s) = shard {
        let study = crate::commands::merge::study_json(&sc, &labels, &x, &y, a.transient);
        crate::commands::merge::write_part(
            &stage,
            &study,
            s,
            &x,
            &y,
            &points,
            &lin,
            trans.as_deref(),
        )?;
        let dest = stage.commit()?;
        if a.json {
            let doc = json!({ "shard": s.k, "shards": s.n, "points": points.len(), "grid_points": n, "out": dest });
            crate::outln!(
                "{}",
                serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
            );
        } else {
            crate::outln!(
                "{}: shard {}/{} — {} of {n} points; output: {} (shard.json, part.csv); gather with `squeal merge`",
                sc.name,
                s.k,
                s.n,
                points.len(),
                dest.display()
            );
        }
        return Ok(());
    }
    let disagree = write_map(&stage, &labels, &x, &y, &lin, trans.as_deref())?;
    let dest = stage.commit()?;
    report(
        &labels,
        &x,
        &y,
        &lin,
        trans.as_ref().map(|_| disagree),
        &dest,
        a.json,
    )
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

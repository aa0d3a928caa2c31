//! `squeal branch [SCENARIO] --param NAME=LO:HI:N --out DIR [--json]`: the
//! limit cycle followed in one parameter by natural-parameter continuation
//! (each point's Newton shooting starts from the previous cycle; a point
//! where that fails is settled afresh by simulation), with the changes of
//! stability and of the event structure along the branch reported.

use crate::commands::cycle::{self, events_json, Found};
use crate::commands::simulate::resolve;
use crate::run::{RunError, Staging};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::{json, Value};
use squeal_core::cycle::Section;
use squeal_core::EventKind;
use squeal_plot::{Format, Panel, Series};
use squeal_study::scenario::{InputError, Scenario};
use std::io::{BufWriter, Write};
use std::path::PathBuf;

/// Arguments of `squeal branch`.
#[derive(Args, Debug)]
pub struct BranchArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// The parameter and its N evenly spaced values, e.g. V=0.05:0.5:20.
    #[arg(long, value_name = "NAME=LO:HI:N", allow_hyphen_values = true)]
    param: String,
    /// Write branch.csv, summary.json and the bifurcation diagram here.
    #[arg(long)]
    out: PathBuf,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Parse `NAME=LO:HI:N`.
fn parse_range(spec: &str) -> Result<(String, f64, f64, usize), InputError> {
    let bad = || {
        InputError(format!(
            "--param {spec}: expected NAME=LO:HI:N with numbers LO < HI and N ≥ 2"
        ))
    };
    let (name, range) = spec.split_once('=').ok_or_else(bad)?;
    let parts: Vec<&str> = range.split(':').collect();
    if parts.len() != 3 {
        return Err(bad());
    }
    let lo: f64 = parts[0].trim().parse().map_err(|_| bad())?;
    let hi: f64 = parts[1].trim().parse().map_err(|_| bad())?;
    let n: usize = parts[2].trim().parse().map_err(|_| bad())?;
    if !(lo.is_finite() && hi.is_finite() && lo < hi && (2..=100_000).contains(&n)) {
        return Err(bad());
    }
    Ok((name.trim().to_string(), lo, hi, n))
}

/// One point of the branch.
struct Point {
    value: f64,
    found: Found,
}

/// What changes between two neighbouring points: a bifurcation's name.
fn transition(a: &Found, b: &Found) -> Vec<String> {
    let mut out = Vec::new();
    if a.events != b.events {
        let show = |e: &[u64; 5]| {
            EventKind::ALL
                .iter()
                .filter(|k| e[k.index()] > 0)
                .map(|k| format!("{} {}", e[k.index()], k.as_str()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        out.push(format!(
            "grazing/sliding: the events per period change ({} → {})",
            show(&a.events),
            show(&b.events)
        ));
    }
    if a.stable != b.stable {
        // The multiplier that crossed the unit circle: the largest non-trivial
        // one on the unstable side.
        let side = if a.stable { b } else { a };
        let crit = side
            .multipliers
            .iter()
            .filter(|m| !m.2)
            .max_by(|x, y| x.0.hypot(x.1).total_cmp(&y.0.hypot(y.1)));
        let kind = match crit {
            Some(&(re, im, _)) if im.abs() > 1e-9 * re.hypot(im) => "Neimark–Sacker",
            Some(&(re, _, _)) if re < 0.0 => "period doubling",
            _ => "fold (a real multiplier through +1)",
        };
        out.push(format!(
            "{kind}: stability {} → {}",
            if a.stable { "stable" } else { "unstable" },
            if b.stable { "stable" } else { "unstable" }
        ));
    }
    if (b.period / a.period - 1.0).abs() > 0.5 {
        out.push(format!(
            "the period jumps ({:.6e} → {:.6e} s): another cycle",
            a.period, b.period
        ));
    }
    out
}

/// Run the command.
pub fn run(a: BranchArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    let (name, lo, hi, n) = parse_range(&a.param)?;
    if sc.model.get(&name).is_none() {
        return Err(InputError(format!(
            "--param {name}: unknown parameter for model {}",
            sc.model.name()
        ))
        .into());
    }
    sc.model.check_simulable().map_err(InputError)?;
    // i9's validation path, the part that applies to a cycle (which budgets
    // its own settling): a linearisation that overflows is named by parameter.
    squeal_study::feasible::scales(&sc.model, Some(&sc))
        .map_err(|e| squeal_study::feasible::stability_failure(&sc.model, e))?;
    let values: Vec<f64> = (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect();
    // Every value must be acceptable before any work.
    for &v in &values {
        let mut m = sc.model.clone();
        m.set(&name, v)
            .and_then(|_| m.validate())
            .map_err(|e| InputError(format!("--param {name}={v}: {e}")))?;
    }
    let stage = Staging::new(&a.out)?;
    let opts = cycle::options(&sc, 20_000_000, 1000.0);
    let names = sc.model.state_names();
    let mut points: Vec<Point> = Vec::with_capacity(n);
    let mut failures: Vec<Value> = Vec::new();
    for &v in &values {
        let mut p = sc.clone();
        p.model
            .set(&name, v)
            .map_err(|e| InputError(e.to_string()))?;
        let prev = points.last().map(|q| &q.found);
        let found = continue_from(&p, prev, &names, &opts)
            .or_else(|_| cycle::of_scenario(&p, &opts, false));
        match found {
            Ok(f) => points.push(Point { value: v, found: f }),
            Err(e) => failures.push(json!({ "value": v, "error": e.to_string() })),
        }
    }
    let mut bifurcations = Vec::new();
    for w in points.windows(2) {
        for what in transition(&w[0].found, &w[1].found) {
            bifurcations.push(json!({ "between": [w[0].value, w[1].value], "kind": what }));
        }
    }
    // The linear picture: where steady sliding changes stability in the
    // range (`critical`'s Hopf point), and the branch's point nearest to it.
    let hopf = squeal_study::critical::locate(&sc.model, &name, lo, hi, 64, &crate::run::NEVER)
        .ok()
        .flatten()
        .map(|c| {
            let near = points.iter().min_by(|p, q| {
                (p.value - c.value)
                    .abs()
                    .total_cmp(&(q.value - c.value).abs())
            });
            json!({
                "value": c.value,
                "freq_hz": c.freq_hz,
                "nearest_point": near.map(|p| json!({
                    "value": p.value,
                    "cycle_freq_hz": 1.0 / p.found.period,
                    "max_multiplier": p.found.max_multiplier,
                })),
            })
        });
    write_csv(&name, &names, &points, &stage.path("branch.csv"))?;
    draw(&sc, &name, &points, &stage)?;
    let doc = json!({
        "param": name,
        "points": points.iter().map(|p| {
            let mut v = p.found.to_json();
            v["value"] = json!(p.value);
            v
        }).collect::<Vec<_>>(),
        "bifurcations": bifurcations,
        "failed": failures,
        "hopf": hopf,
        "scenario": sc.to_json(),
    });
    crate::output::write_json(&doc, &stage.path("summary.json"))?;
    let dest = stage.commit()?;
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        crate::outln!(
            "{}: {} of {} points on the branch over {name} = {lo}…{hi}",
            sc.name,
            points.len(),
            n
        );
        for b in &bifurcations {
            crate::outln!(
                "  between {name} = {} and {}: {}",
                b["between"][0],
                b["between"][1],
                b["kind"].as_str().unwrap_or("")
            );
        }
        if let Some(h) = &hopf {
            crate::outln!(
                "  steady sliding changes stability at {name} = {} ({:.3} Hz, `critical`); the nearest cycle, at {}, has {:.3} Hz",
                h["value"],
                h["freq_hz"].as_f64().unwrap_or(f64::NAN),
                h["nearest_point"]["value"],
                h["nearest_point"]["cycle_freq_hz"].as_f64().unwrap_or(f64::NAN)
            );
        }
        for f in &failures {
            crate::outln!("  no cycle at {name} = {}: {}", f["value"], f["error"]);
        }
        crate::outln!("output: {}", dest.display());
    }
    Ok(())
}

/// Newton shooting from the previous point's cycle.
fn continue_from(
    sc: &Scenario,
    prev: Option<&Found>,
    names: &[String],
    opts: &squeal_core::cycle::CycleOptions,
) -> Result<Found, RunError> {
    let Some(prev) = prev else {
        return Err(RunError::Numerical("no previous point".into()));
    };
    let index = names
        .iter()
        .position(|n| *n == prev.section.0)
        .ok_or_else(|| RunError::Numerical("section lost".into()))?;
    let section = Section {
        index,
        level: prev.section.1,
    };
    squeal_study::with_system!(&sc.model, m => {
        cycle::find(m, &sc.model, &prev.z0, Some((&prev.z0, prev.period, section)), opts, false)
    }, else => Err(RunError::Numerical("not simulable".into())))
}

fn write_csv(
    name: &str,
    states: &[String],
    points: &[Point],
    path: &std::path::Path,
) -> Result<(), RunError> {
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let f = std::fs::File::create(path).map_err(io)?;
    let mut w = BufWriter::new(f);
    let mut header = vec![name.to_string(), "period".to_string()];
    header.extend(states.iter().map(|s| format!("amplitude_{s}")));
    header.push("max_multiplier".into());
    header.push("stable".into());
    header.extend(
        EventKind::ALL
            .iter()
            .map(|k| format!("events_{}", k.as_str())),
    );
    writeln!(w, "{}", header.join(",")).map_err(io)?;
    for p in points {
        let f = &p.found;
        let mut row = vec![format!("{:e}", p.value), format!("{:e}", f.period)];
        row.extend(f.amplitude.iter().map(|a| format!("{a:e}")));
        row.push(format!("{:e}", f.max_multiplier));
        row.push(f.stable.to_string());
        row.extend(
            EventKind::ALL
                .iter()
                .map(|k| f.events[k.index()].to_string()),
        );
        writeln!(w, "{}", row.join(",")).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Bifurcation diagram: the phase portrait's velocity amplitude against the
/// parameter, stable and unstable points as separate series.
fn draw(sc: &Scenario, name: &str, points: &[Point], stage: &Staging) -> Result<(), RunError> {
    if points.is_empty() {
        return Ok(());
    }
    let ch = sc.model.channels();
    let names = sc.model.state_names();
    let Some(k) = names.iter().position(|n| *n == ch.phase.1) else {
        return Ok(());
    };
    let mut xs = [Vec::new(), Vec::new()];
    let mut ys = [Vec::new(), Vec::new()];
    for p in points {
        let s = if p.found.stable { 0 } else { 1 };
        xs[s].push(p.value);
        ys[s].push(p.found.amplitude[k]);
        // A gap between runs of the same stability.
        xs[1 - s].push(f64::NAN);
        ys[1 - s].push(f64::NAN);
    }
    let title = format!("{}: limit cycle branch over {name}", sc.name);
    let y_label = format!("amplitude of {} (m/s)", ch.phase.1);
    let panel = Panel::new(&title, name, &y_label)
        .with_series(Series::new("stable", &xs[0], &ys[0]))
        .with_series(Series::new("unstable", &xs[1], &ys[1]));
    let _ = events_json;
    squeal_plot::line_panels(
        stage.dir().join("branch"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &[panel],
    )
    .map_err(|e| RunError::Io(format!("plot: {e}")))?;
    Ok(())
}

//! `squeal branch [SCENARIO] --param NAME=LO:HI:N --out DIR [--json]`: the
//! limit cycle followed in one parameter by `squeal_core::cycle::continuation`
//! (pseudo-arclength through folds; grid values where the branch is not
//! reached are settled afresh by simulation), with the bifurcations along the
//! branch and its meeting with steady sliding compared with `critical`.

use crate::commands::cycle::{self, Found};
use crate::commands::simulate::resolve;
use crate::run::{self, RunError, Staging};
use crate::scenario::{InputError, Scenario};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::{json, Value};
use squeal_core::cycle::continuation::{
    branch, Branch, BranchOptions, PointKind, Reparametrise, SegmentEnd, Varied,
};
use squeal_core::cycle::{find_cycle, CycleError};
use squeal_core::EventKind;
use squeal_plot::{Format, Panel, Series};
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

/// One row of the branch: a grid value or a fold.
struct Point {
    value: f64,
    found: Found,
    /// `grid` or `fold`.
    kind: &'static str,
    segment: usize,
}

/// What the continuation found, independent of the state count.
struct Outcome {
    /// Grid and fold rows, segment by segment in the order followed.
    points: Vec<Point>,
    /// Every computed point (steps included) for the diagram: segment,
    /// value, velocity amplitude, stable.
    curve: Vec<(usize, f64, Vec<f64>, bool)>,
    bifurcations: Vec<Value>,
    ends: Vec<Value>,
    /// Where a segment shrinks onto steady sliding: (value, frequency in Hz).
    steady: Vec<(f64, f64)>,
    failures: Vec<Value>,
}

fn outcome<const N: usize>(b: &Branch<N>, names: &[String]) -> Outcome {
    let mut points = Vec::new();
    let mut curve = Vec::new();
    for p in &b.points {
        curve.push((
            p.segment,
            p.value,
            p.cycle.amplitude.to_vec(),
            p.cycle.stable,
        ));
        let kind = match p.kind {
            PointKind::Grid(_) => "grid",
            PointKind::Fold => "fold",
            PointKind::Step => continue,
        };
        points.push(Point {
            value: p.value,
            found: cycle::found_of(&p.cycle, names.to_vec()),
            kind,
            segment: p.segment,
        });
    }
    let bifurcations = b
        .bifurcations
        .iter()
        .map(|x| {
            json!({
                "kind": x.kind.as_str(),
                "between": [x.between.0, x.between.1],
                "value": x.value,
                "detail": x.detail,
            })
        })
        .collect();
    let mut steady = Vec::new();
    let ends = b
        .ends
        .iter()
        .map(|e| match e {
            SegmentEnd::LeftRange => json!({ "end": "left_range" }),
            SegmentEnd::Steps => json!({ "end": "steps" }),
            SegmentEnd::Stalled { value, cause } => {
                json!({ "end": "stalled", "value": value, "cause": cause })
            }
            SegmentEnd::SteadySliding { value, freq_hz } => {
                steady.push((*value, *freq_hz));
                json!({ "end": "steady_sliding", "value": value, "freq_hz": freq_hz })
            }
        })
        .collect();
    let failures = b
        .failures
        .iter()
        .map(|(v, e)| json!({ "value": v, "error": e.to_string() }))
        .collect();
    Outcome {
        points,
        curve,
        bifurcations,
        ends,
        steady,
        failures,
    }
}

/// Follow the branch of `sc`'s cycle over `values` of `name`.
fn follow(
    sc: &Scenario,
    name: &str,
    values: &[f64],
    opts: &squeal_core::cycle::CycleOptions,
) -> Result<Outcome, RunError> {
    let names = sc.model.state_names();
    let bopts = BranchOptions {
        cycle: *opts,
        ..BranchOptions::default()
    };
    crate::with_system!(&sc.model, m => {
        let family = Varied { model: m, name };
        let mut settle = |v: f64| {
            let mut out = Err(CycleError::Bad(format!("{name} = {v}: no system")));
            m.with_param(name, v, &mut |sys| {
                out = run::initial_of(sys, sc)
                    .map_err(|e| CycleError::Bad(e.to_string()))
                    .and_then(|z0| find_cycle(sys, 0.0, z0, opts));
            })
            .map_err(CycleError::Bad)?;
            out
        };
        let b = branch(&family, values, &mut settle, &bopts);
        Ok(outcome(&b, &names))
    }, else => Err(RunError::Input(InputError(sc.model.check_simulable().err().unwrap_or_default()))))
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
    crate::feasible::scales(&sc.model, Some(&sc))
        .map_err(|e| crate::feasible::stability_failure(&sc.model, e))?;
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
    let Outcome {
        points,
        curve,
        bifurcations,
        ends,
        steady,
        failures,
    } = follow(&sc, &name, &values, &opts)?;
    // The linear picture: where steady sliding changes stability in the
    // range (`critical`'s Hopf point), the branch's own end on steady
    // sliding (amplitude → 0, extrapolated in A²) nearest to it, and the
    // branch's point nearest to it.
    let hopf = crate::commands::critical::locate(&sc.model, &name, lo, hi, 64)
        .ok()
        .flatten()
        .map(|c| {
            let near = points.iter().min_by(|p, q| {
                (p.value - c.value)
                    .abs()
                    .total_cmp(&(q.value - c.value).abs())
            });
            let end = steady
                .iter()
                .min_by(|a, b| (a.0 - c.value).abs().total_cmp(&(b.0 - c.value).abs()));
            json!({
                "value": c.value,
                "freq_hz": c.freq_hz,
                "nearest_point": near.map(|p| json!({
                    "value": p.value,
                    "cycle_freq_hz": 1.0 / p.found.period,
                    "max_multiplier": p.found.max_multiplier,
                })),
                "branch_end": end.map(|&(v, f)| json!({
                    "value": v,
                    "freq_hz": f,
                    "value_difference": v - c.value,
                    "freq_difference_hz": f - c.freq_hz,
                })),
            })
        });
    write_csv(&name, &names, &points, &stage.path("branch.csv"))?;
    let hopf_value = hopf.as_ref().and_then(|h| h["value"].as_f64());
    draw(&sc, &name, &curve, hopf_value, &stage)?;
    let doc = json!({
        "param": name,
        "points": points.iter().map(|p| {
            let mut v = p.found.to_json();
            v["value"] = json!(p.value);
            v["point"] = json!(p.kind);
            v["segment"] = json!(p.segment);
            v
        }).collect::<Vec<_>>(),
        "bifurcations": bifurcations,
        "segments": ends,
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
            "{}: {} rows ({} grid values of {n}, {} folds) on the branch over {name} = {lo}…{hi}",
            sc.name,
            points.len(),
            points.iter().filter(|p| p.kind == "grid").count(),
            points.iter().filter(|p| p.kind == "fold").count()
        );
        for b in &bifurcations {
            let at = match b["value"].as_f64() {
                Some(v) => format!("at {name} = {v:.9e}"),
                None => format!(
                    "between {name} = {} and {}",
                    b["between"][0], b["between"][1]
                ),
            };
            crate::outln!(
                "  {} {at}: {}",
                b["kind"].as_str().unwrap_or("").replace('_', " "),
                b["detail"].as_str().unwrap_or("")
            );
        }
        for &(v, f) in &steady {
            crate::outln!(
                "  the branch meets steady sliding at {name} = {v:.9e} ({f:.6} Hz; amplitude → 0, extrapolated)"
            );
        }
        if let Some(h) = &hopf {
            crate::outln!(
                "  steady sliding changes stability at {name} = {} ({:.6} Hz, `critical`); the nearest cycle, at {}, has {:.6} Hz",
                h["value"],
                h["freq_hz"].as_f64().unwrap_or(f64::NAN),
                h["nearest_point"]["value"],
                h["nearest_point"]["cycle_freq_hz"].as_f64().unwrap_or(f64::NAN)
            );
            if let Some(d) = h["branch_end"]["value_difference"].as_f64() {
                crate::outln!(
                    "  the branch's end on steady sliding differs from it by {d:.3e} in {name} and {:.3e} Hz",
                    h["branch_end"]["freq_difference_hz"].as_f64().unwrap_or(f64::NAN)
                );
            }
        }
        for f in &failures {
            crate::outln!("  no cycle at {name} = {}: {}", f["value"], f["error"]);
        }
        crate::outln!("output: {}", dest.display());
    }
    Ok(())
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
    header.push("point".into());
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
        row.push(p.kind.to_string());
        writeln!(w, "{}", row.join(",")).map_err(io)?;
    }
    w.flush().map_err(io)
}

/// Bifurcation diagram: the phase portrait's velocity amplitude against the
/// parameter, every computed point of each segment joined in the order
/// followed, stable solid and unstable dashed; `critical`'s Hopf point marked.
fn draw(
    sc: &Scenario,
    name: &str,
    curve: &[(usize, f64, Vec<f64>, bool)],
    hopf: Option<f64>,
    stage: &Staging,
) -> Result<(), RunError> {
    if curve.is_empty() {
        return Ok(());
    }
    let ch = sc.model.channels();
    let names = sc.model.state_names();
    let Some(k) = names.iter().position(|n| *n == ch.phase.1) else {
        return Ok(());
    };
    // Two series over the same points: each keeps the pieces of its own
    // stability (the pieces share their end points so the line is unbroken)
    // and a NaN breaks it elsewhere and between segments.
    let mut xs = [Vec::new(), Vec::new()];
    let mut ys = [Vec::new(), Vec::new()];
    for (i, (seg, v, amp, stable)) in curve.iter().enumerate() {
        let s = usize::from(!*stable);
        let prev = i.checked_sub(1).map(|j| &curve[j]).filter(|p| p.0 == *seg);
        if prev.is_none() {
            for side in 0..2 {
                xs[side].push(f64::NAN);
                ys[side].push(f64::NAN);
            }
        }
        if let Some(p) = prev {
            if p.3 != *stable {
                // The change of stability: start this side's piece at the
                // previous point, end the other side's there.
                xs[s].push(f64::NAN);
                ys[s].push(f64::NAN);
                xs[s].push(p.1);
                ys[s].push(p.2[k]);
                xs[1 - s].push(f64::NAN);
                ys[1 - s].push(f64::NAN);
            }
        }
        xs[s].push(*v);
        ys[s].push(amp[k]);
    }
    let title = format!("{}: limit cycle branch over {name}", sc.name);
    let y_label = format!("amplitude of {} (m/s)", ch.phase.1);
    let mut panel = Panel::new(&title, name, &y_label)
        .with_series(Series::new("stable", &xs[0], &ys[0]).colour(0).with_gaps())
        .with_series(
            Series::new("unstable", &xs[1], &ys[1])
                .colour(0)
                .dashed(true)
                .with_gaps(),
        );
    if let Some(v) = hopf {
        panel = panel.with_peak(v, "Hopf point of steady sliding (critical)");
    }
    squeal_plot::line_panels(
        stage.dir().join("branch"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_SINGLE,
        &[panel],
    )
    .map_err(|e| RunError::Io(format!("plot: {e}")))?;
    Ok(())
}

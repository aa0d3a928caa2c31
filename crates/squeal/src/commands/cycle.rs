//! `squeal cycle [SCENARIO] [--set K=V]… [--json] [--out DIR]`: the limit
//! cycle the scenario settles on — period, Floquet multipliers (saltation
//! matrices at every event), amplitudes, events per period — by
//! `squeal_core::cycle`.

use crate::commands::simulate::resolve;
use crate::model::{observe_all, AnyModel};
use crate::run::{self, RunError, Staging};
use crate::scenario::{InputError, Scenario};
use crate::ScenarioArgs;
use clap::Args;
use serde_json::{json, Map, Value};
use squeal_core::cycle::{self, CycleError, CycleOptions, Section};
use squeal_core::{EventKind, System};
use squeal_plot::{Format, Labels, Panel, Series};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Arguments of `squeal cycle`.
#[derive(Args, Debug)]
pub struct CycleArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Poincaré section: a state name, optionally with its level
    /// (`vx_p` or `vx_p=0.1`); default an upward zero of a velocity.
    #[arg(long, value_name = "STATE[=LEVEL]", allow_hyphen_values = true)]
    pub section: Option<String>,
    /// Most integrator steps spent settling onto the cycle.
    #[arg(long, default_value_t = 20_000_000)]
    pub settle_steps: u64,
    /// Most simulated time spent settling (s), whatever the scenario's duration.
    #[arg(long, default_value_t = 1000.0, allow_hyphen_values = true)]
    pub settle_time: f64,
    /// Settled when two returns to the section agree to this, relative to
    /// the orbit's amplitude (Newton's method does the rest).
    #[arg(long, default_value_t = CycleOptions::default().settle_tol)]
    pub settle_tol: f64,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write orbit.csv, cycle.json and the pictures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// A located cycle, independent of the state count.
#[derive(Debug, Clone)]
pub struct Found {
    /// State names.
    pub names: Vec<String>,
    /// Period (s).
    pub period: f64,
    /// Start state on the section.
    pub z0: Vec<f64>,
    /// Section state name and level.
    pub section: (String, f64),
    /// Multipliers `(re, im, trivial)` sorted by modulus descending.
    pub multipliers: Vec<(f64, f64, bool)>,
    /// Whether every non-trivial multiplier is inside the unit circle.
    pub stable: bool,
    /// Largest non-trivial modulus.
    pub max_multiplier: f64,
    /// Scaled shooting residual.
    pub residual: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Half peak-to-peak of each state.
    pub amplitude: Vec<f64>,
    /// Events per period by kind (order of [`EventKind::ALL`]).
    pub events: [u64; 5],
    /// Simulated settling time (s).
    pub settle_time: f64,
    /// One period, if asked for: columns (t, states, derived) and the event at each row.
    pub orbit: Option<OrbitTable>,
}

/// One period as a table: column names, rows, and the event at each row ("" if none).
pub type OrbitTable = (Vec<String>, Vec<Vec<f64>>, Vec<String>);

/// Build the cycle options from the scenario's solver settings.
pub fn options(sc: &Scenario, settle_steps: u64, settle_time: f64) -> CycleOptions {
    let mut solver = sc.solver;
    solver.rtol = solver.rtol.min(1e-10);
    CycleOptions {
        solver,
        settle_steps,
        settle_time,
        ..CycleOptions::default()
    }
}

/// Parse `--section STATE[=LEVEL]` against the model's state names.
pub fn parse_section(spec: &str, names: &[String]) -> Result<Section, InputError> {
    let (name, level) = match spec.split_once('=') {
        Some((n, l)) => {
            let level: f64 = l
                .trim()
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| {
                    InputError(format!(
                        "--section {spec}: the level must be a finite number"
                    ))
                })?;
            (n.trim(), level)
        }
        None => (spec.trim(), 0.0),
    };
    let index = names.iter().position(|n| n == name).ok_or_else(|| {
        InputError(format!(
            "--section {spec}: unknown state {name} (states: {})",
            names.join(", ")
        ))
    })?;
    Ok(Section { index, level })
}

fn cycle_err(e: CycleError) -> RunError {
    match e {
        CycleError::Bad(m) => RunError::Input(InputError(m)),
        other => RunError::Numerical(format!("cycle: {other}")),
    }
}

/// Settle, shoot and analyse the cycle of `m`, starting from `z0` (or from
/// the guess `(z_guess, period)` if given, skipping the settling).
pub fn find<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    any: &AnyModel,
    z0: &[f64],
    guess: Option<(&[f64], f64, Section)>,
    opts: &CycleOptions,
    with_orbit: bool,
) -> Result<Found, RunError> {
    let mut start = [0.0; N];
    start.copy_from_slice(z0);
    let c = match guess {
        Some((zg, period, section)) => {
            let mut z = [0.0; N];
            z.copy_from_slice(zg);
            cycle::shoot(m, z, period, section, opts).map_err(cycle_err)?
        }
        None => cycle::find_cycle(m, 0.0, start, opts).map_err(cycle_err)?,
    };
    let names = m.names();
    let orbit = if with_orbit {
        let o = cycle::orbit(m, &c, opts).map_err(cycle_err)?;
        let mut columns = vec!["t".to_string()];
        columns.extend(names.iter().cloned());
        columns.extend(any.derived_columns());
        let mut rows = Vec::with_capacity(o.t.len());
        let mut events = Vec::with_capacity(o.t.len());
        let mut obs = Vec::new();
        let mut derived = Vec::new();
        for k in 0..o.t.len() {
            let mut row = vec![o.t[k]];
            row.extend_from_slice(&o.z[k]);
            observe_all(m, o.t[k], &o.modes[k], &o.z[k], &mut obs);
            any.derived_values(&obs, &o.modes[k], &mut derived);
            row.extend_from_slice(&derived);
            rows.push(row);
            events.push(
                o.event[k]
                    .map(|(e, _)| e.as_str().to_string())
                    .unwrap_or_default(),
            );
        }
        Some((columns, rows, events))
    } else {
        None
    };
    let mut found = found_of(&c, names);
    found.orbit = orbit;
    Ok(found)
}

/// The N-independent form of a located cycle (no orbit table).
pub fn found_of<const N: usize>(c: &cycle::Cycle<N>, names: Vec<String>) -> Found {
    Found {
        period: c.period,
        z0: c.z0.to_vec(),
        section: (names[c.section.index].clone(), c.section.level),
        multipliers: c
            .multipliers
            .iter()
            .map(|m| (m.re, m.im, m.trivial))
            .collect(),
        stable: c.stable,
        max_multiplier: c.max_multiplier,
        residual: c.residual,
        iterations: c.iterations,
        amplitude: c.amplitude.to_vec(),
        events: c.events_per_period,
        settle_time: c.settle_time,
        orbit: None,
        names,
    }
}

/// The cycle of a scenario.
pub fn of_scenario(
    sc: &Scenario,
    opts: &CycleOptions,
    with_orbit: bool,
) -> Result<Found, RunError> {
    crate::with_system!(&sc.model, m => {
        let z0 = run::initial_of(m, sc)?;
        find(m, &sc.model, &z0, None, opts, with_orbit)
    }, else => Err(RunError::Input(InputError(sc.model.check_simulable().err().unwrap_or_default()))))
}

impl Found {
    /// The JSON document (`period`, `multipliers`, `stable`, `amplitude`,
    /// `events_per_period`, `residual`, …).
    pub fn to_json(&self) -> Value {
        let multipliers: Vec<Value> = self
            .multipliers
            .iter()
            .map(|&(re, im, trivial)| {
                json!({ "re": re, "im": im, "abs": re.hypot(im), "trivial": trivial })
            })
            .collect();
        let mut amplitude = Map::new();
        for (n, a) in self.names.iter().zip(&self.amplitude) {
            amplitude.insert(n.clone(), json!(a));
        }
        let mut start = Map::new();
        for (n, z) in self.names.iter().zip(&self.z0) {
            start.insert(n.clone(), json!(z));
        }
        json!({
            "period": self.period,
            "frequency_hz": 1.0 / self.period,
            "multipliers": multipliers,
            "stable": self.stable,
            "max_multiplier": self.max_multiplier,
            "amplitude": amplitude,
            "events_per_period": events_json(&self.events),
            "residual": self.residual,
            "newton_iterations": self.iterations,
            "section": { "state": self.section.0, "level": self.section.1 },
            "start": start,
            "settle_time": self.settle_time,
        })
    }
}

/// `{kind: count}` for every event kind.
pub fn events_json(events: &[u64; 5]) -> Value {
    let mut m = Map::new();
    for k in EventKind::ALL {
        m.insert(k.as_str().to_string(), json!(events[k.index()]));
    }
    Value::Object(m)
}

fn io_err(path: &Path, e: std::io::Error) -> RunError {
    RunError::Io(format!("cannot write {}: {e}", path.display()))
}

/// Write `orbit.csv`: the period's samples, each event as two rows (before
/// and after), the event's kind in the last column.
fn write_orbit(found: &Found, path: &Path) -> Result<(), RunError> {
    let Some((columns, rows, events)) = &found.orbit else {
        return Ok(());
    };
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = BufWriter::new(f);
    let mode_cols: Vec<bool> = columns
        .iter()
        .map(|c| c == "mode" || c.ends_with(".mode"))
        .collect();
    let res = (|| -> std::io::Result<()> {
        writeln!(w, "{},event", columns.join(","))?;
        for (row, ev) in rows.iter().zip(events) {
            for (c, v) in row.iter().enumerate() {
                if c > 0 {
                    w.write_all(b",")?;
                }
                if mode_cols[c] {
                    write!(w, "{}", *v as u8)?;
                } else {
                    write!(w, "{v:e}")?;
                }
            }
            writeln!(w, ",{ev}")?;
        }
        w.flush()
    })();
    res.map_err(|e| io_err(path, e))
}

/// Phase portrait and time series over one period.
fn draw(found: &Found, sc: &Scenario, dir: &Path) -> Result<(), RunError> {
    let Some((columns, rows, _)) = &found.orbit else {
        return Ok(());
    };
    let plot_err = |e: squeal_plot::PlotError| RunError::Io(format!("plot: {e}"));
    let col = |name: &str| -> Option<Vec<f64>> {
        let i = columns.iter().position(|c| c == name)?;
        Some(rows.iter().map(|r| r[i]).collect())
    };
    let formats = [Format::Png, Format::Svg];
    let ch = sc.model.channels();
    let t: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    if let (Some(x), Some(v)) = (col(&ch.phase.0), col(&ch.phase.1)) {
        let title = format!(
            "{}: limit cycle, T = {:.6e} s, phase portrait {} – {}",
            sc.name, found.period, ch.phase.0, ch.phase.1
        );
        let (xl, yl) = (
            format!("{} (m)", ch.phase.0),
            format!("{} (m/s)", ch.phase.1),
        );
        squeal_plot::phase_portrait(
            dir.join("cycle_phase"),
            &formats,
            squeal_plot::SIZE_SINGLE,
            &x,
            &v,
            &Labels {
                title: &title,
                x_label: &xl,
                y_label: &yl,
            },
        )
        .map_err(plot_err)?;
    }
    let n = found.names.len();
    let vel: Vec<(String, Vec<f64>)> = found.names[n / 2..]
        .iter()
        .filter_map(|name| col(name).map(|c| (name.clone(), c)))
        .collect();
    let pos: Vec<(String, Vec<f64>)> = found.names[..n / 2]
        .iter()
        .filter_map(|name| {
            col(name).map(|c| {
                // Deviation from the mean: static offsets would hide the motion.
                let mean = c.iter().sum::<f64>() / c.len().max(1) as f64;
                (name.clone(), c.iter().map(|x| x - mean).collect())
            })
        })
        .collect();
    let title_v = format!("{}: velocities over one period", sc.name);
    let title_x = format!("{}: displacements about their mean", sc.name);
    let mut pv = Panel::new(&title_v, "time in the period (s)", "velocity (m/s)");
    for (name, c) in &vel {
        pv = pv.with_series(Series::new(name, &t, c));
    }
    let mut px = Panel::new(&title_x, "time in the period (s)", "displacement (m)");
    for (name, c) in &pos {
        px = px.with_series(Series::new(name, &t, c));
    }
    squeal_plot::line_panels(dir.join("cycle"), &formats, (1200, 700), &[pv, px])
        .map_err(plot_err)?;
    Ok(())
}

/// Run the command.
pub fn run(a: CycleArgs) -> Result<(), RunError> {
    let sc = resolve(&a.scenario)?;
    if !(a.settle_time > 0.0 && a.settle_time.is_finite()) {
        return Err(InputError(format!(
            "--settle-time {}: must be a positive number of seconds",
            a.settle_time
        ))
        .into());
    }
    if !(a.settle_tol > 0.0 && a.settle_tol < 1.0) {
        return Err(InputError(format!("--settle-tol {}: must be in (0, 1)", a.settle_tol)).into());
    }
    if a.settle_steps == 0 {
        return Err(InputError("--settle-steps 0: must be at least 1".into()).into());
    }
    sc.model.check_simulable().map_err(InputError)?;
    // i9's validation path, the part that applies to a cycle (which budgets
    // its own settling): a linearisation that overflows is named by parameter.
    crate::feasible::scales(&sc.model, Some(&sc))
        .map_err(|e| crate::feasible::stability_failure(&sc.model, e))?;
    let mut opts = options(&sc, a.settle_steps, a.settle_time);
    opts.settle_tol = a.settle_tol;
    if let Some(spec) = &a.section {
        opts.section = Some(parse_section(spec, &sc.model.state_names())?);
    }
    let stage = a.out.as_deref().map(Staging::new).transpose()?;
    let found = of_scenario(&sc, &opts, a.out.is_some())?;
    let mut doc = found.to_json();
    doc["scenario"] = sc.to_json();
    if let Some(stage) = stage {
        write_orbit(&found, &stage.path("orbit.csv"))?;
        draw(&found, &sc, stage.dir())?;
        crate::output::write_json(&doc, &stage.path("summary.json"))?;
        stage.commit()?;
    }
    if a.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?
        );
    } else {
        print_human(&found, &sc, a.out.as_deref());
    }
    Ok(())
}

fn print_human(f: &Found, sc: &Scenario, out: Option<&Path>) {
    crate::outln!(
        "{} ({}): limit cycle of period {:.9e} s ({:.3} Hz), {} (largest non-trivial |multiplier| {:.9})",
        sc.name,
        sc.model.name(),
        f.period,
        1.0 / f.period,
        if f.stable { "stable" } else { "unstable" },
        f.max_multiplier
    );
    crate::outln!(
        "section: upward crossing of {} = {}; shooting residual {:.2e} after {} Newton iterations; settled in {:.4} s simulated",
        f.section.0, f.section.1, f.residual, f.iterations, f.settle_time
    );
    crate::outln!("multipliers (|·| descending):");
    for &(re, im, trivial) in &f.multipliers {
        crate::outln!(
            "  {re:+.12e} {im:+.12e}i  |{:.12}|{}",
            re.hypot(im),
            if trivial {
                "  trivial (along the flow)"
            } else {
                ""
            }
        );
    }
    let ev: Vec<String> = EventKind::ALL
        .iter()
        .filter(|k| f.events[k.index()] > 0)
        .map(|k| format!("{} {}", f.events[k.index()], k.as_str()))
        .collect();
    crate::outln!(
        "events per period: {}",
        if ev.is_empty() {
            "none".to_string()
        } else {
            ev.join(", ")
        }
    );
    let amp: Vec<String> = f
        .names
        .iter()
        .zip(&f.amplitude)
        .map(|(n, a)| format!("{n} {a:.4e}"))
        .collect();
    crate::outln!("amplitude (half peak-to-peak): {}", amp.join(", "));
    if let Some(d) = out {
        crate::outln!("output: {}", d.display());
    }
}

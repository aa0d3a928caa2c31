//! `squeal map [SCENARIO] --x NAME=LO:HI:N --y NAME=LO:HI:N [--log-x] [--log-y] --out DIR [--transient]`:
//! stability over a grid of any two parameters, linear (eigenvalues) or
//! nonlinear (simulation), in parallel and deterministic.

use crate::commands::critical::growth_at;
use crate::commands::simulate::{resolve, resolve_run};
use crate::run::{progress_bar, RunError, Staging};
use crate::ScenarioArgs;
use clap::Args;
use rayon::prelude::*;
use serde_json::json;
use squeal_core::integrate::{Flow, Sink};
use squeal_core::stability::StabilityError;
use squeal_core::System;
use squeal_core::{simulate, EventKind, Mode};
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_study::model::AnyModel;
use squeal_study::scenario::{InputError, Scenario};
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

/// One grid axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Parameter name.
    pub name: String,
    /// Grid values.
    pub values: Vec<f64>,
    /// Logarithmic spacing.
    pub log: bool,
}

/// Parse `NAME=LO:HI:N` into grid values.
pub fn parse_axis(spec: &str, flag: &str, log: bool, model: &AnyModel) -> Result<Axis, InputError> {
    let bad = |why: &str| InputError(format!("{flag} {spec}: {why}"));
    let (name, range) = spec
        .split_once('=')
        .ok_or_else(|| bad("expected NAME=LO:HI:N"))?;
    let parts: Vec<&str> = range.split(':').collect();
    if parts.len() != 3 {
        return Err(bad("expected NAME=LO:HI:N"));
    }
    let lo: f64 = parts[0]
        .trim()
        .parse()
        .map_err(|_| bad("LO is not a number"))?;
    let hi: f64 = parts[1]
        .trim()
        .parse()
        .map_err(|_| bad("HI is not a number"))?;
    let n: usize = parts[2]
        .trim()
        .parse()
        .map_err(|_| bad("N is not a whole number"))?;
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(bad("need finite LO < HI"));
    }
    if !(2..=4000).contains(&n) {
        return Err(bad("N must be between 2 and 4000"));
    }
    if log && lo <= 0.0 {
        return Err(bad("a logarithmic axis needs LO > 0"));
    }
    let name = name.trim().to_string();
    if model.get(&name).is_none() {
        return Err(bad(&format!(
            "unknown parameter '{name}' for model {}",
            model.name()
        )));
    }
    crate::commands::critical::check_endpoints(model, &name, lo, hi).map_err(|why| bad(&why))?;
    let values = (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            if i + 1 == n {
                hi
            } else if log {
                (lo.ln() + s * (hi.ln() - lo.ln())).exp()
            } else {
                lo + s * (hi - lo)
            }
        })
        .collect();
    Ok(Axis { name, values, log })
}

/// Unit of a parameter, for axis labels.
pub fn unit_of(model: &AnyModel, name: &str) -> &'static str {
    model
        .keys()
        .into_iter()
        .find(|k| k.0 == name)
        .map(|k| k.1)
        .unwrap_or("")
}

/// Linear map: `(σ_max, freq_hz)` per point, row-major over y then x; NaN
/// where steady sliding does not exist or the parameters are invalid.
/// A point whose state matrix is not finite is an error (naming the point
/// and the parameter to blame), not a blank.
pub fn linear_grid(
    model: &AnyModel,
    x: &Axis,
    y: &Axis,
    progress: &dyn squeal_study::Progress,
) -> Result<Vec<(f64, f64)>, RunError> {
    let nx = x.values.len();
    let points: Vec<Result<(f64, f64), RunError>> = (0..nx * y.values.len())
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            let mut m = model.clone();
            let r = m
                .set(&y.name, y.values[j])
                .map_err(StabilityError::from)
                .and_then(|_| growth_at(&m, &x.name, x.values[i]));
            if i == 0 {
                progress.inc(nx as u64);
            }
            match r {
                Ok(p) => Ok(p),
                Err(e @ StabilityError::NonFinite { .. }) => {
                    let _ = m.set(&x.name, x.values[i]);
                    let why = squeal_study::feasible::stability_failure(&m, e);
                    Err(RunError::Input(InputError(format!(
                        "at {} = {:e}, {} = {:e}: {why}",
                        x.name, x.values[i], y.name, y.values[j]
                    ))))
                }
                Err(_) => Ok((f64::NAN, f64::NAN)),
            }
        })
        .collect();
    points.into_iter().collect()
}

/// Outcome of one transient run.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// decays, grows, stick-slip, steady, out-of-range, or failed.
    pub class: &'static str,
    /// RMS of the tangential velocity over the last window (m/s).
    pub rms: f64,
    /// Fraction of the time in true stick.
    pub stick_fraction: f64,
    /// Time the run ended (early once the class is certain).
    pub t_end: f64,
}

/// Watches the tangential velocities in windows and stops the run once its
/// class is certain: decayed by 60 dB from its peak, or stick-slip/reversals
/// with a steady amplitude (±2 % over three windows).
struct Watch {
    idx: Vec<usize>,
    v_idx: usize,
    window: f64,
    next: f64,
    cur_max: f64,
    sum2: f64,
    count: usize,
    amps: Vec<f64>,
    last_rms: f64,
    events_in_window: usize,
    event_windows: Vec<usize>,
    peak: f64,
    decided: Option<&'static str>,
    /// The scenario's validity bound (m): a position beyond it ends the run `out-of-range`.
    validity: f64,
}

impl<const N: usize> Sink<N> for Watch {
    fn sample(&mut self, t: f64, z: &[f64; N], _mode: Mode) -> Flow {
        if z[..N / 2]
            .iter()
            .any(|q| q.is_nan() || q.abs() > self.validity)
        {
            self.decided = Some("out-of-range");
            return Flow::Stop;
        }
        let a = self.idx.iter().map(|&i| z[i].abs()).fold(0.0, f64::max);
        self.cur_max = self.cur_max.max(a);
        self.sum2 += z[self.v_idx] * z[self.v_idx];
        self.count += 1;
        if t < self.next {
            return Flow::Continue;
        }
        self.next = t + self.window;
        let amp = self.cur_max;
        self.last_rms = (self.sum2 / self.count.max(1) as f64).sqrt();
        self.amps.push(amp);
        self.event_windows.push(self.events_in_window);
        self.peak = self.peak.max(amp);
        (self.cur_max, self.sum2, self.count, self.events_in_window) = (0.0, 0.0, 0, 0);
        let n = self.amps.len();
        if n >= 4 {
            let recent = &self.amps[n - 4..];
            let steady = recent
                .windows(2)
                .all(|w| (w[1] - w[0]).abs() <= 0.02 * w[1].max(1e-300));
            if self.event_windows[n - 3..].iter().all(|&e| e > 0) && steady {
                self.decided = Some("stick-slip");
                return Flow::Stop;
            }
            if amp < 1e-3 * self.peak && recent.windows(2).all(|w| w[1] <= w[0]) {
                self.decided = Some("decays");
                return Flow::Stop;
            }
        }
        Flow::Continue
    }
    fn event(&mut self, _t: f64, kind: EventKind, _z: &[f64; N], _mode: Mode) {
        if matches!(kind, EventKind::Stick | EventKind::Reverse) {
            self.events_in_window += 1;
        }
    }
}

fn transient_point<M: System<N>, const N: usize>(
    model: &M,
    sc: &Scenario,
) -> Result<Outcome, String> {
    let names = model.names();
    let idx: Vec<usize> = (N / 2..N)
        .filter(|&i| names[i].starts_with("vx") || names[i] == "v")
        .collect();
    let v_idx = *idx.first().ok_or("no tangential velocity")?;
    let z0 = crate::run::initial_of(model, sc).map_err(|e| e.to_string())?;
    let window = sc.duration / 50.0;
    let mut w = Watch {
        idx,
        v_idx,
        window,
        next: window,
        cur_max: 0.0,
        sum2: 0.0,
        count: 0,
        amps: Vec::new(),
        last_rms: 0.0,
        events_in_window: 0,
        event_windows: Vec::new(),
        peak: 0.0,
        decided: None,
        validity: sc.validity,
    };
    // Each window's peak is taken over the scenario's samples: at 200 kHz it is
    // within a few % of the envelope, which is all a class needs.
    let info = simulate(
        model,
        0.0,
        z0,
        sc.duration,
        sc.sample_rate,
        sc.solver,
        &mut w,
    )
    .map_err(|e| e.to_string())?;
    let class = w.decided.unwrap_or_else(|| {
        let n = w.amps.len();
        if n < 6 {
            return "steady";
        }
        // Trend over the second half of the run: ±5 % decides.
        let (early, late) = (w.amps[n / 2], w.amps[n - 1]);
        if late > 1.05 * early {
            "grows"
        } else if late < 0.95 * early {
            "decays"
        } else if w.event_windows[n - 3..].iter().any(|&e| e > 0) {
            "stick-slip"
        } else {
            "steady"
        }
    });
    Ok(Outcome {
        class,
        rms: w.last_rms,
        stick_fraction: info.stats.stick_fraction(),
        t_end: info.t_final,
    })
}

/// Transient map: one simulation per point, stopped early once its class is certain.
pub fn transient_grid(
    sc: &Scenario,
    x: &Axis,
    y: &Axis,
    progress: &dyn squeal_study::Progress,
) -> Vec<Outcome> {
    let nx = x.values.len();
    (0..nx * y.values.len())
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            let mut s = sc.clone();
            let r = s
                .model
                .set(&x.name, x.values[i])
                .and_then(|_| s.model.set(&y.name, y.values[j]))
                .and_then(|_| s.model.validate())
                .map_err(|e| e.to_string())
                // Each point gets its own step budget (its stiffness differs).
                .and_then(|_| squeal_study::feasible::prepare(&mut s).map_err(|e| e.to_string()))
                .and_then(|_| {
                    squeal_study::with_system!(&s.model, m => transient_point(m, &s),
                    else => Err(s.model.check_simulable().err().unwrap_or_default()))
                });
            progress.inc(1);
            r.unwrap_or(Outcome {
                class: "failed",
                rms: f64::NAN,
                stick_fraction: f64::NAN,
                t_end: f64::NAN,
            })
        })
        .collect()
}

/// Do the linear verdict (σ) and the simulated outcome tell the same story?
/// `yes` or `no`; `n/a` where there is no linear verdict (no steady sliding)
/// or no outcome (the run failed). Never empty.
fn agree(sigma: f64, o: &Outcome) -> &'static str {
    if !sigma.is_finite() || o.class == "failed" {
        return "n/a";
    }
    let unstable = sigma > 0.0;
    // A growing, friction-limited, sustained or runaway outcome is what an
    // unstable equilibrium predicts; decay is what a stable one predicts.
    let sustained = matches!(o.class, "grows" | "stick-slip" | "steady" | "out-of-range");
    if unstable == sustained {
        "yes"
    } else {
        "no"
    }
}

/// The outcome classes of a transient map, in legend order.
pub const CLASSES: [&str; 6] = [
    "decays",
    "grows",
    "stick-slip",
    "steady",
    "out-of-range",
    "failed",
];

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
    if x.name == y.name {
        return Err(InputError(format!(
            "--x and --y both vary {}: choose two parameters",
            x.name
        ))
        .into());
    }
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
    let lin = linear_grid(&sc.model, &x, &y, &pb)?;
    squeal_study::Progress::finish(&pb);
    let trans = if a.transient {
        let pb = progress_bar(n as u64, "simulating");
        let t = transient_grid(&sc, &x, &y, &pb);
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

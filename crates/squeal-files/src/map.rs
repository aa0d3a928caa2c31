//! A map study and its files: `map.csv` and its pictures (`map.png`/`.svg`,
//! with `--transient` also `transient` and `spl_dba`), or one shard of it
//! (`shard.json` + `part.csv`, see [`crate::shard`]).

use crate::shard::{axis_json, fnv1a, Shard, FORMAT, PART_FILE, SHARD_FILE};
use crate::{Bars, RunError, Staging};
use serde_json::{json, Value};
use squeal_plot::{Colormap, Format, HeatmapSpec};
use squeal_study::map::{
    agree, all_points, linear_grid, point, transient_grid, unit_of, Axis, Outcome, CLASSES,
};
use squeal_study::{Cancel, Scenario, StudyError};
use std::io::Write;

/// A map: a scenario over a grid of two of its parameters, by eigenvalues
/// and with `transient` by simulation too; all of it, or one shard.
pub struct MapStudy {
    /// The resolved scenario (checked as `simulate` checks it when the map
    /// simulates).
    pub sc: Scenario,
    /// First parameter and its values.
    pub x: Axis,
    /// Second parameter and its values.
    pub y: Axis,
    /// Classify every point by simulation too.
    pub transient: bool,
    /// Only this shard's points (`--shard K/N`).
    pub shard: Option<Shard>,
}

/// What a map study computed, point by point in the order of
/// [`MapStudy::points`].
pub struct MapResult {
    /// The flat indices computed ([`squeal_study::map::point`]).
    pub points: Vec<usize>,
    /// (maximum growth rate σ in 1/s, its frequency in Hz) of each point.
    pub lin: Vec<(f64, f64)>,
    /// The simulated outcome of each point (`transient`).
    pub trans: Option<Vec<Outcome>>,
}

impl MapStudy {
    /// The default output folder's name: `SCENARIO-map`, a shard's
    /// `SCENARIO-map-shard-K-of-N`.
    pub fn folder(&self) -> String {
        Shard::folder(&format!("{}-map", self.sc.name), self.shard)
    }

    /// Points in the whole grid.
    pub fn grid_points(&self) -> usize {
        self.x.values.len() * self.y.values.len()
    }

    /// The flat indices this study computes: all, or its shard's.
    pub fn points(&self) -> Vec<usize> {
        match self.shard {
            Some(s) => s.points(self.grid_points()),
            None => all_points(&self.x, &self.y),
        }
    }

    /// The title and axis labels of its pictures.
    pub fn labels(&self) -> Labels {
        let m = &self.sc.model;
        Labels {
            name: self.sc.name.clone(),
            xl: format!("{} ({})", self.x.name, unit_of(m, &self.x.name)),
            yl: format!("{} ({})", self.y.name, unit_of(m, &self.y.name)),
        }
    }

    /// Compute every point (in parallel, deterministic), with a progress
    /// bar from `bars` for the eigen-analysis and one for the simulations.
    pub fn compute(&self, bars: Bars, cancel: &Cancel) -> Result<MapResult, StudyError> {
        let points = self.points();
        let share = |what: &str| match self.shard {
            Some(s) => format!("shard {}/{}: {what}", s.k, s.n),
            None => what.to_string(),
        };
        let n = points.len() as u64;
        let pb = bars(n, &share("eigen-analysis"));
        let lin = linear_grid(&self.sc.model, &self.x, &self.y, &points, &*pb, cancel)?;
        pb.finish();
        let trans = if self.transient {
            let pb = bars(n, &share("simulating"));
            let t = transient_grid(&self.sc, &self.x, &self.y, &points, &*pb, cancel)?;
            pb.finish();
            Some(t)
        } else {
            None
        };
        Ok(MapResult { points, lin, trans })
    }

    /// Write what [`MapStudy::compute`] gave into `stage`: the whole map
    /// ([`write_map`]; returns how many points' linear verdict and simulated
    /// outcome disagree, with `transient`) or the shard's part ([`write_part`]).
    pub fn write(&self, stage: &Staging, r: &MapResult) -> Result<Option<usize>, RunError> {
        let labels = self.labels();
        if let Some(s) = self.shard {
            let study = study_json(&self.sc, &labels, &self.x, &self.y, self.transient);
            write_part(
                stage,
                &study,
                s,
                &self.x,
                &self.y,
                &r.points,
                &r.lin,
                r.trans.as_deref(),
            )?;
            return Ok(None);
        }
        let d = write_map(stage, &labels, &self.x, &self.y, &r.lin, r.trans.as_deref())?;
        Ok(r.trans.as_ref().map(|_| d))
    }
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

/// The study a shard belongs to: every shard of one study has the same.
pub fn study_json(sc: &Scenario, labels: &Labels, x: &Axis, y: &Axis, transient: bool) -> Value {
    let content = sc.to_json();
    let text = serde_json::to_string(&content).unwrap_or_default();
    json!({
        "command": "map",
        "squeal_version": env!("CARGO_PKG_VERSION"),
        "transient": transient,
        "scenario": { "name": sc.name, "hash": fnv1a(text.as_bytes()), "content": content },
        "grid": { "x": axis_json(x, &labels.xl), "y": axis_json(y, &labels.yl) },
    })
}

/// Write a shard (`part.csv` then `shard.json`) into `stage`.
#[allow(clippy::too_many_arguments)]
pub fn write_part(
    stage: &Staging,
    study: &Value,
    s: Shard,
    x: &Axis,
    y: &Axis,
    points: &[usize],
    lin: &[(f64, f64)],
    trans: Option<&[Outcome]>,
) -> Result<(), RunError> {
    let mut bytes = Vec::new();
    write_rows(&mut bytes, x, y, points, lin, trans, true)
        .map_err(|e| RunError::Io(e.to_string()))?;
    let part = stage.path(PART_FILE);
    std::fs::write(&part, &bytes)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", part.display())))?;
    let doc = json!({
        "format": FORMAT,
        "study": study,
        "k": s.k,
        "n": s.n,
        "slicing": "interleaved: flat index i (row-major, y outer) belongs to shard i mod n",
        "points": points.len(),
        "part": { "file": PART_FILE, "rows": points.len(), "bytes": bytes.len(), "fnv1a": fnv1a(&bytes) },
    });
    let path = stage.path(SHARD_FILE);
    let text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    std::fs::write(&path, text + "\n")
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
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

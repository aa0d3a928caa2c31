//! A sweep study and its files: `sweep.csv` and the mode-coupling diagram
//! (`sweep.png`/`.svg`), or one shard of it (`shard.json` + `part.json`, see
//! [`crate::shard`]).

use crate::shard::{axis_json, fnv1a, write_file, Shard, FORMAT, SETS_FILE, SHARD_FILE};
use crate::{RunError, Staging};
use serde_json::{json, Value};
use squeal_core::stability::sweep::Sweep;
use squeal_plot::{BranchSeries, Format, ModeCouplingSpec};
use squeal_study::map::{unit_of, Axis};
use squeal_study::scenario::InputError;
use squeal_study::sweep::shard::{part_of, slice, Part};
use squeal_study::sweep::sweep_model;
use squeal_study::{Cancel, Scenario, StudyError};
use std::io::Write;
use std::ops::Range;

/// A sweep: every eigenvalue of steady sliding along one parameter, modes
/// tracked by shape; all of it, or one shard.
pub struct SweepStudy {
    /// The resolved scenario.
    pub sc: Scenario,
    /// The swept parameter and its values.
    pub param: Axis,
    /// The `--param` text as the user gave it (error messages).
    pub spec: String,
    /// Only this shard's values (`--shard K/N`).
    pub shard: Option<Shard>,
}

/// What a sweep study computed.
pub enum SweepResult {
    /// The whole sweep.
    Whole(Sweep),
    /// A shard's part: the values it owns, the values it computed from (two
    /// before its own, to track the modes across the boundary) and its part.
    Shard {
        /// Which shard.
        shard: Shard,
        /// The indices of the values this shard owns.
        own: Range<usize>,
        /// The indices of the values it computed.
        computed: Range<usize>,
        /// What `merge` reads back.
        part: Part,
    },
}

impl SweepStudy {
    /// A sweep of `sc` over `param`, refusing more shards than values.
    pub fn new(
        sc: Scenario,
        param: Axis,
        spec: &str,
        shard: Option<Shard>,
    ) -> Result<SweepStudy, InputError> {
        if let Some(s) = shard {
            if s.n > param.values.len() {
                return Err(InputError(format!(
                    "--shard {}/{}: more shards than the {} values of --param {spec}",
                    s.k,
                    s.n,
                    param.values.len(),
                )));
            }
        }
        Ok(SweepStudy {
            sc,
            param,
            spec: spec.to_string(),
            shard,
        })
    }

    /// The default output folder's name: `SCENARIO-sweep`, a shard's
    /// `SCENARIO-sweep-shard-K-of-N`.
    pub fn folder(&self) -> String {
        Shard::folder(&format!("{}-sweep", self.sc.name), self.shard)
    }

    /// The axis label of its pictures: `NAME (UNIT)`, or the name alone.
    pub fn label(&self) -> String {
        let unit = unit_of(&self.sc.model, &self.param.name);
        if unit.is_empty() {
            self.param.name.clone()
        } else {
            format!("{} ({unit})", self.param.name)
        }
    }

    /// Compute the sweep (or the shard's slice of it).
    pub fn compute(&self, cancel: &Cancel) -> Result<SweepResult, StudyError> {
        let (m, p) = (&self.sc.model, &self.param);
        let Some(s) = self.shard else {
            return Ok(SweepResult::Whole(sweep_model(
                m, &p.name, &p.values, &self.spec, cancel,
            )?));
        };
        let (own, computed) = slice(p.values.len(), s.k, s.n);
        let sw = sweep_model(m, &p.name, &p.values[computed.clone()], &self.spec, cancel)?;
        let part = part_of(&p.values, s.k, s.n, &sw);
        Ok(SweepResult::Shard {
            shard: s,
            own,
            computed,
            part,
        })
    }

    /// Write what [`SweepStudy::compute`] gave into `stage`.
    pub fn write(&self, stage: &Staging, r: &SweepResult) -> Result<(), RunError> {
        match r {
            SweepResult::Shard { shard, part, .. } => {
                let study = sweep_study(&self.sc, &self.param, &self.label());
                write_sweep_part(stage, &study, *shard, part)
            }
            SweepResult::Whole(sw) => {
                write_sweep(stage, &self.sc.name, &self.param, &self.label(), sw)
            }
        }
    }
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        "nan".into()
    }
}

/// Write `sweep.csv` and the mode-coupling diagram (`sweep.png`/`.svg`) of
/// `sw` into `stage`. `sweep` and `merge` both write through this, so a
/// merged sweep is the unsharded one byte for byte.
pub fn write_sweep(
    stage: &Staging,
    name: &str,
    axis: &Axis,
    xl: &str,
    sw: &Sweep,
) -> Result<(), RunError> {
    let path = stage.path("sweep.csv");
    let io = |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", path.display()));
    let mut w = std::io::BufWriter::new(std::fs::File::create(&path).map_err(io)?);
    writeln!(w, "{},mode,growth_rate,freq_hz,damping_ratio", axis.name).map_err(io)?;
    let two_pi = 2.0 * std::f64::consts::PI;
    for (k, &p) in sw.values.iter().enumerate() {
        for (m, &b) in sw.listed.iter().enumerate() {
            let l = sw.lambda[k][b];
            let mag = l.norm();
            let zeta = if mag > 0.0 { -l.re / mag } else { 0.0 };
            writeln!(
                w,
                "{},{},{},{},{}",
                num(p),
                m + 1,
                num(l.re),
                num(l.im.abs() / two_pi),
                num(zeta)
            )
            .map_err(io)?;
        }
    }
    w.flush().map_err(io)?;
    // The mode-coupling diagram.
    let labels: Vec<String> = (1..=sw.listed.len()).map(|m| format!("mode {m}")).collect();
    let freq: Vec<Vec<f64>> = sw
        .listed
        .iter()
        .map(|&b| sw.lambda.iter().map(|l| l[b].im.abs() / two_pi).collect())
        .collect();
    let sigma: Vec<Vec<f64>> = sw
        .listed
        .iter()
        .map(|&b| sw.lambda.iter().map(|l| l[b].re).collect())
        .collect();
    let growing: Vec<Vec<bool>> = sw
        .listed
        .iter()
        .map(|&b| {
            sw.lambda
                .iter()
                .map(|l| squeal_core::stability::is_growing(l[b].re, l[b].im))
                .collect()
        })
        .collect();
    let branches: Vec<BranchSeries> = (0..sw.listed.len())
        .map(|m| BranchSeries {
            label: &labels[m],
            freq: &freq[m],
            growth: &sigma[m],
            growing: &growing[m],
        })
        .collect();
    let marks: Vec<(f64, f64)> = sw
        .onsets
        .iter()
        .filter(|o| o.coalescence)
        .map(|o| (o.value, o.freq_hz))
        .collect();
    let title = format!("{name}: mode-coupling diagram");
    let spec = ModeCouplingSpec {
        title: &title,
        x_label: xl,
        x: &sw.values,
        branches: &branches,
        coalescences: &marks,
    };
    squeal_plot::mode_coupling(
        stage.path("sweep"),
        &[Format::Png, Format::Svg],
        squeal_plot::SIZE_MULTI,
        &spec,
    )
    .map_err(|e| RunError::Io(format!("drawing failed: {e}")))?;
    Ok(())
}

/// The study a `sweep` shard belongs to: the squeal version, the resolved
/// scenario and its hash, the swept parameter with every value and its label.
pub fn sweep_study(sc: &Scenario, p: &Axis, label: &str) -> Value {
    let content = sc.to_json();
    let text = serde_json::to_string(&content).unwrap_or_default();
    json!({
        "command": "sweep",
        "squeal_version": env!("CARGO_PKG_VERSION"),
        "scenario": { "name": sc.name, "hash": fnv1a(text.as_bytes()), "content": content },
        "param": axis_json(p, label),
    })
}

/// Write a `sweep` shard (`part.json`, then `shard.json`) into `stage`.
pub fn write_sweep_part(
    stage: &Staging,
    study: &Value,
    s: Shard,
    part: &Part,
) -> Result<(), RunError> {
    let bytes = serde_json::to_string(&squeal_study::sweep::shard::to_json(part))
        .map_err(|e| RunError::Io(e.to_string()))?
        + "\n";
    write_file(&stage.path(SETS_FILE), bytes.as_bytes())?;
    let doc = json!({
        "format": FORMAT,
        "study": study,
        "k": s.k,
        "n": s.n,
        "slicing": "contiguous: shard k owns values [k·m/n, (k+1)·m/n) of m and computes from two values before",
        "points": part.lambda.len(),
        "part": { "file": SETS_FILE, "rows": part.lambda.len(), "bytes": bytes.len(), "fnv1a": fnv1a(bytes.as_bytes()) },
    });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    write_file(&stage.path(SHARD_FILE), (text + "\n").as_bytes())
}

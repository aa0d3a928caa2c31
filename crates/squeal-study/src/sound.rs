//! How loud a run is (issue 28 §4, docs/physics.md §5f): the equivalent
//! radiated power and sound pressure levels of a run over its judged
//! window, from the scenario's radiating surfaces ([`crate::radiation`]) by
//! [`squeal_signal::radiation`].

use serde_json::{json, Value};
use squeal_signal::{Levels, Space};

use crate::radiation::{Radiation, ASSUMPTIONS};
use crate::run::Run;

/// One radiating surface's part of a run's sound.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The dof.
    pub dof: String,
    /// Its velocity column.
    pub velocity: String,
    /// Its area (m²).
    pub area_m2: f64,
    /// Its velocity's RMS over the window (m/s).
    pub v_rms: f64,
}

/// The sound of a run over a window.
#[derive(Debug, Clone, PartialEq)]
pub struct Sound {
    /// The levels.
    pub levels: Levels,
    /// Each surface.
    pub surfaces: Vec<Surface>,
    /// The window (s).
    pub window: (f64, f64),
    /// The settings.
    pub settings: Radiation,
}

impl Sound {
    /// The sound of `run` over `window` (s), from the surfaces of `settings`.
    /// `Err` with the reason when the settings name none, or the run lacks
    /// a surface's velocity or the window holds fewer than two samples.
    pub fn of(settings: &Radiation, run: &Run, window: (f64, f64)) -> Result<Sound, String> {
        if settings.areas.is_empty() {
            return Err(
                "the scenario names no radiating surface ([radiation.area_m2], e.g. --set radiation.area_m2.<dof>=<m²>)"
                    .into(),
            );
        }
        let t = run.column("t").ok_or("the run has no time column")?;
        let i0 = t.partition_point(|&x| x < window.0);
        let i1 = t.partition_point(|&x| x <= window.1);
        if i1 < i0 + 2 {
            return Err(format!(
                "the window {:.4}–{:.4} s holds fewer than two samples",
                window.0, window.1
            ));
        }
        let pairs = crate::analysis::state_pairs(run);
        let mut columns = Vec::new();
        let mut surfaces = Vec::new();
        for (dof, area) in &settings.areas {
            let velocity = pairs
                .iter()
                .find(|p| &p.0 == dof)
                .map(|p| p.1.clone())
                .ok_or_else(|| format!("the run has no velocity of {dof}"))?;
            let v = &run.column(&velocity).unwrap_or(&[])[i0..i1];
            let v_rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
            columns.push((*area, v));
            surfaces.push(Surface {
                dof: dof.clone(),
                velocity,
                area_m2: *area,
                v_rms,
            });
        }
        let levels = settings.listener().levels(&columns, run.sample_rate);
        Ok(Sound {
            levels,
            surfaces,
            window: (t[i0], t[i1 - 1]),
            settings: settings.clone(),
        })
    }

    /// Whether `coordinate` (a dof) is one of the radiating surfaces.
    pub fn radiates(&self, coordinate: &str) -> bool {
        self.surfaces.iter().any(|s| s.dof == coordinate)
    }

    /// The note when the squeal's coordinate is not a radiating surface.
    pub fn squeal_note(&self, squeal_coordinate: Option<&str>) -> Option<String> {
        let c = squeal_coordinate?;
        (!self.radiates(c)).then(|| {
            format!(
                "the squeal is on {c}, which is not a radiating surface: the levels count only the motion of {} (including what the squeal mode moves there)",
                self.surfaces.iter().map(|s| s.dof.as_str()).collect::<Vec<_>>().join(", ")
            )
        })
    }
}

/// A level as JSON: `null` for a silent run's `−∞`.
fn level(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// summary.json's `radiation`: `erp_w`, `erp_db`, `spl_db`, `spl_dba`,
/// `distance_m`, `area_m2`, `space`, `rho`, `c`, `surfaces`, `t_start`,
/// `t_end`, `squeal_on_surface`, `note`, `assumptions`; the levels `null`
/// with `reason` when there is no sound to give.
pub fn radiation_json(sound: &Result<Sound, String>, squeal_coordinate: Option<&str>) -> Value {
    match sound {
        Ok(s) => json!({
            "erp_w": s.levels.erp_w,
            "erp_db": level(s.levels.erp_db),
            "spl_db": level(s.levels.spl_db),
            "spl_dba": level(s.levels.spl_dba),
            "distance_m": s.settings.distance_m,
            "area_m2": s.settings.area_m2(),
            "space": s.settings.space.as_str(),
            "rho": s.settings.rho,
            "c": s.settings.c,
            "surfaces": s.surfaces.iter().map(|f| json!({
                "dof": f.dof, "velocity": f.velocity, "area_m2": f.area_m2, "v_rms": f.v_rms,
            })).collect::<Vec<_>>(),
            "t_start": s.window.0,
            "t_end": s.window.1,
            "squeal_on_surface": squeal_coordinate.map(|c| s.radiates(c)),
            "note": s.squeal_note(squeal_coordinate),
            "assumptions": ASSUMPTIONS,
            "reason": null,
        }),
        Err(reason) => json!({
            "erp_w": null, "erp_db": null, "spl_db": null, "spl_dba": null,
            "distance_m": null, "area_m2": null,
            "reason": reason,
        }),
    }
}

/// The sound in words, for the terminal.
pub fn sound_line(sound: &Result<Sound, String>) -> String {
    match sound {
        Ok(s) => {
            let l = &s.levels;
            let db = |x: f64| {
                if x.is_finite() {
                    format!("{x:.1}")
                } else {
                    "−∞".into()
                }
            };
            let space = match s.settings.space {
                Space::Free => "free field",
                Space::Half => "half-space",
            };
            format!(
                "sound: ERP {:.3e} W = {} dB re 1 pW; at {} m ({space}) {} dB, {} dB(A) re 20 µPa; from {} over {:.4}–{:.4} s",
                l.erp_w,
                db(l.erp_db),
                s.settings.distance_m,
                db(l.spl_db),
                db(l.spl_dba),
                s.surfaces
                    .iter()
                    .map(|f| format!("{} ({:.4} m², {:.3e} m/s RMS)", f.dof, f.area_m2, f.v_rms))
                    .collect::<Vec<_>>()
                    .join(", "),
                s.window.0,
                s.window.1
            )
        }
        Err(reason) => format!("sound: not computed: {reason}"),
    }
}

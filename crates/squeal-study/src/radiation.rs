//! How loud a run is (issue 28 §4, docs/physics.md §5f): the scenario's
//! radiating surfaces (`[radiation]`), and the equivalent radiated power and
//! sound pressure levels of a run over its judged window
//! ([`squeal_signal::radiation`]).
//!
//! A scenario names its radiating surfaces as dofs whose velocity is normal
//! to a surface, with the surface's area:
//!
//! ```toml
//! [radiation]
//! distance_m = 1.0     # where the pressure is given (m)
//! space = "free"       # free (4πr², a full sphere) | half (2πr², over a reflecting plane)
//! rho = 1.204          # air density (kg/m³), 20 °C
//! c = 343.2            # speed of sound (m/s), 20 °C
//! [radiation.area_m2]
//! y_d = 0.0829         # the disc's two friction faces (m²)
//! ```
//!
//! `--set radiation.area_m2.y_d=0.05` changes or adds a surface (0 removes
//! it), `--set radiation.distance_m=0.5` the distance. The thesis's
//! `disc-pad` model radiates by default from its disc faces moving with
//! `y_d` ([`DISC_FACES_M2`]); other models radiate only what their scenario
//! names.

use serde_json::{json, Value};
use squeal_signal::radiation::{C_AIR, RHO_AIR};
use squeal_signal::{Levels, Listener, Space};

use crate::model::AnyModel;
use crate::run::Run;

/// The default radiating area of the thesis's disc (m²): both friction
/// faces of an annulus of 280 mm outer and 160 mm inner diameter, a
/// passenger-car front disc, `2·π·(0.14² − 0.08²)` (a **reconstruction**:
/// the thesis gives no disc dimensions; docs/physics.md §5f).
pub const DISC_FACES_M2: f64 = 2.0 * std::f64::consts::PI * (0.14 * 0.14 - 0.08 * 0.08);

/// The assumptions behind every level, as the output states them.
pub const ASSUMPTIONS: &str = "equivalent radiated power: radiation efficiency 1, each surface a rigid piston moving with its dof's velocity, surfaces incoherent (powers add); pressure: the far field of a compact source radiating that power into a full sphere (free field) or a half-space, no reflections; A-weighting IEC 61672-1 on each line of the window's spectrum";

/// The radiating surfaces of a scenario and where the listener is.
#[derive(Debug, Clone, PartialEq)]
pub struct Radiation {
    /// Radiating surfaces: the position coordinate (dof) whose velocity is
    /// normal to the surface, and the surface's area (m²).
    pub areas: Vec<(String, f64)>,
    /// Distance of the listener (m).
    pub distance_m: f64,
    /// Free field or half-space.
    pub space: Space,
    /// Air density (kg/m³).
    pub rho: f64,
    /// Speed of sound (m/s).
    pub c: f64,
}

impl Default for Radiation {
    fn default() -> Self {
        Radiation {
            areas: Vec::new(),
            distance_m: 1.0,
            space: Space::Free,
            rho: RHO_AIR,
            c: C_AIR,
        }
    }
}

/// The keys of `[radiation]` besides `area_m2.<dof>`.
pub const KEYS: [&str; 4] = ["distance_m", "space", "rho", "c"];

impl Radiation {
    /// The default for `model`: the thesis's disc–pad radiates from its
    /// disc faces ([`DISC_FACES_M2`] on `y_d`); other models from nothing.
    pub fn default_for(model: &AnyModel) -> Radiation {
        let mut r = Radiation::default();
        if matches!(model, AnyModel::DiscPad(_)) {
            r.areas.push(("y_d".into(), DISC_FACES_M2));
        }
        r
    }

    /// The listener of these settings.
    pub fn listener(&self) -> Listener {
        Listener {
            rho: self.rho,
            c: self.c,
            distance_m: self.distance_m,
            space: self.space,
        }
    }

    /// Total radiating area (m²).
    pub fn area_m2(&self) -> f64 {
        self.areas.iter().map(|a| a.1).sum()
    }

    /// Set one key (without the `radiation.` prefix): `distance_m`,
    /// `space`, `rho`, `c` or `area_m2.<dof>` with `dof` one of
    /// `positions`. The error names the key and the value.
    pub fn set(&mut self, key: &str, value: &str, positions: &[String]) -> Result<(), String> {
        let shown = format!("radiation.{key}");
        let number = || {
            value
                .parse::<f64>()
                .map_err(|_| format!("{shown} = '{value}': expected a number"))
        };
        let positive = |what: &str| -> Result<f64, String> {
            let x = number()?;
            if x.is_finite() && x > 0.0 {
                Ok(x)
            } else {
                Err(format!(
                    "{shown} = {x}: must be a finite number > 0 ({what})"
                ))
            }
        };
        match key {
            "distance_m" => self.distance_m = positive("m")?,
            "rho" => self.rho = positive("kg/m³")?,
            "c" => self.c = positive("m/s")?,
            "space" => {
                self.space = Space::parse(value).ok_or_else(|| {
                    format!(
                        "{shown} = '{value}': expected free (a full sphere) or half (a half-space)"
                    )
                })?
            }
            k => {
                let Some(dof) = k.strip_prefix("area_m2.") else {
                    return Err(format!(
                        "unknown key '{shown}' (radiation keys: {}, area_m2.<dof>)",
                        KEYS.join(", ")
                    ));
                };
                if !positions.iter().any(|p| p == dof) {
                    return Err(format!(
                        "{shown}: '{dof}' is not a dof of this model (dofs: {})",
                        positions.join(", ")
                    ));
                }
                let a = number()?;
                if !(a.is_finite() && a >= 0.0) {
                    return Err(format!(
                        "{shown} = {a}: must be a finite area ≥ 0 (m²; 0 removes the surface)"
                    ));
                }
                self.areas.retain(|s| s.0 != dof);
                if a > 0.0 {
                    self.areas.push((dof.to_string(), a));
                }
            }
        }
        Ok(())
    }

    /// Every `--set` key: `radiation.distance_m` … and
    /// `radiation.area_m2.<dof>` for each of `positions`.
    pub fn known_keys(positions: &[String]) -> Vec<String> {
        KEYS.iter()
            .map(|k| format!("radiation.{k}"))
            .chain(positions.iter().map(|p| format!("radiation.area_m2.{p}")))
            .collect()
    }

    /// The settings as summary.json's `scenario.radiation`.
    pub fn to_json(&self) -> Value {
        json!({
            "area_m2": self.areas.iter().map(|(d, a)| (d.clone(), json!(a))).collect::<serde_json::Map<String, Value>>(),
            "distance_m": self.distance_m,
            "space": self.space.as_str(),
            "rho": self.rho,
            "c": self.c,
        })
    }

    /// The `[radiation]` table of a scenario file (empty when the settings
    /// are `default`, so that files without one stay without one).
    pub fn to_toml(&self, default: &Radiation) -> String {
        if self == default {
            return String::new();
        }
        let mut t =
            String::from("\n[radiation]                       # how loud: docs/physics.md §5f\n");
        let line = |t: &mut String, kv: String, comment: &str| {
            t.push_str(&format!("{kv:<34}# {comment}\n"));
        };
        line(
            &mut t,
            format!("distance_m = {:?}", self.distance_m),
            "m, where the sound pressure is given",
        );
        line(
            &mut t,
            format!("space = {:?}", self.space.as_str()),
            "free (a full sphere, 4πr²) | half (a half-space, 2πr²)",
        );
        line(
            &mut t,
            format!("rho = {:?}", self.rho),
            "kg/m³, air density",
        );
        line(&mut t, format!("c = {:?}", self.c), "m/s, speed of sound");
        t.push_str("\n[radiation.area_m2]                # radiating surfaces: dof whose velocity is normal to it = area (m²)\n");
        for (d, a) in &self.areas {
            t.push_str(&format!("{d} = {a:?}\n"));
        }
        t
    }
}

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

//! Where a scenario's sound comes from (issue 28 §4, docs/physics.md §5f):
//! its radiating surfaces and listener (`[radiation]`); the `sound` module
//! turns a run into levels with them.
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
use squeal_signal::{Listener, Space};

use crate::model::AnyModel;

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

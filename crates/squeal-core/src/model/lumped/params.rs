//! A lumped model's parameters: the keys `<element>.<key>`, `mass.<dof>`,
//! `matrices.*_scale`, `modal.*` and the shared `[params]`; getting, setting
//! (with the checks of each key's range) and describing them.

use super::*;

impl Lumped {
    /// The analysis options' keys (`modal.dense_max_dofs`, `modal.modes`,
    /// `modal.cutoff_hz`); not in [`Lumped::keys`] (they are not physical
    /// parameters to sweep).
    pub(super) fn modal_get(&self, key: &str) -> Option<f64> {
        match key {
            "modal.dense_max_dofs" => Some(self.modal.dense_max_dofs as f64),
            "modal.modes" => Some(self.modal.modes as f64),
            "modal.cutoff_hz" => Some(self.modal.cutoff_hz),
            _ => None,
        }
    }

    // ---- Parameters: `<element>.<key>` and `mass.<dof>` ----

    /// Every parameter key with its current value, in file order.
    pub fn keys(&self) -> Vec<(String, f64)> {
        let mut out: Vec<(String, f64)> = self
            .shared
            .params()
            .map(|(n, v)| (n.to_string(), v))
            .collect();
        for (i, key) in MATRIX_SCALE_KEYS.iter().enumerate() {
            if self.matrix_base[i].is_some() {
                out.push((format!("matrices.{key}"), self.matrix_scale[i]));
            }
        }
        for (d, m) in self.dofs.iter().zip(&self.masses) {
            if *m > 0.0 {
                out.push((format!("mass.{d}"), *m));
            }
        }
        for s in &self.springs {
            out.push((format!("{}.k", s.name), s.k));
            out.push((format!("{}.c", s.name), s.c));
            out.push((format!("{}.k3", s.name), s.k3));
        }
        for f in &self.forces {
            out.push((format!("{}.value", f.name), f.value));
            out.push((format!("{}.ramp", f.name), f.ramp));
            out.push((format!("{}.amplitude", f.name), f.amplitude));
            out.push((format!("{}.freq_hz", f.name), f.freq_hz));
        }
        for c in &self.contacts {
            match &c.normal {
                Normal::Elastic { k, c: cc, .. } => {
                    out.push((format!("{}.k", c.name), *k));
                    out.push((format!("{}.c", c.name), *cc));
                }
                Normal::Prescribed(f) => out.push((format!("{}.normal_force", c.name), *f)),
            }
            out.push((format!("{}.V", c.name), c.v));
            out.push((format!("{}.alpha", c.name), c.alpha));
            for spec in c.friction.params() {
                out.push((
                    format!("{}.{}", c.name, spec.name),
                    c.friction.get(spec.name).unwrap_or(f64::NAN),
                ));
            }
        }
        out
    }

    /// Value of a parameter by key.
    pub fn get(&self, key: &str) -> Option<f64> {
        if let Some(v) = self.shared.get(key) {
            return Some(v);
        }
        if let Some(v) = self.modal_get(key) {
            return Some(v);
        }
        self.keys()
            .into_iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v)
    }

    /// Set a parameter by key, checking its range; the model is re-checked
    /// (stick constraints, mass matrix) afterwards. Keys are
    /// `<element>.<key>`, `mass.<dof>` and the analysis options
    /// `modal.dense_max_dofs`, `modal.modes`, `modal.cutoff_hz`
    /// ([`ModalOptions`]).
    ///
    /// A shared parameter of `[params]` (a key without a dot) sets every
    /// key bound to it (all or nothing); setting a bound key directly
    /// replaces its expression by the number.
    pub fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        if !key.contains('.') && self.shared.get(key).is_some() {
            let mut next = self.shared.clone();
            let moved = next.set(key, value)?;
            let mut model = self.clone();
            for (k, x) in &moved {
                model.set_element(k, *x).map_err(|e| ParamError::Relation {
                    key: key.into(),
                    value,
                    why: format!("makes {e}"),
                })?;
            }
            model.shared = next;
            *self = model;
            return Ok(());
        }
        self.set_element(key, value)?;
        self.shared.unbind(key);
        Ok(())
    }

    /// Switch contact `contact`'s friction law to `law` (with the values
    /// it carries); the old law's keys lose their expressions.
    pub fn set_friction_law(&mut self, contact: &str, law: FrictionLaw) -> Result<(), ParamError> {
        let c = self
            .contacts
            .iter_mut()
            .find(|c| c.name == contact)
            .ok_or_else(|| ParamError::Unknown {
                key: format!("{contact}.friction"),
            })?;
        for p in c.friction.params() {
            self.shared.unbind(&format!("{contact}.{}", p.name));
        }
        c.friction = law;
        self.rebuild_dense();
        Ok(())
    }

    /// The shared parameters and their bindings.
    pub fn shared(&self) -> &shared::Shared {
        &self.shared
    }

    /// Set one element key (no shared parameter).
    pub(super) fn set_element(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        let invalid = |why: &str| ParamError::Invalid {
            key: key.into(),
            value,
            why: why.into(),
        };
        let unknown = || ParamError::Unknown { key: key.into() };
        let (el, k) = key.split_once('.').ok_or_else(unknown)?;
        let nonneg = |v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(v)
            } else {
                Err(invalid("must be a finite number ≥ 0"))
            }
        };
        let finite = |v: f64| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(invalid("must be a finite number"))
            }
        };
        let mut refresh = false;
        if el == "mass" {
            let i = self.dofs.iter().position(|d| d == k).ok_or_else(unknown)?;
            if !mass_ok(value) {
                return Err(invalid(
                    "a mass must be a number from 1e-30 to 1e30 (kg): squeal's arithmetic cannot resolve masses beyond",
                ));
            }
            self.masses[i] = value;
            refresh = true;
        } else if let Some(s) = self.springs.iter_mut().find(|s| s.name == el) {
            match k {
                "k" => s.k = nonneg(value)?,
                "c" => s.c = nonneg(value)?,
                "k3" => s.k3 = finite(value)?,
                _ => return Err(unknown()),
            }
        } else if let Some(f) = self.forces.iter_mut().find(|f| f.name == el) {
            match k {
                "value" => f.value = finite(value)?,
                "ramp" => f.ramp = nonneg(value)?,
                "amplitude" => f.amplitude = finite(value)?,
                "freq_hz" => f.freq_hz = nonneg(value)?,
                _ => return Err(unknown()),
            }
            self.time_varying = self.forces.iter().any(Force::varies);
        } else if let Some(c) = self.contacts.iter_mut().find(|c| c.name == el) {
            match (k, &mut c.normal) {
                ("k", Normal::Elastic { k, .. }) => *k = nonneg(value)?,
                ("c", Normal::Elastic { c, .. }) => *c = nonneg(value)?,
                ("normal_force", Normal::Prescribed(f)) => *f = nonneg(value)?,
                ("V", _) => c.v = finite(value)?,
                ("alpha", _) => {
                    c.alpha = finite(value)?;
                    refresh = true;
                }
                (fk, _) if c.friction.get(fk).is_some() => {
                    c.friction.set(fk, value).map_err(|e| prefixed(el, e))?;
                }
                _ => return Err(unknown()),
            }
        } else if el == "matrices" {
            let i = MATRIX_SCALE_KEYS
                .iter()
                .position(|x| *x == k)
                .filter(|&i| self.matrix_base[i].is_some())
                .ok_or_else(unknown)?;
            let ok = if i == 0 {
                value.is_finite() && value > 0.0
            } else {
                value.is_finite() && value >= 0.0
            };
            if !ok {
                return Err(invalid(if i == 0 {
                    "a mass matrix's scale must be a finite number > 0"
                } else {
                    "must be a finite number ≥ 0"
                }));
            }
            self.matrix_scale[i] = value;
            let m = self.matrix_base[i].as_ref().map(|b| b.scaled(value));
            match i {
                0 => {
                    self.m_matrix = m;
                    refresh = true;
                }
                1 => self.k_matrix = m,
                _ => self.c_matrix = m,
            }
        } else if el == "modal" {
            let count = |v: f64| {
                if v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= 1e9 {
                    Ok(v as usize)
                } else {
                    Err(invalid("must be a whole number ≥ 0"))
                }
            };
            match k {
                "dense_max_dofs" => self.modal.dense_max_dofs = count(value)?,
                "modes" => self.modal.modes = count(value)?,
                "cutoff_hz" => {
                    if !(value.is_finite() && value > 0.0) {
                        return Err(invalid("must be a finite frequency > 0 (Hz)"));
                    }
                    self.modal.cutoff_hz = value;
                }
                _ => return Err(unknown()),
            }
        } else {
            return Err(unknown());
        }
        if refresh {
            self.refresh().map_err(|e| ParamError::Relation {
                key: key.into(),
                value,
                why: e.0,
            })?;
        }
        self.rebuild_dense();
        Ok(())
    }

    /// Check relations between parameters (each contact's friction law).
    pub fn validate(&self) -> Result<(), ParamError> {
        if let Some(f) = self
            .forces
            .iter()
            .find(|f| f.is_harmonic() && f.freq_hz == 0.0)
        {
            return Err(ParamError::Relation {
                key: format!("{}.freq_hz", f.name),
                value: 0.0,
                why: format!(
                    "leaves {}.amplitude = {} without a frequency: a harmonic force needs freq_hz > 0",
                    f.name, f.amplitude
                ),
            });
        }
        for c in &self.contacts {
            c.friction.validate().map_err(|e| prefixed(&c.name, e))?;
        }
        Ok(())
    }

    /// Unit and meaning of a parameter key (for tables and axis labels).
    pub fn describe(&self, key: &str) -> Option<(&'static str, String)> {
        if self.shared.get(key).is_some() {
            let users = self.shared.users(key);
            return Some((
                "",
                if users.is_empty() {
                    format!("shared parameter {key} (used by no key)")
                } else {
                    format!("shared parameter {key} (sets {})", users.join(", "))
                },
            ));
        }
        let (el, k) = key.split_once('.')?;
        if el == "mass" {
            return Some(("kg", format!("mass of dof {k}")));
        }
        if el == "matrices" && self.get(key).is_some() {
            return Some((
                "",
                format!("scale factor of the matrix {} read from its file", &k[..1]),
            ));
        }
        if el == "modal" && self.modal_get(key).is_some() {
            return Some(match k {
                "dense_max_dofs" => ("", "largest model (dofs) solved by the dense eigen-analysis; larger ones by projection onto undamped modes".to_string()),
                "modes" => ("", "number of undamped modes of the projection basis (0: by modal.cutoff_hz)".to_string()),
                _ => ("Hz", "highest undamped frequency of the projection basis".to_string()),
            });
        }
        if self.springs.iter().any(|s| s.name == el) {
            return match k {
                "k" => Some(("N/m", format!("stiffness of spring {el}"))),
                "c" => Some(("kg/s", format!("damping of spring {el}"))),
                "k3" => Some(("N/m^3", format!("cubic stiffness of spring {el}"))),
                _ => None,
            };
        }
        if self.forces.iter().any(|f| f.name == el) {
            return match k {
                "value" => Some(("N", format!("value of force {el}"))),
                "ramp" => Some(("s", format!("ramp time of force {el}"))),
                "amplitude" => Some(("N", format!("harmonic amplitude of force {el}"))),
                "freq_hz" => Some(("Hz", format!("harmonic frequency of force {el}"))),
                _ => None,
            };
        }
        let c = self.contacts.iter().find(|c| c.name == el)?;
        match k {
            "k" => Some(("N/m", format!("contact stiffness of {el}"))),
            "c" => Some(("kg/s", format!("contact damping of {el}"))),
            "normal_force" => Some(("N", format!("prescribed normal load of {el}"))),
            "V" => Some(("m/s", format!("surface speed at {el}"))),
            "alpha" => Some(("1/m", format!("follower-force coefficient of {el}"))),
            _ => c
                .friction
                .params()
                .iter()
                .find(|p| p.name == k)
                .map(|p| (p.unit, format!("{} ({el})", p.doc))),
        }
    }

    /// The kind of values a key takes (sign), for lever and map ranges.
    pub fn kind_of(&self, key: &str) -> crate::params::ParamKind {
        use crate::params::ParamKind;
        if self.shared.get(key).is_some() {
            // The kind of the key it sets, when it is the bare name.
            return self
                .shared
                .bindings()
                .iter()
                .find(|b| b.source.trim() == key)
                .map_or(ParamKind::Any, |b| self.kind_of(&b.key));
        }
        let (el, k) = key.split_once('.').unwrap_or(("", key));
        if el == "mass" || key == "matrices.M_scale" {
            return ParamKind::Positive;
        }
        if el == "matrices" {
            return ParamKind::NonNegative;
        }
        if el == "modal" {
            return if k == "cutoff_hz" {
                ParamKind::Positive
            } else {
                ParamKind::NonNegative
            };
        }
        match k {
            "value" | "V" | "alpha" | "k3" | "amplitude" => ParamKind::Any,
            "k" | "c" | "ramp" | "normal_force" | "freq_hz" => ParamKind::NonNegative,
            _ => self
                .contacts
                .iter()
                .find(|c| c.name == el)
                .and_then(|c| c.friction.params().iter().find(|p| p.name == k))
                .map_or(ParamKind::Any, |p| p.kind),
        }
    }
}

/// A friction-law error with the key as users type it for a lumped model (`pad1.mu_k`).
pub(super) fn prefixed(el: &str, e: ParamError) -> ParamError {
    match e {
        ParamError::Unknown { key } => ParamError::Unknown {
            key: format!("{el}.{key}"),
        },
        ParamError::Invalid { key, value, why } => ParamError::Invalid {
            key: format!("{el}.{key}"),
            value,
            why,
        },
        ParamError::Relation { key, value, why } => ParamError::Relation {
            key: format!("{el}.{key}"),
            value,
            why: why.replace("mu_k", &format!("{el}.mu_k")),
        },
        other => other,
    }
}

//! Friction laws μ(v) of the sliding speed v ≥ 0, each with its slope dμ/dv
//! and its static coefficient μ_s (the bound on the stick force, μ_s ≥ μ(0+)).
//!
//! Laws are selected by name (`thesis`, `coulomb`, `stribeck`, `rational`, `tanh`) and
//! their parameters are addressed by the ASCII names of MODEL.md §3, so that a
//! scenario can switch laws and keep the parameters the two laws share.

use crate::params::{ParamError, ParamKind, ParamSpec};

/// A friction law. Every model takes any law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionLaw {
    /// The thesis law (Ouyang–Mottershead, thesis Ch. 10):
    /// `μ(v) = f0·(1 − f1·v·(1 − v/(2·Uc)))`, static coefficient `f0`.
    Thesis {
        /// Friction coefficient at zero sliding speed.
        f0: f64,
        /// Stribeck (velocity-weakening) coefficient (s/m); 0 turns it off.
        f1: f64,
        /// Speed of minimum friction (m/s).
        uc: f64,
    },
    /// Coulomb friction: `μ(v) = μ_k` in slip, stick bound `μ_s ≥ μ_k`.
    Coulomb {
        /// Static coefficient.
        mu_s: f64,
        /// Kinetic coefficient.
        mu_k: f64,
    },
    /// Exponential Stribeck law:
    /// `μ(v) = μ_k + (μ_s − μ_k)·exp(−(v/v_s)^δ) + σ·v`.
    Stribeck {
        /// Static coefficient.
        mu_s: f64,
        /// Kinetic (high-speed) coefficient.
        mu_k: f64,
        /// Stribeck speed (m/s).
        v_s: f64,
        /// Stribeck exponent δ.
        delta: f64,
        /// Viscous coefficient σ (s/m).
        sigma: f64,
    },
    /// The rational law of Leine, van Campen, de Kraker & van den Steen (1998,
    /// Nonlinear Dynamics 16, "Stick-slip vibrations induced by alternate
    /// friction models"): `μ(v) = μ_s / (1 + δ·v)`.
    Rational {
        /// Static coefficient.
        mu_s: f64,
        /// Decay coefficient δ (s/m).
        delta: f64,
    },
    /// Regularised Coulomb friction, `μ(v) = μ_k·tanh(v/ε)`: smooth and odd
    /// in the signed sliding speed, so it never sticks (its static
    /// coefficient is `μ(0) = 0`: a contact at zero sliding speed with any
    /// tangential load slides on). The law of NLvib's friction examples
    /// (Krack & Gross 2019, *Harmonic Balance for Nonlinear Vibration
    /// Problems*, §2) and of many harmonic-balance codes; exact Coulomb
    /// friction is its limit `ε → 0`, at the cost of a slope `μ_k/ε` at
    /// `v = 0` that makes the motion stiff.
    Tanh {
        /// Kinetic coefficient (the limit at `|v| ≫ ε`).
        mu_k: f64,
        /// Regularisation speed ε (m/s).
        eps: f64,
    },
}

/// Names of the friction laws, as typed by users.
pub const LAW_NAMES: [&str; 5] = ["thesis", "coulomb", "stribeck", "rational", "tanh"];

const THESIS_PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "f0",
        "1",
        "friction coefficient at zero sliding speed (= μ_s)",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "f1",
        "s/m",
        "Stribeck (velocity-weakening) coefficient; 0 turns it off",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "Uc",
        "m/s",
        "speed of minimum friction",
        ParamKind::Positive,
    ),
];
const COULOMB_PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "mu_s",
        "1",
        "static friction coefficient",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "mu_k",
        "1",
        "kinetic friction coefficient (≤ mu_s)",
        ParamKind::NonNegative,
    ),
];
const STRIBECK_PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "mu_s",
        "1",
        "static friction coefficient",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "mu_k",
        "1",
        "kinetic friction coefficient (≤ mu_s)",
        ParamKind::NonNegative,
    ),
    ParamSpec::new("v_s", "m/s", "Stribeck speed", ParamKind::Positive),
    ParamSpec::new(
        "delta",
        "1",
        "Stribeck exponent (≥ 1 keeps dμ/dv finite at 0)",
        ParamKind::Positive,
    ),
    ParamSpec::new(
        "sigma",
        "s/m",
        "viscous friction coefficient",
        ParamKind::NonNegative,
    ),
];
const RATIONAL_PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "mu_s",
        "1",
        "static friction coefficient",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "delta",
        "s/m",
        "decay coefficient of μ = mu_s/(1 + delta·v)",
        ParamKind::NonNegative,
    ),
];

const TANH_PARAMS: &[ParamSpec] = &[
    ParamSpec::new(
        "mu_k",
        "1",
        "kinetic friction coefficient (μ = mu_k·tanh(v/eps))",
        ParamKind::NonNegative,
    ),
    ParamSpec::new(
        "eps",
        "m/s",
        "regularisation speed of μ = mu_k·tanh(v/eps)",
        ParamKind::Positive,
    ),
];

impl Default for FrictionLaw {
    /// The thesis law with MODEL.md's defaults: f0 = 0.1, f1 = 1/15 s/m, Uc = 50/3 m/s.
    fn default() -> Self {
        FrictionLaw::Thesis {
            f0: 0.1,
            f1: 1.0 / 15.0,
            uc: 50.0 / 3.0,
        }
    }
}

/// Round-off (in units of the larger side's last place) that relations
/// between friction parameters tolerate: values computed on a grid
/// (`0.1 + 7·0.05`) miss their exact decimal by a few ulps.
pub const RELATION_ULPS: f64 = 8.0;

impl FrictionLaw {
    /// The law called `name` with its default parameters.
    pub fn by_name(name: &str) -> Result<Self, ParamError> {
        Ok(match name {
            "thesis" => Self::default(),
            "coulomb" => FrictionLaw::Coulomb {
                mu_s: 0.1,
                mu_k: 0.08,
            },
            "stribeck" => FrictionLaw::Stribeck {
                mu_s: 0.1,
                mu_k: 0.06,
                v_s: 1.0,
                delta: 2.0,
                sigma: 0.0,
            },
            "rational" => FrictionLaw::Rational {
                mu_s: 0.1,
                delta: 0.5,
            },
            "tanh" => FrictionLaw::Tanh {
                mu_k: 0.08,
                eps: 1e-3,
            },
            _ => {
                return Err(ParamError::BadChoice {
                    key: "friction".into(),
                    value: name.into(),
                    allowed: LAW_NAMES.join(", "),
                })
            }
        })
    }

    /// The law called `name`, keeping every parameter it shares by name with `self`.
    pub fn switch_to(&self, name: &str) -> Result<Self, ParamError> {
        let mut new = Self::by_name(name)?;
        for spec in new.params() {
            if let Some(v) = self.get(spec.name) {
                new.set(spec.name, v)?;
            }
        }
        Ok(new)
    }

    /// The law's name as typed by users.
    pub fn name(&self) -> &'static str {
        match self {
            FrictionLaw::Thesis { .. } => "thesis",
            FrictionLaw::Coulomb { .. } => "coulomb",
            FrictionLaw::Stribeck { .. } => "stribeck",
            FrictionLaw::Rational { .. } => "rational",
            FrictionLaw::Tanh { .. } => "tanh",
        }
    }

    /// The law's parameters (names, units, meaning).
    pub fn params(&self) -> &'static [ParamSpec] {
        match self {
            FrictionLaw::Thesis { .. } => THESIS_PARAMS,
            FrictionLaw::Coulomb { .. } => COULOMB_PARAMS,
            FrictionLaw::Stribeck { .. } => STRIBECK_PARAMS,
            FrictionLaw::Rational { .. } => RATIONAL_PARAMS,
            FrictionLaw::Tanh { .. } => TANH_PARAMS,
        }
    }

    /// Value of a parameter by name, `None` if this law has no such parameter.
    pub fn get(&self, key: &str) -> Option<f64> {
        match (*self, key) {
            (FrictionLaw::Thesis { f0, .. }, "f0") => Some(f0),
            (FrictionLaw::Thesis { f1, .. }, "f1") => Some(f1),
            (FrictionLaw::Thesis { uc, .. }, "Uc") => Some(uc),
            (FrictionLaw::Coulomb { mu_s, .. }, "mu_s")
            | (FrictionLaw::Stribeck { mu_s, .. }, "mu_s")
            | (FrictionLaw::Rational { mu_s, .. }, "mu_s") => Some(mu_s),
            (FrictionLaw::Coulomb { mu_k, .. }, "mu_k")
            | (FrictionLaw::Stribeck { mu_k, .. }, "mu_k")
            | (FrictionLaw::Tanh { mu_k, .. }, "mu_k") => Some(mu_k),
            (FrictionLaw::Tanh { eps, .. }, "eps") => Some(eps),
            (FrictionLaw::Stribeck { v_s, .. }, "v_s") => Some(v_s),
            (FrictionLaw::Stribeck { delta, .. }, "delta")
            | (FrictionLaw::Rational { delta, .. }, "delta") => Some(delta),
            (FrictionLaw::Stribeck { sigma, .. }, "sigma") => Some(sigma),
            _ => None,
        }
    }

    /// Set a parameter by name. The value is checked on its own (finite,
    /// sign); relations between parameters are checked by [`Self::validate`].
    pub fn set(&mut self, key: &str, value: f64) -> Result<(), ParamError> {
        let spec = self
            .params()
            .iter()
            .find(|s| s.name == key)
            .ok_or_else(|| ParamError::Unknown { key: key.into() })?;
        spec.check(value)?;
        match (self, key) {
            (FrictionLaw::Thesis { f0, .. }, "f0") => *f0 = value,
            (FrictionLaw::Thesis { f1, .. }, "f1") => *f1 = value,
            (FrictionLaw::Thesis { uc, .. }, "Uc") => *uc = value,
            (FrictionLaw::Coulomb { mu_s, .. }, "mu_s")
            | (FrictionLaw::Stribeck { mu_s, .. }, "mu_s")
            | (FrictionLaw::Rational { mu_s, .. }, "mu_s") => *mu_s = value,
            (FrictionLaw::Coulomb { mu_k, .. }, "mu_k")
            | (FrictionLaw::Stribeck { mu_k, .. }, "mu_k")
            | (FrictionLaw::Tanh { mu_k, .. }, "mu_k") => *mu_k = value,
            (FrictionLaw::Tanh { eps, .. }, "eps") => *eps = value,
            (FrictionLaw::Stribeck { v_s, .. }, "v_s") => *v_s = value,
            (FrictionLaw::Stribeck { delta, .. }, "delta")
            | (FrictionLaw::Rational { delta, .. }, "delta") => *delta = value,
            (FrictionLaw::Stribeck { sigma, .. }, "sigma") => *sigma = value,
            _ => unreachable!("every listed parameter is settable"),
        }
        Ok(())
    }

    /// Check relations between parameters: `mu_s ≥ mu_k`, and a thesis law
    /// whose friction stays non-negative (`f1·Uc ≤ 2`, so μ(Uc) ≥ 0). Both
    /// tolerate [`RELATION_ULPS`] units of round-off: a map step that lands
    /// `mu_k` on 0.45000000000000007 beside `mu_s = 0.45` is equality.
    pub fn validate(&self) -> Result<(), ParamError> {
        for spec in self.params() {
            spec.check(self.get(spec.name).unwrap_or(f64::NAN))?;
        }
        let slack = |x: f64| RELATION_ULPS * f64::EPSILON * x.abs();
        match *self {
            FrictionLaw::Coulomb { mu_s, mu_k } | FrictionLaw::Stribeck { mu_s, mu_k, .. }
                if mu_s < mu_k - slack(mu_k) =>
            {
                Err(ParamError::Relation {
                    key: "mu_s".into(),
                    value: mu_s,
                    why: format!("must be ≥ mu_k = {mu_k}"),
                })
            }
            FrictionLaw::Thesis { f1, uc, .. } if f1 * uc > 2.0 + slack(2.0) => {
                Err(ParamError::Relation {
                    key: "f1".into(),
                    value: f1,
                    why: format!(
                        "f1·Uc = {} > 2 makes the friction coefficient negative near Uc",
                        f1 * uc
                    ),
                })
            }
            _ => Ok(()),
        }
    }

    /// Friction coefficient μ(v) at sliding speed `v ≥ 0`.
    ///
    /// For slightly negative `v` it returns a smooth continuation (the same
    /// formula; the Stribeck law uses |v|), which the integrator evaluates
    /// only inside a step that overshoots a slip reversal before the event is
    /// located: a kink there would make the error estimate reject the step.
    #[inline(always)]
    pub fn mu(&self, v: f64) -> f64 {
        match *self {
            FrictionLaw::Thesis { f0, f1, uc } => f0 * (1.0 - f1 * v * (1.0 - v / (2.0 * uc))),
            FrictionLaw::Coulomb { mu_k, .. } => mu_k,
            FrictionLaw::Stribeck {
                mu_s,
                mu_k,
                v_s,
                delta,
                sigma,
            } => mu_k + (mu_s - mu_k) * (-(v.abs() / v_s).powf(delta)).exp() + sigma * v,
            FrictionLaw::Rational { mu_s, delta } => mu_s / (1.0 + delta * v),
            FrictionLaw::Tanh { mu_k, eps } => mu_k * (v / eps).tanh(),
        }
    }

    /// Slope dμ/dv at sliding speed `v ≥ 0`.
    #[inline]
    pub fn dmu(&self, v: f64) -> f64 {
        match *self {
            FrictionLaw::Thesis { f0, f1, uc } => -f0 * f1 * (1.0 - v / uc),
            FrictionLaw::Coulomb { .. } => 0.0,
            FrictionLaw::Stribeck {
                mu_s,
                mu_k,
                v_s,
                delta,
                sigma,
            } => {
                if v == 0.0 {
                    // (v/v_s)^(δ−1) at 0: 0 for δ > 1, 1 for δ = 1, unbounded below.
                    let lead = if delta > 1.0 {
                        0.0
                    } else if delta == 1.0 {
                        1.0
                    } else {
                        f64::INFINITY
                    };
                    return -(mu_s - mu_k) * delta / v_s * lead + sigma;
                }
                let r = v / v_s;
                -(mu_s - mu_k) * delta / v_s * r.powf(delta - 1.0) * (-r.powf(delta)).exp() + sigma
            }
            FrictionLaw::Rational { mu_s, delta } => {
                let d = 1.0 + delta * v;
                -mu_s * delta / (d * d)
            }
            FrictionLaw::Tanh { mu_k, eps } => {
                // sech² = 1 − tanh², exact to round-off and finite for any v.
                let t = (v / eps).tanh();
                mu_k / eps * (1.0 - t * t)
            }
        }
    }

    /// Whether μ does not depend on the sliding speed (Coulomb).
    pub fn is_constant(&self) -> bool {
        matches!(self, FrictionLaw::Coulomb { .. })
    }

    /// Upper bounds of `|μ(v)|` and `|dμ/dv|` for `v ∈ [lo, hi]` (the
    /// formulas [`Self::mu`] and [`Self::dmu`] evaluate there, continuation
    /// below 0 included). Used to prove that a guard cannot cross zero between
    /// two points; `INFINITY` where no finite bound exists.
    pub fn bounds(&self, lo: f64, hi: f64) -> (f64, f64) {
        let (lo, hi) = (lo.min(hi), lo.max(hi));
        match *self {
            FrictionLaw::Thesis { uc, .. } => {
                // μ is a parabola with its vertex at Uc, dμ/dv is linear.
                let mut m = self.mu(lo).abs().max(self.mu(hi).abs());
                if lo < uc && uc < hi {
                    m = m.max(self.mu(uc).abs());
                }
                (m, self.dmu(lo).abs().max(self.dmu(hi).abs()))
            }
            FrictionLaw::Coulomb { mu_k, .. } => (mu_k.abs(), 0.0),
            FrictionLaw::Stribeck {
                mu_s,
                mu_k,
                v_s,
                delta,
                sigma,
            } => {
                let vmax = lo.abs().max(hi.abs());
                let m = mu_k.abs() + (mu_s - mu_k).abs() + sigma.abs() * vmax;
                // r^(δ−1)·exp(−r^δ) ≤ 1 for δ ≥ 1 (its maximum, at r^δ = 1 − 1/δ).
                let d = if delta >= 1.0 {
                    (mu_s - mu_k).abs() * delta / v_s + sigma.abs()
                } else {
                    f64::INFINITY
                };
                (m, d)
            }
            FrictionLaw::Rational { mu_s, delta } => {
                let d0 = 1.0 + delta * lo;
                if d0 <= 0.0 {
                    (f64::INFINITY, f64::INFINITY)
                } else {
                    (mu_s.abs() / d0, mu_s.abs() * delta / (d0 * d0))
                }
            }
            // |tanh| ≤ 1 and sech² ≤ 1 everywhere.
            FrictionLaw::Tanh { mu_k, eps } => (mu_k.abs(), mu_k.abs() / eps),
        }
    }

    /// Static coefficient μ_s: the stick force bound is μ_s times the normal force.
    #[inline]
    pub fn mu_static(&self) -> f64 {
        match *self {
            FrictionLaw::Thesis { f0, .. } => f0,
            FrictionLaw::Coulomb { mu_s, .. }
            | FrictionLaw::Stribeck { mu_s, .. }
            | FrictionLaw::Rational { mu_s, .. } => mu_s,
            FrictionLaw::Tanh { .. } => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relations_tolerate_round_off_but_not_more() {
        // A map step lands mu_k on 0.45000000000000007 beside mu_s = 0.45:
        // equal up to one ulp, accepted (issue 26 §3).
        let grid_mu_k = 0.1 + 7.0 * 0.05;
        assert_eq!(grid_mu_k, 0.45000000000000007);
        let ok = FrictionLaw::Coulomb {
            mu_s: 0.45,
            mu_k: grid_mu_k,
        };
        assert!(ok.validate().is_ok());
        // A real violation, 1e-12 relative, is still refused.
        let bad = FrictionLaw::Coulomb {
            mu_s: 0.45,
            mu_k: 0.45 * (1.0 + 1e-12),
        };
        assert!(matches!(bad.validate(), Err(ParamError::Relation { .. })));
    }

    #[test]
    fn thesis_law_matches_model_md_numbers() {
        let law = FrictionLaw::default();
        assert!((law.mu(0.0) - 0.1).abs() < 1e-15);
        // Expanded form of MODEL.md: f0(1 − v/15) + 0.0002 v² with the defaults.
        for v in [0.3, 1.0, 5.0, 16.0, 30.0] {
            let expanded = 0.1 * (1.0 - v / 15.0) + 0.0002 * v * v;
            assert!((law.mu(v) - expanded).abs() < 1e-15, "v = {v}");
        }
        // Minimum at Uc = 50/3 with μ ≈ 0.0444.
        assert!(law.dmu(50.0 / 3.0).abs() < 1e-16);
        assert!((law.mu(50.0 / 3.0) - 0.1 * (1.0 - 5.0 / 9.0)).abs() < 1e-15);
    }

    #[test]
    fn slopes_match_central_differences() {
        let laws = [
            FrictionLaw::default(),
            FrictionLaw::by_name("coulomb").unwrap(),
            FrictionLaw::by_name("stribeck").unwrap(),
            FrictionLaw::by_name("rational").unwrap(),
            FrictionLaw::Tanh {
                mu_k: 0.3,
                eps: 0.5,
            },
        ];
        for law in laws {
            for v in [0.05, 0.7, 2.0, 9.0] {
                let h = 1e-6;
                let fd = (law.mu(v + h) - law.mu(v - h)) / (2.0 * h);
                assert!((fd - law.dmu(v)).abs() < 1e-8, "{} at v = {v}", law.name());
            }
            assert!(law.mu_static() >= law.mu(0.0) - 1e-15, "{}", law.name());
        }
    }

    #[test]
    fn switching_keeps_shared_parameters() {
        let mut c = FrictionLaw::by_name("coulomb").unwrap();
        c.set("mu_s", 0.5).unwrap();
        c.set("mu_k", 0.3).unwrap();
        let s = c.switch_to("stribeck").unwrap();
        assert_eq!(s.get("mu_s"), Some(0.5));
        assert_eq!(s.get("mu_k"), Some(0.3));
        assert_eq!(s.get("v_s"), Some(1.0));
        assert!(FrictionLaw::by_name("glue").is_err());
    }

    #[test]
    fn rejects_static_below_kinetic() {
        let mut c = FrictionLaw::by_name("coulomb").unwrap();
        c.set("mu_k", 0.5).unwrap();
        let err = c.validate().unwrap_err().to_string();
        assert!(err.contains("mu_s"), "{err}");
        assert!(c.set("mu_k", f64::NAN).is_err());
        assert!(c.set("v_s", 1.0).is_err());
    }
}

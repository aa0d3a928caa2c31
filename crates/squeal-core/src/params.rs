//! Named scalar parameters: the ASCII keys users type (`--set k_dx=2e9`), with
//! units, meaning and the sign each must have.

use thiserror::Error;

/// What values a parameter accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamKind {
    /// Strictly positive and finite (masses, stiffnesses).
    Positive,
    /// Zero or positive, finite (damping, speeds).
    NonNegative,
    /// Any finite value.
    Any,
}

/// Description of one named parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// ASCII key, e.g. `k_dx`.
    pub name: &'static str,
    /// SI unit, e.g. `N/m`.
    pub unit: &'static str,
    /// One-line meaning.
    pub doc: &'static str,
    /// Accepted values.
    pub kind: ParamKind,
}

impl ParamSpec {
    /// A parameter description.
    pub const fn new(
        name: &'static str,
        unit: &'static str,
        doc: &'static str,
        kind: ParamKind,
    ) -> Self {
        ParamSpec {
            name,
            unit,
            doc,
            kind,
        }
    }

    /// Check a value against the parameter's kind.
    pub fn check(&self, value: f64) -> Result<(), ParamError> {
        let why = if !value.is_finite() {
            Some("must be a finite number")
        } else {
            match self.kind {
                ParamKind::Positive if value <= 0.0 => Some("must be > 0"),
                ParamKind::NonNegative if value < 0.0 => Some("must be ≥ 0"),
                _ => None,
            }
        };
        match why {
            Some(why) => Err(ParamError::Invalid {
                key: self.name.into(),
                value,
                why: why.into(),
            }),
            None => Ok(()),
        }
    }
}

/// A number as a message shows it: as written (`2000`, `0.1`) unless that
/// takes more than 12 characters, then in exponent form (`1e300`, not 301
/// digits).
pub fn short(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 12 {
        plain
    } else {
        format!("{v:e}")
    }
}

/// A bad parameter: every variant names the key and the value.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// No parameter of that name.
    #[error("unknown parameter '{key}'")]
    Unknown {
        /// The key as given.
        key: String,
    },
    /// The value is out of the parameter's range.
    #[error("{key} = {}: {why}", short(*value))]
    Invalid {
        /// The key.
        key: String,
        /// The offending value.
        value: f64,
        /// What is wrong.
        why: String,
    },
    /// The value contradicts another parameter.
    #[error("{key} = {}: {why}", short(*value))]
    Relation {
        /// The key.
        key: String,
        /// The offending value.
        value: f64,
        /// What is wrong.
        why: String,
    },
    /// A named choice that is not one of the allowed names.
    #[error("{key} = '{value}': expected one of {allowed}")]
    BadChoice {
        /// The key.
        key: String,
        /// The value as given.
        value: String,
        /// The allowed names.
        allowed: String,
    },
}

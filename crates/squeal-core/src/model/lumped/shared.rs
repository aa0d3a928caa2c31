//! Shared, named parameters of a lumped model (the `[params]` table of a
//! scenario file): `mu = 0.45`, and element keys bound to expressions of
//! them (`inner.mu_k = "mu"`, `inner.mu_s = "1.2*mu"`, `brake_1.value =
//! "-Fb/2"`). Setting a parameter re-evaluates every key bound to it, so
//! `--param mu=0.3:0.6:31` moves every pad's friction at once. Expressions
//! are parsed and evaluated by the `exmex` crate (arithmetic, powers,
//! parentheses and the usual functions).

use crate::params::ParamError;

/// One element key bound to an expression of the shared parameters.
#[derive(Debug, Clone)]
pub struct Binding {
    /// The element key it sets (`inner.mu_k`).
    pub key: String,
    /// The expression as written (`1.2*mu`).
    pub source: String,
    expr: exmex::FlatEx<f64>,
    /// For each of the expression's variables (in `exmex`'s order), the
    /// index of the shared parameter.
    vars: Vec<usize>,
}

impl PartialEq for Binding {
    fn eq(&self, other: &Self) -> bool {
        self.key == other.key && self.source == other.source && self.vars == other.vars
    }
}

/// The shared parameters and the keys bound to them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Shared {
    names: Vec<String>,
    values: Vec<f64>,
    bindings: Vec<Binding>,
}

/// Whether `name` can name a shared parameter: a letter or `_`, then
/// letters, digits and `_` (a bare TOML key that is also a variable of an
/// expression, with no `.` to clash with element keys).
pub fn is_param_name(name: &str) -> bool {
    let mut c = name.chars();
    matches!(c.next(), Some(f) if f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

impl Shared {
    /// Declare the parameters (`name = value`, in order). Names must be
    /// valid ([`is_param_name`]), distinct and the values finite.
    pub fn new(params: &[(String, f64)]) -> Result<Shared, String> {
        let mut s = Shared::default();
        for (n, v) in params {
            if !is_param_name(n) {
                return Err(format!(
                    "params: '{n}' is not a parameter name (a letter or _, then letters, digits, _)"
                ));
            }
            if s.names.contains(n) {
                return Err(format!("params: '{n}' is declared twice"));
            }
            if !v.is_finite() {
                return Err(format!("params: {n} = {v}: expected a finite number"));
            }
            s.names.push(n.clone());
            s.values.push(*v);
        }
        Ok(s)
    }

    /// Whether there is no parameter.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The parameters `(name, value)`, in declaration order.
    pub fn params(&self) -> impl Iterator<Item = (&str, f64)> {
        self.names
            .iter()
            .map(String::as_str)
            .zip(self.values.iter().copied())
    }

    /// The bindings, in the order they were made.
    pub fn bindings(&self) -> &[Binding] {
        &self.bindings
    }

    /// The value of parameter `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.index(name).map(|i| self.values[i])
    }

    fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Parse `source` and bind `key` to it; the value it has now. Errors
    /// name the key, the expression and what is wrong (a syntax error, an
    /// undeclared name, a value that is not finite).
    pub fn bind(&mut self, key: &str, source: &str) -> Result<f64, String> {
        let expr = exmex::parse::<f64>(source)
            .map_err(|e| format!("{key} = \"{source}\": not an expression of parameters ({e})"))?;
        let mut vars = Vec::new();
        for v in exmex::Express::var_names(&expr) {
            let i = self.index(v).ok_or_else(|| {
                format!(
                    "{key} = \"{source}\": '{v}' is not a parameter of [params] ({})",
                    if self.names.is_empty() {
                        "none is declared".to_string()
                    } else {
                        format!("declared: {}", self.names.join(", "))
                    }
                )
            })?;
            vars.push(i);
        }
        let b = Binding {
            key: key.into(),
            source: source.into(),
            expr,
            vars,
        };
        let x = self.eval(&b);
        if !x.is_finite() {
            return Err(format!(
                "{key} = \"{source}\" is {x} with the parameters' values"
            ));
        }
        self.bindings.retain(|o| o.key != key);
        self.bindings.push(b);
        Ok(x)
    }

    /// Forget the binding of `key` (a number was set for it directly).
    pub fn unbind(&mut self, key: &str) {
        self.bindings.retain(|b| b.key != key);
    }

    /// The binding of `key`, if any.
    pub fn binding(&self, key: &str) -> Option<&Binding> {
        self.bindings.iter().find(|b| b.key == key)
    }

    fn eval(&self, b: &Binding) -> f64 {
        let vals: Vec<f64> = b.vars.iter().map(|&i| self.values[i]).collect();
        exmex::Express::eval(&b.expr, &vals).unwrap_or(f64::NAN)
    }

    /// Set parameter `name` and return the keys bound to it with their new
    /// values (to be set on the model, in binding order). Errors if a bound
    /// value would not be finite.
    pub fn set(&mut self, name: &str, value: f64) -> Result<Vec<(String, f64)>, ParamError> {
        let i = self
            .index(name)
            .ok_or_else(|| ParamError::Unknown { key: name.into() })?;
        if !value.is_finite() {
            return Err(ParamError::Invalid {
                key: name.into(),
                value,
                why: "must be finite".into(),
            });
        }
        let old = self.values[i];
        self.values[i] = value;
        let mut out = Vec::new();
        for b in self.bindings.iter().filter(|b| b.vars.contains(&i)) {
            let x = self.eval(b);
            if !x.is_finite() {
                self.values[i] = old;
                return Err(ParamError::Relation {
                    key: name.into(),
                    value,
                    why: format!("makes {} = \"{}\" {x}", b.key, b.source),
                });
            }
            out.push((b.key.clone(), x));
        }
        Ok(out)
    }

    /// The keys bound to parameter `name`.
    pub fn users(&self, name: &str) -> Vec<&str> {
        match self.index(name) {
            Some(i) => self
                .bindings
                .iter()
                .filter(|b| b.vars.contains(&i))
                .map(|b| b.key.as_str())
                .collect(),
            None => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_follow_their_parameters() {
        let mut s = Shared::new(&[("mu".into(), 0.45), ("Fb".into(), 2000.0)]).unwrap();
        assert_eq!(s.bind("inner.mu_k", "mu").unwrap(), 0.45);
        assert!((s.bind("inner.mu_s", "1.2*mu").unwrap() - 0.54).abs() < 1e-15);
        assert_eq!(s.bind("brake.value", "-Fb/2").unwrap(), -1000.0);
        let moved = s.set("mu", 0.5).unwrap();
        assert_eq!(moved.len(), 2);
        assert_eq!(moved[0], ("inner.mu_k".to_string(), 0.5));
        assert!((moved[1].1 - 0.6).abs() < 1e-15);
        assert_eq!(s.users("Fb"), vec!["brake.value"]);
        let e = s.bind("outer.mu_k", "mu_x").unwrap_err();
        assert!(
            e.contains("'mu_x' is not a parameter") && e.contains("mu, Fb"),
            "{e}"
        );
        let e = s.bind("outer.mu_k", "1.2*(mu").unwrap_err();
        assert!(
            e.starts_with("outer.mu_k = \"1.2*(mu\": not an expression"),
            "{e}"
        );
        assert!(Shared::new(&[("a.b".into(), 1.0)]).is_err());
        assert!(Shared::new(&[("a".into(), 1.0), ("a".into(), 2.0)]).is_err());
        let e = s.bind("x.k", "1/(mu-mu)").unwrap_err();
        assert!(e.contains("is inf") || e.contains("is NaN"), "{e}");
    }
}

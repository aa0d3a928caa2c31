//! `model = "lumped"` scenario files: the TOML tables (`dofs`, `[masses]`,
//! `[[spring]]`, `[[force]]`, `[[contact]]`, `[matrices]`) → a validated
//! [`Lumped`] model, and back to TOML. Every error names the element and key
//! (`spring 'disc_x': on: unknown dof 'x_q'`). Matrix Market files named in
//! `[matrices]` are read relative to the scenario file's folder.

use crate::error::InputError;
use crate::matrix_file::MatrixInfo;
use squeal_core::labelled::LabelledMatrix;
use squeal_core::model::contact::Normal;
use squeal_core::model::lumped::shared::Shared;
use squeal_core::model::lumped::MAX_MODEL_DOFS;
use squeal_core::model::lumped::{ContactSpec, ForceSpec, LumpedSpec, SpringSpec, Terms};
use squeal_core::{FrictionLaw, Lumped};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Where a lumped model's matrices came from (kept for `scenario show`
/// and `inspect`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MatrixFiles {
    /// `M`, `K`, `C` paths as written in the file.
    pub paths: Vec<(String, String)>,
    /// What was read from each (format, size, nonzeros, symmetry), in the
    /// order `M`, `K`, `C`.
    pub info: Vec<MatrixInfo>,
    /// The dofs without mass, condensed statically before any analysis
    /// ([`squeal_core::model::lumped::condense`]).
    pub condensed: Vec<String>,
}

/// The top-level keys a lumped scenario adds.
pub const LUMPED_KEYS: [&str; 7] = [
    "dofs", "masses", "spring", "force", "contact", "matrices", "params",
];

fn err<T>(msg: impl Into<String>) -> Result<T, InputError> {
    Err(InputError(msg.into()))
}
/// The value of a key an element must have.
fn required<'a>(what: &str, t: &'a toml::Table, key: &str) -> Result<&'a toml::Value, InputError> {
    t.get(key)
        .ok_or_else(|| InputError(format!("{what}: {key}: missing")))
}

/// The `[params]` of a file and the keys bound to expressions of them.
struct Exprs {
    shared: Shared,
    bound: Vec<(String, String)>,
}

impl Exprs {
    /// A number, or a string holding an expression of `[params]` bound to
    /// the element key `el.key` (its value now).
    fn value(
        &mut self,
        what: &str,
        el: &str,
        key: &str,
        v: &toml::Value,
    ) -> Result<f64, InputError> {
        match v {
            toml::Value::String(src) => {
                let full = format!("{el}.{key}");
                let x = self
                    .shared
                    .bind(&full, src)
                    .map_err(|e| InputError(format!("{what}: {e}")))?;
                self.bound.push((full, src.clone()));
                Ok(x)
            }
            other => number(what, key, other),
        }
    }
    fn optional(
        &mut self,
        what: &str,
        el: &str,
        t: &toml::Table,
        key: &str,
    ) -> Result<Option<f64>, InputError> {
        t.get(key).map(|v| self.value(what, el, key, v)).transpose()
    }
}

fn number(what: &str, key: &str, v: &toml::Value) -> Result<f64, InputError> {
    match v {
        toml::Value::Float(x) => Ok(*x),
        toml::Value::Integer(i) => Ok(*i as f64),
        toml::Value::String(s) => err(format!(
            "{what}: {key} = \"{s}\": expected a number (coefficients take numbers; element values such as k, value, mu_k may name [params])"
        )),
        other => err(format!("{what}: {key} = {other}: expected a number")),
    }
}

fn terms(what: &str, key: &str, v: &toml::Value) -> Result<Terms, InputError> {
    let toml::Value::Table(t) = v else {
        return err(format!(
            "{what}: {key} = {v}: expected a table of dof = coefficient, e.g. {{ x_d = 1.0 }}"
        ));
    };
    t.iter()
        .map(|(d, c)| Ok((d.clone(), number(what, &format!("{key}.{d}"), c)?)))
        .collect()
}

fn tables<'a>(table: &'a toml::Table, key: &str) -> Result<Vec<&'a toml::Table>, InputError> {
    match table.get(key) {
        None => Ok(Vec::new()),
        Some(toml::Value::Array(a)) => a
            .iter()
            .map(|v| match v {
                toml::Value::Table(t) => Ok(t),
                other => err(format!("[[{key}]]: expected tables, got {other}")),
            })
            .collect(),
        Some(other) => err(format!("{key} = {other}: expected [[{key}]] tables")),
    }
}

fn element_name(kind: &str, i: usize, t: &toml::Table) -> Result<String, InputError> {
    match t.get("name") {
        Some(toml::Value::String(s)) => Ok(s.clone()),
        Some(other) => err(format!(
            "{kind} #{}: name = {other}: expected a string",
            i + 1
        )),
        None => err(format!("{kind} #{}: name: missing", i + 1)),
    }
}

fn check_keys(what: &str, t: &toml::Table, allowed: &[&str]) -> Result<(), InputError> {
    for k in t.keys() {
        if !allowed.contains(&k.as_str()) {
            return err(format!(
                "{what}: unknown key '{k}' (keys: {})",
                allowed.join(", ")
            ));
        }
    }
    Ok(())
}

/// Read a lumped model from a scenario's top-level table. `base` is the
/// folder matrix files are relative to (`None`: the current folder).
pub fn parse(
    table: &toml::Table,
    base: Option<&Path>,
) -> Result<(Lumped, MatrixFiles), InputError> {
    let mut spec = LumpedSpec::default();
    let mut files = MatrixFiles::default();
    if let Some(p) = table.get("params") {
        let toml::Value::Table(p) = p else {
            return err(format!(
                "params = {p}: expected a table [params] of name = number"
            ));
        };
        for (k, v) in p {
            spec.params.push((k.clone(), number("params", k, v)?));
        }
    }
    let mut ex = Exprs {
        shared: Shared::new(&spec.params).map_err(InputError)?,
        bound: Vec::new(),
    };
    let mut read: Vec<(LabelledMatrix, MatrixInfo)> = Vec::new();
    let mut scales: Vec<(String, f64)> = Vec::new();
    if let Some(m) = table.get("matrices") {
        let toml::Value::Table(m) = m else {
            return err(format!(
                "matrices = {m}: expected a table [matrices] with M, K, C files"
            ));
        };
        check_keys(
            "matrices",
            m,
            &["M", "K", "C", "M_scale", "K_scale", "C_scale"],
        )?;
        for (key, v) in m {
            if key.ends_with("_scale") {
                // Applied to the built model (a number or an expression).
                if !m.contains_key(&key[..1]) {
                    return err(format!(
                        "matrices: {key}: there is no matrix {} to scale",
                        &key[..1]
                    ));
                }
                scales.push((key.clone(), ex.value("matrices", "matrices", key, v)?));
                continue;
            }
            let (p, name, format) = match v {
                toml::Value::String(p) => (p.clone(), None, None),
                toml::Value::Table(t) => {
                    let what = format!("matrices: {key}");
                    check_keys(&what, t, &["file", "name", "format"])?;
                    let text = |k: &str| match t.get(k) {
                        None => Ok(None),
                        Some(toml::Value::String(s)) => Ok(Some(s.clone())),
                        Some(o) => err(format!("{what}: {k} = {o}: expected a string")),
                    };
                    let file = text("file")?
                        .ok_or_else(|| InputError(format!("{what}: file: missing")))?;
                    (file, text("name")?, text("format")?)
                }
                _ => {
                    return err(format!(
                        "matrices: {key} = {v}: expected a file name, or {{ file = \"…\", name = \"…\" }}"
                    ))
                }
            };
            let path = base.map_or_else(|| PathBuf::from(&p), |b| b.join(&p));
            let (lm, info) =
                crate::matrix_file::read(key, &path, &p, name.as_deref(), format.as_deref())?;
            // The model's size limit, from the header, before anything is
            // sized from it.
            let t = &lm.triplets;
            if t.rows.max(t.cols) > MAX_MODEL_DOFS {
                return err(format!(
                    "matrices: {key} = '{p}' is {}×{}: more than the {MAX_MODEL_DOFS} dofs a model may have",
                    t.rows, t.cols
                ));
            }
            files.paths.push((key.clone(), p.clone()));
            read.push((lm, info));
        }
    }
    let listed: Option<Vec<String>> = match table.get("dofs") {
        Some(toml::Value::Array(a)) => Some(
            a.iter()
                .map(|v| match v {
                    toml::Value::String(s) => Ok(s.clone()),
                    other => err(format!("dofs: {other}: expected dof names (strings)")),
                })
                .collect::<Result<_, _>>()?,
        ),
        Some(other) => return err(format!("dofs = {other}: expected a list of names")),
        None => None,
    };
    let labelled = read.iter().any(|(m, _)| m.labels.is_some());
    let union = if labelled {
        Some(crate::matrix_file::union_dofs(
            &mut read,
            listed.as_deref(),
        )?)
    } else {
        None
    };
    for (lm, info) in read {
        match info.key.as_str() {
            "M" => spec.m = Some(lm.triplets),
            "K" => spec.k = Some(lm.triplets),
            _ => spec.c = Some(lm.triplets),
        }
        files.info.push(info);
    }
    spec.dofs = match (union, listed) {
        (Some(u), _) => u,
        (None, Some(listed)) => listed,
        (None, None) => {
            // Numbered after the matrices: q1 … qn.
            let (nkey, n) = [("M", &spec.m), ("K", &spec.k), ("C", &spec.c)]
                .iter()
                .find_map(|(k, t)| t.as_ref().map(|t| (*k, t.rows)))
                .ok_or_else(|| {
                    InputError(
                        "dofs: missing (a list of dof names, or [matrices] to number them)".into(),
                    )
                })?;
            // Every dof needs a mass (a positive-definite M has a positive
            // diagonal): a header that claims more dofs than M's diagonal
            // and [masses] can fill is refused before naming them.
            let diagonal = spec.m.as_ref().map_or(0, |t| {
                let mut d: Vec<usize> = t
                    .entries
                    .iter()
                    .filter(|e| e.0 == e.1)
                    .map(|e| e.0)
                    .collect();
                d.sort_unstable();
                d.dedup();
                d.len()
            });
            let listed = match table.get("masses") {
                Some(toml::Value::Table(m)) => m.len(),
                _ => 0,
            };
            if n > diagonal + listed {
                let p = files
                    .paths
                    .iter()
                    .find(|(k, _)| k == nkey)
                    .map_or("", |(_, p)| p.as_str());
                return err(format!(
                    "matrices: {nkey} = '{p}' is {n}×{n}, but M's diagonal and [masses] give a mass to only {} dofs: every dof needs a mass",
                    diagonal + listed
                ));
            }
            (1..=n).map(|i| format!("q{i}")).collect()
        }
    };
    if let Some(m) = table.get("masses") {
        let toml::Value::Table(m) = m else {
            return err(format!(
                "masses = {m}: expected a table [masses] of dof = mass"
            ));
        };
        for (d, v) in m {
            spec.masses
                .push((d.clone(), ex.value("masses", "mass", d, v)?));
        }
    }
    for (i, t) in tables(table, "spring")?.into_iter().enumerate() {
        let name = element_name("spring", i, t)?;
        let what = format!("spring '{name}'");
        check_keys(&what, t, &["name", "on", "k", "c", "k3"])?;
        let on = terms(&what, "on", required(&what, t, "on")?)?;
        let k = ex.value(&what, &name, "k", required(&what, t, "k")?)?;
        let c = ex.optional(&what, &name, t, "c")?.unwrap_or(0.0);
        let k3 = ex.optional(&what, &name, t, "k3")?.unwrap_or(0.0);
        spec.springs.push(SpringSpec { name, on, k, c, k3 });
    }
    for (i, t) in tables(table, "force")?.into_iter().enumerate() {
        let name = element_name("force", i, t)?;
        let what = format!("force '{name}'");
        check_keys(
            &what,
            t,
            &["name", "on", "value", "ramp", "amplitude", "freq_hz"],
        )?;
        let on = terms(&what, "on", required(&what, t, "on")?)?;
        let value = ex.value(&what, &name, "value", required(&what, t, "value")?)?;
        let ramp = ex.optional(&what, &name, t, "ramp")?.unwrap_or(0.0);
        let amplitude = ex.optional(&what, &name, t, "amplitude")?.unwrap_or(0.0);
        let freq_hz = ex.optional(&what, &name, t, "freq_hz")?.unwrap_or(0.0);
        spec.forces.push(ForceSpec {
            name,
            on,
            value,
            ramp,
            amplitude,
            freq_hz,
        });
    }
    for (i, t) in tables(table, "contact")?.into_iter().enumerate() {
        let name = element_name("contact", i, t)?;
        let what = format!("contact '{name}'");
        let law_name = match t.get("friction") {
            Some(toml::Value::String(s)) => s.clone(),
            Some(other) => return err(format!("{what}: friction = {other}: expected a law name")),
            None => "thesis".into(),
        };
        let mut friction =
            FrictionLaw::by_name(&law_name).map_err(|e| InputError(format!("{what}: {e}")))?;
        let mut allowed = vec![
            "name",
            "normal",
            "k",
            "c",
            "contact",
            "normal_force",
            "tangent",
            "V",
            "friction",
            "alpha",
            "slope",
        ];
        allowed.extend(friction.params().iter().map(|p| p.name));
        check_keys(&what, t, &allowed)?;
        for p in friction.params() {
            if let Some(v) = t.get(p.name) {
                let x = ex.value(&what, &name, p.name, v)?;
                friction
                    .set(p.name, x)
                    .map_err(|e| InputError(format!("{what}: {e}")))?;
            }
        }
        let bilateral = match t.get("contact") {
            None => false,
            Some(toml::Value::String(s)) if s == "unilateral" => false,
            Some(toml::Value::String(s)) if s == "bilateral" => true,
            Some(other) => {
                return err(format!(
                    "{what}: contact = {other}: expected \"unilateral\" or \"bilateral\""
                ))
            }
        };
        let k = ex.optional(&what, &name, t, "k")?;
        let c = ex.optional(&what, &name, t, "c")?;
        let normal_force = ex.optional(&what, &name, t, "normal_force")?;
        let v = ex.optional(&what, &name, t, "V")?.unwrap_or(0.0);
        let alpha = ex.optional(&what, &name, t, "alpha")?.unwrap_or(0.0);
        spec.contacts.push(ContactSpec {
            name,
            normal: t
                .get("normal")
                .map(|v| terms(&what, "normal", v))
                .transpose()?,
            k,
            c,
            bilateral,
            normal_force,
            tangent: t
                .get("tangent")
                .map(|v| terms(&what, "tangent", v))
                .transpose()?,
            v,
            friction,
            alpha,
            slope: t
                .get("slope")
                .map(|v| terms(&what, "slope", v))
                .transpose()?
                .unwrap_or_default(),
        });
    }
    spec.expressions = ex.bound;
    files.condensed = squeal_core::model::lumped::condense::condense_massless(&mut spec)
        .map_err(|e| InputError(e.0))?;
    let mut model = Lumped::build(&spec).map_err(|e| InputError(e.0))?;
    for (k, v) in scales {
        let key = format!("matrices.{k}");
        if model.shared().binding(&key).is_none() {
            model
                .set(&key, v)
                .map_err(|e| InputError(format!("matrices: {e}")))?;
        }
    }
    Ok((model, files))
}

fn combo(l: &Lumped, c: &squeal_core::model::contact::Combination) -> String {
    let parts: Vec<String> = c
        .idx
        .iter()
        .zip(&c.coef)
        .map(|(i, v)| format!("{} = {v:?}", l.dofs()[*i]))
        .collect();
    format!("{{ {} }}", parts.join(", "))
}

/// The model's tables as TOML (current parameter values), for `scenario show`.
pub fn to_toml(l: &Lumped, files: &MatrixFiles) -> String {
    let mut t = String::new();
    // A value as written: its expression (with the value now) where the
    // key is bound to one.
    let val = |key: String, x: f64| match l.shared().binding(&key) {
        Some(b) => format!("{:?}  # = {x:?}", b.source),
        None => format!("{x:?}"),
    };
    let dofs: Vec<String> = l.dofs().iter().map(|d| format!("{d:?}")).collect();
    let _ = writeln!(t, "dofs = [{}]", dofs.join(", "));
    if !l.shared().is_empty() {
        let _ = writeln!(
            t,
            "\n[params]                          # shared parameters: keys below may name them"
        );
        for (n, v) in l.shared().params() {
            let _ = writeln!(t, "{n} = {v:?}");
        }
    }
    if !files.paths.is_empty() {
        let _ = writeln!(
            t,
            "\n[matrices]                        # matrix files (Matrix Market, DMIG, Abaqus, Harwell–Boeing), relative to this file"
        );
        for (k, p) in &files.paths {
            // A matrix chosen by name in a file of several keeps its name.
            match files
                .info
                .iter()
                .find(|i| &i.key == k && !i.name.is_empty())
            {
                Some(i) => {
                    let _ = writeln!(t, "{k} = {{ file = {p:?}, name = {:?} }}", i.name);
                }
                None => {
                    let _ = writeln!(t, "{k} = {p:?}");
                }
            }
        }
        for s in squeal_core::model::lumped::MATRIX_SCALE_KEYS {
            let key = format!("matrices.{s}");
            if let Some(v) = l
                .get(&key)
                .filter(|v| *v != 1.0 || l.shared().binding(&key).is_some())
            {
                let _ = writeln!(t, "{s} = {}", val(key, v));
            }
        }
    }
    let masses: Vec<(String, f64)> = l
        .keys()
        .into_iter()
        .filter_map(|(k, v)| k.strip_prefix("mass.").map(|d| (d.to_string(), v)))
        .collect();
    if !masses.is_empty() {
        let _ = writeln!(
            t,
            "\n[masses]                          # kg (kg·m² for a rotation)"
        );
        for (d, m) in masses {
            let _ = writeln!(t, "{d} = {}", val(format!("mass.{d}"), m));
        }
    }
    for s in &l.springs {
        let _ = writeln!(
            t,
            "\n[[spring]]\nname = {:?}\non = {}\nk = {}\nc = {}",
            s.name,
            combo(l, &s.on),
            val(format!("{}.k", s.name), s.k),
            val(format!("{}.c", s.name), s.c)
        );
    }
    for f in &l.forces {
        let _ = writeln!(
            t,
            "\n[[force]]\nname = {:?}\non = {}\nvalue = {}",
            f.name,
            combo(l, &f.on),
            val(format!("{}.value", f.name), f.value)
        );
        if f.ramp > 0.0 {
            let _ = writeln!(t, "ramp = {}", val(format!("{}.ramp", f.name), f.ramp));
        }
    }
    for c in &l.contacts {
        let _ = writeln!(t, "\n[[contact]]\nname = {:?}", c.name);
        match &c.normal {
            Normal::Elastic {
                normal,
                k,
                c: cc,
                bilateral,
            } => {
                let _ = writeln!(
                    t,
                    "normal = {}\nk = {}\nc = {}\ncontact = {:?}",
                    combo(l, normal),
                    val(format!("{}.k", c.name), *k),
                    val(format!("{}.c", c.name), *cc),
                    if *bilateral {
                        "bilateral"
                    } else {
                        "unilateral"
                    }
                );
            }
            Normal::Prescribed(f) => {
                let _ = writeln!(
                    t,
                    "normal_force = {}",
                    val(format!("{}.normal_force", c.name), *f)
                );
            }
        }
        let _ = writeln!(
            t,
            "tangent = {}\nV = {}\nfriction = {:?}",
            combo(l, &c.tangent),
            val(format!("{}.V", c.name), c.v),
            c.friction.name()
        );
        for p in c.friction.params() {
            let _ = writeln!(
                t,
                "{} = {}",
                p.name,
                val(
                    format!("{}.{}", c.name, p.name),
                    c.friction.get(p.name).unwrap_or(f64::NAN)
                )
            );
        }
        if c.alpha != 0.0 || !c.slope.is_empty() {
            let _ = writeln!(
                t,
                "alpha = {}\nslope = {}",
                val(format!("{}.alpha", c.name), c.alpha),
                combo(l, &c.slope)
            );
        }
    }
    t
}

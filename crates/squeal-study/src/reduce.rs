//! `squeal reduce`: a lumped (FE) model reduced by Craig–Bampton
//! ([`squeal_core::stability::craig_bampton`], docs/physics.md §5b″) and
//! written back as a scenario with Matrix Market files, which every command
//! (and any other tool) reads again.
//!
//! The boundary is every dof the scenario names outside its `dofs` list and
//! its matrices — the contacts' normal, tangent and slope terms, the forces,
//! springs and `[masses]`, the radiating surfaces, non-zero offsets — so
//! that each element of the scenario acts on the reduced model unchanged,
//! with its parameters and expressions. The interior keeps its
//! fixed-interface modes up to `modal.cutoff_hz` (or the `modal.modes`
//! lowest), the existing `[modal]` keys. The reduced matrices are those of
//! the files, before their scale factors: a scale multiplies the reduced
//! matrix exactly as it multiplied the full one (`T` depends on neither
//! scale), so `matrices.K_scale` and the other keys keep working.

use crate::error::{InputError, StudyError};
use crate::model::AnyModel;
use crate::scenario::Scenario;
use nalgebra::DMatrix;
use serde::Serialize;
use squeal_core::linear::Basis;
use squeal_core::model::lumped::Triplets;
use squeal_core::stability::craig_bampton::{craig_bampton, craig_bampton_sparse, CraigBampton};

/// The files `squeal reduce --out DIR` writes.
pub const FILES: [&str; 5] = ["scenario.toml", "M.mtx", "K.mtx", "C.mtx", "reduce.json"];

/// A reduced model, ready to write.
#[derive(Debug, Clone, Serialize)]
pub struct Reduction {
    /// The original scenario's name.
    pub source: String,
    /// The reduced scenario's name (`<source>-reduced`).
    pub name: String,
    /// Dofs of the original model (after static condensation).
    pub dofs: usize,
    /// The boundary dofs, kept physical (the original's order).
    pub boundary: Vec<String>,
    /// Names of the fixed-interface modal coordinates (`cb1`, `cb2`, …).
    pub generalised: Vec<String>,
    /// Fixed-interface modes the interior has in all.
    pub interior_modes: usize,
    /// The kept fixed-interface modes' frequencies (Hz), ascending.
    pub modes_hz: Vec<f64>,
    /// What chose them: `{"cutoff_hz": f}` or `{"modes": m}`.
    pub basis: serde_json::Value,
    /// Whether the constraint modes needed the 1 Hz shift (an interior
    /// part the boundary does not hold).
    pub shifted: bool,
    /// Reduced mass matrix (on `boundary ++ generalised`).
    #[serde(skip)]
    pub m: Triplets,
    /// Reduced stiffness matrix.
    #[serde(skip)]
    pub k: Triplets,
    /// Reduced damping matrix (`None` when the model has no `C` file).
    #[serde(skip)]
    pub c: Option<Triplets>,
    /// The reduced scenario's TOML (matrices `M.mtx`, `K.mtx`, `C.mtx`
    /// beside it).
    #[serde(skip)]
    pub toml: String,
}

impl Reduction {
    /// The dofs of the reduced model.
    pub fn reduced_dofs(&self) -> usize {
        self.boundary.len() + self.generalised.len()
    }

    /// One line for the terminal.
    pub fn line(&self) -> String {
        let top = self
            .modes_hz
            .last()
            .map_or("none".to_string(), |f| format!("the highest at {f:.1} Hz"));
        format!(
            "{}: {} dofs → {} (Craig–Bampton: {} boundary dofs kept physical + {} of the interior's {} fixed-interface modes, {top}){}",
            self.source,
            self.dofs,
            self.reduced_dofs(),
            self.boundary.len(),
            self.generalised.len(),
            self.interior_modes,
            if self.shifted {
                "; the interior is not held by the boundary: constraint modes with a 1 Hz shift"
            } else {
                ""
            }
        )
    }
}

fn triplets(a: &DMatrix<f64>) -> Triplets {
    let mut entries = Vec::new();
    for c in 0..a.ncols() {
        for r in 0..a.nrows() {
            if a[(r, c)] != 0.0 {
                entries.push((r, c, a[(r, c)]));
            }
        }
    }
    Triplets {
        rows: a.nrows(),
        cols: a.ncols(),
        entries,
    }
}

/// Every key and string anywhere in `v` that names a dof.
fn named_dofs(v: &toml::Value, is_dof: &dyn Fn(&str) -> bool, out: &mut Vec<String>) {
    match v {
        toml::Value::String(s) if is_dof(s) => out.push(s.clone()),
        toml::Value::Array(a) => a.iter().for_each(|x| named_dofs(x, is_dof, out)),
        toml::Value::Table(t) => {
            for (k, x) in t {
                if is_dof(k) {
                    out.push(k.clone());
                }
                named_dofs(x, is_dof, out);
            }
        }
        _ => {}
    }
}

/// Reduce a lumped scenario (see the module docs).
pub fn reduce(sc: &Scenario) -> Result<Reduction, StudyError> {
    let AnyModel::Lumped(l) = &sc.model else {
        return Err(InputError(format!(
            "reduce: scenario '{}' is the built-in model '{}'; only a lumped model with [matrices] can be reduced",
            sc.name,
            sc.model.name()
        ))
        .into());
    };
    let [m, k, c] = l.file_matrices();
    let (Some(m), Some(k)) = (m, k) else {
        return Err(InputError(format!(
            "reduce: scenario '{}' has no M and K matrix files ([matrices]); a model of elements only has nothing to reduce",
            sc.name
        ))
        .into());
    };
    let names = l.dofs();
    let index = |s: &str| names.iter().position(|d| d == s);
    // The scenario as `scenario show` writes it: the dofs it names.
    let text = sc.to_toml();
    let mut table: toml::Table = toml::from_str(&text)
        .map_err(|e| StudyError::Numerical(format!("reduce: the scenario's TOML: {e}")))?;
    let mut named = Vec::new();
    let is_dof = |s: &str| index(s).is_some();
    for (key, v) in &table {
        if !matches!(key.as_str(), "dofs" | "matrices" | "offsets") {
            named_dofs(v, &is_dof, &mut named);
        }
    }
    // Non-zero offsets (positions by dof name, velocities by state name).
    let n = names.len();
    let states = l.state_names();
    for (i, v) in sc.offsets.iter().enumerate() {
        if *v != 0.0 {
            named.push(names[i % n].clone());
        }
    }
    let mut is_b = vec![false; n];
    for d in &named {
        if let Some(i) = index(d) {
            is_b[i] = true;
        }
    }
    let boundary: Vec<usize> = (0..n).filter(|&i| is_b[i]).collect();
    if boundary.is_empty() {
        return Err(InputError(format!(
            "reduce: scenario '{}' names no dof outside its matrices (no contact, force, spring or mass): nothing would stay physical",
            sc.name
        ))
        .into());
    }
    let basis = if l.modal.modes > 0 {
        Basis::Modes(l.modal.modes)
    } else {
        Basis::CutoffHz(l.modal.cutoff_hz)
    };
    // Dense up to SPARSE_FROM_DOFS dofs (every interior mode, so the
    // truncation is visible); sparse above (only the modes kept).
    let sparse = n > squeal_core::linear::SPARSE_FROM_DOFS;
    let cb: CraigBampton = if sparse {
        craig_bampton_sparse(m.to_faer().as_ref(), k.to_faer().as_ref(), &boundary, basis)
    } else {
        craig_bampton(&m.to_dense(), &k.to_dense(), &boundary, basis)
    }
    .map_err(|e| InputError(format!("reduce: {e}")))?;
    let reduced = |a: &squeal_core::model::lumped::Sparse| {
        let r = if sparse {
            cb.project_sparse(a.to_faer().as_ref())
        } else {
            cb.project(&a.to_dense())
        };
        // Exactly symmetric when A is (the product's round-off would
        // otherwise make a symmetric mass matrix unreadable as one).
        if a.is_symmetric() {
            (&r + r.transpose()) * 0.5
        } else {
            r
        }
    };
    let nm = cb.omega2.len();
    // Modal coordinates named cb1, cb2, …, never a name the model has.
    let mut prefix = "cb".to_string();
    while (1..=nm).any(|j| is_dof(&format!("{prefix}{j}"))) {
        prefix.insert(0, '_');
    }
    let generalised: Vec<String> = (1..=nm).map(|j| format!("{prefix}{j}")).collect();
    let boundary_names: Vec<String> = boundary.iter().map(|&i| names[i].clone()).collect();
    let mut new_dofs = boundary_names.clone();
    new_dofs.extend(generalised.iter().cloned());
    let modes_hz: Vec<f64> = cb
        .omega2
        .iter()
        .map(|w2| w2.max(0.0).sqrt() / std::f64::consts::TAU)
        .collect();
    // The scenario, rewritten.
    let name = format!("{}-reduced", sc.name);
    let top = modes_hz
        .last()
        .map_or("no modes".to_string(), |f| format!("modes to {f:.0} Hz"));
    table.insert("name".into(), toml::Value::String(name.clone()));
    table.insert(
        "description".into(),
        toml::Value::String(format!(
            "Craig–Bampton reduction of '{}' ({n} dofs → {} boundary dofs + {nm} fixed-interface {top}). {}",
            sc.name,
            boundary.len(),
            sc.description
        )),
    );
    table.insert(
        "dofs".into(),
        toml::Value::Array(new_dofs.iter().cloned().map(toml::Value::String).collect()),
    );
    if let Some(toml::Value::Table(mt)) = table.get_mut("matrices") {
        mt.insert("M".into(), toml::Value::String("M.mtx".into()));
        mt.insert("K".into(), toml::Value::String("K.mtx".into()));
        if c.is_some() {
            mt.insert("C".into(), toml::Value::String("C.mtx".into()));
        } else {
            mt.remove("C");
            mt.remove("C_scale");
        }
    }
    if let Some(toml::Value::Table(off)) = table.get_mut("offsets") {
        let keep: Vec<&String> = boundary
            .iter()
            .flat_map(|&i| [&states[i], &states[n + i]])
            .collect();
        off.retain(|key, _| keep.iter().any(|s| s.as_str() == key));
    }
    let basis_json = match basis {
        Basis::Modes(m) => serde_json::json!({ "modes": m }),
        Basis::CutoffHz(f) => serde_json::json!({ "cutoff_hz": f }),
    };
    let body = toml::to_string(&table)
        .map_err(|e| StudyError::Numerical(format!("reduce: writing TOML: {e}")))?;
    let toml = format!(
        "# Written by `squeal reduce` from scenario '{}': a Craig–Bampton reduction\n\
         # ({n} dofs → {} boundary dofs kept physical + {nm} fixed-interface modes;\n\
         # docs/physics.md §5b″). M.mtx, K.mtx, C.mtx beside this file are the\n\
         # reduced matrices of the model's files, before their scale factors.\n\n{body}",
        sc.name,
        boundary.len()
    );
    Ok(Reduction {
        source: sc.name.clone(),
        name,
        dofs: n,
        boundary: boundary_names,
        generalised,
        interior_modes: cb.interior_modes,
        modes_hz,
        basis: basis_json,
        shifted: cb.shifted,
        m: triplets(&reduced(m)),
        k: triplets(&reduced(k)),
        c: c.map(|c| triplets(&reduced(c))),
        toml,
    })
}

//! `squeal inspect SCENARIO`: what was read — each matrix's format, file,
//! size, nonzeros and symmetry, the dofs, the lowest natural frequencies
//! without friction, and each contact with its dofs — before any analysis
//! is trusted.

use crate::lumped_file::MatrixFiles;
use crate::matrix_file::{ends, MatrixInfo};
use crate::model::AnyModel;
use crate::scenario::Scenario;
use serde::Serialize;
use squeal_core::model::contact::{Combination, Normal};
use squeal_core::stability::projected::{undamped_basis, Basis};
use squeal_core::{FrictionLaw, Lumped};

/// How many natural frequencies are reported.
pub const FREQUENCIES: usize = 12;

/// Above this many dofs the natural frequencies are not computed (the
/// dense symmetric eigen-solve would take minutes).
pub const MAX_FREQUENCY_DOFS: usize = 4000;

/// One contact as read.
#[derive(Debug, Clone, Serialize)]
pub struct ContactInfo {
    /// Name.
    pub name: String,
    /// `unilateral`, `bilateral` or `prescribed`.
    pub kind: String,
    /// Layer stiffness (N/m), or the prescribed load (N).
    pub stiffness_or_load: f64,
    /// The compression's dofs and coefficients.
    pub normal: Vec<(String, f64)>,
    /// The sliding velocity's dofs and coefficients.
    pub tangent: Vec<(String, f64)>,
    /// Surface speed (m/s).
    pub v: f64,
    /// Friction law.
    pub friction: String,
}

/// What `inspect` reports.
#[derive(Debug, Clone, Serialize)]
pub struct Inspection {
    /// Scenario name.
    pub name: String,
    /// Model name (`lumped`, or a built-in's).
    pub model: String,
    /// Number of dofs.
    pub dof_count: usize,
    /// The dofs in state order.
    pub dofs: Vec<String>,
    /// Each matrix read.
    pub matrices: Vec<MatrixInfo>,
    /// Dofs given a mass by `[masses]`.
    pub masses: usize,
    /// Dofs without mass, condensed statically (not among `dofs`).
    pub condensed: Vec<String>,
    /// Springs, forces.
    pub springs: usize,
    /// Forces.
    pub forces: usize,
    /// Shared parameters `(name, value)`.
    pub params: Vec<(String, f64)>,
    /// The lowest natural frequencies (Hz) of the structure with its
    /// closed contacts' stiffness and no friction (`None`: not computed,
    /// see `frequencies_note`).
    pub natural_frequencies_hz: Option<Vec<f64>>,
    /// Why the frequencies are missing, or how they were computed.
    pub frequencies_note: String,
    /// The contacts.
    pub contacts: Vec<ContactInfo>,
}

fn terms(l: &Lumped, c: &Combination) -> Vec<(String, f64)> {
    c.idx
        .iter()
        .zip(&c.coef)
        .map(|(i, v)| (l.dofs()[*i].clone(), *v))
        .collect()
}

/// The natural frequencies without friction: every contact's law set to
/// zero friction, steady sliding (the closed contacts' stiffness), then
/// the undamped modes of `M` and the symmetric stiffness.
fn natural_frequencies(l: &Lumped) -> Result<Vec<f64>, String> {
    let free = frictionless(l).map_err(|e| e.to_string())?;
    let z = free.equilibrium_dyn().map_err(|e| e.to_string())?;
    let sys = free.second_order_dyn(&z);
    let b = undamped_basis(&sys, Basis::Modes(FREQUENCIES)).map_err(|e| e.to_string())?;
    Ok(b.omega2
        .iter()
        .map(|w2| w2.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect())
}

/// The model with every contact's friction law set to zero friction (the
/// structure with its contacts' normal stiffness only): its undamped modes
/// are the brake's real modes, as an FE package's normal-modes run gives
/// them.
pub fn frictionless(l: &Lumped) -> Result<Lumped, squeal_core::ParamError> {
    let mut free = l.clone();
    for c in &l.contacts {
        free.set_friction_law(
            &c.name,
            FrictionLaw::Coulomb {
                mu_s: 0.0,
                mu_k: 0.0,
            },
        )?;
    }
    Ok(free)
}

/// Inspect a scenario's model.
pub fn inspect(s: &Scenario) -> Inspection {
    let files: &MatrixFiles = &s.matrices;
    match &s.model {
        AnyModel::Lumped(l) => {
            let n = l.dof_count();
            let (freqs, note) = if n > MAX_FREQUENCY_DOFS {
                (
                    None,
                    format!("not computed: {n} dofs, more than the {MAX_FREQUENCY_DOFS} of the dense eigen-solver"),
                )
            } else {
                match natural_frequencies(l) {
                    Ok(f) => (
                        Some(f),
                        "the structure with its closed contacts' stiffness, no friction (undamped modes of M and the symmetric stiffness)".into(),
                    ),
                    Err(e) => (None, format!("not computed: {e}")),
                }
            };
            let contacts = l
                .contacts
                .iter()
                .map(|c| {
                    let (kind, k, normal) = match &c.normal {
                        Normal::Elastic {
                            normal,
                            k,
                            bilateral,
                            ..
                        } => (
                            if *bilateral {
                                "bilateral"
                            } else {
                                "unilateral"
                            },
                            *k,
                            terms(l, normal),
                        ),
                        Normal::Prescribed(f) => ("prescribed", *f, Vec::new()),
                    };
                    ContactInfo {
                        name: c.name.clone(),
                        kind: kind.into(),
                        stiffness_or_load: k,
                        normal,
                        tangent: terms(l, &c.tangent),
                        v: c.v,
                        friction: c.friction.name().into(),
                    }
                })
                .collect();
            Inspection {
                name: s.name.clone(),
                model: "lumped".into(),
                dof_count: n,
                dofs: l.dofs().to_vec(),
                matrices: files.info.clone(),
                masses: l
                    .keys()
                    .iter()
                    .filter(|(k, _)| k.starts_with("mass."))
                    .count(),
                condensed: files.condensed.clone(),
                springs: l.springs.len(),
                forces: l.forces.len(),
                params: l
                    .shared()
                    .params()
                    .map(|(k, v)| (k.to_string(), v))
                    .collect(),
                natural_frequencies_hz: freqs,
                frequencies_note: note,
                contacts,
            }
        }
        other => Inspection {
            name: s.name.clone(),
            model: other.name().to_string(),
            dof_count: other.state_names().len() / 2,
            dofs: other
                .state_names()
                .iter()
                .take(other.state_names().len() / 2)
                .map(|x| x.to_string())
                .collect(),
            matrices: Vec::new(),
            masses: 0,
            condensed: Vec::new(),
            springs: 0,
            forces: 0,
            params: Vec::new(),
            natural_frequencies_hz: None,
            frequencies_note: "a built-in model: see docs/physics.md for its modes".into(),
            contacts: Vec::new(),
        },
    }
}

fn combo(t: &[(String, f64)]) -> String {
    let parts: Vec<String> = t.iter().map(|(d, c)| format!("{d} = {c}")).collect();
    format!("{{ {} }}", parts.join(", "))
}

impl Inspection {
    /// The report as text for a terminal.
    pub fn to_text(&self) -> String {
        use std::fmt::Write as _;
        let mut t = String::new();
        let _ = writeln!(
            t,
            "{} ({}): {} dofs, {} contacts",
            self.name,
            self.model,
            self.dof_count,
            self.contacts.len()
        );
        if !self.matrices.is_empty() {
            let _ = writeln!(t, "matrices:");
            for m in &self.matrices {
                let name = if m.name.is_empty() {
                    String::new()
                } else {
                    format!(" {}", m.name)
                };
                let _ = writeln!(
                    t,
                    "  {} = {}{}: {}, {}×{}, {} nonzeros, {}{}",
                    m.key,
                    m.file,
                    name,
                    m.format,
                    m.size,
                    m.size,
                    m.nonzeros,
                    if m.symmetric {
                        "symmetric"
                    } else {
                        "unsymmetric"
                    },
                    m.mapping
                        .as_ref()
                        .map_or(String::new(), |p| format!(" (dof labels from {p})"))
                );
            }
        }
        let _ = writeln!(t, "dofs: {}", ends(&self.dofs));
        if !self.condensed.is_empty() {
            let _ = writeln!(
                t,
                "condensed statically: {} dofs without mass ({})",
                self.condensed.len(),
                ends(&self.condensed)
            );
        }
        if self.model == "lumped" {
            let _ = writeln!(
                t,
                "elements: {} masses, {} springs, {} forces",
                self.masses, self.springs, self.forces
            );
        }
        if !self.params.is_empty() {
            let p: Vec<String> = self
                .params
                .iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect();
            let _ = writeln!(t, "params: {}", p.join(", "));
        }
        match &self.natural_frequencies_hz {
            Some(f) => {
                let f: Vec<String> = f.iter().map(|x| format!("{x:.2}")).collect();
                let _ = writeln!(
                    t,
                    "lowest natural frequencies without friction (Hz): {}",
                    f.join(", ")
                );
            }
            None => {
                let _ = writeln!(t, "natural frequencies: {}", self.frequencies_note);
            }
        }
        for c in &self.contacts {
            let normal = if c.kind == "prescribed" {
                format!("load {} N", c.stiffness_or_load)
            } else {
                format!(
                    "k = {} N/m, normal {}",
                    c.stiffness_or_load,
                    combo(&c.normal)
                )
            };
            let _ = writeln!(
                t,
                "contact '{}': {}, {normal}, tangent {}, V = {} m/s, friction {}",
                c.name,
                c.kind,
                combo(&c.tangent),
                c.v,
                c.friction
            );
        }
        t
    }
}

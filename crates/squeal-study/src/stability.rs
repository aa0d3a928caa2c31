//! Eigen-analysis of steady sliding: every eigenvalue, each mode's growth
//! rate, frequency, damping ratio, dominant coordinate and complex mode shape,
//! the verdict (MODEL.md §5), its JSON document, and the levers — the
//! one-parameter changes that flip the verdict.

pub use crate::levers::{Lever, Levers};
use crate::model::AnyModel;
use serde_json::{json, Value};
use squeal_core::stability::{Analysis, StabilityError};

/// How mode shapes are normalised (stated in the JSON and the README).
pub const SHAPE_NORMALISATION: &str = "position part of the eigenvector divided by its largest component: that dof has amplitude 1 and phase 0, every amplitude is in [0, 1], phases in degrees in (-180, 180]";

/// Amplitude and phase (degrees) of every position dof of a mode.
pub fn shape_of(e: &squeal_core::stability::Eigen) -> Vec<(f64, f64)> {
    use squeal_core::stability::modal::{amplitude_phase, mode_shape};
    amplitude_phase(&mode_shape(e))
}

/// Full analysis of any model, with mass-weighted mode attribution.
pub fn analyse(model: &AnyModel) -> Result<Analysis, StabilityError> {
    model.analyse()
}

/// The real modes each growing mode of a lumped model is made of
/// (issue 26 §5): per growing eigenvalue (`+ω` of its pair), its index in
/// `an.eigen`, its `Composition` over the undamped modes of `M` and the
/// stiffness at steady sliding without friction (the real modes `squeal
/// inspect` lists; every mode up to
/// `modal.dense_max_dofs` dofs, the projection basis above), and the
/// contact dofs where it moves most (amplitude relative to its largest).
pub fn coupled_modes(model: &AnyModel, an: &Analysis) -> Vec<CoupledMode> {
    use squeal_core::model::contact::Normal;
    use squeal_core::stability::projected::{undamped_basis, Basis};
    let AnyModel::Lumped(l) = model else {
        return Vec::new();
    };
    let n = l.dof_count();
    let growing: Vec<usize> = (0..an.eigen.len())
        .filter(|&i| an.eigen[i].growing && an.eigen[i].im >= 0.0)
        .collect();
    if growing.is_empty() {
        return Vec::new();
    }
    let sys = l.second_order_dyn(&an.equilibrium);
    // The real modes: the structure at steady sliding (its closed contacts'
    // normal stiffness) without friction, whose symmetric half can make
    // the stiffness indefinite when μ·k_contact exceeds the structure's
    // stiffness (and then yields no modes at all).
    let Ok(free) = crate::inspect::frictionless(l) else {
        return Vec::new();
    };
    let free_sys = free.second_order_dyn(&an.equilibrium);
    let basis = if l.modal.projects(n) {
        l.modal.basis()
    } else {
        Basis::Modes(n)
    };
    let Ok(basis) = undamped_basis(&free_sys, basis) else {
        return Vec::new();
    };
    let mut contact_dofs: Vec<usize> = Vec::new();
    for c in &l.contacts {
        if let Normal::Elastic { normal, .. } = &c.normal {
            contact_dofs.extend(&normal.idx);
        }
        contact_dofs.extend(&c.tangent.idx);
    }
    contact_dofs.sort_unstable();
    contact_dofs.dedup();
    growing
        .into_iter()
        .map(|i| {
            let e = &an.eigen[i];
            let q = &e.vector[..n];
            let top = q.iter().fold(0.0f64, |m, v| m.max(v.norm()));
            let mut at: Vec<(String, f64)> = contact_dofs
                .iter()
                .map(|&d| {
                    (
                        l.dofs()[d].clone(),
                        if top > 0.0 { q[d].norm() / top } else { 0.0 },
                    )
                })
                .collect();
            at.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            at.truncate(3);
            CoupledMode {
                eigenvalue: i,
                composition: squeal_core::stability::coupling::composition(
                    &sys.m, &basis, q, 0.01, 5,
                ),
                contact_dofs: at,
            }
        })
        .collect()
}

/// A growing mode and the real modes it is made of ([`coupled_modes`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CoupledMode {
    /// Index in [`Analysis::eigen`].
    pub eigenvalue: usize,
    /// Its real modes and their shares (those ≥ 1 %, at most 5).
    pub composition: squeal_core::stability::coupling::Composition,
    /// The contact dofs where it moves most, amplitude relative to its
    /// largest (at most 3).
    pub contact_dofs: Vec<(String, f64)>,
}

/// The JSON of [`coupled_modes`].
pub fn coupled_json(an: &Analysis, c: &[CoupledMode]) -> Value {
    json!(c
        .iter()
        .map(|m| {
            let e = &an.eigen[m.eigenvalue];
            json!({
                "eigenvalue": m.eigenvalue + 1,
                "freq_hz": e.freq_hz,
                "growth_rate": e.re,
                "real_modes": m.composition.shares,
                "captured": m.composition.captured,
                "contact_dofs": m.contact_dofs.iter().map(|(d, a)| json!({ "dof": d, "amplitude": a })).collect::<Vec<_>>(),
            })
        })
        .collect::<Vec<_>>())
}

/// The JSON document of an analysis.
pub fn analysis_json(model: &AnyModel, an: &Analysis) -> Value {
    let names = model.state_names();
    let eig: Vec<Value> = an
        .eigen
        .iter()
        .map(|e| {
            let shape: Vec<Value> = shape_of(e)
                .into_iter()
                .enumerate()
                .map(|(i, (a, p))| json!({ "dof": names.get(i).map_or("", String::as_str), "amplitude": a, "phase_deg": p }))
                .collect();
            json!({
                "re": e.re, "im": e.im, "freq_hz": e.freq_hz,
                "damping_ratio": e.damping_ratio, "dominant": e.dominant_name, "growing": e.growing,
                "neutral": e.neutral,
                "shape": shape,
            })
        })
        .collect();
    let eq: serde_json::Map<String, Value> = names
        .iter()
        .zip(&an.equilibrium)
        .map(|(n, v)| (n.to_string(), json!(v)))
        .collect();
    let ls = an.least_stable_mode();
    json!({
        "eigenvalues": eig,
        "max_growth_rate": an.max_growth_rate,
        "stable": an.stable,
        "neutral": an.neutral,
        "verdict": verdict_word(an),
        "least_stable": { "re": ls.re, "im": ls.im, "freq_hz": ls.freq_hz, "dominant": ls.dominant_name },
        "equilibrium": eq,
        "shape_normalisation": SHAPE_NORMALISATION,
        "modal": modal_json(an),
        "coupled_modes": coupled_json(an, &coupled_modes(model, an)),
    })
}

/// Whether levers are searched for this model: every model since issue 26
/// (kept for callers that asked; see [`crate::levers`]).
pub fn searches_levers(_model: &AnyModel) -> bool {
    true
}

/// Every lever of `model` ([`crate::levers::search`]), without progress
/// display or cancellation.
pub fn levers_if_searched(model: &AnyModel) -> Result<Levers, crate::StudyError> {
    crate::levers::search(model, &crate::NoProgress, &crate::Cancel::new())
}

/// The whole document of `squeal stability --json` (and of Python's
/// `Stability.to_dict()`): [`analysis_json`] plus the scenario and what
/// [`Levers::to_json`] holds (`levers`, `sensitivities`, `mode_moves`, …).
pub fn document(sc: &crate::Scenario, an: &Analysis, levers: &Levers) -> Value {
    let mut doc = analysis_json(&sc.model, an);
    doc["scenario"] = sc.to_json();
    if let (Value::Object(d), Value::Object(l)) = (&mut doc, levers.to_json()) {
        d.extend(l);
    }
    doc
}

/// How a study of `model` (a critical value, a map: one eigen-analysis per
/// point) computes its eigenvalues: `{"method": "dense"}`, or for a lumped
/// model above `modal.dense_max_dofs` `{"method": "projected",
/// "dense_max_dofs": …, "modes": …, "cutoff_hz": …}` (the basis is rebuilt
/// at every point).
pub fn modal_options_json(model: &AnyModel) -> Value {
    match model {
        AnyModel::Lumped(l) if l.modal.projects(l.dof_count()) => json!({
            "method": "projected",
            "dense_max_dofs": l.modal.dense_max_dofs,
            "modes": l.modal.modes,
            "cutoff_hz": l.modal.cutoff_hz,
        }),
        _ => json!({ "method": "dense" }),
    }
}

/// How the eigenvalues were computed: `{"method": "dense"}` or
/// `{"method": "projected", "modes": m, "dofs": n, "basis_max_hz": f}`
/// (a reduced-basis answer for the modes in that band).
pub fn modal_json(an: &Analysis) -> Value {
    serde_json::to_value(an.method).unwrap_or(Value::Null)
}

/// `stable` (every σ < 0 beyond round-off), `neutral` (no mode grows, some
/// mode has σ = 0 within round-off) or `unstable`.
pub fn verdict_word(an: &Analysis) -> &'static str {
    if an.stable {
        "stable"
    } else if an.neutral {
        "neutral"
    } else {
        "unstable"
    }
}

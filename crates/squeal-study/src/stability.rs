//! Eigen-analysis of steady sliding: every eigenvalue, each mode's growth
//! rate, frequency, damping ratio, dominant coordinate and complex mode shape,
//! the verdict (MODEL.md §5), its JSON document, and the levers — the
//! one-parameter changes that flip the verdict.

use crate::model::AnyModel;
use serde_json::{json, Value};
use squeal_core::stability::{self, Analysis, CriticalOptions, StabilityError};

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
/// symmetric stiffness at steady sliding (every mode up to
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
    let basis = if l.modal.projects(n) {
        l.modal.basis()
    } else {
        Basis::Modes(n)
    };
    let Ok(basis) = undamped_basis(&sys, basis) else {
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

/// Whether [`levers`] are searched for this model: they need hundreds of
/// analyses, so only models of the fixed-size path (every built-in, lumped
/// models up to `MAX_EXACT_DOFS` dofs) get them.
pub fn searches_levers(model: &AnyModel) -> bool {
    !matches!(model, AnyModel::Lumped(l)
        if l.dof_count() > squeal_core::model::lumped::MAX_EXACT_DOFS)
}

/// The levers of `model` when [`searches_levers`] says so, none otherwise.
pub fn levers_if_searched(model: &AnyModel) -> Vec<Lever> {
    if searches_levers(model) {
        levers(model)
    } else {
        Vec::new()
    }
}

/// The whole document of `squeal stability --json` (and of Python's
/// `Stability.to_dict()`): [`analysis_json`] plus the scenario and the levers.
pub fn document(sc: &crate::Scenario, an: &Analysis, levers: &[Lever]) -> Value {
    let mut doc = analysis_json(&sc.model, an);
    doc["scenario"] = sc.to_json();
    doc["levers"] = json!(levers
        .iter()
        .map(|l| json!({ "param": l.param, "from": l.from, "to": l.to, "freq_hz": l.freq_hz }))
        .collect::<Vec<_>>());
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

/// One parameter change that alone flips the verdict (all else as is).
#[derive(Debug, Clone, PartialEq)]
pub struct Lever {
    /// Parameter name.
    pub param: String,
    /// Its unit.
    pub unit: &'static str,
    /// Its current value.
    pub from: f64,
    /// The value where the verdict flips.
    pub to: f64,
    /// Frequency (Hz) of the mode that crosses there.
    pub freq_hz: f64,
}

/// "What would stop it" (or, for a quiet brake, what would start it): for
/// every parameter, the nearest value above and below the current one where
/// the stability of steady sliding changes, searched over ×1000 either way
/// (±1e5 for a signed parameter) by [`stability::critical`].
pub fn levers(model: &AnyModel) -> Vec<Lever> {
    use squeal_core::params::ParamKind;
    let mut out = Vec::new();
    for (name, unit, _, kind) in model.keys() {
        if name == "t_ramp" || name.ends_with(".ramp") {
            continue; // a start-up setting, no part of steady sliding
        }
        let Some(cur) = model.get(&name) else {
            continue;
        };
        let (lo, hi) = match kind {
            ParamKind::Positive => (cur / 1000.0, cur * 1000.0),
            ParamKind::NonNegative => (0.0, if cur > 0.0 { cur * 1000.0 } else { 1000.0 }),
            ParamKind::Any => (
                cur - 1e5 * cur.abs().max(1.0),
                cur + 1e5 * cur.abs().max(1.0),
            ),
        };
        for (a, b) in [(cur, hi), (cur, lo)] {
            if (b - a).abs() <= 1e-12 * a.abs().max(1e-300) {
                continue;
            }
            // Search outwards from the current value: s ∈ [0, 1] maps to a + s (b − a).
            let f = |s: f64| crate::critical::growth_at(model, &name, a + s * (b - a));
            let opts = CriticalOptions {
                grid: 48,
                ..CriticalOptions::default()
            };
            if let Ok(Some(c)) = stability::critical(f, 0.0, 1.0, &opts) {
                let rough = a + c.value * (b - a);
                // The scan's root is exact in s, i.e. to 1e-10·|b − a| in the
                // parameter; refine it on the parameter itself, with the same
                // Brent iteration and tolerance as `critical`, so a lever and
                // `squeal critical` give the same boundary.
                let (to, freq_hz) = refine(model, &name, rough, (b - a).abs(), (a, b))
                    .unwrap_or((rough, c.freq_hz));
                out.push(Lever {
                    param: name.clone(),
                    unit,
                    from: cur,
                    to,
                    freq_hz,
                });
            }
        }
    }
    out
}

/// The crossing near `rough` located on the parameter itself: a bracket of
/// ±1e-9·`span` around it (inside the searched segment `seg`), then
/// [`stability::critical`] with its default 1e-10 relative tolerance.
fn refine(
    model: &AnyModel,
    name: &str,
    rough: f64,
    span: f64,
    seg: (f64, f64),
) -> Option<(f64, f64)> {
    let (lo_seg, hi_seg) = (seg.0.min(seg.1), seg.0.max(seg.1));
    let d = 1e-9 * span + 4.0 * f64::EPSILON * rough.abs();
    let (lo, hi) = ((rough - d).max(lo_seg), (rough + d).min(hi_seg));
    if lo >= hi {
        return None;
    }
    let opts = CriticalOptions {
        grid: 2,
        ..CriticalOptions::default()
    };
    let f = |p: f64| crate::critical::growth_at(model, name, p);
    match stability::critical(f, lo, hi, &opts) {
        Ok(Some(c)) => Some((c.value, c.freq_hz)),
        _ => None,
    }
}

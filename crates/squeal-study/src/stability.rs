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

/// The JSON lists every mode's shape when dofs × modes is at most this
/// (a few MB of JSON); above, only the growing modes' and the least stable
/// one's (`"shapes": "growing and least stable"`; the others' `shape` is
/// empty): a 10⁵-dof brake's hundreds of modes would be gigabytes.
pub const SHAPE_ENTRIES_MAX: usize = 200_000;

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
    use nalgebra::Complex;
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
    // The real modes: the structure at steady sliding (its closed contacts'
    // normal stiffness) without friction, whose symmetric half can make
    // the stiffness indefinite when μ·k_contact exceeds the structure's
    // stiffness (and then yields no modes at all).
    let Ok(free) = crate::inspect::frictionless(l) else {
        return Vec::new();
    };
    let basis = if l.modal.projects(n) {
        l.modal.basis()
    } else {
        Basis::Modes(n)
    };
    // `M q` of a mode shape, and the real modes.
    type MassTimes = Box<dyn Fn(&[Complex<f64>]) -> Vec<Complex<f64>>>;
    let (mass_times, basis): (MassTimes, _) = if squeal_core::stability::lumped::sparse(l) {
        use squeal_core::stability::projected::Structure;
        let sys = free.second_order_sparse(&an.equilibrium);
        let Ok(b) = sys.undamped(basis) else {
            return Vec::new();
        };
        let m = sys.m;
        let times = move |q: &[Complex<f64>]| {
            let x = faer::Mat::<f64>::from_fn(
                q.len(),
                2,
                |i, j| if j == 0 { q[i].re } else { q[i].im },
            );
            let y = squeal_core::stability::lanczos::sparse_mul(m.as_ref(), x.as_ref());
            (0..q.len())
                .map(|i| Complex::new(y[(i, 0)], y[(i, 1)]))
                .collect()
        };
        (Box::new(times), b)
    } else {
        let sys = free.second_order_dyn(&an.equilibrium);
        let Ok(b) = undamped_basis(&sys, basis) else {
            return Vec::new();
        };
        let m = sys.m;
        let times = move |q: &[Complex<f64>]| {
            let n = q.len();
            (0..n)
                .map(|i| (0..n).fold(Complex::new(0.0, 0.0), |s, j| s + q[j] * m[(i, j)]))
                .collect()
        };
        (Box::new(times), b)
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
                    &mass_times(q),
                    &basis,
                    q,
                    0.01,
                    5,
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
    let dofs = names.len() / 2;
    let all_shapes = dofs * an.eigen.len() <= SHAPE_ENTRIES_MAX;
    let eig: Vec<Value> = an
        .eigen
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let with_shape = all_shapes || e.growing || i == an.least_stable;
            let shape: Vec<Value> = shape_of(e)
                .into_iter()
                .enumerate()
                .take(if with_shape { usize::MAX } else { 0 })
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
        "shapes": if all_shapes { "all" } else { "growing and least stable" },
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
/// "dense_max_dofs": …, "modes": …, "cutoff_hz": …, "basis": …}` (the basis is rebuilt
/// at every point).
pub fn modal_options_json(model: &AnyModel) -> Value {
    match model {
        AnyModel::Lumped(l) if l.modal.projects(l.dof_count()) => json!({
            "method": "projected",
            "dense_max_dofs": l.modal.dense_max_dofs,
            "modes": l.modal.modes,
            "cutoff_hz": l.modal.cutoff_hz,
            "basis": l.modal.kind.as_str(),
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

/// Two bases agree when the tracked eigenvalues differ by at most this
/// fraction of their modulus (issue 27 §2: "below 1e-3 relative").
pub const SETTLED: f64 = 1e-3;

/// How a projected analysis's eigenvalues move as its basis grows
/// ([`squeal_core::stability::projected::truncation_table`]): the
/// truncation error made visible.
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    /// The rows, smallest basis first (the last is the analysis's own).
    pub rows: Vec<squeal_core::stability::projected::Truncation>,
    /// The eigenvalues followed: every growing one of the analysis (`ω ≥ 0`),
    /// or the least stable one when none grows.
    pub tracked: Vec<nalgebra::Complex<f64>>,
    /// Per row, the eigenvalue nearest to each tracked one.
    pub matched: Vec<Vec<nalgebra::Complex<f64>>>,
    /// Per tracked eigenvalue, `|λ_last − λ_previous| / |λ_last|` between
    /// the last two rows (0 with one row).
    pub change: Vec<f64>,
    /// Every change is at most [`SETTLED`] and no tracked growth rate
    /// changes sign between the last two rows.
    pub settled: bool,
}

/// The truncation table of a model analysed by projection, following the
/// eigenvalues of `an` (its analysis); `None` for a model solved dense.
pub fn convergence(model: &AnyModel, an: &Analysis) -> Option<Result<Convergence, StabilityError>> {
    let AnyModel::Lumped(l) = model else {
        return None;
    };
    if !l.modal.projects(l.dof_count()) {
        return None;
    }
    // At the analysis's own steady sliding (not found again).
    Some(
        squeal_core::stability::lumped::truncation_table_at(l, &an.equilibrium)
            .map(|rows| convergence_of(rows, an)),
    )
}

/// The analysis of `model` ([`analyse`]) with its [`convergence`], the
/// modes and static responses computed once for both (a model analysed by
/// projection; others as [`analyse`], with `None`).
#[allow(clippy::type_complexity)]
pub fn analyse_with_convergence(
    model: &AnyModel,
) -> Result<(Analysis, Option<Result<Convergence, StabilityError>>), StabilityError> {
    match model {
        AnyModel::Lumped(l) if l.modal.projects(l.dof_count()) => {
            let (an, table) =
                squeal_core::stability::lumped::analyse_with_table(l, Some(&l.diagonal_masses()))?;
            let conv = table.map(|t| t.map(|rows| convergence_of(rows, &an)));
            Ok((an, conv))
        }
        _ => Ok((analyse(model)?, None)),
    }
}

/// The [`Convergence`] of the truncation-table `rows`, following the
/// eigenvalues of `an`.
fn convergence_of(
    rows: Vec<squeal_core::stability::projected::Truncation>,
    an: &Analysis,
) -> Convergence {
    let mut tracked: Vec<nalgebra::Complex<f64>> = an
        .eigen
        .iter()
        .filter(|e| e.growing && e.im >= 0.0)
        .map(|e| nalgebra::Complex::new(e.re, e.im))
        .collect();
    if tracked.is_empty() {
        let e = an.least_stable_mode();
        tracked.push(nalgebra::Complex::new(e.re, e.im.abs()));
    }
    let matched: Vec<Vec<nalgebra::Complex<f64>>> = rows
        .iter()
        .map(|r| {
            tracked
                .iter()
                .map(|t| {
                    r.eigenvalues
                        .iter()
                        .copied()
                        .min_by(|a, b| (a - t).norm().total_cmp(&(b - t).norm()))
                        .unwrap_or(nalgebra::Complex::new(f64::NAN, f64::NAN))
                })
                .collect()
        })
        .collect();
    let k = matched.len();
    let change: Vec<f64> = (0..tracked.len())
        .map(|j| {
            if k < 2 {
                return 0.0;
            }
            let (last, prev) = (matched[k - 1][j], matched[k - 2][j]);
            (last - prev).norm() / last.norm()
        })
        .collect();
    let signs_kept = k < 2
        || (0..tracked.len()).all(|j| (matched[k - 1][j].re > 0.0) == (matched[k - 2][j].re > 0.0));
    let settled = signs_kept && change.iter().all(|c| *c <= SETTLED);
    Convergence {
        rows,
        tracked,
        matched,
        change,
        settled,
    }
}

impl Convergence {
    /// The warning when the tracked eigenvalues have not settled.
    pub fn warning(&self) -> Option<String> {
        (!self.settled).then(|| {
            let worst = self.change.iter().copied().fold(0.0f64, f64::max);
            let last = self.rows.last().map_or(0.0, |r| r.basis_max_hz);
            format!(
                "the eigenvalues have not settled with the basis: they still move by {worst:.1e} of their modulus (or a growth rate changes sign) between the last two bases; add modes (modal.cutoff_hz above {last:.0} Hz, or modal.modes)"
            )
        })
    }

    /// `stability --json`'s `convergence`: `rows` (`modes`, `basis_max_hz`,
    /// `static_vectors`, `eigenvalues`: the tracked ones as `{re, im,
    /// freq_hz}`), `relative_change`, `tolerance`, `settled`, `warning`.
    pub fn to_json(&self) -> Value {
        json!({
            "rows": self.rows.iter().zip(&self.matched).map(|(r, m)| json!({
                "modes": r.modes,
                "basis_max_hz": r.basis_max_hz,
                "static_vectors": r.static_vectors,
                "eigenvalues": m.iter().map(|e| json!({
                    "re": e.re, "im": e.im, "freq_hz": e.im / std::f64::consts::TAU,
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "relative_change": self.change,
            "tolerance": SETTLED,
            "settled": self.settled,
            "warning": self.warning(),
        })
    }

    /// The table for the terminal: one line per basis, the tracked
    /// eigenvalues as `σ (1/s) @ f (Hz)`.
    pub fn table_lines(&self) -> Vec<String> {
        let mut out = vec![format!(
            "truncation (the {} eigenvalue{} as the basis grows; settled when the last two agree to {SETTLED:.0e} of |λ|):",
            if self.tracked.iter().any(|t| t.re > 0.0) { "growing" } else { "least stable" },
            if self.tracked.len() == 1 { "" } else { "s" }
        )];
        out.push(format!(
            "{:>7}  {:>12}  {:>6}  eigenvalues σ (1/s) @ f (Hz)",
            "modes", "up to (Hz)", "static"
        ));
        for (r, m) in self.rows.iter().zip(&self.matched) {
            let ev: Vec<String> = m
                .iter()
                .map(|e| format!("{:+.6e} @ {:.3}", e.re, e.im / std::f64::consts::TAU))
                .collect();
            out.push(format!(
                "{:>7}  {:>12.1}  {:>6}  {}",
                r.modes,
                r.basis_max_hz,
                r.static_vectors,
                ev.join(", ")
            ));
        }
        let change: Vec<String> = self.change.iter().map(|c| format!("{c:.1e}")).collect();
        out.push(format!(
            "last change: {} of |λ|: {}",
            change.join(", "),
            if self.settled {
                "settled"
            } else {
                "NOT settled"
            }
        ));
        out
    }
}

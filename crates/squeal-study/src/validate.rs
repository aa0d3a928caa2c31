//! `squeal validate`: squeal's benchmark cases, each computed with squeal's
//! own library at run time and compared with a reference that is analytic
//! (a formula, evaluated here), published, or independently computed (a
//! different method, also run here). A case compared only with squeal's own
//! earlier number would be [`Kind::Regression`], never validation.
//!
//! No case holds a computed value: every `value` and every formula
//! `reference` is evaluated when [`run`] is called.

use crate::error::Progress;
use serde::Serialize;
use squeal_core::cycle::{find_cycle, return_map_multipliers, section_returns, CycleOptions};
use squeal_core::model::hoffmann::Hoffmann;
use squeal_core::sink::EventLog;
use squeal_core::stability::{critical, max_growth_rate, CriticalOptions, StabilityError};
use squeal_core::{simulate, Belt, DiscPad, EventKind, FrictionLaw, Parameters, SolverOptions};

/// What a case's reference is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A formula derived from the model's equations, evaluated in code.
    Analytic,
    /// A number published by someone else (a paper, a solver's output).
    Published,
    /// The same quantity by an independent method, computed at run time.
    Independent,
    /// Only squeal's own earlier number: not validation.
    Regression,
}

/// How a case's error is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorKind {
    /// `|value − reference| / |reference|`.
    Relative,
    /// `|value − reference|` (for a reference that is 0).
    Absolute,
}

/// One benchmark case, computed.
#[derive(Debug, Clone, Serialize)]
pub struct Case {
    /// Short name, e.g. `hoffmann-mu-undamped`.
    pub name: &'static str,
    /// What the reference is.
    pub kind: Kind,
    /// The quantity compared, in words.
    pub quantity: &'static str,
    /// Its unit (`"1"` for a dimensionless number).
    pub unit: &'static str,
    /// The reference value.
    pub reference: f64,
    /// Where the reference comes from: paper or formula, with its equation.
    pub source: &'static str,
    /// squeal's value (NaN when its computation failed; see `detail`).
    pub value: f64,
    /// The error, as `error_kind` says.
    pub error: f64,
    /// Relative or absolute.
    pub error_kind: ErrorKind,
    /// The largest error that passes.
    pub tolerance: f64,
    /// `error ≤ tolerance` with a finite value and reference.
    pub pass: bool,
    /// Why the computation failed, if it did.
    pub detail: Option<String>,
}

/// A case before it is computed: its labels and the function that returns
/// `(reference, value)`.
pub struct Spec {
    /// See [`Case::name`].
    pub name: &'static str,
    /// See [`Case::kind`].
    pub kind: Kind,
    /// See [`Case::quantity`].
    pub quantity: &'static str,
    /// See [`Case::unit`].
    pub unit: &'static str,
    /// See [`Case::source`].
    pub source: &'static str,
    /// See [`Case::tolerance`] (relative).
    pub tolerance: f64,
    /// Computes `(reference, value)`.
    pub compute: fn() -> Result<(f64, f64), String>,
}

/// Every case, in the order `squeal validate` prints them.
pub fn specs() -> Vec<Spec> {
    vec![
        Spec {
            name: "belt-coulomb-period",
            kind: Kind::Analytic,
            quantity: "stick-slip period, belt with Coulomb friction (shooting)",
            unit: "s",
            source: "closed form T = 2(x_s − x_k)/V + (π + 2 atan2(V/ω, x_s − x_k))/ω, \
                     docs/physics.md §5a′",
            tolerance: 1e-7,
            compute: belt_coulomb_period,
        },
        Spec {
            name: "belt-hopf-speed",
            kind: Kind::Analytic,
            quantity: "Hopf speed of steady sliding, belt with the thesis law (c = 0.2, N = 100)",
            unit: "m/s",
            source: "V_H = Uc (1 − c/(N f0 f1)), docs/physics.md §5 (thesis eq. 12.1)",
            tolerance: 1e-8,
            compute: belt_hopf_speed,
        },
        Spec {
            name: "disc-pad-hopf-speed",
            kind: Kind::Analytic,
            quantity: "Hopf speed of the thesis disc–pad's pad mode (α = 0, N = 500)",
            unit: "m/s",
            source: "V_H = Uc (1 − c_px/(N f0 f1)), docs/physics.md §5 (the pad's \
                     one-oscillator criterion c_px + F_y* μ′(V) = 0, thesis eq. 12.1)",
            tolerance: 1e-8,
            compute: disc_pad_hopf_speed,
        },
        Spec {
            name: "hoffmann-mu-undamped",
            kind: Kind::Analytic,
            quantity: "critical friction coefficient, Hoffmann 2-dof, c1 = c2 = 0",
            unit: "1",
            source: "μ_c = ((k11 − k22)² + 4 k12²)/(4 k12 k3): coalescence, Hoffmann, Fischer, \
                     Allgaier & Gaul 2002, Mech. Res. Commun. 29; docs/physics.md §5a",
            tolerance: 1e-8,
            compute: hoffmann_undamped,
        },
        Spec {
            name: "hoffmann-mu-damped",
            kind: Kind::Analytic,
            quantity: "critical friction coefficient, Hoffmann 2-dof, c1 = c2 = 0.5 kg/s",
            unit: "1",
            source: "Routh–Hurwitz H = a3 a2 a1 − a4 a1² − a3² a0(μ) = 0 on det(m s² + C s + \
                     K(μ)), docs/physics.md §5a",
            tolerance: 1e-8,
            compute: || hoffmann_damped(0.5, 0.5),
        },
        Spec {
            name: "hoffmann-mu-damped-unequal",
            kind: Kind::Analytic,
            quantity: "critical friction coefficient, Hoffmann 2-dof, c1 = 0.1, c2 = 1 kg/s \
                       (below μ_c: damping destabilises)",
            unit: "1",
            source: "Routh–Hurwitz H = a3 a2 a1 − a4 a1² − a3² a0(μ) = 0 on det(m s² + C s + \
                     K(μ)), docs/physics.md §5a",
            tolerance: 1e-8,
            compute: || hoffmann_damped(0.1, 1.0),
        },
        Spec {
            name: "nastran-punch-frequencies",
            kind: Kind::Published,
            quantity: "natural frequencies of a free-free bar read from MSC Nastran 2013's own \
                       DMIG punch (KAAX, MAAX; the worst of its 8 elastic modes)",
            unit: "Hz",
            source: "MSC Nastran 2013 SOL 103's f06 eigenvalue table (7 digits) of the same \
                     model: ExportNastranKM (MIT licence), crates/squeal/tests/data/\
                     msc-nastran-2013",
            tolerance: 5.01e-7,
            compute: nastran_punch_frequencies,
        },
        Spec {
            name: "fe-brake-every-format",
            kind: Kind::Independent,
            quantity: "natural frequencies of the 124-dof two-pad FE brake read from Matrix \
                       Market, Nastran DMIG, Abaqus and Harwell–Boeing (the worst mode above \
                       1 Hz of the three against Matrix Market)",
            unit: "Hz",
            source: "the same model written by four independent writers (SciPy's Matrix \
                     Market, make_brake.py's DMIG, Abaqus and RSA + ANSYS mapping writers), \
                     examples/fe-brake/two-pad",
            tolerance: 1e-9,
            compute: fe_formats_agree,
        },
        Spec {
            name: "leine-rational-period",
            kind: Kind::Independent,
            quantity: "stick-slip period, belt with μ = 1/(1 + 3|v|), m = k = N = 1, V = 0.2 \
                       (shooting vs a 400 s simulation's stick spacing)",
            unit: "s",
            source: "model of Leine, van Campen, de Kraker & van den Steen 1998, Nonlinear \
                     Dyn. 16, 41–54; the reference is the mean stick-to-stick time of a long \
                     event-driven simulation",
            tolerance: 1e-6,
            compute: leine_period,
        },
        Spec {
            name: "disc-pad-cycle-period",
            kind: Kind::Independent,
            quantity: "period of the default disc–pad's limit cycle (the pad's reversal cycle, \
                       Newton shooting) against the mean return time to its section over 2000 \
                       returns of a simulation started on the cycle",
            unit: "s",
            source: "the event-driven simulation's returns to the Poincaré section (upward \
                     crossings located on the dense output), squeal_core::cycle::section_returns",
            tolerance: 1e-9,
            compute: || disc_pad_cycle().map(|c| (c.returns_period, c.period)),
        },
        Spec {
            name: "disc-pad-cycle-multipliers",
            kind: Kind::Independent,
            quantity: "Floquet multipliers of the default disc–pad's limit cycle (variational \
                       equations, saltation matrices at its reversals): the largest distance \
                       |μ − μ_ref| of the 7 non-trivial ones from the nearest eigenvalue of the \
                       simulated return map",
            unit: "1",
            source: "eigenvalues of the Poincaré map's Jacobian by central differences of \
                     simulated returns (h = 1e-6 of the state scales, rtol 1e-12), no variational \
                     equation: squeal_core::cycle::return_map_multipliers",
            tolerance: 1e-6,
            compute: || disc_pad_cycle().map(|c| (0.0, c.worst_distance)),
        },
        Spec {
            name: "disc-pad-cycle-decay-rate",
            kind: Kind::Independent,
            quantity: "decay rate ln|μ₁|/T of the default disc–pad cycle's slowest perturbation \
                       (its largest non-trivial multiplier, 1 − |μ₁| ≈ 2e-5)",
            unit: "1/s",
            source: "the largest eigenvalue of the simulated return map's Jacobian, as in \
                     disc-pad-cycle-multipliers",
            tolerance: 1e-3,
            compute: || disc_pad_cycle().map(|c| (c.decay_ref, c.decay)),
        },
        Spec {
            name: "duffing-backbone-nma",
            kind: Kind::Analytic,
            quantity: "frequency of the nonlinear mode (extended periodic motion concept, HB \
                       H = 16) of ẍ + αẋ + ω₀²x + βx³ = 0 (C = αM: ξ = α leaves the free \
                       oscillation) at modal amplitude 0.06, 24 % above ω₀",
            unit: "Hz",
            source: "the free Duffing oscillator's exact frequency ω = πω₀√(1 + βa²/ω₀²)/(2K(m)), \
                     m = βa²/(2(ω₀² + βa²)), K the complete elliptic integral; docs/physics.md §5i–5j",
            tolerance: 1e-10,
            compute: duffing_backbone,
        },
        Spec {
            name: "den-hartog-coulomb-amplitude",
            kind: Kind::Analytic,
            quantity: "amplitude of the Coulomb-damped oscillator mẍ + kx + F_f sign ẋ = F cos Ωt \
                       at r = Ω/ω₀ = 1.5, F_f/F = 0.3 (harmonic balance, Richardson 2A(80) − A(40) \
                       of its first-order convergence)",
            unit: "m",
            source: "Den Hartog 1931 (Phil. Mag. 9, 801–817), motion without stops: X = (F/k) \
                     √(1/(1 − r²)² − (βU)²), U = sin(π/r)/(r(1 + cos(π/r))); docs/physics.md §5i",
            tolerance: 2e-5,
            compute: den_hartog,
        },
    ]
}

/// One dof `m ẍ + c ẋ + k x + k3 x³ (+ Coulomb friction F_f) = F cos 2πf t`.
fn one_dof(
    m: f64,
    k: f64,
    c: f64,
    k3: f64,
    force: (f64, f64),
    friction: Option<f64>,
) -> Result<squeal_core::Lumped, String> {
    use squeal_core::model::lumped::{ContactSpec, ForceSpec, LumpedSpec, SpringSpec};
    let x = || vec![("x".to_string(), 1.0)];
    let spec = LumpedSpec {
        dofs: vec!["x".into()],
        masses: vec![("x".into(), m)],
        springs: vec![SpringSpec {
            name: "spring".into(),
            on: x(),
            k,
            c,
            k3,
        }],
        forces: vec![ForceSpec {
            name: "shaker".into(),
            on: x(),
            value: 0.0,
            ramp: 0.0,
            amplitude: force.0,
            freq_hz: force.1,
        }],
        contacts: friction
            .map(|ff| ContactSpec {
                name: "rub".into(),
                normal: None,
                k: None,
                c: None,
                bilateral: false,
                normal_force: Some(ff),
                tangent: Some(x()),
                v: 0.0,
                friction: FrictionLaw::Coulomb {
                    mu_s: 1.0,
                    mu_k: 1.0,
                },
                alpha: 0.0,
                slope: Vec::new(),
            })
            .into_iter()
            .collect(),
        ..LumpedSpec::default()
    };
    squeal_core::Lumped::build(&spec).map_err(err)
}

/// Half peak-to-peak of the position of a one-dof series.
fn series_amplitude(f: &squeal_core::hb::Fourier) -> f64 {
    let m = 20_000;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for j in 0..m {
        let z: [f64; 2] = f.state(std::f64::consts::TAU * j as f64 / m as f64);
        lo = lo.min(z[0]);
        hi = hi.max(z[0]);
    }
    0.5 * (hi - lo)
}

fn duffing_backbone() -> Result<(f64, f64), String> {
    use squeal_core::hb::nma::{mode_guess, nonlinear_mode};
    let (m, k, alpha, k3) = (2.0f64, 2.0e4, 3.0, 4.0e7);
    let l = one_dof(m, k, alpha * m, k3, (0.0, 0.0), None)?;
    let sys = squeal_core::model::lumped::Fixed::<2>(&l);
    let mass = nalgebra::DMatrix::from_element(1, 1, m);
    let phi = [1.0 / m.sqrt()];
    let w0 = (k / m).sqrt();
    let opts = squeal_core::hb::HbOptions {
        harmonics: 16,
        ..Default::default()
    };
    let (mut g, mut xi) = (mode_guess(&[0.0], &phi, w0, 1e-3), 0.0);
    let mut last = None;
    for a in [1e-3, 1e-2, 3e-2, 6e-2] {
        let s = a / (m.sqrt() * g.amplitude(0, 1));
        for c in g.coeffs[0].iter_mut().skip(1) {
            *c *= s;
        }
        let p = nonlinear_mode(&sys, &mass, &phi, a, (&g, xi), &opts).map_err(err)?;
        (g, xi) = (p.orbit.fourier.clone(), p.xi);
        last = Some(p);
    }
    let p = last.ok_or("no point")?;
    let beta = k3 / m;
    let x = series_amplitude(&p.orbit.fourier);
    let s = w0 * w0 + beta * x * x;
    let mm = beta * x * x / (2.0 * s);
    let (mut a, mut b) = (1.0f64, (1.0 - mm).sqrt());
    for _ in 0..60 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    let kk = std::f64::consts::PI / (2.0 * a);
    let exact = std::f64::consts::PI * s.sqrt() / (2.0 * kk);
    let tau = std::f64::consts::TAU;
    Ok((exact / tau, p.freq_hz()))
}

fn den_hartog() -> Result<(f64, f64), String> {
    use squeal_core::hb::{forced_response, Fourier, HbOptions};
    let (m, k, f, ff, r) = (1.0f64, 1.0e4, 10.0, 3.0, 1.5);
    let w0 = (k / m).sqrt();
    let hz = r * w0 / std::f64::consts::TAU;
    let l = one_dof(m, k, 0.0, 0.0, (f, hz), Some(ff))?;
    let sys = squeal_core::model::lumped::Fixed::<2>(&l);
    let (beta, x_st, pi) = (ff / f, f / k, std::f64::consts::PI);
    let u = (pi / r).sin() / (r * (1.0 + (pi / r).cos()));
    let exact = x_st * (1.0 / (1.0 - r * r).powi(2) - (beta * u).powi(2)).sqrt();
    let mut g = Fourier {
        omega: 1.0,
        coeffs: vec![vec![0.0, exact, 0.0]],
    };
    let mut amp = Vec::new();
    for h in [10, 20, 40, 80] {
        let o = forced_response(
            &sys,
            &g,
            &HbOptions {
                harmonics: h,
                ..Default::default()
            },
        )
        .map_err(err)?;
        if o.sticks {
            return Err("the motion stops (stick)".into());
        }
        amp.push(series_amplitude(&o.fourier));
        g = o.fourier;
    }
    Ok((exact, 2.0 * amp[3] - amp[2]))
}

/// Run every case whose name contains `filter` (all when `None`), one
/// `progress.inc(1)` per case. A case whose computation fails is reported
/// failed with its reason in `detail`; nothing panics.
pub fn run(filter: Option<&str>, progress: &dyn Progress) -> Vec<Case> {
    let mut out = Vec::new();
    for s in specs() {
        if let Some(f) = filter {
            if !s.name.contains(f) {
                continue;
            }
        }
        out.push(evaluate(&s));
        progress.inc(1);
    }
    progress.finish();
    out
}

/// Compute one case.
pub fn evaluate(s: &Spec) -> Case {
    let (reference, value, detail) = match (s.compute)() {
        Ok((r, v)) => (r, v, None),
        Err(e) => (f64::NAN, f64::NAN, Some(e)),
    };
    let error_kind = if reference == 0.0 {
        ErrorKind::Absolute
    } else {
        ErrorKind::Relative
    };
    let error = match error_kind {
        ErrorKind::Absolute => (value - reference).abs(),
        ErrorKind::Relative => ((value - reference) / reference).abs(),
    };
    let pass = value.is_finite() && reference.is_finite() && error <= s.tolerance;
    Case {
        name: s.name,
        kind: s.kind,
        quantity: s.quantity,
        unit: s.unit,
        reference,
        source: s.source,
        value,
        error,
        error_kind,
        tolerance: s.tolerance,
        pass,
        detail,
    }
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

fn tight(pos: f64, vel: f64) -> CycleOptions {
    CycleOptions {
        solver: SolverOptions {
            rtol: 1e-12,
            atol_pos: Some(pos),
            atol_vel: Some(vel),
            ..Default::default()
        },
        newton_tol: 1e-11,
        ..CycleOptions::default()
    }
}

fn belt(pairs: &[(&str, f64)], law: FrictionLaw) -> Result<Belt, String> {
    let mut b = Belt {
        friction: law,
        ..Belt::default()
    };
    for (k, v) in pairs {
        b.set(k, *v).map_err(err)?;
    }
    b.validate().map_err(err)?;
    Ok(b)
}

/// The Coulomb belt's stick-slip cycle (docs/physics.md §5a′): stick from
/// `2x_k − x_s` to `x_s`, then a harmonic slip arc about `x_k` through the
/// angle `π + 2φ`, `φ = atan2(V/ω, x_s − x_k)`.
fn belt_coulomb_period() -> Result<(f64, f64), String> {
    let (m, k, n, v, mu_s, mu_k) = (1.0, 1.0e4, 100.0, 0.1, 0.4, 0.3);
    let model = belt(
        &[("m", m), ("k", k), ("c", 0.0), ("N", n), ("V", v)],
        FrictionLaw::Coulomb { mu_s, mu_k },
    )?;
    let omega = (k / m).sqrt();
    let (x_s, x_k) = (mu_s * n / k, mu_k * n / k);
    let xi = x_s - x_k;
    let phi = (v / omega).atan2(xi);
    let reference = 2.0 * xi / v + (std::f64::consts::PI + 2.0 * phi) / omega;
    let cyc = find_cycle(
        &model,
        0.0,
        [2.0 * x_k - x_s, v],
        &tight(1e-9 * x_s, 1e-13 * v),
    )
    .map_err(err)?;
    Ok((reference, cyc.period))
}

fn thesis_law(law: &FrictionLaw) -> Result<(f64, f64, f64), String> {
    match *law {
        FrictionLaw::Thesis { f0, f1, uc } => Ok((f0, f1, uc)),
        _ => Err("the model's default friction law is not the thesis law".into()),
    }
}

fn belt_hopf_speed() -> Result<(f64, f64), String> {
    let (c, n) = (0.2, 100.0);
    let mut b = Belt::default();
    b.set("c", c).map_err(err)?;
    b.set("N", n).map_err(err)?;
    let (f0, f1, uc) = thesis_law(&b.friction)?;
    let reference = uc * (1.0 - c / (n * f0 * f1));
    let cross = critical(
        |v| {
            let mut m = b;
            m.set("V", v)?;
            max_growth_rate(&m)
        },
        0.1,
        0.999 * uc,
        &CriticalOptions::default(),
    )
    .map_err(err)?
    .ok_or("no change of stability found")?;
    Ok((reference, cross.value))
}

fn disc_pad_hopf_speed() -> Result<(f64, f64), String> {
    let brake = DiscPad::default();
    let (f0, f1, uc) = thesis_law(&brake.friction)?;
    let (c, n) = (brake.p.c_px, brake.p.N);
    let reference = uc * (1.0 - c / (n * f0 * f1));
    // Above the disc mode's own Hopf speed (c_dx = 1 kg/s: 11.7 m/s), so
    // the pad's mode is the one that stops growing.
    let cross = critical(
        |v| {
            let mut m = brake;
            m.set("V", v)?;
            max_growth_rate(&m)
        },
        0.5 * (uc + uc * (1.0 - brake.p.c_dx / (n * f0 * f1))),
        0.999 * uc,
        &CriticalOptions::default(),
    )
    .map_err(err)?
    .ok_or("no change of stability found")?;
    Ok((reference, cross.value))
}

fn hoffmann_mu(h: &Hoffmann) -> Result<f64, String> {
    let cross = critical(
        |mu| {
            let mut m = *h;
            m.set("mu", mu)?;
            max_growth_rate(&m)
        },
        0.05,
        0.6,
        &CriticalOptions::default(),
    )
    .map_err(|e: StabilityError| e.to_string())?
    .ok_or("no change of stability found")?;
    Ok(cross.value)
}

fn hoffmann_undamped() -> Result<(f64, f64), String> {
    let mut h = Hoffmann::default();
    h.set("c1", 0.0).map_err(err)?;
    h.set("c2", 0.0).map_err(err)?;
    let p = &h.p;
    let reference = ((p.k11 - p.k22).powi(2) + 4.0 * p.k12 * p.k12) / (4.0 * p.k12 * p.k3);
    Ok((reference, hoffmann_mu(&h)?))
}

/// `det(m s² I + C s + K(μ)) = a4 s⁴ + a3 s³ + a2 s² + a1 s + a0`, with only
/// `a0 = a00 + μ k12 k3` depending on μ; Hurwitz's `H = a3 a2 a1 − a4 a1² −
/// a3² a0` is affine in μ and vanishes at the threshold.
fn hoffmann_damped(c1: f64, c2: f64) -> Result<(f64, f64), String> {
    let mut h = Hoffmann::default();
    h.set("c1", c1).map_err(err)?;
    h.set("c2", c2).map_err(err)?;
    let p = &h.p;
    let a4 = p.m * p.m;
    let a3 = p.m * (p.c1 + p.c2);
    let a2 = p.m * (p.k11 + p.k22) + p.c1 * p.c2;
    let a1 = p.c1 * p.k22 + p.c2 * p.k11;
    let a00 = p.k11 * p.k22 - p.k12 * p.k12;
    let reference = (a3 * a2 * a1 - a4 * a1 * a1 - a3 * a3 * a00) / (a3 * a3 * p.k12 * p.k3);
    Ok((reference, hoffmann_mu(&h)?))
}

/// Leine et al.'s belt: the period by shooting (value) against the mean
/// spacing of the last ten stick events of a 400 s simulation (reference).
fn leine_period() -> Result<(f64, f64), String> {
    let law = FrictionLaw::Rational {
        mu_s: 1.0,
        delta: 3.0,
    };
    let model = belt(
        &[("m", 1.0), ("k", 1.0), ("c", 0.0), ("N", 1.0), ("V", 0.2)],
        law,
    )?;
    let opts = tight(1e-13, 1e-13);
    let cyc = find_cycle(&model, 0.0, [0.0, 0.0], &opts).map_err(err)?;
    let mut log = EventLog::<2>::default();
    simulate(&model, 0.0, [0.0, 0.0], 400.0, 1.0, opts.solver, &mut log).map_err(err)?;
    let sticks: Vec<f64> = log
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Stick)
        .map(|e| e.t)
        .collect();
    let n = sticks.len();
    if n <= 20 {
        return Err(format!("{n} stick events in 400 s: no settled stick-slip"));
    }
    Ok(((sticks[n - 1] - sticks[n - 11]) / 10.0, cyc.period))
}

/// The default disc–pad's cycle, computed once for the three cases that
/// compare it.
struct DiscPadCycle {
    /// Shooting's period (s).
    period: f64,
    /// Mean return time of a 2000-return simulation from the cycle (s).
    returns_period: f64,
    /// Largest distance of a non-trivial multiplier from the nearest
    /// eigenvalue of the simulated return map.
    worst_distance: f64,
    /// `ln|μ₁|/T` of the shooting's largest non-trivial multiplier (1/s).
    decay: f64,
    /// The same of the return map's largest eigenvalue (1/s).
    decay_ref: f64,
}

/// Returns counted for the mean return time.
const CYCLE_RETURNS: usize = 2000;

fn disc_pad_cycle() -> Result<&'static DiscPadCycle, String> {
    static CELL: std::sync::OnceLock<Result<DiscPadCycle, String>> = std::sync::OnceLock::new();
    CELL.get_or_init(|| {
        let brake = DiscPad::default();
        let cyc = find_cycle(&brake, 0.0, [0.0; 8], &CycleOptions::default()).map_err(err)?;
        let solver = SolverOptions {
            rtol: 1e-12,
            atol_pos: Some(1e-20),
            atol_vel: Some(1e-15),
            ..Default::default()
        };
        let t_end = (CYCLE_RETURNS as f64 + 0.5) * cyc.period;
        let returns =
            section_returns(&brake, 0.0, cyc.z0, t_end, cyc.section, solver).map_err(err)?;
        if returns.len() != CYCLE_RETURNS {
            return Err(format!(
                "{} returns to the section in {CYCLE_RETURNS}.5 periods, not {CYCLE_RETURNS}",
                returns.len()
            ));
        }
        let returns_period = returns[CYCLE_RETURNS - 1].0 / CYCLE_RETURNS as f64;
        let map = return_map_multipliers(&brake, &cyc, 1e-6, solver).map_err(err)?;
        let worst_distance = cyc
            .multipliers
            .iter()
            .filter(|m| !m.trivial)
            .map(|a| {
                map.iter()
                    .map(|b| (a.re - b.re).hypot(a.im - b.im))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        let largest = map.first().ok_or("the return map has no eigenvalue")?;
        Ok(DiscPadCycle {
            period: cyc.period,
            returns_period,
            worst_distance,
            decay: cyc.max_multiplier.ln() / cyc.period,
            decay_ref: largest.abs().ln() / cyc.period,
        })
    })
    .as_ref()
    .map_err(Clone::clone)
}

/// The punch file MSC Nastran 2013 wrote (SOL 103, `PARAM,EXTOUT,DMIGPCH`),
/// embedded so that an installed binary validates without the sources.
const NASTRAN_PUNCH: &str = include_str!("../../squeal/tests/data/msc-nastran-2013/test_case.pch");

/// The 8 elastic natural frequencies (Hz) in Nastran's own f06 for that
/// model (its two rigid-body modes left out).
const NASTRAN_F06_HZ: [f64; 8] = [
    2.114057e+01,
    2.135569e+01,
    1.287332e+02,
    1.297476e+02,
    4.371801e+02,
    4.382013e+02,
    1.258988e+03,
    1.259566e+03,
];

/// The undamped natural frequencies (Hz, ascending) of `K φ = ω² M φ`,
/// `M`'s dofs matched to `K`'s by name (numbered dofs as they are), solved
/// as `stability::projected` solves undamped modes.
fn natural_frequencies(
    k: &squeal_core::labelled::LabelledMatrix,
    m: &squeal_core::labelled::LabelledMatrix,
) -> Result<Vec<f64>, String> {
    use squeal_core::stability::projected::{undamped_basis, Basis, SecondOrder};
    let n = k.triplets.rows;
    if m.triplets.rows != n {
        return Err(format!("K has {n} dofs, M {}", m.triplets.rows));
    }
    // Row/column of `a`'s index `i` in K's numbering.
    let place = |a: &squeal_core::labelled::LabelledMatrix, i: usize| -> Result<usize, String> {
        match (&k.labels, &a.labels) {
            (Some(kl), Some(al)) => kl
                .iter()
                .position(|l| *l == al[i])
                .ok_or_else(|| format!("dof {} is not in K", al[i])),
            (None, None) => Ok(i),
            _ => Err("one matrix names its dofs, the other numbers them".into()),
        }
    };
    let dense =
        |a: &squeal_core::labelled::LabelledMatrix| -> Result<nalgebra::DMatrix<f64>, String> {
            let mut d = nalgebra::DMatrix::zeros(n, n);
            for &(i, j, v) in &a.triplets.entries {
                d[(place(a, i)?, place(a, j)?)] += v;
            }
            Ok(d)
        };
    let sys = SecondOrder {
        m: dense(m)?,
        k: dense(k)?,
        c: nalgebra::DMatrix::zeros(n, n),
    };
    let b = undamped_basis(&sys, Basis::Modes(n)).map_err(|e| e.to_string())?;
    Ok(b.omega2
        .iter()
        .map(|w2| w2.max(0.0).sqrt() / std::f64::consts::TAU)
        .collect())
}

/// `(Nastran's, squeal's)` frequency of the elastic mode where they differ
/// most (relatively), from the punch's `KAAX` and `MAAX`.
fn nastran_punch_frequencies() -> Result<(f64, f64), String> {
    let k = squeal_core::dmig::parse_named(NASTRAN_PUNCH, "KAAX")?;
    let m = squeal_core::dmig::parse_named(NASTRAN_PUNCH, "MAAX")?;
    let hz = natural_frequencies(&k, &m)?;
    if hz.len() != NASTRAN_F06_HZ.len() + 2 {
        return Err(format!("{} modes, expected 10", hz.len()));
    }
    hz[2..]
        .iter()
        .zip(NASTRAN_F06_HZ)
        .map(|(&v, r)| (r, v))
        .max_by(|a, b| {
            ((a.1 - a.0) / a.0)
                .abs()
                .total_cmp(&((b.1 - b.0) / b.0).abs())
        })
        .ok_or_else(|| "no modes".into())
}

/// The two-pad FE brake of `examples/fe-brake/two-pad` (124 dofs) as four
/// independent writers wrote it: SciPy (Matrix Market), a Nastran DMIG
/// punch, Abaqus `*MATRIX OUTPUT` and Harwell–Boeing RSA with ANSYS's
/// mapping file (`make_brake.py`), embedded.
mod fe_brake {
    macro_rules! file {
        ($f:literal) => {
            include_str!(concat!("../../../examples/fe-brake/two-pad/", $f))
        };
    }
    pub const MM_K: &str = file!("K.mtx");
    pub const MM_M: &str = file!("M.mtx");
    pub const PUNCH: &str = file!("brake.pch");
    pub const ABAQUS_K: &str = file!("brake_STIF1.mtx");
    pub const ABAQUS_M: &str = file!("brake_MASS1.mtx");
    pub const HB_K: &str = file!("brake_K.matrix");
    pub const HB_K_MAP: &str = file!("brake_K.mapping");
    pub const HB_M: &str = file!("brake_M.matrix");
    pub const HB_M_MAP: &str = file!("brake_M.mapping");
}

/// `(Matrix Market's, another format's)` natural frequency where the
/// formats differ most (relatively, over the modes above 1 Hz): the same
/// model read from every format squeal reads gives the same structure.
fn fe_formats_agree() -> Result<(f64, f64), String> {
    use squeal_core::labelled::LabelledMatrix;
    use squeal_core::{abaqus, dmig, harwell_boeing};
    let mm = |text: &str| -> Result<LabelledMatrix, String> {
        Ok(LabelledMatrix {
            name: String::new(),
            format: "matrix-market",
            labels: None,
            triplets: squeal_core::matrix_market::parse(text)?,
            symmetric: false,
        })
    };
    let reference = natural_frequencies(&mm(fe_brake::MM_K)?, &mm(fe_brake::MM_M)?)?;
    let others = [
        natural_frequencies(
            &dmig::parse_named(fe_brake::PUNCH, "KAAX")?,
            &dmig::parse_named(fe_brake::PUNCH, "MAAX")?,
        )?,
        natural_frequencies(
            &abaqus::parse(fe_brake::ABAQUS_K)?,
            &abaqus::parse(fe_brake::ABAQUS_M)?,
        )?,
        natural_frequencies(
            &harwell_boeing::parse(fe_brake::HB_K, Some(fe_brake::HB_K_MAP))?,
            &harwell_boeing::parse(fe_brake::HB_M, Some(fe_brake::HB_M_MAP))?,
        )?,
    ];
    let mut worst: Option<(f64, f64)> = None;
    for hz in &others {
        if hz.len() != reference.len() {
            return Err(format!(
                "{} modes against Matrix Market's {}",
                hz.len(),
                reference.len()
            ));
        }
        for (&r, &v) in reference.iter().zip(hz) {
            if r > 1.0 {
                let e = ((v - r) / r).abs();
                if worst.is_none_or(|(wr, wv)| e > ((wv - wr) / wr).abs()) {
                    worst = Some((r, v));
                }
            }
        }
    }
    worst.ok_or_else(|| "no mode above 1 Hz".into())
}

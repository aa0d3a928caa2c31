//! `squeal hb`: the self-excited periodic orbit of a scenario by harmonic
//! balance (`squeal_core::hb`), with its convergence in the number of
//! harmonics and its stability by one shooting period from the HB orbit.
//!
//! The guess is a settled simulation's last period (the settling of
//! `squeal cycle`); HB is then solved for `H/4`, `H/2` and `H` harmonics,
//! each from the last, and the table of frequency and amplitude changes
//! shows whether the series has converged. The Floquet multipliers come
//! from the variational equations and saltation matrices along the exact
//! event-driven flow over one period from the HB orbit's state at phase
//! 0 (`squeal_core::cycle::floquet_from`); the scaled defect of that
//! period, `|φ_T(z₀) − z₀|`, measures how far the HB orbit is from a
//! periodic orbit of the exact model.

use crate::cycle::{events_json, multipliers_json, named_json, real_states};
use crate::error::{Cancel, StudyError};
use crate::scenario::{InputError, Scenario};
use serde_json::{json, Map, Value};
use squeal_core::cycle::{self, CycleError, CycleOptions};
use squeal_core::hb::{
    forced_response, forcing_omega, harmonic_balance, Fourier, HbError, HbOptions, HbOrbit,
};
use squeal_core::System;

/// Most harmonics `squeal hb` takes: the Jacobian is dense, `(n(2H+1))²`.
pub const MAX_HARMONICS: usize = 400;

/// Largest relative change of the frequency (and, ×100, of the amplitudes)
/// between the last two truncations that counts as converged.
pub const CONVERGED_FREQ: f64 = 1e-5;

/// One row of the convergence table.
#[derive(Debug, Clone, PartialEq)]
pub struct Truncation {
    /// Harmonics kept.
    pub harmonics: usize,
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Largest relative change of a state's amplitude from the previous row
    /// (states above 1e-6 of the largest of their kind; NaN for the first row).
    pub amplitude_change: f64,
    /// Final scaled residual.
    pub residual: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// Table rows `[t, states…]`.
pub type Rows = Vec<Vec<f64>>;

/// A harmonic-balance orbit, independent of the state count.
#[derive(Debug, Clone)]
pub struct HbFound {
    /// Real state names (positions, then velocities).
    pub names: Vec<String>,
    /// The final series (the real dofs' coefficients and ω).
    pub series: Fourier,
    /// Harmonics of the final solution.
    pub harmonics: usize,
    /// Period (s).
    pub period: f64,
    /// The forcing frequency (Hz) of a forced response; `None` for a
    /// self-excited orbit.
    pub forcing_hz: Option<f64>,
    /// Half peak-to-peak of each state over one period (from the series).
    pub amplitude: Vec<f64>,
    /// Per dof (position state): the mean and the amplitude `√(a_k² + b_k²)` of harmonics 1…H (m).
    pub spectrum: Vec<Vec<f64>>,
    /// Per contact: name and the fraction of the period in slip+, slip−, stick, no contact.
    pub fractions: Vec<(String, [f64; 4])>,
    /// Whether stick was a constraint (the dynamic Lagrangian step,
    /// `squeal_core::hb` module documentation): the orbit sticks.
    pub stick_constraint: bool,
    /// Mode switches per period.
    pub switches: usize,
    /// Panels per period of the frequency–time step.
    pub panels: usize,
    /// Floquet multipliers `(re, im, trivial)` of one exact period from the HB orbit.
    pub multipliers: Vec<(f64, f64, bool)>,
    /// Whether every non-trivial multiplier is inside the unit circle.
    pub stable: bool,
    /// Whether the multipliers resolve that verdict: the largest non-trivial
    /// one is farther from the unit circle than the trivial one is from 1
    /// (its error, since exactly 1 on an exact orbit) and than the defect
    /// ([`unresolved`]).
    pub stability_resolved: bool,
    /// Largest non-trivial modulus.
    pub max_multiplier: f64,
    /// Of a smooth orbit (no mode switches) on which Newton converged, the
    /// multipliers `(re, im, trivial)` by Hill's method from the series alone
    /// (`squeal_core::hb::hill`), and their largest non-trivial modulus.
    pub hill: Option<HillMultipliers>,
    /// Scaled `|φ_T(z₀) − z₀|` of the exact flow from the HB orbit.
    pub defect: f64,
    /// Events of the exact flow over that period (order of `EventKind::ALL`).
    pub events: [u64; 5],
    /// The convergence table, coarsest first.
    pub convergence: Vec<Truncation>,
    /// Final scaled HB residual and Newton iterations.
    pub residual: f64,
    /// Newton iterations of the final solution.
    pub iterations: usize,
    /// Simulated settling time of the guess (s; 0 from the Hopf guess).
    pub settle_time: f64,
    /// Where the guess that gave the orbit came from.
    pub guess: Guess,
    /// What the numbers do not support, if anything.
    pub warnings: Vec<String>,
    /// One period, if asked for: the series sampled at `16(2H+1)` phases
    /// (at least 1024), and the exact flow from its state at phase 0
    /// (step ends and events); rows `[t, states…]`.
    pub orbit: Option<(Rows, Rows)>,
}

/// The multipliers of a smooth orbit by Hill's method.
#[derive(Debug, Clone)]
pub struct HillMultipliers {
    /// `(re, im, trivial)`, by real part of the exponent, largest first.
    pub multipliers: Vec<(f64, f64, bool)>,
    /// The largest non-trivial modulus.
    pub max_multiplier: f64,
}

/// Check `--harmonics`.
pub fn check_harmonics(h: usize) -> Result<(), InputError> {
    if h == 0 || h > MAX_HARMONICS {
        return Err(InputError(format!(
            "--harmonics {h}: must be in 1..={MAX_HARMONICS} (the Newton matrix is dense, (dofs·(2H+1))² entries)"
        )));
    }
    Ok(())
}

fn cycle_err(e: CycleError) -> StudyError {
    match e {
        CycleError::Bad(m) => StudyError::Input(InputError(m)),
        other => StudyError::Numerical(format!("hb: settling for a guess: {other}")),
    }
}

fn hb_err(e: HbError) -> StudyError {
    match e {
        HbError::Bad(m) => StudyError::Input(InputError(format!("hb: {m}"))),
        other => StudyError::Numerical(format!("hb: {other}")),
    }
}

/// Half peak-to-peak of every state of the series (`N` states), from
/// `16(2H+1)` samples (at least 4096).
pub(crate) fn amplitudes<const N: usize>(f: &Fourier) -> [f64; N] {
    let m = (16 * (2 * f.harmonics() + 1)).max(4096);
    let mut lo = [f64::INFINITY; N];
    let mut hi = [f64::NEG_INFINITY; N];
    for j in 0..m {
        let z: [f64; N] = f.state(std::f64::consts::TAU * j as f64 / m as f64);
        for i in 0..N {
            lo[i] = lo[i].min(z[i]);
            hi[i] = hi[i].max(z[i]);
        }
    }
    let mut a = [0.0; N];
    for i in 0..N {
        a[i] = 0.5 * (hi[i] - lo[i]);
    }
    a
}

/// Largest relative change between two amplitude lists, over the states
/// above 1e-6 of the largest of their block (positions, velocities).
fn amplitude_change(real: &[usize], a: &[f64], b: &[f64]) -> f64 {
    let half = real.len() / 2;
    let mut out: f64 = 0.0;
    for blk in [&real[..half], &real[half..]] {
        let top = blk.iter().map(|&i| b[i]).fold(0.0, f64::max);
        for &i in blk {
            if b[i] > 1e-6 * top {
                out = out.max((a[i] / b[i] - 1.0).abs());
            }
        }
    }
    out
}

/// HB at `H/4`, `H/2` and `H` from `simulated` (each rung from the last
/// solution, else from `simulated`; a coarse rung that fails is left out of
/// the table, with a note): the final orbit, the table, the amplitudes.
/// With `stick`, stick is a constraint (the dynamic Lagrangian step);
/// without it, an orbit found to stick is solved again with it.
#[allow(clippy::type_complexity)]
fn ladder<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    simulated: &Fourier,
    harmonics: usize,
    real: &[usize],
    stick: bool,
    cancel: &Cancel,
) -> Result<(HbOrbit, Vec<Truncation>, [f64; N], Vec<String>), StudyError> {
    let found = rungs(m, simulated, harmonics, real, stick, cancel)?;
    if !stick && found.0.sticks {
        return rungs(m, simulated, harmonics, real, true, cancel);
    }
    Ok(found)
}

/// The rungs of [`ladder`] with stick as a constraint or not.
#[allow(clippy::type_complexity)]
fn rungs<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    simulated: &Fourier,
    harmonics: usize,
    real: &[usize],
    stick: bool,
    cancel: &Cancel,
) -> Result<(HbOrbit, Vec<Truncation>, [f64; N], Vec<String>), StudyError> {
    let mut rungs = vec![(harmonics / 4).max(1), (harmonics / 2).max(1), harmonics];
    rungs.dedup();
    let mut guess = simulated.clone();
    let mut convergence = Vec::new();
    let mut notes = Vec::new();
    let mut last: Option<(HbOrbit, [f64; N])> = None;
    for &h in &rungs {
        let hb_opts = HbOptions {
            harmonics: h,
            lagrangian: stick,
            ..HbOptions::default()
        };
        // From the last truncation's solution, else from the simulation
        // (a coarse truncation can converge onto a smoothed orbit far from
        // the finer one, or onto the steady state).
        let forced = !m.forcing_hz().is_empty();
        let hb = |g: &Fourier| {
            if forced {
                forced_response(m, g, &hb_opts)
            } else {
                harmonic_balance(m, g, &hb_opts)
            }
        };
        let tried = match hb(&guess) {
            Err(HbError::Bad(e)) => return Err(hb_err(HbError::Bad(e))),
            Err(_) if guess != *simulated => hb(simulated),
            other => other,
        };
        cancel.check()?;
        let o = match tried {
            Ok(o) => o,
            Err(e) if h < harmonics => {
                notes.push(format!(
                    "H = {h} gave no orbit ({e}); left out of the table"
                ));
                continue;
            }
            Err(e) => return Err(hb_err(e)),
        };
        let amp = amplitudes::<N>(&o.fourier);
        convergence.push(Truncation {
            harmonics: h,
            freq_hz: 1.0 / o.period(),
            amplitude_change: last
                .as_ref()
                .map_or(f64::NAN, |(_, p)| amplitude_change(real, &amp, p)),
            residual: o.residual,
            iterations: o.iterations,
        });
        guess = o.fourier.clone();
        last = Some((o, amp));
    }
    let (o, amp) = last.expect("the last rung succeeded or returned");
    Ok((o, convergence, amp, notes))
}

/// Where `squeal hb` takes its first guess from (`--guess`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Guess {
    /// The last turn of a settled simulation (as `squeal cycle`): the orbit
    /// the scenario's motion settles on.
    Settle,
    /// Steady sliding's fastest-growing mode at the amplitude where the
    /// linear motion first reaches a nonlinearity (a contact's sliding
    /// velocity or normal force reaching zero), no simulation; the settled
    /// guess if that finds no stable orbit.
    Hopf,
}

impl Guess {
    /// Parse `settle` or `hopf`.
    pub fn parse(s: &str) -> Result<Guess, InputError> {
        match s {
            "settle" => Ok(Guess::Settle),
            "hopf" => Ok(Guess::Hopf),
            other => Err(InputError(format!(
                "--guess {other}: must be settle or hopf"
            ))),
        }
    }

    /// The name (`settle`, `hopf`).
    pub fn as_str(self) -> &'static str {
        match self {
            Guess::Settle => "settle",
            Guess::Hopf => "hopf",
        }
    }
}

/// The guess from steady sliding's fastest-growing mode `u` (eigenvalue
/// `σ + iω`): `q = q* + A·Re(u e^{iωt})`, with `A` the amplitude at which
/// the linear motion first takes a contact's sliding velocity or normal
/// force to zero (each is affine in the state near steady sliding, so its
/// linear variation is exact by differences), times `factor`. `None` if
/// steady sliding has no growing oscillatory mode (`growing_only`), or no
/// oscillatory mode at all (else: the least stable one, as at a Hopf point,
/// where it is neutral).
pub(crate) fn hopf_guess<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    real: &[usize],
    factor: f64,
    growing_only: bool,
) -> Result<Option<Fourier>, StudyError> {
    let a = squeal_core::stability::analyse(m)
        .map_err(|e| StudyError::Numerical(format!("hb --guess hopf: {e}")))?;
    let Some(e) = a
        .eigen
        .iter()
        .filter(|e| (e.growing || !growing_only) && e.im > 0.0)
        .max_by(|x, y| x.re.total_cmp(&y.re))
    else {
        return Ok(None);
    };
    let mut zs = [0.0; N];
    zs.copy_from_slice(&a.equilibrium);
    let t_a = cycle::autonomous_from(m);
    let modes = m.start_modes(t_a, &zs);
    let h = 1e-8;
    let along = |part: fn(&nalgebra::Complex<f64>) -> f64| {
        let mut z = zs;
        for (zi, ui) in z.iter_mut().zip(&e.vector) {
            *zi += h * part(ui);
        }
        z
    };
    let (z_re, z_im) = (along(|c| c.re), along(|c| c.im));
    let mut amplitude = f64::INFINITY;
    for i in 0..m.contacts() {
        let o0 = m.observe_contact(t_a, &modes, &zs, i);
        let (or, oi) = (
            m.observe_contact(t_a, &modes, &z_re, i),
            m.observe_contact(t_a, &modes, &z_im, i),
        );
        let gv = ((or.v_rel - o0.v_rel) / h).hypot((oi.v_rel - o0.v_rel) / h);
        let gn = ((or.normal_force - o0.normal_force) / h)
            .hypot((oi.normal_force - o0.normal_force) / h);
        if gv > 0.0 {
            amplitude = amplitude.min(o0.v_rel.abs() / gv);
        }
        if gn > 0.0 && o0.normal_force > 0.0 {
            amplitude = amplitude.min(o0.normal_force / gn);
        }
    }
    if !(amplitude.is_finite() && amplitude > 0.0) {
        return Ok(None);
    }
    let amp = factor * amplitude;
    let coeffs = real[..real.len() / 2]
        .iter()
        .map(|&i| {
            let mut c = vec![0.0; 3];
            c[0] = zs[i];
            c[1] = amp * e.vector[i].re;
            c[2] = -amp * e.vector[i].im;
            c
        })
        .collect();
    Ok(Some(Fourier {
        omega: e.im,
        coeffs,
    }))
}

/// The HB orbit from the Hopf guess at amplitude factors 1, 2 and 0.5 of
/// the first nonlinearity: the first that converges to a stable orbit.
#[allow(clippy::type_complexity)]
fn from_hopf<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    real: &[usize],
    harmonics: usize,
    opts: &CycleOptions,
    cancel: &Cancel,
) -> Result<Option<Solved<N>>, StudyError> {
    for factor in [1.0, 2.0, 0.5] {
        let Some(g) = hopf_guess(m, real, factor, true)? else {
            return Ok(None);
        };
        let Ok((o, conv, amp, notes)) =
            ladder(m, &g.resized(harmonics), harmonics, real, false, cancel)
        else {
            continue;
        };
        let z_hb: [f64; N] = o.fourier.state(0.0);
        let Ok(c) = cycle::floquet_from(m, &z_hb, o.period(), opts) else {
            continue;
        };
        if c.stable {
            return Ok(Some((o, conv, amp, notes, c, z_hb)));
        }
    }
    Ok(None)
}

/// The modulus of the trivial multiplier (1 on an exact orbit; its
/// distance from 1 measures the multipliers' error).
fn trivial_abs<const N: usize>(c: &cycle::Cycle<N>) -> f64 {
    c.multipliers
        .iter()
        .find(|m| m.trivial)
        .map_or(1.0, |m| m.re.hypot(m.im))
}

/// Whether the Floquet verdict of `c` (one exact period from an HB orbit)
/// is within the multipliers' error: the largest non-trivial modulus is no
/// farther from 1 than the trivial multiplier (exactly 1 on an exact orbit)
/// or than the scaled defect of the period.
pub fn unresolved<const N: usize>(c: &cycle::Cycle<N>) -> bool {
    let err = (trivial_abs(c) - 1.0).abs().max(c.residual);
    (c.max_multiplier - 1.0).abs() <= err
}

/// An HB orbit with its table, amplitudes, notes, Floquet analysis and start.
type Solved<const N: usize> = (
    HbOrbit,
    Vec<Truncation>,
    [f64; N],
    Vec<String>,
    cycle::Cycle<N>,
    [f64; N],
);

fn solve<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    any: &crate::AnyModel,
    z0: &[f64],
    harmonics: usize,
    opts: &CycleOptions,
    guess: Guess,
    with_orbit: bool,
    cancel: &Cancel,
) -> Result<HbFound, StudyError> {
    let mut start = [0.0; N];
    start.copy_from_slice(z0);
    let real = real_states::<N>(m.norm_states());
    let n = real.len() / 2;
    // What the motion settles on is stable: as `squeal cycle` does, an
    // unstable orbit met on the way is left by simulating on until its
    // instability has grown a thousandfold, then settling again (at most
    // four times).
    let (mut t, mut z) = (0.0, start);
    let mut spent = 0.0;
    let mut attempt = 0;
    let hopf = match guess {
        Guess::Hopf => from_hopf(m, &real, harmonics, opts, cancel)?,
        Guess::Settle => None,
    };
    let from = if hopf.is_some() {
        Guess::Hopf
    } else {
        Guess::Settle
    };
    let hopf_failed = guess == Guess::Hopf && hopf.is_none();
    let (o, convergence, amp, mut notes, c, z_hb) = if let Some(found) = hopf {
        found
    } else {
        loop {
            attempt += 1;
            let (_, zs, period, settled) = cycle::settle(m, t, z, opts).map_err(cycle_err)?;
            spent += settled;
            cancel.check()?;
            let orbit = cycle::sample_period(m, &zs, period, opts).map_err(cycle_err)?;
            // A settled orbit that sticks: stick as a constraint.
            let sticks = orbit
                .modes
                .iter()
                .any(|md| md.as_slice().contains(&squeal_core::Mode::Stick));
            // Fitted with enough harmonics to see whether the settled "period"
            // is several turns of the orbit (the turns of a settling run agree
            // to its tolerance only: up to 1e-2 of the energy may leak into
            // the other harmonics); tried at the minimal period first, then,
            // if that orbit is not the stable one, at the settled period (a
            // genuine period-k orbit, near a period doubling say).
            let full = Fourier::from_orbit(&orbit, period, n, 4 * harmonics.max(8));
            let reduced = full.minimal(1e-2);
            let mut guesses = vec![reduced.resized(harmonics)];
            if reduced.omega != full.omega {
                guesses.push(full.resized(harmonics));
            }
            let mut best = None;
            let mut failure = None;
            for g in &guesses {
                match ladder(m, g, harmonics, &real, sticks, cancel) {
                    Ok((o, conv, amp, notes)) => {
                        let z_hb: [f64; N] = o.fourier.state(0.0);
                        let c =
                            cycle::floquet_from(m, &z_hb, o.period(), opts).map_err(cycle_err)?;
                        // An orbit not known to be unstable ends the search:
                        // the settled period's k turns of it would only
                        // repeat it (with its multipliers' k-th powers).
                        let done = c.stable || unresolved(&c);
                        if best.is_none() || c.stable {
                            best = Some((o, conv, amp, notes, c, z_hb));
                        }
                        if done {
                            break;
                        }
                    }
                    Err(e) => failure = failure.or(Some(e)),
                }
            }
            let Some(found) = best else {
                // No orbit near this guess (a transient that only looked
                // periodic, say): simulate on for as long again (at least 100
                // of its periods) and settle anew.
                if attempt >= 4 || spent >= opts.settle_time {
                    return Err(failure.expect("a guess failed"));
                }
                let skip = settled.max(100.0 * period);
                (t, z) = cycle::advance(m, t + settled, zs, skip, opts).map_err(cycle_err)?;
                spent += skip;
                continue;
            };
            let c = &found.4;
            // An orbit not known to be unstable (its multipliers do not
            // resolve the verdict) is the answer: simulating past it as past
            // an unstable one would take up to 10⁶ periods for nothing.
            if c.stable
                || unresolved(c)
                || attempt >= 4
                || c.max_multiplier <= 1.0
                || spent >= opts.settle_time
            {
                break found;
            }
            let skip = cycle::past_unstable(c.period, c.max_multiplier);
            (t, z) = cycle::advance(m, t + settled, zs, skip, opts).map_err(cycle_err)?;
            spent += skip;
        }
    };
    if hopf_failed {
        notes.push(
            "--guess hopf found no stable orbit from steady sliding's growing mode; the guess was settled by simulation instead".into(),
        );
    }
    let st = Stability::of_cycle(&c);
    finish(
        m,
        any,
        Hb {
            orbit: o,
            convergence,
            amp,
            notes,
        },
        st,
        &z_hb,
        spent,
        from,
        with_orbit,
        opts,
    )
}

/// A solved HB orbit with its convergence table, amplitudes and notes.
struct Hb<const N: usize> {
    orbit: HbOrbit,
    convergence: Vec<Truncation>,
    amp: [f64; N],
    notes: Vec<String>,
}

/// The stability of an HB orbit by one exact period from it.
pub(crate) struct Stability {
    multipliers: Vec<(f64, f64, bool)>,
    pub(crate) stable: bool,
    pub(crate) resolved: bool,
    pub(crate) max: f64,
    defect: f64,
    events: [u64; 5],
    /// The trivial multiplier's modulus (autonomous), whose distance from 1
    /// is the multipliers' error; `None` for a forced response.
    reference: Option<f64>,
}

impl Stability {
    /// Of an autonomous orbit (`cycle::floquet_from`): the non-trivial
    /// multipliers, the verdict unresolved within the trivial one's error.
    pub(crate) fn of_cycle<const N: usize>(c: &cycle::Cycle<N>) -> Stability {
        Stability {
            multipliers: c
                .multipliers
                .iter()
                .map(|m| (m.re, m.im, m.trivial))
                .collect(),
            stable: c.stable,
            resolved: !unresolved(c),
            max: c.max_multiplier,
            defect: c.residual,
            events: c.events_per_period,
            reference: Some(trivial_abs(c)),
        }
    }

    /// Of a forced response (`cycle::forced_floquet`): every multiplier of
    /// the monodromy counts.
    pub(crate) fn forced(list: &[cycle::Multiplier], defect: f64, events: [u64; 5]) -> Stability {
        let max = list.iter().map(|m| m.re.hypot(m.im)).fold(0.0, f64::max);
        Stability {
            multipliers: list.iter().map(|m| (m.re, m.im, false)).collect(),
            stable: max < 1.0,
            resolved: (max - 1.0).abs() > defect,
            max,
            defect,
            events,
            reference: None,
        }
    }
}

/// The answer from a solved orbit: the sampled period (if asked for), the
/// warnings, the JSON-ready summary.
#[allow(clippy::too_many_arguments)]
fn finish<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    any: &crate::AnyModel,
    hb: Hb<N>,
    st: Stability,
    z_hb: &[f64; N],
    settled: f64,
    from: Guess,
    with_orbit: bool,
    opts: &CycleOptions,
) -> Result<HbFound, StudyError> {
    let Hb {
        orbit: o,
        convergence,
        amp,
        mut notes,
    } = hb;
    let harmonics = o.fourier.harmonics();
    let real = real_states::<N>(m.norm_states());
    let names = any.state_names();
    let orbit = if with_orbit {
        let period = o.period();
        let m_rows = (16 * (2 * harmonics + 1)).max(1024);
        let series = (0..=m_rows)
            .map(|j| {
                let th = std::f64::consts::TAU * j as f64 / m_rows as f64;
                let z: [f64; N] = o.fourier.state(th);
                std::iter::once(period * j as f64 / m_rows as f64)
                    .chain(real.iter().map(|&i| z[i]))
                    .collect()
            })
            .collect();
        let flow = cycle::sample_period(m, z_hb, period, opts).map_err(cycle_err)?;
        let exact = flow
            .t
            .iter()
            .zip(&flow.z)
            .map(|(t, z)| {
                std::iter::once(*t)
                    .chain(real.iter().map(|&i| z[i]))
                    .collect()
            })
            .collect();
        Some((series, exact))
    } else {
        None
    };
    let contacts: Vec<(String, [f64; 4])> = o
        .fractions
        .iter()
        .enumerate()
        .map(|(i, f)| (m.contact_name(i).to_string(), *f))
        .collect();
    let mut warnings = std::mem::take(&mut notes);
    if convergence.len() >= 2 {
        let (a, b) = (
            &convergence[convergence.len() - 2],
            &convergence[convergence.len() - 1],
        );
        let df = (b.freq_hz / a.freq_hz - 1.0).abs();
        if df > CONVERGED_FREQ || b.amplitude_change > 100.0 * CONVERGED_FREQ {
            warnings.push(format!(
                "not converged in the harmonics: from H = {} to {} the frequency changed by {df:.1e} and an amplitude by {:.1e} (relative); raise --harmonics",
                a.harmonics, b.harmonics, b.amplitude_change
            ));
        }
    }
    if !o.converged {
        warnings.push(format!(
            "Newton's method stalled at a residual of {:.2e} (tolerance {:.0e}): the orbit is approximate to that",
            o.residual,
            HbOptions::default().newton_tol
        ));
    }
    if o.sticks && !o.lagrangian {
        warnings.push(
            "a contact sticks on the orbit: harmonic balance treats stick as slip at zero speed, not as a constraint; use squeal cycle".into(),
        );
    }
    if !st.resolved {
        warnings.push(match st.reference {
            Some(trivial) => format!(
                "the stability is not resolved: the largest non-trivial multiplier, |μ| = {:.9}, is as close to the unit circle as the multipliers' own error (the trivial one, exactly 1 on an exact orbit, is {:.9}; the defect {:.1e}); `squeal cycle` computes the multipliers on the exact orbit",
                st.max, trivial, st.defect
            ),
            None => format!(
                "the stability is not resolved: the largest multiplier, |μ| = {:.9}, is within the defect {:.1e} of the unit circle",
                st.max, st.defect
            ),
        });
    }
    if st.defect > 1e-2 {
        warnings.push(format!(
            "one period of the exact model from the HB orbit misses its start by {:.2e} (scaled): the series is not yet the orbit (truncation, or stick), and the multipliers are those of a nearby trajectory; compare with squeal cycle",
            st.defect
        ));
    }
    // Hill's method where it is exact in the limit: a smooth, converged orbit.
    let hill = if o.switches == 0 && !o.sticks && !o.lagrangian && o.converged {
        match squeal_core::hb::hill::hill(m, &o) {
            Ok(h) => {
                if (h.max_multiplier - st.max).abs() > 1e-3 * st.max.max(1.0) {
                    warnings.push(format!(
                        "Hill's method gives a largest non-trivial |multiplier| of {:.9}, one exact period {:.9}: the series is truncated (raise --harmonics); the exact period's is the one to trust",
                        h.max_multiplier, st.max
                    ));
                }
                Some(HillMultipliers {
                    multipliers: h
                        .multipliers
                        .iter()
                        .enumerate()
                        .map(|(k, mu)| (mu.re, mu.im, h.trivial == Some(k)))
                        .collect(),
                    max_multiplier: h.max_multiplier,
                })
            }
            Err(e) => {
                warnings.push(format!("no multipliers by Hill's method: {e}"));
                None
            }
        }
    } else {
        None
    };
    Ok(HbFound {
        harmonics,
        period: o.period(),
        forcing_hz: match m.forcing_hz().as_slice() {
            [f] => Some(*f),
            _ => None,
        },
        amplitude: real.iter().map(|&i| amp[i]).collect(),
        series: o.fourier.clone(),
        spectrum: o
            .fourier
            .coeffs
            .iter()
            .enumerate()
            .map(|(i, co)| {
                std::iter::once(co[0])
                    .chain((1..=o.fourier.harmonics()).map(|k| o.fourier.amplitude(i, k)))
                    .collect()
            })
            .collect(),
        fractions: contacts,
        stick_constraint: o.lagrangian,
        switches: o.switches,
        panels: o.panels,
        multipliers: st.multipliers,
        stable: st.stable,
        stability_resolved: st.resolved,
        max_multiplier: st.max,
        hill,
        defect: st.defect,
        events: st.events,
        convergence,
        residual: o.residual,
        iterations: o.iterations,
        settle_time: settled,
        guess: from,
        warnings,
        orbit,
        names,
    })
}

/// The forced response of `m` (one harmonic forcing frequency): settled by
/// simulating whole forcing periods from `z0` until the state at a period's
/// start repeats to `opts.settle_tol` (scaled by each block's largest
/// value; at most `opts.settle_time`), its last period fitted as the
/// guess, then HB at `H/4`, `H/2`, `H` ([`forced_response`]) and the
/// Floquet multipliers of one exact forcing period from the HB orbit
/// (`cycle::forced_floquet`: the whole monodromy, none trivial).
#[allow(clippy::too_many_arguments)]
fn solve_forced<M: System<N> + ?Sized, const N: usize>(
    m: &M,
    any: &crate::AnyModel,
    z0: &[f64],
    harmonics: usize,
    opts: &CycleOptions,
    with_orbit: bool,
    cancel: &Cancel,
) -> Result<HbFound, StudyError> {
    let omega = forcing_omega(m)
        .map_err(hb_err)?
        .ok_or_else(|| StudyError::Input(InputError("hb: the model is not forced".into())))?;
    let period = std::f64::consts::TAU / omega;
    let real = real_states::<N>(m.norm_states());
    let n = real.len() / 2;
    let mut z = [0.0; N];
    z.copy_from_slice(z0);
    let t_a = cycle::autonomous_from(m);
    let mut t = 0.0;
    if t_a > 0.0 {
        (t, z) = cycle::advance(m, 0.0, z, t_a, opts).map_err(cycle_err)?;
    }
    let mut spent = t;
    loop {
        cancel.check()?;
        let (t1, z1) = cycle::advance(m, t, z, period, opts).map_err(cycle_err)?;
        spent += period;
        let scale = |blk: std::ops::Range<usize>| {
            blk.map(|i| z1[i].abs().max(z[i].abs()))
                .fold(f64::MIN_POSITIVE, f64::max)
        };
        let (sp, sv) = (scale(0..N / 2), scale(N / 2..N));
        let err = (0..N)
            .map(|i| (z1[i] - z[i]).abs() / if i < N / 2 { sp } else { sv })
            .fold(0.0, f64::max);
        (t, z) = (t1, z1);
        if err <= opts.settle_tol {
            break;
        }
        if spent >= opts.settle_time {
            return Err(StudyError::Numerical(format!(
                "hb: the forced response did not settle in {:.4} s simulated (the state a forcing period apart still differs by {err:.2e}, scaled; --settle-tol {:e}): raise --settle-time, or the response is not periodic with the forcing",
                spent, opts.settle_tol
            )));
        }
    }
    let orbit = cycle::sample_period(m, &z, period, opts).map_err(cycle_err)?;
    let guess = Fourier::from_orbit(&orbit, period, n, harmonics);
    let sticks = orbit
        .modes
        .iter()
        .any(|md| md.as_slice().contains(&squeal_core::Mode::Stick));
    let (o, convergence, amp, notes) = ladder(m, &guess, harmonics, &real, sticks, cancel)?;
    let z_hb: [f64; N] = o.fourier.state(0.0);
    let (list, defect, events) =
        cycle::forced_floquet(m, &z_hb, period, opts).map_err(cycle_err)?;
    let st = Stability::forced(&list, defect, events);
    finish(
        m,
        any,
        Hb {
            orbit: o,
            convergence,
            amp,
            notes,
        },
        st,
        &z_hb,
        spent,
        Guess::Settle,
        with_orbit,
        opts,
    )
}

/// The harmonic-balance orbit of a scenario with `harmonics` harmonics,
/// its guess settled from the scenario's initial state with `opts` (those
/// of `squeal cycle`, [`crate::cycle::checked_options`]); `with_orbit`:
/// also one period of the series and of the exact flow from it; `guess`:
/// where the first guess comes from ([`Guess`]).
pub fn of_scenario(
    sc: &Scenario,
    harmonics: usize,
    opts: &CycleOptions,
    guess: Guess,
    with_orbit: bool,
    cancel: &Cancel,
) -> Result<HbFound, StudyError> {
    check_harmonics(harmonics)?;
    cancel.check()?;
    crate::with_sim_system!(&sc.model, m => {
        let z0 = crate::run::initial_of(m, sc)?;
        if m.forcing_hz().is_empty() {
            solve(m, &sc.model, &z0, harmonics, opts, guess, with_orbit, cancel)
        } else if guess == Guess::Hopf {
            Err(StudyError::Input(InputError(
                "--guess hopf: the model is forced (a [[force]] with amplitude and freq_hz): its response is settled by simulating whole forcing periods".into(),
            )))
        } else {
            solve_forced(m, &sc.model, &z0, harmonics, opts, with_orbit, cancel)
        }
    }, else => Err(StudyError::Input(InputError(sc.model.check_cycle_size().err().unwrap_or_default()))))
}

impl HbFound {
    /// The JSON document: `squeal cycle`'s keys where they mean the same
    /// (`period`, `frequency_hz`, `amplitude`, `stable`, `multipliers`,
    /// `max_multiplier`, `events_per_period`) plus `freq_hz`, `harmonics`
    /// (per dof: mean, then the amplitude of each harmonic, m),
    /// `harmonic_count`, `contact_modes`, `stick_constraint`, `convergence`,
    /// `shooting_defect`, `hill` (of a smooth orbit, `multipliers` and
    /// `max_multiplier` by Hill's method; null where the orbit switches
    /// modes) and `warnings`.
    pub fn to_json(&self) -> Value {
        let mut modes = Map::new();
        for (name, f) in &self.fractions {
            modes.insert(
                name.clone(),
                json!({ "slip_pos": f[0], "slip_neg": f[1], "stick": f[2], "free": f[3] }),
            );
        }
        let convergence: Vec<Value> = self
            .convergence
            .iter()
            .map(|t| {
                json!({
                    "harmonics": t.harmonics,
                    "freq_hz": t.freq_hz,
                    "amplitude_change": if t.amplitude_change.is_finite() { json!(t.amplitude_change) } else { Value::Null },
                    "residual": t.residual,
                    "newton_iterations": t.iterations,
                })
            })
            .collect();
        json!({
            "method": "harmonic balance",
            "forced": self.forcing_hz.is_some(),
            "forcing_hz": self.forcing_hz,
            "period": self.period,
            "freq_hz": 1.0 / self.period,
            "frequency_hz": 1.0 / self.period,
            "harmonic_count": self.harmonics,
            "harmonics": named_json(&self.names, &self.spectrum),
            "amplitude": named_json(&self.names, &self.amplitude),
            "stable": self.stable,
            "stability_resolved": self.stability_resolved,
            "multipliers": multipliers_json(&self.multipliers),
            "max_multiplier": self.max_multiplier,
            "hill": self.hill.as_ref().map_or(Value::Null, |h| {
                json!({ "multipliers": multipliers_json(&h.multipliers), "max_multiplier": h.max_multiplier })
            }),
            "events_per_period": events_json(&self.events),
            "shooting_defect": self.defect,
            "contact_modes": modes,
            "stick_constraint": self.stick_constraint,
            "switches_per_period": self.switches,
            "panels": self.panels,
            "convergence": convergence,
            "residual": self.residual,
            "newton_iterations": self.iterations,
            "settle_time": self.settle_time,
            "guess": self.guess.as_str(),
            "warnings": self.warnings,
        })
    }
}

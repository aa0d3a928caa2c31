//! Continuation of harmonic-balance solutions in one parameter `p`, through
//! folds: the frequency-response curve of a forced model (`p` its forcing
//! frequency, or its amplitude, or any model parameter) and the branch of
//! a self-excited orbit.
//!
//! A point of the branch is `X = (x, p̃)`: the scaled unknowns of the HB
//! equations `R(x; p) = 0` ([`super`]: the coefficients, and `ω` with the
//! phase condition for an autonomous model) and the parameter in grid
//! spacings, `p = p₀ + p̃·Δp`. The branch is followed by pseudo-arclength
//! continuation (Keller 1977; Allgower & Georg 1990, §2.2): the tangent
//! `t` solves `[∂R/∂X; t_prevᵀ] t = (0, 1)` (normalised, its orientation
//! kept), the predictor is `X̂ = X + Δs t`, and the corrector is Newton's
//! method on `R(X) = 0, tᵀ(X − X̂) = 0`, so it passes folds where `p`
//! turns back and a natural-parameter corrector would fail. The Jacobian is
//! by forward differences (the `p` column through the model rebuilt at
//! `p + δ`). The step grows by half after an easy corrector (≤ 3
//! iterations), shrinks after a hard one, halves after a failure, and is at
//! most one grid spacing `Δp` in the scaled metric. A fold is where the
//! tangent's `p` component changes sign; it is located on the parabola
//! `p(s)` through the three points around it (chord arclength). The last
//! point is solved at the range's end exactly.
//!
//! A self-excited branch may also start at a Hopf point inside the range
//! ([`BranchStart::Hopf`]), where it is born from steady sliding with zero
//! amplitude: entered at two small first-harmonic amplitudes with the
//! parameter free (Kuznetsov, *Elements of Applied Bifurcation Theory*,
//! §3.4: `p − p_h ∝ A²` on either side), then followed as above.

use super::{
    forced_scales, forcing_omega, harmonic_amplitudes, newton, Balance, Fourier, HbError,
    HbOptions, HbOrbit, Layout,
};
use crate::cycle::continuation::Family;
use nalgebra::{DMatrix, DVector};

/// A unit tangent's `p` component below this is round-off (no fold sign).
const DP_ROUNDOFF: f64 = 1e-6;

/// Settings of [`hb_branch`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HbBranchOptions {
    /// The HB settings (harmonics, panels, Newton tolerance).
    pub hb: HbOptions,
    /// Most points of the branch.
    pub max_points: usize,
    /// Smallest step (grid spacings, scaled metric) before giving up.
    pub min_step: f64,
    /// Largest step (grid spacings, scaled metric).
    pub max_step: f64,
    /// The first step (grid spacings, scaled metric; at most `max_step`):
    /// small where the branch starts at a corner (the start of stick),
    /// where the tangent of the branch left behind points the wrong way.
    pub first_step: f64,
}

impl Default for HbBranchOptions {
    fn default() -> Self {
        HbBranchOptions {
            hb: HbOptions::default(),
            max_points: 2000,
            min_step: 1e-4,
            max_step: 1.0,
            first_step: 1.0,
        }
    }
}

/// One point of an HB branch.
#[derive(Debug, Clone)]
pub struct HbPoint {
    /// The parameter.
    pub p: f64,
    /// The orbit there.
    pub orbit: HbOrbit,
    /// The `p` component of the unit tangent (scaled): its sign changes at a fold.
    pub dp_ds: f64,
}

/// Why a branch ended.
#[derive(Debug, Clone, PartialEq)]
pub enum HbBranchEnd {
    /// At the range's end.
    Reached,
    /// The branch turned back and left the range at its start.
    LeftRange,
    /// The orbit shrank onto the steady state (a Hopf point near `p`).
    Collapsed(f64),
    /// No step down to the smallest converged, at `p`.
    Stalled(f64, String),
    /// [`HbBranchOptions::max_points`] reached.
    MaxPoints,
}

/// Where a branch starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BranchStart {
    /// The solution given, solved at `p = lo`.
    Lo,
    /// A Hopf point `p_h` of an autonomous model inside the range: the
    /// solution given is the small orbit `q* + A·Re(φ e^{iωt})` of the
    /// critical mode there (its largest first-harmonic amplitude `A`), and
    /// `scale` (m, > `A`) the amplitude in which the branch's coefficients
    /// are measured (where that motion first meets a nonlinearity, say).
    /// The branch is entered at the first-harmonic amplitudes `A` and `2A`
    /// with `p` free (`R(x; p) = 0` and `a₁ = A` of the phase dof; near a
    /// Hopf point `p − p_h ∝ A²`, so this finds super- and subcritical
    /// branches alike), and followed from `2A` in the direction of growing
    /// amplitude.
    Hopf {
        /// The Hopf point.
        p_h: f64,
        /// The amplitude scale (m).
        scale: f64,
    },
}

/// A branch of HB solutions.
#[derive(Debug, Clone)]
pub struct HbBranch {
    /// The points in the order followed.
    pub points: Vec<HbPoint>,
    /// The folds: `(index of the point before it, p at the fold)`.
    pub folds: Vec<(usize, f64)>,
    /// Why it ended.
    pub end: HbBranchEnd,
}

/// Follow the HB solution `start` (solved at `p = lo`, by
/// [`super::harmonic_balance`] or [`super::forced_response`]; resized to
/// `opts.hb.harmonics` harmonics) of the family `family` from `lo` to
/// `hi`, the grid spacing `(hi − lo)/(steps − 1)` setting the largest
/// step (module documentation).
pub fn hb_branch<const N: usize>(
    family: &(dyn Family<N> + Sync),
    lo: f64,
    hi: f64,
    steps: usize,
    start: &Fourier,
    opts: &HbBranchOptions,
) -> Result<HbBranch, HbError> {
    hb_branch_from(family, lo, hi, steps, start, BranchStart::Lo, opts)
}

/// [`hb_branch`] from where `from` says: `lo`, or a Hopf point inside the
/// range ([`BranchStart::Hopf`]).
pub fn hb_branch_from<const N: usize>(
    family: &(dyn Family<N> + Sync),
    lo: f64,
    hi: f64,
    steps: usize,
    start: &Fourier,
    from: BranchStart,
    opts: &HbBranchOptions,
) -> Result<HbBranch, HbError> {
    if !(lo.is_finite() && hi.is_finite() && lo != hi && steps >= 2) {
        return Err(HbError::Bad(format!(
            "the range {lo}:{hi}:{steps}: needs two different ends and at least 2 steps"
        )));
    }
    let dp = (hi - lo) / (steps - 1) as f64;
    let end = (steps - 1) as f64;
    let h = opts.hb.harmonics;
    let mut f0 = start.resized(h);
    let n = f0.coeffs.len();
    let mut forced = None;
    family
        .visit(lo, &mut |sys| forced = Some(forcing_omega(sys)))
        .map_err(HbError::Bad)?;
    let forced = forced.expect("visited")?;
    if forced.is_some() && from != BranchStart::Lo {
        return Err(HbError::Bad(
            "a forced model's branch has no Hopf point to start from".into(),
        ));
    }
    let lay = if forced.is_some() {
        Layout {
            n,
            h,
            panels: opts.hb.panel_count(),
            scale: forced_scales(&f0, 1.0),
            omega0: f0.omega,
            phase_dof: None,
            mode: None,
            lagrangian: opts.hb.lagrangian.then_some(opts.hb.lagrangian_weight),
        }
    } else {
        let amp = harmonic_amplitudes(&f0);
        let top = amp.iter().cloned().fold(0.0, f64::max);
        let phase_dof = (0..n)
            .max_by(|&a, &b| f0.amplitude(a, 1).total_cmp(&f0.amplitude(b, 1)))
            .unwrap_or(0);
        // The time origin where the phase condition holds (free for an
        // autonomous orbit).
        f0 = f0.shifted(f0.coeffs[phase_dof][2].atan2(f0.coeffs[phase_dof][1]));
        // From a Hopf point the orbit is measured in the given scale, not
        // in its own (small) size.
        let grow = match from {
            BranchStart::Hopf { scale, .. } if top > 0.0 => (scale / top).max(1.0),
            _ => 1.0,
        };
        Layout {
            n,
            h,
            panels: opts.hb.panel_count(),
            scale: amp.iter().map(|a| grow * a.max(1e-6 * top)).collect(),
            omega0: f0.omega,
            phase_dof: Some(phase_dof),
            mode: None,
            lagrangian: opts.hb.lagrangian.then_some(opts.hb.lagrangian_weight),
        }
    };
    let m = lay.unknowns();
    let autonomous = lay.phase_dof.is_some();
    let param = |pt: f64| lo + pt * dp;
    // R(x; p) at X = (x, p̃).
    let residual = |xx: &[f64], out: &mut [f64]| {
        let mut done = false;
        let _ = family.visit(param(xx[m]), &mut |sys| {
            if let Ok(bal) = Balance::new(sys, &lay) {
                bal.residual(&xx[..m], &mut out[..m]);
                done = true;
            }
        });
        if !done {
            out[..m].fill(f64::NAN);
        }
    };
    // ∂R/∂X, m × (m + 1).
    let jacobian = |xx: &[f64], r: &[f64], differences: bool| -> DMatrix<f64> {
        let p = param(xx[m]);
        let mut jx = DMatrix::<f64>::from_element(m, m, f64::NAN);
        let _ = family.visit(p, &mut |sys| {
            if let Ok(bal) = Balance::new(sys, &lay) {
                jx = bal.jacobian(&xx[..m], &r[..m], differences);
            }
        });
        let dh = 1e-7 * xx[m].abs().max(1.0);
        let mut xp = xx.to_vec();
        xp[m] += dh;
        let mut rp = vec![0.0; m];
        residual(&xp, &mut rp);
        let mut j = DMatrix::<f64>::zeros(m, m + 1);
        j.view_mut((0, 0), (m, m)).copy_from(&jx);
        for i in 0..m {
            j[(i, m)] = (rp[i] - r[i]) / dh;
        }
        j
    };
    let tangent = |xx: &[f64], prev: &DVector<f64>| -> Option<DVector<f64>> {
        let mut r = vec![0.0; m];
        residual(xx, &mut r);
        let j = jacobian(xx, &r, false);
        let mut a = DMatrix::<f64>::zeros(m + 1, m + 1);
        a.view_mut((0, 0), (m, m + 1)).copy_from(&j);
        for c in 0..=m {
            a[(m, c)] = prev[c];
        }
        let mut b = DVector::<f64>::zeros(m + 1);
        b[m] = 1.0;
        let t = a.lu().solve(&b)?;
        let norm = t.norm();
        (norm.is_finite() && norm > 0.0).then(|| {
            let t = t / norm;
            if t.dot(prev) < 0.0 {
                -t
            } else {
                t
            }
        })
    };
    let point = |xx: &[f64], residual: f64, iterations: usize, converged: bool, dp_ds: f64| {
        let mut out = None;
        let _ = family.visit(param(xx[m]), &mut |sys| {
            if let Ok(bal) = Balance::new(sys, &lay) {
                out = Some(bal.orbit(&xx[..m], residual, iterations, converged));
            }
        });
        out.map(|orbit| HbPoint {
            p: param(xx[m]),
            orbit,
            dp_ds,
        })
    };
    let admissible = |xx: &[f64]| !autonomous || xx[m - 1] > 0.0;
    let mut x: Vec<f64> = lay.to_x(&f0);
    let mut t_prev = DVector::<f64>::zeros(m + 1);
    match from {
        BranchStart::Lo => {
            x.push(0.0);
            t_prev[m] = 1.0;
        }
        BranchStart::Hopf { p_h, .. } => {
            let k = lay.phase_dof.expect("autonomous");
            // The first-harmonic cosine of the phase dof (scaled): fixed.
            let ia = k * lay.width() + 1;
            let at = |xx: &[f64], a: f64| {
                let fixed = |xs: &[f64], o: &mut [f64]| {
                    residual(xs, &mut o[..m]);
                    o[m] = xs[ia] - a;
                };
                let fixed_jac = |xs: &[f64], r: &[f64], d: bool| {
                    let mut j = DMatrix::<f64>::zeros(m + 1, m + 1);
                    j.view_mut((0, 0), (m, m + 1))
                        .copy_from(&jacobian(xs, r, d));
                    j[(m, ia)] = 1.0;
                    j
                };
                newton(
                    &fixed,
                    &fixed_jac,
                    &admissible,
                    xx.to_vec(),
                    opts.hb.newton_tol,
                    opts.hb.newton_iterations,
                    "the branch's start at the Hopf point",
                )
            };
            let p_hs = (p_h - lo) / dp;
            x.push(p_hs);
            let a1 = x[ia];
            let s1 = at(&x, a1)?;
            // Twice the amplitude: every harmonic doubled, p − p_h four times.
            let mut x2 = s1.x.clone();
            for i in 0..n {
                for c in 1..lay.width() {
                    x2[i * lay.width() + c] *= 2.0;
                }
            }
            x2[m] = p_hs + 4.0 * (s1.x[m] - p_hs);
            let s2 = at(&x2, 2.0 * a1)?;
            for i in 0..=m {
                t_prev[i] = s2.x[i] - s1.x[i];
            }
            let norm = t_prev.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(HbError::NotConverged(
                    "no direction out of the Hopf point".into(),
                ));
            }
            t_prev /= norm;
            x = s2.x;
        }
    }
    let mut t = tangent(&x, &t_prev)
        .ok_or_else(|| HbError::NotConverged("no tangent at the branch's start".into()))?;
    let mut r0 = vec![0.0; m];
    residual(&x, &mut r0);
    let res0 = super::max_abs(&r0);
    if res0.is_nan() || res0 > super::STALLED * opts.hb.newton_tol {
        return Err(HbError::NotConverged(format!(
            "the start is not a solution at {} (residual {res0:.3e})",
            param(x[m])
        )));
    }
    let first = point(&x, res0, 0, res0 <= opts.hb.newton_tol, t[m])
        .ok_or_else(|| HbError::Bad(format!("the model at {}", param(x[m]))))?;
    let amp_of = |o: &HbOrbit| {
        harmonic_amplitudes(&o.fourier)
            .into_iter()
            .fold(0.0, f64::max)
    };
    let mut a_max = amp_of(&first.orbit);
    let mut out = HbBranch {
        points: vec![first],
        folds: Vec::new(),
        end: HbBranchEnd::MaxPoints,
    };
    let mut s_hist = vec![0.0f64];
    let mut sig_dp = if t[m].abs() > DP_ROUNDOFF { t[m] } else { 0.0 };
    let mut ds = opts.first_step.min(opts.max_step);
    let tol = opts.hb.newton_tol;
    while out.points.len() < opts.max_points {
        let pred: Vec<f64> = x.iter().zip(t.iter()).map(|(a, b)| a + ds * b).collect();
        let tc = t.clone();
        let xc = pred.clone();
        let aug = |xx: &[f64], o: &mut [f64]| {
            residual(xx, o);
            o[m] = (0..=m).map(|i| tc[i] * (xx[i] - xc[i])).sum();
        };
        let aug_jac = |xx: &[f64], r: &[f64], d: bool| {
            let j = jacobian(xx, r, d);
            let mut a = DMatrix::<f64>::zeros(m + 1, m + 1);
            a.view_mut((0, 0), (m, m + 1)).copy_from(&j);
            for c in 0..=m {
                a[(m, c)] = tc[c];
            }
            a
        };
        let solved = newton(&aug, &aug_jac, &admissible, pred, tol, 12, "continuation");
        let Ok(sol) = solved else {
            ds *= 0.5;
            if ds < opts.min_step {
                out.end = HbBranchEnd::Stalled(
                    param(x[m]),
                    solved.err().map(|e| e.to_string()).unwrap_or_default(),
                );
                break;
            }
            continue;
        };
        let mut xn = sol.x;
        let (mut res, mut its, mut conv) = (sol.residual, sol.iterations, sol.converged);
        let past_end = xn[m] > end;
        if past_end {
            // The range's end, exactly: natural-parameter Newton from the
            // chord between the last point and this one.
            let w = (end - x[m]) / (xn[m] - x[m]);
            let mut guess: Vec<f64> = x.iter().zip(&xn).map(|(a, b)| a + w * (b - a)).collect();
            guess[m] = end;
            let fixed = |xs: &[f64], o: &mut [f64]| {
                let mut full = xs.to_vec();
                full.push(end);
                residual(&full, o);
            };
            let fixed_jac = |xs: &[f64], r: &[f64], d: bool| {
                let mut jx = DMatrix::<f64>::from_element(m, m, f64::NAN);
                let _ = family.visit(param(end), &mut |sys| {
                    if let Ok(bal) = Balance::new(sys, &lay) {
                        jx = bal.jacobian(xs, r, d);
                    }
                });
                jx
            };
            match newton(
                &fixed,
                &fixed_jac,
                &|xs: &[f64]| !autonomous || xs[m - 1] > 0.0,
                guess[..m].to_vec(),
                tol,
                opts.hb.newton_iterations,
                "continuation's end",
            ) {
                Ok(s) => {
                    xn = s.x;
                    xn.push(end);
                    (res, its, conv) = (s.residual, s.iterations, s.converged);
                }
                Err(_) => {
                    ds *= 0.5;
                    if ds < opts.min_step {
                        out.end = HbBranchEnd::Stalled(param(x[m]), "at the range's end".into());
                        break;
                    }
                    continue;
                }
            }
        }
        let Some(tn) = tangent(&xn, &t) else {
            ds *= 0.5;
            if ds < opts.min_step {
                out.end = HbBranchEnd::Stalled(param(x[m]), "no tangent".into());
                break;
            }
            continue;
        };
        let Some(pt) = point(&xn, res, its, conv, tn[m]) else {
            out.end = HbBranchEnd::Stalled(param(xn[m]), "the model rejects the parameter".into());
            break;
        };
        let chord = xn
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        s_hist.push(s_hist.last().copied().unwrap_or(0.0) + chord);
        let amp = amp_of(&pt.orbit);
        a_max = a_max.max(amp);
        out.points.push(pt);
        let k = out.points.len() - 1;
        // A fold where dp/ds changes sign; components at round-off (a
        // branch leaving a Hopf point vertically, where the model is linear
        // below its first nonlinearity) carry no sign.
        let turned = tn[m].abs() > DP_ROUNDOFF && sig_dp * tn[m] < 0.0;
        if tn[m].abs() > DP_ROUNDOFF {
            sig_dp = tn[m];
        }
        if turned && k >= 2 {
            // The fold: the extreme of the parabola p(s) through the last three points.
            let (s0, s1, s2) = (s_hist[k - 2], s_hist[k - 1], s_hist[k]);
            let (p0, p1, p2) = (out.points[k - 2].p, out.points[k - 1].p, out.points[k].p);
            let d01 = (p1 - p0) / (s1 - s0);
            let d12 = (p2 - p1) / (s2 - s1);
            let c2 = (d12 - d01) / (s2 - s0);
            let c1 = d01 - c2 * (s0 + s1);
            let pf = if c2 != 0.0 {
                let sf = (-c1 / (2.0 * c2)).clamp(s0, s2);
                p0 + d01 * (sf - s0) + c2 * (sf - s0) * (sf - s1)
            } else {
                p1
            };
            out.folds.push((k - 1, pf));
        }
        x = xn;
        t = tn;
        if past_end {
            out.end = HbBranchEnd::Reached;
            break;
        }
        if x[m] < 0.0 {
            out.end = HbBranchEnd::LeftRange;
            break;
        }
        if autonomous && amp < 1e-3 * a_max {
            out.end = HbBranchEnd::Collapsed(param(x[m]));
            break;
        }
        ds = if its <= 3 {
            (ds * 1.5).min(opts.max_step)
        } else if its > 6 {
            ds * 0.7
        } else {
            ds
        };
    }
    Ok(out)
}

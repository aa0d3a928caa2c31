//! Complex eigenvalue analysis of a state matrix of any size (the "CEA" of
//! FE packages): every eigenvalue, its eigenvector, the mode attribution and
//! the complex mode shape, for a first-order state matrix `A` whose size is
//! known only at run time (lumped models from a file, matrices exported from
//! an FE package).
//!
//! Two dense solvers, chosen by size:
//!
//! - up to [`SMALL_MAX`] states: the hand-written path of [`super::eigen`]
//!   (Parlett–Reinsch balancing, Householder–Hessenberg, Francis double-shift
//!   QR, inverse iteration per eigenvalue) on a runtime-sized [`Workspace`].
//!   It performs exactly the operations of the fixed-size [`super::analyse`],
//!   so a built-in model gives the same eigenvalues bit for bit;
//! - above: balancing as above, then faer's real non-symmetric
//!   eigendecomposition (blocked Hessenberg reduction, multishift QR with
//!   aggressive early deflation, eigenvectors by back-substitution on the
//!   Schur form; sequential, `Par::Seq`), eigenvectors mapped back `u = D ũ`.
//!   Inverse iteration costs O(n³) per eigenvalue and would be O(n⁴) in all;
//!   the Schur route is O(n³) in all.
//!
//! **Mode shapes** ([`mode_shape`]): for a mechanical state `z = (q, q̇)` with
//! `n` coordinates, the position part `q = (u_0 … u_{n−1})` of the
//! eigenvector, scaled so that its largest component (the first, on ties) is
//! real and equal to 1: each coordinate's amplitude is in `[0, 1]` and its
//! phase (degrees, in `(−180, 180]`) is measured from that coordinate (0
//! for an entry below [`PHASE_FLOOR`], zero to working precision). The
//! velocity part is `λ·q` and carries no further information.

use super::eigen::{self, Workspace};
use super::{is_growing, Analysis, Eigen, StabilityError};
use nalgebra::{Complex, DMatrix};

/// An eigenvalue and its right eigenvector.
pub type EigenPair = (Complex<f64>, Vec<Complex<f64>>);

/// Largest state dimension solved by the hand-written balanced Francis QR +
/// inverse iteration; larger matrices go to faer (see the module docs).
pub const SMALL_MAX: usize = 64;

/// Every eigenvalue of `a` with its right eigenvector (unit 2-norm, largest
/// component real positive), in the order the solver returns them
/// (conjugate pairs adjacent). `a` must be square and finite.
///
/// Errors: [`StabilityError::BadInput`] for a non-square matrix,
/// [`StabilityError::NonFinite`] for NaN or infinite entries,
/// [`StabilityError::NoConvergence`] if QR does not converge.
pub fn eigenpairs(a: &DMatrix<f64>) -> Result<Vec<EigenPair>, StabilityError> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(StabilityError::BadInput(format!(
            "state matrix is {} × {}, not square",
            a.nrows(),
            a.ncols()
        )));
    }
    if a.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "Jacobian" });
    }
    if n == 0 {
        return Ok(Vec::new());
    }
    // Row-major copy: the layout of the fixed-size path.
    let rows: Vec<f64> = (0..n * n).map(|k| a[(k / n, k % n)]).collect();
    if n <= SMALL_MAX {
        let (mut ws, ev) = Workspace::eigenvalues(&rows, n).ok_or(StabilityError::NoConvergence)?;
        super::check_finite(&ev)?;
        let mut out: Vec<EigenPair> = Vec::with_capacity(n);
        for (k, &lambda) in ev.iter().enumerate() {
            // The second of a conjugate pair (adjacent, exactly conjugate) has
            // the conjugate eigenvector: as in `super::analyse`.
            let u = match out.last() {
                Some((_, prev)) if k > 0 && lambda.im != 0.0 && ev[k - 1] == lambda.conj() => {
                    prev.iter().map(|c| c.conj()).collect()
                }
                _ => ws.eigenvector(lambda),
            };
            out.push((lambda, u));
        }
        Ok(out)
    } else {
        large_eigenpairs(rows, n)
    }
}

/// Every eigenvalue of `a`, without eigenvectors: the same solvers and
/// errors as [`eigenpairs`] (identical values up to [`SMALL_MAX`] states;
/// above, faer's eigenvalue-only QR, equal to round-off).
pub fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, StabilityError> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(StabilityError::BadInput(format!(
            "state matrix is {} × {}, not square",
            a.nrows(),
            a.ncols()
        )));
    }
    if a.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite { what: "Jacobian" });
    }
    let mut rows: Vec<f64> = (0..n * n).map(|k| a[(k / n, k % n)]).collect();
    if n <= SMALL_MAX {
        let ev = Workspace::eigenvalues(&rows, n)
            .map(|(_, ev)| ev)
            .ok_or(StabilityError::NoConvergence)?;
        super::check_finite(&ev)?;
        return Ok(ev);
    }
    let mut d = vec![1.0; n];
    eigen::balance_flat(&mut rows, n, &mut d);
    let (_, s_re, s_im) = faer_evd(&rows, n, false)?;
    (0..n)
        .map(|j| {
            let (re, im) = (s_re[j], s_im[j]);
            if re.is_finite() && im.is_finite() {
                Ok(Complex::new(re, im))
            } else {
                Err(StabilityError::NoConvergence)
            }
        })
        .collect()
}

/// faer's real non-symmetric eigendecomposition of the row-major `n × n`
/// matrix `rows`, sequential: right eigenvectors (if `vectors`; faer's real
/// packing: a conjugate pair's columns hold Re and Im of the vector of the
/// `+` eigenvalue), and the real and imaginary parts of the eigenvalues.
#[allow(clippy::type_complexity)]
fn faer_evd(
    rows: &[f64],
    n: usize,
    vectors: bool,
) -> Result<(Option<faer::Mat<f64>>, Vec<f64>, Vec<f64>), StabilityError> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{self, ComputeEigenvectors};
    use faer::{Mat, Par};
    let b = Mat::<f64>::from_fn(n, n, |i, j| rows[i * n + j]);
    let mut u = vectors.then(|| Mat::<f64>::zeros(n, n));
    let mut s_re = faer::diag::Diag::<f64>::zeros(n);
    let mut s_im = faer::diag::Diag::<f64>::zeros(n);
    let par = Par::Seq;
    let want = if vectors {
        ComputeEigenvectors::Yes
    } else {
        ComputeEigenvectors::No
    };
    let scratch =
        evd::evd_scratch::<f64>(n, ComputeEigenvectors::No, want, par, Default::default());
    evd::evd_real(
        b.as_ref(),
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        u.as_mut().map(|u| u.as_mut()),
        par,
        MemStack::new(&mut MemBuffer::new(scratch)),
        Default::default(),
    )
    .map_err(|_| StabilityError::NoConvergence)?;
    let re = (0..n).map(|j| s_re[j]).collect();
    let im = (0..n).map(|j| s_im[j]).collect();
    Ok((u, re, im))
}

/// The faer path of [`eigenpairs`] for `n > SMALL_MAX`.
fn large_eigenpairs(mut rows: Vec<f64>, n: usize) -> Result<Vec<EigenPair>, StabilityError> {
    let mut d = vec![1.0; n];
    eigen::balance_flat(&mut rows, n, &mut d);
    let (u, s_re, s_im) = faer_evd(&rows, n, true)?;
    drop(rows);
    let u = u.expect("eigenvectors were asked for");
    let mut out = Vec::with_capacity(n);
    let mut j = 0;
    while j < n {
        let (re, im) = (s_re[j], s_im[j]);
        if !(re.is_finite() && im.is_finite()) {
            return Err(StabilityError::NoConvergence);
        }
        if im == 0.0 || j + 1 == n {
            let mut x: Vec<Complex<f64>> = (0..n)
                .map(|i| Complex::new(u[(i, j)] * d[i], 0.0))
                .collect();
            eigen::normalise(&mut x);
            out.push((Complex::new(re, 0.0), x));
            j += 1;
        } else {
            // A conjugate pair: columns j, j+1 hold Re and Im of the vector of re + i·im.
            let mut x: Vec<Complex<f64>> = (0..n)
                .map(|i| Complex::new(u[(i, j)] * d[i], u[(i, j + 1)] * d[i]))
                .collect();
            eigen::normalise(&mut x);
            let xc: Vec<Complex<f64>> = x.iter().map(|c| c.conj()).collect();
            out.push((Complex::new(re, im), x));
            out.push((Complex::new(re, -im), xc));
            j += 2;
        }
    }
    Ok(out)
}

/// Full complex eigenvalue analysis of a state matrix of any size: the same
/// [`Analysis`] as [`super::analyse`] (eigenvalues by growth rate descending,
/// `+ω` first on ties; mode attribution by energy share; eigenvectors of
/// unit 2-norm, largest component real positive).
///
/// - `a`: the state matrix `A = ∂f/∂z` at `z`, state `z = (q, q̇)` with
///   `n = dim/2` position coordinates first (the dimension must be even);
/// - `z`: the equilibrium (stored in [`Analysis::equilibrium`]), `dim` values;
/// - `state_names`: `dim` names; [`Eigen::dominant_name`] is one of the first
///   `n`;
/// - `masses`: `n` finite positive masses for the energy shares
///   ([`Eigen::participation`]), or `None` for unit masses.
///
/// Up to [`SMALL_MAX`] states the eigenvalues equal those of
/// [`super::analyse`] on the same matrix bit for bit; above, faer solves
/// (see the module docs). Errors name the bad input
/// ([`StabilityError::BadInput`]), or are [`StabilityError::NonFinite`] /
/// [`StabilityError::NoConvergence`].
pub fn analyse_matrix(
    a: &DMatrix<f64>,
    z: &[f64],
    state_names: &[String],
    masses: Option<&[f64]>,
) -> Result<Analysis, StabilityError> {
    let dim = a.nrows();
    if a.ncols() != dim || !dim.is_multiple_of(2) {
        return Err(StabilityError::BadInput(format!(
            "state matrix is {} × {}: need a square matrix of even size (positions, then velocities)",
            a.nrows(),
            a.ncols()
        )));
    }
    if z.len() != dim || state_names.len() != dim {
        return Err(StabilityError::BadInput(format!(
            "state matrix is {dim} × {dim} but the equilibrium has {} values and there are {} state names",
            z.len(),
            state_names.len()
        )));
    }
    if z.iter().any(|x| !x.is_finite()) {
        return Err(StabilityError::NonFinite {
            what: "equilibrium",
        });
    }
    if let Some(m) = masses {
        if m.len() != dim / 2 || m.iter().any(|m| !(m.is_finite() && *m > 0.0)) {
            return Err(StabilityError::BadInput(format!(
                "masses must be {} finite positive values, got {m:?}",
                dim / 2
            )));
        }
    }
    let pairs = eigenpairs(a)?;
    let modes = pairs
        .into_iter()
        .map(|(lambda, u)| describe(lambda, u, masses, state_names))
        .collect();
    Ok(finish(modes, z.to_vec()))
}

/// The [`Eigen`] description of eigenvalue `lambda` with eigenvector `u`
/// (already normalised): frequency, damping ratio, growth verdict, energy
/// shares and dominant coordinate (see [`Eigen::participation`]).
pub(crate) fn describe<S: AsRef<str>>(
    lambda: Complex<f64>,
    u: Vec<Complex<f64>>,
    masses: Option<&[f64]>,
    names: &[S],
) -> Eigen {
    let n = u.len() / 2;
    let mag = lambda.norm();
    let mut e: Vec<f64> = (0..n)
        .map(|i| {
            let m = masses.map_or(1.0, |m| m[i]);
            m * (u[n + i].norm_sqr() + mag * mag * u[i].norm_sqr())
        })
        .collect();
    let mut total: f64 = e.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        e = (0..n).map(|i| u[i].norm_sqr()).collect();
        total = e.iter().sum();
    }
    if total > 0.0 {
        e.iter_mut().for_each(|x| *x /= total);
    }
    let dominant = (0..n).max_by(|&i, &j| e[i].total_cmp(&e[j])).unwrap_or(0);
    Eigen {
        re: lambda.re,
        im: lambda.im,
        freq_hz: lambda.im.abs() / (2.0 * std::f64::consts::PI),
        damping_ratio: if mag > 0.0 { -lambda.re / mag } else { 0.0 },
        growing: is_growing(lambda.re, lambda.im),
        neutral: super::is_neutral(lambda.re, lambda.im),
        dominant,
        dominant_name: names
            .get(dominant)
            .map_or(String::new(), |s| s.as_ref().to_string()),
        participation: e,
        vector: u,
    }
}

/// Sort the modes (growth rate descending, `+ω` first) and assemble the
/// [`Analysis`].
pub(crate) fn finish(mut modes: Vec<Eigen>, equilibrium: Vec<f64>) -> Analysis {
    modes.sort_by(|p, q| q.re.total_cmp(&p.re).then(q.im.total_cmp(&p.im)));
    let growing = modes.iter().any(|m| m.growing);
    let neutral = !growing && modes.iter().any(|m| m.neutral);
    let stable = !growing && !neutral;
    Analysis {
        neutral,
        max_growth_rate: modes.first().map_or(f64::NEG_INFINITY, |m| m.re),
        stable,
        least_stable: 0,
        equilibrium,
        eigen: modes,
        // Dense (the default); the projected analysis sets its own.
        method: Default::default(),
    }
}

/// The complex mode shape of a mode: the position part `q` of its
/// eigenvector (the first half of [`Eigen::vector`]) divided by its largest
/// component (the first, on ties), so that component is exactly `1 + 0i` and
/// every amplitude `|q_i| ≤ 1`. All zeros if the position part vanishes.
pub fn mode_shape(mode: &Eigen) -> Vec<Complex<f64>> {
    let n = mode.vector.len() / 2;
    let q = &mode.vector[..n];
    let mut big = 0;
    for i in 0..n {
        if q[i].norm() > q[big].norm() {
            big = i;
        }
    }
    match q.get(big) {
        Some(&r) if r.norm() > 0.0 => q.iter().map(|c| c / r).collect(),
        _ => vec![Complex::new(0.0, 0.0); n],
    }
}

/// Amplitude and phase (degrees, `(−180, 180]`) of each entry of a
/// [`mode_shape`]. An entry with amplitude below [`PHASE_FLOOR`] is zero to
/// working precision: its phase would be round-off and is reported as 0.
pub fn amplitude_phase(shape: &[Complex<f64>]) -> Vec<(f64, f64)> {
    shape
        .iter()
        .map(|c| {
            let amp = c.norm();
            let phase = if amp > PHASE_FLOOR {
                c.arg().to_degrees()
            } else {
                0.0
            };
            // arg ∈ [−π, π]: fold −180 onto +180.
            (amp, if phase <= -180.0 { 180.0 } else { phase })
        })
        .collect()
}

/// Relative amplitude (to the reference entry, 1) below which a mode-shape
/// entry's phase is not reported ([`amplitude_phase`]): ≈ 5000 ε, the
/// round-off of an eigenvector component that is exactly zero.
pub const PHASE_FLOOR: f64 = 1e-12;

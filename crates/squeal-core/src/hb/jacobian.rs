//! The Jacobian of the HB equations, assembled from the model's own field
//! instead of one residual evaluation per unknown.
//!
//! The residual of dof `i`, basis function `j` (module [`super`]) is
//! `R_ij = (−ω²k_j² c_ij − P_ij)/(ω₀² s_i)` with the projections
//! `P_ij = Σ_pieces ∫ (a_i(z(θ)) + ξ v_i) ψ_j(θ) dθ` of the accelerations
//! over the smooth pieces of the period (`ψ₀ = 1/2π`, `ψ_j = φ_j/π`). On a
//! piece the modes are fixed and `a` is smooth in the state, so with
//! `q_l = Σ_c c_lc φ_c(θ)` and `v_l = ω Σ_c c_lc φ_c'(θ)`:
//!
//! ```text
//! ∂P_ij/∂c_lc = ∫ ψ_j (A^q_il φ_c + (A^v_il + ξ δ_il) ω φ_c') dθ,
//! ∂P_ij/∂ω    = ∫ ψ_j Σ_l (A^v_il + ξ δ_il) v_l/ω dθ,      ∂P_ij/∂ξ = ∫ ψ_j v_i dθ,
//! ```
//!
//! with `A^q = ∂a/∂q`, `A^v = ∂a/∂v` at each quadrature node (central
//! differences of the field in its piece's modes: `4n` field evaluations a
//! node, where differencing the whole residual costs `n(2H+1)` residuals),
//! each `(i, l)` block from the moments `∫ A_il cos kθ`, `∫ A_il sin kθ`
//! (`k ≤ 2H`) by the product-to-sum identities ([`Moments`]).
//! Where the modes change at a switching phase `θ_s` the force jumps (a slip
//! reversal) and the piece ends move with the unknowns: Leibniz's rule adds
//! `−Δa_i ψ_j(θ_s) ∂θ_s/∂X`, with `Δa` the field's jump across `θ_s` and
//! `∂θ_s/∂X = −(∂g/∂X)/(dg/dθ)` from the guard `g` that vanishes there (the
//! implicit-function theorem on `g(z(θ_s; X)) = 0`). This is the analytic
//! AFT Jacobian of Krack & Gross (2019), §3.3, extended by the switch terms
//! that the exact switch location (rather than sampling) needs.
//!
//! The dynamic Lagrangian step (stick as a constraint) makes the field a
//! function of the series' own derivatives and its mode rules are not
//! guards: there, and wherever a switch cannot be matched to a guard (a
//! grazing one, say), the Jacobian is by finite differences of the whole
//! residual, as before.

use super::{fd_jacobian, Balance, Fourier, Piece, GAUSS};
use crate::model::{Guards, Modes, System};
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// A switch is matched to a guard whose zero lies within this phase (rad).
const SWITCH_MATCH: f64 = 1e-8;

/// One quadrature node: its phase, weight, and the field's derivatives there.
pub(super) struct Node {
    pub(super) theta: f64,
    pub(super) weight: f64,
    /// `∂a_i/∂q_l`, row-major `n × n`.
    pub(super) aq: Vec<f64>,
    /// `∂a_i/∂v_l + ξ δ_il`, row-major `n × n`.
    pub(super) av: Vec<f64>,
    /// The velocities `v_l`.
    v: Vec<f64>,
}

/// `φ_c(θ)` and `φ_c'(θ)` for `c = 0 … 2H` (`1, cos θ, sin θ, cos 2θ, …`).
pub(super) fn basis(theta: f64, h: usize, phi: &mut [f64], dphi: &mut [f64]) {
    let (s1, c1) = theta.sin_cos();
    let (mut ck, mut sk) = (1.0, 0.0);
    phi[0] = 1.0;
    dphi[0] = 0.0;
    for k in 1..=h {
        let (cn, sn) = (ck * c1 - sk * s1, sk * c1 + ck * s1);
        ck = cn;
        sk = sn;
        let kf = k as f64;
        phi[2 * k - 1] = ck;
        phi[2 * k] = sk;
        dphi[2 * k - 1] = -kf * sk;
        dphi[2 * k] = kf * ck;
    }
}

/// The test functions `ψ_j` of the Galerkin projection from `φ`.
pub(super) fn test_functions(phi: &[f64], psi: &mut [f64]) {
    psi[0] = 1.0 / TAU;
    for (p, f) in psi.iter_mut().zip(phi).skip(1) {
        *p = f / PI;
    }
}

/// `cos kθ`, `sin kθ` for `k = 0 … 2H` at one phase (angle addition).
pub(super) struct Trig {
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl Trig {
    pub(super) fn new(h: usize) -> Self {
        Trig {
            cos: vec![0.0; 2 * h + 1],
            sin: vec![0.0; 2 * h + 1],
        }
    }

    pub(super) fn at(&mut self, theta: f64) {
        let (s1, c1) = theta.sin_cos();
        self.cos[0] = 1.0;
        self.sin[0] = 0.0;
        for k in 1..self.cos.len() {
            let (c, s) = (self.cos[k - 1], self.sin[k - 1]);
            self.cos[k] = c * c1 - s * s1;
            self.sin[k] = s * c1 + c * s1;
        }
    }
}

/// The moments `C_k = ∫ g cos kθ`, `S_k = ∫ g sin kθ` (`k = 0 … 2H`) of a
/// function `g` on the period, accumulated node by node. From them every
/// Galerkin product `∫ g φ_j φ_c ψ` of the `(2H+1)²` pairs follows by the
/// product-to-sum identities, so a block of the Jacobian costs
/// `O(nodes·H + H²)` rather than `O(nodes·H²)`.
#[derive(Clone)]
pub(super) struct Moments {
    c: Vec<f64>,
    s: Vec<f64>,
}

/// Basis index → (is a sine, harmonic): `0 → (cos, 0)`, `2k−1 → (cos, k)`,
/// `2k → (sin, k)`.
fn kind(idx: usize) -> (bool, usize) {
    (idx > 0 && idx.is_multiple_of(2), idx.div_ceil(2))
}

impl Moments {
    pub(super) fn new(h: usize) -> Self {
        Moments {
            c: vec![0.0; 2 * h + 1],
            s: vec![0.0; 2 * h + 1],
        }
    }

    /// Add `g = value` at the phase of `trig` (`value` carries the weight).
    pub(super) fn add(&mut self, trig: &Trig, value: f64) {
        for (m, t) in self.c.iter_mut().zip(&trig.cos) {
            *m += value * t;
        }
        for (m, t) in self.s.iter_mut().zip(&trig.sin) {
            *m += value * t;
        }
    }

    /// `∫ g φ_j φ_c dθ`.
    fn product(&self, j: usize, c: usize) -> f64 {
        let ((sj, kj), (sc, kc)) = (kind(j), kind(c));
        let sum = kj + kc;
        let d = kj as isize - kc as isize;
        let cd = self.c[d.unsigned_abs()];
        let sd = if d >= 0 {
            self.s[d as usize]
        } else {
            -self.s[(-d) as usize]
        };
        match (sj, sc) {
            (false, false) => 0.5 * (cd + self.c[sum]),
            (false, true) => 0.5 * (self.s[sum] - sd),
            (true, false) => 0.5 * (self.s[sum] + sd),
            (true, true) => 0.5 * (cd - self.c[sum]),
        }
    }

    /// `∫ g ψ_j φ_c dθ` (`ψ₀ = 1/2π`, `ψ_j = φ_j/π`).
    pub(super) fn galerkin(&self, j: usize, c: usize) -> f64 {
        let scale = if j == 0 { 1.0 / TAU } else { 1.0 / PI };
        scale * self.product(j, c)
    }

    /// `∫ g ψ_j φ_c' dθ`: `(cos kθ)' = −k sin kθ`, `(sin kθ)' = k cos kθ`.
    pub(super) fn galerkin_rate(&self, j: usize, c: usize) -> f64 {
        let (sc, kc) = kind(c);
        if kc == 0 {
            return 0.0;
        }
        let k = kc as f64;
        if sc {
            k * self.galerkin(j, 2 * kc - 1)
        } else {
            -k * self.galerkin(j, 2 * kc)
        }
    }
}

impl<S: System<N> + ?Sized, const N: usize> Balance<'_, S, N> {
    /// The Jacobian of [`Balance::residual`] at `x` (residual `r`): assembled
    /// (module documentation) where it can be, else by finite differences.
    pub(crate) fn jacobian(&self, x: &[f64], r: &[f64], differences: bool) -> DMatrix<f64> {
        if self.lay.lagrangian.is_none() && !differences {
            if let Some(j) = self.assembled(x) {
                return j;
            }
        }
        fd_jacobian(&|x: &[f64], out: &mut [f64]| self.residual(x, out), x, r)
    }

    /// The Jacobian by central differences of the whole residual (the
    /// reference the assembled one is tested against).
    #[cfg(test)]
    pub(crate) fn central(&self, x: &[f64], step: f64) -> DMatrix<f64> {
        let m = x.len();
        let mut jac = DMatrix::<f64>::zeros(m, m);
        let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
        for c in 0..m {
            let mut xp = x.to_vec();
            let dh = step * x[c].abs().max(1.0);
            xp[c] = x[c] + dh;
            self.residual(&xp, &mut rp);
            xp[c] = x[c] - dh;
            self.residual(&xp, &mut rm);
            for r in 0..m {
                jac[(r, c)] = (rp[r] - rm[r]) / (2.0 * dh);
            }
        }
        jac
    }

    /// The field's derivatives at phase `theta` in `modes`.
    pub(super) fn node(
        &self,
        f: &Fourier,
        theta: f64,
        weight: f64,
        modes: &Modes,
        xi: f64,
    ) -> Node {
        let (n, h) = (self.lay.n, N / 2);
        let z: [f64; N] = f.state(theta);
        let t = self.time(f.omega, theta);
        let mut aq = vec![0.0; n * n];
        let mut av = vec![0.0; n * n];
        let (mut up, mut down) = ([0.0; N], [0.0; N]);
        // Steps on the model's own scale of motion: a tiny orbit about a
        // large static state (near a Hopf point) is still differenced on the
        // scale of that state, where a law such as μ(V − v) resolves it.
        let reach = (0..n)
            .map(|l| z[l].abs().max(self.lay.scale[l]))
            .fold(0.0, f64::max);
        for l in 0..n {
            let q_scale = z[l].abs().max(self.lay.scale[l]).max(1e-3 * reach);
            for (col, at, floor) in [(&mut aq, l, q_scale), (&mut av, h + l, f.omega * q_scale)] {
                // Central differences: O(step²) in a nonlinear law,
                // round-off ~1e-10 of the field.
                let step = 1e-6 * z[at].abs().max(floor);
                let mut zs = z;
                zs[at] = z[at] + step;
                self.sys.field(t, modes, &zs, &mut up);
                zs[at] = z[at] - step;
                self.sys.field(t, modes, &zs, &mut down);
                for i in 0..n {
                    col[i * n + l] = (up[h + i] - down[h + i]) / (2.0 * step);
                }
            }
            av[l * n + l] += xi;
        }
        Node {
            theta,
            weight,
            aq,
            av,
            v: z[h..h + n].to_vec(),
        }
    }

    /// Every quadrature node of `pieces` with the field's derivatives there
    /// (in parallel; each node alone, so the result does not depend on the
    /// thread count).
    pub(super) fn nodes(&self, f: &Fourier, pieces: &[Piece], xi: f64) -> Vec<Node> {
        let mut at: Vec<(f64, f64, Modes)> = Vec::with_capacity(4 * pieces.len());
        for pc in pieces {
            let (mid, half) = (0.5 * (pc.a + pc.b), 0.5 * (pc.b - pc.a));
            if half > 0.0 {
                at.extend(
                    GAUSS
                        .iter()
                        .map(|&(xg, wg)| (mid + half * xg, half * wg, pc.modes)),
                );
            }
        }
        at.par_iter()
            .map(|(th, wt, modes)| self.node(f, *th, *wt, modes, xi))
            .collect()
    }

    /// `∂θ_s/∂X` of the switch at `theta` from `ma` to `mb` over the
    /// coefficients (unscaled, `n(2H+1)` entries) and ω (last entry), or
    /// `None` if no guard of either mode vanishes there.
    fn switch_rate(&self, f: &Fourier, theta: f64, ma: &Modes, mb: &Modes) -> Option<Vec<f64>> {
        let (n, h, w) = (self.lay.n, self.lay.h, self.lay.width());
        let at = |th: f64| -> ([f64; N], f64) { (f.state(th), self.time(f.omega, th)) };
        let (z, t) = at(theta);
        let delta = 1e-6;
        let (zp, tp) = at(theta + delta);
        let (zm, tm) = at(theta - delta);
        let mut guards = Guards::<N>::default();
        let mut best: Option<(f64, f64, [f64; N])> = None;
        for modes in [ma, mb] {
            self.sys.mode_guards(modes, &mut guards);
            for g in guards.as_slice() {
                let value = self.sys.guard_value(t, modes, g, &z);
                let rate = (self.sys.guard_value(tp, modes, g, &zp)
                    - self.sys.guard_value(tm, modes, g, &zm))
                    / (2.0 * delta);
                let dist = (value / rate).abs();
                if dist.is_finite() && best.is_none_or(|(d, _, _)| dist < d) {
                    best = Some((dist, rate, self.sys.guard_gradient(t, modes, g, &z)));
                }
            }
        }
        let (dist, rate, grad) = best?;
        if dist > SWITCH_MATCH {
            return None;
        }
        let mut phi = vec![0.0; w];
        let mut dphi = vec![0.0; w];
        basis(theta, h, &mut phi, &mut dphi);
        let half = N / 2;
        let mut out = vec![0.0; n * w + 1];
        for l in 0..n {
            for c in 0..w {
                out[l * w + c] = -(grad[l] * phi[c] + grad[half + l] * f.omega * dphi[c]) / rate;
            }
        }
        let dg_domega: f64 = (0..n).map(|l| grad[half + l] * z[half + l] / f.omega).sum();
        out[n * w] = -dg_domega / rate;
        Some(out)
    }

    /// The assembled Jacobian (module documentation), or `None` where a
    /// switch has no guard to differentiate.
    fn assembled(&self, x: &[f64]) -> Option<DMatrix<f64>> {
        let lay = self.lay;
        let (n, h, w) = (lay.n, lay.h, lay.width());
        let m = lay.unknowns();
        let autonomous = lay.phase_dof.is_some();
        let f = self.to_fourier(x);
        let omega = f.omega;
        let xi = match lay.mode {
            Some(_) => x[n * w + 1] * lay.omega0,
            None => 0.0,
        };
        let pieces: Vec<Piece> = self.pieces(&f);
        let nodes = self.nodes(&f, &pieces, xi);
        // ∂P/∂(c, ω, ξ): rows i·w + j, columns as x's (unscaled).
        let blocks: Vec<Vec<f64>> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut blk = vec![0.0; w * m];
                let (mut phi, mut dphi, mut psi) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
                let mut trig = Trig::new(h);
                // The moments of A^q_il and ω A^v_il, one dof l at a time.
                let mut mq = vec![Moments::new(h); n];
                let mut mv = vec![Moments::new(h); n];
                for nd in &nodes {
                    trig.at(nd.theta);
                    let mut d_omega = 0.0;
                    for l in 0..n {
                        let (aq, av) = (nd.aq[i * n + l], nd.av[i * n + l]);
                        if aq == 0.0 && av == 0.0 {
                            continue;
                        }
                        d_omega += av * nd.v[l] / omega;
                        mq[l].add(&trig, nd.weight * aq);
                        mv[l].add(&trig, nd.weight * av * omega);
                    }
                    if autonomous || lay.mode.is_some() {
                        basis(nd.theta, h, &mut phi, &mut dphi);
                        test_functions(&phi, &mut psi);
                        for (j, pj) in psi.iter().enumerate() {
                            if autonomous {
                                blk[j * m + n * w] += nd.weight * pj * d_omega;
                            }
                            if lay.mode.is_some() {
                                blk[j * m + n * w + 1] += nd.weight * pj * nd.v[i];
                            }
                        }
                    }
                }
                for l in 0..n {
                    for j in 0..w {
                        let row = &mut blk[j * m + l * w..j * m + (l + 1) * w];
                        for (c, r) in row.iter_mut().enumerate() {
                            *r = mq[l].galerkin(j, c) + mv[l].galerkin_rate(j, c);
                        }
                    }
                }
                blk
            })
            .collect();
        let mut dp = DMatrix::<f64>::zeros(n * w, m);
        for (i, blk) in blocks.iter().enumerate() {
            for j in 0..w {
                for c in 0..m {
                    dp[(i * w + j, c)] = blk[j * m + c];
                }
            }
        }
        // The switches: −Δa_i ψ_j(θ_s) ∂θ_s/∂X.
        let (mut phi, mut dphi, mut psi) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
        for (k, pc) in pieces.iter().enumerate() {
            let Some(next) = pieces.get(k + 1) else {
                break;
            };
            if next.modes == pc.modes {
                continue;
            }
            let theta = pc.b;
            let rate = self.switch_rate(&f, theta, &pc.modes, &next.modes)?;
            let z: [f64; N] = f.state(theta);
            let t = self.time(omega, theta);
            let (mut before, mut after) = ([0.0; N], [0.0; N]);
            self.sys.field(t, &pc.modes, &z, &mut before);
            self.sys.field(t, &next.modes, &z, &mut after);
            basis(theta, h, &mut phi, &mut dphi);
            test_functions(&phi, &mut psi);
            for i in 0..n {
                let jump = after[N / 2 + i] - before[N / 2 + i];
                if jump == 0.0 {
                    continue;
                }
                for (j, pj) in psi.iter().enumerate() {
                    let s = -jump * pj;
                    for c in 0..n * w {
                        dp[(i * w + j, c)] += s * rate[c];
                    }
                    if autonomous {
                        dp[(i * w + j, n * w)] += s * rate[n * w];
                    }
                }
            }
        }
        // The residual's own terms and the scaling of rows and unknowns.
        let mut jac = DMatrix::<f64>::zeros(m, m);
        let norm = lay.omega0 * lay.omega0;
        let order = |j: usize| j.div_ceil(2) as f64;
        for i in 0..n {
            let row_scale = 1.0 / (norm * lay.scale[i]);
            for j in 0..w {
                let r = i * w + j;
                for l in 0..n {
                    for c in 0..w {
                        jac[(r, l * w + c)] = -dp[(r, l * w + c)] * lay.scale[l] * row_scale;
                    }
                }
                let kk = order(j) * order(j);
                jac[(r, r)] -= omega * omega * kk * lay.scale[i] * row_scale;
                if autonomous {
                    let c_ij = f.coeffs[i][j];
                    jac[(r, n * w)] =
                        (-2.0 * omega * kk * c_ij - dp[(r, n * w)]) * lay.omega0 * row_scale;
                }
                if lay.mode.is_some() {
                    jac[(r, n * w + 1)] = -dp[(r, n * w + 1)] * lay.omega0 * row_scale;
                }
            }
        }
        if let Some(mn) = &lay.mode {
            // The phase φᵀM b₁/A and amplitude (a₁ᵀMa₁ + b₁ᵀMb₁)/A² − 1.
            let a2 = mn.amplitude * mn.amplitude;
            for l in 0..n {
                jac[(n * w, l * w + 2)] = mn.m_phi[l] * lay.scale[l] / mn.amplitude;
                for c in [1, 2] {
                    let s: f64 = (0..n)
                        .map(|j| (mn.mass[(l, j)] + mn.mass[(j, l)]) * f.coeffs[j][c])
                        .sum();
                    jac[(n * w + 1, l * w + c)] = s * lay.scale[l] / a2;
                }
            }
        } else if let Some(d) = lay.phase_dof {
            jac[(n * w, d * w + 2)] = 1.0;
        }
        Some(jac)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{HbOptions, Layout};
    use super::*;
    use crate::cycle::{self, find_cycle, CycleOptions};

    /// The largest difference between the assembled Jacobian and central
    /// differences (relative `step`) of the residual at `x`, relative to the
    /// largest entry of its column.
    fn deviation<S: System<N>, const N: usize>(
        bal: &Balance<'_, S, N>,
        x: &[f64],
        step: f64,
    ) -> f64 {
        let ja = bal.assembled(x).expect("every switch has its guard");
        let jc = bal.central(x, step);
        (0..ja.ncols())
            .map(|c| {
                let scale = jc.column(c).amax().max(1e-12);
                (ja.column(c) - jc.column(c)).amax() / scale
            })
            .fold(0.0, f64::max)
    }

    /// The assembled Jacobian against central differences (relative step
    /// `steps`) of the residual at the Fourier fit of the shooting cycle of
    /// `sys` (switches included): for each step, the largest difference
    /// relative to the largest entry of its column; and the switches.
    fn worst<S: System<N>, const N: usize>(sys: &S, h: usize, steps: &[f64]) -> (Vec<f64>, usize) {
        let mut z = sys.steady_sliding().unwrap();
        z[0] += 1e-4;
        let cyc = find_cycle(sys, 0.0, z, &CycleOptions::default()).unwrap();
        let o = cycle::orbit(sys, &cyc, &CycleOptions::default()).unwrap();
        let n = sys.norm_states() / 2;
        let f = Fourier::from_orbit(&o, cyc.period, n, h);
        let amp = |i: usize| (1..=h).map(|k| f.amplitude(i, k)).fold(0.0, f64::max);
        let top = (0..n).map(amp).fold(0.0, f64::max);
        let lay = Layout {
            n,
            h,
            panels: HbOptions {
                harmonics: h,
                ..HbOptions::default()
            }
            .panel_count(),
            scale: (0..n).map(|i| amp(i).max(1e-6 * top)).collect(),
            omega0: f.omega,
            phase_dof: Some(0),
            mode: None,
            lagrangian: None,
        };
        let bal = Balance::<S, N>::new(sys, &lay).unwrap();
        let x = lay.to_x(&f);
        let errors = steps
            .iter()
            .map(|&step| deviation(&bal, &x, step))
            .collect();
        let switches = bal.orbit(&x, 0.0, 0, true).switches;
        (errors, switches)
    }

    /// Slip reversals (the disc–pad's cycle: the friction force jumps twice
    /// a period, the switch terms carry the jumps). The switching phases
    /// move strongly with the high harmonics (the sliding velocity crosses
    /// zero at a shallow slope), so central differences converge to the
    /// assembled Jacobian only as their step falls: measured 1.6e-3 at a
    /// step of 1e-5, 1.2e-4 at 1e-6 (round-off from there on).
    #[test]
    fn assembled_equals_finite_differences_across_reversals() {
        let (e, s) = worst(&crate::DiscPad::default(), 10, &[1e-5, 1e-6]);
        eprintln!("disc-pad: {e:?}, {s} switches");
        assert!(s >= 2, "{s} switches");
        assert!(e[1] < 3e-4 && e[1] < 0.2 * e[0], "{e:?}");
    }

    /// Contact loss (Hoffmann's model): the normal force has a kink, the
    /// friction force vanishes with it.
    #[test]
    fn assembled_equals_finite_differences_across_contact_loss() {
        let (e, s) = worst(&crate::Hoffmann::default(), 10, &[1e-5, 1e-6]);
        eprintln!("Hoffmann: {e:?}, {s} switches");
        assert!(s >= 2, "{s} switches");
        assert!(e[0] < 1e-7 && e[1] < 1e-7, "{e:?}");
    }

    /// A forced Coulomb oscillator (`ẍ + x + 0.2 sign ẋ = cos 0.8t`, the
    /// model's time runs with the phase) and a nonlinear mode's layout (the
    /// damping ξ and the mode's phase and amplitude conditions) on
    /// Hoffmann's model.
    #[test]
    fn assembled_equals_finite_differences_forced_and_for_a_mode() {
        use crate::model::lumped::{ContactSpec, ForceSpec, LumpedSpec, SpringSpec};
        let x = || vec![("x".to_string(), 1.0)];
        let spec = LumpedSpec {
            dofs: vec!["x".into()],
            masses: vec![("x".into(), 1.0)],
            springs: vec![SpringSpec {
                name: "spring".into(),
                on: x(),
                k: 1.0,
                c: 0.0,
                k3: 0.0,
            }],
            forces: vec![ForceSpec {
                name: "shaker".into(),
                on: x(),
                value: 0.0,
                ramp: 0.0,
                amplitude: 1.0,
                freq_hz: 0.8 / TAU,
            }],
            contacts: vec![ContactSpec {
                name: "rub".into(),
                normal: None,
                k: None,
                c: None,
                bilateral: false,
                normal_force: Some(0.2),
                tangent: Some(x()),
                v: 0.0,
                friction: crate::FrictionLaw::Coulomb {
                    mu_s: 1.0,
                    mu_k: 1.0,
                },
                alpha: 0.0,
                slope: Vec::new(),
            }],
            ..LumpedSpec::default()
        };
        let sys = crate::Lumped::build(&spec).unwrap();
        let h = 8;
        let lay = Layout {
            n: 1,
            h,
            panels: 136,
            scale: vec![2.0],
            omega0: 0.8,
            phase_dof: None,
            mode: None,
            lagrangian: None,
        };
        let bal = Balance::<_, 2>::new(&sys, &lay).unwrap();
        // x = 2.6 cos θ + 0.3 sin θ + 0.05 cos 3θ: two reversals a period.
        let mut coeffs = vec![0.0; 2 * h + 1];
        (coeffs[1], coeffs[2], coeffs[5]) = (2.6, 0.3, 0.05);
        let f = Fourier {
            omega: 0.8,
            coeffs: vec![coeffs],
        };
        let x = lay.to_x(&f);
        assert_eq!(bal.orbit(&x, 0.0, 0, true).switches, 2);
        let e = deviation(&bal, &x, 1e-6);
        assert!(e < 1e-6, "forced: {e:.3e}");

        let sys = crate::Hoffmann::default();
        let mut z = sys.steady_sliding().unwrap();
        z[0] += 1e-4;
        let cyc = find_cycle(&sys, 0.0, z, &CycleOptions::default()).unwrap();
        let o = cycle::orbit(&sys, &cyc, &CycleOptions::default()).unwrap();
        let f = Fourier::from_orbit(&o, cyc.period, 2, h);
        let mass = DMatrix::from_row_slice(2, 2, &[1.0, 0.2, 0.2, 2.0]);
        let lay = Layout {
            n: 2,
            h,
            panels: 136,
            scale: vec![f.amplitude(0, 1), f.amplitude(1, 1)],
            omega0: f.omega,
            phase_dof: Some(0),
            mode: Some(super::super::ModeNorm {
                m_phi: vec![1.0, 0.7],
                amplitude: 0.9 * f.amplitude(0, 1),
                mass,
            }),
            lagrangian: None,
        };
        let bal = Balance::<_, 4>::new(&sys, &lay).unwrap();
        let mut x = lay.to_x(&f);
        x[2 * (2 * h + 1) + 1] = 0.03;
        let e = deviation(&bal, &x, 1e-6);
        assert!(e < 1e-6, "mode: {e:.3e}");
    }
}

//! Steady sliding of a lumped model: the equilibrium with every velocity
//! zero and every closed contact sliding in the direction of its `V`
//! (docs/physics.md, "Steady sliding of a lumped model").
//!
//! With `q̇ = 0` the force balance is, for a set `S` of closed contacts
//! (a unilateral contact closed, or a bilateral one carrying friction),
//!
//! ```text
//! A_S q = b + λ Σ_{i∈S} α_i s_i μ_i k_i (n_i·q)(σ_i·q) n_i
//! A_S = K + Σ_springs k a aᵀ + Σ_{elastic} k_i n_i n_iᵀ + Σ_{i∈S} s_i μ_i k_i t_i n_iᵀ
//! ```
//!
//! (`s_i = sign V_i`, `μ_i = μ(|V_i|)`, `b` the constant forces and the
//! friction of prescribed loads; a bilateral layer's normal spring acts
//! whether or not it carries friction, an open unilateral one not at all).
//! Without follower force (`α = 0`) this is one sparse linear solve per
//! contact set. Which set is the right one is a complementarity problem:
//! a closed contact must push (`F_n = k n·q ≥ 0`), an open one must not
//! penetrate (`n·q ≤ 0`). The sets are searched by a primal–dual active-set
//! iteration from "all closed" (flip every inconsistent contact), and if that
//! revisits a set, by enumeration of every set in order of fewer open
//! contacts (at most 2⁸), which cannot cycle. With follower forces the
//! quadratic term is followed by continuation in `λ` from 0 (the linear
//! solution) to 1, Newton-corrected; where the step falls below 1e-10 the
//! steady state folds away and the fold's `λ` is reported.
//!
//! Every tolerance is relative to the problem: consistency of a contact to
//! 1e-9 of the largest force in the balance, the solve checked by its scaled
//! residual, singularity by the equilibrated system's condition.

use super::{Lumped, ModelError, Normal};

/// A contact's force below this fraction of the balance's largest force
/// counts as zero when deciding open or closed (round-off).
const CONTACT_TOL: f64 = 1e-9;

/// An equilibrated system whose solution shows a condition number above
/// this is singular (1/(2000 ε): three digits above round-off).
const SINGULAR_COND: f64 = 2.2e12;

/// Models up to this size are solved dense (nalgebra), larger ones with
/// faer's sparse LU.
const DENSE_SOLVE_DOFS: usize = 64;

/// Why one contact set has no steady sliding.
#[derive(Debug, Clone)]
enum SetFailure {
    /// The stiffness of this set is singular; the dofs that move freely.
    Singular(String),
    /// The follower forces fold the steady state away at this `λ`.
    Fold(f64),
}

/// Why a contact set failed: the contacts it contradicts (`(contact,
/// F_n)`), or no solution.
type Verdict = Result<Vec<(usize, f64)>, SetFailure>;

/// The result of one contact set: the positions and the contacts whose
/// state contradicts the solution (`(contact, F_n)`).
struct SetSolution {
    q: Vec<f64>,
    wrong: Vec<(usize, f64)>,
}

impl Lumped {
    /// Steady sliding `z = (q, 0)`: every contact that touches slides in the
    /// direction of its `V`; unilateral contacts that would pull are open.
    /// See the module docs for the method. Errors name the contact that
    /// must open, the dofs left free or the follower force's fold.
    pub fn equilibrium_dyn(&self) -> Result<Vec<f64>, ModelError> {
        if let Some(c) = self.contacts.iter().find(|c| c.v == 0.0) {
            return Err(ModelError::NoSteadySliding(format!(
                "contact '{}': V = 0 (the surface must move)",
                c.name
            )));
        }
        let switchable: Vec<usize> = (0..self.contacts.len())
            .filter(|&i| matches!(self.contacts[i].normal, Normal::Elastic { .. }))
            .collect();
        let all: u32 = switchable.iter().fold(0, |m, &i| m | (1 << i));
        let mut tried = vec![false; 1 << self.contacts.len()];
        // The sets of the active-set iteration, with why each failed.
        let mut failed: Vec<(u32, Verdict)> = Vec::new();
        let mut mask = all;
        // Primal–dual active set from "all closed".
        loop {
            tried[mask as usize] = true;
            match self.solve_set(mask) {
                Ok(s) if s.wrong.is_empty() => return Ok(self.finish(s.q)),
                Ok(s) => {
                    let flip = s.wrong.iter().fold(0u32, |m, (i, _)| m | (1 << i));
                    failed.push((mask, Ok(s.wrong)));
                    mask ^= flip;
                    if tried[mask as usize] {
                        break;
                    }
                }
                Err(e) => {
                    failed.push((mask, Err(e)));
                    break;
                }
            }
        }
        // Enumeration: fewer open contacts first, then in contact order.
        let mut sets: Vec<u32> = (0..=all).filter(|m| m & !all == 0).collect();
        sets.sort_by_key(|m| ((all & !m).count_ones(), *m));
        for m in sets {
            if tried[m as usize] {
                continue;
            }
            tried[m as usize] = true;
            if let Ok(s) = self.solve_set(m) {
                if s.wrong.is_empty() {
                    return Ok(self.finish(s.q));
                }
            }
        }
        let lead = if matches!(failed.first(), Some((_, Ok(_)))) {
            "no consistent set of open and closed contacts: "
        } else {
            ""
        };
        let why: Vec<String> = failed
            .into_iter()
            .take(2)
            .map(|(m, w)| self.explain(m, w))
            .collect();
        Err(ModelError::NoSteadySliding(format!(
            "{lead}{}",
            why.join("; ")
        )))
    }

    /// The modes of steady sliding at `z` (from
    /// [`Lumped::equilibrium_dyn`]): slip in the direction of each
    /// contact's `V`, free where a unilateral contact is open (`F_n ≤ 0`).
    pub fn steady_modes_at(&self, z: &[f64]) -> crate::model::Modes {
        self.sliding_modes_at(z)
    }

    /// `z = (q, 0)` from the positions.
    fn finish(&self, q: Vec<f64>) -> Vec<f64> {
        let n = self.dofs.len();
        let mut z = q;
        z.resize(2 * n, 0.0);
        z
    }

    /// One line on why there is no steady sliding, from the first set tried.
    fn explain(&self, mask: u32, why: Verdict) -> String {
        let open: Vec<&str> = (0..self.contacts.len())
            .filter(|&i| {
                matches!(self.contacts[i].normal, Normal::Elastic { .. }) && mask & (1 << i) == 0
            })
            .map(|i| self.contacts[i].name.as_str())
            .collect();
        let with = if open.is_empty() {
            "with every contact closed".to_string()
        } else {
            format!("with {} open", quoted(&open))
        };
        match why {
            Err(SetFailure::Singular(dofs)) => format!(
                "the stiffness at steady sliding is singular {with}: {dofs} freely \
                 (a rigid-body mode: is every dof held by a spring, a matrix or a closed contact?)"
            ),
            Err(SetFailure::Fold(lambda)) => {
                let alphas: Vec<String> = self
                    .contacts
                    .iter()
                    .filter(|c| c.alpha != 0.0)
                    .map(|c| format!("{}.alpha = {}", c.name, crate::params::short(c.alpha)))
                    .chain(
                        self.springs
                            .iter()
                            .filter(|s| s.k3 != 0.0)
                            .map(|s| format!("{}.k3 = {}", s.name, crate::params::short(s.k3))),
                    )
                    .collect();
                format!(
                    "the follower force (or cubic spring) folds the steady state away {with}: \
                     it exists up to {lambda:.4} of the given nonlinearity ({}) and not beyond",
                    alphas.join(", ")
                )
            }
            Ok(wrong) => {
                let parts: Vec<String> = wrong
                    .iter()
                    .map(|&(i, f)| {
                        let c = &self.contacts[i];
                        if mask & (1 << i) != 0 {
                            format!("'{}' would pull (F_n = {:.3e} N)", c.name, f)
                        } else {
                            format!("'{}' would penetrate (F_n = {:.3e} N)", c.name, f)
                        }
                    })
                    .collect();
                format!("{with}, {}", parts.join(", "))
            }
        }
    }

    /// The sliding direction `s = sign V` and `μ(|V|)` of contact `i`.
    fn steady_friction(&self, i: usize) -> (f64, f64) {
        let c = &self.contacts[i];
        let s = if c.v >= 0.0 { 1.0 } else { -1.0 };
        (s, c.friction.mu(c.v.abs()))
    }

    /// The linear part `(A_S, b)` of the balance for the contact set `mask`
    /// (bit `i` set: contact `i` closed / carrying friction), `A` as
    /// unsorted triplets.
    fn steady_linear(&self, mask: u32) -> (Vec<(usize, usize, f64)>, Vec<f64>) {
        let n = self.dofs.len();
        let mut a: Vec<(usize, usize, f64)> = Vec::new();
        let mut b = vec![0.0; n];
        for f in &self.forces {
            f.on.add_scaled(&mut b, f.value * f.factor(f64::INFINITY));
        }
        for s in &self.springs {
            outer(&mut a, &s.on.idx, &s.on.coef, &s.on.idx, &s.on.coef, s.k);
        }
        if let Some(k) = &self.k_matrix {
            a.extend(k.entries());
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let (s, mu) = self.steady_friction(i);
            match &c.normal {
                Normal::Prescribed(f_n) => c.tangent.add_scaled(&mut b, -s * mu * f_n),
                Normal::Elastic {
                    normal,
                    k,
                    bilateral,
                    ..
                } => {
                    let closed = mask & (1 << i) != 0;
                    if closed || *bilateral {
                        outer(
                            &mut a,
                            &normal.idx,
                            &normal.coef,
                            &normal.idx,
                            &normal.coef,
                            *k,
                        );
                    }
                    if closed {
                        let t = &c.tangent;
                        outer(
                            &mut a,
                            &t.idx,
                            &t.coef,
                            &normal.idx,
                            &normal.coef,
                            s * mu * k,
                        );
                    }
                }
            }
        }
        for i in 0..n {
            // A structural zero on the diagonal would hide a free dof from
            // the sparse factorisation's pattern: keep the entry.
            a.push((i, i, 0.0));
        }
        (a, b)
    }

    /// Follower forces `λ Σ α s μ k (n·q)(σ·q) n` of the closed contacts
    /// added to `r`, and, if `jac` is given, `−∂/∂q` of them appended to it
    /// as triplets (the Jacobian of `A q − b − follower`).
    fn follower(
        &self,
        mask: u32,
        lambda: f64,
        q: &[f64],
        r: &mut [f64],
        mut jac: Option<&mut Vec<(usize, usize, f64)>>,
    ) {
        // Cubic springs: −λ k3 e³ a (their linear part is in A).
        for s in self.springs.iter().filter(|s| s.k3 != 0.0) {
            let e = s.on.dot(q);
            s.on.add_scaled(r, -lambda * s.k3 * e * e * e);
            if let Some(j) = jac.as_deref_mut() {
                let g = 3.0 * lambda * s.k3 * e * e;
                outer(j, &s.on.idx, &s.on.coef, &s.on.idx, &s.on.coef, g);
            }
        }
        for (i, c) in self.contacts.iter().enumerate() {
            if c.alpha == 0.0 || mask & (1 << i) == 0 {
                continue;
            }
            let Normal::Elastic { normal, k, .. } = &c.normal else {
                continue;
            };
            let (s, mu) = self.steady_friction(i);
            let g = lambda * c.alpha * s * mu * k;
            let (dn, ds) = (normal.dot(q), c.slope.dot(q));
            normal.add_scaled(r, g * dn * ds);
            if let Some(j) = jac.as_deref_mut() {
                outer(
                    j,
                    &normal.idx,
                    &normal.coef,
                    &normal.idx,
                    &normal.coef,
                    -g * ds,
                );
                outer(
                    j,
                    &normal.idx,
                    &normal.coef,
                    &c.slope.idx,
                    &c.slope.coef,
                    -g * dn,
                );
            }
        }
    }

    /// Whether any closed contact of `mask` has a follower force, or a
    /// spring is cubic (both followed from the linear solution).
    fn has_follower(&self, mask: u32) -> bool {
        self.springs.iter().any(|s| s.k3 != 0.0)
            || self
                .contacts
                .iter()
                .enumerate()
                .any(|(i, c)| c.alpha != 0.0 && mask & (1 << i) != 0)
    }

    /// Steady sliding for one contact set, and the contacts it contradicts.
    fn solve_set(&self, mask: u32) -> Result<SetSolution, SetFailure> {
        let (a, b) = self.steady_linear(mask);
        let mut q = solve(self, &a, &b)?;
        if self.has_follower(mask) {
            q = self.continue_follower(mask, &a, &b, q)?;
        }
        // The largest force in the balance, for the contact tolerance.
        let mut scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for c in &self.contacts {
            if let Normal::Elastic { normal, k, .. } = &c.normal {
                scale = scale.max((k * normal.dot(&q)).abs());
            }
        }
        let tol = CONTACT_TOL * scale;
        let mut wrong = Vec::new();
        for (i, c) in self.contacts.iter().enumerate() {
            let Normal::Elastic { normal, k, .. } = &c.normal else {
                continue;
            };
            let f_n = k * normal.dot(&q);
            let closed = mask & (1 << i) != 0;
            if (closed && f_n < -tol) || (!closed && f_n > tol) {
                wrong.push((i, f_n));
            }
        }
        Ok(SetSolution { q, wrong })
    }

    /// Follow the follower forces from `λ = 0` (`q0`) to `λ = 1` by
    /// natural-parameter continuation with a tangent predictor and Newton
    /// correction; a step below 1e-10 is a fold.
    fn continue_follower(
        &self,
        mask: u32,
        a: &[(usize, usize, f64)],
        b: &[f64],
        q0: Vec<f64>,
    ) -> Result<Vec<f64>, SetFailure> {
        let n = q0.len();
        let mut q = q0;
        let (mut lambda, mut step) = (0.0f64, 1.0f64);
        // d(residual)/dλ at q: the follower forces at λ = 1.
        let dlambda = |q: &[f64]| {
            let mut r = vec![0.0; n];
            self.follower(mask, 1.0, q, &mut r, None);
            r
        };
        while lambda < 1.0 {
            if step < 1e-10 {
                return Err(SetFailure::Fold(lambda));
            }
            let target = (lambda + step).min(1.0);
            // Tangent predictor: J dq/dλ = follower(q).
            let mut jac = a.to_vec();
            self.follower(mask, lambda, &q, &mut vec![0.0; n], Some(&mut jac));
            let pred = match solve(self, &jac, &dlambda(&q)) {
                Ok(t) => t,
                Err(_) => {
                    step /= 4.0;
                    continue;
                }
            };
            let mut x: Vec<f64> = q
                .iter()
                .zip(&pred)
                .map(|(qi, ti)| qi + (target - lambda) * ti)
                .collect();
            if self.newton(mask, a, b, target, &mut x) {
                q = x;
                lambda = target;
                step = (step * 2.0).min(1.0);
            } else {
                step /= 4.0;
            }
        }
        Ok(q)
    }

    /// Newton's method on `A q − b − follower(q) = 0` at `λ`; converged
    /// when the residual is below 1e-13 of the balance's scale (or the
    /// update below 1e-13 of `q`). `false` if it does not converge in 20
    /// iterations.
    fn newton(
        &self,
        mask: u32,
        a: &[(usize, usize, f64)],
        b: &[f64],
        lambda: f64,
        q: &mut [f64],
    ) -> bool {
        let n = q.len();
        for _ in 0..20 {
            // r = b + follower − A q; scale = |b| + |A||q| + |follower|.
            let mut r = b.to_vec();
            let mut sc: Vec<f64> = b.iter().map(|x| x.abs()).collect();
            for &(i, j, v) in a {
                r[i] -= v * q[j];
                sc[i] += (v * q[j]).abs();
            }
            let mut f = vec![0.0; n];
            self.follower(mask, lambda, q, &mut f, None);
            for i in 0..n {
                r[i] += f[i];
                sc[i] += f[i].abs();
            }
            let scale = sc.iter().fold(0.0f64, |m, x| m.max(*x));
            let res = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            if !res.is_finite() {
                return false;
            }
            if res <= 1e-13 * scale {
                return true;
            }
            let mut jac = a.to_vec();
            self.follower(mask, lambda, q, &mut vec![0.0; n], Some(&mut jac));
            let Ok(dq) = solve(self, &jac, &r) else {
                return false;
            };
            let size = q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let upd = dq.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (qi, d) in q.iter_mut().zip(&dq) {
                *qi += d;
            }
            if upd <= 1e-13 * size {
                return true;
            }
        }
        false
    }
}

/// `a += w·(x ⊗ y)` for sparse `x = Σ xc_k e_{xi_k}`, `y` likewise.
fn outer(
    a: &mut Vec<(usize, usize, f64)>,
    xi: &[usize],
    xc: &[f64],
    yi: &[usize],
    yc: &[f64],
    w: f64,
) {
    if w == 0.0 {
        return;
    }
    for (&r, &cr) in xi.iter().zip(xc) {
        for (&c, &cc) in yi.iter().zip(yc) {
            a.push((r, c, w * cr * cc));
        }
    }
}

/// `'a', 'b' and 'c'`.
fn quoted(names: &[&str]) -> String {
    let q: Vec<String> = names.iter().map(|s| format!("'{s}'")).collect();
    match q.len() {
        0 => String::new(),
        1 => q[0].clone(),
        k => format!("{} and {}", q[..k - 1].join(", "), q[k - 1]),
    }
}

/// A factorised square matrix.
enum Factors {
    Dense(nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>),
    Sparse(Box<faer::sparse::linalg::solvers::Lu<usize, f64>>),
    Woodbury(Box<Woodbury>),
}

/// `A = S + P E Pᵀ` with `S = (A + Aᵀ)/2` factorised by sparse Cholesky
/// and `E = (A − Aᵀ)/2` non-zero only on a few dofs `J` (the friction
/// contacts'; `P` selects them): `A x = b` is `x = S⁻¹ b − S⁻¹ P E y` with
/// `(I + G E) y = Pᵀ S⁻¹ b`, `G = Pᵀ S⁻¹ P` (`|J|` solves once). A sparse
/// LU of an FE model's `A` (10⁵ dofs) took 30 s where the Cholesky of its
/// symmetric part takes a few.
struct Woodbury {
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
    /// The dofs `J`.
    j: Vec<usize>,
    /// `S⁻¹ P` (`n × |J|`).
    sp: faer::Mat<f64>,
    /// `E_JJ`.
    e: faer::Mat<f64>,
    /// LU of `I + G E`.
    small: faer::linalg::solvers::PartialPivLu<f64>,
}

/// Most dofs in the non-symmetric part for [`Woodbury`]; beyond, sparse LU.
const WOODBURY_MAX_DOFS: usize = 200;

impl Woodbury {
    /// `None` when the non-symmetric part is not small or `S` is not
    /// positive definite.
    fn new(n: usize, merged: &[faer::sparse::Triplet<usize, usize, f64>]) -> Option<Woodbury> {
        use faer::sparse::{SparseColMat, Triplet};
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, merged).ok()?;
        let at = a.as_ref().transpose().to_col_major().ok()?;
        let scale = merged.iter().fold(0.0f64, |m, t| m.max(t.val.abs()));
        let mut sym = Vec::with_capacity(merged.len() + 16);
        let mut skew: Vec<(usize, usize, f64)> = Vec::new();
        // Column j of A and of Aᵀ (both sorted by row): S = (A + Aᵀ)/2 and
        // E = (A − Aᵀ)/2 in one merge.
        for c in 0..n {
            let (ra, va) = (a.row_idx_of_col_raw(c), a.val_of_col(c));
            let (rt, vt) = (at.row_idx_of_col_raw(c), at.val_of_col(c));
            let (mut p, mut q) = (0, 0);
            while p < ra.len() || q < rt.len() {
                let (r, x, y) = match (ra.get(p), rt.get(q)) {
                    (Some(&i), Some(&k)) if i == k => {
                        p += 1;
                        q += 1;
                        (i, va[p - 1], vt[q - 1])
                    }
                    (Some(&i), Some(&k)) if i < k => {
                        p += 1;
                        (i, va[p - 1], 0.0)
                    }
                    (Some(_), Some(&k)) => {
                        q += 1;
                        (k, 0.0, vt[q - 1])
                    }
                    (Some(&i), None) => {
                        p += 1;
                        (i, va[p - 1], 0.0)
                    }
                    (None, Some(&k)) => {
                        q += 1;
                        (k, 0.0, vt[q - 1])
                    }
                    (None, None) => unreachable!(),
                };
                sym.push(Triplet::new(r, c, 0.5 * (x + y)));
                let k = 0.5 * (x - y);
                if k.abs() > 1e-15 * scale {
                    skew.push((r, c, k));
                }
            }
        }
        let mut j: Vec<usize> = skew.iter().flat_map(|&(r, c, _)| [r, c]).collect();
        j.sort_unstable();
        j.dedup();
        if j.len() > WOODBURY_MAX_DOFS {
            return None;
        }
        let s = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &sym).ok()?;
        let llt = s.sp_cholesky(faer::Side::Lower).ok()?;
        let nj = j.len();
        let slot = |d: usize| j.binary_search(&d).expect("a dof of J");
        let mut e = faer::Mat::<f64>::zeros(nj, nj);
        for &(r, c, v) in &skew {
            e[(slot(r), slot(c))] += v;
        }
        let mut sp = faer::Mat::<f64>::zeros(n, nj);
        for (c, &d) in j.iter().enumerate() {
            sp[(d, c)] = 1.0;
        }
        {
            use faer::linalg::solvers::Solve;
            llt.solve_in_place(sp.as_mut());
        }
        let g = faer::Mat::<f64>::from_fn(nj, nj, |r, c| sp[(j[r], c)]);
        let ige = faer::Mat::<f64>::identity(nj, nj) + &g * &e;
        let small = ige.partial_piv_lu();
        Some(Woodbury {
            llt,
            j,
            sp,
            e,
            small,
        })
    }

    fn solve(&self, b: &[f64]) -> Vec<f64> {
        use faer::linalg::solvers::Solve;
        let n = b.len();
        let mut x0 = faer::Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        self.llt.solve_in_place(x0.as_mut());
        if self.j.is_empty() {
            return (0..n).map(|i| x0[(i, 0)]).collect();
        }
        let px = faer::Mat::<f64>::from_fn(self.j.len(), 1, |r, _| x0[(self.j[r], 0)]);
        let y = self.small.solve(&px);
        let ey = &self.e * &y;
        let corr = &self.sp * &ey;
        (0..n).map(|i| x0[(i, 0)] - corr[(i, 0)]).collect()
    }
}

impl Factors {
    /// Factorise the `n×n` matrix of triplets (duplicates summed); `None`
    /// if the factorisation meets a zero pivot.
    fn new(n: usize, a: &[(usize, usize, f64)]) -> Option<Factors> {
        if n <= DENSE_SOLVE_DOFS {
            let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
            for &(i, j, v) in a {
                m[(i, j)] += v;
            }
            let lu = m.lu();
            lu.is_invertible().then_some(Factors::Dense(lu))
        } else {
            use faer::sparse::{SparseColMat, Triplet};
            let mut t = a.to_vec();
            t.sort_unstable_by_key(|&(i, j, _)| (j, i));
            let mut merged: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(t.len());
            for (i, j, v) in t {
                match merged.last_mut() {
                    Some(last) if last.row == i && last.col == j => last.val += v,
                    _ => merged.push(Triplet::new(i, j, v)),
                }
            }
            if let Some(w) = Woodbury::new(n, &merged) {
                return Some(Factors::Woodbury(Box::new(w)));
            }
            let m = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &merged).ok()?;
            m.sp_lu().ok().map(|lu| Factors::Sparse(Box::new(lu)))
        }
    }

    /// `x = A⁻¹ b`.
    fn solve(&self, b: &[f64]) -> Vec<f64> {
        match self {
            Factors::Dense(lu) => {
                let v = nalgebra::DVector::from_column_slice(b);
                lu.solve(&v)
                    .map_or_else(|| vec![f64::NAN; b.len()], |x| x.as_slice().to_vec())
            }
            Factors::Sparse(lu) => {
                use faer::linalg::solvers::Solve;
                let rhs = faer::Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
                let x = lu.solve(rhs);
                (0..b.len()).map(|i| x[(i, 0)]).collect()
            }
            Factors::Woodbury(w) => w.solve(b),
        }
    }
}

/// Solve `A x = b` (triplets, duplicates summed) with two steps of
/// iterative refinement; a singular `A` (a zero pivot, or an equilibrated
/// condition above [`SINGULAR_COND`] shown by the solution) is reported
/// with the dofs its near-null vector moves.
fn solve(model: &Lumped, a: &[(usize, usize, f64)], b: &[f64]) -> Result<Vec<f64>, SetFailure> {
    let n = b.len();
    // Equilibration D = |diag A|^(-1/2) (1 where the diagonal is zero), for
    // a condition estimate that does not depend on the dofs' units.
    let mut diag = vec![0.0f64; n];
    for &(i, j, v) in a {
        if i == j {
            diag[i] += v;
        }
    }
    let d: Vec<f64> = diag
        .iter()
        .map(|x| if *x != 0.0 { 1.0 / x.abs().sqrt() } else { 1.0 })
        .collect();
    let singular = || SetFailure::Singular(free_dofs(model, a, &diag, &d));
    let Some(f) = Factors::new(n, a) else {
        return Err(singular());
    };
    let mut x = f.solve(b);
    for _ in 0..2 {
        let mut r = b.to_vec();
        for &(i, j, v) in a {
            r[i] -= v * x[j];
        }
        let dx = f.solve(&r);
        for (xi, di) in x.iter_mut().zip(&dx) {
            *xi += di;
        }
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(singular());
    }
    // Lower bound of the equilibrated condition: ‖Â‖ ‖x̂‖ / ‖b̂‖ with
    // Â = D A D, x̂ = D⁻¹ x, b̂ = D b (row sums for the ∞-norm).
    let mut rows = vec![0.0f64; n];
    for &(i, j, v) in a {
        rows[i] += (d[i] * v * d[j]).abs();
    }
    let a_norm = rows.iter().fold(0.0f64, |m, x| m.max(*x));
    let x_norm = x
        .iter()
        .zip(&d)
        .fold(0.0f64, |m, (xi, di)| m.max((xi / di).abs()));
    let b_norm = b
        .iter()
        .zip(&d)
        .fold(0.0f64, |m, (bi, di)| m.max((bi * di).abs()));
    if b_norm > 0.0 && a_norm * x_norm > SINGULAR_COND * b_norm {
        return Err(singular());
    }
    Ok(x)
}

/// The dofs a near-null vector of `A` moves (those within a tenth of the
/// largest scaled component), found by one solve of `A + ε|diag A|` with
/// `ε = 1e-10` against a load on every dof.
fn free_dofs(model: &Lumped, a: &[(usize, usize, f64)], diag: &[f64], d: &[f64]) -> String {
    let n = diag.len();
    let big = diag.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1.0);
    let mut shifted = a.to_vec();
    for (i, x) in diag.iter().enumerate() {
        shifted.push((i, i, 1e-10 * if *x != 0.0 { x.abs() } else { big }));
    }
    let b: Vec<f64> = d.iter().map(|di| 1.0 / di).collect();
    let x = Factors::new(n, &shifted).map(|f| f.solve(&b));
    let names = &model.dofs;
    let Some(x) = x.filter(|x| x.iter().all(|v| v.is_finite())) else {
        return "some dofs move".into();
    };
    let xs: Vec<f64> = x.iter().zip(d).map(|(xi, di)| (xi / di).abs()).collect();
    let top = xs.iter().fold(0.0f64, |m, v| m.max(*v));
    let mut idx: Vec<usize> = (0..n).filter(|&i| xs[i] >= 0.1 * top).collect();
    idx.sort_by(|&i, &j| xs[j].total_cmp(&xs[i]).then(i.cmp(&j)));
    let shown: Vec<&str> = idx.iter().take(6).map(|&i| names[i].as_str()).collect();
    let more = idx.len().saturating_sub(6);
    let list = shown.join(", ");
    match (idx.len(), more) {
        (1, _) => format!("dof {list} moves"),
        (_, 0) => format!("dofs {list} move"),
        _ => format!("dofs {list} and {more} more move"),
    }
}

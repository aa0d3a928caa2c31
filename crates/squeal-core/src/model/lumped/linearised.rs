//! The linearisation of a lumped model's sliding equations: the analytic
//! Jacobian of the generalised force, the state matrix `∂f/∂z`, and the
//! second-order system `M q̈ + C q̇ + K q = 0` (dense and sparse) that the
//! stability analysis works on.

use super::*;

impl Lumped {
    /// `∂(generalised force)/∂z` in the sliding modes at `z` (n × 2n): the
    /// analytic Jacobian of the force (see the module docs).
    pub(super) fn force_jacobian(&self, modes: &Modes, z: &[f64]) -> DMatrix<f64> {
        let n = self.dofs.len();
        let mut j = DMatrix::<f64>::zeros(n, 2 * n);
        self.force_jacobian_terms(modes, z, &mut |r, c, v| j[(r, c)] += v);
        j
    }

    /// The terms of [`Lumped::force_jacobian`], each `(row, col, value)`
    /// (repeated positions add up) to `add`.
    pub(super) fn force_jacobian_terms(
        &self,
        modes: &Modes,
        z: &[f64],
        add: &mut dyn FnMut(usize, usize, f64),
    ) {
        let n = self.dofs.len();
        let (q, u) = z.split_at(n);
        for s in &self.springs {
            // A cubic spring's tangent stiffness at q: k + 3 k3 e².
            let k = if s.k3 != 0.0 {
                let e = s.on.dot(q);
                s.k + 3.0 * s.k3 * e * e
            } else {
                s.k
            };
            for (a, ca) in s.on.idx.iter().zip(&s.on.coef) {
                for (b, cb) in s.on.idx.iter().zip(&s.on.coef) {
                    add(*a, *b, -(k * ca * cb));
                    add(*a, n + *b, -(s.c * ca * cb));
                }
            }
        }
        if let Some(k) = &self.k_matrix {
            for (r, c, v) in k.entries() {
                add(r, c, -(v));
            }
        }
        if let Some(cm) = &self.c_matrix {
            for (r, c, v) in cm.entries() {
                add(r, n + c, -(v));
            }
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let mode = modes.get(i);
            if mode == Mode::Free {
                continue;
            }
            let f_n = c.normal_force(q, u);
            // ∇F_n (dense, 2n).
            let mut g_n = vec![0.0; 2 * n];
            if let Normal::Elastic {
                normal, k, c: cc, ..
            } = &c.normal
            {
                for (a, ca) in normal.idx.iter().zip(&normal.coef) {
                    g_n[*a] += k * ca;
                    g_n[n + *a] += cc * ca;
                }
                // −F_n·n
                for (a, ca) in normal.idx.iter().zip(&normal.coef) {
                    for (col, g) in g_n.iter().enumerate() {
                        add(*a, col, -(ca * g));
                    }
                }
            }
            let v = c.sliding_velocity(u);
            let s = mode.slip_sign();
            let (fnf, g_nf) = if matches!(
                c.normal,
                Normal::Elastic {
                    bilateral: true,
                    ..
                }
            ) && f_n < 0.0
            {
                (0.0, vec![0.0; 2 * n])
            } else {
                (f_n, g_n.clone())
            };
            let mu = c.friction.mu(s * v);
            let dmu = c.friction.dmu(s * v);
            let f_t = s * mu * fnf;
            // ∇F_t = s μ ∇F_n + F_n μ'(s v) ∇v.
            let mut g_t = vec![0.0; 2 * n];
            for (col, g) in g_nf.iter().enumerate() {
                g_t[col] = s * mu * g;
            }
            for (a, ca) in c.tangent.idx.iter().zip(&c.tangent.coef) {
                g_t[n + *a] += fnf * dmu * ca;
            }
            for (a, ca) in c.tangent.idx.iter().zip(&c.tangent.coef) {
                for (col, g) in g_t.iter().enumerate() {
                    add(*a, col, -(ca * g));
                }
            }
            if c.alpha != 0.0 {
                if let Normal::Elastic { normal, .. } = &c.normal {
                    // ∇F_f = α((s·q) ∇F_t + F_t s).
                    let sq = c.slope.dot(q);
                    let mut g_f: Vec<f64> = g_t.iter().map(|g| c.alpha * sq * g).collect();
                    for (a, ca) in c.slope.idx.iter().zip(&c.slope.coef) {
                        g_f[*a] += c.alpha * f_t * ca;
                    }
                    for (a, ca) in normal.idx.iter().zip(&normal.coef) {
                        for (col, g) in g_f.iter().enumerate() {
                            add(*a, col, ca * g);
                        }
                    }
                }
            }
        }
    }

    /// The state matrix `∂f/∂z` (2n × 2n) of the sliding equations at `z`.
    pub fn jacobian_dyn(&self, z: &[f64]) -> DMatrix<f64> {
        let n = self.dofs.len();
        let modes = self.sliding_modes_at(z);
        let jf = self.force_jacobian(&modes, z);
        let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
        }
        match &self.inv_mass {
            // One matrix product (blocked, cache-friendly) rather than 2n
            // matrix–vector products: the dense M⁻¹ of an FE model made this
            // the largest cost of an eigen-analysis.
            InvMass::Dense(inv) => {
                let minv = DMatrix::from_row_slice(n, n, inv);
                a.view_mut((n, 0), (n, 2 * n)).copy_from(&(minv * &jf));
            }
            InvMass::Factored(f) => {
                let mut x = faer::Mat::<f64>::from_fn(n, 2 * n, |r, c| jf[(r, c)]);
                f.solve_in_place(x.as_mut());
                for c in 0..2 * n {
                    for r in 0..n {
                        a[(n + r, c)] = x[(r, c)];
                    }
                }
            }
            InvMass::Diagonal(inv) => {
                for c in 0..2 * n {
                    for r in 0..n {
                        a[(n + r, c)] = inv[r] * jf[(r, c)];
                    }
                }
            }
        }
        a
    }

    /// Slip modes by the sign of each contact's v at `z` (free where a unilateral layer is open).
    pub(super) fn sliding_modes_at(&self, z: &[f64]) -> Modes {
        let n = self.dofs.len();
        let mut m = self.steady_modes();
        for (i, c) in self.contacts.iter().enumerate() {
            let v = c.sliding_velocity(&z[n..]);
            if v > 0.0 {
                m.set(i, Mode::SlipPos);
            } else if v < 0.0 {
                m.set(i, Mode::SlipNeg);
            }
            if c.can_open() && c.normal_force(&z[..n], &z[n..]) <= 0.0 {
                m.set(i, Mode::Free);
            }
        }
        m
    }

    /// The linearised second-order system `M q̈ + C q̇ + K q = 0` of the
    /// sliding equations at `z` (the same linearisation as
    /// [`Lumped::jacobian_dyn`], `M` with the `[masses]` added, `K`, `C` the
    /// negated force Jacobian, non-symmetric where friction acts).
    pub fn second_order_dyn(&self, z: &[f64]) -> SecondOrder {
        let n = self.dofs.len();
        let modes = self.sliding_modes_at(z);
        let jf = self.force_jacobian(&modes, z);
        let mut m = self
            .m_matrix
            .as_ref()
            .map_or_else(|| DMatrix::<f64>::zeros(n, n), Sparse::to_dense);
        for i in 0..n {
            m[(i, i)] += self.masses[i];
        }
        SecondOrder {
            m,
            k: -jf.columns(0, n),
            c: -jf.columns(n, n),
        }
    }

    /// [`Lumped::second_order_dyn`] with sparse matrices (what a large FE
    /// model needs: its files' matrices plus the contacts' few terms, never
    /// an `n × n` dense matrix).
    pub fn second_order_sparse(&self, z: &[f64]) -> SparseSecondOrder {
        let n = self.dofs.len();
        let modes = self.sliding_modes_at(z);
        let (mut k, mut c) = (Vec::new(), Vec::new());
        self.force_jacobian_terms(&modes, z, &mut |r, col, v| {
            if v != 0.0 {
                if col < n {
                    k.push((r, col, -v));
                } else {
                    c.push((r, col - n, -v));
                }
            }
        });
        let mut m: Vec<(usize, usize, f64)> = self
            .m_matrix
            .as_ref()
            .map_or_else(Vec::new, |m| m.entries().collect());
        m.extend(
            (0..n)
                .filter(|&i| self.masses[i] != 0.0)
                .map(|i| (i, i, self.masses[i])),
        );
        SparseSecondOrder::from_triplets(n, &m, &k, &c)
            .expect("the model's indices are within its dofs")
    }
}

impl Lumped {
    /// The undamped modes of the model linearised at the static state `z`
    /// with its contacts stuck: the structure (springs, `K`, the cubic
    /// springs' tangent stiffness) plus the normal stiffness `k n nᵀ` of each
    /// closed elastic contact, constrained by `t_i·q = 0` for every closed
    /// contact (a stuck contact's tangent does not move). Returns the mass
    /// matrix and the modes `(ω, φ)`, ascending in `ω` (rad/s), `φ` mass
    /// normalised (`φᵀMφ = 1`); the low-amplitude limit of a friction-damped
    /// mode (docs/physics.md §5j). Rigid-body modes have `ω = 0`.
    pub fn stuck_modes(&self, z: &[f64]) -> Result<StuckModes, String> {
        let n = self.dofs.len();
        let (q, u) = z.split_at(n);
        let free = Modes::all(self.contacts.len(), Mode::Free);
        let jf = self.force_jacobian(&free, z);
        let mut k: DMatrix<f64> = -jf.columns(0, n);
        let mut rows: Vec<Vec<f64>> = Vec::new();
        for c in &self.contacts {
            let closed = match &c.normal {
                Normal::Prescribed(_) => true,
                Normal::Elastic {
                    normal,
                    k: kn,
                    bilateral,
                    ..
                } => {
                    let on = *bilateral || c.normal_force(q, u) > 0.0;
                    if on {
                        for (a, ca) in normal.idx.iter().zip(&normal.coef) {
                            for (b, cb) in normal.idx.iter().zip(&normal.coef) {
                                k[(*a, *b)] += kn * ca * cb;
                            }
                        }
                    }
                    on
                }
            };
            if closed {
                let mut r = vec![0.0; n];
                c.tangent.add_scaled(&mut r, 1.0);
                rows.push(r);
            }
        }
        let so = self.second_order_dyn(z);
        let m = so.m;
        // T: an orthonormal basis of the constraints' null space.
        let t = if rows.is_empty() {
            DMatrix::<f64>::identity(n, n)
        } else {
            let g = DMatrix::from_fn(rows.len(), n, |i, j| rows[i][j]);
            let svd = (g.transpose() * &g).symmetric_eigen();
            let top = svd.eigenvalues.iter().cloned().fold(0.0, f64::max);
            let keep: Vec<usize> = (0..n)
                .filter(|&i| svd.eigenvalues[i] <= 1e-12 * top)
                .collect();
            DMatrix::from_fn(n, keep.len(), |i, j| svd.eigenvectors[(i, keep[j])])
        };
        let r = t.ncols();
        if r == 0 {
            return Err("with every contact stuck no dof can move (no mode)".into());
        }
        let ksym = 0.5 * (&k + k.transpose());
        let mr = t.transpose() * &m * &t;
        let kr = t.transpose() * &ksym * &t;
        let l = mr
            .clone()
            .cholesky()
            .ok_or("the mass matrix is not positive definite")?;
        let linv = l.l().try_inverse().ok_or("the mass matrix is singular")?;
        let a = &linv * kr * linv.transpose();
        let eig = (0.5 * (&a + a.transpose())).symmetric_eigen();
        let mut order: Vec<usize> = (0..r).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        let modes = order
            .into_iter()
            .map(|i| {
                let w2 = eig.eigenvalues[i].max(0.0);
                let y = linv.transpose() * eig.eigenvectors.column(i);
                let phi = &t * y;
                (w2.sqrt(), phi.iter().copied().collect())
            })
            .collect();
        Ok(StuckModes { mass: m, modes })
    }
}

/// What [`Lumped::stuck_modes`] returns.
#[derive(Debug, Clone)]
pub struct StuckModes {
    /// The mass matrix `M` (n × n).
    pub mass: DMatrix<f64>,
    /// `(ω (rad/s), φ)` ascending, `φᵀMφ = 1`.
    pub modes: Vec<(f64, Vec<f64>)>,
}

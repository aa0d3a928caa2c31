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

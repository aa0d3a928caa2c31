//! The right-hand side of a small lumped model on operators folded once per
//! parameter change ([`DenseField`]), and the general one for any size.

use super::*;

impl Lumped {
    pub(super) fn rebuild_dense(&mut self) {
        let n = self.dofs.len();
        // Cubic springs are not folded into the linear operators: such a
        // model takes the general right-hand side.
        if n > DENSE_FIELD_DOFS || self.springs.iter().any(|s| s.k3 != 0.0) {
            self.dense = None;
            return;
        }
        let mut kc = vec![0.0; 2 * n * n];
        for sp in &self.springs {
            for (a, ca) in sp.on.idx.iter().zip(&sp.on.coef) {
                for (b, cb) in sp.on.idx.iter().zip(&sp.on.coef) {
                    kc[a * 2 * n + b] -= sp.k * ca * cb;
                    kc[a * 2 * n + n + b] -= sp.c * ca * cb;
                }
            }
        }
        if let Some(k) = &self.k_matrix {
            for (r, c, v) in k.entries() {
                kc[r * 2 * n + c] -= v;
            }
        }
        if let Some(cm) = &self.c_matrix {
            for (r, c, v) in cm.entries() {
                kc[r * 2 * n + n + c] -= v;
            }
        }
        let (mut kd, mut cd) = ([0.0; DENSE_FIELD_DOFS], [0.0; DENSE_FIELD_DOFS]);
        let mut off = Vec::new();
        for (k, &x) in kc.iter().enumerate() {
            let (r, c) = (k / (2 * n), k % (2 * n));
            if c == r {
                kd[r] = x;
            } else if c == n + r {
                cd[r] = x;
            } else if x != 0.0 {
                off.push((r, c, x));
            }
        }
        let mut f0 = [0.0; DENSE_FIELD_DOFS];
        for f in self.forces.iter().filter(|f| !f.varies()) {
            f.on.add_scaled(&mut f0, f.value);
        }
        let mut inv_mass = [0.0; DENSE_FIELD_DOFS];
        let diagonal = match &self.inv_mass {
            InvMass::Diagonal(inv) => {
                inv_mass[..n].copy_from_slice(inv);
                true
            }
            InvMass::Dense(_) | InvMass::Factored(_) => false,
        };
        let plain = diagonal && off.is_empty() && !self.time_varying;
        let contacts = self
            .contacts
            .iter()
            .map(|c| {
                let (fn_q, fn_u, normal) = match &c.normal {
                    Normal::Elastic {
                        normal, k, c: cc, ..
                    } => (
                        dense_row(normal, *k),
                        dense_row(normal, *cc),
                        dense_row(normal, 1.0),
                    ),
                    Normal::Prescribed(_) => {
                        let zero = [0.0; DENSE_FIELD_DOFS];
                        (zero, zero, zero)
                    }
                };
                FoldedContact {
                    fn_q,
                    fn_u,
                    normal,
                    tangent: dense_row(&c.tangent, 1.0),
                    slope: dense_row(&c.slope, 1.0),
                    bilateral: matches!(
                        c.normal,
                        Normal::Elastic {
                            bilateral: true,
                            ..
                        }
                    ),
                }
            })
            .collect();
        self.dense = Some(DenseField {
            f0,
            kd,
            cd,
            off,
            inv_mass,
            plain,
            contacts,
        });
    }

    /// `F_n` of a contact that touches, from its folded rows.
    #[inline(always)]
    pub(super) fn normal_folded(c: &Contact, fc: &FoldedContact, q: &[f64], u: &[f64]) -> f64 {
        let n = q.len();
        match c.normal {
            Normal::Elastic { .. } => dot_from(dot(&fc.fn_q[..n], q), &fc.fn_u[..n], u),
            Normal::Prescribed(f) => f,
        }
    }

    /// The friction force `F_t = s·μ(s·v)·F_n` (`F_n⁺` for a bilateral
    /// layer) of a contact in slip mode `mode`, from its folded rows.
    #[inline(always)]
    pub(super) fn slip_folded(
        c: &Contact,
        fc: &FoldedContact,
        mode: Mode,
        f_n: f64,
        u: &[f64],
    ) -> f64 {
        let n = u.len();
        let v = c.v + dot(&fc.tangent[..n], u);
        let f_nf = if fc.bilateral { f_n.max(0.0) } else { f_n };
        // s = ±1 applied as negations (the same bits, no multiplications on
        // the critical path), one call of the law (so that it stays inline).
        let pos = mode == Mode::SlipPos;
        let mu = c.friction.mu(if pos { v } else { -v });
        if pos {
            mu * f_nf
        } else {
            -mu * f_nf
        }
    }

    /// Add the force of contact `c` in `mode` to `acc` (its normal force,
    /// and in slip its friction and follower force), from its folded rows
    /// `fc`; `true` if it sticks (its friction force is a multiplier).
    #[inline(always)]
    pub(super) fn contact_folded(
        c: &Contact,
        fc: &FoldedContact,
        mode: Mode,
        q: &[f64],
        u: &[f64],
        acc: &mut [f64],
    ) -> bool {
        let n = acc.len();
        if mode == Mode::Free {
            return false;
        }
        let f_n = Self::normal_folded(c, fc, q, u);
        if mode == Mode::Stick {
            // (A prescribed load's normal row is zero: `a − F_n·0 = a`.)
            for (a, x) in acc.iter_mut().zip(&fc.normal[..n]) {
                *a -= f_n * x;
            }
            return true;
        }
        let f_t = Self::slip_folded(c, fc, mode, f_n, u);
        for ((a, x), y) in acc.iter_mut().zip(&fc.normal[..n]).zip(&fc.tangent[..n]) {
            *a = *a - f_n * x - f_t * y;
        }
        if c.alpha != 0.0 {
            let f_f = c.alpha * f_t * dot(&fc.slope[..n], q);
            for (a, x) in acc.iter_mut().zip(&fc.normal[..n]) {
                *a += f_f * x;
            }
        }
        false
    }

    /// The right-hand side on the folded operators ([`DenseField`]) for
    /// `N = 2n ≤ 2·DENSE_FIELD_DOFS` states: the same force as
    /// [`Lumped::base_force`] (summed in another order) with the stick
    /// multipliers, then `M⁻¹`. For models whose springs, `K` and `C` act on
    /// single dofs (no off-diagonal entries) the sums are those of the
    /// element-by-element fold this replaced, bit for bit.
    #[inline(always)]
    pub(super) fn field_folded<const N: usize>(
        &self,
        d: &DenseField,
        t: f64,
        modes: &Modes,
        z: &[f64; N],
        dz: &mut [f64; N],
    ) {
        let n = N / 2;
        let (q, u) = z.split_at(n);
        // The force is summed in `dz[n..]` (every component is written), then scaled by M⁻¹ in place.
        let (dq, acc) = dz.split_at_mut(n);
        dq.copy_from_slice(u);
        if d.plain {
            for (i, a) in acc.iter_mut().enumerate() {
                *a = d.f0[i] + d.kd[i] * q[i] + d.cd[i] * u[i];
            }
        } else {
            acc.copy_from_slice(&d.f0[..n]);
            for f in self.forces.iter().filter(|f| f.varies()) {
                f.on.add_scaled(acc, f.at(t));
            }
            for (i, a) in acc.iter_mut().enumerate() {
                *a = *a + d.kd[i] * q[i] + d.cd[i] * u[i];
            }
            for &(r, c, v) in &d.off {
                acc[r] += v * z[c];
            }
        }
        // A plain model with one contact in slip: the contact's forces and
        // M⁻¹ in one pass (the same operations, one store per dof).
        if let (true, [c], [fc]) = (d.plain, &self.contacts[..], &d.contacts[..]) {
            let mode = modes.first();
            if mode == Mode::SlipPos || mode == Mode::SlipNeg {
                let f_n = Self::normal_folded(c, fc, q, u);
                let f_t = Self::slip_folded(c, fc, mode, f_n, u);
                let (nrm, tan, inv) = (&fc.normal[..n], &fc.tangent[..n], &d.inv_mass[..n]);
                if c.alpha != 0.0 {
                    let f_f = c.alpha * f_t * dot(&fc.slope[..n], q);
                    for i in 0..n {
                        acc[i] = (acc[i] - f_n * nrm[i] - f_t * tan[i] + f_f * nrm[i]) * inv[i];
                    }
                } else {
                    for i in 0..n {
                        acc[i] = (acc[i] - f_n * nrm[i] - f_t * tan[i]) * inv[i];
                    }
                }
                return;
            }
        }
        // One contact (the commonest case) without the loop's machinery.
        let sticking = match (&self.contacts[..], &d.contacts[..]) {
            ([c], [fc]) => Self::contact_folded(c, fc, modes.first(), q, u, acc),
            _ => {
                let mut sticking = false;
                for ((c, fc), &mode) in self.contacts.iter().zip(&d.contacts).zip(modes.as_slice())
                {
                    sticking |= Self::contact_folded(c, fc, mode, q, u, acc);
                }
                sticking
            }
        };
        if sticking {
            self.add_stick_forces(modes, q, acc);
        }
        if d.plain {
            for (a, m) in acc.iter_mut().zip(&d.inv_mass[..n]) {
                *a *= m;
            }
        } else {
            let mut f = [0.0; N];
            f[..n].copy_from_slice(acc);
            self.apply_inv_mass(&f[..n], acc);
        }
    }

    /// The right-hand side of any model: on the folded operators up to
    /// [`DENSE_FIELD_DOFS`] dofs, else on the elements.
    #[inline(never)]
    pub(super) fn field_general<const N: usize>(
        &self,
        t: f64,
        modes: &Modes,
        z: &[f64; N],
        dz: &mut [f64; N],
    ) {
        match &self.dense {
            Some(d) if N / 2 <= DENSE_FIELD_DOFS => self.field_folded(d, t, modes, z, dz),
            _ => {
                let n = N / 2;
                let (q, u) = z.split_at(n);
                let mut acc = [0.0; N];
                self.force(t, modes, q, u, &mut acc[..n]);
                dz[..n].copy_from_slice(u);
                self.apply_inv_mass(&acc[..n], &mut dz[n..]);
            }
        }
    }
}

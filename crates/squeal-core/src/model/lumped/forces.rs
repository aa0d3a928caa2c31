//! The force law of a lumped model: the generalised force without and with
//! the stick multipliers (one small linear system per set of sticking
//! contacts), the stick-break guards and the friction of a sticking contact.

use super::*;

impl Lumped {
    /// The distinct frequencies of the harmonic forces (Hz), ascending.
    pub fn forcing_hz(&self) -> Vec<f64> {
        let mut f: Vec<f64> = self
            .forces
            .iter()
            .filter(|f| f.is_harmonic())
            .map(|f| f.freq_hz)
            .collect();
        f.sort_by(f64::total_cmp);
        f.dedup();
        f
    }

    /// Generalised force without the stick multipliers:
    /// `F(t) − K q − C q̇ − springs − contacts` (slip friction only if
    /// `slip_friction`), into `acc[..n]`.
    #[inline]
    pub(super) fn base_force(
        &self,
        t: f64,
        modes: &Modes,
        q: &[f64],
        u: &[f64],
        acc: &mut [f64],
        slip_friction: bool,
    ) {
        acc.fill(0.0);
        for f in &self.forces {
            f.on.add_scaled(acc, f.at(t));
        }
        for s in &self.springs {
            let e = s.on.dot(q);
            let ed = s.on.dot(u);
            s.on.add_scaled(acc, -(s.k * e + s.k3 * e * e * e + s.c * ed));
        }
        if let Some(k) = &self.k_matrix {
            k.mul_add(q, acc, -1.0);
        }
        if let Some(c) = &self.c_matrix {
            c.mul_add(u, acc, -1.0);
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let mode = modes.get(i);
            if mode == Mode::Free {
                continue;
            }
            let f_n = c.normal_force(q, u);
            if let Normal::Elastic { normal, .. } = &c.normal {
                normal.add_scaled(acc, -f_n);
            }
            if slip_friction && mode != Mode::Stick {
                let f_t = c.slip_force(mode, c.sliding_velocity(u), f_n);
                c.tangent.add_scaled(acc, -f_t);
                if c.alpha != 0.0 {
                    if let Normal::Elastic { normal, .. } = &c.normal {
                        normal.add_scaled(acc, c.alpha * f_t * c.slope.dot(q));
                    }
                }
            }
        }
    }

    /// The stick multipliers (friction forces of the sticking contacts, in
    /// the order of `set`) for the force `acc` without them. `false` if the
    /// constraint matrix is singular.
    #[inline]
    pub(super) fn multipliers(
        &self,
        set: &[usize],
        q: &[f64],
        acc: &[f64],
        lambda: &mut [f64; MAX_CONTACTS],
    ) -> bool {
        let k = set.len();
        let mut g = [[0.0; MAX_CONTACTS]; MAX_CONTACTS];
        for (a, &j) in set.iter().enumerate() {
            lambda[a] = self.minv_t[j].iter().zip(acc).map(|(x, y)| x * y).sum();
            for (b, &l) in set.iter().enumerate() {
                let c = &self.contacts[l];
                g[a][b] = self.gram[j][l];
                if c.alpha != 0.0 {
                    g[a][b] -= c.alpha * c.slope.dot(q) * self.tn[j][l];
                }
            }
        }
        solve_small(&mut g, lambda, k)
    }

    /// Add the sticking contacts' forces `−λ_k w_k` to `acc`.
    #[inline]
    pub(super) fn apply_multipliers(
        &self,
        set: &[usize],
        q: &[f64],
        lambda: &[f64],
        acc: &mut [f64],
    ) {
        for (a, &j) in set.iter().enumerate() {
            let c = &self.contacts[j];
            c.tangent.add_scaled(acc, -lambda[a]);
            if c.alpha != 0.0 {
                if let Normal::Elastic { normal, .. } = &c.normal {
                    normal.add_scaled(acc, c.alpha * lambda[a] * c.slope.dot(q));
                }
            }
        }
    }

    /// The full generalised force (multipliers included) into `acc`, and the
    /// multipliers of the sticking contacts (indexed by contact).
    #[inline]
    pub(super) fn force(
        &self,
        t: f64,
        modes: &Modes,
        q: &[f64],
        u: &[f64],
        acc: &mut [f64],
    ) -> [f64; MAX_CONTACTS] {
        self.base_force(t, modes, q, u, acc, true);
        self.add_stick_forces(modes, q, acc)
    }

    /// Add the sticking contacts' forces (the multipliers for the force
    /// `acc` without them) to `acc`; the multipliers indexed by contact.
    #[inline]
    pub(super) fn add_stick_forces(
        &self,
        modes: &Modes,
        q: &[f64],
        acc: &mut [f64],
    ) -> [f64; MAX_CONTACTS] {
        let (set, k) = stick_set(modes);
        let mut out = [0.0; MAX_CONTACTS];
        if k > 0 {
            let mut lambda = [0.0; MAX_CONTACTS];
            // Regular by construction (checked in `refresh`); a singular
            // solve leaves λ = NaN, which the integrator reports.
            if !self.multipliers(&set[..k], q, acc, &mut lambda) {
                lambda = [f64::NAN; MAX_CONTACTS];
            }
            self.apply_multipliers(&set[..k], q, &lambda, acc);
            for a in 0..k {
                out[set[a]] = lambda[a];
            }
        }
        out
    }

    /// The stick-break guard value `sign·λ_i − μ_s F_n,i` of contact `i`
    /// (slip friction of the other contacts included if `slip_friction`).
    pub(super) fn stick_guard(
        &self,
        t: f64,
        modes: &Modes,
        i: usize,
        sign: f64,
        z: &[f64],
        slip_friction: bool,
    ) -> f64 {
        let n = self.dofs.len();
        let (q, u) = z.split_at(n);
        let mut stack = [0.0; STACK_DOFS];
        let mut heap;
        let acc: &mut [f64] = if n <= STACK_DOFS {
            &mut stack[..n]
        } else {
            heap = vec![0.0; n];
            &mut heap
        };
        self.base_force(t, modes, q, u, acc, slip_friction);
        let (set, k) = stick_set(modes);
        let mut lambda = [0.0; MAX_CONTACTS];
        if !self.multipliers(&set[..k], q, acc, &mut lambda) {
            return f64::NAN;
        }
        let a = set[..k].iter().position(|&j| j == i).unwrap_or(0);
        let c = &self.contacts[i];
        sign * lambda[a] - c.friction.mu_static() * c.normal_force(q, u)
    }

    /// Whether the stick guards of `modes` are affine in the state.
    pub(super) fn stick_guards_affine(&self, modes: &Modes) -> bool {
        !self.time_varying
            && self.contacts.iter().enumerate().all(|(j, c)| {
                let m = modes.get(j);
                !(m == Mode::SlipPos || m == Mode::SlipNeg)
                    || (c.friction.is_constant()
                        && !matches!(
                            c.normal,
                            Normal::Elastic {
                                bilateral: true,
                                ..
                            }
                        ))
            })
    }
}

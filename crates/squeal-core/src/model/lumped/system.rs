//! A lumped model as a [`System`] of the integrator, stability and cycles:
//! for any size through [`Lumped`] itself and at a fixed state count through
//! [`Fixed`] (and [`with_lumped_size!`](crate::with_lumped_size)).

use super::*;

impl<const N: usize> System<N> for Lumped {
    fn system_name(&self) -> &str {
        "lumped"
    }
    fn names(&self) -> Vec<String> {
        self.states.clone()
    }
    fn contacts(&self) -> usize {
        self.contacts.len()
    }
    fn contact_name(&self, i: usize) -> &str {
        &self.contacts[i].name
    }

    /// The commonest small model (plain, one contact) inline in the
    /// integrator's stages; every other model through `Lumped::field_general`
    /// (one out-of-line copy, so that the stages stay compact).
    #[inline(always)]
    fn field(&self, t: f64, modes: &Modes, z: &[f64; N], dz: &mut [f64; N]) {
        match &self.dense {
            // (The size test is a constant of each compiled size.)
            Some(d)
                if N / 2 <= DENSE_FIELD_DOFS
                    && d.plain
                    && d.contacts.len() == 1
                    && self.contacts.len() == 1 =>
            {
                self.field_folded(d, t, modes, z, dz)
            }
            _ => self.field_general(t, modes, z, dz),
        }
    }

    fn mode_guards(&self, modes: &Modes, out: &mut Guards<N>) {
        out.clear();
        let n = N / 2;
        let affine_stick = self.stick_guards_affine(modes);
        for (i, c) in self.contacts.iter().enumerate() {
            let ci = i as u8;
            let mode = modes.get(i);
            let mut push = |kind: GuardKind, cvec: [f64; N], d: f64, affine: bool| {
                out.push_guard(Guard {
                    kind,
                    c: cvec,
                    d,
                    contact: ci,
                    affine,
                })
            };
            if mode == Mode::Free {
                if let Normal::Elastic { normal, .. } = &c.normal {
                    let mut g = [0.0; N];
                    normal.add_scaled(&mut g[..n], 1.0);
                    push(GuardKind::Contact, g, 0.0, true);
                }
                continue;
            }
            if c.can_open() {
                if let Normal::Elastic {
                    normal, k, c: cc, ..
                } = &c.normal
                {
                    // F_n = k δ + c δ̇.
                    let mut f_n = [0.0; N];
                    normal.add_scaled(&mut f_n[..n], *k);
                    normal.add_scaled(&mut f_n[n..], *cc);
                    let (g, d) = contact::separation_guard(&(f_n, 0.0));
                    push(GuardKind::Separation, g, d, true);
                }
            }
            match mode {
                Mode::SlipPos | Mode::SlipNeg => {
                    // v = V + t·q̇.
                    let mut v = [0.0; N];
                    c.tangent.add_scaled(&mut v[n..], 1.0);
                    let (g, d) = contact::slip_zero_guard(mode, &(v, c.v));
                    push(GuardKind::SlipZero, g, d, true);
                }
                Mode::Stick => {
                    for (kind, sign) in [
                        (GuardKind::StickBreakPos, 1.0),
                        (GuardKind::StickBreakNeg, -1.0),
                    ] {
                        // The (linear part's) gradient by unit evaluations: exact for an affine
                        // function. At a finite time: a force that varies in time adds the same
                        // term to every evaluation (and cancels), but a harmonic one is NaN at
                        // t = ∞, which made the gradient, the guard's slope bound and so every
                        // event search of a forced model in stick NaN (the step then shrank to
                        // underflow). The constant `d` is used only by affine guards, which have
                        // no time-varying force.
                        let t = 0.0;
                        let zero = [0.0; N];
                        let d = self.stick_guard(t, modes, i, sign, &zero, affine_stick);
                        let mut g = [0.0; N];
                        for (k, gk) in g.iter_mut().enumerate() {
                            let mut e = [0.0; N];
                            e[k] = 1.0;
                            *gk = self.stick_guard(t, modes, i, sign, &e, affine_stick) - d;
                        }
                        push(kind, g, d, affine_stick);
                    }
                }
                Mode::Free => unreachable!("handled above"),
            }
        }
    }

    fn guard_value(&self, t: f64, modes: &Modes, g: &Guard<N>, z: &[f64; N]) -> f64 {
        if g.affine {
            return g.eval(z);
        }
        let sign = if g.kind == GuardKind::StickBreakPos {
            1.0
        } else {
            -1.0
        };
        self.stick_guard(t, modes, g.contact as usize, sign, z, true)
    }

    fn guard_gradient(&self, _t: f64, modes: &Modes, g: &Guard<N>, z: &[f64; N]) -> [f64; N] {
        if g.affine {
            return g.c;
        }
        // The linear part (g.c) plus −a_ij ∇(s_j μ(s_j v_j) F_n,j) of each slipping contact j.
        let n = N / 2;
        let i = g.contact as usize;
        let sign = if g.kind == GuardKind::StickBreakPos {
            1.0
        } else {
            -1.0
        };
        let a = self.slip_coupling(modes, i);
        let mut out = g.c;
        let (q, u) = z.split_at(n);
        for (j, c) in self.contacts.iter().enumerate() {
            let mode = modes.get(j);
            if !(mode == Mode::SlipPos || mode == Mode::SlipNeg) || a[j] == 0.0 {
                continue;
            }
            let s = mode.slip_sign();
            let v = c.sliding_velocity(u);
            let f_n = c.normal_force(q, u);
            let fnf = c.friction_normal(f_n);
            let clipped = fnf != f_n;
            let (mu, dmu) = (c.friction.mu(s * v), c.friction.dmu(s * v));
            let w = -sign * a[j];
            // ∇(s μ(s v) F) = s μ ∇F + F μ' ∇v.
            if let (
                Normal::Elastic {
                    normal, k, c: cc, ..
                },
                false,
            ) = (&c.normal, clipped)
            {
                normal.add_scaled(&mut out[..n], w * s * mu * k);
                normal.add_scaled(&mut out[n..], w * s * mu * cc);
            }
            c.tangent.add_scaled(&mut out[n..], w * fnf * dmu);
        }
        out
    }

    fn guard_slope_bound(
        &self,
        t0: f64,
        h: f64,
        modes: &Modes,
        g: &Guard<N>,
        lo: &[f64; N],
        hi: &[f64; N],
        rate: &[f64; N],
    ) -> f64 {
        let n = N / 2;
        let mut l: f64 = (0..N).map(|k| g.c[k].abs() * rate[k]).sum();
        if g.affine {
            return l;
        }
        let i = g.contact as usize;
        let a = self.slip_coupling(modes, i);
        for (j, c) in self.contacts.iter().enumerate() {
            let mode = modes.get(j);
            if !(mode == Mode::SlipPos || mode == Mode::SlipNeg) || a[j] == 0.0 {
                continue;
            }
            let s = mode.slip_sign();
            let (vlo, vhi) = c.tangent.range(lo, hi, n);
            let (vlo, vhi) = (s * (c.v + vlo), s * (c.v + vhi));
            let (mu_max, dmu_max) = c.friction.bounds(vlo.min(vhi), vlo.max(vhi));
            let (f_max, f_rate) = match &c.normal {
                Normal::Elastic {
                    normal, k, c: cc, ..
                } => (
                    k * normal.abs_bound(lo, hi, 0) + cc * normal.abs_bound(lo, hi, n),
                    k * normal.abs_weighted(rate, 0) + cc * normal.abs_weighted(rate, n),
                ),
                Normal::Prescribed(f) => (f.abs(), 0.0),
            };
            let v_rate = c.tangent.abs_weighted(rate, n);
            l += a[j].abs() * (dmu_max * v_rate * f_max + mu_max * f_rate);
        }
        if self.time_varying {
            // ∂g/∂t from the forces that vary in time: |P_i·on| times a
            // bound of the force's rate (ramps, harmonic parts).
            let p = self.stick_projection(modes, i);
            for f in self.forces.iter().filter(|f| f.varies()) {
                let rate = f.rate_bound(t0);
                if rate > 0.0 {
                    let pf: f64 =
                        f.on.idx
                            .iter()
                            .zip(&f.on.coef)
                            .map(|(k, c)| c * p[*k])
                            .sum();
                    l += h * pf.abs() * rate;
                }
            }
        }
        l
    }

    fn switch(
        &self,
        t: f64,
        modes: &Modes,
        g: &Guard<N>,
        z: &mut [f64; N],
    ) -> (Modes, Option<EventKind>) {
        let n = N / 2;
        let i = g.contact as usize;
        let old = modes.get(i);
        let mut next = *modes;
        let c = &self.contacts[i];
        if g.kind == GuardKind::SlipZero {
            // On the surface v = 0 exactly: the mass-weighted projection
            // u ← u − v·M⁻¹t/(t·M⁻¹t).
            let v = c.sliding_velocity(&z[n..]);
            let w = v / self.gram[i][i];
            for k in 0..n {
                z[n + k] -= w * self.minv_t[i][k];
            }
        }
        let z = &*z;
        let (m, event) = contact::after_guard(g.kind, old, || {
            if g.kind == GuardKind::SlipZero {
                let m = self.contact_mode_at(t, modes, i, &z[..], true);
                // Reached v = 0 without leaving the contact: stick or slip on.
                if m == Mode::Free {
                    old
                } else {
                    m
                }
            } else {
                // On the surface δ = 0: decide the friction mode as in contact.
                let f_n = c.normal_force(&z[..n], &z[n..]);
                let v = c.sliding_velocity(&z[n..]);
                let f_stick = if v != 0.0 {
                    0.0
                } else {
                    let mut trial = *modes;
                    trial.set(i, Mode::Stick);
                    self.stick_force(t, &trial, i, &z[..])
                };
                c.mode_for(v, f_stick, f_n)
            }
        });
        next.set(i, m);
        (next, event)
    }

    fn start_modes(&self, t: f64, z: &[f64; N]) -> Modes {
        let mut m = Modes::all(self.contacts.len(), Mode::Free);
        for i in 0..self.contacts.len() {
            let mode = self.contact_mode(t, &m, i, &z[..]);
            m.set(i, mode);
        }
        m
    }

    fn observe_contact(&self, t: f64, modes: &Modes, z: &[f64; N], i: usize) -> Observables {
        self.observe_dyn(t, modes, z, i)
    }

    #[inline]
    fn breakpoint_after(&self, t: f64) -> Option<f64> {
        if !self.time_varying {
            return None;
        }
        self.forces
            .iter()
            .filter(|f| f.ramp > 0.0 && t < f.ramp)
            .map(|f| f.ramp)
            .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.min(b))))
    }

    fn forcing_hz(&self) -> Vec<f64> {
        Lumped::forcing_hz(self)
    }

    fn steady_sliding(&self) -> Result<[f64; N], ModelError> {
        let z = self.equilibrium_dyn()?;
        let mut out = [0.0; N];
        out.copy_from_slice(&z);
        Ok(out)
    }

    fn norm_states(&self) -> usize {
        self.real_state_count()
    }

    fn state_jacobian(&self, z: &[f64; N]) -> [[f64; N]; N] {
        let a = self.jacobian_dyn(z);
        let mut out = [[0.0; N]; N];
        for (r, row) in out.iter_mut().enumerate() {
            for (c, x) in row.iter_mut().enumerate() {
                *x = a[(r, c)];
            }
        }
        out
    }
}

impl Lumped {
    /// Row `i` of `P = G_S⁻¹ T_S M⁻¹` for the stick set of `modes`, as a dense n-vector:
    /// `λ_i = P_i·f`.
    pub(super) fn stick_projection(&self, modes: &Modes, i: usize) -> Vec<f64> {
        let n = self.dofs.len();
        let (set, k) = stick_set(modes);
        let a = set[..k].iter().position(|&j| j == i).unwrap_or(0);
        let mut p = vec![0.0; n];
        // Row a of G⁻¹: solve Gᵀ x = e_a (G is symmetric without follower terms).
        let mut g = [[0.0; MAX_CONTACTS]; MAX_CONTACTS];
        for (r, &j) in set[..k].iter().enumerate() {
            for (c, &l) in set[..k].iter().enumerate() {
                g[r][c] = self.gram[l][j];
            }
        }
        let mut x = [0.0; MAX_CONTACTS];
        x[a] = 1.0;
        if !solve_small(&mut g, &mut x, k) {
            return vec![f64::INFINITY; n];
        }
        for (r, &j) in set[..k].iter().enumerate() {
            for (pk, m) in p.iter_mut().zip(&self.minv_t[j]) {
                *pk += x[r] * m;
            }
        }
        p
    }

    /// `a_ij = P_i·t_j`: how contact j's friction force enters sticking contact i's multiplier.
    pub(super) fn slip_coupling(&self, modes: &Modes, i: usize) -> [f64; MAX_CONTACTS] {
        let p = self.stick_projection(modes, i);
        let mut a = [0.0; MAX_CONTACTS];
        for (j, c) in self.contacts.iter().enumerate() {
            a[j] = c.tangent.dot(&p);
        }
        a
    }
}

/// A lumped model seen at one state count `N = 2·dofs`, so that generic code
/// (`simulate`, `analyse`) infers `N` from the type. Delegates everything.
#[derive(Debug, Clone, Copy)]
pub struct Fixed<'a, const N: usize>(pub &'a Lumped);

impl<const N: usize> System<N> for Fixed<'_, N> {
    fn system_name(&self) -> &str {
        "lumped"
    }
    fn names(&self) -> Vec<String> {
        self.0.states.clone()
    }
    fn contacts(&self) -> usize {
        self.0.contacts.len()
    }
    fn contact_name(&self, i: usize) -> &str {
        &self.0.contacts[i].name
    }
    #[inline(always)]
    fn field(&self, t: f64, modes: &Modes, z: &[f64; N], dz: &mut [f64; N]) {
        <Lumped as System<N>>::field(self.0, t, modes, z, dz)
    }
    fn mode_guards(&self, modes: &Modes, out: &mut Guards<N>) {
        <Lumped as System<N>>::mode_guards(self.0, modes, out)
    }
    #[inline]
    fn guard_value(&self, t: f64, modes: &Modes, g: &Guard<N>, z: &[f64; N]) -> f64 {
        <Lumped as System<N>>::guard_value(self.0, t, modes, g, z)
    }
    fn guard_gradient(&self, t: f64, modes: &Modes, g: &Guard<N>, z: &[f64; N]) -> [f64; N] {
        <Lumped as System<N>>::guard_gradient(self.0, t, modes, g, z)
    }
    fn guard_slope_bound(
        &self,
        t0: f64,
        h: f64,
        modes: &Modes,
        g: &Guard<N>,
        lo: &[f64; N],
        hi: &[f64; N],
        rate: &[f64; N],
    ) -> f64 {
        <Lumped as System<N>>::guard_slope_bound(self.0, t0, h, modes, g, lo, hi, rate)
    }
    fn switch(
        &self,
        t: f64,
        modes: &Modes,
        g: &Guard<N>,
        z: &mut [f64; N],
    ) -> (Modes, Option<EventKind>) {
        <Lumped as System<N>>::switch(self.0, t, modes, g, z)
    }
    fn start_modes(&self, t: f64, z: &[f64; N]) -> Modes {
        <Lumped as System<N>>::start_modes(self.0, t, z)
    }
    fn observe_contact(&self, t: f64, modes: &Modes, z: &[f64; N], i: usize) -> Observables {
        self.0.observe_dyn(t, modes, z, i)
    }
    #[inline]
    fn breakpoint_after(&self, t: f64) -> Option<f64> {
        <Lumped as System<N>>::breakpoint_after(self.0, t)
    }
    fn forcing_hz(&self) -> Vec<f64> {
        self.0.forcing_hz()
    }
    fn steady_sliding(&self) -> Result<[f64; N], ModelError> {
        <Lumped as System<N>>::steady_sliding(self.0)
    }
    fn state_jacobian(&self, z: &[f64; N]) -> [[f64; N]; N] {
        <Lumped as System<N>>::state_jacobian(self.0, z)
    }
    fn norm_states(&self) -> usize {
        self.0.real_state_count()
    }
}

/// Run `$body` with `$m` bound to `&Fixed<N>` for the lumped model `$l`
/// (`N = 2·dofs`, dofs ≤ [`MAX_EXACT_DOFS`]), or evaluate `$fallback` for a
/// larger model (see [`with_padded_size!`](crate::with_padded_size) for simulation).
#[macro_export]
macro_rules! with_lumped_size {
    ($l:expr, $m:ident => $body:expr, else => $fallback:expr) => {{
        use $crate::model::lumped::Fixed;
        let l: &$crate::Lumped = $l;
        match l.dof_count() {
            1 => {
                let $m = &Fixed::<2>(l);
                $body
            }
            2 => {
                let $m = &Fixed::<4>(l);
                $body
            }
            3 => {
                let $m = &Fixed::<6>(l);
                $body
            }
            4 => {
                let $m = &Fixed::<8>(l);
                $body
            }
            5 => {
                let $m = &Fixed::<10>(l);
                $body
            }
            6 => {
                let $m = &Fixed::<12>(l);
                $body
            }
            7 => {
                let $m = &Fixed::<14>(l);
                $body
            }
            8 => {
                let $m = &Fixed::<16>(l);
                $body
            }
            9 => {
                let $m = &Fixed::<18>(l);
                $body
            }
            10 => {
                let $m = &Fixed::<20>(l);
                $body
            }
            11 => {
                let $m = &Fixed::<22>(l);
                $body
            }
            12 => {
                let $m = &Fixed::<24>(l);
                $body
            }
            13 => {
                let $m = &Fixed::<26>(l);
                $body
            }
            14 => {
                let $m = &Fixed::<28>(l);
                $body
            }
            15 => {
                let $m = &Fixed::<30>(l);
                $body
            }
            16 => {
                let $m = &Fixed::<32>(l);
                $body
            }
            _ => $fallback,
        }
    }};
}

//! General lumped mechanical models with several frictional contacts, built
//! from a description ([`LumpedSpec`]) rather than written in Rust.
//!
//! Degrees of freedom `q` (named), masses (a diagonal, and/or a full
//! symmetric positive definite matrix `M`), springs on linear combinations of
//! dofs, stiffness and damping matrices `K`, `C`, constant (or ramped) forces
//! and up to [`MAX_CONTACTS`] frictional [`Contact`]s:
//!
//! ```text
//! M q̈ = F(t) − K q − C q̇ − Σ_springs (k e + c ė) a − Σ_contacts (F_n n + F_t t − F_f n)
//! ```
//!
//! with `e = a·q` per spring, and per contact the compression `δ = n·q`,
//! `F_n = k δ + c δ̇` (or a prescribed load), sliding velocity `v = V + t·q̇`,
//! friction `F_t = μ(|v|) F_n sign(v)` in slip and follower force
//! `F_f = α F_t (s·q)`.
//!
//! **Sticking contacts** are constraints `t_i·q̈ = 0`: their friction forces
//! `λ` (Lagrange multipliers) solve one small linear system
//! `Σ_k (t_j M⁻¹ w_k) λ_k = t_j M⁻¹ f` with `w_k = t_k − α_k (s_k·q) n_k`,
//! `f` the force without them. A contact leaves stick when its own multiplier
//! exceeds `μ_s F_n` in either direction. The constraint set of all contacts
//! is checked once, when the model is built: if the tangents are linearly
//! dependent in the metric `M⁻¹` (a redundant or contradictory set), the
//! model is refused naming the contacts, so every subset is regular.
//!
//! **Guards.** Slip reversal, separation and recontact are affine in the
//! state. A stick-break guard is affine too unless another contact slips with
//! velocity-dependent friction (its multiplier then contains `μ(v)` of the
//! other contact), a bilateral contact slips, or a force is ramped; such
//! guards are evaluated exactly and searched with a Lipschitz bound
//! ([`System::guard_slope_bound`]), so no crossing is missed either.
//!
//! State `z = (q, q̇)`; positions named after the dofs, velocities `v<dof>`.

use super::contact::{self, Combination, Contact, Normal};
use super::{
    EventKind, Guard, GuardKind, Guards, Mode, ModelError, Modes, Observables, System, MAX_CONTACTS,
};
use crate::friction::FrictionLaw;
use crate::linear::{ModalOptions, SecondOrder, SparseSecondOrder, SPARSE_FROM_DOFS};
use crate::params::ParamError;
use nalgebra::DMatrix;

/// A bad model description: one line naming the element and key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SpecError(pub String);

fn bad<T>(msg: impl Into<String>) -> Result<T, SpecError> {
    Err(SpecError(msg.into()))
}

/// `M⁻¹`: diagonal, dense row-major, or (a large model's non-diagonal
/// `M`, more than [`SPARSE_FROM_DOFS`] dofs) a sparse Cholesky factor of
/// `M` (a dense inverse would take `n³/3` flops and `8 n²` bytes).
#[derive(Debug, Clone, PartialEq)]
enum InvMass {
    Diagonal(Vec<f64>),
    Dense(Vec<f64>),
    Factored(MassFactor),
}

/// The sparse Cholesky factor of a large model's `M` ([`InvMass`]). Two
/// factors compare equal: they are derived from the mass matrices, which
/// the model compares itself.
#[derive(Debug, Clone)]
struct MassFactor(std::sync::Arc<faer::sparse::linalg::solvers::Llt<usize, f64>>);

impl PartialEq for MassFactor {
    fn eq(&self, _: &MassFactor) -> bool {
        true
    }
}

impl MassFactor {
    /// `X ← M⁻¹ X`.
    fn solve_in_place(&self, x: faer::MatMut<'_, f64>) {
        use faer::linalg::solvers::Solve;
        self.0.solve_in_place(x);
    }
}

/// A lumped model (see the module docs). Build it with [`Lumped::build`].
#[derive(Debug, Clone, PartialEq)]
pub struct Lumped {
    dofs: Vec<String>,
    states: Vec<String>,
    /// Diagonal masses from `[masses]` (0 where only `M` gives one).
    masses: Vec<f64>,
    m_matrix: Option<Sparse>,
    k_matrix: Option<Sparse>,
    c_matrix: Option<Sparse>,
    /// `M`, `K`, `C` as read, and the scale factor each is used with
    /// (keys `matrices.M_scale`, `matrices.K_scale`, `matrices.C_scale`).
    matrix_base: [Option<Sparse>; 3],
    matrix_scale: [f64; 3],
    /// Springs. Change their parameters through [`Lumped::set`]: the
    /// right-hand side of a small model uses operators derived from them.
    pub springs: Vec<Spring>,
    /// Forces (as [`Lumped::springs`]: change them through [`Lumped::set`]).
    pub forces: Vec<Force>,
    /// Contacts (their combinations, `k`, `c` and the bilateral flag are
    /// folded into the right-hand side's operators: change those through
    /// [`Lumped::set`]; laws, `V` and `alpha` are read directly).
    pub contacts: Vec<Contact>,
    /// How the complex eigenvalue analysis is solved (dense or projected;
    /// keys `modal.dense_max_dofs`, `modal.modes`, `modal.cutoff_hz`).
    pub modal: ModalOptions,
    /// Shared parameters and the keys bound to them (see [`shared`]).
    shared: shared::Shared,
    // Derived from the above by `refresh`.
    inv_mass: InvMass,
    /// `M⁻¹ t_j` per contact, dense.
    minv_t: Vec<Vec<f64>>,
    /// `t_i·M⁻¹ t_j`.
    gram: [[f64; MAX_CONTACTS]; MAX_CONTACTS],
    /// `t_i·M⁻¹ n_j`.
    tn: [[f64; MAX_CONTACTS]; MAX_CONTACTS],
    /// Whether a force varies in time (a ramp or a harmonic part).
    time_varying: bool,
    /// Dense operators of the right-hand side (models of at most
    /// [`DENSE_FIELD_DOFS`] dofs); rebuilt whenever a parameter changes.
    dense: Option<DenseField>,
}

/// The keys scaling the matrices read from files: `matrices.<key>`.
pub const MATRIX_SCALE_KEYS: [&str; 3] = ["M_scale", "K_scale", "C_scale"];

/// Up to this many dofs the simulated right-hand side runs on operators
/// folded once per parameter change (every spring, `K` and `C` in one
/// operator, the constant forces in one vector, each contact's combinations
/// as dense rows) instead of looping over the elements.
pub const DENSE_FIELD_DOFS: usize = 16;

/// A dense row on the dofs (`n ≤ DENSE_FIELD_DOFS` entries used).
type Row = [f64; DENSE_FIELD_DOFS];

/// The right-hand side of a small model on folded operators. The force of
/// every spring, `K` and `C`, `∂force/∂z`, is split into its diagonals on
/// `q` and on `q̇` (dense rows: the loops over them have the model's size
/// as a compile-time trip count in [`System::field`] and no bounds checks)
/// and the remaining off-diagonal entries; each contact's combinations are
/// dense rows, so its dot products and scatters are straight-line code.
#[derive(Debug, Clone, PartialEq)]
struct DenseField {
    /// `Σ value·on` of the forces without a ramp.
    f0: Row,
    /// Diagonal of `∂force/∂q` (springs and `K`, negated).
    kd: Row,
    /// Diagonal of `∂force/∂q̇` (springs and `C`, negated).
    cd: Row,
    /// The other entries `(row, column on z, value)`, row-major, duplicates
    /// summed: their force is `Σ value·z[column]` into `row`.
    off: Vec<(usize, usize, f64)>,
    /// `M⁻¹` when it is diagonal (else zero).
    inv_mass: Row,
    /// Plain: no ramped force, no off-diagonal entry, a diagonal `M⁻¹`: the
    /// force is `f0 + kd·q + cd·q̇` and the contacts', then scaled by `inv_mass`.
    plain: bool,
    /// Per contact (in order), its combinations as dense rows.
    contacts: Vec<FoldedContact>,
}

/// One contact's combinations as dense rows (the contact's `V`, friction
/// law and `alpha` are read from the [`Contact`] itself).
#[derive(Debug, Clone, PartialEq)]
struct FoldedContact {
    /// `F_n = fn_q·q + fn_u·q̇` (`k n` and `c n`; zero for a prescribed load).
    fn_q: Row,
    /// See `fn_q`.
    fn_u: Row,
    /// The normal `n` on the dofs.
    normal: Row,
    /// The tangent `t` (the sliding velocity is `V + t·q̇`).
    tangent: Row,
    /// The follower force's slope `s` (on `q`).
    slope: Row,
    /// A bilateral layer: friction acts on `max(F_n, 0)`.
    bilateral: bool,
}

/// `Σ a_i·b_i` summed in index order (the terms with a zero coefficient add
/// an exact zero, so the sum equals the sum over the non-zero terms),
/// starting from the first product rather than from `0 + a_0·b_0` (one
/// addition less on the critical path; only the sign of an all-zero sum can
/// differ).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    match (a.split_first(), b.split_first()) {
        (Some((x, a)), Some((y, b))) => dot_from(x * y, a, b),
        _ => 0.0,
    }
}

/// `Σ a_i·b_i` in four interleaved partial sums (term `i` into sum
/// `i mod 4`, then `(s0 + s1) + (s2 + s3)`, then the tail in order): the
/// sums are independent, so the compiler keeps them in one SIMD register
/// instead of a chain of dependent additions (a dense `M⁻¹` row of a
/// reduced FE model: hundreds of terms). The same order for every call;
/// zero terms add exact zeros, so every padded size (a multiple of 4, the
/// real entries leading each row) gives the same bits.
#[inline(always)]
fn dot_lanes(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    dot_from((s[0] + s[1]) + (s[2] + s[3]), ar, br)
}

/// `s + Σ a_i·b_i`, added in index order.
#[inline(always)]
fn dot_from(mut s: f64, a: &[f64], b: &[f64]) -> f64 {
    for (x, y) in a.iter().zip(b) {
        s += x * y;
    }
    s
}

/// A combination as a dense row on `n ≤ DENSE_FIELD_DOFS` dofs, scaled by `a`.
fn dense_row(c: &Combination, a: f64) -> Row {
    let mut r = [0.0; DENSE_FIELD_DOFS];
    c.add_scaled(&mut r, a);
    r
}

/// Up to this many dofs, guard evaluations use a stack buffer (no allocation).
const STACK_DOFS: usize = 64;

/// Keys of a spring, force and contact (beside the friction law's).
pub const SPRING_KEYS: [&str; 3] = ["k", "c", "k3"];
/// See [`SPRING_KEYS`].
pub const FORCE_KEYS: [&str; 4] = ["value", "ramp", "amplitude", "freq_hz"];

/// The small dense solve `G x = b` (`k ≤ MAX_CONTACTS`), Gaussian elimination
/// with partial pivoting on stack arrays. `false` if `G` is singular.
fn solve_small(
    g: &mut [[f64; MAX_CONTACTS]; MAX_CONTACTS],
    b: &mut [f64; MAX_CONTACTS],
    k: usize,
) -> bool {
    for col in 0..k {
        let mut p = col;
        for r in col + 1..k {
            if g[r][col].abs() > g[p][col].abs() {
                p = r;
            }
        }
        if g[p][col] == 0.0 || !g[p][col].is_finite() {
            return false;
        }
        g.swap(col, p);
        b.swap(col, p);
        for r in col + 1..k {
            let f = g[r][col] / g[col][col];
            if f != 0.0 {
                for c in col..k {
                    g[r][c] -= f * g[col][c];
                }
                b[r] -= f * b[col];
            }
        }
    }
    for col in (0..k).rev() {
        let mut s = b[col];
        for c in col + 1..k {
            s -= g[col][c] * b[c];
        }
        b[col] = s / g[col][col];
    }
    true
}

/// The contacts sticking in `modes`, in order, and how many.
#[inline]
fn stick_set(modes: &Modes) -> ([usize; MAX_CONTACTS], usize) {
    let mut s = [0; MAX_CONTACTS];
    let mut k = 0;
    for (i, m) in modes.as_slice().iter().enumerate() {
        if *m == Mode::Stick {
            s[k] = i;
            k += 1;
        }
    }
    (s, k)
}

impl Lumped {
    /// `M⁻¹ x` (allocating; for set-up).
    fn apply_inv_mass_vec(&self, x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; x.len()];
        self.apply_inv_mass(x, &mut out);
        out
    }

    /// `out = M⁻¹ x`.
    #[inline]
    fn apply_inv_mass(&self, x: &[f64], out: &mut [f64]) {
        match &self.inv_mass {
            InvMass::Diagonal(inv) => {
                for i in 0..inv.len() {
                    out[i] = x[i] * inv[i];
                }
            }
            InvMass::Dense(inv) => {
                let n = x.len();
                for r in 0..n {
                    out[r] = dot_lanes(&inv[r * n..(r + 1) * n], x);
                }
            }
            InvMass::Factored(f) => {
                let mut v = faer::Mat::<f64>::from_fn(x.len(), 1, |i, _| x[i]);
                f.solve_in_place(v.as_mut());
                for (i, o) in out.iter_mut().enumerate() {
                    *o = v[(i, 0)];
                }
            }
        }
    }

    /// Number of dofs.
    pub fn dof_count(&self) -> usize {
        self.dofs.len()
    }
    /// Dof names.
    pub fn dofs(&self) -> &[String] {
        &self.dofs
    }
    /// `M`, `K`, `C` as read from the model's files, on [`Lumped::dofs`]
    /// (after the static condensation of massless dofs), before their
    /// scale factors (`matrices.M_scale`, …) and without `[masses]`,
    /// springs or contacts; `None` where the file has no such matrix.
    pub fn file_matrices(&self) -> [Option<&Sparse>; 3] {
        [
            self.matrix_base[0].as_ref(),
            self.matrix_base[1].as_ref(),
            self.matrix_base[2].as_ref(),
        ]
    }
    /// State names: the dofs, then `v<dof>`.
    pub fn state_names(&self) -> &[String] {
        &self.states
    }
    /// The mass on each dof's diagonal (for energy-weighted mode attribution).
    pub fn diagonal_masses(&self) -> Vec<f64> {
        (0..self.dofs.len())
            .map(|i| self.masses[i] + self.m_matrix.as_ref().map_or(0.0, |m| m.get(i, i)))
            .collect()
    }

    /// Mode of contact `i` at `(t, z)` given the others' `modes`: free if a
    /// unilateral layer is open, else by the sign of v, and at `v = 0` stick
    /// if its multiplier (with it sticking) is within `μ_s F_n`.
    fn contact_mode(&self, t: f64, modes: &Modes, i: usize, z: &[f64]) -> Mode {
        self.contact_mode_at(t, modes, i, z, false)
    }

    /// [`Self::contact_mode`]; with `at_rest`, the contact is known to be at
    /// `v = 0` (just projected there), so the `v` recomputed from the state,
    /// `V + t·q̇`, is round-off (≈ 1e-17 of cancelling terms) and its sign
    /// must not choose a slip direction: the stick test decides.
    fn contact_mode_at(&self, t: f64, modes: &Modes, i: usize, z: &[f64], at_rest: bool) -> Mode {
        let n = self.dofs.len();
        let (q, u) = z.split_at(n);
        let c = &self.contacts[i];
        let f_n = c.normal_force(q, u);
        if c.can_open() {
            if let Normal::Elastic { normal, .. } = &c.normal {
                if normal.dot(q) < 0.0 || f_n < 0.0 {
                    return Mode::Free;
                }
            }
        }
        let v = if at_rest { 0.0 } else { c.sliding_velocity(u) };
        if v != 0.0 {
            return c.mode_for(v, 0.0, f_n);
        }
        let mut trial = *modes;
        trial.set(i, Mode::Stick);
        let lambda = self.stick_force(t, &trial, i, z);
        c.mode_for(0.0, lambda, f_n)
    }

    /// Multiplier of sticking contact `i` in `modes`.
    fn stick_force(&self, t: f64, modes: &Modes, i: usize, z: &[f64]) -> f64 {
        // λ_i − μ_s F_n + μ_s F_n, without a second copy of the solve.
        let c = &self.contacts[i];
        let n = self.dofs.len();
        self.stick_guard(t, modes, i, 1.0, z, true)
            + c.friction.mu_static() * c.normal_force(&z[..n], &z[n..])
    }

    /// The sliding direction of contact `i` at steady sliding (`sign V`).
    fn steady_mode(&self, i: usize) -> Mode {
        if self.contacts[i].v >= 0.0 {
            Mode::SlipPos
        } else {
            Mode::SlipNeg
        }
    }

    /// The modes of steady sliding.
    pub fn steady_modes(&self) -> Modes {
        let mut m = Modes::all(self.contacts.len(), Mode::SlipPos);
        for i in 0..self.contacts.len() {
            m.set(i, self.steady_mode(i));
        }
        m
    }

    /// Right-hand side for any size (allocating; stability and tests).
    pub fn field_dyn(&self, t: f64, modes: &Modes, z: &[f64]) -> Vec<f64> {
        let n = self.dofs.len();
        let (q, u) = z.split_at(n);
        let mut acc = vec![0.0; n];
        self.force(t, modes, q, u, &mut acc);
        let mut dz = vec![0.0; 2 * n];
        dz[..n].copy_from_slice(u);
        self.apply_inv_mass(&acc, &mut dz[n..]);
        dz
    }

    /// Forces and sliding velocity of contact `i` (any size).
    pub fn observe_dyn(&self, t: f64, modes: &Modes, z: &[f64], i: usize) -> Observables {
        let n = self.dofs.len();
        let (q, u) = z.split_at(n);
        let c = &self.contacts[i];
        let v_rel = c.sliding_velocity(u);
        let mode = modes.get(i);
        let (normal_force, friction_force) = match mode {
            Mode::Free => (0.0, 0.0),
            Mode::Stick => (c.normal_force(q, u), self.stick_force(t, modes, i, z)),
            _ => {
                let f_n = c.normal_force(q, u);
                (f_n, c.slip_force(mode, v_rel, f_n))
            }
        };
        Observables {
            normal_force,
            friction_force,
            v_rel,
        }
    }
}

/// The masses a model may have (kg, or kg·m² for a rotation): from 1e-30 to
/// 1e30. Beyond, `1/m` vanishes beside the other masses' in double
/// precision (a pad of 1e300 kg leaves the stick constraints of a two-pad
/// brake numerically dependent) or overflows: such a mass is refused as a
/// bad mass, naming it, rather than surfacing as a numerical failure.
pub const MASS_RANGE: (f64, f64) = (1e-30, 1e30);

/// Whether `m` is a mass squeal accepts ([`MASS_RANGE`]).
pub fn mass_ok(m: f64) -> bool {
    m.is_finite() && (MASS_RANGE.0..=MASS_RANGE.1).contains(&m)
}

/// Most dofs a model may have (10⁶, an FE brake at full size): checked from
/// a matrix file's header before anything is sized from it, and by
/// [`Lumped::build`].
pub const MAX_MODEL_DOFS: usize = 1_000_000;

/// Most dofs a lumped model may have to be simulated: the integrator works on
/// fixed-size state arrays, so each size is compiled in — every size up to
/// [`MAX_EXACT_DOFS`], then the padded sizes of [`PADDED_DOFS`] (see
/// [`padding`]). Stability analysis works for any size.
pub const MAX_SIM_DOFS: usize = 128;

/// Most dofs a lumped model may have for a transient run (`simulate`,
/// `listen`, `map --transient`): above [`MAX_SIM_DOFS`] it runs in one of the
/// larger padded sizes of [`TRANSIENT_PADDED_DOFS`] (limit cycles do not).
pub const MAX_TRANSIENT_DOFS: usize = 512;

mod build;
pub mod condense;
mod folded;
mod forces;
pub mod lanes;
mod linearised;
pub mod padding;
mod params;
pub mod shared;
mod sparse;
mod spec;
mod specs;
mod steady;
mod system;
pub use linearised::StuckModes;
pub use padding::{
    embed, padded_dofs, padded_solver, real_states, transient_padded_dofs, MAX_EXACT_DOFS,
    PADDED_DOFS, TRANSIENT_PADDED_DOFS,
};
use params::prefixed;
pub use sparse::{Sparse, Triplets};
pub use specs::{disc_pad_spec, two_pad_spec};
pub use system::Fixed;

pub use spec::{ContactSpec, Force, ForceSpec, LumpedSpec, Spring, SpringSpec, Terms};

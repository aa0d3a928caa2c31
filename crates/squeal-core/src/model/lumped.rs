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

/// A matrix as coordinate triplets (0-based), e.g. read from Matrix Market.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Triplets {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// `(row, col, value)`; repeated entries add up.
    pub entries: Vec<(usize, usize, f64)>,
}

/// A square sparse matrix in compressed rows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sparse {
    /// Size.
    pub n: usize,
    row_ptr: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
}

impl Sparse {
    /// From triplets (duplicates summed, zeros dropped).
    pub fn from_triplets(t: &Triplets) -> Sparse {
        let n = t.rows;
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for &(r, c, v) in &t.entries {
            rows[r].push((c, v));
        }
        let mut s = Sparse {
            n,
            row_ptr: vec![0],
            col: Vec::new(),
            val: Vec::new(),
        };
        for mut row in rows {
            row.sort_by_key(|e| e.0);
            let mut merged: Vec<(usize, f64)> = Vec::new();
            for (c, v) in row {
                match merged.last_mut() {
                    Some(last) if last.0 == c => last.1 += v,
                    _ => merged.push((c, v)),
                }
            }
            for (c, v) in merged.into_iter().filter(|e| e.1 != 0.0) {
                s.col.push(c);
                s.val.push(v);
            }
            s.row_ptr.push(s.col.len());
        }
        s
    }
    /// `out += a·(A x)`.
    #[inline]
    pub fn mul_add(&self, x: &[f64], out: &mut [f64], a: f64) {
        for r in 0..self.n {
            let mut s = 0.0;
            for k in self.row_ptr[r]..self.row_ptr[r + 1] {
                s += self.val[k] * x[self.col[k]];
            }
            out[r] += a * s;
        }
    }
    /// Every entry times `f` (`f = 1`: an exact copy).
    pub fn scaled(&self, f: f64) -> Sparse {
        let mut s = self.clone();
        if f != 1.0 {
            for v in &mut s.val {
                *v *= f;
            }
        }
        s
    }
    /// Entry `(r, c)`.
    pub fn get(&self, r: usize, c: usize) -> f64 {
        (self.row_ptr[r]..self.row_ptr[r + 1])
            .find(|&k| self.col[k] == c)
            .map_or(0.0, |k| self.val[k])
    }
    /// Non-zero entries `(row, col, value)`.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (0..self.n).flat_map(move |r| {
            (self.row_ptr[r]..self.row_ptr[r + 1]).map(move |k| (r, self.col[k], self.val[k]))
        })
    }
    /// The same matrix in faer's compressed columns (for sparse
    /// factorisations and products).
    pub fn to_faer(&self) -> faer::sparse::SparseColMat<usize, f64> {
        let t: Vec<faer::sparse::Triplet<usize, usize, f64>> = self
            .entries()
            .map(|(r, c, v)| faer::sparse::Triplet::new(r, c, v))
            .collect();
        faer::sparse::SparseColMat::try_new_from_triplets(self.n, self.n, &t)
            .expect("a Sparse's indices are within its size")
    }
    /// Whether `A = Aᵀ` exactly.
    pub fn is_symmetric(&self) -> bool {
        self.entries().all(|(r, c, v)| self.get(c, r) == v)
    }
    /// The same matrix, dense.
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut d = DMatrix::<f64>::zeros(self.n, self.n);
        for (r, c, v) in self.entries() {
            d[(r, c)] += v;
        }
        d
    }
    /// Whether only diagonal entries are non-zero.
    pub fn is_diagonal(&self) -> bool {
        self.entries().all(|(r, c, _)| r == c)
    }
}

/// A linear spring–damper on `e = on·q`: generalised force `−(k e + c ė)·on`.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// Element name.
    pub name: String,
    /// The elongation's coefficients.
    pub on: Combination,
    /// Stiffness (N/m).
    pub k: f64,
    /// Damping (kg/s).
    pub c: f64,
}

/// A constant generalised force `value·on`, optionally ramped up linearly over `ramp` seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Force {
    /// Element name.
    pub name: String,
    /// Where it acts.
    pub on: Combination,
    /// Value (N).
    pub value: f64,
    /// Ramp time (s); 0: a step at t = 0.
    pub ramp: f64,
}

impl Force {
    /// Factor of the value at time `t` (1 after the ramp).
    #[inline]
    pub fn factor(&self, t: f64) -> f64 {
        if self.ramp > 0.0 && t < self.ramp {
            (t / self.ramp).max(0.0)
        } else {
            1.0
        }
    }
}

/// A dof combination as written by users: `(dof name, coefficient)`.
pub type Terms = Vec<(String, f64)>;

/// Description of a spring.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringSpec {
    /// Element name.
    pub name: String,
    /// `on`.
    pub on: Terms,
    /// `k` (N/m).
    pub k: f64,
    /// `c` (kg/s).
    pub c: f64,
}

/// Description of a force.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceSpec {
    /// Element name.
    pub name: String,
    /// `on`.
    pub on: Terms,
    /// `value` (N).
    pub value: f64,
    /// `ramp` (s).
    pub ramp: f64,
}

/// Description of a contact (the keys of a `[[contact]]` table).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSpec {
    /// Element name.
    pub name: String,
    /// `normal`: the compression's coefficients (with `k`, `c`).
    pub normal: Option<Terms>,
    /// `k` (N/m).
    pub k: Option<f64>,
    /// `c` (kg/s).
    pub c: Option<f64>,
    /// `contact`: unilateral (default) or bilateral.
    pub bilateral: bool,
    /// `normal_force`: a prescribed load instead of `normal`/`k`/`c`.
    pub normal_force: Option<f64>,
    /// `tangent`.
    pub tangent: Option<Terms>,
    /// `V` (m/s).
    pub v: f64,
    /// The friction law with its parameters.
    pub friction: FrictionLaw,
    /// `alpha` (1/m).
    pub alpha: f64,
    /// `slope`.
    pub slope: Terms,
}

/// Everything a lumped model is built from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LumpedSpec {
    /// Dof names, in state order.
    pub dofs: Vec<String>,
    /// `[masses]`: dof → mass (kg), added to the diagonal of `M`.
    pub masses: Vec<(String, f64)>,
    /// Mass matrix (symmetric positive definite with the masses added).
    pub m: Option<Triplets>,
    /// Stiffness matrix.
    pub k: Option<Triplets>,
    /// Damping matrix.
    pub c: Option<Triplets>,
    /// Springs.
    pub springs: Vec<SpringSpec>,
    /// Forces.
    pub forces: Vec<ForceSpec>,
    /// Contacts.
    pub contacts: Vec<ContactSpec>,
    /// `[params]`: shared, named parameters (`mu = 0.45`), in order.
    pub params: Vec<(String, f64)>,
    /// Element keys bound to expressions of `params` (`("inner.mu_k",
    /// "mu")`); the spec's numbers for these keys are replaced by the
    /// expressions' values when the model is built.
    pub expressions: Vec<(String, String)>,
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
    has_ramp: bool,
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
pub const SPRING_KEYS: [&str; 2] = ["k", "c"];
/// See [`SPRING_KEYS`].
pub const FORCE_KEYS: [&str; 2] = ["value", "ramp"];

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
    /// Build and validate a model. Every error names the element and key
    /// (`spring 'disc_x': on: unknown dof 'x_q'`).
    pub fn build(spec: &LumpedSpec) -> Result<Lumped, SpecError> {
        let n = spec.dofs.len();
        if n == 0 {
            return bad("dofs: the model needs at least one dof");
        }
        if n > MAX_MODEL_DOFS {
            return bad(format!(
                "dofs: {n} dofs, more than the {MAX_MODEL_DOFS} a model may have"
            ));
        }
        // Names to indices through a hash map: FE models have 10⁵–10⁶ dofs,
        // where a linear search per name is quadratic.
        let mut index: std::collections::HashMap<&str, usize> =
            std::collections::HashMap::with_capacity(n);
        for (i, d) in spec.dofs.iter().enumerate() {
            if d.is_empty() || d.contains(['.', '=', ',', ' ']) {
                return bad(format!(
                    "dofs: '{d}' is not a valid dof name (no '.', '=', ',' or spaces)"
                ));
            }
            if index.insert(d.as_str(), i).is_some() {
                return bad(format!("dofs: '{d}' is listed twice"));
            }
        }
        let dof = |what: &str, key: &str, name: &str| -> Result<usize, SpecError> {
            index
                .get(name)
                .copied()
                .ok_or_else(|| SpecError(format!("{what}: {key}: unknown dof '{name}'")))
        };
        let combo = |what: &str, key: &str, terms: &Terms| -> Result<Combination, SpecError> {
            let mut c = Combination::default();
            for (name, v) in terms {
                let i = dof(what, key, name)?;
                if !v.is_finite() {
                    return bad(format!(
                        "{what}: {key}.{name} = {v}: must be a finite number"
                    ));
                }
                if c.idx.contains(&i) {
                    return bad(format!("{what}: {key}: dof '{name}' given twice"));
                }
                if *v != 0.0 {
                    c.idx.push(i);
                    c.coef.push(*v);
                }
            }
            Ok(c)
        };
        let mut masses = vec![0.0; n];
        for (name, m) in &spec.masses {
            let i = dof("masses", name, name).map_err(|_| {
                SpecError(format!(
                    "masses: unknown dof '{name}' (dofs: {})",
                    spec.dofs.join(", ")
                ))
            })?;
            if !mass_ok(*m) {
                return bad(format!(
                    "masses: {name} = {}: a mass must be a number from {:e} to {:e} (kg)",
                    crate::params::short(*m),
                    MASS_RANGE.0,
                    MASS_RANGE.1
                ));
            }
            masses[i] = *m;
        }
        let matrix = |key: &str, t: &Option<Triplets>| -> Result<Option<Sparse>, SpecError> {
            let Some(t) = t else { return Ok(None) };
            if t.rows != t.cols {
                return bad(format!(
                    "matrices: {key} is {}×{}, not square",
                    t.rows, t.cols
                ));
            }
            if t.rows != n {
                return bad(format!(
                    "matrices: {key} is {}×{} but the model has {n} dofs",
                    t.rows, t.cols
                ));
            }
            if let Some(e) = t.entries.iter().find(|e| !e.2.is_finite()) {
                return bad(format!(
                    "matrices: {key}[{}, {}] = {}: must be finite",
                    e.0 + 1,
                    e.1 + 1,
                    e.2
                ));
            }
            Ok(Some(Sparse::from_triplets(t)))
        };
        let m_matrix = matrix("M", &spec.m)?;
        let k_matrix = matrix("K", &spec.k)?;
        let c_matrix = matrix("C", &spec.c)?;
        if let Some(m) = &m_matrix {
            for (r, c, v) in m.entries() {
                let w = m.get(c, r);
                if (v - w).abs() > 1e-12 * v.abs().max(w.abs()) {
                    return bad(format!(
                        "matrices: M is not symmetric: M[{}, {}] = {v} but M[{}, {}] = {w}",
                        r + 1,
                        c + 1,
                        c + 1,
                        r + 1
                    ));
                }
            }
        }
        if m_matrix.is_none() {
            if let Some(i) = masses.iter().position(|m| *m <= 0.0) {
                return bad(format!(
                    "masses: dof '{}' has no mass (give one per dof, or a mass matrix)",
                    spec.dofs[i]
                ));
            }
        }
        let mut names: Vec<String> = Vec::new();
        let mut name_ok = |kind: &str, name: &str| -> Result<(), SpecError> {
            if name.is_empty() || name.contains(['.', '=', ',', ' ']) {
                return bad(format!(
                    "{kind} '{name}': name: not a valid element name (no '.', '=', ',' or spaces)"
                ));
            }
            if name == "mass" || name == "modal" || names.iter().any(|x| x == name) {
                return bad(format!(
                    "{kind} '{name}': name: already used (element names must be unique and not 'mass' or 'modal')"
                ));
            }
            names.push(name.to_string());
            Ok(())
        };
        let mut springs = Vec::new();
        for s in &spec.springs {
            let what = format!("spring '{}'", s.name);
            name_ok("spring", &s.name)?;
            let on = combo(&what, "on", &s.on)?;
            if on.is_empty() {
                return bad(format!(
                    "{what}: on: needs at least one dof with a non-zero coefficient"
                ));
            }
            for (key, v) in [("k", s.k), ("c", s.c)] {
                if !(v.is_finite() && v >= 0.0) {
                    return bad(format!("{what}: {key} = {v}: must be a finite number ≥ 0"));
                }
            }
            springs.push(Spring {
                name: s.name.clone(),
                on,
                k: s.k,
                c: s.c,
            });
        }
        let mut forces = Vec::new();
        for f in &spec.forces {
            let what = format!("force '{}'", f.name);
            name_ok("force", &f.name)?;
            let on = combo(&what, "on", &f.on)?;
            if !f.value.is_finite() {
                return bad(format!(
                    "{what}: value = {}: must be a finite number",
                    f.value
                ));
            }
            if !(f.ramp.is_finite() && f.ramp >= 0.0) {
                return bad(format!(
                    "{what}: ramp = {}: must be a finite number ≥ 0 (s)",
                    f.ramp
                ));
            }
            forces.push(Force {
                name: f.name.clone(),
                on,
                value: f.value,
                ramp: f.ramp,
            });
        }
        if spec.contacts.len() > MAX_CONTACTS {
            return bad(format!(
                "contact '{}': at most {MAX_CONTACTS} contacts are supported",
                spec.contacts[MAX_CONTACTS].name
            ));
        }
        let mut contacts = Vec::new();
        for c in &spec.contacts {
            let what = format!("contact '{}'", c.name);
            name_ok("contact", &c.name)?;
            let Some(tangent) = &c.tangent else {
                return bad(format!("{what}: tangent: missing (the sliding direction, e.g. tangent = {{ x_d = 1.0, x_p = -1.0 }})"));
            };
            let tangent = combo(&what, "tangent", tangent)?;
            if tangent.is_empty() {
                return bad(format!(
                    "{what}: tangent: needs at least one dof with a non-zero coefficient"
                ));
            }
            let normal = match (&c.normal, c.normal_force) {
                (Some(_), Some(_)) => {
                    return bad(format!(
                        "{what}: normal_force: give either normal (with k, c) or normal_force, not both"
                    ))
                }
                (None, None) => {
                    return bad(format!(
                        "{what}: normal: missing (normal with k and c, or normal_force)"
                    ))
                }
                (None, Some(f)) => {
                    if !(f.is_finite() && f >= 0.0) {
                        return bad(format!("{what}: normal_force = {f}: must be a finite number ≥ 0 (N)"));
                    }
                    if c.k.is_some() || c.c.is_some() {
                        return bad(format!("{what}: k: a prescribed normal_force takes no k or c"));
                    }
                    Normal::Prescribed(f)
                }
                (Some(terms), None) => {
                    let normal = combo(&what, "normal", terms)?;
                    if normal.is_empty() {
                        return bad(format!("{what}: normal: needs at least one dof with a non-zero coefficient"));
                    }
                    let k = c.k.ok_or_else(|| SpecError(format!("{what}: k: missing (the contact stiffness, N/m)")))?;
                    let cc = c.c.unwrap_or(0.0);
                    for (key, v) in [("k", k), ("c", cc)] {
                        if !(v.is_finite() && v >= 0.0) {
                            return bad(format!("{what}: {key} = {v}: must be a finite number ≥ 0"));
                        }
                    }
                    Normal::Elastic {
                        normal,
                        k,
                        c: cc,
                        bilateral: c.bilateral,
                    }
                }
            };
            if !c.v.is_finite() {
                return bad(format!(
                    "{what}: V = {}: must be a finite number (m/s)",
                    c.v
                ));
            }
            if !c.alpha.is_finite() {
                return bad(format!(
                    "{what}: alpha = {}: must be a finite number (1/m)",
                    c.alpha
                ));
            }
            c.friction
                .validate()
                .map_err(|e| SpecError(format!("{what}: {}", prefixed(&c.name, e))))?;
            let slope = combo(&what, "slope", &c.slope)?;
            if c.alpha != 0.0 && matches!(normal, Normal::Prescribed(_)) {
                return bad(format!(
                    "{what}: alpha = {}: a follower force needs a normal (not a prescribed normal_force)",
                    c.alpha
                ));
            }
            contacts.push(Contact {
                name: c.name.clone(),
                normal,
                tangent,
                v: c.v,
                friction: c.friction,
                alpha: c.alpha,
                slope,
            });
        }
        let mut model = Lumped {
            states: spec
                .dofs
                .iter()
                .cloned()
                .chain(spec.dofs.iter().map(|d| format!("v{d}")))
                .collect(),
            dofs: spec.dofs.clone(),
            masses,
            matrix_base: [m_matrix.clone(), k_matrix.clone(), c_matrix.clone()],
            matrix_scale: [1.0; 3],
            m_matrix,
            k_matrix,
            c_matrix,
            springs,
            forces,
            contacts,
            modal: ModalOptions::default(),
            shared: shared::Shared::new(&spec.params).map_err(SpecError)?,
            inv_mass: InvMass::Diagonal(Vec::new()),
            minv_t: Vec::new(),
            gram: [[0.0; MAX_CONTACTS]; MAX_CONTACTS],
            tn: [[0.0; MAX_CONTACTS]; MAX_CONTACTS],
            has_ramp: false,
            dense: None,
        };
        model.refresh()?;
        for (key, source) in &spec.expressions {
            let x = model.shared.bind(key, source).map_err(SpecError)?;
            model
                .set_element(key, x)
                .map_err(|e| SpecError(format!("{key} = \"{source}\": {e}")))?;
        }
        Ok(model)
    }

    /// Recompute what derives from the parameters (M⁻¹, the constraint
    /// metric) and check the stick constraints.
    fn refresh(&mut self) -> Result<(), SpecError> {
        let n = self.dofs.len();
        self.has_ramp = self.forces.iter().any(|f| f.ramp > 0.0);
        self.inv_mass = match &self.m_matrix {
            Some(m) if !m.is_diagonal() && n > SPARSE_FROM_DOFS => {
                let mut t: Vec<faer::sparse::Triplet<usize, usize, f64>> = m
                    .entries()
                    .map(|(r, c, v)| faer::sparse::Triplet::new(r, c, v))
                    .collect();
                t.extend(
                    (0..n)
                        .filter(|&i| self.masses[i] != 0.0)
                        .map(|i| faer::sparse::Triplet::new(i, i, self.masses[i])),
                );
                let not_pd = || {
                    SpecError(
                        "matrices: M (with the [masses] added) is not positive definite".into(),
                    )
                };
                let full =
                    faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t)
                        .map_err(|_| not_pd())?;
                let llt = full.sp_cholesky(faer::Side::Lower).map_err(|_| not_pd())?;
                InvMass::Factored(MassFactor(std::sync::Arc::new(llt)))
            }
            Some(m) if !m.is_diagonal() => {
                let mut full = DMatrix::from_fn(n, n, |r, c| m.get(r, c));
                for i in 0..n {
                    full[(i, i)] += self.masses[i];
                }
                let chol = full.cholesky().ok_or_else(|| {
                    SpecError(
                        "matrices: M (with the [masses] added) is not positive definite".into(),
                    )
                })?;
                let inv = chol.inverse();
                InvMass::Dense((0..n * n).map(|k| inv[(k / n, k % n)]).collect())
            }
            _ => {
                let mut inv = Vec::with_capacity(n);
                for i in 0..n {
                    let m = self.masses[i] + self.m_matrix.as_ref().map_or(0.0, |m| m.get(i, i));
                    if !(m > 0.0 && m.is_finite()) {
                        return bad(format!(
                            "matrices: M[{}, {}] = {m}: the mass of dof '{}' must be > 0",
                            i + 1,
                            i + 1,
                            self.dofs[i]
                        ));
                    }
                    inv.push(1.0 / m);
                }
                InvMass::Diagonal(inv)
            }
        };
        let nc = self.contacts.len();
        self.minv_t = self
            .contacts
            .iter()
            .map(|c| self.apply_inv_mass_vec(&c.tangent.dense(n)))
            .collect();
        for i in 0..nc {
            for j in 0..nc {
                self.gram[i][j] = self.contacts[j].tangent.dot(&self.minv_t[i]);
                self.tn[i][j] = match &self.contacts[j].normal {
                    Normal::Elastic { normal, .. } => normal.dot(&self.minv_t[i]),
                    Normal::Prescribed(_) => 0.0,
                };
            }
        }
        // A follower force along n_j must not enter another contact's stick
        // constraint (it would make the constraint matrix depend on q).
        for j in 0..nc {
            if self.contacts[j].alpha == 0.0 {
                continue;
            }
            for i in 0..nc {
                let scale = (self.gram[i][i] * self.gram[j][j]).sqrt();
                if self.tn[i][j].abs() > 1e-12 * scale {
                    return bad(format!(
                        "contact '{}': alpha: a follower force along the normal of '{}' acts on the tangent of '{}' (through the masses); squeal supports follower forces only where they do not",
                        self.contacts[j].name, self.contacts[j].name, self.contacts[i].name
                    ));
                }
            }
        }
        // The stick constraints of all contacts together must be independent
        // (then every subset is): Cholesky of the Gram matrix, contact by contact.
        let mut l = [[0.0; MAX_CONTACTS]; MAX_CONTACTS];
        for i in 0..nc {
            for j in 0..=i {
                let mut s = self.gram[i][j];
                for k in 0..j {
                    s -= l[i][k] * l[j][k];
                }
                if i == j {
                    if s <= 1e-10 * self.gram[i][i] {
                        if let Some(msg) = self.dependence_from_masses(i) {
                            return bad(msg);
                        }
                        let others: Vec<String> = (0..i)
                            .filter(|&k| {
                                self.gram[i][k].abs()
                                    > 1e-12 * (self.gram[i][i] * self.gram[k][k]).sqrt()
                            })
                            .map(|k| format!("'{}'", self.contacts[k].name))
                            .collect();
                        if others.is_empty() {
                            return bad(format!(
                                "contact '{}': tangent: moves no mass (t·M⁻¹·t = {:e}): its stick force is not determined",
                                self.contacts[i].name, self.gram[i][i]
                            ));
                        }
                        return bad(format!(
                            "contact '{}': tangent: its stick constraint is redundant with {} (the tangents are linearly dependent, so the stick forces are not determined)",
                            self.contacts[i].name,
                            others.join(" and ")
                        ));
                    }
                    l[i][i] = s.sqrt();
                } else {
                    l[i][j] = s / l[j][j];
                }
            }
        }
        self.rebuild_dense();
        Ok(())
    }

    /// Rebuild the folded operators of the right-hand side ([`DenseField`])
    /// from the elements (small models only).
    /// When the stick constraints up to contact `i` are dependent in the
    /// metric `M⁻¹` but their tangents are independent as vectors (the
    /// same Cholesky test with unit masses passes), the masses are the
    /// cause: a message naming the largest mass on contact `i`'s tangent
    /// against the smallest of the model.
    fn dependence_from_masses(&self, i: usize) -> Option<String> {
        let n = self.dofs.len();
        let dense: Vec<Vec<f64>> = (0..=i).map(|k| self.contacts[k].tangent.dense(n)).collect();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let mut l = vec![vec![0.0; i + 1]; i + 1];
        for a in 0..=i {
            for b in 0..=a {
                let mut s = dot(&dense[a], &dense[b]);
                for k in 0..b {
                    s -= l[a][k] * l[b][k];
                }
                if a == b {
                    if s <= 1e-10 * dot(&dense[a], &dense[a]) {
                        return None; // dependent as vectors: truly redundant
                    }
                    l[a][a] = s.sqrt();
                } else {
                    l[a][b] = s / l[b][b];
                }
            }
        }
        let masses = self.diagonal_masses();
        let (heavy, m_heavy) = self.contacts[i]
            .tangent
            .idx
            .iter()
            .map(|&d| (d, masses[d]))
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        let (light, m_light) = masses
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        Some(format!(
            "mass.{} = {m_heavy:e}: a bad mass: beside mass.{} = {m_light:e} it leaves contact '{}''s tangent no motion double precision can resolve, so its stick force is not determined (the tangents themselves are independent); keep the masses within a factor 1e12 of each other",
            self.dofs[heavy], self.dofs[light], self.contacts[i].name
        ))
    }

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
                    let row = &inv[r * n..(r + 1) * n];
                    out[r] = row.iter().zip(x).map(|(a, b)| a * b).sum();
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

    /// Generalised force without the stick multipliers:
    /// `F(t) − K q − C q̇ − springs − contacts` (slip friction only if
    /// `slip_friction`), into `acc[..n]`.
    #[inline]
    fn base_force(
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
            f.on.add_scaled(acc, f.value * f.factor(t));
        }
        for s in &self.springs {
            let e = s.on.dot(q);
            let ed = s.on.dot(u);
            s.on.add_scaled(acc, -(s.k * e + s.c * ed));
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
    fn multipliers(
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
    fn apply_multipliers(&self, set: &[usize], q: &[f64], lambda: &[f64], acc: &mut [f64]) {
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
    fn force(
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
    fn add_stick_forces(&self, modes: &Modes, q: &[f64], acc: &mut [f64]) -> [f64; MAX_CONTACTS] {
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
    fn stick_guard(
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
    fn stick_guards_affine(&self, modes: &Modes) -> bool {
        !self.has_ramp
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

pub mod condense;
mod folded;
pub mod lanes;
mod linearised;
pub mod padding;
mod params;
pub mod shared;
mod specs;
mod steady;
mod system;
pub use padding::{embed, padded_dofs, padded_solver, real_states, MAX_EXACT_DOFS, PADDED_DOFS};
use params::prefixed;
pub use specs::{disc_pad_spec, two_pad_spec};
pub use system::Fixed;

//! Building a lumped model from its description: every element checked
//! (errors name element and key), the operators folded, the contact
//! constraint set checked for regularity in the metric `M⁻¹`.

use super::*;

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
            if !s.k3.is_finite() {
                return bad(format!(
                    "{what}: k3 = {}: must be a finite number (N/m³)",
                    s.k3
                ));
            }
            springs.push(Spring {
                name: s.name.clone(),
                on,
                k: s.k,
                c: s.c,
                k3: s.k3,
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
            if !f.amplitude.is_finite() {
                return bad(format!(
                    "{what}: amplitude = {}: must be a finite number (N)",
                    f.amplitude
                ));
            }
            if !(f.freq_hz.is_finite() && f.freq_hz >= 0.0) {
                return bad(format!(
                    "{what}: freq_hz = {}: must be a finite number ≥ 0 (Hz)",
                    f.freq_hz
                ));
            }
            if f.amplitude != 0.0 && f.freq_hz == 0.0 {
                return bad(format!(
                    "{what}: amplitude = {}: a harmonic force needs freq_hz > 0 (a static force is its value)",
                    f.amplitude
                ));
            }
            forces.push(Force {
                name: f.name.clone(),
                on,
                value: f.value,
                ramp: f.ramp,
                amplitude: f.amplitude,
                freq_hz: f.freq_hz,
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
            time_varying: false,
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
    pub(super) fn refresh(&mut self) -> Result<(), SpecError> {
        let n = self.dofs.len();
        self.time_varying = self.forces.iter().any(Force::varies);
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
    pub(super) fn dependence_from_masses(&self, i: usize) -> Option<String> {
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
}

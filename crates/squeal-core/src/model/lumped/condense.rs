//! Static (Guyan) condensation of the dofs without mass of a lumped model
//! described by matrices: rotations of shells and constraint dofs that an
//! FE export keeps but no mass moves (Guyan, AIAA J. 3 (1965) 380).
//!
//! With the dofs split into those with mass (`a`) and without (`b`), and
//! the massless ones in static equilibrium at every instant (`K_ba q_a +
//! K_bb q_b = 0`, no force acting on them), `q = T q_a` with
//! `T = [I; −K_bb⁻¹ K_ba]`, and
//!
//! ```text
//! K_c = Tᵀ K T = K_aa − K_ab K_bb⁻¹ K_ba,   C_c = Tᵀ C T,   M_c = M_aa
//! ```
//!
//! (`M_ab = 0`: a dof without mass has no mass coupling either). This is
//! exact for the static response and for the dynamics, because a massless
//! dof has no inertia of its own to lag behind. Elements other than the
//! matrices (springs, forces, contacts) must not touch a condensed dof:
//! they are refused by name. The condensed matrices are dense on the kept
//! dofs that the massless ones couple, as in any Guyan reduction.

use super::{LumpedSpec, SpecError, Triplets};
use nalgebra::DMatrix;

/// Condense the dofs of `spec` that no mass moves (no entry of `M` in
/// their row or column, no `[masses]` entry). Returns their names (empty:
/// nothing to do). Errors name the element that touches one, or say that
/// their stiffness is singular.
pub fn condense_massless(spec: &mut LumpedSpec) -> Result<Vec<String>, SpecError> {
    let n = spec.dofs.len();
    if spec.m.is_none() && spec.k.is_none() {
        // A model of elements only: every dof needs its mass (Lumped::build).
        return Ok(Vec::new());
    }
    let mut has_mass = vec![false; n];
    if let Some(m) = &spec.m {
        for &(i, j, v) in &m.entries {
            if v != 0.0 && i < n && j < n {
                has_mass[i] = true;
                has_mass[j] = true;
            }
        }
    }
    for (d, v) in &spec.masses {
        if *v != 0.0 {
            if let Some(i) = spec.dofs.iter().position(|x| x == d) {
                has_mass[i] = true;
            }
        }
    }
    let b: Vec<usize> = (0..n).filter(|&i| !has_mass[i]).collect();
    if b.is_empty() || b.len() == n {
        // Nothing to condense, or nothing would be left (the model's own
        // mass check says so).
        return Ok(Vec::new());
    }
    let names: Vec<String> = b.iter().map(|&i| spec.dofs[i].clone()).collect();
    let touched = |what: &str, key: &str, terms: &[(String, f64)]| -> Result<(), SpecError> {
        match terms.iter().find(|(d, _)| names.contains(d)) {
            Some((d, _)) => Err(SpecError(format!(
                "{what}: {key}: dof '{d}' has no mass: squeal condenses massless dofs statically, and only the matrices may act on them (give it a mass, or act on a dof with mass)"
            ))),
            None => Ok(()),
        }
    };
    for s in &spec.springs {
        touched(&format!("spring '{}'", s.name), "on", &s.on)?;
    }
    for f in &spec.forces {
        touched(&format!("force '{}'", f.name), "on", &f.on)?;
    }
    for c in &spec.contacts {
        let what = format!("contact '{}'", c.name);
        if let Some(t) = &c.normal {
            touched(&what, "normal", t)?;
        }
        if let Some(t) = &c.tangent {
            touched(&what, "tangent", t)?;
        }
        touched(&what, "slope", &c.slope)?;
    }
    let a: Vec<usize> = (0..n).filter(|&i| has_mass[i]).collect();
    let dense = |t: &Option<Triplets>| {
        let mut m = DMatrix::<f64>::zeros(n, n);
        if let Some(t) = t {
            for &(i, j, v) in &t.entries {
                m[(i, j)] += v;
            }
        }
        m
    };
    let k = dense(&spec.k);
    let kbb = k.select_rows(&b).select_columns(&b);
    let kba = k.select_rows(&b).select_columns(&a);
    let lu = kbb.lu();
    let x = lu.solve(&kba).filter(|x| x.iter().all(|v| v.is_finite()));
    let Some(x) = x else {
        return Err(SpecError(format!(
            "the {} dofs without mass ({}) cannot be condensed statically: their stiffness K_bb is singular (a massless dof held by nothing)",
            names.len(),
            short_list(&names)
        )));
    };
    // T = [I; −X] on (a, b); the condensed matrices on a.
    let condensed = |full: &DMatrix<f64>| {
        let faa = full.select_rows(&a).select_columns(&a);
        let fab = full.select_rows(&a).select_columns(&b);
        let fba = full.select_rows(&b).select_columns(&a);
        let fbb = full.select_rows(&b).select_columns(&b);
        &faa - &fab * &x - x.transpose() * &fba + x.transpose() * &fbb * &x
    };
    let to_triplets = |m: DMatrix<f64>| {
        let na = m.nrows();
        let mut t = Triplets {
            rows: na,
            cols: na,
            entries: Vec::new(),
        };
        for j in 0..na {
            for i in 0..na {
                if m[(i, j)] != 0.0 {
                    t.entries.push((i, j, m[(i, j)]));
                }
            }
        }
        t
    };
    let kc = condensed(&k);
    spec.k = Some(to_triplets(kc));
    if spec.c.is_some() {
        let c = dense(&spec.c);
        spec.c = Some(to_triplets(condensed(&c)));
    }
    if spec.m.is_some() {
        let m = dense(&spec.m);
        spec.m = Some(to_triplets(m.select_rows(&a).select_columns(&a)));
    }
    spec.dofs = a.iter().map(|&i| spec.dofs[i].clone()).collect();
    Ok(names)
}

/// `a, b, c` or `a, b, c, … (N)`.
fn short_list(names: &[String]) -> String {
    if names.len() <= 6 {
        names.join(", ")
    } else {
        format!("{}, … ({})", names[..5].join(", "), names.len())
    }
}

//! The built-in models written as lumped descriptions (the thesis's
//! disc–pad, the two-pad brake): the same models as `scenarios/lumped/`.

use super::*;

/// The thesis's disc–pad (a [`crate::model::disc_pad::DiscPad`]'s parameters) as a
/// lumped description, exactly as `scenarios/lumped/disc-pad.toml` writes it:
/// springs `disc_x`, `disc_y`, `pad_x`, the force `brake` (−N on y_p, with
/// its ramp) and the contact `pad` (normal {y_d: 1, y_p: −1}, tangent
/// {x_d: 1, x_p: −1}, follower slope {y_d: 1}).
pub fn disc_pad_spec(m: &crate::model::disc_pad::DiscPad) -> LumpedSpec {
    let p = &m.p;
    let t = |v: &[(&str, f64)]| -> Terms { v.iter().map(|(n, c)| (n.to_string(), *c)).collect() };
    let spring = |name: &str, dof: &str, k: f64, c: f64| SpringSpec {
        name: name.into(),
        on: t(&[(dof, 1.0)]),
        k,
        c,
        k3: 0.0,
    };
    LumpedSpec {
        dofs: ["x_d", "x_p", "y_d", "y_p"].map(String::from).to_vec(),
        masses: t(&[
            ("x_d", p.m_d),
            ("x_p", p.m_p),
            ("y_d", p.m_d),
            ("y_p", p.m_p),
        ]),
        springs: vec![
            spring("disc_x", "x_d", p.k_dx, p.c_dx),
            spring("disc_y", "y_d", p.k_dy, p.c_dy),
            spring("pad_x", "x_p", p.k_px, p.c_px),
        ],
        forces: vec![ForceSpec {
            name: "brake".into(),
            on: t(&[("y_p", 1.0)]),
            value: -p.N,
            ramp: p.t_ramp,
            amplitude: 0.0,
            freq_hz: 0.0,
        }],
        contacts: vec![ContactSpec {
            name: "pad".into(),
            normal: Some(t(&[("y_d", 1.0), ("y_p", -1.0)])),
            k: Some(p.k_py),
            c: Some(p.c_py),
            bilateral: m.contact == crate::model::disc_pad::Contact::Bilateral,
            normal_force: None,
            tangent: Some(t(&[("x_d", 1.0), ("x_p", -1.0)])),
            v: p.V,
            friction: m.friction,
            alpha: p.alpha,
            slope: t(&[("y_d", 1.0)]),
        }],
        ..Default::default()
    }
}

/// The symmetric two-pad brake of `scenarios/lumped/two-pad-brake.toml`: a
/// disc (x_d, y_d; twice the thesis's modal mass, stiffness and damping)
/// between two thesis pads pressed from opposite sides.
pub fn two_pad_spec() -> LumpedSpec {
    let half = disc_pad_spec(&crate::model::disc_pad::DiscPad::default());
    let t = |v: &[(&str, f64)]| -> Terms { v.iter().map(|(n, c)| (n.to_string(), *c)).collect() };
    let pad = &half.contacts[0];
    let contact = |name: &str, normal: &[(&str, f64)], tangent: &[(&str, f64)]| ContactSpec {
        name: name.into(),
        normal: Some(t(normal)),
        tangent: Some(t(tangent)),
        slope: Vec::new(),
        ..pad.clone()
    };
    let spring = |name: &str, dof: &str, k: f64, c: f64| SpringSpec {
        name: name.into(),
        on: t(&[(dof, 1.0)]),
        k,
        c,
        k3: 0.0,
    };
    let force = |name: &str, dof: &str, value: f64| ForceSpec {
        name: name.into(),
        on: t(&[(dof, 1.0)]),
        value,
        ramp: 0.0,
        amplitude: 0.0,
        freq_hz: 0.0,
    };
    LumpedSpec {
        dofs: ["x_d", "y_d", "x_p1", "y_p1", "x_p2", "y_p2"]
            .map(String::from)
            .to_vec(),
        masses: t(&[
            ("x_d", 2.0),
            ("y_d", 2.0),
            ("x_p1", 0.1),
            ("y_p1", 0.1),
            ("x_p2", 0.1),
            ("y_p2", 0.1),
        ]),
        springs: vec![
            spring("disc_x", "x_d", 2.0e9, 2.0),
            spring("disc_y", "y_d", 1.6e7, 2.0),
            spring("pad1_x", "x_p1", 1.7e9, 0.2),
            spring("pad2_x", "x_p2", 1.7e9, 0.2),
        ],
        forces: vec![
            force("brake_1", "y_p1", -500.0),
            force("brake_2", "y_p2", 500.0),
        ],
        contacts: vec![
            contact(
                "pad1",
                &[("y_d", 1.0), ("y_p1", -1.0)],
                &[("x_d", 1.0), ("x_p1", -1.0)],
            ),
            contact(
                "pad2",
                &[("y_p2", 1.0), ("y_d", -1.0)],
                &[("x_d", 1.0), ("x_p2", -1.0)],
            ),
        ],
        ..Default::default()
    }
}

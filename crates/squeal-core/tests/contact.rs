//! The one contact component (`model::contact`) used by every model: the
//! hand-written disc–pad, belt and Hoffmann models build their guards and
//! transitions through it. These tests hold each built-in to the formulas it
//! had before (written out here once more, by hand, from MODEL.md §3–4):
//! the same guards (gradient and constant, exactly) in every mode, and the
//! same next mode and event for every guard at states on and off the stick
//! bound. The engine tests (`tests/engine.rs`: event times, the exact belt
//! cycle, grazing) run unchanged on top.

use squeal_core::model::contact::{after_guard, friction_mode};
use squeal_core::model::disc_pad::Contact as Layer;
use squeal_core::model::{stick_or_slip, GuardKind, Guards};
use squeal_core::{Belt, DiscPad, EventKind, FrictionLaw, Hoffmann, Mode, Model};

const MODES: [Mode; 4] = [Mode::SlipPos, Mode::SlipNeg, Mode::Stick, Mode::Free];
const KINDS: [GuardKind; 5] = [
    GuardKind::SlipZero,
    GuardKind::StickBreakPos,
    GuardKind::StickBreakNeg,
    GuardKind::Separation,
    GuardKind::Contact,
];

fn stribeck() -> FrictionLaw {
    FrictionLaw::Stribeck {
        mu_s: 0.45,
        mu_k: 0.3,
        v_s: 0.1,
        delta: 2.0,
        sigma: 0.0,
    }
}

/// The guards of `mode` as `(kind, c, d)`.
fn guards_of<M: Model<N>, const N: usize>(m: &M, mode: Mode) -> Vec<(GuardKind, [f64; N], f64)> {
    let mut g = Guards::<N>::default();
    m.guards(mode, &mut g);
    g.as_slice().iter().map(|g| (g.kind, g.c, g.d)).collect()
}

/// The friction-event name of a mode change at a zero of v (MODEL.md §4).
fn event(from: Mode, to: Mode) -> Option<EventKind> {
    match (from, to) {
        (a, b) if a == b => None,
        (_, Mode::Stick) => Some(EventKind::Stick),
        (Mode::Stick, _) => Some(EventKind::Slip),
        (Mode::SlipPos, Mode::SlipNeg) | (Mode::SlipNeg, Mode::SlipPos) => Some(EventKind::Reverse),
        _ => None,
    }
}

// ---- The disc–pad: z = (x_d, x_p, y_d, y_p, ẋ_d, ẋ_p, ẏ_d, ẏ_p) ----

fn disc_pad_guards(m: &DiscPad, mode: Mode) -> Vec<(GuardKind, [f64; 8], f64)> {
    let p = &m.p;
    let mut out = Vec::new();
    // F_y = k_py (y_d − y_p) + c_py (ẏ_d − ẏ_p).
    let fy = [0.0, 0.0, p.k_py, -p.k_py, 0.0, 0.0, p.c_py, -p.c_py];
    if mode == Mode::Free {
        out.push((
            GuardKind::Contact,
            [0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0],
            0.0,
        ));
        return out;
    }
    if m.contact == Layer::Unilateral {
        out.push((GuardKind::Separation, fy.map(|x| -x), 0.0));
    }
    match mode {
        Mode::SlipPos | Mode::SlipNeg => {
            let s = mode.slip_sign();
            out.push((
                GuardKind::SlipZero,
                [0.0, 0.0, 0.0, 0.0, -s, s, 0.0, 0.0],
                -s * p.V,
            ));
        }
        _ => {
            // Stick force m_p a + k_px x_p + c_px ẋ_p with the common acceleration a.
            let mt = p.m_d + p.m_p;
            let fs = [
                -p.m_p * p.k_dx / mt,
                p.k_px * p.m_d / mt,
                0.0,
                0.0,
                -p.m_p * p.c_dx / mt,
                p.c_px * p.m_d / mt,
                0.0,
                0.0,
            ];
            let mu_s = m.friction.mu_static();
            let up: [f64; 8] = std::array::from_fn(|i| fs[i] - mu_s * fy[i]);
            let dn: [f64; 8] = std::array::from_fn(|i| -fs[i] - mu_s * fy[i]);
            out.push((GuardKind::StickBreakPos, up, 0.0));
            out.push((GuardKind::StickBreakNeg, dn, 0.0));
        }
    }
    out
}

/// Every mode of the default disc–pad, a bilateral one and one with a
/// Stribeck law (μ_s ≠ μ_k) has the guards of the formulas, exactly; every
/// guard leads to the mode and event of the rules, on and off the stick
/// bound, with v = 0 projected (the pad's velocity) where it fired.
#[test]
fn disc_pad_guards_and_transitions_are_the_formulas() {
    let mut models = vec![DiscPad::default()];
    models.push(DiscPad {
        contact: Layer::Bilateral,
        ..Default::default()
    });
    models.push(DiscPad {
        friction: stribeck(),
        ..Default::default()
    });
    for m in &models {
        for mode in MODES {
            assert_eq!(guards_of(m, mode), disc_pad_guards(m, mode), "{mode:?}");
        }
        let p = m.p;
        let mu_s = m.friction.mu_static();
        // States: in compression; sliding, or at v = 0 with a small or a large stick force.
        let mut outcomes = std::collections::BTreeSet::new();
        for (xp, vdiff) in [
            (1e-9, 0.0),
            (1e-4, 0.0),
            (-1e-4, 0.0),
            (1e-7, 0.3),
            (1e-7, -0.3),
        ] {
            let z0 = [0.0, xp, -1e-7, -2e-7, 0.01, p.V + 0.01 - vdiff, 0.0, 0.0];
            for mode in MODES {
                for kind in KINDS {
                    let mut z = z0;
                    let got = m.transition(0.0, mode, kind, &mut z);
                    let mut zw = z0;
                    if kind == GuardKind::SlipZero {
                        zw[5] = p.V + zw[4];
                    }
                    assert_eq!(z, zw, "{kind:?}: projection");
                    let fy = p.k_py * (zw[2] - zw[3]) + p.c_py * (zw[6] - zw[7]);
                    let f_n = match m.contact {
                        Layer::Unilateral => fy,
                        Layer::Bilateral => fy.max(0.0),
                    }
                    .max(0.0);
                    let a = (-p.k_dx * zw[0] - p.c_dx * zw[4] - p.k_px * zw[1] - p.c_px * zw[5])
                        / (p.m_d + p.m_p);
                    let fs = p.m_p * a + p.k_px * zw[1] + p.c_px * zw[5];
                    let v = p.V + zw[4] - zw[5];
                    let want = match kind {
                        GuardKind::SlipZero => {
                            let next = stick_or_slip(fs, mu_s * f_n);
                            (next, event(mode, next))
                        }
                        GuardKind::StickBreakPos => (Mode::SlipPos, Some(EventKind::Slip)),
                        GuardKind::StickBreakNeg => (Mode::SlipNeg, Some(EventKind::Slip)),
                        GuardKind::Separation => (Mode::Free, Some(EventKind::Separate)),
                        GuardKind::Contact => {
                            let next = if v > 0.0 {
                                Mode::SlipPos
                            } else if v < 0.0 {
                                Mode::SlipNeg
                            } else {
                                stick_or_slip(fs, mu_s * f_n)
                            };
                            (next, Some(EventKind::Contact))
                        }
                    };
                    assert_eq!(got, want, "{mode:?} {kind:?} at {z0:?}");
                    if kind == GuardKind::SlipZero {
                        outcomes.insert(format!("{:?}", got.0));
                    }
                }
            }
        }
        // Both sides of the stick bound were tried.
        assert_eq!(outcomes.len(), 3, "{outcomes:?}");
    }
}

// ---- Hoffmann: z = (x, y, ẋ, ẏ) ----

/// Hoffmann's guards (k3 ≠ 0: the contact can open and close; k3 = 0: it
/// cannot) and transitions are the formulas.
#[test]
fn hoffmann_guards_and_transitions_are_the_formulas() {
    let mut models = vec![Hoffmann::default()];
    let mut h = Hoffmann::default();
    h.p.k3 = 0.0;
    models.push(h);
    models.push(Hoffmann {
        friction: stribeck(),
        ..Default::default()
    });
    for h in &models {
        let p = h.p;
        let mu_s = h.friction.mu_static();
        for mode in MODES {
            let mut want = Vec::new();
            if mode == Mode::Free {
                if p.k3 != 0.0 {
                    want.push((GuardKind::Contact, [0.0, p.k3, 0.0, 0.0], p.N0));
                }
            } else {
                if p.k3 != 0.0 {
                    want.push((GuardKind::Separation, [0.0, -p.k3, 0.0, 0.0], -p.N0));
                }
                if mode == Mode::Stick {
                    want.push((
                        GuardKind::StickBreakPos,
                        [p.k11, p.k12 - mu_s * p.k3, p.c1, 0.0],
                        -mu_s * p.N0,
                    ));
                    want.push((
                        GuardKind::StickBreakNeg,
                        [-p.k11, -p.k12 - mu_s * p.k3, -p.c1, 0.0],
                        -mu_s * p.N0,
                    ));
                } else {
                    let s = mode.slip_sign();
                    want.push((GuardKind::SlipZero, [0.0, 0.0, s, 0.0], -s * p.V));
                }
            }
            assert_eq!(guards_of(h, mode), want, "{mode:?}");
        }
        for z0 in [
            [1e-3, 1e-3, p.V, 0.0],
            [0.5, 1e-3, p.V, 0.0],
            [-0.5, 1e-3, p.V, 0.0],
            [1e-3, 1e-3, p.V + 0.2, 0.0],
            [1e-3, 1e-3, p.V - 0.2, 0.0],
        ] {
            for mode in MODES {
                for kind in KINDS {
                    let mut z = z0;
                    let got = h.transition(0.0, mode, kind, &mut z);
                    let mut zw = z0;
                    if kind == GuardKind::SlipZero {
                        zw[2] = p.V;
                    }
                    assert_eq!(z, zw);
                    let n = (p.N0 + p.k3 * zw[1]).max(0.0);
                    let fs = p.c1 * zw[2] + p.k11 * zw[0] + p.k12 * zw[1];
                    let v = p.V - zw[2];
                    let decided = if v > 0.0 {
                        Mode::SlipPos
                    } else if v < 0.0 {
                        Mode::SlipNeg
                    } else {
                        stick_or_slip(fs, mu_s * n)
                    };
                    let want = match kind {
                        GuardKind::SlipZero => {
                            let next = stick_or_slip(fs, mu_s * n);
                            (next, event(mode, next))
                        }
                        GuardKind::StickBreakPos => (Mode::SlipPos, Some(EventKind::Slip)),
                        GuardKind::StickBreakNeg => (Mode::SlipNeg, Some(EventKind::Slip)),
                        GuardKind::Separation => (Mode::Free, Some(EventKind::Separate)),
                        GuardKind::Contact => (decided, Some(EventKind::Contact)),
                    };
                    assert_eq!(got, want, "{mode:?} {kind:?} at {z0:?}");
                }
            }
            let start = if p.N0 + p.k3 * z0[1] <= 0.0 {
                Mode::Free
            } else {
                let v = p.V - z0[2];
                let fs = p.c1 * z0[2] + p.k11 * z0[0] + p.k12 * z0[1];
                friction_mode(v, fs, mu_s * (p.N0 + p.k3 * z0[1]).max(0.0))
            };
            assert_eq!(h.initial_mode(0.0, &z0), start);
        }
    }
}

// ---- The belt: z = (x, ẋ) ----

/// The belt's guards and transitions are the formulas; it has no
/// separation or contact (prescribed load): those leave the mode alone.
#[test]
fn belt_guards_and_transitions_are_the_formulas() {
    let mut models = vec![Belt::default()];
    let mut b = Belt::default();
    b.p.c = 0.7;
    b.friction = stribeck();
    models.push(b);
    for b in &models {
        let p = b.p;
        let bound = b.friction.mu_static() * p.N;
        for mode in MODES {
            let want = match mode {
                Mode::SlipPos | Mode::SlipNeg => {
                    let s = mode.slip_sign();
                    vec![(GuardKind::SlipZero, [0.0, s], -s * p.V)]
                }
                Mode::Stick => vec![
                    (GuardKind::StickBreakPos, [p.k, p.c], -bound),
                    (GuardKind::StickBreakNeg, [-p.k, -p.c], -bound),
                ],
                Mode::Free => vec![],
            };
            assert_eq!(guards_of(b, mode), want, "{mode:?}");
        }
        for z0 in [
            [1e-4, p.V],
            [1.0, p.V],
            [-1.0, p.V],
            [0.0, p.V + 0.05],
            [0.0, p.V - 0.05],
        ] {
            for mode in MODES {
                for kind in KINDS {
                    let mut z = z0;
                    let got = b.transition(0.0, mode, kind, &mut z);
                    let fs = |z: &[f64; 2]| p.k * z[0] + p.c * z[1];
                    let want = match kind {
                        GuardKind::SlipZero => {
                            assert_eq!(z, [z0[0], p.V]);
                            let next = stick_or_slip(fs(&z), bound);
                            (next, event(mode, next))
                        }
                        GuardKind::StickBreakPos => (Mode::SlipPos, Some(EventKind::Slip)),
                        GuardKind::StickBreakNeg => (Mode::SlipNeg, Some(EventKind::Slip)),
                        GuardKind::Separation | GuardKind::Contact => (mode, None),
                    };
                    assert_eq!(got, want, "{mode:?} {kind:?} at {z0:?}");
                }
            }
            let v = p.V - z0[1];
            let start = if v > 0.0 {
                Mode::SlipPos
            } else if v < 0.0 {
                Mode::SlipNeg
            } else {
                stick_or_slip(p.k * z0[0] + p.c * z0[1], bound)
            };
            assert_eq!(b.initial_mode(0.0, &z0), start);
        }
    }
}

/// The shared rules themselves: the guard table and the decision at v = 0.
#[test]
fn after_guard_and_friction_mode_follow_the_rules() {
    for mode in MODES {
        assert_eq!(
            after_guard(GuardKind::StickBreakPos, mode, || unreachable!()),
            (Mode::SlipPos, Some(EventKind::Slip))
        );
        assert_eq!(
            after_guard(GuardKind::StickBreakNeg, mode, || unreachable!()),
            (Mode::SlipNeg, Some(EventKind::Slip))
        );
        assert_eq!(
            after_guard(GuardKind::Separation, mode, || unreachable!()),
            (Mode::Free, Some(EventKind::Separate))
        );
        for decided in MODES {
            assert_eq!(
                after_guard(GuardKind::Contact, mode, || decided),
                (decided, Some(EventKind::Contact))
            );
            assert_eq!(
                after_guard(GuardKind::SlipZero, mode, || decided),
                (decided, event(mode, decided))
            );
        }
    }
    assert_eq!(friction_mode(1e-300, 1e9, 0.0), Mode::SlipPos);
    assert_eq!(friction_mode(-1e-300, -1e9, 0.0), Mode::SlipNeg);
    assert_eq!(friction_mode(0.0, 1.0, 1.0), Mode::Stick);
    assert_eq!(friction_mode(0.0, -1.0, 1.0), Mode::Stick);
    assert_eq!(friction_mode(0.0, 1.0 + 1e-15, 1.0), Mode::SlipPos);
    assert_eq!(friction_mode(0.0, -1.0 - 1e-15, 1.0), Mode::SlipNeg);
}

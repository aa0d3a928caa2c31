//! The generic Newton solve for steady sliding (for models without a closed
//! form) against the closed forms of the shipped models.

use squeal_core::model::newton_equilibrium;
use squeal_core::{Belt, DiscPad, FrictionLaw, Hoffmann, Model, Parameters};

fn close<const N: usize>(a: &[f64; N], b: &[f64; N], what: &str) {
    let size = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for i in 0..N {
        assert!(
            (a[i] - b[i]).abs() <= 1e-12 * b[i].abs().max(1e-6 * size),
            "{what}: state {i}: {} vs {}",
            a[i],
            b[i]
        );
    }
}

#[test]
fn newton_matches_the_closed_forms() {
    // Disc–pad: the follower force makes the normal balance nonlinear in y_d.
    for (alpha, law) in [
        (0.0, "thesis"),
        (-1.0e4, "thesis"),
        (-3.0e4, "thesis"),
        (2.0e4, "stribeck"),
    ] {
        let mut m = DiscPad::default();
        m.friction = m.friction.switch_to(law).unwrap();
        m.set("alpha", alpha).unwrap();
        m.set("N", 2000.0).unwrap();
        let closed = m.equilibrium().unwrap();
        let newton = newton_equilibrium(&m, &[0.0; 8]).unwrap();
        close(&newton, &closed, &format!("disc-pad α = {alpha}, {law}"));
    }
    let mut b = Belt {
        friction: FrictionLaw::by_name("rational").unwrap(),
        ..Belt::default()
    };
    b.set("V", 2.5).unwrap();
    close(
        &newton_equilibrium(&b, &[0.0; 2]).unwrap(),
        &b.equilibrium().unwrap(),
        "belt",
    );
    let h = Hoffmann::default();
    close(
        &newton_equilibrium(&h, &[0.0; 4]).unwrap(),
        &h.equilibrium().unwrap(),
        "hoffmann",
    );
}

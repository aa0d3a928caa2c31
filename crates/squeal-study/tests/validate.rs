//! `squeal_study::validate`: each benchmark case is also a test — its value
//! finite and its error within its tolerance.

use squeal_study::validate::{evaluate, specs};

#[test]
fn every_validation_case_passes() {
    for s in specs() {
        let c = evaluate(&s);
        assert!(c.detail.is_none(), "{}: {:?}", c.name, c.detail);
        assert!(
            c.value.is_finite() && c.reference.is_finite(),
            "{}: {} vs {}",
            c.name,
            c.value,
            c.reference
        );
        assert!(
            c.error <= c.tolerance && c.pass,
            "{}: {} vs {} (error {:e} > {:e})",
            c.name,
            c.value,
            c.reference,
            c.error,
            c.tolerance
        );
    }
}

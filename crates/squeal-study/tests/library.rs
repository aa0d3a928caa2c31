//! The library's contract with its callers (the CLI, the Python package,
//! shards): scenario sources agree, a grid's points do not depend on which
//! others are computed with them, and a cancel token stops the work.

use squeal_study::feasible::resolve_run;
use squeal_study::map::{self, Axis};
use squeal_study::scenario::{resolve, Source};
use squeal_study::{Cancel, NoProgress, StudyError};

fn axes(model: &squeal_study::AnyModel, nx: usize, ny: usize) -> (Axis, Axis) {
    let x = map::parse_axis(&format!("V=0.5:20:{nx}"), "--x", false, model).unwrap();
    let y = map::parse_axis(&format!("N=100:3000:{ny}"), "--y", false, model).unwrap();
    (x, y)
}

#[test]
fn a_table_a_toml_text_and_a_file_spec_give_the_same_scenario() {
    for name in ["disc-pad", "hoffmann", "belt", "two-pad"] {
        let Ok(builtin) = resolve(Source::Spec(name), &[]) else {
            continue; // not every name is a built-in in every version
        };
        let text = builtin.to_toml();
        let table: toml::Table = text.parse().unwrap();
        let sets = vec!["V=3.5".to_string()];
        let a = resolve(Source::Spec(name), &sets).unwrap();
        let b = resolve(Source::Toml(&text), &sets).unwrap();
        let c = resolve(Source::Table(&table), &sets).unwrap();
        if name == "disc-pad" {
            assert_eq!(a.model.get("V"), Some(3.5));
        }
        assert_eq!(a.to_json(), b.to_json(), "{name}: TOML text");
        assert_eq!(a.to_json(), c.to_json(), "{name}: table");
    }
}

#[test]
fn a_bad_set_key_is_an_input_error_naming_it() {
    let e = resolve(Source::Spec("disc-pad"), &["no_such_key=1".into()]).unwrap_err();
    assert!(e.0.contains("no_such_key"), "{}", e.0);
    let mut t = toml::Table::new();
    t.insert("bogus".into(), toml::Value::Integer(1));
    let e = resolve(Source::Table(&t), &[]).unwrap_err();
    assert!(e.0.contains("bogus"), "{}", e.0);
}

#[test]
fn linear_grid_points_are_the_same_bits_in_any_subset() {
    let sc = resolve(Source::Spec("disc-pad"), &[]).unwrap();
    let (x, y) = axes(&sc.model, 7, 5);
    let all = map::all_points(&x, &y);
    let full = map::linear_grid(&sc.model, &x, &y, &all, &NoProgress, &Cancel::new()).unwrap();
    assert_eq!(full.len(), 35);
    // Shard 1 of 3, interleaved, and a contiguous slice in reverse order.
    let shard: Vec<usize> = all.iter().copied().filter(|k| k % 3 == 1).collect();
    let part = map::linear_grid(&sc.model, &x, &y, &shard, &NoProgress, &Cancel::new()).unwrap();
    for (k, p) in shard.iter().zip(&part) {
        assert_eq!(full[*k].0.to_bits(), p.0.to_bits(), "point {k}");
        assert_eq!(full[*k].1.to_bits(), p.1.to_bits(), "point {k}");
    }
    let rev: Vec<usize> = (10..20).rev().collect();
    let part = map::linear_grid(&sc.model, &x, &y, &rev, &NoProgress, &Cancel::new()).unwrap();
    for (k, p) in rev.iter().zip(&part) {
        assert_eq!(full[*k].0.to_bits(), p.0.to_bits(), "point {k}");
    }
    // Some points of this grid are unstable and some stable: the test sees both.
    assert!(full.iter().any(|p| p.0 > 0.0) && full.iter().any(|p| p.0 < 0.0));
}

/// Two transient outcomes the same: the class, and every number to the bit.
fn assert_same_outcome(what: &str, a: &map::Outcome, b: &map::Outcome) {
    assert_eq!(a.class, b.class, "{what}");
    for (x, y) in [
        (a.rms, b.rms),
        (a.t_end, b.t_end),
        (a.stick_fraction, b.stick_fraction),
    ] {
        assert_eq!(x.to_bits(), y.to_bits(), "{what}: {x} vs {y}");
    }
}

#[test]
fn transient_grid_points_are_the_same_in_any_subset() {
    let sc = resolve_run(Source::Spec("disc-pad"), &[], Some(0.05)).unwrap();
    let (x, y) = axes(&sc.model, 3, 2);
    let all = map::all_points(&x, &y);
    let full = map::transient_grid(&sc, &x, &y, &all, &NoProgress, &Cancel::new()).unwrap();
    let shard = [5, 0, 3];
    let part = map::transient_grid(&sc, &x, &y, &shard, &NoProgress, &Cancel::new()).unwrap();
    for (k, o) in shard.iter().zip(&part) {
        assert_same_outcome(&format!("point {k}"), &full[*k], o);
        assert_ne!(o.class, "failed", "point {k}");
    }
}

/// A transient grid runs its disc–pad points four at a time (the ensemble
/// with the lane-wise right-hand side); every point's outcome is bit for bit
/// the one-at-a-time run's (`transient_at`), for points that grow, stay
/// steady and stick-slip (lanes in stick use the per-lane field), in a grid
/// larger than one task (16) with points repeated.
#[test]
fn transient_grid_equals_one_point_at_a_time() {
    let sc = resolve_run(Source::Spec("disc-pad"), &["c_px=2".into()], Some(0.04)).unwrap();
    let x = map::parse_axis("V=0.3:9:6", "--x", false, &sc.model).unwrap();
    let y = map::parse_axis("N=0:4000:3", "--y", false, &sc.model).unwrap();
    let all = map::all_points(&x, &y);
    let mut points = all.clone();
    points.extend(all.iter().rev().take(5));
    let grid = map::transient_grid(&sc, &x, &y, &points, &NoProgress, &Cancel::new()).unwrap();
    assert_eq!(grid.len(), points.len());
    for (k, o) in points.iter().zip(&grid) {
        assert_same_outcome(
            &format!("point {k}"),
            &map::transient_at(&sc, &x, &y, *k),
            o,
        );
    }
    let classes: std::collections::BTreeSet<&str> = grid.iter().map(|o| o.class).collect();
    assert!(
        classes.contains("grows") && classes.contains("stick-slip"),
        "{classes:?}"
    );
    assert!(
        grid.iter().any(|o| o.stick_fraction > 0.0),
        "a point sticks"
    );
}

#[test]
fn a_set_cancel_token_interrupts_runs_and_grids() {
    let cancel = Cancel::new();
    cancel.cancel();
    let sc = resolve_run(Source::Spec("disc-pad"), &[], Some(0.01)).unwrap();
    let r = squeal_study::run::run(&sc, &NoProgress, &cancel);
    assert!(matches!(r, Err(StudyError::Interrupted)));
    let (x, y) = axes(&sc.model, 3, 3);
    let all = map::all_points(&x, &y);
    let r = map::linear_grid(&sc.model, &x, &y, &all, &NoProgress, &cancel);
    assert!(matches!(r, Err(StudyError::Interrupted)));
    let r = map::transient_grid(&sc, &x, &y, &all, &NoProgress, &cancel);
    assert!(matches!(r, Err(StudyError::Interrupted)));
    let r = squeal_study::critical::locate(&sc.model, "V", 1.0, 16.5, 64, &cancel);
    assert!(matches!(r, Err(StudyError::Interrupted)));
    // Not set: the same run completes, and its series has every sample.
    let ok = squeal_study::run::run(&sc, &NoProgress, &Cancel::new()).unwrap();
    assert_eq!(ok.len(), (0.01 * sc.sample_rate) as usize + 1);
}

#[test]
fn a_cancel_set_during_a_run_stops_it_early() {
    use squeal_study::Progress;
    use std::sync::atomic::{AtomicU64, Ordering};
    // A progress sink that cancels once a tenth of the run is done.
    struct CancelAt<'a>(&'a Cancel, AtomicU64);
    impl Progress for CancelAt<'_> {
        fn inc(&self, n: u64) {
            if self.1.fetch_add(n, Ordering::Relaxed) + n >= 100 {
                self.0.cancel();
            }
        }
    }
    let cancel = Cancel::new();
    let p = CancelAt(&cancel, AtomicU64::new(0));
    let sc = resolve_run(Source::Spec("disc-pad"), &[], Some(0.2)).unwrap();
    let r = squeal_study::run::run(&sc, &p, &cancel);
    assert!(matches!(r, Err(StudyError::Interrupted)));
    // It stopped within a few thousand samples of the request, not at the end.
    assert!(
        p.1.load(Ordering::Relaxed) < 200,
        "{}",
        p.1.load(Ordering::Relaxed)
    );
}

/// A transient grid of lumped models (the user's own brake) runs them four
/// at a time too (the lumped lane-wise right-hand side); every outcome is
/// bit for bit `transient_at`'s. The thesis disc–pad as a lumped model (one
/// contact) and the two-pad brake (two contacts), over speeds and loads
/// that slide steadily, grow and stick–slip.
#[test]
fn lumped_transient_grid_equals_one_point_at_a_time() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios/lumped/");
    for (file, xs, ys) in [
        ("disc-pad.toml", "pad.V=0.3:9:5", "brake.value=-4000:-100:3"),
        (
            "two-pad-brake.toml",
            "pad1.f0=0.1:0.4:4",
            "brake_1.value=-2000:-200:3",
        ),
    ] {
        let path = format!("{root}{file}");
        let sc = resolve_run(Source::Spec(&path), &[], Some(0.02)).unwrap();
        let x = map::parse_axis(xs, "--x", false, &sc.model).unwrap();
        let y = map::parse_axis(ys, "--y", false, &sc.model).unwrap();
        let points = map::all_points(&x, &y);
        let grid = map::transient_grid(&sc, &x, &y, &points, &NoProgress, &Cancel::new()).unwrap();
        for (k, o) in points.iter().zip(&grid) {
            let one = map::transient_at(&sc, &x, &y, *k);
            assert_same_outcome(&format!("{file} point {k}"), &one, o);
        }
        let classes: Vec<&str> = grid.iter().map(|o| o.class).collect();
        assert!(!classes.contains(&"failed"), "{file}: {classes:?}");
        assert!(classes.contains(&"stick-slip"), "{file}: {classes:?}");
    }
}

//! `run::run_many` (the disc–pads as ensembles, issue 16 point 2) gives
//! every scenario's `run::run` result bit for bit: columns, events, solver
//! statistics and error texts, with lanes that end early, refill, fail or
//! stick while the others go on, and runs refused before they start.

use squeal_core::EventKind;
use squeal_study::run::{run, run_many, Run};
use squeal_study::scenario::{resolve, Source};
use squeal_study::{Cancel, NoProgress, Progress, Scenario, StudyError};
use std::sync::atomic::{AtomicU64, Ordering};

/// A prepared scenario `name` with `sets` applied (each run gets its own
/// step budget, as the CLI does).
fn scenario(name: &str, sets: &[&str]) -> Scenario {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let mut sc = resolve(Source::Spec(name), &sets).unwrap();
    squeal_study::feasible::prepare(&mut sc).unwrap();
    sc
}

/// A disc–pad that cannot start: no steady sliding at V = 0 to take its
/// equilibrium from (refused before it is integrated).
fn unstartable() -> Scenario {
    let mut sc = scenario("disc-pad", &["duration=0.01"]);
    sc.model.set("V", 0.0).unwrap();
    sc.initial = squeal_core::initial::Initial::Equilibrium;
    sc
}

/// Both results identical: every column and statistic to the bit, the
/// events and the error texts equal.
fn assert_same(k: usize, a: &Result<Run, StudyError>, b: &Result<Run, StudyError>) {
    let (a, b) = match (a, b) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(a), Err(b)) => {
            assert_eq!(a.to_string(), b.to_string(), "scenario {k}: error");
            return;
        }
        _ => panic!("scenario {k}: one run failed, the other did not: {a:?} / {b:?}"),
    };
    assert_eq!(a.columns, b.columns, "scenario {k}: columns");
    assert_eq!(a.data.len(), b.data.len());
    for (c, (x, y)) in a.data.iter().zip(&b.data).enumerate() {
        assert_eq!(x.len(), y.len(), "scenario {k}, column {}", a.columns[c]);
        for (i, (u, v)) in x.iter().zip(y).enumerate() {
            assert_eq!(
                u.to_bits(),
                v.to_bits(),
                "scenario {k}, column {}, sample {i}: {u} vs {v}",
                a.columns[c]
            );
        }
    }
    assert_eq!(a.events.len(), b.events.len(), "scenario {k}: events");
    for ((ta, ka), (tb, kb)) in a.events.iter().zip(&b.events) {
        assert_eq!(
            (ta.to_bits(), ka),
            (tb.to_bits(), kb),
            "scenario {k}: event"
        );
    }
    assert_eq!(a.event_contacts, b.event_contacts, "scenario {k}");
    assert_eq!(a.contact_names, b.contact_names, "scenario {k}");
    assert_eq!(a.info, b.info, "scenario {k}: RunInfo");
    // Debug prints every f64 in its shortest round-trip form: equal text, equal bits.
    assert_eq!(format!("{:?}", a.info), format!("{:?}", b.info));
    assert_eq!(a.info.t_final.to_bits(), b.info.t_final.to_bits());
    assert_eq!(a.sample_rate.to_bits(), b.sample_rate.to_bits());
}

#[derive(Default)]
struct Count(AtomicU64, AtomicU64);

impl Progress for Count {
    fn inc(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }
    fn finish(&self) {
        self.1.fetch_add(1, Ordering::Relaxed);
    }
}

#[test]
fn run_many_is_run_on_each_scenario_bit_for_bit() {
    let mut budget = scenario("disc-pad", &["duration=0.05", "V=3"]);
    // A budget far too small: this run fails early while the others go on.
    budget.solver.max_steps = 300;
    let scs = vec![
        // The default run (it squeals from rest), long.
        scenario("disc-pad", &["duration=0.12"]),
        // Stick-slip: slow disc, high force.
        scenario("disc-pad", &["V=1", "N=2000", "duration=0.1"]),
        budget,
        // A belt between the disc–pads (not an ensemble's model).
        scenario("belt", &["duration=2"]),
        // Short runs: their lanes end and take the next scenario.
        scenario("disc-pad", &["V=10", "N=300", "duration=0.01"]),
        scenario("disc-pad", &["V=0.5", "N=1500", "duration=0.02"]),
        // Another sample rate: an ensemble of its own.
        scenario("disc-pad", &["V=2", "duration=0.03", "sample_rate=100000"]),
        scenario("disc-pad", &["V=20", "N=800", "duration=0.015"]),
        scenario("two-pad-brake", &["duration=0.02"]),
        scenario("disc-pad", &["V=4", "N=1000", "duration=0.04"]),
        unstartable(),
    ];
    let cancel = Cancel::new();
    let one: Vec<_> = scs.iter().map(|s| run(s, &NoProgress, &cancel)).collect();
    let count = Count::default();
    let many = run_many(&scs, &count, &cancel);
    assert_eq!(many.len(), scs.len());
    for (k, (a, b)) in one.iter().zip(&many).enumerate() {
        assert_same(k, a, b);
    }
    // The cases the test is meant to cover did occur.
    let err = one[2].as_ref().unwrap_err().to_string();
    assert!(err.contains("work budget exhausted"), "{err}");
    let stick = one[1].as_ref().unwrap();
    assert!(
        stick.events.iter().any(|e| e.1 == EventKind::Stick),
        "scenario 1 sticks"
    );
    let err = one[10].as_ref().unwrap_err().to_string();
    assert!(err.contains("initial = equilibrium"), "{err}");
    assert!(one.iter().filter(|r| r.is_ok()).count() == scs.len() - 2);
    // One bar for all: finished once, about 1000 thousandths per finished run.
    assert_eq!(count.1.load(Ordering::Relaxed), 1);
    let ticks = count.0.load(Ordering::Relaxed);
    assert!(
        ticks <= 1000 * scs.len() as u64 && ticks >= 900 * (scs.len() - 2) as u64,
        "{ticks}"
    );
    // The scenarios by reference, and in another order, give the same runs.
    let refs: Vec<&Scenario> = scs.iter().rev().collect();
    let rev = run_many(&refs, &NoProgress, &cancel);
    for (k, b) in rev.iter().rev().enumerate() {
        assert_same(k, &one[k], b);
    }
}

#[test]
fn run_many_after_cancel_interrupts_every_scenario() {
    let scs = vec![
        scenario("disc-pad", &["duration=0.01"]),
        scenario("belt", &["duration=0.5"]),
        unstartable(),
    ];
    let cancel = Cancel::new();
    cancel.cancel();
    for r in run_many(&scs, &NoProgress, &cancel) {
        assert!(matches!(r, Err(StudyError::Interrupted)), "{r:?}");
    }
}

/// `tasks` groups at most four scenarios, and never more series memory than
/// `TASK_SERIES_BYTES` at once (a scenario larger than that runs alone).
#[test]
fn tasks_bound_lanes_and_memory() {
    use squeal_study::feasible::series_bytes;
    use squeal_study::run::{tasks, TASK_SERIES_BYTES};
    let small = scenario("disc-pad", &["duration=0.05"]);
    // 200 kHz for 20 s: 4·10⁶ samples of 13 columns, 416 MB.
    let big = scenario("disc-pad", &["duration=20", "sample_rate=200000"]);
    assert!(series_bytes(&small) < 0.1 * TASK_SERIES_BYTES);
    assert!(series_bytes(&big) > TASK_SERIES_BYTES);
    let mut list = vec![small.clone(); 6];
    assert_eq!(tasks(&list), vec![0..4, 4..6]);
    list.insert(2, big.clone());
    assert_eq!(tasks(&list), vec![0..2, 2..3, 3..7]);
    // Two of a third of the budget fit together, the third does not.
    let third = TASK_SERIES_BYTES / 3.0 + 1.0;
    let mut mid = big.clone();
    mid.duration *= third / series_bytes(&big);
    assert!((series_bytes(&mid) - third).abs() / third < 1e-3);
    assert_eq!(tasks(&[&mid, &mid, &mid, &small]), vec![0..2, 2..4]);
    assert!(tasks::<Scenario>(&[]).is_empty());
}

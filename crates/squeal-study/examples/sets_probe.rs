//! The runs of `squeal reproduce`'s 40 sets on one thread, one at a time
//! ([`run`]) and in groups ([`run_many`]: the disc–pads as lane ensembles),
//! for BENCHMARKS.md (issue 16, point 2).
//!
//! `cargo run --release -p squeal-study --example sets_probe -- [SCALE] [ROUNDS]`
//! (SCALE multiplies every set's duration, as `--duration-scale`; default 1,
//! 2 rounds). Each round times both ways, alternating, and checks that they
//! took the same number of steps. Time is this thread's CPU time from
//! `/proc/thread-self/schedstat` (Linux), wall time elsewhere.

use squeal_study::reproduce::prepared_sets;
use squeal_study::run::{run, run_many};
use squeal_study::{Cancel, NoProgress, Scenario};
use std::time::Instant;

/// Seconds of CPU time this thread has run (wall time if not on Linux).
fn cpu(wall: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|t| t.split_whitespace().next()?.parse::<f64>().ok())
        .map_or_else(|| wall.elapsed().as_secs_f64(), |ns| ns * 1e-9)
}

/// Accepted steps of every run, one at a time.
fn one_at_a_time(sets: &[Scenario], cancel: &Cancel) -> u64 {
    sets.iter()
        .map(|s| run(s, &NoProgress, cancel).map_or(0, |r| r.info.stats.accepted))
        .sum()
}

/// Accepted steps of every run, `group` sets per `run_many`.
fn grouped(sets: &[Scenario], group: usize, cancel: &Cancel) -> u64 {
    sets.chunks(group)
        .flat_map(|g| run_many(g, &NoProgress, cancel))
        .map(|r| r.map_or(0, |r| r.info.stats.accepted))
        .sum()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let scale: f64 = args.next().map_or(1.0, |s| s.parse().expect("SCALE"));
    let rounds: usize = args.next().map_or(2, |s| s.parse().expect("ROUNDS"));
    let sets = prepared_sets(scale).expect("--duration-scale in (0, 10]");
    let cancel = Cancel::new();
    let wall = Instant::now();
    for round in 1..=rounds {
        let t = cpu(wall);
        let steps = one_at_a_time(&sets, &cancel);
        let one = cpu(wall) - t;
        let mut line = format!("round {round}: one at a time {one:.2} s ({steps} steps)");
        for group in [4, 40] {
            let t = cpu(wall);
            assert_eq!(grouped(&sets, group, &cancel), steps, "the same steps");
            let s = cpu(wall) - t;
            line += &format!("; run_many by {group}: {s:.2} s ({:.2}x)", one / s);
        }
        println!("{line}");
    }
}

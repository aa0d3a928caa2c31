//! The measurement behind issue 16's ensemble aim (BENCHMARKS.md, "Several
//! trajectories per core"): a transient map's points per CPU-second against
//! the same points run one at a time with `simulate`, on one thread.
//!
//! `cargo build --release -p squeal-study --example transient_cost`, then
//! `RAYON_NUM_THREADS=1 target/release/examples/transient_cost MODE` with
//! `MODE` one of
//! - `simulate`: every point's full run, one after the other, through
//!   `squeal_core::simulate` with a sink that keeps nothing (the
//!   integration alone: no output, no early stop);
//! - `early`: every point through `map::transient_at`, one at a time (early
//!   stopping, no lanes);
//! - `map`: the points through `map::transient_grid` (early stopping, four
//!   lanes).
//!
//! The grid is `map disc-pad --x V=0.5:20:8 --y N=100:3000:4 --transient`
//! (32 points, 0.5 s each). Each mode prints its wall time and a checksum of
//! the outcomes (`early` and `map` must print the same).

use squeal_core::simulate;
use squeal_core::sink::Discard;
use squeal_study::error::{Cancel, NoProgress};
use squeal_study::map::{parse_axis, point, transient_at, transient_grid};
use squeal_study::scenario::{resolve, Source};
use std::time::Instant;

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_else(|| "map".into());
    let sc = resolve(Source::Spec("disc-pad"), &[]).expect("built-in scenario");
    let x = parse_axis("V=0.5:20:8", "--x", false, &sc.model).expect("axis");
    let y = parse_axis("N=100:3000:4", "--y", false, &sc.model).expect("axis");
    let points: Vec<usize> = (0..x.values.len() * y.values.len()).collect();
    let start = Instant::now();
    let summary = match mode.as_str() {
        "simulate" => {
            let mut steps = 0u64;
            for &k in &points {
                let (i, j) = point(&x, k);
                let mut s = sc.clone();
                s.model.set(&x.name, x.values[i]).expect("V");
                s.model.set(&y.name, y.values[j]).expect("N");
                squeal_study::feasible::prepare(&mut s).expect("feasible");
                let squeal_study::model::AnyModel::DiscPad(m) = &s.model else {
                    unreachable!("the disc–pad scenario")
                };
                let z0 = squeal_study::run::initial_of::<_, 8>(m, &s).expect("initial state");
                let opts = squeal_study::run::sim_options::<8>(&s);
                let info = simulate(m, 0.0, z0, s.duration, s.sample_rate, opts, &mut Discard)
                    .expect("every point of this grid runs");
                steps += info.stats.accepted;
            }
            format!("{steps} steps")
        }
        "early" | "map" => {
            let outcomes = if mode == "early" {
                points
                    .iter()
                    .map(|&k| transient_at(&sc, &x, &y, k))
                    .collect()
            } else {
                transient_grid(&sc, &x, &y, &points, &NoProgress, &Cancel::new())
                    .expect("not cancelled")
            };
            let sum: f64 = outcomes.iter().map(|o| o.rms + o.t_end).sum();
            let classes: Vec<&str> = outcomes.iter().map(|o| o.class).collect();
            format!("checksum {sum:.17e}, classes {}", classes.join(" "))
        }
        other => panic!("MODE is simulate, early or map, not {other}"),
    };
    println!(
        "{mode}: {} points in {:.3} s; {summary}",
        points.len(),
        start.elapsed().as_secs_f64()
    );
}

//! The Rust side of BENCHMARKS.md's "Python" table: what one
//! `squeal.stability("disc-pad", levers=False)` computes — resolve the
//! built-in scenario, analyse steady sliding, build the JSON document — timed
//! over many calls (`cargo run --release -p squeal-study --example stability_call`).

use squeal_study::scenario::{resolve, Source};
use squeal_study::stability::{analyse, document};
use std::time::Instant;

fn main() {
    let calls = 20_000;
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = Instant::now();
        let mut checksum = 0.0;
        for _ in 0..calls {
            let sc = resolve(Source::Spec("disc-pad"), &[]).expect("built-in");
            let an = analyse(&sc.model).expect("steady sliding");
            let doc = document(&sc, &an, &squeal_study::levers::Levers::none());
            checksum += doc["max_growth_rate"].as_f64().unwrap_or(0.0);
        }
        let per = start.elapsed().as_secs_f64() / calls as f64;
        best = best.min(per);
        std::hint::black_box(checksum);
    }
    println!(
        "resolve + analyse + document, disc-pad: {:.2} µs per call (best of 5 × {calls})",
        best * 1e6
    );
}

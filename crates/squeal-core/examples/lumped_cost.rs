//! The lumped disc–pad against the dedicated model, for instruction counts:
//! `valgrind --tool=callgrind target/release/examples/lumped_cost dedicated|lumped [SECONDS]`
//! simulates the default thesis disc–pad from rest (200 kHz output into a
//! `Discard` sink) with the dedicated model or the same brake as a lumped
//! model, and prints the step count.

use squeal_core::model::lumped::{disc_pad_spec, Fixed};
use squeal_core::sink::Discard;
use squeal_core::{simulate, DiscPad, Lumped, SolverOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map_or("lumped", String::as_str);
    let t_end: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.2);
    let disc = DiscPad::default();
    let info = if which == "dedicated" {
        simulate(
            &disc,
            0.0,
            [0.0; 8],
            t_end,
            200_000.0,
            SolverOptions::default(),
            &mut Discard,
        )
    } else {
        let lumped = Lumped::build(&disc_pad_spec(&disc)).expect("the disc-pad spec is valid");
        simulate(
            &Fixed::<8>(&lumped),
            0.0,
            [0.0; 8],
            t_end,
            200_000.0,
            SolverOptions::default(),
            &mut Discard,
        )
    }
    .expect("the default disc-pad runs");
    println!("{which}: {:?}", info.stats);
}

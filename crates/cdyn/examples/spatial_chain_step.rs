//! Steps the benchmark's spatial chain (`cdyn bench`'s control and scheme),
//! cdyn's model and the hand-written one in turn, for profiling:
//! `spatial_chain_step N STEPS [cdyn|hand]`. Prints the time per step;
//! callgrind's difference between two step counts gives instructions per step.

use cdyn::Simulation;
use cdyn::baseline::HandWrittenChain;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let count = |i: usize, default: usize| args.get(i).map_or(default, |a| a.parse().expect("a count"));
    let (n, steps) = (count(0, 1000), count(1, 1000));
    let which = args.get(2).map_or("both", String::as_str);
    let h = 1e-3;
    let mut hand = HandWrittenChain::new(n, 0.3, 1.0, h, 0.4 / h, 0.4 / h);
    if which != "hand" {
        let built = cdyn::spatial::chain(n, 0.3, 1.0).build().expect("the chain builds");
        let mut sim = Simulation::new(&built.model, hand.settings(), &built.q0, &built.v0).expect("a simulation");
        let start = Instant::now();
        for _ in 0..steps {
            sim.step().expect("a step");
        }
        println!("cdyn N = {n}: {:.1} µs per step", start.elapsed().as_secs_f64() / steps as f64 * 1e6);
    }
    if which != "cdyn" {
        let start = Instant::now();
        for _ in 0..steps {
            hand.step();
        }
        println!("hand N = {n}: {:.1} µs per step", start.elapsed().as_secs_f64() / steps as f64 * 1e6);
    }
}

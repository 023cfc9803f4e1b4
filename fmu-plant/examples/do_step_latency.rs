//! Times 100 000 individual master-style communication steps of TowingPlant through its C
//! functions (set 8 inputs, fmi2DoStep 0.1 s, get every Real output; 8 active obstacles)
//! and prints the median, p99 and max in microseconds (criterion does not report p99).
//! Run with `cargo run --release -p fmu-plant --example do_step_latency`.
#![allow(clippy::print_stdout, clippy::unwrap_used)]

use fmi2_slave::ffi::Fmi2Status;
use std::time::Instant;

#[path = "../tests/support/mod.rs"]
mod support;

fn main() {
    let bench = support::Bench::new();
    for k in 0..1000 {
        assert_eq!(bench.communication_step(k), Fmi2Status::Ok);
    }
    let n = 100_000;
    let mut times = Vec::with_capacity(n);
    for k in 0..n {
        let start = Instant::now();
        let status = bench.communication_step(k);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        assert_eq!(status, Fmi2Status::Ok);
    }
    times.sort_by(f64::total_cmp);
    let at = |q: f64| times[((n as f64 - 1.0) * q).round() as usize];
    println!(
        "TowingPlant communication step (set 8 inputs, DoStep 0.1 s, get all Real outputs), {n} samples: median {:.2} us, p99 {:.2} us, max {:.2} us",
        at(0.5),
        at(0.99),
        times[n - 1]
    );
}

//! One communication step of TowingPlant through its exported C functions, as a master pays
//! for it: `fmi2SetReal` of the 8 inputs, `fmi2DoStep` of 0.1 s (10 RK4 substeps, nonlinear
//! hull, all three vessels and both towlines) and `fmi2GetReal` of every Real output, with
//! 8 active obstacles. Target: median <= 20 us. The same with the MCAP log on
//! (`log_file` set: every plant topic after each step, docs/logging.md) shows what logging
//! adds per step.
//! Run with `cargo bench -p fmu-plant --bench do_step`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use fmi2_slave::ffi::Fmi2Status;
use std::hint::black_box;

#[path = "../tests/support/mod.rs"]
mod support;

fn do_step(c: &mut Criterion) {
    let bench = support::Bench::new();
    let mut k = 0usize;
    c.bench_function("plant_do_step_0.1s_8_obstacles_ffi", |b| {
        b.iter(|| {
            k += 1;
            assert_eq!(bench.communication_step(black_box(k)), Fmi2Status::Ok);
        });
    });
}

fn do_step_logging(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let bench = support::Bench::with_log(Some(&dir.path().join("bench.mcap")));
    let mut k = 0usize;
    c.bench_function("plant_do_step_0.1s_8_obstacles_ffi_mcap_log", |b| {
        b.iter(|| {
            k += 1;
            assert_eq!(bench.communication_step(black_box(k)), Fmi2Status::Ok);
        });
    });
}

criterion_group!(benches, do_step, do_step_logging);
criterion_main!(benches);

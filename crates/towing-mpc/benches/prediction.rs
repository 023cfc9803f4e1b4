//! One prediction sample (T_s = 1 s, 10 RK4 substeps of 0.1 s) of the ship and the
//! tug model, plain and with the exact Jacobians, nonlinear hull damping; plus the
//! H_P = 3 linearised ship rollout. Seeded inputs, setup outside the timed part.
//! Run with `cargo bench -p towing-mpc --bench prediction`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use towing_model::{HullModel, Scenario};
use towing_mpc::{
    PredictionParams, ShipInput, ShipLinearisation, ShipModel, ShipState, TowlinePull, TugInput,
    TugModel, TugState,
};

/// Seeded pseudo-random numbers in [-1, 1) (64-bit LCG).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

type ShipCase = (ShipState, ShipInput);
type TugCase = (TugState, TugInput, TowlinePull);

fn cases(n: usize) -> (Vec<ShipCase>, Vec<TugCase>) {
    let mut rnd = uniform(2022);
    let state = |rnd: &mut dyn FnMut() -> f64| {
        [
            -10.0 + 5.0 * rnd(),
            20.0 + 5.0 * rnd(),
            1.8 + rnd(),
            0.5 + 0.5 * rnd(),
            0.2 * rnd(),
            0.2 * rnd(),
        ]
    };
    let mut ships = Vec::with_capacity(n);
    let mut tugs = Vec::with_capacity(n);
    for _ in 0..n {
        let x = state(&mut rnd);
        let u = [
            1.5 + 1.5 * rnd(),
            1.5 + 1.5 * rnd(),
            0.5 * rnd(),
            0.5 * rnd(),
        ];
        ships.push((x, u));
        let x = state(&mut rnd);
        let tau = [5.0 + 5.0 * rnd(), 2.0 * rnd(), 0.5 * rnd()];
        let pull = TowlinePull {
            tension: 1.5 + 1.5 * rnd(),
            bearing: x[2] + 0.5 * rnd(),
        };
        tugs.push((x, tau, pull));
    }
    (ships, tugs)
}

fn prediction(c: &mut Criterion) {
    let scenario = Scenario::paper().expect("paper scenario parses");
    let params = PredictionParams::default();
    let ship = ShipModel::from_scenario(&scenario, HullModel::NonlinearDamping, params)
        .expect("ship model builds");
    let tug = TugModel::from_scenario(&scenario, 1, HullModel::NonlinearDamping, params)
        .expect("tug model builds");
    let (ships, tugs) = cases(1024);

    let mut k = 0;
    c.bench_function("ship_step_1s", |b| {
        b.iter(|| {
            k = (k + 1) % ships.len();
            let (x, u) = &ships[k];
            black_box(ship.step(black_box(x), black_box(u)))
        });
    });
    c.bench_function("ship_step_linearised_1s", |b| {
        b.iter(|| {
            k = (k + 1) % ships.len();
            let (x, u) = &ships[k];
            black_box(ship.step_linearised(black_box(x), black_box(u)))
        });
    });
    c.bench_function("tug_step_1s", |b| {
        b.iter(|| {
            k = (k + 1) % tugs.len();
            let (x, tau, pull) = &tugs[k];
            black_box(tug.step(black_box(x), black_box(tau), black_box(pull)))
        });
    });
    c.bench_function("tug_step_linearised_1s", |b| {
        b.iter(|| {
            k = (k + 1) % tugs.len();
            let (x, tau, pull) = &tugs[k];
            black_box(tug.step_linearised(black_box(x), black_box(tau), black_box(pull)))
        });
    });
    let mut buffer = [ShipLinearisation::default(); 3];
    c.bench_function("ship_linearised_rollout_h3", |b| {
        b.iter(|| {
            k = (k + 1) % ships.len();
            let (x, u) = &ships[k];
            ship.linearise_rollout_into(black_box(x), black_box(&[*u; 3]), &mut buffer);
            black_box(&buffer);
        });
    });
}

criterion_group!(benches, prediction);
criterion_main!(benches);

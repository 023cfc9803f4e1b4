//! One SCP step (linearised rollout, condensed QP, Clarabel solve, true-cost check)
//! of each ADMM subproblem: the tug local problem (25) and the coordination
//! problem (26), H_P = 3, nonlinear hull damping, one obstacle. Each iteration restarts from the
//! same plan and trust radius, so every timed step is a full step from a
//! non-converged plan (its linearisation cached, see below). Run with `cargo bench -p towing-mpc --bench subproblems`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use towing_model::{HullModel, Scenario};
use towing_mpc::{
    FormationMap, Obstacle, PredictionParams, ShipModel, ShipMpc, ShipMpcParams, ShipStepData,
    TowlinePull, TugModel, TugMpc, TugMpcParams, TugStepData, HORIZON,
};

fn bench(c: &mut Criterion) {
    let scenario = Scenario::paper().expect("paper scenario");
    let params = PredictionParams::default();
    let hull = HullModel::NonlinearDamping;
    let formation = FormationMap::from_scenario(&scenario).expect("formation");
    // One obstacle in view (distance cost and up to one clearance row per sample:
    // a step solves the QP with only the obstacle slots in use, and drops the rows
    // the increments' boxes imply). Restarting from the same plan and state, each
    // timed step after the first reuses the linearised rollout (the subproblems
    // cache it per (state, plan, pulls)): the figures are QP, assembly and the
    // candidate's true cost; a fresh linearisation adds about 15-20 us.
    let obstacles = [Obstacle::Circle {
        centre: [4.0, 1.5],
        radius: 0.8,
    }];

    let tug_model = TugModel::from_scenario(&scenario, 1, hull, params).expect("tug model");
    let mut tug = TugMpc::new(tug_model, TugMpcParams::default()).expect("tug QP");
    let tug_data = TugStepData {
        state: [0.0, 0.0, 0.0, 0.1, 0.0, 0.0],
        pulls: [TowlinePull::from_plan(1.0, 0.0, 0.0); HORIZON],
        reference: [[1.0, 0.2, 0.05]; HORIZON],
        lambda: [[0.1, -0.1, 0.0]; HORIZON],
        rho: 1.0,
        obstacles: &obstacles,
        distance_cost_off: 0,
        waterway: None,
        own_ship: None,
        other_tug: None,
    };
    let tug_plan = [[1.0, 0.0, 0.0]; HORIZON];
    c.bench_function("tug_scp_step", |b| {
        b.iter(|| {
            tug.set_inputs(tug_plan);
            tug.trust_region_mut().reset();
            black_box(tug.step(black_box(&tug_data)))
        })
    });
    // The same without clearance rows (distance cost only): the price of the rows.
    let mut no_rows = TugMpcParams::default();
    no_rows.clearance.max_obstacles = 0;
    let tug_model = TugModel::from_scenario(&scenario, 1, hull, params).expect("tug model");
    let mut tug = TugMpc::new(tug_model, no_rows).expect("tug QP");
    c.bench_function("tug_scp_step_no_clearance_rows", |b| {
        b.iter(|| {
            tug.set_inputs(tug_plan);
            tug.trust_region_mut().reset();
            black_box(tug.step(black_box(&tug_data)))
        })
    });

    let ship_model = ShipModel::from_scenario(&scenario, hull, params).expect("ship model");
    let mut ship = ShipMpc::new(ship_model, formation, ShipMpcParams::default()).expect("ship QP");
    let mut tug_poses = [[[0.0; 3]; HORIZON]; 2];
    for (i, poses) in tug_poses.iter_mut().enumerate() {
        *poses = [formation.tug_reference([0.0; 3], 0.05, i); HORIZON];
    }
    let ship_data = ShipStepData {
        state: [0.0, 0.0, 0.0, 0.05, 0.0, 0.0],
        previous: [0.5, 1.0, 0.0, 0.0],
        reference: [[2.0, 0.3, 0.1]; HORIZON],
        tug_poses,
        lambda: [[[0.05; 3]; HORIZON]; 2],
        rho: 1.0,
        obstacles: &obstacles,
        distance_cost_off: 0,
        heading_floor: None,
        max_surge: None,
        waterway: None,
    };
    let ship_plan = [[0.5, 1.0, 0.0, 0.0]; HORIZON];
    c.bench_function("ship_scp_step", |b| {
        b.iter(|| {
            ship.set_inputs(ship_plan);
            ship.trust_region_mut().reset();
            black_box(ship.step(black_box(&ship_data)))
        })
    });
    let mut no_rows = ShipMpcParams::default();
    no_rows.clearance.max_obstacles = 0;
    let ship_model = ShipModel::from_scenario(&scenario, hull, params).expect("ship model");
    let mut ship = ShipMpc::new(ship_model, formation, no_rows).expect("ship QP");
    c.bench_function("ship_scp_step_no_clearance_rows", |b| {
        b.iter(|| {
            ship.set_inputs(ship_plan);
            ship.trust_region_mut().reset();
            black_box(ship.step(black_box(&ship_data)))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);

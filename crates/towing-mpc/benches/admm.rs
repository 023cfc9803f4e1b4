//! One control sample of the ADMM loop (Algorithm 1: per iteration one SCP step
//! of each tug problem (25) and of the coordination problem (26)) at the paper's
//! initial state (ship at rest at W_PO, tugs in formation, reference 2 m ahead
//! along the route) with one circular obstacle (radius 0.5 m) 3 m ahead of the
//! ship: on the ship's centre line (the formation puts tug 2 inside the tug's
//! clearance of it, so consensus is not reachable and the loop runs to S), and
//! 1.5 m to starboard. Every timed sample starts cold ([`Admm::reset`]). The
//! iteration counts are printed to stderr. The same samples, and one without the
//! obstacle, with the centralized MPC of eq. (12) ([`Centralized`], SCP to
//! convergence of the first move, cold each time). Run with
//! `cargo bench -p towing-mpc --bench admm`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use towing_model::{HullModel, Scenario};
use towing_mpc::{
    Admm, AdmmSettings, AppliedCommand, Centralized, CentralizedSettings, Obstacle,
    PredictionParams, SampleInput, ShipMpcParams, TugMpcParams,
};

fn bench(c: &mut Criterion) {
    let scenario = Scenario::paper().expect("paper scenario");
    let state =
        |v: &towing_model::VesselState| [v.eta[0], v.eta[1], v.eta[2], v.nu[0], v.nu[1], v.nu[2]];
    let ship = state(&scenario.ship);
    let (s, co) = ship[2].sin_cos();
    let ahead = |d: f64, lateral: f64| {
        [
            ship[0] + d * co - lateral * s,
            ship[1] + d * s + lateral * co,
        ]
    };
    let reference = [[ahead(2.0, 0.0)[0], ahead(2.0, 0.0)[1], ship[2]]; 3];
    for (name, lateral) in [
        ("admm_sample_near_encounter", 0.0),
        ("admm_sample_near_encounter_offset", 1.5),
    ] {
        let obstacles = [Obstacle::Circle {
            centre: ahead(3.0, lateral),
            radius: 0.5,
        }];
        let input = SampleInput {
            ship,
            tugs: [state(&scenario.tugs[0]), state(&scenario.tugs[1])],
            previous: AppliedCommand::default(),
            reference,
            obstacles: &obstacles,
            distance_cost_off: 0,
            heading_floor: None,
            max_surge: None,
            waterway: None,
        };
        let mut admm = Admm::from_scenario(
            &scenario,
            HullModel::NonlinearDamping,
            PredictionParams::default(),
            AdmmSettings::default(),
        )
        .expect("ADMM");
        let report = admm.solve_sample(&input);
        eprintln!(
            "{name}: {} iterations, converged {}, r_pri {:?} (eps {:?}), r_dual {:?} (eps {:?}), failed steps {}",
            report.iterations,
            report.converged,
            report.r_pri,
            report.eps_pri,
            report.r_dual,
            report.eps_dual,
            report.failed_steps
        );
        c.bench_function(name, |b| {
            b.iter(|| {
                admm.reset();
                black_box(admm.solve_sample(black_box(&input)))
            })
        });
    }
    for (name, obstacles) in [
        ("centralized_sample_free", &[][..]),
        (
            "centralized_sample_near_encounter_offset",
            &[Obstacle::Circle {
                centre: ahead(3.0, 1.5),
                radius: 0.5,
            }][..],
        ),
    ] {
        let input = SampleInput {
            ship,
            tugs: [state(&scenario.tugs[0]), state(&scenario.tugs[1])],
            previous: AppliedCommand::default(),
            reference,
            obstacles,
            distance_cost_off: 0,
            heading_floor: None,
            max_surge: None,
            waterway: None,
        };
        let mut central = Centralized::from_scenario(
            &scenario,
            HullModel::NonlinearDamping,
            PredictionParams::default(),
            ShipMpcParams::default(),
            TugMpcParams::default(),
            CentralizedSettings::default(),
        )
        .expect("centralized");
        let report = central.solve_sample(&input);
        eprintln!(
            "{name}: {} SCP iterations, converged {}, failed {}, cost {}, consensus max {:e}",
            report.iterations,
            report.converged,
            report.failed,
            report.cost,
            report.breakdown.consensus_max
        );
        c.bench_function(name, |b| {
            b.iter(|| {
                central.reset();
                black_box(central.solve_sample(black_box(&input)))
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);

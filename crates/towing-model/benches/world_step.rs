//! One 0.1 s `World::step`: ship + two tugs + two towlines, nonlinear hull
//! damping, default integration step (10 RK4 substeps), 8 active obstacles.
//! Target: median <= 20 us. Run with `cargo bench -p towing-model --bench world_step`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use towing_model::{
    HullModel, ObstacleKind, Scenario, World, WorldConfig, WorldInputs, MAX_OBSTACLES,
};

const SCENARIO: &str = include_str!("eight_obstacles.toml");

/// Seeded pseudo-random inputs within the paper's limits (64-bit LCG).
fn inputs(seed: u64, n: usize) -> Vec<WorldInputs> {
    let mut state = seed;
    let mut unit = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n)
        .map(|_| {
            let mut i = WorldInputs::default();
            for tug in 0..2 {
                i.tug_tau[tug] = [3.0 + 2.0 * unit(), unit(), 0.2 * unit()];
                i.tension_cmd[tug] = 1.5 + 1.5 * unit();
            }
            i
        })
        .collect()
}

fn world_step(c: &mut Criterion) {
    let scenario = Scenario::from_toml_str(SCENARIO, "benches/eight_obstacles.toml")
        .expect("bench scenario parses");
    let config = WorldConfig {
        hull_model: HullModel::NonlinearDamping,
        ..WorldConfig::default()
    };
    let mut world = World::new(&scenario, config).expect("bench world builds");
    assert!((0..MAX_OBSTACLES).all(|k| world.obstacle(k).kind != ObstacleKind::None));
    let inputs = inputs(2022, 1024);
    let mut k = 0;
    c.bench_function("world_step_0.1s_nonlinear_8_obstacles", |b| {
        b.iter(|| {
            k = (k + 1) % inputs.len();
            world
                .step(black_box(&inputs[k]), black_box(0.1))
                .expect("finite step");
        });
    });
}

criterion_group!(benches, world_step);
criterion_main!(benches);

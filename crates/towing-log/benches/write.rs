//! The writer's cost per simulated step of the plant's log (docs/logging.md): the nine
//! per-step topics of the paper scenario (three vessel states, two towlines, inputs, `/tf`,
//! the moving scene with two towlines and two target ships, five obstacles), serialized,
//! compressed and written on the calling thread (what the FMUs' writer thread does). This is
//! the plant with `log_scene_interval = 0`; by default it writes `/tf` and the moving scene
//! only every 0.5 s (docs/logging.md).
//! Run with `cargo bench -p towing-log --bench write`.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use towing_log::scene::{self, colors};
use towing_log::topics::*;
use towing_log::{LogError, LogOptions, LogWriter};

fn vessel(t: f64, k: f64) -> VesselState {
    VesselState {
        t,
        x: -4.9 - 0.0123456789 * t + k,
        y: 7.0 + 0.0487654321 * t,
        psi: 1.7679021385 + 1e-4 * t.sin(),
        u: 0.0501234567,
        v: -0.0012345678,
        r: 1e-4 * t.cos(),
    }
}

fn step(w: &mut LogWriter, t: f64) -> Result<(), LogError> {
    for (k, topic) in [names::PLANT_SHIP, names::PLANT_TUG1, names::PLANT_TUG2]
        .into_iter()
        .enumerate()
    {
        w.write(topic, t, &vessel(t, k as f64 * 2.1))?;
    }
    for topic in [names::PLANT_TOWLINE1, names::PLANT_TOWLINE2] {
        w.write(
            topic,
            t,
            &TowlineState {
                t,
                length: 1.0123456789,
                angle: 0.0123456789,
                tension: 1.9876543210,
                tension_cmd: 2.0,
                slack: false,
                elongation_error: 0.0123456789,
            },
        )?;
    }
    w.write(
        names::PLANT_INPUTS,
        t,
        &PlantInputs {
            t,
            tug1: [3.123456789, -0.123456789, 0.0123456789],
            tug2: [2.987654321, 0.234567891, -0.0234567891],
            tension_cmd: [2.0, 2.0],
        },
    )?;
    let transforms = FrameTransforms {
        transforms: [FRAME_SHIP, FRAME_TUG1, FRAME_TUG2]
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let v = vessel(t, k as f64 * 2.1);
                scene::frame_transform(f, t, v.x, v.y, v.psi)
            })
            .collect(),
    };
    w.write(names::TF, t, &transforms)?;
    let mut lines = SceneEntity::new("towlines", t);
    for k in 0..2 {
        let a = vessel(t, k as f64);
        lines.lines.push(scene::line_strip(
            [[a.x, a.y], [a.x + 0.9123, a.y - 0.4123]],
            0.1,
            0.02,
            colors::TOWLINE,
        ));
    }
    let mut targets = SceneEntity::new("targets", t);
    for k in 0..2 {
        targets.cylinders.push(scene::cylinder(
            16.0 + 0.07 * t,
            21.0 + k as f64,
            0.0,
            1.48,
            0.48,
            0.2,
            colors::TARGET,
        ));
    }
    w.write(
        names::PLANT_SCENE,
        t,
        &SceneUpdate {
            deletions: vec![],
            entities: vec![lines, targets],
        },
    )?;
    let obstacles = (1..=5)
        .map(|slot| ObstacleState {
            slot,
            name: ["a", "b", "c", "A", "B"][slot as usize - 1].to_owned(),
            kind: if slot <= 3 { 1 } else { 2 },
            x: -10.0 - 2.0 * slot as f64 + 0.07 * t,
            y: 15.0 + 10.0 * slot as f64,
            psi: 0.0,
            speed: 0.07,
            length: 1.48,
            width: 0.48,
        })
        .collect();
    w.write(names::PLANT_OBSTACLES, t, &Obstacles { t, obstacles })
}

fn write(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let mut w = LogWriter::create(dir.path().join("bench.mcap"), LogOptions::default()).unwrap();
    let mut k = 0u64;
    c.bench_function("plant_log_one_step_paper_topics", |b| {
        b.iter(|| {
            k += 1;
            step(&mut w, black_box(k as f64 * 0.1)).unwrap();
        });
    });
    w.finish().unwrap();
}

criterion_group!(benches, write);
criterion_main!(benches);

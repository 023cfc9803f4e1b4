//! Helpers shared by the integration tests: synthetic runs through the library.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use analyzer::analysis::{Analysis, Metrics};
use analyzer::stream::StreamOptions;
use analyzer::synth::{SynthObstacle, SynthRun, SynthShape};

/// Writes `run` into `dir` and returns the plant and controller log paths.
pub fn write_logs(run: &SynthRun, dir: &Path) -> (PathBuf, PathBuf) {
    let plant = dir.join("plant.mcap");
    let controller = dir.join("controller.mcap");
    run.write(&plant, &controller).expect("synthetic logs");
    (plant, controller)
}

/// Writes and analyses `run` (no tables written), and hands the analysis to `f`.
pub fn with_analysis<R>(run: &SynthRun, dir: &Path, f: impl FnOnce(&Analysis) -> R) -> R {
    with_options(run, dir, &StreamOptions::default(), f)
}

/// [`with_analysis`] with the streaming analysis' sizes `opts`.
pub fn with_options<R>(
    run: &SynthRun,
    dir: &Path,
    opts: &StreamOptions,
    f: impl FnOnce(&Analysis) -> R,
) -> R {
    let (plant, controller) = write_logs(run, dir);
    let multi = analyzer::progress::multi(true);
    let loaded = analyzer::run::load_run(&[controller, plant], &multi).expect("run");
    let a = analyzer::analysis::analyze_run(
        loaded,
        None,
        &multi,
        opts,
        &analyzer::thresholds::Thresholds::default(),
    )
    .expect("analysis");
    f(&a)
}

/// Writes and analyses `run`: its metrics.
pub fn analyze_run(run: &SynthRun, dir: &Path) -> Metrics {
    with_analysis(run, dir, |a| a.metrics.clone())
}

/// A straight run North from (0, 0) to (`length`, 0) at `speed`, no obstacles.
pub fn straight(length: f64, speed: f64, steps: usize) -> SynthRun {
    let mut run = SynthRun::paper(steps);
    run.name = "straight".to_owned();
    run.route = vec![
        [0.0, 0.0, 0.0],
        [length / 2.0, 0.0, 0.0],
        [length, 0.0, 0.0],
    ];
    run.speed = speed;
    run.obstacles.clear();
    run.scene = false;
    run
}

/// A target ship.
pub fn target(name: &str, x: f64, y: f64, course_deg: f64, speed: f64) -> SynthObstacle {
    SynthObstacle {
        name: name.to_owned(),
        pos: [x, y],
        shape: SynthShape::Ship(1.48, 0.48, course_deg, speed),
        active_from: 0.0,
    }
}

/// A static hazard of diameter 1 m.
pub fn hazard(name: &str, x: f64, y: f64) -> SynthObstacle {
    SynthObstacle {
        name: name.to_owned(),
        pos: [x, y],
        shape: SynthShape::Circle(1.0),
        active_from: 0.0,
    }
}

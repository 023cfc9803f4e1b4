//! Logs of two different runs are not combined silently (analyzer::same_run): the real
//! 3 s runs of `tests/data` (Gauss-Seidel and Jacobi coupling) each pass, paired across
//! the two runs they are refused naming both files and the first sample that differs;
//! logs with different `run_id`s are refused naming both ids.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn data(run: &str, log: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(run)
        .join(log)
}

fn analyse(logs: &[PathBuf]) -> Result<analyzer::analysis::Analysis, String> {
    let multi = analyzer::progress::multi(true);
    let run = analyzer::run::load_run(logs, &multi).map_err(|e| e.to_string())?;
    analyzer::analysis::analyze_run(
        run,
        None,
        &multi,
        &analyzer::stream::StreamOptions::default(),
        &analyzer::thresholds::Thresholds::default(),
    )
    .map_err(|e| e.to_string())
}

#[test]
fn the_logs_of_one_run_pass_under_either_coupling() {
    for run in ["real-3s", "real-3s-jacobi"] {
        let a = analyse(&[data(run, "plant.mcap"), data(run, "controller.mcap")])
            .unwrap_or_else(|e| panic!("{run}: {e}"));
        assert_eq!(a.metrics.run.plant_steps, 31, "{run}");
    }
}

#[test]
fn a_plant_log_and_a_controller_log_of_different_runs_are_refused() {
    for (plant_run, controller_run) in
        [("real-3s", "real-3s-jacobi"), ("real-3s-jacobi", "real-3s")]
    {
        let plant = data(plant_run, "plant.mcap");
        let controller = data(controller_run, "controller.mcap");
        let e = analyse(&[controller.clone(), plant.clone()]).expect_err("two runs");
        assert!(
            e.starts_with(&format!(
                "{} and {} are logs of different runs",
                plant.display(),
                controller.display()
            )),
            "{e}"
        );
        // Both runs compute the same first command; they part at the second sample.
        assert!(e.contains("command of t = 1.000 s"), "{e}");
    }
    // The binary: one line, exit status 1, no report.
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("report");
    let o = Command::new(env!("CARGO_BIN_EXE_analyzer"))
        .args(["report", "--quiet", "--out"])
        .arg(&out)
        .arg(data("real-3s", "plant.mcap"))
        .arg(data("real-3s-jacobi", "controller.mcap"))
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("analyzer report: "), "{err}");
    assert!(!out.join("metrics.json").exists());
    assert!(
        !out.join("timeseries.csv").exists(),
        "tables written so far are removed"
    );
}

#[test]
fn logs_with_different_run_ids_are_refused_naming_both() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut run = common::straight(10.0, 0.1, 50);
    let mut logs = Vec::new();
    for id in ["run-a", "run-b"] {
        run.run_id = id.to_owned();
        let sub = dir.path().join(id);
        std::fs::create_dir_all(&sub).expect("dir");
        logs.push(common::write_logs(&run, &sub));
    }
    // The same run twice (identical commands), only the ids differ.
    let (plant_a, controller_a) = logs[0].clone();
    let (_, controller_b) = logs[1].clone();
    analyse(&[plant_a.clone(), controller_a]).expect("same id");
    let e = analyse(&[plant_a.clone(), controller_b.clone()]).expect_err("two ids");
    assert_eq!(
        e,
        format!(
            "{} and {} are logs of different runs: run_id `run-a` in the first, `run-b` in \
             the second (the `run` metadata)",
            plant_a.display(),
            controller_b.display()
        )
    );
}

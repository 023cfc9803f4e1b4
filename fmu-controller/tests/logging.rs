//! TowingController's MCAP log (docs/logging.md) through the exported FMI functions: one
//! message per topic at each control sample, fallbacks on `/controller/log`, the run's
//! metadata, errors at creation and closing at free.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod support;

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::Fmu;
use std::path::Path;
use support::*;
use towing_controller::variables::{self as vars, DESCRIPTION};
use towing_interface::testing::{assert_uncreatable_log_file_is_named, read_log_messages};
use towing_log::topics::{self, names, *};

fn logging_to(name: &str, path: &Path) -> Fmu {
    let fmu = controller(name);
    assert_eq!(
        fmu.set_string(vars::LOG_FILE, path.to_str().unwrap()),
        Fmi2Status::Ok
    );
    set_states(&fmu, &paper_states());
    fmu
}

fn steps(fmu: &Fmu, t0: f64, h: f64, n: usize) -> f64 {
    let mut t = t0;
    for _ in 0..n {
        let s = fmu.step(t, h);
        assert!(
            s == Fmi2Status::Ok || s == Fmi2Status::Warning,
            "{}",
            fmu.log_text()
        );
        t += h;
    }
    t
}

#[test]
fn every_sample_logs_every_topic_once() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("controller.mcap");
    let fmu = logging_to("log", &path);
    fmu.init(0.0, None);
    // A target ship in slot 5 (active), the rest empty.
    let ship = paper_states()[0];
    set_obstacle(
        &fmu,
        4,
        [ship[0] - 6.0, ship[1] + 6.0, 0.0, 0.1, 1.48, 0.48],
        2,
    );
    // 3.05 s with 0.1 s steps: samples at t = 0, 1, 2, 3 s (sample time 1 s).
    steps(&fmu, 0.0, 0.1, 31);
    let samples = fmu.get_integer(vars::SAMPLES) as usize;
    assert!(samples >= 2, "{samples}");
    let command = commands(&fmu);
    assert_eq!(fmu.terminate(), Fmi2Status::Ok, "{}", fmu.log_text());

    let bytes = std::fs::read(&path).unwrap();
    let (msgs, _) = read_log_messages(&bytes);
    for (topic, _) in topics::CONTROLLER_TOPICS {
        let expected = if topic == names::CONTROLLER_LOG {
            0
        } else {
            samples
        };
        assert_eq!(msgs.get(topic).map_or(0, Vec::len), expected, "{topic}");
    }
    let times: Vec<u64> = msgs[names::CONTROLLER_SOLVER].iter().map(|m| m.0).collect();
    let expected: Vec<u64> = (0..samples as u64).map(|k| k * 1_000_000_000).collect();
    assert_eq!(times, expected, "one sample per sample_time from the start");

    let solver: Vec<Solver> = msgs[names::CONTROLLER_SOLVER]
        .iter()
        .map(|(_, d)| serde_json::from_slice(d).unwrap())
        .collect();
    assert_eq!(solver.last().unwrap().samples, samples as u64);
    assert_eq!(
        solver[0].architecture,
        fmu.get_integer(vars::parameter_vr_of("architecture").unwrap())
    );
    assert!(solver.iter().all(|s| s.fallback.is_empty()));
    let colregs: Colregs =
        serde_json::from_slice(&msgs[names::CONTROLLER_COLREGS].last().unwrap().1).unwrap();
    assert_eq!(colregs.targets.len(), 1);
    assert_eq!(colregs.targets[0].slot, 5);
    assert_eq!(
        colregs.targets[0].situation_code,
        fmu.get_integer(vars::colregs_situation(4))
    );
    assert_eq!(
        colregs.targets[0].situation,
        situation_name(colregs.targets[0].situation_code)
    );
    let reference: Reference =
        serde_json::from_slice(&msgs[names::CONTROLLER_REFERENCE].last().unwrap().1).unwrap();
    assert_eq!(reference.x, fmu.get_real(vars::reference(0)));
    assert_eq!(reference.d_ob, fmu.get_real(vars::D_OB));
    assert_eq!(
        reference.active_waypoint as i32,
        fmu.get_integer(vars::ACTIVE_WAYPOINT)
    );
    let prediction: Prediction =
        serde_json::from_slice(&msgs[names::CONTROLLER_PREDICTION].last().unwrap().1).unwrap();
    assert_eq!(prediction.ship.len(), towing_mpc::HORIZON);
    assert_eq!(
        prediction.ship[0].x,
        fmu.get_real(vars::prediction(0, 0, 0))
    );
    let scene: SceneUpdate = serde_json::from_slice(&msgs[names::CONTROLLER_SCENE][0].1).unwrap();
    assert_eq!(scene.entities[0].lines.len(), 3);
    assert_eq!(scene.entities[1].arrows.len(), 1);
    // The first sample's command is what the FMU output at t = 0; with 31 steps the last
    // step (t = 3.0 s) was a sample step, so the last command is the current output.
    let last: Command =
        serde_json::from_slice(&msgs[names::CONTROLLER_COMMAND].last().unwrap().1).unwrap();
    assert_eq!(last.tug1.to_vec(), command[0..3].to_vec());
    assert_eq!(last.tension.to_vec(), command[6..8].to_vec());

    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("a finished file");
    let run = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(run.metadata["unit"], "TowingController");
    assert_eq!(run.metadata["guid"], DESCRIPTION.guid());
    // No run_id given: no key (an analyzer reads it as empty).
    assert!(!run.metadata.contains_key("run_id"));
    let params: serde_json::Value = serde_json::from_str(&run.metadata["parameters"]).unwrap();
    assert!(params["mpc.sample_time"].is_number(), "{params}");
    assert_eq!(params["run_id"], "");
    assert_eq!(params["log_file"], path.to_str().unwrap());
    assert_eq!(
        params["avoidance_scheme"],
        fmu.get_integer(vars::parameter_vr_of("avoidance_scheme").unwrap())
    );
    assert_eq!(summary.attachment_indexes.len(), 1);
}

/// A fallback (fmi2OK by default) is a warning line in `/controller/log`.
#[test]
fn a_fallback_is_logged_as_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fallback.mcap");
    let fmu = logging_to("fallback", &path);
    fmu.init(0.0, None);
    let ship = paper_states()[0];
    let t = steps(&fmu, 0.0, 1.0, 2);
    set_obstacle(&fmu, 7, [ship[0], ship[1], 0.0, 0.0, 200.0, 200.0], 1);
    assert_eq!(fmu.step(t, 1.0), Fmi2Status::Ok, "{}", fmu.log_text());
    drop(fmu); // fmi2FreeInstance without fmi2Terminate closes the file
    let bytes = std::fs::read(&path).unwrap();
    assert!(mcap::Summary::read(&bytes).unwrap().is_some());
    let (msgs, _) = read_log_messages(&bytes);
    let logs = &msgs[names::CONTROLLER_LOG];
    assert_eq!(logs.len(), 1);
    let line: Log = serde_json::from_slice(&logs[0].1).unwrap();
    assert_eq!(line.level, Log::WARNING);
    assert!(line.message.starts_with("fallback:"), "{}", line.message);
    assert_eq!(line.name, "TowingController");
    assert_eq!(logs[0].0, 2_000_000_000);
    let solver: Solver =
        serde_json::from_slice(&msgs[names::CONTROLLER_SOLVER].last().unwrap().1).unwrap();
    assert!(!solver.fallback.is_empty());
    assert_eq!(solver.fallbacks, 1);
}

#[test]
fn a_log_file_that_cannot_be_created_is_an_error_naming_it() {
    let path = "/nonexistent-dir/controller.mcap";
    assert_uncreatable_log_file_is_named(&logging_to("bad", Path::new(path)), path);
}

/// Regression (issue 15, item 8): a log write that fails during the run is reported by the
/// next step, every run, also when that step has no sample to write. The log's writes fail
/// from the end of initialization on (a file size limit in a process of its own); the
/// first write to the file comes when the chunk of 0..10 s is flushed, with the sample at
/// 10 s in the step with index 100; the step with index 101 returns fmi2Warning, in each of
/// 3 runs.
#[test]
fn a_log_write_failure_is_reported_by_the_next_step_every_time() {
    use towing_interface::testing::{limit_file_size, rerun_in_child};
    if !rerun_in_child("a_log_write_failure_is_reported_by_the_next_step_every_time") {
        return;
    }
    for run in 0..3 {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("limited.mcap");
        let fmu = logging_to("limited", &path);
        fmu.init(0.0, None);
        limit_file_size(Some(std::fs::metadata(&path).unwrap().len()));
        let statuses = (0..150).map(|k| fmu.step(k as f64 * 0.1, 0.1));
        let odd: Vec<_> = statuses
            .enumerate()
            .filter(|(_, s)| *s != Fmi2Status::Ok)
            .collect();
        let text = fmu.log_text();
        assert_eq!(fmu.terminate(), Fmi2Status::Error);
        limit_file_size(None);
        assert_eq!(odd, [(101, Fmi2Status::Warning)], "run {run}: {text}");
        assert!(
            text.contains("logging stopped") && text.contains("File too large"),
            "{text}"
        );
    }
}

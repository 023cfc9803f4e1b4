//! TowingPlant's MCAP log (docs/logging.md) through the exported FMI functions: what the
//! file holds after a run, errors at creation, closing at terminate or at free, and FMU
//! states that go back in time.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::{Exports, Fmu};
use std::path::Path;
use towing_interface::testing::{self, assert_uncreatable_log_file_is_named, read_log_messages};
use towing_log::topics::{self, names, *};
use towing_plant::variables::{self as vars, DESCRIPTION};

fn exports() -> Exports {
    fmi2_slave::exports_of!(towing_plant)
}

fn plant_logging_to(name: &str, path: &Path) -> Fmu {
    let fmu = testing::instantiate(exports(), &DESCRIPTION, name);
    assert_eq!(
        fmu.set_string(vars::LOG_FILE, path.to_str().unwrap()),
        Fmi2Status::Ok
    );
    fmu
}

fn pull(fmu: &Fmu) {
    assert_eq!(fmu.set_real(vars::tug_force(1, 0), 3.0), Fmi2Status::Ok);
    assert_eq!(fmu.set_real(vars::tension_cmd(1), 2.0), Fmi2Status::Ok);
}

fn steps(fmu: &Fmu, t0: f64, n: usize) -> f64 {
    let mut t = t0;
    for _ in 0..n {
        assert_eq!(fmu.step(t, 0.1), Fmi2Status::Ok, "{}", fmu.log_text());
        t += 0.1;
    }
    t
}

#[test]
fn a_run_logs_every_topic_once_at_the_start_and_after_each_step() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plant.mcap");
    let fmu = plant_logging_to("log", &path);
    assert_eq!(
        fmu.set_string(vars::RUN_ID, "run-7 of the test"),
        Fmi2Status::Ok
    );
    fmu.init(0.0, None);
    assert_eq!(fmu.get_string(vars::LOG_FILE), path.to_str().unwrap());
    assert_eq!(fmu.get_string(vars::RUN_ID), "run-7 of the test");
    pull(&fmu);
    let n = 50;
    steps(&fmu, 0.0, n);
    assert_eq!(fmu.terminate(), Fmi2Status::Ok, "{}", fmu.log_text());

    let bytes = std::fs::read(&path).unwrap();
    let (msgs, last) = read_log_messages(&bytes);
    assert_eq!(last, 5_000_000_000);
    for (topic, _) in topics::PLANT_TOPICS {
        let expected = match topic {
            names::PLANT_LOG => 0,
            names::PLANT_SCENE_STATIC => 1,
            // `log_scene_interval` 0.5 s: t = 0, 0.5, ..., 5 s.
            names::TF | names::PLANT_SCENE => n / 5 + 1,
            _ => n + 1,
        };
        assert_eq!(msgs.get(topic).map_or(0, Vec::len), expected, "{topic}");
    }
    // Contents: the ship where the plant says it is, the inputs used, the obstacles.
    let ship: Vec<VesselState> = msgs[names::PLANT_SHIP]
        .iter()
        .map(|(_, d)| serde_json::from_slice(d).unwrap())
        .collect();
    assert_eq!((ship[0].t, ship[0].x, ship[0].y), (0.0, -4.9, 7.0));
    assert_eq!(ship[n].x, fmu.get_real(vars::vessel_state(0, 0)));
    assert!((ship[n].t - 5.0).abs() < 1e-12);
    let inputs: PlantInputs = serde_json::from_slice(&msgs[names::PLANT_INPUTS][n].1).unwrap();
    assert_eq!(inputs.tug2[0], 3.0);
    assert_eq!(inputs.tension_cmd, [0.0, 2.0]);
    let line: TowlineState = serde_json::from_slice(&msgs[names::PLANT_TOWLINE2][n].1).unwrap();
    assert_eq!(line.length, fmu.get_real(vars::towline(1, 0)));
    assert!((line.elongation_error - (line.length - 1.0)).abs() < 1e-12);
    assert_eq!(line.tension_cmd, 2.0);
    let obstacles: Obstacles = serde_json::from_slice(&msgs[names::PLANT_OBSTACLES][n].1).unwrap();
    // Active slots only, as the plant's `obstacle[k].kind` outputs.
    let active: Vec<u32> = (0..8)
        .filter(|&k| fmu.get_integer(vars::obstacle(k, vars::OBSTACLE_KIND)) != 0)
        .map(|k| k + 1)
        .collect();
    let logged: Vec<u32> = obstacles.obstacles.iter().map(|o| o.slot).collect();
    assert_eq!(logged, active);
    assert_eq!(obstacles.obstacles[0].name, "a");
    assert_eq!(obstacles.obstacles[0].kind, 1);
    let tf: FrameTransforms = serde_json::from_slice(&msgs[names::TF][0].1).unwrap();
    let children: Vec<_> = tf
        .transforms
        .iter()
        .map(|t| t.child_frame_id.as_str())
        .collect();
    assert_eq!(children, ["ship", "tug1", "tug2"]);
    assert_eq!(
        (
            tf.transforms[0].translation.x,
            tf.transforms[0].translation.y
        ),
        (7.0, -4.9)
    );
    let scene: SceneUpdate = serde_json::from_slice(&msgs[names::PLANT_SCENE][1].1).unwrap();
    assert_eq!(scene.entities[0].id, "towlines");
    assert_eq!(scene.entities[0].lines.len(), 2);
    assert_eq!(scene.entities[0].timestamp.nsec, 500_000_000);
    assert_eq!(msgs[names::TF][1].0, 500_000_000);
    let fixed: SceneUpdate = serde_json::from_slice(&msgs[names::PLANT_SCENE_STATIC][0].1).unwrap();
    let ids: Vec<_> = fixed.entities.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(
        ids,
        ["route", "hazards", "ship_hull", "tug1_hull", "tug2_hull"]
    );
    assert_eq!(fixed.entities[1].cylinders.len(), 3);
    assert_eq!(fixed.entities[2].frame_id, "ship");
    assert!(fixed.entities[2].frame_locked);
    assert_eq!(fixed.entities[2].cubes[0].size.x, 1.255);

    // Records besides messages.
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("a finished file");
    let run = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(run.name, topics::METADATA_RUN);
    assert_eq!(run.metadata["unit"], "TowingPlant");
    assert_eq!(run.metadata["guid"], DESCRIPTION.guid());
    assert_eq!(run.metadata["scenario"], topics::BUNDLED_SCENARIO_LABEL);
    assert_eq!(run.metadata["scenario_name"], "paper");
    assert_eq!(run.metadata["start_time"], "0");
    assert_eq!(run.metadata["run_id"], "run-7 of the test");
    let params: serde_json::Value = serde_json::from_str(&run.metadata["parameters"]).unwrap();
    assert_eq!(params["log_file"], path.to_str().unwrap());
    assert_eq!(params["run_id"], "run-7 of the test");
    assert_eq!(params["scenario"], "");
    assert_eq!(params["model.hull_from_scenario"], true);
    assert_eq!(
        params["model.hull"], 2,
        "an Enumeration as its item's value"
    );
    assert_eq!(params["log.scene_interval"], 0.5);
    let att = mcap::read::attachment(&bytes, &summary.attachment_indexes[0]).unwrap();
    assert_eq!(att.name, "scenario.toml");
    assert_eq!(
        String::from_utf8(att.data.to_vec()).unwrap(),
        testing::read_repository_file("scenarios/paper.toml")
    );
}

/// Log times (ns) of `/tf` after `n` steps of `h` from `t0` with `log_scene_interval` set
/// to `interval`; `/plant/scene` has the same times.
fn scene_times(name: &str, interval: f64, t0: f64, h: f64, n: usize) -> Vec<u64> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("{name}.mcap"));
    let fmu = plant_logging_to(name, &path);
    assert_eq!(
        fmu.set_real(
            vars::parameter_vr_of("log.scene_interval").unwrap(),
            interval
        ),
        Fmi2Status::Ok
    );
    fmu.init(t0, None);
    let mut t = t0;
    for _ in 0..n {
        assert_eq!(fmu.step(t, h), Fmi2Status::Ok, "{}", fmu.log_text());
        t += h;
    }
    assert_eq!(fmu.terminate(), Fmi2Status::Ok);
    let (msgs, _) = read_log_messages(&std::fs::read(&path).unwrap());
    let times: Vec<u64> = msgs[names::TF].iter().map(|m| m.0).collect();
    let scene: Vec<u64> = msgs[names::PLANT_SCENE].iter().map(|m| m.0).collect();
    assert_eq!(times, scene);
    assert_eq!(msgs[names::PLANT_SHIP].len(), n + 1);
    times
}

#[test]
fn the_foxglove_topics_follow_log_scene_interval() {
    let ms = |v: &[u64]| v.iter().map(|t| t / 1_000_000).collect::<Vec<_>>();
    // 0: every step.
    assert_eq!(
        ms(&scene_times("every", 0.0, 0.0, 0.1, 4)),
        [0, 100, 200, 300, 400]
    );
    // 0.25 s with 0.1 s steps: the first step reaching each multiple (0.3, 0.5, 0.8, 1.0 s),
    // counted from the start time.
    assert_eq!(
        ms(&scene_times("quarter", 0.25, 10.0, 0.1, 10)),
        [10_000, 10_300, 10_500, 10_800, 11_000]
    );
    // An interval longer than the run: the start only.
    assert_eq!(ms(&scene_times("long", 100.0, 0.0, 0.1, 30)), [0]);
}

#[test]
fn a_negative_log_scene_interval_is_refused_naming_it() {
    let fmu = testing::instantiate(exports(), &DESCRIPTION, "negative");
    assert_eq!(
        fmu.set_real(vars::parameter_vr_of("log.scene_interval").unwrap(), -1.0),
        Fmi2Status::Error
    );
    assert!(
        fmu.log_text()
            .contains("parameter `log.scene_interval`: must be finite and >= 0 s"),
        "{}",
        fmu.log_text()
    );
    assert_eq!(
        fmu.get_real(vars::parameter_vr_of("log.scene_interval").unwrap()),
        0.5
    );
}

#[test]
fn without_a_log_file_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let fmu = testing::instantiate(exports(), &DESCRIPTION, "nolog");
    fmu.init(0.0, None);
    assert_eq!(fmu.get_string(vars::LOG_FILE), "");
    steps(&fmu, 0.0, 3);
    assert_eq!(fmu.terminate(), Fmi2Status::Ok);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_log_file_that_cannot_be_created_is_an_error_naming_it() {
    let path = "/nonexistent-dir/plant.mcap";
    assert_uncreatable_log_file_is_named(&plant_logging_to("bad", Path::new(path)), path);
}

#[test]
fn free_instance_finishes_a_log_that_terminate_did_not() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("freed.mcap");
    {
        let fmu = plant_logging_to("freed", &path);
        fmu.init(0.0, None);
        steps(&fmu, 0.0, 20);
        // Dropped without fmi2Terminate: fmi2FreeInstance closes the file.
    }
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("a finished file");
    assert_eq!(summary.stats.unwrap().channel_message_counts.len(), 10);
    let (msgs, _) = read_log_messages(&bytes);
    assert_eq!(msgs[names::PLANT_SHIP].len(), 21);
}

#[test]
fn a_start_time_other_than_zero_is_the_time_of_the_first_messages() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("late.mcap");
    let fmu = plant_logging_to("late", &path);
    fmu.init(100.0, None);
    steps(&fmu, 100.0, 2);
    assert_eq!(fmu.terminate(), Fmi2Status::Ok);
    let bytes = std::fs::read(&path).unwrap();
    let (msgs, last) = read_log_messages(&bytes);
    assert_eq!(msgs[names::PLANT_SHIP][0].0, 100_000_000_000);
    assert_eq!(last, 100_200_000_000);
}

#[test]
fn going_back_to_an_earlier_fmu_state_keeps_log_times_non_decreasing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rollback.mcap");
    let fmu = plant_logging_to("rollback", &path);
    fmu.init(0.0, None);
    pull(&fmu);
    let t = steps(&fmu, 0.0, 10);
    let saved = fmu.get_state();
    let end = steps(&fmu, t, 10);
    // SAFETY: `saved` is a live state of this instance, freed once below.
    assert_eq!(unsafe { fmu.set_state(saved) }, Fmi2Status::Ok);
    unsafe { fmu.free_state(saved) };
    // Redo the last 10 steps and go 5 further: the repeated times are dropped from the
    // log (times must not decrease), the new ones are written; no warning.
    steps(&fmu, t, 15);
    assert_eq!(fmu.terminate(), Fmi2Status::Ok, "{}", fmu.log_text());
    let bytes = std::fs::read(&path).unwrap();
    let (msgs, last) = read_log_messages(&bytes);
    assert_eq!(last, ((end + 0.5) * 1e9).round() as u64);
    // 0..=2.0 s first, then 2.1..=2.5 s after the replay (2.0 s itself is written again:
    // equal times are allowed).
    let ship = &msgs[names::PLANT_SHIP];
    assert_eq!(ship.len(), 21 + 1 + 5);
}

#[test]
fn a_log_that_cannot_be_written_is_an_error_at_exit_initialization() {
    // /dev/full takes the open and refuses every write (ENOSPC). (A failure during the
    // run, a warning and then fmi2Error at terminate, is tested on `SharedLog` in
    // towing-log.)
    if !Path::new("/dev/full").exists() {
        return;
    }
    let fmu = plant_logging_to("full", Path::new("/dev/full"));
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Ok);
    assert_eq!(fmu.exit_init(), Fmi2Status::Error);
    let text = fmu.last_text();
    assert!(
        text.contains("`log_file`") && text.contains("/dev/full") && text.contains("No space left"),
        "{text}"
    );
}

/// Regression (issue 15, item 8): `fmi2SetFMUstate` with a state of another instance moved
/// the instance onto that instance's log file. The log is not part of the state: each
/// instance writes its own file to its own end.
#[test]
fn set_fmu_state_keeps_the_instance_s_own_log() {
    let dir = tempfile::tempdir().unwrap();
    let (path_a, path_b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let a = plant_logging_to("a", &path_a);
    let b = plant_logging_to("b", &path_b);
    for fmu in [&a, &b] {
        fmu.init(0.0, None);
        pull(fmu);
    }
    let t = steps(&a, 0.0, 50);
    b.restore(&a.serialize());
    let end = steps(&b, t, 50);
    // And a state taken of `b` set on `a` (in memory, as the layer keeps it).
    let in_memory = b.get_state();
    // SAFETY: a live state of `b`; the layer recognises it as one of this model.
    assert_eq!(unsafe { a.set_state(in_memory) }, Fmi2Status::Ok);
    unsafe { b.free_state(in_memory) };
    let end_a = steps(&a, end, 10);
    for fmu in [&a, &b] {
        assert_eq!(fmu.terminate(), Fmi2Status::Ok, "{}", fmu.log_text());
    }
    let last = |p: &Path| read_log_messages(&std::fs::read(p).unwrap()).1;
    assert_eq!(last(&path_b), (end * 1e9).round() as u64);
    assert_eq!(last(&path_a), (end_a * 1e9).round() as u64);
    let ship_b = read_log_messages(&std::fs::read(&path_b).unwrap()).0;
    // b: 0 s, its first step was not logged (it jumped to 5 s), then 5.1 ..= 10 s.
    assert_eq!(ship_b[names::PLANT_SHIP].len(), 1 + 50);
}

/// The indexes of the steps that did not return fmi2OK in 150 steps of 0.1 s of `fmu`,
/// whose log breaks after initialization (writes beyond the file's size then fail), and
/// the log text.
fn statuses_after_the_log_breaks(fmu: &Fmu, path: &Path) -> (Vec<(usize, Fmi2Status)>, String) {
    fmu.init(0.0, None);
    pull(fmu);
    testing::limit_file_size(Some(std::fs::metadata(path).unwrap().len()));
    let statuses = (0..150).map(|k| fmu.step(k as f64 * 0.1, 0.1));
    let odd = statuses
        .enumerate()
        .filter(|(_, s)| *s != Fmi2Status::Ok)
        .collect();
    let text = fmu.log_text();
    assert_eq!(fmu.terminate(), Fmi2Status::Error);
    testing::assert_last_message_contains(fmu, "the file is incomplete");
    testing::limit_file_size(None);
    (odd, text)
}

/// Regression (issue 15, item 8): a log write that fails during the run was reported
/// after a delay that depended on the writer thread's timing, often only at terminate.
/// Now the step after the one whose messages failed returns fmi2Warning, every run: the
/// log's writes fail from the end of initialization on (a file size limit in a process of
/// its own); the first write to the file comes when the chunk holding 0..10 s is flushed,
/// with the message at 10.0 s (the step with index 99), so the step with index 100
/// reports it, in each of 3 runs.
#[test]
fn a_log_write_failure_is_reported_by_the_next_step_every_time() {
    if !testing::rerun_in_child("a_log_write_failure_is_reported_by_the_next_step_every_time") {
        return;
    }
    for run in 0..3 {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("limited.mcap");
        let fmu = plant_logging_to("limited", &path);
        let (odd, text) = statuses_after_the_log_breaks(&fmu, &path);
        assert_eq!(odd, [(100, Fmi2Status::Warning)], "run {run}: {text}");
        assert!(
            text.contains("logging stopped") && text.contains("File too large"),
            "{text}"
        );
    }
}

/// Groundings: in a waterway 0.1 m wide each side every hull pokes beyond the bank from
/// the start (the ship's half beam is 0.145 m): the three `aground.*` outputs are true
/// and the log holds one grounding event per vessel at the start time, none after (the
/// episodes go on); in the paper's 5 m waterway nothing is aground (the run test above:
/// no `/plant/log` message).
#[test]
fn a_hull_beyond_the_bank_is_aground_and_logged_once_per_episode() {
    use towing_plant::outputs::OUTPUTS;
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("narrow.toml");
    let text = testing::read_repository_file("scenarios/paper.toml").replace(
        "[waterway]\nhalf_width = 5.0",
        "[waterway]\nhalf_width = 0.1",
    );
    assert!(text.contains("half_width = 0.1"));
    std::fs::write(&scenario, text).unwrap();
    let path = dir.path().join("plant.mcap");
    let fmu = plant_logging_to("narrow", &path);
    assert_eq!(
        fmu.set_string(vars::SCENARIO, scenario.to_str().unwrap()),
        Fmi2Status::Ok
    );
    fmu.init(0.0, None);
    for o in &OUTPUTS {
        assert!(fmu.get_boolean(o.value_reference), "{}", o.name);
    }
    pull(&fmu);
    steps(&fmu, 0.0, 20);
    for o in &OUTPUTS {
        assert!(fmu.get_boolean(o.value_reference), "{}", o.name);
    }
    assert_eq!(fmu.terminate(), Fmi2Status::Ok, "{}", fmu.log_text());
    let (msgs, _) = read_log_messages(&std::fs::read(&path).unwrap());
    let events: Vec<(u64, Log)> = msgs[names::PLANT_LOG]
        .iter()
        .map(|(t, d)| (*t, serde_json::from_slice(d).unwrap()))
        .collect();
    assert_eq!(events.len(), 3, "{events:?}");
    for ((t, e), vessel) in events.iter().zip(["ship", "tug1", "tug2"]) {
        assert_eq!((*t, e.level), (0, Log::WARNING));
        assert!(
            e.message
                .starts_with(&format!("grounding: {vessel} aground at t = 0.000 s")),
            "{}",
            e.message
        );
    }
}

/// The outputs are Booleans of their own in the model description.
#[test]
fn the_aground_outputs_are_in_the_model_description() {
    use towing_plant::outputs::OUTPUTS;
    for (o, name) in OUTPUTS
        .iter()
        .zip(["aground.ship", "aground.tug1", "aground.tug2"])
    {
        assert_eq!(o.name, name);
        let v = DESCRIPTION
            .find(fmi2_slave::ValueType::Boolean, o.value_reference)
            .unwrap();
        assert_eq!(v.name, name);
    }
}

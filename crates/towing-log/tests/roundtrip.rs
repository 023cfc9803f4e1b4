//! Writes logs and reads them back with the mcap crate's readers: counts, channels,
//! schemas, every message into its struct, records besides messages, truncated files and
//! the time rules.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use towing_log::scene::{self, colors};
use towing_log::topics::{self, names, *};
use towing_log::writer::Batch;
use towing_log::{LogError, LogOptions, LogWriter, SharedLog, TopicMessage};

fn vessel(t: f64) -> VesselState {
    VesselState {
        t,
        x: -4.9 + 0.01 * t,
        y: 7.0 + 0.05 * t,
        psi: 1.768,
        u: 0.05,
        v: -0.001,
        r: 0.0,
    }
}

fn scene_update(t: f64) -> SceneUpdate {
    let mut hulls = SceneEntity::new("hulls", t);
    hulls.cubes.push(scene::hull_cube(
        -4.9,
        7.0 + t,
        1.77,
        1.255,
        0.29,
        colors::SHIP,
    ));
    let mut route = SceneEntity::new("route", t);
    route.lines.push(scene::line_strip(
        [[-4.9, 7.0], [-6.3, 14.0]],
        0.0,
        0.03,
        colors::ROUTE,
    ));
    route
        .spheres
        .push(scene::sphere(-6.3, 14.0, 0.0, 0.2, colors::ROUTE));
    route.cylinders.push(scene::cylinder(
        -10.0,
        15.0,
        0.0,
        1.0,
        1.0,
        0.3,
        colors::HAZARD,
    ));
    route
        .arrows
        .push(scene::arrow(-6.3, 14.0, 1.77, 0.1, 0.5, colors::REFERENCE));
    SceneUpdate {
        deletions: vec![],
        entities: vec![hulls, route],
    }
}

/// Writes `steps` + 1 samples (t = 0, 0.1, ...) of a small plant-like log; returns the
/// writer (not finished).
fn write_run(path: &Path, steps: usize, options: LogOptions) -> LogWriter {
    let mut w = LogWriter::create(path, options).unwrap();
    let mut run = BTreeMap::new();
    run.insert("unit".to_owned(), "Test".to_owned());
    run.insert("epoch".to_owned(), topics::EPOCH.to_owned());
    w.metadata(topics::METADATA_RUN, run).unwrap();
    w.attach(
        topics::SCENARIO_ATTACHMENT,
        topics::SCENARIO_MEDIA_TYPE,
        0.0,
        b"name = \"t\"\n",
    )
    .unwrap();
    w.register::<Log>(names::PLANT_LOG).unwrap();
    for k in 0..=steps {
        let t = k as f64 * 0.1;
        w.write(names::PLANT_SHIP, t, &vessel(t)).unwrap();
        w.write(
            names::PLANT_TOWLINE1,
            t,
            &TowlineState {
                t,
                length: 1.0,
                angle: 0.0,
                tension: 2.0,
                tension_cmd: 2.0,
                slack: false,
                elongation_error: 0.0,
            },
        )
        .unwrap();
        w.write(
            names::TF,
            t,
            &FrameTransforms {
                transforms: vec![scene::frame_transform("ship", t, -4.9, 7.0, 1.77)],
            },
        )
        .unwrap();
        w.write(names::PLANT_SCENE, t, &scene_update(t)).unwrap();
        w.write(
            names::CONTROLLER_SOLVER,
            t,
            &Solver {
                t,
                architecture: 1,
                scheme: 1,
                iterations: 3,
                converged: k % 2 == 0,
                r_pri: [1e-3, 2e-3],
                r_dual: [1e-4, 2e-4],
                compute_time_ms: 12.5,
                samples: k as u64 + 1,
                fallbacks: 0,
                fallback: if k == 3 {
                    "the ship QP gave no usable solution".to_owned()
                } else {
                    String::new()
                },
            },
        )
        .unwrap();
    }
    w
}

const TOPICS_PER_STEP: usize = 5;

/// Decodes one message by its schema name into the matching struct; panics on failure.
fn decode(schema: &str, data: &[u8]) {
    fn check<M: TopicMessage + serde::de::DeserializeOwned>(data: &[u8]) {
        serde_json::from_slice::<M>(data).unwrap_or_else(|e| {
            panic!("{}: {e}: {}", M::SCHEMA_NAME, String::from_utf8_lossy(data))
        });
    }
    match schema {
        "towing.VesselState" => check::<VesselState>(data),
        "towing.TowlineState" => check::<TowlineState>(data),
        "towing.Obstacles" => check::<Obstacles>(data),
        "towing.PlantInputs" => check::<PlantInputs>(data),
        "towing.Reference" => check::<Reference>(data),
        "towing.Colregs" => check::<Colregs>(data),
        "towing.Command" => check::<Command>(data),
        "towing.Solver" => check::<Solver>(data),
        "towing.Prediction" => check::<Prediction>(data),
        "foxglove.FrameTransforms" => check::<FrameTransforms>(data),
        "foxglove.SceneUpdate" => check::<SceneUpdate>(data),
        "foxglove.Log" => check::<Log>(data),
        other => panic!("unknown schema {other}"),
    }
}

#[test]
fn a_log_reads_back_with_its_channels_schemas_and_records() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let steps = 200;
    let mut w = write_run(&path, steps, LogOptions::default());
    assert_eq!(w.message_count(), ((steps + 1) * TOPICS_PER_STEP) as u64);
    w.finish().unwrap();
    assert!(w.is_finished());
    w.finish().unwrap(); // idempotent
    assert!(matches!(
        w.write(names::PLANT_SHIP, 100.0, &vessel(100.0)),
        Err(LogError::Finished { .. })
    ));

    let bytes = std::fs::read(&path).unwrap();
    let mut counts: HashMap<String, usize> = HashMap::new();
    let mut last = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert!(m.log_time >= last, "log times must not decrease");
        assert_eq!(m.log_time, m.publish_time);
        last = m.log_time;
        assert_eq!(m.channel.message_encoding, topics::MESSAGE_ENCODING);
        let schema = m.channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, topics::SCHEMA_ENCODING);
        decode(&schema.name, &m.data);
        *counts.entry(m.channel.topic.clone()).or_default() += 1;
    }
    assert_eq!(last, 20_000_000_000);
    for topic in [
        names::PLANT_SHIP,
        names::PLANT_TOWLINE1,
        names::TF,
        names::PLANT_SCENE,
        names::CONTROLLER_SOLVER,
    ] {
        assert_eq!(counts[topic], steps + 1, "{topic}");
    }

    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let stats = summary.stats.unwrap();
    assert_eq!(stats.message_count, ((steps + 1) * TOPICS_PER_STEP) as u64);
    assert_eq!(stats.metadata_count, 1);
    assert_eq!(stats.attachment_count, 1);
    // The log channel is registered up front, without messages.
    let topics: Vec<_> = summary.channels.values().map(|c| c.topic.clone()).collect();
    assert!(topics.iter().any(|t| t == names::PLANT_LOG), "{topics:?}");
    assert_eq!(summary.channels.len(), TOPICS_PER_STEP + 1);
    // Chunks were closed about every 10 s of simulated time (20 s of data -> >= 2 chunks).
    assert!(stats.chunk_count >= 2, "{}", stats.chunk_count);
    // Every schema is JSON, self-contained and named as the contract says.
    for schema in summary.schemas.values() {
        let json: serde_json::Value = serde_json::from_slice(&schema.data).unwrap();
        assert_eq!(json["type"], "object", "{}", schema.name);
        assert!(
            !String::from_utf8_lossy(&schema.data).contains("$ref"),
            "{} has a $ref",
            schema.name
        );
    }
    let names: Vec<_> = summary.schemas.values().map(|s| s.name.clone()).collect();
    for n in [
        "towing.VesselState",
        "foxglove.SceneUpdate",
        "foxglove.FrameTransforms",
        "foxglove.Log",
    ] {
        assert!(names.iter().any(|s| s == n), "{n} in {names:?}");
    }
    // Metadata and attachment.
    let meta = &summary.metadata_indexes[0];
    assert_eq!(meta.name, topics::METADATA_RUN);
    let record = mcap::read::metadata(&bytes, meta).unwrap();
    assert_eq!(record.metadata["epoch"], topics::EPOCH);
    let att = mcap::read::attachment(&bytes, &summary.attachment_indexes[0]).unwrap();
    assert_eq!(att.name, topics::SCENARIO_ATTACHMENT);
    assert_eq!(att.media_type, topics::SCENARIO_MEDIA_TYPE);
    assert_eq!(&att.data[..], b"name = \"t\"\n");

    // The linear, bounded-memory reader sees the same messages.
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let mut linear = 0;
    for m in mcap::io::MessageReader::new(file) {
        m.unwrap();
        linear += 1;
    }
    assert_eq!(linear, (steps + 1) * TOPICS_PER_STEP);
}

/// Messages readable by the linear reader before its first error.
fn readable(bytes: &[u8]) -> (usize, u64) {
    let mut n = 0;
    let mut last = 0;
    for m in mcap::io::MessageReader::new(std::io::Cursor::new(bytes)) {
        match m {
            Ok(m) => {
                n += 1;
                last = m.log_time;
            }
            Err(_) => break,
        }
    }
    (n, last)
}

#[test]
fn an_unfinished_file_is_readable_up_to_the_last_flush() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crash.mcap");
    // 35 s of data with a 10 s interval: the chunk is closed before the first message at
    // t = 10, 20, 30 s (the first message is at t = 0); from t = 30 s on everything stays
    // in the open chunk.
    let mut w = write_run(&path, 350, LogOptions::default());
    // A copy of the bytes now is what a crash would leave behind.
    let crashed = std::fs::read(&path).unwrap();
    let (n, last) = readable(&crashed);
    assert_eq!(n, 300 * TOPICS_PER_STEP, "every message before t = 30 s");
    assert_eq!(last, 29_900_000_000);
    w.finish().unwrap();
}

#[test]
fn a_finished_file_cut_anywhere_yields_a_prefix_of_its_messages() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.mcap");
    let options = LogOptions {
        flush_interval: 2.0,
        ..LogOptions::default()
    };
    let mut w = write_run(&path, 100, options);
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let (all, _) = readable(&bytes);
    assert_eq!(all, 101 * TOPICS_PER_STEP);
    let mut previous = 0;
    for fraction in [0.1, 0.25, 0.5, 0.75, 0.9, 0.99] {
        let cut = (bytes.len() as f64 * fraction) as usize;
        let (n, last) = readable(&bytes[..cut]);
        assert!(n <= all);
        assert!(n >= previous, "a longer prefix never yields fewer messages");
        previous = n;
        if fraction >= 0.5 {
            // Chunks closed every 2 s of simulated time: at most one chunk is lost.
            assert!(n > 0 && last > 0, "cut at {cut}: {n} messages");
        }
    }
    // Cut inside the summary: every message is there.
    let data_end = bytes.len() - 200;
    assert_eq!(readable(&bytes[..data_end]).0, all);
}

#[test]
fn times_are_refused_when_they_go_back_or_are_not_representable() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("time.mcap");
    let mut w = LogWriter::create(&path, LogOptions::default()).unwrap();
    w.write(names::PLANT_SHIP, 1.0, &vessel(1.0)).unwrap();
    // Equal times are fine (several topics per step).
    w.write(names::PLANT_TUG1, 1.0, &vessel(1.0)).unwrap();
    let e = w.write(names::PLANT_SHIP, 0.9, &vessel(0.9)).unwrap_err();
    assert!(matches!(e, LogError::TimeWentBack { .. }), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("time.mcap") && text.contains("earlier"),
        "{text}"
    );
    for t in [-0.1, f64::NAN, f64::INFINITY, 1e11] {
        let e = w.write(names::PLANT_SHIP, t, &vessel(1.0)).unwrap_err();
        assert!(matches!(e, LogError::BadTime { .. }), "{e}");
    }
    // A refused message changes nothing: the next one at the same time is accepted.
    w.write(names::PLANT_SHIP, 1.0, &vessel(1.0)).unwrap();
    assert_eq!(w.message_count(), 3);
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(mcap::MessageStream::new(&bytes).unwrap().count(), 3);
}

#[test]
fn log_time_is_the_rounded_simulation_time_in_ns() {
    assert_eq!(towing_log::time_ns(0.0), Some(0));
    assert_eq!(towing_log::time_ns(0.1), Some(100_000_000));
    assert_eq!(towing_log::time_ns(0.30000000000000004), Some(300_000_000));
    assert_eq!(
        towing_log::time_ns(1000.0000000004),
        Some(1_000_000_000_000)
    );
    assert_eq!(towing_log::time_ns(-1e-12), None);
}

#[test]
fn errors_name_the_file_and_the_reason() {
    let e = LogWriter::create("/nonexistent-dir/x.mcap", LogOptions::default()).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("/nonexistent-dir/x.mcap"), "{text}");
    assert!(text.contains("No such file"), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let bad = LogOptions {
        flush_interval: 0.0,
        ..LogOptions::default()
    };
    let e = LogWriter::create(dir.path().join("o.mcap"), bad).unwrap_err();
    assert!(e.to_string().contains("flush_interval"), "{e}");
}

/// A batch writing the ship's state at `t`.
fn ship_at(t: f64) -> Batch {
    Box::new(move |w| w.write(names::PLANT_SHIP, t, &vessel(t)))
}

fn shared(path: &Path, background: bool, options: LogOptions) -> SharedLog {
    let writer = LogWriter::create(path, options).unwrap();
    if background {
        SharedLog::spawn(writer).unwrap()
    } else {
        SharedLog::new(writer)
    }
}

#[test]
fn a_shared_log_is_one_writer_for_every_clone() {
    let none = SharedLog::none();
    assert!(!none.is_active());
    assert_eq!(
        none.batch(Box::new(|_| panic!("no writer, no batch"))),
        None
    );
    assert!(!none.finish().unwrap());
    assert_eq!(none.path(), None);

    for background in [false, true] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("shared.mcap");
        let log = shared(&path, background, LogOptions::default());
        let copy = log.clone();
        assert!(log.is_active() && copy.is_active());
        assert_eq!(log.batch(ship_at(0.0)), None);
        assert_eq!(copy.batch(ship_at(0.1)), None);
        // A batch whose time went back (the master restored an earlier state) is dropped.
        assert_eq!(log.batch(ship_at(0.05)), None);
        for k in 2..1000 {
            assert_eq!(copy.batch(ship_at(k as f64 * 0.1)), None);
        }
        assert_eq!(log.path().unwrap(), path);
        assert!(copy.finish().unwrap());
        assert_eq!(log.dropped(), 1, "background {background}");
        assert!(!log.is_active());
        assert!(!log.finish().unwrap());
        assert_eq!(log.batch(Box::new(|_| panic!("finished, no batch"))), None);
        let bytes = std::fs::read(&path).unwrap();
        let times: Vec<u64> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(|m| m.unwrap().log_time)
            .collect();
        let expected: Vec<u64> = (0..1000).map(|k| k * 100_000_000).collect();
        assert_eq!(
            times, expected,
            "background {background}: every batch, in order"
        );
    }
}

/// The index of the first batch that returns a warning, and the warning.
fn first_warning(log: &SharedLog, batches: impl Iterator<Item = Batch>) -> (usize, String) {
    for (k, batch) in batches.enumerate() {
        if let Some(w) = log.batch(batch) {
            return (k, w);
        }
    }
    panic!("no warning")
}

#[test]
fn a_failing_disk_stops_the_log_and_the_next_batch_reports_it() {
    // /dev/full accepts the open and refuses every write with ENOSPC: the first batch,
    // which writes its channel's schema, fails. Inline, that batch reports it; with a
    // writer thread, the next one, every time (no sleeping needed).
    let options = LogOptions {
        flush_interval: 0.1,
        ..LogOptions::default()
    };
    for (background, expected) in [(false, 0), (true, 1), (true, 1), (true, 1)] {
        let log = shared(Path::new("/dev/full"), background, options);
        let (k, warning) = first_warning(&log, (0..100).map(|k| ship_at(k as f64 * 0.1)));
        assert_eq!(k, expected, "background {background}");
        assert!(warning.contains("/dev/full"), "{warning}");
        assert!(!log.is_active());
        // The warning is given once; later batches are ignored.
        assert_eq!(log.batch(ship_at(100.0)), None);
        assert_eq!(log.settle(), None);
        let e = log.finish().unwrap_err();
        assert!(matches!(e, LogError::Stopped { .. }), "{e}");
        assert!(e.to_string().contains("/dev/full"), "{e}");
        // Reported once.
        assert!(!log.finish().unwrap());
    }
}

#[test]
fn settle_reports_a_failure_of_the_batches_before() {
    let log = shared(
        Path::new("/dev/full"),
        true,
        LogOptions {
            flush_interval: 0.1,
            ..LogOptions::default()
        },
    );
    assert_eq!(log.batch(ship_at(0.0)), None);
    let warning = log.settle().expect("the first batch failed");
    assert!(warning.contains("No space left"), "{warning}");
    assert_eq!(log.settle(), None);
}

#[test]
fn a_panicking_batch_stops_the_log_without_unwinding_into_the_caller() {
    let dir = tempfile::tempdir().unwrap();
    for (background, expected) in [(false, 1), (true, 2)] {
        let path = dir.path().join(format!("panic-{background}.mcap"));
        let log = shared(&path, background, LogOptions::default());
        let batches = (0..10).map(|k| match k {
            1 => Box::new(|_: &mut LogWriter| -> Result<(), LogError> {
                panic!("a bug in a message builder")
            }) as Batch,
            k => ship_at(f64::from(k)),
        });
        let (k, warning) = first_warning(&log, batches);
        assert_eq!(k, expected, "background {background}");
        assert!(warning.contains("a bug in a message builder"), "{warning}");
        assert!(log.finish().is_err());
        // The file was finished after the panic: its first message is readable.
        let bytes = std::fs::read(&path).unwrap();
        assert!(mcap::Summary::read(&bytes).unwrap().is_some());
    }
}

#[test]
fn run_metadata_and_the_scenario_attachment() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let mut w = LogWriter::create(&path, LogOptions::default()).unwrap();
    w.write_run(&towing_log::RunInfo {
        unit: "TowingPlant",
        guid: "{0000}",
        version: "0.1.0",
        scenario: "",
        scenario_name: "paper",
        run_id: "run 42",
        start_time: 0.0,
        parameters: serde_json::json!({"hull_model": 0, "scenario": ""}),
        scenario_text: "name = \"paper\"\n",
    })
    .unwrap();
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let run = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(run.name, "run");
    let m = &run.metadata;
    assert_eq!(m["unit"], "TowingPlant");
    assert_eq!(m["scenario"], topics::BUNDLED_SCENARIO_LABEL);
    assert_eq!(m["epoch"], "simulation time 0 s");
    assert_eq!(m["start_time"], "0");
    assert_eq!(m["run_id"], "run 42");
    let params: serde_json::Value = serde_json::from_str(&m["parameters"]).unwrap();
    assert_eq!(params["hull_model"], 0);
    for key in ["guid", "version", "scenario_name"] {
        assert!(m.contains_key(key), "{key}");
    }
    let att = mcap::read::attachment(&bytes, &summary.attachment_indexes[0]).unwrap();
    assert_eq!(&att.data[..], b"name = \"paper\"\n");
}

#[test]
fn every_contract_type_has_a_self_contained_object_schema() {
    fn check<M: TopicMessage>() {
        let data = towing_log::schema_json::<M>().unwrap();
        let json: serde_json::Value = serde_json::from_slice(&data).unwrap();
        assert_eq!(json["type"], "object", "{}", M::SCHEMA_NAME);
        assert!(json.get("$defs").is_none(), "{}", M::SCHEMA_NAME);
        assert!(json["properties"].is_object(), "{}", M::SCHEMA_NAME);
    }
    check::<VesselState>();
    check::<TowlineState>();
    check::<Obstacles>();
    check::<PlantInputs>();
    check::<Reference>();
    check::<Colregs>();
    check::<Command>();
    check::<Solver>();
    check::<Prediction>();
    check::<FrameTransforms>();
    check::<SceneUpdate>();
    check::<Log>();
    // Foxglove's field names.
    let data = towing_log::schema_json::<SceneUpdate>().unwrap();
    let json: serde_json::Value = serde_json::from_slice(&data).unwrap();
    let entity = &json["properties"]["entities"]["items"]["properties"];
    for field in [
        "timestamp",
        "frame_id",
        "id",
        "lifetime",
        "frame_locked",
        "metadata",
        "arrows",
        "cubes",
        "spheres",
        "cylinders",
        "lines",
        "triangles",
        "texts",
        "models",
    ] {
        assert!(entity.get(field).is_some(), "SceneEntity.{field}");
    }
    assert!(entity["lines"]["items"]["properties"].get("type").is_some());
    let t = &entity["timestamp"]["properties"];
    assert!(t.get("sec").is_some() && t.get("nsec").is_some());
}

#[test]
fn topic_tables_match_the_contract() {
    assert_eq!(topics::PLANT_TOPICS.len(), 11);
    assert_eq!(topics::CONTROLLER_TOPICS.len(), 7);
    assert!(topics::PLANT_TOPICS
        .iter()
        .chain(&topics::CONTROLLER_TOPICS)
        .all(
            |(t, s)| t.starts_with('/') && (s.starts_with("towing.") || s.starts_with("foxglove."))
        ));
    assert_eq!(topics::situation_name(2), "crossing give-way");
    assert_eq!(topics::role_name(2), "stand-on");
}

#[test]
fn a_run_id_is_written_in_the_run_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let mut w = LogWriter::create(&path, LogOptions::default()).unwrap();
    w.write_run(&towing_log::RunInfo {
        unit: "TowingController",
        run_id: "campaign-7/run-0042",
        ..towing_log::RunInfo::default()
    })
    .unwrap();
    w.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let run = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(
        run.metadata[topics::metadata_keys::RUN_ID],
        "campaign-7/run-0042"
    );
    let empty = dir.path().join("empty.mcap");
    let mut w = LogWriter::create(&empty, LogOptions::default()).unwrap();
    w.write_run(&towing_log::RunInfo::default()).unwrap();
    w.finish().unwrap();
    let bytes = std::fs::read(&empty).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let run = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert!(
        !run.metadata.contains_key("run_id"),
        "no run_id when none given"
    );
}

#[test]
fn a_solver_message_of_an_older_log_with_a_null_fallback_reads_as_empty() {
    let old = r#"{"t":1.0,"architecture":1,"scheme":1,"iterations":7,"converged":true,
        "r_pri":[0.001,0.002],"r_dual":[0.0005,0.0001],"compute_time_ms":4.5,"samples":2,
        "fallbacks":0,"fallback":null}"#;
    let m: Solver = serde_json::from_str(old).unwrap();
    assert_eq!(m.fallback, "");
    let fell = old.replace("null", "\"the ship QP failed\"");
    let m: Solver = serde_json::from_str(&fell).unwrap();
    assert_eq!(m.fallback, "the ship QP failed");
    // Written as a string, never null.
    let back = serde_json::to_value(Solver {
        fallback: String::new(),
        ..m
    })
    .unwrap();
    assert_eq!(back["fallback"], "");
}

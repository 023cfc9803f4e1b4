//! The streaming reader on synthetic MCAP files: written with the mcap crate and the
//! towing-log structs directly, and with towing_log::LogWriter; truncated at many byte
//! offsets; not MCAP; missing.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use analyzer::read::{read_log, Unit};
use analyzer::AnalyzerError;
use indicatif::ProgressBar;
use towing_log::topics::{names, Solver, VesselState};
use towing_log::TopicMessage;

fn hidden() -> ProgressBar {
    ProgressBar::hidden()
}

fn write_raw(path: &Path, steps: usize, chunked: bool) {
    let mut w = mcap::WriteOptions::new()
        .use_chunks(chunked)
        .create(std::io::BufWriter::new(
            std::fs::File::create(path).expect("file"),
        ))
        .expect("writer");
    let ids = vessel_channels(&mut w);
    let solver_schema = w
        .add_schema(Solver::SCHEMA_NAME, "jsonschema", b"{}")
        .expect("schema");
    let foreign = w
        .add_channel(solver_schema, "/something/else", "json", &BTreeMap::new())
        .expect("channel");
    for k in 0..u32::try_from(steps).expect("steps") {
        write_vessels(&mut w, &ids, k);
        w.write_to_known_channel(&header(foreign, k), b"{\"anything\": 1}")
            .expect("write");
    }
    w.finish().expect("finish");
}

/// The channels of the three vessels' `VesselState` topics.
fn vessel_channels<W: std::io::Write + std::io::Seek>(w: &mut mcap::Writer<W>) -> Vec<u16> {
    let schema = w
        .add_schema(VesselState::SCHEMA_NAME, "jsonschema", b"{}")
        .expect("schema");
    [names::PLANT_SHIP, names::PLANT_TUG1, names::PLANT_TUG2]
        .iter()
        .map(|topic| {
            w.add_channel(schema, topic, "json", &BTreeMap::new())
                .expect("channel")
        })
        .collect()
}

/// The header of message `k` (t = k * 0.1 s) on `channel_id`.
fn header(channel_id: u16, k: u32) -> mcap::records::MessageHeader {
    let ns = u64::from(k) * 100_000_000;
    mcap::records::MessageHeader {
        channel_id,
        sequence: k,
        log_time: ns,
        publish_time: ns,
    }
}

/// Step `k` of a straight run at 0.1 m/s on the three vessel channels `ids`.
fn write_vessels<W: std::io::Write + std::io::Seek>(w: &mut mcap::Writer<W>, ids: &[u16], k: u32) {
    let t = f64::from(k) * 0.1;
    for (j, &id) in ids.iter().enumerate() {
        let m = VesselState {
            t,
            x: 0.1 * t + j as f64,
            y: 0.0,
            psi: 0.0,
            u: 0.1,
            v: 0.0,
            r: 0.0,
        };
        w.write_to_known_channel(&header(id, k), &serde_json::to_vec(&m).expect("json"))
            .expect("write");
    }
}

#[test]
fn raw_mcap_with_the_contract_structs() {
    let dir = tempfile::tempdir().expect("tempdir");
    for chunked in [false, true] {
        let path = dir.path().join(format!("raw-{chunked}.mcap"));
        write_raw(&path, 500, chunked);
        let log = read_log(&path, &hidden()).expect("readable");
        assert_eq!(log.unit, Unit::Plant, "recognised by its topics");
        assert!(log.truncated.is_none());
        assert_eq!(log.plant.ship.t_ns.len(), 500);
        assert_eq!(log.plant.tug2.x[10], 0.1 * 1.0 + 2.0);
        assert_eq!(log.plant.ship.t_ns[499], 49_900_000_000);
        assert_eq!(log.message_counts["/something/else"], 500);
        assert!(log.metadata.is_empty() && log.scenario_text.is_none());
    }
}

#[test]
fn logwriter_logs_are_recognised_by_metadata() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = common::straight(10.0, 0.1, 300);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let p = read_log(&plant, &hidden()).expect("plant");
    let c = read_log(&controller, &hidden()).expect("controller");
    assert_eq!(p.unit, Unit::Plant);
    assert_eq!(c.unit, Unit::Controller);
    assert_eq!(p.metadata["unit"], "TowingPlant");
    assert_eq!(p.plant.ship.t_ns.len(), 301);
    assert_eq!(c.controller.solver.t_ns.len(), 31);
    assert!(p
        .scenario_text
        .as_deref()
        .is_some_and(|s| s.contains("straight")));
    // Any order: the run puts them together.
    let multi = analyzer::progress::multi(true);
    let r = analyzer::run::load_run(&[controller.clone(), plant.clone()], &multi).expect("run");
    assert_eq!(r.config.scenario_name, "straight");
    assert_eq!(r.config.architecture, Some(1));
    // Two plant logs: refused, naming both.
    let err = analyzer::run::load_run(&[plant.clone(), plant.clone()], &multi)
        .expect_err("two plant logs");
    assert!(matches!(err, AnalyzerError::DuplicateUnit { .. }));
    // A controller log alone: no plant log.
    let err = analyzer::run::load_run(&[controller], &multi).expect_err("no plant");
    assert!(err.to_string().contains("no plant log"), "{err}");
}

#[test]
fn truncated_at_many_offsets_never_panics() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 40 s of plant steps: the writer closes a chunk every 10 s of simulated time.
    let run = common::straight(10.0, 0.1, 400);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let full = std::fs::read(&plant).expect("read");
    let whole = read_log(&plant, &hidden()).expect("whole");
    let n_whole = whole.plant.ship.t_ns.len();
    let cut = dir.path().join("cut.mcap");
    let mut offsets: Vec<usize> = vec![1, 7, 8, 9, 20, 100, 500, 1000, 3000];
    offsets.extend((1..20).map(|k| full.len() * k / 20));
    offsets.extend([full.len() - 30, full.len() - 8, full.len() - 1]);
    let mut truncated_ok = 0;
    for &off in &offsets {
        std::fs::write(&cut, &full[..off]).expect("write");
        match read_log(&cut, &hidden()) {
            Ok(log) => {
                assert!(
                    log.truncated.is_some(),
                    "offset {off}: not marked truncated"
                );
                assert!(log.plant.ship.t_ns.len() <= n_whole);
                truncated_ok += 1;
                // The earliest readable cuts hold a few topics only (the ship's first
                // messages): the whole report must still come out.
                if truncated_ok <= 3 {
                    let out = dir.path().join(format!("report-{off}"));
                    let r = analyzer::report(&out, &[cut.clone(), controller.clone()], true);
                    match r {
                        Ok(o) => assert!(o.metrics.run.truncated, "offset {off}"),
                        Err(e) => assert!(e.to_string().contains("cut.mcap"), "offset {off}: {e}"),
                    }
                }
            }
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.contains("cut.mcap"), "offset {off}: {msg}");
                assert!(
                    matches!(
                        e,
                        AnalyzerError::NotMcap { .. }
                            | AnalyzerError::Unreadable { .. }
                            | AnalyzerError::NoExpectedTopics { .. }
                            | AnalyzerError::NoUsableData { .. }
                            | AnalyzerError::TruncatedEmpty { .. }
                    ),
                    "offset {off}: {e:?}"
                );
            }
        }
    }
    // Most cuts keep something; the later the cut, the more.
    assert!(truncated_ok >= 15, "{truncated_ok}");
    std::fs::write(&cut, &full[..full.len() * 3 / 4]).expect("write");
    let three_quarters = read_log(&cut, &hidden()).expect("3/4");
    assert!(three_quarters.plant.ship.t_ns.len() >= n_whole / 2);
}

#[test]
fn a_truncated_log_still_gives_a_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = common::straight(10.0, 0.1, 400);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let full = std::fs::read(&plant).expect("read");
    std::fs::write(&plant, &full[..full.len() * 2 / 3]).expect("cut");
    let out = dir.path().join("report");
    let outcome = analyzer::report(&out, &[plant, controller], true).expect("report");
    assert!(outcome.metrics.run.truncated);
    assert_eq!(outcome.metrics.run.truncated_files.len(), 1);
    assert!(outcome.metrics.run.truncated_files[0]
        .file
        .ends_with("plant.mcap"));
    let json = std::fs::read_to_string(out.join("metrics.json")).expect("metrics");
    assert!(json.contains("\"truncated\": true"));
    let md = std::fs::read_to_string(out.join("report.md")).expect("md");
    assert!(md.contains("WARNING") && md.contains("truncated"));
}

#[test]
fn not_mcap_and_missing_files_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = dir.path().join("notes.txt");
    std::fs::write(&text, "this is not an MCAP file at all, just text\n").expect("write");
    let e = read_log(&text, &hidden()).expect_err("not mcap");
    assert!(matches!(e, AnalyzerError::NotMcap { .. }), "{e:?}");
    assert!(e.to_string().contains("notes.txt") && e.to_string().contains("not an MCAP"));

    let empty = dir.path().join("empty.mcap");
    std::fs::write(&empty, b"").expect("write");
    let e = read_log(&empty, &hidden()).expect_err("empty");
    assert!(e.to_string().contains("empty.mcap"), "{e}");

    let missing = dir.path().join("nowhere.mcap");
    let e = read_log(&missing, &hidden()).expect_err("missing");
    assert!(matches!(e, AnalyzerError::Io { .. }));
    assert!(e.to_string().contains("nowhere.mcap"), "{e}");
}

#[test]
fn an_mcap_without_the_topics_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("other.mcap");
    let mut w = mcap::WriteOptions::new()
        .create(std::io::BufWriter::new(
            std::fs::File::create(&path).expect("file"),
        ))
        .expect("writer");
    let s = w.add_schema("x", "jsonschema", b"{}").expect("schema");
    let c = w
        .add_channel(s, "/camera/image", "json", &BTreeMap::new())
        .expect("channel");
    w.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id: c,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        },
        b"{}",
    )
    .expect("write");
    w.finish().expect("finish");
    drop(w);
    let e = read_log(&path, &hidden()).expect_err("no topics");
    assert!(matches!(e, AnalyzerError::NoExpectedTopics { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("other.mcap") && msg.contains("/camera/image"),
        "{msg}"
    );
}

#[test]
fn messages_that_do_not_match_the_contract_are_counted() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("bad.mcap");
    let mut w = mcap::WriteOptions::new()
        .create(std::io::BufWriter::new(
            std::fs::File::create(&path).expect("file"),
        ))
        .expect("writer");
    let s = w
        .add_schema(VesselState::SCHEMA_NAME, "jsonschema", b"{}")
        .expect("schema");
    let c = w
        .add_channel(s, names::PLANT_SHIP, "json", &BTreeMap::new())
        .expect("channel");
    for k in 0..3u32 {
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: c,
                sequence: k,
                log_time: u64::from(k),
                publish_time: u64::from(k),
            },
            b"{\"t\": 0.0, \"x\": 1.0}",
        )
        .expect("write");
    }
    w.finish().expect("finish");
    drop(w);
    let e = read_log(&path, &hidden()).expect_err("nothing usable");
    let msg = e.to_string();
    assert!(
        msg.contains("bad.mcap") && msg.contains("/plant/ship") && msg.contains("missing field"),
        "{msg}"
    );
}

#[test]
fn a_controller_log_cut_before_its_first_message_is_left_out() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = common::straight(10.0, 0.1, 300);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let full = std::fs::read(&controller).expect("read");
    // The header, metadata and attachment survive; no channel or message does.
    std::fs::write(&controller, &full[..600]).expect("cut");
    let e = read_log(&controller, &hidden()).expect_err("nothing usable");
    assert!(matches!(e, AnalyzerError::TruncatedEmpty { .. }), "{e:?}");
    assert!(e.to_string().contains("controller.mcap"));
    let out = dir.path().join("r");
    let o = analyzer::report(&out, &[plant.clone(), controller.clone()], true).expect("report");
    assert!(o.metrics.run.truncated);
    assert!(o.metrics.run.architecture.is_none());
    assert!(o.metrics.run.notes.iter().any(|n| n.contains("left out")));
    // Alone it is nothing useful: an error naming it.
    let e = analyzer::report(&out, &[controller], true).expect_err("nothing");
    assert!(e.to_string().contains("controller.mcap"), "{e}");
}

/// A merged log (plant and controller topics in one file, not written by `LogWriter`)
/// whose controller channel and scenario attachment come only after the first plant
/// message: the first records say "plant", the stream finds the rest, and the file is read
/// again whole (once) so nothing is lost.
#[test]
fn a_merged_log_with_late_controller_topics_and_scenario_is_read_whole() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("merged.mcap");
    let scenario = common::straight(10.0, 0.1, 100).scenario_toml();
    let mut w = mcap::WriteOptions::new()
        .create(std::io::BufWriter::new(
            std::fs::File::create(&path).expect("file"),
        ))
        .expect("writer");
    let ids = vessel_channels(&mut w);
    let mut solver = None;
    for k in 0..300u32 {
        let t = f64::from(k) * 0.1;
        let ns = u64::from(k) * 100_000_000;
        write_vessels(&mut w, &ids, k);
        if k == 5 {
            w.attach(&mcap::Attachment {
                log_time: ns,
                create_time: ns,
                name: "scenario.toml".to_owned(),
                media_type: "application/toml".to_owned(),
                data: std::borrow::Cow::Borrowed(scenario.as_bytes()),
            })
            .expect("attach");
            let s = w
                .add_schema(Solver::SCHEMA_NAME, "jsonschema", b"{}")
                .expect("schema");
            solver = Some(
                w.add_channel(s, names::CONTROLLER_SOLVER, "json", &BTreeMap::new())
                    .expect("channel"),
            );
        }
        if let (Some(id), true) = (solver, k % 10 == 0) {
            let m = Solver {
                t,
                architecture: 2,
                scheme: 3,
                iterations: 7,
                converged: true,
                r_pri: [1e-3; 2],
                r_dual: [1e-3; 2],
                compute_time_ms: 4.0,
                samples: u64::from(k / 10 + 1),
                fallbacks: 0,
                fallback: String::new(),
            };
            w.write_to_known_channel(&header(id, k), &serde_json::to_vec(&m).expect("json"))
                .expect("write");
        }
    }
    w.finish().expect("finish");
    drop(w);
    let peek = analyzer::read::peek_log(&path).expect("peek");
    assert_eq!(peek.unit, Some(Unit::Plant), "the first records say plant");
    assert!(peek.scenario_text.is_none());
    let out = dir.path().join("r");
    let o = analyzer::report(&out, &[path], true).expect("report");
    let m = &o.metrics;
    assert_eq!(m.run.plant_steps, 300);
    assert_eq!(m.run.control_samples, 29, "samples from k = 10 on");
    assert_eq!(m.run.architecture.as_ref().map(|a| a.code), Some(2));
    assert_eq!(m.run.scenario, "straight", "the late attachment is used");
    assert_eq!(m.files.len(), 1);
    assert_eq!(m.files[0].unit, "plant and controller");
    assert_eq!(m.files[0].messages["/plant/ship"], 300);
    // Every table exactly once: nothing left from the abandoned first pass.
    let ts = std::fs::read_to_string(out.join("timeseries.csv")).expect("csv");
    assert_eq!(ts.lines().count(), 301);
}

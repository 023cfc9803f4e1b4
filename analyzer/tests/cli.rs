//! The `analyzer` binary end to end on synthetic logs.

mod common;

use std::process::Command;

use analyzer::synth::SynthRun;

fn analyzer() -> Command {
    Command::new(env!("CARGO_BIN_EXE_analyzer"))
}

const REPORT_FILES: [&str; 29] = [
    "metrics.json",
    "report.md",
    "report.html",
    "timeseries.csv",
    "timeseries.parquet",
    "controller.csv",
    "controller.parquet",
    "obstacles.csv",
    "obstacles.parquet",
    "colregs.csv",
    "colregs.parquet",
    "encounters.csv",
    "encounters.parquet",
    "min_distances.csv",
    "min_distances.parquet",
    "map.png",
    "map.svg",
    "states.png",
    "states.svg",
    "towing.png",
    "towing.svg",
    "rates.png",
    "rates.svg",
    "distances.png",
    "distances.svg",
    "admm.png",
    "admm.svg",
    "compute_time.png",
    "compute_time.svg",
];

#[test]
fn report_writes_every_file_and_compare_lays_out_the_tables() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut run = SynthRun::paper(3500);
    run.speed = 0.2; // arrives at 317 s
                     // B and C appear where they would for the paper's slower tow (times x 0.06 / 0.2).
    run.obstacles[4].active_from = 405.0 * 0.3;
    run.obstacles[5].active_from = 590.0 * 0.3;
    let (plant, controller) = common::write_logs(&run, dir.path());
    let out = dir.path().join("report");
    let o = analyzer()
        .args(["report", "--quiet", "--out"])
        .arg(&out)
        .arg(&controller)
        .arg(&plant)
        .output()
        .expect("run analyzer");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("report written"), "{stdout}");
    assert!(
        o.stderr.is_empty(),
        "quiet: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    for f in REPORT_FILES {
        let p = out.join(f);
        let len = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{f} missing or empty");
    }
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).expect("read"))
            .expect("json");
    let expected = run.expected_settling_time().expect("arrives");
    let ts = m["settling_time_s"].as_f64().expect("settled");
    assert!((ts - expected).abs() < 1e-6, "{ts} vs {expected}");
    assert_eq!(m["architecture"]["name"], "distributed");
    assert_eq!(m["scheme"]["name"], "I");
    assert_eq!(m["truncated"], false);
    for key in [
        "max_towline_elongation_error",
        "normalized_min_distance",
        "collisions",
        "ship_travel_m",
        "colregs",
        "bound_violations",
        "sample_time_ms",
        "admm_iterations",
        "fallbacks",
    ] {
        assert!(m.get(key).is_some(), "metrics.json lacks {key}");
    }
    assert_eq!(m["colregs"].as_array().map(Vec::len), Some(3));
    let html = std::fs::read_to_string(out.join("report.html")).expect("html");
    assert!(
        html.contains("<svg") && !html.contains("src=\"map.png\""),
        "figures inline"
    );
    assert!(html.contains("Table 6 layout") && html.contains("Table 7 layout"));
    let md = std::fs::read_to_string(out.join("report.md")).expect("md");
    assert!(md.contains("![") && md.contains("map.png"));
    let enc = std::fs::read_to_string(out.join("encounters.csv")).expect("csv");
    assert_eq!(enc.lines().count(), 4, "header and three targets");

    // A second run, centralized scheme I, and the comparison.
    let dir2 = dir.path().join("central");
    std::fs::create_dir_all(&dir2).expect("dir");
    run.architecture = 2;
    let (p2, c2) = common::write_logs(&run, &dir2);
    let out2 = dir.path().join("report2");
    let o = analyzer()
        .args(["report", "-q", "--out"])
        .arg(&out2)
        .arg(&p2)
        .arg(&c2)
        .output()
        .expect("run");
    assert!(o.status.success());
    let cmp = dir.path().join("cmp");
    let o = analyzer()
        .args(["compare", "--out"])
        .arg(&cmp)
        .arg(&out2)
        .arg(&out)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["compare.md", "compare.html", "compare.json"] {
        assert!(cmp.join(f).is_file(), "{f}");
    }
    let md = std::fs::read_to_string(cmp.join("compare.md")).expect("md");
    assert!(md.contains("968"), "paper's settling time beside ours");
    assert!(md.contains("985"));
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cmp.join("compare.json")).expect("json"))
            .expect("json");
    let rows = rows.as_array().expect("array");
    assert_eq!(rows.len(), 2);
    // Distributed first; its paper settling time is Table 7's 968 s.
    assert_eq!(rows[0]["architecture"], 1);
    assert_eq!(rows[0]["paper_settling_time_s"], 968.0);
    assert_eq!(rows[1]["paper_settling_time_s"], 985.0);
    let d = rows[0]["settling_time_difference_s"]
        .as_f64()
        .expect("diff");
    assert!((d - (expected - 968.0)).abs() < 1e-6);
    assert!((rows[0]["paper_d"][0][0].as_f64().expect("D") - 2.45).abs() < 1e-12);
}

#[test]
fn bad_inputs_fail_with_one_clear_message() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = dir.path().join("readme.txt");
    std::fs::write(&text, "hello").expect("write");
    let o = analyzer()
        .args(["report", "--out"])
        .arg(dir.path().join("o"))
        .arg(&text)
        .output()
        .expect("run");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("readme.txt") && err.contains("not an MCAP"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"));

    let o = analyzer()
        .args(["report", "--out"])
        .arg(dir.path().join("o"))
        .arg(dir.path().join("missing.mcap"))
        .output()
        .expect("run");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("missing.mcap"), "{err}");

    let o = analyzer()
        .args(["compare", "--out"])
        .arg(dir.path().join("c"))
        .arg(dir.path())
        .output()
        .expect("run");
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("metrics.json"));
}

#[test]
fn a_truncated_log_is_reported_and_marked() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = common::straight(20.0, 0.1, 600);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let full = std::fs::read(&plant).expect("read");
    std::fs::write(&plant, &full[..full.len() / 2]).expect("cut");
    let out = dir.path().join("r");
    let o = analyzer()
        .args(["report", "--out"])
        .arg(&out)
        .arg(&plant)
        .arg(&controller)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("plant.mcap") && err.contains("truncated"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("TRUNCATED"));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).expect("read"))
            .expect("json");
    assert_eq!(m["truncated"], true);
    // A truncated log fails the verdict, naming the file.
    assert_eq!(m["verdict"]["passed"], false);
    let r = &m["verdict"]["reasons"][0];
    assert_eq!(r["metric"], "truncated");
    assert!(
        r["message"]
            .as_str()
            .is_some_and(|t| t.contains("plant.mcap")),
        "{r}"
    );
}

#[test]
fn thresholds_file_is_recorded_and_a_bad_one_is_refused_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 250 s at 0.1 m/s along a 20 m route: arrives (within 2 m of the destination at
    // 180 s), so the run passes every verdict.
    let run = common::straight(20.0, 0.1, 2500);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let file = dir.path().join("t.toml");
    std::fs::write(&file, "drift_max_deg = 20.0\nstall_max_s = 60.0\n").expect("write");
    let out = dir.path().join("r");
    let o = analyzer()
        .args(["report", "-q", "--thresholds"])
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .arg(&plant)
        .arg(&controller)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("verdict: passed"), "{stdout}");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).expect("read"))
            .expect("json");
    assert_eq!(m["thresholds"]["drift_max_deg"], 20.0);
    assert_eq!(m["thresholds"]["stall_max_s"], 60.0);
    assert_eq!(
        m["thresholds"]["cross_ahead_min_m"], 7.0,
        "the rest are defaults"
    );
    assert_eq!(m["verdict"]["passed"], true);
    assert_eq!(m["verdict"]["reasons"].as_array().map(Vec::len), Some(0));

    std::fs::write(&file, "drift_max = 20.0\n").expect("write");
    let o = analyzer()
        .args(["report", "-q", "--thresholds"])
        .arg(&file)
        .arg("--out")
        .arg(dir.path().join("bad"))
        .arg(&plant)
        .output()
        .expect("run");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("t.toml") && err.contains("drift_max"), "{err}");
    assert!(err.starts_with("analyzer report: thresholds "), "{err}");
}

#[test]
fn a_closed_stdout_is_not_a_panic() {
    // `analyzer report ... | head -1` closed the pipe before the summary lines: they
    // panicked ("failed printing to stdout: Broken pipe") after the report was written.
    let dir = tempfile::tempdir().expect("tempdir");
    let run = common::straight(10.0, 0.1, 100);
    let (plant, controller) = common::write_logs(&run, dir.path());
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let out = dir.path().join("report");
    let o = analyzer()
        .args(["report", "--quiet", "--out"])
        .arg(&out)
        .arg(&plant)
        .arg(&controller)
        .stdout(writer)
        .output()
        .expect("run");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("internal error"),
        "{err}"
    );
    assert!(o.status.success(), "{err}");
    assert!(out.join("metrics.json").exists());
}

//! The fuzzers, bounded: a few thousand executions of each target through the whole
//! harness (children, batches) find nothing; the planted target shows that the harness
//! counts every execution once and catches panics, aborts and hangs with their inputs.

use std::path::Path;
use std::process::{Command, Output};

fn fuzz(bin: &str, out: &Path, args: &str) -> (Output, String) {
    let o = Command::new(bin)
        .args(args.split_whitespace())
        .arg("--out")
        .arg(out)
        .output()
        .expect("run the fuzzer");
    let stdout = String::from_utf8_lossy(&o.stdout).trim().to_owned();
    (o, stdout)
}

#[test]
fn the_scenario_loader_survives_five_thousand_mutated_scenarios() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (o, summary) = fuzz(
        env!("CARGO_BIN_EXE_fuzz-scenario"),
        dir.path(),
        "--iterations 5000 --seed 1 --batch 2500",
    );
    assert!(
        summary.starts_with("fuzz-scenario: 5000 executions, 0 panics, 0 aborts, 0 hangs"),
        "{summary}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success());
}

#[test]
fn the_mcap_reader_survives_three_thousand_mutated_logs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (o, summary) = fuzz(
        env!("CARGO_BIN_EXE_fuzz-mcap"),
        dir.path(),
        "--iterations 3000 --seed 1 --batch 1500",
    );
    assert!(
        summary.starts_with("fuzz-mcap: 3000 executions, 0 panics, 0 aborts, 0 hangs"),
        "{summary}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success());
}

#[test]
fn the_harness_catches_planted_panics_aborts_and_hangs_and_keeps_their_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (o, summary) = fuzz(
        env!("CARGO_BIN_EXE_fuzz-selftest"),
        dir.path(),
        "--iterations 40 --seed 2 --batch 10 --hang-secs 1",
    );
    // Deterministic for the seed: 40 executions, each counted once.
    assert!(
        summary.starts_with("fuzz-selftest: 40 executions, 1 panics, 2 aborts, 4 hangs"),
        "{summary}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(o.status.code(), Some(1), "findings: exit status 1");
    let mut kept: Vec<String> = std::fs::read_dir(dir.path())
        .expect("out")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".bin"))
        .collect();
    kept.sort();
    assert_eq!(kept.len(), 7, "{kept:?}");
    for name in &kept {
        let input = std::fs::read(dir.path().join(name)).expect("input");
        let word: &[u8] = if name.contains("-panic-") {
            b"PANIC"
        } else if name.contains("-abort-") {
            b"ABORT"
        } else {
            b"HANG"
        };
        assert!(
            input.windows(word.len()).any(|w| w == word),
            "{name}: {:?}",
            String::from_utf8_lossy(&input)
        );
        let note =
            std::fs::read_to_string(dir.path().join(name.replace(".bin", ".txt"))).expect("note");
        assert!(note.contains("replay: fuzz-selftest --replay"), "{note}");
    }
}

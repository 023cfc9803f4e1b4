//! Bad input never aborts, panics or hangs the analyzer (docs/analyzer.md, "Reading and
//! tables" and the plots): every case gives a report or one line naming the file and the
//! reason, within a time limit. Named after what broke: one flipped bit in a record length
//! aborted the reader (`memory allocation of ... bytes failed`), the MCAP magic followed
//! by random bytes panicked it (`capacity overflow`, `range start index 9 out of range`),
//! and a tow at 1.8e308 m (a towline of `desired_length = 1.7976931348623157e308`) hung
//! the map plot.

mod common;

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use analyzer::progress;
use analyzer::read::{peek_log_bytes, read_log_bytes};
use analyzer::run::load_run;
use analyzer::stream::StreamOptions;
use analyzer::thresholds::Thresholds;

/// Far beyond any case's time on a loaded machine: only a hang reaches it.
const LIMIT: Duration = Duration::from_secs(120);

/// `f` on a thread of its own; its result, or a failure naming `what` when it panics or
/// does not answer within [`LIMIT`] (a hang: the thread is left behind).
fn within<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(LIMIT) {
        Ok(v) => v,
        Err(RecvTimeoutError::Timeout) => panic!("{what}: no answer within {LIMIT:?} (a hang)"),
        Err(RecvTimeoutError::Disconnected) => panic!("{what}: panicked"),
    }
}

/// The analysis of a run (no files written): `Ok` or the error's text.
fn analyse(logs: &[PathBuf]) -> Result<(), String> {
    let multi = progress::multi(true);
    let run = load_run(logs, &multi).map_err(|e| e.to_string())?;
    analyzer::analysis::analyze_run(
        run,
        None,
        &multi,
        &StreamOptions::default(),
        &Thresholds::default(),
    )
    .map(|_| ())
    .map_err(|e| e.to_string())
}

/// The whole report into `out`: `Ok` or the error's text.
fn report(out: &Path, logs: &[PathBuf]) -> Result<(), String> {
    analyzer::report::report(out, logs, true)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// A clean error: one line naming the file.
fn assert_clean(case: &str, err: &str, file: &str) {
    assert!(!err.contains('\n'), "{case}: more than one line: {err}");
    assert!(err.contains(file), "{case}: does not name {file}: {err}");
}

/// Offsets of the length fields of the top-level records (opcode, u64 length, body) of an
/// MCAP file: where a flipped bit once made the reader allocate exabytes.
fn record_length_fields(bytes: &[u8]) -> Vec<usize> {
    let mut at = 8;
    let mut fields = Vec::new();
    while at + 9 <= bytes.len() {
        fields.push(at + 1);
        let mut len = [0u8; 8];
        len.copy_from_slice(&bytes[at + 1..at + 9]);
        let Some(next) = usize::try_from(u64::from_le_bytes(len))
            .ok()
            .and_then(|l| (at + 9).checked_add(l))
        else {
            break;
        };
        at = next;
    }
    fields
}

/// The bits flipped in `bytes`: bits low and high in every top-level record's length, and
/// `spread` bits spread over the whole file (one at a varying place in each stretch).
fn bits_to_flip(bytes: &[u8], spread: usize) -> Vec<usize> {
    let mut bits = Vec::new();
    for field in record_length_fields(bytes) {
        for bit in [0, 3, 9, 17, 26, 34, 45, 56, 62, 63] {
            bits.push(field * 8 + bit);
        }
    }
    let total = bytes.len() * 8;
    let stretch = (total / spread).max(1);
    for k in 0..spread {
        bits.push((k * stretch + (k * 7919) % stretch) % total);
    }
    bits
}

/// Every bit of `bits_to_flip` flipped in turn in one log of the real 3 s run (`which`:
/// `plant` or `controller`), the other log intact; every 40th case through the whole
/// report, plots included.
fn flip_sweep(which: &str, spread: usize) -> usize {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/real-3s");
    let original = std::fs::read(data.join(format!("{which}.mcap"))).expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let flipped = dir.path().join(format!("flipped-{which}.mcap"));
    let other = data.join(if which == "plant" {
        "controller.mcap"
    } else {
        "plant.mcap"
    });
    let bits = bits_to_flip(&original, spread);
    let mut reports = 0;
    for (k, &bit) in bits.iter().enumerate() {
        let mut bytes = original.clone();
        bytes[bit / 8] ^= 1 << (bit % 8);
        std::fs::write(&flipped, &bytes).expect("write");
        let logs = vec![flipped.clone(), other.clone()];
        let case = format!("{which}.mcap, bit {bit} flipped");
        let out = dir.path().join("report");
        let full = k % 40 == 0;
        let result = within(&case, move || {
            if full {
                report(&out, &logs)
            } else {
                analyse(&logs)
            }
        });
        match result {
            Ok(()) => reports += 1,
            Err(e) => assert_clean(&case, &e, "flipped-"),
        }
    }
    assert!(bits.len() > 500, "{} cases", bits.len());
    reports
}

#[test]
fn a_flipped_bit_in_the_plant_log_gives_a_report_or_a_clean_error() {
    let reports = flip_sweep("plant", 600);
    // Most flips land in message data: still a report (decode errors counted, or marked
    // truncated).
    assert!(reports > 0, "not one report");
}

#[test]
fn a_flipped_bit_in_the_controller_log_gives_a_report_or_a_clean_error() {
    let reports = flip_sweep("controller", 600);
    assert!(reports > 0, "not one report");
}

#[test]
fn a_string_length_of_2e9_in_the_run_metadata_is_a_clean_error() {
    // Found by fuzz-mcap: mcap's record parser sized a buffer by a string's length prefix
    // (4 GB here), an abort under a memory limit.
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/real-3s");
    let mut bytes = std::fs::read(data.join("plant.mcap")).expect("fixture");
    let metadata = record_length_fields(&bytes)
        .into_iter()
        .find(|&field| bytes[field - 1] == 0x0c)
        .expect("a top-level Metadata record");
    // The name's length: 3 (`run`) with its top bit set.
    let name_len = metadata + 8;
    assert_eq!(bytes[name_len..name_len + 4], [3, 0, 0, 0]);
    bytes[name_len + 3] ^= 0x80;
    let name = Path::new("metadata.mcap");
    let e = within("a corrupt metadata string", move || {
        read_log_bytes(name, &bytes)
            .map(|_| ())
            .map_err(|e| e.to_string())
    })
    .expect_err("no message before it");
    assert_clean("corrupt metadata", &e, "metadata.mcap");
    assert!(
        e.contains("a record (opcode 0x0c) is corrupt: its name claims 2147483651 bytes"),
        "{e}"
    );
}

#[test]
fn the_mcap_magic_followed_by_random_bytes_is_a_clean_error() {
    const MAGIC: &[u8] = b"\x89MCAP0\r\n";
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        // xorshift64*
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        state.wrapping_mul(0x2545_f491_4f6c_dd1d)
    };
    let name = Path::new("random.mcap");
    for case in 0..3000 {
        let len = usize::try_from(next() % 1200).unwrap_or(0);
        let mut bytes = MAGIC.to_vec();
        bytes.extend((0..len).map(|_| next().to_le_bytes()[3]));
        // Sometimes a plausible record head: a known opcode.
        if len > 0 && case % 3 == 0 {
            bytes[8] = [0x01, 0x02, 0x03, 0x05, 0x06, 0x08, 0x0c][case % 7];
        }
        let what = format!("magic + {len} random bytes (case {case})");
        let (read, peek) = within(&what, move || {
            let read = read_log_bytes(name, &bytes)
                .map(|_| ())
                .map_err(|e| e.to_string());
            let peek = peek_log_bytes(name, &bytes)
                .map(|_| ())
                .map_err(|e| e.to_string());
            (read, peek)
        });
        match read {
            Ok(()) => panic!("{what}: read as a log"),
            Err(e) => assert_clean(&what, &e, "random.mcap"),
        }
        if let Err(e) = peek {
            assert_clean(&what, &e, "random.mcap");
        }
    }
}

#[test]
fn a_tow_at_1e308_m_gives_a_clipped_map_not_a_hang() {
    // The plant accepted a towline of desired_length = 1.7976931348623157e308 (the tugs
    // in formation about that far from the ship, one aft and one ahead: x of 1.8e308 m of
    // both signs, an axis that spans more than f64::MAX); it refuses lengths beyond 1e8 m
    // now, but a runaway tug still logs positions beyond 1e154 m before its step is
    // discarded. Here the towlines stretch to about 1.7e308 m (an elongation amplitude of
    // f64::MAX on lines of 1 m).
    let dir = tempfile::tempdir().expect("tempdir");
    let mut run = common::straight(20.0, 0.1, 200);
    run.towline_length = [1.0, 1.0];
    run.elongation = [f64::MAX, f64::MAX];
    run.scene = true;
    let (plant, controller) = common::write_logs(&run, dir.path());
    let out = dir.path().join("report");
    let logs = vec![plant, controller];
    let written = out.clone();
    within("report of a tow at 1.8e308 m", move || {
        report(&written, &logs)
    })
    .expect("a report");
    let map = image::open(out.join("map.png")).expect("map.png decodes");
    assert!(map.width() > 100 && map.height() > 100);
    let states = image::open(out.join("states.png")).expect("states.png decodes");
    assert!(states.width() > 100);
    let svg = std::fs::read_to_string(out.join("map.svg")).expect("map.svg");
    // The map holds the ship and the route; no coordinate is astronomical.
    assert!(svg.contains("ship"), "no ship in the legend");
    assert!(
        !svg.contains("e308") && !svg.contains("inf"),
        "unclipped coordinates"
    );
}

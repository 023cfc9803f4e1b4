//! The targets and their seed corpora (from this repository).

use std::borrow::Cow;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use mcap::records::Record;

use crate::driver::Target;

/// The repository's root (this crate is `crates/fuzz`).
#[must_use]
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("seed {}: {e}", path.display()))
}

/// The scenario loader: `Scenario::from_toml_str` on the input as text (invalid UTF-8
/// replaced), and for a scenario it accepts, the world the plant builds from it
/// (`World::new` with the scenario's configuration). Seeds: every `*.toml` under
/// `scenarios/`.
#[derive(Debug, Clone, Copy, Default)]
pub struct ScenarioLoader;

impl Target for ScenarioLoader {
    fn name(&self) -> &'static str {
        "scenario"
    }

    fn corpus(&self) -> Result<Vec<Vec<u8>>, String> {
        let mut files = Vec::new();
        collect_toml(&repo_root().join("scenarios"), &mut files)?;
        files.sort();
        files.iter().map(|p| read(p)).collect()
    }

    fn run(&self, input: &[u8]) {
        let text = String::from_utf8_lossy(input);
        if let Ok(scenario) = towing_model::Scenario::from_toml_str(&text, "fuzz input") {
            let _ = towing_model::World::new(&scenario, scenario.world_config);
        }
    }
}

/// Every `*.toml` below `dir`.
fn collect_toml(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for entry in entries {
        let path = entry.map_err(|e| format!("{}: {e}", dir.display()))?.path();
        if path.is_dir() {
            collect_toml(&path, out)?;
        } else if path.extension().is_some_and(|e| e == "toml") {
            out.push(path);
        }
    }
    Ok(())
}

/// The analyzer's MCAP reader: `read_log_bytes` and `peek_log_bytes` on the input. Seeds:
/// the real 3 s logs of `analyzer/tests/data` (zstd chunks, as the FMUs write them), and
/// the plant and controller log of the Gauss-Seidel run written again without compression,
/// chunked and unchunked, so mutations reach the records and the JSON inside.
#[derive(Debug, Clone, Copy, Default)]
pub struct McapReader;

impl Target for McapReader {
    fn name(&self) -> &'static str {
        "mcap"
    }

    fn corpus(&self) -> Result<Vec<Vec<u8>>, String> {
        let data = repo_root().join("analyzer/tests/data");
        let mut corpus = Vec::new();
        for run in ["real-3s", "real-3s-jacobi"] {
            for log in ["plant.mcap", "controller.mcap"] {
                corpus.push(read(&data.join(run).join(log))?);
            }
        }
        for k in 0..2 {
            for chunked in [true, false] {
                let again = uncompressed(&corpus[k], chunked)
                    .map_err(|e| format!("seed {k} written again: {e}"))?;
                corpus.push(again);
            }
        }
        Ok(corpus)
    }

    fn run(&self, input: &[u8]) {
        let name = Path::new("fuzz.mcap");
        let _ = analyzer::read::read_log_bytes(name, input);
        let _ = analyzer::read::peek_log_bytes(name, input);
    }
}

/// `log` written again record by record (schemas, channels, messages, metadata,
/// attachments, in file order) without compression, in chunks or not.
///
/// # Errors
/// The mcap crate's, on a log that does not read or write.
pub fn uncompressed(log: &[u8], chunked: bool) -> Result<Vec<u8>, mcap::McapError> {
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .use_chunks(chunked)
        .create(Cursor::new(Vec::new()))?;
    for record in mcap::read::ChunkFlattener::new(log)? {
        match record? {
            Record::Schema { header, data } => {
                w.add_schema_with_id(header.id, &header.name, &header.encoding, &data)?;
            }
            Record::Channel(c) => {
                w.add_channel_with_id(
                    c.id,
                    c.schema_id,
                    &c.topic,
                    &c.message_encoding,
                    &c.metadata,
                )?;
            }
            Record::Message { header, data } => w.write_to_known_channel(&header, &data)?,
            Record::Metadata(m) => w.write_metadata(&m)?,
            Record::Attachment { header, data, .. } => w.attach(&mcap::Attachment {
                log_time: header.log_time,
                create_time: header.create_time,
                name: header.name,
                media_type: header.media_type,
                data: Cow::Borrowed(&data),
            })?,
            _ => {}
        }
    }
    w.finish()?;
    Ok(w.into_inner().into_inner())
}

/// A planted target that checks the harness: an input holding `PANIC` panics, `ABORT`
/// aborts the process, `HANG` never returns; anything else passes. Seeds: one of each and
/// a calm one.
#[derive(Debug, Clone, Copy, Default)]
pub struct Planted;

impl Target for Planted {
    fn name(&self) -> &'static str {
        "selftest"
    }

    fn corpus(&self) -> Result<Vec<Vec<u8>>, String> {
        Ok(["calm 1.5", "PANIC 2.5", "ABORT 3.5", "HANG 4.5"]
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect())
    }

    fn run(&self, input: &[u8]) {
        let has = |word: &[u8]| input.windows(word.len()).any(|w| w == word);
        if has(b"PANIC") {
            panic!("planted panic");
        }
        if has(b"ABORT") {
            std::process::abort();
        }
        if has(b"HANG") {
            loop {
                std::thread::sleep(std::time::Duration::from_secs(3600));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_corpora_load_and_the_rewritten_logs_read_as_the_originals() {
        let scenarios = ScenarioLoader.corpus().expect("scenarios");
        assert!(scenarios.len() >= 30, "{} scenario seeds", scenarios.len());
        let logs = McapReader.corpus().expect("logs");
        assert_eq!(logs.len(), 8);
        let name = Path::new("seed.mcap");
        let original = analyzer::read::read_log_bytes(name, &logs[0]).expect("original");
        for again in &logs[4..6] {
            let log = analyzer::read::read_log_bytes(name, again).expect("rewritten");
            assert_eq!(log.message_counts, original.message_counts);
            assert_eq!(log.metadata, original.metadata);
            assert_eq!(log.scenario_text, original.scenario_text);
            assert_eq!(log.truncated, None);
        }
    }
}

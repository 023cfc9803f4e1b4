//! Errors of the analyzer: every one names the file (or directory) and the problem.

use std::path::PathBuf;

/// Everything that can stop a report or a comparison.
///
/// A truncated log is not an error: what was read is reported and marked truncated
/// ([`crate::read::LogFile::truncated`]).
#[derive(Debug, thiserror::Error)]
pub enum AnalyzerError {
    /// The file cannot be opened or read (missing, no permission, ...).
    #[error("{path}: cannot read: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is empty.
    #[error("{path}: empty file, not an MCAP log")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The file does not start with the MCAP magic.
    #[error("{path}: not an MCAP file (no MCAP magic at the start)")]
    NotMcap {
        /// The file.
        path: PathBuf,
    },
    /// The MCAP file is broken before any message could be read.
    #[error("{path}: unreadable MCAP log: {reason}")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// What the MCAP reader said.
        reason: String,
    },
    /// A readable MCAP file without the topics of docs/logging.md.
    #[error(
        "{path}: not a towing plant or controller log: none of the expected topics \
         (/plant/ship, /controller/solver, ...){found}"
    )]
    NoExpectedTopics {
        /// The file.
        path: PathBuf,
        /// `"; found: a, b"` or `"; no channels at all"`.
        found: String,
    },
    /// The expected topics are there but not one message could be used.
    #[error("{path}: no usable message: {reason}")]
    NoUsableData {
        /// The file.
        path: PathBuf,
        /// Why (truncated before the first message, every message failed to decode, ...).
        reason: String,
    },
    /// The log ends before anything usable (a run may still be reported from the others).
    #[error("{path}: truncated, nothing usable: {reason}")]
    TruncatedEmpty {
        /// The file.
        path: PathBuf,
        /// Where it ends.
        reason: String,
    },
    /// Two logs of the same unit were given for one run.
    #[error("{first} and {second} are both {unit} logs; give one plant and one controller log")]
    DuplicateUnit {
        /// The unit (`plant` or `controller`).
        unit: &'static str,
        /// The first file.
        first: PathBuf,
        /// The second file.
        second: PathBuf,
    },
    /// The logs given for one run are of different runs (`crate::same_run`).
    #[error("{first} and {second} are logs of different runs: {reason}")]
    DifferentRuns {
        /// One log.
        first: PathBuf,
        /// The other.
        second: PathBuf,
        /// What differs, and where.
        reason: String,
    },
    /// No log with the plant's vessel states among the inputs.
    #[error("no plant log among {files}: the report needs /plant/ship, /plant/tug1, /plant/tug2")]
    NoPlantLog {
        /// The files given, comma separated.
        files: String,
    },
    /// The scenario attached to a log does not parse.
    #[error("{path}: attached scenario: {reason}")]
    Scenario {
        /// The log holding the attachment.
        path: PathBuf,
        /// The scenario loader's message.
        reason: String,
    },
    /// A dataframe operation failed.
    #[error("table `{table}`: {reason}")]
    Frame {
        /// The table.
        table: String,
        /// The polars message.
        reason: String,
    },
    /// A plot could not be drawn or written.
    #[error("{path}: cannot draw the plot: {reason}")]
    Plot {
        /// The output file.
        path: PathBuf,
        /// The plotting backend's message.
        reason: String,
    },
    /// An output file could not be written.
    #[error("{path}: cannot write: {reason}")]
    Write {
        /// The output file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A report directory given to `compare` has no usable `metrics.json`.
    #[error("{path}: {reason}")]
    Metrics {
        /// The metrics file.
        path: PathBuf,
        /// Why it cannot be used.
        reason: String,
    },
    /// Nothing to do (no input given).
    #[error("{0}")]
    Usage(String),
}

impl AnalyzerError {
    /// A polars error on table `table`.
    pub(crate) fn frame(table: &str, err: impl std::fmt::Display) -> Self {
        AnalyzerError::Frame {
            table: table.to_owned(),
            reason: err.to_string(),
        }
    }

    /// A write error on `path`.
    pub(crate) fn write(path: impl Into<PathBuf>, err: impl std::fmt::Display) -> Self {
        AnalyzerError::Write {
            path: path.into(),
            reason: err.to_string(),
        }
    }
}

/// Result of the analyzer.
pub type Result<T, E = AnalyzerError> = std::result::Result<T, E>;

//! Analyzer of the towing co-simulation's MCAP logs (docs/logging.md, docs/analyzer.md).
//!
//! `analyzer report` reads one run (the plant's and the controller's log, any order) with
//! a streaming MCAP reader, computes the metrics of Du, Negenborn, Reppa (2022), section
//! 4.2 (settling time, towline elongation error, normalised minimum distance eq. (30),
//! ship travel) and the checks added here (collisions, COLREGS assessment and scoring,
//! command bounds, solver statistics), and writes `metrics.json`, tables, plots and a
//! report. The controller log is read whole first; the plant log is then analysed while it
//! streams by, in batches of plant steps, so memory does not grow with its length.
//! `analyzer compare` lays several runs out as the paper's Tables 6 and 7 beside the
//! published figures.
//!
//! Modules, in the order of the data flow: [`read`] (MCAP to messages and columns),
//! [`run`] (which log is which, the controller's data, scenario, bounds), [`frames`]
//! (DataFrames, as-of joins), [`rows`] (a batch's typed [`step::PlantStep`]s),
//! [`metric`] (one module per metric behind [`metric::Metric`], and the registry that
//! generates the typed [`metric::Metrics`] and the verdict), [`plot_sink`] (plot series
//! of bounded size, [`decimate`]), [`stream`] (the plant log in batches through the
//! metrics and the plot sink), [`analysis`] (a run to metrics and plot data), [`plots`],
//! [`report`], [`compare`]. [`metrics`], [`colregs`] and [`geometry`] are the pure
//! computations the metric modules use; [`verdict`] and [`thresholds`] the verdict's
//! types.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod analysis;
pub mod colregs;
pub mod compare;
pub mod decimate;
pub mod doc;
pub mod error;
pub mod frames;
pub mod geometry;
pub mod metric;
pub mod metrics;
pub mod paper;
pub mod plot_clip;
pub mod plot_sink;
pub mod plots;
pub mod progress;
pub mod read;
pub mod record_lengths;
pub mod report;
pub mod rows;
pub mod run;
pub mod same_run;
pub mod step;
pub mod stream;
pub mod synth;
pub mod thresholds;
pub mod verdict;

pub use compare::compare;
pub use error::{AnalyzerError, Result};
pub use report::report;

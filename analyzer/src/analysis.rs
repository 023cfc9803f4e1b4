//! From a run to `metrics.json` and the data of the plots.
//!
//! The plant log is analysed while it streams by ([`crate::stream`]): each batch of plant
//! steps goes to every registered metric ([`crate::metric`], one module per metric, O(1)
//! state or a little per obstacle slot) and to the plot sink ([`crate::plot_sink`], series
//! at a bounded resolution); no per-step series is kept, so the memory does not grow with
//! the log. [`analyze_run`] then finishes the metrics with the controller's tables (read
//! whole: per-sample statistics such as percentiles need all samples) into the typed
//! [`Metrics`] and its verdict.

use std::path::{Path, PathBuf};

use crate::error::{AnalyzerError, Result};
use crate::frames::ControllerFrames;
use crate::metric::FinishContext;
pub use crate::metric::Metrics;
pub use crate::plot_sink::PlotData;
use crate::run::Run;
use crate::same_run::{Checked, CommandCheck};
use crate::stream::{PlantStream, StreamOptions};
use crate::thresholds::Thresholds;

/// The result of the analysis.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// `metrics.json`.
    pub metrics: Metrics,
    /// Plot data.
    pub plot: PlotData,
    /// The controller's tables.
    pub controller: ControllerFrames,
    /// Tables written while the plant log streamed (`timeseries`, `obstacles`; CSV and
    /// Parquet), empty when no table directory was given.
    pub tables: Vec<PathBuf>,
}

/// Analyses a run: streams its plant log through the analysis (writing the `timeseries`
/// and `obstacles` tables into `tables` when given) and computes every metric and the plot
/// data; the verdict under `thresholds`. Progress (bytes of the plant log) goes to
/// `progress`.
///
/// # Errors
/// The plant log cannot be used (see [`crate::read::read_log`]) or has no vessel states,
/// a table cannot be written, a frame lacks a column (unexpected).
pub fn analyze_run(
    run: Run,
    tables: Option<&Path>,
    progress: &indicatif::MultiProgress,
    opts: &StreamOptions,
    thresholds: &Thresholds,
) -> Result<Analysis> {
    let mut run = run;
    loop {
        let mut check = run
            .controller_log()
            .map(|c| CommandCheck::new(&run.controller.command, &run.plant_path, c));
        let ctrl = crate::frames::build_controller(
            std::mem::take(&mut run.controller),
            &run.config.route,
        )?;
        let mut stream = PlantStream::new(&run.config, &ctrl, tables, opts, thresholds)?;
        let bar = progress.add(crate::progress::bytes_bar(&run.plant_path));
        let read = match &mut check {
            Some(check) => {
                let mut checked = Checked {
                    inner: &mut stream,
                    check,
                };
                crate::read::read_into(&run.plant_path, &bar, &mut checked)
            }
            None => crate::read::read_into(&run.plant_path, &bar, &mut stream),
        };
        bar.finish_and_clear();
        let read = read.and_then(|log| {
            check.as_ref().map_or(Ok(()), CommandCheck::finish)?;
            Ok(log)
        });
        let log = match read {
            Ok(log) => log,
            Err(e) => {
                stream.abandon();
                return Err(e);
            }
        };
        match run.needs_whole_read(&log) {
            Ok(false) => {}
            Ok(true) => {
                // The plant log holds controller messages or its scenario after its first
                // message: read it whole first (once), then stream it again.
                stream.abandon();
                run = run.reload(progress)?;
                continue;
            }
            Err(e) => {
                stream.abandon();
                return Err(e);
            }
        }
        if !log.has_plant() {
            stream.abandon();
            return Err(AnalyzerError::NoPlantLog {
                files: run.file_list(),
            });
        }
        let (trackers, plot, written) = stream.finish()?;
        let config = run.config.clone();
        let (files, notes, levels) = run.complete(log);
        let ctx = FinishContext {
            config: &config,
            ctrl: &ctrl,
            files: &files,
            notes: &notes,
            unit_levels: &levels,
        };
        let metrics = trackers.finish(&ctx, thresholds)?;
        let plot = plot.finish(&ctrl, &metrics)?;
        return Ok(Analysis {
            metrics,
            plot,
            controller: ctrl,
            tables: written,
        });
    }
}

//! The plant log streamed through the analysis in bounded memory.
//!
//! [`PlantStream`] is the [`Sink`] the plant log is read into: it collects the decoded
//! messages of a batch of plant steps (at most [`StreamOptions::batch_steps`] ship
//! messages, ending at a change of log time), then builds the batch's frames
//! ([`crate::frames::build_plant_batch`], as-of joins with the rows carried from the last
//! batch), hands them to the metrics ([`Trackers`]: each batch column-wise, then its
//! [`crate::step::PlantStep`]s in time order, [`StepBuilder`]) and to the [`PlotSink`],
//! and appends
//! the `timeseries` and `obstacles` tables to their CSV and Parquet files (polars' batched
//! writers), and drops them. Memory is one batch, the controller's tables and the bounded
//! plot series, whatever the length of the log.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use polars::io::csv::write::BatchedWriter as CsvBatched;
use polars::io::parquet::write::BatchedWriter as ParquetBatched;
use polars::prelude::*;

use crate::error::{AnalyzerError, Result};
use crate::frames::{build_plant_batch, Carry, ControllerFrames};
use crate::metric::{RunContext, Trackers};
use crate::plot_sink::PlotSink;
use crate::read::{Msg, PlantData, Sink};
use crate::rows::StepBuilder;
use crate::run::RunConfig;
use crate::thresholds::Thresholds;

/// Sizes of the streaming analysis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamOptions {
    /// Plant steps (ship messages) per batch: the tables are built and written per batch.
    pub batch_steps: usize,
    /// Buckets per plot line (at most four points each; every sample is kept up to this
    /// many).
    pub plot_points: usize,
    /// Rows kept of the tow's poses and of each obstacle's track (every row up to this
    /// many, then at a stride that doubles).
    pub track_rows: usize,
}

impl Default for StreamOptions {
    /// 16 384 steps per batch (about 50 MB of frames), 16 384 points per plot line and
    /// rows per track: a run of up to 1 638 s at 0.1 s is one batch and plotted from
    /// every step.
    fn default() -> Self {
        StreamOptions {
            batch_steps: 16_384,
            plot_points: 16_384,
            track_rows: 16_384,
        }
    }
}

/// One table written in batches, as CSV and Parquet.
pub(crate) struct TableOut {
    csv_path: PathBuf,
    pq_path: PathBuf,
    writers: Option<(CsvBatched<BufWriter<File>>, ParquetBatched<File>)>,
}

impl TableOut {
    pub(crate) fn new(dir: &Path, stem: &str) -> Self {
        TableOut {
            csv_path: dir.join(format!("{stem}.csv")),
            pq_path: dir.join(format!("{stem}.parquet")),
            writers: None,
        }
    }

    pub(crate) fn write(&mut self, df: &mut DataFrame) -> Result<()> {
        df.rechunk_mut();
        if self.writers.is_none() {
            let schema = df.schema().as_ref().clone();
            let f = File::create(&self.csv_path)
                .map_err(|e| AnalyzerError::write(&self.csv_path, e))?;
            let csv = CsvWriter::new(BufWriter::new(f))
                .batched(&schema)
                .map_err(|e| AnalyzerError::write(&self.csv_path, e))?;
            let f =
                File::create(&self.pq_path).map_err(|e| AnalyzerError::write(&self.pq_path, e))?;
            let pq = ParquetWriter::new(f)
                .batched(&schema)
                .map_err(|e| AnalyzerError::write(&self.pq_path, e))?;
            self.writers = Some((csv, pq));
        }
        if let Some((csv, pq)) = &mut self.writers {
            csv.write_batch(df)
                .map_err(|e| AnalyzerError::write(&self.csv_path, e))?;
            pq.write_batch(df)
                .map_err(|e| AnalyzerError::write(&self.pq_path, e))?;
        }
        Ok(())
    }

    pub(crate) fn finish(self) -> Result<Vec<PathBuf>> {
        if let Some((mut csv, pq)) = self.writers {
            csv.finish()
                .map_err(|e| AnalyzerError::write(&self.csv_path, e))?;
            pq.finish()
                .map_err(|e| AnalyzerError::write(&self.pq_path, e))?;
        }
        Ok(vec![self.csv_path, self.pq_path])
    }

    /// Removes what was written (the analysis failed).
    fn remove(self) {
        drop(self.writers);
        for p in [&self.csv_path, &self.pq_path] {
            // Best effort: the error that stopped the analysis is the one reported.
            let _ = std::fs::remove_file(p);
        }
    }
}

/// The plant log's sink: batches of plant steps through the frames, the metrics, the plot
/// series and the tables (see the module docs).
pub struct PlantStream<'a> {
    opts: StreamOptions,
    ctrl: &'a ControllerFrames,
    batch: PlantData,
    batch_steps: usize,
    batch_max_t: i64,
    batches: usize,
    carry: Carry,
    tables: Option<[TableOut; 2]>,
    steps: usize,
    builder: StepBuilder,
    metrics: Trackers,
    plot: PlotSink,
}

impl std::fmt::Debug for PlantStream<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlantStream")
            .field("opts", &self.opts)
            .field("batches", &self.batches)
            .field("batch_steps", &self.batch_steps)
            .field("steps", &self.steps)
            .field("tables", &self.tables.is_some())
            .finish_non_exhaustive()
    }
}

impl<'a> PlantStream<'a> {
    /// A stream for a run with `config` and the controller's frames `ctrl`, writing the
    /// `timeseries` and `obstacles` tables into `tables` when given; the metrics measure
    /// against `thresholds`.
    ///
    /// # Errors
    /// The controller's reference table lacks a column (unexpected).
    pub fn new(
        config: &RunConfig,
        ctrl: &'a ControllerFrames,
        tables: Option<&Path>,
        opts: &StreamOptions,
        thresholds: &Thresholds,
    ) -> Result<Self> {
        let geometry = config.geometry();
        let run = RunContext {
            config,
            geometry: &geometry,
            thresholds,
        };
        Ok(PlantStream {
            opts: *opts,
            ctrl,
            batch: PlantData::default(),
            batch_steps: 0,
            batch_max_t: i64::MIN,
            batches: 0,
            carry: Carry::default(),
            tables: tables.map(|d| {
                [
                    TableOut::new(d, "timeseries"),
                    TableOut::new(d, "obstacles"),
                ]
            }),
            steps: 0,
            builder: StepBuilder::new(ctrl)?,
            metrics: Trackers::new(&run),
            plot: PlotSink::new(config, opts.plot_points, opts.track_rows),
        })
    }

    /// Batches processed so far.
    #[must_use]
    pub fn batches(&self) -> usize {
        self.batches
    }

    /// Plant steps handed to the metrics so far.
    #[must_use]
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// The plot series so far.
    #[must_use]
    pub fn plot(&self) -> &PlotSink {
        &self.plot
    }

    fn flush(&mut self) -> Result<()> {
        let plant = std::mem::take(&mut self.batch);
        self.batch_steps = 0;
        let b = build_plant_batch(plant, &mut self.carry, self.ctrl)?;
        self.metrics.batch(&b)?;
        self.plot.batch(&b)?;
        let (metrics, plot, steps) = (&mut self.metrics, &mut self.plot, &mut self.steps);
        self.builder.for_each(&b, self.ctrl, |s| {
            *steps += 1;
            metrics.step(s);
            plot.step(s);
        })?;
        if let Some([ts, ob]) = &mut self.tables {
            ts.write(&mut b.timeseries(self.ctrl)?)?;
            ob.write(&mut b.obstacles.clone())?;
        }
        self.batches += 1;
        Ok(())
    }

    /// Processes the last batch and closes the tables: the metrics' and the plots' states
    /// and the files written.
    ///
    /// # Errors
    /// A table cannot be written; a polars error (unexpected).
    pub fn finish(mut self) -> Result<(Trackers, PlotSink, Vec<PathBuf>)> {
        if let Err(e) = self.flush() {
            self.abandon();
            return Err(e);
        }
        let mut written = Vec::new();
        if let Some(tables) = self.tables.take() {
            for t in tables {
                written.extend(t.finish()?);
            }
        }
        Ok((self.metrics, self.plot, written))
    }

    /// Drops the stream and removes the tables written so far.
    pub fn abandon(mut self) {
        if let Some(tables) = self.tables.take() {
            for t in tables {
                t.remove();
            }
        }
    }
}

impl Sink for PlantStream<'_> {
    fn put(&mut self, t_ns: i64, msg: Msg) -> Result<()> {
        if !msg.is_plant() {
            return Ok(());
        }
        // A batch ends before the first message of a later time, so no time is split
        // between batches (the carried rows then give the whole log's as-of joins).
        if self.batch_steps >= self.opts.batch_steps && t_ns > self.batch_max_t {
            self.flush()?;
        }
        if matches!(msg, Msg::Vessel(0, _)) {
            self.batch_steps += 1;
        }
        self.batch_max_t = self.batch_max_t.max(t_ns);
        self.batch.push(t_ns, msg);
        Ok(())
    }
}

//! [`LogWriter`]: one MCAP file of JSON messages on simulated time, and [`SharedLog`], the
//! handle an FMU model keeps (cloneable, as the FMI layer clones models for FMU states).
//!
//! Records: `log_time = publish_time = round(t * 1e9)` ns, `t` the simulation time in s
//! (the epoch is simulation time 0 s); log times never decrease within a file (a message
//! earlier than the last one is refused with [`LogError::TimeWentBack`]). Chunks are zstd
//! compressed; the writer closes the current chunk ([`mcap::Writer::flush`]) before the first
//! message of a new time once the simulated time has advanced by at least
//! [`LogOptions::flush_interval`] since the last flush, so a run that is killed leaves a file
//! readable with a linear reader (`mcap::io::MessageReader`, Python `NonSeekingReader`) up
//! to the last flush, never with half the messages of one time.

use crate::topics::{TopicMessage, MESSAGE_ENCODING, SCHEMA_ENCODING};
use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, McapError, WriteOptions};
use schemars::generate::SchemaSettings;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;

/// What can go wrong while logging; every message names the file and the reason.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The options are not usable.
    #[error("MCAP log {path}: {reason}")]
    Options {
        /// The file.
        path: String,
        /// Which option and why.
        reason: String,
    },
    /// The file could not be created.
    #[error("cannot create MCAP log {path}: {source}")]
    Create {
        /// The file.
        path: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The MCAP writer failed (I/O or a record it refused).
    #[error("MCAP log {path}: cannot write {what}: {}", chain(.source))]
    Write {
        /// The file.
        path: String,
        /// What was being written (a topic, the metadata, the summary, ...).
        what: String,
        /// The writer's reason.
        source: McapError,
    },
    /// Closing the file failed.
    #[error("MCAP log {path}: cannot close the file: {source}")]
    Close {
        /// The file.
        path: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A message or schema could not be serialized to JSON.
    #[error("MCAP log {path}: cannot serialize {what} to JSON: {source}")]
    Serialize {
        /// The file.
        path: String,
        /// The topic or schema.
        what: String,
        /// serde_json's reason.
        source: serde_json::Error,
    },
    /// A time that is not finite, before the epoch (t < 0), or too large for u64 ns.
    #[error("MCAP log {path}: time t = {t} s on {topic} is not representable (finite, >= 0 s, below 1.8e10 s)")]
    BadTime {
        /// The file.
        path: String,
        /// The topic.
        topic: String,
        /// The offending time, s.
        t: f64,
    },
    /// A message earlier than the last one written (log times must not decrease).
    #[error("MCAP log {path}: message on {topic} at t = {t} s is earlier than the last one at t = {last} s; log times must not decrease")]
    TimeWentBack {
        /// The file.
        path: String,
        /// The topic.
        topic: String,
        /// The refused time, s.
        t: f64,
        /// The time of the last message written, s.
        last: f64,
    },
    /// Logging was stopped by an earlier error (reported by [`SharedLog::finish`]).
    #[error("logging stopped early, the file is incomplete: {reason}")]
    Stopped {
        /// The error that stopped it (it names the file).
        reason: String,
    },
    /// The writer thread could not be started, or it panicked.
    #[error("MCAP log {path}: writer thread: {source}")]
    Thread {
        /// The file.
        path: String,
        /// The reason.
        source: std::io::Error,
    },
    /// A write after [`LogWriter::finish`].
    #[error("MCAP log {path}: already finished")]
    Finished {
        /// The file.
        path: String,
    },
}

/// `e` and its sources, so an I/O error shows the operating system's reason.
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        let more = s.to_string();
        if !text.contains(&more) {
            text = format!("{text}: {more}");
        }
        source = s.source();
    }
    text
}

/// Options of a [`LogWriter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogOptions {
    /// Simulated time (s) after which the current chunk is closed and the file flushed:
    /// what a crash can lose at most. Finite and > 0. Default 10 s.
    pub flush_interval: f64,
    /// Target uncompressed chunk size (bytes): a chunk is also closed when it grows beyond
    /// it. Default 1 MiB (mcap's default).
    pub chunk_size: u64,
    /// zstd level; 0 is zstd's default (3).
    pub compression_level: u32,
    /// zstd worker threads; 0 compresses on the calling thread (the default: an FMU
    /// should not start threads, and the chunks are small).
    pub compression_threads: u32,
}

impl Default for LogOptions {
    fn default() -> Self {
        Self {
            flush_interval: 10.0,
            chunk_size: WriteOptions::DEFAULT_CHUNK_SIZE,
            compression_level: 1,
            compression_threads: 0,
        }
    }
}

/// Largest time in s whose nanoseconds fit a u64 (with margin).
const MAX_TIME_S: f64 = 1.8e10;

/// Log time in ns of simulation time `t` (s): `round(t * 1e9)`; `None` when `t` is not
/// finite, negative or too large.
#[must_use]
pub fn time_ns(t: f64) -> Option<u64> {
    if t.is_finite() && (0.0..MAX_TIME_S).contains(&t) {
        // In range: 0 <= t * 1e9 < 1.8e19 < u64::MAX.
        Some((t * 1e9).round() as u64)
    } else {
        None
    }
}

/// The JSON schema of `M` as MCAP schema data: draft 2020-12, self-contained (every
/// sub-schema inlined, no `$ref`), as Foxglove's own JSON schemas.
///
/// # Errors
/// serde_json's error (not expected for derived schemas).
pub fn schema_json<M: TopicMessage>() -> Result<Vec<u8>, serde_json::Error> {
    let schema = SchemaSettings::draft2020_12()
        .with(|s| s.inline_subschemas = true)
        .into_generator()
        .into_root_schema_for::<M>();
    serde_json::to_vec(&schema)
}

#[derive(Debug)]
struct Channel {
    topic: String,
    id: u16,
    sequence: u32,
}

/// One MCAP file (module docs).
pub struct LogWriter {
    path: PathBuf,
    display: String,
    writer: Option<mcap::Writer<BufWriter<File>>>,
    options: LogOptions,
    /// (schema name, schema id).
    schemas: Vec<(&'static str, u16)>,
    channels: Vec<Channel>,
    last_ns: Option<u64>,
    last_flush_ns: Option<u64>,
    flush_interval_ns: u64,
    /// Reused JSON buffer.
    buf: Vec<u8>,
    messages: u64,
}

impl std::fmt::Debug for LogWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LogWriter")
            .field("path", &self.path)
            .field("finished", &self.writer.is_none())
            .field("messages", &self.messages)
            .field("last_ns", &self.last_ns)
            .finish_non_exhaustive()
    }
}

impl LogWriter {
    /// Creates (truncates) the file at `path` and writes the MCAP header.
    ///
    /// # Errors
    /// [`LogError::Options`] for a bad option, [`LogError::Create`] when the file cannot be
    /// created, [`LogError::Write`] when the header cannot be written.
    pub fn create(path: impl AsRef<Path>, options: LogOptions) -> Result<Self, LogError> {
        let path = path.as_ref().to_path_buf();
        let display = path.display().to_string();
        let interval_ns = time_ns(options.flush_interval)
            .filter(|&ns| ns > 0)
            .ok_or_else(|| LogError::Options {
                path: display.clone(),
                reason: format!(
                    "flush_interval must be finite and > 0 s, got {} s",
                    options.flush_interval
                ),
            })?;
        if options.chunk_size == 0 {
            return Err(LogError::Options {
                path: display,
                reason: "chunk_size must be > 0 bytes".to_owned(),
            });
        }
        let file = File::create(&path).map_err(|source| LogError::Create {
            path: display.clone(),
            source,
        })?;
        let writer = WriteOptions::new()
            .profile("")
            .library(concat!(
                "towing-log ",
                env!("CARGO_PKG_VERSION"),
                " (mcap 0.26)"
            ))
            .chunk_size(Some(options.chunk_size))
            .compression_level(options.compression_level)
            .compression_threads(options.compression_threads)
            .create(BufWriter::with_capacity(64 * 1024, file))
            .map_err(|source| LogError::Write {
                path: display.clone(),
                what: "the header".to_owned(),
                source,
            })?;
        Ok(Self {
            path,
            display,
            writer: Some(writer),
            options,
            schemas: Vec::new(),
            channels: Vec::new(),
            last_ns: None,
            last_flush_ns: None,
            flush_interval_ns: interval_ns,
            buf: Vec::with_capacity(4096),
            messages: 0,
        })
    }

    /// The file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The options in use.
    #[must_use]
    pub fn options(&self) -> &LogOptions {
        &self.options
    }

    /// True after [`finish`](Self::finish).
    #[must_use]
    pub fn is_finished(&self) -> bool {
        self.writer.is_none()
    }

    /// Messages written so far.
    #[must_use]
    pub fn message_count(&self) -> u64 {
        self.messages
    }

    /// Time of the last message written (s), if any.
    #[must_use]
    pub fn last_time(&self) -> Option<f64> {
        self.last_ns.map(|ns| ns as f64 * 1e-9)
    }

    fn writer(&mut self) -> Result<&mut mcap::Writer<BufWriter<File>>, LogError> {
        let path = &self.display;
        self.writer
            .as_mut()
            .ok_or_else(|| LogError::Finished { path: path.clone() })
    }

    fn write_error(&self, what: impl Into<String>) -> impl FnOnce(McapError) -> LogError + '_ {
        let what = what.into();
        move |source| LogError::Write {
            path: self.display.clone(),
            what,
            source,
        }
    }

    /// Registers the channel `topic` with `M`'s schema (once; later calls return the same
    /// channel). Writing registers lazily too; registering up front makes a channel visible
    /// in the file even if it never gets a message.
    ///
    /// # Errors
    /// [`LogError::Finished`], [`LogError::Serialize`] or [`LogError::Write`].
    pub fn register<M: TopicMessage>(&mut self, topic: &str) -> Result<usize, LogError> {
        if let Some(i) = self.channels.iter().position(|c| c.topic == topic) {
            return Ok(i);
        }
        self.writer()?;
        let schema_id = match self.schemas.iter().find(|(n, _)| *n == M::SCHEMA_NAME) {
            Some(&(_, id)) => id,
            None => {
                let data = schema_json::<M>().map_err(|source| LogError::Serialize {
                    path: self.display.clone(),
                    what: format!("the schema {}", M::SCHEMA_NAME),
                    source,
                })?;
                let result = self
                    .writer()?
                    .add_schema(M::SCHEMA_NAME, SCHEMA_ENCODING, &data);
                let id =
                    result.map_err(self.write_error(format!("the schema {}", M::SCHEMA_NAME)))?;
                self.schemas.push((M::SCHEMA_NAME, id));
                id
            }
        };
        let result =
            self.writer()?
                .add_channel(schema_id, topic, MESSAGE_ENCODING, &BTreeMap::new());
        let id = result.map_err(self.write_error(format!("the channel {topic}")))?;
        self.channels.push(Channel {
            topic: topic.to_owned(),
            id,
            sequence: 0,
        });
        Ok(self.channels.len() - 1)
    }

    /// Writes `msg` on `topic` at simulation time `t` (s): JSON into a reused buffer,
    /// `log_time = publish_time = round(t * 1e9)`. Before the first message of a new time at
    /// least [`LogOptions::flush_interval`] after the last flush, closes the chunk: every
    /// message of an earlier time then survives a crash.
    ///
    /// # Errors
    /// [`LogError::BadTime`], [`LogError::TimeWentBack`] (nothing written),
    /// [`LogError::Finished`], [`LogError::Serialize`], [`LogError::Write`].
    pub fn write<M: TopicMessage>(&mut self, topic: &str, t: f64, msg: &M) -> Result<(), LogError> {
        let ns = time_ns(t).ok_or_else(|| LogError::BadTime {
            path: self.display.clone(),
            topic: topic.to_owned(),
            t,
        })?;
        if let Some(last) = self.last_ns.filter(|&last| ns < last) {
            return Err(LogError::TimeWentBack {
                path: self.display.clone(),
                topic: topic.to_owned(),
                t,
                last: last as f64 * 1e-9,
            });
        }
        let index = self.register::<M>(topic)?;
        // Close the chunk before the first message of a new time once the interval has
        // passed, so a flush never splits the messages of one time.
        match self.last_flush_ns {
            None => self.last_flush_ns = Some(ns),
            Some(last) if ns - last >= self.flush_interval_ns && self.last_ns < Some(ns) => {
                self.flush_at(ns)?;
            }
            Some(_) => {}
        }
        self.buf.clear();
        if let Err(source) = serde_json::to_writer(&mut self.buf, msg) {
            return Err(LogError::Serialize {
                path: self.display.clone(),
                what: format!("a message on {topic}"),
                source,
            });
        }
        let channel = &mut self.channels[index];
        let header = MessageHeader {
            channel_id: channel.id,
            sequence: channel.sequence,
            log_time: ns,
            publish_time: ns,
        };
        channel.sequence = channel.sequence.wrapping_add(1);
        let Some(writer) = self.writer.as_mut() else {
            return Err(LogError::Finished {
                path: self.display.clone(),
            });
        };
        let result = writer.write_to_known_channel(&header, &self.buf);
        result.map_err(self.write_error(topic))?;
        self.messages += 1;
        self.last_ns = Some(ns);
        Ok(())
    }

    fn flush_at(&mut self, ns: u64) -> Result<(), LogError> {
        let result = self.writer()?.flush();
        result.map_err(self.write_error("a chunk (flush)"))?;
        self.last_flush_ns = Some(ns);
        Ok(())
    }

    /// Closes the current chunk and flushes the file now: every message written so far
    /// survives a crash.
    ///
    /// # Errors
    /// [`LogError::Finished`] or [`LogError::Write`].
    pub fn flush(&mut self) -> Result<(), LogError> {
        let ns = self.last_ns.or(self.last_flush_ns).unwrap_or(0);
        self.flush_at(ns)
    }

    /// Writes a Metadata record `name` with string values.
    ///
    /// # Errors
    /// [`LogError::Finished`] or [`LogError::Write`].
    pub fn metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), LogError> {
        let record = Metadata {
            name: name.to_owned(),
            metadata: entries,
        };
        let result = self.writer()?.write_metadata(&record);
        result.map_err(self.write_error(format!("the metadata {name}")))
    }

    /// Writes an Attachment `name` of `media_type` created at simulation time `t` (s).
    ///
    /// # Errors
    /// [`LogError::BadTime`], [`LogError::Finished`] or [`LogError::Write`].
    pub fn attach(
        &mut self,
        name: &str,
        media_type: &str,
        t: f64,
        data: &[u8],
    ) -> Result<(), LogError> {
        let ns = time_ns(t).ok_or_else(|| LogError::BadTime {
            path: self.display.clone(),
            topic: format!("attachment {name}"),
            t,
        })?;
        let attachment = Attachment {
            log_time: ns,
            create_time: ns,
            name: name.to_owned(),
            media_type: media_type.to_owned(),
            data: Cow::Borrowed(data),
        };
        let result = self.writer()?.attach(&attachment);
        result.map_err(self.write_error(format!("the attachment {name}")))
    }

    /// Writes the summary and footer and closes the file. Idempotent: a second call does
    /// nothing. After it every write returns [`LogError::Finished`].
    ///
    /// # Errors
    /// [`LogError::Write`] (the summary) or [`LogError::Close`] (flushing the file).
    pub fn finish(&mut self) -> Result<(), LogError> {
        let Some(mut writer) = self.writer.take() else {
            return Ok(());
        };
        let finished = writer.finish();
        // Close the file even when the summary failed, and report the first error.
        let buffered = writer.into_inner();
        let closed = buffered.into_inner().map_err(|e| LogError::Close {
            path: self.display.clone(),
            source: e.into_error(),
        });
        finished.map_err(self.write_error("the summary"))?;
        closed.map(drop)
    }
}

/// What a run's `run` Metadata record and scenario attachment hold (docs/logging.md).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunInfo<'a> {
    /// `TowingPlant` or `TowingController`.
    pub unit: &'a str,
    /// The model description's GUID.
    pub guid: &'a str,
    /// The FMU's version.
    pub version: &'a str,
    /// The `scenario` parameter; empty for the bundled scenario
    /// ([`crate::topics::BUNDLED_SCENARIO_LABEL`] is written then).
    pub scenario: &'a str,
    /// The scenario's name.
    pub scenario_name: &'a str,
    /// The run's identifier (the FMUs' `run_id` parameter; empty: none given): the same in
    /// the plant's and the controller's log of one run. Written as the metadata key
    /// `run_id` when not empty; the analyzer refuses to put together logs whose ids differ.
    pub run_id: &'a str,
    /// Start time of the run (simulation time, s).
    pub start_time: f64,
    /// Every parameter's value, a JSON object.
    pub parameters: serde_json::Value,
    /// The scenario text used (attached as `scenario.toml`).
    pub scenario_text: &'a str,
}

impl LogWriter {
    /// Writes the `run` Metadata record and the `scenario.toml` attachment of `info`.
    ///
    /// # Errors
    /// As [`LogWriter::metadata`] and [`LogWriter::attach`].
    pub fn write_run(&mut self, info: &RunInfo<'_>) -> Result<(), LogError> {
        use crate::topics::{self as t, metadata_keys as k};
        let scenario = if info.scenario.is_empty() {
            t::BUNDLED_SCENARIO_LABEL
        } else {
            info.scenario
        };
        let entries: BTreeMap<String, String> = [
            (k::UNIT, info.unit.to_owned()),
            (k::GUID, info.guid.to_owned()),
            (k::VERSION, info.version.to_owned()),
            (k::SCENARIO, scenario.to_owned()),
            (k::SCENARIO_NAME, info.scenario_name.to_owned()),
            (k::RUN_ID, info.run_id.to_owned()),
            (k::EPOCH, t::EPOCH.to_owned()),
            (k::START_TIME, format!("{}", info.start_time)),
            (k::PARAMETERS, info.parameters.to_string()),
        ]
        .into_iter()
        .filter(|(key, value)| *key != k::RUN_ID || !value.is_empty())
        .map(|(key, value)| (key.to_owned(), value))
        .collect();
        self.metadata(t::METADATA_RUN, entries)?;
        self.attach(
            t::SCENARIO_ATTACHMENT,
            t::SCENARIO_MEDIA_TYPE,
            info.start_time.max(0.0),
            info.scenario_text.as_bytes(),
        )
    }
}

/// A batch of writes for [`SharedLog::batch`]: it owns its data, so a background writer can
/// run it later on its own thread.
pub type Batch = Box<dyn FnOnce(&mut LogWriter) -> Result<(), LogError> + Send>;

/// What the writer side reports back.
#[derive(Debug, Default)]
struct Status {
    /// The error that stopped logging early (it names the file).
    failure: Option<String>,
    /// Whether [`SharedLog::batch`] has returned the failure as a warning yet.
    warned: bool,
    /// Batches dropped because their time went back.
    dropped: u64,
}

impl Status {
    /// Runs `batch` on `writer` with the failure policy of [`SharedLog::batch`]; returns
    /// false when logging has to stop.
    fn run(status: &Mutex<Status>, writer: &mut LogWriter, batch: Batch) -> bool {
        let outcome = catch_unwind(AssertUnwindSafe(|| batch(writer)));
        let message = match outcome {
            Ok(Ok(())) => return true,
            Ok(Err(LogError::TimeWentBack { .. })) => {
                lock(status).dropped += 1;
                return true;
            }
            Ok(Err(e)) => e.to_string(),
            Err(payload) => {
                let text = payload
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_owned())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "(no message)".to_owned());
                format!("MCAP log {}: a panic while writing: {text}", writer.display)
            }
        };
        let message = match writer.finish() {
            Ok(()) => message,
            Err(close) => format!("{message}; closing it: {close}"),
        };
        lock(status).failure.get_or_insert(message);
        false
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Records that the writer thread ended before it was asked to (its own failure, if any,
/// stays the one reported).
fn stopped(status: &Mutex<Status>) {
    lock(status)
        .failure
        .get_or_insert_with(|| "the log writer thread stopped".to_owned());
}

/// The failure's text, the first time it is asked for.
fn warning_once(status: &Mutex<Status>) -> Option<String> {
    let mut st = lock(status);
    match &st.failure {
        Some(message) if !st.warned => {
            let warning = format!("logging stopped: {message}");
            st.warned = true;
            Some(warning)
        }
        _ => None,
    }
}

/// How far the writer thread has got: batches written (or skipped after a failure), and
/// whether the thread has ended (normally or by a panic outside a batch).
#[derive(Debug, Default)]
struct Progress {
    done: u64,
    exited: bool,
}

/// The caller's side of [`Progress`], with its signal.
#[derive(Debug, Default)]
struct Tracker {
    progress: Mutex<Progress>,
    changed: Condvar,
}

impl Tracker {
    fn update(&self, f: impl FnOnce(&mut Progress)) {
        f(&mut lock(&self.progress));
        self.changed.notify_all();
    }
}

/// Marks the thread as ended when dropped, also while it unwinds, so that a caller
/// waiting for it never waits for ever.
struct ExitSignal(Arc<Tracker>);

impl Drop for ExitSignal {
    fn drop(&mut self) {
        self.0.update(|p| p.exited = true);
    }
}

/// The writer thread: the queue into it, how many batches went in, its progress, and its
/// handle (returning the finish result).
struct Worker {
    queue: SyncSender<Batch>,
    sent: u64,
    tracker: Arc<Tracker>,
    handle: JoinHandle<Result<(), LogError>>,
}

impl std::fmt::Debug for Worker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Worker")
            .field("sent", &self.sent)
            .finish_non_exhaustive()
    }
}

impl Worker {
    /// Waits until the thread has written every batch handed to it (or has ended); false
    /// if it ended.
    fn settle(&self) -> bool {
        let mut p = lock(&self.tracker.progress);
        while p.done < self.sent && !p.exited {
            p = self
                .tracker
                .changed
                .wait(p)
                .unwrap_or_else(PoisonError::into_inner);
        }
        !p.exited
    }

    /// Hands `batch` to the thread; false if it is gone.
    fn send(&mut self, batch: Batch) -> bool {
        let sent = self.queue.send(batch).is_ok();
        self.sent += u64::from(sent);
        sent
    }
}

#[derive(Debug)]
enum Mode {
    /// Batches run on the caller's thread.
    Inline(Option<Box<LogWriter>>),
    /// Batches run on a writer thread, in order; `None` once finished.
    Background(Option<Worker>),
}

#[derive(Debug)]
struct Shared {
    path: PathBuf,
    mode: Mode,
    status: Arc<Mutex<Status>>,
}

/// The handle an FMU model keeps: either no log (empty `log_file`: nothing is built or
/// serialized) or a shared [`LogWriter`]. Clones share the writer, so the copies the FMI
/// layer makes for FMU states write to the same file; after [`SharedLog::finish`] every
/// clone is inactive.
///
/// Two modes: [`SharedLog::new`] runs each batch on the caller's thread;
/// [`SharedLog::spawn`] hands the batches to a writer thread (serialization, compression
/// and I/O off the simulation's thread, in order), which the FMUs
/// use. Either way a failure stops the log, is returned once as a warning and again as the
/// error of [`finish`](SharedLog::finish). When the warning comes is fixed, whatever the
/// threads' timing: inline, by the [`batch`](SharedLog::batch) call that failed; with the
/// writer thread, by the next [`batch`](SharedLog::batch) or [`settle`](SharedLog::settle)
/// call, which first waits for the thread to finish what it was given (each batch is
/// handed over at once, so the thread writes one step while the simulation computes the
/// next). An FMU calls one of them at every step, so a failure is reported by the step
/// after the one whose messages failed.
#[derive(Debug, Clone, Default)]
pub struct SharedLog {
    inner: Option<Arc<Mutex<Shared>>>,
}

impl SharedLog {
    /// No log.
    #[must_use]
    pub fn none() -> Self {
        Self::default()
    }

    fn with_mode(path: PathBuf, mode: Mode, status: Arc<Mutex<Status>>) -> Self {
        Self {
            inner: Some(Arc::new(Mutex::new(Shared { path, mode, status }))),
        }
    }

    /// A log writing to `writer` on the caller's thread.
    #[must_use]
    pub fn new(writer: LogWriter) -> Self {
        let path = writer.path().to_path_buf();
        Self::with_mode(path, Mode::Inline(Some(Box::new(writer))), Arc::default())
    }

    /// Creates the log at `path`, writes the run description of `info` and whatever
    /// `setup` writes (channels, messages at the start), then hands the writer to its
    /// own thread ([`SharedLog::spawn`]). On an error the file is finished as far as
    /// possible and the error returned.
    ///
    /// # Errors
    /// The first error of creating, writing or spawning, naming the file.
    pub fn open(
        path: impl AsRef<Path>,
        options: LogOptions,
        info: &RunInfo<'_>,
        setup: impl FnOnce(&mut LogWriter) -> Result<(), LogError>,
    ) -> Result<Self, LogError> {
        let mut writer = LogWriter::create(path, options)?;
        if let Err(e) = writer.write_run(info).and_then(|()| setup(&mut writer)) {
            let _ = writer.finish();
            return Err(e);
        }
        Self::spawn(writer)
    }

    /// A log writing to `writer` on a thread of its own.
    ///
    /// # Errors
    /// [`LogError::Thread`] when the thread cannot be started (the writer is finished).
    pub fn spawn(mut writer: LogWriter) -> Result<Self, LogError> {
        let path = writer.path().to_path_buf();
        let status: Arc<Mutex<Status>> = Arc::default();
        let tracker: Arc<Tracker> = Arc::default();
        // One batch in flight: the caller waits for it before handing over the next.
        let (tx, rx) = sync_channel::<Batch>(1);
        let thread_status = Arc::clone(&status);
        let thread_tracker = Arc::clone(&tracker);
        let display = writer.display.clone();
        // The writer moves into the thread; if spawning fails, the closure (and the writer
        // with it) is dropped, which finishes the file as far as possible.
        let handle = std::thread::Builder::new()
            .name("towing-log".to_owned())
            .spawn(move || {
                let exit = ExitSignal(thread_tracker);
                let mut open = true;
                for batch in rx {
                    if open {
                        open = Status::run(&thread_status, &mut writer, batch);
                    }
                    exit.0.update(|p| p.done += 1);
                }
                if open {
                    writer.finish()
                } else {
                    Ok(())
                }
            })
            .map_err(|source| LogError::Thread {
                path: display,
                source,
            })?;
        Ok(Self::with_mode(
            path,
            Mode::Background(Some(Worker {
                queue: tx,
                sent: 0,
                tracker,
                handle,
            })),
            status,
        ))
    }

    fn lock(&self) -> Option<std::sync::MutexGuard<'_, Shared>> {
        self.inner.as_deref().map(lock)
    }

    /// True while the log is open and has not failed: build and write messages only then.
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.lock().is_some_and(|s| {
            let open = match &s.mode {
                Mode::Inline(w) => w.as_ref().is_some_and(|w| !w.is_finished()),
                Mode::Background(b) => b.is_some(),
            };
            open && lock(&s.status).failure.is_none()
        })
    }

    /// Runs `batch` (a batch of writes) on the open writer, now or on the writer thread,
    /// with the failure policy both FMUs want: a batch refused with
    /// [`LogError::TimeWentBack`] is dropped and counted (the master went back to an
    /// earlier FMU state, and log times must not decrease); any other error stops the log
    /// (the file is finished as far as possible and the error kept for
    /// [`finish`](Self::finish)). Returns the failure's text, once, for the FMU to report
    /// as a warning: inline, the failure of this batch; with a writer thread, of the
    /// batches before this one, all written before it is handed over (type docs). Nothing
    /// happens without an open log.
    pub fn batch(&self, batch: Batch) -> Option<String> {
        let mut shared = self.lock()?;
        let Shared { mode, status, .. } = &mut *shared;
        match mode {
            Mode::Inline(slot) => {
                if lock(status).failure.is_none() {
                    if let Some(writer) = slot.as_mut().filter(|w| !w.is_finished()) {
                        if !Status::run(status, writer, batch) {
                            *slot = None;
                        }
                    }
                }
                warning_once(status)
            }
            Mode::Background(Some(worker)) => {
                if !worker.settle() {
                    stopped(status);
                }
                // Taken before this batch goes over: the thread may fail it at once, and
                // that is for the next call to report (never sooner, never later).
                let warning = warning_once(status);
                if lock(status).failure.is_none() && !worker.send(batch) {
                    stopped(status);
                }
                warning
            }
            Mode::Background(None) => warning_once(status),
        }
    }

    /// Waits for a writer thread to write every batch handed to it and returns a failure
    /// not reported yet, once (as [`batch`](Self::batch)): for a step that writes nothing,
    /// so that the failure of an earlier step's messages is still reported by the next
    /// step.
    pub fn settle(&self) -> Option<String> {
        let shared = self.lock()?;
        if let Mode::Background(Some(worker)) = &shared.mode {
            if !worker.settle() {
                stopped(&shared.status);
            }
        }
        warning_once(&shared.status)
    }

    /// Finishes the writer (waiting for a writer thread to write everything queued) and
    /// drops it, for every clone. `Ok(false)` when there was no log open.
    ///
    /// # Errors
    /// As [`LogWriter::finish`]; [`LogError::Stopped`] when a batch stopped the log
    /// earlier (reported once); [`LogError::Thread`] when the writer thread panicked.
    pub fn finish(&self) -> Result<bool, LogError> {
        let Some(mut shared) = self.lock() else {
            return Ok(false);
        };
        let display = shared.path.display().to_string();
        let finished = match &mut shared.mode {
            Mode::Inline(slot) => match slot.take() {
                Some(mut w) if !w.is_finished() => w.finish().map(|()| true),
                _ => Ok(false),
            },
            Mode::Background(b) => match b.take() {
                Some(worker) => {
                    // If the thread is gone, its status or the join says why.
                    let Worker { queue, handle, .. } = worker;
                    drop(queue);
                    match handle.join() {
                        Ok(result) => result.map(|()| true),
                        Err(_) => Err(LogError::Thread {
                            path: display,
                            source: std::io::Error::other("the writer thread panicked"),
                        }),
                    }
                }
                None => Ok(false),
            },
        };
        let failure = lock(&shared.status).failure.take();
        match failure {
            Some(reason) => Err(LogError::Stopped { reason }),
            None => finished,
        }
    }

    /// Batches dropped so far because their time went back (see [`batch`](Self::batch)).
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.lock().map_or(0, |s| lock(&s.status).dropped)
    }

    /// The file, while a log is open.
    #[must_use]
    pub fn path(&self) -> Option<PathBuf> {
        self.lock().and_then(|s| {
            let open = match &s.mode {
                Mode::Inline(w) => w.is_some(),
                Mode::Background(b) => b.is_some(),
            };
            open.then(|| s.path.clone())
        })
    }
}

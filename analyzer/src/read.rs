//! Streaming reader of one MCAP log.
//!
//! The file is read front to back through a `BufReader` with the MCAP crate's sans-io
//! [`LinearReader`] (mcap 0.26): memory scales with the largest chunk (1 MiB by default in
//! the writer), never with the file. Each message of a topic of docs/logging.md is decoded
//! into its `towing_log::topics` struct and handed to a [`Sink`], in file order: the
//! column vectors of [`PlantData`] / [`ControllerData`] ([`read_log`], the controller log),
//! or the streaming analysis of the plant log (`crate::stream`), which keeps nothing per
//! step. The scene, `/tf` and prediction topics are skipped without decoding (they are most
//! of a log's bytes and the report does not need them). Besides messages the reader keeps
//! the `run` Metadata record and the `scenario.toml` attachment; [`peek_log`] reads only
//! the records before the first message (metadata, attachment, channels) to tell a plant
//! log from a controller log before either is read.
//!
//! A log that ends early (a crashed run, a file being written, a partial copy) stops the
//! MCAP reader with an error at the first broken record; everything before it is kept and
//! the file is marked [`LogFile::truncated`].
//!
//! Lengths in a file are not trusted: the reader never asks for more bytes than the file
//! has left (a record length corrupted into the exabytes reads to the end of the file and
//! stops there as a truncation), and a record longer than [`MAX_RECORD_BYTES`] (in the
//! file or inside a decompressed chunk) stops it the same way, before any buffer is sized
//! by it. The length fields inside the records the analyzer parses (schemas, channels,
//! messages, metadata, attachments) are checked against the record before the mcap crate
//! parses it ([`crate::record_lengths`]); the other records are not parsed. The same
//! reading works on bytes in memory ([`read_log_bytes`],
//! [`peek_log_bytes`]: tests and the fuzzers).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use serde::de::DeserializeOwned;
use towing_log::topics::{
    self, metadata_keys, names, Colregs, Command, Log, Obstacles, PlantInputs, Reference, Solver,
    TowlineState, VesselState,
};

use crate::error::{AnalyzerError, Result};
use crate::record_lengths;

/// The longest record the reader accepts, bytes (the MCAP reader's `record_length_limit`):
/// 64 MiB. `towing_log` writes chunks of at most 1 MiB uncompressed, messages of a few kB
/// and the scenario text as the only attachment; a longer record is a corrupted length,
/// and the log is read as truncated before it.
pub const MAX_RECORD_BYTES: usize = 64 << 20;

/// Which FMU wrote a log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// `TowingPlant`: topics `/plant/...`.
    Plant,
    /// `TowingController`: topics `/controller/...`.
    Controller,
    /// Both prefixes in one file (a merged log).
    Both,
}

impl Unit {
    /// Lower-case name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Plant => "plant",
            Unit::Controller => "controller",
            Unit::Both => "plant and controller",
        }
    }
}

/// Columns of one vessel topic (`towing.VesselState`).
#[derive(Debug, Default, Clone)]
pub struct VesselCols {
    /// Log time, ns since the epoch (simulation time 0 s).
    pub t_ns: Vec<i64>,
    /// North, m.
    pub x: Vec<f64>,
    /// East, m.
    pub y: Vec<f64>,
    /// Heading, rad.
    pub psi: Vec<f64>,
    /// Surge, m/s.
    pub u: Vec<f64>,
    /// Sway, m/s.
    pub v: Vec<f64>,
    /// Yaw rate, rad/s.
    pub r: Vec<f64>,
}

impl VesselCols {
    fn push(&mut self, t_ns: i64, m: VesselState) {
        self.t_ns.push(t_ns);
        self.x.push(m.x);
        self.y.push(m.y);
        self.psi.push(m.psi);
        self.u.push(m.u);
        self.v.push(m.v);
        self.r.push(m.r);
    }
}

/// Columns of one towline topic (`towing.TowlineState`).
#[derive(Debug, Default, Clone)]
pub struct TowlineCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Distance between the attachment points, m.
    pub length: Vec<f64>,
    /// Towing angle, rad.
    pub angle: Vec<f64>,
    /// Mean tension over the step, N.
    pub tension: Vec<f64>,
    /// Commanded tension, N.
    pub tension_cmd: Vec<f64>,
    /// Slack at the end of the step.
    pub slack: Vec<bool>,
    /// (length - desired) / desired, signed fraction.
    pub elongation_error: Vec<f64>,
}

impl TowlineCols {
    fn push(&mut self, t_ns: i64, m: TowlineState) {
        self.t_ns.push(t_ns);
        self.length.push(m.length);
        self.angle.push(m.angle);
        self.tension.push(m.tension);
        self.tension_cmd.push(m.tension_cmd);
        self.slack.push(m.slack);
        self.elongation_error.push(m.elongation_error);
    }
}

/// Obstacles in long form: one row per active slot per message.
#[derive(Debug, Default, Clone)]
pub struct ObstacleCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Slot, 1-based.
    pub slot: Vec<u32>,
    /// Index into [`ObstacleCols::names`].
    pub name_idx: Vec<u32>,
    /// 1 circle, 2 ship ellipse.
    pub kind: Vec<i32>,
    /// North of the centre, m.
    pub x: Vec<f64>,
    /// East of the centre, m.
    pub y: Vec<f64>,
    /// Course, rad.
    pub psi: Vec<f64>,
    /// Speed, m/s.
    pub speed: Vec<f64>,
    /// Major axis or diameter, m.
    pub length: Vec<f64>,
    /// Minor axis or diameter, m.
    pub width: Vec<f64>,
    /// Distinct obstacle names (interned: a long log repeats them every step).
    pub names: Vec<String>,
}

impl ObstacleCols {
    fn push(&mut self, t_ns: i64, m: Obstacles) {
        for o in m.obstacles {
            let idx = intern(&mut self.names, o.name);
            self.t_ns.push(t_ns);
            self.slot.push(o.slot);
            self.name_idx.push(idx);
            self.kind.push(o.kind);
            self.x.push(o.x);
            self.y.push(o.y);
            self.psi.push(o.psi);
            self.speed.push(o.speed);
            self.length.push(o.length);
            self.width.push(o.width);
        }
    }

    /// Name of row `i`.
    pub fn name(&self, i: usize) -> &str {
        self.name_idx
            .get(i)
            .and_then(|&k| self.names.get(k as usize))
            .map_or("", String::as_str)
    }
}

/// Plant inputs (`towing.PlantInputs`).
#[derive(Debug, Default, Clone)]
pub struct InputCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Aft tug surge, sway force (N) and yaw moment (N m).
    pub tug1: [Vec<f64>; 3],
    /// Forward tug surge, sway force (N) and yaw moment (N m).
    pub tug2: [Vec<f64>; 3],
    /// Commanded tensions, N.
    pub tension_cmd: [Vec<f64>; 2],
}

impl InputCols {
    fn push(&mut self, t_ns: i64, m: PlantInputs) {
        self.t_ns.push(t_ns);
        for k in 0..3 {
            self.tug1[k].push(m.tug1[k]);
            self.tug2[k].push(m.tug2[k]);
        }
        for k in 0..2 {
            self.tension_cmd[k].push(m.tension_cmd[k]);
        }
    }
}

/// Guidance references (`towing.Reference`).
#[derive(Debug, Default, Clone)]
pub struct ReferenceCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Reference North, m.
    pub x: Vec<f64>,
    /// Reference East, m.
    pub y: Vec<f64>,
    /// Reference heading, rad.
    pub psi: Vec<f64>,
    /// Active waypoint, 1-based.
    pub active_waypoint: Vec<u32>,
    /// Altered waypoint in use.
    pub altered: Vec<bool>,
    /// Range-equivalent distance to the nearest obstacle, m.
    pub d_ob: Vec<f64>,
    /// Active waypoint as used: North, East (m), heading (rad).
    pub waypoint: [Vec<f64>; 3],
}

impl ReferenceCols {
    fn push(&mut self, t_ns: i64, m: Reference) {
        self.t_ns.push(t_ns);
        self.x.push(m.x);
        self.y.push(m.y);
        self.psi.push(m.psi);
        self.active_waypoint.push(m.active_waypoint);
        self.altered.push(m.altered);
        self.d_ob.push(m.d_ob);
        for k in 0..3 {
            self.waypoint[k].push(m.waypoint[k]);
        }
    }
}

/// COLREGS encounters in long form: one row per slot per sample.
#[derive(Debug, Default, Clone)]
pub struct ColregsCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Slot, 1-based.
    pub slot: Vec<u32>,
    /// Index into [`ColregsCols::labels`] of the situation text.
    pub situation_idx: Vec<u32>,
    /// Index into [`ColregsCols::labels`] of the role text.
    pub role_idx: Vec<u32>,
    /// Situation code (-1 none, 0 safe, 1 head-on, 2 crossing give-way, 3 crossing
    /// stand-on, 4 overtaking, 5 being overtaken, 6 unclassified).
    pub situation_code: Vec<i32>,
    /// Role code (0 none, 1 give-way, 2 stand-on).
    pub role_code: Vec<i32>,
    /// Distinct texts.
    pub labels: Vec<String>,
}

impl ColregsCols {
    fn push(&mut self, t_ns: i64, m: Colregs) {
        for e in m.targets {
            let s = intern(&mut self.labels, e.situation);
            let r = intern(&mut self.labels, e.role);
            self.t_ns.push(t_ns);
            self.slot.push(e.slot);
            self.situation_idx.push(s);
            self.role_idx.push(r);
            self.situation_code.push(e.situation_code);
            self.role_code.push(e.role_code);
        }
    }

    /// Text of label index `k`.
    pub fn label(&self, k: u32) -> &str {
        self.labels.get(k as usize).map_or("", String::as_str)
    }
}

/// Commands (`towing.Command`).
#[derive(Debug, Default, Clone)]
pub struct CommandCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Aft tug thrust (surge N, sway N, yaw N m).
    pub tug1: [Vec<f64>; 3],
    /// Forward tug thrust (surge N, sway N, yaw N m).
    pub tug2: [Vec<f64>; 3],
    /// Commanded tensions, N.
    pub tension: [Vec<f64>; 2],
    /// Towing angles of the plan, rad.
    pub desired_angle: [Vec<f64>; 2],
}

impl CommandCols {
    fn push(&mut self, t_ns: i64, m: Command) {
        self.t_ns.push(t_ns);
        for k in 0..3 {
            self.tug1[k].push(m.tug1[k]);
            self.tug2[k].push(m.tug2[k]);
        }
        for k in 0..2 {
            self.tension[k].push(m.tension[k]);
            self.desired_angle[k].push(m.desired_angle[k]);
        }
    }
}

/// Solver reports (`towing.Solver`).
#[derive(Debug, Default, Clone)]
pub struct SolverCols {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Architecture code (1 distributed, 2 centralized).
    pub architecture: Vec<i32>,
    /// Avoidance scheme code (1 I, 2 II, 3 III).
    pub scheme: Vec<i32>,
    /// ADMM iterations (centralized: SCP loops).
    pub iterations: Vec<u32>,
    /// Stopping rule met.
    pub converged: Vec<bool>,
    /// Primal residuals of tug 1 and tug 2.
    pub r_pri: [Vec<f64>; 2],
    /// Dual residuals of tug 1 and tug 2.
    pub r_dual: [Vec<f64>; 2],
    /// Wall time of the sample, ms.
    pub compute_time_ms: Vec<f64>,
    /// Samples so far.
    pub samples: Vec<u64>,
    /// Fallbacks so far.
    pub fallbacks: Vec<u64>,
    /// Index into [`SolverCols::reasons`] of this sample's fallback reason, if any.
    pub fallback_idx: Vec<Option<u32>>,
    /// Distinct fallback reasons.
    pub reasons: Vec<String>,
}

impl SolverCols {
    fn push(&mut self, t_ns: i64, m: Solver) {
        self.t_ns.push(t_ns);
        self.architecture.push(m.architecture);
        self.scheme.push(m.scheme);
        self.iterations.push(m.iterations);
        self.converged.push(m.converged);
        for k in 0..2 {
            self.r_pri[k].push(m.r_pri[k]);
            self.r_dual[k].push(m.r_dual[k]);
        }
        self.compute_time_ms.push(m.compute_time_ms);
        self.samples.push(m.samples);
        self.fallbacks.push(m.fallbacks);
        let idx = (!m.fallback.is_empty()).then(|| intern(&mut self.reasons, m.fallback));
        self.fallback_idx.push(idx);
    }
}

/// A warning or error a unit logged (`foxglove.Log`).
#[derive(Debug, Clone, PartialEq)]
pub struct LogLine {
    /// Log time, ns.
    pub t_ns: i64,
    /// Foxglove level (3 warning, 4 error).
    pub level: i32,
    /// Unit name.
    pub name: String,
    /// The message.
    pub message: String,
}

/// Everything kept from the plant topics.
#[derive(Debug, Default, Clone)]
pub struct PlantData {
    /// `/plant/ship`.
    pub ship: VesselCols,
    /// `/plant/tug1` (aft).
    pub tug1: VesselCols,
    /// `/plant/tug2` (forward).
    pub tug2: VesselCols,
    /// `/plant/towline1`, `/plant/towline2`.
    pub towlines: [TowlineCols; 2],
    /// `/plant/obstacles`.
    pub obstacles: ObstacleCols,
    /// `/plant/inputs`.
    pub inputs: InputCols,
}

/// Everything kept from the controller topics.
#[derive(Debug, Default, Clone)]
pub struct ControllerData {
    /// `/controller/reference`.
    pub reference: ReferenceCols,
    /// `/controller/colregs`.
    pub colregs: ColregsCols,
    /// `/controller/command`.
    pub command: CommandCols,
    /// `/controller/solver`.
    pub solver: SolverCols,
}

/// Count and first error of the messages of one topic that did not decode.
#[derive(Debug, Clone, PartialEq)]
pub struct DecodeErrors {
    /// Messages that failed.
    pub count: u64,
    /// The first failure.
    pub first: String,
}

/// One decoded message of a topic the analyzer uses.
#[derive(Debug, Clone, PartialEq)]
pub enum Msg {
    /// `/plant/ship` (0), `/plant/tug1` (1), `/plant/tug2` (2).
    Vessel(usize, VesselState),
    /// `/plant/towline1` (0), `/plant/towline2` (1).
    Towline(usize, TowlineState),
    /// `/plant/obstacles`.
    Obstacles(Obstacles),
    /// `/plant/inputs`.
    Inputs(PlantInputs),
    /// `/controller/reference`.
    Reference(Reference),
    /// `/controller/colregs`.
    Colregs(Colregs),
    /// `/controller/command`.
    Command(Command),
    /// `/controller/solver`.
    Solver(Solver),
}

impl Msg {
    /// True for the plant's topics.
    #[must_use]
    pub fn is_plant(&self) -> bool {
        matches!(
            self,
            Msg::Vessel(..) | Msg::Towline(..) | Msg::Obstacles(_) | Msg::Inputs(_)
        )
    }
}

/// Receives the decoded messages of a log in file order, with their log time (ns).
pub trait Sink {
    /// One message.
    ///
    /// # Errors
    /// The sink's own failure (writing a table); it stops the reading.
    fn put(&mut self, t_ns: i64, msg: Msg) -> Result<()>;
}

impl PlantData {
    /// Appends a plant message to the columns (controller messages are ignored).
    pub fn push(&mut self, t_ns: i64, msg: Msg) {
        match msg {
            Msg::Vessel(0, m) => self.ship.push(t_ns, m),
            Msg::Vessel(1, m) => self.tug1.push(t_ns, m),
            Msg::Vessel(_, m) => self.tug2.push(t_ns, m),
            Msg::Towline(k, m) => self.towlines[k.min(1)].push(t_ns, m),
            Msg::Obstacles(m) => self.obstacles.push(t_ns, m),
            Msg::Inputs(m) => self.inputs.push(t_ns, m),
            _ => {}
        }
    }
}

impl Sink for PlantData {
    fn put(&mut self, t_ns: i64, msg: Msg) -> Result<()> {
        self.push(t_ns, msg);
        Ok(())
    }
}

impl ControllerData {
    /// Appends a controller message to the columns (plant messages are ignored).
    pub fn push(&mut self, t_ns: i64, msg: Msg) {
        match msg {
            Msg::Reference(m) => self.reference.push(t_ns, m),
            Msg::Colregs(m) => self.colregs.push(t_ns, m),
            Msg::Command(m) => self.command.push(t_ns, m),
            Msg::Solver(m) => self.solver.push(t_ns, m),
            _ => {}
        }
    }
}

impl Sink for ControllerData {
    fn put(&mut self, t_ns: i64, msg: Msg) -> Result<()> {
        self.push(t_ns, msg);
        Ok(())
    }
}

/// Both units' columns (everything [`read_log`] keeps).
struct Everything<'a> {
    plant: &'a mut PlantData,
    controller: &'a mut ControllerData,
}

impl Sink for Everything<'_> {
    fn put(&mut self, t_ns: i64, msg: Msg) -> Result<()> {
        if msg.is_plant() {
            self.plant.push(t_ns, msg);
        } else {
            self.controller.push(t_ns, msg);
        }
        Ok(())
    }
}

/// Messages decoded per kind (whether or not a sink kept them).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Decoded {
    /// `/plant/ship` messages.
    pub ship: u64,
    /// All plant messages.
    pub plant: u64,
    /// `/controller/solver`, `/controller/command` and `/controller/reference` messages.
    pub controller_core: u64,
    /// All controller messages.
    pub controller: u64,
    /// Messages whose log time is earlier than the message before them.
    pub out_of_order: u64,
}

/// What the records before a log's first message say (see [`peek_log`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Peek {
    /// The file.
    pub path: PathBuf,
    /// Size of the file, bytes.
    pub bytes: u64,
    /// The unit, from the `run` metadata and the topics of the channels seen; `None` when
    /// neither tells.
    pub unit: Option<Unit>,
    /// The `run` Metadata record (empty if not seen).
    pub metadata: BTreeMap<String, String>,
    /// The `scenario.toml` attachment, if seen before the first message.
    pub scenario_text: Option<String>,
}

/// One log read: what was found, and the columns when read with [`read_log`].
#[derive(Debug, Clone)]
pub struct LogFile {
    /// The file.
    pub path: PathBuf,
    /// Which unit wrote it (from the `run` metadata's `unit`, else from the topics).
    pub unit: Unit,
    /// The `run` Metadata record (empty if absent).
    pub metadata: BTreeMap<String, String>,
    /// The `scenario.toml` attachment, if present.
    pub scenario_text: Option<String>,
    /// Messages read per topic (including the skipped topics).
    pub message_counts: BTreeMap<String, u64>,
    /// Messages that did not decode, per topic.
    pub decode_errors: BTreeMap<String, DecodeErrors>,
    /// Why the log ended early, if it did (the MCAP reader's error).
    pub truncated: Option<String>,
    /// Channels whose schema name differs from docs/logging.md (decoded anyway).
    pub schema_mismatches: Vec<String>,
    /// Size of the file, bytes.
    pub bytes: u64,
    /// Plant topics (filled by [`read_log`] only).
    pub plant: PlantData,
    /// Controller topics (filled by [`read_log`] only).
    pub controller: ControllerData,
    /// `/plant/log` and `/controller/log`.
    pub logs: Vec<LogLine>,
    /// Messages decoded, per kind.
    pub decoded: Decoded,
}

impl LogFile {
    /// True when the file holds the plant's vessel states.
    pub fn has_plant(&self) -> bool {
        self.decoded.ship > 0
    }

    /// True when the file holds any controller message (solver, command or reference).
    pub fn has_controller(&self) -> bool {
        self.decoded.controller_core > 0
    }

    /// Messages decoded into [`Msg`]s (the unit logs not counted).
    fn decoded_total(&self) -> u64 {
        self.decoded.plant + self.decoded.controller
    }
}

/// Topics the reader decodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Topic {
    Ship,
    Tug1,
    Tug2,
    Towline1,
    Towline2,
    Obstacles,
    Inputs,
    PlantLog,
    Reference,
    Colregs,
    Command,
    Solver,
    ControllerLog,
    /// Known topic, not needed (scene, tf, prediction).
    Skip,
    /// Not in the contract.
    Foreign,
}

fn classify(topic: &str) -> Topic {
    match topic {
        names::PLANT_SHIP => Topic::Ship,
        names::PLANT_TUG1 => Topic::Tug1,
        names::PLANT_TUG2 => Topic::Tug2,
        names::PLANT_TOWLINE1 => Topic::Towline1,
        names::PLANT_TOWLINE2 => Topic::Towline2,
        names::PLANT_OBSTACLES => Topic::Obstacles,
        names::PLANT_INPUTS => Topic::Inputs,
        names::PLANT_LOG => Topic::PlantLog,
        names::CONTROLLER_REFERENCE => Topic::Reference,
        names::CONTROLLER_COLREGS => Topic::Colregs,
        names::CONTROLLER_COMMAND => Topic::Command,
        names::CONTROLLER_SOLVER => Topic::Solver,
        names::CONTROLLER_LOG => Topic::ControllerLog,
        names::TF | names::PLANT_SCENE | names::CONTROLLER_SCENE | names::CONTROLLER_PREDICTION => {
            Topic::Skip
        }
        _ => Topic::Foreign,
    }
}

/// Counts the bytes pulled from the file, for the progress bar.
struct Counting<R> {
    inner: R,
    progress: indicatif::ProgressBar,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.progress.inc(n as u64);
        Ok(n)
    }
}

struct ChannelInfo {
    topic: String,
    kind: Topic,
    json: bool,
}

/// Reads one log into columns (both units' topics). `progress` is advanced by the bytes
/// read (pass `ProgressBar::hidden()` for none).
///
/// # Errors
/// The file is missing or unreadable, not MCAP, has none of the expected topics, or not one
/// message could be used. A log that ends early is not an error (see
/// [`LogFile::truncated`]).
pub fn read_log(path: &Path, progress: &indicatif::ProgressBar) -> Result<LogFile> {
    let mut plant = PlantData::default();
    let mut controller = ControllerData::default();
    let mut log = read_into(
        path,
        progress,
        &mut Everything {
            plant: &mut plant,
            controller: &mut controller,
        },
    )?;
    log.plant = plant;
    log.controller = controller;
    Ok(log)
}

/// Reads one log, handing every decoded message to `sink` in file order; the returned
/// [`LogFile`] has empty columns.
///
/// # Errors
/// As [`read_log`], and the sink's errors.
pub fn read_into(
    path: &Path,
    progress: &indicatif::ProgressBar,
    sink: &mut dyn Sink,
) -> Result<LogFile> {
    let (log, channels) = scan(path, progress, Some(sink))?;
    finish(log, &channels)
}

/// Reads the records of a log up to its first message: the `run` metadata, the scenario
/// attachment and the channels registered before it (`towing_log::LogWriter` registers
/// every channel and writes both records when the file is created), enough to tell the
/// unit. Reads at most one chunk.
///
/// # Errors
/// The file is missing or unreadable, empty, or not MCAP (the errors [`read_log`] would
/// give first).
pub fn peek_log(path: &Path) -> Result<Peek> {
    let (log, channels) = scan(path, &indicatif::ProgressBar::hidden(), None)?;
    Ok(peek_of(log, &channels))
}

/// What [`peek_log`] says of the records read.
fn peek_of(log: LogFile, channels: &BTreeMap<u16, ChannelInfo>) -> Peek {
    let (plant, controller) = unit_topics(channels);
    Peek {
        path: log.path,
        bytes: log.bytes,
        unit: decide_unit(&log.metadata, plant, controller),
        metadata: log.metadata,
        scenario_text: log.scenario_text,
    }
}

/// [`read_log`] of a log held in memory, `data`; `name` stands for the file in messages.
///
/// # Errors
/// As [`read_log`] (an empty `data` is [`AnalyzerError::Empty`]).
pub fn read_log_bytes(name: &Path, data: &[u8]) -> Result<LogFile> {
    let mut plant = PlantData::default();
    let mut controller = ControllerData::default();
    let mut sink = Everything {
        plant: &mut plant,
        controller: &mut controller,
    };
    let (log, channels) = scan_bytes(name, data, Some(&mut sink))?;
    let mut log = finish(log, &channels)?;
    log.plant = plant;
    log.controller = controller;
    Ok(log)
}

/// [`peek_log`] of a log held in memory, `data`; `name` stands for the file in messages.
///
/// # Errors
/// As [`peek_log`].
pub fn peek_log_bytes(name: &Path, data: &[u8]) -> Result<Peek> {
    let (log, channels) = scan_bytes(name, data, None)?;
    Ok(peek_of(log, &channels))
}

/// The reading loop over `data`, the bytes of the log `name`.
fn scan_bytes(
    name: &Path,
    data: &[u8],
    sink: Option<&mut dyn Sink>,
) -> Result<(LogFile, BTreeMap<u16, ChannelInfo>)> {
    if data.is_empty() {
        return Err(AnalyzerError::Empty {
            path: name.to_owned(),
        });
    }
    let mut source = data;
    scan_source(name, &mut source, data.len() as u64, sink)
}

/// The reading loop over the file `path`: every record with `sink`, or (`None`) up to the
/// first message.
fn scan(
    path: &Path,
    progress: &indicatif::ProgressBar,
    sink: Option<&mut dyn Sink>,
) -> Result<(LogFile, BTreeMap<u16, ChannelInfo>)> {
    let (mut source, bytes) = open_counted(path, progress)?;
    let scanned = scan_source(path, &mut source, bytes, sink);
    progress.set_position(bytes);
    scanned
}

/// The reading loop over `source`, the `bytes` bytes of the log `path` (named in messages):
/// every record with `sink`, or (`None`) up to the first message.
fn scan_source(
    path: &Path,
    source: &mut dyn Read,
    bytes: u64,
    mut sink: Option<&mut dyn Sink>,
) -> Result<(LogFile, BTreeMap<u16, ChannelInfo>)> {
    let mut log = nothing_read(path, bytes);
    let mut channels: BTreeMap<u16, ChannelInfo> = BTreeMap::new();
    let mut schema_names: BTreeMap<u16, String> = BTreeMap::new();
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES),
    );
    let mut unread = bytes;
    let mut past_data_end = false;
    let mut records = 0u64;
    let mut last_t_ns = i64::MIN;

    while let Some(event) = reader.next_event() {
        let event = match event {
            Ok(event) => event,
            Err(err) => {
                stop_at_error(&mut log, err, records, bytes)?;
                break;
            }
        };
        match event {
            LinearReadEvent::ReadRequest(need) => {
                feed(&mut reader, source, need, &mut unread).map_err(|source| {
                    AnalyzerError::Io {
                        path: path.to_owned(),
                        source,
                    }
                })?;
            }
            LinearReadEvent::Record { opcode, data } => {
                records += 1;
                if opcode == mcap::records::op::DATA_END {
                    past_data_end = true;
                    continue;
                }
                if past_data_end || !record_lengths::parsed(opcode) {
                    // The summary repeats schemas and channels; nothing new there. Nor in
                    // the header, the message indexes or records unknown to us.
                    continue;
                }
                if let Err(reason) = record_lengths::check(opcode, data) {
                    broken_record(&mut log, opcode, &reason, records - 1)?;
                    break;
                }
                let record = match mcap::parse_record(opcode, data) {
                    Ok(record) => record,
                    Err(err) => {
                        stop_at_error(&mut log, err, records, bytes)?;
                        break;
                    }
                };
                match record {
                    Record::Schema { header, .. } => {
                        schema_names.insert(header.id, header.name);
                    }
                    Record::Channel(ch) => add_channel(&mut log, &mut channels, &schema_names, ch),
                    Record::Message { header, data } => {
                        let Some(sink) = sink.as_deref_mut() else {
                            // Peeking: the records before the first message are read.
                            break;
                        };
                        if let Some(channel) = channels.get(&header.channel_id) {
                            let t_ns = i64::try_from(header.log_time).unwrap_or(i64::MAX);
                            put_message(&mut log, channel, t_ns, &data, sink, &mut last_t_ns)?;
                        }
                    }
                    Record::Metadata(m) if m.name == topics::METADATA_RUN => {
                        log.metadata = m.metadata;
                    }
                    Record::Attachment { header, data, .. }
                        if header.name == topics::SCENARIO_ATTACHMENT =>
                    {
                        log.scenario_text = Some(String::from_utf8_lossy(&data).into_owned());
                    }
                    _ => {}
                }
            }
        }
    }
    Ok((log, channels))
}

/// Answers the reader's request for `need` more bytes from `source`, which has `unread`
/// bytes left: never more than that, so a corrupted length sizes no buffer beyond the
/// file (the reader then meets the end of the file and stops as truncated).
fn feed(
    reader: &mut LinearReader,
    source: &mut dyn Read,
    need: usize,
    unread: &mut u64,
) -> std::io::Result<()> {
    let want = need.min(usize::try_from(*unread).unwrap_or(usize::MAX));
    let buf = reader.insert(want);
    let read = loop {
        match source.read(buf) {
            Ok(n) => break n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    };
    *unread = unread.saturating_sub(read as u64);
    reader.notify_read(read);
    Ok(())
}

/// Opens `path` for reading through a 1 MiB buffer that advances `progress` (its length
/// set to the file's size); with the size, bytes.
///
/// # Errors
/// The file cannot be opened or its size read, or it is empty.
fn open_counted(
    path: &Path,
    progress: &indicatif::ProgressBar,
) -> Result<(BufReader<Counting<File>>, u64)> {
    let io_err = |source| AnalyzerError::Io {
        path: path.to_owned(),
        source,
    };
    let file = File::open(path).map_err(io_err)?;
    let bytes = file.metadata().map_err(io_err)?.len();
    if bytes == 0 {
        return Err(AnalyzerError::Empty {
            path: path.to_owned(),
        });
    }
    progress.set_length(bytes);
    progress.set_position(0);
    let source = BufReader::with_capacity(
        1 << 20,
        Counting {
            inner: file,
            progress: progress.clone(),
        },
    );
    Ok((source, bytes))
}

/// The [`LogFile`] of `path` (`bytes` long) before its first record is read.
fn nothing_read(path: &Path, bytes: u64) -> LogFile {
    LogFile {
        path: path.to_owned(),
        unit: Unit::Plant,
        metadata: BTreeMap::new(),
        scenario_text: None,
        message_counts: BTreeMap::new(),
        decode_errors: BTreeMap::new(),
        truncated: None,
        schema_mismatches: Vec::new(),
        bytes,
        plant: PlantData::default(),
        controller: ControllerData::default(),
        logs: Vec::new(),
        decoded: Decoded::default(),
    }
}

/// Registers the channel `ch`, noting in `log` a schema (named in `schema_names` by id)
/// that differs from docs/logging.md.
fn add_channel(
    log: &mut LogFile,
    channels: &mut BTreeMap<u16, ChannelInfo>,
    schema_names: &BTreeMap<u16, String>,
    ch: mcap::records::Channel,
) {
    let kind = classify(&ch.topic);
    let json = ch.message_encoding == topics::MESSAGE_ENCODING;
    if let (Some(expected), Some(found)) = (expected_schema(kind), schema_names.get(&ch.schema_id))
    {
        if expected != found {
            log.schema_mismatches.push(format!(
                "{}: schema `{found}`, docs/logging.md says `{expected}`",
                ch.topic
            ));
        }
    }
    channels.insert(
        ch.id,
        ChannelInfo {
            topic: ch.topic,
            kind,
            json,
        },
    );
}

/// Counts one message of `channel` (log time `t_ns`, payload `data`) and hands it decoded
/// to `sink`; a message that is not JSON is noted as a decode error unless its topic is
/// skipped or not in the contract. `last_t_ns`, the latest log time so far, tells the
/// messages out of order.
///
/// # Errors
/// The sink's.
fn put_message(
    log: &mut LogFile,
    channel: &ChannelInfo,
    t_ns: i64,
    data: &[u8],
    sink: &mut dyn Sink,
    last_t_ns: &mut i64,
) -> Result<()> {
    *log.message_counts.entry(channel.topic.clone()).or_insert(0) += 1;
    if !channel.json {
        if !matches!(channel.kind, Topic::Skip | Topic::Foreign) {
            note_decode_error(
                log,
                &channel.topic,
                "message encoding is not json".to_owned(),
            );
        }
        return Ok(());
    }
    if let Some(msg) = decode_msg(log, channel, t_ns, data) {
        if t_ns < *last_t_ns {
            log.decoded.out_of_order += 1;
        }
        *last_t_ns = (*last_t_ns).max(t_ns);
        sink.put(t_ns, msg)?;
    }
    Ok(())
}

/// Turns the reader's error into "not MCAP" (nothing read yet) or a truncation mark.
fn stop_at_error(log: &mut LogFile, err: McapError, records: u64, bytes: u64) -> Result<()> {
    match err {
        McapError::BadMagic if records == 0 => Err(AnalyzerError::NotMcap {
            path: log.path.clone(),
        }),
        McapError::UnexpectedEof if records == 0 && bytes < 8 => Err(AnalyzerError::NotMcap {
            path: log.path.clone(),
        }),
        err if records == 0 => Err(AnalyzerError::Unreadable {
            path: log.path.clone(),
            reason: reader_reason(&err),
        }),
        err => {
            log.truncated = Some(match err {
                McapError::UnexpectedEof => {
                    "the log ends in the middle of a record (truncated)".to_owned()
                }
                other => format!(
                    "the log is broken after {records} records: {}",
                    reader_reason(&other)
                ),
            });
            Ok(())
        }
    }
}

/// A record whose length fields do not fit in it ([`record_lengths::check`]): the log is
/// unreadable when no record came before it (`read` of them did), else truncated there.
fn broken_record(log: &mut LogFile, opcode: u8, reason: &str, read: u64) -> Result<()> {
    let reason = format!("a record (opcode 0x{opcode:02x}) is corrupt: {reason}");
    if read == 0 {
        return Err(AnalyzerError::Unreadable {
            path: log.path.clone(),
            reason,
        });
    }
    log.truncated = Some(format!("the log is broken after {read} records: {reason}"));
    Ok(())
}

/// The MCAP reader's error in words; a length beyond [`MAX_RECORD_BYTES`] is called what
/// it is.
fn reader_reason(err: &McapError) -> String {
    match err {
        McapError::RecordTooLarge { opcode, len } => format!(
            "a record (opcode 0x{opcode:02x}) claims {len} bytes, more than the {} MiB a \
             record may have (a corrupted length)",
            MAX_RECORD_BYTES >> 20
        ),
        McapError::ChunkTooLarge(len) => format!(
            "a chunk claims {len} bytes, more than the {} MiB a record may have (a \
             corrupted length)",
            MAX_RECORD_BYTES >> 20
        ),
        other => other.to_string(),
    }
}

fn note_decode_error(log: &mut LogFile, topic: &str, err: String) {
    log.decode_errors
        .entry(topic.to_owned())
        .and_modify(|e| e.count += 1)
        .or_insert(DecodeErrors {
            count: 1,
            first: err,
        });
}

fn decode<T: DeserializeOwned>(log: &mut LogFile, topic: &str, data: &[u8]) -> Option<T> {
    match serde_json::from_slice::<T>(data) {
        Ok(m) => Some(m),
        Err(e) => {
            note_decode_error(log, topic, e.to_string());
            None
        }
    }
}

/// Decodes one message of a used topic (unit logs go to [`LogFile::logs`]) and counts it.
fn decode_msg(log: &mut LogFile, channel: &ChannelInfo, t_ns: i64, data: &[u8]) -> Option<Msg> {
    let topic = channel.topic.as_str();
    let msg = match channel.kind {
        Topic::Ship => Msg::Vessel(0, decode(log, topic, data)?),
        Topic::Tug1 => Msg::Vessel(1, decode(log, topic, data)?),
        Topic::Tug2 => Msg::Vessel(2, decode(log, topic, data)?),
        Topic::Towline1 => Msg::Towline(0, decode(log, topic, data)?),
        Topic::Towline2 => Msg::Towline(1, decode(log, topic, data)?),
        Topic::Obstacles => Msg::Obstacles(decode(log, topic, data)?),
        Topic::Inputs => Msg::Inputs(decode(log, topic, data)?),
        Topic::Reference => Msg::Reference(decode(log, topic, data)?),
        Topic::Colregs => Msg::Colregs(decode(log, topic, data)?),
        Topic::Command => Msg::Command(decode(log, topic, data)?),
        Topic::Solver => Msg::Solver(decode(log, topic, data)?),
        Topic::PlantLog | Topic::ControllerLog => {
            let m: Log = decode(log, topic, data)?;
            log.logs.push(LogLine {
                t_ns,
                level: m.level,
                name: m.name,
                message: m.message,
            });
            return None;
        }
        Topic::Skip | Topic::Foreign => return None,
    };
    let d = &mut log.decoded;
    match &msg {
        Msg::Vessel(0, _) => {
            d.ship += 1;
            d.plant += 1;
        }
        Msg::Reference(_) | Msg::Command(_) | Msg::Solver(_) => {
            d.controller_core += 1;
            d.controller += 1;
        }
        Msg::Colregs(_) => d.controller += 1,
        _ => d.plant += 1,
    }
    Some(msg)
}

/// Whether the channels include plant topics and controller topics of the contract.
fn unit_topics(channels: &BTreeMap<u16, ChannelInfo>) -> (bool, bool) {
    let plant = channels
        .values()
        .any(|c| c.topic.starts_with("/plant/") && c.kind != Topic::Foreign);
    let controller = channels
        .values()
        .any(|c| c.topic.starts_with("/controller/") && c.kind != Topic::Foreign);
    (plant, controller)
}

/// The unit from both prefixes, else the metadata, else the topics.
fn decide_unit(
    metadata: &BTreeMap<String, String>,
    plant_topics: bool,
    controller_topics: bool,
) -> Option<Unit> {
    let by_metadata = match metadata.get(metadata_keys::UNIT).map(String::as_str) {
        Some("TowingPlant") => Some(Unit::Plant),
        Some("TowingController") => Some(Unit::Controller),
        _ => None,
    };
    match (by_metadata, plant_topics, controller_topics) {
        (_, true, true) => Some(Unit::Both),
        (Some(unit), _, _) => Some(unit),
        (None, true, false) => Some(Unit::Plant),
        (None, false, true) => Some(Unit::Controller),
        (None, false, false) => None,
    }
}

/// Decides the unit and refuses files with nothing useful.
fn finish(mut log: LogFile, channels: &BTreeMap<u16, ChannelInfo>) -> Result<LogFile> {
    let (plant_topics, controller_topics) = unit_topics(channels);
    log.unit = match decide_unit(&log.metadata, plant_topics, controller_topics) {
        Some(unit) => unit,
        None => {
            let mut topics: Vec<&str> = channels.values().map(|c| c.topic.as_str()).collect();
            topics.sort_unstable();
            topics.dedup();
            let found = if topics.is_empty() {
                if let Some(reason) = &log.truncated {
                    return Err(AnalyzerError::TruncatedEmpty {
                        path: log.path.clone(),
                        reason: format!("it ends before its first channel ({reason})"),
                    });
                }
                "; no channels at all".to_owned()
            } else {
                format!("; found: {}", topics.join(", "))
            };
            return Err(AnalyzerError::NoExpectedTopics {
                path: log.path.clone(),
                found,
            });
        }
    };
    if log.decoded_total() == 0 {
        let reason = if let Some((topic, e)) = log.decode_errors.iter().next() {
            format!(
                "{} messages of {topic} do not match docs/logging.md: {}",
                e.count, e.first
            )
        } else if let Some(reason) = &log.truncated {
            return Err(AnalyzerError::TruncatedEmpty {
                path: log.path.clone(),
                reason: format!("it ends before its first message ({reason})"),
            });
        } else {
            "the log has the channels but no messages".to_owned()
        };
        return Err(AnalyzerError::NoUsableData {
            path: log.path.clone(),
            reason,
        });
    }
    Ok(log)
}

/// Index of `name` in `names`, appended if new. The lists are short (obstacle names,
/// situation labels); fallback reasons can be many, so the search runs from the end, where
/// a repeated reason usually is.
fn intern(names: &mut Vec<String>, name: String) -> u32 {
    if let Some(k) = names.iter().rposition(|n| *n == name) {
        return u32::try_from(k).unwrap_or(u32::MAX);
    }
    names.push(name);
    u32::try_from(names.len() - 1).unwrap_or(u32::MAX)
}

/// The schema name docs/logging.md gives a decoded topic.
fn expected_schema(kind: Topic) -> Option<&'static str> {
    use towing_log::TopicMessage;
    Some(match kind {
        Topic::Ship | Topic::Tug1 | Topic::Tug2 => VesselState::SCHEMA_NAME,
        Topic::Towline1 | Topic::Towline2 => TowlineState::SCHEMA_NAME,
        Topic::Obstacles => Obstacles::SCHEMA_NAME,
        Topic::Inputs => PlantInputs::SCHEMA_NAME,
        Topic::Reference => Reference::SCHEMA_NAME,
        Topic::Colregs => Colregs::SCHEMA_NAME,
        Topic::Command => Command::SCHEMA_NAME,
        Topic::Solver => Solver::SCHEMA_NAME,
        Topic::PlantLog | Topic::ControllerLog => Log::SCHEMA_NAME,
        Topic::Skip | Topic::Foreign => return None,
    })
}

#[cfg(test)]
mod tests {
    /// The logs' floats are read exactly as they were written (serde_json's
    /// `float_roundtrip`, set for the whole workspace): the same log gives the same figures
    /// however the analyzer was built. Before 2026-12-07 an analyzer built alone
    /// (`cargo build -p analyzer`) read about one float in ten 1 ulp off, and one built with
    /// the workspace (clarabel enables the feature) read them exactly, so their reports
    /// differed in the last digits.
    #[test]
    fn log_floats_are_read_exactly() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..10_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 100.0;
            let text = serde_json::to_string(&v).expect("finite");
            let back: f64 = serde_json::from_str(&text).expect("a number");
            assert_eq!(back.to_bits(), v.to_bits(), "{text}");
        }
    }
}

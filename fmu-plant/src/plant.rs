//! The plant model behind the FMI layer: parameters, inputs, and the [`World`] it steps.
//!
//! Life cycle: the scenario is read when the master enters initialization mode (so every
//! output is valid during initialization, as libcosim reads them there), and read again if a
//! parameter changes before initialization ends. A bad scenario or parameter is refused with
//! `fmi2Error` and a message naming the file, the field and the reason.
//!
//! MCAP log (docs/logging.md): with `log_file` set, the file is created when initialization
//! ends (with the state at the start time) and gets every topic after each step; terminate
//! closes it (a failure is `fmi2Error`), and `fmi2FreeInstance` closes it if terminate did
//! not. The log is the instance's own: it is not part of the FMU state, and the copies the
//! layer keeps for FMU states share it.

use crate::logging::{self, LogScenario, StepSnapshot};
use crate::variables as vars;
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, StepContext, StepOutcome};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use towing_interface::ScenarioFile;
use towing_log::topics::Log;
use towing_log::{LogOptions, RunInfo, SharedLog};
use towing_model::{
    HullModel, Scenario, TowlineModel, World, WorldConfig, WorldInputs, MAX_OBSTACLES,
};

/// Version of [`Plant`]'s serialized state; bump on any layout change.
const STATE_FORMAT_VERSION: u16 = 1;
const STATE_MAGIC: &[u8; 4] = b"TWPL";

/// Parameter values (FMI `parameter` variables); the model parameters are all 0 (empty) by
/// default: as the scenario says, the bundled scenario.
#[derive(Debug, Clone, PartialEq)]
struct Parameters {
    scenario: String,
    log_file: String,
    /// Interval of the Foxglove topics `/tf` and `/plant/scene` in the log, s; 0: every step.
    log_scene_interval: f64,
    hull_model: i32,
    towline_model: i32,
    integration_step: f64,
}

impl Default for Parameters {
    fn default() -> Self {
        Self {
            scenario: String::new(),
            log_file: String::new(),
            log_scene_interval: vars::LOG_SCENE_INTERVAL_START,
            hull_model: 0,
            towline_model: 0,
            integration_step: 0.0,
        }
    }
}

impl Parameters {
    /// Checks the values alone (before any scenario is read).
    fn validate(&self) -> Result<(), String> {
        if !(0..=2).contains(&self.hull_model) {
            return Err(format!(
                "hull_model must be 0 (as the scenario says), 1 (linear damping) or 2 (nonlinear damping), got {}",
                self.hull_model
            ));
        }
        if !(0..=2).contains(&self.towline_model) {
            return Err(format!(
                "towline_model must be 0 (as the scenario says), 1 (ideal winch) or 2 (elastic line), got {}",
                self.towline_model
            ));
        }
        let d = self.log_scene_interval;
        if !(d.is_finite() && d >= 0.0) {
            return Err(format!(
                "log_scene_interval must be 0 (every step) or a positive number of seconds, got {d} s"
            ));
        }
        let h = self.integration_step;
        if !(h == 0.0 || (h > 0.0 && h <= WorldConfig::MAX_INTEGRATION_STEP)) {
            return Err(format!(
                "integration_step must be 0 (as the scenario says) or in (0, {}] s, got {h} s",
                WorldConfig::MAX_INTEGRATION_STEP
            ));
        }
        Ok(())
    }

    /// The world configuration: the scenario's `[simulation]` section, overridden by every
    /// parameter that is not 0.
    fn world_config(&self, scenario: &Scenario) -> WorldConfig {
        let mut config = scenario.world_config;
        match self.hull_model {
            1 => config.hull_model = HullModel::LinearDamping,
            2 => config.hull_model = HullModel::NonlinearDamping,
            _ => {}
        }
        match self.towline_model {
            1 => config.towline_model = TowlineModel::IdealWinch,
            2 => config.towline_model = scenario.elastic_towline.into(),
            _ => {}
        }
        if self.integration_step > 0.0 {
            config.integration_step = self.integration_step;
        }
        config
    }
}

/// A scenario as loaded: its text (so a saved FMU state does not depend on the file still
/// existing), where it came from, and the world built from it.
#[derive(Debug, Clone)]
struct Loaded {
    origin: String,
    text: String,
    world: World,
    /// What the log needs from the scenario (shared with the log's writer thread).
    log_info: Arc<LogScenario>,
}

/// The towing plant: ship, two tugs, two towlines and traffic.
#[derive(Debug, Clone)]
pub struct Plant {
    params: Parameters,
    inputs: WorldInputs,
    resource_dir: Option<PathBuf>,
    /// Set once initialization mode was entered: parameter changes then reload at once.
    initializing: bool,
    loaded: Option<Loaded>,
    /// `fmi2SetupExperiment`'s start time (s).
    start_time: f64,
    /// The MCAP log, open from the end of initialization while `log_file` is set.
    log: SharedLog,
}

impl Plant {
    /// Reads the scenario named by the `scenario` parameter (or the bundled one) and builds the world.
    fn load(&mut self, log: &Logger) -> Result<(), String> {
        self.params.validate()?;
        let ScenarioFile {
            origin,
            text,
            scenario,
        } = ScenarioFile::load(&self.params.scenario, self.resource_dir.as_deref())?;
        let world = World::new(&scenario, self.params.world_config(&scenario))
            .map_err(|e| format!("{origin}: {e}"))?;
        let log_info = Arc::new(LogScenario::of(&scenario));
        log.info(
            "logEvents",
            &format!(
                "scenario '{}' loaded from {origin} ({} obstacles)",
                scenario.name,
                scenario.obstacles.len()
            ),
        );
        self.loaded = Some(Loaded {
            origin,
            text,
            world,
            log_info,
        });
        Ok(())
    }

    fn reload_if_initializing(&mut self, log: &Logger) -> Result<(), String> {
        if self.initializing {
            self.load(log)
        } else {
            Ok(())
        }
    }

    fn world(&self) -> Option<&World> {
        self.loaded.as_ref().map(|l| &l.world)
    }

    /// Creates the log named by `log_file` (if any) and writes the run description, the
    /// static scene and the state at the start time.
    fn open_log(&mut self, log: &Logger) -> Result<(), String> {
        // A log of an earlier initialization (after fmi2Reset) is closed by `release`.
        if self.params.log_file.is_empty() {
            return Ok(());
        }
        let Some(loaded) = self.loaded.as_ref() else {
            return Ok(());
        };
        let t = self.start_time;
        let guid = vars::DESCRIPTION.guid();
        let p = &self.params;
        let parameters = serde_json::json!({
            "scenario": p.scenario,
            "log_file": p.log_file,
            "log_scene_interval": p.log_scene_interval,
            "hull_model": p.hull_model,
            "towline_model": p.towline_model,
            "integration_step": p.integration_step,
        });
        let info = RunInfo {
            unit: vars::MODEL_IDENTIFIER,
            guid: &guid,
            version: env!("CARGO_PKG_VERSION"),
            scenario: &p.scenario,
            scenario_name: &loaded.log_info.name,
            start_time: t,
            parameters,
            scenario_text: &loaded.text,
            ..RunInfo::default()
        };
        // Written before the log's own thread takes over.
        self.log = SharedLog::open(&p.log_file, LogOptions::default(), &info, |writer| {
            logging::register_topics(writer)?;
            logging::write_static_scene(writer, t, &loaded.world, &loaded.log_info)?;
            let snap = StepSnapshot::capture(t, &loaded.world, &self.inputs);
            logging::write_state(writer, &snap, &loaded.log_info, true)
        })
        .map_err(|e| format!("parameter `log_file`: {e}"))?;
        log.info(
            "logEvents",
            &format!("MCAP log {} created", self.params.log_file),
        );
        Ok(())
    }

    /// Writes the state at the end `t` of the step that began at `t_prev`; the Foxglove
    /// topics only when the step crossed a multiple of `log_scene_interval` (counted from
    /// the start time). A logging failure becomes a warning.
    fn log_step(&self, t_prev: f64, t: f64) -> Option<String> {
        let loaded = self.loaded.as_ref()?;
        let snap = StepSnapshot::capture(t, &loaded.world, &self.inputs);
        let info = Arc::clone(&loaded.log_info);
        let scene = logging::scene_due(
            self.params.log_scene_interval,
            t_prev - self.start_time,
            t - self.start_time,
        );
        self.log.batch(Box::new(move |w| {
            logging::write_state(w, &snap, &info, scene)
        }))
    }

    /// Writes a warning or error the plant reports to `/plant/log`.
    fn log_line(&self, t: f64, level: i32, message: &str) -> Option<String> {
        let message = message.to_owned();
        self.log.batch(Box::new(move |w| {
            logging::write_log_line(w, t, level, &message)
        }))
    }
}

impl Fmi2Model for Plant {
    fn description() -> &'static fmi2_slave::description::ModelDescription {
        &vars::DESCRIPTION
    }

    fn instantiate(ctx: &InstanceContext<'_>) -> Result<Self, String> {
        Ok(Self {
            params: Parameters::default(),
            inputs: WorldInputs::default(),
            resource_dir: ctx.resource_dir.map(Path::to_path_buf),
            initializing: false,
            loaded: None,
            start_time: 0.0,
            log: SharedLog::none(),
        })
    }

    fn setup_experiment(
        &mut self,
        _log: &Logger,
        start_time: f64,
        _stop_time: Option<f64>,
        _tolerance: Option<f64>,
    ) -> Result<(), String> {
        self.start_time = start_time;
        Ok(())
    }

    fn enter_initialization_mode(&mut self, log: &Logger) -> Result<(), String> {
        self.initializing = true;
        self.load(log)
    }

    fn exit_initialization_mode(&mut self, log: &Logger) -> Result<(), String> {
        self.initializing = false;
        match self.loaded {
            Some(_) => self.open_log(log),
            None => Err("no scenario is loaded".to_owned()),
        }
    }

    fn get_real(&self, vr: u32) -> f64 {
        match vr {
            vars::INTEGRATION_STEP => self.params.integration_step,
            vars::LOG_SCENE_INTERVAL => self.params.log_scene_interval,
            200..=299 => {
                for tug in 0..2 {
                    for c in 0..3 {
                        if vr == vars::tug_force(tug, c) {
                            return self.inputs.tug_tau[tug as usize][c as usize];
                        }
                    }
                }
                for line in 0..2 {
                    if vr == vars::tension_cmd(line) {
                        return self.inputs.tension_cmd[line as usize];
                    }
                }
                f64::NAN
            }
            _ => self.world().map_or(0.0, |w| output_real(w, vr)),
        }
    }

    fn set_real(&mut self, log: &Logger, vr: u32, value: f64) -> Result<(), String> {
        if vr == vars::LOG_SCENE_INTERVAL {
            let previous = self.params.log_scene_interval;
            self.params.log_scene_interval = value;
            return self.params.validate().inspect_err(|_| {
                self.params.log_scene_interval = previous;
            });
        }
        if vr == vars::INTEGRATION_STEP {
            let previous = self.params.clone();
            self.params.integration_step = value;
            if let Err(e) = self
                .params
                .validate()
                .and_then(|()| self.reload_if_initializing(log))
            {
                self.params = previous;
                return Err(e);
            }
            return Ok(());
        }
        for tug in 0..2 {
            for c in 0..3 {
                if vr == vars::tug_force(tug, c) {
                    self.inputs.tug_tau[tug as usize][c as usize] = value;
                    return Ok(());
                }
            }
        }
        for line in 0..2 {
            if vr == vars::tension_cmd(line) {
                self.inputs.tension_cmd[line as usize] = value;
                return Ok(());
            }
        }
        Err(format!("value reference {vr} is not a settable Real"))
    }

    fn get_integer(&self, vr: u32) -> i32 {
        match vr {
            vars::HULL_MODEL => self.params.hull_model,
            vars::TOWLINE_MODEL => self.params.towline_model,
            _ => {
                let slot = (vr.saturating_sub(1000) / 10) as usize;
                match self.world() {
                    Some(w) if slot < MAX_OBSTACLES => w.obstacle(slot).kind,
                    _ => 0,
                }
            }
        }
    }

    fn set_integer(&mut self, log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        let previous = self.params.clone();
        match vr {
            vars::HULL_MODEL => self.params.hull_model = value,
            vars::TOWLINE_MODEL => self.params.towline_model = value,
            _ => return Err(format!("value reference {vr} is not a settable Integer")),
        }
        if let Err(e) = self
            .params
            .validate()
            .and_then(|()| self.reload_if_initializing(log))
        {
            self.params = previous;
            return Err(e);
        }
        Ok(())
    }

    fn get_boolean(&self, vr: u32) -> bool {
        for line in 0..2 {
            if vr == vars::towline(line, vars::TOWLINE_SLACK) {
                return self.world().is_none_or(|w| w.towline(line as usize).slack);
            }
        }
        false
    }

    fn set_boolean(&mut self, _log: &Logger, vr: u32, _value: bool) -> Result<(), String> {
        Err(format!("value reference {vr} is not a settable Boolean"))
    }

    fn get_string(&self, vr: u32) -> String {
        match vr {
            vars::SCENARIO => self.params.scenario.clone(),
            vars::LOG_FILE => self.params.log_file.clone(),
            _ => String::new(),
        }
    }

    fn set_string(&mut self, log: &Logger, vr: u32, value: &str) -> Result<(), String> {
        match vr {
            vars::SCENARIO => {
                let previous = std::mem::replace(&mut self.params.scenario, value.to_owned());
                if let Err(e) = self.reload_if_initializing(log) {
                    self.params.scenario = previous;
                    return Err(e);
                }
                Ok(())
            }
            vars::LOG_FILE => {
                value.clone_into(&mut self.params.log_file);
                Ok(())
            }
            _ => Err(format!("value reference {vr} is not a settable String")),
        }
    }

    fn do_step(&mut self, _log: &Logger, step: &StepContext) -> StepOutcome {
        let Some(loaded) = self.loaded.as_mut() else {
            return StepOutcome::Error("no scenario is loaded".to_owned());
        };
        let outcome = match loaded.world.step(&self.inputs, step.step_size) {
            Ok(()) => StepOutcome::Ok,
            Err(e) => StepOutcome::Discard(format!(
                "step from t = {} s by h = {} s refused: {e}; the state is left at t = {} s",
                step.current_time,
                step.step_size,
                loaded.world.time()
            )),
        };
        if !self.log.is_active() {
            return outcome;
        }
        let failed = match &outcome {
            StepOutcome::Ok | StepOutcome::Warning(_) => {
                self.log_step(step.current_time, step.current_time + step.step_size)
            }
            StepOutcome::Discard(m) | StepOutcome::Error(m) => {
                self.log_line(step.current_time, Log::ERROR, m)
            }
        };
        match (failed, outcome) {
            (Some(warning), StepOutcome::Ok) => StepOutcome::Warning(warning),
            (Some(warning), StepOutcome::Warning(m)) => {
                StepOutcome::Warning(format!("{m}; {warning}"))
            }
            (_, outcome) => outcome,
        }
    }

    fn terminate(&mut self, _log: &Logger) -> Result<(), String> {
        self.log
            .finish()
            .map(drop)
            .map_err(|e| format!("closing the log: {e}"))
    }

    fn release(&mut self, log: &Logger) {
        if let Err(e) = self.log.finish() {
            log.error(&format!("closing the log: {e}"));
        }
    }

    fn serialize_state(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(STATE_MAGIC);
        out.extend_from_slice(&STATE_FORMAT_VERSION.to_le_bytes());
        put_str(out, &self.params.scenario);
        out.extend_from_slice(&self.params.hull_model.to_le_bytes());
        out.extend_from_slice(&self.params.towline_model.to_le_bytes());
        out.extend_from_slice(&self.params.integration_step.to_le_bytes());
        for tau in &self.inputs.tug_tau {
            for x in tau {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        for x in &self.inputs.tension_cmd {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out.push(u8::from(self.initializing));
        match &self.loaded {
            None => out.push(0),
            Some(l) => {
                out.push(1);
                put_str(out, &l.origin);
                put_str(out, &l.text);
                let mut world = Vec::new();
                l.world.write_state(&mut world);
                put_bytes(out, &world);
            }
        }
    }

    fn deserialize_state(&mut self, _log: &Logger, bytes: &[u8]) -> Result<(), String> {
        let mut r = Reader { bytes, pos: 0 };
        if r.take(4)? != STATE_MAGIC {
            return Err("not a TowingPlant state (wrong magic)".to_owned());
        }
        let version = u16::from_le_bytes(r.array()?);
        if version != STATE_FORMAT_VERSION {
            return Err(format!(
                "TowingPlant state format version {version} is not supported (this build reads {STATE_FORMAT_VERSION})"
            ));
        }
        let params = Parameters {
            scenario: r.string()?,
            log_file: String::new(),
            log_scene_interval: self.params.log_scene_interval,
            hull_model: i32::from_le_bytes(r.array()?),
            towline_model: i32::from_le_bytes(r.array()?),
            integration_step: f64::from_le_bytes(r.array()?),
        };
        let mut inputs = WorldInputs::default();
        for tau in &mut inputs.tug_tau {
            for x in tau.iter_mut() {
                *x = f64::from_le_bytes(r.array()?);
            }
        }
        for x in &mut inputs.tension_cmd {
            *x = f64::from_le_bytes(r.array()?);
        }
        let initializing = r.take(1)?[0] != 0;
        let mut restored = Self {
            params: Parameters {
                // The log is the instance's own, not part of the state.
                log_file: self.params.log_file.clone(),
                ..params
            },
            inputs,
            resource_dir: self.resource_dir.clone(),
            initializing,
            loaded: None,
            start_time: self.start_time,
            log: self.log.clone(),
        };
        if r.take(1)?[0] == 1 {
            let origin = r.string()?;
            let text = r.string()?;
            let world_bytes = r.bytes()?;
            restored.params.validate()?;
            let ScenarioFile {
                origin,
                text,
                scenario,
            } = ScenarioFile::parse(origin, text)?;
            let config = restored.params.world_config(&scenario);
            let mut world = World::new(&scenario, config).map_err(|e| format!("{origin}: {e}"))?;
            world.read_state(world_bytes)?;
            let log_info = Arc::new(LogScenario::of(&scenario));
            restored.loaded = Some(Loaded {
                origin,
                text,
                world,
                log_info,
            });
        }
        if r.pos != bytes.len() {
            return Err(format!(
                "TowingPlant state has {} trailing bytes",
                bytes.len() - r.pos
            ));
        }
        *self = restored;
        Ok(())
    }
}

/// Real outputs read from the world.
fn output_real(w: &World, vr: u32) -> f64 {
    match vr {
        100..=125 => {
            let vessel = (vr - 100) / 10;
            let c = ((vr - 100) % 10) as usize;
            let state = match vessel {
                0 => w.ship(),
                1 => w.tug(0),
                _ => w.tug(1),
            };
            if c < 3 {
                state.eta[c]
            } else {
                state.nu[c - 3]
            }
        }
        300..=313 => {
            let line = w.towline(((vr - 300) / 10) as usize);
            match (vr - 300) % 10 {
                0 => line.length,
                1 => line.angle,
                _ => line.tension,
            }
        }
        _ => {
            let slot = ((vr - 1000) / 10) as usize;
            let o = w.obstacle(slot);
            match (vr - 1000) % 10 {
                0 => o.x,
                1 => o.y,
                2 => o.psi,
                3 => o.speed,
                4 => o.length,
                5 => o.width,
                _ => f64::NAN,
            }
        }
    }
}

fn put_str(out: &mut Vec<u8>, s: &str) {
    put_bytes(out, s.as_bytes());
}

fn put_bytes(out: &mut Vec<u8>, b: &[u8]) {
    out.extend_from_slice(&(b.len() as u64).to_le_bytes());
    out.extend_from_slice(b);
}

/// Bounds-checked little-endian reader for [`Plant::deserialize_state`].
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                format!(
                    "TowingPlant state is truncated: needs {n} more bytes at offset {}",
                    self.pos
                )
            })?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }

    fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = u64::from_le_bytes(self.array()?);
        let n = usize::try_from(n).map_err(|_| "TowingPlant state length overflows".to_owned())?;
        self.take(n)
    }

    fn string(&mut self) -> Result<String, String> {
        let b = self.bytes()?;
        String::from_utf8(b.to_vec())
            .map_err(|_| "TowingPlant state holds invalid UTF-8".to_owned())
    }
}

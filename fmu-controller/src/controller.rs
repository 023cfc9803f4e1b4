//! The controller model behind the FMI layer: parameters, inputs, outputs, and the
//! [`Controller`] of `towing-control` it forwards to.
//!
//! Life cycle: the scenario is read when the master enters initialization mode (as the
//! plant does), and again if `scenario` changes during initialization; every other
//! parameter is checked and the [`Controller`] (solvers, buffers) is built once at
//! `fmi2ExitInitializationMode`. A bad scenario or parameter is refused with `fmi2Error` and
//! a message naming the parameter (or file and field) and the reason.
//!
//! Timing: `fmi2DoStep(t, h)` first runs a control sample ([`Controller::sample`]) when `t`
//! has reached the next sample instant `startTime + k sample_time` (within 1 us, on the
//! layer's nanosecond clock), then sets the commands to
//! [`Controller::command_at`]`(t - t_sample, inputs)`: the tug thrusts with the inner loop
//! on the current velocities, the tensions held. The outputs after `fmi2DoStep(t, h)` are the
//! command for the plant's step starting at `t` (docs/interface.md, "Controller FMU").
//!
//! MCAP log (docs/logging.md): with `log_file` set, the file is created when initialization
//! ends and gets every topic at each control sample; terminate closes it (a failure is
//! `fmi2Error`), and `fmi2FreeInstance` closes it if terminate did not.
//!
//! FMU state: the solvers' warm starts and factorisations cannot be copied, so the FMU
//! declares `canGetAndSetFMUstate="false"`. The layer still clones the model on
//! `fmi2GetFMUstate`; a clone carries no controller, and an instance restored from one
//! refuses to step with a message saying why (never a silent cold start).

use crate::logging::{self, Sample};
use crate::variables::{self as vars, Tunables, NO_OBSTACLE_DISTANCE, REAL_PARAMETERS};
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, StepContext, StepOutcome};
use std::path::{Path, PathBuf};
use towing_control::{
    Architecture, AvoidanceScheme, Command, Controller, ControllerConfig, Measurement, SampleReport,
};
use towing_interface::ScenarioFile;
use towing_log::{LogOptions, RunInfo, SharedLog};
use towing_model::{HullModel, Scenario, MAX_OBSTACLES};
use towing_mpc::HORIZON;

/// Tolerance of the sample-instant test (ns): a communication point within 1 us before a
/// sample instant samples.
const SAMPLE_TOLERANCE_NS: i64 = 1_000;

const STATE_MAGIC: &[u8; 4] = b"TWCT";

/// Parameter values (FMI `parameter` variables).
#[derive(Debug, Clone, PartialEq)]
struct Parameters {
    scenario: String,
    log_file: String,
    hull_model: i32,
    architecture: i32,
    avoidance_scheme: i32,
    max_iterations: i32,
    prediction_horizon: i32,
    reals: [f64; REAL_PARAMETERS.len()],
}

impl Default for Parameters {
    fn default() -> Self {
        let defaults = Tunables::default();
        let ints = vars::integer_parameter_defaults();
        let int = |vr: u32| ints.iter().find(|(v, _)| *v == vr).map_or(0, |(_, s)| *s);
        Self {
            scenario: String::new(),
            log_file: String::new(),
            hull_model: int(vars::HULL_MODEL),
            architecture: int(vars::ARCHITECTURE),
            avoidance_scheme: int(vars::AVOIDANCE_SCHEME),
            max_iterations: int(vars::MAX_ITERATIONS),
            prediction_horizon: int(vars::PREDICTION_HORIZON),
            reals: std::array::from_fn(|i| (REAL_PARAMETERS[i].get)(&defaults)),
        }
    }
}

impl Parameters {
    /// The controller configuration for `scenario`: `ControllerConfig::new`'s defaults,
    /// overridden by every parameter, each checked on its own first.
    fn config(&self, scenario: Scenario) -> Result<ControllerConfig, String> {
        let hull = match self.hull_model {
            0 => scenario.world_config.hull_model,
            1 => HullModel::LinearDamping,
            2 => HullModel::NonlinearDamping,
            other => {
                return Err(format!(
                    "parameter `hull_model`: must be 0 (as the scenario says), 1 (linear damping) or 2 (nonlinear damping), got {other}"
                ))
            }
        };
        let architecture = Architecture::from_code(self.architecture).map_err(|e| e.to_string())?;
        let scheme =
            AvoidanceScheme::from_code(self.avoidance_scheme).map_err(|e| e.to_string())?;
        let max_iterations = usize::try_from(self.max_iterations)
            .ok()
            .filter(|&s| (1..=towing_mpc::admm::MAX_ITERATIONS).contains(&s))
            .ok_or_else(|| {
                format!(
                    "parameter `max_iterations`: must be in 1..={}, got {}",
                    towing_mpc::admm::MAX_ITERATIONS,
                    self.max_iterations
                )
            })?;
        if usize::try_from(self.prediction_horizon) != Ok(towing_mpc::HORIZON) {
            return Err(format!(
                "parameter `prediction_horizon`: this build is compiled for H_P = {} (Table 3), got {}",
                towing_mpc::HORIZON,
                self.prediction_horizon
            ));
        }
        for (p, &value) in REAL_PARAMETERS.iter().zip(&self.reals) {
            let ok = value.is_finite()
                && if p.exclusive {
                    value > p.min
                } else {
                    value >= p.min
                };
            if !ok {
                let unit = if p.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", p.unit)
                };
                return Err(format!(
                    "parameter `{}`: must be finite and {} {}{unit}, got {value}{unit}",
                    p.name,
                    if p.exclusive { ">" } else { ">=" },
                    p.min
                ));
            }
        }
        let mut config = ControllerConfig::new(scenario);
        config.hull = hull;
        config.architecture = architecture;
        config.scheme = scheme;
        let mut tunables = Tunables::of(&config);
        for (p, &value) in REAL_PARAMETERS.iter().zip(&self.reals) {
            (p.set)(&mut tunables, value);
        }
        tunables.admm.max_iterations = max_iterations;
        tunables.apply_to(&mut config);
        if config.ship.min_tension > config.ship.max_tension {
            return Err(format!(
                "parameter `min_tension`: must be <= max_tension = {} N, got {} N",
                config.ship.max_tension, config.ship.min_tension
            ));
        }
        Ok(config)
    }
}

/// The inputs: the plant's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Inputs {
    measurement: Measurement,
    /// Towline length, angle, tension (accepted, not used by the controller).
    towlines: [[f64; 3]; 2],
}

impl Inputs {
    fn real_mut(&mut self, vr: u32) -> Option<&mut f64> {
        let m = &mut self.measurement;
        match vr {
            100..=105 => Some(&mut m.ship[(vr - 100) as usize]),
            110..=115 => Some(&mut m.tugs[0][(vr - 110) as usize]),
            120..=125 => Some(&mut m.tugs[1][(vr - 120) as usize]),
            300..=302 => Some(&mut self.towlines[0][(vr - 300) as usize]),
            310..=312 => Some(&mut self.towlines[1][(vr - 310) as usize]),
            1000..=1079 => {
                let slot = ((vr - 1000) / 10) as usize;
                let o = &mut m.obstacles[slot];
                match (vr - 1000) % 10 {
                    0 => Some(&mut o.x),
                    1 => Some(&mut o.y),
                    2 => Some(&mut o.psi),
                    3 => Some(&mut o.speed),
                    4 => Some(&mut o.length),
                    5 => Some(&mut o.width),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    fn real(&self, vr: u32) -> Option<f64> {
        let m = &self.measurement;
        match vr {
            100..=105 => Some(m.ship[(vr - 100) as usize]),
            110..=115 => Some(m.tugs[0][(vr - 110) as usize]),
            120..=125 => Some(m.tugs[1][(vr - 120) as usize]),
            300..=302 => Some(self.towlines[0][(vr - 300) as usize]),
            310..=312 => Some(self.towlines[1][(vr - 310) as usize]),
            1000..=1079 => {
                let o = &m.obstacles[((vr - 1000) / 10) as usize];
                match (vr - 1000) % 10 {
                    0 => Some(o.x),
                    1 => Some(o.y),
                    2 => Some(o.psi),
                    3 => Some(o.speed),
                    4 => Some(o.length),
                    5 => Some(o.width),
                    _ => None,
                }
            }
            _ => None,
        }
    }
}

/// The outputs: commands and diagnostics, holding their start values until the first step.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Outputs {
    command: Command,
    iterations: i32,
    converged: bool,
    r_pri: [f64; 2],
    r_dual: [f64; 2],
    compute_time: f64,
    fallbacks: i32,
    samples: i32,
    reference: [f64; 3],
    active_waypoint: i32,
    altered: bool,
    d_ob: f64,
    angle_desired: [f64; 2],
    situation: [i32; MAX_OBSTACLES],
    role: [i32; MAX_OBSTACLES],
    /// `[h][vessel][axis]`.
    prediction: [[[f64; 2]; 3]; HORIZON],
}

impl Default for Outputs {
    fn default() -> Self {
        Self {
            command: Command::default(),
            iterations: 0,
            converged: false,
            r_pri: [0.0; 2],
            r_dual: [0.0; 2],
            compute_time: 0.0,
            fallbacks: 0,
            samples: 0,
            reference: [0.0; 3],
            active_waypoint: 0,
            altered: false,
            d_ob: NO_OBSTACLE_DISTANCE,
            angle_desired: [0.0; 2],
            situation: [-1; MAX_OBSTACLES],
            role: [0; MAX_OBSTACLES],
            prediction: [[[0.0; 2]; 3]; HORIZON],
        }
    }
}

fn saturating_i32<T: TryInto<i32>>(x: T) -> i32 {
    x.try_into().unwrap_or(i32::MAX)
}

impl Outputs {
    fn record(&mut self, r: &SampleReport) {
        self.iterations = saturating_i32(r.iterations);
        self.converged = r.converged;
        self.r_pri = r.r_pri;
        self.r_dual = r.r_dual;
        self.compute_time = r.compute_time;
        self.fallbacks = saturating_i32(r.fallbacks);
        self.samples = self.samples.saturating_add(1);
        self.reference = r.reference;
        self.active_waypoint = saturating_i32(r.guidance.active_waypoint);
        self.altered = r.guidance.altered;
        self.d_ob = if r.guidance.d_ob.is_finite() {
            r.guidance.d_ob.min(NO_OBSTACLE_DISTANCE)
        } else {
            NO_OBSTACLE_DISTANCE
        };
        self.angle_desired = r.desired_angle;
        self.situation = r.situation;
        self.role = r.role;
        for h in 0..HORIZON {
            let states = [
                &r.prediction.ship[h],
                &r.prediction.tugs[0][h],
                &r.prediction.tugs[1][h],
            ];
            for (vessel, s) in states.iter().enumerate() {
                self.prediction[h][vessel] = [s[0], s[1]];
            }
        }
    }
}

/// Sample clock on the layer's nanosecond time since the start time.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Clock {
    start_time: f64,
    sample_ns: i64,
    next_sample_ns: i64,
    last_sample_ns: i64,
}

/// The controller FMU's model.
#[derive(Debug)]
pub struct ControllerFmu {
    params: Parameters,
    inputs: Inputs,
    outputs: Outputs,
    resource_dir: Option<PathBuf>,
    /// Set once initialization mode was entered: a new `scenario` is then read at once.
    initializing: bool,
    scenario: Option<Scenario>,
    controller: Option<Controller>,
    clock: Clock,
    /// This value is a copy made by `fmi2GetFMUstate` of an initialized instance: it has
    /// no controller and refuses to step.
    copied_without_controller: bool,
    /// The scenario text as loaded (for the log's attachment).
    scenario_text: String,
    /// The MCAP log, open from the end of initialization while `log_file` is set (shared
    /// with copies).
    log: SharedLog,
}

impl Clone for ControllerFmu {
    /// Copies everything but the [`Controller`], whose solvers cannot be copied (module
    /// docs): the copy refuses to step.
    fn clone(&self) -> Self {
        Self {
            params: self.params.clone(),
            inputs: self.inputs,
            outputs: self.outputs,
            resource_dir: self.resource_dir.clone(),
            initializing: self.initializing,
            scenario: self.scenario.clone(),
            controller: None,
            clock: self.clock,
            copied_without_controller: self.controller.is_some() || self.copied_without_controller,
            scenario_text: self.scenario_text.clone(),
            log: self.log.clone(),
        }
    }
}

impl ControllerFmu {
    /// Reads the scenario named by the `scenario` parameter (or the bundled one).
    fn load(&mut self, log: &Logger) -> Result<(), String> {
        let ScenarioFile {
            origin,
            scenario,
            text,
        } = ScenarioFile::load(&self.params.scenario, self.resource_dir.as_deref())?;
        log.info(
            "logEvents",
            &format!("scenario '{}' loaded from {origin}", scenario.name),
        );
        self.scenario = Some(scenario);
        self.scenario_text = text;
        Ok(())
    }

    /// Creates the log named by `log_file` (if any) and writes the run description.
    fn open_log(&mut self, log: &Logger) -> Result<(), String> {
        if self.params.log_file.is_empty() {
            return Ok(());
        }
        let guid = vars::DESCRIPTION.guid();
        let p = &self.params;
        let mut parameters = serde_json::Map::new();
        parameters.insert("scenario".into(), p.scenario.clone().into());
        parameters.insert("log_file".into(), p.log_file.clone().into());
        for (name, value) in [
            ("hull_model", p.hull_model),
            ("architecture", p.architecture),
            ("avoidance_scheme", p.avoidance_scheme),
            ("max_iterations", p.max_iterations),
            ("prediction_horizon", p.prediction_horizon),
        ] {
            parameters.insert(name.into(), value.into());
        }
        for (rp, &value) in REAL_PARAMETERS.iter().zip(&p.reals) {
            parameters.insert(rp.name.into(), value.into());
        }
        let info = RunInfo {
            unit: vars::MODEL_IDENTIFIER,
            guid: &guid,
            version: env!("CARGO_PKG_VERSION"),
            scenario: &p.scenario,
            scenario_name: self.scenario.as_ref().map_or("", |s| s.name.as_str()),
            start_time: self.clock.start_time,
            parameters: serde_json::Value::Object(parameters),
            scenario_text: &self.scenario_text,
            ..RunInfo::default()
        };
        self.log = SharedLog::open(
            &p.log_file,
            LogOptions::default(),
            &info,
            logging::register_topics,
        )
        .map_err(|e| format!("parameter `log_file`: {e}"))?;
        log.info(
            "logEvents",
            &format!("MCAP log {} created", self.params.log_file),
        );
        Ok(())
    }

    fn real_parameter(&self, vr: u32) -> Option<f64> {
        vars::real_parameter_index(vr).map(|i| self.params.reals[i])
    }

    fn output_real(&self, vr: u32) -> Option<f64> {
        let o = &self.outputs;
        Some(match vr {
            200..=202 => o.command.tug_thrust[0][(vr - 200) as usize],
            210..=212 => o.command.tug_thrust[1][(vr - 210) as usize],
            220 | 221 => o.command.tension[(vr - 220) as usize],
            3002 | 3003 => o.r_pri[(vr - 3002) as usize],
            3004 | 3005 => o.r_dual[(vr - 3004) as usize],
            vars::COMPUTE_TIME => o.compute_time,
            3020..=3022 => o.reference[(vr - 3020) as usize],
            vars::D_OB => o.d_ob,
            3040 | 3041 => o.angle_desired[(vr - 3040) as usize],
            3200..=3299 => {
                let h = ((vr - 3200) / 10) as usize;
                let j = ((vr - 3200) % 10) as usize;
                *o.prediction.get(h)?.get(j / 2)?.get(j % 2)?
            }
            _ => return None,
        })
    }
}

impl Fmi2Model for ControllerFmu {
    fn description() -> &'static fmi2_slave::description::ModelDescription {
        &vars::DESCRIPTION
    }

    fn instantiate(ctx: &InstanceContext<'_>) -> Result<Self, String> {
        Ok(Self {
            params: Parameters::default(),
            inputs: Inputs::default(),
            outputs: Outputs::default(),
            resource_dir: ctx.resource_dir.map(Path::to_path_buf),
            initializing: false,
            scenario: None,
            controller: None,
            clock: Clock::default(),
            copied_without_controller: false,
            scenario_text: String::new(),
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
        self.clock.start_time = start_time;
        Ok(())
    }

    fn enter_initialization_mode(&mut self, log: &Logger) -> Result<(), String> {
        self.initializing = true;
        self.load(log)
    }

    fn exit_initialization_mode(&mut self, log: &Logger) -> Result<(), String> {
        self.initializing = false;
        let scenario = self
            .scenario
            .clone()
            .ok_or_else(|| "no scenario is loaded".to_owned())?;
        let config = self.params.config(scenario)?;
        let sample_time = config.prediction.sample_time;
        let controller = Controller::new(config).map_err(|e| e.to_string())?;
        // sample_time > 0 and finite (checked); at least 1 ns.
        let sample_ns = ((sample_time * 1e9).round() as i64).max(1);
        self.clock = Clock {
            start_time: self.clock.start_time,
            sample_ns,
            next_sample_ns: 0,
            last_sample_ns: 0,
        };
        self.outputs = Outputs::default();
        // Until the first sample the outputs hold the command the controller starts
        // from (the lines at their pretension, no thrust), so the first sample's rate
        // bound is measured from what the plant was given.
        let start = controller.applied();
        self.outputs.command.tension = [start.ship[0], start.ship[1]];
        self.outputs.command.tug_thrust = start.tugs;
        self.controller = Some(controller);
        log.info(
            "logEvents",
            &format!(
                "controller built: architecture {}, avoidance scheme {}, sample time {sample_time} s",
                self.params.architecture, self.params.avoidance_scheme
            ),
        );
        self.open_log(log)
    }

    fn get_real(&self, vr: u32) -> f64 {
        self.real_parameter(vr)
            .or_else(|| self.inputs.real(vr))
            .or_else(|| self.output_real(vr))
            .unwrap_or(f64::NAN)
    }

    fn set_real(&mut self, _log: &Logger, vr: u32, value: f64) -> Result<(), String> {
        let name = || {
            vars::DESCRIPTION
                .find(fmi2_slave::ValueType::Real, vr)
                .map_or_else(|| format!("vr {vr}"), |v| v.name.clone())
        };
        if !value.is_finite() {
            return Err(format!("input `{}` is not finite ({value})", name()));
        }
        if let Some(i) = vars::real_parameter_index(vr) {
            self.params.reals[i] = value;
            return Ok(());
        }
        match self.inputs.real_mut(vr) {
            Some(x) => {
                *x = value;
                Ok(())
            }
            None => Err(format!("value reference {vr} is not a settable Real")),
        }
    }

    fn get_integer(&self, vr: u32) -> i32 {
        let o = &self.outputs;
        match vr {
            vars::HULL_MODEL => self.params.hull_model,
            vars::ARCHITECTURE => self.params.architecture,
            vars::AVOIDANCE_SCHEME => self.params.avoidance_scheme,
            vars::MAX_ITERATIONS => self.params.max_iterations,
            vars::PREDICTION_HORIZON => self.params.prediction_horizon,
            vars::ADMM_ITERATIONS => o.iterations,
            vars::FALLBACKS => o.fallbacks,
            vars::SAMPLES => o.samples,
            vars::ACTIVE_WAYPOINT => o.active_waypoint,
            1000..=1079 => self.inputs.measurement.obstacles[((vr - 1000) / 10) as usize].kind,
            3100..=3179 => {
                let slot = ((vr - 3100) / 10) as usize;
                match (vr - 3100) % 10 {
                    0 => o.situation[slot],
                    _ => o.role[slot],
                }
            }
            _ => 0,
        }
    }

    fn set_integer(&mut self, _log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        match vr {
            vars::HULL_MODEL => self.params.hull_model = value,
            vars::ARCHITECTURE => self.params.architecture = value,
            vars::AVOIDANCE_SCHEME => self.params.avoidance_scheme = value,
            vars::MAX_ITERATIONS => self.params.max_iterations = value,
            vars::PREDICTION_HORIZON => self.params.prediction_horizon = value,
            1000..=1079 if (vr - 1000) % 10 == vars::OBSTACLE_KIND => {
                self.inputs.measurement.obstacles[((vr - 1000) / 10) as usize].kind = value;
            }
            _ => return Err(format!("value reference {vr} is not a settable Integer")),
        }
        Ok(())
    }

    fn get_boolean(&self, vr: u32) -> bool {
        match vr {
            vars::ADMM_CONVERGED => self.outputs.converged,
            vars::ALTERED => self.outputs.altered,
            _ => false,
        }
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
                if self.initializing {
                    if let Err(e) = self.load(log) {
                        self.params.scenario = previous;
                        return Err(e);
                    }
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
        let Some(controller) = self.controller.as_mut() else {
            return StepOutcome::Error(if self.copied_without_controller {
                "this instance was restored from an FMU state, which TowingController does not support \
                 (canGetAndSetFMUstate=\"false\": the solvers' warm starts and factorisations cannot be copied); \
                 re-instantiate or fmi2Reset and initialize again"
                    .to_owned()
            } else {
                "the controller is not built (initialization did not complete)".to_owned()
            });
        };
        // The layer's clock is whole nanoseconds since the start time; recover them.
        let now_ns = ((step.current_time - self.clock.start_time) * 1e9).round() as i64;
        let mut outcome = StepOutcome::Ok;
        let mut sampled = None;
        if now_ns + SAMPLE_TOLERANCE_NS >= self.clock.next_sample_ns {
            match controller.sample(&self.inputs.measurement) {
                Ok(report) => {
                    if self.log.is_active() {
                        sampled = Some(report);
                    }
                    self.outputs.record(&report);
                    self.clock.last_sample_ns = now_ns;
                    while self.clock.next_sample_ns <= now_ns + SAMPLE_TOLERANCE_NS {
                        self.clock.next_sample_ns += self.clock.sample_ns;
                    }
                    if let Some(reason) = report.fallback {
                        outcome = StepOutcome::Warning(format!(
                            "fallback: {reason} (sample at t = {} s; the previous plan, shifted, is applied)",
                            step.current_time
                        ));
                    }
                }
                Err(e) => {
                    return StepOutcome::Error(format!(
                        "sample at t = {} s refused: {e}",
                        step.current_time
                    ))
                }
            }
        }
        let elapsed = (now_ns - self.clock.last_sample_ns) as f64 * 1e-9;
        match controller.command_at(elapsed, &self.inputs.measurement) {
            Ok(command) => self.outputs.command = command,
            Err(e) => {
                return StepOutcome::Error(format!(
                    "command at t = {} s refused: {e}",
                    step.current_time
                ))
            }
        }
        if let Some(report) = sampled {
            let warning = match &outcome {
                StepOutcome::Warning(m) => Some(m.clone()),
                _ => None,
            };
            let sample = Sample {
                t: step.current_time,
                report,
                measurement: self.inputs.measurement,
                command: self.outputs.command,
                d_ob: self.outputs.d_ob,
                samples: u64::try_from(self.outputs.samples).unwrap_or(0),
                architecture: self.params.architecture,
                scheme: self.params.avoidance_scheme,
                scheme_alters: AvoidanceScheme::from_code(self.params.avoidance_scheme)
                    .is_ok_and(AvoidanceScheme::alters),
                warning,
            };
            let failed = self
                .log
                .batch(Box::new(move |w| logging::write_sample(w, &sample)));
            if let Some(failed) = failed {
                outcome = match outcome {
                    StepOutcome::Warning(m) => StepOutcome::Warning(format!("{m}; {failed}")),
                    _ => StepOutcome::Warning(failed),
                };
            }
        }
        outcome
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

    /// Writes only a marker: the state is not serialisable (`canSerializeFMUstate="false"`),
    /// and [`deserialize_state`](Self::deserialize_state) refuses every input.
    fn serialize_state(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(STATE_MAGIC);
    }

    fn deserialize_state(&mut self, _log: &Logger, _bytes: &[u8]) -> Result<(), String> {
        Err(
            "TowingController does not support FMU state serialization (canSerializeFMUstate=\"false\"): \
             the solvers' warm starts and factorisations are not serialisable"
                .to_owned(),
        )
    }
}

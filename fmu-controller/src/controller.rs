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
//! Loading the scenario and the log's life cycle are `towing-interface`'s [`RunSession`],
//! which the plant uses too.
//!
//! FMU state: the solvers' warm starts and factorisations cannot be copied, so the FMU
//! declares `canGetAndSetFMUstate="false"`. The layer still clones the model on
//! `fmi2GetFMUstate`; a clone carries no controller, and an instance restored from one
//! refuses to step with a message saying why (never a silent cold start).

use crate::diagnostics::Outputs;
use crate::logging::{self, Sample};
use crate::variables::{self as vars, ControllerVariable as V, Tunables, REAL_PARAMETERS};
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, StepContext, StepOutcome, ValueType};
use towing_control::{Architecture, AvoidanceScheme, Controller, ControllerConfig, Measurement};
use towing_interface::codec::{
    obstacle_kind_code, obstacle_kind_from_code, ContractVariable, ObstacleField, TowlineField,
    Vessel,
};
use towing_interface::{LogHeader, RunSession};
use towing_model::{HullModel, Scenario};

/// Tolerance of the sample-instant test (ns): a communication point within 1 us before a
/// sample instant samples.
const SAMPLE_TOLERANCE_NS: i64 = 1_000;

const STATE_MAGIC: &[u8; 4] = b"TWCT";

/// Parameter values (FMI `parameter` variables).
#[derive(Debug, Clone, PartialEq)]
struct Parameters {
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
    /// The vessel state array of `vessel`: `[x, y, psi, u, v, r]`.
    fn vessel_mut(&mut self, vessel: Vessel) -> &mut [f64; 6] {
        let m = &mut self.measurement;
        match vessel {
            Vessel::Ship => &mut m.ship,
            Vessel::Tug1 => &mut m.tugs[0],
            Vessel::Tug2 => &mut m.tugs[1],
        }
    }

    /// The Real input `c`, to write; `None` when `c` is not a Real input.
    fn real_mut(&mut self, c: ContractVariable) -> Option<&mut f64> {
        match c {
            ContractVariable::VesselState(vessel, component) => {
                Some(&mut self.vessel_mut(vessel)[component.index()])
            }
            ContractVariable::Towline(line, field) => {
                let [length, angle, tension] = &mut self.towlines[line.index()];
                match field {
                    TowlineField::Length => Some(length),
                    TowlineField::Angle => Some(angle),
                    TowlineField::Tension => Some(tension),
                    TowlineField::Slack => None,
                }
            }
            ContractVariable::Obstacle(slot, field) => {
                field.of_mut(&mut self.measurement.obstacles[slot.index()])
            }
            _ => None,
        }
    }

    /// The Real input `c`; `None` when `c` is not a Real input.
    fn real(&self, c: ContractVariable) -> Option<f64> {
        let m = &self.measurement;
        match c {
            ContractVariable::VesselState(vessel, component) => {
                let state = match vessel {
                    Vessel::Ship => &m.ship,
                    Vessel::Tug1 => &m.tugs[0],
                    Vessel::Tug2 => &m.tugs[1],
                };
                Some(state[component.index()])
            }
            ContractVariable::Towline(line, field) => {
                let [length, angle, tension] = self.towlines[line.index()];
                match field {
                    TowlineField::Length => Some(length),
                    TowlineField::Angle => Some(angle),
                    TowlineField::Tension => Some(tension),
                    TowlineField::Slack => None,
                }
            }
            ContractVariable::Obstacle(slot, field) => field.of(&m.obstacles[slot.index()]),
            _ => None,
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
    /// Set once initialization mode was entered: a new `scenario` is then read at once.
    initializing: bool,
    /// `scenario`, `log_file`, the scenario as loaded and the MCAP log (open from the end
    /// of initialization while `log_file` is set; shared with copies).
    session: RunSession,
    controller: Option<Controller>,
    clock: Clock,
    /// This value is a copy made by `fmi2GetFMUstate` of an initialized instance: it has
    /// no controller and refuses to step.
    copied_without_controller: bool,
}

impl Clone for ControllerFmu {
    /// Copies everything but the [`Controller`], whose solvers cannot be copied (module
    /// docs): the copy refuses to step.
    fn clone(&self) -> Self {
        Self {
            params: self.params.clone(),
            inputs: self.inputs,
            outputs: self.outputs,
            initializing: self.initializing,
            session: self.session.clone(),
            controller: None,
            clock: self.clock,
            copied_without_controller: self.controller.is_some() || self.copied_without_controller,
        }
    }
}

impl ControllerFmu {
    /// Reads the scenario named by the `scenario` parameter (or the bundled one).
    fn load(&mut self, log: &Logger) -> Result<(), String> {
        self.session.load(|file| {
            log.info(
                "logEvents",
                &format!(
                    "scenario '{}' loaded from {}",
                    file.scenario.name, file.origin
                ),
            );
            Ok(())
        })
    }

    /// Creates the log named by `log_file` (if any) and writes the run description.
    fn open_log(&mut self, log: &Logger) -> Result<(), String> {
        let guid = vars::DESCRIPTION.guid();
        let p = &self.params;
        let mut parameters = serde_json::Map::new();
        parameters.insert("scenario".into(), self.session.scenario_parameter().into());
        parameters.insert("log_file".into(), self.session.log_file().into());
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
        let header = LogHeader {
            unit: vars::MODEL_IDENTIFIER,
            guid: &guid,
            version: env!("CARGO_PKG_VERSION"),
            start_time: self.clock.start_time,
            parameters: serde_json::Value::Object(parameters),
        };
        self.session.open_log(log, header, logging::register_topics)
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
            initializing: false,
            session: RunSession::new(ctx.resource_dir),
            controller: None,
            clock: Clock::default(),
            copied_without_controller: false,
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
            .session
            .scenario()
            .cloned()
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

    fn get_real(&self, vr: u32) -> Result<f64, String> {
        use ContractVariable as C;
        let o = &self.outputs;
        let variable = vars::VARIABLES.decode(ValueType::Real, vr)?;
        let value = match variable {
            V::RealParameter(i) => self.params.reals.get(i).copied(),
            V::Diagnostic(d) => d.get().real_in(o),
            V::Contract(C::TugForce(tug, c)) => Some(o.command.tug_thrust[tug.index()][c.index()]),
            V::Contract(C::TensionCmd(line)) => Some(o.command.tension[line.index()]),
            V::Contract(c) => self.inputs.real(c),
            _ => None,
        };
        value.ok_or_else(|| vars::VARIABLES.unhandled(ValueType::Real, variable, "get"))
    }

    fn set_real(&mut self, _log: &Logger, vr: u32, value: f64) -> Result<(), String> {
        let name = || {
            vars::DESCRIPTION
                .find(ValueType::Real, vr)
                .map_or_else(|| format!("vr {vr}"), |v| v.name.clone())
        };
        if !value.is_finite() {
            return Err(format!("input `{}` is not finite ({value})", name()));
        }
        let target = match vars::VARIABLES.decode(ValueType::Real, vr)? {
            V::RealParameter(i) => self.params.reals.get_mut(i),
            V::Contract(c) => self.inputs.real_mut(c),
            _ => None,
        };
        match target {
            Some(x) => {
                *x = value;
                Ok(())
            }
            None => Err(format!("value reference {vr} is not a settable Real")),
        }
    }

    fn get_integer(&self, vr: u32) -> Result<i32, String> {
        let p = &self.params;
        let variable = vars::VARIABLES.decode(ValueType::Integer, vr)?;
        let value = match variable {
            V::HullModel => Some(p.hull_model),
            V::Architecture => Some(p.architecture),
            V::AvoidanceScheme => Some(p.avoidance_scheme),
            V::MaxIterations => Some(p.max_iterations),
            V::PredictionHorizon => Some(p.prediction_horizon),
            V::Diagnostic(d) => d.get().integer_in(&self.outputs),
            V::Contract(ContractVariable::Obstacle(slot, ObstacleField::Kind)) => Some(
                obstacle_kind_code(self.inputs.measurement.obstacles[slot.index()].kind),
            ),
            _ => None,
        };
        value.ok_or_else(|| vars::VARIABLES.unhandled(ValueType::Integer, variable, "get"))
    }

    fn set_integer(&mut self, _log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        let p = &mut self.params;
        match vars::VARIABLES.decode(ValueType::Integer, vr)? {
            V::HullModel => p.hull_model = value,
            V::Architecture => p.architecture = value,
            V::AvoidanceScheme => p.avoidance_scheme = value,
            V::MaxIterations => p.max_iterations = value,
            V::PredictionHorizon => p.prediction_horizon = value,
            V::Contract(ContractVariable::Obstacle(slot, ObstacleField::Kind)) => {
                self.inputs.measurement.obstacles[slot.index()].kind =
                    obstacle_kind_from_code(value)?;
            }
            _ => return Err(format!("value reference {vr} is not a settable Integer")),
        }
        Ok(())
    }

    fn get_boolean(&self, vr: u32) -> Result<bool, String> {
        let variable = vars::VARIABLES.decode(ValueType::Boolean, vr)?;
        let value = match variable {
            V::Diagnostic(d) => d.get().boolean_in(&self.outputs),
            _ => None,
        };
        value.ok_or_else(|| vars::VARIABLES.unhandled(ValueType::Boolean, variable, "get"))
    }

    fn set_boolean(&mut self, _log: &Logger, vr: u32, _value: bool) -> Result<(), String> {
        vars::VARIABLES.decode(ValueType::Boolean, vr)?;
        Err(format!("value reference {vr} is not a settable Boolean"))
    }

    fn get_string(&self, vr: u32) -> Result<String, String> {
        match vars::VARIABLES.decode(ValueType::String, vr)? {
            V::Contract(ContractVariable::Scenario) => {
                Ok(self.session.scenario_parameter().to_owned())
            }
            V::Contract(ContractVariable::LogFile) => Ok(self.session.log_file().to_owned()),
            other => Err(vars::VARIABLES.unhandled(ValueType::String, other, "get")),
        }
    }

    fn set_string(&mut self, log: &Logger, vr: u32, value: &str) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::String, vr)? {
            V::Contract(ContractVariable::Scenario) => {
                let previous = self.session.replace_scenario_parameter(value);
                if self.initializing {
                    if let Err(e) = self.load(log) {
                        self.session.replace_scenario_parameter(&previous);
                        return Err(e);
                    }
                }
                Ok(())
            }
            V::Contract(ContractVariable::LogFile) => {
                self.session.set_log_file(value);
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
                    if self.session.log().is_active() {
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
                .session
                .log()
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
        self.session.terminate()
    }

    fn release(&mut self, log: &Logger) {
        self.session.release(log);
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

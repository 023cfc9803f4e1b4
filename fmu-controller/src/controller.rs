//! The controller model behind the FMI layer: parameters, inputs, outputs, and the
//! [`Controller`] of `towing-control` it forwards to.
//!
//! Life cycle: the scenario is read when the master enters initialization mode (as the
//! plant does), and again if `scenario` changes during initialization. A parameter
//! (the registry's, [`towing_control::params`]) is checked against its range when it is
//! set, and the rules between parameters when the [`Controller`] (solvers, buffers) is
//! built at `fmi2ExitInitializationMode`: the same checks and messages as the Rust API's.
//! A bad scenario or parameter is refused with `fmi2Error` and a message naming the
//! parameter (or file and field) and the reason.
//!
//! Timing: `fmi2DoStep(t, h)` is [`Controller::step`]`(t, inputs)`, which owns the sample
//! clock: a control sample when `t` has reached the next sample instant
//! `startTime + k mpc.sample_time` (within 1 us, on a nanosecond clock), then the commands:
//! the tug thrusts with the inner loop on the current velocities, the tensions held. The
//! outputs after `fmi2DoStep(t, h)` are the command for the plant's step starting at `t`
//! (docs/interface.md, "Controller FMU").
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
use crate::variables::{self as vars, ControllerVariable as V};
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, StepContext, StepOutcome, ValueType};
use towing_control::params::{Value, PARAMETERS};
use towing_control::{
    ConfigError, Controller, ControllerConfig, Measurement, SampleReport, Tuning,
};
use towing_interface::codec::{
    obstacle_kind_code, obstacle_kind_from_code, ContractVariable, ObstacleField, TowlineField,
    Vessel,
};
use towing_interface::{parameters, LogHeader, RunSession};

const STATE_MAGIC: &[u8; 4] = b"TWCT";

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

/// The controller FMU's model.
#[derive(Debug)]
pub struct ControllerFmu {
    /// The parameters' values (the registry's, [`towing_control::params`]).
    params: Tuning,
    inputs: Inputs,
    outputs: Outputs,
    /// Set once initialization mode was entered: a new `scenario` is then read at once.
    initializing: bool,
    /// `scenario`, `log_file`, the scenario as loaded and the MCAP log (open from the end
    /// of initialization while `log_file` is set; shared with copies).
    session: RunSession,
    controller: Option<Controller>,
    /// `setupExperiment`'s start time: the first sample instant.
    start_time: f64,
    /// This value is a copy made by `fmi2GetFMUstate` of an initialized instance: it has
    /// no controller and refuses to step.
    copied_without_controller: bool,
}

impl Clone for ControllerFmu {
    /// Copies everything but the [`Controller`], whose solvers cannot be copied (module
    /// docs): the copy refuses to step.
    fn clone(&self) -> Self {
        Self {
            params: self.params,
            inputs: self.inputs,
            outputs: self.outputs,
            initializing: self.initializing,
            session: self.session.clone(),
            controller: None,
            start_time: self.start_time,
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
        let header = LogHeader {
            unit: vars::MODEL_IDENTIFIER,
            guid: &guid,
            version: env!("CARGO_PKG_VERSION"),
            start_time: self.start_time,
            parameters: parameters::values_json(PARAMETERS, &self.params),
        };
        self.session.open_log(log, header, logging::register_topics)
    }
}

impl ControllerFmu {
    /// Sets the registry's parameter `index`, checked against its range (the same
    /// check and message as [`ControllerConfig::validate`]).
    fn set_parameter(&mut self, index: usize, value: Value) -> Result<(), String> {
        let p = &PARAMETERS[index];
        let refused = |e| ConfigError::from(e).to_string();
        p.check(&value).map_err(refused)?;
        p.set(&mut self.params, value).map_err(refused)
    }
}

/// What a sample tells the master: a fallback, or the first sample of a run at rest (the
/// inputs describe no tow); `None` for a sample that solved, or that rests on.
fn sample_warning(report: &SampleReport, t: f64) -> Option<String> {
    if let Some(reason) = report.fallback {
        return Some(format!(
            "fallback: {reason} (sample at t = {t} s; the previous plan, shifted, is applied)"
        ));
    }
    report.rest.filter(|r| r.first).map(|r| {
        format!(
            "at rest: {} (sample at t = {t} s; the tensions go to the pretension and the angles \
             to zero, no thrust, until the inputs describe a tow)",
            r.overlap
        )
    })
}

impl Fmi2Model for ControllerFmu {
    fn description() -> &'static fmi2_slave::description::ModelDescription {
        &vars::DESCRIPTION
    }

    fn instantiate(ctx: &InstanceContext<'_>) -> Result<Self, String> {
        Ok(Self {
            params: Tuning::default(),
            inputs: Inputs::default(),
            outputs: Outputs::default(),
            initializing: false,
            session: RunSession::new(ctx.resource_dir),
            controller: None,
            start_time: 0.0,
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
        self.start_time = start_time;
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
        let sample_time = self.params.prediction.sample_time;
        let mut controller = Controller::new(ControllerConfig::with_tuning(scenario, self.params))
            .map_err(|e| e.to_string())?;
        controller.set_start_time(self.start_time);
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
                self.params.architecture.code(),
                self.params.scheme.code()
            ),
        );
        self.open_log(log)
    }

    fn get_real(&self, vr: u32) -> Result<f64, String> {
        use ContractVariable as C;
        let o = &self.outputs;
        let variable = vars::VARIABLES.decode(ValueType::Real, vr)?;
        let value = match variable {
            V::Parameter(i) => match PARAMETERS[i].get(&self.params) {
                Value::Real(v) => Some(v),
                _ => None,
            },
            V::Diagnostic(d) => d.get().real_in(o),
            V::Contract(C::TugForce(tug, c)) => Some(o.command.tug_thrust[tug.index()][c.index()]),
            V::Contract(C::TensionCmd(line)) => Some(o.command.tension[line.index()]),
            V::Contract(c) => self.inputs.real(c),
            V::Session(_) => None,
        };
        value.ok_or_else(|| vars::VARIABLES.unhandled(ValueType::Real, variable, "get"))
    }

    fn set_real(&mut self, _log: &Logger, vr: u32, value: f64) -> Result<(), String> {
        let target = match vars::VARIABLES.decode(ValueType::Real, vr)? {
            // The registry's check covers non-finite values, with its message.
            V::Parameter(i) => return self.set_parameter(i, Value::Real(value)),
            V::Contract(c) => self.inputs.real_mut(c),
            _ => None,
        };
        let Some(x) = target else {
            return Err(format!("value reference {vr} is not a settable Real"));
        };
        if !value.is_finite() {
            let name = vars::DESCRIPTION
                .find(ValueType::Real, vr)
                .map_or_else(|| format!("vr {vr}"), |v| v.name.clone());
            return Err(format!("input `{name}` is not finite ({value})"));
        }
        *x = value;
        Ok(())
    }

    fn get_integer(&self, vr: u32) -> Result<i32, String> {
        let variable = vars::VARIABLES.decode(ValueType::Integer, vr)?;
        let value = match variable {
            V::Parameter(i) => match PARAMETERS[i].get(&self.params) {
                Value::Integer(v) => Some(v),
                _ => None,
            },
            V::Diagnostic(d) => d.get().integer_in(&self.outputs),
            V::Contract(ContractVariable::Obstacle(slot, ObstacleField::Kind)) => Some(
                obstacle_kind_code(self.inputs.measurement.obstacles[slot.index()].kind),
            ),
            _ => None,
        };
        value.ok_or_else(|| vars::VARIABLES.unhandled(ValueType::Integer, variable, "get"))
    }

    fn set_integer(&mut self, _log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::Integer, vr)? {
            V::Parameter(i) => return self.set_parameter(i, Value::Integer(value)),
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
            V::Parameter(i) => match PARAMETERS[i].get(&self.params) {
                Value::Boolean(v) => Some(v),
                _ => None,
            },
            V::Diagnostic(d) => d.get().boolean_in(&self.outputs),
            _ => None,
        };
        value.ok_or_else(|| vars::VARIABLES.unhandled(ValueType::Boolean, variable, "get"))
    }

    fn set_boolean(&mut self, _log: &Logger, vr: u32, value: bool) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::Boolean, vr)? {
            V::Parameter(i) => self.set_parameter(i, Value::Boolean(value)),
            _ => Err(format!("value reference {vr} is not a settable Boolean")),
        }
    }

    fn get_string(&self, vr: u32) -> Result<String, String> {
        match vars::VARIABLES.decode(ValueType::String, vr)? {
            V::Session(i) => Ok(self.session.parameter(i)),
            other => Err(vars::VARIABLES.unhandled(ValueType::String, other, "get")),
        }
    }

    /// A session parameter; a new `scenario` during initialization is read at once (and
    /// undone when that fails).
    fn set_string(&mut self, log: &Logger, vr: u32, value: &str) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::String, vr)? {
            V::Session(i) => match self.session.set_parameter(i, value)? {
                Some(previous) if self.initializing => self.load(log).inspect_err(|_| {
                    self.session.replace_scenario_parameter(&previous);
                }),
                _ => Ok(()),
            },
            _ => Err(format!("value reference {vr} is not a settable String")),
        }
    }

    /// A fallback is logged as a warning (category `logStatusWarning`) and written to the
    /// MCAP log; it is `fmi2Warning` only with `fmi.warning_on_fallback` (masters such as
    /// fmusim and OMSimulator stop on any status above `fmi2OK`). The first sample at rest
    /// ([`towing_control::Rest`]) is logged the same way, and is `fmi2OK`.
    fn do_step(&mut self, log: &Logger, step: &StepContext) -> StepOutcome {
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
        let step_result = match controller.step(step.current_time, &self.inputs.measurement) {
            Ok(done) => done,
            Err(e) => return StepOutcome::Error(e.to_string()),
        };
        self.outputs.command = step_result.command;
        let mut outcome = StepOutcome::Ok;
        let mut sampled = None;
        let mut warning = None;
        if let Some(report) = step_result.sample {
            self.outputs.record(&report);
            warning = sample_warning(&report, step.current_time);
            if let Some(message) = &warning {
                if report.fallback.is_some() && self.params.warning_on_fallback {
                    outcome = StepOutcome::Warning(message.clone());
                } else {
                    log.warning(&format!("fmi2DoStep: {message}"));
                }
            }
            if self.session.log().is_active() {
                sampled = Some(report);
            }
        }
        if let Some(report) = sampled {
            let sample = Sample {
                t: step.current_time,
                report,
                measurement: self.inputs.measurement,
                command: self.outputs.command,
                d_ob: self.outputs.d_ob,
                samples: u64::try_from(self.outputs.samples).unwrap_or(0),
                architecture: self.params.architecture.code(),
                scheme: self.params.scheme.code(),
                scheme_alters: self.params.scheme.alters(),
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

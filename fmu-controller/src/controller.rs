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
//! FMU state (FMI 2.0 section 2.1.8; `canGetAndSetFMUstate`, `canSerializeFMUstate`): the
//! parameters, inputs, outputs, the scenario as loaded, the time and the controller's
//! [`ControllerState`] (guidance memory, plans, multipliers, warm starts, spare plan, the
//! inner loop's ramp, the sample clock). A copy for an FMU state carries that state, not
//! the solvers; `fmi2SetFMUstate` restores it into the instance's controller, rebuilt from
//! the state's configuration when that differs, and the next steps continue bit for bit.
//! The log, `log_file` and `run_id` stay the instance's.

use crate::diagnostics::Outputs;
use crate::logging::{self, Sample};
use crate::variables::{self as vars, ControllerVariable as V};
use fmi2_slave::codec::{put_header, put_value, Reader};
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, StepContext, StepOutcome, ValueType};
use serde::{Deserialize, Serialize};
use towing_control::params::{Value, PARAMETERS};
use towing_control::{
    ConfigError, Controller, ControllerConfig, ControllerState, Measurement, SampleReport, Tuning,
};
use towing_interface::codec::{
    obstacle_kind_code, obstacle_kind_from_code, ContractVariable, ObstacleField, TowlineField,
    Vessel,
};
use towing_interface::{parameters, LogHeader, RunSession, ScenarioFile};

const STATE_MAGIC: &[u8; 4] = b"TWCT";
/// Version of the controller's serialized state; bump on any change of [`SavedState`] or
/// of what it holds.
const STATE_FORMAT_VERSION: u16 = 1;
/// Names the controller's part in the messages of a refused state.
const STATE_OWNER: &str = "TowingController state";

/// The inputs: the plant's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
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

/// The controller of an instance, or of a copy kept for an FMU state.
#[derive(Debug)]
enum Core {
    /// Not built (before initialization ends).
    None,
    /// The instance's controller.
    Live(Box<Controller>),
    /// A copy's: the controller's state without its solvers (module docs).
    Saved(Box<ControllerState>),
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
    core: Core,
    /// `setupExperiment`'s start time: the first sample instant.
    start_time: f64,
    /// The end of the last step (the start time before the first).
    time: f64,
}

impl Clone for ControllerFmu {
    /// Copies everything; the controller as its [`ControllerState`] (the solvers are
    /// rebuilt when a copy is restored, [`Fmi2Model::restore_state`]).
    fn clone(&self) -> Self {
        let core = match &self.core {
            Core::None => Core::None,
            Core::Live(c) => Core::Saved(Box::new(c.snapshot())),
            Core::Saved(s) => Core::Saved(s.clone()),
        };
        self.with(self.session.clone(), core)
    }
}

impl ControllerFmu {
    /// A copy of everything but the session and the controller, which are given.
    fn with(&self, session: RunSession, core: Core) -> Self {
        Self {
            params: self.params,
            inputs: self.inputs,
            outputs: self.outputs,
            initializing: self.initializing,
            session,
            core,
            start_time: self.start_time,
            time: self.time,
        }
    }
}

/// The controller's part of a serialized FMU state (MessagePack, [`fmi2_slave::codec`]).
#[derive(Debug, Serialize, Deserialize)]
struct SavedState {
    start_time: f64,
    time: f64,
    scenario_parameter: String,
    parameters: Vec<Value>,
    inputs: Inputs,
    outputs: Outputs,
    initializing: bool,
    /// The scenario as loaded: origin and text.
    scenario: Option<(String, String)>,
    controller: Option<ControllerState>,
}

/// A controller of `params` for `scenario`, in the state `state`.
fn controller_in(
    params: Tuning,
    scenario: &ScenarioFile,
    state: &ControllerState,
) -> Result<Controller, String> {
    let config = ControllerConfig::with_tuning(scenario.scenario.clone(), params);
    let mut controller = Controller::new(config).map_err(|e| e.to_string())?;
    controller.restore(state)?;
    Ok(controller)
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
            core: Core::None,
            start_time: 0.0,
            time: 0.0,
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
        self.time = start_time;
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
        self.core = Core::Live(Box::new(controller));
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
        let controller = match &mut self.core {
            Core::Live(c) => c,
            Core::None => {
                return StepOutcome::Error(
                    "the controller is not built (initialization did not complete)".to_owned(),
                )
            }
            Core::Saved(_) => {
                return StepOutcome::Error(
                    "internal: a copy kept for an FMU state was stepped".to_owned(),
                )
            }
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
            sampled = Some(report);
        }
        self.time = step.current_time + step.step_size;
        // A logging failure is a warning (docs/interface.md, "MCAP log").
        let failed = self.session.log_step(|| {
            let report = sampled?;
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
            Some(Box::new(move |w| logging::write_sample(w, &sample)))
        });
        if let Some(failed) = failed {
            outcome = match outcome {
                StepOutcome::Warning(m) => StepOutcome::Warning(format!("{m}; {failed}")),
                _ => StepOutcome::Warning(failed),
            };
        }
        outcome
    }

    fn terminate(&mut self, _log: &Logger) -> Result<(), String> {
        self.session.terminate()
    }

    fn release(&mut self, log: &Logger) {
        self.session.release(log);
    }

    fn serialize_state(&self, out: &mut Vec<u8>) -> Result<(), String> {
        let controller = match &self.core {
            Core::None => None,
            Core::Live(c) => Some(c.snapshot()),
            Core::Saved(s) => Some((**s).clone()),
        };
        let saved = SavedState {
            start_time: self.start_time,
            time: self.time,
            scenario_parameter: self.session.scenario_parameter().to_owned(),
            parameters: parameters::values(PARAMETERS, &self.params),
            inputs: self.inputs,
            outputs: self.outputs,
            initializing: self.initializing,
            scenario: self
                .session
                .loaded()
                .map(|f| (f.origin.clone(), f.text.clone())),
            controller,
        };
        put_header(out, STATE_MAGIC, STATE_FORMAT_VERSION);
        put_value(out, &saved).map_err(|e| format!("{STATE_OWNER}: {e}"))
    }

    /// Reads the state and checks it completely: the controller is rebuilt from the
    /// state's parameters and scenario and restored (then dropped: the copy keeps the
    /// state, [`restore_state`](Self::restore_state) builds again).
    fn deserialize_state(&mut self, _log: &Logger, bytes: &[u8]) -> Result<(), String> {
        let mut r = Reader::new(bytes, STATE_OWNER);
        r.header(STATE_MAGIC, STATE_FORMAT_VERSION)?;
        let saved: SavedState = r.value("the controller state")?;
        r.finish()?;
        let owned = |e: String| format!("{STATE_OWNER}: {e}");
        let params = parameters::from_values(PARAMETERS, &saved.parameters).map_err(owned)?;
        let loaded = saved
            .scenario
            .map(|(origin, text)| ScenarioFile::parse(origin, text))
            .transpose()?;
        let core = match (saved.controller, &loaded) {
            (None, _) => Core::None,
            (Some(state), Some(file)) => {
                controller_in(params, file, &state).map_err(owned)?;
                Core::Saved(Box::new(state))
            }
            (Some(_), None) => {
                return Err(owned("a controller state without a scenario".to_owned()))
            }
        };
        let mut session = self.session.clone();
        session.restore(saved.scenario_parameter, loaded);
        *self = Self {
            params,
            inputs: saved.inputs,
            outputs: saved.outputs,
            initializing: saved.initializing,
            session,
            core,
            start_time: saved.start_time,
            time: saved.time,
        };
        Ok(())
    }

    /// Becomes `saved`, keeping the instance's log: the controller is restored from the
    /// copy's state into this instance's controller when both have the same parameters and
    /// scenario, else into one built anew (module docs).
    fn restore_state(&mut self, _log: &Logger, saved: &Self) -> Result<(), String> {
        let core = match (&saved.core, std::mem::replace(&mut self.core, Core::None)) {
            (Core::Saved(state), Core::Live(mut live))
                if self.params == saved.params
                    && self.session.loaded().map(|f| &f.text)
                        == saved.session.loaded().map(|f| &f.text) =>
            {
                let restored = live.restore(state);
                self.core = Core::Live(live);
                restored?;
                std::mem::replace(&mut self.core, Core::None)
            }
            (Core::Saved(state), previous) => {
                let file = saved.session.loaded();
                let built = file
                    .ok_or_else(|| "the FMU state has a controller but no scenario".to_owned())
                    .and_then(|f| controller_in(saved.params, f, state));
                match built {
                    Ok(c) => Core::Live(Box::new(c)),
                    Err(e) => {
                        self.core = previous;
                        return Err(e);
                    }
                }
            }
            (Core::None, _) => Core::None,
            (Core::Live(_), previous) => {
                self.core = previous;
                return Err("internal: an FMU state holds a live controller".to_owned());
            }
        };
        let mut session = std::mem::take(&mut self.session);
        session.restore_from(&saved.session);
        *self = saved.with(session, core);
        Ok(())
    }

    /// The end of the last step, once initialized.
    fn time(&self) -> Option<f64> {
        Some(self.time)
    }
}

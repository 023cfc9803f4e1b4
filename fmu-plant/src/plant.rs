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
//! not. The log is the instance's own: it is not part of the FMU state (`fmi2SetFMUstate`
//! keeps the instance's log, [`RunSession::restore_from`]), and the copies the layer keeps
//! for FMU states share it. Loading the scenario and the log's life cycle are
//! `towing-interface`'s [`RunSession`], which the controller uses too.

use crate::logging::{self, LogScenario, StepSnapshot};
use crate::outputs::{Groundings, OUTPUTS};
use crate::params::{PlantParams, PARAMETERS};
use crate::variables::{self as vars, PlantVariable};
use fmi2_slave::codec::{put_bytes, put_f64, put_header, put_str, put_value, Reader};
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, StepContext, StepOutcome, ValueType};
use std::sync::Arc;
use towing_interface::codec::{
    obstacle_kind_code, ContractVariable, ObstacleField, TowlineField, Vessel,
};
use towing_interface::{parameters, LogHeader, RunSession, ScenarioFile};
use towing_log::topics::Log;
use towing_log::writer::Batch;
use towing_model::registry::Value;
use towing_model::{ObstacleSlot, TowlineOutput, World, WorldInputs};

/// Version of [`Plant`]'s serialized state; bump on any layout change (3: the start time).
const STATE_FORMAT_VERSION: u16 = 3;
/// Names the plant's part in the messages of a refused state.
const STATE_OWNER: &str = "TowingPlant state";
const STATE_MAGIC: &[u8; 4] = b"TWPL";

/// What the plant builds from the loaded scenario: the world, and what the log needs from
/// the scenario.
#[derive(Debug, Clone)]
struct Built {
    world: World,
    /// Which hulls are aground ([`crate::outputs`]).
    groundings: Groundings,
    /// Shared with the log's writer thread.
    log_info: Arc<LogScenario>,
}

/// The towing plant: ship, two tugs, two towlines and traffic.
#[derive(Debug, Clone)]
pub struct Plant {
    /// The parameters' values (the registry's, [`crate::params`]).
    params: PlantParams,
    inputs: WorldInputs,
    /// Set once initialization mode was entered: parameter changes then reload at once.
    initializing: bool,
    /// `scenario`, `log_file`, the scenario as loaded and the MCAP log (open from the end
    /// of initialization while `log_file` is set).
    session: RunSession,
    /// The world of the loaded scenario.
    built: Option<Built>,
    /// `fmi2SetupExperiment`'s start time (s).
    start_time: f64,
}

impl Plant {
    /// Reads the scenario named by the `scenario` parameter (or the bundled one) and builds the world.
    fn load(&mut self, log: &Logger) -> Result<(), String> {
        let params = &self.params;
        let built = self.session.load(|file| {
            let scenario = &file.scenario;
            let world = World::new(scenario, params.world_config(scenario))
                .map_err(|e| format!("{}: {e}", file.origin))?;
            Ok(Built {
                groundings: Groundings::of(&world),
                world,
                log_info: Arc::new(LogScenario::of(scenario)),
            })
        })?;
        if let Some(file) = self.session.loaded() {
            log.info(
                "logEvents",
                &format!(
                    "scenario '{}' loaded from {} ({} obstacles)",
                    file.scenario.name,
                    file.origin,
                    file.scenario.obstacles.len()
                ),
            );
        }
        self.built = Some(built);
        Ok(())
    }

    /// Sets the registry's parameter `index`, checked against its range; during
    /// initialization the world is rebuilt with it (and the old value kept if that
    /// fails).
    fn set_parameter(&mut self, log: &Logger, index: usize, value: Value) -> Result<(), String> {
        let p = &PARAMETERS[index];
        p.check(&value)
            .map_err(|e| format!("parameter `{}`: {}", e.field, e.reason))?;
        let previous = self.params;
        p.set(&mut self.params, value)
            .map_err(|e| format!("parameter `{}`: {}", e.field, e.reason))?;
        self.reload_if_initializing(log)
            .inspect_err(|_| self.params = previous)
    }

    fn reload_if_initializing(&mut self, log: &Logger) -> Result<(), String> {
        if self.initializing {
            self.load(log)
        } else {
            Ok(())
        }
    }

    fn world(&self) -> Option<&World> {
        self.built.as_ref().map(|b| &b.world)
    }

    /// Creates the log named by `log_file` (if any) and writes the run description, the
    /// static scene and the state at the start time.
    fn open_log(&mut self, log: &Logger) -> Result<(), String> {
        let Some(built) = self.built.as_ref() else {
            return Ok(());
        };
        let t = self.start_time;
        let guid = vars::DESCRIPTION.guid();
        let header = LogHeader {
            unit: vars::MODEL_IDENTIFIER,
            guid: &guid,
            version: env!("CARGO_PKG_VERSION"),
            start_time: t,
            parameters: parameters::values_json(PARAMETERS, &self.params),
        };
        let inputs = &self.inputs;
        // Written before the log's own thread takes over.
        self.session.open_log(log, header, |writer| {
            logging::register_topics(writer)?;
            logging::write_static_scene(writer, t, &built.world, &built.log_info)?;
            let snap = StepSnapshot::capture(t, &built.world, inputs);
            logging::write_state(writer, &snap, &built.log_info, true)?;
            // A hull aground from the start: its episode begins now.
            for event in Groundings::default().update(&built.world) {
                logging::write_log_line(writer, t, Log::WARNING, &event.message(t))?;
            }
            Ok(())
        })
    }

    /// The messages of the state at the end `t` of the step that began at `t_prev`; the
    /// Foxglove topics only when the step crossed a multiple of `log_scene_interval`
    /// (counted from the start time).
    fn state_messages(&self, t_prev: f64, t: f64) -> Option<Batch> {
        let built = self.built.as_ref()?;
        let snap = StepSnapshot::capture(t, &built.world, &self.inputs);
        let info = Arc::clone(&built.log_info);
        let scene = logging::scene_due(
            self.params.log_scene_interval,
            t_prev - self.start_time,
            t - self.start_time,
        );
        Some(Box::new(move |w| {
            logging::write_state(w, &snap, &info, scene)
        }))
    }

    /// The message of a warning or error the plant reports, for `/plant/log`.
    fn line_message(t: f64, level: i32, message: &str) -> Batch {
        let message = message.to_owned();
        Box::new(move |w| logging::write_log_line(w, t, level, &message))
    }
}

impl Fmi2Model for Plant {
    fn description() -> &'static fmi2_slave::description::ModelDescription {
        &vars::DESCRIPTION
    }

    fn instantiate(ctx: &InstanceContext<'_>) -> Result<Self, String> {
        Ok(Self {
            params: PlantParams::default(),
            inputs: WorldInputs::default(),
            initializing: false,
            session: RunSession::new(ctx.resource_dir),
            built: None,
            start_time: 0.0,
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
        match self.built {
            Some(_) => self.open_log(log),
            None => Err("no scenario is loaded".to_owned()),
        }
    }

    fn get_real(&self, vr: u32) -> Result<f64, String> {
        use ContractVariable as C;
        Ok(match vars::VARIABLES.decode(ValueType::Real, vr)? {
            PlantVariable::Parameter(i) => match PARAMETERS[i].get(&self.params) {
                Value::Real(v) => v,
                _ => {
                    return Err(vars::VARIABLES.unhandled(
                        ValueType::Real,
                        PlantVariable::Parameter(i),
                        "get",
                    ))
                }
            },
            PlantVariable::Contract(C::TugForce(tug, c)) => {
                self.inputs.tug_tau[tug.index()][c.index()]
            }
            PlantVariable::Contract(C::TensionCmd(line)) => self.inputs.tension_cmd[line.index()],
            PlantVariable::Contract(c) => real_output(self.world(), c).ok_or_else(|| {
                vars::VARIABLES.unhandled(ValueType::Real, PlantVariable::Contract(c), "get")
            })?,
            other @ (PlantVariable::Session(_) | PlantVariable::Output(_)) => {
                return Err(vars::VARIABLES.unhandled(ValueType::Real, other, "get"))
            }
        })
    }

    fn set_real(&mut self, log: &Logger, vr: u32, value: f64) -> Result<(), String> {
        use ContractVariable as C;
        match vars::VARIABLES.decode(ValueType::Real, vr)? {
            PlantVariable::Parameter(i) => self.set_parameter(log, i, Value::Real(value)),
            PlantVariable::Contract(C::TugForce(tug, c)) => {
                self.inputs.tug_tau[tug.index()][c.index()] = value;
                Ok(())
            }
            PlantVariable::Contract(C::TensionCmd(line)) => {
                self.inputs.tension_cmd[line.index()] = value;
                Ok(())
            }
            _ => Err(format!("value reference {vr} is not a settable Real")),
        }
    }

    fn get_integer(&self, vr: u32) -> Result<i32, String> {
        use ContractVariable as C;
        Ok(match vars::VARIABLES.decode(ValueType::Integer, vr)? {
            PlantVariable::Parameter(i) => match PARAMETERS[i].get(&self.params) {
                Value::Integer(v) => v,
                _ => {
                    return Err(vars::VARIABLES.unhandled(
                        ValueType::Integer,
                        PlantVariable::Parameter(i),
                        "get",
                    ))
                }
            },
            PlantVariable::Contract(C::Obstacle(slot, ObstacleField::Kind)) => self
                .world()
                .map_or(0, |w| obstacle_kind_code(w.obstacle(slot.index()).kind)),
            other => return Err(vars::VARIABLES.unhandled(ValueType::Integer, other, "get")),
        })
    }

    fn set_integer(&mut self, log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::Integer, vr)? {
            PlantVariable::Parameter(i) => self.set_parameter(log, i, Value::Integer(value)),
            _ => Err(format!("value reference {vr} is not a settable Integer")),
        }
    }

    fn get_boolean(&self, vr: u32) -> Result<bool, String> {
        match vars::VARIABLES.decode(ValueType::Boolean, vr)? {
            PlantVariable::Parameter(i) => match PARAMETERS[i].get(&self.params) {
                Value::Boolean(v) => Ok(v),
                _ => Err(vars::VARIABLES.unhandled(
                    ValueType::Boolean,
                    PlantVariable::Parameter(i),
                    "get",
                )),
            },
            PlantVariable::Contract(ContractVariable::Towline(line, TowlineField::Slack)) => {
                Ok(self.world().is_none_or(|w| w.towline(line.index()).slack))
            }
            PlantVariable::Output(i) => Ok(self
                .built
                .as_ref()
                .is_some_and(|b| (OUTPUTS[i].get)(&b.groundings))),
            other => Err(vars::VARIABLES.unhandled(ValueType::Boolean, other, "get")),
        }
    }

    fn set_boolean(&mut self, log: &Logger, vr: u32, value: bool) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::Boolean, vr)? {
            PlantVariable::Parameter(i) => self.set_parameter(log, i, Value::Boolean(value)),
            _ => Err(format!("value reference {vr} is not a settable Boolean")),
        }
    }

    fn get_string(&self, vr: u32) -> Result<String, String> {
        match vars::VARIABLES.decode(ValueType::String, vr)? {
            PlantVariable::Session(i) => Ok(self.session.parameter(i)),
            other => Err(vars::VARIABLES.unhandled(ValueType::String, other, "get")),
        }
    }

    /// A session parameter; a new `scenario` during initialization rebuilds the world (and
    /// is undone when that fails).
    fn set_string(&mut self, log: &Logger, vr: u32, value: &str) -> Result<(), String> {
        match vars::VARIABLES.decode(ValueType::String, vr)? {
            PlantVariable::Session(i) => match self.session.set_parameter(i, value)? {
                Some(previous) => self.reload_if_initializing(log).inspect_err(|_| {
                    self.session.replace_scenario_parameter(&previous);
                }),
                None => Ok(()),
            },
            _ => Err(format!("value reference {vr} is not a settable String")),
        }
    }

    fn do_step(&mut self, _log: &Logger, step: &StepContext) -> StepOutcome {
        let Some(built) = self.built.as_mut() else {
            return StepOutcome::Error("no scenario is loaded".to_owned());
        };
        let mut groundings = Vec::new();
        let outcome = match built.world.step(&self.inputs, step.step_size) {
            Ok(()) => {
                groundings = built.groundings.update(&built.world);
                StepOutcome::Ok
            }
            Err(e) => StepOutcome::Discard(format!(
                "step from t = {} s by h = {} s refused: {e}; the state is left at t = {} s",
                step.current_time,
                step.step_size,
                built.world.time()
            )),
        };
        // A logging failure is a warning (docs/interface.md, "MCAP log").
        let t_end = step.current_time + step.step_size;
        let failed = self.session.log_step(|| match &outcome {
            StepOutcome::Ok | StepOutcome::Warning(_) => {
                let state = self.state_messages(step.current_time, t_end);
                let lines: Vec<Batch> = groundings
                    .iter()
                    .map(|g| Self::line_message(t_end, Log::WARNING, &g.message(t_end)))
                    .collect();
                if lines.is_empty() {
                    state
                } else {
                    Some(Box::new(move |w| {
                        if let Some(state) = state {
                            state(w)?;
                        }
                        lines.into_iter().try_for_each(|line| line(w))
                    }))
                }
            }
            StepOutcome::Discard(m) | StepOutcome::Error(m) => {
                Some(Self::line_message(step.current_time, Log::ERROR, m))
            }
        });
        match (failed, outcome) {
            (Some(warning), StepOutcome::Ok) => StepOutcome::Warning(warning),
            (Some(warning), StepOutcome::Warning(m)) => {
                StepOutcome::Warning(format!("{m}; {warning}"))
            }
            (Some(warning), StepOutcome::Discard(m)) => {
                StepOutcome::Discard(format!("{m}; {warning}"))
            }
            (Some(warning), StepOutcome::Error(m)) => StepOutcome::Error(format!("{m}; {warning}")),
            (None, outcome) => outcome,
        }
    }

    fn terminate(&mut self, _log: &Logger) -> Result<(), String> {
        self.session.terminate()
    }

    fn release(&mut self, log: &Logger) {
        self.session.release(log);
    }

    fn serialize_state(&self, out: &mut Vec<u8>) -> Result<(), String> {
        put_header(out, STATE_MAGIC, STATE_FORMAT_VERSION);
        put_f64(out, self.start_time);
        put_str(out, self.session.scenario_parameter());
        put_value(out, &parameters::values(PARAMETERS, &self.params))?;
        for x in self
            .inputs
            .tug_tau
            .iter()
            .flatten()
            .chain(&self.inputs.tension_cmd)
        {
            put_f64(out, *x);
        }
        out.push(u8::from(self.initializing));
        match (self.session.loaded(), &self.built) {
            (Some(file), Some(built)) => {
                out.push(1);
                put_str(out, &file.origin);
                put_str(out, &file.text);
                let mut world = Vec::new();
                built.world.write_state(&mut world);
                put_bytes(out, &world);
            }
            _ => out.push(0),
        }
        Ok(())
    }

    fn deserialize_state(&mut self, _log: &Logger, bytes: &[u8]) -> Result<(), String> {
        let mut r = Reader::new(bytes, STATE_OWNER);
        r.header(STATE_MAGIC, STATE_FORMAT_VERSION)?;
        let start_time = r.finite_f64("the start time")?;
        let scenario_parameter = r.string("the scenario parameter")?;
        let values: Vec<Value> = r.value("the parameters")?;
        let params = parameters::from_values(PARAMETERS, &values)
            .map_err(|e| format!("{STATE_OWNER}: {e}"))?;
        let mut inputs = WorldInputs::default();
        for x in inputs.tug_tau.iter_mut().flatten() {
            *x = r.finite_f64("a tug force input")?;
        }
        for x in &mut inputs.tension_cmd {
            *x = r.finite_f64("a tension command input")?;
        }
        let initializing = r.flag("the initialization flag")?;
        let mut restored = Self {
            params,
            inputs,
            initializing,
            // The log, `log_file` and the resources folder are the instance's own, not part
            // of the state.
            session: self.session.clone(),
            built: None,
            start_time,
        };
        let mut loaded = None;
        if r.flag("the loaded flag")? {
            let origin = r.string("the scenario origin")?;
            let text = r.string("the scenario text")?;
            let world_bytes = r.bytes("the world state")?;
            let file = ScenarioFile::parse(origin, text)?;
            let config = restored.params.world_config(&file.scenario);
            let mut world =
                World::new(&file.scenario, config).map_err(|e| format!("{}: {e}", file.origin))?;
            world.read_state(world_bytes)?;
            let log_info = Arc::new(LogScenario::of(&file.scenario));
            restored.built = Some(Built {
                groundings: Groundings::of(&world),
                world,
                log_info,
            });
            loaded = Some(file);
        }
        r.finish()?;
        restored.session.restore(scenario_parameter, loaded);
        *self = restored;
        Ok(())
    }

    fn restore_state(&mut self, _log: &Logger, saved: &Self) -> Result<(), String> {
        let mut session = std::mem::take(&mut self.session);
        session.restore_from(&saved.session);
        self.clone_from(saved);
        self.session = session;
        Ok(())
    }

    /// The start time plus the world's time (the sum of the steps taken), once a scenario
    /// is loaded.
    fn time(&self) -> Option<f64> {
        self.world().map(|w| self.start_time + w.time())
    }
}

/// The Real output `c` of the world (0 before a scenario is loaded); `None` when `c` is not
/// a Real output of the plant.
fn real_output(world: Option<&World>, c: ContractVariable) -> Option<f64> {
    let read = |f: &dyn Fn(&World) -> f64| Some(world.map_or(0.0, f));
    match c {
        ContractVariable::VesselState(vessel, component) => read(&|w| {
            let state = match vessel {
                Vessel::Ship => w.ship(),
                Vessel::Tug1 => w.tug(0),
                Vessel::Tug2 => w.tug(1),
            };
            component.of(state)
        }),
        ContractVariable::Towline(line, field) => {
            let value: fn(&TowlineOutput) -> f64 = match field {
                TowlineField::Length => |l| l.length,
                TowlineField::Angle => |l| l.angle,
                TowlineField::Tension => |l| l.tension,
                TowlineField::Slack => return None,
            };
            read(&|w| value(&w.towline(line.index())))
        }
        ContractVariable::Obstacle(slot, field) => {
            field.of(&ObstacleSlot::EMPTY)?;
            read(&|w| field.of(&w.obstacle(slot.index())).unwrap_or(f64::NAN))
        }
        _ => None,
    }
}

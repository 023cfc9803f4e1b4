//! Test model shared by the integration tests, and the `fmi2_slave::testing` harness bound to
//! it.
//!
//! Each test binary invokes `fmi2_slave::export_fmi2!(common::Lag)` at its root, so the 34
//! `fmi2*` functions exist as `crate::fmi2*`; [`exports`] collects them and the constructors
//! below instantiate [`Lag`] through them exactly as a master would.
#![allow(dead_code, clippy::unwrap_used)]

use std::ffi::CString;
use std::path::PathBuf;
use std::sync::LazyLock;

use fmi2_slave::testing::{Exports, Fmu, Msg};
use fmi2_slave::{
    BaseUnit, Causality, DefaultExperiment, EnumerationItem, Fmi2Model, Initial, InstanceContext,
    LogCategory, Logger, ModelDescription, SimpleType, StepContext, StepOutcome, UnitDefinition,
    Variability, Variable, VariableKind,
};

// ---- value references ------------------------------------------------------------------
pub const R_U: u32 = 1;
pub const R_Y: u32 = 2;
pub const R_T: u32 = 3;
pub const R_Y0: u32 = 4;
pub const R_RATE: u32 = 5;
pub const I_SUBSTEPS: u32 = 1;
pub const I_STEPS: u32 = 2;
pub const I_FAULT: u32 = 13;
pub const I_VERSION: u32 = 4;
/// The Enumeration parameter `method` (type `Method`: 1 euler, 2 heun), accessed as an
/// Integer (FMI 2.0 section 2.1.7).
pub const E_METHOD: u32 = 6;
pub const METHOD_EULER: i32 = 1;
pub const METHOD_HEUN: i32 = 2;
pub const B_ENABLED: u32 = 1;
pub const B_PANIC_NOW: u32 = 2;
pub const S_LABEL: u32 = 1;

/// Fault modes of input `fault_mode`: what the next `do_step` returns.
pub const FAULT_WARNING: i32 = 1;
pub const FAULT_DISCARD: i32 = 2;
pub const FAULT_ERROR: i32 = 3;
pub const FAULT_PANIC: i32 = 4;
/// Fault mode whose getter of `steps` refuses (a model error of a getter).
pub const FAULT_GET: i32 = 5;
/// Fault mode whose getter of the output `y` returns NaN (a model bug the layer catches).
pub const FAULT_NAN: i32 = 6;

pub static DESCRIPTION: LazyLock<ModelDescription> = LazyLock::new(|| {
    let mut log_categories = LogCategory::standard();
    log_categories.push(LogCategory::new("logEvents", "model events"));
    ModelDescription {
        model_name: "Lag".into(),
        model_identifier: "Lag".into(),
        description: "first-order lag y' = (u - y) / T, explicit Euler substeps".into(),
        author: "fmi2-slave tests".into(),
        version: "1.0".into(),
        generation_tool: "fmi2-slave".into(),
        units: vec![
            UnitDefinition::new(
                "s",
                BaseUnit {
                    s: 1,
                    ..BaseUnit::default()
                },
            ),
            UnitDefinition::new(
                "1/s",
                BaseUnit {
                    s: -1,
                    ..BaseUnit::default()
                },
            ),
        ],
        type_definitions: vec![SimpleType::enumeration(
            "Method",
            "",
            vec![
                EnumerationItem::new("euler", METHOD_EULER, "explicit Euler substeps"),
                EnumerationItem::new("heun", METHOD_HEUN, "Heun substeps (explicit trapezoidal)"),
            ],
        )],
        log_categories,
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 10.0,
            tolerance: None,
            step_size: 0.1,
        },
        variables: vec![
            Variable::real_input("u", R_U, "", 0.0, "input"),
            Variable::real_output("y", R_Y, "", "output").initial_depends_on(&[R_Y0]),
            Variable::real_parameter("T", R_T, "s", 1.0, Variability::Tunable, "time constant"),
            Variable::real_parameter("y0", R_Y0, "", 0.0, Variability::Fixed, "initial output"),
            Variable::real_calculated_parameter("rate", R_RATE, "1/s", Variability::Tunable, "1/T")
                .initial_depends_on(&[R_T]),
            Variable::integer_parameter(
                "substeps",
                I_SUBSTEPS,
                4,
                Variability::Fixed,
                "Euler substeps",
            ),
            Variable::integer_output("steps", I_STEPS, "accepted steps"),
            Variable::integer_input(
                "fault_mode",
                I_FAULT,
                0,
                "0 ok, 1 warning, 2 discard, 3 error, 4 panic, 5 getter of steps fails, 6 y reads NaN",
            ),
            Variable {
                name: "version".into(),
                value_reference: I_VERSION,
                description: "model version".into(),
                causality: Causality::Output,
                variability: Variability::Constant,
                initial: Some(Initial::Exact),
                kind: VariableKind::Integer {
                    declared_type: None,
                    start: Some(7),
                    min: None,
                    max: None,
                },
                output_dependencies: Some(vec![]),
                initial_dependencies: None,
            },
            Variable::boolean_parameter(
                "enabled",
                B_ENABLED,
                true,
                Variability::Tunable,
                "integrate",
            ),
            Variable::boolean_input("panic_now", B_PANIC_NOW, false, "panics when set to true"),
            Variable::string_parameter("label", S_LABEL, "lag", "free text"),
            Variable::enumeration_parameter(
                "method",
                E_METHOD,
                "Method",
                METHOD_EULER,
                Variability::Tunable,
                "integration method",
            ),
        ],
        can_get_and_set_fmu_state: true,
        can_serialize_fmu_state: true,
    }
});

/// The test model: a first-order lag y' = (u - y) / T with one variable of each kind.
pub type Lag = LagModel<false>;
/// The same model with an invalid description (an input with `initial`), and a different
/// Rust type (so a different type tag).
pub type BrokenLag = LagModel<true>;

pub static BROKEN_DESCRIPTION: LazyLock<ModelDescription> = LazyLock::new(|| {
    let mut md = DESCRIPTION.clone();
    md.variables[0].initial = Some(Initial::Exact);
    md
});

/// The model's refusal of a value reference it does not decode.
fn unknown(ty: &str, vr: u32) -> String {
    format!("unknown value reference {vr}: no {ty} variable of Lag has it")
}

#[derive(Debug, Clone, PartialEq)]
pub struct LagModel<const BROKEN: bool> {
    u: f64,
    y: f64,
    t_const: f64,
    y0: f64,
    substeps: i32,
    steps: i32,
    fault_mode: i32,
    enabled: bool,
    label: String,
    method: i32,
    resource_dir: Option<PathBuf>,
}

impl<const BROKEN: bool> Fmi2Model for LagModel<BROKEN> {
    fn description() -> &'static ModelDescription {
        if BROKEN {
            &BROKEN_DESCRIPTION
        } else {
            &DESCRIPTION
        }
    }

    fn instantiate(ctx: &InstanceContext<'_>) -> Result<Self, String> {
        if ctx.instance_name == "refuse" {
            return Err("the test model refuses the instance name 'refuse'".into());
        }
        ctx.logger.info(
            "logEvents",
            &format!("instantiated with resources at {:?}", ctx.resource_dir),
        );
        Ok(LagModel {
            u: 0.0,
            y: 0.0,
            t_const: 1.0,
            y0: 0.0,
            substeps: 4,
            steps: 0,
            fault_mode: 0,
            enabled: true,
            label: "lag".into(),
            method: METHOD_EULER,
            resource_dir: ctx.resource_dir.map(PathBuf::from),
        })
    }

    fn enter_initialization_mode(&mut self, log: &Logger) -> Result<(), String> {
        log.info("logEvents", "entering initialization mode");
        Ok(())
    }

    fn exit_initialization_mode(&mut self, _log: &Logger) -> Result<(), String> {
        self.y = self.y0;
        Ok(())
    }

    fn get_real(&self, vr: u32) -> Result<f64, String> {
        Ok(match vr {
            R_U => self.u,
            R_Y if self.fault_mode == FAULT_NAN => f64::NAN,
            R_Y => self.y,
            R_T => self.t_const,
            R_Y0 => self.y0,
            R_RATE => 1.0 / self.t_const,
            _ => return Err(unknown("Real", vr)),
        })
    }

    fn set_real(&mut self, _log: &Logger, vr: u32, value: f64) -> Result<(), String> {
        match vr {
            R_U => self.u = value,
            R_T if value <= 0.0 => return Err(format!("T must be > 0, got {value}")),
            R_T => self.t_const = value,
            R_Y0 => self.y0 = value,
            _ => unreachable!("layer checked settable vr {vr}"),
        }
        Ok(())
    }

    fn get_integer(&self, vr: u32) -> Result<i32, String> {
        Ok(match vr {
            I_SUBSTEPS => self.substeps,
            I_STEPS if self.fault_mode == FAULT_GET => {
                return Err(format!("refused by fault_mode {FAULT_GET}"))
            }
            I_STEPS => self.steps,
            I_FAULT => self.fault_mode,
            I_VERSION => 7,
            E_METHOD => self.method,
            _ => return Err(unknown("Integer", vr)),
        })
    }

    fn set_integer(&mut self, _log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        match vr {
            I_SUBSTEPS if value < 1 => return Err(format!("substeps must be >= 1, got {value}")),
            I_SUBSTEPS => self.substeps = value,
            I_FAULT => self.fault_mode = value,
            E_METHOD if value == METHOD_EULER || value == METHOD_HEUN => self.method = value,
            E_METHOD => {
                return Err(format!(
                    "method must be one of 1 euler, 2 heun, got {value}"
                ))
            }
            _ => unreachable!(),
        }
        Ok(())
    }

    fn get_boolean(&self, vr: u32) -> Result<bool, String> {
        match vr {
            B_ENABLED => Ok(self.enabled),
            B_PANIC_NOW => Ok(false),
            _ => Err(unknown("Boolean", vr)),
        }
    }

    fn set_boolean(&mut self, _log: &Logger, vr: u32, value: bool) -> Result<(), String> {
        match vr {
            B_ENABLED => self.enabled = value,
            B_PANIC_NOW if value => panic!("panic_now was set to true"),
            B_PANIC_NOW => {}
            _ => unreachable!(),
        }
        Ok(())
    }

    fn get_string(&self, vr: u32) -> Result<String, String> {
        match vr {
            S_LABEL => Ok(self.label.clone()),
            _ => Err(unknown("String", vr)),
        }
    }

    fn set_string(&mut self, _log: &Logger, vr: u32, value: &str) -> Result<(), String> {
        assert_eq!(vr, S_LABEL);
        self.label = value.to_string();
        Ok(())
    }

    fn do_step(&mut self, log: &Logger, step: &StepContext) -> StepOutcome {
        match self.fault_mode {
            FAULT_DISCARD => return StepOutcome::Discard("fault_mode 2 discards".into()),
            FAULT_ERROR => return StepOutcome::Error("fault_mode 3 fails".into()),
            FAULT_PANIC => panic!(
                "fault_mode 4 panics in do_step at t = {}",
                step.current_time
            ),
            _ => {}
        }
        log.info(
            "logEvents",
            &format!("step {} at t = {}", step.step_index, step.current_time),
        );
        if self.enabled {
            let dt = step.step_size / f64::from(self.substeps);
            let slope = |y: f64| (self.u - y) / self.t_const;
            for _ in 0..self.substeps {
                self.y += if self.method == METHOD_HEUN {
                    let predicted = self.y + dt * slope(self.y);
                    0.5 * dt * (slope(self.y) + slope(predicted))
                } else {
                    dt * slope(self.y)
                };
            }
        }
        self.steps += 1;
        if self.fault_mode == FAULT_WARNING {
            StepOutcome::Warning("100% %s %d warning with NUL\0inside".into())
        } else {
            StepOutcome::Ok
        }
    }

    fn terminate(&mut self, _log: &Logger) -> Result<(), String> {
        Ok(())
    }

    fn serialize_state(&self, out: &mut Vec<u8>) -> Result<(), String> {
        out.push(1); // model state version
        for x in [self.u, self.y, self.t_const, self.y0] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        for i in [self.substeps, self.steps, self.fault_mode, self.method] {
            out.extend_from_slice(&i.to_le_bytes());
        }
        out.push(u8::from(self.enabled));
        out.extend_from_slice(&(self.label.len() as u32).to_le_bytes());
        out.extend_from_slice(self.label.as_bytes());
        Ok(())
    }

    fn deserialize_state(&mut self, _log: &Logger, b: &[u8]) -> Result<(), String> {
        if b.first() != Some(&1) || b.len() < 1 + 32 + 16 + 1 + 4 {
            return Err("Lag state: bad version or too short".into());
        }
        let f = |i: usize| f64::from_le_bytes(b[1 + 8 * i..9 + 8 * i].try_into().unwrap());
        let n = |i: usize| i32::from_le_bytes(b[33 + 4 * i..37 + 4 * i].try_into().unwrap());
        let len = u32::from_le_bytes(b[50..54].try_into().unwrap()) as usize;
        if b.len() != 54 + len {
            return Err("Lag state: length mismatch".into());
        }
        *self = LagModel {
            u: f(0),
            y: f(1),
            t_const: f(2),
            y0: f(3),
            substeps: n(0),
            steps: n(1),
            fault_mode: n(2),
            method: n(3),
            enabled: b[49] != 0,
            label: String::from_utf8(b[54..].to_vec()).map_err(|e| e.to_string())?,
            resource_dir: self.resource_dir.clone(),
        };
        Ok(())
    }
}

// ---- the harness, bound to this test binary's exports ---------------------------------

/// The functions `export_fmi2!(common::Lag)` generated at the root of the test binary.
pub fn exports() -> Exports {
    fmi2_slave::exports_of!(crate)
}

/// The GUID of [`DESCRIPTION`] as a C string.
pub fn guid() -> CString {
    CString::new(DESCRIPTION.guid()).unwrap()
}

/// Instantiates the test model (co-simulation, [`DESCRIPTION`]'s GUID); the log on failure.
pub fn try_fmu(name: &str, uri: Option<&str>, logging_on: bool) -> Result<Fmu, Vec<Msg>> {
    Fmu::try_new(exports(), &DESCRIPTION, name, uri, logging_on)
}

/// A new instance with logging off.
pub fn new_fmu(name: &str) -> Fmu {
    try_fmu(name, None, false).unwrap()
}

/// A new instance with logging on.
pub fn logging_fmu(name: &str) -> Fmu {
    try_fmu(name, None, true).unwrap()
}

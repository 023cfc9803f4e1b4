//! Test model and FFI harness shared by the integration tests.
//!
//! Each test binary invokes `fmi2_slave::export_fmi2!(common::Lag)` at its root, so the 34
//! `fmi2*` functions exist as `crate::fmi2*` and are called here exactly as a master would.
#![allow(dead_code, clippy::unwrap_used, clippy::missing_safety_doc)]

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::PathBuf;
use std::ptr;
use std::sync::{LazyLock, Mutex};

use fmi2_slave::ffi::*;
use fmi2_slave::{
    BaseUnit, Causality, DefaultExperiment, Fmi2Model, Initial, InstanceContext, LogCategory,
    Logger, ModelDescription, StepContext, StepOutcome, UnitDefinition, Variability, Variable,
    VariableKind,
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
pub const B_ENABLED: u32 = 1;
pub const B_PANIC_NOW: u32 = 2;
pub const S_LABEL: u32 = 1;

/// Fault modes of input `fault_mode`: what the next `do_step` returns.
pub const FAULT_WARNING: i32 = 1;
pub const FAULT_DISCARD: i32 = 2;
pub const FAULT_ERROR: i32 = 3;
pub const FAULT_PANIC: i32 = 4;

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
                "0 ok, 1 warning, 2 discard, 3 error, 4 panic",
            ),
            Variable {
                name: "version".into(),
                value_reference: I_VERSION,
                description: "model version".into(),
                causality: Causality::Output,
                variability: Variability::Constant,
                initial: Some(Initial::Exact),
                kind: VariableKind::Integer {
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
        ],
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

    fn get_real(&self, vr: u32) -> f64 {
        match vr {
            R_U => self.u,
            R_Y => self.y,
            R_T => self.t_const,
            R_Y0 => self.y0,
            R_RATE => 1.0 / self.t_const,
            _ => unreachable!("layer checked vr {vr}"),
        }
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

    fn get_integer(&self, vr: u32) -> i32 {
        match vr {
            I_SUBSTEPS => self.substeps,
            I_STEPS => self.steps,
            I_FAULT => self.fault_mode,
            I_VERSION => 7,
            _ => unreachable!(),
        }
    }

    fn set_integer(&mut self, _log: &Logger, vr: u32, value: i32) -> Result<(), String> {
        match vr {
            I_SUBSTEPS if value < 1 => return Err(format!("substeps must be >= 1, got {value}")),
            I_SUBSTEPS => self.substeps = value,
            I_FAULT => self.fault_mode = value,
            _ => unreachable!(),
        }
        Ok(())
    }

    fn get_boolean(&self, vr: u32) -> bool {
        match vr {
            B_ENABLED => self.enabled,
            B_PANIC_NOW => false,
            _ => unreachable!(),
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

    fn get_string(&self, vr: u32) -> String {
        assert_eq!(vr, S_LABEL);
        self.label.clone()
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
            for _ in 0..self.substeps {
                self.y += dt * (self.u - self.y) / self.t_const;
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

    fn serialize_state(&self, out: &mut Vec<u8>) {
        out.push(1); // model state version
        for x in [self.u, self.y, self.t_const, self.y0] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        for i in [self.substeps, self.steps, self.fault_mode] {
            out.extend_from_slice(&i.to_le_bytes());
        }
        out.push(u8::from(self.enabled));
        out.extend_from_slice(&(self.label.len() as u32).to_le_bytes());
        out.extend_from_slice(self.label.as_bytes());
    }

    fn deserialize_state(&mut self, _log: &Logger, b: &[u8]) -> Result<(), String> {
        if b.first() != Some(&1) || b.len() < 1 + 32 + 12 + 1 + 4 {
            return Err("Lag state: bad version or too short".into());
        }
        let f = |i: usize| f64::from_le_bytes(b[1 + 8 * i..9 + 8 * i].try_into().unwrap());
        let n = |i: usize| i32::from_le_bytes(b[33 + 4 * i..37 + 4 * i].try_into().unwrap());
        let len = u32::from_le_bytes(b[46..50].try_into().unwrap()) as usize;
        if b.len() != 50 + len {
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
            enabled: b[45] != 0,
            label: String::from_utf8(b[50..].to_vec()).map_err(|e| e.to_string())?,
            resource_dir: self.resource_dir.clone(),
        };
        Ok(())
    }
}

// ---- logger capture -------------------------------------------------------------------

#[derive(Debug, Clone, PartialEq)]
pub struct Msg {
    pub instance: String,
    pub status: c_int,
    pub category: String,
    pub format: String,
    pub text: String,
}

#[derive(Debug, Default)]
pub struct Capture {
    pub messages: Mutex<Vec<Msg>>,
}

unsafe fn lossy(p: *const c_char) -> String {
    if p.is_null() {
        "<NULL>".into()
    } else {
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// Receives exactly the arguments the layer passes: format plus one `char*`.
unsafe extern "C" fn capture_logger(
    env: *mut c_void,
    instance: *const c_char,
    status: c_int,
    category: *const c_char,
    format: *const c_char,
    arg: *const c_char,
) {
    let capture = unsafe { &*env.cast::<Capture>() };
    let msg = unsafe {
        Msg {
            instance: lossy(instance),
            status,
            category: lossy(category),
            format: lossy(format),
            text: lossy(arg),
        }
    };
    capture
        .messages
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(msg);
}

/// The logger as the C-variadic `fmi2CallbackLogger`.
///
/// Stable Rust cannot define a variadic function, so the test defines a function with one
/// fixed `char*` in the vararg position. On the targets this project builds for (x86_64
/// SysV and Windows x64, aarch64 Linux) a single pointer vararg is passed exactly like a
/// sixth fixed pointer argument, so the call the layer makes reaches it intact. (Not valid
/// on Apple arm64, where varargs go on the stack.)
pub fn logger_fn() -> Fmi2CallbackLogger {
    type Fixed = unsafe extern "C" fn(
        *mut c_void,
        *const c_char,
        c_int,
        *const c_char,
        *const c_char,
        *const c_char,
    );
    unsafe { std::mem::transmute::<Fixed, Fmi2CallbackLogger>(capture_logger as Fixed) }
}

pub fn callbacks(capture: &Capture) -> Fmi2CallbackFunctions {
    Fmi2CallbackFunctions {
        logger: Some(logger_fn()),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: ptr::from_ref(capture).cast_mut().cast(),
    }
}

pub fn guid() -> CString {
    CString::new(DESCRIPTION.guid()).unwrap()
}

// ---- an instance as a master sees it ------------------------------------------------------

/// An instance with its own logger capture; freed on drop.
pub struct Fmu {
    pub c: Fmi2Component,
    pub capture: Box<Capture>,
}

// FMI allows an instance to be called from any thread as long as calls do not overlap
// (libcosim steps on pool threads); the capture is a Mutex.
unsafe impl Send for Fmu {}

impl Fmu {
    pub fn try_new(name: &str, uri: Option<&str>, logging_on: bool) -> Result<Fmu, Vec<Msg>> {
        let capture = Box::<Capture>::default();
        let functions = callbacks(&capture);
        let name = CString::new(name).unwrap();
        let uri = uri.map(|u| CString::new(u).unwrap());
        let c = unsafe {
            crate::fmi2Instantiate(
                name.as_ptr(),
                FMI2_CO_SIMULATION,
                guid().as_ptr(),
                uri.as_ref().map_or(ptr::null(), |u| u.as_ptr()),
                &functions,
                FMI2_FALSE,
                c_int::from(logging_on),
            )
        };
        if c.is_null() {
            Err(capture.messages.lock().unwrap().clone())
        } else {
            Ok(Fmu { c, capture })
        }
    }

    pub fn new(name: &str) -> Fmu {
        Self::try_new(name, None, false).unwrap()
    }

    pub fn logging(name: &str) -> Fmu {
        Self::try_new(name, None, true).unwrap()
    }

    pub fn messages(&self) -> Vec<Msg> {
        self.capture.messages.lock().unwrap().clone()
    }

    pub fn clear(&self) {
        self.capture.messages.lock().unwrap().clear();
    }

    pub fn last_text(&self) -> String {
        self.messages()
            .last()
            .map(|m| m.text.clone())
            .unwrap_or_default()
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> Fmi2Status {
        unsafe {
            crate::fmi2SetupExperiment(
                self.c,
                FMI2_FALSE,
                0.0,
                start,
                c_int::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        }
    }

    /// SetupExperiment(start, stop), Enter/ExitInitializationMode, all expected OK.
    pub fn init(&self, start: f64, stop: Option<f64>) {
        assert_eq!(self.setup(start, stop), Fmi2Status::Ok);
        assert_eq!(
            unsafe { crate::fmi2EnterInitializationMode(self.c) },
            Fmi2Status::Ok
        );
        assert_eq!(
            unsafe { crate::fmi2ExitInitializationMode(self.c) },
            Fmi2Status::Ok
        );
    }

    pub fn step(&self, t: f64, h: f64) -> Fmi2Status {
        unsafe { crate::fmi2DoStep(self.c, t, h, FMI2_TRUE) }
    }

    pub fn get_real(&self, vr: u32) -> f64 {
        let mut v = f64::NAN;
        assert_eq!(
            unsafe { crate::fmi2GetReal(self.c, &vr, 1, &mut v) },
            Fmi2Status::Ok
        );
        v
    }

    pub fn try_get_real(&self, vr: u32) -> (Fmi2Status, f64) {
        let mut v = f64::NAN;
        let s = unsafe { crate::fmi2GetReal(self.c, &vr, 1, &mut v) };
        (s, v)
    }

    pub fn set_real(&self, vr: u32, value: f64) -> Fmi2Status {
        unsafe { crate::fmi2SetReal(self.c, &vr, 1, &value) }
    }

    pub fn get_integer(&self, vr: u32) -> i32 {
        let mut v = -1;
        assert_eq!(
            unsafe { crate::fmi2GetInteger(self.c, &vr, 1, &mut v) },
            Fmi2Status::Ok
        );
        v
    }

    pub fn set_integer(&self, vr: u32, value: i32) -> Fmi2Status {
        unsafe { crate::fmi2SetInteger(self.c, &vr, 1, &value) }
    }

    pub fn set_boolean(&self, vr: u32, value: bool) -> Fmi2Status {
        let v = c_int::from(value);
        unsafe { crate::fmi2SetBoolean(self.c, &vr, 1, &v) }
    }

    pub fn last_successful_time(&self) -> f64 {
        let mut t = f64::NAN;
        assert_eq!(
            unsafe { crate::fmi2GetRealStatus(self.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) },
            Fmi2Status::Ok
        );
        t
    }

    pub fn get_state(&self) -> Fmi2FmuState {
        let mut s: Fmi2FmuState = ptr::null_mut();
        assert_eq!(
            unsafe { crate::fmi2GetFMUstate(self.c, &mut s) },
            Fmi2Status::Ok
        );
        assert!(!s.is_null());
        s
    }

    pub fn free_state(&self, mut s: Fmi2FmuState) {
        assert_eq!(
            unsafe { crate::fmi2FreeFMUstate(self.c, &mut s) },
            Fmi2Status::Ok
        );
        assert!(s.is_null());
    }

    pub fn serialize(&self) -> Vec<u8> {
        let s = self.get_state();
        let mut size = 0usize;
        assert_eq!(
            unsafe { crate::fmi2SerializedFMUstateSize(self.c, s, &mut size) },
            Fmi2Status::Ok
        );
        let mut bytes = vec![0u8; size];
        assert_eq!(
            unsafe { crate::fmi2SerializeFMUstate(self.c, s, bytes.as_mut_ptr().cast(), size) },
            Fmi2Status::Ok
        );
        self.free_state(s);
        bytes
    }

    /// DeSerialize into a new FMU state; returns the status and the state (NULL on error).
    pub fn deserialize(&self, bytes: &[u8]) -> (Fmi2Status, Fmi2FmuState) {
        let mut s: Fmi2FmuState = ptr::null_mut();
        let status = unsafe {
            crate::fmi2DeSerializeFMUstate(self.c, bytes.as_ptr().cast(), bytes.len(), &mut s)
        };
        (status, s)
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { crate::fmi2FreeInstance(self.c) };
    }
}

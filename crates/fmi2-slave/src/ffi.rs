//! The C types of FMI 2.0 (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`), spelled in Rust.
//!
//! Only the export macro and the layer itself use these; a model crate never needs them.
//! Enumerations that the master passes *in* (`fmi2Type`, `fmi2StatusKind`) are taken as
//! [`c_int`] so that an out-of-range value from a foreign caller is a reported error
//! instead of undefined behaviour.

use std::ffi::{c_char, c_int, c_uint, c_void};

/// `fmi2Component`: the opaque instance handle returned by `fmi2Instantiate`.
pub type Fmi2Component = *mut c_void;
/// `fmi2ComponentEnvironment`: the master's pointer handed back to its logger.
pub type Fmi2ComponentEnvironment = *mut c_void;
/// `fmi2FMUstate`: an opaque snapshot of an instance (FMI 2.0 section 2.1.8).
pub type Fmi2FmuState = *mut c_void;
/// `fmi2ValueReference`.
pub type Fmi2ValueReference = c_uint;
/// `fmi2Real`.
pub type Fmi2Real = f64;
/// `fmi2Integer`.
pub type Fmi2Integer = c_int;
/// `fmi2Boolean`: `fmi2True` = 1, `fmi2False` = 0 (any non-zero value is read as true).
pub type Fmi2Boolean = c_int;
/// `fmi2Char`.
pub type Fmi2Char = c_char;
/// `fmi2String`: a NUL-terminated, UTF-8 encoded C string.
pub type Fmi2String = *const c_char;
/// `fmi2Byte`: element of a serialized FMU state.
pub type Fmi2Byte = c_char;

/// `fmi2True`.
pub const FMI2_TRUE: Fmi2Boolean = 1;
/// `fmi2False`.
pub const FMI2_FALSE: Fmi2Boolean = 0;

/// `fmi2Type` value `fmi2ModelExchange`.
pub const FMI2_MODEL_EXCHANGE: c_int = 0;
/// `fmi2Type` value `fmi2CoSimulation`.
pub const FMI2_CO_SIMULATION: c_int = 1;

/// `fmi2StatusKind` value `fmi2DoStepStatus` (FMI 2.0 section 4.2.3).
pub const FMI2_DO_STEP_STATUS: c_int = 0;
/// `fmi2StatusKind` value `fmi2PendingStatus`.
pub const FMI2_PENDING_STATUS: c_int = 1;
/// `fmi2StatusKind` value `fmi2LastSuccessfulTime`.
pub const FMI2_LAST_SUCCESSFUL_TIME: c_int = 2;
/// `fmi2StatusKind` value `fmi2Terminated`.
pub const FMI2_TERMINATED: c_int = 3;

/// `fmi2Status` (FMI 2.0 section 2.1.3), returned by every FMI function and passed to the
/// logger.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Fmi2Status {
    /// `fmi2OK`.
    Ok = 0,
    /// `fmi2Warning`: result usable, something to tell the user.
    Warning = 1,
    /// `fmi2Discard`: step rejected (co-simulation), retry with a smaller step or restore a state.
    Discard = 2,
    /// `fmi2Error`: this instance cannot continue (only reset, state restore, free).
    Error = 3,
    /// `fmi2Fatal`: the instance is corrupted; only `fmi2FreeInstance` is allowed.
    Fatal = 4,
    /// `fmi2Pending`: asynchronous step in progress (never returned by this layer).
    Pending = 5,
}

impl Fmi2Status {
    /// The C enumerator name, e.g. `"fmi2Warning"`.
    pub fn name(self) -> &'static str {
        match self {
            Fmi2Status::Ok => "fmi2OK",
            Fmi2Status::Warning => "fmi2Warning",
            Fmi2Status::Discard => "fmi2Discard",
            Fmi2Status::Error => "fmi2Error",
            Fmi2Status::Fatal => "fmi2Fatal",
            Fmi2Status::Pending => "fmi2Pending",
        }
    }
}

/// `fmi2CallbackLogger`: `void logger(fmi2ComponentEnvironment, fmi2String instanceName,
/// fmi2Status status, fmi2String category, fmi2String message, ...)`. The message is a
/// `printf` format; this layer always passes `"%s"` and the text as the single argument.
pub type Fmi2CallbackLogger =
    unsafe extern "C" fn(Fmi2ComponentEnvironment, Fmi2String, c_int, Fmi2String, Fmi2String, ...);

/// `fmi2CallbackAllocateMemory` (never called: `canNotUseMemoryManagementFunctions="true"`).
pub type Fmi2CallbackAllocateMemory = unsafe extern "C" fn(usize, usize) -> *mut c_void;
/// `fmi2CallbackFreeMemory` (never called).
pub type Fmi2CallbackFreeMemory = unsafe extern "C" fn(*mut c_void);
/// `fmi2StepFinished` (never called: no asynchronous stepping).
pub type Fmi2StepFinished = unsafe extern "C" fn(Fmi2ComponentEnvironment, c_int);

/// `fmi2CallbackFunctions` (FMI 2.0 section 2.1.5). Only `logger` and
/// `componentEnvironment` are used; the memory functions may be NULL.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct Fmi2CallbackFunctions {
    /// Required; `fmi2Instantiate` returns NULL without it.
    pub logger: Option<Fmi2CallbackLogger>,
    /// Ignored (Rust allocator).
    pub allocate_memory: Option<Fmi2CallbackAllocateMemory>,
    /// Ignored (Rust allocator).
    pub free_memory: Option<Fmi2CallbackFreeMemory>,
    /// Ignored (synchronous `fmi2DoStep` only).
    pub step_finished: Option<Fmi2StepFinished>,
    /// Passed back unchanged as the logger's first argument.
    pub component_environment: Fmi2ComponentEnvironment,
}

//! FMI 2.0 Co-Simulation **export** (slave) layer.
//!
//! This crate holds every line of `unsafe` code of the project and every FMI C type. A
//! model crate implements the safe trait [`Fmi2Model`], describes its variables with a
//! [`ModelDescription`], and invokes [`export_fmi2!`] once; it never sees a raw pointer and
//! can keep `#![deny(unsafe_code)]` (not `forbid`: the macro expansion carries
//! `#[allow(unsafe_code)]`).
//!
//! ```ignore
//! fmi2_slave::export_fmi2!(MyModel);
//! ```
//!
//! # Architecture
//!
//! * **Exports** — [`export_fmi2!`] defines the 34 `#[no_mangle] extern "C"` functions of
//!   FMI 2.0 CS that fmpy binds (FMI 2.0 sections 2.1 and 4.2). Each forwards to a generic
//!   implementation in this crate, monomorphised for the model type.
//! * **Guard** — every function taking an `fmi2Component` runs inside one guard function:
//!   NULL check, magic-tag check (best-effort detection of foreign pointers), call-state
//!   check, then the body inside `std::panic::catch_unwind`. `Err(message)` from the body
//!   or the model becomes `fmi2Error` with a log line, a panic becomes `fmi2Fatal` with a
//!   log line containing the panic message. No panic hook is installed.
//! * **State table** — the FMI 2.0 CS call-sequence states (section 4.2.4: instantiated,
//!   initializationMode, stepComplete, stepFailed, terminated, error, fatal; stepInProgress
//!   and stepCanceled are never entered because stepping is synchronous) with the allowed
//!   functions per state, as in the Modelica Reference FMUs. An out-of-sequence call logs
//!   `"Illegal call sequence: <function> in state <state>"` and returns `fmi2Error`. Every
//!   `fmi2Error` moves the instance to `error` (only getters, FMU-state functions, reset,
//!   free remain), every `fmi2Fatal` to `fatal` (only free remains).
//! * **Instance layout** — `fmi2Component` points to a heap `Instance<M>` (`repr(C)`,
//!   magic tag and `TypeId` first) holding the layer state (call state, start/stop time,
//!   tolerance, a nanosecond clock `i64` and a step counter), the model value, the
//!   [`Logger`], the static model description with a value-reference index built once,
//!   the stored instantiation context (for `fmi2Reset`) and the `CString` storage behind
//!   `fmi2GetString`. No thread-locals and no global mutable state besides the count of live
//!   instances and the list of [`LibraryLazy`] values to free on unload: instances are
//!   independent and may live on different threads.
//! * **Time** — the clock counts whole nanoseconds since the start time; `fmi2DoStep`
//!   checks the master's communication point `tc` against it with tolerance
//!   `1e-5 * max(1, |t|)` and ends the step at the master's `tc + h` rounded to the
//!   nanosecond, so the clock follows a master that sums its steps without drifting from
//!   it, and a master with exact times gets steps of exactly `round(h * 1e9)` ns. A step
//!   that rounds to no nanosecond (the clipped last step of a summing master) advances
//!   nothing and is `fmi2OK` (FMI 2.0 section 4.2.2 asks only `h > 0`).
//! * **Finite outputs** — after every step and at the end of initialization the layer
//!   reads every Real output: a non-finite one makes the step `fmi2Discard` (the end of
//!   initialization `fmi2Error`), naming it.
//! * **FMU state** (section 2.1.8) — `fmi2GetFMUstate` boxes a clone of the model plus the
//!   layer state; `fmi2SetFMUstate` restores it with [`Fmi2Model::restore_state`], which
//!   keeps what is the instance's own (its log). The serialized form is versioned,
//!   pointer-free, little-endian: magic `RSFMI2ST`, format version, model identifier, GUID,
//!   layer state, the model's own bytes ([`Fmi2Model::serialize_state`], written with
//!   [`codec`]) with a length prefix, and a CRC-32; deserialization checks each part, that
//!   the state makes sense (a call state to continue from, finite times, the model's time
//!   equal to the clock's) and names what does not, leaving the instance as it was. It
//!   works across processes and into a freshly instantiated instance.
//! * **Logging** ([`Logger`]) — through the master's variadic callback with format `"%s"`;
//!   warnings and errors are always sent, info messages only when logging is on and their
//!   category (from [`ModelDescription::log_categories`]) is enabled.
//! * **Model description** ([`description`]) — the XML writer, the deterministic GUID and
//!   the consistency check used at instantiation.
//! * **Unloading** ([`LibraryLazy`]) — what the library builds once (model description,
//!   variable tables) lives in `LibraryLazy` statics, freed by the library's destructor when
//!   a host unloads it (`dlclose`) with no instance alive, so load/unload cycles do not
//!   leak (issue 15); kept at process exit. [`export_fmi2!`] places the constructor and
//!   destructor.

#![warn(missing_docs)]

pub mod codec;
pub mod description;
pub mod doc;
mod exports;
pub mod ffi;
mod logger;
mod serial;
mod state;
pub mod testing;
mod unload;
mod uri;

use std::path::Path;

pub use description::{
    BaseUnit, Causality, DefaultExperiment, DisplayUnit, EnumerationItem, Initial, LogCategory,
    ModelDescription, SimpleType, SimpleTypeKind, UnitDefinition, ValueType, Variability, Variable,
    VariableKind,
};
pub use ffi::Fmi2Status;
pub use logger::Logger;
pub use state::CallState;
pub use unload::LibraryLazy;
pub use uri::resource_dir_from_uri;

/// Implementation detail of [`export_fmi2!`]; not a stable API.
#[doc(hidden)]
pub mod __export {
    pub use crate::exports::*;
    pub use crate::unload::{on_load, on_unload};
}

/// What `fmi2Instantiate` (and `fmi2Reset`) hands to [`Fmi2Model::instantiate`].
#[derive(Debug, Clone, Copy)]
pub struct InstanceContext<'a> {
    /// `instanceName` (non-empty).
    pub instance_name: &'a str,
    /// The FMU's `resources` directory decoded from `fmuResourceLocation`
    /// ([`resource_dir_from_uri`]); `None` when the master passed NULL. Not checked for
    /// existence.
    pub resource_dir: Option<&'a Path>,
    /// The instance's logger.
    pub logger: &'a Logger,
}

/// Arguments of one `fmi2DoStep` as seen by the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepContext {
    /// Internal time at the start of the step: `startTime + ns / 1e9`, where `ns` is the
    /// layer's nanosecond clock (within `1e-5 * max(1, |t|)` of the master's
    /// `currentCommunicationPoint`).
    pub current_time: f64,
    /// The step in seconds, whole nanoseconds: from the FMU's time to the master's
    /// `currentCommunicationPoint + h` rounded to the nanosecond (`round(h * 1e9) / 1e9` when
    /// the master's time equals the FMU's); never 0 (an empty step does not reach the model).
    pub step_size: f64,
    /// Number of steps accepted since the start (0 for the first step); empty steps (no
    /// nanosecond to advance) are not counted.
    pub step_index: u64,
}

/// Result of [`Fmi2Model::do_step`] (FMI 2.0 section 4.2.2); outcomes are values, not
/// errors.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StepOutcome {
    /// `fmi2OK`; time advances.
    Ok,
    /// `fmi2Warning`: the message is logged, time advances.
    Warning(String),
    /// `fmi2Discard`: the message is logged, the instance goes to `stepFailed`, time does
    /// **not** advance (`fmi2GetRealStatus(fmi2LastSuccessfulTime)` returns the step's start).
    /// The master may restore an FMU state and retry with a smaller step.
    Discard(String),
    /// `fmi2Error`: the message is logged, the instance goes to `error`.
    Error(String),
}

/// The safe model interface behind the FMI 2.0 Co-Simulation exports.
///
/// Before any get/set method is called the layer has checked that `vr` names a variable of
/// that type in [`description`](Self::description), that the call is allowed in the current
/// state for that variable's causality/variability (FMI 2.0 section 4.2.4), and (Real) that
/// the value is finite. The model only stores and returns values. An `Err(message)` from a
/// getter or a setter becomes `fmi2Error` with the message logged after the variable's name
/// and value reference; a panic becomes `fmi2Fatal`. A model that does not decode a value
/// reference of its own description (a variable added without its getter) returns `Err`
/// naming the reference and the FMI type, never panics.
///
/// A vectorised `fmi2Set*` call is checked completely before the first setter runs, so a
/// layer-detected problem (unknown value reference, wrong causality or state, NaN) leaves
/// every variable unchanged. If the model's own setter returns `Err` for element `k`, the
/// elements before `k` have been applied and the instance is in the `error` state.
pub trait Fmi2Model: Clone + Send + Sized + 'static {
    /// The model description; keep it in a [`LibraryLazy`] static (not a `LazyLock`, whose
    /// value a host's `dlclose` would leak: see [`LibraryLazy`]). Validated at every
    /// instantiation; its GUID must match the one the master passes.
    fn description() -> &'static ModelDescription;

    /// Create an instance with start values (`fmi2Instantiate`, and again on `fmi2Reset`).
    fn instantiate(ctx: &InstanceContext<'_>) -> Result<Self, String>;

    /// `fmi2SetupExperiment` (FMI 2.0 section 2.1.6); the layer has already checked the
    /// numbers and records them itself.
    fn setup_experiment(
        &mut self,
        _log: &Logger,
        _start_time: f64,
        _stop_time: Option<f64>,
        _tolerance: Option<f64>,
    ) -> Result<(), String> {
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    fn enter_initialization_mode(&mut self, log: &Logger) -> Result<(), String>;

    /// `fmi2ExitInitializationMode`: compute everything that depends on parameters.
    fn exit_initialization_mode(&mut self, log: &Logger) -> Result<(), String>;

    /// Value of a Real variable.
    fn get_real(&self, vr: u32) -> Result<f64, String>;
    /// Store a Real variable (finite, settable now).
    fn set_real(&mut self, log: &Logger, vr: u32, value: f64) -> Result<(), String>;
    /// Value of an Integer variable.
    fn get_integer(&self, vr: u32) -> Result<i32, String>;
    /// Store an Integer variable.
    fn set_integer(&mut self, log: &Logger, vr: u32, value: i32) -> Result<(), String>;
    /// Value of a Boolean variable.
    fn get_boolean(&self, vr: u32) -> Result<bool, String>;
    /// Store a Boolean variable.
    fn set_boolean(&mut self, log: &Logger, vr: u32, value: bool) -> Result<(), String>;
    /// Value of a String variable (interior NULs are replaced on the way out).
    fn get_string(&self, vr: u32) -> Result<String, String>;
    /// Store a String variable (valid UTF-8).
    fn set_string(&mut self, log: &Logger, vr: u32, value: &str) -> Result<(), String>;

    /// Advance from `step.current_time` by `step.step_size` (FMI 2.0 section 4.2.2).
    fn do_step(&mut self, log: &Logger, step: &StepContext) -> StepOutcome;

    /// `fmi2Terminate`: flush logs, close files.
    fn terminate(&mut self, log: &Logger) -> Result<(), String>;

    /// Called by `fmi2FreeInstance` and `fmi2Reset` just before the model is dropped,
    /// whether or not `fmi2Terminate` ran: close what [`terminate`](Self::terminate) did
    /// not (a log file, say) and report problems through `log`, since neither function can
    /// return them to the master. A panic here is caught and logged. Default: nothing.
    fn release(&mut self, _log: &Logger) {}

    /// Append the model's state as pointer-free bytes with the model's own versioning
    /// (`fmi2SerializeFMUstate`), built with [`codec`]. `Err` (a value that cannot be
    /// restored, such as a NaN) refuses the serialization with `fmi2Error`.
    fn serialize_state(&self, out: &mut Vec<u8>) -> Result<(), String>;

    /// Restore from bytes written by [`serialize_state`](Self::serialize_state), possibly in
    /// another process. Called on a clone of a live (possibly freshly instantiated)
    /// instance; the result becomes an FMU state that [`restore_state`](Self::restore_state)
    /// later applies. Check everything that can be checked here (the layer has checked the
    /// checksum, its own part and nothing else): an `Err` is `fmi2Error` from
    /// `fmi2DeSerializeFMUstate` with the instance unchanged.
    fn deserialize_state(&mut self, log: &Logger, bytes: &[u8]) -> Result<(), String>;

    /// `fmi2SetFMUstate` (FMI 2.0 section 2.1.8): become `saved` (a copy made by
    /// `fmi2GetFMUstate`, or [`deserialize_state`](Self::deserialize_state)'s result), keeping
    /// what belongs to the instance and not to its state, such as an open log file: the
    /// instance goes on writing its own log. Default: a plain copy. An `Err` is `fmi2Error`;
    /// leave `self` unchanged then.
    fn restore_state(&mut self, _log: &Logger, saved: &Self) -> Result<(), String> {
        self.clone_from(saved);
        Ok(())
    }

    /// The model's own time (s), the end of its last step (the start time before the
    /// first), if it keeps one. A deserialized state is refused when this differs from the
    /// layer's clock by more than 1 us. Default: `None`, not checked.
    fn time(&self) -> Option<f64> {
        None
    }
}

/// Defines the 34 FMI 2.0 Co-Simulation functions (`fmi2GetTypesPlatform` …
/// `fmi2GetStringStatus`) as `#[no_mangle] pub unsafe extern "C" fn` for one
/// [`Fmi2Model`] type. Invoke it once, at the root of a `cdylib` crate.
///
/// The expansion carries `#[allow(unsafe_code)]`, so the model crate may use
/// `#![deny(unsafe_code)]` (not `forbid`, which cannot be overridden).
#[macro_export]
macro_rules! export_fmi2 {
    ($model:ty) => {
        const _: fn() = || {
            fn assert_model<M: $crate::Fmi2Model>() {}
            assert_model::<$model>();
        };

        /// The library's constructor: lets the destructor tell process exit from unload.
        #[allow(unsafe_code)]
        #[used]
        #[cfg_attr(target_os = "linux", link_section = ".init_array")]
        static __FMI2_SLAVE_ON_LOAD: extern "C" fn() = $crate::__export::on_load;

        /// The library's destructor: frees the `LibraryLazy` values when a host unloads the
        /// library (issue 15; see `fmi2_slave::LibraryLazy`).
        #[allow(unsafe_code)]
        #[used]
        #[cfg_attr(target_os = "linux", link_section = ".fini_array")]
        static __FMI2_SLAVE_ON_UNLOAD: extern "C" fn() = $crate::__export::on_unload;

        /// FMI 2.0 `fmi2GetTypesPlatform`: `"default"`.
        ///
        /// # Safety
        /// None beyond the C ABI.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetTypesPlatform() -> *const ::std::ffi::c_char {
            $crate::__export::get_types_platform()
        }

        /// FMI 2.0 `fmi2GetVersion`: `"2.0"`.
        ///
        /// # Safety
        /// None beyond the C ABI.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetVersion() -> *const ::std::ffi::c_char {
            $crate::__export::get_version()
        }

        /// FMI 2.0 `fmi2SetDebugLogging`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (valid or NULL pointers with the given lengths).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetDebugLogging(
            c: $crate::ffi::Fmi2Component,
            logging_on: $crate::ffi::Fmi2Boolean,
            n_categories: usize,
            categories: *const $crate::ffi::Fmi2String,
        ) -> $crate::ffi::Fmi2Status {
            unsafe {
                $crate::__export::set_debug_logging::<$model>(
                    c,
                    logging_on,
                    n_categories,
                    categories,
                )
            }
        }

        /// FMI 2.0 `fmi2Instantiate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (valid or NULL pointers).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2Instantiate(
            instance_name: $crate::ffi::Fmi2String,
            fmu_type: ::std::ffi::c_int,
            fmu_guid: $crate::ffi::Fmi2String,
            fmu_resource_location: $crate::ffi::Fmi2String,
            functions: *const $crate::ffi::Fmi2CallbackFunctions,
            visible: $crate::ffi::Fmi2Boolean,
            logging_on: $crate::ffi::Fmi2Boolean,
        ) -> $crate::ffi::Fmi2Component {
            unsafe {
                $crate::__export::instantiate::<$model>(
                    instance_name,
                    fmu_type,
                    fmu_guid,
                    fmu_resource_location,
                    functions,
                    visible,
                    logging_on,
                )
            }
        }

        /// FMI 2.0 `fmi2FreeInstance` (NULL is a no-op).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2FreeInstance(c: $crate::ffi::Fmi2Component) {
            unsafe { $crate::__export::free_instance::<$model>(c) }
        }

        /// FMI 2.0 `fmi2SetupExperiment`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetupExperiment(
            c: $crate::ffi::Fmi2Component,
            tolerance_defined: $crate::ffi::Fmi2Boolean,
            tolerance: $crate::ffi::Fmi2Real,
            start_time: $crate::ffi::Fmi2Real,
            stop_time_defined: $crate::ffi::Fmi2Boolean,
            stop_time: $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe {
                $crate::__export::setup_experiment::<$model>(
                    c,
                    tolerance_defined,
                    tolerance,
                    start_time,
                    stop_time_defined,
                    stop_time,
                )
            }
        }

        /// FMI 2.0 `fmi2EnterInitializationMode`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2EnterInitializationMode(
            c: $crate::ffi::Fmi2Component,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::enter_initialization_mode::<$model>(c) }
        }

        /// FMI 2.0 `fmi2ExitInitializationMode`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2ExitInitializationMode(
            c: $crate::ffi::Fmi2Component,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::exit_initialization_mode::<$model>(c) }
        }

        /// FMI 2.0 `fmi2Terminate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2Terminate(
            c: $crate::ffi::Fmi2Component,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::terminate::<$model>(c) }
        }

        /// FMI 2.0 `fmi2Reset`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2Reset(
            c: $crate::ffi::Fmi2Component,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::reset::<$model>(c) }
        }

        /// FMI 2.0 `fmi2GetReal`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetReal(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_real::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2GetInteger`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetInteger(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::ffi::Fmi2Integer,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_integer::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2GetBoolean`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetBoolean(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::ffi::Fmi2Boolean,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_boolean::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2GetString`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetString(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::ffi::Fmi2String,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_string::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2SetReal`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetReal(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *const $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::set_real::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2SetInteger`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetInteger(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *const $crate::ffi::Fmi2Integer,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::set_integer::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2SetBoolean`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetBoolean(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *const $crate::ffi::Fmi2Boolean,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::set_boolean::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2SetString`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (arrays of `nvr` elements, or NULL when `nvr == 0`).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetString(
            c: $crate::ffi::Fmi2Component,
            vr: *const $crate::ffi::Fmi2ValueReference,
            nvr: usize,
            value: *const $crate::ffi::Fmi2String,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::set_string::<$model>(c, vr, nvr, value) }
        }

        /// FMI 2.0 `fmi2GetFMUstate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetFMUstate(
            c: $crate::ffi::Fmi2Component,
            fmu_state: *mut $crate::ffi::Fmi2FmuState,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_fmu_state::<$model>(c, fmu_state) }
        }

        /// FMI 2.0 `fmi2SetFMUstate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetFMUstate(
            c: $crate::ffi::Fmi2Component,
            fmu_state: $crate::ffi::Fmi2FmuState,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::set_fmu_state::<$model>(c, fmu_state) }
        }

        /// FMI 2.0 `fmi2FreeFMUstate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2FreeFMUstate(
            c: $crate::ffi::Fmi2Component,
            fmu_state: *mut $crate::ffi::Fmi2FmuState,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::free_fmu_state::<$model>(c, fmu_state) }
        }

        /// FMI 2.0 `fmi2SerializedFMUstateSize`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
            c: $crate::ffi::Fmi2Component,
            fmu_state: $crate::ffi::Fmi2FmuState,
            size: *mut usize,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::serialized_fmu_state_size::<$model>(c, fmu_state, size) }
        }

        /// FMI 2.0 `fmi2SerializeFMUstate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (`serialized_state` holds `size` bytes).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SerializeFMUstate(
            c: $crate::ffi::Fmi2Component,
            fmu_state: $crate::ffi::Fmi2FmuState,
            serialized_state: *mut $crate::ffi::Fmi2Byte,
            size: usize,
        ) -> $crate::ffi::Fmi2Status {
            unsafe {
                $crate::__export::serialize_fmu_state::<$model>(
                    c,
                    fmu_state,
                    serialized_state,
                    size,
                )
            }
        }

        /// FMI 2.0 `fmi2DeSerializeFMUstate`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract (`serialized_state` holds `size` bytes).
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
            c: $crate::ffi::Fmi2Component,
            serialized_state: *const $crate::ffi::Fmi2Byte,
            size: usize,
            fmu_state: *mut $crate::ffi::Fmi2FmuState,
        ) -> $crate::ffi::Fmi2Status {
            unsafe {
                $crate::__export::de_serialize_fmu_state::<$model>(
                    c,
                    serialized_state,
                    size,
                    fmu_state,
                )
            }
        }

        /// FMI 2.0 `fmi2GetDirectionalDerivative` (not supported: logs, `fmi2Error`).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
            c: $crate::ffi::Fmi2Component,
            _v_unknown_ref: *const $crate::ffi::Fmi2ValueReference,
            _n_unknown: usize,
            _v_known_ref: *const $crate::ffi::Fmi2ValueReference,
            _n_known: usize,
            _dv_known: *const $crate::ffi::Fmi2Real,
            _dv_unknown: *mut $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_directional_derivative::<$model>(c) }
        }

        /// FMI 2.0 `fmi2SetRealInputDerivatives` (not supported: logs, `fmi2Error`).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
            c: $crate::ffi::Fmi2Component,
            _vr: *const $crate::ffi::Fmi2ValueReference,
            _nvr: usize,
            _order: *const $crate::ffi::Fmi2Integer,
            _value: *const $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::set_real_input_derivatives::<$model>(c) }
        }

        /// FMI 2.0 `fmi2GetRealOutputDerivatives` (not supported: logs, `fmi2Error`).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
            c: $crate::ffi::Fmi2Component,
            _vr: *const $crate::ffi::Fmi2ValueReference,
            _nvr: usize,
            _order: *const $crate::ffi::Fmi2Integer,
            _value: *mut $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_real_output_derivatives::<$model>(c) }
        }

        /// FMI 2.0 `fmi2DoStep`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2DoStep(
            c: $crate::ffi::Fmi2Component,
            current_communication_point: $crate::ffi::Fmi2Real,
            communication_step_size: $crate::ffi::Fmi2Real,
            no_set_fmu_state_prior_to_current_point: $crate::ffi::Fmi2Boolean,
        ) -> $crate::ffi::Fmi2Status {
            unsafe {
                $crate::__export::do_step::<$model>(
                    c,
                    current_communication_point,
                    communication_step_size,
                    no_set_fmu_state_prior_to_current_point,
                )
            }
        }

        /// FMI 2.0 `fmi2CancelStep` (never in sequence: stepping is synchronous).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2CancelStep(
            c: $crate::ffi::Fmi2Component,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::cancel_step::<$model>(c) }
        }

        /// FMI 2.0 `fmi2GetStatus`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetStatus(
            c: $crate::ffi::Fmi2Component,
            kind: ::std::ffi::c_int,
            value: *mut $crate::ffi::Fmi2Status,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_status::<$model>(c, kind, value) }
        }

        /// FMI 2.0 `fmi2GetRealStatus` (`fmi2LastSuccessfulTime`).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetRealStatus(
            c: $crate::ffi::Fmi2Component,
            kind: ::std::ffi::c_int,
            value: *mut $crate::ffi::Fmi2Real,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_real_status::<$model>(c, kind, value) }
        }

        /// FMI 2.0 `fmi2GetIntegerStatus`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetIntegerStatus(
            c: $crate::ffi::Fmi2Component,
            kind: ::std::ffi::c_int,
            value: *mut $crate::ffi::Fmi2Integer,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_integer_status::<$model>(c, kind, value) }
        }

        /// FMI 2.0 `fmi2GetBooleanStatus` (`fmi2Terminated`).
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetBooleanStatus(
            c: $crate::ffi::Fmi2Component,
            kind: ::std::ffi::c_int,
            value: *mut $crate::ffi::Fmi2Boolean,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_boolean_status::<$model>(c, kind, value) }
        }

        /// FMI 2.0 `fmi2GetStringStatus`.
        ///
        /// # Safety
        /// FMI 2.0 calling contract.
        #[allow(unsafe_code, non_snake_case)]
        #[no_mangle]
        pub unsafe extern "C" fn fmi2GetStringStatus(
            c: $crate::ffi::Fmi2Component,
            kind: ::std::ffi::c_int,
            value: *mut $crate::ffi::Fmi2String,
        ) -> $crate::ffi::Fmi2Status {
            unsafe { $crate::__export::get_string_status::<$model>(c, kind, value) }
        }
    };
}

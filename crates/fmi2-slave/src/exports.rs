//! The generic implementations behind the 34 exported `fmi2*` functions.
//!
//! Not public API: the [`export_fmi2!`](crate::export_fmi2) macro instantiates these for one
//! model type. Every function that takes an `fmi2Component` runs through [`guard`]:
//!
//! 1. NULL component → `fmi2Error` (nothing to log to);
//! 2. magic tag and model type checked (best-effort detection of foreign pointers);
//! 3. call-state check against the FMI 2.0 CS table ([`Func::mask`]); out of sequence →
//!    log `"Illegal call sequence: <function> in state <state>"`, `fmi2Error`;
//! 4. the body runs inside `std::panic::catch_unwind`; `Err(message)` → log
//!    `"<function>: <message>"`, `fmi2Error`; a panic → log `"<function>: panic: <text>"`,
//!    `fmi2Fatal`.
//!
//! Every `fmi2Error` puts the instance into the `error` state, every `fmi2Fatal` into
//! `fatal` (FMI 2.0 section 2.1.3), except a refusal by the functions that only read FMU
//! states or make one from bytes ([`Func::refusal_keeps_state`]): bad bytes do not touch the
//! instance, which goes on from where it was.

#![allow(clippy::missing_safety_doc)] // safety contract documented once, on the module

use std::any::{Any, TypeId};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::ptr;

use crate::description::{Causality, ModelDescription, ValueType, Variability, Variable};
use crate::ffi::*;
use crate::logger::{status_category, to_cstring, Logger};
use crate::serial::{self, ns_to_s, LayerState};
use crate::state::{CallState, Func};
use crate::unload;
use crate::uri::resource_dir_from_uri;
use crate::{Fmi2Model, InstanceContext, StepContext, StepOutcome};

const INSTANCE_MAGIC: u64 = u64::from_le_bytes(*b"FMI2INST");
const STATE_MAGIC: u64 = u64::from_le_bytes(*b"FMI2STAT");
const DEAD_MAGIC: u64 = u64::from_le_bytes(*b"FMI2DEAD");

/// Header at offset 0 of every instance and every FMU state box.
#[repr(C)]
#[derive(Clone, Copy)]
struct Tag {
    magic: u64,
    type_id: TypeId,
}

impl Tag {
    fn new<M: 'static>(magic: u64) -> Self {
        Tag {
            magic,
            type_id: TypeId::of::<M>(),
        }
    }
}

/// Value-reference lookup built once per instance: per type, `(vr, position)` sorted by vr.
/// Enumeration variables are listed with the Integers: their value references share that
/// numbering and `fmi2GetInteger`/`fmi2SetInteger` access them (FMI 2.0 sections 2.1.7,
/// 2.2.7).
struct VarIndex {
    by_type: [Vec<(u32, usize)>; 4],
    /// Positions of the Real outputs, the variables every step checks for finite values.
    real_outputs: Vec<usize>,
}

fn type_slot(ty: ValueType) -> usize {
    match ty {
        ValueType::Real => 0,
        ValueType::Integer => 1,
        ValueType::Boolean => 2,
        ValueType::String => 3,
    }
}

impl VarIndex {
    fn new(desc: &ModelDescription) -> Self {
        let mut by_type: [Vec<(u32, usize)>; 4] = Default::default();
        for (pos, v) in desc.variables.iter().enumerate() {
            by_type[type_slot(v.value_type())].push((v.value_reference, pos));
        }
        for list in &mut by_type {
            list.sort_unstable();
        }
        let real_outputs = (desc.variables.iter().enumerate())
            .filter(|(_, v)| v.causality == Causality::Output && v.value_type() == ValueType::Real)
            .map(|(pos, _)| pos)
            .collect();
        VarIndex {
            by_type,
            real_outputs,
        }
    }

    fn position(&self, ty: ValueType, vr: u32) -> Option<usize> {
        let list = &self.by_type[type_slot(ty)];
        list.binary_search_by_key(&vr, |&(r, _)| r)
            .ok()
            .map(|i| list[i].1)
    }
}

/// One FMU instance; `fmi2Component` points here. Allocated in `fmi2Instantiate`, freed in
/// `fmi2FreeInstance`.
#[repr(C)]
pub(crate) struct Instance<M> {
    tag: Tag,
    layer: LayerState,
    model: M,
    logger: Logger,
    desc: &'static ModelDescription,
    guid: String,
    instance_name: String,
    resource_dir: Option<PathBuf>,
    index: VarIndex,
    /// Backing store of the pointers returned by the last `fmi2GetString`.
    strings: Vec<CString>,
}

/// An `fmi2FMUstate`: a deep copy of the model and the layer state.
#[repr(C)]
struct StateBox<M> {
    tag: Tag,
    layer: LayerState,
    model: M,
    /// Cached serialization (filled by `fmi2SerializedFMUstateSize`).
    serialized: Option<Vec<u8>>,
}

impl<M: Fmi2Model> Instance<M> {
    fn enter_error(&mut self) {
        if self.layer.call_state != CallState::Fatal {
            self.layer.call_state = CallState::Error;
        }
    }

    fn lookup(&self, ty: ValueType, vr: u32) -> Result<&'static Variable, String> {
        let desc = self.desc;
        if let Some(pos) = self.index.position(ty, vr) {
            return Ok(&desc.variables[pos]);
        }
        let other = [
            ValueType::Real,
            ValueType::Integer,
            ValueType::Boolean,
            ValueType::String,
        ]
        .into_iter()
        .filter(|&t| t != ty)
        .find_map(|t| self.index.position(t, vr).map(|p| &desc.variables[p]));
        Err(match other {
            Some(v) => format!(
                "value reference {vr} does not name a variable of type {} (it names the {} variable '{}')",
                ty.as_str(),
                v.kind.element(),
                v.name
            ),
            None => format!("unknown value reference {vr}: no {} variable has it", ty.as_str()),
        })
    }

    /// The first Real output whose value is not finite, as a message naming it; `None` when
    /// every one is finite. The layer's guarantee that no step or initialization ends with
    /// fmi2OK and a non-finite output (FMI 2.0 section 4.2.2: a step whose result is not
    /// usable is `fmi2Discard`), whatever the model computed. A getter's own error is the
    /// master's to see when it reads the variable, not a reason here.
    fn non_finite_output(&self) -> Option<String> {
        self.index
            .real_outputs
            .iter()
            .map(|&pos| &self.desc.variables[pos])
            .find_map(|v| match self.model.get_real(v.value_reference) {
                Ok(x) if !x.is_finite() => Some(format!(
                    "output '{}' (vr {}) is not finite ({x})",
                    v.name, v.value_reference
                )),
                _ => None,
            })
    }

    /// The serialized FMU state of `layer` and `model` (format: [`serial`]).
    fn serialize(&self, layer: &LayerState, model: &M) -> Result<Vec<u8>, String> {
        layer.check_continuable()?;
        let mut result = Ok(());
        let mut out = Vec::new();
        serial::encode(
            &mut out,
            &self.desc.model_identifier,
            &self.guid,
            layer,
            |o| {
                result = model.serialize_state(o);
            },
        );
        result.map(|()| out)
    }
}

/// Whether the setting rules of FMI 2.0 section 4.2.4 (footnotes of the state table)
/// allow `fmi2Set*` on `var` in `state`.
fn check_settable(var: &Variable, state: CallState) -> Result<(), String> {
    let vr = var.value_reference;
    let name = &var.name;
    if var.variability == Variability::Constant {
        return Err(format!(
            "variable '{name}' (vr {vr}) is a constant and cannot be set"
        ));
    }
    match var.causality {
        Causality::Input => Ok(()),
        Causality::Parameter => {
            if var.variability == Variability::Tunable || state != CallState::StepComplete {
                Ok(())
            } else {
                Err(format!(
                    "variable '{name}' (vr {vr}) is a fixed parameter; it can only be set before fmi2ExitInitializationMode"
                ))
            }
        }
        other => Err(format!(
            "variable '{name}' (vr {vr}) has causality {} and cannot be set",
            other.as_str()
        )),
    }
}

fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_string()
    }
}

/// Drops a panic payload; a payload whose destructor panics again is leaked instead of
/// aborting the master.
fn drop_payload(payload: Box<dyn Any + Send>) {
    if let Err(again) = catch_unwind(AssertUnwindSafe(move || drop(payload))) {
        std::mem::forget(again);
    }
}

/// Reads the tag at `p`. Best effort: `p` must be NULL or point to readable memory of at
/// least `size_of::<Tag>()` bytes.
unsafe fn tag_matches<M: 'static>(p: *const c_void, magic: u64) -> bool {
    if p.is_null() || !p.cast::<Tag>().is_aligned() {
        return false;
    }
    // SAFETY: non-NULL and aligned; readability is the caller's contract. The magic is read
    // first, so the TypeId is only read from memory that carries our tag.
    let first = unsafe { p.cast::<u64>().read() };
    if first != magic {
        return false;
    }
    // SAFETY: as above; `Tag` is `repr(C)` with the magic at offset 0.
    let tag = unsafe { p.cast::<Tag>().read() };
    tag.type_id == TypeId::of::<M>()
}

/// The instance behind `c`, if `c` is a live instance of model `M`.
unsafe fn instance_mut<'a, M: Fmi2Model>(c: Fmi2Component) -> Option<&'a mut Instance<M>> {
    // SAFETY: forwarded contract: `c` is NULL or points to readable memory.
    if unsafe { tag_matches::<M>(c, INSTANCE_MAGIC) } {
        // SAFETY: the tag identifies an `Instance<M>` created by `fmi2Instantiate` and not yet
        // freed; FMI forbids concurrent calls on one instance, so the borrow is unique.
        Some(unsafe { &mut *c.cast::<Instance<M>>() })
    } else {
        None
    }
}

/// The state box behind `s`, if `s` is a live FMU state of model `M`.
unsafe fn state_box_mut<'a, M: Fmi2Model>(s: Fmi2FmuState) -> Result<&'a mut StateBox<M>, String> {
    if s.is_null() {
        return Err("FMUstate is NULL".to_string());
    }
    // SAFETY: forwarded contract: `s` points to readable memory.
    if unsafe { tag_matches::<M>(s, STATE_MAGIC) } {
        // SAFETY: the tag identifies a `StateBox<M>` from `fmi2GetFMUstate` or
        // `fmi2DeSerializeFMUstate`, not yet freed.
        Ok(unsafe { &mut *s.cast::<StateBox<M>>() })
    } else {
        Err("FMUstate is not an FMU state created by this FMU (or was already freed)".to_string())
    }
}

/// Input array of `n` elements; NULL allowed only when `n == 0`.
unsafe fn in_slice<'a, T>(p: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        return Ok(&[]);
    }
    check_array(p, n, what)?;
    // SAFETY: non-NULL, aligned, size in range; the caller promises `n` readable elements.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// Output array of `n` elements; NULL allowed only when `n == 0`.
unsafe fn out_slice<'a, T>(p: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        return Ok(&mut []);
    }
    check_array(p, n, what)?;
    // SAFETY: non-NULL, aligned, size in range; the caller promises `n` writable elements
    // not aliased by any other argument.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

fn check_array<T>(p: *const T, n: usize, what: &str) -> Result<(), String> {
    if p.is_null() {
        return Err(format!("{what} is NULL but its length is {n}"));
    }
    if !p.is_aligned() {
        return Err(format!("{what} is misaligned"));
    }
    if n > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(format!("{what} has an impossible length {n}"));
    }
    Ok(())
}

/// Output scalar.
unsafe fn out_ref<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T, String> {
    check_array(p, 1, what)?;
    // SAFETY: non-NULL and aligned; the caller promises it is writable.
    Ok(unsafe { &mut *p })
}

/// A borrowed UTF-8 string from the master.
unsafe fn c_str<'a>(p: *const c_char) -> Result<Option<&'a str>, String> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: non-NULL; the caller promises a NUL-terminated string valid for the call.
    let s = unsafe { CStr::from_ptr(p) };
    s.to_str()
        .map(Some)
        .map_err(|_| "string is not valid UTF-8".to_string())
}

/// The one guard every instance function runs in (see the module documentation).
///
/// # Safety
/// `c` is NULL or points to readable memory (ideally an instance of `M`); pointers used by
/// `body` follow the FMI 2.0 contract of the function.
unsafe fn guard<M, F>(c: Fmi2Component, func: Func, body: F) -> Fmi2Status
where
    M: Fmi2Model,
    F: FnOnce(&mut Instance<M>) -> Result<Fmi2Status, String>,
{
    // SAFETY: forwarded contract.
    let Some(inst) = (unsafe { instance_mut::<M>(c) }) else {
        return Fmi2Status::Error;
    };
    if inst.logger.calls_enabled() {
        inst.logger.info("logCalls", func.name());
    }
    let state = inst.layer.call_state;
    if !func.allowed_in(state) {
        inst.logger.error(&format!(
            "Illegal call sequence: {} in state {}",
            func.name(),
            state.name()
        ));
        inst.enter_error();
        return Fmi2Status::Error;
    }
    match catch_unwind(AssertUnwindSafe(|| body(&mut *inst))) {
        Ok(Ok(status)) => status,
        Ok(Err(msg)) => {
            inst.logger.error(&format!("{}: {msg}", func.name()));
            if !func.refusal_keeps_state() {
                inst.enter_error();
            }
            Fmi2Status::Error
        }
        Err(payload) => {
            let text = panic_text(payload.as_ref());
            drop_payload(payload);
            inst.logger.log(
                Fmi2Status::Fatal,
                status_category(Fmi2Status::Fatal),
                &format!("{}: panic: {text}", func.name()),
            );
            inst.layer.call_state = CallState::Fatal;
            Fmi2Status::Fatal
        }
    }
}

// ---------------------------------------------------------------------------------------
// Functions without an instance
// ---------------------------------------------------------------------------------------

/// `fmi2GetTypesPlatform` → `"default"`.
pub fn get_types_platform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion` → `"2.0"`.
pub fn get_version() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate` (FMI 2.0 section 2.1.5). Returns NULL (after logging, where a logger
/// exists) for a NULL functions struct or logger, a NULL/empty/non-UTF-8 instance name, a
/// missing or wrong GUID, an fmuType other than Co-Simulation, an invalid model
/// description, a bad resource URI, a failing or panicking `Fmi2Model::instantiate`.
pub unsafe fn instantiate<M: Fmi2Model>(
    instance_name: Fmi2String,
    fmu_type: c_int,
    guid: Fmi2String,
    resource_location: Fmi2String,
    functions: *const Fmi2CallbackFunctions,
    _visible: Fmi2Boolean,
    logging_on: Fmi2Boolean,
) -> Fmi2Component {
    if functions.is_null() || !functions.is_aligned() {
        return ptr::null_mut();
    }
    // SAFETY: non-NULL and aligned; the master passes a valid callback struct.
    let functions = unsafe { functions.read() };
    let Some(callback) = functions.logger else {
        return ptr::null_mut();
    };
    let env = functions.component_environment;
    // SAFETY: the master passes NUL-terminated strings or NULL.
    let name = unsafe { c_str(instance_name) };
    let guid = unsafe { c_str(guid) };
    let resource = unsafe { c_str(resource_location) };
    let display_name = match &name {
        Ok(Some(n)) => *n,
        _ => "",
    };
    // Counted before the model description is touched: the library's destructor frees the
    // `LibraryLazy` values only when no instance is alive or being made.
    unload::instance_begun();
    let result = catch_unwind(AssertUnwindSafe(|| {
        instantiate_checked::<M>(
            callback,
            env,
            name,
            fmu_type,
            guid,
            resource,
            logging_on != FMI2_FALSE,
        )
    }));
    if !matches!(result, Ok(Some(_))) {
        unload::instance_ended();
    }
    match result {
        Ok(Some(instance)) => Box::into_raw(instance).cast(),
        Ok(None) => ptr::null_mut(),
        Err(payload) => {
            let text = panic_text(payload.as_ref());
            drop_payload(payload);
            Logger::master(callback, env, display_name, &[], true).log(
                Fmi2Status::Fatal,
                status_category(Fmi2Status::Fatal),
                &format!("fmi2Instantiate: panic: {text}"),
            );
            ptr::null_mut()
        }
    }
}

fn instantiate_checked<M: Fmi2Model>(
    callback: Fmi2CallbackLogger,
    env: Fmi2ComponentEnvironment,
    name: Result<Option<&str>, String>,
    fmu_type: c_int,
    guid: Result<Option<&str>, String>,
    resource: Result<Option<&str>, String>,
    logging_on: bool,
) -> Option<Box<Instance<M>>> {
    let display_name = match &name {
        Ok(Some(n)) => *n,
        _ => "",
    };
    let early = Logger::master(callback, env, display_name, &[], logging_on);
    let fail = |msg: String| {
        early.error(&format!("fmi2Instantiate: {msg}"));
        None
    };
    let name = match name {
        Ok(Some("")) => return fail("instanceName is empty".into()),
        Ok(Some(n)) => n,
        Ok(None) => return fail("instanceName is NULL".into()),
        Err(e) => return fail(format!("instanceName: {e}")),
    };
    if fmu_type != FMI2_CO_SIMULATION {
        let kind = if fmu_type == FMI2_MODEL_EXCHANGE {
            "fmi2ModelExchange"
        } else {
            "unknown"
        };
        return fail(format!(
            "fmuType {fmu_type} ({kind}) is not supported; this FMU implements Co-Simulation only (fmi2CoSimulation = 1)"
        ));
    }
    let desc: &'static ModelDescription = M::description();
    if let Err(problems) = desc.validate() {
        return fail(format!(
            "the model description of '{}' is invalid: {}",
            desc.model_identifier,
            problems.join("; ")
        ));
    }
    let expected = desc.guid();
    match guid {
        Ok(Some(g)) if g == expected => {}
        Ok(Some(g)) => {
            return fail(format!("wrong GUID: expected {expected}, given {g}"));
        }
        Ok(None) => return fail(format!("fmuGUID is NULL; expected {expected}")),
        Err(e) => return fail(format!("fmuGUID: {e}; expected {expected}")),
    }
    let resource_dir = match resource.and_then(resource_dir_from_uri) {
        Ok(dir) => dir,
        Err(e) => return fail(e),
    };
    let logger = Logger::master(callback, env, name, &desc.log_categories, logging_on);
    let ctx = InstanceContext {
        instance_name: name,
        resource_dir: resource_dir.as_deref(),
        logger: &logger,
    };
    let model = match M::instantiate(&ctx) {
        Ok(m) => m,
        Err(e) => {
            logger.error(&format!("fmi2Instantiate: {e}"));
            return None;
        }
    };
    Some(Box::new(Instance {
        tag: Tag::new::<M>(INSTANCE_MAGIC),
        layer: LayerState::new(),
        model,
        logger,
        desc,
        guid: expected,
        instance_name: name.to_string(),
        resource_dir,
        index: VarIndex::new(desc),
        strings: Vec::new(),
    }))
}

/// `fmi2FreeInstance`: NULL or a foreign pointer is ignored; otherwise
/// [`Fmi2Model::release`] runs and the instance and everything it owns is dropped (a panic
/// in either is logged, not propagated).
pub unsafe fn free_instance<M: Fmi2Model>(c: Fmi2Component) {
    // SAFETY: forwarded contract.
    let Some(inst) = (unsafe { instance_mut::<M>(c) }) else {
        return;
    };
    if inst.logger.calls_enabled() {
        inst.logger.info("logCalls", Func::FreeInstance.name());
    }
    inst.tag.magic = DEAD_MAGIC;
    {
        // SAFETY: `c` came from `Box::into_raw` in `fmi2Instantiate` (tag checked) and is
        // freed exactly once (the tag is now dead).
        let boxed = unsafe { Box::from_raw(c.cast::<Instance<M>>()) };
        let Instance {
            mut model, logger, ..
        } = *boxed;
        let guarded = |what: &str, f: &mut dyn FnMut()| {
            if let Err(payload) = catch_unwind(AssertUnwindSafe(f)) {
                let text = panic_text(payload.as_ref());
                drop_payload(payload);
                logger.log(
                    Fmi2Status::Fatal,
                    status_category(Fmi2Status::Fatal),
                    &format!("fmi2FreeInstance: panic while {what} the model: {text}"),
                );
            }
        };
        guarded("releasing", &mut || model.release(&logger));
        let mut model = Some(model);
        guarded("dropping", &mut || drop(model.take()));
    }
    // Everything of the instance is dropped: it no longer holds the library's tables.
    unload::instance_ended();
}

// ---------------------------------------------------------------------------------------
// Instance functions
// ---------------------------------------------------------------------------------------

/// `fmi2SetDebugLogging` (FMI 2.0 section 2.1.5).
pub unsafe fn set_debug_logging<M: Fmi2Model>(
    c: Fmi2Component,
    logging_on: Fmi2Boolean,
    n_categories: usize,
    categories: *const Fmi2String,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::SetDebugLogging, |inst| {
            let cats = in_slice(categories, n_categories, "categories[]")?;
            let mut names = Vec::with_capacity(cats.len());
            for (i, &p) in cats.iter().enumerate() {
                match c_str(p) {
                    Ok(Some(s)) => names.push(s),
                    Ok(None) => return Err(format!("categories[{i}] is NULL")),
                    Err(e) => return Err(format!("categories[{i}]: {e}")),
                }
            }
            inst.logger
                .set_debug_logging(logging_on != FMI2_FALSE, &names)?;
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2SetupExperiment` (FMI 2.0 section 2.1.6): records start time, stop time (if
/// defined) and tolerance (if defined); resets the step clock.
pub unsafe fn setup_experiment<M: Fmi2Model>(
    c: Fmi2Component,
    tolerance_defined: Fmi2Boolean,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: Fmi2Boolean,
    stop_time: f64,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::SetupExperiment, |inst| {
            if !start_time.is_finite() {
                return Err(format!("startTime = {start_time} is not finite"));
            }
            let stop = (stop_time_defined != FMI2_FALSE).then_some(stop_time);
            if let Some(stop) = stop {
                if !stop.is_finite() || stop < start_time {
                    return Err(format!(
                        "stopTime = {stop} must be finite and >= startTime = {start_time}"
                    ));
                }
            }
            let tol = (tolerance_defined != FMI2_FALSE).then_some(tolerance);
            if let Some(tol) = tol {
                if !(tol.is_finite() && tol >= 0.0) {
                    return Err(format!("tolerance = {tol} must be finite and >= 0"));
                }
            }
            inst.model
                .setup_experiment(&inst.logger, start_time, stop, tol)?;
            inst.layer.start_time = start_time;
            inst.layer.stop_time = stop;
            inst.layer.tolerance = tol;
            inst.layer.time_ns = 0;
            inst.layer.steps = 0;
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2EnterInitializationMode` (FMI 2.0 section 2.1.6).
pub unsafe fn enter_initialization_mode<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::EnterInitializationMode, |inst| {
            inst.model.enter_initialization_mode(&inst.logger)?;
            inst.layer.call_state = CallState::InitializationMode;
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2ExitInitializationMode` (FMI 2.0 section 2.1.6) → `stepComplete`; a Real output
/// that is not finite then ([`Instance::non_finite_output`]) is `fmi2Error` naming it.
pub unsafe fn exit_initialization_mode<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::ExitInitializationMode, |inst| {
            inst.model.exit_initialization_mode(&inst.logger)?;
            if let Some(bad) = inst.non_finite_output() {
                return Err(format!("{bad} at the end of initialization"));
            }
            inst.layer.call_state = CallState::StepComplete;
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2Terminate` (FMI 2.0 section 2.1.6) → `terminated`.
pub unsafe fn terminate<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::Terminate, |inst| {
            inst.model.terminate(&inst.logger)?;
            inst.layer.call_state = CallState::Terminated;
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2Reset` (FMI 2.0 section 2.1.6): re-runs `Fmi2Model::instantiate` with the stored
/// context (after [`Fmi2Model::release`] on the old model) and returns to `instantiated`;
/// logger and debug-logging settings are kept.
pub unsafe fn reset<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::Reset, |inst| {
            let model = {
                let ctx = InstanceContext {
                    instance_name: &inst.instance_name,
                    resource_dir: inst.resource_dir.as_deref(),
                    logger: &inst.logger,
                };
                M::instantiate(&ctx)?
            };
            inst.model.release(&inst.logger);
            inst.model = model;
            inst.layer = LayerState::new();
            inst.strings.clear();
            Ok(Fmi2Status::Ok)
        })
    }
}

/// The error of a model's getter or setter for `vr`, after the variable's name and value
/// reference.
fn model_error(inst: &Instance<impl Fmi2Model>, ty: ValueType, vr: u32, e: &str) -> String {
    let name = inst.lookup(ty, vr).map(|v| v.name.as_str()).unwrap_or("?");
    format!("variable '{name}' (vr {vr}): {e}")
}

/// Shared body of `fmi2Get{Real,Integer,Boolean}`: validate every value reference, then
/// read; a model's `Err` is the call's `fmi2Error`.
unsafe fn get_values<M: Fmi2Model, T>(
    c: Fmi2Component,
    func: Func,
    ty: ValueType,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut T,
    get: impl Fn(&M, u32) -> Result<T, String>,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, func, |inst| {
            let vrs = in_slice(vr, nvr, "vr[]")?;
            let out = out_slice(value, nvr, "value[]")?;
            for &r in vrs {
                inst.lookup(ty, r)?;
            }
            for (o, &r) in out.iter_mut().zip(vrs) {
                *o = get(&inst.model, r).map_err(|e| model_error(inst, ty, r, &e))?;
            }
            Ok(Fmi2Status::Ok)
        })
    }
}

/// Shared body of `fmi2Set{Real,Integer,Boolean}`: validate every element (type, state and
/// causality rules, `check`), then apply.
#[allow(clippy::too_many_arguments)]
unsafe fn set_values<M: Fmi2Model, T: Copy>(
    c: Fmi2Component,
    func: Func,
    ty: ValueType,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const T,
    check: impl Fn(&Variable, T) -> Result<(), String>,
    set: impl Fn(&mut M, &Logger, u32, T) -> Result<(), String>,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, func, |inst| {
            let vrs = in_slice(vr, nvr, "vr[]")?;
            let vals = in_slice(value, nvr, "value[]")?;
            let state = inst.layer.call_state;
            for (&r, &v) in vrs.iter().zip(vals) {
                let var = inst.lookup(ty, r)?;
                check_settable(var, state)?;
                check(var, v)?;
            }
            for (&r, &v) in vrs.iter().zip(vals) {
                set(&mut inst.model, &inst.logger, r, v)
                    .map_err(|e| model_error(inst, ty, r, &e))?;
            }
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2GetReal` (FMI 2.0 section 2.1.7).
pub unsafe fn get_real<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        get_values::<M, _>(
            c,
            Func::GetReal,
            ValueType::Real,
            vr,
            nvr,
            value,
            M::get_real,
        )
    }
}

/// `fmi2GetInteger` (FMI 2.0 section 2.1.7): Integer and Enumeration variables.
pub unsafe fn get_integer<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        get_values::<M, _>(
            c,
            Func::GetInteger,
            ValueType::Integer,
            vr,
            nvr,
            value,
            M::get_integer,
        )
    }
}

/// `fmi2GetBoolean` (FMI 2.0 section 2.1.7): writes `fmi2True` (1) or `fmi2False` (0).
pub unsafe fn get_boolean<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        get_values::<M, _>(
            c,
            Func::GetBoolean,
            ValueType::Boolean,
            vr,
            nvr,
            value,
            |m, r| {
                m.get_boolean(r)
                    .map(|b| if b { FMI2_TRUE } else { FMI2_FALSE })
            },
        )
    }
}

/// `fmi2GetString` (FMI 2.0 section 2.1.7): the returned pointers stay valid until the next
/// `fmi2GetString`, `fmi2Reset` or `fmi2FreeInstance` on this instance.
pub unsafe fn get_string<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *mut Fmi2String,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetString, |inst| {
            let vrs = in_slice(vr, nvr, "vr[]")?;
            let out = out_slice(value, nvr, "value[]")?;
            for &r in vrs {
                inst.lookup(ValueType::String, r)?;
            }
            inst.strings.clear();
            for (o, &r) in out.iter_mut().zip(vrs) {
                let s = inst
                    .model
                    .get_string(r)
                    .map_err(|e| model_error(inst, ValueType::String, r, &e))?;
                let s = to_cstring(&s);
                // The CString's heap buffer does not move when `strings` grows.
                *o = s.as_ptr();
                inst.strings.push(s);
            }
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2SetReal` (FMI 2.0 section 2.1.7): NaN and ±inf are rejected naming the variable.
pub unsafe fn set_real<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Real,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        set_values::<M, f64>(
            c,
            Func::SetReal,
            ValueType::Real,
            vr,
            nvr,
            value,
            |var, v| {
                if v.is_finite() {
                    Ok(())
                } else {
                    Err(format!(
                        "variable '{}' (vr {}): value {v} is not finite",
                        var.name, var.value_reference
                    ))
                }
            },
            |m, log, r, v| m.set_real(log, r, v),
        )
    }
}

/// `fmi2SetInteger` (FMI 2.0 section 2.1.7): Integer and Enumeration variables. Whether a
/// value lies in an Integer's range or is one of an Enumeration's items is the model's
/// check (its setter's error names the variable, the value and what it accepts).
pub unsafe fn set_integer<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        set_values::<M, c_int>(
            c,
            Func::SetInteger,
            ValueType::Integer,
            vr,
            nvr,
            value,
            |_, _| Ok(()),
            |m, log, r, v| m.set_integer(log, r, v),
        )
    }
}

/// `fmi2SetBoolean` (FMI 2.0 section 2.1.7): any non-zero value is true.
pub unsafe fn set_boolean<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        set_values::<M, c_int>(
            c,
            Func::SetBoolean,
            ValueType::Boolean,
            vr,
            nvr,
            value,
            |_, _| Ok(()),
            |m, log, r, v| m.set_boolean(log, r, v != FMI2_FALSE),
        )
    }
}

/// `fmi2SetString` (FMI 2.0 section 2.1.7): each value must be a non-NULL UTF-8 string.
pub unsafe fn set_string<M: Fmi2Model>(
    c: Fmi2Component,
    vr: *const Fmi2ValueReference,
    nvr: usize,
    value: *const Fmi2String,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract; each `value[i]` is NUL-terminated or NULL.
    unsafe {
        set_values::<M, Fmi2String>(
            c,
            Func::SetString,
            ValueType::String,
            vr,
            nvr,
            value,
            |var, p| match c_str(p) {
                Ok(Some(_)) => Ok(()),
                Ok(None) => Err(format!(
                    "variable '{}' (vr {}): value is NULL",
                    var.name, var.value_reference
                )),
                Err(e) => Err(format!(
                    "variable '{}' (vr {}): {e}",
                    var.name, var.value_reference
                )),
            },
            |m, log, r, p| match c_str(p) {
                Ok(Some(s)) => m.set_string(log, r, s),
                _ => Err("value changed during the call".to_string()),
            },
        )
    }
}

/// Refuses the FMU-state functions the model description does not declare
/// (`canGetAndSetFMUstate`, `canSerializeFMUstate`).
fn require_state_capability<M: Fmi2Model>(serialize: bool) -> Result<(), String> {
    let d = M::description();
    if !d.can_get_and_set_fmu_state {
        return Err(format!(
            "{} declares canGetAndSetFMUstate=\"false\"",
            d.model_identifier
        ));
    }
    if serialize && !d.can_serialize_fmu_state {
        return Err(format!(
            "{} declares canSerializeFMUstate=\"false\"",
            d.model_identifier
        ));
    }
    Ok(())
}

/// `fmi2GetFMUstate` (FMI 2.0 section 2.1.8): a deep copy of the model and the layer state
/// (call state, clock, start/stop time). A non-NULL `*FMUstate` is overwritten in place.
pub unsafe fn get_fmu_state<M: Fmi2Model>(
    c: Fmi2Component,
    fmu_state: *mut Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetFmuState, |inst| {
            require_state_capability::<M>(false)?;
            let slot = out_ref(fmu_state, "FMUstate")?;
            if slot.is_null() {
                let b = Box::new(StateBox {
                    tag: Tag::new::<M>(STATE_MAGIC),
                    layer: inst.layer,
                    model: inst.model.clone(),
                    serialized: None,
                });
                *slot = Box::into_raw(b).cast();
            } else {
                let b = state_box_mut::<M>(*slot)?;
                b.layer = inst.layer;
                b.model.clone_from(&inst.model);
                b.serialized = None;
            }
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2SetFMUstate` (FMI 2.0 section 2.1.8): restores model and layer state; the model
/// keeps what is the instance's own ([`Fmi2Model::restore_state`]).
pub unsafe fn set_fmu_state<M: Fmi2Model>(c: Fmi2Component, fmu_state: Fmi2FmuState) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::SetFmuState, |inst| {
            require_state_capability::<M>(false)?;
            let b = state_box_mut::<M>(fmu_state)?;
            inst.model.restore_state(&inst.logger, &b.model)?;
            inst.layer = b.layer;
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2FreeFMUstate` (FMI 2.0 section 2.1.8): frees `*FMUstate` and sets it to NULL; a
/// NULL `*FMUstate` is ignored.
pub unsafe fn free_fmu_state<M: Fmi2Model>(
    c: Fmi2Component,
    fmu_state: *mut Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::FreeFmuState, |_inst| {
            let slot = out_ref(fmu_state, "FMUstate")?;
            if slot.is_null() {
                return Ok(Fmi2Status::Ok);
            }
            let b = state_box_mut::<M>(*slot)?;
            b.tag.magic = DEAD_MAGIC;
            // SAFETY: tag checked: the box came from `Box::into_raw` and is freed once.
            drop(Box::from_raw((*slot).cast::<StateBox<M>>()));
            *slot = ptr::null_mut();
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2SerializedFMUstateSize` (FMI 2.0 section 2.1.8).
pub unsafe fn serialized_fmu_state_size<M: Fmi2Model>(
    c: Fmi2Component,
    fmu_state: Fmi2FmuState,
    size: *mut usize,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::SerializedFmuStateSize, |inst| {
            require_state_capability::<M>(true)?;
            let b = state_box_mut::<M>(fmu_state)?;
            let size = out_ref(size, "size")?;
            if b.serialized.is_none() {
                b.serialized = Some(inst.serialize(&b.layer, &b.model)?);
            }
            *size = b.serialized.as_ref().map_or(0, Vec::len);
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2SerializeFMUstate` (FMI 2.0 section 2.1.8): `size` must equal the value reported by
/// `fmi2SerializedFMUstateSize`. Format: see the crate documentation.
pub unsafe fn serialize_fmu_state<M: Fmi2Model>(
    c: Fmi2Component,
    fmu_state: Fmi2FmuState,
    serialized_state: *mut Fmi2Byte,
    size: usize,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::SerializeFmuState, |inst| {
            require_state_capability::<M>(true)?;
            let b = state_box_mut::<M>(fmu_state)?;
            if b.serialized.is_none() {
                b.serialized = Some(inst.serialize(&b.layer, &b.model)?);
            }
            let bytes = b.serialized.as_deref().unwrap_or_default();
            if size != bytes.len() {
                return Err(format!(
                    "size {size} does not match the serialized size {} (fmi2SerializedFMUstateSize)",
                    bytes.len()
                ));
            }
            let out = out_slice(serialized_state.cast::<u8>(), size, "serializedState[]")?;
            out.copy_from_slice(bytes);
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2DeSerializeFMUstate` (FMI 2.0 section 2.1.8): checks magic, format version,
/// checksum, model identifier, GUID, lengths and the layer state's sense ([`serial`]), lets
/// the model read its part into a copy of this instance's model, and checks the model's
/// time against the clock. Writes a new FMU state to `*FMUstate` (or overwrites a non-NULL
/// one); on any error neither the instance nor `*FMUstate` changes.
pub unsafe fn de_serialize_fmu_state<M: Fmi2Model>(
    c: Fmi2Component,
    serialized_state: *const Fmi2Byte,
    size: usize,
    fmu_state: *mut Fmi2FmuState,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::DeSerializeFmuState, |inst| {
            require_state_capability::<M>(true)?;
            let slot = out_ref(fmu_state, "FMUstate")?;
            let existing = if slot.is_null() {
                None
            } else {
                Some(state_box_mut::<M>(*slot)?)
            };
            let bytes = in_slice(serialized_state.cast::<u8>(), size, "serializedState[]")?;
            let (layer, model_bytes) =
                serial::decode(bytes, &inst.desc.model_identifier, &inst.guid)?;
            let mut model = inst.model.clone();
            model
                .deserialize_state(&inst.logger, model_bytes)
                .map_err(|e| format!("model state: {e}"))?;
            serial::check_model_time(&layer, model.time())?;
            match existing {
                Some(b) => {
                    b.layer = layer;
                    b.model = model;
                    b.serialized = None;
                }
                None => {
                    let b = Box::new(StateBox {
                        tag: Tag::new::<M>(STATE_MAGIC),
                        layer,
                        model,
                        serialized: None,
                    });
                    *slot = Box::into_raw(b).cast();
                }
            }
            Ok(Fmi2Status::Ok)
        })
    }
}

/// `fmi2GetDirectionalDerivative`: not supported (`providesDirectionalDerivative="false"`).
pub unsafe fn get_directional_derivative<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetDirectionalDerivative, |_| {
            Err("not supported: this FMU declares providesDirectionalDerivative=\"false\"".into())
        })
    }
}

/// `fmi2SetRealInputDerivatives`: not supported (`canInterpolateInputs="false"`).
pub unsafe fn set_real_input_derivatives<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::SetRealInputDerivatives, |_| {
            Err("not supported: this FMU declares canInterpolateInputs=\"false\"".into())
        })
    }
}

/// `fmi2GetRealOutputDerivatives`: not supported (`maxOutputDerivativeOrder="0"`).
pub unsafe fn get_real_output_derivatives<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetRealOutputDerivatives, |_| {
            Err("not supported: this FMU declares maxOutputDerivativeOrder=\"0\"".into())
        })
    }
}

/// `fmi2DoStep` (FMI 2.0 section 4.2.2). Checks `h > 0` and finite,
/// `currentCommunicationPoint` finite and within `1e-5 * max(1, |t|)` of the internal time
/// `t`, and `t + h <= stopTime + tol` when a stop time is defined. The internal clock counts
/// whole nanoseconds and follows the master's time: the step ends at the master's
/// `currentCommunicationPoint + h` rounded to the nanosecond ([`step_end_ns`]), so the clock
/// does not drift from a master that sums its steps, and a step that rounds to no
/// nanosecond (a master's last step clipped to the stop time, `2.5e-12` s) advances nothing
/// and returns `fmi2OK` without calling the model. Model outcome: `Ok` → `fmi2OK`;
/// `Warning` → logged, `fmi2Warning`, time advanced; `Discard` → logged, `fmi2Discard`,
/// state `stepFailed`, time not advanced; `Error` → `fmi2Error`, state `error`. After an
/// `Ok` or `Warning` every Real output is checked ([`Instance::non_finite_output`]): a
/// non-finite one turns the step into `fmi2Discard` naming it.
pub unsafe fn do_step<M: Fmi2Model>(
    c: Fmi2Component,
    current_communication_point: f64,
    communication_step_size: f64,
    _no_set_fmu_state_prior_to_current_point: Fmi2Boolean,
) -> Fmi2Status {
    let (tc, h) = (current_communication_point, communication_step_size);
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::DoStep, |inst| {
            let t = inst.layer.time();
            if !(h.is_finite() && h > 0.0) {
                return Err(format!(
                    "communicationStepSize = {h} must be finite and > 0"
                ));
            }
            if !tc.is_finite() {
                return Err(format!("currentCommunicationPoint = {tc} is not finite"));
            }
            let tol = 1e-5 * t.abs().max(1.0);
            if (tc - t).abs() > tol {
                return Err(format!(
                    "currentCommunicationPoint = {tc} does not match the FMU's time {t} (tolerance {tol})"
                ));
            }
            if let Some(stop) = inst.layer.stop_time {
                if t + h > stop + tol {
                    return Err(format!(
                        "currentCommunicationPoint + communicationStepSize = {t} + {h} = {} exceeds stopTime = {stop} (tolerance {tol})",
                        t + h
                    ));
                }
            }
            let Some(new_ns) = step_end_ns(inst.layer.time_ns, tc - t, h) else {
                return Err(format!(
                    "communicationStepSize = {h} overflows the FMU's nanosecond clock"
                ));
            };
            let dns = new_ns - inst.layer.time_ns;
            if dns == 0 {
                return Ok(Fmi2Status::Ok);
            }
            let step = StepContext {
                current_time: t,
                step_size: ns_to_s(dns),
                step_index: inst.layer.steps,
            };
            let advance = |inst: &mut Instance<M>| {
                inst.layer.time_ns = new_ns;
                inst.layer.steps += 1;
            };
            let mut outcome = inst.model.do_step(&inst.logger, &step);
            if matches!(outcome, StepOutcome::Ok | StepOutcome::Warning(_)) {
                if let Some(bad) = inst.non_finite_output() {
                    outcome = StepOutcome::Discard(bad);
                }
            }
            match outcome {
                StepOutcome::Ok => {
                    advance(inst);
                    Ok(Fmi2Status::Ok)
                }
                StepOutcome::Warning(msg) => {
                    advance(inst);
                    inst.logger.warning(&format!("fmi2DoStep: {msg}"));
                    Ok(Fmi2Status::Warning)
                }
                StepOutcome::Discard(msg) => {
                    inst.layer.call_state = CallState::StepFailed;
                    inst.logger.log(
                        Fmi2Status::Discard,
                        status_category(Fmi2Status::Discard),
                        &format!(
                            "fmi2DoStep: step from t = {t} with h = {h} discarded: {msg}; last successful time {t}"
                        ),
                    );
                    Ok(Fmi2Status::Discard)
                }
                StepOutcome::Error(msg) => Err(msg),
            }
        })
    }
}

/// The clock (ns since the start time) at the end of `fmi2DoStep(tc, h)` from `now_ns`, where
/// `lead = tc - t` is how far the master's `currentCommunicationPoint` is ahead of the FMU's
/// time `t` (within the tolerance `fmi2DoStep` checked): the master's end of step `tc + h`,
/// rounded to the nanosecond, and never before `now_ns`. With a master whose time is exact
/// (`lead = 0`) every step is `round(h * 1e9)` ns; with one that sums `t += h` the clock
/// follows its sum (the clipped last step of such a master, `stop - t` of a few 1e-12 s,
/// rounds to 0 ns: nothing to advance). `None` when the end overflows the i64 clock.
fn step_end_ns(now_ns: i64, lead: f64, h: f64) -> Option<i64> {
    let dns = ((lead + h) * 1e9).round().max(0.0);
    // 9.2e18 ns ~ 292 years: both checks keep the i64 clock exact and finite.
    if dns < 9.2e18 {
        now_ns.checked_add(dns as i64)
    } else {
        None
    }
}

/// `fmi2CancelStep`: never allowed (`fmi2DoStep` is synchronous, so there is no step in
/// progress); always an illegal call sequence.
pub unsafe fn cancel_step<M: Fmi2Model>(c: Fmi2Component) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::CancelStep, |_| {
            Err("no asynchronous step is in progress".into())
        })
    }
}

fn status_kind_name(kind: c_int) -> Option<&'static str> {
    Some(match kind {
        FMI2_DO_STEP_STATUS => "fmi2DoStepStatus",
        FMI2_PENDING_STATUS => "fmi2PendingStatus",
        FMI2_LAST_SUCCESSFUL_TIME => "fmi2LastSuccessfulTime",
        FMI2_TERMINATED => "fmi2Terminated",
        _ => return None,
    })
}

/// Status not available for `kind`: FMI 2.0 section 4.2.3 prescribes `fmi2Discard`
/// (the call state does not change). An undefined `kind` is an error.
fn status_unavailable<M: Fmi2Model>(
    inst: &Instance<M>,
    func: Func,
    kind: c_int,
) -> Result<Fmi2Status, String> {
    let Some(kind_name) = status_kind_name(kind) else {
        return Err(format!("undefined fmi2StatusKind {kind}"));
    };
    inst.logger.log(
        Fmi2Status::Discard,
        status_category(Fmi2Status::Discard),
        &format!(
            "{}: status {kind_name} is not available (this FMU steps synchronously and never returns fmi2Pending)",
            func.name()
        ),
    );
    Ok(Fmi2Status::Discard)
}

/// `fmi2GetStatus` (FMI 2.0 section 4.2.3): nothing is available → `fmi2Discard`.
pub unsafe fn get_status<M: Fmi2Model>(
    c: Fmi2Component,
    kind: c_int,
    value: *mut Fmi2Status,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetStatus, |inst| {
            out_ref(value, "value")?;
            status_unavailable(inst, Func::GetStatus, kind)
        })
    }
}

/// `fmi2GetRealStatus` (FMI 2.0 section 4.2.3): `fmi2LastSuccessfulTime` → the internal
/// time (not advanced by a discarded step); other kinds → `fmi2Discard`.
pub unsafe fn get_real_status<M: Fmi2Model>(
    c: Fmi2Component,
    kind: c_int,
    value: *mut Fmi2Real,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetRealStatus, |inst| {
            let out = out_ref(value, "value")?;
            if kind == FMI2_LAST_SUCCESSFUL_TIME {
                *out = inst.layer.time();
                Ok(Fmi2Status::Ok)
            } else {
                status_unavailable(inst, Func::GetRealStatus, kind)
            }
        })
    }
}

/// `fmi2GetIntegerStatus` (FMI 2.0 section 4.2.3): no integer status exists → `fmi2Discard`.
pub unsafe fn get_integer_status<M: Fmi2Model>(
    c: Fmi2Component,
    kind: c_int,
    value: *mut Fmi2Integer,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetIntegerStatus, |inst| {
            out_ref(value, "value")?;
            status_unavailable(inst, Func::GetIntegerStatus, kind)
        })
    }
}

/// `fmi2GetBooleanStatus` (FMI 2.0 section 4.2.3): `fmi2Terminated` → `fmi2False` (the
/// model never asks to end the simulation); other kinds → `fmi2Discard`.
pub unsafe fn get_boolean_status<M: Fmi2Model>(
    c: Fmi2Component,
    kind: c_int,
    value: *mut Fmi2Boolean,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetBooleanStatus, |inst| {
            let out = out_ref(value, "value")?;
            if kind == FMI2_TERMINATED {
                *out = FMI2_FALSE;
                Ok(Fmi2Status::Ok)
            } else {
                status_unavailable(inst, Func::GetBooleanStatus, kind)
            }
        })
    }
}

/// `fmi2GetStringStatus` (FMI 2.0 section 4.2.3): never pending → `fmi2Discard`.
pub unsafe fn get_string_status<M: Fmi2Model>(
    c: Fmi2Component,
    kind: c_int,
    value: *mut Fmi2String,
) -> Fmi2Status {
    // SAFETY: forwarded FMI contract.
    unsafe {
        guard::<M, _>(c, Func::GetStringStatus, |inst| {
            out_ref(value, "value")?;
            status_unavailable(inst, Func::GetStringStatus, kind)
        })
    }
}

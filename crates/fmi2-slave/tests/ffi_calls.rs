//! In-process tests of the exported C ABI: the function set, instantiation, pointer
//! checks, the call-sequence table, variable access rules, logging and the panic guard.
#![allow(clippy::unwrap_used)]

mod common;

fmi2_slave::export_fmi2!(common::Lag);

use std::ffi::{c_char, c_int, CStr, CString};
use std::ptr;

use common::*;
use fmi2_slave::ffi::*;
use fmi2_slave::testing::{callbacks, Capture, Fmu};
use fmi2_slave::Fmi2Status;

const ERROR: c_int = Fmi2Status::Error as c_int;

fn assert_logged(fmu: &Fmu, status: Fmi2Status, fragment: &str) {
    let msgs = fmu.messages();
    assert!(
        msgs.iter()
            .any(|m| m.status == status as c_int && m.text.contains(fragment)),
        "no {status:?} message containing {fragment:?} in {msgs:#?}"
    );
}

/// A fresh instance driven into `state` ("instantiated", "initializationMode",
/// "stepComplete", "stepFailed", "terminated", "error").
fn fresh_in(state: &str) -> Fmu {
    let f = new_fmu("in_state");
    unsafe {
        match state {
            "instantiated" => {}
            "initializationMode" => {
                assert_eq!(f.setup(0.0, None), Fmi2Status::Ok);
                assert_eq!(fmi2EnterInitializationMode(f.c), Fmi2Status::Ok);
            }
            "stepComplete" => f.init(0.0, None),
            "stepFailed" => {
                f.init(0.0, None);
                assert_eq!(f.set_integer(I_FAULT, FAULT_DISCARD), Fmi2Status::Ok);
                assert_eq!(f.step(0.0, 0.1), Fmi2Status::Discard);
            }
            "terminated" => {
                f.init(0.0, None);
                assert_eq!(fmi2Terminate(f.c), Fmi2Status::Ok);
            }
            "error" => {
                assert_eq!(fmi2DoStep(f.c, 0.0, 0.1, 0), Fmi2Status::Error);
            }
            other => panic!("unknown state {other}"),
        }
    }
    f.clear();
    f
}

#[test]
fn exports_all_34_functions_with_fmi2_signatures() {
    use std::ffi::c_void;
    type C = Fmi2Component;
    type S = Fmi2Status;
    type Vr = *const Fmi2ValueReference;
    // Each cast fails to compile unless the export has exactly the fmi2FunctionTypes.h type.
    let table: [(&str, usize); 34] = [
        (
            "fmi2GetTypesPlatform",
            fmi2GetTypesPlatform as unsafe extern "C" fn() -> *const c_char as usize,
        ),
        (
            "fmi2GetVersion",
            fmi2GetVersion as unsafe extern "C" fn() -> *const c_char as usize,
        ),
        (
            "fmi2SetDebugLogging",
            fmi2SetDebugLogging as unsafe extern "C" fn(C, c_int, usize, *const *const c_char) -> S
                as usize,
        ),
        (
            "fmi2Instantiate",
            fmi2Instantiate
                as unsafe extern "C" fn(
                    *const c_char,
                    c_int,
                    *const c_char,
                    *const c_char,
                    *const Fmi2CallbackFunctions,
                    c_int,
                    c_int,
                ) -> C as usize,
        ),
        (
            "fmi2FreeInstance",
            fmi2FreeInstance as unsafe extern "C" fn(C) as usize,
        ),
        (
            "fmi2SetupExperiment",
            fmi2SetupExperiment as unsafe extern "C" fn(C, c_int, f64, f64, c_int, f64) -> S
                as usize,
        ),
        (
            "fmi2EnterInitializationMode",
            fmi2EnterInitializationMode as unsafe extern "C" fn(C) -> S as usize,
        ),
        (
            "fmi2ExitInitializationMode",
            fmi2ExitInitializationMode as unsafe extern "C" fn(C) -> S as usize,
        ),
        (
            "fmi2Terminate",
            fmi2Terminate as unsafe extern "C" fn(C) -> S as usize,
        ),
        (
            "fmi2Reset",
            fmi2Reset as unsafe extern "C" fn(C) -> S as usize,
        ),
        (
            "fmi2GetReal",
            fmi2GetReal as unsafe extern "C" fn(C, Vr, usize, *mut f64) -> S as usize,
        ),
        (
            "fmi2GetInteger",
            fmi2GetInteger as unsafe extern "C" fn(C, Vr, usize, *mut c_int) -> S as usize,
        ),
        (
            "fmi2GetBoolean",
            fmi2GetBoolean as unsafe extern "C" fn(C, Vr, usize, *mut c_int) -> S as usize,
        ),
        (
            "fmi2GetString",
            fmi2GetString as unsafe extern "C" fn(C, Vr, usize, *mut *const c_char) -> S as usize,
        ),
        (
            "fmi2SetReal",
            fmi2SetReal as unsafe extern "C" fn(C, Vr, usize, *const f64) -> S as usize,
        ),
        (
            "fmi2SetInteger",
            fmi2SetInteger as unsafe extern "C" fn(C, Vr, usize, *const c_int) -> S as usize,
        ),
        (
            "fmi2SetBoolean",
            fmi2SetBoolean as unsafe extern "C" fn(C, Vr, usize, *const c_int) -> S as usize,
        ),
        (
            "fmi2SetString",
            fmi2SetString as unsafe extern "C" fn(C, Vr, usize, *const *const c_char) -> S as usize,
        ),
        (
            "fmi2GetFMUstate",
            fmi2GetFMUstate as unsafe extern "C" fn(C, *mut *mut c_void) -> S as usize,
        ),
        (
            "fmi2SetFMUstate",
            fmi2SetFMUstate as unsafe extern "C" fn(C, *mut c_void) -> S as usize,
        ),
        (
            "fmi2FreeFMUstate",
            fmi2FreeFMUstate as unsafe extern "C" fn(C, *mut *mut c_void) -> S as usize,
        ),
        (
            "fmi2SerializedFMUstateSize",
            fmi2SerializedFMUstateSize as unsafe extern "C" fn(C, *mut c_void, *mut usize) -> S
                as usize,
        ),
        (
            "fmi2SerializeFMUstate",
            fmi2SerializeFMUstate as unsafe extern "C" fn(C, *mut c_void, *mut c_char, usize) -> S
                as usize,
        ),
        (
            "fmi2DeSerializeFMUstate",
            fmi2DeSerializeFMUstate
                as unsafe extern "C" fn(C, *const c_char, usize, *mut *mut c_void) -> S
                as usize,
        ),
        (
            "fmi2GetDirectionalDerivative",
            fmi2GetDirectionalDerivative
                as unsafe extern "C" fn(C, Vr, usize, Vr, usize, *const f64, *mut f64) -> S
                as usize,
        ),
        (
            "fmi2SetRealInputDerivatives",
            fmi2SetRealInputDerivatives
                as unsafe extern "C" fn(C, Vr, usize, *const c_int, *const f64) -> S
                as usize,
        ),
        (
            "fmi2GetRealOutputDerivatives",
            fmi2GetRealOutputDerivatives
                as unsafe extern "C" fn(C, Vr, usize, *const c_int, *mut f64) -> S
                as usize,
        ),
        (
            "fmi2DoStep",
            fmi2DoStep as unsafe extern "C" fn(C, f64, f64, c_int) -> S as usize,
        ),
        (
            "fmi2CancelStep",
            fmi2CancelStep as unsafe extern "C" fn(C) -> S as usize,
        ),
        (
            "fmi2GetStatus",
            fmi2GetStatus as unsafe extern "C" fn(C, c_int, *mut S) -> S as usize,
        ),
        (
            "fmi2GetRealStatus",
            fmi2GetRealStatus as unsafe extern "C" fn(C, c_int, *mut f64) -> S as usize,
        ),
        (
            "fmi2GetIntegerStatus",
            fmi2GetIntegerStatus as unsafe extern "C" fn(C, c_int, *mut c_int) -> S as usize,
        ),
        (
            "fmi2GetBooleanStatus",
            fmi2GetBooleanStatus as unsafe extern "C" fn(C, c_int, *mut c_int) -> S as usize,
        ),
        (
            "fmi2GetStringStatus",
            fmi2GetStringStatus as unsafe extern "C" fn(C, c_int, *mut *const c_char) -> S as usize,
        ),
    ];
    let mut addresses: Vec<usize> = table.iter().map(|(_, a)| *a).collect();
    addresses.sort_unstable();
    addresses.dedup();
    assert_eq!(addresses.len(), 34, "34 distinct functions");
    assert!(addresses.iter().all(|&a| a != 0));
    unsafe {
        assert_eq!(
            CStr::from_ptr(fmi2GetTypesPlatform()).to_str(),
            Ok("default")
        );
        assert_eq!(CStr::from_ptr(fmi2GetVersion()).to_str(), Ok("2.0"));
    }
}

#[test]
fn instantiate_returns_null_and_logs_for_each_bad_argument() {
    let capture = Capture::default();
    let functions = callbacks(&capture);
    let good_guid = guid();
    let name = CString::new("x").unwrap();
    let empty = CString::new("").unwrap();
    let wrong_guid = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
    let http = CString::new("http://example.com/resources").unwrap();
    let refuse = CString::new("refuse").unwrap();
    let no_logger = Fmi2CallbackFunctions {
        logger: None,
        ..functions
    };
    let expected = good_guid.to_str().unwrap().to_string();
    /// (what, instanceName, fmuType, fmuGUID, fmuResourceLocation, functions, message)
    type Case<'a> = (
        &'a str,
        *const c_char,
        c_int,
        *const c_char,
        *const c_char,
        *const Fmi2CallbackFunctions,
        Option<String>,
    );
    let cases: Vec<Case<'_>> = vec![
        (
            "NULL functions",
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            good_guid.as_ptr(),
            ptr::null(),
            ptr::null(),
            None,
        ),
        (
            "NULL logger",
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            good_guid.as_ptr(),
            ptr::null(),
            &no_logger,
            None,
        ),
        (
            "NULL name",
            ptr::null(),
            FMI2_CO_SIMULATION,
            good_guid.as_ptr(),
            ptr::null(),
            &functions,
            Some("fmi2Instantiate: instanceName is NULL".into()),
        ),
        (
            "empty name",
            empty.as_ptr(),
            FMI2_CO_SIMULATION,
            good_guid.as_ptr(),
            ptr::null(),
            &functions,
            Some("fmi2Instantiate: instanceName is empty".into()),
        ),
        (
            "NULL GUID",
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            ptr::null(),
            ptr::null(),
            &functions,
            Some(format!("fmuGUID is NULL; expected {expected}")),
        ),
        (
            "wrong GUID",
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            wrong_guid.as_ptr(),
            ptr::null(),
            &functions,
            Some(format!(
                "wrong GUID: expected {expected}, given {{00000000-0000-0000-0000-000000000000}}"
            )),
        ),
        (
            "Model Exchange",
            name.as_ptr(),
            FMI2_MODEL_EXCHANGE,
            good_guid.as_ptr(),
            ptr::null(),
            &functions,
            Some("fmuType 0 (fmi2ModelExchange) is not supported".into()),
        ),
        (
            "http resources",
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            good_guid.as_ptr(),
            http.as_ptr(),
            &functions,
            Some("is not a file: URI".into()),
        ),
        (
            "model refuses",
            refuse.as_ptr(),
            FMI2_CO_SIMULATION,
            good_guid.as_ptr(),
            ptr::null(),
            &functions,
            Some("fmi2Instantiate: the test model refuses the instance name 'refuse'".into()),
        ),
    ];
    for (what, n, ty, g, uri, f, expected_msg) in cases {
        capture.messages.lock().unwrap().clear();
        let c = unsafe { fmi2Instantiate(n, ty, g, uri, f, FMI2_FALSE, FMI2_FALSE) };
        assert!(c.is_null(), "{what}: instance created");
        let msgs = capture.messages.lock().unwrap().clone();
        match expected_msg {
            None => assert!(msgs.is_empty(), "{what}: {msgs:?}"),
            Some(m) => {
                assert_eq!(msgs.len(), 1, "{what}: {msgs:?}");
                assert!(
                    msgs[0].text.contains(&m),
                    "{what}: {:?} lacks {m:?}",
                    msgs[0].text
                );
                assert_eq!(msgs[0].status, ERROR, "{what}");
                assert_eq!(msgs[0].format, "%s", "{what}");
                assert_eq!(msgs[0].category, "logStatusError", "{what}");
            }
        }
    }
}

#[test]
fn instantiate_passes_decoded_resource_dir_and_accepts_null_memory_callbacks() {
    let dir = tempfile::Builder::new()
        .prefix("res dir æ ")
        .tempdir()
        .unwrap();
    let path = dir.path().to_str().unwrap();
    let mut uri = String::from("file://");
    for b in path.bytes() {
        if b.is_ascii_alphanumeric() || b"/-_.".contains(&b) {
            uri.push(char::from(b));
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri.push('/');
    assert!(uri.contains("%20") && uri.contains("%C3%A6"), "{uri}");
    let fmu = try_fmu("with_resources", Some(&uri), true).unwrap();
    let want = format!("instantiated with resources at {:?}", Some(dir.path()));
    let msgs = fmu.messages();
    assert!(
        msgs.iter()
            .any(|m| m.text == want && m.status == 0 && m.category == "logEvents"),
        "{msgs:#?} lacks {want:?}"
    );
    assert_eq!(msgs[0].instance, "with_resources");
}

#[test]
fn null_component_is_an_error_everywhere_and_free_null_is_a_no_op() {
    let c = ptr::null_mut();
    let vr = 1u32;
    let mut r = 0.0;
    let mut i = 0;
    let mut s: Fmi2FmuState = ptr::null_mut();
    let mut p: *const c_char = ptr::null();
    let mut st = Fmi2Status::Ok;
    let mut size = 0usize;
    unsafe {
        fmi2FreeInstance(c);
        let statuses = [
            fmi2SetDebugLogging(c, 1, 0, ptr::null()),
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            fmi2EnterInitializationMode(c),
            fmi2ExitInitializationMode(c),
            fmi2Terminate(c),
            fmi2Reset(c),
            fmi2GetReal(c, &vr, 1, &mut r),
            fmi2GetInteger(c, &vr, 1, &mut i),
            fmi2GetBoolean(c, &vr, 1, &mut i),
            fmi2GetString(c, &vr, 1, &mut p),
            fmi2SetReal(c, &vr, 1, &r),
            fmi2SetInteger(c, &vr, 1, &i),
            fmi2SetBoolean(c, &vr, 1, &i),
            fmi2SetString(c, &vr, 1, &p),
            fmi2GetFMUstate(c, &mut s),
            fmi2SetFMUstate(c, s),
            fmi2FreeFMUstate(c, &mut s),
            fmi2SerializedFMUstateSize(c, s, &mut size),
            fmi2SerializeFMUstate(c, s, ptr::null_mut(), 0),
            fmi2DeSerializeFMUstate(c, ptr::null(), 0, &mut s),
            fmi2GetDirectionalDerivative(c, &vr, 1, &vr, 1, &r, &mut r),
            fmi2SetRealInputDerivatives(c, &vr, 1, &i, &r),
            fmi2GetRealOutputDerivatives(c, &vr, 1, &i, &mut r),
            fmi2DoStep(c, 0.0, 0.1, 0),
            fmi2CancelStep(c),
            fmi2GetStatus(c, FMI2_DO_STEP_STATUS, &mut st),
            fmi2GetRealStatus(c, FMI2_LAST_SUCCESSFUL_TIME, &mut r),
            fmi2GetIntegerStatus(c, FMI2_DO_STEP_STATUS, &mut i),
            fmi2GetBooleanStatus(c, FMI2_TERMINATED, &mut i),
            fmi2GetStringStatus(c, FMI2_PENDING_STATUS, &mut p),
        ];
        assert!(
            statuses.iter().all(|&s| s == Fmi2Status::Error),
            "{statuses:?}"
        );
    }
    assert!(s.is_null());
}

#[test]
fn foreign_pointers_are_rejected_by_the_magic_tag() {
    let mut foreign = [0x5au64; 32];
    let c = foreign.as_mut_ptr().cast();
    let vr = R_U;
    let mut r = 0.0;
    unsafe {
        assert_eq!(fmi2GetReal(c, &vr, 1, &mut r), Fmi2Status::Error);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), Fmi2Status::Error);
        fmi2FreeInstance(c); // ignored, must not free stack memory
    }
    assert!(
        foreign.iter().all(|&w| w == 0x5a),
        "foreign memory untouched"
    );

    let fmu = fresh_in("stepComplete");
    unsafe {
        assert_eq!(
            fmi2SetFMUstate(fmu.c, foreign.as_mut_ptr().cast()),
            Fmi2Status::Error
        );
    }
    assert_logged(
        &fmu,
        Fmi2Status::Error,
        "fmi2SetFMUstate: FMUstate is not an FMU state created by this FMU",
    );
    // an instance is not an FMU state either
    unsafe { fmi2Reset(fmu.c) };
    unsafe {
        assert_eq!(fmi2SetFMUstate(fmu.c, fmu.c), Fmi2Status::Error);
    }
}

#[test]
fn null_arrays_and_outputs_are_errors_unless_empty() {
    let fmu = fresh_in("stepComplete");
    unsafe {
        // n == 0 with NULL arrays is fine
        assert_eq!(
            fmi2GetReal(fmu.c, ptr::null(), 0, ptr::null_mut()),
            Fmi2Status::Ok
        );
        assert_eq!(
            fmi2SetReal(fmu.c, ptr::null(), 0, ptr::null()),
            Fmi2Status::Ok
        );
        type Call = fn(&Fmu) -> Fmi2Status;
        let checks: [(Call, &str); 10] = [
            (
                |f| fmi2GetReal(f.c, ptr::null(), 1, &mut 0.0),
                "fmi2GetReal: vr[] is NULL but its length is 1",
            ),
            (
                |f| fmi2GetReal(f.c, &R_U, 1, ptr::null_mut()),
                "fmi2GetReal: value[] is NULL",
            ),
            (
                |f| fmi2SetInteger(f.c, &I_FAULT, 1, ptr::null()),
                "fmi2SetInteger: value[] is NULL",
            ),
            (
                |f| fmi2GetString(f.c, &S_LABEL, 1, ptr::null_mut()),
                "fmi2GetString: value[] is NULL",
            ),
            (
                |f| fmi2GetRealStatus(f.c, FMI2_LAST_SUCCESSFUL_TIME, ptr::null_mut()),
                "fmi2GetRealStatus: value is NULL",
            ),
            (
                |f| fmi2GetFMUstate(f.c, ptr::null_mut()),
                "fmi2GetFMUstate: FMUstate is NULL",
            ),
            (
                |f| fmi2SetFMUstate(f.c, ptr::null_mut()),
                "fmi2SetFMUstate: FMUstate is NULL",
            ),
            (
                |f| fmi2FreeFMUstate(f.c, ptr::null_mut()),
                "fmi2FreeFMUstate: FMUstate is NULL",
            ),
            (
                |f| fmi2DeSerializeFMUstate(f.c, ptr::null(), 4, &mut ptr::null_mut()),
                "fmi2DeSerializeFMUstate: serializedState[] is NULL",
            ),
            (
                |f| fmi2SetDebugLogging(f.c, 1, 2, ptr::null()),
                "fmi2SetDebugLogging: categories[] is NULL",
            ),
        ];
        for (call, fragment) in checks {
            assert_eq!(call(&fmu), Fmi2Status::Error, "{fragment}");
            assert!(
                fmu.last_text().contains(fragment),
                "{:?} lacks {fragment:?}",
                fmu.last_text()
            );
            // every error leaves the instance in the error state; reset and re-initialize
            assert_eq!(fmi2Reset(fmu.c), Fmi2Status::Ok);
            fmu.init(0.0, None);
        }
        // a NULL element of a string array names the variable
        let label = S_LABEL;
        let values: [*const c_char; 1] = [ptr::null()];
        assert_eq!(fmi2Reset(fmu.c), Fmi2Status::Ok);
        assert_eq!(
            fmi2SetString(fmu.c, &label, 1, values.as_ptr()),
            Fmi2Status::Error
        );
        assert!(fmu
            .last_text()
            .contains("variable 'label' (vr 1): value is NULL"));
        // freeing a NULL *FMUstate is a no-op
        assert_eq!(fmi2Reset(fmu.c), Fmi2Status::Ok);
        let mut none: Fmi2FmuState = ptr::null_mut();
        assert_eq!(fmi2FreeFMUstate(fmu.c, &mut none), Fmi2Status::Ok);
    }
}

#[test]
fn illegal_call_sequence_is_logged_and_enters_the_error_state() {
    let fmu = new_fmu("seq");
    unsafe {
        assert_eq!(fmu.step(0.0, 0.1), Fmi2Status::Error);
        let m = fmu.messages();
        assert_eq!(m.len(), 1);
        assert_eq!(
            m[0].text,
            "Illegal call sequence: fmi2DoStep in state instantiated"
        );
        assert_eq!(
            (m[0].status, m[0].category.as_str(), m[0].format.as_str()),
            (ERROR, "logStatusError", "%s")
        );
        // in the error state setters are illegal, getters and reset are not
        assert_eq!(fmu.set_real(R_U, 1.0), Fmi2Status::Error);
        assert_eq!(
            fmu.last_text(),
            "Illegal call sequence: fmi2SetReal in state error"
        );
        assert_eq!(fmu.try_get_real(R_U), (Fmi2Status::Ok, 0.0));
        assert_eq!(fmi2Reset(fmu.c), Fmi2Status::Ok);
        fmu.init(0.0, None);
        assert_eq!(fmu.step(0.0, 0.1), Fmi2Status::Ok);
    }
}

#[test]
fn call_state_table() {
    use Fmi2Status::{Error as E, Ok as K};
    type Call = fn(&Fmu) -> Fmi2Status;
    let get: Call = |f| f.try_get_real(R_U).0;
    let set: Call = |f| f.set_real(R_U, 1.0);
    let setup: Call = |f| f.setup(0.0, None);
    let enter: Call = |f| unsafe { fmi2EnterInitializationMode(f.c) };
    let exit: Call = |f| unsafe { fmi2ExitInitializationMode(f.c) };
    let step: Call = |f| f.step(0.0, 0.1);
    let term: Call = |f| unsafe { fmi2Terminate(f.c) };
    let reset: Call = |f| unsafe { fmi2Reset(f.c) };
    let cancel: Call = |f| unsafe { fmi2CancelStep(f.c) };
    let status: Call = |f| {
        let mut t = 0.0;
        unsafe { fmi2GetRealStatus(f.c, FMI2_LAST_SUCCESSFUL_TIME, &mut t) }
    };
    let state: Call = |f| {
        let mut s = ptr::null_mut();
        let r = unsafe { fmi2GetFMUstate(f.c, &mut s) };
        if !s.is_null() {
            unsafe { fmi2FreeFMUstate(f.c, &mut s) };
        }
        r
    };
    let debug: Call = |f| unsafe { fmi2SetDebugLogging(f.c, 0, 0, ptr::null()) };
    let calls: [(&str, Call); 12] = [
        ("fmi2GetReal", get),
        ("fmi2SetReal", set),
        ("fmi2SetupExperiment", setup),
        ("fmi2EnterInitializationMode", enter),
        ("fmi2ExitInitializationMode", exit),
        ("fmi2DoStep", step),
        ("fmi2Terminate", term),
        ("fmi2Reset", reset),
        ("fmi2CancelStep", cancel),
        ("fmi2GetRealStatus", status),
        ("fmi2GetFMUstate", state),
        ("fmi2SetDebugLogging", debug),
    ];
    // expected result per state, in the order of `calls` (FMI 2.0 section 4.2.4)
    let table: [(&str, [Fmi2Status; 12]); 6] = [
        ("instantiated", [E, K, K, K, E, E, E, K, E, E, K, K]),
        ("initializationMode", [K, K, E, E, K, E, E, K, E, E, K, K]),
        ("stepComplete", [K, K, E, E, E, K, K, K, E, K, K, K]),
        ("stepFailed", [K, E, E, E, E, E, K, K, E, K, K, K]),
        ("terminated", [K, E, E, E, E, E, E, K, E, K, K, K]),
        ("error", [K, E, E, E, E, E, E, K, E, E, K, K]),
    ];
    for (state, expected) in table {
        for ((name, call), want) in calls.iter().zip(expected) {
            let f = fresh_in(state);
            let got = call(&f);
            assert_eq!(got, want, "{name} in state {state}: {:?}", f.messages());
            if want == E {
                assert_eq!(
                    f.last_text(),
                    format!("Illegal call sequence: {name} in state {state}"),
                    "{name} in {state}"
                );
            }
        }
    }
}

#[test]
fn setting_obeys_causality_variability_and_state() {
    // (state, variable kind, vr, expected status, message fragment)
    let cases: Vec<(&str, &str, u32, Fmi2Status, &str)> = vec![
        ("instantiated", "real", R_Y, Fmi2Status::Error, "variable 'y' (vr 2) has causality output and cannot be set"),
        ("instantiated", "real", R_RATE, Fmi2Status::Error, "variable 'rate' (vr 5) has causality calculatedParameter and cannot be set"),
        ("instantiated", "int", I_VERSION, Fmi2Status::Error, "variable 'version' (vr 4) is a constant and cannot be set"),
        ("instantiated", "int", I_STEPS, Fmi2Status::Error, "variable 'steps' (vr 2) has causality output"),
        ("instantiated", "real", R_Y0, Fmi2Status::Ok, ""),
        ("instantiated", "real", R_T, Fmi2Status::Ok, ""),
        ("instantiated", "real", R_U, Fmi2Status::Ok, ""),
        ("instantiated", "int", I_SUBSTEPS, Fmi2Status::Ok, ""),
        ("initializationMode", "real", R_Y0, Fmi2Status::Ok, ""),
        ("initializationMode", "real", R_Y, Fmi2Status::Error, "variable 'y' (vr 2) has causality output"),
        ("stepComplete", "real", R_Y0, Fmi2Status::Error, "variable 'y0' (vr 4) is a fixed parameter; it can only be set before fmi2ExitInitializationMode"),
        ("stepComplete", "int", I_SUBSTEPS, Fmi2Status::Error, "variable 'substeps' (vr 1) is a fixed parameter"),
        ("stepComplete", "real", R_T, Fmi2Status::Ok, ""),
        ("stepComplete", "real", R_U, Fmi2Status::Ok, ""),
        ("stepComplete", "int", I_FAULT, Fmi2Status::Ok, ""),
        ("stepComplete", "bool", B_ENABLED, Fmi2Status::Ok, ""),
        ("stepComplete", "string", S_LABEL, Fmi2Status::Error, "variable 'label' (vr 1) is a fixed parameter"),
    ];
    let text = CString::new("new").unwrap();
    for (state, kind, vr, want, fragment) in cases {
        let f = fresh_in(state);
        let got = unsafe {
            match kind {
                "real" => f.set_real(vr, 2.0),
                "int" => f.set_integer(vr, 2),
                "bool" => f.set_boolean(vr, false),
                _ => fmi2SetString(f.c, &vr, 1, &text.as_ptr()),
            }
        };
        assert_eq!(got, want, "{kind} vr {vr} in {state}: {:?}", f.messages());
        if want == Fmi2Status::Error {
            assert!(
                f.last_text().contains(fragment),
                "{:?} lacks {fragment:?}",
                f.last_text()
            );
            assert!(f.last_text().starts_with("fmi2Set"));
        }
    }
}

#[test]
fn unknown_or_mistyped_value_references_are_named() {
    let f = fresh_in("stepComplete");
    let mut r = 0.0;
    let mut i = 0;
    unsafe {
        assert_eq!(fmi2GetReal(f.c, &99, 1, &mut r), Fmi2Status::Error);
        assert_eq!(
            f.last_text(),
            "fmi2GetReal: unknown value reference 99: no Real variable has it"
        );
        fmi2Reset(f.c);
        f.init(0.0, None);
        assert_eq!(fmi2GetInteger(f.c, &R_RATE, 1, &mut i), Fmi2Status::Error);
        assert_eq!(
            f.last_text(),
            "fmi2GetInteger: value reference 5 does not name a variable of type Integer (it names the Real variable 'rate')"
        );
        fmi2Reset(f.c);
        assert_eq!(f.set_boolean(77, true), Fmi2Status::Error);
        assert!(f.last_text().contains("unknown value reference 77"));
        // a bad element in the middle: nothing is read into value[]
        fmi2Reset(f.c);
        f.init(0.0, None);
        let vrs = [R_U, 42, R_Y];
        let mut out = [-1.0; 3];
        assert_eq!(
            fmi2GetReal(f.c, vrs.as_ptr(), 3, out.as_mut_ptr()),
            Fmi2Status::Error
        );
        assert_eq!(out, [-1.0; 3]);
        assert!(f.last_text().contains("value reference 42"));
    }
}

/// A getter's `Err` (here the model refusing `steps` in fault mode 5, as a model refuses a
/// reference it does not decode) is fmi2Error naming the variable, never fmi2Fatal.
#[test]
fn a_getter_error_of_the_model_is_an_error_naming_the_variable() {
    let f = fresh_in("stepComplete");
    assert_eq!(f.set_integer(I_FAULT, FAULT_GET), Fmi2Status::Ok);
    let mut i = 0;
    unsafe {
        assert_eq!(fmi2GetInteger(f.c, &I_STEPS, 1, &mut i), Fmi2Status::Error);
    }
    assert_eq!(
        f.last_text(),
        "fmi2GetInteger: variable 'steps' (vr 2): refused by fault_mode 5"
    );
    // The instance is in the error state: only getters, FMU-state functions, reset, free.
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Error);
    assert!(f.last_text().contains("Illegal call sequence"));
}

#[test]
fn non_finite_reals_are_rejected_and_a_bad_element_leaves_everything_unchanged() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let f = fresh_in("stepComplete");
        assert_eq!(f.set_real(R_U, bad), Fmi2Status::Error);
        assert!(
            f.last_text().contains("variable 'u' (vr 1): value"),
            "{}",
            f.last_text()
        );
        assert!(f.last_text().contains("is not finite"));
        assert_eq!(f.get_real(R_U), 0.0, "model unchanged");
    }
    let f = fresh_in("stepComplete");
    let vrs = [R_U, R_T];
    let vals = [0.5, f64::INFINITY];
    unsafe {
        assert_eq!(
            fmi2SetReal(f.c, vrs.as_ptr(), 2, vals.as_ptr()),
            Fmi2Status::Error
        );
    }
    assert!(f.last_text().contains("variable 'T' (vr 3)"));
    assert_eq!((f.get_real(R_U), f.get_real(R_T)), (0.0, 1.0));
    // a causality violation later in the array also leaves the earlier ones unapplied
    let f = fresh_in("stepComplete");
    let vrs = [R_U, R_Y];
    let vals = [0.5, 0.5];
    unsafe {
        assert_eq!(
            fmi2SetReal(f.c, vrs.as_ptr(), 2, vals.as_ptr()),
            Fmi2Status::Error
        );
    }
    assert_eq!(f.get_real(R_U), 0.0);
    // the model's own validation error names the variable too
    let f = fresh_in("stepComplete");
    assert_eq!(f.set_real(R_T, -1.0), Fmi2Status::Error);
    assert_eq!(
        f.last_text(),
        "fmi2SetReal: variable 'T' (vr 3): T must be > 0, got -1"
    );
}

#[test]
fn get_and_set_every_type_vectorised() {
    let f = fresh_in("instantiated");
    unsafe {
        let vrs = [R_U, R_T];
        let vals = [0.5, 2.0];
        assert_eq!(
            fmi2SetReal(f.c, vrs.as_ptr(), 2, vals.as_ptr()),
            Fmi2Status::Ok
        );
        assert_eq!(f.set_integer(I_SUBSTEPS, 8), Fmi2Status::Ok);
        let on = [5 as c_int]; // any non-zero value is true
        assert_eq!(
            fmi2SetBoolean(f.c, &B_ENABLED, 1, on.as_ptr()),
            Fmi2Status::Ok
        );
        let label = CString::new("häst ✓ %s").unwrap();
        assert_eq!(
            fmi2SetString(f.c, &S_LABEL, 1, &label.as_ptr()),
            Fmi2Status::Ok
        );
        f.init(0.0, None);

        let vrs = [R_U, R_T, R_RATE, R_Y];
        let mut out = [0.0; 4];
        assert_eq!(
            fmi2GetReal(f.c, vrs.as_ptr(), 4, out.as_mut_ptr()),
            Fmi2Status::Ok
        );
        assert_eq!(out, [0.5, 2.0, 0.5, 0.0]);

        let vrs = [I_SUBSTEPS, I_STEPS, I_VERSION, I_FAULT];
        let mut out = [-1; 4];
        assert_eq!(
            fmi2GetInteger(f.c, vrs.as_ptr(), 4, out.as_mut_ptr()),
            Fmi2Status::Ok
        );
        assert_eq!(out, [8, 0, 7, 0]);

        let vrs = [B_ENABLED, B_PANIC_NOW];
        let mut out = [-1; 2];
        assert_eq!(
            fmi2GetBoolean(f.c, vrs.as_ptr(), 2, out.as_mut_ptr()),
            Fmi2Status::Ok
        );
        assert_eq!(out, [FMI2_TRUE, FMI2_FALSE]);

        let vrs = [S_LABEL, S_LABEL];
        let mut out: [*const c_char; 2] = [ptr::null(); 2];
        assert_eq!(
            fmi2GetString(f.c, vrs.as_ptr(), 2, out.as_mut_ptr()),
            Fmi2Status::Ok
        );
        // both pointers valid at the same time
        assert_eq!(CStr::from_ptr(out[0]).to_str(), Ok("häst ✓ %s"));
        assert_eq!(CStr::from_ptr(out[1]).to_str(), Ok("häst ✓ %s"));
        let mut again: *const c_char = ptr::null();
        assert_eq!(fmi2GetString(f.c, &S_LABEL, 1, &mut again), Fmi2Status::Ok);
        assert_eq!(CStr::from_ptr(again).to_str(), Ok("häst ✓ %s"));

        // non-UTF-8 strings are rejected naming the variable
        fmi2Reset(f.c);
        let bad = [0xffu8, 0xfe, 0];
        let p = bad.as_ptr().cast::<c_char>();
        assert_eq!(fmi2SetString(f.c, &S_LABEL, 1, &p), Fmi2Status::Error);
        assert!(f
            .last_text()
            .contains("variable 'label' (vr 1): string is not valid UTF-8"));
    }
}

/// An Enumeration variable is read and written with fmi2GetInteger/fmi2SetInteger (FMI 2.0
/// section 2.1.7) under the Integer value-reference numbering; the other typed functions
/// refuse it naming it as an Enumeration, and a value that is not one of its items is the
/// model's refusal (fmi2Error naming the variable, the value and the items).
#[test]
fn enumeration_variables_are_set_and_read_as_integers() {
    let f = fresh_in("initializationMode");
    assert_eq!(f.get_integer(E_METHOD), METHOD_EULER);
    assert_eq!(f.set_integer(E_METHOD, METHOD_HEUN), Fmi2Status::Ok);
    assert_eq!(f.get_integer(E_METHOD), METHOD_HEUN);
    // vectorised with plain Integers
    let vrs = [I_SUBSTEPS, E_METHOD];
    let mut out = [-1; 2];
    unsafe {
        assert_eq!(
            fmi2GetInteger(f.c, vrs.as_ptr(), 2, out.as_mut_ptr()),
            Fmi2Status::Ok
        );
    }
    assert_eq!(out, [4, METHOD_HEUN]);
    // The value reaches the model: Heun's step differs from Euler's.
    assert_eq!(f.exit_init(), Fmi2Status::Ok);
    assert_eq!(f.set_real(R_U, 1.0), Fmi2Status::Ok);
    assert_eq!(f.step(0.0, 0.4), Fmi2Status::Ok);
    let heun = f.get_real(R_Y);
    let euler = new_fmu("euler");
    euler.init(0.0, None);
    assert_eq!(euler.set_real(R_U, 1.0), Fmi2Status::Ok);
    assert_eq!(euler.step(0.0, 0.4), Fmi2Status::Ok);
    // y' = 1 - y from 0 over 0.4 s: exactly 1 - e^-0.4; Heun is second order.
    let exact = 1.0 - (-0.4f64).exp();
    let euler = euler.get_real(R_Y);
    assert!(
        (heun - exact).abs() < 0.1 * (euler - exact).abs(),
        "heun {heun}, euler {euler}, exact {exact}"
    );
    // Tunable: settable after initialization; a value not among the items is refused.
    assert_eq!(f.set_integer(E_METHOD, METHOD_EULER), Fmi2Status::Ok);
    assert_eq!(f.set_integer(E_METHOD, 3), Fmi2Status::Error);
    assert_eq!(
        f.last_text(),
        "fmi2SetInteger: variable 'method' (vr 6): method must be one of 1 euler, 2 heun, got 3"
    );
    // Another type's function names it as the Enumeration it is.
    let g = fresh_in("stepComplete");
    let mut r = 0.0;
    unsafe {
        assert_eq!(fmi2GetReal(g.c, &E_METHOD, 1, &mut r), Fmi2Status::Error);
    }
    assert_eq!(
        g.last_text(),
        "fmi2GetReal: value reference 6 does not name a variable of type Real (it names the Enumeration variable 'method')"
    );
}

#[test]
fn warnings_are_always_logged_with_percent_s_and_nul_replaced() {
    let f = fresh_in("stepComplete"); // loggingOn = false
    assert_eq!(f.set_integer(I_FAULT, FAULT_WARNING), Fmi2Status::Ok);
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Warning);
    let m = f.messages();
    assert_eq!(m.len(), 1, "info suppressed, warning sent: {m:#?}");
    assert_eq!(m[0].status, Fmi2Status::Warning as c_int);
    assert_eq!(m[0].category, "logStatusWarning");
    assert_eq!(m[0].format, "%s");
    assert_eq!(
        m[0].text,
        "fmi2DoStep: 100% %s %d warning with NUL\u{FFFD}inside"
    );
    assert_eq!(m[0].instance, "in_state");
}

#[test]
fn info_needs_logging_on_and_an_enabled_category() {
    let f = logging_fmu("dbg");
    assert!(f
        .messages()
        .iter()
        .any(|m| m.category == "logEvents" && m.text.starts_with("instantiated")));
    let events = |f: &Fmu| {
        f.messages()
            .iter()
            .filter(|m| m.category == "logEvents")
            .count()
    };
    unsafe {
        // off for everything
        f.clear();
        assert_eq!(
            fmi2SetDebugLogging(f.c, FMI2_FALSE, 0, ptr::null()),
            Fmi2Status::Ok
        );
        f.init(0.0, None);
        assert_eq!(events(&f), 0);
        // on for one category only
        let cats = [CString::new("logEvents").unwrap()];
        let ptrs: Vec<*const c_char> = cats.iter().map(|c| c.as_ptr()).collect();
        assert_eq!(
            fmi2SetDebugLogging(f.c, FMI2_TRUE, 1, ptrs.as_ptr()),
            Fmi2Status::Ok
        );
        f.clear();
        assert_eq!(f.step(0.0, 0.1), Fmi2Status::Ok);
        assert_eq!(events(&f), 1);
        assert!(!f.messages().iter().any(|m| m.category == "logCalls"));
        // the layer's call trace
        let calls = [CString::new("logCalls").unwrap()];
        assert_eq!(
            fmi2SetDebugLogging(f.c, FMI2_TRUE, 1, &calls[0].as_ptr()),
            Fmi2Status::Ok
        );
        f.clear();
        f.get_real(R_Y);
        assert_eq!(
            f.messages()
                .iter()
                .map(|m| (m.category.as_str(), m.text.as_str()))
                .collect::<Vec<_>>(),
            [("logCalls", "fmi2GetReal")]
        );
        // an unknown category is an error naming it
        let bad = [
            CString::new("logEvents").unwrap(),
            CString::new("logNope").unwrap(),
        ];
        let ptrs: Vec<*const c_char> = bad.iter().map(|c| c.as_ptr()).collect();
        assert_eq!(
            fmi2SetDebugLogging(f.c, FMI2_FALSE, 2, ptrs.as_ptr()),
            Fmi2Status::Error
        );
        assert!(
            f.last_text().contains("unknown log category 'logNope'"),
            "{}",
            f.last_text()
        );
    }
}

#[test]
fn panic_in_a_setter_becomes_fatal_and_only_free_remains() {
    let f = fresh_in("stepComplete");
    assert_eq!(f.set_boolean(B_PANIC_NOW, true), Fmi2Status::Fatal);
    let m = f.messages();
    let last = m.last().unwrap();
    assert_eq!(last.status, Fmi2Status::Fatal as c_int);
    assert_eq!(last.category, "logStatusFatal");
    assert_eq!(
        last.text,
        "fmi2SetBoolean: panic: panic_now was set to true"
    );
    unsafe {
        assert_eq!(f.try_get_real(R_Y).0, Fmi2Status::Error);
        assert_eq!(
            f.last_text(),
            "Illegal call sequence: fmi2GetReal in state fatal"
        );
        assert_eq!(fmi2Reset(f.c), Fmi2Status::Error);
        let mut s = ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(f.c, &mut s), Fmi2Status::Error);
        assert!(s.is_null());
    }
    // dropping `f` calls fmi2FreeInstance, allowed in `fatal`
}

#[test]
fn panic_in_do_step_becomes_fatal_with_the_message() {
    let f = fresh_in("stepComplete");
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Ok);
    assert_eq!(f.set_integer(I_FAULT, FAULT_PANIC), Fmi2Status::Ok);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Fatal);
    assert_eq!(
        f.last_text(),
        "fmi2DoStep: panic: fault_mode 4 panics in do_step at t = 0.1"
    );
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Error);
    assert_eq!(
        f.last_text(),
        "Illegal call sequence: fmi2DoStep in state fatal"
    );
}

#[test]
fn invalid_model_description_refuses_instantiation() {
    let capture = Capture::default();
    let functions = callbacks(&capture);
    let name = CString::new("broken").unwrap();
    let c = unsafe {
        fmi2_slave::__export::instantiate::<BrokenLag>(
            name.as_ptr(),
            FMI2_CO_SIMULATION,
            CString::new(BROKEN_DESCRIPTION.guid()).unwrap().as_ptr(),
            ptr::null(),
            &functions,
            FMI2_FALSE,
            FMI2_FALSE,
        )
    };
    assert!(c.is_null());
    let msgs = capture.messages.lock().unwrap().clone();
    assert_eq!(msgs.len(), 1);
    assert_eq!(
        msgs[0].text,
        "fmi2Instantiate: the model description of 'Lag' is invalid: variable 'u': causality=\"input\" must not define initial (has \"exact\")"
    );
}

#[test]
fn an_instance_of_another_model_type_is_rejected_by_the_type_tag() {
    let f = fresh_in("stepComplete");
    let mut r = -1.0;
    unsafe {
        assert_eq!(
            fmi2_slave::__export::get_real::<BrokenLag>(f.c, &R_U, 1, &mut r),
            Fmi2Status::Error
        );
        assert_eq!(
            fmi2_slave::__export::do_step::<BrokenLag>(f.c, 0.0, 0.1, 0),
            Fmi2Status::Error
        );
        fmi2_slave::__export::free_instance::<BrokenLag>(f.c); // ignored
    }
    assert_eq!(r, -1.0);
    assert!(
        f.messages().is_empty(),
        "nothing logged through a foreign instance"
    );
    // the instance itself is untouched and still in stepComplete
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Ok);
}

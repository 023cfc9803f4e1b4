//! In-process tests of stepping, time keeping, FMU state (in memory and serialized),
//! reset, status queries and concurrency, through the exported C ABI.
#![allow(clippy::unwrap_used)]

mod common;

fmi2_slave::export_fmi2!(common::Lag);

use std::ffi::{c_char, c_int};
use std::ptr;

use common::*;
use fmi2_slave::ffi::*;
use fmi2_slave::testing::{self, Fmu};
use fmi2_slave::Fmi2Status;

/// The model's own arithmetic, replicated: Euler substeps of y' = (u - y) / T.
fn reference_step(y: f64, u: f64, t_const: f64, h: f64, substeps: i32) -> f64 {
    let dt = h / f64::from(substeps);
    let mut y = y;
    for _ in 0..substeps {
        y += dt * (u - y) / t_const;
    }
    y
}

#[test]
fn clock_counts_nanoseconds_and_does_not_drift() {
    let f = new_fmu("clock");
    assert_eq!(f.set_real(R_U, 1.0), Fmi2Status::Ok);
    f.init(0.0, Some(100.0));
    let mut t_master = 0.0; // accumulated like a naive master: drifts in the last bits
    let mut y_ref = 0.0;
    for k in 0..1000 {
        // fmpy-style steps that vary in the last bits
        let h = if k % 2 == 0 { 0.1 } else { 0.10000000000000003 };
        assert_eq!(
            f.step(t_master, h),
            Fmi2Status::Ok,
            "step {k}: {:?}",
            f.messages()
        );
        t_master += h;
        y_ref = reference_step(y_ref, 1.0, 1.0, 0.1, 4);
        assert_eq!(f.get_real(R_Y).to_bits(), y_ref.to_bits(), "step {k}");
    }
    assert_ne!(t_master, 100.0, "the master's sum drifted");
    assert_eq!(f.last_successful_time(), 100.0, "the FMU's clock did not");
    assert_eq!(f.get_integer(I_STEPS), 1000);
    // and the stop time is honoured exactly at the end
    assert_eq!(f.step(100.0, 0.1), Fmi2Status::Error);
    assert!(
        f.last_text().contains("exceeds stopTime = 100"),
        "{}",
        f.last_text()
    );
}

/// A master that sums `t += 0.1` and clips its last step at the stop time (OMSimulator)
/// sends a last step of a few 1e-12 s: every step is fmi2OK, the clock ends at the stop time
/// exactly, and the model integrated exactly `10 stop` steps of 0.1 s (the empty last step
/// does not reach it).
#[test]
fn a_summing_master_reaches_every_stop_time_with_fmi2ok() {
    for stop in testing::SUMMING_MASTER_STOP_TIMES {
        let steps = testing::summing_master_steps(0.0, stop, 0.1);
        let last = steps.last().unwrap().1;
        assert!(
            last < 1e-9,
            "stop {stop}: the sum's last step {last} is sub-ns"
        );
        let f = new_fmu("summing");
        assert_eq!(f.set_real(R_U, 1.0), Fmi2Status::Ok);
        f.init(0.0, Some(stop));
        testing::assert_summing_master_reaches(&f, stop, 0.1);
        let n = (stop * 10.0).round() as i32;
        assert_eq!(f.get_integer(I_STEPS), n, "stop {stop}");
        let y_ref = (0..n).fold(0.0, |y, _| reference_step(y, 1.0, 1.0, 0.1, 4));
        assert_eq!(f.get_real(R_Y).to_bits(), y_ref.to_bits(), "stop {stop}");
    }
}

/// Steps below the clock's resolution: the clock follows the master's sum of them (to the
/// nanosecond) instead of dropping each one, and never goes backwards.
#[test]
fn sub_nanosecond_steps_follow_the_masters_sum() {
    let f = new_fmu("sub_ns");
    f.init(0.0, None);
    let (mut t, h) = (0.0, 0.3e-9);
    let mut previous = 0.0;
    for k in 0..1000 {
        assert_eq!(f.step(t, h), Fmi2Status::Ok, "step {k}");
        t += h;
        let now = f.last_successful_time();
        assert!(now >= previous, "step {k}: the clock went back");
        assert!(
            (now - t).abs() <= 0.5e-9 + 1e-18,
            "step {k}: {now} vs the master's {t}"
        );
        previous = now;
    }
    // 300 ns in whole-nanosecond model steps.
    assert_eq!(f.last_successful_time(), 3e-7);
    assert_eq!(f.get_integer(I_STEPS), 300);
}

#[test]
fn start_time_offsets_the_clock() {
    let f = new_fmu("start");
    f.init(5.0, None);
    assert_eq!(f.last_successful_time(), 5.0);
    assert_eq!(f.step(5.0, 0.25), Fmi2Status::Ok);
    assert_eq!(f.last_successful_time(), 5.25);
    assert_eq!(
        f.step(5.25 + 1e-6, 0.25),
        Fmi2Status::Ok,
        "within 1e-5 * max(1, |t|)"
    );
    // The step ends at the master's end of step, to the nanosecond: the clock follows it.
    assert!((f.last_successful_time() - 5.500_001).abs() < 1e-12);
    assert_eq!(f.step(5.500_001, 0.499_999), Fmi2Status::Ok);
    assert_eq!(f.last_successful_time(), 6.0);
}

#[test]
fn do_step_rejects_bad_arguments_with_the_numbers() {
    // (internal time reached first, stop time, t, h, expected message fragment)
    let cases: Vec<(Option<f64>, f64, f64, &str)> = vec![
        (
            None,
            0.0,
            0.0,
            "communicationStepSize = 0 must be finite and > 0",
        ),
        (
            None,
            0.0,
            -0.1,
            "communicationStepSize = -0.1 must be finite and > 0",
        ),
        (
            None,
            0.0,
            f64::NAN,
            "communicationStepSize = NaN must be finite and > 0",
        ),
        (
            None,
            0.0,
            f64::INFINITY,
            "communicationStepSize = inf must be finite and > 0",
        ),
        (
            None,
            f64::NAN,
            0.1,
            "currentCommunicationPoint = NaN is not finite",
        ),
        (
            None,
            0.5,
            0.1,
            "currentCommunicationPoint = 0.5 does not match the FMU's time 0 (tolerance 0.00001)",
        ),
        (
            None,
            2e-5,
            0.1,
            "currentCommunicationPoint = 0.00002 does not match the FMU's time 0",
        ),
        (
            Some(1.0),
            0.0,
            2.0,
            "currentCommunicationPoint + communicationStepSize = 0 + 2 = 2 exceeds stopTime = 1",
        ),
        (None, 0.0, 1e12, "overflows the FMU's nanosecond clock"),
    ];
    for (stop, t, h, fragment) in cases {
        let f = new_fmu("bad_step");
        f.init(0.0, stop);
        assert_eq!(f.step(t, h), Fmi2Status::Error, "t = {t}, h = {h}");
        let text = f.last_text();
        assert!(text.starts_with("fmi2DoStep: "), "{text}");
        assert!(text.contains(fragment), "{text:?} lacks {fragment:?}");
        assert_eq!(f.step(0.0, 0.1), Fmi2Status::Error, "error state");
        assert_eq!(
            f.last_text(),
            "Illegal call sequence: fmi2DoStep in state error"
        );
    }
    // within tolerance of the stop time and of the clock: accepted
    let f = new_fmu("edge");
    f.init(0.0, Some(1.0));
    assert_eq!(f.step(1e-6, 1.0 + 1e-6), Fmi2Status::Ok);
}

/// A step that ends with a non-finite output is fmi2Discard naming it, whatever the model
/// returned (FMI 2.0 section 4.2.2): the time stays at the step's start, the instance is
/// stepFailed, and a restored state steps on.
#[test]
fn a_non_finite_output_discards_the_step_naming_it() {
    let f = new_fmu("overflow");
    assert_eq!(f.set_real(R_T, 1e-3), Fmi2Status::Ok);
    f.init(0.0, None);
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Ok);
    let before = f.get_state();
    // y' = (u - y) / T overflows: the model itself reports fmi2OK.
    assert_eq!(f.set_real(R_U, 1.7e308), Fmi2Status::Ok);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Discard, "{:?}", f.messages());
    let m = f.messages().pop().unwrap();
    assert_eq!(m.status, Fmi2Status::Discard as c_int);
    assert_eq!(m.category, "logStatusDiscard");
    assert!(
        m.text.starts_with(
            "fmi2DoStep: step from t = 0.1 with h = 0.1 discarded: output 'y' (vr 2) is not finite ("
        ),
        "{}",
        m.text
    );
    assert!(m.text.ends_with("; last successful time 0.1"), "{}", m.text);
    assert_eq!(f.last_successful_time(), 0.1);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Error, "stepFailed");
    // The master restores the state of 0.1 s and steps on with a finite input.
    unsafe {
        assert_eq!(fmi2SetFMUstate(f.c, before), Fmi2Status::Ok);
        f.free_state(before);
    }
    assert_eq!(f.set_real(R_U, 1.0), Fmi2Status::Ok);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Ok);
    assert!(f.get_real(R_Y).is_finite());
    // A warning with a non-finite output is a discard too.
    let f = new_fmu("warning_nan");
    f.init(0.0, None);
    assert_eq!(f.set_integer(I_FAULT, FAULT_WARNING), Fmi2Status::Ok);
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Warning);
    assert_eq!(f.set_integer(I_FAULT, FAULT_NAN), Fmi2Status::Ok);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Discard);
    assert!(f
        .last_text()
        .contains("output 'y' (vr 2) is not finite (NaN)"));
}

/// Initialization that ends with a non-finite output is fmi2Error naming it.
#[test]
fn a_non_finite_output_after_initialization_is_an_error_naming_it() {
    let f = new_fmu("init_nan");
    assert_eq!(f.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(f.enter_init(), Fmi2Status::Ok);
    assert_eq!(f.set_integer(I_FAULT, FAULT_NAN), Fmi2Status::Ok);
    assert_eq!(f.exit_init(), Fmi2Status::Error);
    assert_eq!(
        f.last_text(),
        "fmi2ExitInitializationMode: output 'y' (vr 2) is not finite (NaN) at the end of initialization"
    );
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Error, "error state");
}

#[test]
fn setup_experiment_rejects_bad_times() {
    for (start, stop, tol, fragment) in [
        (f64::NAN, None, None, "startTime = NaN is not finite"),
        (
            1.0,
            Some(0.5),
            None,
            "stopTime = 0.5 must be finite and >= startTime = 1",
        ),
        (0.0, Some(f64::INFINITY), None, "stopTime = inf"),
        (
            0.0,
            None,
            Some(-1e-6),
            "tolerance = -0.000001 must be finite and >= 0",
        ),
    ] {
        let f = new_fmu("setup");
        let status = unsafe {
            fmi2SetupExperiment(
                f.c,
                c_int::from(tol.is_some()),
                tol.unwrap_or(0.0),
                start,
                c_int::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        };
        assert_eq!(status, Fmi2Status::Error);
        assert!(
            f.last_text().contains(fragment),
            "{:?} lacks {fragment:?}",
            f.last_text()
        );
    }
}

#[test]
fn warning_advances_time_discard_does_not_error_stops() {
    let f = new_fmu("outcomes");
    f.init(0.0, None);
    for k in 0..3 {
        assert_eq!(f.step(f64::from(k) * 0.1, 0.1), Fmi2Status::Ok);
    }
    assert_eq!(f.set_integer(I_FAULT, FAULT_WARNING), Fmi2Status::Ok);
    assert_eq!(f.step(0.3, 0.1), Fmi2Status::Warning);
    assert_eq!(f.last_successful_time(), 0.4);
    assert_eq!(f.get_integer(I_STEPS), 4);

    let before = f.get_state();
    assert_eq!(f.set_integer(I_FAULT, FAULT_DISCARD), Fmi2Status::Ok);
    assert_eq!(f.step(0.4, 0.1), Fmi2Status::Discard);
    let m = f.messages();
    let last = m.last().unwrap();
    assert_eq!(last.status, Fmi2Status::Discard as c_int);
    assert_eq!(last.category, "logStatusDiscard");
    assert!(last.text.contains("fault_mode 2 discards"), "{}", last.text);
    assert_eq!(f.last_successful_time(), 0.4, "time not advanced");
    assert_eq!(
        f.step(0.4, 0.05),
        Fmi2Status::Error,
        "stepFailed forbids DoStep"
    );
    assert_eq!(
        f.last_text(),
        "Illegal call sequence: fmi2DoStep in state stepFailed"
    );

    // the master restores the state taken before the step and retries
    unsafe { assert_eq!(fmi2SetFMUstate(f.c, before), Fmi2Status::Ok) };
    assert_eq!(f.set_integer(I_FAULT, 0), Fmi2Status::Ok);
    assert_eq!(f.step(0.4, 0.05), Fmi2Status::Ok);
    assert_eq!(f.last_successful_time(), 0.45);

    assert_eq!(f.set_integer(I_FAULT, FAULT_ERROR), Fmi2Status::Ok);
    assert_eq!(f.step(0.45, 0.05), Fmi2Status::Error);
    assert_eq!(f.last_text(), "fmi2DoStep: fault_mode 3 fails");
    assert_eq!(f.set_integer(I_FAULT, 0), Fmi2Status::Error, "error state");

    // after fmi2Error the master may restore an earlier state (FMI 2.0 section 2.1.3)
    unsafe { assert_eq!(fmi2SetFMUstate(f.c, before), Fmi2Status::Ok) };
    assert_eq!(f.last_successful_time(), 0.4);
    assert_eq!(
        f.step(0.4, 0.1),
        Fmi2Status::Warning,
        "fault_mode restored to 1"
    );
    // SAFETY: a live state of this instance, freed once.
    unsafe { f.free_state(before) };
}

#[test]
fn discard_then_terminate_is_allowed() {
    let f = new_fmu("discard_terminate");
    f.init(0.0, None);
    assert_eq!(f.set_integer(I_FAULT, FAULT_DISCARD), Fmi2Status::Ok);
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Discard);
    let mut terminated = -1;
    unsafe {
        assert_eq!(
            fmi2GetBooleanStatus(f.c, FMI2_TERMINATED, &mut terminated),
            Fmi2Status::Ok
        );
        assert_eq!(terminated, FMI2_FALSE);
        assert_eq!(fmi2Terminate(f.c), Fmi2Status::Ok);
    }
    assert_eq!(f.get_real(R_Y), 0.0);
}

#[test]
fn fmu_state_restores_model_and_layer_and_is_overwritten_in_place() {
    let f = new_fmu("state");
    assert_eq!(f.set_real(R_U, 2.0), Fmi2Status::Ok);
    f.init(0.0, None);
    let run = |from: usize, n: usize| -> Vec<u64> {
        (from..from + n)
            .map(|k| {
                assert_eq!(f.step(k as f64 * 0.1, 0.1), Fmi2Status::Ok);
                f.get_real(R_Y).to_bits()
            })
            .collect()
    };
    run(0, 5);
    let mut s = f.get_state();
    let first = run(5, 5);
    unsafe { assert_eq!(fmi2SetFMUstate(f.c, s), Fmi2Status::Ok) };
    assert_eq!(f.last_successful_time(), 0.5);
    assert_eq!(f.get_integer(I_STEPS), 5);
    assert_eq!(run(5, 5), first, "bit-identical after restore");

    // overwrite the same FMUstate in place at t = 1.0
    let same = s;
    unsafe { assert_eq!(fmi2GetFMUstate(f.c, &mut s), Fmi2Status::Ok) };
    assert_eq!(s, same, "pointer unchanged");
    let after = run(10, 3);
    unsafe { assert_eq!(fmi2SetFMUstate(f.c, s), Fmi2Status::Ok) };
    assert_eq!(f.last_successful_time(), 1.0);
    assert_eq!(run(10, 3), after);

    // the call state is part of the FMU state
    unsafe { assert_eq!(fmi2Terminate(f.c), Fmi2Status::Ok) };
    assert_eq!(f.step(1.3, 0.1), Fmi2Status::Error);
    unsafe { assert_eq!(fmi2SetFMUstate(f.c, s), Fmi2Status::Ok) };
    assert_eq!(run(10, 1), after[..1]);
    // SAFETY: a live state of this instance, freed once.
    unsafe { f.free_state(s) };
}

#[test]
fn serialized_state_continues_bit_identically_in_a_fresh_instance() {
    let a = new_fmu("a");
    assert_eq!(a.set_real(R_T, 0.7), Fmi2Status::Ok);
    assert_eq!(a.set_integer(I_SUBSTEPS, 3), Fmi2Status::Ok);
    let label = std::ffi::CString::new("serialized ✓").unwrap();
    unsafe {
        assert_eq!(
            fmi2SetString(a.c, &S_LABEL, 1, &label.as_ptr()),
            Fmi2Status::Ok
        )
    };
    a.init(0.5, Some(50.0));
    for k in 0..17 {
        assert_eq!(a.set_real(R_U, (k as f64 * 0.37).sin()), Fmi2Status::Ok);
        assert_eq!(a.step(0.5 + k as f64 * 0.125, 0.125), Fmi2Status::Ok);
    }
    let bytes = a.serialize();
    assert_eq!(&bytes[..8], b"RSFMI2ST");

    let b = new_fmu("b"); // only instantiated
    let (status, s) = b.deserialize(&bytes);
    assert_eq!(status, Fmi2Status::Ok, "{:?}", b.messages());
    unsafe { assert_eq!(fmi2SetFMUstate(b.c, s), Fmi2Status::Ok) };
    // SAFETY: a live state of this instance, freed once.
    unsafe { b.free_state(s) };
    assert_eq!(b.last_successful_time(), a.last_successful_time());
    assert_eq!(b.get_integer(I_STEPS), 17);
    let mut p: *const c_char = ptr::null();
    unsafe {
        assert_eq!(fmi2GetString(b.c, &S_LABEL, 1, &mut p), Fmi2Status::Ok);
        assert_eq!(std::ffi::CStr::from_ptr(p).to_str(), Ok("serialized ✓"));
    }
    for k in 17..40 {
        let t = 0.5 + k as f64 * 0.125;
        for f in [&a, &b] {
            assert_eq!(f.set_real(R_U, (k as f64 * 0.37).sin()), Fmi2Status::Ok);
            assert_eq!(f.step(t, 0.125), Fmi2Status::Ok);
        }
        assert_eq!(
            a.get_real(R_Y).to_bits(),
            b.get_real(R_Y).to_bits(),
            "step {k}"
        );
        assert_eq!(a.last_successful_time(), b.last_successful_time());
    }
    // serializing again gives the same bytes for the same state
    assert_eq!(a.serialize(), b.serialize());
}

#[test]
fn deserialize_names_what_does_not_match() {
    let a = new_fmu("src");
    a.init(0.0, None);
    assert_eq!(a.step(0.0, 0.1), Fmi2Status::Ok);
    let good = a.serialize();
    // The checksum made anew, so that the part after it is what the reader trips on.
    let reseal = |mut b: Vec<u8>| {
        let n = b.len() - 4;
        let crc = crc32fast::hash(&b[..n]);
        b[n..].copy_from_slice(&crc.to_le_bytes());
        b
    };
    let id_at = 8 + 4 + 8; // magic, version, identifier length
    let guid_at = id_at + 3 + 8 + 1; // "Lag", GUID length, '{'
    let model_at = good.len() - 4 - 54 - 3; // Lag state: 54 bytes + label "lag", CRC
    let mut cases: Vec<(Vec<u8>, &str)> = Vec::new();
    let mut m = good.clone();
    m[0] ^= 1;
    cases.push((m, "wrong magic"));
    let mut v = good.clone();
    v[8] = 1;
    cases.push((v, "unsupported format version 1 (this FMU reads version 2)"));
    let mut c = good.clone();
    c[id_at + 1] = b'X';
    cases.push((c.clone(), "checksum mismatch: the state is corrupt"));
    cases.push((
        reseal(c),
        "model identifier mismatch: the state belongs to 'LXg', this FMU is 'Lag'",
    ));
    let mut g = good.clone();
    g[guid_at] = if g[guid_at] == b'0' { b'1' } else { b'0' };
    cases.push((reseal(g), "GUID mismatch"));
    cases.push((good[..good.len() - 1].to_vec(), "checksum mismatch"));
    let mut t = good.clone();
    t.push(0);
    cases.push((t, "checksum mismatch"));
    cases.push((Vec::new(), "truncated"));
    cases.push((good[..10].to_vec(), "truncated"));
    let mut model = good.clone();
    model[model_at] = 9;
    cases.push((reseal(model), "model state: Lag state: bad version"));

    let b = new_fmu("dst");
    b.init(0.0, None);
    let mut t = 0.0;
    for (bytes, fragment) in cases {
        let (status, s) = b.deserialize(&bytes);
        assert_eq!(status, Fmi2Status::Error, "{fragment}");
        assert!(s.is_null());
        let text = b.last_text();
        assert!(text.starts_with("fmi2DeSerializeFMUstate: "), "{text}");
        assert!(text.contains(fragment), "{text:?} lacks {fragment:?}");
        // Refusing bytes leaves the instance as it was (not in the error state).
        assert_eq!(
            b.step(t, 0.1),
            Fmi2Status::Ok,
            "{fragment}: {}",
            b.log_text()
        );
        t += 0.1;
    }
    let (status, s) = b.deserialize(&good);
    assert_eq!(status, Fmi2Status::Ok);
    // SAFETY: a live state of this instance, freed once.
    unsafe { b.free_state(s) };
}

#[test]
fn serialize_requires_the_reported_size() {
    let f = new_fmu("size");
    f.init(0.0, None);
    let s = f.get_state();
    let mut size = 0usize;
    unsafe {
        assert_eq!(
            fmi2SerializedFMUstateSize(f.c, s, &mut size),
            Fmi2Status::Ok
        );
        let mut buf = vec![0u8; size + 1];
        assert_eq!(
            fmi2SerializeFMUstate(f.c, s, buf.as_mut_ptr().cast(), size + 1),
            Fmi2Status::Error
        );
        assert!(f.last_text().contains(&format!(
            "size {} does not match the serialized size {size}",
            size + 1
        )));
        assert_eq!(fmi2Reset(f.c), Fmi2Status::Ok);
        assert_eq!(
            fmi2SerializeFMUstate(f.c, s, buf.as_mut_ptr().cast(), size),
            Fmi2Status::Ok
        );
        assert_eq!(buf[size], 0, "nothing written past size");
    }
    // SAFETY: a live state of this instance, freed once.
    unsafe { f.free_state(s) };
}

#[test]
fn deserialize_overwrites_an_existing_state_in_place() {
    let f = new_fmu("inplace");
    f.init(0.0, None);
    assert_eq!(f.set_real(R_U, 1.0), Fmi2Status::Ok);
    assert_eq!(f.step(0.0, 0.1), Fmi2Status::Ok);
    let bytes = f.serialize();
    let y1 = f.get_real(R_Y);
    assert_eq!(f.step(0.1, 0.1), Fmi2Status::Ok);
    let mut s = f.get_state();
    let same = s;
    unsafe {
        assert_eq!(
            fmi2DeSerializeFMUstate(f.c, bytes.as_ptr().cast(), bytes.len(), &mut s),
            Fmi2Status::Ok
        );
        assert_eq!(s, same);
        assert_eq!(fmi2SetFMUstate(f.c, s), Fmi2Status::Ok);
    }
    assert_eq!(f.get_real(R_Y), y1);
    assert_eq!(f.last_successful_time(), 0.1);
    // SAFETY: a live state of this instance, freed once.
    unsafe { f.free_state(s) };
}

#[test]
fn reset_restores_start_values_and_keeps_debug_logging_settings() {
    let f = logging_fmu("reset");
    assert_eq!(f.set_real(R_T, 3.0), Fmi2Status::Ok);
    assert_eq!(f.set_real(R_U, 1.0), Fmi2Status::Ok);
    f.init(2.0, Some(3.0));
    assert_eq!(f.step(2.0, 0.5), Fmi2Status::Ok);
    unsafe {
        assert_eq!(
            fmi2SetDebugLogging(f.c, FMI2_FALSE, 0, ptr::null()),
            Fmi2Status::Ok
        );
        f.clear();
        assert_eq!(fmi2Reset(f.c), Fmi2Status::Ok);
    }
    assert!(
        f.messages().is_empty(),
        "logging stays off across reset: {:?}",
        f.messages()
    );
    // back in `instantiated`: getters are illegal until initialization mode
    f.init(0.0, None);
    assert_eq!(f.get_real(R_T), 1.0);
    assert_eq!(f.get_real(R_U), 0.0);
    assert_eq!(f.get_integer(I_STEPS), 0);
    assert_eq!(f.last_successful_time(), 0.0);
    assert_eq!(
        f.step(0.0, 0.5),
        Fmi2Status::Ok,
        "stop time forgotten, clock restarted"
    );
}

#[test]
fn status_queries_follow_the_standard() {
    let f = new_fmu("status");
    f.init(0.0, None);
    let mut st = Fmi2Status::Ok;
    let mut i: c_int = -1;
    let mut p: *const c_char = ptr::null();
    unsafe {
        assert_eq!(
            fmi2GetStatus(f.c, FMI2_DO_STEP_STATUS, &mut st),
            Fmi2Status::Discard
        );
        assert!(f
            .last_text()
            .contains("fmi2GetStatus: status fmi2DoStepStatus is not available"));
        assert_eq!(
            fmi2GetIntegerStatus(f.c, FMI2_LAST_SUCCESSFUL_TIME, &mut i),
            Fmi2Status::Discard
        );
        assert_eq!(
            fmi2GetStringStatus(f.c, FMI2_PENDING_STATUS, &mut p),
            Fmi2Status::Discard
        );
        assert!(p.is_null());
        let mut r = 0.0;
        assert_eq!(
            fmi2GetRealStatus(f.c, FMI2_TERMINATED, &mut r),
            Fmi2Status::Discard
        );
        assert_eq!(
            fmi2GetBooleanStatus(f.c, FMI2_TERMINATED, &mut i),
            Fmi2Status::Ok
        );
        assert_eq!(i, FMI2_FALSE);
        // a Discard from a status query does not change the call state
        assert_eq!(f.step(0.0, 0.1), Fmi2Status::Ok);
        // an undefined kind is an error
        assert_eq!(fmi2GetStatus(f.c, 42, &mut st), Fmi2Status::Error);
        assert!(f.last_text().contains("undefined fmi2StatusKind 42"));
    }
}

#[test]
fn unsupported_functions_log_and_return_error() {
    type Call = fn(&Fmu) -> Fmi2Status;
    let cases: [(Call, &str); 4] = [
        (
            |f| unsafe { fmi2GetDirectionalDerivative(f.c, ptr::null(), 0, ptr::null(), 0, ptr::null(), ptr::null_mut()) },
            "fmi2GetDirectionalDerivative: not supported: this FMU declares providesDirectionalDerivative=\"false\"",
        ),
        (
            |f| unsafe { fmi2SetRealInputDerivatives(f.c, ptr::null(), 0, ptr::null(), ptr::null()) },
            "fmi2SetRealInputDerivatives: not supported: this FMU declares canInterpolateInputs=\"false\"",
        ),
        (
            |f| unsafe { fmi2GetRealOutputDerivatives(f.c, ptr::null(), 0, ptr::null(), ptr::null_mut()) },
            "fmi2GetRealOutputDerivatives: not supported: this FMU declares maxOutputDerivativeOrder=\"0\"",
        ),
        (
            |f| unsafe { fmi2CancelStep(f.c) },
            "Illegal call sequence: fmi2CancelStep in state stepComplete",
        ),
    ];
    for (call, text) in cases {
        let f = new_fmu("unsupported");
        f.init(0.0, None);
        assert_eq!(call(&f), Fmi2Status::Error, "{text}");
        assert_eq!(f.last_text(), text);
    }
}

/// One run of an instance: per step the output bits.
fn trajectory(f: &Fmu, t_const: f64, steps: usize) -> Vec<u64> {
    assert_eq!(f.set_real(R_T, t_const), Fmi2Status::Ok);
    f.init(0.0, None);
    (0..steps)
        .map(|k| {
            assert_eq!(f.set_real(R_U, (k as f64 * t_const).cos()), Fmi2Status::Ok);
            assert_eq!(f.step(k as f64 * 0.01, 0.01), Fmi2Status::Ok);
            f.get_real(R_Y).to_bits()
        })
        .collect()
}

#[test]
fn eight_instances_on_eight_threads_match_sequential_runs() {
    const N: usize = 8;
    const STEPS: usize = 2000;
    let t_consts: Vec<f64> = (0..N).map(|i| 0.1 + 0.3 * i as f64).collect();
    let sequential: Vec<Vec<u64>> = t_consts
        .iter()
        .map(|&tc| trajectory(&new_fmu("seq"), tc, STEPS))
        .collect();
    // instances created on this thread, each stepped on its own thread (as libcosim does)
    let instances: Vec<Fmu> = (0..N).map(|i| new_fmu(&format!("par{i}"))).collect();
    let concurrent: Vec<Vec<u64>> = std::thread::scope(|scope| {
        let handles: Vec<_> = instances
            .into_iter()
            .zip(&t_consts)
            .map(|(f, &tc)| scope.spawn(move || trajectory(&f, tc, STEPS)))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(concurrent, sequential);
    // the runs differ from each other, so the comparison is meaningful
    assert_ne!(sequential[0], sequential[1]);
}

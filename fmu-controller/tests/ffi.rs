//! TowingController through its exported FMI functions, in-process, as a master calls them:
//! commands within bounds, NaN inputs, bad parameters, sample timing independent of the
//! communication step, obstacles on top of the ship, refused measurements and the FMU
//! state (get/set, serialization, corrupt and forged states).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)]

mod support;

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::{Causality, ValueType, VariableKind};
use support::*;
use towing_controller::variables::{self as vars, DESCRIPTION, NO_OBSTACLE_DISTANCE};
use towing_interface::testing;
use towing_mpc::ShipMpcParams;

fn var(name: &str) -> u32 {
    DESCRIPTION
        .variables
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .value_reference
}

/// Steps `n` times by `h` from `t0`, asserting Ok; returns the end time.
fn steps(fmu: &fmi2_slave::testing::Fmu, t0: f64, h: f64, n: usize) -> f64 {
    let mut t = t0;
    for _ in 0..n {
        assert_eq!(fmu.step(t, h), Fmi2Status::Ok, "{}", fmu.log_text());
        t += h;
    }
    t
}

#[test]
fn paper_inputs_give_finite_commands_within_bounds() {
    let fmu = initialized("paper");
    let mut t = 0.0;
    for _ in 0..20 {
        assert_eq!(fmu.step(t, 0.1), Fmi2Status::Ok, "{}", fmu.log_text());
        t += 0.1;
        assert_commands_within_bounds(&fmu);
    }
    // The ship starts at rest and the route leads away: the MPC pulls.
    let v = commands(&fmu);
    assert!(v[6] > 0.0 || v[7] > 0.0, "no tension commanded: {v:?}");
    assert_eq!(fmu.get_integer(vars::SAMPLES), 2);
    assert!(fmu.get_integer(vars::ADMM_ITERATIONS) >= 1);
    assert_eq!(fmu.get_integer(vars::FALLBACKS), 0);
    assert!(fmu.get_integer(vars::ACTIVE_WAYPOINT) >= 1);
    // No obstacles: d_ob is the documented large finite number, no situations.
    assert_eq!(fmu.get_real(vars::D_OB), NO_OBSTACLE_DISTANCE);
    for slot in 0..8 {
        assert_eq!(fmu.get_integer(vars::colregs_situation(slot)), -1);
        assert_eq!(fmu.get_integer(vars::colregs_role(slot)), 0);
    }
    let compute_time = fmu.get_real(vars::COMPUTE_TIME);
    assert!(compute_time > 0.0 && compute_time.is_finite());
    for c in 0..3 {
        assert!(fmu.get_real(vars::reference(c)).is_finite());
    }
    // The plan's predicted ship positions are near the ship (it moves < 1 m in 3 s).
    let ship = paper_states()[0];
    for h in 0..3 {
        let x = fmu.get_real(vars::prediction(h, 0, 0));
        let y = fmu.get_real(vars::prediction(h, 0, 1));
        assert!(
            (x - ship[0]).hypot(y - ship[1]) < 1.0,
            "h = {h}: ({x}, {y})"
        );
    }
}

#[test]
fn outputs_hold_their_start_values_until_the_first_step() {
    let fmu = initialized("start");
    let mut checked = 0;
    for v in DESCRIPTION
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
    {
        let vr = v.value_reference;
        match &v.kind {
            VariableKind::Real { start: None, .. } => {
                // The tension commands: calculated, the pretension.
                assert!(v.name.ends_with(".tension_cmd"), "{}", v.name);
                assert_eq!(fmu.get_real(vr), ShipMpcParams::default().min_tension);
            }
            VariableKind::Real { start, .. } => {
                assert_eq!(fmu.get_real(vr), start.unwrap(), "{}", v.name);
            }
            VariableKind::Integer { start, .. } | VariableKind::Enumeration { start, .. } => {
                assert_eq!(fmu.get_integer(vr), start.unwrap(), "{}", v.name);
            }
            VariableKind::Boolean { start } => {
                assert_eq!(fmu.get_boolean(vr), start.unwrap(), "{}", v.name);
            }
            VariableKind::String { .. } => panic!("String output {}", v.name),
        }
        checked += 1;
    }
    // 8 commands, 19 diagnostics, 8 x 2 COLREGS, 3 x 3 x 2 predictions.
    assert_eq!(checked, 8 + 19 + 16 + 18);
}

#[test]
fn non_finite_real_inputs_are_refused_naming_the_variable() {
    let inputs: Vec<_> = DESCRIPTION
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Input && v.value_type() == ValueType::Real)
        .collect();
    // 3 vessels x 6, 2 towlines x 3, 8 obstacle slots x 6.
    assert_eq!(inputs.len(), 18 + 6 + 48);
    for (i, v) in inputs.iter().enumerate() {
        let fmu = controller("nan");
        let vr = v.value_reference;
        assert_eq!(fmu.set_real(vr, 1.25), Fmi2Status::Ok);
        let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][i % 3];
        assert_eq!(fmu.set_real(vr, bad), Fmi2Status::Error, "{}", v.name);
        let text = fmu.log_text();
        assert!(
            text.contains(&format!("'{}'", v.name)) && text.contains("not finite"),
            "{}: {text}",
            v.name
        );
        assert_eq!(fmu.get_real(vr), 1.25, "{} changed", v.name);
    }
}

/// Sets one parameter on an instance; the status.
type SetParameter = Box<dyn Fn(&fmi2_slave::testing::Fmu) -> Fmi2Status>;

/// A value out of a parameter's range is refused when it is set (`fmi2Error`),
/// naming the parameter and the range.
#[test]
fn out_of_range_parameters_are_refused_when_set_naming_them() {
    let cases: [(&str, SetParameter); 6] = [
        (
            "architecture",
            Box::new(|f| f.set_integer(var("architecture"), 7)),
        ),
        (
            "avoidance_scheme",
            Box::new(|f| f.set_integer(var("avoidance_scheme"), 0)),
        ),
        (
            "mpc.sample_time",
            Box::new(|f| f.set_real(var("mpc.sample_time"), -1.0)),
        ),
        (
            "mpc.hull_model",
            Box::new(|f| f.set_integer(var("mpc.hull_model"), 3)),
        ),
        (
            "admm.max_iterations",
            Box::new(|f| f.set_integer(var("admm.max_iterations"), 0)),
        ),
        ("admm.rho", Box::new(|f| f.set_real(var("admm.rho"), -0.5))),
    ];
    for (name, set) in &cases {
        let fmu = controller(name);
        set_states(&fmu, &paper_states());
        assert_eq!(set(&fmu), Fmi2Status::Error, "{name} was accepted");
        let text = fmu.last_text();
        assert!(text.contains(&format!("`{name}`")), "{name}: {text}");
        assert!(text.contains("must be"), "{name}: {text}");
    }
}

/// What only the whole configuration shows is refused at exit initialization,
/// naming the parameter: a log file that cannot be created, a pretension above the
/// largest tension.
#[test]
fn bad_configurations_are_refused_at_exit_initialization_naming_them() {
    let cases: [(&str, SetParameter); 2] = [
        (
            "log_file",
            Box::new(|f| f.set_string(var("log_file"), "/nonexistent-dir/run.mcap")),
        ),
        (
            "mpc.ship.min_tension",
            Box::new(|f| f.set_real(var("mpc.ship.min_tension"), 5.0)),
        ),
    ];
    for (name, set) in &cases {
        let fmu = controller(name);
        set_states(&fmu, &paper_states());
        assert_eq!(set(&fmu), Fmi2Status::Ok, "{name}: {}", fmu.log_text());
        assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
        assert_eq!(fmu.enter_init(), Fmi2Status::Ok, "{}", fmu.log_text());
        assert_eq!(fmu.exit_init(), Fmi2Status::Error, "{name} was accepted");
        let text = fmu.last_text();
        assert!(text.contains(&format!("`{name}`")), "{name}: {text}");
        // No controller: stepping is refused, not a crash.
        assert_ne!(fmu.step(0.0, 0.1), Fmi2Status::Ok);
    }
}

#[test]
fn a_valid_non_default_parameter_set_is_accepted() {
    let fmu = controller("params");
    set_states(&fmu, &paper_states());
    assert_eq!(fmu.set_integer(var("architecture"), 1), Fmi2Status::Ok);
    assert_eq!(fmu.set_integer(var("avoidance_scheme"), 3), Fmi2Status::Ok);
    assert_eq!(
        fmu.set_boolean(var("mpc.hull_from_scenario"), false),
        Fmi2Status::Ok
    );
    assert_eq!(fmu.set_integer(var("mpc.hull_model"), 1), Fmi2Status::Ok);
    assert_eq!(
        fmu.set_real(var("mpc.ship.max_tension"), 2.0),
        Fmi2Status::Ok
    );
    assert_eq!(
        fmu.set_boolean(var("waterway.from_scenario"), false),
        Fmi2Status::Ok
    );
    assert_eq!(
        fmu.set_real(var("waterway.half_width"), 4.0),
        Fmi2Status::Ok
    );
    fmu.init(0.0, None);
    steps(&fmu, 0.0, 0.5, 2);
    let v = commands(&fmu);
    assert!(v[6] <= 2.0 + 1e-9 && v[7] <= 2.0 + 1e-9, "{v:?}");
}

#[test]
fn without_resources_and_scenario_initialization_is_refused_with_a_reason() {
    testing::assert_no_resources_and_no_scenario_is_refused(exports(), &DESCRIPTION);
}

#[test]
fn a_missing_scenario_file_is_named() {
    testing::assert_missing_scenario_file_is_named(exports(), &DESCRIPTION);
}

#[test]
fn run_id_is_kept_and_a_control_character_refused() {
    testing::assert_run_id_is_kept_and_checked(exports(), &DESCRIPTION);
}

/// With h = 0.1 and T_s = 1 s the tensions hold over the 10 steps of a sample and the
/// counter counts samples, not steps.
#[test]
fn outputs_hold_between_samples_and_the_counter_counts_samples() {
    let fmu = initialized("hold");
    let mut t = 0.0;
    let mut tensions = Vec::new();
    for k in 0..20 {
        assert_eq!(fmu.step(t, 0.1), Fmi2Status::Ok, "{}", fmu.log_text());
        t += 0.1;
        let expected_samples = if k < 10 { 1 } else { 2 };
        assert_eq!(
            fmu.get_integer(vars::SAMPLES),
            expected_samples,
            "after step {k}"
        );
        tensions.push([
            fmu.get_real(vars::tension_cmd(0)),
            fmu.get_real(vars::tension_cmd(1)),
        ]);
    }
    for k in 1..10 {
        assert_eq!(
            tensions[k], tensions[0],
            "step {k} changed the held tension"
        );
        assert_eq!(
            tensions[10 + k],
            tensions[10],
            "step {} changed the held tension",
            10 + k
        );
    }
    assert_ne!(
        tensions[10], tensions[0],
        "the second sample did not compute anything new"
    );
}

/// The sample instants are multiples of sample_time whatever the communication step.
#[test]
fn sampling_is_independent_of_the_communication_step() {
    let first_tension = |h: f64, n: usize, expected_samples: i32| {
        let fmu = initialized("rate");
        assert_eq!(fmu.step(0.0, h), Fmi2Status::Ok, "{}", fmu.log_text());
        let first = [
            fmu.get_real(vars::tension_cmd(0)),
            fmu.get_real(vars::tension_cmd(1)),
        ];
        steps(&fmu, h, h, n - 1);
        assert_eq!(fmu.get_integer(vars::SAMPLES), expected_samples, "h = {h}");
        first
    };
    // Samples at t = 0, 1 (8 steps of 0.25 s end at 2.0 s, the last step starts at 1.75).
    let a = first_tension(0.25, 8, 2);
    // Samples at t = 0, 1, 2.
    let b = first_tension(1.0, 3, 3);
    // Samples at t = 0, 1.0 (0.1 s steps: 1.0 arrives as 0.1 * 10 on the ns clock).
    let c = first_tension(0.1, 11, 2);
    // The first sample sees the same inputs: the same command, whatever h.
    assert_eq!(a, b);
    assert_eq!(a, c);

    // sample_time 0.5 s with h = 0.25: samples at 0, 0.5, 1.0, 1.5.
    let fmu = controller("half");
    set_states(&fmu, &paper_states());
    assert_eq!(fmu.set_real(var("mpc.sample_time"), 0.5), Fmi2Status::Ok);
    fmu.init(0.0, None);
    steps(&fmu, 0.0, 0.25, 8);
    assert_eq!(fmu.get_integer(vars::SAMPLES), 4);
}

#[test]
fn a_start_time_other_than_zero_keeps_the_sample_grid() {
    let fmu = controller("t0");
    set_states(&fmu, &paper_states());
    fmu.init(100.0, None);
    steps(&fmu, 100.0, 0.1, 11);
    assert_eq!(fmu.get_integer(vars::SAMPLES), 2);
}

/// Regression guard: an obstacle exactly on the ship (a circle and a vessel at the ship's
/// position) must not panic; the step is Ok or Warning and the commands stay in bounds.
#[test]
fn obstacles_on_top_of_the_ship_do_not_break_the_controller() {
    let states = paper_states();
    let ship = states[0];
    let fmu = controller("overlap");
    set_states(&fmu, &states);
    set_obstacle(&fmu, 0, [ship[0], ship[1], 0.0, 0.0, 1.0, 1.0], 1);
    set_obstacle(&fmu, 1, [ship[0], ship[1], ship[2], 0.1, 1.5, 0.5], 2);
    fmu.init(0.0, None);
    let mut t = 0.0;
    for _ in 0..3 {
        let s = fmu.step(t, 1.0);
        assert!(
            matches!(s, Fmi2Status::Ok | Fmi2Status::Warning),
            "{s:?}: {}",
            fmu.log_text()
        );
        if s == Fmi2Status::Warning {
            assert!(fmu.log_text().contains("fallback: "), "{}", fmu.log_text());
        }
        t += 1.0;
        assert_commands_within_bounds(&fmu);
    }
    assert_eq!(fmu.get_integer(vars::SAMPLES), 3);
    let d_ob = fmu.get_real(vars::D_OB);
    assert!(d_ob.is_finite() && d_ob < NO_OBSTACLE_DISTANCE, "{d_ob}");
    // The vessel slot is classified (static and empty slots are -1).
    assert_ne!(fmu.get_integer(vars::colregs_situation(1)), -1);
    assert_eq!(fmu.get_integer(vars::colregs_situation(0)), -1);
    assert_eq!(fmu.get_integer(vars::colregs_situation(2)), -1);
}

#[test]
fn an_invalid_obstacle_is_an_error_naming_its_slot() {
    let fmu = initialized("bad-obstacle");
    // A vessel ellipse wider than long is refused by the guidance.
    set_obstacle(&fmu, 2, [10.0, 10.0, 0.0, 0.1, 0.5, 1.0], 2);
    assert_eq!(fmu.step(0.0, 0.1), Fmi2Status::Error);
    testing::assert_last_message_contains(&fmu, "obstacle[3]");
}

#[test]
fn unknown_value_references_of_every_type_are_errors_naming_reference_and_type() {
    testing::assert_unknown_references_are_errors(support::exports(), &DESCRIPTION);
    testing::assert_model_refuses_unknown_references::<towing_controller::ControllerFmu>(
        &DESCRIPTION,
    );
}

/// The kind is converted from the FMI Integer when it is set: a code other than 0, 1, 2 is
/// refused there, naming the variable and the code, and the slot keeps its kind.
#[test]
fn an_unknown_obstacle_kind_is_refused_when_set() {
    let fmu = initialized("bad-kind");
    let kind = vars::obstacle(4, vars::OBSTACLE_KIND);
    assert_eq!(fmu.set_integer(kind, 2), Fmi2Status::Ok);
    assert_eq!(fmu.set_integer(kind, 3), Fmi2Status::Error);
    testing::assert_last_message_contains(&fmu, "obstacle[5].kind");
    testing::assert_last_message_contains(&fmu, "unknown obstacle kind 3");
    assert_eq!(fmu.get_integer(kind), 2);
}

/// Every output but the wall-clock compute time, as bits, after `n` steps of 0.1 s from
/// `t0` with the inputs held.
fn output_bits(fmu: &fmi2_slave::testing::Fmu, t0: f64, n: usize) -> Vec<u64> {
    let mut bits = Vec::new();
    for k in 0..n {
        let t = t0 + k as f64 * 0.1;
        assert_eq!(fmu.step(t, 0.1), Fmi2Status::Ok, "{}", fmu.log_text());
        for v in DESCRIPTION.variables.iter() {
            if v.causality != Causality::Output || v.value_reference == vars::COMPUTE_TIME {
                continue;
            }
            let vr = v.value_reference;
            bits.push(match v.value_type() {
                ValueType::Real => fmu.get_real(vr).to_bits(),
                ValueType::Integer => fmu.get_integer(vr) as u64,
                ValueType::Boolean => u64::from(fmu.get_boolean(vr)),
                ValueType::String => continue,
            });
        }
    }
    bits
}

/// Issue 15, item 9: the controller's FMU state (get/set and serialized into a fresh
/// instance) holds everything that decides its later outputs: both continue bit for bit,
/// with either architecture.
#[test]
fn fmu_state_get_set_and_serialization_continue_bit_for_bit() {
    for architecture in [1, 2] {
        let fmu = controller("state");
        set_states(&fmu, &paper_states());
        assert_eq!(
            fmu.set_integer(var("architecture"), architecture),
            Fmi2Status::Ok
        );
        fmu.init(0.0, None);
        output_bits(&fmu, 0.0, 35);
        let saved = fmu.get_state();
        let bytes = fmu.serialize();
        let expected = output_bits(&fmu, 3.5, 30);

        // SAFETY: `saved` is a live state of this instance, freed once below.
        assert_eq!(
            unsafe { fmu.set_state(saved) },
            Fmi2Status::Ok,
            "{}",
            fmu.log_text()
        );
        unsafe { fmu.free_state(saved) };
        assert!(
            output_bits(&fmu, 3.5, 30) == expected,
            "get/set, architecture {architecture}"
        );

        // A fresh instance, never initialized, restores everything from the bytes.
        let fresh = controller("fresh");
        assert_eq!(fresh.setup(0.0, None), Fmi2Status::Ok);
        fresh.restore(&bytes);
        assert_eq!(fresh.get_integer(vars::SAMPLES), 4);
        assert!(
            output_bits(&fresh, 3.5, 30) == expected,
            "serialized, architecture {architecture}"
        );
    }
}

/// Issue 15, item 8, for the controller: no single flipped bit of a serialized state is
/// accepted, nor a state whose time is shifted or that records a fatal call state; the
/// instance goes on.
#[test]
fn a_corrupt_or_forged_controller_state_is_refused() {
    use fmi2_slave::testing::{accepted_bit_flips, forge_state};
    let fmu = initialized("flips");
    output_bits(&fmu, 0.0, 12);
    let bytes = fmu.serialize();
    assert_eq!(
        accepted_bit_flips(&fmu, &bytes),
        0,
        "of {} bits",
        8 * bytes.len()
    );
    for (reason, forged) in [
        (
            "does not match the clock's 2.2 s",
            forge_state(&bytes, &DESCRIPTION, |l| l.time_ns += 1_000_000_000),
        ),
        (
            "does not match the clock's 9223372036.854776 s",
            forge_state(&bytes, &DESCRIPTION, |l| l.time_ns = i64::MAX),
        ),
        (
            "records the call state fatal",
            forge_state(&bytes, &DESCRIPTION, |l| {
                l.call_state = fmi2_slave::CallState::Fatal;
            }),
        ),
    ] {
        let (status, state) = fmu.deserialize(&forged.unwrap());
        assert_eq!(status, Fmi2Status::Error);
        assert!(state.is_null());
        testing::assert_last_message_contains(&fmu, reason);
    }
    output_bits(&fmu, 1.2, 5);
}

/// A sample whose QPs fail (a circle of 100 m radius over the tow makes every
/// clearance row infeasible) falls back: by default fmi2OK, the fallback logged as a
/// warning (category logStatusWarning, "fallback: <reason>") and counted; with
/// `fmi.warning_on_fallback` fmi2Warning. The commands stay finite and within their bounds.
#[test]
fn a_failed_solve_is_a_counted_fallback_logged_as_a_warning() {
    for warning_on_fallback in [false, true] {
        let states = paper_states();
        let ship = states[0];
        let fmu = controller("fallback");
        set_states(&fmu, &states);
        if warning_on_fallback {
            assert_eq!(
                fmu.set_boolean(var("fmi.warning_on_fallback"), true),
                Fmi2Status::Ok
            );
        }
        fmu.init(0.0, None);
        let expected = if warning_on_fallback {
            Fmi2Status::Warning
        } else {
            Fmi2Status::Ok
        };
        let mut t = steps(&fmu, 0.0, 1.0, 2);
        set_obstacle(&fmu, 7, [ship[0], ship[1], 0.0, 0.0, 200.0, 200.0], 1);
        for k in 1..=3 {
            fmu.clear();
            assert_eq!(fmu.step(t, 1.0), expected, "{}", fmu.log_text());
            let m = fmu.messages().pop().unwrap();
            assert_eq!(m.status, Fmi2Status::Warning as i32, "{m:?}");
            assert_eq!(m.category, "logStatusWarning");
            assert!(
                m.text.starts_with("fmi2DoStep: fallback: the "),
                "{}",
                m.text
            );
            assert!(
                m.text.contains(&format!("(sample at t = {t} s;")),
                "{}",
                m.text
            );
            t += 1.0;
            assert_eq!(fmu.get_integer(vars::FALLBACKS), k);
            let c = commands(&fmu);
            assert!(c.iter().all(|v| v.is_finite()), "{c:?}");
            assert!(
                c[6] >= 0.0 && c[6] <= 3.0 && c[7] >= 0.0 && c[7] <= 3.0,
                "{c:?}"
            );
        }
    }
}

/// `fmi2DoStep(t, h)` is fmi2OK and every one of `outputs` is finite after it.
fn step_ok_and_finite(fmu: &fmi2_slave::testing::Fmu, t: f64, h: f64, outputs: &[u32], what: &str) {
    assert_eq!(fmu.step(t, h), Fmi2Status::Ok, "{what}: {}", fmu.log_text());
    let (s, values) = fmu.try_get_reals(outputs);
    assert_eq!(s, Fmi2Status::Ok);
    for (vr, v) in outputs.iter().zip(&values) {
        assert!(v.is_finite(), "{what}: vr {vr} = {v}");
    }
}

/// Run alone, as fmuCheck, fmusim and `fmpy.simulate_fmu` do (inputs never set: every
/// vessel at (0, 0)), the controller rests: 60 s of fmi2OK, no fallback, every output
/// finite, the tensions at the pretension and no thrust, and one log line saying why.
#[test]
fn run_alone_with_inputs_never_set_the_controller_rests_without_fallbacks() {
    let fmu = controller("alone");
    fmu.init(0.0, None);
    let outputs = testing::real_outputs(&DESCRIPTION);
    let mut t = 0.0;
    for k in 0..600 {
        step_ok_and_finite(&fmu, t, 0.1, &outputs, &format!("step {k}"));
        t += 0.1;
    }
    assert_eq!(fmu.get_integer(vars::SAMPLES), 60);
    assert_eq!(fmu.get_integer(vars::FALLBACKS), 0, "{}", fmu.log_text());
    let c = commands(&fmu);
    let pretension = ShipMpcParams::default().min_tension;
    assert_eq!(&c[..6], &[0.0; 6], "no thrust: {c:?}");
    assert_eq!(&c[6..], &[pretension; 2], "the pretension: {c:?}");
    let lines: Vec<_> = fmu
        .messages()
        .into_iter()
        .filter(|m| m.status != Fmi2Status::Ok as i32)
        .collect();
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert_eq!(lines[0].category, "logStatusWarning");
    assert!(
        lines[0].text.starts_with(
            "fmi2DoStep: at rest: the measured tug1 is 0 m from the ship, less than half a beam"
        ),
        "{}",
        lines[0].text
    );
    assert!(
        lines[0].text.contains("sample at t = 0 s"),
        "{}",
        lines[0].text
    );
    // Once the inputs describe the tow, the controller solves again.
    set_states(&fmu, &paper_states());
    assert_eq!(fmu.step(t, 1.0), Fmi2Status::Ok, "{}", fmu.log_text());
    assert!(fmu.get_integer(vars::ADMM_ITERATIONS) >= 1);
    assert_eq!(fmu.get_integer(vars::FALLBACKS), 0);
}

/// Speeds far beyond the model's range (10 to 1000 m/s) make the MPC's iterates
/// overflow: the sample falls back, and every output stays finite (the residuals of the
/// overflowed iterate at f64::MAX, the predictions the measured states held), with the
/// commands within their bounds and fmi2OK.
#[test]
fn absurd_speeds_give_finite_outputs_never_nan() {
    let outputs = testing::real_outputs(&DESCRIPTION);
    for speed in [10.0, 100.0, 1000.0] {
        let fmu = controller("fast");
        let mut states = paper_states();
        for s in &mut states {
            s[3] = speed;
            s[4] = -0.5 * speed;
        }
        set_states(&fmu, &states);
        fmu.init(0.0, None);
        let mut t = 0.0;
        for k in 0..5 {
            step_ok_and_finite(&fmu, t, 1.0, &outputs, &format!("{speed} m/s, sample {k}"));
            t += 1.0;
            assert_commands_within_bounds(&fmu);
        }
    }
}

/// A master that sums `t += 0.1` and clips its last step at the stop time (OMSimulator)
/// ends with a step of a few 1e-12 s: every doStep is fmi2OK, to every stop time the issue
/// names.
#[test]
fn a_summing_master_reaches_every_stop_time_with_fmi2ok() {
    for stop in fmi2_slave::testing::SUMMING_MASTER_STOP_TIMES {
        let fmu = controller("summing");
        set_states(&fmu, &paper_states());
        fmu.init(0.0, Some(stop));
        fmi2_slave::testing::assert_summing_master_reaches(&fmu, stop, 0.1);
        assert_eq!(i64::from(fmu.get_integer(vars::SAMPLES)), stop as i64);
        assert_eq!(fmu.get_integer(vars::FALLBACKS), 0);
    }
}

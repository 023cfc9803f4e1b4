//! The packaged FMUs through a Rust importer (fmi-rs 0.3, the code behind fmusim): the
//! validator on both, a plant run, and the closed loop of both FMUs connected by name in
//! both couplings (`e2e_tests::closed_loop`), no Python involved.
#![allow(non_snake_case, clippy::unwrap_used, clippy::expect_used)]

use e2e_tests::closed_loop::{run_closed_loop, ClosedLoop, Coupling, InitialInputs, Trajectory};
use e2e_tests::packaged_fmu;
use fmi_rs::fmi2::builder::FMU2Builder;
use fmi_rs::fmi2::types::fmi2Status;
use fmi_rs::model_description::fmi2::ModelDescription;

#[test]
fn fmi_rs_validator_reports_no_problems() {
    for model in ["TowingPlant", "TowingController"] {
        let fmu = packaged_fmu(model);
        let dir = tempfile::tempdir().unwrap();
        fmi_rs::zip::extract_zip_archive(&fmu, &dir).unwrap();
        let md = ModelDescription::from_path(&dir.path().join("modelDescription.xml")).unwrap();
        let problems: Vec<String> = md.validate().into_iter().map(|p| p.message).collect();
        assert!(
            problems.is_empty(),
            "{model}: fmi-rs validation problems: {problems:#?}"
        );
    }
}

/// The closed loop in `coupling` over `steps` steps of 0.1 s (paper scenario).
fn closed_loop(coupling: Coupling, steps: u32) -> Trajectory {
    run_closed_loop(
        &packaged_fmu("TowingPlant"),
        &packaged_fmu("TowingController"),
        coupling,
        InitialInputs::Exchanged,
        0.1,
        steps,
    )
    .unwrap_or_else(|e| panic!("{coupling:?}: {e}"))
}

/// Distance the ship made good along the route's first leg (course 101.3 deg).
fn along_route(t: &Trajectory) -> f64 {
    let (x, y) = (t.column("ship.x").unwrap(), t.column("ship.y").unwrap());
    let psi0 = 101.3_f64.to_radians();
    let n = x.len() - 1;
    (x[n] - x[0]) * psi0.cos() + (y[n] - y[0]) * psi0.sin()
}

/// Both FMUs, connected by name, Gauss-Seidel with the controller first, 0.1 s steps,
/// 120 s of the paper scenario: every command finite, the ship under way along the route,
/// the controller's sample counter at one per second.
#[test]
fn closed_loop_under_fmi_rs() {
    let t = closed_loop(Coupling::GaussSeidel, 1200);
    assert_eq!(t.to_plant.len(), 8, "six thrusts and two tension commands");
    assert!(
        t.to_controller.len() >= 18 + 7 * 8,
        "vessel states and obstacles"
    );
    assert_eq!(t.warnings, 0, "no fmi2Warning");
    assert_eq!(
        *t.column("controller.fallbacks").unwrap().last().unwrap(),
        0.0,
        "no MPC fallback"
    );
    for name in &t.to_plant {
        let command = t.column(name).unwrap();
        assert!(command.iter().all(|v| v.is_finite()), "{name}: {command:?}");
    }
    let along = along_route(&t);
    assert!(along > 4.0, "ship moved {along} m along the route in 120 s");
    assert_eq!(
        *t.column("controller.samples").unwrap().last().unwrap(),
        120.0
    );
}

/// The Jacobi coupling (libcosim's and fmpy's SSP runner's order: both FMUs step on the
/// other's outputs at the step's start) runs the same scenario, is deterministic to the bit
/// (every output but the wall-clock compute time), and gives another trajectory than Gauss-Seidel (the plant applies each command one step
/// later): the cross-check of the masters (tests/python/test_systems.py) compares like with
/// like, and would notice a master that silently uses the other order.
#[test]
fn jacobi_coupling_under_fmi_rs_is_deterministic_and_differs_from_gauss_seidel() {
    let jacobi = closed_loop(Coupling::Jacobi, 600);
    let again = closed_loop(Coupling::Jacobi, 600);
    assert_eq!(jacobi.columns, again.columns);
    for name in &jacobi.columns {
        if name == "controller.compute_time" {
            continue; // wall-clock time of a sample
        }
        let (a, b) = (jacobi.column(name).unwrap(), again.column(name).unwrap());
        let same = a.iter().zip(&b).all(|(p, q)| p.to_bits() == q.to_bits());
        assert!(same, "{name}: reruns differ");
    }
    assert_eq!(jacobi.warnings, 0);
    let along = along_route(&jacobi);
    assert!(along > 1.5, "ship moved {along} m along the route in 60 s");
    let gauss_seidel = closed_loop(Coupling::GaussSeidel, 600);
    let mut largest = 0.0_f64;
    for name in ["ship.x", "ship.y", "ship.psi"] {
        let (a, b) = (
            jacobi.column(name).unwrap(),
            gauss_seidel.column(name).unwrap(),
        );
        assert_eq!(a[0], b[0], "{name}: same initial state");
        for (p, q) in a.iter().zip(&b) {
            largest = largest.max((p - q).abs());
        }
    }
    assert!(
        largest > 1e-6 && largest < 1.0,
        "Jacobi and Gauss-Seidel differ by {largest} (expected: visibly, but both sane)"
    );
}

#[test]
fn plant_steps_under_fmi_rs_and_the_forward_tug_tows_the_ship() {
    let fmu = packaged_fmu("TowingPlant");
    let builder = FMU2Builder::new(&fmu).unwrap();
    let md = &builder.model_description;
    let vr = |name: &str| md.variable_by_name(name).unwrap().valueReference;
    let instance = builder.instantiate_cs("plant").unwrap();
    assert_eq!(
        instance.setupExperiment(None, 0.0, Some(60.0)),
        fmi2Status::Ok
    );
    assert_eq!(instance.enterInitializationMode(), fmi2Status::Ok);
    assert_eq!(instance.exitInitializationMode(), fmi2Status::Ok);
    assert_eq!(
        instance.setReal(
            &[vr("tug2.force_surge"), vr("towline2.tension_cmd")],
            &[3.0, 2.0]
        ),
        fmi2Status::Ok
    );
    let outputs = [vr("ship.x"), vr("ship.y"), vr("towline2.tension")];
    let mut start = [0.0; 3];
    assert_eq!(instance.getReal(&outputs, &mut start), fmi2Status::Ok);
    for k in 0..600 {
        let t = f64::from(k) * 0.1;
        assert_eq!(
            instance.doStep(t, 0.1, 1),
            fmi2Status::Ok,
            "step at t = {t}"
        );
    }
    let mut end = [0.0; 3];
    assert_eq!(instance.getReal(&outputs, &mut end), fmi2Status::Ok);
    let psi0 = 101.3_f64.to_radians();
    let along = (end[0] - start[0]) * psi0.cos() + (end[1] - start[1]) * psi0.sin();
    assert!(along > 2.0, "ship moved {along} m along its heading");
    assert_eq!(end[2], 2.0);
    // One step past the stop time is refused.
    assert_eq!(instance.doStep(60.0, 0.1, 1), fmi2Status::Error);
}

/// Issue 15, item 9: a closed loop whose two FMU states are serialized at 600 s and
/// restored into fresh instances in another process (`closed-loop-resume`) continues bit
/// for bit like the uninterrupted run, every output (but the wall-clock compute time) at
/// every step to 700 s, with either controller architecture.
#[test]
fn a_closed_loop_serialized_at_600_s_continues_bit_for_bit_in_another_process() {
    let (plant, controller) = (
        packaged_fmu("TowingPlant"),
        packaged_fmu("TowingController"),
    );
    let (save_at, end, stop) = (6000, 7000, 700.0);
    for architecture in [1, 2] {
        let dir = tempfile::tempdir().unwrap();
        let mut lp = ClosedLoop::load(&plant, &controller).unwrap();
        let exchanged = InitialInputs::Exchanged;
        lp.initialize(exchanged, stop, &[("architecture", architecture)])
            .unwrap();
        lp.run(Coupling::GaussSeidel, exchanged, 0.1, 0..save_at)
            .unwrap();
        lp.save(dir.path()).unwrap();
        let expected = lp
            .run(Coupling::GaussSeidel, exchanged, 0.1, save_at..end)
            .unwrap();
        let columns = lp.finish(Vec::new()).unwrap().columns;

        let out = dir.path().join("resumed.txt");
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_closed-loop-resume"))
            .args([&plant, &controller, dir.path()])
            .args([&save_at.to_string(), &end.to_string(), &stop.to_string()])
            .arg(&out)
            .status()
            .unwrap();
        assert!(status.success(), "architecture {architecture}: {status}");
        let resumed: Vec<Vec<u64>> = std::fs::read_to_string(&out)
            .unwrap()
            .lines()
            .map(|l| {
                l.split(' ')
                    .map(|w| u64::from_str_radix(w, 16).unwrap())
                    .collect()
            })
            .collect();
        assert_eq!(resumed.len(), expected.len());
        let skip = columns
            .iter()
            .position(|c| c == "controller.compute_time")
            .unwrap();
        for (k, (a, b)) in expected.iter().zip(&resumed).enumerate() {
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                if i != skip {
                    assert_eq!(
                        x.to_bits(),
                        *y,
                        "architecture {architecture}, step {}, {}",
                        save_at as usize + k,
                        columns[i]
                    );
                }
            }
        }
        // The comparison can fail: the loop moved on after 600 s.
        let x = columns.iter().position(|c| c == "ship.x").unwrap();
        assert_ne!(expected[0][x], expected[expected.len() - 1][x]);
    }
}

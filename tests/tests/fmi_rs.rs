//! The packaged FMUs through a Rust importer (fmi-rs 0.3, the code behind fmusim): the
//! validator on both, a plant run, and the closed loop of both FMUs connected by name,
//! no Python involved.
#![allow(non_snake_case, clippy::unwrap_used, clippy::expect_used)]

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

/// `(from value reference, to value reference)` pairs of one type.
type Pairs = Vec<(u32, u32)>;

/// Connections by identical names, per type (Real, Integer, Boolean).
fn connections(from: &ModelDescription, to: &ModelDescription) -> (Pairs, Pairs, Pairs) {
    use fmi_rs::model_description::fmi2::{Causality, VariableType};
    let (mut reals, mut ints, mut bools) = (Vec::new(), Vec::new(), Vec::new());
    for input in to
        .modelVariables
        .iter()
        .filter(|v| matches!(v.causality, Causality::Input))
    {
        let Ok(output) = from.variable_by_name(&input.name) else {
            continue;
        };
        assert!(
            matches!(output.causality, Causality::Output),
            "{} is not an output",
            input.name
        );
        let pair = (output.valueReference, input.valueReference);
        match input.variableType {
            VariableType::Real { .. } => reals.push(pair),
            VariableType::Integer { .. } => ints.push(pair),
            VariableType::Boolean { .. } => bools.push(pair),
            _ => panic!("{}: unexpected type", input.name),
        }
    }
    (reals, ints, bools)
}

/// Both FMUs, connected by name, Gauss-Seidel with the controller first, 0.1 s steps,
/// 120 s of the paper scenario: every command within its bound, the ship under way
/// along the route, the controller's sample counter at one per second.
#[test]
fn closed_loop_under_fmi_rs() {
    let plant_b = FMU2Builder::new(&packaged_fmu("TowingPlant")).unwrap();
    let ctrl_b = FMU2Builder::new(&packaged_fmu("TowingController")).unwrap();
    let (p_md, c_md) = (&plant_b.model_description, &ctrl_b.model_description);
    let to_ctrl = connections(p_md, c_md);
    let to_plant = connections(c_md, p_md);
    assert_eq!(to_plant.0.len(), 8, "six thrusts and two tension commands");
    assert!(to_ctrl.0.len() >= 18 + 6 * 8, "vessel states and obstacles");
    let plant = plant_b.instantiate_cs("plant").unwrap();
    let ctrl = ctrl_b.instantiate_cs("controller").unwrap();
    for fmu in [&plant, &ctrl] {
        assert_eq!(fmu.setupExperiment(None, 0.0, Some(120.0)), fmi2Status::Ok);
        assert_eq!(fmu.enterInitializationMode(), fmi2Status::Ok);
        assert_eq!(fmu.exitInitializationMode(), fmi2Status::Ok);
    }
    let copy_reals = |from: &fmi_rs::fmi2::FMU2<fmi_rs::fmi2::CS>,
                      to: &fmi_rs::fmi2::FMU2<fmi_rs::fmi2::CS>,
                      c: &[(u32, u32)]| {
        let (src, dst): (Vec<u32>, Vec<u32>) = c.iter().copied().unzip();
        let mut v = vec![0.0; src.len()];
        assert_eq!(from.getReal(&src, &mut v), fmi2Status::Ok);
        assert_eq!(to.setReal(&dst, &v), fmi2Status::Ok);
        v
    };
    let copy_ints = |from: &fmi_rs::fmi2::FMU2<fmi_rs::fmi2::CS>,
                     to: &fmi_rs::fmi2::FMU2<fmi_rs::fmi2::CS>,
                     c: &[(u32, u32)]| {
        let (src, dst): (Vec<u32>, Vec<u32>) = c.iter().copied().unzip();
        let mut v = vec![0; src.len()];
        assert_eq!(from.getInteger(&src, &mut v), fmi2Status::Ok);
        assert_eq!(to.setInteger(&dst, &v), fmi2Status::Ok);
    };
    let vr = |md: &ModelDescription, name: &str| md.variable_by_name(name).unwrap().valueReference;
    let ship = [vr(p_md, "ship.x"), vr(p_md, "ship.y")];
    let mut start = [0.0; 2];
    assert_eq!(plant.getReal(&ship, &mut start), fmi2Status::Ok);
    for k in 0..1200 {
        let t = f64::from(k) * 0.1;
        copy_reals(&plant, &ctrl, &to_ctrl.0);
        copy_ints(&plant, &ctrl, &to_ctrl.1);
        assert!(to_ctrl.2.is_empty());
        let status = ctrl.doStep(t, 0.1, 1);
        assert_eq!(status, fmi2Status::Ok, "controller at t = {t}");
        let commands = copy_reals(&ctrl, &plant, &to_plant.0);
        for (name_vr, value) in to_plant.0.iter().zip(&commands) {
            assert!(value.is_finite(), "command vr {} = {value}", name_vr.0);
        }
        assert_eq!(plant.doStep(t, 0.1, 1), fmi2Status::Ok, "plant at t = {t}");
    }
    let mut end = [0.0; 2];
    assert_eq!(plant.getReal(&ship, &mut end), fmi2Status::Ok);
    let psi0 = 101.3_f64.to_radians();
    let along = (end[0] - start[0]) * psi0.cos() + (end[1] - start[1]) * psi0.sin();
    assert!(along > 4.0, "ship moved {along} m along the route in 120 s");
    let mut samples = [0];
    assert_eq!(
        ctrl.getInteger(&[vr(c_md, "controller.samples")], &mut samples),
        fmi2Status::Ok
    );
    assert_eq!(samples[0], 120);
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

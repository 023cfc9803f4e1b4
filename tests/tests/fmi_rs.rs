//! The packaged TowingPlant FMU through a Rust importer (fmi-rs 0.3, the code behind fmusim):
//! its validator and an FMI 2.0 co-simulation run, no Python involved.
#![allow(non_snake_case, clippy::unwrap_used, clippy::expect_used)]

use e2e_tests::packaged_fmu;
use fmi_rs::fmi2::builder::FMU2Builder;
use fmi_rs::fmi2::types::fmi2Status;
use fmi_rs::model_description::fmi2::ModelDescription;

#[test]
fn fmi_rs_validator_reports_no_problems() {
    let fmu = packaged_fmu("TowingPlant");
    let dir = tempfile::tempdir().unwrap();
    fmi_rs::zip::extract_zip_archive(&fmu, &dir).unwrap();
    let md = ModelDescription::from_path(&dir.path().join("modelDescription.xml")).unwrap();
    let problems: Vec<String> = md.validate().into_iter().map(|p| p.message).collect();
    assert!(
        problems.is_empty(),
        "fmi-rs validation problems: {problems:#?}"
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

//! Prints the controller's generated `modelDescription.xml` (`xml`), its variable table
//! (`markdown`) or its HTML documentation (`html`); used by `cargo xtask model-description`
//! and `cargo xtask fmu`.
fn main() -> std::process::ExitCode {
    towing_interface::model_description_main(
        &towing_controller::variables::DESCRIPTION,
        &towing_interface::parameters::markdown(towing_control::PARAMETERS),
    )
}

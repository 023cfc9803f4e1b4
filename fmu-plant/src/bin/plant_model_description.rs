//! Prints the plant's generated `modelDescription.xml` (`xml`), its variable table
//! (`markdown`) or its HTML documentation (`html`); used by `cargo xtask model-description`
//! and `cargo xtask fmu`.
fn main() -> std::process::ExitCode {
    towing_interface::model_description_main(
        &towing_plant::variables::DESCRIPTION,
        &towing_interface::parameters::markdown(towing_plant::params::PARAMETERS),
    )
}

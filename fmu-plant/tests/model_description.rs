//! The committed model description and the interface document must be what the Rust
//! variable table generates (`cargo xtask model-description` regenerates both), and the
//! contract's names must be declared.

towing_interface::model_description_tests!(
    towing_plant::variables::DESCRIPTION,
    towing_plant::variables::VARIABLES
);

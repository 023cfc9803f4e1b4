//! The towing world as an FMI 2.0 Co-Simulation FMU (modelIdentifier `TowingPlant`).
//!
//! Thin by design: the variable table ([`variables`]), the [`Fmi2Model`](fmi2_slave::Fmi2Model)
//! implementation forwarding to the pure physics of `towing-model` ([`plant`]), and one
//! `export_fmi2!` that generates the 34 exported FMI functions. Every line of `unsafe` lives
//! in `fmi2-slave`; this crate denies it.
#![deny(unsafe_code)]

pub mod logging;
pub mod outputs;
pub mod params;
pub mod plant;
pub mod variables;

pub use plant::Plant;

fmi2_slave::export_fmi2!(Plant);

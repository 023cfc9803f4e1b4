//! The interface contract both towing FMUs implement (DESIGN.md, "Interface contract";
//! docs/interface.md): every variable a master connects by name is declared here once, with
//! its name, value reference, unit, declared type and description, for both ends of the
//! connection.
//!
//! * [`codec`]: the value-reference codec: every variable of the contract as a typed
//!   [`ContractVariable`] with `encode` and `decode`, the [`VariableTable`] through which
//!   each FMU decodes its own variables, [`UnknownReference`], and the FMI code of an
//!   obstacle slot's kind.
//! * [`vr`]: the numbering of the contract's value references (equal in both FMUs), which
//!   [`ContractVariable::encode`] follows.
//! * [`variables`]: builders of those variables for one end of the connection
//!   ([`Direction::Output`] in the FMU that computes them, [`Direction::Input`] in the one
//!   that reads them), and the generic parameter/input/output builders.
//! * [`types`]: the units and declared types, and the model-description skeleton
//!   ([`ModelInfo`]).
//! * [`parameters`]: an FMU's parameter registry as FMI variables (value references,
//!   types, model-description variables, Enumeration types, the values as JSON), for
//!   both FMUs.
//! * [`scenario`]: the `scenario` String parameter (a file path, or the bundled
//!   `resources/paper.toml`).
//! * [`session`]: the scenario and log life cycle both FMUs share ([`RunSession`]): its
//!   registry of String parameters `scenario`, `log_file` and `run_id`
//!   ([`session::PARAMETERS`], in both FMUs before their own), the scenario as loaded, the
//!   MCAP log opened with the run description and finished at terminate or release.
//! * [`model_description_main`]: the body of each FMU's model description binary (`plant_model_description`, `controller_model_description`).
//! * `testing` (feature `testing`): in-process test helpers shared by the FMU crates.
//!
//! Who produces what: the plant (`TowingPlant`) outputs the vessel states, the towline
//! values and the obstacle slots and reads the commands (tug forces, tension commands); the
//! controller (`TowingController`) does the opposite.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod codec;
pub mod parameters;
pub mod scenario;
pub mod session;
pub mod types;
pub mod variables;
pub mod vr;

#[cfg(feature = "testing")]
pub mod testing;

use codec::{ForceComponent, Towline, TowlineField, Tug, Vessel};
use fmi2_slave::description::ModelDescription;
use std::io::Write as _;
use std::process::ExitCode;

pub use codec::{ContractVariable, ModelVariable, UnknownReference, VariableTable};
pub use scenario::{ScenarioFile, BUNDLED_SCENARIO};
pub use session::{LogHeader, RunSession};
pub use types::{ModelInfo, RealType};
pub use variables::Direction;

/// The vessels in value-reference order ([`codec::Vessel`]): name prefix and description.
pub const VESSELS: [(&str, &str); 3] = [
    (Vessel::Ship.name(), "ship (CyberShip II)"),
    (Vessel::Tug1.name(), "aft tug (TitoNeri)"),
    (Vessel::Tug2.name(), "forward tug (TitoNeri)"),
];

/// The command vector in the order masters and tests use it: tug1 surge force, sway force,
/// yaw moment, tug2 the same, towline1 and towline2 tension commands.
pub const COMMANDS: [u32; 8] = {
    use ContractVariable::{TensionCmd, TugForce};
    use ForceComponent::{Surge, Sway, Yaw};
    [
        TugForce(Tug::Tug1, Surge).encode(),
        TugForce(Tug::Tug1, Sway).encode(),
        TugForce(Tug::Tug1, Yaw).encode(),
        TugForce(Tug::Tug2, Surge).encode(),
        TugForce(Tug::Tug2, Sway).encode(),
        TugForce(Tug::Tug2, Yaw).encode(),
        TensionCmd(Towline::Towline1).encode(),
        TensionCmd(Towline::Towline2).encode(),
    ]
};

/// The names of DESIGN.md's interface contract every FMU declares: the session's
/// parameters (`scenario`, `log_file`, `run_id`), the vessel states, the commands, the
/// towline values, the obstacle slots (every [`ContractVariable`] but the plant's own
/// `towlineN.slack`).
#[must_use]
pub fn contract_names() -> Vec<String> {
    let session = session::PARAMETERS.iter().map(|p| p.name.to_owned());
    let connected = ContractVariable::all()
        .filter(|v| !matches!(v, ContractVariable::Towline(_, TowlineField::Slack)))
        .map(ContractVariable::name);
    session.chain(connected).collect()
}

/// The body of an FMU's model description binary: prints `description` as
/// `modelDescription.xml` (argument `xml` or none), as the Markdown variable table of
/// docs/interface.md (`markdown`), the Markdown parameter tables of its registry
/// (`parameters`, given) or as HTML documentation (`html`); used by
/// `cargo xtask model-description` and `cargo xtask fmu`. Exit code 2 for an unknown
/// argument, 1 when stdout cannot be written.
#[must_use]
pub fn model_description_main(description: &ModelDescription, parameters: &str) -> ExitCode {
    let text = match std::env::args().nth(1).as_deref() {
        Some("xml") | None => description.to_xml(),
        Some("markdown") => fmi2_slave::doc::variables_markdown(description),
        Some("parameters") => parameters.to_owned(),
        Some("html") => fmi2_slave::doc::documentation_html(description),
        Some(other) => {
            let _ = writeln!(
                std::io::stderr(),
                "unknown output {other:?}: use xml or html"
            );
            return ExitCode::from(2);
        }
    };
    let mut out = std::io::stdout().lock();
    if out
        .write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .is_err()
    {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

//! Prints the controller's generated `modelDescription.xml` (`xml`) or its HTML documentation
//! (`html`); used by `cargo xtask model-description` and `cargo xtask fmu`.
use std::io::Write as _;

fn main() -> std::process::ExitCode {
    let description = &*towing_controller::variables::DESCRIPTION;
    let text = match std::env::args().nth(1).as_deref() {
        Some("xml") | None => towing_controller::variables::model_description_xml(),
        Some("markdown") => fmi2_slave::doc::variables_markdown(description),
        Some("html") => fmi2_slave::doc::documentation_html(description),
        Some(other) => {
            let _ = writeln!(
                std::io::stderr(),
                "unknown output {other:?}: use xml, markdown or html"
            );
            return std::process::ExitCode::from(2);
        }
    };
    let mut out = std::io::stdout().lock();
    if out
        .write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .is_err()
    {
        return std::process::ExitCode::FAILURE;
    }
    std::process::ExitCode::SUCCESS
}

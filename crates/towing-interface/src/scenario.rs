//! The `scenario` String parameter of both FMUs: the path of a scenario file, or empty for
//! the paper scenario bundled in the FMU's `resources/` folder.

use std::path::Path;
use towing_model::Scenario;

/// Name of the bundled default scenario inside the FMU's `resources/` folder.
pub const BUNDLED_SCENARIO: &str = "paper.toml";

/// A scenario as read: where it came from, its text (so a saved FMU state does not depend
/// on the file still existing) and the parsed scenario.
#[derive(Debug, Clone)]
pub struct ScenarioFile {
    /// The file path, as it appears in messages.
    pub origin: String,
    /// The TOML text.
    pub text: String,
    /// The parsed scenario.
    pub scenario: Scenario,
}

impl ScenarioFile {
    /// Reads the scenario named by the `scenario` parameter `parameter`: that file, or
    /// [`BUNDLED_SCENARIO`] in `resource_dir` when `parameter` is empty.
    ///
    /// # Errors
    /// A message naming the file and the reason (unreadable, bad TOML, a field's value), or
    /// saying to set `scenario` when it is empty and there is no resources folder.
    pub fn load(parameter: &str, resource_dir: Option<&Path>) -> Result<Self, String> {
        let path = if parameter.is_empty() {
            let dir = resource_dir.ok_or_else(|| {
                "the scenario parameter is empty and the FMU has no resources folder holding the bundled \
                 paper scenario; set scenario to a file path"
                    .to_owned()
            })?;
            dir.join(BUNDLED_SCENARIO)
        } else {
            Path::new(parameter).to_path_buf()
        };
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read scenario file {origin}: {e}"))?;
        Self::parse(origin, text)
    }

    /// Parses `text` read from `origin`.
    ///
    /// # Errors
    /// The parse or validation error of [`Scenario::from_toml_str`], naming `origin`.
    pub fn parse(origin: String, text: String) -> Result<Self, String> {
        let scenario = Scenario::from_toml_str(&text, &origin).map_err(|e| e.to_string())?;
        Ok(ScenarioFile {
            origin,
            text,
            scenario,
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_parameter_without_resources_says_to_set_scenario() {
        let e = ScenarioFile::load("", None).unwrap_err();
        assert!(e.contains("set scenario to a file path"), "{e}");
    }

    #[test]
    fn a_missing_file_is_named() {
        let e = ScenarioFile::load("/nonexistent/s.toml", None).unwrap_err();
        assert!(
            e.contains("cannot read scenario file /nonexistent/s.toml"),
            "{e}"
        );
    }

    #[test]
    fn the_bundled_scenario_is_read_from_the_resources_folder() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios");
        let file = ScenarioFile::load("", Some(&dir)).unwrap();
        assert!(file.origin.ends_with(BUNDLED_SCENARIO));
        assert_eq!(file.scenario.ship.eta[0], -4.9);
    }
}

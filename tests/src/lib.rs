//! Helpers of the end-to-end tests in `tests/tests/`: the packaged FMUs, built on demand
//! through `cargo xtask fmu` (the same command users run), once per test binary.
#![forbid(unsafe_code)]

pub mod closed_loop;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// Repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// Path of `target/fmu/<model_identifier>.fmu`, packaging the FMUs first (once per process).
///
/// # Panics
/// When packaging fails: the test cannot run without the FMU, and says why.
pub fn packaged_fmu(model_identifier: &str) -> PathBuf {
    static PACKAGED: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let dir = PACKAGED.get_or_init(|| {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let status = Command::new(cargo)
            .args(["xtask", "fmu"])
            .current_dir(root())
            .status()
            .map_err(|e| format!("cannot run cargo xtask fmu: {e}"))?;
        if !status.success() {
            return Err(format!("cargo xtask fmu failed: {status}"));
        }
        let target = std::env::var_os("CARGO_TARGET_DIR")
            .map_or_else(|| root().join("target"), PathBuf::from);
        Ok(target.join("fmu"))
    });
    match dir {
        Ok(dir) => dir.join(format!("{model_identifier}.fmu")),
        Err(e) => panic!("{e}"),
    }
}

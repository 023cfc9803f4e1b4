//! Build automation for the towing co-simulation workspace.
//!
//! ```text
//! cargo xtask fmu                 build release libraries, package target/fmu/<Model>.fmu
//! cargo xtask model-description   regenerate modelDescription/<Model>.xml from the Rust tables
//! cargo xtask python              create/refresh the Python environment in .venv
//! cargo xtask ssp [--update]      systems/towing.ssp and the OSP files (docs/masters.md)
//! cargo xtask test                the README's test command: everything CI checks
//! cargo xtask demo                the README's main command (out/paper/report.html)
//! cargo xtask reproduce           the paper's six runs and docs/RESULTS.md
//! cargo xtask campaign FILE --out DIR [--workers N] [--scheduler ADDRESS] [--resume]
//!                                 many runs on Dask, judged by the analyzer (docs/campaigns.md)
//! cargo xtask bench-baseline [--from S] [--to S] [--samples N] [--scheme N] [--repeats N]
//!                                 CasADi + IPOPT beside the centralized MPC (docs/benchmarks.md)
//! ```
//!
//! Every step prints what it does; a failing step names itself and the reason.

use std::fmt;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

mod baseline;
mod campaign;
mod fmu;
mod python;
mod runs;
mod systems;

/// One FMU of the workspace: the crate that builds it and its identifiers.
#[derive(Debug, Clone, Copy)]
pub struct FmuCrate {
    /// Cargo package name.
    pub package: &'static str,
    /// `[lib] name` of the package, i.e. the stem of `lib<name>.so`.
    pub lib_name: &'static str,
    /// FMI modelIdentifier: the binary name inside the FMU and the FMU's file name.
    pub model_identifier: &'static str,
    /// The package's binary that prints the model description (`xml`, `html`, `markdown`).
    pub description_bin: &'static str,
    /// Files copied into the FMU's `resources/` folder (repository-relative source, name inside).
    pub resources: &'static [(&'static str, &'static str)],
}

/// The FMUs `cargo xtask fmu` packages.
pub const FMUS: &[FmuCrate] = &[
    FmuCrate {
        package: "fmu-plant",
        lib_name: "towing_plant",
        model_identifier: "TowingPlant",
        description_bin: "plant_model_description",
        resources: &[("scenarios/paper.toml", "paper.toml")],
    },
    FmuCrate {
        package: "fmu-controller",
        lib_name: "towing_controller",
        model_identifier: "TowingController",
        description_bin: "controller_model_description",
        resources: &[("scenarios/paper.toml", "paper.toml")],
    },
];

/// Error of one xtask step: which step failed and why.
#[derive(Debug)]
pub struct StepError {
    pub step: String,
    pub reason: String,
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "step '{}' failed: {}", self.step, self.reason)
    }
}

pub type Result<T> = std::result::Result<T, StepError>;

pub fn fail<T>(step: &str, reason: impl Into<String>) -> Result<T> {
    Err(StepError {
        step: step.to_owned(),
        reason: reason.into(),
    })
}

/// Repository root (the workspace directory).
pub fn root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().unwrap_or(manifest).to_path_buf()
}

/// The shared cargo target directory.
pub fn target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            if dir.is_absolute() {
                dir
            } else {
                root().join(dir)
            }
        }
        None => root().join("target"),
    }
}

/// Prints a progress line (xtask is a terminal program; progress goes to stderr).
pub fn progress(message: &str) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "xtask: {message}");
}

/// Runs a command in the repository root, streaming its output; fails the step on non-zero exit.
pub fn run(step: &str, cmd: &mut Command) -> Result<()> {
    progress(&format!("{step}: {}", describe(cmd)));
    let status = cmd.current_dir(root()).status().map_err(|e| StepError {
        step: step.to_owned(),
        reason: format!("could not start {}: {e}", describe(cmd)),
    })?;
    if status.success() {
        Ok(())
    } else {
        fail(step, format!("{} exited with {status}", describe(cmd)))
    }
}

/// Runs a command and returns its standard output (standard error is passed through).
pub fn output(step: &str, cmd: &mut Command) -> Result<String> {
    let out = cmd
        .current_dir(root())
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| StepError {
            step: step.to_owned(),
            reason: format!("could not start {}: {e}", describe(cmd)),
        })?;
    if !out.status.success() {
        return fail(
            step,
            format!("{} exited with {}", describe(cmd), out.status),
        );
    }
    String::from_utf8(out.stdout).or_else(|_| fail(step, "output is not UTF-8"))
}

fn describe(cmd: &Command) -> String {
    let mut s = cmd.get_program().to_string_lossy().into_owned();
    for a in cmd.get_args() {
        s.push(' ');
        s.push_str(&a.to_string_lossy());
    }
    s
}

pub fn cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

/// What a release build compiles. Both select the whole workspace, and cargo resolves the
/// same features for polars and every other dependency of the analyzer either way (the
/// dev-dependencies only add `towing-interface`'s `testing` helpers, so just that crate and
/// the two FMU crates compile a second time), so the demo, the FMU packaging, the campaigns,
/// `cargo test --workspace --release` and the baseline share every compiled dependency,
/// polars above all, instead of compiling it once per selection.
#[derive(Debug, Clone, Copy)]
pub enum Build {
    /// Libraries and binaries: the FMUs, the analyzer, the fuzz commands, the model
    /// description printers. What the demo, the packaging and the campaigns run; a cold
    /// demo does not wait for the tests and benches.
    Products,
    /// Also every test, bench and example (the baseline's recorder is an example).
    AllTargets,
}

/// The release build of `what` (see [`Build`]).
pub fn build_release(what: Build) -> Result<()> {
    let (step, selection): (&str, &[&str]) = match what {
        Build::Products => (
            "release build (workspace, libraries and binaries)",
            &["--lib", "--bins"],
        ),
        Build::AllTargets => ("release build (workspace, all targets)", &["--all-targets"]),
    };
    run(
        step,
        cargo()
            .args(["build", "--release", "--workspace"])
            .args(selection),
    )
}

const USAGE: &str = "usage: cargo xtask <command>

commands:
  fmu                 build the release libraries and write target/fmu/<Model>.fmu
  model-description   regenerate modelDescription/<Model>.xml from the Rust variable tables
  python              create or refresh the Python environment (.venv) with fmpy and libcosimpy
  ssp [--update]      package the FMUs, write systems/towing.ssp (SSP 1.0) and check (--update:
                      rewrite) systems/OspSystemStructure.xml and the OSP model descriptions
  test                run every check CI runs (fmt, clippy, FMU packaging, Rust and Python tests)
  demo                package both FMUs, run the closed loop on the paper scenario under fmpy with
                      MCAP logs and the analyzer's report (writes out/paper/report.html)
  reproduce           the paper's runs (distributed and centralized, schemes I, II, III) into
                      out/reproduce/, analyzer compare, and docs/RESULTS.md's tables and figures
  campaign FILE --out DIR [--workers N] [--scheduler ADDRESS] [--resume]
                      the campaign file's runs (scenarios x parameter values) on Dask, each judged
                      by the analyzer's verdict: DIR/summary.json, runs.parquet, report.html
                      (docs/campaigns.md)
  bench-baseline [--from S] [--to S] [--samples N] [--scheme 1|2|3] [--repeats N]
                 [--ipopt KEY=VALUE] [--out DIR]
                      the centralized MPC's problems of the paper scenario's closed loop (default
                      0-1200 s, scheme I) solved by ours and by CasADi + IPOPT; one table of solve
                      times and merits (out/bench-baseline/, docs/benchmarks.md)";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("fmu") => fmu::package_all().map(|_| ()),
        Some("model-description") => fmu::write_model_descriptions(),
        Some("python") => python::ensure_env().map(|_| ()),
        Some("ssp") => systems::run(&args[1..]),
        Some("test") => test_all(),
        Some("demo") => runs::demo(),
        Some("reproduce") => runs::reproduce(),
        Some("campaign") => campaign::campaign(&args[1..]),
        Some("bench-baseline") => baseline::bench_baseline(&args[1..]),
        Some("-h" | "--help" | "help") => {
            progress(USAGE);
            Ok(())
        }
        other => {
            progress(&format!("unknown command {other:?}\n{USAGE}"));
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            progress(&format!("error: {e}"));
            ExitCode::FAILURE
        }
    }
}

/// The README's test command: formatting, lints, packaging, Rust tests, Python tests. The
/// venv is set up while cargo works ([`python::ensure_env_during`]).
fn test_all() -> Result<()> {
    let (python, ()) = python::ensure_env_during(rust_checks)?;
    run(
        "python tests",
        Command::new(&python).args(["-m", "pytest", "tests/python", "-q", "-ra"]),
    )?;
    progress("all checks passed");
    Ok(())
}

/// Formatting, lints, packaging and the Rust tests of [`test_all`].
fn rust_checks() -> Result<()> {
    run(
        "format check",
        cargo().args(["fmt", "--all", "--", "--check"]),
    )?;
    run(
        "clippy",
        cargo().args([
            "clippy",
            "--workspace",
            "--all-targets",
            "--release",
            "--",
            "-D",
            "warnings",
        ]),
    )?;
    fmu::package_all()?;
    run(
        "rust tests",
        cargo().args(["test", "--workspace", "--release", "--no-fail-fast"]),
    )
}

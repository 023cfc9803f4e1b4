//! Closed-loop runs with logs and reports: `cargo xtask demo` (the README's main command)
//! and `cargo xtask reproduce` (the paper's six runs and `docs/RESULTS.md`).
//!
//! A run is three steps, each named when it fails: the master `masters/closed_loop.py`
//! under fmpy with `--log-dir` (both FMUs' MCAP logs, docs/logging.md), then
//! `analyzer report` on the two logs (docs/analyzer.md). A run directory holds:
//!
//! ```text
//! DIR/logs/plant.mcap, DIR/logs/controller.mcap   the MCAP logs (open them in Foxglove)
//! DIR/run/                                        the master's map.png, timeseries.csv, summary.json
//! DIR/report.html, report.md, metrics.json, ...   the analyzer's report
//! ```

use crate::{fail, fmu, progress, python, root, run, target_dir, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// One closed-loop case: controller architecture and avoidance scheme of Du et al. (2022).
#[derive(Debug, Clone, Copy)]
struct Case {
    /// Directory name under the output directory.
    name: &'static str,
    /// Controller `architecture`: 1 distributed (ADMM), 2 centralized.
    architecture: u8,
    /// Controller `avoidance_scheme`: 1, 2, 3 (schemes I, II, III).
    scheme: u8,
}

/// The paper's runs (section 4): both architectures, schemes I, II, III.
const PAPER_CASES: [Case; 6] = [
    Case {
        name: "distributed-I",
        architecture: 1,
        scheme: 1,
    },
    Case {
        name: "distributed-II",
        architecture: 1,
        scheme: 2,
    },
    Case {
        name: "distributed-III",
        architecture: 1,
        scheme: 3,
    },
    Case {
        name: "centralized-I",
        architecture: 2,
        scheme: 1,
    },
    Case {
        name: "centralized-II",
        architecture: 2,
        scheme: 2,
    },
    Case {
        name: "centralized-III",
        architecture: 2,
        scheme: 3,
    },
];

/// Simulated time of every run, s: the paper's runs settle by about 1150 s.
const STOP_TIME: &str = "1200";

/// What every run needs: the Python environment, the packaged FMUs, the analyzer binary
/// (the paper's runs here, the campaigns in `campaign.rs`).
pub struct Tools {
    /// The venv's Python.
    pub python: PathBuf,
    /// `TowingPlant.fmu`.
    pub plant: PathBuf,
    /// `TowingController.fmu`.
    pub controller: PathBuf,
    /// The release `analyzer` binary.
    pub analyzer: PathBuf,
}

impl Tools {
    /// Prepares all of them (a second call reuses what exists: the venv's stamp, cargo's
    /// incremental build). The venv is set up while cargo builds.
    pub fn prepare() -> Result<Self> {
        let (python, fmus) = python::ensure_env_during(fmu::package_all)?;
        let find = |model: &str| {
            fmus.iter()
                .find(|p| p.file_stem().is_some_and(|n| n == model))
                .cloned()
                .map_or_else(
                    || fail("package FMUs", format!("{model}.fmu was not packaged")),
                    Ok,
                )
        };
        let plant = find("TowingPlant")?;
        let controller = find("TowingController")?;
        let analyzer = target_dir().join("release/analyzer");
        if !analyzer.is_file() {
            return fail(
                "build the analyzer",
                format!("{} is missing after the build", analyzer.display()),
            );
        }
        Ok(Self {
            python,
            plant,
            controller,
            analyzer,
        })
    }

    /// Runs `case` into `dir` (see the module documentation); progress lines from the
    /// master every 100 s of simulated time unless `quiet`.
    fn run_case(&self, case: &Case, dir: &Path, quiet: bool) -> Result<()> {
        let logs = dir.join("logs");
        let mut master = Command::new(&self.python);
        master
            .arg("masters/closed_loop.py")
            .arg("--plant")
            .arg(&self.plant)
            .arg("--controller")
            .arg(&self.controller)
            .args(["--stop-time", STOP_TIME])
            .args(["--architecture", &case.architecture.to_string()])
            .args(["--scheme", &case.scheme.to_string()])
            .arg("--log-dir")
            .arg(&logs)
            .arg("--out")
            .arg(dir.join("run"));
        if quiet {
            master.arg("--quiet");
        }
        run(
            &format!("{}: closed loop under fmpy ({STOP_TIME} s)", case.name),
            &mut master,
        )?;
        let mut report = Command::new(&self.analyzer);
        report.arg("report");
        if quiet {
            report.arg("--quiet");
        }
        report
            .arg("--out")
            .arg(dir)
            .arg(logs.join("plant.mcap"))
            .arg(logs.join("controller.mcap"));
        run(&format!("{}: analyzer report", case.name), &mut report)
    }
}

/// `cargo xtask demo`: the paper scenario, distributed MPC, scheme I, 1200 s under fmpy with
/// logs, and the analyzer's report in `out/paper/`.
pub fn demo() -> Result<()> {
    let tools = Tools::prepare()?;
    let out = root().join("out/paper");
    let case = PAPER_CASES[0];
    tools.run_case(&case, &out, false)?;
    progress(&format!(
        "demo finished: report {} (map {}, metrics {}); logs for Foxglove in {} (docs/foxglove.md)",
        out.join("report.html").display(),
        out.join("map.png").display(),
        out.join("metrics.json").display(),
        out.join("logs").display()
    ));
    Ok(())
}

/// Marks the generated part of `docs/RESULTS.md`; the text around it is written by hand.
const BEGIN: &str = "<!-- BEGIN generated by `cargo xtask reproduce` -->";
const END: &str = "<!-- END generated by `cargo xtask reproduce` -->";

/// Plots copied into `docs/img/results/` (as `<run>-<plot>.png`) for `docs/RESULTS.md`: the
/// map of every run, and the paper's Fig. 12 and 13 (states, towing angles and forces) of the
/// scheme I runs (Table 7 compares those); the rest stays in the run directories.
fn figures(case: &Case) -> &'static [&'static str] {
    if case.scheme == 1 {
        &["map", "states", "towing"]
    } else {
        &["map"]
    }
}

/// `cargo xtask reproduce`: the six runs of the paper into `out/reproduce/<run>/`,
/// `analyzer compare` into `out/reproduce/compare/`, and the generated part of
/// `docs/RESULTS.md` (the tables and the figures) rewritten from them.
pub fn reproduce() -> Result<()> {
    const STEP: &str = "write docs/RESULTS.md";
    let tools = Tools::prepare()?;
    // Commands run in the repository root (see `run`), so the runs are given paths relative
    // to it: the generated tables then name the run directories the same on every machine.
    let relative = Path::new("out/reproduce");
    let out = root().join(relative);
    let mut names = Vec::new();
    for case in &PAPER_CASES {
        let name = relative.join(case.name);
        tools.run_case(case, &name, true)?;
        names.push(name);
    }
    let compare = out.join("compare");
    let mut cmd = Command::new(&tools.analyzer);
    cmd.args(["compare", "--quiet", "--out"])
        .arg(relative.join("compare"));
    cmd.args(&names);
    let dirs: Vec<PathBuf> = names.iter().map(|name| root().join(name)).collect();
    run("analyzer compare", &mut cmd)?;

    let tables = std::fs::read_to_string(compare.join("compare.md")).or_else(|e| {
        fail(
            STEP,
            format!("cannot read {}: {e}", compare.join("compare.md").display()),
        )
    })?;
    let img = root().join("docs/img/results");
    std::fs::create_dir_all(&img)
        .or_else(|e| fail(STEP, format!("cannot create {}: {e}", img.display())))?;
    let mut generated = String::new();
    generated.push_str(&demote_headings(&tables));
    generated.push_str("\n### Figures\n");
    for (case, dir) in PAPER_CASES.iter().zip(&dirs) {
        generated.push_str(&format!("\n#### {}\n\n", case.name));
        for plot in figures(case) {
            let from = dir.join(format!("{plot}.png"));
            let name = format!("{}-{plot}.png", case.name);
            std::fs::copy(&from, img.join(&name)).or_else(|e| {
                fail(
                    STEP,
                    format!("cannot copy {} into {}: {e}", from.display(), img.display()),
                )
            })?;
            generated.push_str(&format!("![{} {plot}](img/results/{name})\n", case.name));
        }
    }
    let path = root().join("docs/RESULTS.md");
    let text = std::fs::read_to_string(&path)
        .or_else(|e| fail(STEP, format!("cannot read {}: {e}", path.display())))?;
    let updated = replace_generated(&text, &generated)
        .or_else(|reason| fail(STEP, format!("{}: {reason}", path.display())))?;
    std::fs::write(&path, updated)
        .or_else(|e| fail(STEP, format!("cannot write {}: {e}", path.display())))?;
    progress(&format!(
        "reproduce finished: {} (tables from {}; run directories in {})",
        path.display(),
        compare.join("compare.md").display(),
        out.display()
    ));
    Ok(())
}

/// `text` with every Markdown heading two levels deeper (the compare report's `#` title
/// becomes a `###` section of RESULTS.md); lines in code fences are left alone.
fn demote_headings(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 64);
    let mut fenced = false;
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        }
        if !fenced && line.starts_with('#') {
            out.push_str("##");
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// `text` with the part between the [`BEGIN`] and [`END`] lines replaced by `generated`.
fn replace_generated(text: &str, generated: &str) -> std::result::Result<String, String> {
    let begin = text
        .find(BEGIN)
        .ok_or_else(|| format!("the line {BEGIN} is missing"))?;
    let end = text
        .find(END)
        .ok_or_else(|| format!("the line {END} is missing"))?;
    if end < begin {
        return Err(format!("{END} comes before {BEGIN}"));
    }
    Ok(format!(
        "{}{BEGIN}\n{}\n{}",
        &text[..begin],
        generated.trim_end(),
        &text[end..]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_generated_part_is_replaced() {
        let text = format!("intro\n{BEGIN}\nold\n{END}\nhand-written\n");
        let out = replace_generated(&text, "new\n").unwrap_or_default();
        assert_eq!(out, format!("intro\n{BEGIN}\nnew\n{END}\nhand-written\n"));
        assert!(replace_generated("no markers", "x").is_err());
        let swapped = format!("{END}\n{BEGIN}\n");
        assert!(replace_generated(&swapped, "x").is_err());
    }

    #[test]
    fn headings_are_demoted_outside_code_fences() {
        let text = "# Title\ntext\n```\n# comment\n```\n## Sub\n";
        assert_eq!(
            demote_headings(text),
            "### Title\ntext\n```\n# comment\n```\n#### Sub\n"
        );
    }
}

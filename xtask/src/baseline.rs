//! `cargo xtask bench-baseline`: the side-by-side baseline of the centralized MPC
//! (`docs/benchmarks.md`). Ours (`towing_mpc::Centralized`, SCP on Clarabel) and CasADi +
//! IPOPT solve the same problems, recorded from the paper scenario's closed loop, and one
//! table compares the solve times and the merits.
//!
//! Steps, each named when it fails:
//!
//! 1. the Python environment with casadi (`masters/requirements.txt`, [`python::ensure_env`]);
//! 2. the recorder, `examples/record_centralized` of towing-control, from the one workspace build;
//! 3. `record_centralized record`: the closed loop, the recorded inputs
//!    (`DIR/recorded.json`) and ours replayed and timed (`DIR/ours.json`);
//! 4. `benches/baseline/casadi_centralized.py solve`: IPOPT on the same inputs
//!    (`DIR/ipopt.json`);
//! 5. `record_centralized evaluate`: IPOPT's plans evaluated by `Centralized::evaluate`
//!    (`DIR/evaluated.json`);
//! 6. `casadi_centralized.py report`: the table (also `DIR/summary.json`).

use crate::{fail, progress, python, root, run, target_dir, Result};
use std::path::PathBuf;
use std::process::Command;

const STEP: &str = "bench-baseline";

/// The command's options (`USAGE` in main.rs).
#[derive(Debug)]
struct Options {
    /// Options passed to the recorder's `record` (window, scheme, repeats).
    record: Vec<String>,
    repeats: String,
    ipopt: Vec<String>,
    out: PathBuf,
}

fn parse(args: &[String]) -> Result<Options> {
    let mut o = Options {
        record: Vec::new(),
        repeats: "1".to_owned(),
        ipopt: Vec::new(),
        out: root().join("out/bench-baseline"),
    };
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let Some(value) = it.next() else {
            return fail(STEP, format!("option {flag} needs a value"));
        };
        match flag.as_str() {
            "--from" | "--to" | "--samples" | "--scheme" => {
                o.record.extend([flag.clone(), value.clone()]);
            }
            "--repeats" => o.repeats = value.clone(),
            "--ipopt" => o.ipopt.extend(["--ipopt".to_owned(), value.clone()]),
            "--out" => o.out = root().join(value),
            _ => {
                return fail(
                    STEP,
                    format!(
                        "unknown option {flag} (known: --from S, --to S, --samples N, \
                         --scheme 1|2|3, --repeats N, --ipopt KEY=VALUE, --out DIR)"
                    ),
                )
            }
        }
    }
    Ok(o)
}

/// The command (module docs).
pub fn bench_baseline(args: &[String]) -> Result<()> {
    let o = parse(args)?;
    let (python, ()) =
        python::ensure_env_during(|| crate::build_release(crate::Build::AllTargets))?;
    let recorder = target_dir().join("release/examples/record_centralized");
    let script = root().join("benches/baseline/casadi_centralized.py");
    let dir = &o.out;
    let file = |name: &str| dir.join(name);
    run(
        "record the closed loop and replay ours",
        Command::new(&recorder)
            .arg("record")
            .args(&o.record)
            .args(["--repeats", &o.repeats, "--out"])
            .arg(dir),
    )?;
    run(
        "solve the recorded problems with IPOPT",
        Command::new(&python)
            .arg(&script)
            .arg("solve")
            .arg(file("recorded.json"))
            .arg("--out")
            .arg(file("ipopt.json"))
            .arg("--ours")
            .arg(file("ours.json"))
            .args(["--repeats", &o.repeats])
            .args(&o.ipopt),
    )?;
    run(
        "evaluate IPOPT's plans with Centralized::evaluate",
        Command::new(&recorder)
            .arg("evaluate")
            .arg(file("recorded.json"))
            .arg(file("ipopt.json"))
            .arg("--out")
            .arg(file("evaluated.json")),
    )?;
    run(
        "compare",
        Command::new(&python).arg(&script).arg("report").arg(dir),
    )?;
    progress(&format!(
        "bench-baseline: inputs, times, plans and summary.json in {}",
        dir.display()
    ));
    Ok(())
}

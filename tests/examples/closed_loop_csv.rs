//! The closed loop of the packaged FMUs under the Rust importer (fmi-rs), written as CSV to
//! standard output: header `time` + every plant output + every controller output, one row
//! per communication step from t = 0 (the layout of `masters/closed_loop.py`'s
//! timeseries.csv), every number in the shortest form that reads back to the same f64.
//! `tests/python/test_systems.py` compares it with the other masters.
//!
//! ```text
//! cargo run --release -p e2e-tests --example closed_loop_csv -- \
//!     [--plant FMU] [--controller FMU] [--coupling gauss-seidel|jacobi] \
//!     [--initial-inputs exchanged|zero] [--stop-time S] [--step H]
//! ```
//!
//! Defaults: the FMUs packaged by `cargo xtask fmu`, gauss-seidel, exchanged, 60 s, 0.1 s.
//! `--initial-inputs zero` starts every connected input at 0 without exchanging the initial
//! outputs, as fmpy's SSP runner does.

use e2e_tests::closed_loop::{run_closed_loop, Coupling, InitialInputs};
use e2e_tests::packaged_fmu;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "closed_loop_csv: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let mut plant: Option<PathBuf> = None;
    let mut controller: Option<PathBuf> = None;
    let mut coupling = Coupling::GaussSeidel;
    let mut initial = InitialInputs::Exchanged;
    let mut stop_time = 60.0_f64;
    let mut step = 0.1_f64;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{flag} needs a value"));
        let number = |s: String| s.parse::<f64>().map_err(|e| format!("{flag} {s}: {e}"));
        match flag.as_str() {
            "--plant" => plant = Some(value()?.into()),
            "--controller" => controller = Some(value()?.into()),
            "--coupling" => coupling = value()?.parse()?,
            "--initial-inputs" => {
                initial = match value()?.as_str() {
                    "exchanged" => InitialInputs::Exchanged,
                    "zero" => InitialInputs::Zero,
                    other => return Err(format!("unknown --initial-inputs {other:?}")),
                }
            }
            "--stop-time" => stop_time = number(value()?)?,
            "--step" => step = number(value()?)?,
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if !(step > 0.0 && step.is_finite() && stop_time > 0.0 && stop_time.is_finite()) {
        return Err(format!(
            "need step > 0 and stop time > 0, got {step} and {stop_time}"
        ));
    }
    let steps = (stop_time / step - 1e-9).ceil();
    if steps > f64::from(u32::MAX) {
        return Err(format!("too many steps: {steps}"));
    }
    let plant = plant.unwrap_or_else(|| packaged_fmu("TowingPlant"));
    let controller = controller.unwrap_or_else(|| packaged_fmu("TowingController"));
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let trajectory = run_closed_loop(&plant, &controller, coupling, initial, step, steps as u32)?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let io = |e: std::io::Error| format!("writing the CSV: {e}");
    writeln!(out, "{}", trajectory.columns.join(",")).map_err(io)?;
    for row in &trajectory.rows {
        let line: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
        writeln!(out, "{}", line.join(",")).map_err(io)?;
    }
    out.flush().map_err(io)?;
    let mut err = std::io::stderr().lock();
    writeln!(
        err,
        "closed_loop_csv: {} steps of {step} s, {coupling:?} coupling, {initial:?} initial inputs, {} fmi2Warning",
        trajectory.rows.len() - 1,
        trajectory.warnings
    )
    .map_err(io)
}

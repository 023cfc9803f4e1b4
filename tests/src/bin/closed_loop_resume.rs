//! Resumes a closed loop of the packaged FMUs from serialized FMU states, in a process of
//! its own (`tests/tests/fmi_rs.rs`): fresh instances, set up, restored from the files
//! `e2e_tests::closed_loop::ClosedLoop::save` wrote, then stepped; every row written as
//! the bits of its values (hexadecimal, one row per line).
//!
//! `closed-loop-resume PLANT.fmu CONTROLLER.fmu STATE_DIR FIRST_STEP LAST_STEP STOP_TIME OUT`
//! steps `FIRST_STEP..LAST_STEP` of 0.1 s, Gauss-Seidel.

use e2e_tests::closed_loop::{ClosedLoop, Coupling, InitialInputs};
use std::path::Path;
use std::process::ExitCode;

fn resume(args: &[String]) -> Result<(), String> {
    let [plant, controller, dir, first, last, stop, out] = args else {
        return Err(format!(
            "usage: closed-loop-resume PLANT.fmu CONTROLLER.fmu STATE_DIR FIRST_STEP LAST_STEP STOP_TIME OUT (got {} arguments)",
            args.len()
        ));
    };
    let number = |s: &str, what: &str| -> Result<u32, String> {
        s.parse().map_err(|e| format!("{what} {s:?}: {e}"))
    };
    let (first, last) = (number(first, "FIRST_STEP")?, number(last, "LAST_STEP")?);
    let stop: f64 = stop
        .parse()
        .map_err(|e| format!("STOP_TIME {stop:?}: {e}"))?;
    let mut lp = ClosedLoop::load(Path::new(plant), Path::new(controller))?;
    lp.restore(Path::new(dir), stop)?;
    let rows = lp.run(
        Coupling::GaussSeidel,
        InitialInputs::Exchanged,
        0.1,
        first..last,
    )?;
    let text: String = rows
        .iter()
        .map(|r| {
            let words: Vec<String> = r.iter().map(|v| format!("{:016x}", v.to_bits())).collect();
            words.join(" ") + "\n"
        })
        .collect();
    lp.finish(Vec::new())?;
    std::fs::write(out, text).map_err(|e| format!("writing {out}: {e}"))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match resume(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("closed-loop-resume: {e}");
            ExitCode::FAILURE
        }
    }
}

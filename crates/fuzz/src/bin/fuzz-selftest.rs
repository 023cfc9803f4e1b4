//! `fuzz-selftest --iterations N --seed S --out DIR`: see `towing_fuzz::targets::Planted` and
//! docs/analyzer.md ("Fuzzing").

fn main() -> std::process::ExitCode {
    towing_fuzz::run_main(&towing_fuzz::targets::Planted)
}

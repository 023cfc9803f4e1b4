//! Mutation fuzzers on stable Rust for the inputs the project reads from outside: the
//! scenario loader (`towing_model::Scenario::from_toml_str`, and the world built from what
//! it accepts) and the analyzer's MCAP reader (`analyzer::read::read_log_bytes` and
//! `peek_log_bytes`). No sanitizer or nightly toolchain: a mutation loop over a seed
//! corpus, deterministic for a seed (the input of execution `i` depends on the seed, `i`
//! and the corpus only, [`input_for`]).
//!
//! - [`mutate`]: bit flips, byte changes, insertions, deletions, splices from other seeds,
//!   numeric tokens replaced by extreme values, integer fields overwritten, truncation.
//! - [`driver`]: the executions run in child processes of the same binary, in batches; a
//!   panic is caught (`catch_unwind`, here only, to count it and keep the input) and the
//!   batch goes on; an abort or a hang ends the child, and the parent finds the input from
//!   the child's progress file, keeps it and goes on after it. Every failing input is saved
//!   in the output directory and can be replayed (`--replay FILE`).
//! - [`targets`]: the two targets, and a planted one that checks the harness itself.
//!
//! Binaries: `fuzz-scenario`, `fuzz-mcap` (`--iterations N --seed S --out DIR`, see
//! [`driver::USAGE`]), and `fuzz-selftest`.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod driver;
pub mod mutate;
pub mod rng;
pub mod targets;

pub use driver::{run_main, Target};
pub use mutate::mutate;
pub use rng::Rng;

/// The input of execution `index` of a run with `seed` over `corpus` (not empty): a seed
/// picked and mutated by a generator seeded from both.
#[must_use]
pub fn input_for(seed: u64, index: u64, corpus: &[Vec<u8>]) -> Vec<u8> {
    let mut rng = Rng::for_execution(seed, index);
    let base = rng.below(corpus.len());
    mutate(&mut rng, &corpus[base], corpus)
}

//! `analyzer report --out DIR LOG...` and `analyzer compare --out DIR RUN_DIR...`
//! (docs/analyzer.md).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Metrics, plots and reports from the towing co-simulation's MCAP logs.
#[derive(Debug, Parser)]
#[command(name = "analyzer", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Analyse one run: its plant and controller logs (any order).
    Report {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// No progress bars.
        #[arg(long, short)]
        quiet: bool,
        /// Thresholds of the verdict (TOML, any subset of the keys; docs/analyzer.md,
        /// "Verdict"); the defaults without it.
        #[arg(long, value_name = "FILE")]
        thresholds: Option<PathBuf>,
        /// The run's MCAP logs (plant and controller).
        #[arg(required = true)]
        logs: Vec<PathBuf>,
    },
    /// Compare report directories in the layout of the paper's Tables 6 and 7.
    Compare {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// No progress bars.
        #[arg(long, short)]
        quiet: bool,
        /// Directories written by `analyzer report`.
        #[arg(required = true)]
        runs: Vec<PathBuf>,
    },
}

/// `println!` that does not panic when stdout is closed (`analyzer report ... | head -1`):
/// the report is written either way, and nobody reads the lines.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

fn main() -> ExitCode {
    // Library code returns errors; should anything still panic, say so in one line.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("analyzer: internal error: {info}");
    }));
    let cli = Cli::parse();
    match cli.command {
        Command::Report {
            out,
            quiet,
            thresholds,
            logs,
        } => match report(&out, &logs, quiet, thresholds.as_deref()) {
            Ok(outcome) => {
                let m = &outcome.metrics;
                for t in &m.run.truncated_files {
                    eprintln!(
                        "warning: {}: {}; the report covers what was read",
                        t.file, t.reason
                    );
                }
                say!(
                    "report written to {} ({} files){}",
                    out.display(),
                    outcome.written.len(),
                    if m.run.truncated {
                        ", from a TRUNCATED log"
                    } else {
                        ""
                    }
                );
                say!(
                    "settling time: {}; max elongation error: {} / {}; ship travel {:.2} m; collisions {}; bound violations {}; fallbacks {}",
                    m.settling
                        .settling_time_s
                        .map_or_else(|| "never settled".to_owned(), |t| format!("{t:.1} s")),
                    pct(m.elongation.max_towline_elongation_error[0]),
                    pct(m.elongation.max_towline_elongation_error[1]),
                    m.travel.ship_travel_m,
                    m.collisions.collisions,
                    m.bounds.bound_violations.report.total,
                    m.solver.fallbacks
                );
                if m.verdict.passed {
                    say!("verdict: passed");
                } else {
                    say!("verdict: FAILED ({} reasons)", m.verdict.reasons.len());
                    for r in &m.verdict.reasons {
                        say!("  {}", r.line());
                    }
                }
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("analyzer report: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Compare {
            out,
            quiet: _,
            runs,
        } => match analyzer::compare(&out, &runs) {
            Ok(outcome) => {
                say!(
                    "comparison of {} runs written to {}",
                    outcome.runs.len(),
                    out.display()
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("analyzer compare: {e}");
                ExitCode::FAILURE
            }
        },
    }
}

/// `analyzer report` with the thresholds of `thresholds` (a TOML file) or the defaults.
fn report(
    out: &std::path::Path,
    logs: &[PathBuf],
    quiet: bool,
    thresholds: Option<&std::path::Path>,
) -> analyzer::Result<analyzer::report::ReportOutcome> {
    let thresholds = match thresholds {
        Some(path) => analyzer::thresholds::Thresholds::from_file(path)?,
        None => analyzer::thresholds::Thresholds::default(),
    };
    analyzer::report::report_with(
        out,
        logs,
        quiet,
        &analyzer::stream::StreamOptions::default(),
        &thresholds,
    )
}

fn pct(v: Option<f64>) -> String {
    analyzer::metric::elongation::pct(v)
}

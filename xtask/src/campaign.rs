//! `cargo xtask campaign FILE --out DIR [--workers N] [--scheduler ADDRESS] [--resume]`:
//! many closed-loop runs judged by the analyzer's verdict (docs/campaigns.md).
//!
//! Prepares what every run needs (the packaged FMUs, the release analyzer, the Python
//! environment with Dask) and hands over to `masters/campaign.py`, which holds the campaign
//! logic: Dask, the task that travels to the workers and the fmpy master all live in Python.

use crate::runs::Tools;
use crate::{fail, run, Result};
use std::path::PathBuf;
use std::process::Command;

const USAGE: &str =
    "usage: cargo xtask campaign FILE --out DIR [--workers N] [--scheduler ADDRESS] [--resume]";

/// The command line of `cargo xtask campaign`, checked before anything is built.
#[derive(Debug, PartialEq)]
struct Options {
    file: PathBuf,
    out: PathBuf,
    workers: Option<String>,
    scheduler: Option<String>,
    resume: bool,
}

fn parse(args: &[String]) -> std::result::Result<Options, String> {
    let mut file = None;
    let mut out = None;
    let mut workers = None;
    let mut scheduler = None;
    let mut resume = false;
    let mut it = args.iter();
    while let Some(arg) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value"))
        };
        match arg.as_str() {
            "--out" => out = Some(PathBuf::from(value("--out")?)),
            "--workers" => {
                let n = value("--workers")?;
                if !n.parse::<usize>().is_ok_and(|n| n >= 1) {
                    return Err(format!("--workers must be a whole number >= 1, got {n:?}"));
                }
                workers = Some(n);
            }
            "--scheduler" => scheduler = Some(value("--scheduler")?),
            "--resume" => resume = true,
            other if other.starts_with('-') => return Err(format!("unknown option {other:?}")),
            other if file.is_none() => file = Some(PathBuf::from(other)),
            other => return Err(format!("unexpected argument {other:?}")),
        }
    }
    Ok(Options {
        file: file.ok_or("the campaign FILE is missing")?,
        out: out.ok_or("--out DIR is missing")?,
        workers,
        scheduler,
        resume,
    })
}

/// `cargo xtask campaign ...` (see the module documentation).
pub fn campaign(args: &[String]) -> Result<()> {
    const STEP: &str = "campaign";
    let options = parse(args).or_else(|e| fail(STEP, format!("{e}\n{USAGE}")))?;
    // Paths as the user gave them, relative to where cargo was started (commands run in
    // the repository root).
    let cwd =
        std::env::current_dir().or_else(|e| fail(STEP, format!("no current directory: {e}")))?;
    let tools = Tools::prepare()?;
    let mut cmd = Command::new(&tools.python);
    cmd.arg("masters/campaign.py")
        .arg(cwd.join(&options.file))
        .arg("--out")
        .arg(cwd.join(&options.out))
        .arg("--plant")
        .arg(&tools.plant)
        .arg("--controller")
        .arg(&tools.controller)
        .arg("--analyzer")
        .arg(&tools.analyzer);
    if let Some(n) = &options.workers {
        cmd.args(["--workers", n]);
    }
    if let Some(address) = &options.scheduler {
        cmd.args(["--scheduler", address]);
    }
    if options.resume {
        cmd.arg("--resume");
    }
    run(STEP, &mut cmd)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| (*s).to_owned()).collect()
    }

    #[test]
    fn options_are_parsed_and_bad_ones_named() {
        let o = parse(&args(&[
            "c.toml",
            "--out",
            "o",
            "--workers",
            "2",
            "--resume",
        ]));
        assert_eq!(
            o,
            Ok(Options {
                file: "c.toml".into(),
                out: "o".into(),
                workers: Some("2".into()),
                scheduler: None,
                resume: true,
            })
        );
        let e = |list: &[&str]| parse(&args(list)).err().unwrap_or_default();
        assert!(e(&["--out", "o"]).contains("FILE"));
        assert!(e(&["c.toml"]).contains("--out"));
        assert!(e(&["c.toml", "--out", "o", "--workers", "0"]).contains("--workers"));
        assert!(e(&["c.toml", "--out", "o", "--frobnicate"]).contains("--frobnicate"));
        assert!(e(&["c.toml", "--out"]).contains("needs a value"));
    }
}

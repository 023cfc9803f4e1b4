//! The fuzzing loop of one target: arguments, the parent that runs the executions in
//! batches in child processes, the child that executes a batch.
//!
//! The parent starts the same binary as a child for the executions `start..end` (a memory
//! limit set with `ulimit -v` first, so a runaway allocation aborts the child rather than
//! the machine). The child writes the index of each execution to a progress file before
//! running it, catches a panic (`catch_unwind`; the input is saved, the count goes on) and
//! ends with `done <executions> <panics>`; a watchdog thread ends it with exit status
//! [`HANG_EXIT`] when one execution takes longer than `--hang-secs`. When a child dies (a
//! signal, an abort, a hang), the parent reads the index from the progress file, runs the
//! executions before it again in a fresh child (to count them and their panics), runs the
//! culprit alone to confirm it, saves its input and goes on after it. So every execution
//! is counted once, and every panic, abort and hang keeps its input.

use std::fs::File;
use std::io::Read as _;
use std::os::unix::fs::FileExt as _;
use std::os::unix::process::ExitStatusExt as _;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::input_for;

/// Exit status of a child whose watchdog found an execution running too long.
pub const HANG_EXIT: i32 = 3;

/// How the binaries are called.
pub const USAGE: &str = "usage: fuzz-TARGET --iterations N --seed S --out DIR \
[--batch B (10000)] [--hang-secs H (20)] [--memory-mb M (4096; 0: no limit)]
       fuzz-TARGET --replay FILE   (one input, in this process, no panic caught)";

/// A fuzzing target.
pub trait Target: Sync {
    /// Its name, in messages and in the names of the saved inputs.
    fn name(&self) -> &'static str;
    /// The seed inputs (not empty).
    ///
    /// # Errors
    /// A seed cannot be read.
    fn corpus(&self) -> Result<Vec<Vec<u8>>, String>;
    /// One execution on `input`: returning is success, whatever the target's own result;
    /// a panic or an abort is a finding.
    fn run(&self, input: &[u8]);
}

/// What a binary was asked to do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Mode {
    /// Run `iterations` executions through children.
    Parent,
    /// Execute `start..end`, writing each index to `progress` first.
    Child {
        /// First execution.
        start: u64,
        /// End of the range (excluded).
        end: u64,
        /// The progress file.
        progress: PathBuf,
    },
    /// Run the target once on the input in this file.
    Replay(PathBuf),
}

/// The command line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Options {
    /// Executions in all.
    pub iterations: u64,
    /// Seed of the inputs.
    pub seed: u64,
    /// Where failing inputs are saved.
    pub out: PathBuf,
    /// Executions per child process.
    pub batch: u64,
    /// One execution longer than this (s) is a hang.
    pub hang_secs: u64,
    /// Address-space limit of a child, MiB (0: none).
    pub memory_mb: u64,
    /// Parent, child or replay.
    pub mode: Mode,
}

impl Options {
    /// Parses the arguments after the program name.
    ///
    /// # Errors
    /// A missing or malformed argument, named.
    pub fn parse(args: impl IntoIterator<Item = String>) -> Result<Options, String> {
        let mut args = args.into_iter();
        let mut opts = Options {
            iterations: 0,
            seed: 0,
            out: PathBuf::new(),
            batch: 10_000,
            hang_secs: 20,
            memory_mb: 4096,
            mode: Mode::Parent,
        };
        let (mut child, mut progress, mut have_out) = (None, None, false);
        while let Some(arg) = args.next() {
            let mut value = |name: &str| args.next().ok_or_else(|| format!("{name} needs a value"));
            let number = |name: &str, v: String| {
                v.parse::<u64>()
                    .map_err(|e| format!("{name} {v}: not a whole number ({e})"))
            };
            match arg.as_str() {
                "--iterations" => opts.iterations = number(&arg, value(&arg)?)?,
                "--seed" => opts.seed = number(&arg, value(&arg)?)?,
                "--batch" => opts.batch = number(&arg, value(&arg)?)?.max(1),
                "--hang-secs" => opts.hang_secs = number(&arg, value(&arg)?)?.max(1),
                "--memory-mb" => opts.memory_mb = number(&arg, value(&arg)?)?,
                "--out" => {
                    opts.out = PathBuf::from(value(&arg)?);
                    have_out = true;
                }
                "--replay" => opts.mode = Mode::Replay(PathBuf::from(value(&arg)?)),
                "--progress" => progress = Some(PathBuf::from(value(&arg)?)),
                "--child" => {
                    let start = number(&arg, value(&arg)?)?;
                    child = Some((start, number(&arg, value(&arg)?)?));
                }
                other => return Err(format!("unknown argument {other}")),
            }
        }
        if let (Some((start, end)), Some(progress)) = (child, progress) {
            opts.mode = Mode::Child {
                start,
                end,
                progress,
            };
        }
        if opts.mode == Mode::Parent && (!have_out || opts.iterations == 0) {
            return Err("--iterations (at least 1) and --out are required".to_owned());
        }
        Ok(opts)
    }
}

/// Counts of a run.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Tally {
    /// Executions done.
    pub executions: u64,
    /// Panics caught.
    pub panics: u64,
    /// Children that died otherwise (abort, signal).
    pub aborts: u64,
    /// Executions that ran longer than `--hang-secs`.
    pub hangs: u64,
}

impl Tally {
    /// Panics, aborts and hangs.
    #[must_use]
    pub fn findings(&self) -> u64 {
        self.panics + self.aborts + self.hangs
    }
}

/// The `main` of a fuzzer binary for `target` (module docs): exit status 0 when nothing
/// was found, 1 when something was, 2 on a usage or harness error.
#[allow(clippy::print_stdout)]
pub fn run_main(target: &dyn Target) -> ExitCode {
    let opts = match Options::parse(std::env::args().skip(1)) {
        Ok(opts) => opts,
        Err(e) => {
            eprintln!("fuzz-{}: {e}\n{USAGE}", target.name());
            return ExitCode::from(2);
        }
    };
    let result = match &opts.mode {
        Mode::Replay(file) => replay(target, file),
        Mode::Child {
            start,
            end,
            progress,
        } => child(target, &opts, *start..*end, progress),
        Mode::Parent => parent(target, &opts).inspect(|tally| {
            println!("{}", summary(target, &opts, tally));
        }),
    };
    match result {
        Ok(tally) if tally.findings() == 0 => ExitCode::SUCCESS,
        Ok(_) => ExitCode::from(1),
        Err(e) => {
            eprintln!("fuzz-{}: {e}", target.name());
            ExitCode::from(2)
        }
    }
}

/// The closing line of a run.
#[must_use]
pub fn summary(target: &dyn Target, opts: &Options, t: &Tally) -> String {
    format!(
        "fuzz-{}: {} executions, {} panics, {} aborts, {} hangs (seed {}); failing inputs in {}",
        target.name(),
        t.executions,
        t.panics,
        t.aborts,
        t.hangs,
        opts.seed,
        opts.out.display()
    )
}

/// `--replay FILE`: the target once on the file's bytes, nothing caught.
fn replay(target: &dyn Target, file: &Path) -> Result<Tally, String> {
    let input = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
    target.run(&input);
    eprintln!(
        "fuzz-{}: {} ran without a panic or an abort",
        target.name(),
        file.display()
    );
    Ok(Tally {
        executions: 1,
        ..Tally::default()
    })
}

/// The message of the last panic (the hook's report, location included).
static LAST_PANIC: Mutex<String> = Mutex::new(String::new());

/// Which execution runs, and since when (ms from the child's start); `u64::MAX`: none.
struct Watch {
    index: AtomicU64,
    since_ms: AtomicU64,
    start: Instant,
}

impl Watch {
    fn now_ms(&self) -> u64 {
        u64::try_from(self.start.elapsed().as_millis()).unwrap_or(u64::MAX)
    }

    fn begin(&self, index: u64) {
        self.since_ms.store(self.now_ms(), Ordering::SeqCst);
        self.index.store(index, Ordering::SeqCst);
    }

    fn end(&self) {
        self.index.store(u64::MAX, Ordering::SeqCst);
    }
}

/// Ends the process with [`HANG_EXIT`] when one execution runs longer than `hang`.
fn start_watchdog(watch: Arc<Watch>, hang: Duration) {
    std::thread::spawn(move || loop {
        std::thread::sleep((hang / 4).min(Duration::from_millis(250)));
        let index = watch.index.load(Ordering::SeqCst);
        let since = watch.since_ms.load(Ordering::SeqCst);
        let hang_ms = u64::try_from(hang.as_millis()).unwrap_or(u64::MAX);
        if index != u64::MAX && watch.now_ms().saturating_sub(since) > hang_ms {
            eprintln!("execution {index} runs longer than {hang:?}");
            std::process::exit(HANG_EXIT);
        }
    });
}

/// A child: executions `range`, each index written to `progress` before it runs.
#[allow(clippy::print_stdout)]
fn child(
    target: &dyn Target,
    opts: &Options,
    range: std::ops::Range<u64>,
    progress: &Path,
) -> Result<Tally, String> {
    let corpus = target.corpus()?;
    let file = File::create(progress).map_err(|e| format!("{}: {e}", progress.display()))?;
    let watch = Arc::new(Watch {
        index: AtomicU64::new(u64::MAX),
        since_ms: AtomicU64::new(0),
        start: Instant::now(),
    });
    start_watchdog(Arc::clone(&watch), Duration::from_secs(opts.hang_secs));
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = info.to_string();
        }
    }));
    let mut tally = Tally::default();
    for index in range {
        let input = input_for(opts.seed, index, &corpus);
        file.write_all_at(&index.to_le_bytes(), 0)
            .map_err(|e| format!("{}: {e}", progress.display()))?;
        watch.begin(index);
        let outcome = catch_unwind(AssertUnwindSafe(|| target.run(&input)));
        watch.end();
        tally.executions += 1;
        if outcome.is_err() {
            tally.panics += 1;
            let message = LAST_PANIC.lock().map(|m| m.clone()).unwrap_or_default();
            keep(target, opts, "panic", index, &input, &message)?;
        }
    }
    println!("done {} {}", tally.executions, tally.panics);
    // A child's findings are the parent's to report.
    Ok(Tally { panics: 0, ..tally })
}

/// Saves a failing input as `OUT/TARGET-KIND-seedS-INDEX.bin`, with a `.txt` beside it:
/// what happened and how to replay it.
fn keep(
    target: &dyn Target,
    opts: &Options,
    kind: &str,
    index: u64,
    input: &[u8],
    what: &str,
) -> Result<(), String> {
    let stem = format!("{}-{kind}-seed{}-{index}", target.name(), opts.seed);
    let bin = opts.out.join(format!("{stem}.bin"));
    std::fs::write(&bin, input).map_err(|e| format!("{}: {e}", bin.display()))?;
    let txt = opts.out.join(format!("{stem}.txt"));
    let note = format!(
        "{kind} in execution {index} of fuzz-{} with --seed {}:\n{what}\nreplay: fuzz-{} --replay {}\n",
        target.name(),
        opts.seed,
        target.name(),
        bin.display()
    );
    std::fs::write(&txt, note).map_err(|e| format!("{}: {e}", txt.display()))
}

/// How a child ended.
#[derive(Debug, Clone, PartialEq, Eq)]
enum ChildEnd {
    /// It ran its range: executions, panics.
    Done(u64, u64),
    /// It died at an execution: the index (from the progress file; `None` when it died
    /// before its first), hang or abort, and a description.
    Died(Option<u64>, Kind, String),
}

/// What killed a child.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Abort,
    Hang,
}

/// The parent: every execution, batch by batch, through children.
fn parent(target: &dyn Target, opts: &Options) -> Result<Tally, String> {
    let corpus = target.corpus()?;
    if corpus.is_empty() {
        return Err("the corpus is empty".to_owned());
    }
    std::fs::create_dir_all(&opts.out).map_err(|e| format!("{}: {e}", opts.out.display()))?;
    let started = Instant::now();
    let mut tally = Tally::default();
    let mut next = 0;
    while next < opts.iterations {
        let end = (next + opts.batch).min(opts.iterations);
        run_range(target, opts, &corpus, next..end, &mut tally)?;
        next = end;
        let secs = started.elapsed().as_secs_f64();
        eprintln!(
            "fuzz-{}: {}/{} executions, {} panics, {} aborts, {} hangs, {:.0} s, {:.0}/s",
            target.name(),
            tally.executions,
            opts.iterations,
            tally.panics,
            tally.aborts,
            tally.hangs,
            secs,
            tally.executions as f64 / secs.max(1e-9)
        );
    }
    Ok(tally)
}

/// Executions `range` through as many children as the deaths need (module docs).
fn run_range(
    target: &dyn Target,
    opts: &Options,
    corpus: &[Vec<u8>],
    range: std::ops::Range<u64>,
    tally: &mut Tally,
) -> Result<(), String> {
    let mut from = range.start;
    while from < range.end {
        match spawn_child(target, opts, from..range.end)? {
            ChildEnd::Done(executions, panics) => {
                tally.executions += executions;
                tally.panics += panics;
                return Ok(());
            }
            ChildEnd::Died(None, _, what) => {
                return Err(format!(
                    "a child died before its first execution ({what}); the harness itself fails"
                ))
            }
            ChildEnd::Died(Some(at), kind, what) => {
                // The executions before the culprit, counted in a fresh child.
                run_range(target, opts, corpus, from..at, tally)?;
                let alone = spawn_child(target, opts, at..at + 1)?;
                let (kind, what) = match alone {
                    ChildEnd::Died(_, k, w) => (k, w),
                    ChildEnd::Done(..) => (kind, format!("{what} (not again when run alone)")),
                };
                tally.executions += 1;
                match kind {
                    Kind::Abort => tally.aborts += 1,
                    Kind::Hang => tally.hangs += 1,
                }
                let name = if kind == Kind::Abort { "abort" } else { "hang" };
                let input = input_for(opts.seed, at, corpus);
                keep(target, opts, name, at, &input, &what)?;
                from = at + 1;
            }
        }
    }
    Ok(())
}

/// Runs one child on `range` and tells how it ended.
fn spawn_child(
    target: &dyn Target,
    opts: &Options,
    range: std::ops::Range<u64>,
) -> Result<ChildEnd, String> {
    let file = |suffix: &str| {
        opts.out.join(format!(
            ".{}-{}.{suffix}",
            target.name(),
            std::process::id()
        ))
    };
    let (progress, stdout, stderr) = (file("progress"), file("stdout"), file("stderr"));
    let _ = std::fs::remove_file(&progress);
    let create = |p: &Path| File::create(p).map_err(|e| format!("{}: {e}", p.display()));
    let mut command = child_command(opts, &range, &progress)?;
    command
        .stdin(Stdio::null())
        .stdout(create(&stdout)?)
        .stderr(create(&stderr)?);
    let mut child = command
        .spawn()
        .map_err(|e| format!("cannot start a child: {e}"))?;
    // Only a child stuck beyond its own watchdog reaches this.
    let deadline = Instant::now()
        + Duration::from_secs(60 + 2 * opts.hang_secs)
        + Duration::from_millis(50) * u32::try_from(range.end - range.start).unwrap_or(u32::MAX);
    let status = loop {
        match child
            .try_wait()
            .map_err(|e| format!("waiting for a child: {e}"))?
        {
            Some(status) => break Some(status),
            None if Instant::now() > deadline => {
                // Our own child, by its handle.
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            None => std::thread::sleep(Duration::from_millis(5)),
        }
    };
    let at = last_index(&progress);
    let tail = text_tail(&stderr);
    Ok(match status {
        Some(s) if s.success() => parse_done(&stdout)?,
        Some(s) if s.code() == Some(HANG_EXIT) => ChildEnd::Died(at, Kind::Hang, tail),
        Some(s) => ChildEnd::Died(at, Kind::Abort, format!("{}: {tail}", describe(s))),
        None => ChildEnd::Died(at, Kind::Hang, "the child did not end: killed".to_owned()),
    })
}

/// The command of a child for `range`: this binary, under `ulimit -v` when a memory limit
/// is set.
fn child_command(
    opts: &Options,
    range: &std::ops::Range<u64>,
    progress: &Path,
) -> Result<Command, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this binary: {e}"))?;
    let args: Vec<String> = vec![
        "--child".into(),
        range.start.to_string(),
        range.end.to_string(),
        "--progress".into(),
        progress.display().to_string(),
        "--seed".into(),
        opts.seed.to_string(),
        "--out".into(),
        opts.out.display().to_string(),
        "--hang-secs".into(),
        opts.hang_secs.to_string(),
    ];
    let sh = Path::new("/bin/sh");
    Ok(if opts.memory_mb > 0 && sh.exists() {
        let mut c = Command::new(sh);
        c.arg("-c")
            .arg(format!(
                "ulimit -v {} && exec \"$0\" \"$@\"",
                opts.memory_mb * 1024
            ))
            .arg(exe)
            .args(args);
        c
    } else {
        let mut c = Command::new(exe);
        c.args(args);
        c
    })
}

/// The last index a child wrote to its progress file.
fn last_index(progress: &Path) -> Option<u64> {
    let bytes = std::fs::read(progress).ok()?;
    let first: [u8; 8] = bytes.get(..8)?.try_into().ok()?;
    Some(u64::from_le_bytes(first))
}

/// The last lines a child wrote to stderr (what an abort says), on one line.
fn text_tail(path: &Path) -> String {
    let mut text = String::new();
    if let Ok(mut f) = File::open(path) {
        let _ = f.read_to_string(&mut text);
    }
    let lines: Vec<&str> = text.lines().rev().take(3).collect();
    lines.into_iter().rev().collect::<Vec<_>>().join(" | ")
}

/// A child's exit status in words.
fn describe(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (_, Some(signal)) => format!("killed by signal {signal}"),
        (Some(code), _) => format!("exit status {code}"),
        _ => status.to_string(),
    }
}

/// The `done <executions> <panics>` line of a child that ran its range.
fn parse_done(stdout: &Path) -> Result<ChildEnd, String> {
    let text = std::fs::read_to_string(stdout).map_err(|e| format!("{}: {e}", stdout.display()))?;
    let line = text
        .lines()
        .rev()
        .find(|l| l.starts_with("done "))
        .unwrap_or("");
    let mut words = line.split_whitespace().skip(1).map(str::parse::<u64>);
    match (words.next(), words.next()) {
        (Some(Ok(executions)), Some(Ok(panics))) => Ok(ChildEnd::Done(executions, panics)),
        _ => Err(format!(
            "a child ended without its `done` line (stdout: {text:?})"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(str::to_owned).collect()
    }

    #[test]
    fn arguments_are_parsed_and_bad_ones_named() {
        let o = Options::parse(args("--iterations 1000 --seed 7 --out /tmp/x")).expect("ok");
        assert_eq!((o.iterations, o.seed, o.batch), (1000, 7, 10_000));
        assert_eq!(o.mode, Mode::Parent);
        let c = Options::parse(args("--child 5 9 --progress p --seed 1 --out o")).expect("ok");
        assert_eq!(
            c.mode,
            Mode::Child {
                start: 5,
                end: 9,
                progress: PathBuf::from("p")
            }
        );
        let e = Options::parse(args("--iterations x --out o")).expect_err("bad");
        assert!(e.contains("--iterations x"), "{e}");
        assert!(Options::parse(args("--seed 1")).is_err());
        assert!(Options::parse(args("--frobnicate 1")).is_err());
    }
}

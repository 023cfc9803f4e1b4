//! The logs given for one run are of one run: two checks that need nothing from the master.
//!
//! - **`run_id`**: when the `run` metadata of two logs both hold a `run_id`
//!   (`towing_log::RunInfo::run_id`, written when not empty), the ids are equal
//!   ([`check_run_ids`]).
//! - **Commands**: the controller logs the command of each sample (`/controller/command` at
//!   the sample time `t`), the plant logs the inputs it used for each step
//!   (`/plant/inputs` at the step's end). In one run the command of a sample is what the
//!   plant applied over the first or the second plant step after `t`: the first under a
//!   Gauss-Seidel master (`masters/closed_loop.py` by default: the command logged at
//!   t = 0 s is the plant's input logged at 0.1 s, bit for bit), the second under a Jacobi
//!   master (`--coupling jacobi`, libcosim, fmpy's SSP runner: the plant applies the
//!   outputs of the controller's previous step). [`CommandCheck`] follows the plant log as
//!   it streams by and refuses the run at the first sample whose command (tug thrusts and
//!   tensions, compared exactly) is in neither step. A command followed by another before
//!   the next plant step is not checked (the plant may never have seen it); the samples
//!   after the plant log's end are not checked.

use std::path::{Path, PathBuf};

use towing_log::topics::{metadata_keys, PlantInputs};

use crate::error::{AnalyzerError, Result};
use crate::read::{CommandCols, Msg, Peek, Sink};

/// The command values compared: tug 1 thrust (3), tug 2 thrust (3), tensions (2).
type Values = [f64; 8];

/// Refuses logs whose `run` metadata hold different `run_id`s (a log without one, or with
/// an empty one, agrees with any).
///
/// # Errors
/// [`AnalyzerError::DifferentRuns`] naming the first two files that differ and their ids.
pub fn check_run_ids(peeks: &[Peek]) -> Result<()> {
    let ids: Vec<(&Path, &str)> = peeks
        .iter()
        .filter_map(|p| {
            let id = p.metadata.get(metadata_keys::RUN_ID)?;
            (!id.is_empty()).then_some((p.path.as_path(), id.as_str()))
        })
        .collect();
    let Some(&(first, first_id)) = ids.first() else {
        return Ok(());
    };
    match ids.iter().find(|(_, id)| *id != first_id) {
        Some(&(other, other_id)) => Err(AnalyzerError::DifferentRuns {
            first: first.to_owned(),
            second: other.to_owned(),
            reason: format!(
                "run_id `{first_id}` in the first, `{other_id}` in the second (the `run` \
                 metadata)"
            ),
        }),
        None => Ok(()),
    }
}

/// A command waiting for the plant steps after it.
#[derive(Debug, Clone, Copy)]
struct Pending {
    /// Index into [`CommandCheck::commands`].
    index: usize,
    /// Distinct plant times seen after the command (1 or 2).
    steps: u8,
}

/// The command check of the module docs, fed the plant log's messages in file order.
#[derive(Debug, Clone)]
pub struct CommandCheck {
    plant: PathBuf,
    controller: PathBuf,
    /// Log time (ns) and values of every command, in time order.
    commands: Vec<(i64, Values)>,
    /// The first command not yet reached by the plant's times.
    next: usize,
    /// Commands waiting for their second plant step (at most two).
    pending: Vec<Pending>,
    /// Latest plant time of an input message so far, ns.
    last_t_ns: Option<i64>,
}

impl CommandCheck {
    /// The check of the commands `cmd` of the controller log `controller` against the
    /// plant log `plant`.
    #[must_use]
    pub fn new(cmd: &CommandCols, plant: &Path, controller: &Path) -> Self {
        let mut commands: Vec<(i64, Values)> = (0..cmd.t_ns.len())
            .map(|i| {
                let v = [
                    cmd.tug1[0][i],
                    cmd.tug1[1][i],
                    cmd.tug1[2][i],
                    cmd.tug2[0][i],
                    cmd.tug2[1][i],
                    cmd.tug2[2][i],
                    cmd.tension[0][i],
                    cmd.tension[1][i],
                ];
                (cmd.t_ns[i], v)
            })
            .collect();
        commands.sort_by_key(|c| c.0);
        CommandCheck {
            plant: plant.to_owned(),
            controller: controller.to_owned(),
            commands,
            next: 0,
            pending: Vec::new(),
            last_t_ns: None,
        }
    }

    /// One `/plant/inputs` message at log time `t_ns`.
    ///
    /// # Errors
    /// [`AnalyzerError::DifferentRuns`] when a command is in neither plant step after it.
    pub fn input(&mut self, t_ns: i64, m: &PlantInputs) -> Result<()> {
        match self.last_t_ns {
            // Out of order: not a step after the pending commands.
            Some(last) if t_ns < last => return Ok(()),
            Some(last) if t_ns == last => {}
            _ => self.new_step(t_ns)?,
        }
        let received = [
            m.tug1[0],
            m.tug1[1],
            m.tug1[2],
            m.tug2[0],
            m.tug2[1],
            m.tug2[2],
            m.tension_cmd[0],
            m.tension_cmd[1],
        ];
        let commands = &self.commands;
        self.pending.retain(|p| commands[p.index].1 != received);
        Ok(())
    }

    /// A plant time later than any before: the pending commands pass a step (a command
    /// past its second is refused); the last command before it starts waiting.
    fn new_step(&mut self, t_ns: i64) -> Result<()> {
        self.finish()?;
        for p in &mut self.pending {
            p.steps += 1;
        }
        let mut last = None;
        while self.next < self.commands.len() && self.commands[self.next].0 < t_ns {
            last = Some(self.next);
            self.next += 1;
        }
        if let Some(index) = last {
            self.pending.push(Pending { index, steps: 1 });
        }
        self.last_t_ns = Some(t_ns);
        Ok(())
    }

    /// At the end of the plant log: a command that saw both its plant steps without a
    /// match is refused.
    ///
    /// # Errors
    /// [`AnalyzerError::DifferentRuns`].
    pub fn finish(&self) -> Result<()> {
        match self.pending.iter().find(|p| p.steps >= 2) {
            Some(p) => Err(self.mismatch(p.index)),
            None => Ok(()),
        }
    }

    fn mismatch(&self, index: usize) -> AnalyzerError {
        let (t_ns, v) = self.commands[index];
        AnalyzerError::DifferentRuns {
            first: self.plant.clone(),
            second: self.controller.clone(),
            reason: format!(
                "the controller's command of t = {:.3} s (tug 1 {:?} N, N, N m; tug 2 {:?}; \
                 tensions {:?} N) is not in the plant's inputs of the two steps after it",
                t_ns as f64 * 1e-9,
                &v[0..3],
                &v[3..6],
                &v[6..8],
            ),
        }
    }
}

/// A [`Sink`] that checks the plant's inputs against the commands ([`CommandCheck`]) and
/// hands every message on to `inner`.
pub struct Checked<'a> {
    /// The sink the messages go to.
    pub inner: &'a mut dyn Sink,
    /// The check.
    pub check: &'a mut CommandCheck,
}

impl std::fmt::Debug for Checked<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Checked")
            .field("check", &self.check)
            .finish_non_exhaustive()
    }
}

impl Sink for Checked<'_> {
    fn put(&mut self, t_ns: i64, msg: Msg) -> Result<()> {
        if let Msg::Inputs(m) = &msg {
            self.check.input(t_ns, m)?;
        }
        self.inner.put(t_ns, msg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: i64 = 100_000_000;

    /// Commands every 10 steps of 0.1 s; the plant applies each `delay` steps after it.
    fn run(delay: i64, samples: i64) -> (CommandCols, Vec<(i64, PlantInputs)>) {
        let value = |k: i64| 0.1 * k as f64 + 0.3;
        let mut cmd = CommandCols::default();
        for s in 0..samples {
            cmd.t_ns.push(s * 10 * H);
            for j in 0..3 {
                cmd.tug1[j].push(value(s) + j as f64);
                cmd.tug2[j].push(-value(s));
            }
            for j in 0..2 {
                cmd.tension[j].push(value(s) * 2.0);
                cmd.desired_angle[j].push(0.0);
            }
        }
        let mut inputs = Vec::new();
        for k in 0..samples * 10 {
            // The last sample at least `delay` steps before.
            let s = (k - delay).div_euclid(10);
            let m = if k < delay {
                PlantInputs {
                    t: 0.0,
                    tug1: [0.0; 3],
                    tug2: [0.0; 3],
                    tension_cmd: [0.0; 2],
                }
            } else {
                let i = usize::try_from(s).unwrap_or(0);
                PlantInputs {
                    t: 0.0,
                    tug1: [cmd.tug1[0][i], cmd.tug1[1][i], cmd.tug1[2][i]],
                    tug2: [cmd.tug2[0][i], cmd.tug2[1][i], cmd.tug2[2][i]],
                    tension_cmd: [cmd.tension[0][i], cmd.tension[1][i]],
                }
            };
            inputs.push((k * H, m));
        }
        (cmd, inputs)
    }

    fn check(cmd: &CommandCols, inputs: &[(i64, PlantInputs)]) -> Result<()> {
        let mut c = CommandCheck::new(cmd, Path::new("p.mcap"), Path::new("c.mcap"));
        for (t, m) in inputs {
            c.input(*t, m)?;
        }
        c.finish()
    }

    #[test]
    fn gauss_seidel_and_jacobi_runs_pass_and_a_three_step_delay_does_not() {
        for delay in [1, 2] {
            let (cmd, inputs) = run(delay, 30);
            check(&cmd, &inputs).expect("one run");
        }
        let (cmd, inputs) = run(3, 30);
        let e = check(&cmd, &inputs).expect_err("not a coupling of ours");
        let text = e.to_string();
        assert!(
            text.starts_with("p.mcap and c.mcap are logs of different runs"),
            "{text}"
        );
        assert!(text.contains("command of t = 0.000 s"), "{text}");
    }

    #[test]
    fn the_first_sample_that_differs_is_named() {
        let (cmd, mut inputs) = run(1, 30);
        // The plant of another run: the inputs differ from sample 12 on.
        for (t, m) in &mut inputs {
            if *t > 120 * H {
                m.tension_cmd[1] += 1e-9;
            }
        }
        let e = check(&cmd, &inputs).expect_err("two runs");
        assert!(e.to_string().contains("command of t = 12.000 s"), "{e}");
        // A plant log that ends before a sample's steps does not judge it.
        // (Jacobi: sample 12's command is the input of 12.2 s; the log ends at 12.1 s.)
        let (cmd, inputs) = run(2, 30);
        check(&cmd, &inputs[..122]).expect("cut after one step of sample 12");
    }

    #[test]
    fn differing_run_ids_are_refused_and_a_missing_one_agrees() {
        let peek = |path: &str, id: Option<&str>| Peek {
            path: PathBuf::from(path),
            bytes: 1,
            unit: None,
            metadata: id
                .map(|id| [(metadata_keys::RUN_ID.to_owned(), id.to_owned())].into())
                .unwrap_or_default(),
            scenario_text: None,
        };
        check_run_ids(&[peek("p", Some("a")), peek("c", Some("a"))]).expect("same");
        check_run_ids(&[peek("p", Some("a")), peek("c", None)]).expect("one missing");
        check_run_ids(&[peek("p", Some("")), peek("c", Some("b"))]).expect("one empty");
        let e = check_run_ids(&[peek("p", Some("a")), peek("c", Some("b"))]).expect_err("two");
        assert_eq!(
            e.to_string(),
            "p and c are logs of different runs: run_id `a` in the first, `b` in the second \
             (the `run` metadata)"
        );
    }
}

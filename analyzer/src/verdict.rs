//! The run verdict: passed, or failed with every reason naming the metric or rule, the
//! target and the time.

use serde::{Deserialize, Serialize};

/// One reason a run fails.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reason {
    /// The metric or rule that failed (`collisions`, `drift`, `rule15_give_way`, ...): the
    /// key of the metric's section in `metrics.json`, or the rule's name.
    pub metric: String,
    /// The target ship or hazard concerned, by its scenario name (`None`: the run).
    pub target: Option<String>,
    /// When it happened (or began), s of simulation time.
    pub t_s: Option<f64>,
    /// What failed, with the measured value and the threshold.
    pub message: String,
}

impl Reason {
    /// A reason about the whole run.
    #[must_use]
    pub fn run(metric: &str, t_s: Option<f64>, message: impl Into<String>) -> Self {
        Reason {
            metric: metric.to_owned(),
            target: None,
            t_s,
            message: message.into(),
        }
    }

    /// A reason about one target ship or hazard.
    #[must_use]
    pub fn target(
        metric: &str,
        target: &str,
        t_s: Option<f64>,
        message: impl Into<String>,
    ) -> Self {
        Reason {
            metric: metric.to_owned(),
            target: Some(target.to_owned()),
            t_s,
            message: message.into(),
        }
    }

    /// One line: `metric [target] at t s: message`.
    #[must_use]
    pub fn line(&self) -> String {
        let mut s = self.metric.clone();
        if let Some(target) = &self.target {
            s.push_str(&format!(" [{target}]"));
        }
        if let Some(t) = self.t_s {
            s.push_str(&format!(" at {t:.1} s"));
        }
        s.push_str(": ");
        s.push_str(&self.message);
        s
    }
}

/// The verdict of a run.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Verdict {
    /// True when no metric gave a reason.
    pub passed: bool,
    /// Every reason, in the metrics' registration order, then by time.
    pub reasons: Vec<Reason>,
}

impl Verdict {
    /// The verdict of these reasons.
    #[must_use]
    pub fn from_reasons(reasons: Vec<Reason>) -> Self {
        Verdict {
            passed: reasons.is_empty(),
            reasons,
        }
    }
}

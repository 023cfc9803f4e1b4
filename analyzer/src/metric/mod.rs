//! The metrics of a run, one module each behind the [`Metric`] trait, and the registry
//! that lists them ([`registry`]: the typed [`Metrics`] of `metrics.json`, the trackers
//! fed while the plant log streams by, the report parts and the verdict).
//!
//! A metric is created with the run's geometry ([`RunContext`]), is handed every plant
//! step in time order ([`Metric::step`], a [`PlantStep`]) and may also read each batch's
//! frames column-wise ([`Metric::batch`]: the fast paths the metrics predating
//! [`PlantStep`] keep, for identical outputs); once the log is read it finishes into its
//! typed section of `metrics.json` ([`Metric::finish`]), which gives its part of the
//! report ([`Metric::report`]) and its reasons to the run's verdict ([`Metric::reasons`]).
//! Adding a metric: its module here, and one line in [`registry`] (docs/architecture.md,
//! "How to add a metric").

use std::collections::BTreeMap;
use std::fmt::Debug;

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::doc::Block;
use crate::error::Result;
use crate::frames::{ControllerFrames, PlantBatch};
use crate::run::{FileSummary, RunConfig};
use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// What a metric knows of the run before the first step.
#[derive(Debug, Clone, Copy)]
pub struct RunContext<'a> {
    /// Sizes and settings from the scenario and the controller's parameters.
    pub config: &'a RunConfig,
    /// Vessel sizes, route, waterway, detection distance.
    pub geometry: &'a RunGeometry,
    /// The thresholds the run is judged by (metrics that measure against one while the
    /// steps go by, e.g. the under-way speed, read it here).
    pub thresholds: &'a Thresholds,
}

/// Facts a metric publishes at a plant step for the metrics registered after it
/// ([`Metric::step`]), reset before every step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepFacts {
    /// The tow is giving way to a target ship that is not yet past and clear (the `rules`
    /// metric; the `progress` metric excuses a stall while it holds).
    pub giving_way: bool,
}

/// What a metric may read when it finishes: the controller's tables (read whole) and
/// what was read of the files.
#[derive(Debug, Clone, Copy)]
pub struct FinishContext<'a> {
    /// Sizes and settings.
    pub config: &'a RunConfig,
    /// The controller's tables.
    pub ctrl: &'a ControllerFrames,
    /// What was read from each file.
    pub files: &'a [FileSummary],
    /// Notes on missing inputs.
    pub notes: &'a [String],
    /// Levels of the messages the units logged (`/plant/log`, `/controller/log`).
    pub unit_levels: &'a [i32],
}

/// Facts a metric publishes for the others before any finishes ([`Metric::share`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Shared {
    /// The assessed COLREGS situation of each target ship by slot (`none` when no
    /// encounter was assessed): the label of the eq. (30) table.
    pub situations: BTreeMap<u32, String>,
}

/// A metric's part of the report, in four places: the head (before the summary), rows
/// of the summary table (`metric`, `value`, `definition`), blocks right after the
/// summary table, and the detail blocks (after the paper's tables). Parts are laid out
/// in registration order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportPart {
    /// Blocks before the summary.
    pub head: Vec<Block>,
    /// Rows of the summary table.
    pub summary: Vec<[String; 3]>,
    /// Blocks right after the summary table.
    pub after_summary: Vec<Block>,
    /// Detail blocks.
    pub details: Vec<Block>,
}

/// One metric: fed the plant steps in time order, finished into its typed section of
/// `metrics.json`, which gives its part of the report and its reasons to the verdict.
pub trait Metric: Sized {
    /// The metric's section of `metrics.json` (under its registry key, or flattened into
    /// the top level with `#[serde(flatten)]`).
    type Section: Serialize + DeserializeOwned + Clone + Debug + PartialEq;

    /// The metric's state before the first step.
    fn new(run: &RunContext<'_>) -> Self;

    /// One plant step (every step of the log, in time order). `facts` holds what the
    /// metrics registered before this one published at this step; a metric may add its
    /// own for those after it.
    fn step(&mut self, _step: &PlantStep<'_>, _facts: &mut StepFacts) {}

    /// One batch of plant steps column-wise, before its steps are handed to
    /// [`Metric::step`]: the fast path of metrics that read the towline, input or
    /// obstacle rows on their own time base.
    ///
    /// # Errors
    /// A frame lacks a column (unexpected).
    fn batch(&mut self, _batch: &PlantBatch) -> Result<()> {
        Ok(())
    }

    /// Publishes facts other metrics' sections cite; called on every metric, in
    /// registration order, before any [`Metric::finish`].
    ///
    /// # Errors
    /// A controller table lacks a column (unexpected).
    fn share(&mut self, _ctx: &FinishContext<'_>, _shared: &mut Shared) -> Result<()> {
        Ok(())
    }

    /// The section, once every step was seen.
    ///
    /// # Errors
    /// A controller table lacks a column (unexpected).
    fn finish(self, ctx: &FinishContext<'_>, shared: &Shared) -> Result<Self::Section>;

    /// The section's part of the report (`metrics`: the whole run, for what the part
    /// cites of it).
    fn report(_section: &Self::Section, _metrics: &Metrics) -> ReportPart {
        ReportPart::default()
    }

    /// Why the run fails by this metric (empty: it passes), in time order.
    fn reasons(_section: &Self::Section, _thresholds: &Thresholds) -> Vec<Reason> {
        Vec::new()
    }
}

/// A row of the summary table.
#[must_use]
pub fn summary_row(metric: &str, value: String, definition: &str) -> [String; 3] {
    [metric.to_owned(), value, definition.to_owned()]
}

/// Declares the registered metrics (invoked once, at the end of this file): `key:
/// module::Type` per metric (its section's key in `metrics.json`, the metric's module,
/// declared here, and its type; `#[serde(flatten)]` puts the section's fields at the top
/// level, as the metrics predating the registry have them). Generates [`Metrics`] (the sections in
/// order, then `config`, `files`, `verdict`, `thresholds`) and [`Trackers`] (one state
/// per metric, fed and finished in order).
macro_rules! define_metrics {
    ($( $(#[$attr:meta])* $key:ident : $module:ident :: $ty:ident ),* $(,)?) => {
        $( pub mod $module; )*
        /// Everything in `metrics.json`: one section per registered metric, the run's
        /// settings and files, the verdict and the thresholds it used.
        #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
        pub struct Metrics {
            $(
                #[doc = concat!("Section of the `", stringify!($key), "` metric.")]
                $(#[$attr])*
                pub $key: <$module::$ty as $crate::metric::Metric>::Section,
            )*
            /// Sizes and settings used.
            pub config: $crate::run::RunConfig,
            /// What was read from each file.
            pub files: Vec<$crate::run::FileSummary>,
            /// The run's verdict: every registered metric's reasons.
            #[serde(default)]
            pub verdict: $crate::verdict::Verdict,
            /// The thresholds of the verdict.
            #[serde(default)]
            pub thresholds: $crate::thresholds::Thresholds,
        }

        /// The state of every registered metric while the plant log streams by.
        #[derive(Debug)]
        pub struct Trackers {
            $( $key: $module::$ty, )*
        }

        impl Trackers {
            /// Every metric's state before the first step.
            #[must_use]
            pub fn new(run: &$crate::metric::RunContext<'_>) -> Self {
                Trackers { $( $key: <$module::$ty as $crate::metric::Metric>::new(run), )* }
            }

            /// One batch column-wise, to every metric.
            ///
            /// # Errors
            /// A frame lacks a column (unexpected).
            pub fn batch(&mut self, b: &$crate::frames::PlantBatch) -> $crate::error::Result<()> {
                $( $crate::metric::Metric::batch(&mut self.$key, b)?; )*
                Ok(())
            }

            /// One plant step, to every metric.
            pub fn step(&mut self, s: &$crate::step::PlantStep<'_>) {
                let mut facts = $crate::metric::StepFacts::default();
                $( $crate::metric::Metric::step(&mut self.$key, s, &mut facts); )*
            }

            /// Every section, and the verdict under `thresholds`.
            ///
            /// # Errors
            /// A controller table lacks a column (unexpected).
            pub fn finish(
                mut self,
                ctx: &$crate::metric::FinishContext<'_>,
                thresholds: &$crate::thresholds::Thresholds,
            ) -> $crate::error::Result<Metrics> {
                let mut shared = $crate::metric::Shared::default();
                $( $crate::metric::Metric::share(&mut self.$key, ctx, &mut shared)?; )*
                let mut m = Metrics {
                    $( $key: $crate::metric::Metric::finish(self.$key, ctx, &shared)?, )*
                    config: ctx.config.clone(),
                    files: ctx.files.to_vec(),
                    verdict: $crate::verdict::Verdict::default(),
                    thresholds: *thresholds,
                };
                m.verdict = $crate::verdict::Verdict::from_reasons(m.reasons(thresholds));
                Ok(m)
            }
        }

        impl Metrics {
            /// Every registered metric's reasons under `thresholds`, in registration
            /// order.
            #[must_use]
            pub fn reasons(
                &self,
                thresholds: &$crate::thresholds::Thresholds,
            ) -> Vec<$crate::verdict::Reason> {
                let mut r = Vec::new();
                $(
                    let mut part = <$module::$ty as $crate::metric::Metric>::reasons(&self.$key, thresholds);
                    // Each metric's by time (stable: equal times keep the metric's order),
                    // reasons without a time last.
                    part.sort_by(|a, b| {
                        a.t_s
                            .unwrap_or(f64::INFINITY)
                            .total_cmp(&b.t_s.unwrap_or(f64::INFINITY))
                    });
                    r.append(&mut part);
                )*
                r
            }

            /// Every registered metric's part of the report, in registration order.
            #[must_use]
            pub fn report_parts(&self) -> Vec<$crate::metric::ReportPart> {
                vec![ $( <$module::$ty as $crate::metric::Metric>::report(&self.$key, self), )* ]
            }
        }
    };
}

// The registered metrics, in the order of their sections in `metrics.json`, of their
// parts of the report and of the verdict's reasons. A new metric: its module file in
// this folder and one line here (docs/architecture.md, "How to add a metric").
define_metrics! {
    #[serde(flatten)] run: run_info::RunInfo,
    #[serde(flatten)] settling: settling::Settling,
    #[serde(flatten)] elongation: elongation::Elongation,
    #[serde(flatten)] distances: distances::Distances,
    #[serde(flatten)] collisions: collisions::Collisions,
    #[serde(flatten)] travel: travel::Travel,
    #[serde(flatten)] colregs: encounters::Encounters,
    #[serde(flatten)] bounds: bounds::BoundChecks,
    #[serde(flatten)] solver: solver::Solver,
    #[serde(flatten)] units: units::UnitLogs,
    rules: rules::RulesTracker,
    progress: progress::ProgressTracker,
    drift: drift::DriftTracker,
    speed: speed::SpeedTracker,
    astern: astern::AsternTracker,
    waterway: waterway::WaterwayTracker,
}

//! The one list of the registered metrics: a metric is its module plus one line here
//! (`key: module::Type,`). The order is the order of the sections in `metrics.json`, of
//! the parts of the report and of the verdict's reasons.

use super::{
    bounds, collisions, define_metrics, distances, elongation, encounters, run_info, settling,
    solver, travel, units,
};

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
}

//! Normalised minimum distance (Du et al. 2022, eq. (30)): per obstacle and vessel of the
//! tow, the least centre distance `min d` and `D = min d / L_*` with `L_*` the vessel's
//! length. Reads the obstacle rows of each batch (the column-wise path). The table's
//! label of a target ship is the COLREGS situation the `colregs` metric assessed
//! ([`Shared::situations`]). No verdict reason (collisions are their own metric).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::{FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::doc::Block;
use crate::error::Result;
use crate::frames::PlantBatch;
use crate::metrics::ArgMin;
use crate::rows::{slot_index, ObstacleRows, VESSELS};

/// Minimum distance of one vessel to one obstacle (Du et al. 2022, eq. (30)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VesselDistance {
    /// Smallest centre distance, m.
    pub min_distance_m: f64,
    /// Own vessel length `L_*`, m.
    pub own_length_m: f64,
    /// `D = min d / L_*`.
    pub normalized: f64,
    /// When, s.
    pub t_s: f64,
}

/// Normalised minimum distances to one obstacle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObstacleDistance {
    /// Obstacle name (scenario).
    pub obstacle: String,
    /// Slot.
    pub slot: u32,
    /// `static` (circle) or `ship` (target ellipse).
    pub kind: String,
    /// `static hazard`, or the target encounter's situation.
    pub encounter: String,
    /// Per vessel: `ship`, `tug1`, `tug2` (absent if never both present).
    pub vessels: BTreeMap<String, VesselDistance>,
}

/// The distances section (top-level key of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DistanceSection {
    /// Eq. (30) per obstacle and vessel.
    pub normalized_min_distance: Vec<ObstacleDistance>,
}

#[derive(Debug, Clone)]
struct Slot {
    slot: u32,
    name: String,
    ship: bool,
    min: [ArgMin; 3],
}

/// The least distance per obstacle slot and vessel so far.
#[derive(Debug, Clone)]
pub struct Distances {
    lengths: [f64; 3],
    slots: Vec<Slot>,
}

impl Metric for Distances {
    type Section = DistanceSection;

    fn new(run: &RunContext<'_>) -> Self {
        Distances {
            lengths: run.geometry.sizes.map(|s| s[0]),
            slots: Vec::new(),
        }
    }

    fn batch(&mut self, b: &PlantBatch) -> Result<()> {
        let Some(rows) = ObstacleRows::of(&b.obstacles)? else {
            return Ok(());
        };
        for i in 0..rows.len() {
            let k = slot_index(
                &mut self.slots,
                rows.slot[i],
                |s| s.slot,
                || Slot {
                    slot: u32::try_from(rows.slot[i]).unwrap_or(0),
                    name: rows.name(i).to_owned(),
                    ship: rows.kind[i] as i64 == 2,
                    min: [ArgMin::default(); 3],
                },
            );
            for (v, d) in rows.dist(i).into_iter().enumerate() {
                if d.is_finite() {
                    self.slots[k].min[v].push(d, rows.t[i]);
                }
            }
        }
        Ok(())
    }

    fn finish(self, _ctx: &FinishContext<'_>, shared: &Shared) -> Result<DistanceSection> {
        let lengths = self.lengths;
        let normalized_min_distance = self
            .slots
            .into_iter()
            .map(|s| {
                let mut vessels = BTreeMap::new();
                for (k, v) in VESSELS.iter().enumerate() {
                    if let Some((m, at)) = s.min[k].value() {
                        vessels.insert(
                            (*v).to_owned(),
                            VesselDistance {
                                min_distance_m: m,
                                own_length_m: lengths[k],
                                normalized: m / lengths[k],
                                t_s: at,
                            },
                        );
                    }
                }
                let encounter = if s.ship {
                    shared
                        .situations
                        .get(&s.slot)
                        .cloned()
                        .unwrap_or_else(|| "none".to_owned())
                } else {
                    "static hazard".to_owned()
                };
                ObstacleDistance {
                    obstacle: s.name,
                    slot: s.slot,
                    kind: if s.ship { "ship" } else { "static" }.to_owned(),
                    encounter,
                    vessels,
                }
            })
            .collect();
        Ok(DistanceSection {
            normalized_min_distance,
        })
    }

    fn report(m: &DistanceSection, _all: &Metrics) -> ReportPart {
        let rows = m
            .normalized_min_distance
            .iter()
            .map(|o| {
                let cell = |v: &str| {
                    o.vessels.get(v).map_or_else(
                        || "-".to_owned(),
                        |d| {
                            format!(
                                "{:.2} ({:.3} m at {:.0} s)",
                                d.normalized, d.min_distance_m, d.t_s
                            )
                        },
                    )
                };
                vec![
                    o.obstacle.clone(),
                    o.kind.clone(),
                    o.encounter.clone(),
                    cell("ship"),
                    cell("tug1"),
                    cell("tug2"),
                ]
            })
            .collect();
        ReportPart {
            details: vec![
                Block::Heading(
                    2,
                    "Normalised minimum distance to every obstacle (eq. (30))".to_owned(),
                ),
                Block::Table {
                    headers: [
                        "obstacle",
                        "kind",
                        "encounter",
                        "D ship",
                        "D tug 1",
                        "D tug 2",
                    ]
                    .map(String::from)
                    .to_vec(),
                    rows,
                },
            ],
            ..ReportPart::default()
        }
    }
}

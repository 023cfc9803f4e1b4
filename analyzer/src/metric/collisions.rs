//! Collisions: hull-overlap events (maximal runs of overlapping samples) of the tow's
//! hull rectangles with the hazard circles, the target ships' ellipses and each other.
//! The vessel pairs are checked on every plant step; the obstacles on their rows of
//! each batch (the column-wise path, the vessels' poses joined as of each row). Every
//! event fails the verdict.

use serde::{Deserialize, Serialize};

use super::{StepFacts, summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::doc::Block;
use crate::error::Result;
use crate::frames::PlantBatch;
use crate::geometry::{convex_overlap, ellipse_polygon, rect_circle_overlap, HullRect};
use crate::metrics::{CollisionEvent, OverlapTracker};
use crate::rows::{slot_index, ObstacleRows, VESSELS};
use crate::step::PlantStep;
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// Pairs of the tow's vessels checked for hull overlaps.
const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// The collisions section (top-level keys of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CollisionSection {
    /// Hull-overlap events (vessel hulls vs hazard circles, target ellipses, each other).
    pub collisions: usize,
    /// The events, by start time.
    pub collision_events: Vec<CollisionEvent>,
}

#[derive(Debug, Clone)]
struct Slot {
    slot: u32,
    /// A target ship (kind of the slot's first row).
    ship: bool,
    overlaps: [OverlapTracker; 3],
}

/// The overlap trackers of the vessel pairs and of every obstacle slot and vessel.
#[derive(Debug, Clone)]
pub struct Collisions {
    sizes: [[f64; 2]; 3],
    pairs: [OverlapTracker; 3],
    slots: Vec<Slot>,
}

/// Hull of vessel `k` at pose `[x, y, psi]` overlaps obstacle `obs` (North, East, course,
/// speed, length, width; `ship`: an ellipse, else a circle of the larger size).
fn overlaps_obstacle(pose: [f64; 3], size: [f64; 2], obs: [f64; 6], ship: bool) -> bool {
    let [x, y, psi] = pose;
    let [ox, oy, opsi, _, olen, owid] = obs;
    if !(x.is_finite() && y.is_finite() && psi.is_finite()) {
        false
    } else if ship {
        let hull = HullRect::new(size[0], size[1]).corners(x, y, psi);
        let e = ellipse_polygon(ox, oy, opsi, olen / 2.0, owid / 2.0);
        convex_overlap(&hull, &e)
    } else {
        rect_circle_overlap(
            (x, y, psi, size[0], size[1]),
            [ox, oy],
            olen.max(owid) / 2.0,
        )
    }
}

impl Metric for Collisions {
    type Section = CollisionSection;

    fn new(run: &RunContext<'_>) -> Self {
        Collisions {
            sizes: run.geometry.sizes,
            pairs: PAIRS.map(|(a, b)| OverlapTracker::new(VESSELS[a], VESSELS[b])),
            slots: Vec::new(),
        }
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        for (p, &(a, b)) in PAIRS.iter().enumerate() {
            let (va, vb) = (&s.vessels[a], &s.vessels[b]);
            let (sa, sb) = (self.sizes[a], self.sizes[b]);
            let ha = HullRect::new(sa[0], sa[1]).corners(va.x, va.y, va.psi);
            let hb = HullRect::new(sb[0], sb[1]).corners(vb.x, vb.y, vb.psi);
            let overlap = ha
                .iter()
                .chain(&hb)
                .all(|p| p[0].is_finite() && p[1].is_finite())
                && convex_overlap(&ha, &hb);
            self.pairs[p].push(s.t, overlap);
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
                    ship: rows.kind[i] as i64 == 2,
                    overlaps: VESSELS.map(|v| OverlapTracker::new(v, rows.name(i))),
                },
            );
            let (obs, poses, ship) = (rows.obs(i), rows.poses(i), self.slots[k].ship);
            for (v, tracker) in self.slots[k].overlaps.iter_mut().enumerate() {
                let overlap = overlaps_obstacle(poses[v], self.sizes[v], obs, ship);
                tracker.push(rows.t[i], overlap);
            }
        }
        Ok(())
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<CollisionSection> {
        let mut events: Vec<CollisionEvent> = Vec::new();
        for s in self.slots {
            for o in s.overlaps {
                events.extend(o.finish());
            }
        }
        for p in self.pairs {
            events.extend(p.finish());
        }
        events.sort_by(|a, b| a.t_start_s.total_cmp(&b.t_start_s));
        Ok(CollisionSection {
            collisions: events.len(),
            collision_events: events,
        })
    }

    fn report(m: &CollisionSection, _all: &Metrics) -> ReportPart {
        let mut details = Vec::new();
        if !m.collision_events.is_empty() {
            details.push(Block::Heading(2, "Collisions (hull overlaps)".to_owned()));
            details.push(Block::Table {
                headers: ["a", "b", "from (s)", "to (s)", "samples"]
                    .map(String::from)
                    .to_vec(),
                rows: m
                    .collision_events
                    .iter()
                    .map(|e| {
                        vec![
                            e.a.clone(),
                            e.b.clone(),
                            format!("{:.1}", e.t_start_s),
                            format!("{:.1}", e.t_end_s),
                            e.samples.to_string(),
                        ]
                    })
                    .collect(),
            });
        }
        ReportPart {
            summary: vec![summary_row(
                "collisions",
                m.collisions.to_string(),
                "hull-overlap events: hull rectangles vs hazard circles, target ellipses and each other",
            )],
            details,
            ..ReportPart::default()
        }
    }

    fn reasons(m: &CollisionSection, _thresholds: &Thresholds) -> Vec<Reason> {
        m.collision_events
            .iter()
            .map(|e| {
                Reason::target(
                    "collisions",
                    &e.b,
                    Some(e.t_start_s),
                    format!(
                        "hull of {} overlaps {} from {:.1} s to {:.1} s ({} samples)",
                        e.a, e.b, e.t_start_s, e.t_end_s, e.samples
                    ),
                )
            })
            .collect()
    }
}

//! From a batch's frames to typed rows: the [`PlantStep`]s every metric is handed, and
//! the column views of the obstacle rows the existing metrics' fast paths read.
//!
//! [`StepBuilder`] turns each batch of plant steps ([`PlantBatch`]) into [`PlantStep`]s in
//! time order: the vessels of the step, the obstacle rows logged since the previous step
//! (one per slot, the last one), and the controller's last sample at or before the step
//! (a cursor over the controller's tables, which are read whole before the plant log).
//! Its state between batches is O(1) plus the current control sample.

use std::borrow::Cow;

use polars::prelude::{DataFrame, StringChunked};

use crate::colregs::Situation;
use crate::error::{AnalyzerError, Result};
use crate::frames::{bools, col, i64s, seconds, ControllerFrames, PlantBatch};
use crate::step::{ControlEncounter, ControlSample, Obstacle, ObstacleKind, PlantStep, Vessel};

/// Names of the tow's vessels, in the order used everywhere (column prefixes, `metrics.json`
/// keys).
pub const VESSELS: [&str; 3] = ["ship", "tug1", "tug2"];

/// The six state columns of one vessel (`{prefix}_x`, ... `{prefix}_r`).
fn vessel_columns<'a>(df: &'a DataFrame, prefix: &str) -> Result<[Cow<'a, [f64]>; 6]> {
    Ok([
        col(df, &format!("{prefix}_x"))?,
        col(df, &format!("{prefix}_y"))?,
        col(df, &format!("{prefix}_psi"))?,
        col(df, &format!("{prefix}_u"))?,
        col(df, &format!("{prefix}_v"))?,
        col(df, &format!("{prefix}_r"))?,
    ])
}

/// The obstacle rows of a batch (long form: one row per slot and log time, the vessels'
/// poses joined as of the row, the centre distances and the guidance's alteration flag).
pub struct ObstacleRows<'a> {
    /// Log time, ns.
    pub t_ns: Vec<i64>,
    /// Time, s.
    pub t: Vec<f64>,
    /// Slot, 1-based.
    pub slot: Vec<i64>,
    /// Kind code (1 circle, 2 ship).
    pub kind: Cow<'a, [f64]>,
    /// North, East, course, speed, length, width of the obstacle.
    obs: [Cow<'a, [f64]>; 6],
    names: &'a StringChunked,
    /// North, East, heading of ship, tug 1, tug 2.
    poses: [[Cow<'a, [f64]>; 3]; 3],
    ship_u: Cow<'a, [f64]>,
    ship_v: Cow<'a, [f64]>,
    /// Centre distance of ship, tug 1, tug 2, m.
    dist: [Cow<'a, [f64]>; 3],
    /// The guidance's reference was altered (as of the row; `None` before any).
    pub altered: Vec<Option<bool>>,
}

impl std::fmt::Debug for ObstacleRows<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObstacleRows")
            .field("rows", &self.len())
            .finish_non_exhaustive()
    }
}

impl<'a> ObstacleRows<'a> {
    /// The rows of `ob` (`None`: no rows).
    ///
    /// # Errors
    /// A column is missing (unexpected).
    pub fn of(ob: &'a DataFrame) -> Result<Option<Self>> {
        if ob.height() == 0 {
            return Ok(None);
        }
        let pose = |v: &str| -> Result<[Cow<'a, [f64]>; 3]> {
            Ok([
                col(ob, &format!("{v}_x"))?,
                col(ob, &format!("{v}_y"))?,
                col(ob, &format!("{v}_psi"))?,
            ])
        };
        Ok(Some(ObstacleRows {
            t_ns: i64s(ob, "t_ns")?,
            t: seconds(ob)?,
            slot: i64s(ob, "slot")?,
            kind: col(ob, "kind")?,
            obs: [
                col(ob, "obs_x")?,
                col(ob, "obs_y")?,
                col(ob, "obs_psi")?,
                col(ob, "obs_speed")?,
                col(ob, "obs_length")?,
                col(ob, "obs_width")?,
            ],
            names: ob
                .column("name")
                .and_then(|c| c.str())
                .map_err(|e| AnalyzerError::frame("obstacles", e))?,
            poses: [pose("ship")?, pose("tug1")?, pose("tug2")?],
            ship_u: col(ob, "ship_u")?,
            ship_v: col(ob, "ship_v")?,
            dist: [col(ob, "d_ship")?, col(ob, "d_tug1")?, col(ob, "d_tug2")?],
            altered: bools(ob, "altered_effective")?,
        }))
    }

    /// Rows.
    #[must_use]
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True without rows.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Name of the obstacle at row `i` (empty if null).
    #[must_use]
    pub fn name(&self, i: usize) -> &str {
        self.names.get(i).unwrap_or("")
    }

    /// North, East, course, speed, length, width at row `i`.
    #[must_use]
    pub fn obs(&self, i: usize) -> [f64; 6] {
        std::array::from_fn(|j| self.obs[j][i])
    }

    /// North, East, heading of ship, tug 1, tug 2 at row `i`.
    #[must_use]
    pub fn poses(&self, i: usize) -> [[f64; 3]; 3] {
        std::array::from_fn(|k| std::array::from_fn(|j| self.poses[k][j][i]))
    }

    /// The ship's speed over ground at row `i`, m/s.
    #[must_use]
    pub fn ship_speed(&self, i: usize) -> f64 {
        self.ship_u[i].hypot(self.ship_v[i])
    }

    /// Centre distances of ship, tug 1, tug 2 at row `i`, m.
    #[must_use]
    pub fn dist(&self, i: usize) -> [f64; 3] {
        std::array::from_fn(|k| self.dist[k][i])
    }

    /// The typed obstacle of row `i`.
    #[must_use]
    pub fn obstacle(&self, i: usize) -> Obstacle {
        let [x, y, course, speed, length, width] = self.obs(i);
        let ship = self.kind[i] as i64 == 2;
        Obstacle {
            slot: u32::try_from(self.slot[i]).unwrap_or(0),
            name: self.name(i).to_owned(),
            kind: if ship {
                ObstacleKind::Ship
            } else {
                ObstacleKind::Static
            },
            x,
            y,
            course: if ship { course } else { 0.0 },
            speed: if ship { speed } else { 0.0 },
            length,
            width,
        }
    }
}

/// The controller's samples (the guidance's references) in time order, as a cursor.
#[derive(Debug, Clone, Default)]
struct ControlCursor {
    t_ns: Vec<i64>,
    t: Vec<f64>,
    altered: Vec<Option<bool>>,
    waypoint: Vec<i64>,
    /// The colregs rows' indices in time order.
    colregs: Vec<usize>,
    /// Next reference row not yet taken.
    next: usize,
    /// Next colregs row (time order) not yet passed.
    next_colregs: usize,
    current: Option<ControlSample>,
}

impl ControlCursor {
    fn new(ctrl: &ControllerFrames) -> Result<Self> {
        let r = &ctrl.reference;
        if r.height() == 0 {
            return Ok(ControlCursor::default());
        }
        Ok(ControlCursor {
            t_ns: i64s(r, "t_ns")?,
            t: seconds(r)?,
            altered: bools(r, "altered_effective")?,
            waypoint: i64s(r, "active_waypoint")?,
            colregs: ctrl.colregs_indices().collect(),
            next: 0,
            next_colregs: 0,
            current: None,
        })
    }

    /// Moves to the last sample at or before `t_ns`.
    fn advance(&mut self, t_ns: i64, ctrl: &ControllerFrames) {
        let mut last = None;
        while self.next < self.t_ns.len() && self.t_ns[self.next] <= t_ns {
            last = Some(self.next);
            self.next += 1;
        }
        let Some(k) = last else { return };
        let at = self.t_ns[k];
        let c = &ctrl.colregs;
        while self.next_colregs < self.colregs.len() && c.t_ns[self.colregs[self.next_colregs]] < at
        {
            self.next_colregs += 1;
        }
        let mut encounters = Vec::new();
        while self.next_colregs < self.colregs.len()
            && c.t_ns[self.colregs[self.next_colregs]] == at
        {
            let i = self.colregs[self.next_colregs];
            encounters.push(ControlEncounter {
                slot: c.slot[i],
                situation: Situation::from_code(c.situation_code[i]),
                role_code: c.role_code[i],
            });
            self.next_colregs += 1;
        }
        encounters.sort_by_key(|e| e.slot);
        self.current = Some(ControlSample {
            t: self.t[k],
            altered: self.altered[k] == Some(true),
            active_waypoint: u32::try_from(self.waypoint[k]).unwrap_or(0),
            encounters,
        });
    }
}

/// Builds the [`PlantStep`]s of each batch, in time order (see the module docs).
#[derive(Debug, Clone)]
pub struct StepBuilder {
    control: ControlCursor,
    /// Log time of the last step handed out, ns.
    last_t_ns: i64,
}

impl StepBuilder {
    /// A builder for a run with the controller's frames `ctrl`.
    ///
    /// # Errors
    /// The reference table lacks a column (unexpected).
    pub fn new(ctrl: &ControllerFrames) -> Result<Self> {
        Ok(StepBuilder {
            control: ControlCursor::new(ctrl)?,
            last_t_ns: i64::MIN,
        })
    }

    /// Hands every plant step of `b` to `f`, in time order. A step's obstacles are the
    /// rows logged after the previous step up to it (the last per slot, in slot order).
    ///
    /// # Errors
    /// A frame lacks a column (unexpected).
    pub fn for_each(
        &mut self,
        b: &PlantBatch,
        ctrl: &ControllerFrames,
        mut f: impl FnMut(&PlantStep<'_>),
    ) -> Result<()> {
        let df = &b.vessels;
        let t_ns = i64s(df, "t_ns")?;
        let t = seconds(df)?;
        let v = [
            vessel_columns(df, "ship")?,
            vessel_columns(df, "tug1")?,
            vessel_columns(df, "tug2")?,
        ];
        let rows = ObstacleRows::of(&b.obstacles)?;
        let mut next_row = 0;
        let mut obstacles: Vec<Obstacle> = Vec::new();
        for (i, &ti) in t.iter().enumerate() {
            obstacles.clear();
            if let Some(rows) = &rows {
                while next_row < rows.len() && rows.t_ns[next_row] <= t_ns[i] {
                    if rows.t_ns[next_row] > self.last_t_ns {
                        let o = rows.obstacle(next_row);
                        match obstacles.iter_mut().find(|p| p.slot == o.slot) {
                            Some(p) => *p = o,
                            None => obstacles.push(o),
                        }
                    }
                    next_row += 1;
                }
                obstacles.sort_by_key(|o| o.slot);
            }
            self.control.advance(t_ns[i], ctrl);
            self.last_t_ns = t_ns[i];
            let vessels = std::array::from_fn(|k| Vessel {
                x: v[k][0][i],
                y: v[k][1][i],
                psi: v[k][2][i],
                u: v[k][3][i],
                v: v[k][4][i],
                r: v[k][5][i],
            });
            f(&PlantStep {
                t: ti,
                vessels,
                obstacles: &obstacles,
                control: self.control.current.as_ref(),
            });
        }
        Ok(())
    }
}

/// The index in `slots` of the state of obstacle `slot`, created by `make` at its first
/// row (slots keep the order of their first rows).
pub fn slot_index<T>(
    slots: &mut Vec<T>,
    slot: i64,
    slot_of: impl Fn(&T) -> u32,
    make: impl FnOnce() -> T,
) -> usize {
    match slots.iter().position(|s| i64::from(slot_of(s)) == slot) {
        Some(i) => i,
        None => {
            slots.push(make());
            slots.len() - 1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::{build_controller, build_plant_batch, Carry};
    use crate::synth::{SynthObstacle, SynthRun, SynthShape};

    /// Every plant step once, in time order, with the vessels of its row, the obstacles
    /// active at it (slot order) and the controller's latest sample at or before it.
    #[test]
    fn steps_carry_the_vessels_the_active_obstacles_and_the_last_control_sample() {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut run = SynthRun::paper(400);
        run.scene = false;
        run.obstacles = vec![
            SynthObstacle {
                name: "late".to_owned(),
                pos: [20.0, 5.0],
                shape: SynthShape::Ship(1.48, 0.48, 180.0, 0.1),
                active_from: 20.0,
            },
            SynthObstacle {
                name: "rock".to_owned(),
                pos: [10.0, 3.0],
                shape: SynthShape::Circle(1.0),
                active_from: 0.0,
            },
        ];
        let (plant, controller) = (dir.path().join("p.mcap"), dir.path().join("c.mcap"));
        run.write(&plant, &controller).expect("logs");
        let bar = indicatif::ProgressBar::hidden();
        let p = crate::read::read_log(&plant, &bar).expect("plant");
        let c = crate::read::read_log(&controller, &bar).expect("controller");
        let ctrl = build_controller(c.controller, &run.route).expect("controller frames");
        let control_t = seconds(&ctrl.reference).expect("t");
        let b = build_plant_batch(p.plant, &mut Carry::default(), &ctrl).expect("batch");
        let ship_x = col(&b.vessels, "ship_x").expect("x").into_owned();
        let mut builder = StepBuilder::new(&ctrl).expect("builder");
        let mut seen: Vec<(f64, f64, Vec<String>, Option<f64>)> = Vec::new();
        builder
            .for_each(&b, &ctrl, |s| {
                let names = s.obstacles.iter().map(|o| o.name.clone()).collect();
                seen.push((s.t, s.vessels[0].x, names, s.control.map(|c| c.t)));
            })
            .expect("steps");
        assert_eq!(seen.len(), ship_x.len());
        assert!(seen.windows(2).all(|w| w[0].0 < w[1].0), "time order");
        for (i, (t, x, names, ct)) in seen.iter().enumerate() {
            assert_eq!(x.to_bits(), ship_x[i].to_bits());
            // Slot order: "late" is slot 1, "rock" slot 2; "late" from its activation on.
            let expect: Vec<&str> = if *t >= 20.0 - 1e-9 {
                vec!["late", "rock"]
            } else {
                vec!["rock"]
            };
            assert_eq!(names, &expect, "t = {t}");
            let latest = control_t.iter().copied().rfind(|c| c <= t);
            assert_eq!(*ct, latest, "t = {t}");
        }
    }
}

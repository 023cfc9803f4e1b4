//! From a run to `metrics.json` and the data of the plots.
//!
//! The plant log is analysed while it streams by ([`crate::stream`]): each batch of plant
//! steps ([`PlantBatch`]) updates a [`PlantAccumulator`], which keeps per metric the O(1)
//! state of its incremental form (`crate::metrics`, [`EncounterTracker`]) and the plot
//! series at a bounded resolution (`crate::decimate`); no per-step series is kept, so the
//! memory does not grow with the log. Every metric is computed on every plant step.
//! [`analyze_run`] puts it together with the controller's metrics (from the controller
//! log, read whole: per-sample statistics such as percentiles need all samples).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::DataFrame;
use serde::Serialize;

use crate::colregs::{
    ControllerView, EncounterReport, EncounterSample, EncounterTracker, ScoringParams,
};
use crate::decimate::{Decimator, PathDecimator, StrideBuffer};
use crate::error::{AnalyzerError, Result};
use crate::frames::{bools, col, f64s, i64s, seconds, ControllerFrames, PlantBatch};
use crate::geometry::{convex_overlap, ellipse_polygon, hull_rect, rect_circle_overlap, wrap};
use crate::metrics::{
    check_bounds, rates, settled, stats, ArgMax, ArgMin, BoundReport, CollisionEvent,
    CommandSeries, InputBoundCheck, OverlapTracker, SettleCriteria, SettlingTracker, Stats,
    TravelTracker, VesselTrack,
};
use crate::run::{Bounds, FileSummary, Run, RunConfig};
use crate::stream::{PlantStream, StreamOptions};

/// Names of the tow's vessels, in the order used everywhere.
pub const VESSELS: [&str; 3] = ["ship", "tug1", "tug2"];

/// A code with its name (architecture, scheme).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Code {
    /// The controller's code.
    pub code: i32,
    /// Its name (`distributed`, `centralized`; `I`, `II`, `III`).
    pub name: String,
}

/// Name of an architecture code.
#[must_use]
pub fn architecture_name(code: i32) -> String {
    match code {
        1 => "distributed".to_owned(),
        2 => "centralized".to_owned(),
        c => format!("architecture {c}"),
    }
}

/// Name of an avoidance-scheme code.
#[must_use]
pub fn scheme_name(code: i32) -> String {
    match code {
        1 => "I".to_owned(),
        2 => "II".to_owned(),
        3 => "III".to_owned(),
        c => format!("scheme {c}"),
    }
}

/// Minimum distance of one vessel to one obstacle (Du et al. 2022, eq. (30)).
#[derive(Debug, Clone, PartialEq, Serialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize)]
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

/// Truncated file and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Truncation {
    /// The file.
    pub file: String,
    /// The reader's reason.
    pub reason: String,
}

/// Ship pose at the end of the log relative to the destination.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FinalState {
    /// Time, s.
    pub t_s: f64,
    /// Distance to the destination, m.
    pub distance_to_destination_m: f64,
    /// Heading error, deg.
    pub heading_error_deg: f64,
    /// Speed over ground, m/s.
    pub speed_m_s: f64,
}

/// Bound checks with the bounds used.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundSection {
    /// The bounds.
    pub bounds: Bounds,
    /// The violations.
    #[serde(flatten)]
    pub report: BoundReport,
}

/// Everything in `metrics.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Metrics {
    /// Version of the analyzer.
    pub analyzer_version: String,
    /// Scenario name.
    pub scenario: String,
    /// Where the scenario came from.
    pub scenario_source: String,
    /// Control architecture (controller log).
    pub architecture: Option<Code>,
    /// Avoidance scheme (controller log).
    pub scheme: Option<Code>,
    /// True when any log ended early.
    pub truncated: bool,
    /// Which files ended early, and why.
    pub truncated_files: Vec<Truncation>,
    /// Notes on missing inputs.
    pub notes: Vec<String>,
    /// First plant time, s.
    pub start_s: f64,
    /// Last plant time, s.
    pub end_s: f64,
    /// Plant steps read.
    pub plant_steps: usize,
    /// Control samples read.
    pub control_samples: usize,
    /// Settling time (Du et al. 2022, section 4.2.3), s; null if never settled.
    pub settling_time_s: Option<f64>,
    /// The settling criteria used.
    pub settling_criteria: SettleCriteria,
    /// The ship at the end of the log.
    pub final_state: Option<FinalState>,
    /// Largest `|l - l_tow| / l_tow` of towline 1 and 2, fractions.
    pub max_towline_elongation_error: [Option<f64>; 2],
    /// When each maximum happened, s.
    pub max_towline_elongation_error_t_s: [Option<f64>; 2],
    /// Desired towline lengths, m.
    pub towline_desired_length_m: [f64; 2],
    /// Eq. (30) per obstacle and vessel.
    pub normalized_min_distance: Vec<ObstacleDistance>,
    /// Hull-overlap events (vessel hulls vs hazard circles, target ellipses, each other).
    pub collisions: usize,
    /// The events.
    pub collision_events: Vec<CollisionEvent>,
    /// Length of the ship's track, m.
    pub ship_travel_m: f64,
    /// One entry per target ship.
    pub colregs: Vec<EncounterReport>,
    /// Commands outside their bounds.
    pub bound_violations: BoundSection,
    /// Wall time per control sample, ms.
    pub sample_time_ms: Option<Stats>,
    /// ADMM iterations per sample (centralized: SCP loops).
    pub admm_iterations: Option<Stats>,
    /// Fraction of samples whose ADMM met the stopping rule.
    pub admm_converged_fraction: Option<f64>,
    /// Samples whose plan fell back to the shifted previous plan.
    pub fallbacks: u64,
    /// Fallback reasons and their counts.
    pub fallback_reasons: BTreeMap<String, u64>,
    /// Warnings (level 3) the units logged.
    pub unit_warnings: usize,
    /// Errors (level >= 4) the units logged.
    pub unit_errors: usize,
    /// Sizes and settings used.
    pub config: RunConfig,
    /// What was read from each file.
    pub files: Vec<FileSummary>,
}

/// One obstacle's track for the plots.
#[derive(Debug, Clone, Default)]
pub struct ObstacleTrack {
    /// Name.
    pub name: String,
    /// 1 circle, 2 ship.
    pub kind: i32,
    /// Times, s (every row up to `StreamOptions::track_rows`, then at a stride).
    pub t: Vec<f64>,
    /// North, m.
    pub x: Vec<f64>,
    /// East, m.
    pub y: Vec<f64>,
    /// Course, rad.
    pub psi: Vec<f64>,
    /// Centre distance of the ship at these rows, m.
    pub ship_distance: Vec<f64>,
    /// Major axis (or diameter), m.
    pub length: f64,
    /// Minor axis (or diameter), m.
    pub width: f64,
    /// Centre distance of ship, tug 1, tug 2 over time `(t s, d m)`, extremes kept.
    pub distance: [Vec<(f64, f64)>; 3],
    /// Safe distance of ship, tug 1, tug 2 on the centre-distance scale, m
    /// (`docs/colregs.md` section 1: circles `L + R + d_S0`, ships `L + a + d_S0`).
    pub safe: [f64; 3],
}

/// Commanded towing angles and tensions (controller) `(t s, value)`, extremes kept.
#[derive(Debug, Clone, Default)]
pub struct CommandPlot {
    /// Towing angles of line 1 and 2, deg.
    pub angle_deg: [Vec<(f64, f64)>; 2],
    /// Tensions of line 1 and 2, N.
    pub tension: [Vec<(f64, f64)>; 2],
    /// Rates of the towing angles between consecutive samples, deg/s.
    pub angle_rate_deg: [Vec<(f64, f64)>; 2],
    /// Rates of the tensions between consecutive samples, N/s.
    pub tension_rate: [Vec<(f64, f64)>; 2],
}

/// The plant's actual towing angles and tensions `(t s, value)`, extremes kept.
#[derive(Debug, Clone, Default)]
pub struct ActualTowing {
    /// Towing angles of line 1 and 2, deg.
    pub angle_deg: [Vec<(f64, f64)>; 2],
    /// Tensions of line 1 and 2, N.
    pub tension: [Vec<(f64, f64)>; 2],
}

/// The tow's poses at kept plant steps (for the hull outlines of the map).
#[derive(Debug, Clone, Default)]
pub struct PoseSamples {
    /// Times, s (every step up to `StreamOptions::track_rows`, then at a stride; the
    /// last step always).
    pub t: Vec<f64>,
    /// North (m), East (m), heading (rad) of ship, tug 1, tug 2 at these times.
    pub pose: Vec<[[f64; 3]; 3]>,
}

/// Solver series `(t s, value)`, extremes kept.
#[derive(Debug, Clone, Default)]
pub struct SolverPlot {
    /// Iterations.
    pub iterations: Vec<(f64, f64)>,
    /// `log10` of the primal residuals of tug 1 and 2.
    pub log_r_pri: [Vec<(f64, f64)>; 2],
    /// `log10` of the dual residuals of tug 1 and 2.
    pub log_r_dual: [Vec<(f64, f64)>; 2],
    /// Histogram of the compute time per sample.
    pub compute_time: Histogram,
}

/// A histogram of equal bins from 0.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Histogram {
    /// Counts per bin.
    pub counts: Vec<u32>,
    /// Upper end of the last bin.
    pub hi: f64,
    /// Values counted.
    pub samples: usize,
}

impl Histogram {
    /// `bins` bins from 0 to 1.02 times the largest finite value of `values` (at least
    /// 1e-3); the largest value falls in the last bin.
    #[must_use]
    pub fn new(values: &[f64], bins: usize) -> Self {
        let bins = bins.max(1);
        let finite = || values.iter().copied().filter(|v| v.is_finite());
        let hi = finite().fold(0.0f64, f64::max).max(1e-3) * 1.02;
        let width = hi / bins as f64;
        let mut counts = vec![0u32; bins];
        let mut samples = 0;
        for v in finite() {
            let k = ((v / width) as usize).min(bins - 1);
            counts[k] += 1;
            samples += 1;
        }
        Histogram {
            counts,
            hi,
            samples,
        }
    }
}

/// Everything the plots draw; the plant's series at a bounded resolution.
#[derive(Debug, Clone, Default)]
pub struct PlotData {
    /// Title line (scenario, architecture, scheme).
    pub title: String,
    /// First and last plant time, s.
    pub t_span: Option<(f64, f64)>,
    /// Per vessel (ship, tug 1, tug 2): `(t s, value)` of x (m), y (m), psi (deg,
    /// unwrapped), u (m/s), v (m/s), r (deg/s); extremes kept.
    pub states: [[Vec<(f64, f64)>; 6]; 3],
    /// Per vessel: the track `(East m, North m)` in time order, thinned by distance
    /// beyond `StreamOptions::plot_points` (`crate::decimate::PathDecimator`).
    pub tracks: [Vec<(f64, f64)>; 3],
    /// Poses for the hull outlines.
    pub poses: PoseSamples,
    /// Length and width of ship, tug 1, tug 2, m.
    pub sizes: [[f64; 2]; 3],
    /// Obstacles.
    pub obstacles: Vec<ObstacleTrack>,
    /// Route points (North, East, heading).
    pub route: Vec<[f64; 3]>,
    /// Distinct altered waypoints the guidance used (North, East, heading).
    pub altered_waypoints: Vec<[f64; 3]>,
    /// Commanded towing angles and tensions (controller).
    pub command: Option<CommandPlot>,
    /// Actual towing angles and tensions (plant).
    pub actual: ActualTowing,
    /// Solver.
    pub solver: Option<SolverPlot>,
    /// Bounds.
    pub bounds: Bounds,
}

/// The result of the analysis.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// `metrics.json`.
    pub metrics: Metrics,
    /// Plot data.
    pub plot: PlotData,
    /// The controller's tables.
    pub controller: ControllerFrames,
    /// Tables written while the plant log streamed (`timeseries`, `obstacles`; CSV and
    /// Parquet), empty when no table directory was given.
    pub tables: Vec<PathBuf>,
}

fn track<'a>(df: &'a DataFrame, prefix: &str) -> Result<VesselTrack<'a>> {
    Ok(VesselTrack {
        x: col(df, &format!("{prefix}_x"))?,
        y: col(df, &format!("{prefix}_y"))?,
        psi: col(df, &format!("{prefix}_psi"))?,
        u: col(df, &format!("{prefix}_u"))?,
        v: col(df, &format!("{prefix}_v"))?,
        r: col(df, &format!("{prefix}_r"))?,
    })
}

/// What is kept of one obstacle slot while the plant log streams by.
#[derive(Debug, Clone)]
struct SlotState {
    slot: u32,
    name: String,
    kind: i64,
    length: f64,
    width: f64,
    /// Target ships: the encounter over the rows near the ship.
    encounter: Option<EncounterTracker>,
    /// Rows within the encounter window (twice the detection range).
    near: usize,
    /// The closest row (its sample if usable), for a target never near.
    closest: Option<(f64, Option<EncounterSample>)>,
    /// Eq. (30): least centre distance per vessel.
    min: [ArgMin; 3],
    /// Hull overlaps per vessel.
    overlaps: [OverlapTracker; 3],
    /// Rows `t, x, y, psi, d_ship` for the map.
    track: StrideBuffer<5>,
    /// Distance per vessel over time.
    distance: [Decimator; 3],
}

/// One obstacle row with the vessels' poses joined.
struct ObstacleRow {
    t: f64,
    /// North, East, course, speed, length, width.
    obs: [f64; 6],
    /// North, East, heading of ship, tug 1, tug 2.
    poses: [[f64; 3]; 3],
    ship_speed: f64,
    dist: [f64; 3],
    altered: Option<bool>,
}

impl SlotState {
    fn push(&mut self, row: &ObstacleRow, window: f64, sizes: &[[f64; 2]; 3]) {
        let [ox, oy, opsi, ospeed, olen, owid] = row.obs;
        let t = row.t;
        if let Some(tracker) = &mut self.encounter {
            // Only the rows near the ship matter (detection, action, CPA): those within
            // twice the detection range, or the closest row if none.
            let p = row.poses[0];
            let sample = EncounterSample {
                t,
                own: [p[0], p[1], p[2], row.ship_speed],
                target: [ox, oy, opsi, ospeed],
                altered: row.altered,
                tow_range: row.dist[0].min(row.dist[1]).min(row.dist[2]),
            };
            let usable = sample
                .own
                .iter()
                .chain(&sample.target)
                .all(|v| v.is_finite());
            let d0 = row.dist[0];
            if d0 < window {
                self.near += 1;
                if usable {
                    tracker.push(sample);
                }
            }
            if d0.is_finite() && self.closest.is_none_or(|(c, _)| d0 < c) {
                self.closest = Some((d0, usable.then_some(sample)));
            }
        }
        for (k, &[length, width]) in sizes.iter().enumerate() {
            let d = row.dist[k];
            if d.is_finite() {
                self.min[k].push(d, t);
            }
            // Hull overlap of vessel k with this obstacle.
            let [x, y, psi] = row.poses[k];
            let overlap = if !(x.is_finite() && y.is_finite() && psi.is_finite()) {
                false
            } else if self.kind == 2 {
                let hull = hull_rect(x, y, psi, length, width);
                let e = ellipse_polygon(ox, oy, opsi, olen / 2.0, owid / 2.0);
                convex_overlap(&hull, &e)
            } else {
                rect_circle_overlap((x, y, psi, length, width), [ox, oy], olen.max(owid) / 2.0)
            };
            self.overlaps[k].push(t, overlap);
            self.distance[k].push(t, d);
        }
        self.track.push([t, ox, oy, opsi, row.dist[0]]);
    }
}

/// Everything kept of the plant log while it streams by: O(1) per metric, the plot series
/// at a bounded resolution, a little per obstacle slot.
#[derive(Debug, Clone)]
pub struct PlantAccumulator {
    config: RunConfig,
    opts: StreamOptions,
    criteria: SettleCriteria,
    sizes: [[f64; 2]; 3],
    steps: usize,
    t_span: Option<(f64, f64)>,
    settle: SettlingTracker,
    /// The last plant step: t, ship x, y, psi, u, v.
    last: Option<[f64; 6]>,
    travel: TravelTracker,
    pairs: [OverlapTracker; 3],
    elongation: [ArgMax; 2],
    inputs: InputBoundCheck,
    slots: Vec<SlotState>,
    states: [[Decimator; 6]; 3],
    tracks: [PathDecimator; 3],
    unwrap: [Option<f64>; 3],
    poses: StrideBuffer<10>,
    actual_angle: [Decimator; 2],
    actual_tension: [Decimator; 2],
}

/// The points of the line `(t, v)` kept by a [`Decimator`] of `capacity` points.
fn line(capacity: usize, t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    let mut d = Decimator::new(capacity);
    for (&a, &b) in t.iter().zip(v) {
        d.push(a, b);
    }
    d.points()
}

/// Pairs of the tow's vessels checked for hull overlaps.
const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

impl PlantAccumulator {
    /// An empty accumulator for a run with `config`.
    #[must_use]
    pub fn new(config: &RunConfig, opts: &StreamOptions) -> Self {
        let dec = || Decimator::new(opts.plot_points);
        PlantAccumulator {
            config: config.clone(),
            opts: *opts,
            criteria: SettleCriteria::paper(config.ship_size[0]),
            sizes: [config.ship_size, config.tug1_size, config.tug2_size],
            steps: 0,
            t_span: None,
            settle: SettlingTracker::default(),
            last: None,
            travel: TravelTracker::default(),
            pairs: PAIRS.map(|(a, b)| OverlapTracker::new(VESSELS[a], VESSELS[b])),
            elongation: [ArgMax::default(); 2],
            inputs: InputBoundCheck::new(&config.bounds),
            slots: Vec::new(),
            states: std::array::from_fn(|_| std::array::from_fn(|_| dec())),
            tracks: std::array::from_fn(|_| PathDecimator::new(opts.plot_points)),
            unwrap: [None; 3],
            poses: StrideBuffer::new(opts.track_rows),
            actual_angle: std::array::from_fn(|_| dec()),
            actual_tension: std::array::from_fn(|_| dec()),
        }
    }

    /// Plant steps seen.
    #[must_use]
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Points held by the plot series now (bounded by the options, whatever the log's
    /// length).
    #[must_use]
    pub fn plot_points(&self) -> usize {
        let lines: usize = self
            .states
            .iter()
            .flatten()
            .chain(&self.actual_angle)
            .chain(&self.actual_tension)
            .chain(self.slots.iter().flat_map(|s| &s.distance))
            .map(Decimator::len)
            .sum::<usize>()
            + self.tracks.iter().map(|t| t.points().len()).sum::<usize>();
        let rows = self.poses.rows().len()
            + self
                .slots
                .iter()
                .map(|s| s.track.rows().len())
                .sum::<usize>();
        lines + rows
    }

    /// Adds one batch of plant steps.
    ///
    /// # Errors
    /// A frame lacks a column it should have (unexpected).
    pub fn update(&mut self, b: &PlantBatch) -> Result<()> {
        self.update_vessels(&b.vessels)?;
        self.update_towlines(&b.towlines)?;
        if b.inputs.height() > 0 {
            let c = &b.inputs;
            let t = seconds(c)?;
            let cols = [
                "in_tug1_X",
                "in_tug1_Y",
                "in_tug1_N",
                "in_tug2_X",
                "in_tug2_Y",
                "in_tug2_N",
            ]
            .iter()
            .map(|n| f64s(c, n))
            .collect::<Result<Vec<_>>>()?;
            for i in 0..t.len() {
                self.inputs.push(
                    t[i],
                    [
                        [cols[0][i], cols[1][i], cols[2][i]],
                        [cols[3][i], cols[4][i], cols[5][i]],
                    ],
                );
            }
        }
        self.update_obstacles(&b.obstacles)
    }

    fn update_vessels(&mut self, df: &DataFrame) -> Result<()> {
        let t = seconds(df)?;
        let v = [track(df, "ship")?, track(df, "tug1")?, track(df, "tug2")?];
        let dest = self.config.destination;
        let sizes = self.sizes;
        for (i, &ti) in t.iter().enumerate() {
            self.steps += 1;
            self.t_span = Some(self.t_span.map_or((ti, ti), |(a, _)| (a, ti)));
            let s = &v[0];
            let ship = [s.x[i], s.y[i], s.psi[i], s.u[i], s.v[i], s.r[i]];
            self.settle.push(ti, settled(ship, dest, self.criteria));
            self.last = Some([ti, ship[0], ship[1], ship[2], ship[3], ship[4]]);
            self.travel.push(ship[0], ship[1]);
            for (p, &(a, b)) in PAIRS.iter().enumerate() {
                let (va, vb) = (&v[a], &v[b]);
                let ha = hull_rect(va.x[i], va.y[i], va.psi[i], sizes[a][0], sizes[a][1]);
                let hb = hull_rect(vb.x[i], vb.y[i], vb.psi[i], sizes[b][0], sizes[b][1]);
                let overlap = ha
                    .iter()
                    .chain(&hb)
                    .all(|p| p[0].is_finite() && p[1].is_finite())
                    && convex_overlap(&ha, &hb);
                self.pairs[p].push(ti, overlap);
            }
            // Plot series (Fig. 12 style): heading unwrapped (no jump at +-180 deg when
            // heading South), yaw rate in deg/s.
            let mut pose = [0.0; 10];
            pose[0] = ti;
            for (k, vk) in v.iter().enumerate() {
                let psi = vk.psi[i];
                let unwrapped = match self.unwrap[k] {
                    Some(p) if psi.is_finite() => p + wrap(psi - p),
                    _ => psi,
                };
                if unwrapped.is_finite() {
                    self.unwrap[k] = Some(unwrapped);
                }
                let values = [
                    vk.x[i],
                    vk.y[i],
                    unwrapped.to_degrees(),
                    vk.u[i],
                    vk.v[i],
                    vk.r[i].to_degrees(),
                ];
                for (j, value) in values.into_iter().enumerate() {
                    self.states[k][j].push(ti, value);
                }
                self.tracks[k].push(vk.y[i], vk.x[i]);
                pose[1 + 3 * k] = vk.x[i];
                pose[2 + 3 * k] = vk.y[i];
                pose[3 + 3 * k] = psi;
            }
            self.poses.push(pose);
        }
        Ok(())
    }

    fn update_towlines(&mut self, df: &DataFrame) -> Result<()> {
        let t = seconds(df)?;
        for k in 0..2 {
            let len = col(df, &format!("line{}_length", k + 1))?;
            let angle = col(df, &format!("line{}_angle", k + 1))?;
            let tension = col(df, &format!("line{}_tension", k + 1))?;
            let desired = self.config.towline_desired_length[k];
            for i in 0..t.len() {
                // Du et al. (2022), section 4.2.3: |l - l_tow| / l_tow.
                if len[i].is_finite() {
                    self.elongation[k].push((len[i] - desired).abs() / desired, t[i]);
                }
                self.actual_angle[k].push(t[i], angle[i].to_degrees());
                self.actual_tension[k].push(t[i], tension[i]);
            }
        }
        Ok(())
    }

    fn update_obstacles(&mut self, ob: &DataFrame) -> Result<()> {
        if ob.height() == 0 {
            return Ok(());
        }
        let t = seconds(ob)?;
        let slot = i64s(ob, "slot")?;
        let kind = col(ob, "kind")?;
        let obs = [
            col(ob, "obs_x")?,
            col(ob, "obs_y")?,
            col(ob, "obs_psi")?,
            col(ob, "obs_speed")?,
            col(ob, "obs_length")?,
            col(ob, "obs_width")?,
        ];
        let name_col = ob
            .column("name")
            .and_then(|c| c.str())
            .map_err(|e| AnalyzerError::frame("obstacles", e))?;
        let poses = VESSELS
            .iter()
            .map(|v| -> Result<[_; 3]> {
                Ok([
                    col(ob, &format!("{v}_x"))?,
                    col(ob, &format!("{v}_y"))?,
                    col(ob, &format!("{v}_psi"))?,
                ])
            })
            .collect::<Result<Vec<_>>>()?;
        let ship_u = col(ob, "ship_u")?;
        let ship_v = col(ob, "ship_v")?;
        let dist = VESSELS
            .iter()
            .map(|v| col(ob, &format!("d_{v}")))
            .collect::<Result<Vec<_>>>()?;
        let altered = bools(ob, "altered_effective")?;
        let window = 2.0 * self.config.detection_distance_m;
        for i in 0..t.len() {
            let s = slot[i];
            let idx = match self.slots.iter().position(|st| i64::from(st.slot) == s) {
                Some(idx) => idx,
                None => {
                    let st = self.new_slot(s, name_col.get(i).unwrap_or(""), kind[i], &obs, i);
                    self.slots.push(st);
                    self.slots.len() - 1
                }
            };
            let row = ObstacleRow {
                t: t[i],
                obs: std::array::from_fn(|j| obs[j][i]),
                poses: std::array::from_fn(|k| std::array::from_fn(|j| poses[k][j][i])),
                ship_speed: ship_u[i].hypot(ship_v[i]),
                dist: std::array::from_fn(|k| dist[k][i]),
                altered: altered[i],
            };
            self.slots[idx].push(&row, window, &self.sizes);
        }
        Ok(())
    }

    /// The state of a slot first seen at row `i`: name, kind and size from that row.
    fn new_slot(
        &self,
        slot: i64,
        name: &str,
        kind: f64,
        obs: &[std::borrow::Cow<'_, [f64]>; 6],
        i: usize,
    ) -> SlotState {
        let kind = kind as i64;
        let (length, width) = (obs[4][i], obs[5][i]);
        let encounter = (kind == 2).then(|| {
            EncounterTracker::new(ScoringParams::model_scale(
                self.config.ship_size[0],
                length,
                self.config.detection_distance_m,
                self.config.safety_buffer_m,
            ))
        });
        let name_owned = name.to_owned();
        SlotState {
            slot: u32::try_from(slot).unwrap_or(0),
            overlaps: VESSELS.map(|v| OverlapTracker::new(v, &name_owned)),
            name: name_owned,
            kind,
            length,
            width,
            encounter,
            near: 0,
            closest: None,
            min: [ArgMin::default(); 3],
            track: StrideBuffer::new(self.opts.track_rows),
            distance: std::array::from_fn(|_| Decimator::new(self.opts.plot_points)),
        }
    }

    /// The metrics and the plot data of the run.
    ///
    /// # Errors
    /// A frame lacks a column it should have (unexpected).
    #[allow(clippy::too_many_lines)]
    pub fn finish(
        self,
        ctrl: ControllerFrames,
        files: Vec<FileSummary>,
        notes: Vec<String>,
        unit_levels: &[i32],
    ) -> Result<Analysis> {
        let config = &self.config;
        let lengths = [self.sizes[0][0], self.sizes[1][0], self.sizes[2][0]];

        let final_state = self.last.map(|[t, x, y, psi, u, v]| FinalState {
            t_s: t,
            distance_to_destination_m: (x - config.destination[0]).hypot(y - config.destination[1]),
            heading_error_deg: wrap(psi - config.destination[2]).to_degrees(),
            speed_m_s: u.hypot(v),
        });
        let mut elongation = [None, None];
        let mut elongation_t = [None, None];
        for k in 0..2 {
            if let Some((e, at)) = self.elongation[k].value() {
                elongation[k] = Some(e);
                elongation_t[k] = Some(at);
            }
        }

        // The controller's situations per target slot.
        let have_controller = ctrl.solver.height() + ctrl.command.height() > 0;
        let view_of = |slot: u32| -> Option<ControllerView> {
            if !have_controller {
                return None;
            }
            let c = &ctrl.colregs;
            let mut v = ControllerView::default();
            for i in ctrl.colregs_indices() {
                if c.slot[i] == slot {
                    v.situation_codes.push(c.situation_code[i]);
                    v.roles.push(c.label(c.role_idx[i]).to_owned());
                }
            }
            (!v.situation_codes.is_empty()).then_some(v)
        };
        let mut normalized = Vec::new();
        let mut encounters = Vec::new();
        let mut collision_events = Vec::new();
        let mut obstacle_tracks = Vec::new();
        for st in self.slots {
            let mut label = "static hazard".to_owned();
            if let Some(mut tracker) = st.encounter {
                if st.near == 0 {
                    if let Some((_, Some(sample))) = st.closest {
                        tracker.push(sample);
                    }
                }
                let view = view_of(st.slot);
                if let Some(rep) = tracker.finish(&st.name, st.slot, view.as_ref()) {
                    label = rep
                        .situation_assessed
                        .clone()
                        .unwrap_or_else(|| "none".to_owned());
                    encounters.push(rep);
                } else {
                    label = "none".to_owned();
                }
            }
            // Eq. (30) per vessel, and the safe distances for the plots.
            let mut per_vessel = BTreeMap::new();
            let mut safe = [0.0; 3];
            let half = if st.kind == 2 {
                st.length / 2.0
            } else {
                st.length.max(st.width) / 2.0
            };
            for (k, v) in VESSELS.iter().enumerate() {
                if let Some((m, at)) = st.min[k].value() {
                    per_vessel.insert(
                        (*v).to_owned(),
                        VesselDistance {
                            min_distance_m: m,
                            own_length_m: lengths[k],
                            normalized: m / lengths[k],
                            t_s: at,
                        },
                    );
                }
                safe[k] = lengths[k] + half + config.safety_buffer_m;
            }
            normalized.push(ObstacleDistance {
                obstacle: st.name.clone(),
                slot: st.slot,
                kind: if st.kind == 2 { "ship" } else { "static" }.to_owned(),
                encounter: label,
                vessels: per_vessel,
            });
            for o in st.overlaps {
                collision_events.extend(o.finish());
            }
            let rows = st.track.rows();
            obstacle_tracks.push(ObstacleTrack {
                name: st.name,
                kind: i32::try_from(st.kind).unwrap_or(0),
                t: rows.iter().map(|r| r[0]).collect(),
                x: rows.iter().map(|r| r[1]).collect(),
                y: rows.iter().map(|r| r[2]).collect(),
                psi: rows.iter().map(|r| r[3]).collect(),
                ship_distance: rows.iter().map(|r| r[4]).collect(),
                length: st.length,
                width: st.width,
                distance: st.distance.map(|d| d.points()),
                safe,
            });
        }
        for p in self.pairs {
            collision_events.extend(p.finish());
        }
        collision_events.sort_by(|a, b| a.t_start_s.total_cmp(&b.t_start_s));

        // Commands and bounds.
        let cap = self.opts.plot_points;
        let (bound_report, command_plot) = if ctrl.command.height() > 0 {
            let c = &ctrl.command;
            let t = seconds(c)?;
            let tension = [col(c, "cmd_tension1")?, col(c, "cmd_tension2")?];
            let angle = [col(c, "cmd_angle1")?, col(c, "cmd_angle2")?];
            let thrust = [
                [
                    col(c, "cmd_tug1_X")?,
                    col(c, "cmd_tug1_Y")?,
                    col(c, "cmd_tug1_N")?,
                ],
                [
                    col(c, "cmd_tug2_X")?,
                    col(c, "cmd_tug2_Y")?,
                    col(c, "cmd_tug2_N")?,
                ],
            ];
            let series = CommandSeries {
                t: &t,
                tension: [&tension[0], &tension[1]],
                angle: [&angle[0], &angle[1]],
                thrust: [
                    [&thrust[0][0], &thrust[0][1], &thrust[0][2]],
                    [&thrust[1][0], &thrust[1][1], &thrust[1][2]],
                ],
            };
            let report = check_bounds(Some(series), None, &config.bounds);
            let deg = |a: &[f64]| a.iter().map(|v| v.to_degrees()).collect::<Vec<f64>>();
            let angle_deg = [deg(&angle[0]), deg(&angle[1])];
            let plot = CommandPlot {
                angle_deg: [0, 1].map(|k| line(cap, &t, &angle_deg[k])),
                tension: [0, 1].map(|k| line(cap, &t, &tension[k])),
                angle_rate_deg: [0, 1].map(|k| line(cap, &t, &rates(&t, &angle_deg[k]))),
                tension_rate: [0, 1].map(|k| line(cap, &t, &rates(&t, &tension[k]))),
            };
            (report, Some(plot))
        } else {
            (check_bounds(None, None, &config.bounds), None)
        };
        let bound_report: BoundReport = bound_report.with_inputs(self.inputs.result());

        // Solver.
        let (sample_time_ms, admm_iterations, converged, fallbacks, reasons, solver_plot) =
            if ctrl.solver.height() > 0 {
                let s = &ctrl.solver;
                let ms = f64s(s, "compute_time_ms")?;
                let it = f64s(s, "iterations")?;
                let conv = bools(s, "converged")?;
                let n = conv.len().max(1) as f64;
                let conv_frac = conv.iter().filter(|c| **c == Some(true)).count() as f64 / n;
                let mut reasons: BTreeMap<String, u64> = BTreeMap::new();
                let reasons_col = s
                    .column("fallback")
                    .and_then(|c| c.str())
                    .map_err(|e| AnalyzerError::frame("solver", e))?;
                for r in reasons_col.iter().flatten().filter(|r| !r.is_empty()) {
                    *reasons.entry(r.to_owned()).or_insert(0) += 1;
                }
                let counted: u64 = reasons.values().sum();
                let cumulative = i64s(s, "fallbacks")?
                    .last()
                    .copied()
                    .and_then(|v| u64::try_from(v).ok())
                    .unwrap_or(0);
                let t = seconds(s)?;
                let log = |name: &str| -> Result<Vec<(f64, f64)>> {
                    let v = col(s, name)?;
                    let l: Vec<f64> = v
                        .iter()
                        .map(|x| if *x > 0.0 { x.log10() } else { f64::NAN })
                        .collect();
                    Ok(line(cap, &t, &l))
                };
                let plot = SolverPlot {
                    iterations: line(cap, &t, &it),
                    log_r_pri: [log("r_pri1")?, log("r_pri2")?],
                    log_r_dual: [log("r_dual1")?, log("r_dual2")?],
                    compute_time: Histogram::new(&ms, 40),
                };
                (
                    stats(&ms),
                    stats(&it),
                    Some(conv_frac),
                    counted.max(cumulative),
                    reasons,
                    Some(plot),
                )
            } else {
                (None, None, None, 0, BTreeMap::new(), None)
            };

        // Altered waypoints the guidance used.
        let mut altered_waypoints: Vec<[f64; 3]> = Vec::new();
        if ctrl.reference.height() > 0 {
            let r = &ctrl.reference;
            let alt = bools(r, "altered_effective")?;
            let (wx, wy, wp) = (f64s(r, "wp_x")?, f64s(r, "wp_y")?, f64s(r, "wp_psi")?);
            for i in 0..alt.len() {
                if alt[i] == Some(true) {
                    let w = [wx[i], wy[i], wp[i]];
                    if !altered_waypoints
                        .iter()
                        .any(|a| (a[0] - w[0]).hypot(a[1] - w[1]) < 1e-6)
                    {
                        altered_waypoints.push(w);
                    }
                }
            }
        }

        let architecture = config.architecture.map(|c| Code {
            code: c,
            name: architecture_name(c),
        });
        let scheme = config.scheme.map(|c| Code {
            code: c,
            name: scheme_name(c),
        });
        let truncated_files: Vec<Truncation> = files
            .iter()
            .filter_map(|f| {
                f.truncated.as_ref().map(|r| Truncation {
                    file: f.path.display().to_string(),
                    reason: r.clone(),
                })
            })
            .collect();
        let title = format!(
            "scenario {}{}{}{}",
            config.scenario_name,
            architecture
                .as_ref()
                .map(|a| format!(", {}", a.name))
                .unwrap_or_default(),
            scheme
                .as_ref()
                .map(|s| format!(", scheme {}", s.name))
                .unwrap_or_default(),
            if truncated_files.is_empty() {
                ""
            } else {
                " (TRUNCATED LOG)"
            }
        );
        let control_samples = ctrl.controller_height();

        let metrics = Metrics {
            analyzer_version: env!("CARGO_PKG_VERSION").to_owned(),
            scenario: config.scenario_name.clone(),
            scenario_source: config.scenario_source.clone(),
            architecture,
            scheme,
            truncated: !truncated_files.is_empty(),
            truncated_files,
            notes,
            start_s: self.t_span.map_or(0.0, |s| s.0),
            end_s: self.t_span.map_or(0.0, |s| s.1),
            plant_steps: self.steps,
            control_samples,
            settling_time_s: self.settle.value(),
            settling_criteria: self.criteria,
            final_state,
            max_towline_elongation_error: elongation,
            max_towline_elongation_error_t_s: elongation_t,
            towline_desired_length_m: config.towline_desired_length,
            normalized_min_distance: normalized,
            collisions: collision_events.len(),
            collision_events,
            ship_travel_m: self.travel.value(),
            colregs: encounters,
            bound_violations: BoundSection {
                bounds: config.bounds,
                report: bound_report,
            },
            sample_time_ms,
            admm_iterations,
            admm_converged_fraction: converged,
            fallbacks,
            fallback_reasons: reasons,
            unit_warnings: unit_levels.iter().filter(|&&l| l == 3).count(),
            unit_errors: unit_levels.iter().filter(|&&l| l >= 4).count(),
            config: config.clone(),
            files,
        };

        let pose_rows = self.poses.rows();
        let plot = PlotData {
            title,
            t_span: self.t_span,
            states: self.states.map(|v| v.map(|d| d.points())),
            tracks: self.tracks.map(|d| d.points()),
            poses: PoseSamples {
                t: pose_rows.iter().map(|r| r[0]).collect(),
                pose: pose_rows
                    .iter()
                    .map(|r| std::array::from_fn(|k| [r[1 + 3 * k], r[2 + 3 * k], r[3 + 3 * k]]))
                    .collect(),
            },
            sizes: self.sizes,
            obstacles: obstacle_tracks,
            route: config.route.clone(),
            altered_waypoints,
            command: command_plot,
            actual: ActualTowing {
                angle_deg: self.actual_angle.map(|d| d.points()),
                tension: self.actual_tension.map(|d| d.points()),
            },
            solver: solver_plot,
            bounds: config.bounds,
        };
        Ok(Analysis {
            metrics,
            plot,
            controller: ctrl,
            tables: Vec::new(),
        })
    }
}

/// Analyses a run: streams its plant log through the analysis (writing the `timeseries`
/// and `obstacles` tables into `tables` when given) and computes every metric and the plot
/// data. Progress (bytes of the plant log) goes to `progress`.
///
/// # Errors
/// The plant log cannot be used (see [`crate::read::read_log`]) or has no vessel states,
/// a table cannot be written, a frame lacks a column (unexpected).
pub fn analyze_run(
    run: Run,
    tables: Option<&Path>,
    progress: &indicatif::MultiProgress,
    opts: &StreamOptions,
) -> Result<Analysis> {
    let mut run = run;
    loop {
        let ctrl = crate::frames::build_controller(
            std::mem::take(&mut run.controller),
            &run.config.route,
        )?;
        let mut stream = PlantStream::new(&run.config, &ctrl, tables, opts);
        let bar = progress.add(crate::progress::bytes_bar(&run.plant_path));
        let read = crate::read::read_into(&run.plant_path, &bar, &mut stream);
        bar.finish_and_clear();
        let log = match read {
            Ok(log) => log,
            Err(e) => {
                stream.abandon();
                return Err(e);
            }
        };
        match run.needs_whole_read(&log) {
            Ok(false) => {}
            Ok(true) => {
                // The plant log holds controller messages or its scenario after its first
                // message: read it whole first (once), then stream it again.
                stream.abandon();
                run = run.reload(progress)?;
                continue;
            }
            Err(e) => {
                stream.abandon();
                return Err(e);
            }
        }
        if !log.has_plant() {
            stream.abandon();
            return Err(AnalyzerError::NoPlantLog {
                files: run.file_list(),
            });
        }
        let (acc, written) = stream.finish()?;
        let (files, notes, levels) = run.complete(log);
        let mut analysis = acc.finish(ctrl, files, notes, &levels)?;
        analysis.tables = written;
        return Ok(analysis);
    }
}

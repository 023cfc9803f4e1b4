//! The plot sink: the plant's series at a bounded resolution, fed the same plant steps
//! (and batches) as the metrics, and the controller's series when the run is complete;
//! [`PlotData`] is everything [`crate::plots`] draws. Kept apart from the metrics: the
//! plots are a consumer of the steps, not a metric.

use polars::prelude::DataFrame;

use crate::decimate::{Decimator, PathDecimator, StrideBuffer};
use crate::error::Result;
use crate::frames::{bools, col, f64s, seconds, ControllerFrames, PlantBatch};
use crate::geometry::wrap;
use crate::metric::Metrics;
use crate::metrics::rates;
use crate::rows::{slot_index, ObstacleRows};
use crate::run::{Bounds, RunConfig};
use crate::step::PlantStep;

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

/// The points of the line `(t, v)` kept by a [`Decimator`] of `capacity` points.
fn line(capacity: usize, t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    let mut d = Decimator::new(capacity);
    for (&a, &b) in t.iter().zip(v) {
        d.push(a, b);
    }
    d.points()
}

/// What the map and the distance plot keep of one obstacle slot.
#[derive(Debug, Clone)]
struct SlotPlot {
    slot: u32,
    name: String,
    kind: i64,
    length: f64,
    width: f64,
    /// Rows `t, x, y, psi, d_ship` for the map.
    track: StrideBuffer<5>,
    /// Distance per vessel over time.
    distance: [Decimator; 3],
}

/// The plot series while the plant log streams by (bounded by the sizes given).
#[derive(Debug, Clone)]
pub struct PlotSink {
    plot_points: usize,
    track_rows: usize,
    sizes: [[f64; 2]; 3],
    states: [[Decimator; 6]; 3],
    tracks: [PathDecimator; 3],
    unwrap: [Option<f64>; 3],
    poses: StrideBuffer<10>,
    actual_angle: [Decimator; 2],
    actual_tension: [Decimator; 2],
    slots: Vec<SlotPlot>,
}

impl PlotSink {
    /// An empty sink: `plot_points` buckets per line, `track_rows` rows per track.
    #[must_use]
    pub fn new(config: &RunConfig, plot_points: usize, track_rows: usize) -> Self {
        let dec = || Decimator::new(plot_points);
        PlotSink {
            plot_points,
            track_rows,
            sizes: [config.ship_size, config.tug1_size, config.tug2_size],
            states: std::array::from_fn(|_| std::array::from_fn(|_| dec())),
            tracks: std::array::from_fn(|_| PathDecimator::new(plot_points)),
            unwrap: [None; 3],
            poses: StrideBuffer::new(track_rows),
            actual_angle: std::array::from_fn(|_| dec()),
            actual_tension: std::array::from_fn(|_| dec()),
            slots: Vec::new(),
        }
    }

    /// Points held by the plot series now (bounded by the sizes, whatever the log's
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

    /// One plant step: the states (Fig. 12 style: heading unwrapped, no jump at +-180
    /// deg when heading South; yaw rate in deg/s), the tracks and the poses.
    pub fn step(&mut self, s: &PlantStep<'_>) {
        let mut pose = [0.0; 10];
        pose[0] = s.t;
        for (k, vk) in s.vessels.iter().enumerate() {
            let psi = vk.psi;
            let unwrapped = match self.unwrap[k] {
                Some(p) if psi.is_finite() => p + wrap(psi - p),
                _ => psi,
            };
            if unwrapped.is_finite() {
                self.unwrap[k] = Some(unwrapped);
            }
            let values = [
                vk.x,
                vk.y,
                unwrapped.to_degrees(),
                vk.u,
                vk.v,
                vk.r.to_degrees(),
            ];
            for (j, value) in values.into_iter().enumerate() {
                self.states[k][j].push(s.t, value);
            }
            self.tracks[k].push(vk.y, vk.x);
            pose[1 + 3 * k] = vk.x;
            pose[2 + 3 * k] = vk.y;
            pose[3 + 3 * k] = psi;
        }
        self.poses.push(pose);
    }

    /// One batch: the actual towing angles and tensions, the obstacles' tracks and
    /// distances (their own time bases).
    ///
    /// # Errors
    /// A frame lacks a column (unexpected).
    pub fn batch(&mut self, b: &PlantBatch) -> Result<()> {
        self.towlines(&b.towlines)?;
        let Some(rows) = ObstacleRows::of(&b.obstacles)? else {
            return Ok(());
        };
        for i in 0..rows.len() {
            let (points, track_rows) = (self.plot_points, self.track_rows);
            let k = slot_index(
                &mut self.slots,
                rows.slot[i],
                |s| s.slot,
                || {
                    let o = rows.obs(i);
                    SlotPlot {
                        slot: u32::try_from(rows.slot[i]).unwrap_or(0),
                        name: rows.name(i).to_owned(),
                        kind: rows.kind[i] as i64,
                        length: o[4],
                        width: o[5],
                        track: StrideBuffer::new(track_rows),
                        distance: std::array::from_fn(|_| Decimator::new(points)),
                    }
                },
            );
            let (t, [ox, oy, opsi, ..], dist) = (rows.t[i], rows.obs(i), rows.dist(i));
            let st = &mut self.slots[k];
            for (v, d) in dist.into_iter().enumerate() {
                st.distance[v].push(t, d);
            }
            st.track.push([t, ox, oy, opsi, dist[0]]);
        }
        Ok(())
    }

    fn towlines(&mut self, df: &DataFrame) -> Result<()> {
        let t = seconds(df)?;
        for k in 0..2 {
            let angle = col(df, &format!("line{}_angle", k + 1))?;
            let tension = col(df, &format!("line{}_tension", k + 1))?;
            for i in 0..t.len() {
                self.actual_angle[k].push(t[i], angle[i].to_degrees());
                self.actual_tension[k].push(t[i], tension[i]);
            }
        }
        Ok(())
    }

    /// The obstacles' tracks, with the safe distances of ship, tug 1, tug 2 on the
    /// centre-distance scale (`docs/colregs.md` section 1).
    fn obstacle_tracks(slots: Vec<SlotPlot>, lengths: [f64; 3], d_s0: f64) -> Vec<ObstacleTrack> {
        slots
            .into_iter()
            .map(|st| {
                let half = if st.kind == 2 {
                    st.length / 2.0
                } else {
                    st.length.max(st.width) / 2.0
                };
                let rows = st.track.rows();
                ObstacleTrack {
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
                    safe: lengths.map(|l| l + half + d_s0),
                }
            })
            .collect()
    }

    /// The plot data, with the controller's series and the title from `metrics`.
    ///
    /// # Errors
    /// A controller table lacks a column (unexpected).
    pub fn finish(self, ctrl: &ControllerFrames, metrics: &Metrics) -> Result<PlotData> {
        let config = &metrics.config;
        let cap = self.plot_points;
        let lengths = self.sizes.map(|s| s[0]);
        let pose_rows = self.poses.rows();
        Ok(PlotData {
            title: title(metrics),
            t_span: (metrics.run.plant_steps > 0)
                .then_some((metrics.run.start_s, metrics.run.end_s)),
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
            obstacles: Self::obstacle_tracks(self.slots, lengths, config.safety_buffer_m),
            route: config.route.clone(),
            altered_waypoints: altered_waypoints(ctrl)?,
            command: command_plot(ctrl, cap)?,
            actual: ActualTowing {
                angle_deg: self.actual_angle.map(|d| d.points()),
                tension: self.actual_tension.map(|d| d.points()),
            },
            solver: solver_plot(ctrl, cap)?,
            bounds: config.bounds,
        })
    }
}

/// Title line: scenario, architecture, scheme, and a truncation mark.
fn title(m: &Metrics) -> String {
    let r = &m.run;
    format!(
        "scenario {}{}{}{}",
        r.scenario,
        r.architecture
            .as_ref()
            .map(|a| format!(", {}", a.name))
            .unwrap_or_default(),
        r.scheme
            .as_ref()
            .map(|s| format!(", scheme {}", s.name))
            .unwrap_or_default(),
        if r.truncated_files.is_empty() {
            ""
        } else {
            " (TRUNCATED LOG)"
        }
    )
}

/// Commanded towing angles and tensions and their rates (controller log).
fn command_plot(ctrl: &ControllerFrames, cap: usize) -> Result<Option<CommandPlot>> {
    if ctrl.command.height() == 0 {
        return Ok(None);
    }
    let c = &ctrl.command;
    let t = seconds(c)?;
    let tension = [col(c, "cmd_tension1")?, col(c, "cmd_tension2")?];
    let angle = [col(c, "cmd_angle1")?, col(c, "cmd_angle2")?];
    let deg = |a: &[f64]| a.iter().map(|v| v.to_degrees()).collect::<Vec<f64>>();
    let angle_deg = [deg(&angle[0]), deg(&angle[1])];
    Ok(Some(CommandPlot {
        angle_deg: [0, 1].map(|k| line(cap, &t, &angle_deg[k])),
        tension: [0, 1].map(|k| line(cap, &t, &tension[k])),
        angle_rate_deg: [0, 1].map(|k| line(cap, &t, &rates(&t, &angle_deg[k]))),
        tension_rate: [0, 1].map(|k| line(cap, &t, &rates(&t, &tension[k]))),
    }))
}

/// The solver's iterations, residuals and compute-time histogram (controller log).
fn solver_plot(ctrl: &ControllerFrames, cap: usize) -> Result<Option<SolverPlot>> {
    if ctrl.solver.height() == 0 {
        return Ok(None);
    }
    let s = &ctrl.solver;
    let t = seconds(s)?;
    let log = |name: &str| -> Result<Vec<(f64, f64)>> {
        let v = col(s, name)?;
        let l: Vec<f64> = v
            .iter()
            .map(|x| if *x > 0.0 { x.log10() } else { f64::NAN })
            .collect();
        Ok(line(cap, &t, &l))
    };
    Ok(Some(SolverPlot {
        iterations: line(cap, &t, &f64s(s, "iterations")?),
        log_r_pri: [log("r_pri1")?, log("r_pri2")?],
        log_r_dual: [log("r_dual1")?, log("r_dual2")?],
        compute_time: Histogram::new(&f64s(s, "compute_time_ms")?, 40),
    }))
}

/// Distinct altered waypoints the guidance used (North, East, heading).
fn altered_waypoints(ctrl: &ControllerFrames) -> Result<Vec<[f64; 3]>> {
    let mut out: Vec<[f64; 3]> = Vec::new();
    if ctrl.reference.height() == 0 {
        return Ok(out);
    }
    let r = &ctrl.reference;
    let alt = bools(r, "altered_effective")?;
    let (wx, wy, wp) = (f64s(r, "wp_x")?, f64s(r, "wp_y")?, f64s(r, "wp_psi")?);
    for i in 0..alt.len() {
        if alt[i] == Some(true) {
            let w = [wx[i], wy[i], wp[i]];
            if !out.iter().any(|a| (a[0] - w[0]).hypot(a[1] - w[1]) < 1e-6) {
                out.push(w);
            }
        }
    }
    Ok(out)
}

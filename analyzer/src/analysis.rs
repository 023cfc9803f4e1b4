//! From the frames of a run to `metrics.json` and the data of the plots.

use std::borrow::Cow;
use std::collections::BTreeMap;

use polars::prelude::DataFrame;
use serde::Serialize;

use crate::colregs::{self, ControllerView, EncounterReport, EncounterSample, ScoringParams};
use crate::error::Result;
use crate::frames::{bools, col, f64s, i64s, seconds, strs, Frames};
use crate::geometry::{convex_overlap, ellipse_polygon, hull_rect, rect_circle_overlap, wrap};
use crate::metrics::{
    check_bounds, max_elongation_error, min_with_time, overlap_events, settling_time, stats,
    travel, BoundReport, CollisionEvent, CommandSeries, SettleCriteria, Stats, VesselTrack,
};
use crate::run::{Bounds, FileSummary, RunConfig};

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

/// Most rows an obstacle's track keeps for the plots (every k-th row beyond that; the
/// tracks and distances are smooth at the plots' resolution).
const PLOT_ROWS: usize = 16_000;

/// One obstacle's track for the plots.
#[derive(Debug, Clone, Default)]
pub struct ObstacleTrack {
    /// Name.
    pub name: String,
    /// 1 circle, 2 ship.
    pub kind: i32,
    /// Times, s.
    pub t: Vec<f64>,
    /// North, m.
    pub x: Vec<f64>,
    /// East, m.
    pub y: Vec<f64>,
    /// Course, rad.
    pub psi: Vec<f64>,
    /// Major axis (or diameter), m.
    pub length: f64,
    /// Minor axis (or diameter), m.
    pub width: f64,
    /// Centre distance of ship, tug 1, tug 2, m.
    pub distance: [Vec<f64>; 3],
    /// Safe distance of ship, tug 1, tug 2 on the centre-distance scale, m
    /// (`docs/colregs.md` section 1: circles `L + R + d_S0`, ships `L + a + d_S0`).
    pub safe: [f64; 3],
}

/// Series for the towing angle and force plots.
#[derive(Debug, Clone, Default)]
pub struct TowingSeries<'a> {
    /// Times, s.
    pub t: Cow<'a, [f64]>,
    /// Towing angles of line 1 and 2, rad.
    pub angle: [Cow<'a, [f64]>; 2],
    /// Tensions of line 1 and 2, N.
    pub tension: [Cow<'a, [f64]>; 2],
}

/// Solver series.
#[derive(Debug, Clone, Default)]
pub struct SolverSeries {
    /// Times, s.
    pub t: Vec<f64>,
    /// Iterations.
    pub iterations: Vec<f64>,
    /// Primal residuals of tug 1 and 2.
    pub r_pri: [Vec<f64>; 2],
    /// Dual residuals of tug 1 and 2.
    pub r_dual: [Vec<f64>; 2],
    /// Compute time, ms.
    pub compute_ms: Vec<f64>,
}

/// Everything the plots draw (the long series borrowed from the frames).
#[derive(Debug, Clone, Default)]
pub struct PlotData<'a> {
    /// Title line (scenario, architecture, scheme).
    pub title: String,
    /// Plant times, s.
    pub t: Vec<f64>,
    /// Ship, tug 1, tug 2.
    pub vessels: [VesselTrack<'a>; 3],
    /// Length and width of ship, tug 1, tug 2, m.
    pub sizes: [[f64; 2]; 3],
    /// Obstacles.
    pub obstacles: Vec<ObstacleTrack>,
    /// Route points (North, East, heading).
    pub route: Vec<[f64; 3]>,
    /// Distinct altered waypoints the guidance used (North, East, heading).
    pub altered_waypoints: Vec<[f64; 3]>,
    /// Commanded towing angles and tensions (controller), per sample.
    pub command: Option<TowingSeries<'static>>,
    /// Actual towing angles and tensions (plant), per step.
    pub actual: TowingSeries<'a>,
    /// Solver.
    pub solver: Option<SolverSeries>,
    /// Bounds.
    pub bounds: Bounds,
}

/// The result of the analysis.
#[derive(Debug, Clone)]
pub struct Analysis<'a> {
    /// `metrics.json`.
    pub metrics: Metrics,
    /// Plot data.
    pub plot: PlotData<'a>,
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

/// Rows of the obstacle frame per slot, in first-seen order.
fn group_rows(slots: &[i64]) -> Vec<(i64, Vec<u32>)> {
    let mut groups: Vec<(i64, Vec<u32>)> = Vec::new();
    for (i, &s) in slots.iter().enumerate() {
        let i = u32::try_from(i).unwrap_or(u32::MAX);
        match groups.iter_mut().find(|(g, _)| *g == s) {
            Some((_, rows)) => rows.push(i),
            None => groups.push((s, vec![i])),
        }
    }
    groups
}

/// Computes every metric and the plot data.
///
/// # Errors
/// A frame lacks a column it should have (unexpected).
#[allow(clippy::too_many_lines)]
pub fn analyze<'a>(
    frames: &'a Frames,
    config: &RunConfig,
    files: Vec<FileSummary>,
    notes: Vec<String>,
    unit_levels: &[i32],
) -> Result<Analysis<'a>> {
    let t = seconds(&frames.vessels)?;
    let vessels = [
        track(&frames.vessels, "ship")?,
        track(&frames.vessels, "tug1")?,
        track(&frames.vessels, "tug2")?,
    ];
    let sizes = [config.ship_size, config.tug1_size, config.tug2_size];
    let lengths = [sizes[0][0], sizes[1][0], sizes[2][0]];

    // Settling time and the final state.
    let criteria = SettleCriteria::paper(config.ship_size[0]);
    let settling_time_s = settling_time(&t, &vessels[0], config.destination, criteria);
    let final_state = t.last().map(|&tl| {
        let ship = &vessels[0];
        let i = ship.len() - 1;
        FinalState {
            t_s: tl,
            distance_to_destination_m: (ship.x[i] - config.destination[0])
                .hypot(ship.y[i] - config.destination[1]),
            heading_error_deg: wrap(ship.psi[i] - config.destination[2]).to_degrees(),
            speed_m_s: ship.u[i].hypot(ship.v[i]),
        }
    });

    // Towlines.
    let line_t = seconds(&frames.towlines)?;
    let mut elongation = [None, None];
    let mut elongation_t = [None, None];
    let mut actual = TowingSeries::default();
    for k in 0..2 {
        let len = col(&frames.towlines, &format!("line{}_length", k + 1))?;
        if let Some((e, at)) = max_elongation_error(&line_t, &len, config.towline_desired_length[k])
        {
            elongation[k] = Some(e);
            elongation_t[k] = Some(at);
        }
        actual.angle[k] = col(&frames.towlines, &format!("line{}_angle", k + 1))?;
        actual.tension[k] = col(&frames.towlines, &format!("line{}_tension", k + 1))?;
    }
    actual.t = Cow::Owned(line_t);

    // Obstacles: distances, collisions, encounters.
    let ob = &frames.obstacles;
    let ob_t = seconds(ob)?;
    let ob_slot = i64s(ob, "slot")?;
    let ob_kind = col(ob, "kind")?;
    let ob_x = col(ob, "obs_x")?;
    let ob_y = col(ob, "obs_y")?;
    let ob_psi = col(ob, "obs_psi")?;
    let ob_speed = col(ob, "obs_speed")?;
    let ob_len = col(ob, "obs_length")?;
    let ob_wid = col(ob, "obs_width")?;
    let name_col = ob
        .column("name")
        .and_then(|c| c.str())
        .map_err(|e| crate::error::AnalyzerError::frame("obstacles", e))?;
    let poses: Vec<[Cow<'_, [f64]>; 3]> = VESSELS
        .iter()
        .map(|v| -> Result<[Cow<'_, [f64]>; 3]> {
            Ok([
                col(ob, &format!("{v}_x"))?,
                col(ob, &format!("{v}_y"))?,
                col(ob, &format!("{v}_psi"))?,
            ])
        })
        .collect::<Result<_>>()?;
    let ship_u = col(ob, "ship_u")?;
    let ship_v = col(ob, "ship_v")?;
    let dist: Vec<Cow<'_, [f64]>> = VESSELS
        .iter()
        .map(|v| col(ob, &format!("d_{v}")))
        .collect::<Result<_>>()?;
    let ob_altered = if ob.column("altered_effective").is_ok() {
        bools(ob, "altered_effective")?
    } else {
        vec![None; ob.height()]
    };

    // The controller's situations per slot.
    let mut views: BTreeMap<i64, ControllerView> = BTreeMap::new();
    if frames.colregs.height() > 0 {
        let slots = i64s(&frames.colregs, "slot")?;
        let codes = i64s(&frames.colregs, "situation_code")?;
        let roles = strs(&frames.colregs, "role")?;
        for ((s, c), r) in slots.into_iter().zip(codes).zip(roles) {
            let v = views.entry(s).or_default();
            v.situation_codes.push(i32::try_from(c).unwrap_or(-1));
            v.roles.push(r);
        }
    }
    let have_controller = frames.solver.height() + frames.command.height() > 0;

    let mut normalized = Vec::new();
    let mut encounters = Vec::new();
    let mut collision_events = Vec::new();
    let mut obstacle_tracks = Vec::new();
    let ob_slot_groups = group_rows(&ob_slot);
    drop(ob_slot);
    for (slot, rows) in ob_slot_groups {
        let rows: Vec<usize> = rows.into_iter().map(|i| i as usize).collect();
        let Some(&first) = rows.first() else { continue };
        let name = name_col.get(first).unwrap_or("").to_owned();
        let kind = ob_kind[first] as i64;
        let slot = u32::try_from(slot).unwrap_or(0);
        let tt: Vec<f64> = rows.iter().map(|&i| ob_t[i]).collect();
        let (length, width) = (ob_len[first], ob_wid[first]);

        // Encounter (target ships).
        let mut label = "static hazard".to_owned();
        if kind == 2 {
            // Only the rows near the ship matter (detection, action, CPA): those within
            // twice the detection range, or the closest row if none.
            let window = 2.0 * config.detection_distance_m;
            let mut near: Vec<usize> = rows
                .iter()
                .copied()
                .filter(|&i| dist[0][i] < window)
                .collect();
            if near.is_empty() {
                near.extend(
                    rows.iter()
                        .copied()
                        .filter(|&i| dist[0][i].is_finite())
                        .min_by(|&a, &b| dist[0][a].total_cmp(&dist[0][b])),
                );
            }
            let samples: Vec<EncounterSample> = near
                .iter()
                .map(|&i| EncounterSample {
                    t: ob_t[i],
                    own: [
                        poses[0][0][i],
                        poses[0][1][i],
                        poses[0][2][i],
                        ship_u[i].hypot(ship_v[i]),
                    ],
                    target: [ob_x[i], ob_y[i], ob_psi[i], ob_speed[i]],
                    altered: ob_altered[i],
                    tow_range: dist[0][i].min(dist[1][i]).min(dist[2][i]),
                })
                .filter(|s| s.own.iter().chain(&s.target).all(|v| v.is_finite()))
                .collect();
            let params = ScoringParams::model_scale(
                config.ship_size[0],
                length,
                config.detection_distance_m,
                config.safety_buffer_m,
            );
            let view = views.get(&i64::from(slot));
            let view = if have_controller { view } else { None };
            if let Some(rep) = colregs::assess(&name, slot, &samples, view, &params) {
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
        let stride = rows.len().div_ceil(PLOT_ROWS).max(1);
        let mut dseries: [Vec<f64>; 3] = Default::default();
        let mut safe = [0.0; 3];
        let half = if kind == 2 {
            length / 2.0
        } else {
            length.max(width) / 2.0
        };
        for (k, v) in VESSELS.iter().enumerate() {
            let d: Vec<f64> = rows.iter().map(|&i| dist[k][i]).collect();
            let plot_d: Vec<f64> = d.iter().step_by(stride).copied().collect();
            if let Some((m, at)) = min_with_time(&tt, &d) {
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
            dseries[k] = plot_d;
            safe[k] = lengths[k] + half + config.safety_buffer_m;
        }
        normalized.push(ObstacleDistance {
            obstacle: name.clone(),
            slot,
            kind: if kind == 2 { "ship" } else { "static" }.to_owned(),
            encounter: label,
            vessels: per_vessel,
        });

        // Hull overlaps with this obstacle.
        for (k, v) in VESSELS.iter().enumerate() {
            let flags: Vec<bool> = rows
                .iter()
                .map(|&i| {
                    let (x, y, psi) = (poses[k][0][i], poses[k][1][i], poses[k][2][i]);
                    if !(x.is_finite() && y.is_finite() && psi.is_finite()) {
                        return false;
                    }
                    if kind == 2 {
                        let hull = hull_rect(x, y, psi, sizes[k][0], sizes[k][1]);
                        let e = ellipse_polygon(
                            ob_x[i],
                            ob_y[i],
                            ob_psi[i],
                            ob_len[i] / 2.0,
                            ob_wid[i] / 2.0,
                        );
                        convex_overlap(&hull, &e)
                    } else {
                        rect_circle_overlap(
                            (x, y, psi, sizes[k][0], sizes[k][1]),
                            [ob_x[i], ob_y[i]],
                            ob_len[i].max(ob_wid[i]) / 2.0,
                        )
                    }
                })
                .collect();
            collision_events.extend(overlap_events(&tt, &flags, v, &name));
        }

        let plot_rows: Vec<usize> = rows.iter().step_by(stride).copied().collect();
        obstacle_tracks.push(ObstacleTrack {
            name,
            kind: i32::try_from(kind).unwrap_or(0),
            x: plot_rows.iter().map(|&i| ob_x[i]).collect(),
            y: plot_rows.iter().map(|&i| ob_y[i]).collect(),
            psi: plot_rows.iter().map(|&i| ob_psi[i]).collect(),
            t: tt.iter().step_by(stride).copied().collect(),
            length,
            width,
            distance: dseries,
            safe,
        });
    }

    // Hull overlaps between the tow's vessels.
    for (a, b) in [(0usize, 1usize), (0, 2), (1, 2)] {
        let flags: Vec<bool> = (0..t.len())
            .map(|i| {
                let va = &vessels[a];
                let vb = &vessels[b];
                let ha = hull_rect(va.x[i], va.y[i], va.psi[i], sizes[a][0], sizes[a][1]);
                let hb = hull_rect(vb.x[i], vb.y[i], vb.psi[i], sizes[b][0], sizes[b][1]);
                ha.iter()
                    .chain(&hb)
                    .all(|p| p[0].is_finite() && p[1].is_finite())
                    && convex_overlap(&ha, &hb)
            })
            .collect();
        collision_events.extend(overlap_events(&t, &flags, VESSELS[a], VESSELS[b]));
    }
    collision_events.sort_by(|a, b| a.t_start_s.total_cmp(&b.t_start_s));

    // Commands and bounds.
    let command = if frames.command.height() > 0 {
        let c = &frames.command;
        Some((
            seconds(c)?,
            [f64s(c, "cmd_tension1")?, f64s(c, "cmd_tension2")?],
            [f64s(c, "cmd_angle1")?, f64s(c, "cmd_angle2")?],
            [
                [
                    f64s(c, "cmd_tug1_X")?,
                    f64s(c, "cmd_tug1_Y")?,
                    f64s(c, "cmd_tug1_N")?,
                ],
                [
                    f64s(c, "cmd_tug2_X")?,
                    f64s(c, "cmd_tug2_Y")?,
                    f64s(c, "cmd_tug2_N")?,
                ],
            ],
        ))
    } else {
        None
    };
    let inputs = if frames.inputs.height() > 0 {
        let c = &frames.inputs;
        Some((
            seconds(c)?,
            [
                [
                    f64s(c, "in_tug1_X")?,
                    f64s(c, "in_tug1_Y")?,
                    f64s(c, "in_tug1_N")?,
                ],
                [
                    f64s(c, "in_tug2_X")?,
                    f64s(c, "in_tug2_Y")?,
                    f64s(c, "in_tug2_N")?,
                ],
            ],
        ))
    } else {
        None
    };
    let cmd_series = command.as_ref().map(|(t, f, a, th)| CommandSeries {
        t,
        tension: [&f[0], &f[1]],
        angle: [&a[0], &a[1]],
        thrust: [
            [&th[0][0], &th[0][1], &th[0][2]],
            [&th[1][0], &th[1][1], &th[1][2]],
        ],
    });
    let in_series = inputs.as_ref().map(|(t, th)| {
        (
            t.as_slice(),
            [
                [th[0][0].as_slice(), &th[0][1], &th[0][2]],
                [th[1][0].as_slice(), &th[1][1], &th[1][2]],
            ],
        )
    });
    let bound_report = check_bounds(cmd_series, in_series, &config.bounds);

    // Solver.
    let (sample_time_ms, admm_iterations, converged, fallbacks, reasons, solver_series) =
        if frames.solver.height() > 0 {
            let s = &frames.solver;
            let ms = f64s(s, "compute_time_ms")?;
            let it = f64s(s, "iterations")?;
            let conv = bools(s, "converged")?;
            let n = conv.len().max(1) as f64;
            let conv_frac = conv.iter().filter(|c| **c == Some(true)).count() as f64 / n;
            let reasons_col = strs(s, "fallback")?;
            let mut reasons: BTreeMap<String, u64> = BTreeMap::new();
            for r in reasons_col.into_iter().filter(|r| !r.is_empty()) {
                *reasons.entry(r).or_insert(0) += 1;
            }
            let counted: u64 = reasons.values().sum();
            let cumulative = i64s(s, "fallbacks")?
                .last()
                .copied()
                .and_then(|v| u64::try_from(v).ok())
                .unwrap_or(0);
            let series = SolverSeries {
                t: seconds(s)?,
                iterations: it.clone(),
                r_pri: [f64s(s, "r_pri1")?, f64s(s, "r_pri2")?],
                r_dual: [f64s(s, "r_dual1")?, f64s(s, "r_dual2")?],
                compute_ms: ms.clone(),
            };
            (
                stats(&ms),
                stats(&it),
                Some(conv_frac),
                counted.max(cumulative),
                reasons,
                Some(series),
            )
        } else {
            (None, None, None, 0, BTreeMap::new(), None)
        };

    // Altered waypoints the guidance used.
    let mut altered_waypoints: Vec<[f64; 3]> = Vec::new();
    if frames.reference.height() > 0 {
        let r = &frames.reference;
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
    let control_samples = frames
        .solver
        .height()
        .max(frames.command.height())
        .max(frames.reference.height());

    let metrics = Metrics {
        analyzer_version: env!("CARGO_PKG_VERSION").to_owned(),
        scenario: config.scenario_name.clone(),
        scenario_source: config.scenario_source.clone(),
        architecture,
        scheme,
        truncated: !truncated_files.is_empty(),
        truncated_files,
        notes,
        start_s: t.first().copied().unwrap_or(0.0),
        end_s: t.last().copied().unwrap_or(0.0),
        plant_steps: t.len(),
        control_samples,
        settling_time_s,
        settling_criteria: criteria,
        final_state,
        max_towline_elongation_error: elongation,
        max_towline_elongation_error_t_s: elongation_t,
        towline_desired_length_m: config.towline_desired_length,
        normalized_min_distance: normalized,
        collisions: collision_events.len(),
        collision_events,
        ship_travel_m: travel(&vessels[0].x, &vessels[0].y),
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

    let command_plot = command.map(|(t, [f1, f2], [a1, a2], _)| TowingSeries {
        t: Cow::Owned(t),
        angle: [Cow::Owned(a1), Cow::Owned(a2)],
        tension: [Cow::Owned(f1), Cow::Owned(f2)],
    });
    let plot = PlotData {
        title,
        t,
        vessels,
        sizes,
        obstacles: obstacle_tracks,
        route: config.route.clone(),
        altered_waypoints,
        command: command_plot,
        actual,
        solver: solver_series,
        bounds: config.bounds,
    };
    Ok(Analysis { metrics, plot })
}

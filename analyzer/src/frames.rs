//! The run as polars DataFrames: one per topic family, each with an `Int64` column `t_ns`
//! (log time, ns since simulation time 0), aligned in time by backward as-of joins (the
//! last row of the right table at or before each left row).
//!
//! | frame | rows | columns |
//! |---|---|---|
//! | `vessels` | plant steps | `t_ns`, `t_s`, `{ship,tug1,tug2}_{x,y,psi,u,v,r}` (tugs as-of joined onto the ship's times) |
//! | `towlines` | plant steps | `line{1,2}_{length,angle,tension,tension_cmd,slack,elongation_error}` |
//! | `inputs` | plant steps | `in_tug{1,2}_{X,Y,N}`, `in_tension_cmd{1,2}` |
//! | `obstacles` | plant steps x active slots | `slot`, `name`, `kind`, `obs_{x,y,psi,speed,length,width}`, the vessels' poses joined as of the row's time, and the centre distances `d_{ship,tug1,tug2}` |
//! | `reference`, `command`, `solver`, `colregs` | control samples (`colregs`: x slots) | the controller's topics |
//! | `controller` | control samples | `solver` with `reference` and `command` joined |
//! | `timeseries` ([`Frames::timeseries`], in slices) | plant steps | `vessels` with `towlines`, `inputs` and `controller` joined |

use std::borrow::Cow;

use polars::prelude::*;

use crate::error::{AnalyzerError, Result};
use crate::read::{ControllerData, PlantData, VesselCols};

/// All tables of a run.
#[derive(Debug, Clone)]
pub struct Frames {
    /// Vessel states on the ship's time base.
    pub vessels: DataFrame,
    /// Towline states.
    pub towlines: DataFrame,
    /// Plant inputs.
    pub inputs: DataFrame,
    /// Obstacles (long form) with the vessels' poses and the centre distances.
    pub obstacles: DataFrame,
    /// Guidance references.
    pub reference: DataFrame,
    /// COLREGS situations (long form).
    pub colregs: DataFrame,
    /// Commands.
    pub command: DataFrame,
    /// Solver reports.
    pub solver: DataFrame,
    /// Controller topics on one time base.
    pub controller: DataFrame,
}

impl Frames {
    /// Rows `offset .. offset + len` of the plant-time table: `vessels` with `towlines`,
    /// `inputs` and `controller` joined as of each step. Built in slices so the joined
    /// copy of a long run never exists whole.
    ///
    /// # Errors
    /// A polars error (unexpected).
    pub fn timeseries(&self, offset: usize, len: usize) -> Result<DataFrame> {
        let offset = i64::try_from(offset).unwrap_or(i64::MAX);
        let base = self.vessels.slice(offset, len);
        let mut ts = asof(&base, &self.towlines, "timeseries")?;
        ts = asof(&ts, &self.inputs, "timeseries")?;
        ts = asof(&ts, &self.controller, "timeseries")?;
        Ok(ts)
    }
}

// The column constructors take the vectors over; `shrink_to_fit` first, or the spare
// capacity of the reader's growing vectors (up to half) would stay allocated.

fn f64_col(name: &str, mut v: Vec<f64>) -> Column {
    v.shrink_to_fit();
    Float64Chunked::from_vec(name.into(), v)
        .into_series()
        .into_column()
}

fn i64_col(name: &str, mut v: Vec<i64>) -> Column {
    v.shrink_to_fit();
    Int64Chunked::from_vec(name.into(), v)
        .into_series()
        .into_column()
}

fn i32_col(name: &str, mut v: Vec<i32>) -> Column {
    v.shrink_to_fit();
    Int32Chunked::from_vec(name.into(), v)
        .into_series()
        .into_column()
}

fn u32_col(name: &str, mut v: Vec<u32>) -> Column {
    v.shrink_to_fit();
    UInt32Chunked::from_vec(name.into(), v)
        .into_series()
        .into_column()
}

fn u64_col(name: &str, mut v: Vec<u64>) -> Column {
    v.shrink_to_fit();
    UInt64Chunked::from_vec(name.into(), v)
        .into_series()
        .into_column()
}

fn bool_col(name: &str, v: &[bool]) -> Column {
    BooleanChunked::from_slice(name.into(), v)
        .into_series()
        .into_column()
}

fn str_col<'a>(name: &str, v: impl Iterator<Item = &'a str>) -> Column {
    StringChunked::from_iter_values(name.into(), v)
        .into_series()
        .into_column()
}

fn opt_str_col<'a>(name: &str, v: impl Iterator<Item = Option<&'a str>>) -> Column {
    StringChunked::from_iter_options(name.into(), v)
        .into_series()
        .into_column()
}

/// A frame from columns, sorted by `t_ns` (stable) if it is not already, with the sorted
/// flag set so as-of joins accept it.
fn frame(table: &str, columns: Vec<Column>) -> Result<DataFrame> {
    let mut df =
        DataFrame::new_infer_height(columns).map_err(|e| AnalyzerError::frame(table, e))?;
    let sorted = {
        let t = df
            .column("t_ns")
            .and_then(|c| c.i64())
            .map_err(|e| AnalyzerError::frame(table, e))?;
        let mut prev = i64::MIN;
        t.into_no_null_iter().all(|v| {
            let ok = v >= prev;
            prev = v;
            ok
        })
    };
    if !sorted {
        df = df
            .sort(
                ["t_ns"],
                SortMultipleOptions::default().with_maintain_order(true),
            )
            .map_err(|e| AnalyzerError::frame(table, e))?;
    }
    let mut cols = df.into_columns();
    for c in &mut cols {
        if c.name().as_str() == "t_ns" {
            c.set_sorted_flag(polars::series::IsSorted::Ascending);
        }
    }
    DataFrame::new_infer_height(cols).map_err(|e| AnalyzerError::frame(table, e))
}

/// Backward as-of join of `right` onto `left` on `t_ns` (equal times match).
fn asof(left: &DataFrame, right: &DataFrame, table: &str) -> Result<DataFrame> {
    if right.height() == 0 {
        // Nothing to join (a topic without messages): its columns, all null, so the
        // table's shape does not depend on what the log happened to hold.
        let mut out = left.clone();
        for c in right.columns() {
            if c.name().as_str() != "t_ns" && out.column(c.name().as_str()).is_err() {
                out.with_column(Column::full_null(
                    c.name().clone(),
                    left.height(),
                    c.dtype(),
                ))
                .map_err(|e| AnalyzerError::frame(table, e))?;
            }
        }
        return Ok(out);
    }
    let options = AsOfOptions {
        strategy: AsofStrategy::Backward,
        allow_eq: true,
        check_sortedness: true,
        ..AsOfOptions::default()
    };
    left.join(
        right,
        ["t_ns"],
        ["t_ns"],
        JoinArgs::new(JoinType::AsOf(Box::new(options))),
        None,
    )
    .map_err(|e| AnalyzerError::frame(table, e))
}

fn vessel_columns(prefix: &str, v: VesselCols, with_time: bool) -> Vec<Column> {
    let mut cols = Vec::with_capacity(8);
    if with_time {
        let t_s: Vec<f64> = v.t_ns.iter().map(|&t| t as f64 * 1e-9).collect();
        cols.push(i64_col("t_ns", v.t_ns));
        cols.push(f64_col("t_s", t_s));
    } else {
        cols.push(i64_col("t_ns", v.t_ns));
    }
    cols.push(f64_col(&format!("{prefix}_x"), v.x));
    cols.push(f64_col(&format!("{prefix}_y"), v.y));
    cols.push(f64_col(&format!("{prefix}_psi"), v.psi));
    cols.push(f64_col(&format!("{prefix}_u"), v.u));
    cols.push(f64_col(&format!("{prefix}_v"), v.v));
    cols.push(f64_col(&format!("{prefix}_r"), v.r));
    cols
}

/// Builds every frame, taking the columns over (no copy of the plant's vectors). `route`
/// (origin, waypoints, destination: North, East, heading) tells which references were
/// really altered (see `altered_effective`).
///
/// # Errors
/// A polars error (unexpected; the message names the table).
pub fn build(plant: PlantData, controller: ControllerData, route: &[[f64; 3]]) -> Result<Frames> {
    let PlantData {
        ship,
        tug1,
        tug2,
        towlines,
        obstacles,
        inputs,
    } = plant;

    let ship_df = frame("vessels", vessel_columns("ship", ship, true))?;
    let tug1_df = frame("vessels", vessel_columns("tug1", tug1, false))?;
    let tug2_df = frame("vessels", vessel_columns("tug2", tug2, false))?;
    let vessels = asof(&asof(&ship_df, &tug1_df, "vessels")?, &tug2_df, "vessels")?;
    drop((ship_df, tug1_df, tug2_df));

    let [l1, l2] = towlines;
    let line_cols = |k: usize, l: crate::read::TowlineCols| {
        let mut c = Vec::with_capacity(7);
        c.push(i64_col("t_ns", l.t_ns));
        c.push(f64_col(&format!("line{k}_length"), l.length));
        c.push(f64_col(&format!("line{k}_angle"), l.angle));
        c.push(f64_col(&format!("line{k}_tension"), l.tension));
        c.push(f64_col(&format!("line{k}_tension_cmd"), l.tension_cmd));
        c.push(bool_col(&format!("line{k}_slack"), &l.slack));
        c.push(f64_col(
            &format!("line{k}_elongation_error"),
            l.elongation_error,
        ));
        c
    };
    let l1_df = frame("towlines", line_cols(1, l1))?;
    let l2_df = frame("towlines", line_cols(2, l2))?;
    let towlines = asof(&l1_df, &l2_df, "towlines")?;

    let [i1x, i1y, i1n] = inputs.tug1;
    let [i2x, i2y, i2n] = inputs.tug2;
    let [ic1, ic2] = inputs.tension_cmd;
    let inputs = frame(
        "inputs",
        vec![
            i64_col("t_ns", inputs.t_ns),
            f64_col("in_tug1_X", i1x),
            f64_col("in_tug1_Y", i1y),
            f64_col("in_tug1_N", i1n),
            f64_col("in_tug2_X", i2x),
            f64_col("in_tug2_Y", i2y),
            f64_col("in_tug2_N", i2n),
            f64_col("in_tension_cmd1", ic1),
            f64_col("in_tension_cmd2", ic2),
        ],
    )?;

    let name_col = str_col("name", (0..obstacles.t_ns.len()).map(|i| obstacles.name(i)));
    let crate::read::ObstacleCols {
        t_ns,
        slot,
        kind,
        x,
        y,
        psi,
        speed,
        length,
        width,
        ..
    } = obstacles;
    let obstacle_df = frame(
        "obstacles",
        vec![
            i64_col("t_ns", t_ns),
            u32_col("slot", slot),
            name_col,
            i32_col("kind", kind),
            f64_col("obs_x", x),
            f64_col("obs_y", y),
            f64_col("obs_psi", psi),
            f64_col("obs_speed", speed),
            f64_col("obs_length", length),
            f64_col("obs_width", width),
        ],
    )?;
    // Only what the distances, collisions and encounters need.
    let vessel_poses = vessels
        .select([
            "t_ns", "ship_x", "ship_y", "ship_psi", "ship_u", "ship_v", "tug1_x", "tug1_y",
            "tug1_psi", "tug2_x", "tug2_y", "tug2_psi",
        ])
        .map_err(|e| AnalyzerError::frame("obstacles", e))?;
    let joined = asof(&obstacle_df, &vessel_poses, "obstacles")?;
    drop((obstacle_df, vessel_poses));
    let obstacles = with_distances(joined)?;

    let ControllerData {
        reference,
        colregs,
        command,
        solver,
    } = controller;
    let [wpx, wpy, wpp] = reference.waypoint;
    // The guidance's `altered` is its decision; with avoidance scheme III the MPC still
    // tracks the route's waypoint. An alteration is in effect when the waypoint used
    // differs from the route's waypoint of the same index (1-based into the waypoints,
    // the last being the destination: index k of `route`, whose 0 is the origin).
    let effective: Vec<bool> = (0..reference.altered.len())
        .map(|i| {
            let k = reference.active_waypoint[i] as usize;
            reference.altered[i]
                && route
                    .get(k)
                    .is_none_or(|p| (p[0] - wpx[i]).hypot(p[1] - wpy[i]) > 1e-6)
        })
        .collect();
    let reference = frame(
        "reference",
        vec![
            i64_col("t_ns", reference.t_ns),
            f64_col("ref_x", reference.x),
            f64_col("ref_y", reference.y),
            f64_col("ref_psi", reference.psi),
            u32_col("active_waypoint", reference.active_waypoint),
            bool_col("altered", &reference.altered),
            bool_col("altered_effective", &effective),
            f64_col("d_ob", reference.d_ob),
            f64_col("wp_x", wpx),
            f64_col("wp_y", wpy),
            f64_col("wp_psi", wpp),
        ],
    )?;
    // The guidance's alteration flag beside each obstacle row (for the COLREGS first
    // action).
    let altered = reference
        .select(["t_ns", "altered_effective"])
        .map_err(|e| AnalyzerError::frame("obstacles", e))?;
    let obstacles = asof(&obstacles, &altered, "obstacles")?;
    let situation_col = str_col(
        "situation",
        colregs.situation_idx.iter().map(|&k| colregs.label(k)),
    );
    let role_col = str_col("role", colregs.role_idx.iter().map(|&k| colregs.label(k)));
    let colregs_df = frame(
        "colregs",
        vec![
            i64_col("t_ns", colregs.t_ns),
            u32_col("slot", colregs.slot),
            situation_col,
            role_col,
            i32_col("situation_code", colregs.situation_code),
            i32_col("role_code", colregs.role_code),
        ],
    )?;
    let [c1x, c1y, c1n] = command.tug1;
    let [c2x, c2y, c2n] = command.tug2;
    let [ct1, ct2] = command.tension;
    let [ca1, ca2] = command.desired_angle;
    let command = frame(
        "command",
        vec![
            i64_col("t_ns", command.t_ns),
            f64_col("cmd_tug1_X", c1x),
            f64_col("cmd_tug1_Y", c1y),
            f64_col("cmd_tug1_N", c1n),
            f64_col("cmd_tug2_X", c2x),
            f64_col("cmd_tug2_Y", c2y),
            f64_col("cmd_tug2_N", c2n),
            f64_col("cmd_tension1", ct1),
            f64_col("cmd_tension2", ct2),
            f64_col("cmd_angle1", ca1),
            f64_col("cmd_angle2", ca2),
        ],
    )?;
    let fallback_col = opt_str_col(
        "fallback",
        solver.fallback_idx.iter().map(|k| {
            k.and_then(|k| solver.reasons.get(k as usize))
                .map(String::as_str)
        }),
    );
    let crate::read::SolverCols {
        t_ns,
        architecture,
        scheme,
        iterations,
        converged,
        r_pri: [rp1, rp2],
        r_dual: [rd1, rd2],
        compute_time_ms,
        samples,
        fallbacks,
        ..
    } = solver;
    let solver_df = frame(
        "solver",
        vec![
            i64_col("t_ns", t_ns),
            i32_col("architecture", architecture),
            i32_col("scheme", scheme),
            u32_col("iterations", iterations),
            bool_col("converged", &converged),
            f64_col("r_pri1", rp1),
            f64_col("r_pri2", rp2),
            f64_col("r_dual1", rd1),
            f64_col("r_dual2", rd2),
            f64_col("compute_time_ms", compute_time_ms),
            u64_col("samples", samples),
            u64_col("fallbacks", fallbacks),
            fallback_col,
        ],
    )?;

    // The controller's topics on one base: the longest of solver, command, reference.
    let parts = [&solver_df, &command, &reference];
    let base_idx = (0..3).max_by_key(|&k| parts[k].height()).unwrap_or(0);
    let mut controller_df = parts[base_idx].clone();
    for (k, part) in parts.iter().enumerate() {
        if k != base_idx {
            controller_df = asof(&controller_df, part, "controller")?;
        }
    }

    Ok(Frames {
        vessels,
        towlines,
        inputs,
        obstacles,
        reference,
        colregs: colregs_df,
        command,
        solver: solver_df,
        controller: controller_df,
    })
}

/// Adds the centre distances `d_ship`, `d_tug1`, `d_tug2` (m) to the joined obstacle
/// frame: the distance of eq. (30) of Du et al. (2022) before normalisation (static
/// obstacles: eq. (9), the centre distance for the paper's circles; target ships: the
/// distance to the centre).
fn with_distances(mut df: DataFrame) -> Result<DataFrame> {
    let ox = f64s(&df, "obs_x")?;
    let oy = f64s(&df, "obs_y")?;
    let mut add = Vec::new();
    for v in ["ship", "tug1", "tug2"] {
        let x = f64s(&df, &format!("{v}_x"))?;
        let y = f64s(&df, &format!("{v}_y"))?;
        let d: Vec<f64> = (0..ox.len())
            .map(|i| (ox[i] - x[i]).hypot(oy[i] - y[i]))
            .collect();
        add.push(f64_col(&format!("d_{v}"), d));
    }
    for c in add {
        df.with_column(c)
            .map_err(|e| AnalyzerError::frame("obstacles", e))?;
    }
    Ok(df)
}

/// A float column without a copy when it is one chunk of `Float64` without nulls, else
/// copied with nulls as NaN (integer columns are cast).
///
/// # Errors
/// The column is missing or not numeric.
pub fn col<'a>(df: &'a DataFrame, name: &str) -> Result<Cow<'a, [f64]>> {
    let c = df.column(name).map_err(|e| AnalyzerError::frame(name, e))?;
    if let Ok(ca) = c.f64() {
        if let Ok(s) = ca.cont_slice() {
            return Ok(Cow::Borrowed(s));
        }
    }
    Ok(Cow::Owned(f64s(df, name)?))
}

/// A float column as a vector (nulls as NaN); integer columns are cast.
///
/// # Errors
/// The column is missing or not numeric.
pub fn f64s(df: &DataFrame, name: &str) -> Result<Vec<f64>> {
    let col = df.column(name).map_err(|e| AnalyzerError::frame(name, e))?;
    let s = col
        .as_materialized_series()
        .cast(&DataType::Float64)
        .map_err(|e| AnalyzerError::frame(name, e))?;
    let ca = s.f64().map_err(|e| AnalyzerError::frame(name, e))?;
    Ok(ca.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
}

/// An integer column as a vector (nulls as `i64::MIN`).
///
/// # Errors
/// The column is missing or not an integer column.
pub fn i64s(df: &DataFrame, name: &str) -> Result<Vec<i64>> {
    let col = df.column(name).map_err(|e| AnalyzerError::frame(name, e))?;
    let s = col
        .as_materialized_series()
        .cast(&DataType::Int64)
        .map_err(|e| AnalyzerError::frame(name, e))?;
    let ca = s.i64().map_err(|e| AnalyzerError::frame(name, e))?;
    Ok(ca.iter().map(|v| v.unwrap_or(i64::MIN)).collect())
}

/// A boolean column (nulls as `None`).
///
/// # Errors
/// The column is missing or not boolean.
pub fn bools(df: &DataFrame, name: &str) -> Result<Vec<Option<bool>>> {
    let col = df.column(name).map_err(|e| AnalyzerError::frame(name, e))?;
    let ca = col.bool().map_err(|e| AnalyzerError::frame(name, e))?;
    Ok(ca.iter().collect())
}

/// A string column (nulls as empty strings).
///
/// # Errors
/// The column is missing or not a string column.
pub fn strs(df: &DataFrame, name: &str) -> Result<Vec<String>> {
    let col = df.column(name).map_err(|e| AnalyzerError::frame(name, e))?;
    let ca = col.str().map_err(|e| AnalyzerError::frame(name, e))?;
    Ok(ca.iter().map(|v| v.unwrap_or("").to_owned()).collect())
}

/// Seconds from a `t_ns` column.
///
/// # Errors
/// No `t_ns` column.
pub fn seconds(df: &DataFrame) -> Result<Vec<f64>> {
    Ok(i64s(df, "t_ns")?
        .into_iter()
        .map(|t| t as f64 * 1e-9)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::read::{ControllerData, PlantData, ReferenceCols};

    #[test]
    fn an_alteration_is_in_effect_only_off_the_route() {
        let route = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [20.0, 0.0, 0.0]];
        let reference = ReferenceCols {
            t_ns: vec![0, 1_000_000_000, 2_000_000_000],
            x: vec![0.0; 3],
            y: vec![0.0; 3],
            psi: vec![0.0; 3],
            active_waypoint: vec![1, 1, 1],
            // Decided but not tracked (scheme III); decided and tracked; not decided.
            altered: vec![true, true, false],
            d_ob: vec![5.0; 3],
            waypoint: [vec![10.0, 9.6, 10.0], vec![0.0, 2.6, 0.0], vec![0.0; 3]],
        };
        let controller = ControllerData {
            reference,
            ..ControllerData::default()
        };
        let f = build(PlantData::default(), controller, &route).expect("frames");
        let eff = bools(&f.reference, "altered_effective").expect("column");
        assert_eq!(eff, vec![Some(false), Some(true), Some(false)]);
    }
}

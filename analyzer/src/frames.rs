//! The run as polars DataFrames: one per topic family, each with an `Int64` column `t_ns`
//! (log time, ns since simulation time 0), aligned in time by backward as-of joins (the
//! last row of the right table at or before each left row).
//!
//! The controller's frames are built once ([`build_controller`]: the controller log is read
//! whole, about one row per ten plant steps). The plant's frames are built per batch of
//! plant steps while the plant log streams by ([`build_plant_batch`]); a batch ends at a
//! change of log time, and the last row of each right-hand table is carried into the next
//! batch, so every as-of join gives what it would give on the whole log.
//!
//! | frame | rows | columns |
//! |---|---|---|
//! | `vessels` | plant steps | `t_ns`, `t_s`, `{ship,tug1,tug2}_{x,y,psi,u,v,r}` (tugs as-of joined onto the ship's times) |
//! | `towlines` | plant steps | `line{1,2}_{length,angle,tension,tension_cmd,slack,elongation_error}` |
//! | `inputs` | plant steps | `in_tug{1,2}_{X,Y,N}`, `in_tension_cmd{1,2}` |
//! | `obstacles` | plant steps x active slots | `slot`, `name`, `kind`, `obs_{x,y,psi,speed,length,width}`, the vessels' poses joined as of the row's time, the centre distances `d_{ship,tug1,tug2}` and the guidance's `altered_effective` |
//! | `reference`, `command`, `solver` | control samples | the controller's topics |
//! | `colregs` ([`ControllerFrames::colregs_rows`], in chunks) | control samples x slots | the controller's situation and role per slot |
//! | `controller` ([`ControllerFrames::controller_rows`], in chunks) | control samples | the longest of `reference`, `solver`, `command` with the others joined |
//! | `timeseries` ([`PlantBatch::timeseries`]) | plant steps | `vessels` with `towlines`, `inputs` and `controller` joined |

use std::borrow::Cow;

use polars::prelude::*;

use crate::error::{AnalyzerError, Result};
use crate::read::{
    ColregsCols, CommandCols, ControllerData, InputCols, ObstacleCols, PlantData, ReferenceCols,
    SolverCols, TowlineCols, VesselCols,
};

/// The controller's tables (the whole controller log). The joined `controller` table and
/// the long `colregs` table are never whole in memory: they are built per window of rows
/// ([`ControllerFrames::controller_window`], [`ControllerFrames::controller_rows`],
/// [`ControllerFrames::colregs_rows`]).
#[derive(Debug, Clone)]
pub struct ControllerFrames {
    /// Guidance references, with `altered_effective`.
    pub reference: DataFrame,
    /// COLREGS situations (long form, compact: labels interned).
    pub colregs: ColregsCols,
    /// Row order of `colregs` by time (stable; `None`: already in order).
    colregs_order: Option<Vec<usize>>,
    /// Commands.
    pub command: DataFrame,
    /// Solver reports.
    pub solver: DataFrame,
    /// Which of solver (0), command (1), reference (2) is the joined table's base: the
    /// longest (the last of equals).
    base: usize,
}

impl ControllerFrames {
    fn parts(&self) -> [&DataFrame; 3] {
        [&self.solver, &self.command, &self.reference]
    }

    /// Rows of the joined controller table (the solver with the reference and the command
    /// joined as of its times, or whichever of the three is longest as the base).
    #[must_use]
    pub fn controller_height(&self) -> usize {
        self.parts()[self.base].height()
    }

    /// `base_rows` (rows of the base table) with the other two joined as of their times.
    fn joined(&self, base_rows: DataFrame) -> Result<DataFrame> {
        let (lo, hi) = time_span(&base_rows, "controller")?;
        let mut df = base_rows;
        for (k, part) in self.parts().into_iter().enumerate() {
            if k != self.base {
                let t = t_slice(part, "controller")?;
                df = asof(&df, &window(part, &t, lo, hi, "controller")?, "controller")?;
            }
        }
        Ok(df)
    }

    /// Rows `offset .. offset + len` of the joined controller table.
    ///
    /// # Errors
    /// A polars error (unexpected).
    pub fn controller_rows(&self, offset: usize, len: usize) -> Result<DataFrame> {
        let base = self.parts()[self.base];
        let rows = base.slice(i64::try_from(offset).unwrap_or(i64::MAX), len);
        self.joined(sorted(rows, "controller")?)
    }

    /// Rows of the joined controller table an as-of join of plant rows from `lo` to `hi`
    /// (ns) can match.
    ///
    /// # Errors
    /// A polars error (unexpected).
    pub fn controller_window(&self, lo: i64, hi: i64) -> Result<DataFrame> {
        let base = self.parts()[self.base];
        let t = t_slice(base, "controller")?;
        self.joined(window(base, &t, lo, hi, "controller")?)
    }

    fn altered_window(&self, lo: i64, hi: i64) -> Result<DataFrame> {
        let t = t_slice(&self.reference, "obstacles")?;
        let rows = window(&self.reference, &t, lo, hi, "obstacles")?;
        rows.select(["t_ns", "altered_effective"])
            .map_err(|e| AnalyzerError::frame("obstacles", e))
    }

    /// Rows of the colregs table.
    #[must_use]
    pub fn colregs_height(&self) -> usize {
        self.colregs.t_ns.len()
    }

    /// The colregs rows in time order: their indices into [`ControllerFrames::colregs`].
    pub fn colregs_indices(&self) -> impl Iterator<Item = usize> + '_ {
        let n = self.colregs_height();
        (0..n).map(move |i| self.colregs_order.as_ref().map_or(i, |o| o[i]))
    }

    /// Rows `offset .. offset + len` (time order) of the colregs table: `t_ns`, `slot`,
    /// `situation`, `role`, `situation_code`, `role_code`.
    ///
    /// # Errors
    /// A polars error (unexpected).
    pub fn colregs_rows(&self, offset: usize, len: usize) -> Result<DataFrame> {
        let c = &self.colregs;
        let rows: Vec<usize> = self.colregs_indices().skip(offset).take(len).collect();
        let df = DataFrame::new_infer_height(vec![
            i64_col("t_ns", rows.iter().map(|&i| c.t_ns[i]).collect()),
            u32_col("slot", rows.iter().map(|&i| c.slot[i]).collect()),
            str_col(
                "situation",
                rows.iter().map(|&i| c.label(c.situation_idx[i])),
            ),
            str_col("role", rows.iter().map(|&i| c.label(c.role_idx[i]))),
            i32_col(
                "situation_code",
                rows.iter().map(|&i| c.situation_code[i]).collect(),
            ),
            i32_col("role_code", rows.iter().map(|&i| c.role_code[i]).collect()),
        ])
        .map_err(|e| AnalyzerError::frame("colregs", e))?;
        sorted(df, "colregs")
    }
}

/// The `t_ns` column as a slice (borrowed when it is one chunk without nulls).
fn t_slice<'a>(df: &'a DataFrame, table: &str) -> Result<Cow<'a, [i64]>> {
    let c = df
        .column("t_ns")
        .and_then(|c| c.i64())
        .map_err(|e| AnalyzerError::frame(table, e))?;
    if let Ok(s) = c.cont_slice() {
        return Ok(Cow::Borrowed(s));
    }
    Ok(Cow::Owned(
        c.iter().map(|v| v.unwrap_or(i64::MIN)).collect(),
    ))
}

/// The rows of `df` (times `t`, sorted) that a backward as-of join of left rows in
/// `lo ..= hi` can match: from the last time at or before `lo` (all rows of that time) to
/// the last at or before `hi`. Zero-copy.
fn window(df: &DataFrame, t: &[i64], lo: i64, hi: i64, table: &str) -> Result<DataFrame> {
    let j = t.partition_point(|&v| v <= lo);
    let start = if j == 0 {
        0
    } else {
        let tj = t[j - 1];
        t.partition_point(|&v| v < tj)
    };
    let end = t.partition_point(|&v| v <= hi).max(start);
    sorted(
        df.slice(i64::try_from(start).unwrap_or(i64::MAX), end - start),
        table,
    )
}

/// The last row of each right-hand table of the plant's as-of joins, carried from one
/// batch into the next.
#[derive(Debug, Clone, Default)]
pub struct Carry {
    tug1: Option<DataFrame>,
    tug2: Option<DataFrame>,
    line2: Option<DataFrame>,
    vessels: Option<DataFrame>,
    towlines: Option<DataFrame>,
    inputs: Option<DataFrame>,
}

/// The plant's tables of one batch of plant steps.
#[derive(Debug, Clone)]
pub struct PlantBatch {
    /// Vessel states on the ship's time base.
    pub vessels: DataFrame,
    /// Towline states.
    pub towlines: DataFrame,
    /// Plant inputs.
    pub inputs: DataFrame,
    /// Obstacles (long form) with the vessels' poses, the centre distances and the
    /// guidance's alteration flag.
    pub obstacles: DataFrame,
    /// `towlines` after the carried row (the right table of the time-series join).
    towlines_join: DataFrame,
    /// `inputs` after the carried row.
    inputs_join: DataFrame,
}

impl PlantBatch {
    /// The plant-time table of the batch: `vessels` with `towlines`, `inputs` and the
    /// controller's table joined as of each step.
    ///
    /// # Errors
    /// A polars error (unexpected).
    pub fn timeseries(&self, ctrl: &ControllerFrames) -> Result<DataFrame> {
        let (lo, hi) = time_span(&self.vessels, "timeseries")?;
        let mut ts = asof(&self.vessels, &self.towlines_join, "timeseries")?;
        ts = asof(&ts, &self.inputs_join, "timeseries")?;
        ts = asof(&ts, &ctrl.controller_window(lo, hi)?, "timeseries")?;
        Ok(ts)
    }
}

/// First and last `t_ns` of a frame (`(0, -1)` when empty).
fn time_span(df: &DataFrame, table: &str) -> Result<(i64, i64)> {
    let t = df
        .column("t_ns")
        .and_then(|c| c.i64())
        .map_err(|e| AnalyzerError::frame(table, e))?;
    // `ChunkedArray::first` panics on an empty array.
    if t.is_empty() {
        return Ok((0, -1));
    }
    Ok(match (t.get(0), t.get(t.len() - 1)) {
        (Some(a), Some(b)) => (a.min(b), a.max(b)),
        _ => (0, -1),
    })
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

/// A frame from columns, sorted by `t_ns` (see [`sorted`]).
fn frame(table: &str, columns: Vec<Column>) -> Result<DataFrame> {
    let df = DataFrame::new_infer_height(columns).map_err(|e| AnalyzerError::frame(table, e))?;
    sorted(df, table)
}

/// `df` sorted by `t_ns` (stable) if it is not already, with the sorted flag set so as-of
/// joins accept it.
fn sorted(mut df: DataFrame, table: &str) -> Result<DataFrame> {
    let is_sorted = {
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
    if !is_sorted {
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

/// The carried row (if any) followed by `df`, sorted; the new carry is its last row.
fn with_carry(carry: &mut Option<DataFrame>, df: DataFrame, table: &str) -> Result<DataFrame> {
    let joined = match carry.take() {
        Some(c) if c.height() > 0 => {
            let mut c = c;
            c.vstack_mut(&df)
                .map_err(|e| AnalyzerError::frame(table, e))?;
            sorted(c, table)?
        }
        _ => df,
    };
    if joined.height() > 0 {
        *carry = Some(joined.tail(Some(1)));
    }
    Ok(joined)
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

/// Builds the plant's frames of one batch, taking the columns over (no copy of the
/// vectors). `carry` holds the last rows of the previous batch's right-hand tables and is
/// updated; `ctrl` gives the guidance's alteration flag for the obstacle rows.
///
/// # Errors
/// A polars error (unexpected; the message names the table).
pub fn build_plant_batch(
    plant: PlantData,
    carry: &mut Carry,
    ctrl: &ControllerFrames,
) -> Result<PlantBatch> {
    let PlantData {
        ship,
        tug1,
        tug2,
        towlines,
        obstacles,
        inputs,
    } = plant;
    let vessels = vessels_frame(ship, tug1, tug2, carry)?;
    let towlines = towlines_frame(towlines, carry)?;
    let inputs = inputs_frame(inputs)?;
    let obstacles = obstacles_frame(obstacles, &vessels, carry, ctrl)?;
    let towlines_join = with_carry(&mut carry.towlines, towlines.clone(), "timeseries")?;
    let inputs_join = with_carry(&mut carry.inputs, inputs.clone(), "timeseries")?;
    Ok(PlantBatch {
        vessels,
        towlines,
        inputs,
        obstacles,
        towlines_join,
        inputs_join,
    })
}

/// The `vessels` frame: the tugs as-of joined onto the ship's times (their last rows
/// carried in `carry`).
fn vessels_frame(
    ship: VesselCols,
    tug1: VesselCols,
    tug2: VesselCols,
    carry: &mut Carry,
) -> Result<DataFrame> {
    let ship_df = frame("vessels", vessel_columns("ship", ship, true))?;
    let tug1_df = with_carry(
        &mut carry.tug1,
        frame("vessels", vessel_columns("tug1", tug1, false))?,
        "vessels",
    )?;
    let tug2_df = with_carry(
        &mut carry.tug2,
        frame("vessels", vessel_columns("tug2", tug2, false))?,
        "vessels",
    )?;
    asof(&asof(&ship_df, &tug1_df, "vessels")?, &tug2_df, "vessels")
}

/// The columns `t_ns`, `line{k}_*` of towline `k`.
fn towline_columns(k: usize, l: TowlineCols) -> Vec<Column> {
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
}

/// The `towlines` frame: towline 2 as-of joined onto towline 1's times (its last row
/// carried in `carry`).
fn towlines_frame([l1, l2]: [TowlineCols; 2], carry: &mut Carry) -> Result<DataFrame> {
    let l1_df = frame("towlines", towline_columns(1, l1))?;
    let l2_df = with_carry(
        &mut carry.line2,
        frame("towlines", towline_columns(2, l2))?,
        "towlines",
    )?;
    asof(&l1_df, &l2_df, "towlines")
}

/// The `inputs` frame.
fn inputs_frame(inputs: InputCols) -> Result<DataFrame> {
    let [i1x, i1y, i1n] = inputs.tug1;
    let [i2x, i2y, i2n] = inputs.tug2;
    let [ic1, ic2] = inputs.tension_cmd;
    frame(
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
    )
}

/// The `obstacles` frame: the obstacle rows with the poses of `vessels` joined as of their
/// time (the last vessel row carried in `carry`), the centre distances
/// ([`with_distances`]) and the guidance's alteration flag of `ctrl`.
fn obstacles_frame(
    obstacles: ObstacleCols,
    vessels: &DataFrame,
    carry: &mut Carry,
    ctrl: &ControllerFrames,
) -> Result<DataFrame> {
    let name_col = str_col("name", (0..obstacles.t_ns.len()).map(|i| obstacles.name(i)));
    let ObstacleCols {
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
    let vessels_join = with_carry(&mut carry.vessels, vessels.clone(), "obstacles")?;
    let vessel_poses = vessels_join
        .select([
            "t_ns", "ship_x", "ship_y", "ship_psi", "ship_u", "ship_v", "tug1_x", "tug1_y",
            "tug1_psi", "tug2_x", "tug2_y", "tug2_psi",
        ])
        .map_err(|e| AnalyzerError::frame("obstacles", e))?;
    let joined = asof(&obstacle_df, &vessel_poses, "obstacles")?;
    drop((obstacle_df, vessel_poses, vessels_join));
    let obstacles = with_distances(joined)?;
    // The guidance's alteration flag beside each obstacle row (for the COLREGS first
    // action).
    let (lo, hi) = time_span(&obstacles, "obstacles")?;
    asof(&obstacles, &ctrl.altered_window(lo, hi)?, "obstacles")
}

/// Builds the controller's frames, taking the columns over. `route` (origin, waypoints,
/// destination: North, East, heading) tells which references were really altered (see
/// `altered_effective`).
///
/// # Errors
/// A polars error (unexpected; the message names the table).
pub fn build_controller(
    controller: ControllerData,
    route: &[[f64; 3]],
) -> Result<ControllerFrames> {
    let ControllerData {
        reference,
        colregs,
        command,
        solver,
    } = controller;
    let reference = reference_frame(reference, route)?;
    let (colregs, colregs_order) = compact_colregs(colregs);
    let command = command_frame(command)?;
    let solver_df = solver_frame(solver)?;

    // The controller's topics on one base: the longest of solver, command, reference.
    let heights = [solver_df.height(), command.height(), reference.height()];
    let base = (0..3).max_by_key(|&k| heights[k]).unwrap_or(0);
    Ok(ControllerFrames {
        reference,
        colregs,
        colregs_order,
        command,
        solver: solver_df,
        base,
    })
}

/// The `reference` frame, with `altered_effective`: whether an alteration of the waypoint
/// was in effect, given the `route` (origin, waypoints, destination).
fn reference_frame(reference: ReferenceCols, route: &[[f64; 3]]) -> Result<DataFrame> {
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
    frame(
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
    )
}

/// The colregs rows, kept compact (vectors shrunk to fit), with their stable time order if
/// they are not in one.
fn compact_colregs(mut colregs: ColregsCols) -> (ColregsCols, Option<Vec<usize>>) {
    let in_order = colregs.t_ns.windows(2).all(|w| w[0] <= w[1]);
    let colregs_order = (!in_order).then(|| {
        let mut order: Vec<usize> = (0..colregs.t_ns.len()).collect();
        order.sort_by_key(|&i| colregs.t_ns[i]);
        order
    });
    colregs.t_ns.shrink_to_fit();
    colregs.slot.shrink_to_fit();
    colregs.situation_idx.shrink_to_fit();
    colregs.role_idx.shrink_to_fit();
    colregs.situation_code.shrink_to_fit();
    colregs.role_code.shrink_to_fit();
    (colregs, colregs_order)
}

/// The `command` frame.
fn command_frame(command: CommandCols) -> Result<DataFrame> {
    let [c1x, c1y, c1n] = command.tug1;
    let [c2x, c2y, c2n] = command.tug2;
    let [ct1, ct2] = command.tension;
    let [ca1, ca2] = command.desired_angle;
    frame(
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
    )
}

/// The `solver` frame, with the fallback reasons by name.
fn solver_frame(solver: SolverCols) -> Result<DataFrame> {
    let fallback_col = opt_str_col(
        "fallback",
        solver.fallback_idx.iter().map(|k| {
            k.and_then(|k| solver.reasons.get(k as usize))
                .map(String::as_str)
        }),
    );
    let SolverCols {
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
    frame(
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
    )
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
    use crate::read::{ControllerData, ReferenceCols};

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
        let f = build_controller(controller, &route).expect("frames");
        let eff = bools(&f.reference, "altered_effective").expect("column");
        assert_eq!(eff, vec![Some(false), Some(true), Some(false)]);
    }
}

//! What the two subproblems share: the quadratic model of one sequential convex
//! programming (SCP) step, the box-plus-rows QP layout and the trust region.
//!
//! Each subproblem's cost is a sum of weighted squared residuals with a linear term,
//! `sum_k w_k r_k^2 + c_k r_k` (tracking errors, velocities, the ADMM terms), plus
//! smooth convex scalar terms `w phi(d)` (obstacles). With the residuals linearised
//! in the input increments, `r_k ~ r_k + j_k^T du`, the model is the convex QP
//!
//! ```text
//! m(du) = J(u) + g^T du + 1/2 du^T P du,
//! P = sum 2 w_k j_k j_k^T + w phi'' j_d j_d^T,   g = sum j_k (2 w_k r_k + c_k) + w phi' j_d
//! ```
//!
//! (Gauss-Newton: the residuals' curvature is left out, which keeps `P` positive
//! semidefinite). The step is judged by `ratio = (J(u) - J(u + du)) / (m(0) - m(du))`
//! with the true nonlinear cost `J` (from the nonlinear rollout): accepted if
//! `ratio >= accept`, and the trust radius grows (x `grow`, up to `max_radius`) when
//! `ratio >= good`, shrinks (x `shrink`, down to `min_radius`) when `ratio < poor`
//! or the QP gave no usable solution.

use nalgebra::{Matrix6, SMatrix};

use crate::obstacle::{DistanceCost, Obstacle};
use crate::qp::{upper_index, Pattern, Qp, QpBuildError, QpOutcome};

/// Trust-region parameters of the SCP step (dimensionless: the radius multiplies
/// each subproblem's per-variable scale).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScpSettings {
    /// Radius at construction.
    pub initial_radius: f64,
    /// Smallest radius.
    pub min_radius: f64,
    /// Largest radius.
    pub max_radius: f64,
    /// Accept a step when the ratio of actual to predicted decrease is at least this.
    pub accept: f64,
    /// Grow the radius when the ratio is at least this.
    pub good: f64,
    /// Shrink the radius when the ratio is below this.
    pub poor: f64,
    /// Growth factor (> 1).
    pub grow: f64,
    /// Shrink factor (in (0, 1)).
    pub shrink: f64,
}

impl Default for ScpSettings {
    fn default() -> Self {
        ScpSettings {
            initial_radius: 0.5,
            min_radius: 1e-4,
            max_radius: 2.0,
            accept: 0.1,
            good: 0.75,
            poor: 0.25,
            grow: 2.0,
            shrink: 0.25,
        }
    }
}

/// What one SCP step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScpReport {
    /// How the QP ended.
    pub qp: QpOutcome,
    /// Whether the plan was replaced by the candidate.
    pub accepted: bool,
    /// True cost of the plan before the step.
    pub cost_before: f64,
    /// True cost of the plan after the step (= `cost_before` if rejected).
    pub cost_after: f64,
    /// Decrease predicted by the quadratic model (0 if the QP failed).
    pub predicted_decrease: f64,
    /// Actual over predicted decrease (NaN if the QP failed; 1 if nothing was
    /// predicted: converged).
    pub ratio: f64,
    /// Trust radius after the update.
    pub radius: f64,
    /// Interior-point iterations.
    pub qp_iterations: u32,
}

impl ScpReport {
    /// The report of a step whose QP gave no usable solution (`outcome`): the
    /// plan is kept.
    pub(crate) fn rejected(
        outcome: QpOutcome,
        cost_before: f64,
        radius: f64,
        qp_iterations: u32,
    ) -> ScpReport {
        ScpReport {
            qp: outcome,
            accepted: false,
            cost_before,
            cost_after: cost_before,
            predicted_decrease: 0.0,
            ratio: f64::NAN,
            radius,
            qp_iterations,
        }
    }

    /// The report of a step whose QP gave `outcome`, with `costs = [before,
    /// candidate, predicted decrease]` and the trust region's verdict.
    pub(crate) fn judged(
        outcome: QpOutcome,
        costs: [f64; 3],
        accepted: bool,
        ratio: f64,
        radius: f64,
        qp_iterations: u32,
    ) -> ScpReport {
        let [cost_before, cost_candidate, predicted_decrease] = costs;
        ScpReport {
            qp: outcome,
            accepted,
            cost_before,
            cost_after: if accepted {
                cost_candidate
            } else {
                cost_before
            },
            predicted_decrease,
            ratio,
            radius,
            qp_iterations,
        }
    }
}

/// The trust region (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrustRegion {
    settings: ScpSettings,
    radius: f64,
}

impl TrustRegion {
    /// At `settings.initial_radius`.
    #[must_use]
    pub fn new(settings: ScpSettings) -> TrustRegion {
        TrustRegion {
            settings,
            radius: settings.initial_radius,
        }
    }

    /// Current radius.
    #[must_use]
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Back to the initial radius.
    pub fn reset(&mut self) {
        self.radius = self.settings.initial_radius;
    }

    /// Judges a step: returns `(accepted, ratio)` and updates the radius. A
    /// predicted decrease `<= 1e-12 (1 + |J|)` means the plan is (numerically)
    /// stationary in the trust region: the step is not taken (ratio 1, radius
    /// kept), so an accepted step always lowers the true cost strictly.
    pub fn judge(&mut self, cost_before: f64, cost_after: f64, predicted: f64) -> (bool, f64) {
        let s = self.settings;
        let tiny = 1e-12 * (1.0 + cost_before.abs());
        if predicted.is_nan() || predicted <= tiny {
            return (false, 1.0);
        }
        let ratio = (cost_before - cost_after) / predicted;
        let ratio = if ratio.is_finite() { ratio } else { -1.0 };
        if ratio >= s.good {
            self.radius = (self.radius * s.grow).min(s.max_radius);
        } else if ratio < s.poor {
            self.radius = (self.radius * s.shrink).max(s.min_radius);
        }
        (ratio >= s.accept && cost_after < cost_before, ratio)
    }

    /// A failed QP: shrink.
    pub fn fail(&mut self) {
        self.radius = (self.radius * self.settings.shrink).max(self.settings.min_radius);
    }
}

/// The quadratic model of the cost in `n` increments (module docs), accumulated
/// in preallocated buffers. With `value_only` the model is not built, only the
/// cost value (the true cost of a rollout).
#[derive(Debug, Clone)]
pub(crate) struct QuadModel {
    pub p: Vec<f64>,
    pub g: Vec<f64>,
    pub value: f64,
    pub value_only: bool,
}

impl QuadModel {
    pub fn new(n: usize) -> QuadModel {
        QuadModel {
            p: vec![0.0; n * (n + 1) / 2],
            g: vec![0.0; n],
            value: 0.0,
            value_only: false,
        }
    }

    pub fn reset(&mut self, value_only: bool) {
        self.p.fill(0.0);
        self.g.fill(0.0);
        self.value = 0.0;
        self.value_only = value_only;
    }

    /// `w r^2 + c r` with `dr/du = row`.
    pub fn residual(&mut self, r: f64, w: f64, c: f64, row: &[f64]) {
        self.value += w * r * r + c * r;
        if !self.value_only {
            self.rank_one(2.0 * w, row);
            let s = 2.0 * w * r + c;
            for (g, j) in self.g.iter_mut().zip(row) {
                *g += s * j;
            }
        }
    }

    /// `w phi(d)` with `phi(d) = value`, `phi' = slope`, `phi'' = curvature >= 0` and
    /// `dd/du = row`.
    pub fn curved(&mut self, value: f64, slope: f64, curvature: f64, w: f64, row: &[f64]) {
        self.value += w * value;
        if !self.value_only {
            self.rank_one(w * curvature, row);
            for (g, j) in self.g.iter_mut().zip(row) {
                *g += w * slope * j;
            }
        }
    }

    fn rank_one(&mut self, s: f64, row: &[f64]) {
        for (j, rj) in row.iter().enumerate() {
            if *rj == 0.0 {
                continue;
            }
            for (i, ri) in row[..=j].iter().enumerate() {
                self.p[upper_index(i, j)] += s * ri * rj;
            }
        }
    }

    /// `m(0) - m(du) = -(g^T du + 1/2 du^T P du)`.
    pub fn predicted_decrease(&self, du: &[f64]) -> f64 {
        let mut quad = 0.0;
        for j in 0..du.len() {
            for i in 0..j {
                quad += self.p[upper_index(i, j)] * du[i] * du[j];
            }
            quad += 0.5 * self.p[upper_index(j, j)] * du[j] * du[j];
        }
        let lin: f64 = self.g.iter().zip(du).map(|(g, d)| g * d).sum();
        -(lin + quad)
    }
}

/// A QP in `n` increments with a box per variable (rows `2 j`: `du_j <= hi_j`,
/// `2 j + 1`: `-du_j <= -lo_j`) followed by `extra` rows of the given entries
/// (row indices counted from 0 after the box). Returns the QP and, per extra
/// entry, its slot in the value array of `A`.
/// `P` is dense over the first `n_p` variables (the increments) and zero over
/// the rest (the slacks).
pub(crate) fn box_qp(
    n: usize,
    n_p: usize,
    extra_rows: usize,
    extra: &[(usize, usize)],
) -> Result<(Qp, Vec<usize>), QpBuildError> {
    let mut entries: Vec<(usize, usize)> =
        (0..n).flat_map(|j| [(2 * j, j), (2 * j + 1, j)]).collect();
    entries.extend(extra.iter().map(|&(r, c)| (2 * n + r, c)));
    let (pattern, slots) = Pattern::from_entries(2 * n + extra_rows, n, &entries)?;
    let mut qp = Qp::with_p_block(pattern, 0, n_p)?;
    for (k, slot) in slots[..2 * n].iter().enumerate() {
        qp.a_mut()[*slot] = if k % 2 == 0 { 1.0 } else { -1.0 };
    }
    Ok((qp, slots[2 * n..].to_vec()))
}

/// Sets box `j` of a [`box_qp`] to `[lo, hi]`.
pub(crate) fn set_box(qp: &mut Qp, j: usize, lo: f64, hi: f64) {
    let b = qp.b_mut();
    b[2 * j] = hi;
    b[2 * j + 1] = -lo;
}

/// Copies the model into the QP's `P` (dense over the increments, see
/// [`box_qp`]) and `q` (the increments first; any further variables, the slacks,
/// get zero cost here).
pub(crate) fn load_model(qp: &mut Qp, model: &QuadModel) {
    let n = model.g.len();
    qp.p_mut().copy_from_slice(&model.p);
    qp.q_mut()[..n].copy_from_slice(&model.g);
    qp.q_mut()[n..].fill(0.0);
}

/// The hard clearance constraint of the design document, linearised, with an
/// exact L1 penalty on its slack:
///
/// ```text
/// d_j(x_{h+1}) + (dd_j/du) du >= d_min - s_hj,   0 <= s_hj <= s_max,   cost += W s_hj
/// ```
///
/// one row and one slack per sample and obstacle slot. `d` is the distance of
/// [`crate::Obstacle::distance`] (from the obstacle's boundary, focal distance for
/// an ellipse, so `d >= d_min` keeps the vessel's centre outside the circle grown
/// by `d_min`, or the confocal ellipse with semi-major axis `a + d_min`), `d_min`
/// the own hull clearance (about half the own length). The QP is always feasible;
/// the slack is zero whenever the linearised constraint can be met. The penalty
/// `W max(0, d_min - d)` is part of the true cost, so the SCP merit is the exact
/// penalty function. Only the first `max_obstacles` obstacles get rows (all of them
/// enter the distance cost `phi`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClearanceParams {
    /// Obstacle slots (rows per sample), fixed at construction.
    pub max_obstacles: usize,
    /// `d_min` (m).
    pub min_distance: f64,
    /// `W`: L1 penalty on the slack (per m).
    pub penalty: f64,
    /// Upper bound of a slack (m); keeps the QP bounded.
    pub max_slack: f64,
}

impl ClearanceParams {
    /// `max_obstacles = 4`, `W = 1e4`, `s_max = 10 m`, the given `d_min`.
    #[must_use]
    pub fn with_min_distance(min_distance: f64) -> ClearanceParams {
        ClearanceParams {
            max_obstacles: 4,
            min_distance,
            penalty: 1e4,
            max_slack: 10.0,
        }
    }

    /// The penalty term of the true cost at distance `d`.
    #[must_use]
    pub fn penalty_at(&self, d: f64) -> f64 {
        self.penalty * (self.min_distance - d).max(0.0)
    }
}

/// The QP's slack variable is `SLACK_SCALE s` (m): with the penalty `W = 1e4`
/// the unscaled slack's cost dominates the QP's scaling and doubles Clarabel's
/// iterations (measured on the tug problem: 6 without the rows, 11 with them,
/// 8 to 9 with the scale 100; 1e3 and 1e4 are worse again); scaled, the cost entry is
/// `W / SLACK_SCALE`.
pub(crate) const SLACK_SCALE: f64 = 100.0;

/// The clearance rows of one subproblem: layout and the linearisation of the
/// current step (buffers sized at construction). The row of sample `h` has entries
/// for the increments of samples `0..=h` only (causality) and its slack.
#[derive(Debug, Clone)]
pub(crate) struct Clearance {
    params: ClearanceParams,
    /// Number of increments (the first `n_u` variables of the QP).
    n_u: usize,
    /// The QP variable of the first slack (`n_u` unless placed elsewhere).
    first_slack: usize,
    /// Increments per sample.
    per_step: usize,
    horizon: usize,
    /// First clearance row (after the box rows and the other rows).
    first_row: usize,
    /// Per slot `(h, j)` (index `k = h * max_obstacles + j`): the `A` value slots of
    /// the increments of samples `0..=h`, then of the slack, from `offsets[k]`.
    slots: Vec<usize>,
    offsets: Vec<usize>,
    /// Per slot: distance at the linearisation point and `dd/du` (`n_u` each).
    dist: Vec<f64>,
    grad: Vec<f64>,
    active: Vec<bool>,
}

impl Clearance {
    /// Number of slacks.
    pub fn slacks(params: &ClearanceParams, horizon: usize) -> usize {
        params.max_obstacles * horizon
    }

    /// Increments in the row of slot `k`.
    fn width(params: &ClearanceParams, per_step: usize, k: usize) -> usize {
        per_step * (k / params.max_obstacles.max(1) + 1)
    }

    /// The `(row, column)` entries (rows counted from `first_extra_row`, the
    /// numbering of [`box_qp`]'s extra rows), in the order of `slots`.
    pub fn entries(
        params: &ClearanceParams,
        per_step: usize,
        horizon: usize,
        first_extra_row: usize,
    ) -> Vec<(usize, usize)> {
        Clearance::entries_at(
            params,
            per_step,
            horizon,
            first_extra_row,
            per_step * horizon,
        )
    }

    /// As [`Clearance::entries`] with the slacks from QP variable `first_slack`
    /// (several clearance blocks in one QP).
    pub fn entries_at(
        params: &ClearanceParams,
        per_step: usize,
        horizon: usize,
        first_extra_row: usize,
        first_slack: usize,
    ) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for k in 0..Clearance::slacks(params, horizon) {
            for v in 0..Clearance::width(params, per_step, k) {
                out.push((first_extra_row + k, v));
            }
            out.push((first_extra_row + k, first_slack + k));
        }
        out
    }

    /// The layout, with the `A` slots of [`Clearance::entries`] and the index of
    /// the first clearance row in the QP.
    pub fn new(
        params: ClearanceParams,
        per_step: usize,
        horizon: usize,
        first_row: usize,
        slots: Vec<usize>,
    ) -> Clearance {
        let n_u = per_step * horizon;
        Clearance::new_at(params, per_step, horizon, first_row, slots, n_u)
    }

    /// As [`Clearance::new`] with the slacks from QP variable `first_slack`
    /// (the layout of [`Clearance::entries_at`]).
    pub fn new_at(
        params: ClearanceParams,
        per_step: usize,
        horizon: usize,
        first_row: usize,
        slots: Vec<usize>,
        first_slack: usize,
    ) -> Clearance {
        let n = Clearance::slacks(&params, horizon);
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0);
        for k in 0..n {
            offsets.push(offsets[k] + Clearance::width(&params, per_step, k) + 1);
        }
        let n_u = per_step * horizon;
        Clearance {
            params,
            n_u,
            first_slack,
            per_step,
            horizon,
            first_row,
            slots,
            offsets,
            dist: vec![0.0; n],
            grad: vec![0.0; n * n_u],
            active: vec![false; n],
        }
    }

    /// Forgets the last linearisation.
    pub fn clear(&mut self) {
        self.active.fill(false);
    }

    /// Records obstacle `j` at sample `h`: distance `d`, `dd/du = row`.
    pub fn record(&mut self, h: usize, j: usize, d: f64, row: &[f64]) {
        if j >= self.params.max_obstacles || h >= self.horizon {
            return;
        }
        let k = h * self.params.max_obstacles + j;
        self.active[k] = true;
        self.dist[k] = d;
        self.grad[k * self.n_u..(k + 1) * self.n_u].copy_from_slice(&row[..self.n_u]);
    }

    /// Forgets the rows implied by the increments' boxes `[lo_v, hi_v]`: a row
    /// with `min over the box of (dd/du) du >= d_min - d` holds at `s = 0` for every
    /// increment in the box, so its slack (of positive cost, in no other row) is
    /// zero at the optimum and the row never binds: without it the QP has the same
    /// solution (and the penalty `W max(0, d_min - d)` is zero, as is the row's
    /// predicted decrease).
    pub fn drop_redundant(&mut self, lo: &[f64], hi: &[f64]) {
        let n_u = self.n_u;
        for k in 0..self.active.len() {
            if !self.active[k] {
                continue;
            }
            let grad = &self.grad[k * n_u..(k + 1) * n_u];
            let worst: f64 = grad
                .iter()
                .zip(lo.iter().zip(hi))
                .map(|(g, (l, h))| (g * l).min(g * h))
                .sum();
            if worst >= self.params.min_distance - self.dist[k] + 1e-9 {
                self.active[k] = false;
            }
        }
    }

    /// Obstacle slots per sample in use: one more than the highest obstacle index
    /// recorded at any sample (0 if none).
    pub fn slots_used(&self) -> usize {
        let m = self.params.max_obstacles;
        (0..self.active.len())
            .filter(|&k| self.active[k])
            .map(|k| k % m + 1)
            .max()
            .unwrap_or(0)
    }

    /// Takes over the linearisation recorded in `full` (same increments and
    /// horizon, at least as many slots per sample) for this layout's slots. An
    /// unused slot (no row recorded) is a row `-s <= 0` on a slack of positive
    /// cost: its slack is zero at the optimum, so a layout without the unused
    /// slots has the same solution in the increments (and fewer rows).
    pub fn copy_from(&mut self, full: &Clearance) {
        let (m, mf, n_u) = (
            self.params.max_obstacles,
            full.params.max_obstacles,
            self.n_u,
        );
        for k in 0..self.active.len() {
            let kf = (k / m) * mf + k % m;
            self.active[k] = full.active[kf];
            self.dist[k] = full.dist[kf];
            self.grad[k * n_u..(k + 1) * n_u].copy_from_slice(&full.grad[kf * n_u..(kf + 1) * n_u]);
        }
    }

    /// Writes the rows, slack boxes and slack costs into `qp`.
    pub fn load(&self, qp: &mut Qp) {
        let p = &self.params;
        for k in 0..self.active.len() {
            let slots = &self.slots[self.offsets[k]..self.offsets[k + 1]];
            let width = Clearance::width(p, self.per_step, k);
            let active = self.active[k];
            let grad = &self.grad[k * self.n_u..k * self.n_u + width];
            let a = qp.a_mut();
            for (slot, g) in slots.iter().zip(grad) {
                a[*slot] = if active { -g } else { 0.0 };
            }
            a[slots[width]] = -1.0 / SLACK_SCALE;
            qp.b_mut()[self.first_row + k] = if active {
                self.dist[k] - p.min_distance
            } else {
                0.0
            };
            set_box(qp, self.first_slack + k, 0.0, p.max_slack * SLACK_SCALE);
            qp.q_mut()[self.first_slack + k] = p.penalty / SLACK_SCALE;
        }
    }

    /// The model's decrease of the penalty for the solution `x` (increments then
    /// slacks): `W sum (max(0, d_min - d) - s)` over the active slots.
    pub fn predicted_decrease(&self, x: &[f64]) -> f64 {
        let p = &self.params;
        (0..self.active.len())
            .filter(|&k| self.active[k])
            .map(|k| p.penalty_at(self.dist[k]) - p.penalty / SLACK_SCALE * x[self.first_slack + k])
            .sum()
    }
}

/// Condensing (state elimination) of a linearised horizon: with
/// `x_{h+1} = A_h x_h + B_h u_h`, the sensitivity of the predicted state `h` to input `k`
/// is `S[h][k] = B_h` for `k = h` and `A_h S[h-1][k]` for `k < h` (zero for `k > h`).
/// `a[h]`, `b[h]` are the Jacobians of step `h` of the discretised model.
pub(crate) fn condense<const M: usize, const H: usize>(
    a: [&Matrix6<f64>; H],
    b: [&SMatrix<f64, 6, M>; H],
    sens: &mut [[SMatrix<f64, 6, M>; H]; H],
) {
    for h in 0..H {
        let (before, rest) = sens.split_at_mut(h);
        let row = &mut rest[0];
        row[h] = *b[h];
        if let Some(previous) = before.last() {
            for (s, p) in row[..h].iter_mut().zip(&previous[..h]) {
                *s = a[h] * p;
            }
        }
    }
}

/// Loads one SCP step's QP into the smallest of `variants` (one layout per
/// number of clearance slots per sample, the last the full one, which holds the
/// rows recorded at the linearisation) that still holds the clearance rows the
/// boxes `[lo, hi]` leave binding: drops the others, copies the rest into that
/// layout, then loads the quadratic model and the boxes. `parts` gives a
/// variant's QP and clearance rows. Returns the layout's index.
pub(crate) fn load_layout<V>(
    variants: &mut [V],
    parts: fn(&mut V) -> (&mut Qp, &mut Clearance),
    quad: &QuadModel,
    lo: &[f64],
    hi: &[f64],
) -> usize {
    let full = variants.len() - 1;
    let used = {
        let (_, rows) = parts(&mut variants[full]);
        rows.drop_redundant(lo, hi);
        rows.slots_used()
    };
    if used < full {
        let (small, large) = variants.split_at_mut(full);
        let (_, rows) = parts(&mut large[0]);
        parts(&mut small[used]).1.copy_from(rows);
    }
    let (qp, rows) = parts(&mut variants[used]);
    load_model(qp, quad);
    rows.load(qp);
    for (j, (&l, &h)) in lo.iter().zip(hi).enumerate() {
        set_box(qp, j, l, h);
    }
    used
}

/// Solves a loaded step QP of `n_u` input increments: on failure shrinks the
/// trust region and returns the rejected step's report; otherwise the outcome,
/// Clarabel's iterations and the decrease the quadratic model and the
/// clearance penalty predict for the solution (read with `qp.solution()`).
pub(crate) fn solve_layout(
    qp: &mut Qp,
    rows: &Clearance,
    quad: &QuadModel,
    n_u: usize,
    trust: &mut TrustRegion,
) -> Result<(QpOutcome, u32, f64), ScpReport> {
    let outcome = qp.solve();
    let iterations = qp.iterations();
    if !outcome.is_usable() {
        trust.fail();
        return Err(ScpReport::rejected(
            outcome,
            quad.value,
            trust.radius(),
            iterations,
        ));
    }
    let du = qp.solution();
    let predicted = quad.predicted_decrease(&du[..n_u]) + rows.predicted_decrease(du);
    Ok((outcome, iterations, predicted))
}

/// The obstacle terms of one predicted position `pos` (the state after sample
/// `h`; moving obstacles as predicted then, [`Obstacle::after`]) with
/// `d(x, y)/du = (row_x, row_y)` (shared by the tug and ship problems): the
/// distance cost `w phi(d)` of every obstacle and, for the first
/// `params.max_obstacles`, the clearance penalty and (with `clearance`) the
/// linearised row.
#[allow(clippy::too_many_arguments)]
pub(crate) fn obstacle_terms<const N: usize>(
    quad: &mut QuadModel,
    obstacles: &[Obstacle],
    distance: &DistanceCost,
    w: f64,
    params: &ClearanceParams,
    mut clearance: Option<&mut Clearance>,
    h: usize,
    pos: [f64; 2],
    row_x: &[f64; N],
    row_y: &[f64; N],
) {
    for (j, obstacle) in obstacles.iter().enumerate() {
        let (d, grad) = obstacle.after(h + 1).distance(pos);
        let (phi, slope, curvature) = distance.eval(d);
        let mut row = [0.0; N];
        for (r, (a, b)) in row.iter_mut().zip(row_x.iter().zip(row_y)) {
            *r = grad[0] * a + grad[1] * b;
        }
        quad.curved(phi, slope, curvature, w, &row);
        if j < params.max_obstacles {
            quad.value += params.penalty_at(d);
            if let Some(c) = clearance.as_deref_mut() {
                c.record(h, j, d, &row);
            }
        }
    }
}

/// `a - b` wrapped to `(-pi, pi]` (heading differences).
#[must_use]
pub fn angle_difference(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI {
        d - TAU
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_matches_a_quadratic() {
        // r1 = 1 + 2 du0 - du1 (w = 3, c = 0.5), r2 = -1 + du1 (w = 1)
        let mut m = QuadModel::new(2);
        m.reset(false);
        m.residual(1.0, 3.0, 0.5, &[2.0, -1.0]);
        m.residual(-1.0, 1.0, 0.0, &[0.0, 1.0]);
        let cost = |d: [f64; 2]| {
            let r1 = 1.0 + 2.0 * d[0] - d[1];
            let r2 = -1.0 + d[1];
            3.0 * r1 * r1 + 0.5 * r1 + r2 * r2
        };
        for d in [[0.1, -0.2], [1.0, 2.0], [-0.3, 0.0]] {
            let pred = m.predicted_decrease(&d);
            assert!((pred - (cost([0.0; 2]) - cost(d))).abs() < 1e-12);
        }
        assert!((m.value - cost([0.0; 2])).abs() < 1e-12);
    }

    #[test]
    fn trust_region_grows_and_shrinks() {
        let mut tr = TrustRegion::new(ScpSettings::default());
        let r0 = tr.radius();
        assert_eq!(tr.judge(10.0, 9.0, 1.0), (true, 1.0));
        assert!(tr.radius() > r0);
        let r1 = tr.radius();
        let (acc, _) = tr.judge(10.0, 11.0, 1.0);
        assert!(!acc && tr.radius() < r1);
    }

    #[test]
    fn angle_difference_wraps() {
        use std::f64::consts::PI;
        assert!((angle_difference(PI - 0.1, -PI + 0.1) + 0.2).abs() < 1e-12);
        assert!((angle_difference(0.3, 0.1) - 0.2).abs() < 1e-12);
        assert!((angle_difference(7.0, 0.0) - (7.0 - 2.0 * PI)).abs() < 1e-12);
    }
}

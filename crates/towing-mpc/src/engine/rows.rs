//! Soft constraints of the step QP: linearised rows whose violation is a slack
//! variable with an exact L1 penalty (Nocedal and Wright 2006, section 17.2: the
//! `l1` penalty is exact for a weight above the constraint's multiplier). The QP is
//! therefore always feasible, the slack is zero whenever the linearised row can be
//! met, and the penalty `W max(0, violation)` is part of the true merit, so the SCP
//! judges its steps on the exact penalty function.
//!
//! Two kinds, each written once:
//!
//! - [`SlotRows`]: one-sided rows `v_k + g_k^T du >= b_k - s_k`, a fixed number of
//!   *slots* per sample (the clearance to each of the nearest obstacles; any
//!   one-sided bound of a predicted quantity: a waterway edge, a speed);
//! - [`PairRows`]: two-sided rows `|r_m + g_m^T du| <= s_m` (a soft equality: the
//!   centralized problem's configuration restriction).
//!
//! A row of sample `h` has entries for the increments of samples `0..=h` only
//! (causality). A one-sided row's slack has a box `[0, s_max]` (among the QP's
//! box rows); a two-sided row's slack needs none (the pair implies `s >= 0`, and
//! the boxed increments bound it). The recorded values live in the block, sized for the largest
//! layout; a [`BlockLayout`] maps them onto one QP. A subproblem lists its blocks
//! in a [`RowSet`]: a new constraint is a new block in that set, recorded where the
//! subproblem computes its terms.

use crate::qp::Qp;

/// The QP's slack variable is `SLACK_SCALE s` (m): with the penalty `W = 1e4`
/// the unscaled slack's cost dominates the QP's scaling and doubles Clarabel's
/// iterations (measured on the tug problem: 6 without the rows, 11 with them,
/// 8 to 9 with the scale 100; 1e3 and 1e4 are worse again); scaled, the cost entry is
/// `W / SLACK_SCALE`.
pub(crate) const SLACK_SCALE: f64 = 100.0;

/// Sets box `j` (rows `2 j`: `x <= hi`, `2 j + 1`: `-x <= -lo` of the `j`-th
/// boxed variable; the increments' boxes come first, `j` = the increment) of a
/// step QP.
pub(crate) fn set_box(qp: &mut Qp, j: usize, lo: f64, hi: f64) {
    let b = qp.b_mut();
    b[2 * j] = hi;
    b[2 * j + 1] = -lo;
}

/// Where a block's rows, slacks and `A` entries sit in one QP.
#[derive(Debug, Clone)]
pub(crate) struct BlockLayout {
    /// Rows per sample (slot blocks) in this layout.
    slots: usize,
    /// First QP row.
    first_row: usize,
    /// First slack variable.
    first_slack: usize,
    /// The box of the first slack (boxed slacks only).
    first_box: usize,
    /// Per `A` entry of the block, row by row (from `offsets[k]`): its value
    /// slot and its column (an increment, or a slack).
    a: Vec<usize>,
    cols: Vec<usize>,
    offsets: Vec<usize>,
}

/// Which increments a row of a block can touch: those of samples `0..=h`
/// (causality) whose channel moves a vessel the row involves
/// ([`super::Channel::moves`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reach<'a> {
    /// Per increment, the vessels its channel moves.
    pub moves: &'a [u8],
    /// Increments per sample.
    pub per_step: usize,
}

impl Reach<'_> {
    /// The increments a row of sample `h` about `vessels` depends on.
    fn columns(&self, h: usize, vessels: u8) -> impl Iterator<Item = usize> + '_ {
        (0..self.per_step * (h + 1)).filter(move |&v| self.moves[v] & vessels != 0)
    }
}

/// A block's rows in one layout: sizes and entries, row by row.
struct Entries {
    rows: usize,
    slacks: usize,
    /// Whether the slacks have boxes.
    boxed: bool,
    slots: usize,
    entries: Vec<(usize, usize)>,
    offsets: Vec<usize>,
}

impl Entries {
    fn new(slots: usize) -> Entries {
        Entries {
            rows: 0,
            slacks: 0,
            boxed: false,
            slots,
            entries: Vec::new(),
            offsets: vec![0],
        }
    }

    /// Ends the entries of one (or a pair of) row(s).
    fn close_row(&mut self) {
        self.offsets.push(self.entries.len());
    }
}

/// One-sided soft rows with `slots` rows per sample (module docs). Row
/// `k = h slots + j` is slot `j` of sample `h`.
#[derive(Debug, Clone)]
pub struct SlotRows {
    slots: usize,
    horizon: usize,
    n_u: usize,
    /// The vessels whose states the rows involve (a bit per vessel).
    vessels: u8,
    /// `W` (per unit of the row).
    penalty: f64,
    /// Upper bound of a slack (the row's unit).
    max_slack: f64,
    value: Vec<f64>,
    bound: Vec<f64>,
    grad: Vec<f64>,
    active: Vec<bool>,
    /// Per sample (`h slots ..`), the slots in layout order: the active ones
    /// first, in slot order, then the others ([`SlotRows::compact`]).
    order: Vec<usize>,
}

impl SlotRows {
    /// `slots` rows per sample over `horizon` samples of `per_step` increments,
    /// about the states of `vessels` (a bit per vessel, as
    /// [`super::Channel::moves`]), penalty `W` on slacks in `[0, max_slack]`.
    #[must_use]
    pub fn new(
        slots: usize,
        (horizon, per_step): (usize, usize),
        vessels: u8,
        penalty: f64,
        max_slack: f64,
    ) -> SlotRows {
        let n = slots * horizon;
        let n_u = per_step * horizon;
        SlotRows {
            slots,
            horizon,
            n_u,
            vessels,
            penalty,
            max_slack,
            value: vec![0.0; n],
            bound: vec![0.0; n],
            grad: vec![0.0; n * n_u],
            active: vec![false; n],
            order: (0..n).map(|k| k % slots.max(1)).collect(),
        }
    }

    /// Rows per sample.
    #[must_use]
    pub fn slots(&self) -> usize {
        self.slots
    }

    /// Forgets the last linearisation.
    pub fn clear(&mut self) {
        self.active.fill(false);
    }

    /// The value and gradient recorded for slot `j` of sample `h` (`None`: not recorded);
    /// for the tests' finite-difference checks.
    #[cfg(test)]
    #[must_use]
    pub(crate) fn recorded(&self, h: usize, j: usize) -> Option<(f64, &[f64])> {
        let k = h * self.slots + j;
        (j < self.slots && h < self.horizon && self.active[k])
            .then(|| (self.value[k], &self.grad[k * self.n_u..(k + 1) * self.n_u]))
    }

    /// Records slot `j` of sample `h`: `value + row^T du >= bound - s` (`row` over
    /// the increments; entries beyond them are ignored). Out-of-range slots are
    /// ignored.
    pub fn record(&mut self, h: usize, j: usize, value: f64, bound: f64, row: &[f64]) {
        if j >= self.slots || h >= self.horizon {
            return;
        }
        let k = h * self.slots + j;
        self.active[k] = true;
        self.value[k] = value;
        self.bound[k] = bound;
        self.grad[k * self.n_u..(k + 1) * self.n_u].copy_from_slice(&row[..self.n_u]);
    }

    /// Forgets the rows implied by the increments' boxes `[lo_v, hi_v]`: a row
    /// with `min over the box of g^T du >= b - v` holds at `s = 0` for every
    /// increment in the box, so its slack (of positive cost, in no other row) is
    /// zero at the optimum and the row never binds: without it the QP has the same
    /// solution (and the penalty `W max(0, b - v)` is zero, as is the row's
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
            if worst >= self.bound[k] - self.value[k] + 1e-9 {
                self.active[k] = false;
            }
        }
    }

    /// Orders each sample's slots, the active ones first, so that a layout with
    /// as many rows per sample as the busiest sample has active rows holds them
    /// all ([`SlotRows::slots_used`]): which slot a row was recorded in does not
    /// matter to the QP.
    pub fn compact(&mut self) {
        let m = self.slots;
        for h in 0..self.horizon {
            let range = h * m..(h + 1) * m;
            let active = &self.active[range.clone()];
            let order = &mut self.order[range];
            let mut next = 0;
            for first in [true, false] {
                for j in (0..m).filter(|&j| active[j] == first) {
                    order[next] = j;
                    next += 1;
                }
            }
        }
    }

    /// Rows per sample in use: the most active rows of any sample; 0 if none.
    #[must_use]
    pub fn slots_used(&self) -> usize {
        self.active
            .chunks(self.slots.max(1))
            .map(|sample| sample.iter().filter(|&&a| a).count())
            .max()
            .unwrap_or(0)
    }

    /// The recorded row behind layout row `k` of a layout with `m` slots.
    fn source(&self, m: usize, k: usize) -> usize {
        let h = k / m;
        h * self.slots + self.order[h * self.slots + k % m]
    }

    /// One row per layout row, its slack boxed.
    fn entries(
        &self,
        slots: usize,
        reach: Reach<'_>,
        first_row: usize,
        first_slack: usize,
    ) -> Entries {
        let m = slots.min(self.slots);
        let mut e = Entries::new(m);
        for k in 0..m * self.horizon {
            let row = first_row + k;
            for v in reach.columns(k / m, self.vessels) {
                e.entries.push((row, v));
            }
            e.entries.push((row, first_slack + k));
            e.close_row();
        }
        e.rows = m * self.horizon;
        e.slacks = m * self.horizon;
        e.boxed = true;
        e
    }

    /// Writes the rows of `layout` (`-g^T du - s / SC <= v - b`; an inactive one
    /// `-s / SC <= 0`), the slack boxes and their costs into `qp`.
    fn load(&self, layout: &BlockLayout, qp: &mut Qp) {
        let m = layout.slots;
        for k in 0..m * self.horizon {
            let kf = self.source(m, k);
            let span = layout.offsets[k]..layout.offsets[k + 1];
            let (slots, cols) = (&layout.a[span.clone()], &layout.cols[span]);
            let n_inc = slots.len() - 1;
            let active = self.active[kf];
            let grad = &self.grad[kf * self.n_u..(kf + 1) * self.n_u];
            let a = qp.a_mut();
            for (slot, &col) in slots[..n_inc].iter().zip(&cols[..n_inc]) {
                a[*slot] = if active { -grad[col] } else { 0.0 };
            }
            a[slots[n_inc]] = -1.0 / SLACK_SCALE;
            qp.b_mut()[layout.first_row + k] = if active {
                self.value[kf] - self.bound[kf]
            } else {
                0.0
            };
            set_box(qp, layout.first_box + k, 0.0, self.max_slack * SLACK_SCALE);
            qp.q_mut()[layout.first_slack + k] = self.penalty / SLACK_SCALE;
        }
    }

    /// The model's decrease of the penalty for the solution `x` (increments then
    /// slacks): `W sum (max(0, b - v) - s)` over the active rows.
    fn predicted_decrease(&self, layout: &BlockLayout, x: &[f64]) -> f64 {
        let m = layout.slots;
        (0..m * self.horizon)
            .filter(|&k| self.active[self.source(m, k)])
            .map(|k| {
                let kf = self.source(m, k);
                self.penalty * (self.bound[kf] - self.value[kf]).max(0.0)
                    - self.penalty / SLACK_SCALE * x[layout.first_slack + k]
            })
            .sum()
    }
}

/// Two-sided soft rows `|r_m + g_m^T du| <= s_m` (module docs), each of a given
/// sample and about given vessels.
#[derive(Debug, Clone)]
pub struct PairRows {
    /// Per row: its sample (its causal width) and the vessels it involves.
    rows: Vec<(usize, u8)>,
    n_u: usize,
    /// `W` (per unit of the row).
    penalty: f64,
    value: Vec<f64>,
    grad: Vec<f64>,
}

impl PairRows {
    /// Rows of the given `(sample, vessels)` over `n_u` increments, penalty `W`.
    #[must_use]
    pub fn new(rows: Vec<(usize, u8)>, n_u: usize, penalty: f64) -> PairRows {
        let n = rows.len();
        PairRows {
            rows,
            n_u,
            penalty,
            value: vec![0.0; n],
            grad: vec![0.0; n * n_u],
        }
    }

    /// Records row `m`: residual `r` and `dr/du = row` (over the increments).
    pub fn record(&mut self, m: usize, r: f64, row: &[f64]) {
        self.value[m] = r;
        self.grad[m * self.n_u..(m + 1) * self.n_u].copy_from_slice(&row[..self.n_u]);
    }

    /// The recorded residual of row `m`.
    #[must_use]
    pub fn value(&self, m: usize) -> f64 {
        self.value[m]
    }

    /// The recorded `dr/du` of row `m`.
    #[must_use]
    pub fn gradient(&self, m: usize) -> &[f64] {
        &self.grad[m * self.n_u..(m + 1) * self.n_u]
    }

    /// Rows `2 m` and `2 m + 1` per row `m`, sharing its slack.
    fn entries(&self, reach: Reach<'_>, first_row: usize, first_slack: usize) -> Entries {
        let n = self.rows.len();
        let mut e = Entries::new(n);
        for (m, &(h, vessels)) in self.rows.iter().enumerate() {
            for sign in 0..2 {
                let row = first_row + 2 * m + sign;
                e.entries
                    .extend(reach.columns(h, vessels).map(|v| (row, v)));
                e.entries.push((row, first_slack + m));
            }
            e.close_row();
        }
        e.rows = 2 * n;
        e.slacks = n;
        e
    }

    /// Rows `r + g^T du - s / SC <= 0` and `-(r + g^T du) - s / SC <= 0` and the
    /// slack costs.
    fn load(&self, layout: &BlockLayout, qp: &mut Qp) {
        for m in 0..self.rows.len() {
            let span = layout.offsets[m]..layout.offsets[m + 1];
            let (slots, cols) = (&layout.a[span.clone()], &layout.cols[span]);
            let half = slots.len() / 2;
            let grad = &self.grad[m * self.n_u..(m + 1) * self.n_u];
            for (part, sign) in [1.0, -1.0].into_iter().enumerate() {
                let (slots, cols) = (&slots[part * half..(part + 1) * half], &cols[..half - 1]);
                let a = qp.a_mut();
                for (slot, &col) in slots.iter().zip(cols) {
                    a[*slot] = sign * grad[col];
                }
                a[slots[half - 1]] = -1.0 / SLACK_SCALE;
                qp.b_mut()[layout.first_row + 2 * m + part] = -sign * self.value[m];
            }
            qp.q_mut()[layout.first_slack + m] = self.penalty / SLACK_SCALE;
        }
    }

    /// Adds the penalty's decrease from the linear model itself, `W (|r| -
    /// |r + g^T du|)` per row, not from the slacks: their solver tolerance (about
    /// 1e-6 each, times `W`) would swamp small steps and keep the trust ratio
    /// near 0.6.
    fn add_predicted_decrease(&self, du: &[f64], acc: &mut f64) {
        for m in 0..self.rows.len() {
            let grad = &self.grad[m * self.n_u..(m + 1) * self.n_u];
            let lin: f64 = self.value[m]
                + grad
                    .iter()
                    .zip(&du[..self.n_u])
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            *acc += self.penalty * (self.value[m].abs() - lin.abs());
        }
    }
}

/// A block of a [`RowSet`], by reference.
#[derive(Debug)]
pub enum Block<'a> {
    /// One-sided rows.
    Slots(&'a SlotRows),
    /// Two-sided rows.
    Pairs(&'a PairRows),
}

/// A block of a [`RowSet`], mutable.
#[derive(Debug)]
pub enum BlockMut<'a> {
    /// One-sided rows.
    Slots(&'a mut SlotRows),
    /// Two-sided rows.
    Pairs(&'a mut PairRows),
}

/// A subproblem's soft rows: its blocks in QP order (rows and slacks follow the
/// box rows and the rate rows in this order).
pub trait RowSet: std::fmt::Debug {
    /// The blocks, in QP order.
    fn blocks(&self) -> impl Iterator<Item = Block<'_>>;
    /// The blocks, in QP order, mutable.
    fn blocks_mut(&mut self) -> impl Iterator<Item = BlockMut<'_>>;

    /// Forgets the last linearisation of every one-sided block (two-sided rows
    /// are recorded in full each time).
    fn clear(&mut self) {
        for b in self.blocks_mut() {
            if let BlockMut::Slots(s) = b {
                s.clear();
            }
        }
    }
}

/// A block placed in one QP: first row (after the boxes), first slack, slots,
/// its entries' range in [`Placement::entries`] and its row offsets.
struct Placed {
    first_row: usize,
    first_slack: usize,
    first_box: usize,
    slots: usize,
    start: usize,
    offsets: Vec<usize>,
}

/// The blocks of a [`RowSet`] placed in one QP.
pub(crate) struct Placement {
    /// Every block's `(row, column)` entries (rows counted after the box rows).
    pub entries: Vec<(usize, usize)>,
    /// The variables with a box, in box order: the increments, then the boxed
    /// slacks.
    pub boxed: Vec<usize>,
    blocks: Vec<Placed>,
    /// Extra rows in all (after the box rows).
    pub rows: usize,
    /// Variables in all.
    pub variables: usize,
}

/// The layout of every block of `rows` in a QP with `slots[b]` slots per sample
/// for block `b` (ignored for two-sided blocks), its rows from extra row
/// `first_row` and its slacks from variable `first_slack` on (the increments
/// `0..first_slack` are boxed).
pub(crate) fn layout_entries(
    rows: &impl RowSet,
    slots: &[usize],
    reach: Reach<'_>,
    mut first_row: usize,
    mut first_slack: usize,
) -> Placement {
    let mut entries = Vec::new();
    let mut boxed: Vec<usize> = (0..first_slack).collect();
    let mut blocks = Vec::new();
    for (block, &slots) in rows.blocks().zip(slots) {
        let e = match block {
            Block::Slots(s) => s.entries(slots, reach, first_row, first_slack),
            Block::Pairs(p) => p.entries(reach, first_row, first_slack),
        };
        blocks.push(Placed {
            first_row,
            first_slack,
            first_box: boxed.len(),
            slots: e.slots,
            start: entries.len(),
            offsets: e.offsets,
        });
        if e.boxed {
            boxed.extend(first_slack..first_slack + e.slacks);
        }
        first_row += e.rows;
        first_slack += e.slacks;
        entries.extend(e.entries);
    }
    Placement {
        entries,
        boxed,
        blocks,
        rows: first_row,
        variables: first_slack,
    }
}

impl Placement {
    /// The [`BlockLayout`]s, from the `A` slots of the entries (`a_slots`, in
    /// entry order) and the QP row of extra row 0.
    pub(crate) fn block_layouts(&self, a_slots: &[usize], extra_row0: usize) -> Vec<BlockLayout> {
        self.blocks
            .iter()
            .map(|b| {
                let len = b.offsets.last().copied().unwrap_or(0);
                let range = b.start..b.start + len;
                BlockLayout {
                    slots: b.slots,
                    first_row: extra_row0 + b.first_row,
                    first_slack: b.first_slack,
                    first_box: b.first_box,
                    a: a_slots[range.clone()].to_vec(),
                    cols: self.entries[range].iter().map(|e| e.1).collect(),
                    offsets: b.offsets.clone(),
                }
            })
            .collect()
    }
}

/// Drops the one-sided rows the boxes imply and writes, per block, the slots per
/// sample the step needs (0 for two-sided blocks) into `used`: the layout to use.
pub(crate) fn prune(rows: &mut impl RowSet, lo: &[f64], hi: &[f64], used: &mut Vec<usize>) {
    used.clear();
    for b in rows.blocks_mut() {
        used.push(match b {
            BlockMut::Slots(s) => {
                s.drop_redundant(lo, hi);
                s.compact();
                s.slots_used()
            }
            BlockMut::Pairs(_) => 0,
        });
    }
}

/// Per block, the most slots per sample it can use (0 for two-sided blocks).
pub(crate) fn full_slots(rows: &impl RowSet) -> Vec<usize> {
    rows.blocks()
        .map(|b| match b {
            Block::Slots(s) => s.slots(),
            Block::Pairs(_) => 0,
        })
        .collect()
}

/// Writes every block's rows into `qp` (the layouts of that QP).
pub(crate) fn load(rows: &impl RowSet, layouts: &[BlockLayout], qp: &mut Qp) {
    for (block, layout) in rows.blocks().zip(layouts) {
        match block {
            Block::Slots(s) => s.load(layout, qp),
            Block::Pairs(p) => p.load(layout, qp),
        }
    }
}

/// The blocks' predicted decrease of their penalties for the QP solution `x`,
/// added to `acc`: the one-sided blocks first (each as one sum), then the
/// two-sided ones (row by row).
pub(crate) fn add_predicted_decrease(
    rows: &impl RowSet,
    layouts: &[BlockLayout],
    x: &[f64],
    n_u: usize,
    acc: &mut f64,
) {
    for (block, layout) in rows.blocks().zip(layouts) {
        if let Block::Slots(s) = block {
            *acc += s.predicted_decrease(layout, x);
        }
    }
    for block in rows.blocks() {
        if let Block::Pairs(p) = block {
            p.add_predicted_decrease(&x[..n_u], acc);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The active rows of each sample come first, in slot order, and the busiest
    /// sample sets the rows per sample a layout needs; a row dropped as implied by
    /// the boxes no longer counts.
    #[test]
    fn compact_puts_each_samples_active_rows_first() {
        let (slots, horizon, per_step) = (4, 3, 2);
        let mut rows = SlotRows::new(slots, (horizon, per_step), 1, 1e4, 10.0);
        let n_u = per_step * horizon;
        let row = |c: f64| vec![c; n_u];
        rows.record(0, 3, 0.0, 1.0, &row(1.0));
        rows.record(1, 1, 0.0, 1.0, &row(1.0));
        rows.record(1, 2, 0.0, 1.0, &row(1.0));
        rows.compact();
        assert_eq!(rows.slots_used(), 2);
        // Layout of 2 rows per sample: row k of sample h is the recorded slot below.
        let m = 2;
        assert_eq!(rows.source(m, 0), 3);
        assert_eq!(rows.source(m, 2), slots + 1);
        assert_eq!(rows.source(m, 3), slots + 2);
        assert!(rows.active[rows.source(m, 0)] && !rows.active[rows.source(m, 1)]);
        assert!((4..6).all(|k| !rows.active[rows.source(m, k)]));
        // A box that implies slot 3 of sample 0 (its bound met for every increment
        // in it) leaves sample 1 alone the busiest.
        rows.record(0, 3, 2.0, 1.0, &row(0.0));
        rows.drop_redundant(&[-1.0; 6], &[1.0; 6]);
        rows.compact();
        assert_eq!(rows.slots_used(), 2);
        assert!(!rows.active[3]);
        rows.clear();
        rows.compact();
        assert_eq!(rows.slots_used(), 0);
    }
}

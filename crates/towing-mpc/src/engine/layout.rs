//! The QPs of one subproblem: one per combination of soft-row slots per sample
//! (block by block) in use, built when a step first needs it and updated in place
//! afterwards.
//!
//! Variables: the increments, then each block's slacks in block order. Rows: two
//! box rows per increment (`2 j`: `x_j <= hi_j`, `2 j + 1`: `-x_j <= -lo_j`) and
//! per boxed slack, then the rate rows, then each block's rows. `P` is dense over the increments and
//! zero over the slacks. A step uses the smallest layout that holds the rows
//! recorded, each block with as many rows per sample as its busiest sample has
//! active rows ([`super::SlotRows::compact`]; an unused slot would be a row
//! `-s <= 0` on a slack of positive cost: its slack is zero at the optimum, so a
//! layout without it has the same solution in the increments, and fewer rows and
//! variables). A layout built late gives the same bits as one built early: the QP's
//! structure and initial values, hence Clarabel's equilibration, depend on the
//! combination alone, and no solve carries anything to the next.

use super::quad::QuadModel;
use super::rows::{self, set_box, BlockLayout, RowSet};
use super::space::InputSpace;
use crate::qp::{Pattern, Qp, QpBuildError, QpOutcome};

/// One QP layout.
#[derive(Debug)]
pub(crate) struct Layout {
    qp: Qp,
    /// First rate row.
    rate_row: usize,
    blocks: Vec<BlockLayout>,
}

impl Layout {
    /// The layout of `rows` with `slots[b]` slots per sample in block `b`.
    fn new(
        space: &InputSpace,
        rows: &impl RowSet,
        slots: &[usize],
    ) -> Result<Layout, QpBuildError> {
        let n_u = space.len();
        let rate = space.rate_entries(0);
        let n_rate = rate.len();
        let mut entries: Vec<(usize, usize)> = rate.iter().map(|(e, _)| *e).collect();
        let moves = space.moves();
        let reach = rows::Reach {
            moves: &moves,
            per_step: space.per_step(),
        };
        let placed = rows::layout_entries(rows, slots, reach, space.rate_rows(), n_u);
        let n = placed.variables;
        entries.extend(&placed.entries);
        let (mut qp, a_slots) = box_qp(space, n, &placed.boxed, placed.rows, &entries)?;
        for (slot, (_, v)) in a_slots[..n_rate].iter().zip(&rate) {
            qp.a_mut()[*slot] = *v;
        }
        let rate_row = 2 * placed.boxed.len();
        let blocks = placed.block_layouts(&a_slots[n_rate..], rate_row);
        Ok(Layout {
            qp,
            rate_row,
            blocks,
        })
    }

    /// Solves the loaded QP: the outcome, Clarabel's iterations and the decrease
    /// the quadratic model and the soft rows predict for the solution; or the
    /// failed outcome and its iterations.
    pub(crate) fn solve(
        &mut self,
        rows: &impl RowSet,
        quad: &QuadModel,
        n_u: usize,
    ) -> Result<(QpOutcome, u32, f64), (QpOutcome, u32)> {
        let outcome = self.qp.solve();
        let iterations = self.qp.iterations();
        if !outcome.is_usable() {
            return Err((outcome, iterations));
        }
        let x = self.qp.solution();
        let mut predicted = quad.predicted_decrease(&x[..n_u]);
        rows::add_predicted_decrease(rows, &self.blocks, x, n_u, &mut predicted);
        Ok((outcome, iterations, predicted))
    }

    /// The QP.
    pub(crate) fn qp(&self) -> &Qp {
        &self.qp
    }
}

/// Layouts kept at most (the least recently used one is replaced): a combination met
/// again after its layout was dropped is built again, with the same bits (module docs). A run meets a few dozen
/// combinations (the paper scenario 12 centralized).
const MAX_LAYOUTS: usize = 64;

/// The layouts of a subproblem met so far, by slots per sample of each block, with
/// the step each was last used at; the one last loaded, and the key of the step
/// being loaded.
#[derive(Debug)]
pub(crate) struct Layouts {
    layouts: Vec<(Vec<usize>, Layout, u64)>,
    used: usize,
    steps: u64,
    key: Vec<usize>,
}

impl Layouts {
    /// The layout with every slot of every block (which checks that the QPs of
    /// `rows` can be built) and the one without soft rows.
    pub(crate) fn new(space: &InputSpace, rows: &impl RowSet) -> Result<Layouts, QpBuildError> {
        let full = rows::full_slots(rows);
        let none = vec![0; full.len()];
        let mut layouts = Vec::with_capacity(MAX_LAYOUTS);
        for key in [none, full] {
            let layout = Layout::new(space, rows, &key)?;
            layouts.push((key, layout, 0));
        }
        Ok(Layouts {
            layouts,
            used: 0,
            steps: 0,
            key: Vec::new(),
        })
    }

    /// Loads one step: drops the soft rows the boxes `[lo, hi]` imply, picks the
    /// smallest layout holding the rest (built if not met before, the least recently
    /// used one dropped beyond [`MAX_LAYOUTS`]) and writes the quadratic model, the
    /// boxes, the rate rows (from `plan`) and the soft rows into it.
    ///
    /// # Errors
    /// A layout that cannot be built (not expected: its structure is a part of the
    /// full layout's, built at construction).
    pub(crate) fn load(
        &mut self,
        space: &InputSpace,
        rows: &mut impl RowSet,
        quad: &QuadModel,
        plan: &[f64],
        lo: &[f64],
        hi: &[f64],
    ) -> Result<&mut Layout, QpBuildError> {
        rows::prune(rows, lo, hi, &mut self.key);
        self.steps += 1;
        self.used = match self.layouts.iter().position(|(k, _, _)| *k == self.key) {
            Some(i) => i,
            None => {
                let entry = (
                    self.key.clone(),
                    Layout::new(space, rows, &self.key)?,
                    self.steps,
                );
                if self.layouts.len() < MAX_LAYOUTS {
                    self.layouts.push(entry);
                    self.layouts.len() - 1
                } else {
                    let oldest = (0..self.layouts.len())
                        .min_by_key(|&i| self.layouts[i].2)
                        .unwrap_or(0);
                    self.layouts[oldest] = entry;
                    oldest
                }
            }
        };
        let (_, layout, last_used) = &mut self.layouts[self.used];
        *last_used = self.steps;
        let qp = &mut layout.qp;
        let n = quad.g.len();
        qp.p_mut().copy_from_slice(&quad.p);
        qp.q_mut()[..n].copy_from_slice(&quad.g);
        qp.q_mut()[n..].fill(0.0);
        rows::load(rows, &layout.blocks, qp);
        for (j, (&l, &h)) in lo.iter().zip(hi).enumerate() {
            set_box(qp, j, l, h);
        }
        space.load_rate_rows(qp, layout.rate_row, plan);
        Ok(layout)
    }

    /// The last solution of the layout last loaded (increments then slacks).
    pub(crate) fn solution(&self) -> &[f64] {
        self.layouts[self.used].1.qp().solution()
    }
}

/// A QP in `n` variables with a box on each variable of `boxed` (box `k`, of
/// variable `boxed[k]`: rows `2 k`: `x <= hi`, `2 k + 1`: `-x <= -lo`) followed
/// by `extra_rows` rows of the given entries (row indices counted from 0 after
/// the boxes). Returns the QP and, per extra entry, its slot in the value array
/// of `A`. `P` has the entries of the coupled increments
/// ([`InputSpace::coupled`]) and none over the slacks.
fn box_qp(
    space: &InputSpace,
    n: usize,
    boxed: &[usize],
    extra_rows: usize,
    extra: &[(usize, usize)],
) -> Result<(Qp, Vec<usize>), QpBuildError> {
    let n_box = 2 * boxed.len();
    let mut entries: Vec<(usize, usize)> = boxed
        .iter()
        .enumerate()
        .flat_map(|(k, &j)| [(2 * k, j), (2 * k + 1, j)])
        .collect();
    entries.extend(extra.iter().map(|&(r, c)| (n_box + r, c)));
    let (pattern, slots) = Pattern::from_entries(n_box + extra_rows, n, &entries)?;
    let mut qp = Qp::with_p_pattern(pattern, 0, space.len(), |i, j| space.coupled(i, j))?;
    for (k, slot) in slots[..n_box].iter().enumerate() {
        qp.a_mut()[*slot] = if k % 2 == 0 { 1.0 } else { -1.0 };
    }
    Ok((qp, slots[n_box..].to_vec()))
}

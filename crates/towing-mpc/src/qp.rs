//! A thin wrapper over Clarabel for the small condensed QPs of the MPC.
//!
//! ```text
//! minimise   1/2 x^T P x + q^T x
//! subject to A x + s = b,   s in {0}^m_eq x R_+^m_ineq
//! ```
//!
//! (the first `m_eq` rows of `A` are equalities, the rest inequalities `A x <= b`).
//! `P` is dense over its upper triangle (every entry `(i, j)`, `i <= j`, is in the
//! pattern), `A` has a sparsity pattern fixed at construction; a zero value in the
//! pattern stays in it (`input_sparse_dropzeros(false)`). The Clarabel solver is
//! built once, with presolve off so that its data may be updated in place
//! (`update_P/q/A/b`), and each [`Qp::solve`] pushes the caller's current values
//! and re-solves: no new structure, no new solver.
//!
//! Settings (measured fastest in `docs/controller-design.md`): tolerances 1e-6 on
//! the absolute and relative gap and on feasibility, equilibration on, iterative
//! refinement off. The tests check the KKT residuals of the returned solutions
//! with refinement off.
//!
//! Outcomes are values ([`QpOutcome`]), never panics; construction errors (a bad
//! pattern, bad settings) are errors ([`QpBuildError`]).

// Index loops over (sample, channel) pairs: the indices also address the
// flat increment vector (`3 h + c`, `4 h + k`), clearer than zipped iterators.
#![allow(clippy::needless_range_loop)]

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QpOutcome {
    /// Converged to the set tolerances.
    Solved,
    /// Converged to Clarabel's reduced tolerances.
    AlmostSolved,
    /// Iteration (or time) limit reached; the iterate is not a solution.
    MaxIterations,
    /// No usable solution (infeasible, numerical trouble, ...).
    Failed(QpFailure),
}

impl QpOutcome {
    /// `Solved` or `AlmostSolved`: the solution buffer holds a usable solution.
    #[must_use]
    pub fn is_usable(self) -> bool {
        matches!(self, QpOutcome::Solved | QpOutcome::AlmostSolved)
    }
}

/// Why a solve gave no usable solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QpFailure {
    /// Clarabel found (or almost found) a certificate of primal infeasibility.
    PrimalInfeasible,
    /// Clarabel found (or almost found) a certificate of dual infeasibility
    /// (unbounded problem).
    DualInfeasible,
    /// Numerical error or insufficient progress.
    Numerical,
    /// The data pushed to the solver was refused (a non-finite value).
    BadData,
    /// Any other status (unsolved, callback).
    Other,
}

/// A QP could not be built.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct QpBuildError(pub String);

impl std::fmt::Display for QpBuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "QP construction failed: {}", self.0)
    }
}

impl std::error::Error for QpBuildError {}

/// The fixed sparsity pattern of `A` (CSC, `m x n`): `colptr` (n + 1 entries) and
/// sorted row indices per column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pattern {
    /// Number of rows.
    pub m: usize,
    /// Number of columns (= variables).
    pub n: usize,
    /// Column pointers.
    pub colptr: Vec<usize>,
    /// Row indices.
    pub rowval: Vec<usize>,
}

impl Pattern {
    /// The pattern of the given `(row, column)` entries (any order, no
    /// duplicates), and for each entry its index into the CSC value array.
    pub fn from_entries(
        m: usize,
        n: usize,
        entries: &[(usize, usize)],
    ) -> Result<(Pattern, Vec<usize>), QpBuildError> {
        let mut order: Vec<usize> = (0..entries.len()).collect();
        order.sort_by_key(|&k| (entries[k].1, entries[k].0));
        let mut colptr = vec![0; n + 1];
        let mut rowval = Vec::with_capacity(entries.len());
        let mut slot = vec![0; entries.len()];
        for (pos, &k) in order.iter().enumerate() {
            let (r, c) = entries[k];
            if r >= m || c >= n {
                return Err(QpBuildError(format!("entry ({r}, {c}) outside {m} x {n}")));
            }
            if pos > 0 && entries[order[pos - 1]] == (r, c) {
                return Err(QpBuildError(format!("duplicate entry ({r}, {c})")));
            }
            colptr[c + 1] += 1;
            rowval.push(r);
            slot[k] = pos;
        }
        for c in 0..n {
            colptr[c + 1] += colptr[c];
        }
        Ok((
            Pattern {
                m,
                n,
                colptr,
                rowval,
            },
            slot,
        ))
    }
}

/// A QP with a fixed structure, solved repeatedly with new values (module docs).
/// `P` is dense over the upper triangle of its first `n_p` variables
/// ([`Qp::with_p_block`]; all of them with [`Qp::new`]).
pub struct Qp {
    n: usize,
    m_eq: usize,
    solver: DefaultSolver<f64>,
    /// Upper triangle of `P`, column-major (`(i, j)`, `i <= j`, at `j (j + 1) / 2 + i`).
    p: Vec<f64>,
    /// For a sparse `P`: the packed index of each CSC entry, and the CSC values.
    p_gather: Option<Vec<usize>>,
    p_csc: Vec<f64>,
    q: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    x: Vec<f64>,
    z: Vec<f64>,
    iterations: u32,
}

impl std::fmt::Debug for Qp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Qp")
            .field("n", &self.n)
            .field("m", &self.b.len())
            .field("m_eq", &self.m_eq)
            .finish_non_exhaustive()
    }
}

/// Index of `(i, j)`, `i <= j`, in the packed upper triangle.
#[inline]
#[must_use]
pub fn upper_index(i: usize, j: usize) -> usize {
    let (i, j) = if i <= j { (i, j) } else { (j, i) };
    j * (j + 1) / 2 + i
}

impl Qp {
    /// The solver settings used (module docs).
    pub fn settings() -> Result<DefaultSettings<f64>, QpBuildError> {
        DefaultSettingsBuilder::default()
            .verbose(false)
            .presolve_enable(false)
            .input_sparse_dropzeros(false)
            .tol_gap_abs(1e-6)
            .tol_gap_rel(1e-6)
            .tol_feas(1e-6)
            .equilibrate_enable(true)
            .iterative_refinement_enable(false)
            .build()
            .map_err(|e| QpBuildError(e.to_string()))
    }

    /// A QP in `a.n` variables with `a.m` rows, the first `m_eq` equalities; all
    /// values zero until set (a zero `P` is replaced by the identity for the
    /// factorisation's structure only: the values are pushed on every solve).
    pub fn new(a: Pattern, m_eq: usize) -> Result<Qp, QpBuildError> {
        let n = a.n;
        Qp::with_p_block(a, m_eq, n)
    }

    /// As [`Qp::new`] with `P` dense over the first `n_p` variables only and zero
    /// (no entries) over the rest: the packed upper triangle has
    /// `n_p (n_p + 1) / 2` entries, indexed by [`upper_index`] as before.
    pub fn with_p_block(a: Pattern, m_eq: usize, n_p: usize) -> Result<Qp, QpBuildError> {
        Qp::with_p_pattern(a, m_eq, n_p, |_, _| true)
    }

    /// As [`Qp::with_p_block`] with entries `(i, j)` of `P` only where
    /// `coupled(i, j)` (and on the diagonal): values written elsewhere in the
    /// packed triangle ([`Qp::p_mut`]) must be zero, and are not passed to the
    /// solver. A sparser `P` is a sparser KKT system to factor.
    pub fn with_p_pattern(
        a: Pattern,
        m_eq: usize,
        n_p: usize,
        coupled: impl Fn(usize, usize) -> bool,
    ) -> Result<Qp, QpBuildError> {
        let (n, m) = (a.n, a.m);
        if m_eq > m || n_p > n || a.colptr.len() != n + 1 || a.rowval.len() != a.colptr[n] {
            return Err(QpBuildError("inconsistent pattern".into()));
        }
        let np = n_p * (n_p + 1) / 2;
        let mut p_colptr = Vec::with_capacity(n + 1);
        let mut p_rowval = Vec::with_capacity(np);
        let mut p_init = Vec::with_capacity(np);
        let mut gather = Vec::with_capacity(np);
        p_colptr.push(0);
        for j in 0..n {
            if j < n_p {
                for i in (0..=j).filter(|&i| i == j || coupled(i, j)) {
                    p_rowval.push(i);
                    p_init.push(if i == j { 1.0 } else { 0.0 });
                    gather.push(upper_index(i, j));
                }
            }
            p_colptr.push(p_rowval.len());
        }
        // Dense: the packed triangle is the CSC value array itself.
        let p_gather = (gather.len() < np).then_some(gather);
        let p_csc = vec![0.0; p_init.len()];
        let p_mat = CscMatrix::new(n, n, p_colptr, p_rowval, p_init);
        let nnz = a.rowval.len();
        let a_mat = CscMatrix::new(m, n, a.colptr, a.rowval, vec![1.0; nnz]);
        let q = vec![0.0; n];
        let b = vec![1.0; m];
        let mut cones = Vec::new();
        if m_eq > 0 {
            cones.push(SupportedConeT::ZeroConeT(m_eq));
        }
        if m > m_eq {
            cones.push(SupportedConeT::NonnegativeConeT(m - m_eq));
        }
        let solver = DefaultSolver::new(&p_mat, &q, &a_mat, &b, &cones, Qp::settings()?)
            .map_err(|e| QpBuildError(e.to_string()))?;
        Ok(Qp {
            n,
            m_eq,
            solver,
            p_gather,
            p_csc,
            p: vec![0.0; np],
            q,
            a: vec![0.0; nnz],
            b: vec![0.0; m],
            x: vec![0.0; n],
            z: vec![0.0; m],
            iterations: 0,
        })
    }

    /// Number of variables.
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of constraint rows.
    #[must_use]
    pub fn m(&self) -> usize {
        self.b.len()
    }

    /// `P`'s upper triangle, packed column-major (see [`upper_index`]).
    pub fn p_mut(&mut self) -> &mut [f64] {
        &mut self.p
    }

    /// `q`.
    pub fn q_mut(&mut self) -> &mut [f64] {
        &mut self.q
    }

    /// `A`'s values in the order of the pattern given at construction.
    pub fn a_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// `b`.
    pub fn b_mut(&mut self) -> &mut [f64] {
        &mut self.b
    }

    /// Current data, read-only: `(P packed, q, A values, b)`.
    #[must_use]
    pub fn data(&self) -> (&[f64], &[f64], &[f64], &[f64]) {
        (&self.p, &self.q, &self.a, &self.b)
    }

    /// Pushes the current values to the solver (in place) and solves. On a usable
    /// outcome [`Qp::solution`] holds the new solution; otherwise it keeps the
    /// last usable one.
    pub fn solve(&mut self) -> QpOutcome {
        let finite = [&self.p, &self.q, &self.a, &self.b]
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()));
        if !finite {
            return QpOutcome::Failed(QpFailure::BadData);
        }
        let p = match &self.p_gather {
            Some(gather) => {
                for (v, &k) in self.p_csc.iter_mut().zip(gather) {
                    *v = self.p[k];
                }
                &self.p_csc
            }
            None => &self.p,
        };
        let pushed = self
            .solver
            .update_P(p)
            .and_then(|()| self.solver.update_q(&self.q))
            .and_then(|()| self.solver.update_A(&self.a))
            .and_then(|()| self.solver.update_b(&self.b));
        if pushed.is_err() {
            return QpOutcome::Failed(QpFailure::BadData);
        }
        self.solver.solve();
        let sol = &self.solver.solution;
        self.iterations = sol.iterations;
        let outcome = match sol.status {
            SolverStatus::Solved => QpOutcome::Solved,
            SolverStatus::AlmostSolved => QpOutcome::AlmostSolved,
            SolverStatus::MaxIterations | SolverStatus::MaxTime => QpOutcome::MaxIterations,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                QpOutcome::Failed(QpFailure::PrimalInfeasible)
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                QpOutcome::Failed(QpFailure::DualInfeasible)
            }
            SolverStatus::NumericalError | SolverStatus::InsufficientProgress => {
                QpOutcome::Failed(QpFailure::Numerical)
            }
            _ => QpOutcome::Failed(QpFailure::Other),
        };
        if outcome.is_usable() {
            self.x.copy_from_slice(&sol.x);
            self.z.copy_from_slice(&sol.z);
        }
        outcome
    }

    /// The last usable primal solution `x`.
    #[must_use]
    pub fn solution(&self) -> &[f64] {
        &self.x
    }

    /// The last usable dual solution `z` (one per row).
    #[must_use]
    pub fn dual(&self) -> &[f64] {
        &self.z
    }

    /// Interior-point iterations of the last solve.
    #[must_use]
    pub fn iterations(&self) -> u32 {
        self.iterations
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Box rows `x_j <= hi_j`, `-x_j <= -lo_j` (rows `2 j`, `2 j + 1`).
    fn box_qp(n: usize) -> Qp {
        let entries: Vec<_> = (0..n).flat_map(|j| [(2 * j, j), (2 * j + 1, j)]).collect();
        let (pat, slots) = Pattern::from_entries(2 * n, n, &entries).unwrap();
        let mut qp = Qp::new(pat, 0).unwrap();
        for (k, s) in slots.iter().enumerate() {
            qp.a_mut()[*s] = if k % 2 == 0 { 1.0 } else { -1.0 };
        }
        qp
    }

    /// KKT residuals: `|P x + q + A^T z|_inf`, `|A x + s - b|` (as `max(0, A x - b)`),
    /// complementarity `max |z_k (b - A x)_k|`.
    fn kkt(qp: &Qp, a_dense: &[Vec<f64>]) -> (f64, f64, f64) {
        let (n, x, z) = (qp.n(), qp.solution(), qp.dual());
        let (p, q, _, b) = qp.data();
        let mut dual: f64 = 0.0;
        for i in 0..n {
            let mut g = q[i];
            for j in 0..n {
                g += p[upper_index(i, j)] * x[j];
            }
            for (k, row) in a_dense.iter().enumerate() {
                g += row[i] * z[k];
            }
            dual = dual.max(g.abs());
        }
        let (mut prim, mut comp): (f64, f64) = (0.0, 0.0);
        for (k, row) in a_dense.iter().enumerate() {
            let ax: f64 = row.iter().zip(x).map(|(r, x)| r * x).sum();
            prim = prim.max(ax - b[k]);
            comp = comp.max((z[k] * (b[k] - ax)).abs());
        }
        (dual, prim, comp)
    }

    fn box_rows(n: usize) -> Vec<Vec<f64>> {
        (0..2 * n)
            .map(|k| {
                let mut r = vec![0.0; n];
                r[k / 2] = if k % 2 == 0 { 1.0 } else { -1.0 };
                r
            })
            .collect()
    }

    /// min 1/2 |x - c|^2_D over a box: the solution is `clamp(c)` (D diagonal),
    /// repeated with changed data on the same solver.
    #[test]
    fn box_projection_is_exact_and_reusable() {
        let n = 4;
        let mut qp = box_qp(n);
        let rows = box_rows(n);
        for (trial, (c, d)) in [
            ([0.5, -3.0, 2.0, 0.0], [1.0, 2.0, 3.0, 4.0]),
            ([5.0, 0.3, -0.7, -9.0], [10.0, 0.1, 1.0, 1.0]),
            ([-0.2, 0.2, 1.5, -1.5], [1.0, 1.0, 1.0, 100.0]),
        ]
        .into_iter()
        .enumerate()
        {
            let (lo, hi) = (-1.0 - trial as f64 * 0.1, 1.0);
            for j in 0..n {
                qp.p_mut()[upper_index(j, j)] = d[j];
                qp.q_mut()[j] = -d[j] * c[j];
                qp.b_mut()[2 * j] = hi;
                qp.b_mut()[2 * j + 1] = -lo;
            }
            assert_eq!(qp.solve(), QpOutcome::Solved);
            for j in 0..n {
                let want = c[j].clamp(lo, hi);
                assert!(
                    (qp.solution()[j] - want).abs() < 5e-5,
                    "trial {trial}: x{j} = {} vs {want}",
                    qp.solution()[j]
                );
            }
            let (dual, prim, comp) = kkt(&qp, &rows);
            // With refinement off the stationarity residual stays ~1e-11 (1e-15
            // with it on); the error in x (up to ~1e-5 on a weakly weighted
            // variable) is the interior-point complementarity (~1e-6) and the same
            // with refinement on.
            assert!(
                dual < 1e-8 && prim < 1e-9 && comp < 1e-4,
                "{dual} {prim} {comp}"
            );
        }
    }

    /// A coupled QP with an equality: min x1^2 + x1 x2 + x2^2 - x1 s.t.
    /// x1 + x2 = c; substituting x2 = c - x1 gives x1 = (c + 1) / 2: (1, 0) for
    /// c = 1, (2, 1) for c = 3.
    #[test]
    fn equality_constrained_analytic() {
        let (pat, slots) = Pattern::from_entries(1, 2, &[(0, 0), (0, 1)]).unwrap();
        let mut qp = Qp::new(pat, 1).unwrap();
        qp.a_mut()[slots[0]] = 1.0;
        qp.a_mut()[slots[1]] = 1.0;
        qp.b_mut()[0] = 1.0;
        qp.p_mut()[upper_index(0, 0)] = 2.0;
        qp.p_mut()[upper_index(0, 1)] = 1.0;
        qp.p_mut()[upper_index(1, 1)] = 2.0;
        qp.q_mut()[0] = -1.0;
        assert_eq!(qp.solve(), QpOutcome::Solved);
        let x = qp.solution();
        assert!((x[0] - 1.0).abs() < 1e-6 && x[1].abs() < 1e-6, "{x:?}");
        // Changed right-hand side: x1 + x2 = 3 -> x1 - x2 = 1 -> (2, 1).
        qp.b_mut()[0] = 3.0;
        assert_eq!(qp.solve(), QpOutcome::Solved);
        let x = qp.solution();
        assert!(
            (x[0] - 2.0).abs() < 1e-6 && (x[1] - 1.0).abs() < 1e-6,
            "{x:?}"
        );
    }

    /// lo > hi: infeasible, reported as a value; the last usable solution stays.
    #[test]
    fn infeasible_is_an_outcome() {
        let mut qp = box_qp(2);
        for j in 0..2 {
            qp.p_mut()[upper_index(j, j)] = 1.0;
            qp.b_mut()[2 * j] = 1.0;
            qp.b_mut()[2 * j + 1] = 1.0;
        }
        assert_eq!(qp.solve(), QpOutcome::Solved);
        let before = qp.solution().to_vec();
        qp.b_mut()[0] = -2.0; // x0 <= -2 and x0 >= -1
        let out = qp.solve();
        assert!(!out.is_usable(), "{out:?}");
        assert_eq!(out, QpOutcome::Failed(QpFailure::PrimalInfeasible));
        assert_eq!(qp.solution(), &before[..]);
        qp.b_mut()[0] = f64::NAN;
        assert_eq!(qp.solve(), QpOutcome::Failed(QpFailure::BadData));
        // And it recovers.
        qp.b_mut()[0] = 1.0;
        assert_eq!(qp.solve(), QpOutcome::Solved);
    }

    #[test]
    fn bad_patterns_are_errors() {
        assert!(Pattern::from_entries(1, 1, &[(0, 0), (0, 0)]).is_err());
        assert!(Pattern::from_entries(1, 1, &[(1, 0)]).is_err());
    }
}

//! The quadratic model of the cost in the increments of one SCP step.
//!
//! Each subproblem's cost is a sum of weighted squared residuals with a linear
//! term, `sum_k w_k r_k^2 + c_k r_k` (tracking errors, velocities, the ADMM terms),
//! plus smooth convex scalar terms `w phi(d)` (obstacles). With the residuals
//! linearised in the input increments, `r_k ~ r_k + j_k^T du`, the model is the
//! convex QP
//!
//! ```text
//! m(du) = J(u) + g^T du + 1/2 du^T P du,
//! P = sum 2 w_k j_k j_k^T + w phi'' j_d j_d^T,   g = sum j_k (2 w_k r_k + c_k) + w phi' j_d
//! ```
//!
//! (Gauss-Newton: the residuals' curvature is left out, which keeps `P` positive
//! semidefinite; Nocedal and Wright 2006, section 10.3). A new cost kind is a
//! function of [`crate::costs`] that feeds [`QuadModel::residual`] or
//! [`QuadModel::curved`].

use crate::qp::upper_index;

/// The quadratic model (module docs), accumulated in preallocated buffers. With
/// `value_only` the model is not built, only the cost value (the true cost of a
/// rollout).
#[derive(Debug, Clone)]
pub struct QuadModel {
    /// Upper triangle of `P`, packed ([`upper_index`]).
    pub p: Vec<f64>,
    /// `g`.
    pub g: Vec<f64>,
    /// `J(u)`.
    pub value: f64,
    /// Only the value is accumulated.
    pub value_only: bool,
}

impl QuadModel {
    /// A model in `n` increments.
    #[must_use]
    pub fn new(n: usize) -> QuadModel {
        QuadModel {
            p: vec![0.0; n * (n + 1) / 2],
            g: vec![0.0; n],
            value: 0.0,
            value_only: false,
        }
    }

    /// Back to zero.
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
    #[must_use]
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
}

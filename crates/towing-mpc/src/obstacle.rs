//! Obstacles and the distance cost `phi(d)` of eq. (13)-(14), made honest
//! (`docs/controller-design.md`, "The distance term, made honest").
//!
//! Obstacles are static circles or ellipses in the NED plane. The distance `d` of a
//! point is measured from the obstacle's boundary (negative inside):
//!
//! - circle (centre `c`, radius `R`): `d = |p - c| - R`, the Euclidean distance;
//! - ellipse (centre `c`, semi-axes `a >= b`, major axis at bearing `theta`, foci
//!   `F_1,2 = c +- sqrt(a^2 - b^2) (cos, sin)(theta)`): the focal distance
//!   `d = (|p - F_1| + |p - F_2|) / 2 - a`, zero on the ellipse, exact along the
//!   major axis and a smooth lower bound of the Euclidean distance elsewhere
//!   (its gradient has norm <= 1), so it never overstates the clearance.
//!
//! Both are measured from the vessel's centre of origin; the own hull size goes
//! into `d_safe` (and, later, the clearance rows).

/// A static obstacle (module docs). Lengths in m, angles in rad. Serialized as
/// an object tagged by `kind` (`circle`, `ellipse`) with the fields by name (the
/// recorded problems of the side-by-side baseline, docs/benchmarks.md).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Obstacle {
    /// A circle.
    Circle {
        /// Centre `[x, y]` (NED, m).
        centre: [f64; 2],
        /// Radius (m, > 0).
        radius: f64,
    },
    /// An ellipse.
    Ellipse {
        /// Centre `[x, y]` (NED, m).
        centre: [f64; 2],
        /// Semi-major axis `a` (m).
        semi_major: f64,
        /// Semi-minor axis `b` (m, `0 < b <= a`).
        semi_minor: f64,
        /// Bearing of the major axis (rad, from North, clockwise).
        orientation: f64,
        /// Displacement per control sample (m, NED): a target ship's velocity
        /// times `T_s`. The prediction moves the ellipse by `(h + 1) drift` for
        /// the state after sample `h` (constant course and speed, the
        /// assumption of the paper's eq. (9) distances along the horizon);
        /// zero for a stationary ellipse.
        drift: [f64; 2],
    },
}

impl Obstacle {
    /// The obstacle as predicted after `samples` control samples (ellipses move
    /// by their `drift`; circles are static).
    #[must_use]
    pub fn after(&self, samples: usize) -> Obstacle {
        match *self {
            Obstacle::Ellipse {
                centre,
                semi_major,
                semi_minor,
                orientation,
                drift,
            } => {
                let k = samples as f64;
                Obstacle::Ellipse {
                    centre: [centre[0] + k * drift[0], centre[1] + k * drift[1]],
                    semi_major,
                    semi_minor,
                    orientation,
                    drift,
                }
            }
            circle @ Obstacle::Circle { .. } => circle,
        }
    }

    /// Distance `d` of the point `p` (module docs) and its gradient `dd/dp`.
    #[must_use]
    pub fn distance(&self, p: [f64; 2]) -> (f64, [f64; 2]) {
        match *self {
            Obstacle::Circle { centre, radius } => {
                let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
                let r = dx.hypot(dy);
                let grad = if r > 0.0 {
                    [dx / r, dy / r]
                } else {
                    [1.0, 0.0]
                };
                (r - radius, grad)
            }
            Obstacle::Ellipse {
                centre,
                semi_major,
                semi_minor,
                orientation,
                ..
            } => {
                let f = (semi_major * semi_major - semi_minor * semi_minor)
                    .max(0.0)
                    .sqrt();
                let (s, c) = orientation.sin_cos();
                let mut sum = 0.0;
                let mut grad = [0.0; 2];
                for sign in [1.0, -1.0] {
                    let (dx, dy) = (
                        p[0] - centre[0] - sign * f * c,
                        p[1] - centre[1] - sign * f * s,
                    );
                    let r = dx.hypot(dy);
                    sum += r;
                    if r > 0.0 {
                        grad[0] += 0.5 * dx / r;
                        grad[1] += 0.5 * dy / r;
                    }
                }
                (0.5 * sum - semi_major, grad)
            }
        }
    }
}

/// The distance cost `phi(d)`: `(d - d_safe)^-2` for `d >= d_safe + epsilon`, below
/// that its quadratic extension matching value, slope and curvature at
/// `d_0 = d_safe + epsilon`. `phi` is C2, convex and strictly decreasing on the
/// whole line (the slope `phi'(d_0) + phi''(d_0) (d - d_0)` is more negative the
/// smaller `d`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceCost {
    /// `d_safe` (m), eq. (14).
    pub d_safe: f64,
    /// `epsilon` (m, > 0): where the extension starts (0.1 m).
    pub epsilon: f64,
}

impl Default for DistanceCost {
    /// `d_safe = 1 m`, `epsilon = 0.1 m`.
    fn default() -> Self {
        DistanceCost {
            d_safe: 1.0,
            epsilon: 0.1,
        }
    }
}

impl DistanceCost {
    /// `(phi, phi', phi'')` at `d`.
    #[must_use]
    pub fn eval(&self, d: f64) -> (f64, f64, f64) {
        let d0 = self.d_safe + self.epsilon;
        let at = |d: f64| {
            let t = 1.0 / (d - self.d_safe);
            let t2 = t * t;
            (t2, -2.0 * t2 * t, 6.0 * t2 * t2)
        };
        if d >= d0 {
            at(d)
        } else {
            let (v, s, c) = at(d0);
            let e = d - d0;
            (v + s * e + 0.5 * c * e * e, s + c * e, c)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Strictly decreasing, convex (midpoint), C1/C2 by matching finite
        /// differences, and the printed form above `d_safe + epsilon`.
        #[test]
        fn phi_is_convex_decreasing_c2(d in -20.0f64..20.0, h in 1e-3f64..2.0, ds in 0.5f64..5.0) {
            let phi = DistanceCost { d_safe: ds, epsilon: 0.1 };
            let (v, s, c) = phi.eval(d);
            let (v2, _, _) = phi.eval(d + h);
            prop_assert!(v2 < v, "not decreasing at {d}");
            prop_assert!(s < 0.0 && c > 0.0);
            let (vm, _, _) = phi.eval(d + 0.5 * h);
            prop_assert!(vm <= 0.5 * (v + v2) + 1e-12 * v.abs().max(1.0), "not convex at {d}");
            // Derivatives agree with central differences of value and slope.
            let e = 1e-6;
            let (vp, sp, _) = phi.eval(d + e);
            let (vn, sn, _) = phi.eval(d - e);
            let tol = 1e-4 * (1.0 + c.abs() + s.abs());
            prop_assert!(((vp - vn) / (2.0 * e) - s).abs() < tol);
            prop_assert!(((sp - sn) / (2.0 * e) - c).abs() < tol * 10.0);
            if d >= ds + 0.1 {
                prop_assert!((v - (d - ds).powi(-2)).abs() <= 1e-12 * v);
            }
        }
    }

    /// Continuity of value, slope and curvature at the junction.
    #[test]
    fn phi_is_c2_at_the_junction() {
        let phi = DistanceCost::default();
        let d0 = phi.d_safe + phi.epsilon;
        let a = phi.eval(d0 - 1e-9);
        let b = phi.eval(d0 + 1e-9);
        assert!((a.0 - b.0).abs() < 1e-4 && (a.1 - b.1).abs() < 1e-3);
        assert!((a.2 - b.2).abs() / b.2 < 1e-6);
        // Inside d_safe it keeps rising (the printed term would fall).
        assert!(phi.eval(0.5).0 > phi.eval(1.0).0);
    }

    #[test]
    fn distances() {
        let c = Obstacle::Circle {
            centre: [1.0, 2.0],
            radius: 0.5,
        };
        let (d, g) = c.distance([4.0, 6.0]);
        assert!((d - 4.5).abs() < 1e-12 && (g[0] - 0.6).abs() < 1e-12);
        let e = Obstacle::Ellipse {
            centre: [0.0, 0.0],
            semi_major: 2.0,
            semi_minor: 1.0,
            orientation: 0.0,
            drift: [0.0; 2],
        };
        assert!((e.distance([3.0, 0.0]).0 - 1.0).abs() < 1e-12); // on the major axis
        assert!(e.distance([0.0, 1.0]).0.abs() < 1e-12); // on the ellipse
        let (d, g) = e.distance([0.0, 3.0]);
        assert!(d > 0.0 && d <= 2.0 && g[1] > 0.0 && g[0].abs() < 1e-12);
    }
}

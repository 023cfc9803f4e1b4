//! The hull kinetics of a prediction model and their partial derivatives.
//!
//! The value of `nu_dot = M^-1 (tau - C(nu) nu - D(nu) nu)` is always the plant's:
//! [`PredictionHull`] holds the same boxed [`HullDynamics`] that
//! [`HullModel::build`] gives the plant's `World`, and calls its `nu_dot`. Only the
//! partial derivative `d nu_dot / d nu` needs more than the trait offers, and is
//! obtained in one of two ways ([`JacobianMethod`]):
//!
//! - [`JacobianMethod::Analytic`] for the two built-in hulls ([`PredictionHull::new`]
//!   from a [`HullModel`]): exact partials of Fossen's form,
//!   `d nu_dot / d nu = -M^-1 (d(C(nu) nu)/d nu + d(D(nu) nu)/d nu)`, with `C(nu)`
//!   Fossen's `m2c` of the symmetric `M` (Fossen 2021, Theorem 3.2) and `D(nu)` the
//!   damping law of [`Damping`] (Skjetne et al. 2004; linear part only for
//!   [`HullModel::LinearDamping`]).
//! - [`JacobianMethod::FiniteDifference`] for a user hull ([`PredictionHull::custom`]):
//!   the trait exposes `C(nu)` and `D(nu)` as matrices but not their derivatives,
//!   so `d nu_dot / d nu` is taken by central differences of the hull's own
//!   `nu_dot` with steps `6e-6 (1 + |nu_j|)` (about `eps^(1/3)`, relative error
//!   about 1e-10 for smooth hulls). Documented as not exact.
//!
//! Why analytic partials and not a dual-number (forward-mode AD) rewrite of the
//! kinetics: the plant's `nu_dot` is `f64`-only and must stay the single source of
//! the values (the controller has to agree with the plant); an AD version would be a
//! second implementation of the same kinetics, generic over a scalar trait, kept in
//! step with the plant by tests. The partials of the Fossen form are short (the
//! Coriolis term is bilinear in `nu`, the damping entries are polynomials in `u`,
//! `|u|`, `|v|`, `|r|`), they are checked against central differences, and they
//! also define what happens at the kinks of the `|.|` terms, which AD would do
//! implicitly: `sign(0) = 0`, the mean of the one-sided derivatives (the value a
//! central difference converges to).
//!
//! `d nu_dot / d tau = M^-1` for every hull (`nu_dot` is affine in `tau` by the
//! trait's contract).

use nalgebra::Matrix3;
use towing_model::{Damping, HullDynamics, HullModel, ParamError, VesselData};

/// Relative step of the central differences of [`JacobianMethod::FiniteDifference`].
pub const FD_RELATIVE_STEP: f64 = 6e-6;

/// How `d nu_dot / d nu` is computed (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JacobianMethod {
    /// Exact partials of the Fossen form (the built-in hulls).
    Analytic,
    /// Central finite differences of the hull's `nu_dot` (user hulls).
    FiniteDifference,
}

/// What the partials are computed from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Partials {
    /// Fossen's form with `m2c` Coriolis of the symmetric `m` and the damping law of
    /// `damping` (nonlinear derivatives zeroed for the linear hull).
    Analytic {
        m: Matrix3<f64>,
        damping: Damping,
    },
    FiniteDifference,
}

/// The kinetics of one vessel in a prediction model: the plant's [`HullDynamics`]
/// plus `d nu_dot / d nu` (module docs).
#[derive(Debug, Clone)]
pub struct PredictionHull {
    hull: Box<dyn HullDynamics>,
    m_inv: Matrix3<f64>,
    partials: Partials,
}

impl PredictionHull {
    /// The built-in hull `model` of a vessel, built exactly as the plant builds it
    /// ([`HullModel::build`], which validates the data), with analytic partials.
    pub fn new(model: HullModel, data: &VesselData) -> Result<PredictionHull, ParamError> {
        let hull = model.build(data)?;
        let damping = match model {
            HullModel::NonlinearDamping => data.damping,
            HullModel::LinearDamping => linear_part(&data.damping),
        };
        Ok(PredictionHull {
            m_inv: *hull.mass_matrix_inv(),
            partials: Partials::Analytic {
                m: *hull.mass_matrix(),
                damping,
            },
            hull,
        })
    }

    /// A user hull (e.g. the one given to the plant's `World::with_hulls`), with
    /// finite-difference partials. The hull is used as is: hand over a hull the
    /// world accepted (it checks `M`, `M^-1` and `C`).
    #[must_use]
    pub fn custom(hull: Box<dyn HullDynamics>) -> PredictionHull {
        PredictionHull {
            m_inv: *hull.mass_matrix_inv(),
            partials: Partials::FiniteDifference,
            hull,
        }
    }

    /// The kinetics (the same object type the plant integrates).
    #[must_use]
    pub fn dynamics(&self) -> &dyn HullDynamics {
        &*self.hull
    }

    /// How [`PredictionHull::nu_dot_jacobian`] is computed.
    #[must_use]
    pub fn jacobian_method(&self) -> JacobianMethod {
        match self.partials {
            Partials::Analytic { .. } => JacobianMethod::Analytic,
            Partials::FiniteDifference => JacobianMethod::FiniteDifference,
        }
    }

    /// `nu_dot(nu, tau)` of the hull (m/s^2, m/s^2, rad/s^2): the plant's function.
    #[inline]
    #[must_use]
    pub fn nu_dot(&self, nu: &[f64; 3], tau: &[f64; 3]) -> [f64; 3] {
        self.hull.nu_dot(nu, tau)
    }

    /// `M^-1` = `d nu_dot / d tau`.
    #[must_use]
    pub fn mass_matrix_inv(&self) -> &Matrix3<f64> {
        &self.m_inv
    }

    /// `d nu_dot / d nu` at `(nu, tau)` (1/s, ...; row: component of `nu_dot`,
    /// column: component of `nu`). Allocation-free.
    #[must_use]
    pub fn nu_dot_jacobian(&self, nu: &[f64; 3], tau: &[f64; 3]) -> Matrix3<f64> {
        match &self.partials {
            Partials::Analytic { m, damping } => {
                -(self.m_inv
                    * (coriolis_force_jacobian(m, nu) + damping_force_jacobian(damping, nu)))
            }
            Partials::FiniteDifference => {
                let mut j = Matrix3::zeros();
                for col in 0..3 {
                    let step = FD_RELATIVE_STEP * (1.0 + nu[col].abs());
                    let (mut plus, mut minus) = (*nu, *nu);
                    plus[col] += step;
                    minus[col] -= step;
                    let fp = self.hull.nu_dot(&plus, tau);
                    let fm = self.hull.nu_dot(&minus, tau);
                    let width = plus[col] - minus[col];
                    for row in 0..3 {
                        j[(row, col)] = (fp[row] - fm[row]) / width;
                    }
                }
                j
            }
        }
    }
}

/// The linear derivatives of `d` only (what [`HullModel::LinearDamping`] uses).
fn linear_part(d: &Damping) -> Damping {
    Damping {
        x_u: d.x_u,
        y_v: d.y_v,
        y_r: d.y_r,
        n_v: d.n_v,
        n_r: d.n_r,
        ..Damping::ZERO
    }
}

/// `sign(x)` with `sign(0) = 0` (the mean of the one-sided derivatives of `|x|`).
#[inline]
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `d(C(nu) nu) / d nu` for Fossen's `m2c` Coriolis matrix of a symmetric `M`:
/// `C(nu) nu = [-a r, b r, a u - b v]` with `a = m21 u + m22 v + m23 r`,
/// `b = m11 u + m12 v + m13 r`.
fn coriolis_force_jacobian(m: &Matrix3<f64>, &[u, v, r]: &[f64; 3]) -> Matrix3<f64> {
    let a = m[(1, 0)] * u + m[(1, 1)] * v + m[(1, 2)] * r;
    let b = m[(0, 0)] * u + m[(0, 1)] * v + m[(0, 2)] * r;
    Matrix3::new(
        -r * m[(1, 0)],
        -r * m[(1, 1)],
        -r * m[(1, 2)] - a,
        r * m[(0, 0)],
        r * m[(0, 1)],
        r * m[(0, 2)] + b,
        m[(1, 0)] * u + a - m[(0, 0)] * v,
        m[(1, 1)] * u - m[(0, 1)] * v - b,
        m[(1, 2)] * u - m[(0, 2)] * v,
    )
}

/// `d(D(nu) nu) / d nu` for the damping law of [`Damping`] (Skjetne et al. 2004):
/// `D(nu) nu = [d11 u, d22 v + d23 r, d32 v + d33 r]` with
/// `d11 = -X_u - X_|u|u |u| - X_uuu u^2`, `d22 = -Y_v - Y_|v|v |v| - Y_|r|v |r|`,
/// `d23 = -Y_r - Y_|v|r |v| - Y_|r|r |r|`, `d32 = -N_v - N_|v|v |v| - N_|r|v |r|`,
/// `d33 = -N_r - N_|v|r |v| - N_|r|r |r|`.
fn damping_force_jacobian(d: &Damping, &[u, v, r]: &[f64; 3]) -> Matrix3<f64> {
    let (av, ar) = (v.abs(), r.abs());
    let (sv, sr) = (sign(v), sign(r));
    let d22 = -d.y_v - d.y_absv_v * av - d.y_absr_v * ar;
    let d23 = -d.y_r - d.y_absv_r * av - d.y_absr_r * ar;
    let d32 = -d.n_v - d.n_absv_v * av - d.n_absr_v * ar;
    let d33 = -d.n_r - d.n_absv_r * av - d.n_absr_r * ar;
    let j11 = -d.x_u - 2.0 * d.x_absu_u * u.abs() - 3.0 * d.x_uuu * u * u;
    let j22 = d22 - (d.y_absv_v * v + d.y_absv_r * r) * sv;
    let j23 = d23 - (d.y_absr_v * v + d.y_absr_r * r) * sr;
    let j32 = d32 - (d.n_absv_v * v + d.n_absv_r * r) * sv;
    let j33 = d33 - (d.n_absr_v * v + d.n_absr_r * r) * sr;
    Matrix3::new(j11, 0.0, 0.0, 0.0, j22, j23, 0.0, j32, j33)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use towing_model::kinetics::NonlinearDampingHull;

    fn vessels() -> [(&'static str, VesselData); 3] {
        let mut b = VesselData::titoneri();
        b.damping = Damping::titoneri_set_b();
        [
            ("cybership2", VesselData::cybership2()),
            ("titoneri A", VesselData::titoneri()),
            ("titoneri B", b),
        ]
    }

    /// Central differences with a small step, to check the analytic partials.
    fn reference(hull: &PredictionHull, nu: &[f64; 3], tau: &[f64; 3]) -> Matrix3<f64> {
        let mut j = Matrix3::zeros();
        for col in 0..3 {
            let (mut p, mut m) = (*nu, *nu);
            p[col] += 1e-7;
            m[col] -= 1e-7;
            let (fp, fm) = (hull.nu_dot(&p, tau), hull.nu_dot(&m, tau));
            for row in 0..3 {
                j[(row, col)] = (fp[row] - fm[row]) / (p[col] - m[col]);
            }
        }
        j
    }

    #[test]
    fn builtin_hulls_are_analytic_and_custom_ones_are_not() {
        for model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
            let hull = PredictionHull::new(model, &VesselData::cybership2()).unwrap();
            assert_eq!(hull.jacobian_method(), JacobianMethod::Analytic);
        }
        let custom = PredictionHull::custom(Box::new(
            NonlinearDampingHull::new(&VesselData::cybership2()).unwrap(),
        ));
        assert_eq!(custom.jacobian_method(), JacobianMethod::FiniteDifference);
        let mut bad = VesselData::cybership2();
        bad.mass = 0.0;
        assert_eq!(
            PredictionHull::new(HullModel::LinearDamping, &bad)
                .unwrap_err()
                .field,
            "mass"
        );
    }

    #[test]
    fn values_are_the_plants() {
        for (name, data) in vessels() {
            for model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
                let plant = model.build(&data).unwrap();
                let hull = PredictionHull::new(model, &data).unwrap();
                let (nu, tau) = ([0.3, -0.1, 0.2], [1.0, 0.5, -0.2]);
                assert_eq!(hull.nu_dot(&nu, &tau), plant.nu_dot(&nu, &tau), "{name}");
                assert_eq!(hull.mass_matrix_inv(), plant.mass_matrix_inv());
            }
        }
    }

    /// The linear hull's Jacobian is the constant `-M^-1 (dC + D)`.
    #[test]
    fn linear_damping_partial_is_the_damping_matrix() {
        let hull =
            PredictionHull::new(HullModel::LinearDamping, &VesselData::cybership2()).unwrap();
        let j = hull.nu_dot_jacobian(&[0.0; 3], &[0.0; 3]);
        let d = hull.dynamics().damping_matrix(&nalgebra::Vector3::zeros());
        assert!((j + hull.mass_matrix_inv() * d).abs().max() < 1e-15, "{j}");
    }

    proptest! {
        // Fixed seed: the same cases on every run.
        #![proptest_config(ProptestConfig {
            cases: 512,
            rng_seed: proptest::test_runner::RngSeed::Fixed(1),
            ..ProptestConfig::default()
        })]

        #[test]
        fn analytic_partials_match_central_differences(
            u in -1.0f64..1.0, v in -0.5f64..0.5, r in -0.5f64..0.5,
            tu in -10.0f64..10.0, tv in -10.0f64..10.0, tr in -10.0f64..10.0,
        ) {
            // Away from the kinks of |u|, |v|, |r|: no kink within either difference
            // step (1e-7 here, 6e-6 (1 + |nu|) in the fallback).
            prop_assume!(v.abs() > 1e-4 && r.abs() > 1e-4 && u.abs() > 1e-4);
            let (nu, tau) = ([u, v, r], [tu, tv, tr]);
            for (name, data) in vessels() {
                for model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
                    let hull = PredictionHull::new(model, &data).unwrap();
                    let j = hull.nu_dot_jacobian(&nu, &tau);
                    let fd = reference(&hull, &nu, &tau);
                    let scale = j.abs().max();
                    prop_assert!((j - fd).abs().max() < 1e-7 * scale, "{} {:?}: {} vs {}", name, model, j, fd);
                    // The fallback agrees with the analytic partials.
                    let custom = PredictionHull::custom(model.build(&data).unwrap());
                    let jf = custom.nu_dot_jacobian(&nu, &tau);
                    prop_assert!((j - jf).abs().max() < 1e-8 * scale, "{} {:?}: {} vs {}", name, model, j, jf);
                }
            }
        }
    }
}

//! Fossen's 3-DoF manoeuvring model in NED (Fossen 2021, ch. 2 kinematics, ch. 3
//! and 6 kinetics; Du et al. 2022, eq. (1)):
//!
//! ```text
//! eta_dot = R(psi) nu
//! M nu_dot + C(nu) nu + D(nu) nu = tau
//! ```
//!
//! with `eta = [x, y, psi]` (North, East, heading), `nu = [u, v, r]` (body frame),
//! `R(psi) = [[cos, -sin, 0], [sin, cos, 0], [0, 0, 1]]`, `M = sym(M_RB + M_A)`
//! ([`VesselData::mass_matrix`]), `C(nu)` built from the total `M` as Fossen's
//! `m2c` does (Fossen 2021, Theorem 3.2; this equals `C_RB + C_A` of Skjetne et al.
//! 2004), and `D(nu)` from the damping derivatives ([`Damping`]) according to the
//! [`HullModel`]. Symbols follow Fossen in ASCII; vectors are `nalgebra::Vector3`.
//!
//! # Energy and passivity
//!
//! The kinetic energy is `T = 1/2 nu^T M nu`. Because `M` is symmetric and constant
//! and `C(nu)` is skew-symmetric, `C` does no work and
//! `dT/dt = nu^T tau - nu^T D(nu) nu` exactly ([`Hull::power_balance`]).
//! Free motion (`tau = 0`) therefore loses energy exactly where the symmetric
//! part of `D(nu)` is positive definite. Checked numerically (and pinned by tests):
//!
//! - TitoNeri, damping set A: `sym(D) = [[2.64, 0, 0], [0, 21.90, -1.10],
//!   [0, -1.10, 0.105]]` is positive definite (`21.90 * 0.105 > 1.10^2`); set B is
//!   diagonal positive. Both hull models are identical for the tug (no nonlinear
//!   terms), so the tug's kinetic energy never increases in free decay.
//! - CyberShip II is *not* dissipative. Its identified `Y_r = -7.25` makes
//!   `d23 = 7.25` while `d32 = -N_v = -0.0313`, so the sway-yaw part of `D` is far
//!   from symmetric: with linear damping `nu^T D nu = 0.890 v^2 + 7.219 v r + 1.9 r^2`,
//!   negative whenever `v / r` lies in `(-7.84, -0.272)` m/rad at any speed. With
//!   the full nonlinear damping the quadratic terms win at larger speeds and
//!   `nu^T D nu < 0` only inside about `|v| < 0.163 m/s`, `|r| < 0.36 rad/s` with
//!   `v r < 0`, which is exactly the low-speed regime of the towing operation.
//!   Example: `nu = [0, 0.05, -0.1]` gives `dT/dt = +0.0103 W` (nonlinear) and
//!   `+0.0149 W` (linear) with no input. The free-decay energy of the ship
//!   can therefore rise for a while; it does not diverge (the linearisation
//!   `-M^-1 D` is Hurwitz, so all velocities still decay), but `T` is not a Lyapunov
//!   function for the identified model. Pure surge motion (`v = r = 0`, an
//!   invariant set of the free dynamics) is dissipative for both hull models
//!   (`d11 > 0`). This is a property of the published coefficients, not of this
//!   code; the data are used as published.

#![allow(non_snake_case)]

use nalgebra::{Matrix3, Vector3};

use crate::vessel::{Damping, ParamError, VesselData};

/// Which damping model the hulls use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HullModel {
    /// Constant `D = -[[X_u, 0, 0], [0, Y_v, Y_r], [0, N_v, N_r]]` from the linear
    /// derivatives only: the form of the paper's eq. (1) and of its prediction model
    /// (eq. (15)-(16)).
    LinearDamping,
    /// The full `D(nu)` of Skjetne et al. (2004) for CyberShip II (linear,
    /// `|.|`-quadratic and cubic terms). The tug has only linear data, so it is the
    /// same under both models. Default: the plant represents the identified vessel.
    #[default]
    NonlinearDamping,
}

/// Rotation from body to NED, `R(psi)` (Fossen 2021, ch. 2, 3-DoF).
#[must_use]
pub fn R(psi: f64) -> Matrix3<f64> {
    let (s, c) = psi.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Kinematics `eta_dot = R(psi) nu`.
#[must_use]
pub fn eta_dot(eta: &Vector3<f64>, nu: &Vector3<f64>) -> Vector3<f64> {
    R(eta[2]) * nu
}

/// Coriolis-centripetal matrix from a 3x3 inertia matrix (Fossen 2021, Theorem 3.2,
/// Fossen's `m2c` for 3 DoF). `M` is symmetrised first; the result is
/// skew-symmetric:
///
/// ```text
/// C = [[0, 0, -(m21 u + m22 v + m23 r)],
///      [0, 0,   m11 u + m12 v + m13 r ],
///      [m21 u + m22 v + m23 r, -(m11 u + m12 v + m13 r), 0]]
/// ```
#[must_use]
pub fn C(M: &Matrix3<f64>, nu: &Vector3<f64>) -> Matrix3<f64> {
    let m = (M + M.transpose()) * 0.5;
    let a = m[(1, 0)] * nu[0] + m[(1, 1)] * nu[1] + m[(1, 2)] * nu[2];
    let b = m[(0, 0)] * nu[0] + m[(0, 1)] * nu[1] + m[(0, 2)] * nu[2];
    Matrix3::new(0.0, 0.0, -a, 0.0, 0.0, b, a, -b, 0.0)
}

/// Damping matrix `D(nu)` (Skjetne et al. 2004; see [`Damping`] for the entries).
#[must_use]
pub fn D(damping: &Damping, model: HullModel, nu: &Vector3<f64>) -> Matrix3<f64> {
    let [d11, d22, d23, d32, d33] = damping_entries(damping, model, nu[0], nu[1], nu[2]);
    Matrix3::new(d11, 0.0, 0.0, 0.0, d22, d23, 0.0, d32, d33)
}

/// `[d11, d22, d23, d32, d33]` of `D(nu)`.
#[inline]
fn damping_entries(d: &Damping, model: HullModel, u: f64, v: f64, r: f64) -> [f64; 5] {
    match model {
        HullModel::LinearDamping => [-d.x_u, -d.y_v, -d.y_r, -d.n_v, -d.n_r],
        HullModel::NonlinearDamping => {
            let (au, av, ar) = (u.abs(), v.abs(), r.abs());
            [
                -d.x_u - d.x_absu_u * au - d.x_uuu * u * u,
                -d.y_v - d.y_absv_v * av - d.y_absr_v * ar,
                -d.y_r - d.y_absv_r * av - d.y_absr_r * ar,
                -d.n_v - d.n_absv_v * av - d.n_absr_v * ar,
                -d.n_r - d.n_absv_r * av - d.n_absr_r * ar,
            ]
        }
    }
}

/// One hull's kinetics, with `M` and `M^-1` computed once from validated data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hull {
    M: Matrix3<f64>,
    M_inv: Matrix3<f64>,
    damping: Damping,
    model: HullModel,
}

impl Hull {
    /// Builds the kinetics of a vessel; validates the data
    /// ([`VesselData::validate`]) first.
    pub fn new(data: &VesselData, model: HullModel) -> Result<Hull, ParamError> {
        data.validate()?;
        let M = data.mass_matrix();
        let M_inv = M
            .try_inverse()
            .ok_or_else(|| ParamError::new("", "the mass matrix is singular"))?;
        Ok(Hull {
            M,
            M_inv,
            damping: data.damping,
            model,
        })
    }

    /// The symmetric total mass matrix `M = sym(M_RB + M_A)`.
    #[must_use]
    pub fn M(&self) -> &Matrix3<f64> {
        &self.M
    }

    /// `M^-1`.
    #[must_use]
    pub fn M_inv(&self) -> &Matrix3<f64> {
        &self.M_inv
    }

    /// The damping derivatives.
    #[must_use]
    pub fn damping(&self) -> &Damping {
        &self.damping
    }

    /// The damping model.
    #[must_use]
    pub fn model(&self) -> HullModel {
        self.model
    }

    /// `C(nu)` from the total mass matrix (skew-symmetric).
    #[must_use]
    pub fn C(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        C(&self.M, nu)
    }

    /// `D(nu)` for this hull's model.
    #[must_use]
    pub fn D(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        D(&self.damping, self.model, nu)
    }

    /// `nu_dot = M^-1 (tau - C(nu) nu - D(nu) nu)` (Du et al. 2022, eq. (1)).
    #[must_use]
    pub fn nu_dot(&self, nu: &Vector3<f64>, tau: &Vector3<f64>) -> Vector3<f64> {
        Vector3::from(self.nu_dot_arr([nu[0], nu[1], nu[2]], [tau[0], tau[1], tau[2]]))
    }

    /// Same as [`Hull::nu_dot`] on arrays, with `C(nu) nu` and `D(nu) nu` expanded
    /// (the integrator's hot path).
    #[inline]
    #[must_use]
    pub fn nu_dot_arr(&self, nu: [f64; 3], tau: [f64; 3]) -> [f64; 3] {
        let [u, v, r] = nu;
        let m = &self.M;
        // C(nu) nu with a = m21 u + m22 v + m23 r, b = m11 u + m12 v + m13 r.
        let a = m[(1, 0)] * u + m[(1, 1)] * v + m[(1, 2)] * r;
        let b = m[(0, 0)] * u + m[(0, 1)] * v + m[(0, 2)] * r;
        let cnu = [-a * r, b * r, a * u - b * v];
        let [d11, d22, d23, d32, d33] = damping_entries(&self.damping, self.model, u, v, r);
        let dnu = [d11 * u, d22 * v + d23 * r, d32 * v + d33 * r];
        let rhs = Vector3::new(
            tau[0] - cnu[0] - dnu[0],
            tau[1] - cnu[1] - dnu[1],
            tau[2] - cnu[2] - dnu[2],
        );
        let out = self.M_inv * rhs;
        [out[0], out[1], out[2]]
    }

    /// Kinetic energy `T = 1/2 nu^T M nu` (J).
    #[must_use]
    pub fn kinetic_energy(&self, nu: &Vector3<f64>) -> f64 {
        0.5 * nu.dot(&(self.M * nu))
    }

    /// Power balance `dT/dt = nu^T tau - nu^T D(nu) nu` (W): the Coriolis terms do
    /// no work. Equal to `nu^T M nu_dot` up to rounding.
    #[must_use]
    pub fn power_balance(&self, nu: &Vector3<f64>, tau: &Vector3<f64>) -> f64 {
        nu.dot(tau) - nu.dot(&(self.D(nu) * nu))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn hulls() -> Vec<(&'static str, Hull)> {
        let mut out = Vec::new();
        for model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
            out.push((
                "cybership2",
                Hull::new(&VesselData::cybership2(), model).unwrap(),
            ));
            out.push((
                "titoneri A",
                Hull::new(&VesselData::titoneri(), model).unwrap(),
            ));
            let mut b = VesselData::titoneri();
            b.damping = Damping::titoneri_set_b();
            out.push(("titoneri B", Hull::new(&b, model).unwrap()));
        }
        out
    }

    fn rk4_free(hull: &Hull, nu: [f64; 3], h: f64) -> [f64; 3] {
        let f = |x: [f64; 3]| hull.nu_dot_arr(x, [0.0; 3]);
        let add =
            |x: [f64; 3], k: [f64; 3], s: f64| [x[0] + s * k[0], x[1] + s * k[1], x[2] + s * k[2]];
        let k1 = f(nu);
        let k2 = f(add(nu, k1, h / 2.0));
        let k3 = f(add(nu, k2, h / 2.0));
        let k4 = f(add(nu, k3, h));
        [
            nu[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            nu[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            nu[2] + h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]),
        ]
    }

    #[test]
    fn cybership2_coriolis_matches_reference_form() {
        // vessels.md: C = [[0,0,-(m22 v + m23 r)],[0,0,m11 u],[m22 v + m23 r,-m11 u,0]].
        let hull = Hull::new(&VesselData::cybership2(), HullModel::LinearDamping).unwrap();
        let nu = Vector3::new(0.3, -0.1, 0.2);
        let a = 33.8 * nu[1] + 1.0948 * nu[2];
        let expected = Matrix3::new(0.0, 0.0, -a, 0.0, 0.0, 25.8 * nu[0], a, -25.8 * nu[0], 0.0);
        assert!((hull.C(&nu) - expected).abs().max() < 1e-12);
    }

    #[test]
    fn linear_damping_matrix_is_constant_and_signed_as_published() {
        let hull = Hull::new(&VesselData::cybership2(), HullModel::LinearDamping).unwrap();
        let d = hull.D(&Vector3::new(1.0, 0.5, -0.3));
        let expected = Matrix3::new(0.72253, 0.0, 0.0, 0.0, 0.88965, 7.25, 0.0, -0.0313, 1.9);
        assert!((d - expected).abs().max() < 1e-12, "{d}");
    }

    #[test]
    fn tug_is_the_same_under_both_hull_models() {
        for data in [VesselData::titoneri(), {
            let mut b = VesselData::titoneri();
            b.damping = Damping::titoneri_set_b();
            b
        }] {
            assert!(data.damping.is_linear());
            let lin = Hull::new(&data, HullModel::LinearDamping).unwrap();
            let nl = Hull::new(&data, HullModel::NonlinearDamping).unwrap();
            let nu = Vector3::new(0.7, -0.3, 0.4);
            assert_eq!(lin.D(&nu), nl.D(&nu));
        }
    }

    /// vessels.md check values: steady surge speed of CyberShip II under a
    /// constant surge force (nonlinear damping), within 1 %.
    #[test]
    fn cybership2_steady_surge_speeds() {
        let hull = Hull::new(&VesselData::cybership2(), HullModel::NonlinearDamping).unwrap();
        let cases = [
            (0.5, 0.302),
            (1.0, 0.426),
            (2.0, 0.579),
            (3.0, 0.685),
            (4.0, 0.768),
            (6.0, 0.900),
        ];
        for (force, speed) in cases {
            let mut nu = Vector3::zeros();
            let tau = Vector3::new(force, 0.0, 0.0);
            let h = 0.01;
            for _ in 0..30_000 {
                // 300 s, > 30 time constants (25.8 kg / 3.1 kg/s ~ 8 s at 0.3 m/s).
                let k1 = hull.nu_dot(&nu, &tau);
                let k2 = hull.nu_dot(&(nu + k1 * (h / 2.0)), &tau);
                let k3 = hull.nu_dot(&(nu + k2 * (h / 2.0)), &tau);
                let k4 = hull.nu_dot(&(nu + k3 * h), &tau);
                nu += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
            }
            let rel = (nu[0] - speed).abs() / speed;
            assert!(rel < 0.01, "{force} N: {} m/s, expected {speed}", nu[0]);
            assert!(nu[1].abs() < 1e-12 && nu[2].abs() < 1e-12);
            // Steady state: the damping balances the force.
            assert!(hull.nu_dot(&nu, &tau).norm() < 1e-9);
        }
    }

    /// The paper's ship damping is not dissipative at low speed (module docs).
    /// Pins the counter-example nu = [0, 0.05, -0.1] for both hull models and shows
    /// that free decay from there really increases T.
    #[test]
    fn cybership2_damping_is_not_dissipative_at_low_sway_and_yaw() {
        let nu = Vector3::new(0.0, 0.05, -0.1);
        let expected = [
            (HullModel::NonlinearDamping, 0.010_281_153_75),
            (HullModel::LinearDamping, 0.014_869_375),
        ];
        for (model, power) in expected {
            let hull = Hull::new(&VesselData::cybership2(), model).unwrap();
            let dt = hull.power_balance(&nu, &Vector3::zeros());
            assert!((dt - power).abs() < 1e-12, "{model:?}: dT/dt = {dt}");
            // nu^T M nu_dot gives the same power.
            let nu_dot = hull.nu_dot(&nu, &Vector3::zeros());
            assert!((nu.dot(&(hull.M() * nu_dot)) - dt).abs() < 1e-12);
            // And a 0.5 s RK4 free decay gains energy.
            let t0 = hull.kinetic_energy(&nu);
            let mut x = [nu[0], nu[1], nu[2]];
            for _ in 0..50 {
                x = rk4_free(&hull, x, 0.01);
            }
            let t1 = hull.kinetic_energy(&Vector3::from(x));
            assert!(t1 > t0 * 1.01, "{model:?}: T {t0} -> {t1}");
        }
        // Outside the low-speed box the nonlinear terms dominate: dissipative.
        let hull = Hull::new(&VesselData::cybership2(), HullModel::NonlinearDamping).unwrap();
        assert!(hull.power_balance(&Vector3::new(0.0, 0.3, -0.5), &Vector3::zeros()) < 0.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn coriolis_is_skew_symmetric(u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0) {
            let nu = Vector3::new(u, v, r);
            for (name, hull) in hulls() {
                let c = hull.C(&nu);
                prop_assert!((c + c.transpose()).abs().max() == 0.0, "{name}: {c}");
                prop_assert!(nu.dot(&(c * nu)).abs() < 1e-12);
            }
        }

        #[test]
        fn fast_path_matches_matrix_form(
            u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0,
            tu in -10.0f64..10.0, tv in -10.0f64..10.0, tr in -10.0f64..10.0,
        ) {
            let nu = Vector3::new(u, v, r);
            let tau = Vector3::new(tu, tv, tr);
            for (name, hull) in hulls() {
                let slow = hull.M_inv() * (tau - hull.C(&nu) * nu - hull.D(&nu) * nu);
                let fast = hull.nu_dot(&nu, &tau);
                prop_assert!((slow - fast).abs().max() < 1e-10 * (1.0 + slow.abs().max()), "{name}");
            }
        }

        /// C does no work: dT/dt = nu^T M nu_dot equals nu^T tau - nu^T D nu.
        #[test]
        fn power_balance_is_exact(
            u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0,
            tu in -10.0f64..10.0, tv in -10.0f64..10.0, tr in -10.0f64..10.0,
        ) {
            let nu = Vector3::new(u, v, r);
            let tau = Vector3::new(tu, tv, tr);
            for (name, hull) in hulls() {
                let from_dynamics = nu.dot(&(hull.M() * hull.nu_dot(&nu, &tau)));
                let balance = hull.power_balance(&nu, &tau);
                prop_assert!((from_dynamics - balance).abs() < 1e-9 * (1.0 + balance.abs()), "{name}: {from_dynamics} vs {balance}");
            }
        }

        /// CyberShip II with nonlinear damping is dissipative outside the low-speed
        /// box of the module docs (|v| < 0.163 m/s, |r| < 0.36 rad/s).
        #[test]
        fn cybership2_nonlinear_is_dissipative_outside_the_low_speed_box(
            u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0,
        ) {
            prop_assume!(v.abs() >= 0.17 || r.abs() >= 0.37);
            let hull = Hull::new(&VesselData::cybership2(), HullModel::NonlinearDamping).unwrap();
            let nu = Vector3::new(u, v, r);
            prop_assert!(hull.power_balance(&nu, &Vector3::zeros()) < 0.0, "{nu}");
        }

        /// Tug (set A and B, both hull models): sym(D) > 0, so nu^T D nu > 0.
        #[test]
        fn tug_damping_is_dissipative(u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0) {
            prop_assume!(u != 0.0 || v != 0.0 || r != 0.0);
            let nu = Vector3::new(u, v, r);
            for (name, hull) in hulls().into_iter().filter(|(n, _)| n.starts_with("titoneri")) {
                prop_assert!(hull.power_balance(&nu, &Vector3::zeros()) < 0.0, "{name}");
            }
        }
    }
}

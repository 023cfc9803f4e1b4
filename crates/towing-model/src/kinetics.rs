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
//! 2004), and `D(nu)` from the damping derivatives ([`Damping`]). Symbols follow
//! Fossen in ASCII; vectors are `nalgebra::Vector3`.
//!
//! # Hull models
//!
//! The kinetics of one hull (everything but the kinematics `eta_dot = R(psi) nu`,
//! which is the same for every hull) are behind the trait [`HullDynamics`]. Two
//! implementations come with the crate, selected by the plant parameter
//! [`HullModel`] (`WorldConfig::hull_model`, the scenario's
//! `[simulation] hull_model`, the plant FMU's `hull_model` parameter):
//!
//! - [`LinearDampingHull`] ([`HullModel::LinearDamping`]): constant
//!   `D = -[[X_u, 0, 0], [0, Y_v, Y_r], [0, N_v, N_r]]`, the paper's eq. (1);
//! - [`NonlinearDampingHull`] ([`HullModel::NonlinearDamping`], the default): the
//!   full `D(nu)` of Skjetne et al. (2004) with `|.|`-quadratic and cubic terms.
//!
//! Both take `M` and the damping derivatives from a validated [`VesselData`] and
//! override [`HullDynamics::nu_dot`] with an expanded form that is exactly the
//! matrix form ([`nu_dot_matrix_form`]) written out (the integrator's hot path).
//!
//! # Implementing your own hull
//!
//! A higher-fidelity hull (another damping law, a non-diagonal added mass, a
//! Coriolis matrix of a different parametrisation, ...) implements [`HullDynamics`]
//! and is handed to `World::with_hulls` (one boxed hull per vessel: index 0 ship,
//! 1 tug 1 (aft), 2 tug 2 (forward)). The minimum is three matrices and
//! `clone_box`:
//!
//! ```
//! use nalgebra::{Matrix3, Vector3};
//! use towing_model::kinetics::{HullDynamics, NonlinearDampingHull};
//! use towing_model::VesselData;
//!
//! /// CyberShip II with twice the identified damping (e.g. a fouled hull).
//! #[derive(Debug, Clone)]
//! struct FouledHull(NonlinearDampingHull);
//!
//! impl HullDynamics for FouledHull {
//!     fn mass_matrix(&self) -> &Matrix3<f64> {
//!         self.0.mass_matrix()
//!     }
//!     fn mass_matrix_inv(&self) -> &Matrix3<f64> {
//!         self.0.mass_matrix_inv()
//!     }
//!     fn damping_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
//!         self.0.damping_matrix(nu) * 2.0
//!     }
//!     fn clone_box(&self) -> Box<dyn HullDynamics> {
//!         Box::new(self.clone())
//!     }
//! }
//!
//! let hull = FouledHull(NonlinearDampingHull::new(&VesselData::cybership2())?);
//! // Default nu_dot = M^-1 (tau - C(nu) nu - D(nu) nu): 1 N of surge at rest.
//! let nu_dot = hull.nu_dot(&[0.0; 3], &[1.0, 0.0, 0.0]);
//! assert!((nu_dot[0] - 1.0 / 25.8).abs() < 1e-12);
//! # Ok::<(), towing_model::ParamError>(())
//! ```
//!
//! Units and frames: SI throughout. `nu = [u (m/s), v (m/s), r (rad/s)]` are the
//! body-frame velocities of the body origin CO (the point `eta` describes and from
//! which the towing points are measured, x forward, y starboard, z down);
//! `tau = [X (N), Y (N), N (N m)]` is the generalised force on the hull in the same
//! body frame about CO (thrusters plus towlines, as the world sums them). `M`, `C`
//! and `D` must be expressed about CO as well (if your data are about the CG,
//! transform them, Fossen 2021, sec. 3.3).
//!
//! What the rest of the code relies on:
//!
//! - `M` is constant, symmetric and positive definite, and
//!   [`HullDynamics::mass_matrix_inv`] is its inverse. `World::with_hulls` checks
//!   this (exact symmetry, Cholesky, `M^-1 M = I` to 1e-9) and refuses the hull
//!   otherwise. The kinetic energy `T = 1/2 nu^T M nu` is only an energy for a
//!   symmetric `M`.
//! - `C(nu)` is skew-symmetric (`C = -C^T`, so `nu^T C nu = 0`: Coriolis does no
//!   work). The default [`HullDynamics::power_balance`] drops the Coriolis term on
//!   that basis; `World::with_hulls` checks skew-symmetry at a few reference
//!   velocities. The default [`HullDynamics::coriolis_matrix`] (Fossen's `m2c`
//!   from `M`) is skew-symmetric by construction; every 3-DoF `M` has such a
//!   parametrisation (Fossen 2021, Theorem 3.2).
//! - `D(nu)` needs no symmetry (CyberShip II's is far from symmetric, see below);
//!   dissipativity is a property of the data, not a requirement of the code.
//! - Every method is a deterministic pure function of its arguments (no interior
//!   mutability, no randomness, no dependence on wall time): the world's steps are
//!   reproducible bit for bit and the saved-state fingerprint samples the hull's
//!   matrices. Return finite values for finite inputs: a non-finite `nu_dot` makes
//!   the step fail (`StepError::NonFinite`), the world is then unchanged.
//! - [`HullDynamics::nu_dot`] is called once per vessel per RK4 stage (four
//!   times per substep) and must not allocate (the world promises allocation-free
//!   steps). Override it only with an exact rearrangement of the default; [`nu_dot_matrix_form`] is the reference to test
//!   an override against.
//!
//! # Energy and passivity
//!
//! The kinetic energy is `T = 1/2 nu^T M nu`. Because `M` is symmetric and constant
//! and `C(nu)` is skew-symmetric, `C` does no work and
//! `dT/dt = nu^T tau - nu^T D(nu) nu` exactly ([`HullDynamics::power_balance`]).
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

use crate::registry::{Enumeration, Item};
use crate::vessel::{Damping, ParamError, VesselData};

/// Which built-in hull model the world uses: the damping law (scenario `[simulation]
/// hull_model`, the plant's parameter `model.hull`, the controller's `mpc.hull_model`).
/// [`HullModel::build`] makes the [`HullDynamics`] of one vessel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HullModel {
    /// [`LinearDampingHull`]: constant `D = -[[X_u, 0, 0], [0, Y_v, Y_r], [0, N_v,
    /// N_r]]` from the linear derivatives only: the form of the paper's eq. (1) and
    /// of its prediction model (eq. (15)-(16)).
    LinearDamping,
    /// [`NonlinearDampingHull`]: the full `D(nu)` of Skjetne et al. (2004) for
    /// CyberShip II (linear, `|.|`-quadratic and cubic terms). The tug has only
    /// linear data, so it is the same under both models. Default: the plant
    /// represents the identified vessel.
    #[default]
    NonlinearDamping,
}

impl HullModel {
    /// The FMI Enumeration type `HullModel` of the parameters that choose a hull model
    /// (FMI 2.0 section 2.2.3): 1 `linear_damping`, 2 `nonlinear_damping` (the scenario
    /// format's names; the codes the masters have always used).
    pub const ENUMERATION: Enumeration = Enumeration {
        name: "HullModel",
        description: "Hull damping model",
        items: &[
            Item {
                name: "linear_damping",
                value: 1,
                description: "constant D from the linear derivatives, the paper's eq. (1)",
            },
            Item {
                name: "nonlinear_damping",
                value: 2,
                description: "the full D(nu) of Skjetne et al. (2004) for CyberShip II",
            },
        ],
    };

    /// The value of its item of [`HullModel::ENUMERATION`].
    #[must_use]
    pub const fn code(self) -> i32 {
        match self {
            HullModel::LinearDamping => 1,
            HullModel::NonlinearDamping => 2,
        }
    }

    /// The hull model of an item's value of [`HullModel::ENUMERATION`]; `None` for
    /// another value.
    #[must_use]
    pub const fn from_code(code: i32) -> Option<HullModel> {
        match code {
            1 => Some(HullModel::LinearDamping),
            2 => Some(HullModel::NonlinearDamping),
            _ => None,
        }
    }

    /// Builds this model's hull for one vessel; validates the data
    /// ([`VesselData::validate`]) first. The only allocation is the box.
    pub fn build(self, data: &VesselData) -> Result<Box<dyn HullDynamics>, ParamError> {
        Ok(match self {
            HullModel::LinearDamping => Box::new(LinearDampingHull::new(data)?),
            HullModel::NonlinearDamping => Box::new(NonlinearDampingHull::new(data)?),
        })
    }
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

/// The kinetics of one hull in Fossen's form `M nu_dot + C(nu) nu + D(nu) nu = tau`
/// (Fossen 2021, eq. 6.1; Du et al. 2022, eq. (1)). See the module docs for units,
/// frames, the properties the rest of the code relies on and an example.
///
/// Required: [`mass_matrix`](HullDynamics::mass_matrix),
/// [`mass_matrix_inv`](HullDynamics::mass_matrix_inv),
/// [`damping_matrix`](HullDynamics::damping_matrix) and
/// [`clone_box`](HullDynamics::clone_box) (`Box::new(self.clone())`, which makes
/// `Box<dyn HullDynamics>` and so the world [`Clone`]). Everything else has a
/// default from those.
pub trait HullDynamics: std::fmt::Debug + Send + Sync {
    /// The total mass matrix `M = M_RB + M_A` about CO (kg, kg m, kg m^2):
    /// constant, symmetric, positive definite.
    fn mass_matrix(&self) -> &Matrix3<f64>;

    /// `M^-1`, computed once.
    fn mass_matrix_inv(&self) -> &Matrix3<f64>;

    /// The damping matrix `D(nu)` (kg/s, kg m/s, kg m^2/s): the hydrodynamic
    /// damping force is `-D(nu) nu`. No symmetry required.
    fn damping_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64>;

    /// The Coriolis-centripetal matrix `C(nu)` (rigid body plus added mass); must
    /// be skew-symmetric. Default: [`C`] from [`HullDynamics::mass_matrix`]
    /// (Fossen 2021, Theorem 3.2).
    fn coriolis_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        C(self.mass_matrix(), nu)
    }

    /// `nu_dot = M^-1 (tau - C(nu) nu - D(nu) nu)` (m/s^2, m/s^2, rad/s^2) for body
    /// velocities `nu = [u, v, r]` and the generalised force `tau = [X, Y, N]` (N,
    /// N, N m). Default: [`nu_dot_matrix_form`]. Implementors may override it with
    /// a faster, exactly equivalent form (the integrator's hot path); it must not
    /// allocate.
    ///
    /// The arguments are references so that the world can pass `nu` in place from
    /// its state vector: a freshly stored by-value copy read back with a different
    /// access width across the dynamic call stalls store-to-load forwarding (about
    /// 25 % of a world step when measured).
    fn nu_dot(&self, nu: &[f64; 3], tau: &[f64; 3]) -> [f64; 3] {
        nu_dot_matrix_form(self, nu, tau)
    }

    /// Kinetic energy `T = 1/2 nu^T M nu` (J).
    fn kinetic_energy(&self, nu: &Vector3<f64>) -> f64 {
        0.5 * nu.dot(&(self.mass_matrix() * nu))
    }

    /// Power balance `dT/dt = nu^T tau - nu^T D(nu) nu` (W): the Coriolis terms do
    /// no work (skew-symmetric `C`). Equal to `nu^T M nu_dot` up to rounding.
    fn power_balance(&self, nu: &Vector3<f64>, tau: &Vector3<f64>) -> f64 {
        nu.dot(tau) - nu.dot(&(self.damping_matrix(nu) * nu))
    }

    /// A boxed copy (`Box::new(self.clone())`); backs `Clone for Box<dyn
    /// HullDynamics>`.
    fn clone_box(&self) -> Box<dyn HullDynamics>;
}

impl Clone for Box<dyn HullDynamics> {
    fn clone(&self) -> Self {
        (**self).clone_box()
    }
}

/// `M^-1 (tau - C(nu) nu - D(nu) nu)` from the hull's matrices: the default of
/// [`HullDynamics::nu_dot`], and the reference to test an override against.
#[must_use]
pub fn nu_dot_matrix_form<H: HullDynamics + ?Sized>(
    hull: &H,
    nu: &[f64; 3],
    tau: &[f64; 3],
) -> [f64; 3] {
    let nu = Vector3::from(*nu);
    let rhs = Vector3::from(*tau) - hull.coriolis_matrix(&nu) * nu - hull.damping_matrix(&nu) * nu;
    let out = hull.mass_matrix_inv() * rhs;
    [out[0], out[1], out[2]]
}

/// `M` and `M^-1` of validated data.
fn mass_matrices(data: &VesselData) -> Result<(Matrix3<f64>, Matrix3<f64>), ParamError> {
    data.validate()?;
    let M = data.mass_matrix();
    let M_inv = M
        .try_inverse()
        .ok_or_else(|| ParamError::new("", "the mass matrix is singular"))?;
    Ok((M, M_inv))
}

/// `D` from its five non-zero entries `[d11, d22, d23, d32, d33]`.
fn damping_from_entries([d11, d22, d23, d32, d33]: [f64; 5]) -> Matrix3<f64> {
    Matrix3::new(d11, 0.0, 0.0, 0.0, d22, d23, 0.0, d32, d33)
}

/// `[d11, d22, d23, d32, d33]` of the linear `D`.
#[inline]
fn linear_damping_entries(d: &Damping) -> [f64; 5] {
    [-d.x_u, -d.y_v, -d.y_r, -d.n_v, -d.n_r]
}

/// `[d11, d22, d23, d32, d33]` of the nonlinear `D(nu)` (Skjetne et al. 2004).
#[inline]
fn nonlinear_damping_entries(d: &Damping, u: f64, v: f64, r: f64) -> [f64; 5] {
    let (au, av, ar) = (u.abs(), v.abs(), r.abs());
    [
        -d.x_u - d.x_absu_u * au - d.x_uuu * u * u,
        -d.y_v - d.y_absv_v * av - d.y_absr_v * ar,
        -d.y_r - d.y_absv_r * av - d.y_absr_r * ar,
        -d.n_v - d.n_absv_v * av - d.n_absr_v * ar,
        -d.n_r - d.n_absv_r * av - d.n_absr_r * ar,
    ]
}

/// `nu_dot` with `C(nu) nu` (Fossen's `m2c` from a symmetric `M`) and `D nu`
/// (`D` with the sparsity of [`Damping`]) written out; the exact expansion of
/// [`nu_dot_matrix_form`].
#[inline(always)]
fn nu_dot_expanded(
    M: &Matrix3<f64>,
    M_inv: &Matrix3<f64>,
    [d11, d22, d23, d32, d33]: [f64; 5],
    &[u, v, r]: &[f64; 3],
    tau: &[f64; 3],
) -> [f64; 3] {
    // C(nu) nu with a = m21 u + m22 v + m23 r, b = m11 u + m12 v + m13 r.
    let a = M[(1, 0)] * u + M[(1, 1)] * v + M[(1, 2)] * r;
    let b = M[(0, 0)] * u + M[(0, 1)] * v + M[(0, 2)] * r;
    let cnu = [-a * r, b * r, a * u - b * v];
    let dnu = [d11 * u, d22 * v + d23 * r, d32 * v + d33 * r];
    let rhs = Vector3::new(
        tau[0] - cnu[0] - dnu[0],
        tau[1] - cnu[1] - dnu[1],
        tau[2] - cnu[2] - dnu[2],
    );
    let out = M_inv * rhs;
    [out[0], out[1], out[2]]
}

/// The paper's hull, eq. (1) of Du et al. (2022): `M` from the data and the
/// constant `D = -[[X_u, 0, 0], [0, Y_v, Y_r], [0, N_v, N_r]]` of the linear
/// derivatives ([`HullModel::LinearDamping`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearDampingHull {
    M: Matrix3<f64>,
    M_inv: Matrix3<f64>,
    damping: Damping,
    D: Matrix3<f64>,
    d: [f64; 5],
}

impl LinearDampingHull {
    /// Builds the hull; validates the data ([`VesselData::validate`]) first.
    pub fn new(data: &VesselData) -> Result<Self, ParamError> {
        let (M, M_inv) = mass_matrices(data)?;
        let d = linear_damping_entries(&data.damping);
        Ok(LinearDampingHull {
            M,
            M_inv,
            damping: data.damping,
            D: damping_from_entries(d),
            d,
        })
    }

    /// The damping derivatives (only the five linear ones are used).
    #[must_use]
    pub fn damping(&self) -> &Damping {
        &self.damping
    }
}

impl HullDynamics for LinearDampingHull {
    fn mass_matrix(&self) -> &Matrix3<f64> {
        &self.M
    }

    fn mass_matrix_inv(&self) -> &Matrix3<f64> {
        &self.M_inv
    }

    /// The constant linear `D`.
    fn damping_matrix(&self, _nu: &Vector3<f64>) -> Matrix3<f64> {
        self.D
    }

    /// Expanded exact form of the default.
    fn nu_dot(&self, nu: &[f64; 3], tau: &[f64; 3]) -> [f64; 3] {
        nu_dot_expanded(&self.M, &self.M_inv, self.d, nu, tau)
    }

    fn clone_box(&self) -> Box<dyn HullDynamics> {
        Box::new(*self)
    }
}

/// The identified hull of Skjetne, Smogeli, Fossen (2004): `M` from the data and
/// the full `D(nu)` of [`Damping`] (linear, `|.|`-quadratic and cubic terms;
/// [`HullModel::NonlinearDamping`]). With purely linear data (the TitoNeri tug) it
/// equals [`LinearDampingHull`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NonlinearDampingHull {
    M: Matrix3<f64>,
    M_inv: Matrix3<f64>,
    damping: Damping,
}

impl NonlinearDampingHull {
    /// Builds the hull; validates the data ([`VesselData::validate`]) first.
    pub fn new(data: &VesselData) -> Result<Self, ParamError> {
        let (M, M_inv) = mass_matrices(data)?;
        Ok(NonlinearDampingHull {
            M,
            M_inv,
            damping: data.damping,
        })
    }

    /// The damping derivatives.
    #[must_use]
    pub fn damping(&self) -> &Damping {
        &self.damping
    }
}

impl HullDynamics for NonlinearDampingHull {
    fn mass_matrix(&self) -> &Matrix3<f64> {
        &self.M
    }

    fn mass_matrix_inv(&self) -> &Matrix3<f64> {
        &self.M_inv
    }

    /// `D(nu)` of Skjetne et al. (2004), entries as in [`Damping`].
    fn damping_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        damping_from_entries(nonlinear_damping_entries(
            &self.damping,
            nu[0],
            nu[1],
            nu[2],
        ))
    }

    /// Expanded exact form of the default.
    fn nu_dot(&self, nu: &[f64; 3], tau: &[f64; 3]) -> [f64; 3] {
        let d = nonlinear_damping_entries(&self.damping, nu[0], nu[1], nu[2]);
        nu_dot_expanded(&self.M, &self.M_inv, d, nu, tau)
    }

    fn clone_box(&self) -> Box<dyn HullDynamics> {
        Box::new(*self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn hulls() -> Vec<(&'static str, Box<dyn HullDynamics>)> {
        let mut out = Vec::new();
        for model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
            out.push((
                "cybership2",
                model.build(&VesselData::cybership2()).unwrap(),
            ));
            out.push(("titoneri A", model.build(&VesselData::titoneri()).unwrap()));
            let mut b = VesselData::titoneri();
            b.damping = Damping::titoneri_set_b();
            out.push(("titoneri B", model.build(&b).unwrap()));
        }
        out
    }

    fn build(model: HullModel) -> Box<dyn HullDynamics> {
        model.build(&VesselData::cybership2()).unwrap()
    }

    /// `nu_dot` on vectors.
    fn nu_dot(hull: &dyn HullDynamics, nu: &Vector3<f64>, tau: &Vector3<f64>) -> Vector3<f64> {
        Vector3::from(hull.nu_dot(&[nu[0], nu[1], nu[2]], &[tau[0], tau[1], tau[2]]))
    }

    fn rk4_free(hull: &dyn HullDynamics, nu: [f64; 3], h: f64) -> [f64; 3] {
        let f = |x: [f64; 3]| hull.nu_dot(&x, &[0.0; 3]);
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

    /// A hull that keeps every default: the built-in matrices, the trait's
    /// matrix-form `nu_dot`.
    #[derive(Debug, Clone)]
    struct DefaultsOnly(Box<dyn HullDynamics>);

    impl HullDynamics for DefaultsOnly {
        fn mass_matrix(&self) -> &Matrix3<f64> {
            self.0.mass_matrix()
        }
        fn mass_matrix_inv(&self) -> &Matrix3<f64> {
            self.0.mass_matrix_inv()
        }
        fn damping_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
            self.0.damping_matrix(nu)
        }
        fn clone_box(&self) -> Box<dyn HullDynamics> {
            Box::new(self.clone())
        }
    }

    #[test]
    fn cybership2_coriolis_matches_reference_form() {
        // vessels.md: C = [[0,0,-(m22 v + m23 r)],[0,0,m11 u],[m22 v + m23 r,-m11 u,0]].
        let hull = build(HullModel::LinearDamping);
        let nu = Vector3::new(0.3, -0.1, 0.2);
        let a = 33.8 * nu[1] + 1.0948 * nu[2];
        let expected = Matrix3::new(0.0, 0.0, -a, 0.0, 0.0, 25.8 * nu[0], a, -25.8 * nu[0], 0.0);
        assert!((hull.coriolis_matrix(&nu) - expected).abs().max() < 1e-12);
    }

    #[test]
    fn linear_damping_matrix_is_constant_and_signed_as_published() {
        let hull = build(HullModel::LinearDamping);
        let d = hull.damping_matrix(&Vector3::new(1.0, 0.5, -0.3));
        let expected = Matrix3::new(0.72253, 0.0, 0.0, 0.0, 0.88965, 7.25, 0.0, -0.0313, 1.9);
        assert!((d - expected).abs().max() < 1e-12, "{d}");
        assert_eq!(hull.damping_matrix(&Vector3::zeros()), d);
    }

    #[test]
    fn tug_is_the_same_under_both_hull_models() {
        for data in [VesselData::titoneri(), {
            let mut b = VesselData::titoneri();
            b.damping = Damping::titoneri_set_b();
            b
        }] {
            assert!(data.damping.is_linear());
            let lin = HullModel::LinearDamping.build(&data).unwrap();
            let nl = HullModel::NonlinearDamping.build(&data).unwrap();
            let nu = Vector3::new(0.7, -0.3, 0.4);
            assert_eq!(lin.damping_matrix(&nu), nl.damping_matrix(&nu));
        }
    }

    #[test]
    fn constructors_validate_the_data() {
        let mut bad = VesselData::cybership2();
        bad.mass = -1.0;
        assert_eq!(LinearDampingHull::new(&bad).unwrap_err().field, "mass");
        assert_eq!(NonlinearDampingHull::new(&bad).unwrap_err().field, "mass");
        for model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
            assert_eq!(model.build(&bad).unwrap_err().field, "mass");
        }
        let hull = NonlinearDampingHull::new(&VesselData::cybership2()).unwrap();
        assert_eq!(*hull.damping(), Damping::cybership2());
        assert_eq!(*hull.mass_matrix(), VesselData::cybership2().mass_matrix());
        let identity = hull.mass_matrix() * hull.mass_matrix_inv();
        assert!((identity - Matrix3::identity()).abs().max() < 1e-12);
    }

    #[test]
    fn boxed_hulls_clone() {
        for (name, hull) in hulls() {
            let copy = hull.clone();
            let (nu, tau) = ([0.4, -0.2, 0.3], [1.0, 0.5, -0.1]);
            assert_eq!(copy.nu_dot(&nu, &tau), hull.nu_dot(&nu, &tau), "{name}");
            assert_eq!(copy.mass_matrix(), hull.mass_matrix());
        }
    }

    /// The trait objects reproduce the former `Hull::nu_dot_arr` bit for bit
    /// (values recorded from the pre-trait implementation).
    #[test]
    fn nu_dot_is_unchanged_by_the_trait_refactor() {
        let points = [
            ([0.3, -0.1, 0.2], [1.0, 0.5, -0.2]),
            ([-0.7, 0.4, -0.9], [-2.0, 1.5, 0.3]),
            ([1.2, 0.05, 0.6], [4.0, -3.0, 1.0]),
        ];
        let tug_a: [u64; 9] = [
            13812406531636801172,
            4583608106480549629,
            4602323834142278244,
            13832009262648676091,
            13822398931376119872,
            4618642510415441538,
            4594767572131314826,
            13821517305077870798,
            13828909920435018512,
        ];
        let tug_b: [u64; 9] = [
            13810826201110320738,
            4568913949663792886,
            4596436167221633779,
            13832124495082898622,
            13819638438742557339,
            4620080552667885959,
            4596347902657795261,
            13821491114704243549,
            13834243118206734765,
        ];
        let ship_linear: [u64; 9] = [
            4573399215704275421,
            13812888864089032384,
            13816785017940174974,
            13825963884885409443,
            13822443846186388968,
            4609044208512068095,
            4595509496333653297,
            13828407451313488149,
            13820018035023023130,
        ];
        let ship_nonlinear: [u64; 9] = [
            13795689624949702709,
            13812140928169791336,
            13817944240461079596,
            13824104756164560954,
            13824347546604778301,
            4611286587878280780,
            13822285695809003706,
            13828753533104597130,
            13822164686845480095,
        ];
        let expected = [ship_linear, tug_a, tug_b, ship_nonlinear, tug_a, tug_b];
        for ((name, hull), expected) in hulls().into_iter().zip(expected) {
            let bits: Vec<u64> = points
                .iter()
                .flat_map(|(nu, tau)| hull.nu_dot(nu, tau))
                .map(f64::to_bits)
                .collect();
            assert_eq!(bits, expected, "{name}");
        }
    }

    /// vessels.md check values: steady surge speed of CyberShip II under a
    /// constant surge force (nonlinear damping), within 1 %.
    #[test]
    fn cybership2_steady_surge_speeds() {
        let hull = build(HullModel::NonlinearDamping);
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
                let k1 = nu_dot(&*hull, &nu, &tau);
                let k2 = nu_dot(&*hull, &(nu + k1 * (h / 2.0)), &tau);
                let k3 = nu_dot(&*hull, &(nu + k2 * (h / 2.0)), &tau);
                let k4 = nu_dot(&*hull, &(nu + k3 * h), &tau);
                nu += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
            }
            let rel = (nu[0] - speed).abs() / speed;
            assert!(rel < 0.01, "{force} N: {} m/s, expected {speed}", nu[0]);
            assert!(nu[1].abs() < 1e-12 && nu[2].abs() < 1e-12);
            // Steady state: the damping balances the force.
            assert!(nu_dot(&*hull, &nu, &tau).norm() < 1e-9);
        }
    }

    /// Linear damping: the steady surge speed is exactly `X / d11`.
    #[test]
    fn cybership2_linear_steady_surge_speed() {
        let hull = build(HullModel::LinearDamping);
        for force in [0.5, 2.0, 6.0] {
            let u = force / 0.722_53;
            assert!(hull.nu_dot(&[u, 0.0, 0.0], &[force, 0.0, 0.0])[0].abs() < 1e-14);
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
            let hull = build(model);
            let dt = hull.power_balance(&nu, &Vector3::zeros());
            assert!((dt - power).abs() < 1e-12, "{model:?}: dT/dt = {dt}");
            // nu^T M nu_dot gives the same power.
            let nu_dot = nu_dot(&*hull, &nu, &Vector3::zeros());
            assert!((nu.dot(&(hull.mass_matrix() * nu_dot)) - dt).abs() < 1e-12);
            // And a 0.5 s RK4 free decay gains energy.
            let t0 = hull.kinetic_energy(&nu);
            let mut x = [nu[0], nu[1], nu[2]];
            for _ in 0..50 {
                x = rk4_free(&*hull, x, 0.01);
            }
            let t1 = hull.kinetic_energy(&Vector3::from(x));
            assert!(t1 > t0 * 1.01, "{model:?}: T {t0} -> {t1}");
        }
        // Outside the low-speed box the nonlinear terms dominate: dissipative.
        let hull = build(HullModel::NonlinearDamping);
        assert!(hull.power_balance(&Vector3::new(0.0, 0.3, -0.5), &Vector3::zeros()) < 0.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn coriolis_is_skew_symmetric(u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0) {
            let nu = Vector3::new(u, v, r);
            for (name, hull) in hulls() {
                let c = hull.coriolis_matrix(&nu);
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
                let slow = hull.mass_matrix_inv()
                    * (tau - hull.coriolis_matrix(&nu) * nu - hull.damping_matrix(&nu) * nu);
                let fast = nu_dot(&*hull, &nu, &tau);
                prop_assert!((slow - fast).abs().max() < 1e-10 * (1.0 + slow.abs().max()), "{name}");
            }
        }

        /// The trait's default `nu_dot` (matrix form, through a wrapper that
        /// overrides nothing, and [`nu_dot_matrix_form`] directly) agrees with each
        /// implementation's expanded fast path.
        #[test]
        fn default_nu_dot_agrees_with_the_fast_paths(
            u in -3.0f64..3.0, v in -2.0f64..2.0, r in -3.0f64..3.0,
            tu in -10.0f64..10.0, tv in -10.0f64..10.0, tr in -10.0f64..10.0,
        ) {
            let (nu, tau) = ([u, v, r], [tu, tv, tr]);
            for (name, hull) in hulls() {
                let fast = hull.nu_dot(&nu, &tau);
                let reference = nu_dot_matrix_form(&*hull, &nu, &tau);
                let defaults = DefaultsOnly(hull.clone());
                prop_assert_eq!(defaults.nu_dot(&nu, &tau), reference);
                let scale = 1.0 + reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                for k in 0..3 {
                    prop_assert!((fast[k] - reference[k]).abs() < 1e-10 * scale, "{}: {:?} vs {:?}", name, fast, reference);
                }
                let nu = Vector3::from(nu);
                let tau = Vector3::from(tau);
                prop_assert_eq!(defaults.kinetic_energy(&nu), hull.kinetic_energy(&nu));
                prop_assert_eq!(defaults.power_balance(&nu, &tau), hull.power_balance(&nu, &tau));
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
                let from_dynamics = nu.dot(&(hull.mass_matrix() * nu_dot(&*hull, &nu, &tau)));
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
            let hull = build(HullModel::NonlinearDamping);
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

    #[test]
    fn hull_models_are_the_items_of_their_enumeration() {
        let items = HullModel::ENUMERATION.items;
        assert_eq!(items.len(), 2);
        for (item, model) in items
            .iter()
            .zip([HullModel::LinearDamping, HullModel::NonlinearDamping])
        {
            assert_eq!(model.code(), item.value, "{}", item.name);
            assert_eq!(HullModel::from_code(item.value), Some(model));
        }
        assert_eq!(items[0].name, "linear_damping");
        assert_eq!(HullModel::from_code(0), None);
        assert_eq!(HullModel::from_code(3), None);
    }
}

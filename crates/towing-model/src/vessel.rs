//! Vessel parameters: hull, mass, hydrodynamic derivatives, towing points, actuator
//! and winch limits, with the sourced presets of the two model ships.
//!
//! Hydrodynamic derivatives follow SNAME notation as in Fossen (2021) and Skjetne,
//! Smogeli, Fossen (2004): they are the (usually negative) coefficients of the
//! hydrodynamic force, e.g. `X_udot = -2.0` means 2.0 kg of added mass in surge and
//! the damping matrix entry is `d11 = -X_u - X_|u|u |u| - X_uuu u^2`.
//! Positions along the hull (`x_g`, towing points) are body x coordinates measured
//! from the body origin CO (the point whose position `eta` describes), forward
//! positive; all towing points lie on the centre line (body y = 0).

use std::fmt;

use nalgebra::Matrix3;

/// A parameter that failed validation: which field (path relative to the struct,
/// e.g. `damping.x_u`) and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParamError {
    /// Field path, as in the scenario file (e.g. `mass`, `damping.y_r`).
    pub field: String,
    /// Human-readable reason.
    pub reason: String,
}

impl ParamError {
    /// An error of `field` for `reason`.
    pub fn new(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Prefixes the field path (`prefix.field`).
    #[must_use]
    pub fn within(mut self, prefix: &str) -> Self {
        self.field = if self.field.is_empty() {
            prefix.to_owned()
        } else {
            format!("{prefix}.{}", self.field)
        };
        self
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field, self.reason)
    }
}

impl std::error::Error for ParamError {}

pub(crate) fn check_finite(field: &str, value: f64) -> Result<(), ParamError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ParamError::new(
            field,
            format!("must be finite, got {value}"),
        ))
    }
}

pub(crate) fn check_positive(field: &str, value: f64, unit: &str) -> Result<(), ParamError> {
    check_finite(field, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            field,
            format!("must be > 0 {unit}, got {value}"),
        ))
    }
}

/// The largest coordinate or length a scenario may give (m): 1e8 m, more than twice the
/// Earth's circumference, so every real chart fits (UTM northings reach 1e7 m), while the
/// model's geometry stays well within `f64`: squared distances below 1e17 m^2, and a
/// position's resolution (1.5e-8 m at 1e8 m) far below the millimetres a vessel moves in one
/// integration step. Beyond it a scenario is refused: `desired_length = 1.8e308` placed a tug
/// where the towline's length overflowed to infinity.
pub const MAX_DISTANCE: f64 = 1e8;

/// The largest speed a scenario may give (m/s): far above any vessel's, and small enough
/// that a target ship's track stays within `f64` for any simulated time.
pub const MAX_SPEED: f64 = 1e3;

/// A coordinate: finite and within [`MAX_DISTANCE`] of the origin.
pub(crate) fn check_coordinate(field: &str, value: f64) -> Result<(), ParamError> {
    check_finite(field, value)?;
    check_at_most(field, value.abs(), value, MAX_DISTANCE, "m", "MAX_DISTANCE")
}

/// A length: positive and at most [`MAX_DISTANCE`].
pub(crate) fn check_length(field: &str, value: f64) -> Result<(), ParamError> {
    check_positive(field, value, "m")?;
    check_at_most(field, value, value, MAX_DISTANCE, "m", "MAX_DISTANCE")
}

/// A speed: finite and at most [`MAX_SPEED`] in magnitude.
pub(crate) fn check_speed(field: &str, value: f64) -> Result<(), ParamError> {
    check_finite(field, value)?;
    check_at_most(field, value.abs(), value, MAX_SPEED, "m/s", "MAX_SPEED")
}

fn check_at_most(
    field: &str,
    magnitude: f64,
    value: f64,
    limit: f64,
    unit: &str,
    name: &str,
) -> Result<(), ParamError> {
    if magnitude <= limit {
        Ok(())
    } else {
        Err(ParamError::new(
            field,
            format!(
                "must be at most {limit:e} {unit} in magnitude ({name}: beyond any physical size, \
                 the geometry derived from it would overflow or lose the model's resolution), \
                 got {value:e} {unit}"
            ),
        ))
    }
}

pub(crate) fn check_non_negative(field: &str, value: f64, unit: &str) -> Result<(), ParamError> {
    check_finite(field, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            field,
            format!("must be >= 0 {unit}, got {value}"),
        ))
    }
}

/// Hydrodynamic damping derivatives (Skjetne et al. 2004, damping model and
/// Table 4; Fossen 2021, ch. 6). The damping matrix is
///
/// ```text
/// D(nu) = [[d11, 0, 0], [0, d22, d23], [0, d32, d33]]
/// d11 = -X_u - X_|u|u |u| - X_uuu u^2
/// d22 = -Y_v - Y_|v|v |v| - Y_|r|v |r|      d23 = -Y_r - Y_|v|r |v| - Y_|r|r |r|
/// d32 = -N_v - N_|v|v |v| - N_|r|v |r|      d33 = -N_r - N_|v|r |v| - N_|r|r |r|
/// ```
///
/// [`crate::HullModel::LinearDamping`] uses only the five linear derivatives
/// (`x_u`, `y_v`, `y_r`, `n_v`, `n_r`), which is the constant-`D` form of the
/// paper's eq. (1); [`crate::HullModel::NonlinearDamping`] uses all of them.
/// Units: forces in N, moments in N m, `u`, `v` in m/s, `r` in rad/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Damping {
    /// `X_u`, linear surge damping (kg/s).
    pub x_u: f64,
    /// `X_|u|u`, quadratic surge damping (kg/m).
    pub x_absu_u: f64,
    /// `X_uuu`, cubic surge damping (kg s/m^2).
    pub x_uuu: f64,
    /// `Y_v`, linear sway damping (kg/s).
    pub y_v: f64,
    /// `Y_|v|v`, quadratic sway damping (kg/m).
    pub y_absv_v: f64,
    /// `Y_|r|v`, sway force from `|r| v` (kg/rad).
    pub y_absr_v: f64,
    /// `Y_r`, linear sway force from yaw rate (kg m/(s rad)).
    pub y_r: f64,
    /// `Y_|v|r`, sway force from `|v| r` (kg/rad).
    pub y_absv_r: f64,
    /// `Y_|r|r`, sway force from `|r| r` (kg m/rad^2).
    pub y_absr_r: f64,
    /// `N_v`, linear yaw moment from sway velocity (kg m/s).
    pub n_v: f64,
    /// `N_|v|v`, yaw moment from `|v| v` (kg).
    pub n_absv_v: f64,
    /// `N_|r|v`, yaw moment from `|r| v` (kg m/rad).
    pub n_absr_v: f64,
    /// `N_r`, linear yaw damping (kg m^2/(s rad)).
    pub n_r: f64,
    /// `N_|v|r`, yaw moment from `|v| r` (kg m/rad).
    pub n_absv_r: f64,
    /// `N_|r|r`, quadratic yaw damping (kg m^2/rad^2).
    pub n_absr_r: f64,
}

impl Damping {
    /// All derivatives zero (no damping).
    pub const ZERO: Damping = Damping {
        x_u: 0.0,
        x_absu_u: 0.0,
        x_uuu: 0.0,
        y_v: 0.0,
        y_absv_v: 0.0,
        y_absr_v: 0.0,
        y_r: 0.0,
        y_absv_r: 0.0,
        y_absr_r: 0.0,
        n_v: 0.0,
        n_absv_v: 0.0,
        n_absr_v: 0.0,
        n_r: 0.0,
        n_absv_r: 0.0,
        n_absr_r: 0.0,
    };

    /// CyberShip II, identified by Skjetne, Smogeli, Fossen (2004), Table 4
    /// (values as listed in `reference/vessels.md`; several independent public
    /// implementations agree to the last digit; versions with `X_u = -2.0` or
    /// `Y_r = -0.725` are known typos and are not used).
    #[must_use]
    pub const fn cybership2() -> Damping {
        Damping {
            x_u: -0.722_53,
            x_absu_u: -1.327_42,
            x_uuu: -5.866_43,
            y_v: -0.889_65,
            y_absv_v: -36.472_87,
            y_absr_v: -0.805,
            y_r: -7.250,
            y_absv_r: -0.845,
            y_absr_r: -3.450,
            n_v: 0.031_30,
            n_absv_v: 3.956_45,
            n_absr_v: 0.130,
            n_r: -1.900,
            n_absv_r: 0.080,
            n_absr_r: -0.750,
        }
    }

    /// TitoNeri damping set A, the TU Delft Researchlab Autonomous Shipping's own
    /// (linear) estimate (`reference/vessels.md`): `d11 = 2.6416`, `d22 = 21.9034`,
    /// `d33 = 0.105`, `d23 = d32 = -1.0952`, i.e. `X_u = -2.6416`,
    /// `Y_v = -21.9034`, `N_r = -0.105`, `Y_r = N_v = 1.0952`. The lab quotes
    /// `d33` of about 0.525 at high yaw rates; there are no nonlinear terms, so the
    /// tug behaves the same under both hull models.
    ///
    /// Assumption: chosen as the default tug damping because it is the lab's
    /// estimate for the same hull; none of the candidate sets is confirmed as the
    /// published one (Haseltalab & Negenborn 2019 omit the damping).
    #[must_use]
    pub const fn titoneri_set_a() -> Damping {
        Damping {
            x_u: -2.6416,
            y_v: -21.9034,
            y_r: 1.0952,
            n_v: 1.0952,
            n_r: -0.105,
            ..Damping::ZERO
        }
    }

    /// TitoNeri damping set B, an uncited set published with the same mass data
    /// (`reference/vessels.md`): `X_u = -1.98`, `Y_v = -7.8`, `N_r = -3.87`, no
    /// coupling, no nonlinear terms. Kept selectable as data
    /// ([`TitoNeriDampingSet::B`], scenario key `damping_set = "B"`).
    #[must_use]
    pub const fn titoneri_set_b() -> Damping {
        Damping {
            x_u: -1.98,
            y_v: -7.8,
            n_r: -3.87,
            ..Damping::ZERO
        }
    }

    /// True when every nonlinear derivative is zero (then both hull models agree).
    #[must_use]
    pub fn is_linear(&self) -> bool {
        let Damping {
            x_absu_u,
            x_uuu,
            y_absv_v,
            y_absr_v,
            y_absv_r,
            y_absr_r,
            n_absv_v,
            n_absr_v,
            n_absv_r,
            n_absr_r,
            ..
        } = *self;
        [
            x_absu_u, x_uuu, y_absv_v, y_absr_v, y_absv_r, y_absr_r, n_absv_v, n_absr_v, n_absv_r,
            n_absr_r,
        ]
        .iter()
        .all(|&c| c == 0.0)
    }

    /// `(name, value)` of every derivative, in declaration order (scenario keys).
    #[must_use]
    pub fn fields(&self) -> [(&'static str, f64); 15] {
        [
            ("x_u", self.x_u),
            ("x_absu_u", self.x_absu_u),
            ("x_uuu", self.x_uuu),
            ("y_v", self.y_v),
            ("y_absv_v", self.y_absv_v),
            ("y_absr_v", self.y_absr_v),
            ("y_r", self.y_r),
            ("y_absv_r", self.y_absv_r),
            ("y_absr_r", self.y_absr_r),
            ("n_v", self.n_v),
            ("n_absv_v", self.n_absv_v),
            ("n_absr_v", self.n_absr_v),
            ("n_r", self.n_r),
            ("n_absv_r", self.n_absv_r),
            ("n_absr_r", self.n_absr_r),
        ]
    }

    /// Checks that every derivative is finite. Damping is deliberately *not*
    /// required to be dissipative: CyberShip II's identified set is not (see
    /// [`crate::kinetics`]).
    pub fn validate(&self) -> Result<(), ParamError> {
        for (name, value) in self.fields() {
            check_finite(name, value).map_err(|e| e.within("damping"))?;
        }
        Ok(())
    }
}

/// The two candidate damping sets of TitoNeri (`reference/vessels.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TitoNeriDampingSet {
    /// The lab's estimate, with sway-yaw coupling ([`Damping::titoneri_set_a`]). Default.
    #[default]
    A,
    /// The uncited diagonal set ([`Damping::titoneri_set_b`]).
    B,
}

impl TitoNeriDampingSet {
    /// The damping derivatives of this set.
    #[must_use]
    pub const fn damping(self) -> Damping {
        match self {
            TitoNeriDampingSet::A => Damping::titoneri_set_a(),
            TitoNeriDampingSet::B => Damping::titoneri_set_b(),
        }
    }
}

/// Parameters of one vessel, one field per physical quantity (SI units).
///
/// The mass matrix is `M = M_RB + M_A` (Fossen 2021, ch. 3 rigid-body kinetics and
/// ch. 6 added mass, 3-DoF form; Skjetne et al. 2004, Tables 1-2):
/// `M_RB = [[m, 0, 0], [0, m, m x_g], [0, m x_g, I_z]]`,
/// `M_A = -[[X_udot, 0, 0], [0, Y_vdot, Y_rdot], [0, N_vdot, N_rdot]]`;
/// [`crate::kinetics`] uses its symmetric part. Validate with
/// [`VesselData::validate`] (done once by the hull constructors,
/// [`crate::HullModel::build`], and by the scenario loader).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VesselData {
    /// Length overall `L` (m). Used for obstacle distances and plots.
    pub length: f64,
    /// Beam `B` (m).
    pub width: f64,
    /// Mass `m` (kg).
    pub mass: f64,
    /// Yaw moment of inertia `I_z` about the body z axis through CO (kg m^2), as it
    /// enters `M_RB`.
    pub inertia_z: f64,
    /// Longitudinal position of the centre of gravity from CO, `x_g` (m).
    pub x_g: f64,
    /// Added mass derivative `X_udot` (kg).
    pub x_udot: f64,
    /// Added mass derivative `Y_vdot` (kg).
    pub y_vdot: f64,
    /// Added mass derivative `Y_rdot` (kg m).
    pub y_rdot: f64,
    /// Added mass derivative `N_vdot` (kg m).
    pub n_vdot: f64,
    /// Added mass derivative `N_rdot` (kg m^2).
    pub n_rdot: f64,
    /// Damping derivatives.
    pub damping: Damping,
    /// Body x of the stern towing point from CO (m, negative = aft). The ship's
    /// stern point is towline 1's ship end; the forward tug (tug 2) tows from its
    /// stern point.
    pub stern_tow_point_x: f64,
    /// Body x of the bow towing point from CO (m). The ship's bow point is
    /// towline 2's ship end; the aft tug (tug 1) tows from its bow point.
    pub bow_tow_point_x: f64,
    /// Saturation of the actuator surge force, `|tau_u| <= max_surge_force` (N).
    pub max_surge_force: f64,
    /// Saturation of the actuator sway force (N).
    pub max_sway_force: f64,
    /// Saturation of the actuator yaw moment (N m).
    pub max_yaw_moment: f64,
    /// Maximum pull of this vessel's towing winch, `F_max` (N): commanded
    /// tensions are clamped to `[0, winch_max_tension]`.
    pub winch_max_tension: f64,
}

impl VesselData {
    /// CyberShip II, the towed ship (Skjetne, Smogeli, Fossen 2004; Du et al. 2022,
    /// Table 2).
    ///
    /// - `m = 23.8 kg`, `I_z = 1.76 kg m^2`, `x_g = 0.046 m`, `L x B = 1.255 x 0.29 m`:
    ///   Skjetne et al. (2004) Table 1. Du et al. (2022) Table 2 prints the length as
    ///   1.225 m; every other source, and the paper's own `l_1 + l_2 = 1.255 m`, give
    ///   1.255 m, so 1.225 is taken as a misprint.
    /// - `X_udot = -2.0`, `Y_vdot = -10.0`, `Y_rdot = N_vdot = 0`, `N_rdot = -1.0`:
    ///   Skjetne et al. (2004) Table 2, so `M = [[25.8, 0, 0], [0, 33.8, 1.0948],
    ///   [0, 1.0948, 2.76]]`.
    /// - Damping: [`Damping::cybership2`] (Skjetne et al. 2004, Table 4).
    /// - Towing points: Du et al. (2022) Table 2 gives the distances from the CG to
    ///   the stern and bow towing points, `l_1 = 0.67 m` and `l_2 = 0.585 m`; from
    ///   CO they are `x_g - l_1 = -0.624 m` and `x_g + l_2 = 0.631 m`.
    /// - No actuators and no winch: in the paper the ship is moved only by the
    ///   towlines (eq. (2)), so its force limits and winch pull are 0 (unused).
    #[must_use]
    pub const fn cybership2() -> VesselData {
        VesselData {
            length: 1.255,
            width: 0.29,
            mass: 23.8,
            inertia_z: 1.76,
            x_g: 0.046,
            x_udot: -2.0,
            y_vdot: -10.0,
            y_rdot: 0.0,
            n_vdot: 0.0,
            n_rdot: -1.0,
            damping: Damping::cybership2(),
            stern_tow_point_x: 0.046 - 0.67,
            bow_tow_point_x: 0.046 + 0.585,
            max_surge_force: 0.0,
            max_sway_force: 0.0,
            max_yaw_moment: 0.0,
            winch_max_tension: 0.0,
        }
    }

    /// TitoNeri, the tug (both tugs use it).
    ///
    /// - `m = 16.9 kg`, `X_udot = -1.2`, `Y_vdot = -49.2`, `N_rdot = -1.8`,
    ///   `Y_rdot = N_vdot = 0`, `x_g = 0`: Haseltalab & Negenborn (2019), Applied
    ///   Energy 251, 113308; `M = diag(18.1, 66.1, 2.31)`.
    /// - `I_z = 0.51 kg m^2`: same source as listed in `reference/vessels.md` (one
    ///   source citing Du's thesis gives 0.5).
    /// - `L x B = 0.97 x 0.30 m`: Du et al. (2022) Table 2 (the lab's documentation
    ///   says 0.98 x 0.33).
    /// - Damping: set A, [`Damping::titoneri_set_a`] (an assumption, see there); set
    ///   B is [`Damping::titoneri_set_b`].
    /// - Towing points at `+-l_T = +-0.5 m` from CO (= CG): Du et al. (2022) Table 2
    ///   (`l_T1 = l_T2 = 0.5 m`); tug 1 (aft) tows from its bow, tug 2 (forward) from
    ///   its stern.
    /// - Actuator limits 10 N surge, 10 N sway: Du et al. (2022) Table 2,
    ///   `tau_max = 10`. Assumption: the yaw moment limit is not given separately
    ///   (Table 2 prints `tau_max = 10` for all three components); 10 N m is taken.
    ///   The lab recommends +-3.5 N, +-3.5 N, +-1.0 N m; the paper's limits take
    ///   precedence for the reproduction.
    /// - Winch maximum pull 3 N: Du et al. (2022) Table 2, `F_max = 3 N`.
    #[must_use]
    pub const fn titoneri() -> VesselData {
        VesselData {
            length: 0.97,
            width: 0.30,
            mass: 16.9,
            inertia_z: 0.51,
            x_g: 0.0,
            x_udot: -1.2,
            y_vdot: -49.2,
            y_rdot: 0.0,
            n_vdot: 0.0,
            n_rdot: -1.8,
            damping: Damping::titoneri_set_a(),
            stern_tow_point_x: -0.5,
            bow_tow_point_x: 0.5,
            max_surge_force: 10.0,
            max_sway_force: 10.0,
            max_yaw_moment: 10.0,
            winch_max_tension: 3.0,
        }
    }

    /// Rigid-body mass matrix `M_RB` (Fossen 2021, ch. 3, 3-DoF form with the CG at
    /// `(x_g, 0)`; Skjetne et al. 2004).
    #[must_use]
    pub fn rigid_body_mass_matrix(&self) -> Matrix3<f64> {
        let m = self.mass;
        let mxg = m * self.x_g;
        Matrix3::new(m, 0.0, 0.0, 0.0, m, mxg, 0.0, mxg, self.inertia_z)
    }

    /// Added mass matrix `M_A` as identified, not symmetrised (Fossen 2021, ch. 6,
    /// 3-DoF form; Skjetne et al. 2004).
    #[must_use]
    pub fn added_mass_matrix(&self) -> Matrix3<f64> {
        -Matrix3::new(
            self.x_udot,
            0.0,
            0.0,
            0.0,
            self.y_vdot,
            self.y_rdot,
            0.0,
            self.n_vdot,
            self.n_rdot,
        )
    }

    /// Total mass matrix, symmetrised: `M = sym(M_RB + M_A)` (Fossen's `m2c`
    /// symmetrises M before building C; for both presets `Y_rdot = N_vdot = 0` so
    /// this changes nothing).
    #[must_use]
    pub fn mass_matrix(&self) -> Matrix3<f64> {
        let m = self.rigid_body_mass_matrix() + self.added_mass_matrix();
        (m + m.transpose()) * 0.5
    }

    /// `(name, value)` of every scalar field except damping (scenario keys).
    #[must_use]
    pub fn scalar_fields(&self) -> [(&'static str, f64); 16] {
        [
            ("length", self.length),
            ("width", self.width),
            ("mass", self.mass),
            ("inertia_z", self.inertia_z),
            ("x_g", self.x_g),
            ("x_udot", self.x_udot),
            ("y_vdot", self.y_vdot),
            ("y_rdot", self.y_rdot),
            ("n_vdot", self.n_vdot),
            ("n_rdot", self.n_rdot),
            ("stern_tow_point_x", self.stern_tow_point_x),
            ("bow_tow_point_x", self.bow_tow_point_x),
            ("max_surge_force", self.max_surge_force),
            ("max_sway_force", self.max_sway_force),
            ("max_yaw_moment", self.max_yaw_moment),
            ("winch_max_tension", self.winch_max_tension),
        ]
    }

    /// Validates the data once: everything finite; `length`, `width`, `mass`,
    /// `inertia_z` > 0; limits >= 0; stern towing point aft of the bow point; the
    /// symmetrised total mass matrix positive definite (Sylvester's criterion).
    /// Damping is only required to be finite (see [`Damping::validate`]).
    pub fn validate(&self) -> Result<(), ParamError> {
        for (name, value) in self.scalar_fields() {
            check_finite(name, value)?;
        }
        check_length("length", self.length)?;
        check_length("width", self.width)?;
        check_coordinate("stern_tow_point_x", self.stern_tow_point_x)?;
        check_coordinate("bow_tow_point_x", self.bow_tow_point_x)?;
        check_positive("mass", self.mass, "kg")?;
        check_positive("inertia_z", self.inertia_z, "kg m^2")?;
        check_non_negative("max_surge_force", self.max_surge_force, "N")?;
        check_non_negative("max_sway_force", self.max_sway_force, "N")?;
        check_non_negative("max_yaw_moment", self.max_yaw_moment, "N m")?;
        check_non_negative("winch_max_tension", self.winch_max_tension, "N")?;
        if self.stern_tow_point_x >= self.bow_tow_point_x {
            return Err(ParamError::new(
                "stern_tow_point_x",
                format!(
                    "must lie aft of bow_tow_point_x ({} m), got {} m",
                    self.bow_tow_point_x, self.stern_tow_point_x
                ),
            ));
        }
        self.damping.validate()?;
        let m = self.mass_matrix();
        let minor1 = m[(0, 0)];
        let minor2 = m[(1, 1)] * m[(2, 2)] - m[(1, 2)] * m[(2, 1)];
        let minor3 = m.determinant();
        if !(minor1 > 0.0 && m[(1, 1)] > 0.0 && minor2 > 0.0 && minor3 > 0.0) {
            return Err(ParamError::new(
                "",
                format!(
                    "the mass matrix M = M_RB + M_A (mass, inertia_z, x_g, x_udot, y_vdot, \
                     y_rdot, n_vdot, n_rdot) is not positive definite: M = [[{:.4}, 0, 0], \
                     [0, {:.4}, {:.4}], [0, {:.4}, {:.4}]]",
                    m[(0, 0)],
                    m[(1, 1)],
                    m[(1, 2)],
                    m[(2, 1)],
                    m[(2, 2)]
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid() {
        VesselData::cybership2().validate().unwrap();
        VesselData::titoneri().validate().unwrap();
    }

    #[test]
    fn cybership2_mass_matrix_matches_reference() {
        let m = VesselData::cybership2().mass_matrix();
        let expected = Matrix3::new(25.8, 0.0, 0.0, 0.0, 33.8, 1.0948, 0.0, 1.0948, 2.76);
        assert!((m - expected).abs().max() < 1e-12, "{m}");
    }

    #[test]
    fn titoneri_mass_matrix_matches_reference() {
        let m = VesselData::titoneri().mass_matrix();
        let expected = Matrix3::from_diagonal(&nalgebra::Vector3::new(18.1, 66.1, 2.31));
        assert!((m - expected).abs().max() < 1e-12, "{m}");
    }

    #[test]
    fn cybership2_towing_points_from_co() {
        let d = VesselData::cybership2();
        assert!((d.stern_tow_point_x - (-0.624)).abs() < 1e-12);
        assert!((d.bow_tow_point_x - 0.631).abs() < 1e-12);
        // l_1 + l_2 is the hull length (the 1.225 m of Table 2 is a misprint).
        assert!((d.bow_tow_point_x - d.stern_tow_point_x - d.length).abs() < 1e-12);
    }

    #[test]
    fn refuses_non_physical_values() {
        let mut d = VesselData::titoneri();
        d.mass = 0.0;
        assert_eq!(d.validate().unwrap_err().field, "mass");
        let mut d = VesselData::titoneri();
        d.damping.y_r = f64::NAN;
        assert_eq!(d.validate().unwrap_err().field, "damping.y_r");
        let mut d = VesselData::titoneri();
        d.y_vdot = 60.0; // M22 = 16.9 - 60 < 0
        let err = d.validate().unwrap_err();
        assert!(err.reason.contains("not positive definite"), "{err}");
        let mut d = VesselData::cybership2();
        d.stern_tow_point_x = 1.0;
        assert_eq!(d.validate().unwrap_err().field, "stern_tow_point_x");
        let mut d = VesselData::titoneri();
        d.winch_max_tension = -1.0;
        assert_eq!(d.validate().unwrap_err().field, "winch_max_tension");
    }
}

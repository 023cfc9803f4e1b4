//! COLREGS guidance of a ship towed by two tugs: the ship reference system of Du,
//! Negenborn, Reppa (2022), "COLREGS-compliant collision avoidance for physically
//! coupled multi-vessel systems with distributed MPC", Ocean Engineering 260,
//! 111917, section 3.1 (eq. (8)-(11), (14)), plus a COLREGS encounter classifier.
//!
//! - [`geometry`]: angle wrapping, relative bearing, CPA / TCPA.
//! - [`distance`]: the active obstacles ([`ActiveObstacle`]) of the obstacle slots the
//!   controller reads ([`towing_model::ObstacleSlot`]: none, static circle, vessel
//!   ellipse), eq. (9) distances (circle: centre; ellipse: focal sum),
//!   eq. (14) safe distances, and the range-equivalent distance compared with
//!   `d_D`.
//! - [`waypoint`]: the route (Table 4: [`Route::paper`]) and the clockwise waypoint
//!   altering of eq. (10)-(11) in the consistent form of `paper/NOTES.md`,
//!   bounded by `theta_max`.
//! - [`colregs`]: situations (head-on, crossing give-way / stand-on, overtaking,
//!   being overtaken, safe), threshold presets (Woerner-style, default; Xu et al.),
//!   the tow's status (power-driven as in the paper, or restricted in her ability
//!   to manoeuvre, Rule 3(g)/18), the policy per situation and Rule 17.
//! - [`params`]: every parameter, validated once, including when static hazards
//!   alter the route ([`StaticHazardPolicy`]); assumed values documented.
//! - [`reference`](mod@reference): [`ReferenceSystem`], the per-sample state
//!   machine producing `eta_Sd`.
//!
//! Conventions (`paper/NOTES.md` section 1): NED, `x` North, `y` East, `psi` from
//! North positive clockwise (a starboard turn); body `y` to starboard; radians in
//! code, wrapped to `(-pi, pi]`. The behaviour per situation, the presets and every
//! assumed value are in `docs/colregs.md`.
//!
//! ```
//! use towing_guidance::{GuidanceParams, ReferenceSystem, Route, TowState};
//! use towing_model::{ObstacleSlot, MAX_OBSTACLES};
//!
//! let mut guidance = ReferenceSystem::new(Route::paper(), GuidanceParams::default());
//! let tow = TowState::default(); // from the plant: ship pose and velocity, tug poses
//! let obstacles = [ObstacleSlot::EMPTY; MAX_OBSTACLES]; // the FMI obstacle slots, all empty
//! let out = guidance.update(&tow, &obstacles)?;
//! let [x_d, y_d, psi_d] = out.eta_sd.eta(); // reference for the controller
//! assert_eq!((out.active_waypoint, out.altered), (1, false));
//! # let _ = (x_d, y_d, psi_d);
//! # Ok::<(), towing_guidance::InputError>(())
//! ```
#![forbid(unsafe_code)]
// Tests may unwrap: a panic is the failure report.
#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod colregs;
pub mod distance;
mod error;
pub mod geometry;
pub mod params;
pub mod reference;
pub mod waypoint;

pub use colregs::{
    action, classify, role, safe_reading, Action, ColregsSettings, Encounter, EncounterThresholds,
    Manoeuvre, Role, Rule17Settings, Situation, ThresholdPreset, TowStatus,
};
pub use distance::{ActiveObstacle, Ellipse};
pub use error::{InputError, ParamError};
pub use geometry::{body_to_ned, cpa, relative_bearing, segment_distance, wrap_angle, Cpa};
pub use params::{GuidanceParams, GuidanceSettings, StaticHazardPolicy};
pub use reference::{
    assess_obstacle, AssessContext, GuidanceOutput, ObstacleAssessment, ReferenceSystem, Sighting,
    TowState, TowVessel,
};
pub use waypoint::{rotate_waypoint, theta_max, Route};

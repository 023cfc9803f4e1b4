//! Pure-Rust physics of a ship towed by two tugs, plus the scenario file format.
//!
//! This crate is the plant of the towing co-simulation (Du, Negenborn, Reppa 2022,
//! "COLREGS-compliant collision avoidance for physically coupled multi-vessel systems
//! with distributed MPC", Ocean Engineering 260, 111917) and the prediction model of
//! its controller. It holds no FFI and no `unsafe`.
//!
//! - [`kinetics`]: Fossen's 3-DoF manoeuvring model (Fossen 2021, eq. 6.1 / the
//!   paper's eq. (1)) with CyberShip II (Skjetne et al. 2004) and TitoNeri hulls
//!   behind the [`HullDynamics`] trait: linear or nonlinear damping selected by
//!   [`HullModel`], or your own hull model ([`World::with_hulls`]).
//! - [`vessel`]: the vessel parameter structs and their sourced presets
//!   ([`VesselData::cybership2`], [`VesselData::titoneri`]).
//! - [`towline`]: the two towlines, forces from geometry (tension along the line,
//!   moment `r x F`), ideal winch or elastic line ([`TowlineModel`]).
//! - [`traffic`]: static hazards and target ships ([`TrafficObstacle`]), moved
//!   analytically, and what an obstacle slot shows at a time ([`ObstacleSlot`], its
//!   [`ObstacleKind`]).
//! - [`state`]: a pose ([`Pose`]) and a vessel's pose and velocity ([`VesselState`]);
//!   [`config`]: the physics configuration ([`WorldConfig`]). The scenario and the world
//!   both use them; the world reads the scenario, never the other way round.
//! - [`geometry`]: the hull footprint ([`HullRect`]) and the waterway ([`Lane`]: the
//!   route with its half width), shared by the plant, the MPC and the analyzer.
//! - [`world`]: the three vessels and two towlines integrated jointly with RK4
//!   ([`World`]), atomic steps, state serialisation.
//! - [`scenario`]: the TOML scenario format ([`Scenario`], `docs/scenario-format.md`);
//!   [`PAPER_SCENARIO`] is the paper's route and traffic.
//!
//! Conventions (checked in `paper/NOTES.md` section 1): NED, `eta = [x North, y East,
//! psi]`, `psi` from North positive clockwise seen from above (a starboard turn),
//! `nu = [u, v, r]` in the body frame (x forward, y starboard). Angles are radians in
//! code and wrapped to `(-pi, pi]`; the scenario file uses degrees (`_deg` keys).
//! Tug 1 (index 0) is the aft tug, tug 2 (index 1) the forward tug; towline 1 joins
//! the ship's stern to tug 1's bow, towline 2 the ship's bow to tug 2's stern.
//!
//! ```
//! use towing_model::{Scenario, World, WorldInputs};
//!
//! let scenario = Scenario::paper()?; // or Scenario::from_file("scenarios/paper.toml")?
//! let mut world = World::new(&scenario, scenario.world_config)?;
//! let inputs = WorldInputs {
//!     // Tug 2 (forward) pulls with 4 N surge; tug 1 idles.
//!     tug_tau: [[0.0; 3], [4.0, 0.0, 0.0]],
//!     // Towline tension commands (N): line 1 slack, line 2 at 2 N.
//!     tension_cmd: [0.0, 2.0],
//! };
//! for _ in 0..100 {
//!     world.step(&inputs, 0.1)?; // 0.1 s communication step
//! }
//! assert!(world.ship().nu[0] > 0.0); // the ship is under way
//! assert_eq!(world.towline(1).tension, 2.0);
//! let target_a = world.obstacle(3); // at world.time()
//! assert_eq!(target_a.kind, towing_model::ObstacleKind::VesselEllipse);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
// Tests may unwrap: a panic is the failure report.
#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod angle;
pub mod config;
pub mod geometry;
pub mod kinetics;
pub mod registry;
pub mod scenario;
pub mod state;
pub mod towline;
pub mod traffic;
pub mod vessel;
pub mod world;

pub use angle::wrap_angle;
pub use config::WorldConfig;
pub use geometry::{HullRect, Lane, Polyline};
pub use kinetics::{HullDynamics, HullModel, LinearDampingHull, NonlinearDampingHull};
pub use scenario::{Route, Scenario, ScenarioError, ScenarioErrorKind, TugPlacement, Waterway};
pub use state::{Pose, VesselState};
pub use towline::{ElasticTowlineParams, TowlineModel, TowlineOutput};
pub use traffic::{ObstacleKind, ObstacleShape, ObstacleSlot, TrafficObstacle};
pub use vessel::{Damping, ParamError, TitoNeriDampingSet, VesselData, MAX_DISTANCE, MAX_SPEED};
pub use world::{StepError, World, WorldError, WorldInputs};

/// Number of obstacle output slots of the world (and of the plant FMU's
/// `obstacle[k].*` outputs, k = 1..8). A scenario with more obstacles is refused.
pub const MAX_OBSTACLES: usize = 8;

/// The paper's scenario (Tables 4 and 5 of Du et al. 2022, see `paper/NOTES.md`
/// section 2), as shipped in `scenarios/paper.toml`. Parse it with
/// [`Scenario::from_toml_str`]`(PAPER_SCENARIO, "scenarios/paper.toml")` or
/// [`Scenario::paper`].
pub const PAPER_SCENARIO: &str = include_str!("../../../scenarios/paper.toml");

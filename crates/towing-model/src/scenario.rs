//! Scenario files (TOML): initial state, formation, route, waterway, traffic,
//! optional vessel-data and simulation overrides. The format is documented field
//! by field in `docs/scenario-format.md`; [`crate::PAPER_SCENARIO`] is the paper's.
//!
//! Parsing is strict: unknown fields, missing required fields, wrong types and
//! non-physical values are refused with a [`ScenarioError`] that names the file,
//! the field path (e.g. `obstacles[3].speed`), the line and column when known, and
//! the reason. Nothing is silently defaulted unless the format documents a default.
//! Angles are degrees in the file (`_deg` keys, `r_deg_s` in deg/s) and radians in
//! [`Scenario`].

use std::fmt;
use std::path::Path;

use serde::Deserialize;
use toml::de::{DeTable, DeValue};

use crate::angle::wrap_angle;
use crate::config::WorldConfig;
use crate::kinetics::HullModel;
pub use crate::state::Pose;
use crate::state::VesselState;
use crate::towline::{formation_pose, ElasticTowlineParams, TowlineModel};
use crate::traffic::{ObstacleShape, TrafficObstacle};
use crate::vessel::{
    check_coordinate, check_finite, check_length, check_speed, Damping, ParamError,
    TitoNeriDampingSet, VesselData,
};
use crate::MAX_OBSTACLES;

/// The scenario format version this build reads.
pub const FORMAT_VERSION: i64 = 1;

/// Largest allowed `|towing_angle_deg|` of a formation (exclusive): beyond 90 deg
/// the tug would sit abeam of or behind its own towing point.
pub const MAX_FORMATION_ANGLE_DEG: f64 = 90.0;

/// What kind of problem a [`ScenarioError`] reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScenarioErrorKind {
    /// The file could not be read.
    Io,
    /// The text is not valid TOML.
    Syntax,
    /// Valid TOML, but a field is unknown, missing or of the wrong type.
    Schema,
    /// A value is non-physical or inconsistent.
    Invalid,
}

/// A refused scenario: which file, which field, why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScenarioError {
    /// The file (or other origin) the text came from.
    pub origin: String,
    /// Kind of problem.
    pub kind: ScenarioErrorKind,
    /// Field path, e.g. `obstacles[3].speed`; empty for syntax and I/O errors.
    pub path: String,
    /// Why it was refused.
    pub reason: String,
    /// 1-based line and column in the file, when known.
    pub location: Option<(usize, usize)>,
}

impl ScenarioError {
    pub(crate) fn invalid(origin: &str, e: ParamError) -> ScenarioError {
        ScenarioError {
            origin: origin.to_owned(),
            kind: ScenarioErrorKind::Invalid,
            path: e.field,
            reason: e.reason,
            location: None,
        }
    }

    fn schema(origin: &str, path: impl Into<String>, reason: impl Into<String>) -> ScenarioError {
        ScenarioError {
            origin: origin.to_owned(),
            kind: ScenarioErrorKind::Schema,
            path: path.into(),
            reason: reason.into(),
            location: None,
        }
    }
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.origin)?;
        if let Some((line, column)) = self.location {
            write!(f, ":{line}:{column}")?;
        }
        match self.kind {
            ScenarioErrorKind::Io => write!(f, ": cannot read scenario: {}", self.reason),
            ScenarioErrorKind::Syntax => write!(f, ": TOML syntax error: {}", self.reason),
            ScenarioErrorKind::Schema | ScenarioErrorKind::Invalid => {
                write!(f, ": {}: {}", self.path, self.reason)
            }
        }
    }
}

impl std::error::Error for ScenarioError {}

/// The planned route (Du et al. 2022, Table 4): origin, waypoints, destination.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    /// Start pose `W_PO`.
    pub origin: Pose,
    /// Waypoints `W_P1 .. W_Pn` (at least one).
    pub waypoints: Vec<Pose>,
    /// Destination pose.
    pub destination: Pose,
}

impl Route {
    /// Origin, waypoints and destination in order.
    pub fn points(&self) -> impl Iterator<Item = &Pose> {
        std::iter::once(&self.origin)
            .chain(self.waypoints.iter())
            .chain(std::iter::once(&self.destination))
    }

    /// Length of the polyline through all points (m).
    #[must_use]
    pub fn length(&self) -> f64 {
        let pts: Vec<&Pose> = self.points().collect();
        pts.windows(2)
            .map(|w| (w[1].x - w[0].x).hypot(w[1].y - w[0].y))
            .sum()
    }
}

/// The waterway around the route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waterway {
    /// Distance from the route to the bank on either side, `d_2` of the paper's
    /// `theta_max = arctan(d_2 / d_1)` (m).
    pub half_width: f64,
}

/// How a tug was placed at `t = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TugPlacement {
    /// In formation at the line's desired length with towing angle `alpha` (rad),
    /// see [`crate::towline::formation_pose`].
    Formation {
        /// Towing angle `alpha_i` (rad).
        towing_angle: f64,
    },
    /// Explicit pose from the file.
    Explicit,
}

/// A validated scenario. Fields are public for tools that derive scenarios; a
/// [`crate::World`] re-validates it ([`Scenario::validate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Where it came from (file path or a label), used in error messages.
    pub origin: String,
    /// Format version of the file ([`FORMAT_VERSION`]).
    pub format_version: i64,
    /// Short name.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Initial state of the ship.
    pub ship: VesselState,
    /// Initial states of tug 1 (aft) and tug 2 (forward).
    pub tugs: [VesselState; 2],
    /// How each tug was placed.
    pub tug_placement: [TugPlacement; 2],
    /// Desired towline lengths `l_tow1`, `l_tow2` (m), attachment point to
    /// attachment point.
    pub towline_desired_length: [f64; 2],
    /// The planned route.
    pub route: Route,
    /// The waterway, if given.
    pub waterway: Option<Waterway>,
    /// Static hazards and target ships (at most [`MAX_OBSTACLES`]).
    pub obstacles: Vec<TrafficObstacle>,
    /// Ship parameters (CyberShip II preset with the file's overrides).
    pub ship_data: VesselData,
    /// Tug parameters (TitoNeri preset with the file's overrides).
    pub tug_data: [VesselData; 2],
    /// Physics configuration requested by the file (defaults:
    /// [`WorldConfig::default`]); a user may build the world with another one.
    pub world_config: WorldConfig,
    /// Elastic towline constants of the file (defaults:
    /// [`ElasticTowlineParams::default`]), also when the ideal winch is selected.
    pub elastic_towline: ElasticTowlineParams,
}

impl Scenario {
    /// Parses and validates a scenario from TOML text; `origin` names the source
    /// in error messages.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Scenario, ScenarioError> {
        let doc = DeTable::parse(text).map_err(|e| {
            let location = e.span().map(|s| line_column(text, s.start));
            ScenarioError {
                origin: origin.to_owned(),
                kind: ScenarioErrorKind::Syntax,
                path: String::new(),
                reason: e.message().trim().to_owned(),
                location,
            }
        })?;
        let file: FileScenario =
            toml::from_str(text).map_err(|e| schema_error(origin, text, &doc, &e))?;
        let scenario = convert(file, origin).map_err(|e| locate(e, text, &doc))?;
        scenario.validate().map_err(|e| locate(e, text, &doc))?;
        Ok(scenario)
    }

    /// Reads, parses and validates a scenario file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            origin: origin.clone(),
            kind: ScenarioErrorKind::Io,
            path: String::new(),
            reason: e.to_string(),
            location: None,
        })?;
        Scenario::from_toml_str(&text, &origin)
    }

    /// The paper's scenario ([`crate::PAPER_SCENARIO`]).
    pub fn paper() -> Result<Scenario, ScenarioError> {
        Scenario::from_toml_str(crate::PAPER_SCENARIO, "scenarios/paper.toml")
    }

    /// Recomputes the formation tugs' poses from the ship's pose (after editing
    /// `ship`, `towline_desired_length` or vessel data by hand).
    pub fn place_tugs(&mut self) {
        for (line, placement) in self.tug_placement.iter().enumerate() {
            if let TugPlacement::Formation { towing_angle } = *placement {
                self.tugs[line].eta = formation_pose(
                    line,
                    &self.ship.eta,
                    &self.ship_data,
                    &self.tug_data[line],
                    self.towline_desired_length[line],
                    towing_angle,
                );
            }
        }
    }

    /// Checks every value (the rules of `docs/scenario-format.md`); paths are
    /// those of the file.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        self.check()
            .map_err(|e| ScenarioError::invalid(&self.origin, e))
    }

    fn check(&self) -> Result<(), ParamError> {
        if self.format_version != FORMAT_VERSION {
            return Err(ParamError::new(
                "format_version",
                format!(
                    "unsupported format version {} (this build reads version {FORMAT_VERSION})",
                    self.format_version
                ),
            ));
        }
        if self.name.trim().is_empty() {
            return Err(ParamError::new("name", "must not be empty"));
        }
        self.ship_data
            .validate()
            .map_err(|e| e.within("vessels.ship"))?;
        for (i, d) in self.tug_data.iter().enumerate() {
            d.validate()
                .map_err(|e| e.within(&format!("vessels.tug{}", i + 1)))?;
        }
        self.world_config
            .validate()
            .map_err(|e| e.within("simulation"))?;
        self.elastic_towline
            .validate()
            .map_err(|e| e.within("simulation.elastic_towline"))?;
        check_state("ship", &self.ship)?;
        for (i, length) in self.towline_desired_length.iter().enumerate() {
            check_length(&format!("towline{}.desired_length", i + 1), *length)?;
        }
        for (i, (state, placement)) in self.tugs.iter().zip(&self.tug_placement).enumerate() {
            let tug = format!("tug{}", i + 1);
            if let TugPlacement::Formation { towing_angle } = *placement {
                let field = format!("{tug}.formation.towing_angle_deg");
                check_finite(&field, towing_angle)?;
                let deg = towing_angle.to_degrees();
                if deg.abs() >= MAX_FORMATION_ANGLE_DEG {
                    return Err(ParamError::new(
                        field,
                        format!(
                            "must lie strictly between -{MAX_FORMATION_ANGLE_DEG} and {MAX_FORMATION_ANGLE_DEG} deg \
                             (the tug would be abeam of or behind its towing point), got {deg} deg"
                        ),
                    ));
                }
            }
            check_state(&tug, state)?;
        }
        check_pose("route.origin", &self.route.origin)?;
        if self.route.waypoints.is_empty() {
            return Err(ParamError::new(
                "route.waypoints",
                "at least one waypoint is required, got 0",
            ));
        }
        for (i, p) in self.route.waypoints.iter().enumerate() {
            check_pose(&format!("route.waypoints[{i}]"), p)?;
        }
        check_pose("route.destination", &self.route.destination)?;
        let points: Vec<&Pose> = self.route.points().collect();
        for (k, w) in points.windows(2).enumerate() {
            if (w[1].x - w[0].x).hypot(w[1].y - w[0].y) < 1e-9 {
                let path = if k < self.route.waypoints.len() {
                    format!("route.waypoints[{k}]")
                } else {
                    "route.destination".to_owned()
                };
                return Err(ParamError::new(
                    path,
                    "coincides with the previous route point (the segment's course is undefined)",
                ));
            }
        }
        if let Some(w) = &self.waterway {
            check_length("waterway.half_width", w.half_width)?;
        }
        if self.obstacles.len() > MAX_OBSTACLES {
            return Err(ParamError::new(
                "obstacles",
                format!(
                    "{} obstacles given, at most {MAX_OBSTACLES} (MAX_OBSTACLES, the number of output slots) are supported",
                    self.obstacles.len()
                ),
            ));
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            o.validate()
                .map_err(|e| e.within(&format!("obstacles[{i}]")))?;
            if let Some(j) = self.obstacles[..i].iter().position(|p| p.name == o.name) {
                return Err(ParamError::new(
                    format!("obstacles[{i}].name"),
                    format!("duplicate name {:?} (also obstacles[{j}])", o.name),
                ));
            }
        }
        Ok(())
    }
}

/// A vessel's state: finite, its position within [`crate::vessel::MAX_DISTANCE`] and its
/// speeds within [`crate::vessel::MAX_SPEED`].
fn check_state(prefix: &str, s: &VesselState) -> Result<(), ParamError> {
    let names = ["x", "y", "psi_deg", "u", "v", "r_deg_s"];
    for (name, value) in names.iter().zip(s.eta.iter().chain(s.nu.iter())) {
        check_finite(&format!("{prefix}.{name}"), *value)?;
    }
    check_coordinate(&format!("{prefix}.x"), s.eta[0])?;
    check_coordinate(&format!("{prefix}.y"), s.eta[1])?;
    check_speed(&format!("{prefix}.u"), s.nu[0])?;
    check_speed(&format!("{prefix}.v"), s.nu[1])
}

fn check_pose(prefix: &str, p: &Pose) -> Result<(), ParamError> {
    check_coordinate(&format!("{prefix}.x"), p.x)?;
    check_coordinate(&format!("{prefix}.y"), p.y)?;
    check_finite(&format!("{prefix}.psi_deg"), p.psi)
}

// ---------------------------------------------------------------------------
// File schema (serde). Every struct denies unknown fields.

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileScenario {
    format_version: i64,
    name: String,
    description: Option<String>,
    ship: FileVesselState,
    tug1: FileTug,
    tug2: FileTug,
    towline1: FileTowline,
    towline2: FileTowline,
    route: FileRoute,
    waterway: Option<FileWaterway>,
    obstacles: Option<Vec<FileObstacle>>,
    simulation: Option<FileSimulation>,
    vessels: Option<FileVessels>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileVesselState {
    x: f64,
    y: f64,
    psi_deg: f64,
    u: Option<f64>,
    v: Option<f64>,
    r_deg_s: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileTug {
    formation: Option<FileFormation>,
    x: Option<f64>,
    y: Option<f64>,
    psi_deg: Option<f64>,
    u: Option<f64>,
    v: Option<f64>,
    r_deg_s: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileFormation {
    towing_angle_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileTowline {
    desired_length: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRoute {
    origin: FilePose,
    waypoints: Vec<FilePose>,
    destination: FilePose,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FilePose {
    x: f64,
    y: f64,
    psi_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileWaterway {
    half_width: f64,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "lowercase")]
enum FileObstacleKind {
    Static,
    Ship,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileObstacle {
    name: String,
    kind: FileObstacleKind,
    x: f64,
    y: f64,
    diameter: Option<f64>,
    length: Option<f64>,
    width: Option<f64>,
    course_deg: Option<f64>,
    speed: Option<f64>,
    activation_time: Option<f64>,
    activation_range: Option<f64>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum FileHullModel {
    LinearDamping,
    NonlinearDamping,
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(rename_all = "snake_case")]
enum FileTowlineModel {
    IdealWinch,
    Elastic,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSimulation {
    hull_model: Option<FileHullModel>,
    towline_model: Option<FileTowlineModel>,
    integration_step: Option<f64>,
    elastic_towline: Option<FileElastic>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileElastic {
    stiffness: Option<f64>,
    damping: Option<f64>,
    winch_gain: Option<f64>,
    winch_speed_max: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileVessels {
    ship: Option<FileVesselOverride>,
    tug1: Option<FileVesselOverride>,
    tug2: Option<FileVesselOverride>,
}

#[derive(Debug, Clone, Copy, Deserialize)]
enum FileDampingSet {
    A,
    B,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileVesselOverride {
    length: Option<f64>,
    width: Option<f64>,
    mass: Option<f64>,
    inertia_z: Option<f64>,
    x_g: Option<f64>,
    x_udot: Option<f64>,
    y_vdot: Option<f64>,
    y_rdot: Option<f64>,
    n_vdot: Option<f64>,
    n_rdot: Option<f64>,
    stern_tow_point_x: Option<f64>,
    bow_tow_point_x: Option<f64>,
    max_surge_force: Option<f64>,
    max_sway_force: Option<f64>,
    max_yaw_moment: Option<f64>,
    winch_max_tension: Option<f64>,
    damping_set: Option<FileDampingSet>,
    damping: Option<FileDamping>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDamping {
    x_u: Option<f64>,
    x_absu_u: Option<f64>,
    x_uuu: Option<f64>,
    y_v: Option<f64>,
    y_absv_v: Option<f64>,
    y_absr_v: Option<f64>,
    y_r: Option<f64>,
    y_absv_r: Option<f64>,
    y_absr_r: Option<f64>,
    n_v: Option<f64>,
    n_absv_v: Option<f64>,
    n_absr_v: Option<f64>,
    n_r: Option<f64>,
    n_absv_r: Option<f64>,
    n_absr_r: Option<f64>,
}

fn set(target: &mut f64, value: Option<f64>) {
    if let Some(v) = value {
        *target = v;
    }
}

fn apply_override(
    base: VesselData,
    o: Option<FileVesselOverride>,
    path: &str,
    origin: &str,
    is_tug: bool,
) -> Result<VesselData, ScenarioError> {
    let mut d = base;
    let Some(o) = o else { return Ok(d) };
    set(&mut d.length, o.length);
    set(&mut d.width, o.width);
    set(&mut d.mass, o.mass);
    set(&mut d.inertia_z, o.inertia_z);
    set(&mut d.x_g, o.x_g);
    set(&mut d.x_udot, o.x_udot);
    set(&mut d.y_vdot, o.y_vdot);
    set(&mut d.y_rdot, o.y_rdot);
    set(&mut d.n_vdot, o.n_vdot);
    set(&mut d.n_rdot, o.n_rdot);
    set(&mut d.stern_tow_point_x, o.stern_tow_point_x);
    set(&mut d.bow_tow_point_x, o.bow_tow_point_x);
    set(&mut d.max_surge_force, o.max_surge_force);
    set(&mut d.max_sway_force, o.max_sway_force);
    set(&mut d.max_yaw_moment, o.max_yaw_moment);
    set(&mut d.winch_max_tension, o.winch_max_tension);
    if let Some(s) = o.damping_set {
        if !is_tug {
            return Err(ScenarioError::schema(
                origin,
                format!("{path}.damping_set"),
                "only the tugs (TitoNeri) have alternative damping sets; give the ship's \
                 coefficients under `damping` instead",
            ));
        }
        d.damping = match s {
            FileDampingSet::A => TitoNeriDampingSet::A,
            FileDampingSet::B => TitoNeriDampingSet::B,
        }
        .damping();
    }
    if let Some(c) = o.damping {
        let dm: &mut Damping = &mut d.damping;
        set(&mut dm.x_u, c.x_u);
        set(&mut dm.x_absu_u, c.x_absu_u);
        set(&mut dm.x_uuu, c.x_uuu);
        set(&mut dm.y_v, c.y_v);
        set(&mut dm.y_absv_v, c.y_absv_v);
        set(&mut dm.y_absr_v, c.y_absr_v);
        set(&mut dm.y_r, c.y_r);
        set(&mut dm.y_absv_r, c.y_absv_r);
        set(&mut dm.y_absr_r, c.y_absr_r);
        set(&mut dm.n_v, c.n_v);
        set(&mut dm.n_absv_v, c.n_absv_v);
        set(&mut dm.n_absr_v, c.n_absr_v);
        set(&mut dm.n_r, c.n_r);
        set(&mut dm.n_absv_r, c.n_absv_r);
        set(&mut dm.n_absr_r, c.n_absr_r);
    }
    Ok(d)
}

fn state_of(
    x: f64,
    y: f64,
    psi_deg: f64,
    u: Option<f64>,
    v: Option<f64>,
    r_deg_s: Option<f64>,
) -> VesselState {
    VesselState {
        eta: [x, y, wrap_angle_keep_nan(psi_deg.to_radians())],
        nu: [
            u.unwrap_or(0.0),
            v.unwrap_or(0.0),
            r_deg_s.unwrap_or(0.0).to_radians(),
        ],
    }
}

/// Wraps finite angles; keeps NaN/inf as they are so validation reports them.
fn wrap_angle_keep_nan(a: f64) -> f64 {
    if a.is_finite() {
        wrap_angle(a)
    } else {
        a
    }
}

fn pose_of(p: &FilePose) -> Pose {
    Pose {
        x: p.x,
        y: p.y,
        psi: wrap_angle_keep_nan(p.psi_deg.to_radians()),
    }
}

/// The plant's settings of the `[simulation]` table (defaults where absent).
fn simulation_of(sim: Option<FileSimulation>) -> (WorldConfig, ElasticTowlineParams) {
    let mut world_config = WorldConfig::default();
    let mut elastic_towline = ElasticTowlineParams::default();
    if let Some(sim) = sim {
        if let Some(e) = sim.elastic_towline {
            set(&mut elastic_towline.stiffness, e.stiffness);
            set(&mut elastic_towline.damping, e.damping);
            set(&mut elastic_towline.winch_gain, e.winch_gain);
            set(&mut elastic_towline.winch_speed_max, e.winch_speed_max);
        }
        if let Some(h) = sim.hull_model {
            world_config.hull_model = match h {
                FileHullModel::LinearDamping => HullModel::LinearDamping,
                FileHullModel::NonlinearDamping => HullModel::NonlinearDamping,
            };
        }
        if let Some(t) = sim.towline_model {
            world_config.towline_model = match t {
                FileTowlineModel::IdealWinch => TowlineModel::IdealWinch,
                FileTowlineModel::Elastic => elastic_towline.into(),
            };
        }
        set(&mut world_config.integration_step, sim.integration_step);
    }

    (world_config, elastic_towline)
}

/// The tugs' initial states and how they were placed: an explicit pose, or the
/// formation pose of a towing angle behind the ship's initial pose.
fn tugs_of(
    file_tugs: [&FileTug; 2],
    ship: &VesselState,
    ship_data: &VesselData,
    tug_data: &[VesselData; 2],
    towline_desired_length: [f64; 2],
    origin: &str,
) -> Result<([VesselState; 2], [TugPlacement; 2]), ScenarioError> {
    let mut tugs = [VesselState::default(); 2];
    let mut tug_placement = [TugPlacement::Explicit; 2];
    for (i, t) in file_tugs.into_iter().enumerate() {
        let name = format!("tug{}", i + 1);
        let explicit = [("x", t.x), ("y", t.y), ("psi_deg", t.psi_deg)];
        match &t.formation {
            Some(f) => {
                if let Some((key, _)) = explicit.iter().find(|(_, v)| v.is_some()) {
                    return Err(ScenarioError::schema(
                        origin,
                        format!("{name}.{key}"),
                        "give either `formation` or an explicit pose (`x`, `y`, `psi_deg`), not both",
                    ));
                }
                let alpha = f.towing_angle_deg.to_radians();
                tug_placement[i] = TugPlacement::Formation {
                    towing_angle: alpha,
                };
                let eta = formation_pose(
                    i,
                    &ship.eta,
                    ship_data,
                    &tug_data[i],
                    towline_desired_length[i],
                    alpha,
                );
                tugs[i] = state_of(eta[0], eta[1], 0.0, t.u, t.v, t.r_deg_s);
                tugs[i].eta[2] = eta[2];
            }
            None => {
                if let Some((key, _)) = explicit.iter().find(|(_, v)| v.is_none()) {
                    return Err(ScenarioError::schema(
                        origin,
                        format!("{name}.{key}"),
                        "missing field: an explicit tug pose needs `x`, `y` and `psi_deg` \
                         (or give `formation = { towing_angle_deg = ... }`)",
                    ));
                }
                tugs[i] = state_of(
                    t.x.unwrap_or_default(),
                    t.y.unwrap_or_default(),
                    t.psi_deg.unwrap_or_default(),
                    t.u,
                    t.v,
                    t.r_deg_s,
                );
            }
        }
    }

    Ok((tugs, tug_placement))
}

/// Obstacle `i` of the file, its fields checked against its kind.
fn obstacle_of(i: usize, o: FileObstacle, origin: &str) -> Result<TrafficObstacle, ScenarioError> {
    let path = format!("obstacles[{i}]");
    let given = [
        ("diameter", o.diameter),
        ("length", o.length),
        ("width", o.width),
        ("course_deg", o.course_deg),
        ("speed", o.speed),
        ("activation_time", o.activation_time),
        ("activation_range", o.activation_range),
    ];
    let (required, forbidden, kind): (&[&str], &[&str], &str) = match o.kind {
        FileObstacleKind::Static => (
            &["diameter"],
            &[
                "length",
                "width",
                "course_deg",
                "speed",
                "activation_time",
                "activation_range",
            ],
            "static",
        ),
        FileObstacleKind::Ship => (
            &["length", "width", "course_deg", "speed"],
            &["diameter"],
            "ship",
        ),
    };
    let value = |key: &str| given.iter().find(|(k, _)| *k == key).and_then(|(_, v)| *v);
    for key in forbidden {
        if value(key).is_some() {
            let why = match o.kind {
                FileObstacleKind::Static => "static obstacles are circles that do not move",
                FileObstacleKind::Ship => "a ship's size is its `length` and `width`",
            };
            return Err(ScenarioError::schema(
                origin,
                format!("{path}.{key}"),
                format!("not allowed for kind = \"{kind}\" ({why})"),
            ));
        }
    }
    for key in required {
        if value(key).is_none() {
            return Err(ScenarioError::schema(
                origin,
                format!("{path}.{key}"),
                format!("missing field `{key}` (required for kind = \"{kind}\")"),
            ));
        }
    }
    // The file's time must be finite (`inf` is how the model says "never by
    // time", which the file says by omitting `activation_time`).
    if let Some(t) = o.activation_time.filter(|t| t.is_infinite()) {
        return Err(ScenarioError::invalid(
            origin,
            ParamError::new(
                format!("{path}.activation_time"),
                format!(
                    "must be finite, got {t} (omit it and give `activation_range` for a target \
                     that only the range activates)"
                ),
            ),
        ));
    }
    let shape = match o.kind {
        FileObstacleKind::Static => ObstacleShape::Circle {
            diameter: o.diameter.unwrap_or_default(),
        },
        FileObstacleKind::Ship => ObstacleShape::Vessel {
            length: o.length.unwrap_or_default(),
            width: o.width.unwrap_or_default(),
            course: wrap_angle_keep_nan(o.course_deg.unwrap_or_default().to_radians()),
            speed: o.speed.unwrap_or_default(),
            // Neither trigger given: from t = 0; range only: never by time.
            activation_time: match (o.activation_time, o.activation_range) {
                (Some(t), _) => t,
                (None, Some(_)) => f64::INFINITY,
                (None, None) => 0.0,
            },
            activation_range: o.activation_range,
        },
    };
    Ok(TrafficObstacle {
        name: o.name,
        x: o.x,
        y: o.y,
        shape,
    })
}

fn convert(file: FileScenario, origin: &str) -> Result<Scenario, ScenarioError> {
    let vessels = file.vessels.unwrap_or(FileVessels {
        ship: None,
        tug1: None,
        tug2: None,
    });
    let ship_data = apply_override(
        VesselData::cybership2(),
        vessels.ship,
        "vessels.ship",
        origin,
        false,
    )?;
    let tug_data = [
        apply_override(
            VesselData::titoneri(),
            vessels.tug1,
            "vessels.tug1",
            origin,
            true,
        )?,
        apply_override(
            VesselData::titoneri(),
            vessels.tug2,
            "vessels.tug2",
            origin,
            true,
        )?,
    ];

    let (world_config, elastic_towline) = simulation_of(file.simulation);
    let s = &file.ship;
    let ship = state_of(s.x, s.y, s.psi_deg, s.u, s.v, s.r_deg_s);
    let towline_desired_length = [file.towline1.desired_length, file.towline2.desired_length];

    let (tugs, tug_placement) = tugs_of(
        [&file.tug1, &file.tug2],
        &ship,
        &ship_data,
        &tug_data,
        towline_desired_length,
        origin,
    )?;
    let route = Route {
        origin: pose_of(&file.route.origin),
        waypoints: file.route.waypoints.iter().map(pose_of).collect(),
        destination: pose_of(&file.route.destination),
    };

    let obstacles = file
        .obstacles
        .unwrap_or_default()
        .into_iter()
        .enumerate()
        .map(|(i, o)| obstacle_of(i, o, origin))
        .collect::<Result<Vec<_>, _>>()?;

    Ok(Scenario {
        origin: origin.to_owned(),
        format_version: file.format_version,
        name: file.name,
        description: file.description.unwrap_or_default(),
        ship,
        tugs,
        tug_placement,
        towline_desired_length,
        route,
        waterway: file.waterway.map(|w| Waterway {
            half_width: w.half_width,
        }),
        obstacles,
        ship_data,
        tug_data,
        world_config,
        elastic_towline,
    })
}

// ---------------------------------------------------------------------------
// Locating errors in the text.

/// 1-based (line, column) of a byte offset; the column counts characters.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

#[derive(Debug, Clone, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

fn render(path: &[Seg]) -> String {
    let mut out = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(k);
            }
            Seg::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

fn parse_path(path: &str) -> Vec<Seg> {
    let mut out = Vec::new();
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let mut rest = part;
        if let Some(open) = rest.find('[') {
            out.push(Seg::Key(rest[..open].to_owned()));
            rest = &rest[open..];
            while let Some(stripped) = rest.strip_prefix('[') {
                let Some(close) = stripped.find(']') else {
                    break;
                };
                if let Ok(i) = stripped[..close].parse() {
                    out.push(Seg::Index(i));
                }
                rest = &stripped[close + 1..];
            }
        } else {
            out.push(Seg::Key(rest.to_owned()));
        }
    }
    out
}

type Span = std::ops::Range<usize>;

fn union(a: Span, b: Span) -> Span {
    a.start.min(b.start)..a.end.max(b.end)
}

fn contains(outer: &Span, inner: &Span) -> bool {
    outer.start <= inner.start && inner.end <= outer.end
}

/// Text extent of a value: its own span (for a `[table]` only the header) joined
/// with the spans of everything inside it.
fn extent(value: &toml::Spanned<DeValue<'_>>) -> Span {
    let mut out = value.span();
    match value.get_ref() {
        DeValue::Table(t) => {
            for (k, v) in t.iter() {
                out = union(out, union(k.span(), extent(v)));
            }
        }
        DeValue::Array(items) => {
            for item in items.iter() {
                out = union(out, extent(item));
            }
        }
        _ => {}
    }
    out
}

/// Path of the deepest key or value whose extent contains `span` (the location
/// of a serde error).
fn path_containing(value: &DeValue<'_>, span: &Span, path: &mut Vec<Seg>) {
    match value {
        DeValue::Table(t) => {
            for (key, child) in t.iter() {
                if contains(&key.span(), span) {
                    path.push(Seg::Key(key.get_ref().to_string()));
                    return;
                }
                if contains(&union(key.span(), extent(child)), span) {
                    path.push(Seg::Key(key.get_ref().to_string()));
                    path_containing(child.get_ref(), span, path);
                    return;
                }
            }
        }
        DeValue::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                if contains(&extent(item), span) {
                    path.push(Seg::Index(i));
                    path_containing(item.get_ref(), span, path);
                    return;
                }
            }
        }
        _ => {}
    }
}

/// Byte offset of the deepest existing prefix of `path` in the document.
fn offset_of(doc: &DeTable<'_>, path: &[Seg]) -> Option<usize> {
    let mut found = None;
    let mut table = Some(doc);
    let mut current: Option<&DeValue<'_>> = None;
    for seg in path {
        match seg {
            Seg::Key(k) => {
                let t = match current {
                    None => table?,
                    Some(DeValue::Table(t)) => t,
                    Some(_) => return found,
                };
                let (key, value) = t.iter().find(|(key, _)| key.get_ref() == k)?;
                found = Some(
                    if matches!(value.get_ref(), DeValue::Table(_) | DeValue::Array(_)) {
                        key.span().start
                    } else {
                        value.span().start
                    },
                );
                current = Some(value.get_ref());
                table = None;
            }
            Seg::Index(i) => {
                let Some(DeValue::Array(items)) = current else {
                    return found;
                };
                let Some(item) = items.get(*i) else {
                    return found;
                };
                found = Some(item.span().start);
                current = Some(item.get_ref());
            }
        }
    }
    found
}

fn locate(mut e: ScenarioError, text: &str, doc: &toml::Spanned<DeTable<'_>>) -> ScenarioError {
    if e.location.is_none() {
        e.location = offset_of(doc.get_ref(), &parse_path(&e.path)).map(|o| line_column(text, o));
    }
    e
}

fn schema_error(
    origin: &str,
    text: &str,
    doc: &toml::Spanned<DeTable<'_>>,
    e: &toml::de::Error,
) -> ScenarioError {
    let message = e.message().trim().to_owned();
    let mut path = Vec::new();
    // An empty span is the document itself (e.g. a missing top-level field).
    if let Some(span) = e.span().filter(|s| !s.is_empty()) {
        path_containing(&DeValue::Table(doc.get_ref().clone()), &span, &mut path);
    }
    // serde reports "missing field `x`" against the enclosing table.
    if let Some(rest) = message.strip_prefix("missing field `") {
        if let Some(end) = rest.find('`') {
            path.push(Seg::Key(rest[..end].to_owned()));
        }
    }
    let mut err = ScenarioError::schema(origin, render(&path), message);
    err.location = e.span().map(|s| line_column(text, s.start));
    if err.path.is_empty() {
        err.path = "(document)".to_owned();
    }
    err
}

#[cfg(test)]
mod tests;

//! The plant's MCAP log (docs/logging.md): what it writes when initialization ends and
//! after every step. Messages are built only while a log is open (`log_file` set): after a
//! step the FMU copies what they need into a [`StepSnapshot`] (a few hundred bytes, no
//! allocation), and the log's writer thread builds, serializes and compresses them.

use towing_interface::codec::obstacle_kind_code;
use towing_log::scene::{self, colors};
use towing_log::topics::{
    names, FrameTransforms, LinePrimitive, Log, ObstacleState, Obstacles, PlantInputs, SceneEntity,
    SceneUpdate, TowlineState, VesselState, FRAME_SHIP, FRAME_TUG1, FRAME_TUG2, PLANT_TOPICS,
};
use towing_log::{LogError, LogWriter};
use towing_model::towline::attachment_point;
use towing_model::{
    ObstacleKind, ObstacleShape, ObstacleSlot, Scenario, TowlineOutput, World, WorldInputs,
    MAX_OBSTACLES,
};

/// Buffer `d_S0` (m) of the safe circles drawn around static hazards: Du et al. 2022,
/// eq. (14), `L + R_j + d_S0` with the ship's length `L`. The plant does not know the
/// controller's value; 0.25 m is the guidance's default (`GuidanceParams::safety_buffer`).
pub const SAFE_CIRCLE_BUFFER: f64 = 0.25;

/// Height of hazard cylinders (m).
const HAZARD_HEIGHT: f64 = 0.3;
/// Height of target-ship cylinders (m).
const TARGET_HEIGHT: f64 = 0.2;
/// Diameter of the waypoint spheres (m).
const WAYPOINT_DIAMETER: f64 = 0.25;

/// What the log needs from the scenario beyond the world: kept with the loaded world.
#[derive(Debug, Clone, PartialEq)]
pub struct LogScenario {
    /// The scenario's name.
    pub name: String,
    /// Desired towline lengths (m).
    pub desired_length: [f64; 2],
    /// Route points `[x, y]` (NED, m): origin, waypoints, destination.
    pub route: Vec<[f64; 2]>,
    /// Obstacle names by slot.
    pub obstacle_names: Vec<String>,
}

impl LogScenario {
    /// The parts of `scenario` the log needs.
    pub fn of(scenario: &Scenario) -> Self {
        Self {
            name: scenario.name.clone(),
            desired_length: scenario.towline_desired_length,
            route: scenario.route.points().map(|p| [p.x, p.y]).collect(),
            obstacle_names: scenario.obstacles.iter().map(|o| o.name.clone()).collect(),
        }
    }
}

/// Registers every plant topic ([`PLANT_TOPICS`]), so each channel is in the file even
/// without messages.
pub fn register_topics(w: &mut LogWriter) -> Result<(), LogError> {
    for topic in [names::PLANT_SHIP, names::PLANT_TUG1, names::PLANT_TUG2] {
        w.register::<VesselState>(topic)?;
    }
    for topic in [names::PLANT_TOWLINE1, names::PLANT_TOWLINE2] {
        w.register::<TowlineState>(topic)?;
    }
    w.register::<Obstacles>(names::PLANT_OBSTACLES)?;
    w.register::<PlantInputs>(names::PLANT_INPUTS)?;
    w.register::<FrameTransforms>(names::TF)?;
    w.register::<SceneUpdate>(names::PLANT_SCENE)?;
    w.register::<SceneUpdate>(names::PLANT_SCENE_STATIC)?;
    w.register::<Log>(names::PLANT_LOG)?;
    debug_assert_eq!(PLANT_TOPICS.len(), 11);
    Ok(())
}

/// The static scene at time `t`: the route with its waypoints, the static hazards with
/// their safe circles, and the hulls as boxes in their vessel frames (they move with
/// `/tf`).
pub fn write_static_scene(
    w: &mut LogWriter,
    t: f64,
    world: &World,
    info: &LogScenario,
) -> Result<(), LogError> {
    let mut route = SceneEntity::new("route", t);
    route.lines.push(scene::line_strip(
        info.route.iter().copied(),
        0.0,
        0.03,
        colors::ROUTE,
    ));
    for &[x, y] in info.route.iter().skip(1) {
        route
            .spheres
            .push(scene::sphere(x, y, 0.0, WAYPOINT_DIAMETER, colors::ROUTE));
    }
    let mut hazards = SceneEntity::new("hazards", t);
    let ship_length = world.ship_data().length;
    for o in world.obstacles() {
        if let ObstacleShape::Circle { diameter } = o.shape {
            hazards.cylinders.push(scene::cylinder(
                o.x,
                o.y,
                0.0,
                diameter,
                diameter,
                HAZARD_HEIGHT,
                colors::HAZARD,
            ));
            let safe = ship_length + 0.5 * diameter + SAFE_CIRCLE_BUFFER;
            hazards.lines.push(scene::circle_loop(
                o.x,
                o.y,
                safe,
                64,
                0.01,
                0.02,
                colors::SAFE,
            ));
        }
    }
    let mut entities = vec![route, hazards];
    // Hulls in their own frames, following `/tf`: sent once, not every step.
    let hulls = [
        (FRAME_SHIP, world.ship_data(), colors::SHIP),
        (FRAME_TUG1, world.tug_data(0), colors::TUG),
        (FRAME_TUG2, world.tug_data(1), colors::TUG),
    ];
    for (frame, d, color) in hulls {
        let mut hull = SceneEntity::locked_to(format!("{frame}_hull"), t, frame);
        hull.cubes
            .push(scene::hull_cube_in_vessel_frame(d.length, d.width, color));
        entities.push(hull);
    }
    let update = SceneUpdate {
        deletions: Vec::new(),
        entities,
    };
    w.write(names::PLANT_SCENE_STATIC, t, &update)
}

fn vessel_state(t: f64, s: &towing_model::VesselState) -> VesselState {
    VesselState {
        t,
        x: s.eta[0],
        y: s.eta[1],
        psi: s.eta[2],
        u: s.nu[0],
        v: s.nu[1],
        r: s.nu[2],
    }
}

/// Everything the per-step topics need, copied out of the world at time `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSnapshot {
    /// Simulation time (s).
    pub t: f64,
    /// Ship, tug 1, tug 2.
    pub vessels: [towing_model::VesselState; 3],
    /// Towline 1 and 2.
    pub towlines: [TowlineOutput; 2],
    /// Towline ends `[ship point, tug point]` (NED, m) of towline 1 and 2.
    pub towline_ends: [[[f64; 2]; 2]; 2],
    /// Every obstacle slot.
    pub obstacles: [ObstacleSlot; MAX_OBSTACLES],
    /// The inputs used for the step that ended at `t`.
    pub inputs: WorldInputs,
}

impl StepSnapshot {
    /// The state of `world` at `t` with the `inputs` of the last step.
    pub fn capture(t: f64, world: &World, inputs: &WorldInputs) -> Self {
        let ship = world.ship();
        let data = [world.ship_data(), world.tug_data(0), world.tug_data(1)];
        // Towline 1: ship stern point to tug 1's bow point; towline 2: ship bow point to
        // tug 2's stern point (docs/interface.md).
        let towline_ends = [
            [
                attachment_point(&ship.eta, data[0].stern_tow_point_x),
                attachment_point(&world.tug(0).eta, data[1].bow_tow_point_x),
            ],
            [
                attachment_point(&ship.eta, data[0].bow_tow_point_x),
                attachment_point(&world.tug(1).eta, data[2].stern_tow_point_x),
            ],
        ];
        Self {
            t,
            vessels: [*ship, *world.tug(0), *world.tug(1)],
            towlines: [world.towline(0), world.towline(1)],
            towline_ends,
            obstacles: std::array::from_fn(|slot| world.obstacle(slot)),
            inputs: *inputs,
        }
    }
}

/// Whether a step from `t_prev` to `t` (both counted from the start time, s) reaches a new
/// multiple of `interval` (s), so the Foxglove topics are due; always when `interval` is 0.
/// A tolerance of 1e-9 of a step keeps `k * interval` reached by a sum of equal steps on
/// time despite rounding.
#[must_use]
pub fn scene_due(interval: f64, t_prev: f64, t: f64) -> bool {
    if interval <= 0.0 {
        return true;
    }
    let eps = 1e-9 * (t - t_prev).abs().max(f64::MIN_POSITIVE);
    ((t + eps) / interval).floor() > ((t_prev + eps) / interval).floor()
}

/// Every per-step topic of `snap`; the Foxglove topics `/tf` and `/plant/scene` only with
/// `scene` (see [`scene_due`]).
pub fn write_state(
    w: &mut LogWriter,
    snap: &StepSnapshot,
    info: &LogScenario,
    scene: bool,
) -> Result<(), LogError> {
    let t = snap.t;
    let vessels = &snap.vessels;
    for (topic, s) in [names::PLANT_SHIP, names::PLANT_TUG1, names::PLANT_TUG2]
        .into_iter()
        .zip(vessels)
    {
        w.write(topic, t, &vessel_state(t, s))?;
    }
    for (i, topic) in [names::PLANT_TOWLINE1, names::PLANT_TOWLINE2]
        .into_iter()
        .enumerate()
    {
        let line = &snap.towlines[i];
        let desired = info.desired_length[i];
        w.write(
            topic,
            t,
            &TowlineState {
                t,
                length: line.length,
                angle: line.angle,
                tension: line.tension,
                tension_cmd: snap.inputs.tension_cmd[i],
                slack: line.slack,
                elongation_error: (line.length - desired) / desired,
            },
        )?;
    }
    let inputs = &snap.inputs;
    w.write(
        names::PLANT_INPUTS,
        t,
        &PlantInputs {
            t,
            tug1: inputs.tug_tau[0],
            tug2: inputs.tug_tau[1],
            tension_cmd: inputs.tension_cmd,
        },
    )?;
    if scene {
        let frames = [FRAME_SHIP, FRAME_TUG1, FRAME_TUG2];
        let transforms = FrameTransforms {
            transforms: frames
                .iter()
                .zip(vessels)
                .map(|(frame, s)| scene::frame_transform(frame, t, s.eta[0], s.eta[1], s.eta[2]))
                .collect(),
        };
        w.write(names::TF, t, &transforms)?;
    }
    let obstacles: Vec<ObstacleState> = snap
        .obstacles
        .iter()
        .enumerate()
        .filter(|(_, o)| o.kind != ObstacleKind::None)
        .map(|(slot, o)| ObstacleState {
            slot: slot as u32 + 1,
            name: info.obstacle_names.get(slot).cloned().unwrap_or_default(),
            kind: obstacle_kind_code(o.kind),
            x: o.x,
            y: o.y,
            psi: o.psi,
            speed: o.speed,
            length: o.length,
            width: o.width,
        })
        .collect();
    if scene {
        w.write(names::PLANT_SCENE, t, &moving_scene(snap, &obstacles))?;
    }
    w.write(names::PLANT_OBSTACLES, t, &Obstacles { t, obstacles })
}

/// Towlines (entity `towlines`) and the active target ships (entity `targets`); the hulls
/// are in the static scene, locked to their frames.
fn moving_scene(snap: &StepSnapshot, obstacles: &[ObstacleState]) -> SceneUpdate {
    let t = snap.t;
    let mut towlines = SceneEntity::new("towlines", t);
    for (line, ends) in snap.towlines.iter().zip(snap.towline_ends) {
        let color = if line.slack {
            colors::TOWLINE_SLACK
        } else {
            colors::TOWLINE
        };
        towlines.lines.push(scene::line(
            LinePrimitive::LINE_STRIP,
            ends,
            0.1,
            0.02,
            color,
        ));
    }
    let mut targets = SceneEntity::new("targets", t);
    let vessel = obstacle_kind_code(ObstacleKind::VesselEllipse);
    for o in obstacles.iter().filter(|o| o.kind == vessel) {
        targets.cylinders.push(scene::cylinder(
            o.x,
            o.y,
            o.psi,
            o.length,
            o.width,
            TARGET_HEIGHT,
            colors::TARGET,
        ));
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![towlines, targets],
    }
}

/// A warning or error the plant reported, on `/plant/log`.
pub fn write_log_line(
    w: &mut LogWriter,
    t: f64,
    level: i32,
    message: &str,
) -> Result<(), LogError> {
    w.write(
        names::PLANT_LOG,
        t,
        &scene::log_line(t, level, crate::variables::MODEL_IDENTIFIER, message),
    )
}

//! The controller's MCAP log (docs/logging.md): every topic at each control sample.
//! Messages are built only while a log is open (`log_file` set): the FMU copies the
//! sample into a [`Sample`], and the log's writer thread builds, serializes and
//! compresses them.

use crate::diagnostics::{role_code, situation_code};
use towing_control::{Measurement, SampleReport};
use towing_log::scene::{self, colors};
use towing_log::topics::{
    names, role_name, situation_name, Colregs, Command, Encounter, Log, NedPose, Prediction,
    Reference, SceneEntity, SceneUpdate, Solver, CONTROLLER_TOPICS,
};
use towing_log::{LogError, LogWriter};
use towing_model::{ObstacleKind, Pose, MAX_OBSTACLES};

/// Diameter of the active-waypoint sphere (m).
const WAYPOINT_DIAMETER: f64 = 0.35;
/// Length of the reference arrow (m).
const REFERENCE_ARROW: f64 = 0.8;

/// Registers every controller topic ([`CONTROLLER_TOPICS`]), so each channel is in the
/// file even without messages.
pub fn register_topics(w: &mut LogWriter) -> Result<(), LogError> {
    w.register::<Reference>(names::CONTROLLER_REFERENCE)?;
    w.register::<Colregs>(names::CONTROLLER_COLREGS)?;
    w.register::<Command>(names::CONTROLLER_COMMAND)?;
    w.register::<Solver>(names::CONTROLLER_SOLVER)?;
    w.register::<Prediction>(names::CONTROLLER_PREDICTION)?;
    w.register::<SceneUpdate>(names::CONTROLLER_SCENE)?;
    w.register::<Log>(names::CONTROLLER_LOG)?;
    debug_assert_eq!(CONTROLLER_TOPICS.len(), 7);
    Ok(())
}

/// One control sample, as the FMU saw it (owned: it travels to the writer thread).
#[derive(Debug, Clone)]
pub struct Sample {
    /// Simulation time of the sample (s).
    pub t: f64,
    /// The controller's report.
    pub report: SampleReport,
    /// The measurement the sample used.
    pub measurement: Measurement,
    /// The command the FMU outputs after the sample (inner loop included).
    pub command: towing_control::Command,
    /// `guidance.d_ob` as output (m, at most 1e6).
    pub d_ob: f64,
    /// `controller.samples` as output.
    pub samples: u64,
    /// The `architecture` parameter.
    pub architecture: i32,
    /// The `avoidance_scheme` parameter.
    pub scheme: i32,
    /// Whether the scheme follows the altered waypoint.
    pub scheme_alters: bool,
    /// The warning the FMU reports for this sample (a fallback), if any.
    pub warning: Option<String>,
}

fn pose(p: Pose) -> [f64; 3] {
    [p.x, p.y, p.psi]
}

/// Every controller topic for one sample.
pub fn write_sample(w: &mut LogWriter, s: &Sample) -> Result<(), LogError> {
    let t = s.t;
    let r = &s.report;
    let g = &r.guidance;
    let waypoint = if s.scheme_alters {
        pose(g.eta_sd)
    } else {
        pose(g.route_waypoint)
    };
    w.write(
        names::CONTROLLER_REFERENCE,
        t,
        &Reference {
            t,
            x: r.reference[0],
            y: r.reference[1],
            psi: r.reference[2],
            active_waypoint: u32::try_from(g.active_waypoint).unwrap_or(u32::MAX),
            altered: g.altered,
            d_ob: s.d_ob,
            waypoint,
        },
    )?;
    let targets = (0..MAX_OBSTACLES)
        .filter(|&k| s.measurement.obstacles[k].kind != ObstacleKind::None)
        .map(|k| {
            let (situation, role) = (situation_code(r.situation[k]), role_code(r.role[k]));
            Encounter {
                slot: k as u32 + 1,
                situation: situation_name(situation).to_owned(),
                role: role_name(role).to_owned(),
                situation_code: situation,
                role_code: role,
            }
        })
        .collect();
    w.write(names::CONTROLLER_COLREGS, t, &Colregs { t, targets })?;
    w.write(
        names::CONTROLLER_COMMAND,
        t,
        &Command {
            t,
            tug1: s.command.tug_thrust[0],
            tug2: s.command.tug_thrust[1],
            tension: s.command.tension,
            desired_angle: r.desired_angle,
        },
    )?;
    w.write(
        names::CONTROLLER_SOLVER,
        t,
        &Solver {
            t,
            architecture: s.architecture,
            scheme: s.scheme,
            iterations: u32::try_from(r.iterations).unwrap_or(u32::MAX),
            converged: r.converged,
            r_pri: r.r_pri,
            r_dual: r.r_dual,
            compute_time_ms: r.compute_time * 1e3,
            samples: s.samples,
            fallbacks: r.fallbacks,
            fallback: r.fallback.map(|f| f.to_string()).unwrap_or_default(),
        },
    )?;
    let poses = |states: &[[f64; 6]]| -> Vec<NedPose> {
        states
            .iter()
            .map(|x| NedPose::new([x[0], x[1], x[2]]))
            .collect()
    };
    let prediction = Prediction {
        t,
        ship: poses(&r.prediction.ship),
        tug1: poses(&r.prediction.tugs[0]),
        tug2: poses(&r.prediction.tugs[1]),
    };
    w.write(
        names::CONTROLLER_SCENE,
        t,
        &scene_update(s, &prediction, waypoint),
    )?;
    w.write(names::CONTROLLER_PREDICTION, t, &prediction)?;
    if let Some(message) = &s.warning {
        w.write(
            names::CONTROLLER_LOG,
            t,
            &scene::log_line(t, Log::WARNING, crate::variables::MODEL_IDENTIFIER, message),
        )?;
    }
    Ok(())
}

/// Predicted paths from the measured positions (entity `prediction`), the active (altered)
/// waypoint and the reference pose (entity `reference`).
fn scene_update(s: &Sample, p: &Prediction, waypoint: [f64; 3]) -> SceneUpdate {
    let t = s.t;
    let m = s.measurement;
    let mut paths = SceneEntity::new("prediction", t);
    let starts = [&m.ship, &m.tugs[0], &m.tugs[1]];
    for (start, states) in starts.into_iter().zip([&p.ship, &p.tug1, &p.tug2]) {
        let points = std::iter::once([start[0], start[1]]).chain(states.iter().map(|p| [p.x, p.y]));
        paths
            .lines
            .push(scene::line_strip(points, 0.05, 0.03, colors::PREDICTION));
    }
    let mut reference = SceneEntity::new("reference", t);
    reference.spheres.push(scene::sphere(
        waypoint[0],
        waypoint[1],
        0.0,
        WAYPOINT_DIAMETER,
        colors::REFERENCE,
    ));
    let r = s.report.reference;
    reference.arrows.push(scene::arrow(
        r[0],
        r[1],
        r[2],
        0.1,
        REFERENCE_ARROW,
        colors::REFERENCE,
    ));
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![paths, reference],
    }
}

//! Synthetic runs with known answers, written with `towing_log::LogWriter` exactly as the
//! FMUs write their logs (docs/logging.md): for the tests, the timing measurement and
//! trying the analyzer without the FMUs.
//!
//! The tow is kinematic: the ship moves along the route at a constant speed with the
//! heading of the current leg (turning instantly at waypoints) and stops at the
//! destination; the tugs sit in formation (towing angle 0) at the towline's length, which
//! oscillates with a chosen amplitude. So the settling time is the first sample at or after
//! the arrival, the ship travel is the route length, and the largest elongation errors are
//! the amplitudes.

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;

use towing_log::scene::{self, colors};
use towing_log::topics::{
    names, Colregs, Command, Encounter, FrameTransforms, ObstacleState, Obstacles, PlantInputs,
    Prediction, Reference, SceneEntity, SceneUpdate, Solver, TowlineState, VesselState,
};
use towing_log::{LogError, LogOptions, LogWriter, RunInfo};
use towing_model::Scenario;

use crate::colregs::{classify, Situation};
use crate::geometry::{body_to_ned, relative_bearing};

/// Shape of a synthetic obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SynthShape {
    /// A static circle of this diameter, m.
    Circle(f64),
    /// A target ship: length, width (m), course (deg), speed (m/s).
    Ship(f64, f64, f64, f64),
}

/// A synthetic obstacle.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthObstacle {
    /// Name.
    pub name: String,
    /// North, East at activation, m.
    pub pos: [f64; 2],
    /// Shape and motion.
    pub shape: SynthShape,
    /// Activation time, s (target ships).
    pub active_from: f64,
}

/// A synthetic run.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthRun {
    /// Scenario name.
    pub name: String,
    /// Route: origin, waypoints, destination as North, East (m), heading (deg).
    pub route: Vec<[f64; 3]>,
    /// Ship speed along the route, m/s.
    pub speed: f64,
    /// Plant steps after the initial state.
    pub steps: usize,
    /// Plant step, s.
    pub dt: f64,
    /// Plant steps per control sample.
    pub steps_per_sample: usize,
    /// Obstacles, in slot order.
    pub obstacles: Vec<SynthObstacle>,
    /// Relative elongation amplitude of towline 1 and 2 (a sine of period 100 s).
    pub elongation: [f64; 2],
    /// Write the scene, `/tf` and prediction topics too (realistic file sizes).
    pub scene: bool,
    /// Architecture and scheme codes of the solver topic.
    pub architecture: i32,
    /// Avoidance scheme code.
    pub scheme: i32,
    /// Command a tension of 3.5 N at this control sample (a bound violation).
    pub tension_spike_at_sample: Option<usize>,
}

impl SynthRun {
    /// The paper's route and obstacles (scenarios/paper.toml; B and C activated at 405 s
    /// and 590 s), `steps` plant steps of 0.1 s, control every 1 s, speed 0.06 m/s.
    #[must_use]
    pub fn paper(steps: usize) -> Self {
        let route = vec![
            [-4.9, 7.0, 101.3],
            [-6.3, 14.0, 101.3],
            [-7.7, 21.0, 101.3],
            [-9.1, 28.0, 101.3],
            [-10.7, 36.0, 101.3],
            [-15.0, 40.0, 180.0],
            [-22.0, 40.0, 180.0],
            [-29.0, 40.0, 180.0],
            [-36.0, 40.0, 180.0],
            [-43.0, 40.0, 180.0],
        ];
        let circle = |name: &str, x: f64, y: f64| SynthObstacle {
            name: name.to_owned(),
            pos: [x, y],
            shape: SynthShape::Circle(1.0),
            active_from: 0.0,
        };
        let ship = |name: &str, x: f64, y: f64, t: f64| SynthObstacle {
            name: name.to_owned(),
            pos: [x, y],
            shape: SynthShape::Ship(1.48, 0.48, 0.0, 0.07),
            active_from: t,
        };
        SynthRun {
            name: "paper".to_owned(),
            route,
            speed: 0.06,
            steps,
            dt: 0.1,
            steps_per_sample: 10,
            obstacles: vec![
                circle("a", -10.0, 15.0),
                circle("b", -12.0, 25.0),
                circle("c", -14.0, 35.0),
                ship("A", -19.0, 21.0, 0.0),
                ship("B", -22.0, 40.75, 405.0),
                ship("C", -38.0, 40.5, 590.0),
            ],
            elongation: [0.03, 0.05],
            scene: true,
            architecture: 1,
            scheme: 1,
            tension_spike_at_sample: None,
        }
    }

    /// Length of the route, m.
    #[must_use]
    pub fn route_length(&self) -> f64 {
        self.route
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum()
    }

    /// Time the ship reaches the destination, s.
    #[must_use]
    pub fn arrival_time(&self) -> f64 {
        self.route_length() / self.speed
    }

    /// The settling time the analyzer must find: the first plant sample at or after the
    /// arrival (`None` if the run ends before).
    #[must_use]
    pub fn expected_settling_time(&self) -> Option<f64> {
        let k = (self.arrival_time() / self.dt - 1e-9).ceil() as usize;
        (k <= self.steps).then_some(k as f64 * self.dt)
    }

    /// The scenario text (format of docs/scenario-format.md) of this run.
    #[must_use]
    pub fn scenario_toml(&self) -> String {
        let mut s = String::new();
        let o = self.route[0];
        let _ = writeln!(s, "format_version = 1\nname = \"{}\"\n", self.name);
        let _ = writeln!(
            s,
            "[ship]\nx = {:?}\ny = {:?}\npsi_deg = {:?}\n",
            o[0], o[1], o[2]
        );
        s.push_str("[tug1]\nformation = { towing_angle_deg = 0.0 }\n\n");
        s.push_str("[tug2]\nformation = { towing_angle_deg = 0.0 }\n\n");
        s.push_str("[towline1]\ndesired_length = 1.0\n\n[towline2]\ndesired_length = 1.0\n\n");
        let pose =
            |p: [f64; 3]| format!("{{ x = {:?}, y = {:?}, psi_deg = {:?} }}", p[0], p[1], p[2]);
        let n = self.route.len();
        let _ = writeln!(
            s,
            "[route]\norigin = {}\nwaypoints = [",
            pose(self.route[0])
        );
        for p in &self.route[1..n - 1] {
            let _ = writeln!(s, "    {},", pose(*p));
        }
        let _ = writeln!(s, "]\ndestination = {}\n", pose(self.route[n - 1]));
        for ob in &self.obstacles {
            match ob.shape {
                SynthShape::Circle(d) => {
                    let _ = writeln!(
                        s,
                        "[[obstacles]]\nname = \"{}\"\nkind = \"static\"\nx = {:?}\ny = {:?}\ndiameter = {:?}\n",
                        ob.name, ob.pos[0], ob.pos[1], d
                    );
                }
                SynthShape::Ship(l, w, c, v) => {
                    let _ = writeln!(
                        s,
                        "[[obstacles]]\nname = \"{}\"\nkind = \"ship\"\nx = {:?}\ny = {:?}\nlength = {:?}\nwidth = {:?}\ncourse_deg = {:?}\nspeed = {:?}\nactivation_time = {:?}\n",
                        ob.name, ob.pos[0], ob.pos[1], l, w, c, v, ob.active_from
                    );
                }
            }
        }
        s
    }

    /// Ship pose and surge at time `t`: North, East, heading (rad), u.
    #[must_use]
    pub fn ship_at(&self, t: f64) -> [f64; 4] {
        let mut s = (self.speed * t).max(0.0);
        for w in self.route.windows(2) {
            let (a, b) = (w[0], w[1]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let course = (b[1] - a[1]).atan2(b[0] - a[0]);
            if s < len {
                let f = s / len;
                return [
                    a[0] + f * (b[0] - a[0]),
                    a[1] + f * (b[1] - a[1]),
                    course,
                    self.speed,
                ];
            }
            s -= len;
        }
        let d = self.route[self.route.len() - 1];
        [d[0], d[1], d[2].to_radians(), 0.0]
    }

    fn obstacle_at(&self, k: usize, t: f64) -> Option<ObstacleState> {
        let ob = &self.obstacles[k];
        let slot = u32::try_from(k + 1).unwrap_or(u32::MAX);
        match ob.shape {
            SynthShape::Circle(d) => Some(ObstacleState {
                slot,
                name: ob.name.clone(),
                kind: 1,
                x: ob.pos[0],
                y: ob.pos[1],
                psi: 0.0,
                speed: 0.0,
                length: d,
                width: d,
            }),
            SynthShape::Ship(l, w, c, v) => {
                if t < ob.active_from {
                    return None;
                }
                let c = c.to_radians();
                let dt = t - ob.active_from;
                Some(ObstacleState {
                    slot,
                    name: ob.name.clone(),
                    kind: 2,
                    x: ob.pos[0] + v * dt * c.cos(),
                    y: ob.pos[1] + v * dt * c.sin(),
                    psi: c,
                    speed: v,
                    length: l,
                    width: w,
                })
            }
        }
    }

    /// Writes the plant log and the controller log.
    ///
    /// # Errors
    /// The scenario text does not parse, or a log cannot be written.
    pub fn write(&self, plant_path: &Path, controller_path: &Path) -> Result<(), SynthError> {
        let text = self.scenario_toml();
        let scenario = Scenario::from_toml_str(&text, "synthetic run")
            .map_err(|e| SynthError(e.to_string()))?;
        let options = LogOptions::default();
        let mut plant = LogWriter::create(plant_path, options)?;
        let mut ctrl = LogWriter::create(controller_path, options)?;
        self.write_run_info(&mut plant, &mut ctrl, &text)?;

        let mut held: Vec<Option<Situation>> = vec![None; self.obstacles.len()];
        for k in 0..=self.steps {
            let tow = self.tow_at(&scenario, k);
            let obstacles: Vec<ObstacleState> = (0..self.obstacles.len())
                .filter_map(|j| self.obstacle_at(j, tow.t))
                .collect();
            self.write_plant_step(&mut plant, &scenario, &tow, &obstacles)?;
            if self.scene {
                write_scene(&mut plant, &scenario, &tow, &obstacles)?;
            }
            if k % self.steps_per_sample == 0 {
                self.write_control_sample(&mut ctrl, &tow, &obstacles, &mut held)?;
            }
        }
        plant.finish()?;
        ctrl.finish()?;
        Ok(())
    }

    /// Writes the `run` metadata (with the controller's parameters) and the scenario
    /// `text` into both logs.
    fn write_run_info(
        &self,
        plant: &mut LogWriter,
        ctrl: &mut LogWriter,
        text: &str,
    ) -> Result<(), SynthError> {
        let params = serde_json::json!({
            "architecture": self.architecture,
            "avoidance_scheme": self.scheme,
            "mpc.sample_time": self.dt * self.steps_per_sample as f64,
            "mpc.ship.max_tension": 3.0,
            "mpc.ship.tension_rate": 0.3,
            "mpc.ship.max_towing_angle": 30f64.to_radians(),
            "mpc.ship.towing_angle_rate": 5f64.to_radians(),
            "mpc.tug.max_force_surge": 10.0,
            "mpc.tug.max_force_sway": 10.0,
            "mpc.tug.max_moment_yaw": 10.0,
            "guidance.detection_distance": 7.0,
            "guidance.safety_buffer": 0.25,
        });
        for (w, unit) in [(plant, "TowingPlant"), (ctrl, "TowingController")] {
            w.write_run(&RunInfo {
                unit,
                guid: "{00000000-0000-0000-0000-000000000000}",
                version: "synthetic",
                scenario: "synthetic",
                scenario_name: &self.name,
                run_id: "synthetic",
                start_time: 0.0,
                parameters: params.clone(),
                scenario_text: text,
            })?;
        }
        Ok(())
    }

    /// The tow at plant step `k`: the ship on the route, the towlines at their oscillating
    /// lengths and the tugs in formation with towing angle 0 (tug 2 ahead of the bow
    /// point, tug 1 behind the stern point, both on the ship's heading).
    fn tow_at(&self, scenario: &Scenario, k: usize) -> TowAt {
        let t = k as f64 * self.dt;
        let ship = self.ship_at(t);
        let [sx, sy, sp, _] = ship;
        let l_tow = scenario.towline_desired_length;
        let lengths =
            [0, 1].map(|i| l_tow[i] * (1.0 + self.elongation[i] * (2.0 * PI * t / 100.0).sin()));
        let ship_data = &scenario.ship_data;
        let tug_data = &scenario.tug_data;
        let bow = body_to_ned(sx, sy, sp, ship_data.bow_tow_point_x, 0.0);
        let stern = body_to_ned(sx, sy, sp, ship_data.stern_tow_point_x, 0.0);
        let tug2 = body_to_ned(
            bow[0],
            bow[1],
            sp,
            lengths[1] - tug_data[1].stern_tow_point_x,
            0.0,
        );
        let tug1 = body_to_ned(
            stern[0],
            stern[1],
            sp,
            -(lengths[0] + tug_data[0].bow_tow_point_x),
            0.0,
        );
        TowAt {
            t,
            ship,
            tug1,
            tug2,
            bow,
            stern,
            lengths,
            sample: k / self.steps_per_sample,
        }
    }

    /// Commanded (and measured) tension of towline `i` at control sample `sample`, N: a
    /// slow sine, or the spike of `tension_spike_at_sample`.
    fn tension(&self, sample: usize, i: usize) -> f64 {
        let base = 1.0 + 0.2 * ((2.0 * PI * sample as f64 / 200.0) + i as f64).sin();
        if self.tension_spike_at_sample == Some(sample) {
            3.5
        } else {
            base
        }
    }

    /// Writes the plant's topics of one step: the vessels, the towlines, the obstacles
    /// and the inputs.
    fn write_plant_step(
        &self,
        plant: &mut LogWriter,
        scenario: &Scenario,
        tow: &TowAt,
        obstacles: &[ObstacleState],
    ) -> Result<(), SynthError> {
        let t = tow.t;
        let [sx, sy, sp, su] = tow.ship;
        let vs = |x: f64, y: f64| VesselState {
            t,
            x,
            y,
            psi: sp,
            u: su,
            v: 0.0,
            r: 0.0,
        };
        plant.write(names::PLANT_SHIP, t, &vs(sx, sy))?;
        plant.write(names::PLANT_TUG1, t, &vs(tow.tug1[0], tow.tug1[1]))?;
        plant.write(names::PLANT_TUG2, t, &vs(tow.tug2[0], tow.tug2[1]))?;
        let l_tow = scenario.towline_desired_length;
        let lengths = tow.lengths;
        for i in 0..2 {
            plant.write(
                if i == 0 {
                    names::PLANT_TOWLINE1
                } else {
                    names::PLANT_TOWLINE2
                },
                t,
                &TowlineState {
                    t,
                    length: lengths[i],
                    angle: 0.0,
                    tension: self.tension(tow.sample, i),
                    tension_cmd: self.tension(tow.sample, i),
                    slack: false,
                    elongation_error: (lengths[i] - l_tow[i]) / l_tow[i],
                },
            )?;
        }
        plant.write(
            names::PLANT_OBSTACLES,
            t,
            &Obstacles {
                t,
                obstacles: obstacles.to_vec(),
            },
        )?;
        plant.write(
            names::PLANT_INPUTS,
            t,
            &PlantInputs {
                t,
                tug1: thrust(t),
                tug2: thrust(t),
                tension_cmd: [self.tension(tow.sample, 0), self.tension(tow.sample, 1)],
            },
        )?;
        Ok(())
    }

    /// Writes the controller's topics of one control sample: the reference (the next
    /// route point farther than 0.6 m), the COLREGS situations ([`Self::encounters`]), the
    /// command, the solver report and (with `scene`) the prediction.
    fn write_control_sample(
        &self,
        ctrl: &mut LogWriter,
        tow: &TowAt,
        obstacles: &[ObstacleState],
        held: &mut [Option<Situation>],
    ) -> Result<(), SynthError> {
        let t = tow.t;
        let s = tow.sample;
        let [sx, sy, sp, _] = tow.ship;
        let next = self
            .route
            .iter()
            .skip(1)
            .find(|p| (p[0] - sx).hypot(p[1] - sy) > 0.6)
            .copied()
            .unwrap_or(self.route[self.route.len() - 1]);
        ctrl.write(
            names::CONTROLLER_REFERENCE,
            t,
            &Reference {
                t,
                x: next[0],
                y: next[1],
                psi: next[2].to_radians(),
                active_waypoint: 1,
                altered: false,
                d_ob: 1e6,
                waypoint: [next[0], next[1], next[2].to_radians()],
            },
        )?;
        let targets = encounters(tow, obstacles, held);
        ctrl.write(names::CONTROLLER_COLREGS, t, &Colregs { t, targets })?;
        let angle = |i: usize| 10f64.to_radians() * (2.0 * PI * s as f64 / 300.0 + i as f64).sin();
        ctrl.write(
            names::CONTROLLER_COMMAND,
            t,
            &Command {
                t,
                tug1: thrust(t),
                tug2: thrust(t),
                tension: [self.tension(s, 0), self.tension(s, 1)],
                desired_angle: [angle(0), angle(1)],
            },
        )?;
        let iterations = 10 + u32::try_from(s * 5 % 21).unwrap_or(0);
        let fallback = (s > 0 && s.is_multiple_of(500)).then(|| "synthetic fallback".to_owned());
        ctrl.write(
            names::CONTROLLER_SOLVER,
            t,
            &Solver {
                t,
                architecture: self.architecture,
                scheme: self.scheme,
                iterations,
                converged: iterations < 30,
                r_pri: [1e-3 * (1.0 + (s % 5) as f64), 2e-3],
                r_dual: [5e-4, 1e-4 * (1.0 + (s % 3) as f64)],
                compute_time_ms: 5.0 + (s * 13 % 40) as f64 + 0.5,
                samples: s as u64 + 1,
                fallbacks: (s / 500) as u64,
                fallback,
            },
        )?;
        if self.scene {
            let pose = |x: f64, y: f64| vec![[x, y, sp]; 3];
            ctrl.write(
                names::CONTROLLER_PREDICTION,
                t,
                &Prediction {
                    t,
                    ship: pose(sx, sy),
                    tug1: pose(tow.tug1[0], tow.tug1[1]),
                    tug2: pose(tow.tug2[0], tow.tug2[1]),
                },
            )?;
        }
        Ok(())
    }
}

/// The tow at one plant step of a synthetic run.
struct TowAt {
    /// Time, s.
    t: f64,
    /// Ship North, East (m), heading (rad), surge (m/s).
    ship: [f64; 4],
    /// Tug 1 (aft) North, East, m.
    tug1: [f64; 2],
    /// Tug 2 (forward) North, East, m.
    tug2: [f64; 2],
    /// The ship's bow tow point, North, East, m.
    bow: [f64; 2],
    /// The ship's stern tow point, North, East, m.
    stern: [f64; 2],
    /// Towline 1 and 2 lengths, m.
    lengths: [f64; 2],
    /// Control sample the step belongs to.
    sample: usize,
}

/// Thrust of each tug (X N, Y N, N N m) at time `t`, s: commanded and applied alike.
fn thrust(t: f64) -> [f64; 3] {
    [2.0, 0.1 * (t / 50.0).sin(), 0.05]
}

/// Writes the scene topics of one plant step: `/tf` and the hulls, towlines and target
/// ships.
fn write_scene(
    plant: &mut LogWriter,
    scenario: &Scenario,
    tow: &TowAt,
    obstacles: &[ObstacleState],
) -> Result<(), SynthError> {
    let t = tow.t;
    let [sx, sy, sp, _] = tow.ship;
    let (t1, t2) = (tow.tug1, tow.tug2);
    let poses = [(sx, sy), (t1[0], t1[1]), (t2[0], t2[1])];
    plant.write(
        names::TF,
        t,
        &FrameTransforms {
            transforms: ["ship", "tug1", "tug2"]
                .iter()
                .zip(poses)
                .map(|(n, (x, y))| scene::frame_transform(n, t, x, y, sp))
                .collect(),
        },
    )?;
    let ship_data = &scenario.ship_data;
    let mut e = SceneEntity::new("vessels", t);
    e.cubes.push(scene::hull_cube(
        sx,
        sy,
        sp,
        ship_data.length,
        ship_data.width,
        colors::SHIP,
    ));
    e.cubes
        .push(scene::hull_cube(t1[0], t1[1], sp, 0.97, 0.3, colors::TUG));
    e.cubes
        .push(scene::hull_cube(t2[0], t2[1], sp, 0.97, 0.3, colors::TUG));
    e.lines.push(scene::line_strip(
        [tow.stern, t1],
        0.1,
        0.02,
        colors::TOWLINE,
    ));
    e.lines
        .push(scene::line_strip([tow.bow, t2], 0.1, 0.02, colors::TOWLINE));
    let mut o = SceneEntity::new("targets", t);
    for ob in obstacles.iter().filter(|o| o.kind == 2) {
        o.cylinders.push(scene::cylinder(
            ob.x,
            ob.y,
            ob.psi,
            ob.length,
            ob.width,
            0.2,
            colors::TARGET,
        ));
    }
    plant.write(
        names::PLANT_SCENE,
        t,
        &SceneUpdate {
            deletions: Vec::new(),
            entities: vec![e, o],
        },
    )?;
    Ok(())
}

/// The situation and role of each active obstacle: static ones none; a target ship's is
/// classified once, when it first comes within 7 m (the detection distance), and held in
/// `held` (by slot) afterwards.
fn encounters(
    tow: &TowAt,
    obstacles: &[ObstacleState],
    held: &mut [Option<Situation>],
) -> Vec<Encounter> {
    let [sx, sy, sp, su] = tow.ship;
    let mut targets = Vec::new();
    for ob in obstacles {
        let j = (ob.slot - 1) as usize;
        let (code, role) = if ob.kind == 1 {
            (-1, "none")
        } else {
            let range = (ob.x - sx).hypot(ob.y - sy);
            if held[j].is_none() && range < 7.0 {
                let beta = relative_bearing([sx, sy], sp, [ob.x, ob.y]).to_degrees();
                let alpha = relative_bearing([ob.x, ob.y], ob.psi, [sx, sy]).to_degrees();
                held[j] = Some(classify(beta, alpha, su, ob.speed));
            }
            match held[j] {
                Some(Situation::CrossingStandOn | Situation::BeingOvertaken) => {
                    (situation_code(held[j]), "stand-on")
                }
                Some(_) => (situation_code(held[j]), "give-way"),
                None => (0, "none"),
            }
        };
        targets.push(Encounter {
            slot: ob.slot,
            situation: Situation::from_code(code)
                .map_or("none", Situation::name)
                .to_owned(),
            role: role.to_owned(),
            situation_code: code,
            role_code: match role {
                "give-way" => 1,
                "stand-on" => 2,
                _ => 0,
            },
        });
    }
    targets
}

fn situation_code(s: Option<Situation>) -> i32 {
    s.map_or(0, Situation::code)
}

/// A synthetic run could not be written.
#[derive(Debug, thiserror::Error)]
#[error("synthetic run: {0}")]
pub struct SynthError(pub String);

impl From<LogError> for SynthError {
    fn from(e: LogError) -> Self {
        SynthError(e.to_string())
    }
}

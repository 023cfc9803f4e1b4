//! Physics honesty (DESIGN.md): with the same hull model selected, the
//! controller's one-sample prediction of every vessel agrees with the plant.
//!
//! The plant (`towing_model::World`, paper scenario, tugs placed in formation by
//! the scenario's `formation = { towing_angle_deg = .. }`) is stepped over
//! `T_s = 1 s` (10 communication steps of 0.1 s, its default 0.01 s RK4 substeps)
//! with constant ideal-winch tensions and tug thrusts. The models predict the same
//! second from the plant's initial state: [`ShipModel`] with `u = [F_1, F_2,
//! alpha_1, alpha_2]`, the towing angles the plant reports at the start, and
//! [`TugModel`] with the tension and the line bearing `psi_S + alpha_i` at the
//! start.
//!
//! The one modelling difference: the models hold the towing angle (ship) and the
//! line bearing (tugs) over the sample, while the plant's lines follow the moving
//! geometry. Where that geometry cannot change (a collinear tow: alpha = 0, pure
//! surge), the agreement is to rounding; otherwise the errors measured below are
//! second order in the sample (they vanish with the change of the angles).

use nalgebra::Vector3;
use towing_model::{
    wrap_angle, HullModel, Scenario, TugPlacement, World, WorldInputs, PAPER_SCENARIO,
};
use towing_mpc::{PredictionParams, ShipModel, TowlinePull, TugModel};

const MODELS: [HullModel; 2] = [HullModel::LinearDamping, HullModel::NonlinearDamping];

/// Initial motion of the tow.
#[derive(Clone, Copy, Debug)]
enum Motion {
    /// Every vessel at 0.15 m/s along its own heading, no sway or yaw.
    Surge,
    /// The ship at `[0.15 m/s, 0.01 m/s, 0.01 rad/s]`, the tugs moving rigidly
    /// with it (the formation's velocity field at their positions).
    Manoeuvring,
}

/// The paper scenario with the tugs in formation at `(alpha_1, alpha_2)` degrees.
fn scenario(alpha_deg: [f64; 2], motion: Motion) -> Scenario {
    let text = PAPER_SCENARIO
        .replace(
            "[tug1]\nformation = { towing_angle_deg = 0.0 }",
            &format!(
                "[tug1]\nformation = {{ towing_angle_deg = {} }}",
                alpha_deg[0]
            ),
        )
        .replace(
            "[tug2]\nformation = { towing_angle_deg = 0.0 }",
            &format!(
                "[tug2]\nformation = {{ towing_angle_deg = {} }}",
                alpha_deg[1]
            ),
        );
    assert_ne!(text, PAPER_SCENARIO, "the formation lines were found");
    let mut s = Scenario::from_toml_str(&text, "agreement").expect("scenario parses");
    match motion {
        Motion::Surge => {
            s.ship.nu = [0.15, 0.0, 0.0];
            for tug in &mut s.tugs {
                tug.nu = [0.15, 0.0, 0.0];
            }
        }
        Motion::Manoeuvring => {
            let nu = [0.15, 0.01, 0.01];
            s.ship.nu = nu;
            let psi = s.ship.eta[2];
            let (sn, cs) = psi.sin_cos();
            let vel_n = [cs * nu[0] - sn * nu[1], sn * nu[0] + cs * nu[1]];
            for tug in &mut s.tugs {
                let d = [tug.eta[0] - s.ship.eta[0], tug.eta[1] - s.ship.eta[1]];
                // Rigid motion: v = V_S + r x d (z down: r x d = r (-d_y, d_x)).
                let v = [vel_n[0] - nu[2] * d[1], vel_n[1] + nu[2] * d[0]];
                let (st, ct) = tug.eta[2].sin_cos();
                tug.nu = [ct * v[0] + st * v[1], -st * v[0] + ct * v[1], nu[2]];
            }
        }
    }
    s.validate().expect("valid scenario");
    s
}

/// Line tensions (N), inside the winch range: the ideal winch applies them.
const TENSION: [f64; 2] = [1.0, 2.0];

/// How the tugs are driven over the second.
#[derive(Clone, Copy, Debug)]
enum Thrust {
    /// Tug 2 pulls ahead with 3 N, tug 1 brakes with 0.3 N, no steering: the
    /// formation is not held unless the tow is collinear.
    Fixed,
    /// Each tug's thrust makes its initial acceleration that of the rigid
    /// formation at its position (inverse dynamics with the same hull): the
    /// formation is held to second order at the start.
    HoldFormation,
}

/// The thrusts of `thrust` for the tow at its initial state.
fn thrusts(scenario: &Scenario, hull: HullModel, thrust: Thrust) -> [[f64; 3]; 2] {
    match thrust {
        Thrust::Fixed => [[-0.3, 0.0, 0.0], [3.0, 0.0, 0.0]],
        Thrust::HoldFormation => {
            let params = PredictionParams::default();
            let ship = ShipModel::from_scenario(scenario, hull, params).expect("ship model");
            let s = scenario.ship;
            let alpha = [0, 1].map(|i| match scenario.tug_placement[i] {
                TugPlacement::Formation { towing_angle } => towing_angle,
                TugPlacement::Explicit => unreachable!("placed in formation"),
            });
            let x0 = [s.eta[0], s.eta[1], s.eta[2], s.nu[0], s.nu[1], s.nu[2]];
            let f = ship.derivative(&x0, &[TENSION[0], TENSION[1], alpha[0], alpha[1]]);
            // Ship CO acceleration in NED: R(psi) (nu_dot + r [-v, u]).
            let (sn, cs) = s.eta[2].sin_cos();
            let ab = [f[3] - s.nu[2] * s.nu[1], f[4] + s.nu[2] * s.nu[0]];
            let a_ship = [cs * ab[0] - sn * ab[1], sn * ab[0] + cs * ab[1]];
            let (r, r_dot) = (s.nu[2], f[5]);
            [0, 1].map(|i| {
                let t = scenario.tugs[i];
                let d = [t.eta[0] - s.eta[0], t.eta[1] - s.eta[1]];
                // Rigid body: a = a_S + r_dot x d - r^2 d.
                let a = [
                    a_ship[0] - r_dot * d[1] - r * r * d[0],
                    a_ship[1] + r_dot * d[0] - r * r * d[1],
                ];
                let (st, ct) = t.eta[2].sin_cos();
                let nu_dot = Vector3::new(
                    ct * a[0] + st * a[1] + t.nu[2] * t.nu[1],
                    -st * a[0] + ct * a[1] - t.nu[2] * t.nu[0],
                    r_dot,
                );
                let tug = TugModel::from_scenario(scenario, i, hull, params).expect("tug model");
                let kinetics = tug.hull().dynamics();
                let nu = Vector3::from(t.nu);
                let pull = TowlinePull::from_plan(TENSION[i], s.eta[2], alpha[i]);
                let load = Vector3::from(tug.towline_load(t.eta[2], &pull));
                // tau = M nu_dot + C(nu) nu + D(nu) nu - towline load.
                let tau = kinetics.mass_matrix() * nu_dot
                    + kinetics.coriolis_matrix(&nu) * nu
                    + kinetics.damping_matrix(&nu) * nu
                    - load;
                let tau = [tau[0], tau[1], tau[2]];
                let limit = 10.0;
                assert!(
                    tau.iter().all(|t| t.abs() < limit),
                    "thrust {tau:?} saturates"
                );
                tau
            })
        }
    }
}

/// Errors of one vessel: position (m), heading (rad), velocity (max abs).
#[derive(Debug, Clone, Copy, Default)]
struct Errors {
    position: f64,
    heading: f64,
    velocity: f64,
}

impl Errors {
    fn of(predicted: &[f64; 6], eta: [f64; 3], nu: [f64; 3]) -> Errors {
        Errors {
            position: (predicted[0] - eta[0]).hypot(predicted[1] - eta[1]),
            heading: wrap_angle(predicted[2] - eta[2]).abs(),
            velocity: (0..3)
                .map(|k| (predicted[3 + k] - nu[k]).abs())
                .fold(0.0, f64::max),
        }
    }
}

/// What changed in the plant's line geometry during the sample: the largest
/// change of a towing angle `alpha_i` (what the ship model holds) and of each
/// line's bearing `psi_S + alpha_i` (what tug model `i` holds), in rad.
#[derive(Debug, Clone, Copy, Default)]
struct Change {
    angle: f64,
    bearing: [f64; 2],
}

/// Runs the plant over `sample_time` (in communication steps of `comm_step`) and
/// predicts it with the models (RK4 substep `integration_step`). Returns the
/// errors of ship, tug 1, tug 2 and the change of the line geometry.
fn compare(
    hull: HullModel,
    alpha_deg: [f64; 2],
    motion: Motion,
    thrust: Thrust,
    sample_time: f64,
    comm_step: f64,
    integration_step: f64,
) -> ([Errors; 3], Change) {
    let scenario = scenario(alpha_deg, motion);
    let mut config = scenario.world_config;
    config.hull_model = hull;
    let mut world = World::new(&scenario, config).expect("world builds");
    let inputs = WorldInputs {
        tug_tau: thrusts(&scenario, hull, thrust),
        tension_cmd: TENSION,
    };

    let x0 = |eta: [f64; 3], nu: [f64; 3]| [eta[0], eta[1], eta[2], nu[0], nu[1], nu[2]];
    let ship0 = x0(world.ship().eta, world.ship().nu);
    let tug0 = [0, 1].map(|i| x0(world.tug(i).eta, world.tug(i).nu));
    let alpha0 = [world.towline(0).angle, world.towline(1).angle];
    for (a, deg) in alpha0.iter().zip(alpha_deg) {
        assert!((a - deg.to_radians()).abs() < 1e-14, "placed in formation");
    }
    let tension = inputs.tension_cmd; // inside [0, 3 N]: the ideal winch applies it

    let steps = (sample_time / comm_step).round() as usize;
    let mut change = Change::default();
    for _ in 0..steps {
        world.step(&inputs, comm_step).expect("plant steps");
        for (line, a0) in alpha0.iter().enumerate() {
            let alpha = world.towline(line).angle;
            change.angle = change.angle.max((alpha - a0).abs());
            let turn = wrap_angle(world.ship().eta[2] + alpha - (ship0[2] + a0)).abs();
            change.bearing[line] = change.bearing[line].max(turn);
        }
    }
    for (line, applied) in tension.iter().enumerate() {
        assert_eq!(world.towline(line).tension, *applied, "ideal winch");
    }

    let params = PredictionParams {
        sample_time,
        integration_step,
    };
    let ship = ShipModel::from_scenario(&scenario, hull, params).expect("ship model");
    let u = [tension[0], tension[1], alpha0[0], alpha0[1]];
    let ship_pred = ship.step(&ship0, &u);
    let mut errors = [Errors::of(&ship_pred, world.ship().eta, world.ship().nu); 3];
    for i in 0..2 {
        let tug = TugModel::from_scenario(&scenario, i, hull, params).expect("tug model");
        let pull = TowlinePull::from_plan(tension[i], ship0[2], alpha0[i]);
        let pred = tug.step(&tug0[i], &inputs.tug_tau[i], &pull);
        errors[1 + i] = Errors::of(&pred, world.tug(i).eta, world.tug(i).nu);
    }
    (errors, change)
}

/// Tolerances of one vessel: position (m), heading (rad), velocity (m/s, rad/s).
type Tolerance = [f64; 3];

fn check(label: &str, errors: &[Errors; 3], change: &Change, tolerance: [Tolerance; 3]) {
    let names = ["ship", "tug 1", "tug 2"];
    for ((e, tol), name) in errors.iter().zip(tolerance).zip(names) {
        assert!(
            e.position < tol[0] && e.heading < tol[1] && e.velocity < tol[2],
            "{label}, {name}: errors {e:?} exceed {tol:?} (geometry change {change:?})"
        );
    }
}

const ALPHAS: [[f64; 2]; 2] = [[0.0, 0.0], [-5.0, 10.0]];

/// Exact agreement. A collinear tow (alpha = 0, every vessel in pure surge along
/// the same line, thrust in surge only) keeps its line geometry exactly, so the
/// models' held angle and bearing are the plant's at every RK4 stage: same
/// forces, same hull, same RK4. With the plant's 0.01 s substep the prediction
/// is the plant to rounding, for one substep and for the whole second (measured:
/// position 0, velocity <= 9e-16 m/s).
#[test]
fn collinear_tow_agrees_to_rounding() {
    let exact = [1e-12; 3];
    for hull in MODELS {
        for (sample, comm) in [(0.01, 0.01), (1.0, 0.1), (1.0, 1.0)] {
            let (e, c) = compare(
                hull,
                [0.0; 2],
                Motion::Surge,
                Thrust::Fixed,
                sample,
                comm,
                0.01,
            );
            assert!(
                c.angle < 1e-13 && c.bearing.iter().all(|b| *b < 1e-13),
                "{c:?}"
            );
            check(&format!("{hull:?}, {sample} s"), &e, &c, [exact; 3]);
        }
    }
}

/// The models' default 0.1 s substep against the plant's 0.01 s, where the
/// geometry is exact (collinear tow): the RK4 discretisation difference over
/// 1 s (measured: <= 7.6e-11 m, 1.1e-11 m/s).
#[test]
fn default_substep_changes_the_prediction_by_rk4_error_only() {
    let rk4 = [1e-9, 1e-12, 1e-10];
    for hull in MODELS {
        let (e, c) = compare(hull, [0.0; 2], Motion::Surge, Thrust::Fixed, 1.0, 0.1, 0.1);
        check(&format!("{hull:?}"), &e, &c, [rk4; 3]);
    }
}

/// One plant substep (h = 0.01 s, the models at the same substep) of a turning
/// tow in formation (rigid velocities, formation-holding thrust), towing angles
/// 0 and (-5, 10) deg. The ship model agrees to rounding in position and to
/// 1e-10 m/s (measured 0 m, <= 2.0e-11 m/s: the plant's angles change by <= 3e-8
/// rad in 0.01 s). The tug models hold the line's bearing fixed in NED while the
/// plant's line turns with the ship (r = 0.01 rad/s, 1e-4 rad in the substep): a
/// first-order difference, measured <= 5.1e-11 m, 7.3e-10 rad, 2.2e-7 m/s.
#[test]
fn one_plant_substep_agrees() {
    let ship = [1e-12, 1e-12, 1e-10];
    let tug = [2e-10, 2e-9, 5e-7];
    for hull in MODELS {
        for alpha in ALPHAS {
            let (e, c) = compare(
                hull,
                alpha,
                Motion::Manoeuvring,
                Thrust::HoldFormation,
                0.01,
                0.01,
                0.01,
            );
            assert!(c.angle < 1e-7, "formation held: {c:?}");
            check(&format!("{hull:?} {alpha:?}"), &e, &c, [ship, tug, tug]);
        }
    }
}

/// The test: one sample of T_s = 1 s (10 communication steps of 0.1 s)
/// with constant tensions and thrusts, both hull models, towing angles 0 and
/// (-5, 10) deg, the models at the plant's substep and at their default. Cases:
/// the formation held at the start (rigid velocities, formation-holding thrust:
/// the towing angles still change by up to 0.024 rad over the second, since
/// constant inputs cannot hold it), and drifting formations (fixed thrust, or
/// each vessel surging along its own heading: up to 0.025 rad).
///
/// Measured, worst over all cases: ship 8.4e-5 m, 1.4e-3 rad, 5.0e-3 m/s (m/s or
/// rad/s, whichever component is worst); tug 1 5.1e-5 m, 4.8e-4 rad, 1.3e-3 m/s;
/// tug 2 9.3e-5 m, 2.0e-3 rad, 7.7e-3 m/s, while the plant's towing angles change
/// by up to 0.025 rad and the lines' bearings by up to 0.052 rad. The errors are
/// those of a line force turned by that change (e.g. ship: 3 N turned by 0.025 rad
/// is 0.075 N, 2.9e-3 m/s^2 on 25.8 kg at the end of the second); the model's own
/// discretisation contributes 1e-10 (`default_substep_...`). Asserted with a
/// margin of about 2: ship within 0.2 mm, 3 mrad, 0.01; tugs within 0.2 mm,
/// 4 mrad, 0.015.
#[test]
fn one_sample_agrees_with_the_plant() {
    let ship = [2e-4, 3e-3, 1e-2];
    let tug = [2e-4, 4e-3, 1.5e-2];
    let cases = [
        (Motion::Manoeuvring, Thrust::HoldFormation, ALPHAS[0]),
        (Motion::Manoeuvring, Thrust::HoldFormation, ALPHAS[1]),
        (Motion::Manoeuvring, Thrust::Fixed, ALPHAS[0]),
        (Motion::Manoeuvring, Thrust::Fixed, ALPHAS[1]),
        (Motion::Surge, Thrust::Fixed, ALPHAS[1]),
    ];
    for hull in MODELS {
        for (motion, thrust, alpha) in cases {
            for dt in [0.01, 0.1] {
                let (e, c) = compare(hull, alpha, motion, thrust, 1.0, 0.1, dt);
                assert!(c.angle < 0.03, "{c:?}");
                check(
                    &format!("{hull:?} {motion:?} {thrust:?} {alpha:?} dt {dt}"),
                    &e,
                    &c,
                    [ship, tug, tug],
                );
            }
        }
    }
}

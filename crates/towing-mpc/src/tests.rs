//! Linearisations against central differences, rollouts against repeated steps,
//! the configuration map against the plant's placement.

use nalgebra::DMatrix;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use towing_model::{HullModel, Scenario, VesselData};

use crate::{
    FormationMap, PredictionHull, PredictionParams, ShipLinearisation, ShipModel, ShipState,
    TowlinePull, TugLinearisation, TugModel,
};

const MODELS: [HullModel; 2] = [HullModel::LinearDamping, HullModel::NonlinearDamping];

/// Central-difference step (m, rad, m/s, rad/s, N, N m alike). With positions up
/// to 20 m the rounding error of a difference is about 4e-15 * 20 / 2e-5 = 4e-9
/// absolute (1e-7 of the smallest columns, about 0.03), the truncation error
/// `step^2 f''' / 6` about 1e-11 relative.
const FD_STEP: f64 = 1e-5;

/// Relative error allowed between a Jacobian column and its central difference,
/// measured against the column's largest entry, but at least [`COLUMN_FLOOR`].
const REL_TOL: f64 = 1e-6;

/// Smallest column scale: a column whose entries are all below 1e-3 (e.g. the
/// towing-angle column when the tension is almost 0) is held to an absolute
/// 1e-9, since the central difference itself is only good to about 4e-10 there.
const COLUMN_FLOOR: f64 = 1e-3;

fn ship_model(model: HullModel) -> ShipModel {
    ShipModel::new(
        model,
        &VesselData::cybership2(),
        PredictionParams::default(),
    )
    .unwrap()
}

fn tug_model(line: usize, model: HullModel) -> TugModel {
    TugModel::new(
        line,
        model,
        &VesselData::titoneri(),
        PredictionParams::default(),
    )
    .unwrap()
}

/// Column-relative error `max_i |J_ij - D_ij| / max(max_i |J_ij|, COLUMN_FLOOR)`.
fn column_error(jac: &DMatrix<f64>, fd: &DMatrix<f64>, j: usize) -> f64 {
    let scale = jac.column(j).amax().max(COLUMN_FLOOR);
    (jac.column(j) - fd.column(j)).amax() / scale
}

/// Central difference of `f` along variable `j` of `z`.
fn central<const N: usize>(f: impl Fn(&[f64; N]) -> [f64; 6], z: &[f64; N], j: usize) -> [f64; 6] {
    let (mut p, mut m) = (*z, *z);
    p[j] += FD_STEP;
    m[j] -= FD_STEP;
    let (fp, fm) = (f(&p), f(&m));
    let width = p[j] - m[j];
    std::array::from_fn(|i| (fp[i] - fm[i]) / width)
}

/// Signs of `v` and `r` at every RK4 stage: the `|v|`, `|r|` terms of the
/// nonlinear damping have kinks in their derivatives at 0.
fn kink_pattern(ship: &ShipModel, x: &ShipState, u: &[f64; 4]) -> Vec<(bool, bool)> {
    ship.stage_points(x, u)
        .iter()
        .map(|p| (p[4] > 0.0, p[5] > 0.0))
        .collect()
}

fn ship_jacobian(lin: &ShipLinearisation) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(6, 10);
    j.view_mut((0, 0), (6, 6)).copy_from(&lin.a);
    j.view_mut((0, 6), (6, 4)).copy_from(&lin.b);
    j
}

fn tug_jacobian(lin: &TugLinearisation) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(6, 11);
    j.view_mut((0, 0), (6, 6)).copy_from(&lin.a);
    j.view_mut((0, 6), (6, 3)).copy_from(&lin.b);
    j.view_mut((0, 9), (6, 2)).copy_from(&lin.e);
    j
}

/// Checks a ship linearisation at `z = [x, u]` against central differences;
/// returns the largest column error and the number of columns skipped because the
/// difference straddles a kink of the damping.
fn check_ship(ship: &ShipModel, nonlinear: bool, z: &[f64; 10]) -> (f64, usize) {
    let x: ShipState = std::array::from_fn(|i| z[i]);
    let u: [f64; 4] = std::array::from_fn(|i| z[6 + i]);
    let lin = ship.step_linearised(&x, &u);
    assert_eq!(lin.x_next, ship.step(&x, &u), "x_next is the plain step");
    let jac = ship_jacobian(&lin);
    let step = |z: &[f64; 10]| {
        ship.step(
            &std::array::from_fn(|i| z[i]),
            &std::array::from_fn(|i| z[6 + i]),
        )
    };
    let split = |z: &[f64; 10]| -> (ShipState, [f64; 4]) {
        (
            std::array::from_fn(|i| z[i]),
            std::array::from_fn(|i| z[6 + i]),
        )
    };
    let mut worst: f64 = 0.0;
    let mut skipped = 0;
    for j in 0..10 {
        let (mut p, mut m) = (*z, *z);
        p[j] += FD_STEP;
        m[j] -= FD_STEP;
        let (xp, up) = split(&p);
        let (xm, um) = split(&m);
        if ship.hull().jacobian_method() == crate::JacobianMethod::Analytic
            && nonlinear
            && kink_pattern(ship, &xp, &up) != kink_pattern(ship, &xm, &um)
        {
            skipped += 1;
            continue;
        }
        let d = central(step, z, j);
        let fd = DMatrix::from_fn(6, 10, |i, k| if k == j { d[i] } else { 0.0 });
        let e = column_error(&jac, &fd, j);
        assert!(e < REL_TOL, "column {j}: {e:e}\n{}\n{:?}", jac.column(j), d);
        worst = worst.max(e);
    }
    (worst, skipped)
}

fn check_tug(tug: &TugModel, z: &[f64; 11]) -> f64 {
    let split = |z: &[f64; 11]| {
        let x: [f64; 6] = std::array::from_fn(|i| z[i]);
        let tau: [f64; 3] = std::array::from_fn(|i| z[6 + i]);
        let pull = TowlinePull {
            tension: z[9],
            bearing: z[10],
        };
        (x, tau, pull)
    };
    let (x, tau, pull) = split(z);
    let lin = tug.step_linearised(&x, &tau, &pull);
    assert_eq!(lin.x_next, tug.step(&x, &tau, &pull));
    let jac = tug_jacobian(&lin);
    let step = |z: &[f64; 11]| {
        let (x, tau, pull) = split(z);
        tug.step(&x, &tau, &pull)
    };
    (0..11)
        .map(|j| {
            let d = central(step, z, j);
            let fd = DMatrix::from_fn(6, 11, |i, k| if k == j { d[i] } else { 0.0 });
            let e = column_error(&jac, &fd, j);
            assert!(e < REL_TOL, "column {j}: {e:e}\n{}\n{:?}", jac.column(j), d);
            e
        })
        .fold(0.0, f64::max)
}

/// Fixed seed: the cases are the same on every run (bit-identical results).
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(2022),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config(256))]

    /// Ship: `A` (6x6) and `B` (6x4) against central differences of `step`, both
    /// hull models, over the paper's operating range.
    #[test]
    fn ship_jacobians_match_central_differences(
        x in -20.0f64..20.0, y in -20.0f64..20.0, psi in -3.2f64..3.2,
        u in -1.0f64..1.0, v in -0.5f64..0.5, r in -0.5f64..0.5,
        f1 in 0.0f64..3.0, f2 in 0.0f64..3.0,
        a1 in -30.0f64..30.0, a2 in -30.0f64..30.0,
    ) {
        let z = [x, y, psi, u, v, r, f1, f2, a1.to_radians(), a2.to_radians()];
        for model in MODELS {
            let (err, skipped) = check_ship(&ship_model(model), model == HullModel::NonlinearDamping, &z);
            prop_assert!(err < REL_TOL, "{:?}: column error {:e}", model, err);
            // A kink is straddled rarely (linear hull: never; nonlinear: 15 of 4000
            // cases, at most 4 of 10 columns, when measured).
            prop_assert!(skipped <= 4, "{:?}: {} columns skipped", model, skipped);
            if model == HullModel::LinearDamping {
                prop_assert_eq!(skipped, 0);
            }
        }
    }

    /// Tugs (both lines, both hull models): `A` (6x6), `B` (6x3) and the pull
    /// Jacobian (6x2) against central differences of `step`.
    #[test]
    fn tug_jacobians_match_central_differences(
        x in -20.0f64..20.0, y in -20.0f64..20.0, psi in -3.2f64..3.2,
        u in -1.0f64..1.0, v in -0.5f64..0.5, r in -0.5f64..0.5,
        tx in -10.0f64..10.0, ty in -10.0f64..10.0, tn in -10.0f64..10.0,
        tension in 0.0f64..3.0, alpha in -30.0f64..30.0, ship_psi in -3.2f64..3.2,
    ) {
        let z = [x, y, psi, u, v, r, tx, ty, tn, tension, ship_psi + alpha.to_radians()];
        for line in 0..2 {
            for model in MODELS {
                let err = check_tug(&tug_model(line, model), &z);
                prop_assert!(err < REL_TOL, "line {} {:?}: column error {:e}", line, model, err);
            }
        }
    }

    /// The configuration map's Jacobian against central differences.
    #[test]
    fn tug_reference_jacobian_matches_central_differences(
        x in -20.0f64..20.0, y in -20.0f64..20.0, psi in -3.2f64..3.2,
        alpha in -30.0f64..30.0,
    ) {
        let map = FormationMap::from_scenario(&Scenario::paper().unwrap()).unwrap();
        let z = [x, y, psi, alpha.to_radians()];
        for line in 0..2 {
            let (pose, jac) = map.tug_reference_linearised([x, y, psi], z[3], line);
            prop_assert_eq!(pose, map.tug_reference([x, y, psi], z[3], line));
            for j in 0..4 {
                let (mut p, mut m) = (z, z);
                p[j] += FD_STEP;
                m[j] -= FD_STEP;
                let fp = map.tug_reference([p[0], p[1], p[2]], p[3], line);
                let fm = map.tug_reference([m[0], m[1], m[2]], m[3], line);
                let scale = (0..3).map(|i| jac[(i, j)].abs()).fold(1e-12, f64::max);
                for i in 0..3 {
                    let fd = (fp[i] - fm[i]) / (p[j] - m[j]);
                    prop_assert!((fd - jac[(i, j)]).abs() < REL_TOL * scale,
                        "line {} d{}/d{}: {} vs {}", line, i, j, jac[(i, j)], fd);
                }
            }
        }
    }

    /// A user hull (finite-difference partials) linearises like the analytic one.
    #[test]
    fn finite_difference_fallback_agrees_with_the_analytic_jacobians(
        psi in -3.2f64..3.2, u in -1.0f64..1.0, v in -0.5f64..0.5, r in -0.5f64..0.5,
        f1 in 0.0f64..3.0, f2 in 0.0f64..3.0, a1 in -30.0f64..30.0, a2 in -30.0f64..30.0,
    ) {
        let data = VesselData::cybership2();
        for model in MODELS {
            let exact = ship_model(model);
            let custom = ShipModel::with_hull(
                PredictionHull::custom(model.build(&data).unwrap()),
                &data,
                PredictionParams::default(),
            )
            .unwrap();
            let (x, inp) = ([1.0, 2.0, psi, u, v, r], [f1, f2, a1.to_radians(), a2.to_radians()]);
            let (a, b) = (exact.step_linearised(&x, &inp), custom.step_linearised(&x, &inp));
            prop_assert_eq!(a.x_next, b.x_next);
            let scale = ship_jacobian(&a).amax();
            prop_assert!((ship_jacobian(&a) - ship_jacobian(&b)).amax() < 1e-6 * scale);
        }
    }
}

#[test]
fn rollouts_equal_repeated_steps() {
    let ship = ship_model(HullModel::NonlinearDamping);
    let x0 = [-4.9, 7.0, 1.77, 0.2, 0.01, -0.02];
    let inputs = [
        [1.0, 2.0, 0.05, -0.1],
        [1.2, 2.4, 0.1, -0.05],
        [0.8, 2.9, 0.2, 0.0],
    ];
    let path = ship.rollout(&x0, &inputs);
    let mut x = x0;
    for (k, u) in inputs.iter().enumerate() {
        x = ship.step(&x, u);
        assert_eq!(path[k], x, "ship sample {k}");
    }
    let mut buffer = [[0.0; 6]; 3];
    ship.rollout_into(&x0, &inputs, &mut buffer);
    assert_eq!(buffer, path);
    let mut lin = [ShipLinearisation::default(); 3];
    ship.linearise_rollout_into(&x0, &inputs, &mut lin);
    let mut x = x0;
    for (k, u) in inputs.iter().enumerate() {
        assert_eq!(
            lin[k],
            ship.step_linearised(&x, u),
            "ship linearisation {k}"
        );
        assert_eq!(lin[k].x_next, path[k]);
        x = path[k];
    }

    for line in 0..2 {
        let tug = tug_model(line, HullModel::NonlinearDamping);
        let t0 = [-2.0, 6.0, 1.7, 0.2, -0.02, 0.01];
        let tau = [[3.0, 0.2, 0.1], [2.5, -0.4, 0.0], [4.0, 0.0, -0.2]];
        let pulls = [
            TowlinePull::from_plan(2.0, 1.77, 0.1),
            TowlinePull::from_plan(2.2, 1.78, 0.12),
            TowlinePull::from_plan(2.4, 1.79, 0.15),
        ];
        let path = tug.rollout(&t0, &tau, &pulls);
        let mut x = t0;
        for k in 0..3 {
            x = tug.step(&x, &tau[k], &pulls[k]);
            assert_eq!(path[k], x, "tug {line} sample {k}");
        }
        let mut lin = [TugLinearisation::default(); 3];
        tug.linearise_rollout_into(&t0, &tau, &pulls, &mut lin);
        let mut x = t0;
        for k in 0..3 {
            assert_eq!(lin[k], tug.step_linearised(&x, &tau[k], &pulls[k]));
            x = path[k];
        }
    }
}

#[test]
#[should_panic(expected = "rollout buffer length")]
fn rollout_into_refuses_a_short_buffer() {
    let ship = ship_model(HullModel::LinearDamping);
    let mut out = [[0.0; 6]; 2];
    ship.rollout_into(&[0.0; 6], &[[0.0; 4]; 3], &mut out);
}

/// The map at the scenario's formation reproduces the tugs the plant placed
/// (`Scenario::place_tugs` via `formation = { towing_angle_deg = .. }`).
#[test]
fn tug_reference_reproduces_the_placed_tugs() {
    for (a1, a2) in [(0.0, 0.0), (-5.0, 10.0), (20.0, -25.0)] {
        let text = towing_model::PAPER_SCENARIO
            .replace(
                "[tug1]\nformation = { towing_angle_deg = 0.0 }",
                &format!("[tug1]\nformation = {{ towing_angle_deg = {a1} }}"),
            )
            .replace(
                "[tug2]\nformation = { towing_angle_deg = 0.0 }",
                &format!("[tug2]\nformation = {{ towing_angle_deg = {a2} }}"),
            );
        let scenario = Scenario::from_toml_str(&text, "test").unwrap();
        let world = towing_model::World::new(&scenario, scenario.world_config).unwrap();
        let map = FormationMap::from_scenario(&scenario).unwrap();
        let ship = world.ship().eta;
        for (line, alpha_deg) in [(0, a1), (1, a2)] {
            let alpha = world.towline(line).angle;
            let alpha_f64: f64 = alpha_deg;
            assert!(
                (alpha - alpha_f64.to_radians()).abs() < 1e-14,
                "plant angle"
            );
            let pose = map.tug_reference(ship, alpha, line);
            let placed = world.tug(line).eta;
            assert!((pose[0] - placed[0]).abs() < 1e-12, "{line} x");
            assert!((pose[1] - placed[1]).abs() < 1e-12, "{line} y");
            assert!(
                towing_model::wrap_angle(pose[2] - placed[2]).abs() < 1e-14,
                "{line} psi"
            );
            // The line is at its desired length.
            assert!((world.towline(line).length - 1.0).abs() < 1e-12);
        }
    }
}

/// Near psi = pi the reference heading is continuous (not wrapped).
#[test]
fn tug_reference_heading_is_continuous() {
    let map = FormationMap::from_scenario(&Scenario::paper().unwrap()).unwrap();
    let psi = std::f64::consts::PI - 0.01;
    let pose = map.tug_reference([0.0, 0.0, psi], 0.1, 1);
    assert!((pose[2] - (psi + 0.1)).abs() < 1e-15);
}

#[test]
fn references_along_a_trajectory_pair_states_with_held_angles() {
    let scenario = Scenario::paper().unwrap();
    let map = FormationMap::from_scenario(&scenario).unwrap();
    let ship = ship_model(HullModel::NonlinearDamping);
    let x0 = [-4.9, 7.0, 1.77, 0.2, 0.0, 0.0];
    let inputs = [
        [1.0, 2.0, 0.1, -0.1],
        [1.0, 2.0, 0.2, -0.2],
        [1.0, 2.0, 0.3, -0.3],
    ];
    let path = ship.rollout(&x0, &inputs);
    for line in 0..2 {
        let mut refs = [[0.0; 3]; 3];
        map.tug_references_into(line, &path, &inputs, &mut refs);
        for k in 0..3 {
            let eta = [path[k][0], path[k][1], path[k][2]];
            assert_eq!(refs[k], map.tug_reference(eta, inputs[k][2 + line], line));
        }
    }
}

#[test]
fn constructors_validate() {
    let mut bad = VesselData::titoneri();
    bad.mass = -1.0;
    assert_eq!(
        TugModel::new(
            0,
            HullModel::LinearDamping,
            &bad,
            PredictionParams::default()
        )
        .unwrap_err()
        .field,
        "mass"
    );
    assert_eq!(
        TugModel::new(
            2,
            HullModel::LinearDamping,
            &VesselData::titoneri(),
            PredictionParams::default()
        )
        .unwrap_err()
        .field,
        "line"
    );
    let params = PredictionParams {
        sample_time: -1.0,
        integration_step: 0.1,
    };
    assert_eq!(
        ShipModel::new(HullModel::LinearDamping, &VesselData::cybership2(), params)
            .unwrap_err()
            .field,
        "sample_time"
    );
    let ship = VesselData::cybership2();
    let tugs = [VesselData::titoneri(); 2];
    assert_eq!(
        FormationMap::new(&ship, &tugs, [1.0, 0.0])
            .unwrap_err()
            .field,
        "towline2.desired_length"
    );
}

/// At rest with both lines straight (alpha = 0) the ship only surges, by
/// `(F_2 - F_1) / m11` initially; a line turned to starboard turns the bow to
/// starboard.
#[test]
fn ship_load_signs() {
    let ship = ship_model(HullModel::NonlinearDamping);
    let f = ship.derivative(&[0.0, 0.0, 0.3, 0.0, 0.0, 0.0], &[1.0, 3.0, 0.0, 0.0]);
    assert!((f[3] - 2.0 / 25.8).abs() < 1e-15, "{f:?}");
    assert!(f[4] == 0.0 && f[5] == 0.0);
    for u in [[0.0, 2.0, 0.0, 0.2], [2.0, 0.0, 0.2, 0.0]] {
        let tau = ship.towline_loads(&u);
        assert!(tau[2] > 0.0, "{u:?}: {tau:?}");
    }
}

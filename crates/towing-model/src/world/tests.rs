use super::*;
use crate::kinetics::NonlinearDampingHull;
use crate::towline::TowlineModel;
use crate::traffic::ObstacleKind;
use nalgebra::Vector3;
use proptest::prelude::*;
use std::f64::consts::PI;

/// Ship at the origin heading North, tugs in formation (alpha = 0, l_tow = 1 m).
const BASE: &str = r#"
format_version = 1
name = "world-test"

[ship]
x = 0.0
y = 0.0
psi_deg = 0.0

[tug1]
formation = { towing_angle_deg = 0.0 }

[tug2]
formation = { towing_angle_deg = 0.0 }

[towline1]
desired_length = 1.0

[towline2]
desired_length = 1.0

[route]
origin = { x = 0.0, y = 0.0, psi_deg = 0.0 }
waypoints = [{ x = 10.0, y = 0.0, psi_deg = 0.0 }]
destination = { x = 20.0, y = 0.0, psi_deg = 0.0 }
"#;

fn scenario(text: &str) -> Scenario {
    Scenario::from_toml_str(text, "world-test.toml").unwrap()
}

fn world_with(text: &str, config: WorldConfig) -> World {
    World::new(&scenario(text), config).unwrap()
}

fn configs() -> Vec<WorldConfig> {
    let mut out = Vec::new();
    for hull_model in [HullModel::LinearDamping, HullModel::NonlinearDamping] {
        for towline_model in [TowlineModel::IdealWinch, TowlineModel::elastic_default()] {
            out.push(WorldConfig {
                hull_model,
                towline_model,
                ..WorldConfig::default()
            });
        }
    }
    out
}

fn elastic() -> WorldConfig {
    WorldConfig {
        towline_model: TowlineModel::elastic_default(),
        ..WorldConfig::default()
    }
}

fn state_bytes(w: &World) -> Vec<u8> {
    let mut out = Vec::new();
    w.write_state(&mut out);
    out
}

/// Deterministic pseudo-random inputs (a 64-bit LCG), within the actuator limits.
struct Inputs(u64);

impl Inputs {
    fn next_unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn next(&mut self) -> WorldInputs {
        let mut i = WorldInputs::default();
        for tug in 0..2 {
            i.tug_tau[tug] = [
                4.0 * self.next_unit(),
                1.0 * self.next_unit(),
                0.2 * self.next_unit(),
            ];
            i.tension_cmd[tug] = 1.5 + 1.5 * self.next_unit();
        }
        i
    }
}

#[test]
fn at_rest_nothing_moves() {
    for config in configs() {
        let mut w = world_with(BASE, config);
        let initial = [*w.ship(), *w.tug(0), *w.tug(1)];
        for _ in 0..1000 {
            w.step(&WorldInputs::default(), 0.1).unwrap();
        }
        assert!((w.time() - 100.0).abs() < 1e-9);
        assert_eq!([*w.ship(), *w.tug(0), *w.tug(1)], initial, "{config:?}");
        for line in 0..2 {
            let out = w.towline(line);
            assert_eq!(out.tension, 0.0);
            assert!(out.slack);
            assert!((out.length - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn builds_from_the_paper_scenario_and_reports_obstacles() {
    let w = World::new(&Scenario::paper().unwrap(), WorldConfig::default()).unwrap();
    for line in 0..2 {
        let out = w.towline(line);
        assert!((out.length - 1.0).abs() < 1e-12);
        assert!(out.angle.abs() < 1e-12);
    }
    assert_eq!(w.obstacle(0).kind, ObstacleKind::StaticCircle);
    let a = w.obstacle(3);
    assert_eq!(
        (a.kind, a.x, a.y, a.speed),
        (ObstacleKind::VesselEllipse, -19.0, 21.0, 0.07)
    );
    let b = w.obstacle(4);
    assert_eq!(
        (b.kind, b.x, b.y, b.speed),
        (ObstacleKind::None, -22.0, 40.75, 0.0)
    );
    assert_eq!((b.length, b.width), (1.48, 0.48));
    assert_eq!(w.obstacle(6), ObstacleSlot::EMPTY);
    assert_eq!(w.obstacle(7), ObstacleSlot::EMPTY);
}

#[test]
fn obstacles_follow_world_time() {
    let text = format!(
        "{BASE}{}",
        r#"
[[obstacles]]
name = "T"
kind = "ship"
x = 5.0
y = 5.0
length = 1.48
width = 0.48
course_deg = 90.0
speed = 0.1
activation_time = 1.0
"#
    );
    let mut w = world_with(&text, WorldConfig::default());
    assert_eq!(w.obstacle(0).kind, ObstacleKind::None);
    for _ in 0..30 {
        w.step(&WorldInputs::default(), 0.1).unwrap();
    }
    let o = w.obstacle(0);
    assert_eq!(o.kind, ObstacleKind::VesselEllipse);
    assert!((o.y - (5.0 + 0.1 * (w.time() - 1.0))).abs() < 1e-12);
    assert!((o.x - 5.0).abs() < 1e-12);
}

#[test]
#[should_panic(expected = "obstacle slot 8 out of range")]
fn obstacle_slot_beyond_the_fixed_count_panics() {
    let _ = world_with(BASE, WorldConfig::default()).obstacle(MAX_OBSTACLES);
}

#[test]
fn refuses_invalid_configuration_and_edited_scenario() {
    let s = scenario(BASE);
    let config = WorldConfig {
        integration_step: 0.0,
        ..WorldConfig::default()
    };
    match World::new(&s, config) {
        Err(WorldError::Config(e)) => assert_eq!(e.field, "integration_step"),
        other => panic!("{other:?}"),
    }
    let mut edited = s.clone();
    edited.tug_data[1].mass = -1.0;
    match World::new(&edited, WorldConfig::default()) {
        Err(WorldError::Scenario(e)) => assert_eq!(e.path, "vessels.tug2.mass"),
        other => panic!("{other:?}"),
    }
}

/// The forward tug pulls with constant thrust on a constant-tension ideal winch.
#[test]
fn forward_tug_tows_the_ship_with_the_commanded_tension() {
    let config = WorldConfig {
        hull_model: HullModel::LinearDamping,
        ..WorldConfig::default()
    };
    let mut w = world_with(BASE, config);
    let thrust = 5.0;
    let cmd = 2.0;
    let inputs = WorldInputs {
        tug_tau: [[0.0; 3], [thrust, 0.0, 0.0]],
        tension_cmd: [0.0, cmd],
    };
    let x0 = [w.ship().eta[0], w.tug(0).eta[0], w.tug(1).eta[0]];
    let mut last_u = 0.0;
    for step in 0..200 {
        w.step(&inputs, 0.1).unwrap();
        let line2 = w.towline(1);
        assert_eq!(line2.tension, cmd, "taut line holds the command");
        assert!(!line2.slack);
        assert!(line2.angle.abs() < 1e-12, "the tow stays in line");
        let line1 = w.towline(0);
        assert_eq!((line1.tension, line1.slack), (0.0, true));
        // Ship accelerates forward along the line (North), no sway or yaw.
        let ship = w.ship();
        assert!(ship.nu[0] > last_u, "step {step}");
        last_u = ship.nu[0];
        assert_eq!(
            (ship.nu[1], ship.nu[2], ship.eta[1], ship.eta[2]),
            (0.0, 0.0, 0.0, 0.0)
        );
        // The aft tug feels no force at all.
        assert_eq!(*w.tug(0), scenario(BASE).tugs[0]);
    }
    // Momentum balance along North (linear damping, motion along x only):
    // sum m11 u + sum d11 (x - x0) = F_thrust t; the towline force is internal.
    let m11 = [25.8, 18.1, 18.1];
    let d11 = [0.722_53, 2.6416, 2.6416];
    let states = [*w.ship(), *w.tug(0), *w.tug(1)];
    let lhs: f64 = (0..3)
        .map(|i| m11[i] * states[i].nu[0] + d11[i] * (states[i].eta[0] - x0[i]))
        .sum();
    let rhs = thrust * w.time();
    assert!((lhs - rhs).abs() < 1e-9 * rhs, "{lhs} vs {rhs}");
    // Ship alone: m11 u_S + d11 (x_S - x_S0) = T t.
    let ship_lhs = m11[0] * states[0].nu[0] + d11[0] * (states[0].eta[0] - x0[0]);
    assert!((ship_lhs - cmd * w.time()).abs() < 1e-9 * cmd * w.time());
}

#[test]
fn tension_command_is_clamped_to_the_winch_range() {
    let mut w = world_with(BASE, WorldConfig::default());
    let inputs = WorldInputs {
        tug_tau: [[-2.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        tension_cmd: [-1.0, 50.0],
    };
    w.step(&inputs, 0.1).unwrap();
    assert_eq!(w.towline(1).tension, 3.0, "F_max = 3 N");
    assert_eq!(w.towline(0).tension, 0.0);
    assert!(w.towline(0).slack);
}

#[test]
fn tug_forces_saturate_at_the_actuator_limits() {
    let mut a = world_with(BASE, WorldConfig::default());
    let mut b = world_with(BASE, WorldConfig::default());
    let big = WorldInputs {
        tug_tau: [[100.0, -100.0, 100.0], [-1e9, 30.0, -11.0]],
        tension_cmd: [1.0, 1.0],
    };
    let limited = WorldInputs {
        tug_tau: [[10.0, -10.0, 10.0], [-10.0, 10.0, -10.0]],
        tension_cmd: [1.0, 1.0],
    };
    for _ in 0..10 {
        a.step(&big, 0.1).unwrap();
        b.step(&limited, 0.1).unwrap();
    }
    assert_eq!(state_bytes(&a), state_bytes(&b));
}

/// Elastic line: tension = max(0, k (d - l0) + c d_dot) of the state, and the
/// winch regulates it to the command.
#[test]
fn elastic_tension_follows_the_line_law_and_the_winch_regulates_it() {
    let mut w = world_with(BASE, elastic());
    let cmd = 2.0;
    // Tug 2's thrust balances T = 2 N plus its own resistance at the ship's steady
    // speed under 2 N (0.579 m/s, vessels.md). Tug 1 keeps pace on its own: a zero
    // command does not make an elastic line slack by itself (the winch pays out at
    // most 0.2 m/s, so a ship running away from tug 1 would drag it along).
    let inputs = WorldInputs {
        tug_tau: [[2.6416 * 0.579, 0.0, 0.0], [cmd + 2.6416 * 0.579, 0.0, 0.0]],
        tension_cmd: [0.0, cmd],
    };
    let k = 100.0;
    let c = 5.0;
    let mut max_tension: f64 = 0.0;
    for _ in 0..1200 {
        w.step(&inputs, 0.1).unwrap();
        let out = w.towline(1);
        let l0 = w.towline_paid_out_length(1).unwrap();
        let law = if out.length > l0 {
            (k * (out.length - l0) + c * w.towline_length_rate(1)).max(0.0)
        } else {
            0.0
        };
        assert_eq!(out.tension, law);
        assert_eq!(out.slack, law == 0.0);
        max_tension = max_tension.max(out.tension);
    }
    let out = w.towline(1);
    assert!((out.tension - cmd).abs() < 0.01, "{}", out.tension);
    assert!((w.ship().nu[0] - 0.579).abs() < 0.01, "{}", w.ship().nu[0]);
    // Stretch k (d - l0) = T: 2 cm at 2 N.
    let stretch = out.length - w.towline_paid_out_length(1).unwrap();
    assert!((stretch - cmd / k).abs() < 1e-3, "{stretch}");
    assert!(max_tension < 6.0, "{max_tension}");
    // The aft line: the winch paid out while the ship pulled ahead at the start,
    // then tug 1 caught up and the line ended slack (d < l0, zero tension).
    let aft = w.towline(0);
    assert!(aft.slack && aft.tension == 0.0);
    assert!(aft.length < w.towline_paid_out_length(0).unwrap());
}

#[test]
fn elastic_line_goes_slack_when_the_tug_closes_in_faster_than_the_winch() {
    let text = BASE.replacen(
        "[tug2]\nformation = { towing_angle_deg = 0.0 }",
        "[tug2]\nformation = { towing_angle_deg = 0.0 }\nu = -0.5",
        1,
    );
    let mut w = world_with(&text, elastic());
    let inputs = WorldInputs {
        tug_tau: [[0.0; 3]; 2],
        tension_cmd: [0.0, 2.0],
    };
    let l0 = w.towline_paid_out_length(1).unwrap();
    w.step(&inputs, 0.1).unwrap();
    let out = w.towline(1);
    assert!(out.slack);
    assert_eq!(out.tension, 0.0);
    assert!(out.length < 1.0 - 0.04, "{}", out.length);
    // The winch reels in at its speed limit (0.2 m/s) for the whole step.
    let reeled = l0 - w.towline_paid_out_length(1).unwrap();
    assert!((reeled - 0.02).abs() < 1e-12, "{reeled}");
    assert!(out.length < w.towline_paid_out_length(1).unwrap());
    // The ship felt nothing.
    assert_eq!(*w.ship(), scenario(&text).ship);
}

#[test]
fn heading_wraps_consistently_through_pi() {
    for (moment, tug) in [(0.05, 0), (-0.05, 1)] {
        let mut w = world_with(BASE, WorldConfig::default());
        let mut inputs = WorldInputs::default();
        inputs.tug_tau[tug][2] = moment;
        let mut psi = w.tug(tug).eta[2];
        let mut unwrapped = psi;
        let mut wraps = 0;
        for _ in 0..1500 {
            w.step(&inputs, 0.1).unwrap();
            let next = w.tug(tug).eta[2];
            assert!(next > -PI && next <= PI, "{next}");
            let delta = wrap_angle(next - psi);
            // Steady turn in the sign of the moment, small increments.
            assert!(delta * moment > 0.0 && delta.abs() < 0.06, "{delta}");
            if (next - psi).abs() > PI {
                wraps += 1;
            }
            unwrapped += delta;
            psi = next;
        }
        assert!(wraps >= 4, "{wraps} wraps");
        assert!((wrap_angle(unwrapped) - psi).abs() < 1e-9);
        assert!(w.tug(tug).nu[2] * moment > 0.0);
    }
}

#[test]
fn refuses_bad_step_sizes_and_leaves_the_state_unchanged() {
    let mut w = world_with(BASE, WorldConfig::default());
    let before = state_bytes(&w);
    // 1e5 s at 0.01 s would need 1e7 substeps (> MAX_SUBSTEPS).
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY, 1e300, 1e5] {
        match w.step(&WorldInputs::default(), h) {
            Err(StepError::InvalidStep(got)) => assert_eq!(got.to_bits(), h.to_bits()),
            other => panic!("h = {h}: {other:?}"),
        }
    }
    assert_eq!(state_bytes(&w), before);
}

#[test]
fn refuses_non_finite_inputs_and_leaves_the_state_unchanged() {
    let mut w = world_with(BASE, WorldConfig::default());
    w.step(&Inputs(1).next(), 0.1).unwrap();
    let before = state_bytes(&w);
    let mut bad = WorldInputs::default();
    bad.tug_tau[1][2] = f64::INFINITY;
    match w.step(&bad, 0.1) {
        Err(StepError::NonFinite { what }) => assert!(what.contains("tug_tau[1][2]"), "{what}"),
        other => panic!("{other:?}"),
    }
    let mut bad = WorldInputs::default();
    bad.tension_cmd[0] = f64::NAN;
    match w.step(&bad, 0.1) {
        Err(StepError::NonFinite { what }) => assert!(what.contains("tension_cmd[0]"), "{what}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(state_bytes(&w), before);
}

/// A state that overflows during integration (Coriolis terms ~ nu^2 beyond f64)
/// makes the step fail atomically.
#[test]
fn overflowing_step_is_refused_atomically() {
    let mut w = world_with(BASE, WorldConfig::default());
    let mut bytes = state_bytes(&w);
    // ship.u and ship.v (state fields 3 and 4 after magic, version, fingerprint, time).
    for field in [3, 4] {
        let at = 8 + 4 + 8 + 8 + 8 * field;
        bytes[at..at + 8].copy_from_slice(&1e200f64.to_le_bytes());
    }
    w.read_state(&bytes).unwrap();
    let before = state_bytes(&w);
    match w.step(&WorldInputs::default(), 0.1) {
        Err(StepError::NonFinite { what }) => assert!(what.starts_with("ship."), "{what}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(state_bytes(&w), before);
    assert_eq!(w.time(), 0.0);
}

#[test]
fn write_read_state_reproduces_a_trajectory_bit_for_bit() {
    for config in configs() {
        let mut a = world_with(BASE, config);
        let mut inputs = Inputs(42);
        for _ in 0..30 {
            a.step(&inputs.next(), 0.1).unwrap();
        }
        let saved = state_bytes(&a);
        assert_eq!(saved.len(), STATE_BYTES);
        let rng_state = inputs.0;
        let mut trajectory = Vec::new();
        for _ in 0..30 {
            a.step(&inputs.next(), 0.1).unwrap();
            trajectory.push(state_bytes(&a));
        }
        let mut b = world_with(BASE, config);
        b.read_state(&saved).unwrap();
        assert_eq!(state_bytes(&b), saved);
        assert_eq!(b.towline(1), {
            let mut c = world_with(BASE, config);
            c.read_state(&saved).unwrap();
            c.towline(1)
        });
        let mut inputs = Inputs(rng_state);
        for expected in &trajectory {
            b.step(&inputs.next(), 0.1).unwrap();
            assert_eq!(&state_bytes(&b), expected, "{config:?}");
        }
    }
}

#[test]
fn read_state_refuses_foreign_or_corrupt_states() {
    let w = world_with(BASE, WorldConfig::default());
    let saved = state_bytes(&w);
    let mut other = world_with(BASE, elastic());
    let before = state_bytes(&other);
    assert!(other
        .read_state(&saved)
        .unwrap_err()
        .contains("different scenario or configuration"));
    assert!(other
        .read_state(&saved[..10])
        .unwrap_err()
        .contains("bytes"));
    let mut same = world_with(BASE, WorldConfig::default());
    let mut bad = saved.clone();
    bad[0] = b'X';
    assert!(same.read_state(&bad).unwrap_err().contains("magic"));
    let mut bad = saved.clone();
    bad[8] = 9;
    assert!(same.read_state(&bad).unwrap_err().contains("version"));
    let mut bad = saved.clone();
    let at = 8 + 4 + 8 + 8 + 8 * 2; // ship.psi
    bad[at..at + 8].copy_from_slice(&4.0f64.to_le_bytes());
    assert!(same.read_state(&bad).unwrap_err().contains("ship.psi"));
    bad[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(same.read_state(&bad).unwrap_err().contains("not finite"));
    assert_eq!(state_bytes(&other), before);
    assert_eq!(state_bytes(&same), saved);
}

#[test]
fn two_runs_are_bit_identical() {
    for config in configs() {
        let mut a = world_with(BASE, config);
        let mut b = world_with(BASE, config);
        let (mut ia, mut ib) = (Inputs(7), Inputs(7));
        for _ in 0..300 {
            a.step(&ia.next(), 0.1).unwrap();
            b.step(&ib.next(), 0.1).unwrap();
            assert_eq!(state_bytes(&a), state_bytes(&b));
        }
        // And the run did something.
        assert!(a.ship().eta[0].abs() + a.ship().eta[1].abs() > 0.01);
    }
}

#[test]
fn substeps_split_the_step_evenly() {
    // One 0.1 s step equals ten 0.01 s steps up to rounding (same substeps).
    let inputs = Inputs(3).next();
    let mut a = world_with(BASE, WorldConfig::default());
    let mut b = world_with(BASE, WorldConfig::default());
    a.step(&inputs, 0.1).unwrap();
    for _ in 0..10 {
        b.step(&inputs, 0.01).unwrap();
    }
    for (x, y) in [
        (a.ship(), b.ship()),
        (a.tug(0), b.tug(0)),
        (a.tug(1), b.tug(1)),
    ] {
        for k in 0..3 {
            assert!((x.eta[k] - y.eta[k]).abs() < 1e-12);
            assert!((x.nu[k] - y.nu[k]).abs() < 1e-12);
        }
    }
}

fn kinetic_energies(w: &World, config: WorldConfig) -> [f64; 3] {
    let data = [*w.ship_data(), *w.tug_data(0), *w.tug_data(1)];
    let states = [*w.ship(), *w.tug(0), *w.tug(1)];
    let mut out = [0.0; 3];
    for i in 0..3 {
        let hull = config.hull_model.build(&data[i]).unwrap();
        out[i] = hull.kinetic_energy(&Vector3::from(states[i].nu));
    }
    out
}

/// Free decay text: tugs far apart from the ship (explicit poses), given initial
/// velocities; ship in pure surge.
fn free_decay_text(set: &str, ship_u: f64, tug: [f64; 3]) -> String {
    format!(
        r#"
format_version = 1
name = "free-decay"
[ship]
x = 0.0
y = 0.0
psi_deg = 30.0
u = {ship_u}
[tug1]
x = -20.0
y = 0.0
psi_deg = -120.0
u = {}
v = {}
r_deg_s = {}
[tug2]
x = 20.0
y = 5.0
psi_deg = 170.0
u = {}
v = {}
r_deg_s = {}
[towline1]
desired_length = 1.0
[towline2]
desired_length = 1.0
[route]
origin = {{ x = 0.0, y = 0.0, psi_deg = 0.0 }}
waypoints = [{{ x = 10.0, y = 0.0, psi_deg = 0.0 }}]
destination = {{ x = 20.0, y = 0.0, psi_deg = 0.0 }}
[vessels.tug1]
damping_set = "{set}"
[vessels.tug2]
damping_set = "{set}"
"#,
        tug[0],
        tug[1],
        tug[2].to_degrees(),
        -tug[0],
        tug[1],
        -tug[2].to_degrees(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Free decay (no thrust, no tension): kinetic energy never increases for the
    /// vessels and velocity ranges where sym(D) is positive definite: the tugs
    /// (sets A and B, any velocity) and the ship in pure surge. See
    /// `kinetics` for the ship's sway-yaw counter-example.
    #[test]
    fn kinetic_energy_never_increases_in_free_decay(
        ship_u in -1.5f64..1.5,
        u in -1.5f64..1.5,
        v in -0.8f64..0.8,
        r in -1.5f64..1.5,
        set_b in proptest::bool::ANY,
        linear in proptest::bool::ANY,
    ) {
        let config = WorldConfig {
            hull_model: if linear { HullModel::LinearDamping } else { HullModel::NonlinearDamping },
            ..WorldConfig::default()
        };
        let text = free_decay_text(if set_b { "B" } else { "A" }, ship_u, [u, v, r]);
        let mut w = World::new(&Scenario::from_toml_str(&text, "free-decay").unwrap(), config).unwrap();
        let mut energy = kinetic_energies(&w, config);
        for _ in 0..150 {
            w.step(&WorldInputs::default(), 0.1).unwrap();
            let next = kinetic_energies(&w, config);
            for i in 0..3 {
                prop_assert!(next[i] <= energy[i], "vessel {i}: {} -> {}", energy[i], next[i]);
            }
            energy = next;
            prop_assert!(w.towline(0).slack && w.towline(1).slack);
        }
        // Pure surge stays pure surge.
        prop_assert_eq!((w.ship().nu[1], w.ship().nu[2]), (0.0, 0.0));
    }
}

/// The benchmark's scenario really has 8 obstacles, all active from t = 0.
#[test]
fn bench_scenario_has_eight_active_obstacles() {
    let s = Scenario::from_toml_str(
        include_str!("../../benches/eight_obstacles.toml"),
        "benches/eight_obstacles.toml",
    )
    .unwrap();
    let w = World::new(&s, s.world_config).unwrap();
    assert_eq!(w.obstacles().len(), MAX_OBSTACLES);
    for slot in 0..MAX_OBSTACLES {
        assert_ne!(w.obstacle(slot).kind, ObstacleKind::None, "slot {slot}");
    }
    assert_eq!(w.config().hull_model, HullModel::NonlinearDamping);
}

fn builtin_hulls(scenario: &Scenario, model: HullModel) -> [Box<dyn HullDynamics>; 3] {
    [
        model.build(&scenario.ship_data).unwrap(),
        model.build(&scenario.tug_data[0]).unwrap(),
        model.build(&scenario.tug_data[1]).unwrap(),
    ]
}

/// Ship, tug 1 and tug 2 states after 200 steps of `Inputs(11)` from BASE, for
/// each of `configs()`, recorded (as bits) from the pre-trait implementation.
const PINNED_TRAJECTORY_ENDS: [[u64; 18]; 4] = [
    [
        4594804616932409817,
        13829204579104367791,
        4603073373245058545,
        13814066627394855902,
        13802530172718572190,
        4583273464977373616,
        13823026253125373904,
        13826571835901350804,
        13833650317966607502,
        4583139333844473246,
        13788577689728979389,
        13817170915269402415,
        4607663437542256465,
        13824400167855588925,
        4593261005023507078,
        4586197077676273593,
        4569747681749289031,
        4598520169323776778,
    ],
    [
        4598974170941302126,
        13823675419775475777,
        4603456760292218557,
        13807007173334700994,
        13810990855535793177,
        4581169855506530897,
        13826369845481738876,
        13822734257289209317,
        13829866907917793906,
        4583551553358198487,
        13783554888880038430,
        13816160060484197427,
        4608533590357918736,
        4594989855718218662,
        4600074205465088835,
        13799794336870068431,
        4564943455769422537,
        4590531831208421097,
    ],
    [
        4592041056146074929,
        13828746188974667602,
        4603690231407135470,
        13814986415022991050,
        13808361272082370569,
        4592636736313840942,
        13823447415609950903,
        13825149411473461973,
        13833960846926454604,
        13806903305476815951,
        13794939201624150488,
        13817739039691883717,
        4607611200710495918,
        13823215624043943318,
        4595224345942931595,
        4581090701571648346,
        4567564942275356424,
        4598881176609644617,
    ],
    [
        4598729355265921880,
        13823256008687956826,
        4603262016188717551,
        13806811880859179118,
        13809473661969211022,
        4575650902130522139,
        13826622231450248643,
        13822252233231033087,
        13829673691998239020,
        4582200954250920962,
        13784833885893688487,
        13815716777168162469,
        4608510767151660964,
        4595201988156554173,
        4599899534795325226,
        13798877613390652018,
        4564917634816481091,
        4589756720492525038,
    ],
];

fn vessel_bits(w: &World) -> Vec<u64> {
    [*w.ship(), *w.tug(0), *w.tug(1)]
        .iter()
        .flat_map(|s| s.eta.iter().chain(s.nu.iter()).map(|v| v.to_bits()))
        .collect()
}

/// Both hull models through the trait objects reproduce the former trajectories
/// bit for bit, with `World::new` and with `World::with_hulls` given the same
/// built-in hulls.
#[test]
fn trajectories_are_unchanged_by_the_hull_trait() {
    let s = scenario(BASE);
    for (config, expected) in configs().into_iter().zip(PINNED_TRAJECTORY_ENDS) {
        let mut a = World::new(&s, config).unwrap();
        let mut b = World::with_hulls(&s, config, builtin_hulls(&s, config.hull_model)).unwrap();
        assert_eq!(state_bytes(&a), state_bytes(&b), "same fingerprint");
        let mut inputs = Inputs(11);
        for _ in 0..200 {
            let i = inputs.next();
            a.step(&i, 0.1).unwrap();
            b.step(&i, 0.1).unwrap();
            assert_eq!(state_bytes(&a), state_bytes(&b));
        }
        assert_eq!(vessel_bits(&a), expected, "{config:?}");
    }
}

/// A user hull: CyberShip II with twice the identified (nonlinear) damping. Keeps
/// the trait's defaults for C, nu_dot and the energies.
#[derive(Debug, Clone)]
struct DoubledDamping(NonlinearDampingHull);

impl HullDynamics for DoubledDamping {
    fn mass_matrix(&self) -> &Matrix3<f64> {
        self.0.mass_matrix()
    }
    fn mass_matrix_inv(&self) -> &Matrix3<f64> {
        self.0.mass_matrix_inv()
    }
    fn damping_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        self.0.damping_matrix(nu) * 2.0
    }
    fn clone_box(&self) -> Box<dyn HullDynamics> {
        Box::new(self.clone())
    }
}

fn doubled_damping_hulls(s: &Scenario) -> [Box<dyn HullDynamics>; 3] {
    let [_, tug1, tug2] = builtin_hulls(s, HullModel::NonlinearDamping);
    [
        Box::new(DoubledDamping(
            NonlinearDampingHull::new(&s.ship_data).unwrap(),
        )),
        tug1,
        tug2,
    ]
}

/// Tug 2 tows with 2 N for 300 s: the identified ship reaches the steady speed of
/// 2 N (0.579 m/s, vessels.md), the doubled-damping ship that of 1 N (0.426 m/s,
/// since 2 d11(u) u = 2 N), both within 1 %, and is slower all the way.
#[test]
fn user_hull_with_doubled_damping_tows_slower() {
    let s = scenario(BASE);
    let config = WorldConfig::default();
    let mut identified = World::new(&s, config).unwrap();
    let mut doubled = World::with_hulls(&s, config, doubled_damping_hulls(&s)).unwrap();
    assert_eq!(
        doubled.hull(0).damping_matrix(&Vector3::new(0.5, 0.0, 0.0))[(0, 0)],
        2.0 * identified
            .hull(0)
            .damping_matrix(&Vector3::new(0.5, 0.0, 0.0))[(0, 0)]
    );
    let inputs = WorldInputs {
        tug_tau: [[0.0; 3], [5.0, 0.0, 0.0]],
        tension_cmd: [0.0, 2.0],
    };
    for _ in 0..3000 {
        identified.step(&inputs, 0.1).unwrap();
        doubled.step(&inputs, 0.1).unwrap();
        assert_eq!(doubled.towline(1).tension, 2.0);
        assert!(doubled.ship().nu[0] < identified.ship().nu[0]);
        assert!(doubled.ship().eta[0] < identified.ship().eta[0]);
    }
    let (u_identified, u_doubled) = (identified.ship().nu[0], doubled.ship().nu[0]);
    assert!(
        (u_identified - 0.579).abs() < 0.01 * 0.579,
        "{u_identified}"
    );
    assert!((u_doubled - 0.426).abs() < 0.01 * 0.426, "{u_doubled}");
    // Still a straight tow.
    assert_eq!(
        (
            doubled.ship().nu[1],
            doubled.ship().nu[2],
            doubled.ship().eta[2]
        ),
        (0.0, 0.0, 0.0)
    );
}

/// Everything else works with user hulls: determinism, cloning, state round trip,
/// and the fingerprint tells the worlds apart.
#[test]
fn user_hulls_are_deterministic_and_round_trip_the_state() {
    let s = scenario(BASE);
    for config in configs() {
        let mut a = World::with_hulls(&s, config, doubled_damping_hulls(&s)).unwrap();
        let mut b = World::with_hulls(&s, config, doubled_damping_hulls(&s)).unwrap();
        let mut inputs = Inputs(5);
        for _ in 0..30 {
            let i = inputs.next();
            a.step(&i, 0.1).unwrap();
            b.step(&i, 0.1).unwrap();
            assert_eq!(state_bytes(&a), state_bytes(&b), "{config:?}");
        }
        let saved = state_bytes(&a);
        let rng_state = inputs.0;
        let mut clone = a.clone();
        let mut trajectory = Vec::new();
        for _ in 0..30 {
            let i = inputs.next();
            a.step(&i, 0.1).unwrap();
            clone.step(&i, 0.1).unwrap();
            trajectory.push(state_bytes(&a));
            assert_eq!(state_bytes(&clone), state_bytes(&a));
        }
        let mut c = World::with_hulls(&s, config, doubled_damping_hulls(&s)).unwrap();
        c.read_state(&saved).unwrap();
        assert_eq!(state_bytes(&c), saved);
        let mut inputs = Inputs(rng_state);
        for expected in &trajectory {
            c.step(&inputs.next(), 0.1).unwrap();
            assert_eq!(&state_bytes(&c), expected, "{config:?}");
        }
        // The built-in hulls (same scenario and configuration) refuse the state,
        // and the user-hull world refuses theirs.
        let mut builtin = World::new(&s, config).unwrap();
        let builtin_state = state_bytes(&builtin);
        assert!(builtin
            .read_state(&saved)
            .unwrap_err()
            .contains("different scenario or configuration"));
        assert!(c
            .read_state(&builtin_state)
            .unwrap_err()
            .contains("different scenario or configuration"));
    }
    // The hull_model label is part of the configuration fingerprint.
    let linear = WorldConfig {
        hull_model: HullModel::LinearDamping,
        ..WorldConfig::default()
    };
    let saved = state_bytes(&World::with_hulls(&s, linear, doubled_damping_hulls(&s)).unwrap());
    let mut other =
        World::with_hulls(&s, WorldConfig::default(), doubled_damping_hulls(&s)).unwrap();
    assert!(other.read_state(&saved).is_err());
}

/// A hull with given matrices, for the checks of `World::with_hulls`.
#[derive(Debug, Clone)]
struct MatrixHull {
    m: Matrix3<f64>,
    m_inv: Matrix3<f64>,
    skew_c: bool,
}

impl HullDynamics for MatrixHull {
    fn mass_matrix(&self) -> &Matrix3<f64> {
        &self.m
    }
    fn mass_matrix_inv(&self) -> &Matrix3<f64> {
        &self.m_inv
    }
    fn damping_matrix(&self, _nu: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::identity()
    }
    fn coriolis_matrix(&self, nu: &Vector3<f64>) -> Matrix3<f64> {
        let c = crate::kinetics::C(&self.m, nu);
        if self.skew_c {
            c
        } else {
            c.abs()
        }
    }
    fn clone_box(&self) -> Box<dyn HullDynamics> {
        Box::new(self.clone())
    }
}

#[test]
fn with_hulls_refuses_hulls_that_break_the_documented_properties() {
    let s = scenario(BASE);
    let good = VesselData::titoneri().mass_matrix();
    let hull = |m: Matrix3<f64>, m_inv: Matrix3<f64>, skew_c: bool| -> Box<dyn HullDynamics> {
        Box::new(MatrixHull { m, m_inv, skew_c })
    };
    let good_inv = good.try_inverse().unwrap();
    let mut asymmetric = good;
    asymmetric[(1, 2)] += 0.1;
    let indefinite = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0);
    let cases = [
        (hull(good, good_inv, true), None),
        (
            hull(asymmetric, asymmetric.try_inverse().unwrap(), true),
            Some("hull.tug2.mass_matrix"),
        ),
        (
            hull(indefinite, indefinite, true),
            Some("hull.tug2.mass_matrix"),
        ),
        (
            hull(good, good_inv * 1.01, true),
            Some("hull.tug2.mass_matrix_inv"),
        ),
        (
            hull(good, good_inv, false),
            Some("hull.tug2.coriolis_matrix"),
        ),
    ];
    for (tug2, expected) in cases {
        let [ship, tug1, _] = builtin_hulls(&s, HullModel::NonlinearDamping);
        match (
            World::with_hulls(&s, WorldConfig::default(), [ship, tug1, tug2]),
            expected,
        ) {
            (Ok(w), None) => assert!(format!("{:?}", w.hull(2)).contains("MatrixHull")),
            (Err(WorldError::Hull(e)), Some(field)) => {
                assert_eq!(e.field, field, "{e}");
                assert!(WorldError::Hull(e)
                    .to_string()
                    .starts_with("invalid hull model"));
            }
            (other, _) => panic!("{other:?}"),
        }
    }
    // The scenario and the configuration are still validated.
    let config = WorldConfig {
        integration_step: 0.0,
        ..WorldConfig::default()
    };
    assert!(matches!(
        World::with_hulls(&s, config, builtin_hulls(&s, HullModel::LinearDamping)),
        Err(WorldError::Config(_))
    ));
}

#[test]
#[should_panic(expected = "hull index 3 out of range")]
fn hull_index_beyond_the_tugs_panics() {
    let _ = world_with(BASE, WorldConfig::default()).hull(3);
}

// ---------------------------------------------------------------------------
// Range activation of target ships.

/// The forward tug pulls the tow North (ship from x = 0, accelerating at about
/// 0.08 m/s^2).
const PULL: WorldInputs = WorldInputs {
    tug_tau: [[0.0; 3], [5.0, 0.0, 0.0]],
    tension_cmd: [0.0, 2.0],
};

/// `BASE` with one target ship per `(x, y, trigger lines)`, all heading East at
/// 0.1 m/s.
fn with_targets(targets: &[(f64, f64, &str)]) -> String {
    let mut text = BASE.to_owned();
    for (i, (x, y, lines)) in targets.iter().enumerate() {
        text.push_str(&format!(
            "\n[[obstacles]]\nname = \"T{i}\"\nkind = \"ship\"\nx = {x:?}\ny = {y:?}\n\
             length = 1.48\nwidth = 0.48\ncourse_deg = 90.0\nspeed = 0.1\n{lines}\n"
        ));
    }
    text
}

fn ship_distance_to(w: &World, x: f64, y: f64) -> f64 {
    (w.ship().eta[0] - x).hypot(w.ship().eta[1] - y)
}

/// Steps `PULL` until slot 0 is active; returns the world (at the activation
/// step) and the number of steps.
fn pull_until_active(text: &str) -> (World, usize) {
    let mut w = world_with(text, WorldConfig::default());
    for n in 1..=200 {
        w.step(&PULL, 0.1).unwrap();
        if w.activation_time(0).is_some() {
            return (w, n);
        }
    }
    panic!("slot 0 never activated");
}

#[test]
fn range_target_activates_at_the_first_step_end_within_range_and_not_before() {
    // Spawn 3.61 m from the ship's start; the range 3.2 m is reached when the
    // ship has moved about 0.89 m North (after about 5 s).
    let (sx, sy, range) = (2.0, 3.0, 3.2);
    let text = with_targets(&[(sx, sy, "activation_range = 3.2")]);
    let mut w = world_with(&text, WorldConfig::default());
    assert!(ship_distance_to(&w, sx, sy) > range);
    assert_eq!(w.obstacle(0).kind, ObstacleKind::None);
    let mut steps = 0;
    loop {
        w.step(&PULL, 0.1).unwrap();
        steps += 1;
        let d = ship_distance_to(&w, sx, sy);
        let o = w.obstacle(0);
        if d > range {
            // Not before: outside the range, nothing.
            assert_eq!(w.activation_time(0), None, "step {steps}, d = {d}");
            assert_eq!(
                (o.kind, o.x, o.y, o.speed),
                (ObstacleKind::None, sx, sy, 0.0)
            );
            assert!(steps < 200, "never came within range");
            continue;
        }
        // The first step end within range: active now, at the spawn position.
        assert_eq!(w.activation_time(0), Some(w.time()));
        assert_eq!(
            (o.kind, o.x, o.y, o.speed),
            (ObstacleKind::VesselEllipse, sx, sy, 0.1)
        );
        break;
    }
    assert!((20..100).contains(&steps), "{steps}");
    let t_a = w.time();
    // Then it moves exactly from there, and stays active even when the ship
    // leaves the range (here: the ship keeps going North, past it).
    for _ in 0..300 {
        w.step(&PULL, 0.1).unwrap();
    }
    assert!(ship_distance_to(&w, sx, sy) > range);
    let o = w.obstacle(0);
    assert_eq!(w.activation_time(0), Some(t_a));
    assert_eq!(o.kind, ObstacleKind::VesselEllipse);
    assert!((o.y - (sy + 0.1 * (w.time() - t_a))).abs() < 1e-12);
    assert_eq!(o.x, sx);
}

#[test]
fn range_target_within_range_at_the_start_is_active_from_t_0() {
    let text = with_targets(&[(1.0, 1.0, "activation_range = 2.0")]);
    let w = world_with(&text, WorldConfig::default());
    assert_eq!(w.activation_time(0), Some(0.0));
    assert_eq!(w.obstacle(0).kind, ObstacleKind::VesselEllipse);
}

#[test]
fn range_target_far_away_never_activates() {
    let text = with_targets(&[(200.0, 3.0, "activation_range = 3.2")]);
    let mut w = world_with(&text, WorldConfig::default());
    for _ in 0..300 {
        w.step(&PULL, 0.1).unwrap();
    }
    assert_eq!(w.activation_time(0), None);
    assert_eq!(w.obstacle(0).kind, ObstacleKind::None);
}

#[test]
fn time_and_range_activate_whichever_comes_first() {
    // When does the range alone trigger it?
    let (_, n) = pull_until_active(&with_targets(&[(2.0, 3.0, "activation_range = 3.2")]));
    let t_range = n as f64 * 0.1;
    // Time first, inside the step that ends within range: exactly at the time.
    let early = t_range - 0.05;
    let text = with_targets(&[(
        2.0,
        3.0,
        &format!("activation_range = 3.2\nactivation_time = {early:?}"),
    )]);
    let (w, m) = pull_until_active(&text);
    assert_eq!(m, n);
    assert_eq!(w.activation_time(0), Some(early));
    let o = w.obstacle(0);
    assert!((o.y - (3.0 + 0.1 * (w.time() - early))).abs() < 1e-12);
    assert!(o.y > 3.0);
    // Range first: at the step end, although the time comes a little later.
    let late = t_range + 0.05;
    let text = with_targets(&[(
        2.0,
        3.0,
        &format!("activation_range = 3.2\nactivation_time = {late:?}"),
    )]);
    let (mut w, m) = pull_until_active(&text);
    assert_eq!(m, n);
    let t_a = w.activation_time(0).unwrap();
    assert!((t_a - t_range).abs() < 1e-9, "{t_a} vs {t_range}");
    assert_eq!((w.obstacle(0).x, w.obstacle(0).y), (2.0, 3.0));
    // ... and the later time does not restart it.
    w.step(&PULL, 0.1).unwrap();
    assert_eq!(w.activation_time(0), Some(t_a));
    assert!((w.obstacle(0).y - (3.0 + 0.1 * (w.time() - t_a))).abs() < 1e-12);
    // Time only: unaffected by the ship's range.
    let text = with_targets(&[(2.0, 3.0, &format!("activation_time = {late:?}"))]);
    let (w, m) = pull_until_active(&text);
    assert_eq!(m, n + 1);
    assert_eq!(w.activation_time(0), Some(late));
}

#[test]
fn activation_survives_write_and_read_state() {
    let text = with_targets(&[
        (2.0, 3.0, "activation_range = 3.2"),
        (3.0, -3.0, "activation_range = 3.3"),
    ]);
    // Saved 10 steps in, before either target is active.
    let mut a = world_with(&text, WorldConfig::default());
    for _ in 0..10 {
        a.step(&PULL, 0.1).unwrap();
    }
    assert_eq!((a.activation_time(0), a.activation_time(1)), (None, None));
    let before = state_bytes(&a);
    assert_eq!(before.len(), STATE_BYTES);
    let mut trajectory = Vec::new();
    for _ in 0..100 {
        a.step(&PULL, 0.1).unwrap();
        trajectory.push((state_bytes(&a), a.obstacle(0), a.obstacle(1)));
    }
    let t0 = a.activation_time(0).unwrap();
    let t1 = a.activation_time(1).unwrap();
    assert!(t1 > t0, "{t0} {t1}");
    // A world restored from before the activation activates as the original did.
    let mut b = world_with(&text, WorldConfig::default());
    b.read_state(&before).unwrap();
    for expected in &trajectory {
        b.step(&PULL, 0.1).unwrap();
        assert_eq!(&(state_bytes(&b), b.obstacle(0), b.obstacle(1)), expected);
    }
    // A fresh world (ship at the start, out of range) restored from after the
    // activation keeps the activation times and the targets' positions.
    let after = state_bytes(&a);
    let mut c = world_with(&text, WorldConfig::default());
    assert_eq!(c.activation_time(0), None);
    c.read_state(&after).unwrap();
    assert_eq!(
        (c.activation_time(0), c.activation_time(1)),
        (Some(t0), Some(t1))
    );
    assert_eq!(
        (c.obstacle(0), c.obstacle(1)),
        (a.obstacle(0), a.obstacle(1))
    );
    assert_eq!(state_bytes(&c), after);
    // ... and reading the earlier state back clears them.
    c.read_state(&before).unwrap();
    assert_eq!(
        (c.activation_time(0), c.obstacle(0).kind),
        (None, ObstacleKind::None)
    );
}

#[test]
fn read_state_refuses_bad_activation_times() {
    // Slot 0 a static hazard, slot 1 a range target activated at t_a.
    let mut text = with_targets(&[(2.0, 3.0, "activation_range = 3.2")]);
    text = text.replacen(
        "\n[[obstacles]]",
        "\n[[obstacles]]\nname = \"rock\"\nkind = \"static\"\nx = 9.0\ny = 9.0\ndiameter = 1.0\n\n[[obstacles]]",
        1,
    );
    let mut a = world_with(&text, WorldConfig::default());
    while a.activation_time(1).is_none() {
        a.step(&PULL, 0.1).unwrap();
    }
    a.step(&PULL, 0.1).unwrap();
    let saved = state_bytes(&a);
    let slot_at = |slot: usize| STATE_BYTES - 8 * (MAX_OBSTACLES - slot);
    assert_eq!(
        saved[slot_at(1)..slot_at(1) + 8],
        a.activation_time(1).unwrap().to_le_bytes()
    );
    let mut w = world_with(&text, WorldConfig::default());
    let fresh = state_bytes(&w);
    for (slot, value, reason) in [
        (1, f64::INFINITY, "neither NaN"),
        (1, -1.0, "neither NaN"),
        (1, a.time() + 1.0, "neither NaN"),
        (0, 1.0, "not a target ship"),
        (5, 1.0, "not a target ship"),
    ] {
        let mut bad = saved.clone();
        bad[slot_at(slot)..slot_at(slot) + 8].copy_from_slice(&value.to_le_bytes());
        let e = w.read_state(&bad).unwrap_err();
        assert!(
            e.contains(&format!("activated_at[{slot}]")) && e.contains(reason),
            "{e}"
        );
        assert_eq!(state_bytes(&w), fresh, "a refused state changed the world");
    }
    w.read_state(&saved).unwrap();
    assert_eq!(w.activation_time(1), a.activation_time(1));
}

#[test]
fn fingerprint_covers_the_activation_range() {
    let a = world_with(
        &with_targets(&[(2.0, 3.0, "activation_range = 3.2")]),
        WorldConfig::default(),
    );
    let saved = state_bytes(&a);
    for lines in [
        "activation_range = 3.3",
        "activation_range = 3.2\nactivation_time = 100.0",
        "activation_time = 100.0",
    ] {
        let mut b = world_with(&with_targets(&[(2.0, 3.0, lines)]), WorldConfig::default());
        assert!(
            b.read_state(&saved)
                .unwrap_err()
                .contains("different scenario or configuration"),
            "{lines}"
        );
    }
    let mut same = world_with(
        &with_targets(&[(2.0, 3.0, "activation_range = 3.2")]),
        WorldConfig::default(),
    );
    same.read_state(&saved).unwrap();
}

#[test]
fn paper_targets_b_and_c_wait_for_the_tow() {
    // With the tow at rest at the route origin, B and C never appear, whatever
    // the time (they appeared at 405 s and 590 s before range activation).
    let s = Scenario::paper().unwrap();
    let mut w = World::new(&s, WorldConfig::default()).unwrap();
    w.step(&WorldInputs::default(), 700.0).unwrap();
    assert_eq!(w.obstacle(3).kind, ObstacleKind::VesselEllipse);
    assert_eq!(
        (w.obstacle(4).kind, w.obstacle(5).kind),
        (ObstacleKind::None, ObstacleKind::None)
    );
    // Put the ship where the paper's tow was at 405 s (kinematic estimate, see
    // scenarios/paper.toml): B appears at the next step end, C does not.
    let mut s = Scenario::paper().unwrap();
    s.ship.eta[..2].copy_from_slice(&[-10.11, 33.03]);
    s.place_tugs();
    let mut w = World::new(&s, WorldConfig::default()).unwrap();
    assert_eq!(w.activation_time(4), Some(0.0));
    assert_eq!(w.activation_time(5), None);
    // Just outside B's range: not yet.
    let mut s = Scenario::paper().unwrap();
    s.ship.eta[..2].copy_from_slice(&[-10.0, 33.0]);
    s.place_tugs();
    w = World::new(&s, WorldConfig::default()).unwrap();
    assert!((w.ship().eta[0] + 22.0).hypot(w.ship().eta[1] - 40.75) > 14.2);
    assert_eq!(w.activation_time(4), None);
    // Where the paper's tow was at 590 s: C's range.
    let mut s = Scenario::paper().unwrap();
    s.ship.eta = [-18.22, 40.0, std::f64::consts::PI];
    s.place_tugs();
    let w = World::new(&s, WorldConfig::default()).unwrap();
    assert_eq!(w.activation_time(5), Some(0.0));
}

/// The bank: no waterway, no judgement. In a 0.1 m half width, with the tow in the middle
/// of the route heading along it, each hull pokes out by its half beam less 0.1 m (the
/// ship 0.045 m, the tugs 0.05 m); moved 0.1 m to port, by its half beam. At the route's
/// start the lane ends in a half circle round the origin: the ship's stern corners there
/// are half its diagonal from it. The hulls keep moving.
#[test]
fn bank_excess_measures_the_footprints() {
    let open = World::new(&scenario(BASE), WorldConfig::default()).unwrap();
    assert!(open.lane().is_none() && open.bank_excess().is_none());
    let narrow = format!("{BASE}\n[waterway]\nhalf_width = 0.1\n");
    let mut s = scenario(&narrow);
    let at_start = World::new(&s, WorldConfig::default()).unwrap();
    let d = at_start.data[0];
    let diagonal = (d.length / 2.0).hypot(d.width / 2.0);
    assert!((at_start.bank_excess().unwrap()[0] - (diagonal - 0.1)).abs() < 1e-12);
    s.ship.eta[0] = 10.0;
    s.place_tugs();
    let world = World::new(&s, WorldConfig::default()).unwrap();
    let e = world.bank_excess().unwrap();
    let half_beam = [0, 1, 2].map(|k| world.data[k].width / 2.0);
    for k in 0..3 {
        assert!((e[k] - (half_beam[k] - 0.1)).abs() < 1e-12, "{k}: {e:?}");
    }
    s.ship.eta[1] = -0.1;
    s.place_tugs();
    let world = World::new(&s, WorldConfig::default()).unwrap();
    let e = world.bank_excess().unwrap();
    assert!((e[0] - half_beam[0]).abs() < 1e-12, "{e:?}");
    let wide = format!("{BASE}\n[waterway]\nhalf_width = 5.0\n");
    let world = World::new(&scenario(&wide), WorldConfig::default()).unwrap();
    assert!(
        world.bank_excess().unwrap().iter().all(|&e| e < -2.0),
        "{:?}",
        world.bank_excess()
    );
}

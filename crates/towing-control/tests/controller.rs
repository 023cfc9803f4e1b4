//! Controller behaviour on constructed measurements: refused inputs, obstacles
//! on top of the tow, bounds, the hold and inner loop between samples.
#![allow(clippy::unwrap_used)]

use towing_control::{
    AvoidanceScheme, ConfigError, Controller, ControllerConfig, Measurement, MeasurementError,
};
use towing_guidance::{Role, Situation};
use towing_model::{ObstacleKind, ObstacleSlot, Scenario, World};

fn paper_measurement() -> (Scenario, Measurement) {
    let scenario = Scenario::paper().unwrap();
    let world = World::new(&scenario, scenario.world_config).unwrap();
    (scenario, Measurement::from_world(&world))
}

/// A static circle of `diameter` centred at (`x`, `y`).
fn circle_at(x: f64, y: f64, diameter: f64) -> ObstacleSlot {
    ObstacleSlot {
        x,
        y,
        psi: 0.0,
        speed: 0.0,
        length: diameter,
        width: diameter,
        kind: ObstacleKind::StaticCircle,
    }
}

/// A static circle of `diameter` centred on the ship.
fn circle_on_ship(m: &Measurement, diameter: f64) -> ObstacleSlot {
    circle_at(m.ship[0], m.ship[1], diameter)
}

/// The paper scenario's first leg course (101.3 deg), from its origin (-4.9, 7.0) to
/// its first waypoint (-6.3, 14.0).
fn first_leg_course() -> f64 {
    (14.0f64 - 7.0).atan2(-6.3 + 4.9)
}

/// `m` with every obstacle slot empty.
fn alone(mut m: Measurement) -> Measurement {
    for o in m.obstacles.iter_mut() {
        o.kind = ObstacleKind::None;
    }
    m
}

fn assert_within_bounds(c: &towing_control::Command, config: &ControllerConfig) {
    for f in c.tension {
        assert!(
            f.is_finite()
                && f >= config.tuning.ship.min_tension - 1e-9
                && f <= config.tuning.ship.max_tension + 1e-9,
            "tension {f}"
        );
    }
    for tau in c.tug_thrust {
        for (v, l) in tau.iter().zip(config.tuning.tug.thrust_limit) {
            assert!(v.is_finite() && v.abs() <= l + 1e-9, "thrust {v} over {l}");
        }
    }
}

#[test]
fn a_non_finite_input_is_refused_by_name_and_changes_nothing() {
    let (scenario, m) = paper_measurement();
    let mut c = Controller::new(ControllerConfig::new(scenario)).unwrap();
    let names = ["x", "y", "psi", "u", "v", "r"];
    for (vessel, pick) in [("ship", 0), ("tug1", 1), ("tug2", 2)] {
        for (i, field) in names.iter().enumerate() {
            let mut bad = m;
            match pick {
                0 => bad.ship[i] = f64::NAN,
                n => bad.tugs[n - 1][i] = f64::INFINITY,
            }
            let err = c.sample(&bad).unwrap_err();
            match &err {
                MeasurementError::NonFinite { name, value } => {
                    assert_eq!(name, &format!("{vessel}.{field}"));
                    assert!(!value.is_finite());
                }
                other => panic!("unexpected {other}"),
            }
            assert!(
                err.to_string().contains(&format!("{vessel}.{field}")),
                "{err}"
            );
        }
    }
    let mut bad = m;
    bad.obstacles[2].speed = f64::NAN;
    let err = c.sample(&bad).unwrap_err();
    assert!(err.to_string().contains("obstacle[3]"), "{err}");
    // Nothing was applied: the first real sample starts from rest.
    let f0 = ControllerConfig::new(Scenario::paper().unwrap())
        .tuning
        .ship
        .min_tension;
    assert_eq!(c.applied().ship, [f0, f0, 0.0, 0.0]);
    assert!(c.sample(&m).is_ok());
}

#[test]
fn obstacles_on_top_of_the_tow_give_a_bounded_command_without_fallback_panics() {
    let (scenario, mut m) = paper_measurement();
    let config = ControllerConfig::new(scenario);
    let mut c = Controller::new(config.clone()).unwrap();
    // A static circle on the ship, a target ship on tug 2, another on tug 1.
    m.obstacles[0] = circle_on_ship(&m, 1.0);
    m.obstacles[1] = ObstacleSlot {
        x: m.tugs[1][0],
        y: m.tugs[1][1],
        psi: 1.0,
        speed: 0.07,
        length: 1.48,
        width: 0.48,
        kind: ObstacleKind::VesselEllipse,
    };
    m.obstacles[2] = ObstacleSlot {
        x: m.tugs[0][0],
        y: m.tugs[0][1],
        psi: -2.0,
        speed: 0.07,
        length: 1.48,
        width: 0.48,
        kind: ObstacleKind::VesselEllipse,
    };
    for _ in 0..5 {
        let r = c.sample(&m).unwrap();
        assert_within_bounds(&r.command, &config);
        assert!(r.guidance.d_ob < 1.0, "d_ob {}", r.guidance.d_ob);
        let between = c.command_at(0.5, &m).unwrap();
        assert_within_bounds(&between, &config);
    }
}

#[test]
fn rate_bounds_hold_from_sample_to_sample() {
    let (scenario, m) = paper_measurement();
    let config = ControllerConfig::new(scenario);
    let mut c = Controller::new(config.clone()).unwrap();
    // From the pretension the controller starts with.
    let f0 = config.tuning.ship.min_tension;
    assert_eq!(c.applied().ship, [f0, f0, 0.0, 0.0]);
    let mut prev = [f0, f0, 0.0, 0.0];
    for _ in 0..4 {
        let r = c.sample(&m).unwrap();
        let now = [
            r.command.tension[0],
            r.command.tension[1],
            r.desired_angle[0],
            r.desired_angle[1],
        ];
        for k in 0..2 {
            assert!(
                (now[k] - prev[k]).abs() <= config.tuning.ship.tension_rate + 1e-6,
                "{now:?} {prev:?}"
            );
            assert!((now[2 + k] - prev[2 + k]).abs() <= config.tuning.ship.angle_rate + 1e-6);
        }
        prev = now;
    }
}

#[test]
fn scheme_three_tracks_the_unaltered_route_and_scheme_two_drops_the_distance_cost() {
    let (scenario, mut m) = paper_measurement();
    // A target ship head-on, 4 m ahead of the forward tug: the route is altered.
    let psi = m.ship[2];
    let ahead = 2.1 + 4.0;
    m.obstacles[3] = ObstacleSlot {
        x: m.ship[0] + ahead * psi.cos(),
        y: m.ship[1] + ahead * psi.sin(),
        psi: psi + std::f64::consts::PI,
        speed: 0.07,
        length: 1.48,
        width: 0.48,
        kind: ObstacleKind::VesselEllipse,
    };
    let run = |scheme| {
        let mut config = ControllerConfig::new(scenario.clone());
        config.tuning.scheme = scheme;
        config.tuning.tracking.lookahead = 0.0;
        config.tuning.tracking.los_distance = 0.0;
        // The reference as the scheme gives it, not turned at a bounded rate.
        config.tuning.tracking.course_rate = 0.0;
        config.tuning.tracking.course_lead = 0.0;
        let mut c = Controller::new(config).unwrap();
        c.sample(&m).unwrap()
    };
    let one = run(AvoidanceScheme::AlterAndCost);
    let three = run(AvoidanceScheme::CostOnly);
    assert!(one.guidance.altered && three.guidance.altered);
    assert_eq!(one.reference, one.guidance.eta_sd.eta());
    assert_eq!(three.reference, three.guidance.route_waypoint.eta());
    assert_ne!(one.reference, three.reference);
    assert_eq!(one.situation[3], Some(Situation::HeadOn));
    assert_eq!(one.role[3], Some(Role::GiveWay));
}

/// A target ship passing port to port on the reciprocal course, 2 m abeam to port:
/// forward of the beam and closing it keeps its distance cost; once abaft the beam with
/// the range opening (past its closest approach) the distance cost leaves it out, in
/// schemes I and II, and keeps it in scheme III (no alteration to stand in for it).
#[test]
fn a_target_passed_abaft_the_beam_leaves_the_distance_cost() {
    let (scenario, m) = paper_measurement();
    let psi = m.ship[2];
    let at = |fwd: f64| {
        let mut m = alone(m);
        let port = -2.0;
        m.obstacles[3] = ObstacleSlot {
            x: m.ship[0] + fwd * psi.cos() - port * psi.sin(),
            y: m.ship[1] + fwd * psi.sin() + port * psi.cos(),
            psi: psi + std::f64::consts::PI,
            speed: 0.1,
            length: 1.48,
            width: 0.48,
            kind: ObstacleKind::VesselEllipse,
        };
        m
    };
    let mask = |scheme, m: &Measurement| {
        let mut config = ControllerConfig::new(scenario.clone());
        config.tuning.scheme = scheme;
        let mut c = Controller::new(config).unwrap();
        c.sample(m).unwrap();
        let input = c.last_mpc_input().unwrap();
        assert_eq!(input.obstacles().len(), 1);
        input.distance_cost_off & 1
    };
    for scheme in [AvoidanceScheme::AlterAndCost, AvoidanceScheme::AlterOnly] {
        assert_eq!(mask(scheme, &at(3.0)), 0, "{scheme:?} forward of the beam");
        assert_eq!(mask(scheme, &at(-0.5)), 1, "{scheme:?} abaft the beam");
    }
    assert_eq!(mask(AvoidanceScheme::CostOnly, &at(-0.5)), 0);
}

/// The ship 4 m to port of her first leg, heading along it: the line of sight to the
/// tracked point lies about 50 deg to starboard. The reference course turns towards it
/// by at most `course_rate * T_s` per sample, stays within `course_lead` of the
/// heading, and the tracked point lies on the reference course ahead of the ship.
#[test]
fn the_reference_course_turns_at_a_bounded_rate_and_carries_the_tracked_point() {
    let (scenario, mut m) = paper_measurement();
    let config = ControllerConfig::new(scenario);
    let t = config.tuning.tracking;
    let step = t.course_rate * config.tuning.prediction.sample_time;
    let psi = m.ship[2];
    // 4 m to port of the leg (port of a heading psi is psi - 90 deg).
    m.ship[0] += 4.0 * (psi - std::f64::consts::FRAC_PI_2).cos();
    m.ship[1] += 4.0 * (psi - std::f64::consts::FRAC_PI_2).sin();
    let mut c = Controller::new(config).unwrap();
    let mut previous = psi;
    for k in 0..5 {
        let r = c.sample(&m).unwrap().reference;
        let turn = towing_model::wrap_angle(r[2] - previous);
        assert!(
            turn > 0.0 && turn <= step + 1e-12,
            "sample {k}: turned {turn} rad"
        );
        assert!(towing_model::wrap_angle(r[2] - psi).abs() <= t.course_lead + 1e-12);
        let (dx, dy) = (r[0] - m.ship[0], r[1] - m.ship[1]);
        assert!(
            (dy.atan2(dx) - r[2]).abs() < 1e-9,
            "the point lies on the course"
        );
        assert!(dx.hypot(dy) <= t.lookahead.max(t.los_distance) + 1e-9);
        previous = r[2];
    }
}

#[test]
fn the_lookahead_point_lies_ahead_on_the_leg_and_the_heading_looks_at_it() {
    let (scenario, m) = paper_measurement();
    let mut c = Controller::new(ControllerConfig::new(scenario.clone())).unwrap();
    let r = c.sample(&m).unwrap();
    // At the origin, on the route: `lookahead` along the first leg (course 101.3 deg).
    let course = first_leg_course();
    let ahead = ControllerConfig::new(scenario.clone())
        .tuning
        .tracking
        .lookahead;
    let expect = [-4.9 + ahead * course.cos(), 7.0 + ahead * course.sin()];
    assert!(
        (r.reference[0] - expect[0]).abs() < 1e-9 && (r.reference[1] - expect[1]).abs() < 1e-9,
        "{:?}",
        r.reference
    );
    assert!((r.reference[2] - course).abs() < 1e-9);
}

#[test]
fn bad_configuration_values_are_named() {
    let (scenario, _) = paper_measurement();
    let mut config = ControllerConfig::new(scenario);
    config.tuning.tracking.lookahead = -1.0;
    let name = |e: ConfigError| match e {
        ConfigError::Parameter { name, .. } => name,
        other => panic!("{other}"),
    };
    let err = Controller::new(config.clone()).unwrap_err();
    assert_eq!(name(err), "tracking.lookahead");
    config.tuning.tracking.lookahead = 3.0;
    config.tuning.admm.max_iterations = 0;
    let err = Controller::new(config.clone()).unwrap_err();
    assert_eq!(name(err), "admm.max_iterations");
    config.tuning.admm.max_iterations = 30;
    config.tuning.inner.gain[1] = f64::NAN;
    let err = Controller::new(config).unwrap_err();
    assert_eq!(name(err), "inner_loop.bandwidth_sway");
}

#[test]
fn a_failed_solve_applies_the_shifted_plan_within_bounds_then_comes_to_rest() {
    let (scenario, m) = paper_measurement();
    let config = ControllerConfig::new(scenario);
    let p = config.tuning.ship;
    let mut c = Controller::new(config.clone()).unwrap();
    for _ in 0..4 {
        let r = c.sample(&m).unwrap();
        assert!(r.fallback.is_none(), "{:?}", r.fallback);
    }
    // A circle of 100 m radius on the ship: every clearance row would need more
    // than the slack bound (10 m), so the QPs are infeasible.
    let mut swallowed = m;
    swallowed.obstacles[7] = circle_on_ship(&m, 200.0);
    let mut prev = c.applied().ship;
    for k in 1..=6u64 {
        let r = c.sample(&swallowed).unwrap();
        let why = r.fallback.expect("an infeasible QP falls back");
        assert!(
            why.to_string().contains("QP gave no usable solution"),
            "{why}"
        );
        assert_eq!(r.fallbacks, k);
        assert_eq!(c.fallbacks(), k);
        assert_within_bounds(&r.command, &config);
        let now = [
            r.command.tension[0],
            r.command.tension[1],
            r.desired_angle[0],
            r.desired_angle[1],
        ];
        for i in 0..2 {
            assert!((now[i] - prev[i]).abs() <= p.tension_rate + 1e-12);
            assert!((now[2 + i] - prev[2 + i]).abs() <= p.angle_rate + 1e-12);
        }
        if k > 2 {
            // The spare plan (H - 1 = 2 samples) is used up: towards rest.
            assert_eq!(r.command.tug_thrust, [[0.0; 3]; 2]);
            for i in 0..2 {
                assert!(now[i] <= prev[i] + 1e-12, "tension does not grow at rest");
            }
        }
        prev = now;
    }
    // At rest after enough samples: the pretension, straight lines.
    for _ in 0..20 {
        c.sample(&swallowed).unwrap();
    }
    let rest = c.applied().ship;
    assert_eq!(rest, [p.min_tension, p.min_tension, 0.0, 0.0]);
    // The obstacle gone, the next sample solves again (cold).
    let r = c.sample(&m).unwrap();
    assert!(r.fallback.is_none(), "{:?}", r.fallback);
}

/// A target crossing from starboard (give-way): in schemes I and II the ship's
/// heading at the start of the encounter, less the margin, becomes a floor; it
/// ratchets up with the heading, lifts when the situation ends, and scheme III
/// has none.
/// A measurement that describes no tow (every input 0, as a controller run alone sees):
/// no solve and no fallback, the rest command, every value of the report finite; the
/// first such sample is marked to report, the next not; a tow again solves.
#[test]
fn a_measurement_with_vessels_inside_each_other_rests_without_fallback() {
    let (scenario, m) = paper_measurement();
    let config = ControllerConfig::new(scenario);
    let mut c = Controller::new(config.clone()).unwrap();
    let zero = Measurement::default();
    for k in 0..3 {
        let r = c.sample(&zero).unwrap();
        assert!(r.fallback.is_none(), "{:?}", r.fallback);
        let rest = r.rest.expect("vessels inside each other rest");
        assert_eq!(rest.first, k == 0);
        assert_eq!(rest.overlap.vessels, ["ship", "tug1"]);
        assert_eq!(rest.overlap.distance, 0.0);
        assert_eq!(r.iterations, 0);
        assert_eq!(r.command.tug_thrust, [[0.0; 3]; 2]);
        let f0 = config.tuning.ship.min_tension;
        assert_eq!(r.command.tension, [f0, f0]);
        assert_eq!(r.desired_angle, [0.0, 0.0]);
        let p = &r.prediction;
        assert!(p
            .ship
            .iter()
            .chain(p.tugs.iter().flatten())
            .flatten()
            .all(|v| v.is_finite()));
        assert!(r.r_pri.iter().chain(&r.r_dual).all(|v| v.is_finite()));
    }
    // Tug 2 inside the ship's hull (closer than half its beam) is no tow either.
    let mut inside = m;
    inside.tugs[1][0] = m.ship[0] + 0.1;
    inside.tugs[1][1] = m.ship[1];
    let r = c.sample(&inside).unwrap();
    assert_eq!(r.rest.unwrap().overlap.vessels, ["ship", "tug2"]);
    let r = c.sample(&m).unwrap();
    assert!(r.rest.is_none() && r.fallback.is_none());
    assert!(r.iterations >= 1);
    assert_eq!(c.fallbacks(), 0);
}

/// Speeds far beyond the model's range make the MPC's iterates overflow: the sample
/// falls back, and every value of its report stays finite.
#[test]
fn absurd_speeds_fall_back_with_a_finite_report() {
    let (scenario, m) = paper_measurement();
    let config = ControllerConfig::new(scenario);
    for speed in [10.0, 100.0, 1000.0] {
        let mut c = Controller::new(config.clone()).unwrap();
        let mut fast = m;
        for s in std::iter::once(&mut fast.ship).chain(fast.tugs.iter_mut()) {
            s[3] = speed;
            s[4] = -0.5 * speed;
        }
        for _ in 0..3 {
            let r = c.sample(&fast).unwrap();
            let p = &r.prediction;
            let values = p.ship.iter().chain(p.tugs.iter().flatten()).flatten();
            assert!(values.clone().all(|v| v.is_finite()), "{speed} m/s: {p:?}");
            assert!(
                r.r_pri.iter().chain(&r.r_dual).all(|v| v.is_finite()),
                "{speed} m/s: {:?} {:?}",
                r.r_pri,
                r.r_dual
            );
            assert!(r.reference.iter().all(|v| v.is_finite()));
            assert!(r.desired_angle.iter().all(|v| v.is_finite()));
            assert_within_bounds(&r.command, &config);
        }
    }
}

/// A target ship 5 m ahead of the ship and 3 m to starboard, heading across her bow to
/// port at 0.07 m/s, closing: a crossing in which the tow gives way.
fn crossing_from_starboard(m: &Measurement) -> ObstacleSlot {
    let psi = m.ship[2];
    let (fwd, stb) = (5.0, 3.0);
    ObstacleSlot {
        x: m.ship[0] + fwd * psi.cos() - stb * psi.sin(),
        y: m.ship[1] + fwd * psi.sin() + stb * psi.cos(),
        psi: psi - std::f64::consts::FRAC_PI_2,
        speed: 0.07,
        length: 1.48,
        width: 0.48,
        kind: ObstacleKind::VesselEllipse,
    }
}

/// Rule 8(e): giving way in a crossing, the tow takes the way off at a bounded
/// deceleration and keeps it off: the plan's surge is capped at the measured surge less
/// `tracking.give_way_deceleration` T_s, and at `tracking.give_way_surge` once she is
/// slower. Without the encounter, or with `tracking.give_way_way_off` (on by default)
/// switched off, there is no cap.
#[test]
fn giving_way_in_a_crossing_the_plan_does_not_gather_way() {
    let (scenario, mut m) = paper_measurement();
    let target = crossing_from_starboard(&m);
    let config = ControllerConfig::new(scenario.clone());
    assert!(config.tuning.tracking.give_way_way_off, "on by default");
    let mut switched_off = config.clone();
    switched_off.tuning.tracking.give_way_way_off = false;
    let mut off = Controller::new(switched_off).unwrap();
    let original = m.obstacles[3];
    m.obstacles[3] = target;
    let r = off.sample(&m).unwrap();
    assert_eq!(r.situation[3], Some(Situation::CrossingGiveWay));
    assert_eq!(off.last_mpc_input().unwrap().max_surge, None);
    m.obstacles[3] = original;
    let cap = config.tuning.tracking.give_way_surge;
    let slowing =
        config.tuning.tracking.give_way_deceleration * config.tuning.prediction.sample_time;
    assert!(slowing > 0.0);
    let mut open_water = Controller::new(config.clone()).unwrap();
    open_water.sample(&m).unwrap();
    assert_eq!(open_water.last_mpc_input().unwrap().max_surge, None);

    m.obstacles[3] = target;
    let mut c = Controller::new(config).unwrap();
    for (u, expected) in [(0.1, 0.1 - slowing), (0.01, cap), (0.07, 0.07 - slowing)] {
        m.ship[3] = u;
        let r = c.sample(&m).unwrap();
        assert_eq!(r.situation[3], Some(Situation::CrossingGiveWay));
        assert!(r.guidance.altered);
        let got = c.last_mpc_input().unwrap().max_surge;
        let got = got.expect("a cap while giving way");
        assert!(
            (got - expected).abs() < 1e-12,
            "surge {u}: cap {got}, expected {expected}"
        );
    }
}

/// Rule 8(e) with 8(d) and 15: giving way in a crossing (with
/// `tracking.give_way_way_off` switched off), a tow that has slackened to half her
/// resume speed or less, whose altered course runs into the bank before she could take her way off and
/// keep a ship length in hand, keeps the way off while that alteration lasts, even back
/// in open water and gathering way; the same tow with the water for it, or still at
/// speed, has no cap. The paper's route in a 2 m half width: the 15 deg altered leg from
/// the origin meets the bank about 7.7 m on (4.9 m for the ship's centre, with its
/// hull's margin).
#[test]
fn giving_way_with_the_altered_course_out_of_water_keeps_the_way_off() {
    let (mut scenario, m) = paper_measurement();
    scenario.waterway.as_mut().unwrap().half_width = 2.0;
    let mut config = ControllerConfig::new(scenario);
    config.tuning.tracking.give_way_way_off = false;
    let on_altered_leg = |run: f64, surge: f64| {
        // `run` m from the origin along the altered leg, the tow's formation kept.
        let course = first_leg_course() + 15f64.to_radians();
        let (dx, dy) = (run * course.cos(), run * course.sin());
        let mut m = m;
        m.ship[0] += dx;
        m.ship[1] += dy;
        for tug in &mut m.tugs {
            tug[0] += dx;
            tug[1] += dy;
        }
        m.ship[3] = surge;
        m.obstacles[3] = crossing_from_starboard(&m);
        m
    };
    let caps = |c: &mut Controller, m: &Measurement, samples: usize| -> Vec<Option<f64>> {
        (0..samples)
            .map(|_| {
                let r = c.sample(m).unwrap();
                assert_eq!(r.situation[3], Some(Situation::CrossingGiveWay));
                assert!(r.guidance.altered);
                c.last_mpc_input().unwrap().max_surge
            })
            .collect()
    };
    let none = |v: Vec<Option<f64>>| v.iter().all(Option::is_none);
    let slow = config.tuning.tracking.give_way_surge;
    let mut open = Controller::new(config.clone()).unwrap();
    assert!(none(caps(&mut open, &on_altered_leg(0.0, slow), 30)));
    let mut at_speed = Controller::new(config.clone()).unwrap();
    assert!(none(caps(&mut at_speed, &on_altered_leg(4.0, 0.1), 30)));

    let mut near_bank = Controller::new(config.clone()).unwrap();
    let got = caps(&mut near_bank, &on_altered_leg(4.0, slow), 30);
    let first = got
        .iter()
        .position(Option::is_some)
        .expect("a cap near the bank");
    assert!(got[first..].iter().all(|&c| c == Some(slow)), "{got:?}");
    // Latched for the encounter: back with the water ahead, gathering way, she is
    // still held to the measured surge less the deceleration.
    let slowing =
        config.tuning.tracking.give_way_deceleration * config.tuning.prediction.sample_time;
    for cap in caps(&mut near_bank, &on_altered_leg(0.0, 0.1), 5) {
        assert!((cap.expect("latched") - (0.1 - slowing)).abs() < 1e-12);
    }
}

/// Rule 17(a)(ii), (b) with 8(e): a give-way target from port on a collision course,
/// 9 m off on the port side (beyond d_D) and 54 s from the CPA: the stand-on tow keeps
/// the route and takes the way off, the plan's surge capped at the measured surge less
/// `guidance.rule17_way_off_deceleration` T_s, and at `guidance.rule17_way_off_speed`
/// once she is slower, with both lines at the holding tension
/// (`mpc.ship.holding_tension`). Scheme III (no COLREGS logic) has no cap.
#[test]
fn a_stand_on_tow_takes_the_way_off_under_rule_17() {
    let (scenario, mut m) = paper_measurement();
    let psi = m.ship[2];
    m.ship[3] = 0.1;
    m.ship[4] = 0.0;
    let (fwd, stb) = (5.4, -9.0);
    m.obstacles[3] = ObstacleSlot {
        x: m.ship[0] + fwd * psi.cos() - stb * psi.sin(),
        y: m.ship[1] + fwd * psi.sin() + stb * psi.cos(),
        psi: psi + std::f64::consts::FRAC_PI_2,
        speed: 9.0 / 54.0,
        length: 1.48,
        width: 0.48,
        kind: ObstacleKind::VesselEllipse,
    };
    let config = ControllerConfig::new(scenario.clone());
    let rule17 = config.tuning.guidance.colregs.rule17;
    let slowing = rule17.way_off_deceleration * config.tuning.prediction.sample_time;
    let mut c = Controller::new(config.clone()).unwrap();
    for (u, expected) in [(0.1, 0.1 - slowing), (0.005, rule17.way_off_speed)] {
        m.ship[3] = u;
        let r = c.sample(&m).unwrap();
        assert_eq!(r.situation[3], Some(Situation::CrossingStandOn));
        assert!(
            r.guidance.way_off && !r.guidance.altered,
            "{:?}",
            r.guidance
        );
        let got = c.last_mpc_input().unwrap().max_surge.expect("a cap");
        assert!(
            (got - expected).abs() < 1e-12,
            "surge {u}: cap {got}, expected {expected}"
        );
        // Both lines at least at the holding tension (from the 0.1 N pretension,
        // within one sample's rate bound), so the tugs can hold her head.
        let hold = config.tuning.ship.holding_tension;
        for (i, f) in r.command.tension.iter().enumerate() {
            assert!(*f >= hold - 1e-9, "surge {u}: line {i} at {f} N");
        }
    }
    let mut config = config;
    config.tuning.scheme = AvoidanceScheme::CostOnly;
    let mut c = Controller::new(config).unwrap();
    m.ship[3] = 0.1;
    c.sample(&m).unwrap();
    assert_eq!(c.last_mpc_input().unwrap().max_surge, None);
}

/// Being overtaken (Rules 13 and 17(a)(i)) the tow keeps her course: with the
/// overtaking target on her port quarter the heading floor binds (a port turn is a
/// turn into its path); on her starboard quarter it does not (no floor is a ceiling).
#[test]
fn a_target_overtaking_on_the_port_side_sets_a_heading_floor() {
    let (scenario, mut m) = paper_measurement();
    let psi = m.ship[2];
    let margin = ControllerConfig::new(scenario.clone())
        .tuning
        .tracking
        .port_turn_margin;
    for (side, floor_expected) in [(-1.0, true), (1.0, false)] {
        // 3 m astern, 1.5 m abeam, on the ship's course and faster than her.
        let (aft, abeam) = (-3.0, side * 1.5);
        m.obstacles[3] = ObstacleSlot {
            x: m.ship[0] + aft * psi.cos() - abeam * psi.sin(),
            y: m.ship[1] + aft * psi.sin() + abeam * psi.cos(),
            psi,
            speed: 0.2,
            length: 1.48,
            width: 0.48,
            kind: ObstacleKind::VesselEllipse,
        };
        let mut c = Controller::new(ControllerConfig::new(scenario.clone())).unwrap();
        let r = c.sample(&m).unwrap();
        assert_eq!(
            r.situation[3],
            Some(Situation::BeingOvertaken),
            "side {side}"
        );
        match r.heading_floor {
            Some(f) => {
                assert!(floor_expected, "side {side}: floor {f}");
                assert!((f - (psi - margin)).abs() < 1e-12, "{f} vs {psi}");
            }
            None => assert!(!floor_expected, "side {side}: no floor"),
        }
    }
}

#[test]
fn a_crossing_encounter_sets_a_heading_floor_that_ratchets_and_lifts() {
    let (scenario, mut m) = paper_measurement();
    let psi = m.ship[2];
    let target = crossing_from_starboard(&m);
    m.obstacles[3] = target;
    let margin = ControllerConfig::new(scenario.clone())
        .tuning
        .tracking
        .port_turn_margin;
    let controller = |scheme| {
        let mut config = ControllerConfig::new(scenario.clone());
        config.tuning.scheme = scheme;
        Controller::new(config).unwrap()
    };
    let mut c = controller(AvoidanceScheme::AlterAndCost);
    let r = c.sample(&m).unwrap();
    assert_eq!(r.role[3], Some(Role::GiveWay));
    let floor = r.heading_floor.expect("a floor while giving way");
    assert!((floor - (psi - margin)).abs() < 1e-12, "{floor} vs {psi}");

    // The ship has turned 10 deg to starboard: the floor follows.
    let mut turned = m;
    turned.ship[2] = psi + 10f64.to_radians();
    let r = c.sample(&turned).unwrap();
    let up = r.heading_floor.unwrap();
    assert!((up - (turned.ship[2] - margin)).abs() < 1e-12);
    // Back at the old heading the floor stays up (no port turn is taken back).
    let r = c.sample(&m).unwrap();
    assert!((r.heading_floor.unwrap() - up).abs() < 1e-12);

    // The reference course never lies to port of the floor (a head held to starboard
    // while the reference lay to port of it was answered by a sideways drag), here
    // after a swing of 60 deg: the floor follows it (no turn back to port towards the
    // target before it is past), and so does the reference course.
    let mut swung = m;
    swung.ship[2] = psi + 60f64.to_radians();
    let r = c.sample(&swung).unwrap();
    let floor = r.heading_floor.unwrap();
    assert!((floor - (swung.ship[2] - margin)).abs() < 1e-9);
    let lead = ControllerConfig::new(scenario.clone())
        .tuning
        .tracking
        .course_lead;
    for back in [m, swung] {
        let r = c.sample(&back).unwrap();
        assert!((r.heading_floor.unwrap() - floor).abs() < 1e-9);
        // At most `course_lead` ahead of the ship's head: on the floor, or turning
        // towards it at that lead.
        let wanted = floor.min(back.ship[2] + lead);
        let course = r.reference[2];
        assert!(
            towing_model::wrap_angle(course - wanted) >= -1e-12,
            "{course} vs {wanted}"
        );
    }

    // The target gone: no floor.
    let mut clear = m;
    clear.obstacles[3].kind = ObstacleKind::None;
    assert_eq!(c.sample(&clear).unwrap().heading_floor, None);

    // Scheme III: no COLREGS logic, no floor.
    let mut three = controller(AvoidanceScheme::CostOnly);
    assert_eq!(three.sample(&m).unwrap().heading_floor, None);
}

/// The heading floor is laid off from the route's course (Rule 17's "course" is that of
/// the manoeuvre, `docs/analyzer.md`, "Course changes"): the tow giving way on the
/// paper's first leg, carried unchanged to just short of the route's starboard bend at
/// (-10.7, 36), has the floor turned with the route's course there, the bearing from her
/// nearest point on the route to the point `tracking.lookahead` farther along it.
#[test]
fn the_heading_floor_turns_with_a_bend_of_the_route() {
    let (scenario, mut m) = paper_measurement();
    let psi = m.ship[2];
    m.obstacles[3] = crossing_from_starboard(&m);
    let config = ControllerConfig::new(scenario.clone());
    let margin = config.tuning.tracking.port_turn_margin;
    let lookahead = config.tuning.tracking.lookahead;
    let route = towing_model::geometry::Polyline::of_route(&scenario.route);
    let course = |m: &Measurement| {
        route
            .course_ahead([m.ship[0], m.ship[1]], lookahead)
            .unwrap()
    };
    let mut c = Controller::new(config).unwrap();
    let r = c.sample(&m).unwrap();
    assert_eq!(r.role[3], Some(Role::GiveWay));
    let off = towing_model::wrap_angle(psi - course(&m));
    let floor = r.heading_floor.expect("a floor while giving way");
    assert!((floor - (psi - margin)).abs() < 1e-12, "{floor} vs {psi}");

    // The whole encounter moved, unturned, to 0.5 m short of the bend on the first leg.
    let along = [
        -10.7 + 0.5 * 1.6 / 8.0f64.hypot(1.6),
        36.0 - 0.5 * 8.0 / 8.0f64.hypot(1.6),
    ];
    let shift = [along[0] - m.ship[0], along[1] - m.ship[1]];
    let mut moved = m;
    let [tug1, tug2] = &mut moved.tugs;
    for p in [&mut moved.ship, tug1, tug2] {
        p[0] += shift[0];
        p[1] += shift[1];
    }
    moved.obstacles[3].x += shift[0];
    moved.obstacles[3].y += shift[1];
    let bend = towing_model::wrap_angle(course(&moved) - course(&m));
    assert!(bend > 20f64.to_radians(), "the route turns ahead: {bend}");
    let r = c.sample(&moved).unwrap();
    let floor = r.heading_floor.expect("still giving way");
    let expected = course(&moved) + off - margin;
    assert!(
        towing_model::wrap_angle(floor - expected).abs() < 1e-9,
        "floor {floor} vs the route's course {} off {off}",
        course(&moved)
    );
}

/// The controller's own clock: a sample at the first step and every T_s after
/// (a communication point within 1 us of an instant samples; one that falls
/// between instants does not), the command between samples from the inner loop.
#[test]
fn step_samples_on_its_own_clock() {
    let (scenario, m) = paper_measurement();
    let mut c = Controller::new(ControllerConfig::new(scenario)).unwrap();
    c.set_start_time(10.0);
    let mut sampled = Vec::new();
    // 0.1 s steps summed the way masters do (t += h), with their rounding.
    let mut t = 10.0;
    for _ in 0..35 {
        if c.step(t, &m).unwrap().sample.is_some() {
            sampled.push(t);
        }
        t += 0.1;
    }
    assert_eq!(c.samples(), 4, "{sampled:?}");
    for (k, s) in sampled.iter().enumerate() {
        assert!((s - (10.0 + k as f64)).abs() < 1e-6, "{sampled:?}");
    }
    // A non-finite velocity is refused by name, and the step says where.
    let mut bad = m;
    bad.tugs[1][4] = f64::NAN;
    let e = c.step(t, &bad).unwrap_err();
    assert!(e.to_string().contains("tug2.v"), "{e}");
}

/// A static hazard 2.5 m ahead on the first leg, 1 m to one side of it, the ship at rest
/// on the route and alone with it: the line of sight to the tracked point (3.5 m along
/// the leg) passes 1 m from the hazard, inside the ship's hazard safe range (eq. (14),
/// 2.005 m). The reference course turns away from the hazard, to the side of it the
/// route lies on (to port for a hazard to starboard of the leg, to starboard for one to
/// port), and the tracked point lies short of the hazard's safe range on that course.
#[test]
fn a_hazard_on_the_line_of_sight_turns_the_reference_away_and_holds_the_point_short() {
    let (scenario, m) = paper_measurement();
    let m = alone(m);
    let config = ControllerConfig::new(scenario);
    let step = config.tuning.tracking.course_rate * config.tuning.prediction.sample_time;
    let lookahead = config.tuning.tracking.lookahead;
    let psi = m.ship[2];
    // The first leg's course, within one course step of the ship's heading.
    let leg = first_leg_course();
    let rho = 1.255 + 0.5 + 0.25;
    // Without the hazard: along the leg, the whole lookahead ahead.
    let free = Controller::new(config.clone())
        .unwrap()
        .sample(&m)
        .unwrap()
        .reference;
    assert!(towing_model::wrap_angle(free[2] - leg).abs() < 1e-9);
    assert!(((free[0] - m.ship[0]).hypot(free[1] - m.ship[1]) - lookahead).abs() < 1e-9);
    for side in [1.0, -1.0] {
        // `side` 1: to starboard of the leg (starboard of a course is course + 90 deg).
        let (s, c) = leg.sin_cos();
        let hazard = [
            m.ship[0] + 2.5 * c - side * 1.0 * s,
            m.ship[1] + 2.5 * s + side * 1.0 * c,
        ];
        let mut with = m;
        with.obstacles[0] = circle_at(hazard[0], hazard[1], 1.0);
        let mut c = Controller::new(config.clone()).unwrap();
        let r = c.sample(&with).unwrap().reference;
        let turn = towing_model::wrap_angle(r[2] - psi);
        assert!(
            (turn + side * step).abs() < 1e-9,
            "side {side}: turned {turn} rad, expected {} rad",
            -side * step
        );
        let (dx, dy) = (r[0] - m.ship[0], r[1] - m.ship[1]);
        let reach = dx.hypot(dy);
        let clear = (r[0] - hazard[0]).hypot(r[1] - hazard[1]);
        assert!(
            reach < lookahead - 1.0,
            "side {side}: point {reach} m ahead"
        );
        assert!(
            (clear - rho).abs() < 1e-9,
            "side {side}: point {clear} m from the hazard"
        );
    }
}

/// The ship already inside a hazard's safe range (the hazard 1 m abeam to starboard of
/// the leg, its safe range 2.005 m): the tracked point is not held at the ship, which
/// kept the tow inside; the line of sight leads out, square to the line to the hazard's
/// centre on the route's side of it (here: ahead along the leg, the whole lookahead).
#[test]
fn inside_a_hazards_safe_range_the_tracked_point_is_not_held_at_the_ship() {
    let (scenario, m) = paper_measurement();
    let mut m = alone(m);
    let config = ControllerConfig::new(scenario);
    let lookahead = config.tuning.tracking.lookahead;
    let step = config.tuning.tracking.course_rate * config.tuning.prediction.sample_time;
    let leg = first_leg_course();
    let (s, c) = leg.sin_cos();
    m.obstacles[0] = circle_at(m.ship[0] - s, m.ship[1] + c, 1.0);
    let r = Controller::new(config)
        .unwrap()
        .sample(&m)
        .unwrap()
        .reference;
    let reach = (r[0] - m.ship[0]).hypot(r[1] - m.ship[1]);
    assert!(
        (reach - lookahead).abs() < 1e-9,
        "point {reach} m from the ship"
    );
    assert!(towing_model::wrap_angle(r[2] - leg).abs() <= step + 1e-12);
}

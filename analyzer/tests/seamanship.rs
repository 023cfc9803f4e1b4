//! Known answers of the seamanship and rule verdicts on synthetic trajectories: a straight
//! route North from (0, 0) to (50, 0), the ship at 0.065 m/s with the tugs 2 m ahead and
//! behind on its heading, plant steps of 0.5 s, scripted departures from that.

use analyzer::colregs::Situation;
use analyzer::metric::astern::{self, AsternReport, AsternTracker};
use analyzer::metric::drift::{self, DriftReport, DriftTracker};
use analyzer::metric::progress::{self, ProgressReport, ProgressTracker};
use analyzer::metric::rules::{self, RulesReport, RulesTracker};
use analyzer::metric::speed::{self, SpeedReport, SpeedTracker};
use analyzer::metric::waterway::{self, WaterwayReport, WaterwayTracker};
use analyzer::metric::{Metric, StepFacts};
use analyzer::step::{
    ControlEncounter, ControlSample, Obstacle, ObstacleKind, PlantStep, RunGeometry, Vessel,
};
use analyzer::thresholds::Thresholds;
use analyzer::verdict::Reason;

const DT: f64 = 0.5;
const CRUISE: f64 = 0.065;
const HALF_WIDTH: f64 = 5.0;

fn geometry() -> RunGeometry {
    RunGeometry {
        sizes: [[1.255, 0.3], [0.97, 0.3], [0.97, 0.3]],
        route: vec![[0.0, 0.0, 0.0], [50.0, 0.0, 0.0]],
        half_width: Some(HALF_WIDTH),
        detection_distance: 7.0,
    }
}

/// A target ship on a straight line: position at t = 0 (it may be far), course (deg),
/// speed.
struct Target {
    name: &'static str,
    at_t0: [f64; 2],
    course_deg: f64,
    speed: f64,
}

impl Target {
    fn at(&self, slot: u32, t: f64) -> Obstacle {
        let c = self.course_deg.to_radians();
        Obstacle {
            slot,
            name: self.name.to_owned(),
            kind: ObstacleKind::Ship,
            x: self.at_t0[0] + self.speed * c.cos() * t,
            y: self.at_t0[1] + self.speed * c.sin() * t,
            course: c,
            speed: self.speed,
            length: 1.48,
            width: 0.48,
        }
    }
}

/// The six seamanship and rule metrics, fed as the registry feeds them (`rules` before
/// `progress`, the step's facts handed on), without the log reading around them.
struct Seamanship {
    rules: RulesTracker,
    progress: ProgressTracker,
    drift: DriftTracker,
    speed: SpeedTracker,
    astern: AsternTracker,
    waterway: WaterwayTracker,
}

/// Their reports.
struct SeamanshipReport {
    rules: RulesReport,
    progress: ProgressReport,
    drift: DriftReport,
    speed: SpeedReport,
    astern: AsternReport,
    waterway: WaterwayReport,
}

impl Seamanship {
    fn new(g: &RunGeometry, th: &Thresholds) -> Self {
        Seamanship {
            rules: RulesTracker::new(g, th),
            progress: ProgressTracker::new(g, th),
            drift: DriftTracker::new(g, th),
            speed: SpeedTracker::new(g, th),
            astern: AsternTracker::new(g, th),
            waterway: WaterwayTracker::new(g, th),
        }
    }

    fn push(&mut self, s: &PlantStep<'_>) {
        let mut facts = StepFacts::default();
        Metric::step(&mut self.rules, s, &mut facts);
        Metric::step(&mut self.progress, s, &mut facts);
        Metric::step(&mut self.drift, s, &mut facts);
        Metric::step(&mut self.speed, s, &mut facts);
        Metric::step(&mut self.astern, s, &mut facts);
        Metric::step(&mut self.waterway, s, &mut facts);
    }

    fn finish(self) -> SeamanshipReport {
        SeamanshipReport {
            rules: self.rules.finish(),
            progress: self.progress.finish(),
            drift: self.drift.finish(),
            speed: self.speed.finish(),
            astern: self.astern.finish(),
            waterway: self.waterway.finish(),
        }
    }
}

/// Every reason, metric by metric in the registry's order.
fn reasons(r: &SeamanshipReport, th: &Thresholds) -> Vec<Reason> {
    let mut out = rules::reasons(&r.rules, th);
    out.extend(progress::reasons(&r.progress, th));
    out.extend(drift::reasons(&r.drift, th));
    out.extend(speed::reasons(&r.speed, th));
    out.extend(astern::reasons(&r.astern, th));
    out.extend(waterway::reasons(&r.waterway, th));
    out
}

/// A run: `motion(t, ship position)` gives the ship's heading (deg), surge and sway at the
/// step ending at `t`; the position integrates the velocity over ground; `offset(t)` is
/// added to the ship's position (a scripted excursion); the tugs sit 2 m behind and ahead
/// on the heading.
fn run(
    t_end: f64,
    motion: impl Fn(f64, [f64; 2]) -> (f64, f64, f64),
    offset: impl Fn(f64) -> [f64; 2],
    targets: &[Target],
) -> SeamanshipReport {
    run_controlled(t_end, motion, offset, targets, |_| None)
}

/// [`run`] with the controller's sample at each step given by `control(t)`.
fn run_controlled(
    t_end: f64,
    motion: impl Fn(f64, [f64; 2]) -> (f64, f64, f64),
    offset: impl Fn(f64) -> [f64; 2],
    targets: &[Target],
    control: impl Fn(f64) -> Option<ControlSample>,
) -> SeamanshipReport {
    let g = geometry();
    let mut seamanship = Seamanship::new(&g, &Thresholds::default());
    let mut pos = [0.0, 0.0];
    let mut prev_psi: Option<f64> = None;
    let n = (t_end / DT).round() as usize;
    for k in 0..=n {
        let t = k as f64 * DT;
        let (psi_deg, u, v) = motion(t, pos);
        let psi = psi_deg.to_radians();
        // The yaw rate over the step ending at `t` (the heading script's slope).
        let r = prev_psi.replace(psi).map_or(0.0, |p| (psi - p) / DT);
        let mut ship = Vessel {
            x: 0.0,
            y: 0.0,
            psi,
            u,
            v,
            r,
        };
        if k > 0 {
            let vel = ship.vel_n();
            pos = [pos[0] + vel[0] * DT, pos[1] + vel[1] * DT];
        }
        let off = offset(t);
        ship.x = pos[0] + off[0];
        ship.y = pos[1] + off[1];
        let (s, c) = ship.psi.sin_cos();
        let tug = |d: f64| Vessel {
            x: ship.x + d * c,
            y: ship.y + d * s,
            ..ship
        };
        let obstacles: Vec<Obstacle> = targets
            .iter()
            .enumerate()
            .map(|(i, tg)| tg.at(i as u32 + 1, t))
            .collect();
        let sample = control(t);
        seamanship.push(&PlantStep {
            t,
            vessels: [ship, tug(-2.0), tug(2.0)],
            obstacles: &obstacles,
            control: sample.as_ref(),
        });
    }
    seamanship.finish()
}

/// Straight along the route at cruise speed, stopping at the destination.
fn cruise(_t: f64, p: [f64; 2]) -> (f64, f64, f64) {
    (0.0, if p[0] < 50.0 { CRUISE } else { 0.0 }, 0.0)
}

fn no_offset(_t: f64) -> [f64; 2] {
    [0.0, 0.0]
}

fn verdict(r: &SeamanshipReport) -> Vec<Reason> {
    reasons(r, &Thresholds::default())
}

fn metrics(reasons: &[Reason]) -> Vec<&str> {
    reasons.iter().map(|r| r.metric.as_str()).collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn seamanship_clean_straight_run_has_no_reason() {
    let r = run(800.0, cruise, no_offset, &[]);
    assert!(verdict(&r).is_empty(), "{:?}", verdict(&r));
    assert_eq!(r.progress.route_length_m, Some(50.0));
    // Within 2 m of (50, 0) from x = 48 m: 48 / 0.065 = 738.46 s, the step at 738.5 s.
    assert_eq!(r.progress.t_arrival_s, Some(738.5));
    assert_eq!(r.progress.arrival_deadline_s, Some(50.0 / 0.05 + 300.0));
    assert!(close(r.speed.cruise_m_s.expect("under way"), CRUISE, 1e-4));
    assert!(close(r.speed.max_cruise_ratio.expect("ratio"), 1.0, 2e-3));
    assert_eq!(r.drift.max_drift_deg, Some(0.0));
    assert_eq!(r.astern.time_astern_s, 0.0);
    // Beyond the route's ends the distance is to the end point: tug 1's stern corners at
    // the start are 2 + 0.485 m behind the origin and 0.15 m off the route; tug 2's bow
    // corners at the end as far beyond the destination, plus the ship's overshoot of at
    // most one step (0.0325 m).
    let far = 2.485f64.hypot(0.15) - HALF_WIDTH;
    let max = r.waterway.max_excess_m.expect("route");
    assert!(max >= far - 1e-9 && max <= far + 0.0325, "{:?}", r.waterway);
    assert_eq!(r.waterway.time_outside_s, 0.0);
    assert!(r.waterway.groundings.is_empty());
    // Stalls only of the time to cover 0.5 m: 0.5 / 0.065 = 7.7 s, on 0.5 s steps.
    let stall = r.progress.longest_stall.expect("a stall");
    assert!(stall.duration_s <= 8.0, "{stall:?}");
}

#[test]
fn seamanship_sideways_drift_45_deg() {
    // v = u (to starboard, then to port, back onto the route) from 100 s to 150 s, at
    // the same speed over ground.
    let k = CRUISE / 2f64.sqrt();
    let motion = |t: f64, p: [f64; 2]| {
        if t > 100.0 && t <= 125.0 {
            (0.0, k, k)
        } else if t > 125.0 && t <= 150.0 {
            (0.0, k, -k)
        } else {
            cruise(t, p)
        }
    };
    let r = run(800.0, motion, no_offset, &[]);
    assert!(close(r.drift.max_drift_deg.expect("under way"), 45.0, 1e-9));
    assert_eq!(r.drift.t_max_s, Some(100.5));
    assert!(
        close(r.drift.time_above_s, 50.0, 1e-9),
        "{}",
        r.drift.time_above_s
    );
    let why = verdict(&r);
    assert_eq!(metrics(&why), ["drift"], "{why:?}");
    assert_eq!(why[0].t_s, Some(100.5));
}

#[test]
fn seamanship_stall_of_200_s_is_a_reason() {
    let stop = stop_between(300.0, 500.0);
    let r = run(1000.0, stop, no_offset, &[]);
    let stall = r.progress.longest_stall.expect("a stall");
    // 200 s stopped plus at most the time to cover 0.5 m at cruise around it.
    assert!(
        stall.duration_s >= 200.0 && stall.duration_s <= 200.0 + 0.5 / CRUISE + DT,
        "{stall:?}"
    );
    assert_eq!(stall.giving_way_s, 0.0);
    let why = verdict(&r);
    assert_eq!(metrics(&why), ["progress"], "{why:?}");
}

/// A target from starboard crossing the route 4 m ahead of the stopped ship (at x = 23.5
/// m) westward at 0.05 m/s, on the route line at 490 s.
fn crossing_from_starboard() -> Target {
    Target {
        name: "crossing",
        at_t0: [23.5, 0.05 * 490.0],
        course_deg: 270.0,
        speed: 0.05,
    }
}

/// At cruise along the route, stopped from `from` s (at 300 s: x = 19.5 m) to `resume` s.
fn stop_between(from: f64, resume: f64) -> impl Fn(f64, [f64; 2]) -> (f64, f64, f64) + Copy {
    move |t, p| {
        if t > from && t <= resume {
            (0.0, 0.0, 0.0)
        } else {
            cruise(t, p)
        }
    }
}

#[test]
fn seamanship_stall_while_giving_way_is_excused_and_a_correct_give_way_passes() {
    let r = run(
        1000.0,
        stop_between(300.0, 500.0),
        no_offset,
        &[crossing_from_starboard()],
    );
    let stall = r.progress.longest_stall.expect("a stall");
    assert!(stall.duration_s >= 200.0, "{stall:?}");
    // Detection when tug 2 (x = 21.5) is within 7 m: y < sqrt(45) = 6.708 m, from 356 s;
    // past and clear at 490.5 s (the first step West of the route; 490 s if rounding puts
    // it West already): 269 steps open.
    assert!(
        stall.giving_way_s >= 134.0 && stall.giving_way_s <= 134.5,
        "{stall:?}"
    );
    let target = &r.rules.targets[0];
    assert_eq!(target.t_detect_s, Some(356.0));
    assert_eq!(target.situation.as_deref(), Some("crossing give-way"));
    assert_eq!(target.action.as_deref(), Some("way off"));
    let t_clear = target.t_past_and_clear_s.expect("past and clear");
    assert!(t_clear == 490.0 || t_clear == 490.5, "{t_clear}");
    assert_eq!(target.past_and_clear.as_deref(), Some("crossed ahead"));
    assert_eq!(target.given_up, None);
    assert!(target.crossed_ahead.is_none());
    let why = verdict(&r);
    assert!(why.is_empty(), "{why:?}");
}

#[test]
fn seamanship_give_way_given_up_before_the_target_is_past() {
    // Resumes at 450 s with the target 2 m East of the route, on the starboard bow.
    let r = run(
        1000.0,
        stop_between(300.0, 450.0),
        no_offset,
        &[crossing_from_starboard()],
    );
    let target = &r.rules.targets[0];
    let g = target.given_up.expect("given up");
    assert_eq!(g.t_s, 450.5);
    // Target at (23.5, 1.975), ship at (19.5 + 0.0325, 0).
    assert!(
        close(g.range_m, (4.0f64 - 0.0325).hypot(1.975), 1e-9),
        "{g:?}"
    );
    assert!(g.bearing_deg > 0.0 && g.bearing_deg < 45.0, "{g:?}");
    let why = verdict(&r);
    let rule8: Vec<&Reason> = why
        .iter()
        .filter(|r| r.metric == "rule8_past_and_clear")
        .collect();
    assert_eq!(rule8.len(), 1, "{why:?}");
    assert_eq!(rule8[0].target.as_deref(), Some("crossing"));
    assert_eq!(rule8[0].t_s, Some(450.5));
    // Tug 2 then crosses the target's course line ahead of it, at under 7 m.
    assert!(metrics(&why).contains(&"rule15_give_way"), "{why:?}");
}

/// Stopped from 300 s as [`stop_between`]; from 450 s at cruise again, bringing her head
/// round to starboard at 2 deg/s to `to_deg`.
fn resume_swinging(to_deg: f64) -> impl Fn(f64, [f64; 2]) -> (f64, f64, f64) {
    move |t, p| {
        if t > 450.0 {
            ((2.0 * (t - 450.0)).min(to_deg), CRUISE, 0.0)
        } else {
            stop_between(300.0, 450.0)(t, p)
        }
    }
}

#[test]
fn seamanship_gathering_way_while_altering_to_starboard_holds_the_give_way() {
    // Resumes at 450 s as before, but bringing her head round to starboard at 2 deg/s to
    // 30 deg: for the first 5 s she is neither 10 deg round nor stopped, and that is an
    // alteration under way, not the action given up. She passes astern of the target.
    let r = run(
        1000.0,
        resume_swinging(30.0),
        no_offset,
        &[crossing_from_starboard()],
    );
    let target = &r.rules.targets[0];
    assert_eq!(target.action.as_deref(), Some("way off"));
    assert_eq!(target.given_up, None, "{target:?}");
    assert!(target.t_past_and_clear_s.is_some(), "{target:?}");
    let why = verdict(&r);
    assert!(!metrics(&why).contains(&"rule8_past_and_clear"), "{why:?}");
    // The same resumption with the swing stopping at 5 deg is given up when the swing
    // ends (the head is neither 10 deg round nor still coming round).
    let r = run(
        1000.0,
        resume_swinging(5.0),
        no_offset,
        &[crossing_from_starboard()],
    );
    let g = r.rules.targets[0].given_up.expect("given up");
    assert!(g.t_s > 452.0 && g.t_s <= 453.0, "{g:?}");
}

#[test]
fn seamanship_waterway_excursion_of_1_m_for_50_s() {
    // Every corner 1 m beyond the half width from 200 s to 250 s (the hulls are 0.3 m
    // wide: centres at 5 + 1 - 0.15 m).
    let offset = |t: f64| {
        if t > 200.0 && t <= 250.0 {
            [0.0, HALF_WIDTH + 1.0 - 0.15]
        } else {
            [0.0, 0.0]
        }
    };
    let r = run(800.0, cruise, offset, &[]);
    let w = &r.waterway;
    assert!(close(w.max_excess_m.expect("judged"), 1.0, 1e-9), "{w:?}");
    assert_eq!(w.t_max_s, Some(200.5));
    assert_eq!(w.max_vessel.as_deref(), Some("ship"));
    assert!(close(w.time_outside_s, 50.0, 1e-9));
    // One grounding event per vessel, all three over the same 100 steps.
    assert_eq!(w.groundings.len(), 3, "{w:?}");
    assert_eq!(w.groundings_per_vessel, [1, 1, 1], "{w:?}");
    for (g, name) in w.groundings.iter().zip(["ship", "tug1", "tug2"]) {
        assert_eq!(g.vessel, name);
        assert_eq!((g.t_start_s, g.t_end_s, g.samples), (200.5, 250.0, 100));
    }
    assert_eq!(metrics(&verdict(&r)), ["waterway"; 3]);
}

#[test]
fn seamanship_no_waterway_gives_no_waterway_reason() {
    let offset = |_t: f64| [0.0, 20.0];
    let g = RunGeometry {
        half_width: None,
        ..geometry()
    };
    let mut s = Seamanship::new(&g, &Thresholds::default());
    let v = Vessel {
        y: offset(0.0)[1],
        ..Vessel::default()
    };
    s.push(&PlantStep {
        t: 0.0,
        vessels: [v; 3],
        obstacles: &[],
        control: None,
    });
    let r = s.finish();
    assert_eq!(r.waterway.note.as_deref(), Some("no waterway"));
    assert!(!metrics(&verdict(&r)).contains(&"waterway"));
}

#[test]
fn seamanship_going_astern() {
    let motion = |t: f64, p: [f64; 2]| {
        if t > 300.0 && t <= 340.0 {
            (0.0, -0.04, 0.0)
        } else {
            cruise(t, p)
        }
    };
    // 0.04 m/s astern: below the under-way speed, so no drift angle (180 deg) is counted.
    let r = run(900.0, motion, no_offset, &[]);
    assert_eq!(r.astern.min_surge_m_s, Some(-0.04));
    assert_eq!(r.astern.t_min_s, Some(300.5));
    assert!(close(r.astern.time_astern_s, 40.0, 1e-9));
    assert_eq!(metrics(&verdict(&r)), ["astern"]);
}

#[test]
fn seamanship_speed_over_ground_spike() {
    let motion = |t: f64, p: [f64; 2]| {
        if t > 300.0 && t <= 310.0 {
            (0.0, 2.0 * CRUISE, 0.0)
        } else {
            cruise(t, p)
        }
    };
    let r = run(800.0, motion, no_offset, &[]);
    assert!(close(r.speed.cruise_m_s.expect("under way"), CRUISE, 1e-4));
    assert!(
        close(r.speed.max_cruise_ratio.expect("ratio"), 2.0, 4e-3),
        "{:?}",
        r.speed
    );
    assert_eq!(r.speed.t_max_s, Some(300.5));
    assert_eq!(metrics(&verdict(&r)), ["speed"]);
}

/// A target from port crossing the route eastward at 0.05 m/s, on a collision course with
/// the ship at (26, 0) at 400 s.
fn crossing_from_port() -> Target {
    Target {
        name: "port",
        at_t0: [26.0, -0.05 * 400.0],
        course_deg: 90.0,
        speed: 0.05,
    }
}

#[test]
fn seamanship_stand_on_port_turn_for_a_port_target() {
    let port_turn = |t: f64, p: [f64; 2]| {
        if t > 300.0 {
            (-20.0, CRUISE, 0.0)
        } else {
            cruise(t, p)
        }
    };
    let r = run(600.0, port_turn, no_offset, &[crossing_from_port()]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("crossing stand-on"));
    assert!(close(
        target.port_turn_port_target_deg.expect("port side"),
        20.0,
        1e-9
    ));
    assert_eq!(target.t_port_turn_s, Some(300.5));
    let why = verdict(&r);
    let rule17: Vec<&Reason> = why
        .iter()
        .filter(|r| r.metric == "rule17_stand_on")
        .collect();
    assert!(
        rule17.iter().any(|r| r.message.contains("to port")),
        "{why:?}"
    );
    // Standing on: the same encounter without the turn gives no rule reason.
    let r = run(600.0, cruise, no_offset, &[crossing_from_port()]);
    assert_eq!(
        r.rules.targets[0].situation.as_deref(),
        Some("crossing stand-on")
    );
    assert!(
        !verdict(&r).iter().any(|r| r.metric.starts_with("rule")),
        "{:?}",
        verdict(&r)
    );
}

/// A target on the reciprocal course at cruise speed, `east` m off the route.
fn head_on(east: f64) -> Target {
    Target {
        name: "head-on",
        at_t0: [60.0, east],
        course_deg: 180.0,
        speed: CRUISE,
    }
}

/// Cruise, but with the heading at `deg` (deg, + starboard) from 395 s to 500 s: against
/// a `head_on` target, from just after detection (about 392 s, tug 2 within 7 m).
fn head_on_turn(deg: f64) -> impl Fn(f64, [f64; 2]) -> (f64, f64, f64) {
    move |t: f64, p: [f64; 2]| {
        if t > 395.0 && t <= 500.0 {
            (deg, CRUISE, 0.0)
        } else {
            cruise(t, p)
        }
    }
}

#[test]
fn seamanship_head_on_port_to_port_with_a_starboard_turn_passes() {
    // Detected at about 392 s (tug 2 within 7 m); 15 deg to starboard from 395 s to 500 s.
    let r = run(900.0, head_on_turn(15.0), no_offset, &[head_on(-0.3)]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("head-on"));
    assert!(target.beta_cpa_deg.expect("cpa") < 0.0);
    assert!(close(
        target.starboard_turn_to_cpa_deg.expect("cpa"),
        15.0,
        1e-9
    ));
    assert_eq!(
        target.past_and_clear.as_deref(),
        Some("abaft the beam, opening")
    );
    assert!(target.t_past_and_clear_s.expect("past") < 500.0);
    let why = verdict(&r);
    assert!(why.is_empty(), "{why:?}");
}

/// Head-on with the tow fine on the target's starboard bow (the target 0.3 m east of the
/// route, heading south): her 15 deg starboard alteration takes the forward tug and then
/// the ship across the target's course line ahead of it, to its port side, as Rule 14
/// asks; that crossing is no reason. A port alteration from its port bow crosses onto
/// its starboard side: that one is.
#[test]
fn seamanship_head_on_crossing_ahead_counts_only_onto_the_targets_starboard_side() {
    let r = run(900.0, head_on_turn(15.0), no_offset, &[head_on(0.3)]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("head-on"));
    let c = target.crossed_ahead.as_ref().expect("a crossing ahead");
    assert!(c.range_m < 7.0, "{c:?}");
    assert_eq!(target.crossed_ahead_to_starboard, None);
    assert!(target.beta_cpa_deg.expect("cpa") < 0.0);
    let why = verdict(&r);
    assert!(why.is_empty(), "{why:?}");

    let r = run(900.0, head_on_turn(-15.0), no_offset, &[head_on(-0.3)]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("head-on"));
    assert!(target.crossed_ahead_to_starboard.is_some());
    let why = verdict(&r);
    assert!(
        why.iter()
            .any(|r| r.metric == "rule14_head_on" && r.message.contains("crossed ahead")),
        "{why:?}"
    );
}

#[test]
fn seamanship_head_on_starboard_to_starboard_is_a_reason() {
    let r = run(900.0, cruise, no_offset, &[head_on(1.0)]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("head-on"));
    assert!(target.beta_cpa_deg.expect("cpa") > 0.0);
    let why = verdict(&r);
    assert!(
        why.iter()
            .any(|r| r.metric == "rule14_head_on" && r.message.contains("starboard to starboard")),
        "{why:?}"
    );
    assert!(metrics(&why).contains(&"rule16_action"), "{why:?}");
}

/// Along the route at cruise speed: 20 deg to starboard from 40 s to 100 s (1.33 m gained),
/// then parallel to the route, and from `back` s 20 deg to port for 60 s.
fn overtake_to_starboard(back: f64) -> impl Fn(f64, [f64; 2]) -> (f64, f64, f64) {
    move |t, p| {
        let psi = if (40.0..100.0).contains(&t) {
            20.0
        } else if (back..back + 60.0).contains(&t) {
            -20.0
        } else {
            0.0
        };
        (psi, if p[0] < 50.0 { CRUISE } else { 0.0 }, 0.0)
    }
}

#[test]
fn seamanship_an_offset_held_parallel_to_the_route_holds_the_overtaking_action() {
    // A slower target ahead on the route: the tow alters 20 deg to starboard, then runs
    // parallel to her route 1.33 m to starboard of it until she is past. Her head is
    // back on the route's course from 100 s, long before the target is abaft her beam:
    // the offset she keeps is her action (Rule 8(d)).
    let slow = || Target {
        name: "slow",
        at_t0: [10.0, 0.0],
        course_deg: 0.0,
        speed: 0.03,
    };
    let r = run(
        900.0,
        overtake_to_starboard(f64::INFINITY),
        no_offset,
        &[slow()],
    );
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("overtaking"));
    assert_eq!(target.action.as_deref(), Some("starboard alteration"));
    assert_eq!(target.given_up, None, "{target:?}");
    let passed = target.t_past_and_clear_s.expect("passed");
    assert!(passed > 200.0, "{target:?}");
    assert!(!metrics(&verdict(&r)).contains(&"rule8_past_and_clear"));
    // Turning back towards the route at 150 s, before the target is past: given up once
    // she has given back 0.3 m of the offset (0.022 m/s across the route: 13.6 s).
    let r = run(900.0, overtake_to_starboard(150.0), no_offset, &[slow()]);
    let g = r.rules.targets[0].given_up.expect("given up");
    assert!(g.t_s > 160.0 && g.t_s < 165.0, "{g:?}");
    assert!(metrics(&verdict(&r)).contains(&"rule8_past_and_clear"));
}

#[test]
fn seamanship_overtaking_too_close_is_a_reason() {
    // A slower target on the same course 0.5 m to starboard of the route: side by side,
    // the gap between the hulls (half widths 0.15 m) and the ellipse (semi-minor axis
    // 0.24 m) is 0.5 - 0.15 - 0.24 = 0.11 m.
    let slow = Target {
        name: "slow",
        at_t0: [10.0, 0.5],
        course_deg: 0.0,
        speed: 0.03,
    };
    let r = run(800.0, cruise, no_offset, &[slow]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("overtaking"));
    assert!(
        close(target.min_hull_clearance_m.expect("detected"), 0.11, 1e-9),
        "{target:?}"
    );
    let why = verdict(&r);
    assert!(
        why.iter()
            .any(|r| r.metric == "rule13_overtaking" && r.message.contains("clearance")),
        "{why:?}"
    );
    // Kept its course and speed: no give-way action either.
    assert!(metrics(&why).contains(&"rule16_action"), "{why:?}");
    // 1 m to starboard instead: 0.61 m, no clearance reason.
    let wide = Target {
        name: "wide",
        at_t0: [10.0, 1.0],
        course_deg: 0.0,
        speed: 0.03,
    };
    let r = run(800.0, cruise, no_offset, &[wide]);
    assert!(close(
        r.rules.targets[0].min_hull_clearance_m.expect("detected"),
        0.61,
        1e-9
    ));
    assert!(!verdict(&r).iter().any(|r| r.message.contains("clearance")));
}

#[test]
fn seamanship_own_turn_is_not_the_target_crossing_ahead() {
    // Head-on, the target 0.05 m to starboard of the route: the tow's 15 deg starboard
    // turn puts it on the port side of the ship's heading line, but by the ship's motion,
    // not the target's, so it is not past and clear until it is abaft the beam.
    let r = run(900.0, head_on_turn(15.0), no_offset, &[head_on(0.05)]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("head-on"));
    assert_eq!(
        target.past_and_clear.as_deref(),
        Some("abaft the beam, opening"),
        "{target:?}"
    );
    assert!(
        target.t_past_and_clear_s.expect("past") > 450.0,
        "{target:?}"
    );
    // Not given up. The turn swings tug 2 (2 m ahead of the ship) across the target's
    // course line ahead of it, within 7 m of it, onto its port side: the port-to-port
    // side Rule 14 asks for, so no reason.
    let c = target.crossed_ahead.as_ref().expect("tug 2 crossed");
    assert_eq!(c.vessel, "tug2");
    assert_eq!(target.crossed_ahead_to_starboard, None);
    let why = verdict(&r);
    assert!(why.is_empty(), "{why:?}");
}

#[test]
fn seamanship_a_head_on_target_crossing_the_heading_line_ahead_is_not_past_until_abaft_the_beam() {
    // Regression (paper run, target C): a head-on target moves along the tow's track, so
    // its side of the ship's heading line changes with a small lateral drift of either
    // vessel; that was read as "crossed ahead", past and clear 20 s before the alteration.
    // Here the target drifts across the line ahead, 0.3 m to port to 0.4 m to starboard.
    let drifting = Target {
        name: "head-on",
        at_t0: [60.0, -0.3],
        course_deg: 178.0,
        speed: CRUISE,
    };
    let r = run(900.0, cruise, no_offset, &[drifting]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("head-on"));
    assert_eq!(
        target.past_and_clear.as_deref(),
        Some("abaft the beam, opening")
    );
    let (t_clear, t_cpa) = (
        target.t_past_and_clear_s.expect("past"),
        target.t_cpa_s.expect("cpa"),
    );
    assert!(
        t_clear >= t_cpa - 1.0,
        "past and clear at {t_clear} s, CPA at {t_cpa} s"
    );
}

#[test]
fn seamanship_a_crossing_seen_before_detection_counts_at_detection() {
    // Regression (random-12-0043): a target crossed the stopped tow's heading line 10 m
    // ahead by its own motion before any vessel of the tow was within 7 m of it; it then
    // drew away to port, and was never judged crossed, so the give-way action released
    // after its CPA read as given up. Here the tow stops at 300 s (x = 19.5 m); the
    // target, west-south-westbound at 0.05 m/s, crosses the route at x = 30 m at 330 s
    // (8.4 m from tug 2) and comes within 7 m of tug 2 about 34 s later.
    let crossed_early = Target {
        name: "crossed early",
        at_t0: [
            30.0 + 0.05 * 330.0 * 30f64.to_radians().cos(),
            0.05 * 330.0 * 0.5,
        ],
        course_deg: 210.0,
        speed: 0.05,
    };
    let r = run(
        600.0,
        stop_between(300.0, 2000.0),
        no_offset,
        &[crossed_early],
    );
    let target = &r.rules.targets[0];
    let t_detect = target.t_detect_s.expect("detected");
    assert!(t_detect > 340.0, "{t_detect}");
    assert_eq!(
        target.past_and_clear.as_deref(),
        Some("crossed ahead before detection")
    );
    assert_eq!(target.t_past_and_clear_s, Some(t_detect));
}

#[test]
fn seamanship_a_target_gone_beyond_detection_and_drawing_away_is_past() {
    // Regression (random-12-0038, -0042, -0050): a crossing target from starboard, which
    // the tow let pass by turning 30 deg to starboard and stopping; the turn, not the
    // target, swept the heading line across it, so it never "crossed ahead". It then
    // drew away to port, beyond 7 m of every vessel, still forward of the beam; the
    // guidance released the action as the target had left the encounter, and the
    // instrument judged it a give-up. Here the target, westbound at 0.05 m/s, is 6.4 m
    // off on the starboard bow (20 deg) when the tow turns at 295-310 s.
    let crossing = || Target {
        name: "crossing",
        at_t0: [25.5, 2.2 + 0.05 * 300.0],
        course_deg: 270.0,
        speed: 0.05,
    };
    let turn_and_stop = |resume: f64| {
        move |t: f64, p: [f64; 2]| {
            if t > 295.0 && t <= resume {
                (((t - 295.0) * 2.0).min(30.0), 0.0, 0.0)
            } else {
                cruise(t, p)
            }
        }
    };
    // Resumed at 500 s: the target has been beyond 7 m of tug 2 (the nearest vessel)
    // since about 442 s, 52 deg on the port bow of the ship then, drawing away.
    let r = run(800.0, turn_and_stop(500.0), no_offset, &[crossing()]);
    let target = &r.rules.targets[0];
    assert_eq!(target.situation.as_deref(), Some("crossing give-way"));
    assert_eq!(
        target.past_and_clear.as_deref(),
        Some("gone beyond the detection distance, drawing away"),
        "{target:?}"
    );
    let t_clear = target.t_past_and_clear_s.expect("past");
    assert!((430.0..=460.0).contains(&t_clear), "{t_clear}");
    assert!(target.given_up.is_none(), "{target:?}");
    assert!(!metrics(&verdict(&r)).contains(&"rule8_past_and_clear"));
    // Resumed at 400 s, with the target 6.6 m off the ship and nearer the forward tug:
    // still in the encounter, and the release is a give-up.
    let r = run(800.0, turn_and_stop(400.0), no_offset, &[crossing()]);
    let target = &r.rules.targets[0];
    assert!(target.given_up.is_some(), "{target:?}");
    assert!(metrics(&verdict(&r)).contains(&"rule8_past_and_clear"));
}

#[test]
fn seamanship_rule_17_allows_action_by_the_cpa_before_detection() {
    // Regression (random-12-0012): the guidance acts for a stand-on target by its CPA,
    // wherever it is; the tow took her way off at a TCPA of about 52 s, 2 s before her
    // forward tug came within 7 m, and the instrument, looking for Rule 17's TCPA only
    // from detection, found it pushed back over 60 s by her own braking and held her to
    // her course and speed. Here a target from the port bow (course 150 deg, 0.12 m/s)
    // is on a collision course with the cruising tow (CPA at x = 30 m, 461.5 s); the tow
    // stops at a TCPA of 55 s (406.5 s, the forward tug 8 m off), the forward tug comes
    // within 7 m about 8.5 s later (the TCPA then 72 s) and she turns 21 deg to
    // starboard at 417-424 s.
    let t_cpa = 30.0 / CRUISE;
    let (s, c) = 150f64.to_radians().sin_cos();
    let target = Target {
        name: "from port",
        at_t0: [30.0 - 0.12 * c * t_cpa, -0.12 * s * t_cpa],
        course_deg: 150.0,
        speed: 0.12,
    };
    let stop_and_turn = move |t: f64, p: [f64; 2]| {
        if t > t_cpa - 55.0 {
            (((t - 417.0) * 3.0).clamp(0.0, 21.0), 0.0, 0.0)
        } else {
            cruise(t, p)
        }
    };
    let r = run(600.0, stop_and_turn, no_offset, &[target]);
    let target = &r.rules.targets[0];
    assert_eq!(
        target.situation.as_deref(),
        Some("crossing stand-on"),
        "{target:?}"
    );
    let (t_detect, t_rule17) = (
        target.t_detect_s.expect("detected"),
        target.t_rule17_s.expect("rule 17"),
    );
    assert!((410.0..=417.0).contains(&t_detect), "{target:?}");
    assert!((t_rule17 - (t_cpa - 60.0)).abs() <= 0.5, "{target:?}");
    assert!(target.t_stand_on_broken_s.is_none(), "{target:?}");
    assert!(!metrics(&verdict(&r)).contains(&"rule17_stand_on"));
}

#[test]
fn seamanship_a_stand_on_departure_made_while_acting_for_another_target_is_excused() {
    // Two targets (random-12-0296 is of this kind): one from starboard the tow gives way
    // to (on the route line at x = 30 m at 461.5 s), one from port she stands on for
    // (eastward at 0.02 m/s along x = 27 m, TCPA over 60 s until about 590 s). She slows
    // to 40 % of cruise at 360 s for the first (her give-way action, detected at about
    // 358 s, past and clear at about 462 s) and resumes at 480 s: a lawful action for
    // the first is no breach of the stand-on duty to the second (Rule 2(b)).
    let give_way = || Target {
        name: "starboard",
        at_t0: [30.0, 0.05 * 30.0 / CRUISE],
        course_deg: 270.0,
        speed: 0.05,
    };
    let stand_on = || Target {
        name: "port",
        at_t0: [27.0, -0.02 * 660.0],
        course_deg: 90.0,
        speed: 0.02,
    };
    // Slow at 360 s to 40 % of cruise, to `later` of it from 470 s, cruise from 480 s.
    let slow = |later: f64| {
        move |t: f64, p: [f64; 2]| {
            if t > 360.0 && t <= 470.0 {
                (0.0, 0.4 * CRUISE, 0.0)
            } else if t > 470.0 && t <= 480.0 {
                (0.0, later * CRUISE, 0.0)
            } else {
                cruise(t, p)
            }
        }
    };
    let broken = |r: &SeamanshipReport| {
        let port = r
            .rules
            .targets
            .iter()
            .find(|t| t.target == "port")
            .expect("port");
        assert_eq!(
            port.situation.as_deref(),
            Some("crossing stand-on"),
            "{port:?}"
        );
        assert!(port.t_detect_s.is_some_and(|t| t < 360.0), "{port:?}");
        assert!(port.t_rule17_s.is_none_or(|t| t > 480.0), "{port:?}");
        port.t_stand_on_broken_s
    };
    // Alone, the port target's stand-on is broken by the slowing.
    let r = run(700.0, slow(0.4), no_offset, &[stand_on()]);
    let t = broken(&r).expect("broken");
    assert!((360.0..=361.0).contains(&t), "{t}");
    assert!(metrics(&verdict(&r)).contains(&"rule17_stand_on"));
    // With the give-way target, the same slowing is its action: excused.
    let r = run(700.0, slow(0.4), no_offset, &[give_way(), stand_on()]);
    let starboard = &r.rules.targets[0];
    assert_eq!(starboard.situation.as_deref(), Some("crossing give-way"));
    assert_eq!(starboard.action.as_deref(), Some("way off"));
    let clear = starboard.t_past_and_clear_s.expect("past and clear");
    assert!((455.0..470.0).contains(&clear), "{starboard:?}");
    assert_eq!(broken(&r), None);
    let port = &r.rules.targets[1];
    assert_eq!(port.stand_on_excused_by.as_deref(), Some("starboard"));
    assert!(
        !metrics(&verdict(&r)).contains(&"rule17_stand_on"),
        "{:?}",
        verdict(&r)
    );
    // Slowing further once the give-way target is past is a departure of her own.
    let r = run(700.0, slow(0.2), no_offset, &[give_way(), stand_on()]);
    let t = broken(&r).expect("broken");
    assert!((470.0..=471.0).contains(&t), "{t}");
    assert!(metrics(&verdict(&r)).contains(&"rule17_stand_on"));
}

#[test]
fn seamanship_a_give_way_action_taken_by_the_cpa_before_detection_excuses_the_stand_on() {
    // Regression (random-12-0009, centralized): the guidance gives way by Rule 17's CPA
    // test as well as by d_D, and took her way off for a fast crossing target from
    // starboard 30 s before any vessel of the tow was within 7 m of it; the instrument
    // opened that give-way duty only at detection and held the slowing against her
    // stand-on duty to a slow target from port. Here the starboard target (0.25 m/s) is
    // on a collision course with the tow (both at x = 24 m at 369.2 s, TCPA 60 s at
    // 309.2 s, range from the forward tug then 15 m); she stops at 310 s and resumes at
    // 380 s, after it crossed ahead. The port target (eastward at 0.01 m/s along
    // x = 25 m) is detected at about 282 s, with a TCPA over 60 s until after 380 s.
    let t_cross = 24.0 / CRUISE;
    let give_way = || Target {
        name: "starboard",
        at_t0: [24.0, 0.25 * t_cross],
        course_deg: 270.0,
        speed: 0.25,
    };
    let stand_on = || Target {
        name: "port",
        at_t0: [25.0, -8.0],
        course_deg: 90.0,
        speed: 0.01,
    };
    let stop = stop_between(310.0, 380.0);
    // The controller reads the starboard target (slot 1) as crossing give-way from 310 s.
    let controller = |t: f64| {
        Some(ControlSample {
            t,
            altered: false,
            active_waypoint: 1,
            encounters: vec![ControlEncounter {
                slot: 1,
                situation: (t >= 310.0).then_some(Situation::CrossingGiveWay),
                role_code: if t >= 310.0 { 1 } else { 0 },
            }],
        })
    };
    let port = |r: &SeamanshipReport| {
        let port = r.rules.targets.iter().find(|t| t.target == "port");
        port.expect("port").clone()
    };
    // Judged from detection only (no controller log): the stop breaks the stand-on.
    let r = run(700.0, stop, no_offset, &[give_way(), stand_on()]);
    let starboard = &r.rules.targets[0];
    let t_detect = starboard.t_detect_s.expect("detected");
    assert!((335.0..350.0).contains(&t_detect), "{starboard:?}");
    let p = port(&r);
    let t = p.t_stand_on_broken_s.unwrap_or_else(|| panic!("{p:?}"));
    assert!((310.0..=311.0).contains(&t), "{t}");
    assert!(metrics(&verdict(&r)).contains(&"rule17_stand_on"));
    // The controller gave way by the CPA: the stop is that action, excused from 310 s.
    let r = run_controlled(
        700.0,
        stop,
        no_offset,
        &[give_way(), stand_on()],
        controller,
    );
    let p = port(&r);
    assert_eq!(p.situation.as_deref(), Some("crossing stand-on"), "{p:?}");
    assert_eq!(p.t_stand_on_broken_s, None, "{p:?}");
    assert_eq!(p.stand_on_excused_by.as_deref(), Some("starboard"), "{p:?}");
    assert!(p.t_stand_on_excused_s.is_some_and(|t| t < 312.0), "{p:?}");
    assert!(!metrics(&verdict(&r)).contains(&"rule17_stand_on"));
}

#[test]
fn seamanship_a_target_drawing_ahead_along_the_heading_line_is_gone() {
    // Rule 8(d), "gone": a target whose track runs parallel to the ship's heading line
    // never meets it. Until 2026-12-07 the test asked that the target's own velocity
    // carry it away from the line on its side, which a target on a parallel course does
    // not, so a tow that stopped for a slower vessel she was overtaking and let it draw
    // ahead was judged to have given up when she went on. Here the target, 0.3 m to
    // starboard of the route, northbound at 0.04 m/s, is overtaken by the tow at cruise
    // (0.065 m/s); the tow stops from 140 s to 300 s.
    let ahead = Target {
        name: "ahead",
        at_t0: [12.0, 0.3],
        course_deg: 0.0,
        speed: 0.04,
    };
    let stop = stop_between(140.0, 300.0);
    let r = run(600.0, stop, no_offset, &[ahead]);
    let target = &r.rules.targets[0];
    assert_eq!(
        target.situation.as_deref(),
        Some("overtaking"),
        "{target:?}"
    );
    assert!(target.t_detect_s.is_some_and(|t| t < 140.0), "{target:?}");
    assert_eq!(
        target.past_and_clear.as_deref(),
        Some("gone beyond the detection distance, drawing away"),
        "{target:?}"
    );
    let t_clear = target.t_past_and_clear_s.expect("past");
    assert!((140.0..300.0).contains(&t_clear), "{t_clear}");
    assert!(target.given_up.is_none(), "{target:?}");
    assert!(!metrics(&verdict(&r)).contains(&"rule8_past_and_clear"));
}

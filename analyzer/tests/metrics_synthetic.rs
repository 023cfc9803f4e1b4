//! Every metric on synthetic runs with a known answer, through the whole pipeline (MCAP
//! logs written with towing_log::LogWriter, read back, frames, analysis).

mod common;

use common::{analyze_run, hazard, straight, target};

#[test]
fn settling_elongation_and_travel_are_known() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 30 m at 0.1 m/s: arrives at 300 s, log to 350 s.
    let mut run = straight(30.0, 0.1, 3500);
    run.elongation = [0.0579, 0.0633];
    let m = &analyze_run(&run, dir.path());
    let expected = run.expected_settling_time().expect("arrives");
    assert!((expected - 300.0).abs() < 1e-9);
    let ts = m.settling.settling_time_s.expect("settles");
    assert!((ts - expected).abs() < 1e-6, "settling {ts} vs {expected}");
    let e = m.elongation.max_towline_elongation_error;
    assert!((e[0].expect("line 1") - 0.0579).abs() < 1e-9, "{e:?}");
    assert!((e[1].expect("line 2") - 0.0633).abs() < 1e-9, "{e:?}");
    assert!(
        (m.travel.ship_travel_m - 30.0).abs() < 1e-6,
        "{}",
        m.travel.ship_travel_m
    );
    assert_eq!(m.collisions.collisions, 0);
    assert!(!m.run.truncated);
    assert_eq!(
        m.run.architecture.as_ref().map(|a| a.name.as_str()),
        Some("distributed")
    );
    assert_eq!(m.run.scheme.as_ref().map(|s| s.name.as_str()), Some("I"));
    // Control statistics of the synthetic solver: iterations 10 + (7 k mod 21).
    let it = m.solver.admm_iterations.expect("iterations");
    assert_eq!(it.max, 30.0);
    assert_eq!(m.run.control_samples, 351);
}

#[test]
fn never_settles_when_the_log_ends_early() {
    let dir = tempfile::tempdir().expect("tempdir");
    let run = straight(30.0, 0.1, 2000);
    let m = analyze_run(&run, dir.path());
    assert!(m.settling.settling_time_s.is_none());
    // Travel is what was covered: 200 s at 0.1 m/s.
    assert!((m.travel.ship_travel_m - 20.0).abs() < 1e-6);
}

#[test]
fn head_on_pass_at_a_known_distance_on_port() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Own ship North at 0.1 m/s along y = 0; a target South at 0.07 m/s along y = -1.5:
    // it passes 1.5 m off, on the ship's port side, when both are at x = 40/0.17*0.1
    // (head-on by Woerner's 13 deg from a range of 6.8 m).
    let mut run = straight(60.0, 0.1, 4000);
    run.obstacles = vec![target("C", 40.0, -1.5, 180.0, 0.07)];
    let m = &analyze_run(&run, dir.path());
    let enc = m.colregs.colregs.first().expect("one encounter");
    assert_eq!(enc.target, "C");
    assert!((enc.r_cpa_m - 1.5).abs() < 2e-3, "{}", enc.r_cpa_m);
    assert!((enc.t_cpa_s - 40.0 / 0.17).abs() < 0.11, "{}", enc.t_cpa_s);
    assert_eq!(enc.side, "port");
    assert_eq!(enc.situation.as_deref(), Some("head-on"));
    // The kinematic tow keeps its course: port to port, but no give-way action.
    assert_eq!(enc.verdict, "violation");
    assert_eq!(enc.reasons.len(), 1, "{:?}", enc.reasons);
    assert!(enc.reasons[0].contains("no give-way action"));
    let d = &m.distances.normalized_min_distance[0];
    assert_eq!(d.obstacle, "C");
    assert_eq!(d.encounter, "head-on");
    let ship = &d.vessels["ship"];
    assert!((ship.min_distance_m - 1.5).abs() < 2e-3);
    assert!((ship.normalized - ship.min_distance_m / 1.255).abs() < 1e-12);
    // The tugs are ahead and behind on the same line: the same lateral offset.
    assert!((d.vessels["tug1"].normalized - d.vessels["tug1"].min_distance_m / 0.97).abs() < 1e-12);
    assert!((d.vessels["tug2"].min_distance_m - 1.5).abs() < 2e-3);
    // Mirrored to starboard: starboard-to-starboard, a violation.
    let dir2 = tempfile::tempdir().expect("tempdir");
    run.obstacles = vec![target("C", 40.0, 1.5, 180.0, 0.07)];
    let b = analyze_run(&run, dir2.path());
    let enc = &b.colregs.colregs[0];
    assert_eq!(enc.side, "starboard");
    assert_eq!(enc.verdict, "violation");
    assert!(enc
        .reasons
        .iter()
        .any(|r| r.contains("starboard to starboard")));
}

#[test]
fn a_hazard_on_the_track_is_a_collision_of_each_vessel() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut run = straight(30.0, 0.1, 3500);
    run.obstacles = vec![hazard("a", 15.0, 0.0), hazard("far", 15.0, 5.0)];
    let m = &analyze_run(&run, dir.path());
    // Ship, tug 1 and tug 2 each drive through "a" once; "far" (4.5 m clear) never.
    assert_eq!(
        m.collisions.collisions, 3,
        "{:?}",
        m.collisions.collision_events
    );
    for v in ["ship", "tug1", "tug2"] {
        let e = m
            .collisions
            .collision_events
            .iter()
            .find(|e| e.a == v && e.b == "a")
            .expect("event");
        // Overlap while |x - 15| < L/2 + 0.5: the ship's lasts (1.255/2 + 0.5) * 2 / 0.1 s.
        if v == "ship" {
            let dur = e.t_end_s - e.t_start_s;
            assert!((dur - (0.6275 + 0.5) * 2.0 / 0.1).abs() < 0.25, "{dur}");
        }
    }
    assert!(m.collisions.collision_events.iter().all(|e| e.b != "far"));
    let far = m
        .distances
        .normalized_min_distance
        .iter()
        .find(|o| o.obstacle == "far")
        .expect("far");
    assert!((far.vessels["ship"].min_distance_m - 5.0).abs() < 1e-9);
    assert_eq!(far.encounter, "static hazard");
}

#[test]
fn a_tension_spike_violates_the_bound_and_the_rate() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut run = straight(30.0, 0.1, 1000);
    run.tension_spike_at_sample = Some(50);
    let m = analyze_run(&run, dir.path());
    let b = &m.bounds.bound_violations.report;
    // Both lines at 3.5 N at sample 50: 2 bound violations; rates into and out of it.
    assert_eq!(b.tension.count, 2, "{b:?}");
    assert!((b.tension.worst_excess - 0.5).abs() < 1e-9);
    assert_eq!(b.tension_rate.count, 4);
    assert!((b.tension.first_t_s.expect("first") - 50.0).abs() < 1e-6);
    assert_eq!(b.towing_angle.count + b.towing_angle_rate.count, 0);
    assert_eq!(b.tug_thrust_command.count + b.tug_thrust_input.count, 0);
}

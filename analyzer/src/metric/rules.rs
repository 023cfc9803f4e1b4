//! COLREGS rule checks per target ship, own ship being the towed ship (the tow's COLREGS
//! identity, docs/colregs.md).
//!
//! Detection is the first step at which any vessel of the tow (ship, tugs) is within the
//! detection distance `d_D` of the target (eq. (8): the guidance detects by the nearest
//! vessel). The situation is classified there from the geometry
//! ([`crate::colregs::classify`], Woerner preset); the controller's first definite
//! situation for the slot (neither safe nor unclassified, `step.control`) is recorded too.
//! The checks use the controller's when it has one, else the geometric one, and the report
//! says which. Every check is measured for every target from its detection (O(1) state per
//! target); the situation picks the ones that count at the verdict ([`reasons`]). Course
//! changes ("turn", "course") are the heading's change less the route's own change
//! ([`RouteCourse`]: Rule 17's "course" is that of the manoeuvre the tow is engaged in, so
//! rounding a bend of the route is no alteration, to port or to starboard):
//!
//! - give-way (Rule 16; head-on, crossing give-way, overtaking): action before the CPA, a
//!   course alteration of at least `give_way_turn_deg` to starboard from the heading at
//!   detection or the way off (surge <= `way_off_surge_m_s`); held until the target is
//!   past and clear (Rule 8(d)), else "given up" (`rule8_past_and_clear`); a head to
//!   starboard of its detection heading still coming round at `give_way_turn_rate_deg_s`
//!   or more holds it too (the tow gathering way as she alters), and so does, once she
//!   has altered, the offset to starboard of her route gained since detection, while she
//!   gives back no more than `give_way_offset_m` of it and more than that remains (a tow
//!   steadied on a track parallel to her route keeps her action);
//! - no vessel of the tow crosses ahead of a give-way target closer than
//!   `cross_ahead_min_m` (Rule 15: "avoid crossing ahead"; the same check for overtaking
//!   under Rule 13; head-on, only a crossing onto the target's starboard side counts,
//!   since Rule 14's starboard alteration takes a tow lying fine on the target's
//!   starboard bow across its course line to its port side);
//! - head-on (Rule 14): a starboard alteration of at least `head_on_turn_deg` before the
//!   CPA and a port-to-port pass (the target on the ship's port side at the CPA);
//! - stand-on (Rule 17; crossing stand-on, being overtaken): until Rule 17(a)(ii) allows
//!   action (TCPA <= `rule17_tcpa_s`, from the first step the target is present: before
//!   detection with a DCPA within `d_detect` too), heading within `stand_on_course_deg` and speed over
//!   ground at least `stand_on_speed_fraction` of their values at detection, except while
//!   the tow owes another target an action (gives way to it, or Rule 17 lets her act for
//!   it, until it is past and clear): the rules bind pairwise and a lawful action for one
//!   vessel is no breach of the stand-on duty to another (Rule 2(b)); what that action
//!   left (the largest course change, the least speed) widens the limits afterwards, so
//!   she may come back from it but not depart further; Rule 17(c):
//!   never a port turn of more than `port_turn_max_deg` while the target is on the port
//!   side, until it is past and clear;
//! - overtaking (Rule 13): hull clearance of every vessel of the tow from the target at
//!   least `overtaking_clearance_m` ([`hull_ellipse_clearance`]).
//!
//! Past and clear (Rule 8(d)) is judged from the target's own motion relative to the tow,
//! never from a range opened by the tow's braking: in a crossing, the target has crossed
//! the ship's heading line ahead of the ship by its own motion (between two steps it went
//! from one side of the line to the other and is ahead of the ship, and its own
//! displacement across the earlier step's line, held still, is at least half of the change
//! of its side, [`crate::geometry::crossed_ahead`]: neither the tow's turn nor its sideways
//! motion alone makes the crossing, and the verdict does not depend on the step size); in
//! any situation, it is abaft the ship's
//! beam with the range opening ([`crate::geometry::abaft_and_opening`], the test by which
//! the controller lets a passed target go) while the tow makes way (surge >
//! `way_off_surge_m_s`), or
//! it has gone: beyond `d_detect` of every vessel of the tow and drawing away
//! ([`crate::geometry::drawing_away`]: its own velocity opens the range from the ship and
//! its track no longer meets her heading line ahead of her; the range
//! is the target's doing, not the tow's braking: a crossing target the tow let pass by
//! turning away from it and stopping, which the guidance releases once it has left the
//! encounter distance, `docs/colregs.md`). A
//! crossing seen before detection counts at detection if the target has kept drawing away
//! from the heading line since ("crossed ahead before detection": it crossed ahead of the
//! ship by its own motion before any vessel of the tow was within `d_detect`). A
//! head-on or overtaking target moves along the tow's track, not across it: its side of the
//! heading line changes with a wobble of either vessel, so only the last two tests apply.

use serde::{Deserialize, Serialize};

use super::{FinishContext, Metric, Metrics, ReportPart, RunContext, Shared, StepFacts};
use crate::doc::Block;
use crate::error::Result;

use crate::colregs::{classify, Situation};
use crate::geometry::{
    abaft_and_opening, course_line_crossing, course_velocity, cpa_tcpa, crossed_ahead, dist,
    drawing_away, hull_ellipse_clearance, line_coordinates, relative_bearing, wrap, RouteCourse,
    Track,
};
use crate::rows::VESSELS;
use crate::step::{Obstacle, ObstacleKind, PlantStep, RunGeometry, Vessel};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// Which situation the checks used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SituationSource {
    /// The controller's first definite situation for the slot.
    Controller,
    /// The analyzer's classification at the tow's detection.
    Geometric,
}

/// The tow's give-way action was released before the target was past and clear.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GiveUp {
    /// Time of the release, s.
    pub t_s: f64,
    /// Range ship to target then, m.
    pub range_m: f64,
    /// Bearing of the target from the ship's bow then, deg (+ starboard).
    pub bearing_deg: f64,
}

/// A vessel of the tow crossed the target's course line ahead of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossAhead {
    /// Time, s.
    pub t_s: f64,
    /// The vessel (`ship`, `tug1`, `tug2`).
    pub vessel: String,
    /// Its range to the target then, m.
    pub range_m: f64,
}

/// The checks of one target ship.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetRules {
    /// Target name (scenario).
    pub target: String,
    /// Obstacle slot, 1-based.
    pub slot: u32,
    /// The tow's detection (any vessel within `d_D`), s; `None`: never detected.
    pub t_detect_s: Option<f64>,
    /// Range ship to target at detection, m.
    pub range_detect_m: Option<f64>,
    /// The geometric situation at detection.
    pub situation_geometric: Option<String>,
    /// The controller's first definite situation for the slot.
    pub situation_controller: Option<String>,
    /// The role the controller reported with it (`give-way`, `stand-on`).
    pub role_controller: Option<String>,
    /// The situation the checks used.
    pub situation: Option<String>,
    /// Where it came from.
    pub situation_source: Option<SituationSource>,
    /// Time of the CPA (least ship-target centre range from detection on), s.
    pub t_cpa_s: Option<f64>,
    /// Range at the CPA, m.
    pub r_cpa_m: Option<f64>,
    /// Bearing of the target from the ship's bow at the CPA, deg (+ starboard).
    pub beta_cpa_deg: Option<f64>,
    /// Largest heading change to starboard from detection up to the CPA, deg.
    pub starboard_turn_to_cpa_deg: Option<f64>,
    /// First give-way action (starboard alteration or way off), s.
    pub t_action_s: Option<f64>,
    /// What it was (`starboard alteration`, `way off`).
    pub action: Option<String>,
    /// When the target became past and clear, s.
    pub t_past_and_clear_s: Option<f64>,
    /// How (`crossed ahead`, `abaft the beam, opening`).
    pub past_and_clear: Option<String>,
    /// The first release of the action before the target was past and clear.
    pub given_up: Option<GiveUp>,
    /// The first crossing ahead of the target closer than `cross_ahead_min_m`.
    pub crossed_ahead: Option<CrossAhead>,
    /// The first of those onto the target's starboard side (the side of a
    /// starboard-to-starboard pass; the only one head-on counts, Rule 14).
    pub crossed_ahead_to_starboard: Option<CrossAhead>,
    /// When Rule 17 allowed the stand-on vessel to act (TCPA <= `rule17_tcpa_s`; before
    /// detection also with the DCPA within `d_detect`), s.
    pub t_rule17_s: Option<f64>,
    /// Largest heading change before then, deg (outside the steps excused, below).
    pub stand_on_course_change_deg: Option<f64>,
    /// Least speed over ground before then, as a fraction of its value at detection
    /// (outside the steps excused, below).
    pub stand_on_speed_fraction: Option<f64>,
    /// First time the stand-on course or speed bound was broken before then, s.
    pub t_stand_on_broken_s: Option<f64>,
    /// The first other target the tow owed an action to while she stood on for this one
    /// (give-way from its detection, or Rule 17 action allowed, until it was past and
    /// clear): her course and speed were not judged for this target while she did, and
    /// afterwards only a departure beyond what that action left counts (Rule 2(b)).
    pub stand_on_excused_by: Option<String>,
    /// When that began, s.
    pub t_stand_on_excused_s: Option<f64>,
    /// Largest port turn (from the heading at detection) while the target was on the port
    /// side, before it was past and clear, deg.
    pub port_turn_port_target_deg: Option<f64>,
    /// Its time, s.
    pub t_port_turn_s: Option<f64>,
    /// Least hull clearance of any vessel of the tow from the target after detection, m.
    pub min_hull_clearance_m: Option<f64>,
    /// Its time, s.
    pub t_min_hull_clearance_s: Option<f64>,
}

/// The rule checks of every target ship, in order of first appearance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct RulesReport {
    /// One entry per target ship.
    pub targets: Vec<TargetRules>,
}

/// The state at the tow's detection.
#[derive(Debug, Clone, Copy)]
struct Detection {
    /// The ship's heading less the route's course ([`RouteCourse`]), rad: course changes
    /// are measured from it.
    off_course: f64,
    /// The ship's offset to starboard of her route ([`RouteCourse::track`]), m:
    /// the offset an alteration gains is measured from it.
    cross_track: f64,
    sog: f64,
    geometric: Situation,
}

/// The state of one target's checks.
#[derive(Debug, Clone)]
struct Target {
    r: TargetRules,
    present: bool,
    det: Option<Detection>,
    controller: Option<Situation>,
    stbd_max: f64,
    /// The largest offset to starboard of her route gained since detection, m.
    offset_max: f64,
    acting: bool,
    /// The ship's position and heading, and the target's position, at the previous step.
    prev_pose: Option<([f64; 2], f64, [f64; 2])>,
    /// Before detection: the side of the ship's heading line (+ starboard) the target
    /// crossed to ahead of her by its own motion, while it keeps drawing away from
    /// that line ([`Target::watch_crossing`]).
    crossed_before: Option<f64>,
    /// Before detection: the risk test ([`Target::watch_rule17`]) has held and the target
    /// is not drawing away at this step.
    risk_before_detection: bool,
    /// Each vessel's last side (non-zero) of the target's course line.
    prev_cross: [Option<f64>; 3],
    /// The other target (its index among the tracker's) the tow owes an action to at
    /// this step ([`Target::owes_action`]); set by [`RulesTracker::push`] before the checks.
    excused_by: Option<usize>,
    /// The first of those that excused a stand-on check (its name goes to the report).
    excused_first: Option<usize>,
    /// The stand-on bounds left by the tow's actions for other targets: the largest
    /// course change (deg) and the least speed fraction reached while excused.
    relief: Option<(f64, f64)>,
}

/// Own vessels with the sizes, as the checks need them.
type Tow<'s> = (&'s [Vessel; 3], &'s [[f64; 2]; 3]);

/// The target's side of the ship's heading line and its own velocity across that line
/// (both + starboard): it draws away from the line when their product is positive.
fn side_and_drift(ship: &Vessel, o: &Obstacle) -> (f64, f64) {
    let (_, side) = line_coordinates([ship.x, ship.y], ship.psi, [o.x, o.y]);
    let (_, drift) = line_coordinates([0.0, 0.0], ship.psi, course_velocity(o.course, o.speed));
    (side, drift)
}

/// Whether any vessel of the tow is within `d` of the point `p`.
fn any_within(vessels: &[Vessel; 3], p: [f64; 2], d: f64) -> bool {
    vessels.iter().any(|v| dist([v.x, v.y], p) < d)
}

impl Target {
    fn new(o: &Obstacle) -> Self {
        Target {
            r: TargetRules {
                target: o.name.clone(),
                slot: o.slot,
                t_detect_s: None,
                range_detect_m: None,
                situation_geometric: None,
                situation_controller: None,
                role_controller: None,
                situation: None,
                situation_source: None,
                t_cpa_s: None,
                r_cpa_m: None,
                beta_cpa_deg: None,
                starboard_turn_to_cpa_deg: None,
                t_action_s: None,
                action: None,
                t_past_and_clear_s: None,
                past_and_clear: None,
                given_up: None,
                crossed_ahead: None,
                crossed_ahead_to_starboard: None,
                t_rule17_s: None,
                stand_on_course_change_deg: None,
                stand_on_speed_fraction: None,
                t_stand_on_broken_s: None,
                stand_on_excused_by: None,
                t_stand_on_excused_s: None,
                port_turn_port_target_deg: None,
                t_port_turn_s: None,
                min_hull_clearance_m: None,
                t_min_hull_clearance_s: None,
            },
            present: false,
            det: None,
            controller: None,
            stbd_max: 0.0,
            offset_max: 0.0,
            acting: false,
            prev_pose: None,
            crossed_before: None,
            risk_before_detection: false,
            prev_cross: [None; 3],
            excused_by: None,
            excused_first: None,
            relief: None,
        }
    }

    /// The situation known at this step: the controller's if it has given one, else the
    /// geometric one at detection.
    fn situation(&self) -> Option<Situation> {
        self.controller.or(self.det.map(|d| d.geometric))
    }

    /// Whether the tow gives way to this target at this step: from detection, or before it
    /// from the first step the risk test holds ([`Target::watch_rule17`]) once the
    /// controller reads a give-way situation (it acts by the CPA, Rule 16: a give-way
    /// vessel acts no later than her failure to would let the stand-on vessel act), until
    /// the target is past and clear.
    fn open_give_way(&self) -> bool {
        self.present
            && (self.det.is_some() || self.risk_before_detection)
            && self.r.t_past_and_clear_s.is_none()
            && self.situation().is_some_and(is_give_way)
    }

    /// Whether the tow owes this target an action: she gives way to it
    /// ([`Target::open_give_way`]), or she stands on for it and Rule 17(a)(ii) allows her
    /// to act, until it is past and clear.
    fn owes_action(&self) -> bool {
        self.open_give_way()
            || (self.present
                && self.r.t_rule17_s.is_some()
                && self.r.t_past_and_clear_s.is_none()
                && self.situation().is_some_and(is_stand_on))
    }

    /// The controller's first definite situation for the slot.
    fn watch_controller(&mut self, step: &PlantStep<'_>) {
        if self.controller.is_some() {
            return;
        }
        let Some(c) = step.control else { return };
        for e in c.encounters.iter().filter(|e| e.slot == self.r.slot) {
            if let Some(s) = e.situation {
                if !matches!(s, Situation::Safe | Situation::Unclassified) {
                    self.controller = Some(s);
                    self.r.situation_controller = Some(s.name().to_owned());
                    self.r.role_controller = match e.role_code {
                        1 => Some("give-way".to_owned()),
                        2 => Some("stand-on".to_owned()),
                        _ => None,
                    };
                    return;
                }
            }
        }
    }

    /// Before detection, watches for the target crossing the ship's heading line ahead
    /// of her by its own motion ([`crossed_ahead`], the test [`Target::past_and_clear`]
    /// uses after detection); the crossing is kept while the target draws away from
    /// the line (its own velocity across the line points to the side it is on), so
    /// that a target which crossed before any vessel of the tow came within `d_detect`
    /// counts as crossed at detection.
    fn watch_crossing(&mut self, ship: &Vessel, o: &Obstacle) {
        if self.det.is_some() {
            return;
        }
        let (sp, tp) = ([ship.x, ship.y], [o.x, o.y]);
        let prev = self.prev_pose.replace((sp, ship.psi, tp));
        let (side, drift) = side_and_drift(ship, o);
        if prev.is_some_and(|p| crossed_ahead(p, (sp, ship.psi, tp))) && side != 0.0 {
            self.crossed_before = Some(side.signum());
        }
        if self.crossed_before.is_some_and(|s| side * s <= 0.0 || drift * s <= 0.0) {
            self.crossed_before = None;
        }
    }

    /// Before detection, latches Rule 17's permission once the target is closing to a CPA
    /// within `d_detect` of the ship at most `rule17_tcpa_s` away: Rule 17(a)(ii) lets the
    /// stand-on vessel act as soon as the give-way vessel's failure is apparent, wherever
    /// it is (the guidance acts by the CPA, not by `d_detect`: random-12-0012's tow took
    /// its way off at a TCPA of 52 s, 2 s before the forward tug came within 7 m, and was
    /// then judged on the speed it had kept at detection). The same test opens the give-way
    /// duty before detection ([`Target::open_give_way`]), while the target is not drawing
    /// away.
    fn watch_rule17(&mut self, t: f64, ship: &Vessel, o: &Obstacle, (d_detect, th): (f64, &Thresholds)) {
        if self.det.is_some() {
            return;
        }
        let (sp, tp) = ([ship.x, ship.y], [o.x, o.y]);
        let v_target = course_velocity(o.course, o.speed);
        if self.r.t_rule17_s.is_none() {
            let (tcpa, dcpa) = cpa_tcpa(sp, ship.vel_n(), tp, v_target);
            if (0.0..=th.rule17_tcpa_s).contains(&tcpa) && dcpa < d_detect {
                self.r.t_rule17_s = Some(t);
            }
        }
        // Beyond d_detect the only past-and-clear test is "gone" (drawing away).
        self.risk_before_detection =
            self.r.t_rule17_s.is_some() && !drawing_away(sp, ship.psi, tp, v_target);
    }

    /// Detection at this step if any vessel of the tow is within `d_detect`.
    fn detect(
        &mut self,
        t: f64,
        (ship, track): (&Vessel, Track),
        vessels: &[Vessel; 3],
        o: &Obstacle,
        d: f64,
    ) {
        let tp = [o.x, o.y];
        if self.det.is_some() || !any_within(vessels, tp, d) {
            return;
        }
        let sp = [ship.x, ship.y];
        let beta = relative_bearing(sp, ship.psi, tp).to_degrees();
        let alpha = relative_bearing(tp, o.course, sp).to_degrees();
        let geometric = classify(beta, alpha, ship.sog(), o.speed);
        self.det = Some(Detection {
            off_course: ship.psi - track.course,
            cross_track: track.cross_track,
            sog: ship.sog(),
            geometric,
        });
        self.r.t_detect_s = Some(t);
        self.r.range_detect_m = Some(dist(sp, tp));
        self.r.situation_geometric = Some(geometric.name().to_owned());
        self.r.stand_on_course_change_deg = Some(0.0);
        self.r.stand_on_speed_fraction = Some(1.0);
    }

    /// One step of the checks after detection.
    fn observe(
        &mut self,
        t: f64,
        (tow, track, d_detect): (Tow<'_>, Track, f64),
        o: &Obstacle,
        th: &Thresholds,
    ) {
        let Some(det) = self.det else { return };
        let ship = tow.0[0];
        let (sp, tp) = ([ship.x, ship.y], [o.x, o.y]);
        let v_target = course_velocity(o.course, o.speed);
        let range = dist(sp, tp);
        let beta = relative_bearing(sp, ship.psi, tp).to_degrees();
        // The course change: the heading's, less the route's own turn (a bend).
        let turn = wrap(ship.psi - track.course - det.off_course).to_degrees();
        let gained = track.cross_track - det.cross_track;
        self.stbd_max = self.stbd_max.max(turn);
        if self.r.r_cpa_m.is_none_or(|r| range < r) {
            self.r.t_cpa_s = Some(t);
            self.r.r_cpa_m = Some(range);
            self.r.beta_cpa_deg = Some(beta);
            self.r.starboard_turn_to_cpa_deg = Some(self.stbd_max);
        }
        self.past_and_clear(t, (tow.0, d_detect), o, th);
        self.give_way_action(t, &ship, (range, beta, turn, gained), th);
        self.cross_ahead(t, tow.0, o, th);
        self.stand_on(t, &ship, v_target, o, (turn, beta), th);
        self.clearance(t, tow, o);
    }

    /// Rule 8(d): latches past and clear (see the module's doc).
    fn past_and_clear(
        &mut self,
        t: f64,
        (vessels, d_detect): (&[Vessel; 3], f64),
        o: &Obstacle,
        th: &Thresholds,
    ) {
        let ship = &vessels[0];
        let (sp, tp) = ([ship.x, ship.y], [o.x, o.y]);
        let prev = self.prev_pose.replace((sp, ship.psi, tp));
        if self.r.t_past_and_clear_s.is_some() {
            return;
        }
        let crossing = !matches!(
            self.situation(),
            Some(Situation::HeadOn | Situation::Overtaking | Situation::BeingOvertaken)
        );
        // From one side of the ship's heading line to the other, its own motion at least
        // half of the change: the tow's turn alone never makes the crossing. One seen
        // before detection counts at detection ([`Target::watch_crossing`]).
        let before = self.crossed_before.take().is_some();
        let crossed =
            crossing && (before || prev.is_some_and(|p| crossed_ahead(p, (sp, ship.psi, tp))));
        let v_target = course_velocity(o.course, o.speed);
        let abaft = abaft_and_opening(sp, ship.psi, ship.vel_n(), tp, v_target)
            && ship.u > th.way_off_surge_m_s;
        // Gone: beyond d_detect of every vessel of the tow, its own velocity opening the
        // range from the ship and its track no longer meeting her heading line ahead of
        // her; neither the tow's braking nor her sternway made the range.
        let gone = !any_within(vessels, tp, d_detect) && drawing_away(sp, ship.psi, tp, v_target);
        if crossed || abaft || gone {
            self.r.t_past_and_clear_s = Some(t);
            self.r.past_and_clear = Some(
                if crossed && before {
                    "crossed ahead before detection"
                } else if crossed {
                    "crossed ahead"
                } else if abaft {
                    "abaft the beam, opening"
                } else {
                    "gone beyond the detection distance, drawing away"
                }
                .to_owned(),
            );
        }
    }

    /// Rule 16 and 8(d): the first action, and its release before past and clear.
    fn give_way_action(
        &mut self,
        t: f64,
        ship: &Vessel,
        (range, beta, turn, gained): (f64, f64, f64, f64),
        th: &Thresholds,
    ) {
        let turned = turn >= th.give_way_turn_deg;
        // An alteration made (the head once `give_way_turn_deg` to starboard) is held
        // while the offset it gained is: the tow steadied on a track parallel to her
        // route, to starboard of where she was, has not turned back towards the target
        // (the action of Rule 8(d) is the passing distance it makes, and a narrow
        // waterway leaves no room to hold the heading itself for a long overtaking).
        self.offset_max = self.offset_max.max(gained);
        let slack = th.give_way_offset_m;
        let offset_kept = self.stbd_max >= th.give_way_turn_deg
            && gained > slack
            && gained >= self.offset_max - slack;
        let way_off = ship.u <= th.way_off_surge_m_s;
        let acting = turned || way_off;
        // An alteration to starboard under way: the head already to starboard of its
        // heading at detection and still coming round. It holds an action (the tow
        // gathering way while she brings her head round is not giving way up), it is
        // not yet one (Rule 16 needs the turn or the way off).
        let swinging = turn > 0.0 && ship.r.to_degrees() >= th.give_way_turn_rate_deg_s;
        if acting && self.r.t_action_s.is_none() {
            self.r.t_action_s = Some(t);
            self.r.action = Some(
                if turned {
                    "starboard alteration"
                } else {
                    "way off"
                }
                .to_owned(),
            );
        }
        let released = self.acting && !acting && !swinging && !offset_kept;
        if released && self.r.t_past_and_clear_s.is_none() && self.r.given_up.is_none() {
            self.r.given_up = Some(GiveUp {
                t_s: t,
                range_m: range,
                bearing_deg: beta,
            });
        }
        self.acting = acting || (self.acting && (swinging || offset_kept));
    }

    /// Rule 15: a vessel of the tow crossing the target's course line ahead of it, close
    /// (the first crossing, and the first onto the target's starboard side).
    fn cross_ahead(&mut self, t: f64, vessels: &[Vessel; 3], o: &Obstacle, th: &Thresholds) {
        let tp = [o.x, o.y];
        for (k, v) in vessels.iter().enumerate() {
            let crossed = course_line_crossing(&mut self.prev_cross[k], tp, o.course, [v.x, v.y]);
            let range = dist([v.x, v.y], tp);
            if !(crossed.is_some_and(|along| along > 0.0) && range < th.cross_ahead_min_m) {
                continue;
            }
            // The side it crossed to (+ the target's starboard).
            let side = self.prev_cross[k].unwrap_or(0.0);
            let crossing = CrossAhead {
                t_s: t,
                vessel: VESSELS[k].to_owned(),
                range_m: range,
            };
            if side > 0.0 && self.r.crossed_ahead_to_starboard.is_none() {
                self.r.crossed_ahead_to_starboard = Some(crossing.clone());
            }
            if self.r.crossed_ahead.is_none() {
                self.r.crossed_ahead = Some(crossing);
            }
        }
    }

    /// Rule 17: course and speed kept until action is allowed, except while the tow acts
    /// for another target (Rule 2(b)); no port turn for a target on the port side until it
    /// is past and clear.
    fn stand_on(
        &mut self,
        t: f64,
        ship: &Vessel,
        v_target: [f64; 2],
        o: &Obstacle,
        (turn, beta): (f64, f64),
        th: &Thresholds,
    ) {
        let Some(det) = self.det else { return };
        if self.r.t_rule17_s.is_none() {
            let (tcpa, _) = cpa_tcpa([ship.x, ship.y], ship.vel_n(), [o.x, o.y], v_target);
            if tcpa <= th.rule17_tcpa_s {
                self.r.t_rule17_s = Some(t);
            } else {
                let fraction = if det.sog > 0.0 {
                    ship.sog() / det.sog
                } else {
                    1.0
                };
                self.keep_course_and_speed(t, turn.abs(), fraction, th);
            }
        }
        if beta < 0.0 && self.r.t_past_and_clear_s.is_none() {
            let port = (-turn).max(0.0);
            if self.r.port_turn_port_target_deg.is_none_or(|m| port > m) {
                self.r.port_turn_port_target_deg = Some(port);
                self.r.t_port_turn_s = Some(t);
            }
        }
    }

    /// Rule 17(a)(i): the course change `turn` (deg, magnitude) and the speed `fraction` of
    /// its value at detection, before Rule 17 allows action. While the tow owes another
    /// target an action ([`Target::excused_by`]) they are not judged but widen the bounds
    /// (the relief); afterwards the bounds are the thresholds or the relief, whichever is
    /// wider: she may come back from what she did for the other vessel, not go further.
    fn keep_course_and_speed(&mut self, t: f64, turn: f64, fraction: f64, th: &Thresholds) {
        if let Some(by) = self.excused_by {
            if self.excused_first.is_none() {
                self.excused_first = Some(by);
                self.r.t_stand_on_excused_s = Some(t);
            }
            let (c, f) = self.relief.unwrap_or((0.0, 1.0));
            self.relief = Some((c.max(turn), f.min(fraction)));
            return;
        }
        let (relief_course, relief_speed) = self.relief.unwrap_or((0.0, 1.0));
        let course_max = th.stand_on_course_deg.max(relief_course);
        let speed_min = th.stand_on_speed_fraction.min(relief_speed);
        let course = self.r.stand_on_course_change_deg.unwrap_or(0.0).max(turn);
        let speed = self.r.stand_on_speed_fraction.unwrap_or(1.0).min(fraction);
        self.r.stand_on_course_change_deg = Some(course);
        self.r.stand_on_speed_fraction = Some(speed);
        let broken = turn > course_max || fraction < speed_min;
        if broken && self.r.t_stand_on_broken_s.is_none() {
            self.r.t_stand_on_broken_s = Some(t);
        }
    }

    /// Rule 13: the least hull clearance (the exact distance is skipped when a lower bound,
    /// centre distance less both circumradii, cannot beat the minimum so far).
    fn clearance(&mut self, t: f64, (vessels, sizes): Tow<'_>, o: &Obstacle) {
        for (v, [l, w]) in vessels.iter().zip(sizes) {
            let bound = dist([v.x, v.y], [o.x, o.y]) - (l / 2.0).hypot(w / 2.0) - o.length / 2.0;
            if self.r.min_hull_clearance_m.is_some_and(|m| bound >= m) {
                continue;
            }
            let c = hull_ellipse_clearance(
                (v.x, v.y, v.psi, *l, *w),
                (o.x, o.y, o.course, o.length, o.width),
            );
            if self.r.min_hull_clearance_m.is_none_or(|m| c < m) {
                self.r.min_hull_clearance_m = Some(c);
                self.r.t_min_hull_clearance_s = Some(t);
            }
        }
    }
}

/// The situations in which the tow is the give-way vessel (Rules 13, 14, 15).
#[must_use]
pub fn is_give_way(s: Situation) -> bool {
    matches!(
        s,
        Situation::HeadOn | Situation::CrossingGiveWay | Situation::Overtaking
    )
}

/// The situations in which the tow is the stand-on vessel (Rules 13, 15, 17).
#[must_use]
pub fn is_stand_on(s: Situation) -> bool {
    matches!(s, Situation::CrossingStandOn | Situation::BeingOvertaken)
}

/// The rules tracker: one bounded state per target ship.
#[derive(Debug, Clone)]
pub struct RulesTracker {
    th: Thresholds,
    course: RouteCourse,
    sizes: [[f64; 2]; 3],
    d_detect: f64,
    targets: Vec<Target>,
}

impl RulesTracker {
    /// A tracker.
    #[must_use]
    pub fn new(geometry: &RunGeometry, thresholds: &Thresholds) -> Self {
        RulesTracker {
            th: *thresholds,
            course: RouteCourse::new(&geometry.route, thresholds.route_course_lookahead_m),
            sizes: geometry.sizes,
            d_detect: geometry.detection_distance,
            targets: Vec::new(),
        }
    }

    /// The next step.
    pub fn push(&mut self, step: &PlantStep<'_>) {
        // The actions the tow owed after the last step: each excuses the stand-on checks
        // of the other targets at this one (the first two owed name one for every target).
        let mut owed = (self.targets.iter().enumerate())
            .filter(|(_, t)| t.owes_action())
            .map(|(j, _)| j);
        let (first, second) = (owed.next(), owed.next());
        for (k, t) in self.targets.iter_mut().enumerate() {
            t.present = false;
            t.excused_by = if first == Some(k) { second } else { first };
        }
        let ship = step.vessels[0];
        let track = self.course.track([ship.x, ship.y]);
        for o in step
            .obstacles
            .iter()
            .filter(|o| o.kind == ObstacleKind::Ship)
        {
            let k = match self.targets.iter().position(|t| t.r.slot == o.slot) {
                Some(k) => k,
                None => {
                    self.targets.push(Target::new(o));
                    self.targets.len() - 1
                }
            };
            let target = &mut self.targets[k];
            target.present = true;
            target.watch_controller(step);
            target.watch_crossing(&ship, o);
            target.watch_rule17(step.t, &ship, o, (self.d_detect, &self.th));
            target.detect(step.t, (&ship, track), &step.vessels, o, self.d_detect);
            target.observe(
                step.t,
                ((&step.vessels, &self.sizes), track, self.d_detect),
                o,
                &self.th,
            );
        }
        // The controller may report a target's situation before it is among the active
        // obstacles of a step only in a malformed log; such reports are not kept.
    }

    /// Whether, after the last step pushed, the tow is giving way to a target that is
    /// present, detected and not yet past and clear (the situation known so far: the
    /// controller's, else the geometric one). Progress excuses a stall while it is.
    #[must_use]
    pub fn give_way_open(&self) -> bool {
        self.targets.iter().any(Target::open_give_way)
    }

    /// The report.
    #[must_use]
    pub fn finish(self) -> RulesReport {
        let names: Vec<String> = self.targets.iter().map(|t| t.r.target.clone()).collect();
        RulesReport {
            targets: self
                .targets
                .into_iter()
                .map(|mut t| {
                    let (s, source) = match (t.controller, t.det) {
                        (Some(c), _) => (Some(c), Some(SituationSource::Controller)),
                        (None, Some(d)) => (Some(d.geometric), Some(SituationSource::Geometric)),
                        (None, None) => (None, None),
                    };
                    t.r.situation = s.map(|s| s.name().to_owned());
                    t.r.situation_source = source;
                    t.r.stand_on_excused_by = t.excused_first.and_then(|j| names.get(j).cloned());
                    t.r
                })
                .collect(),
        }
    }
}

/// The situation of a report entry, from its name.
fn situation_of(r: &TargetRules) -> Option<Situation> {
    let name = r.situation.as_deref()?;
    (0..=6)
        .filter_map(Situation::from_code)
        .find(|s| s.name() == name)
}

/// The rule reasons of every target (see the module's doc for the checks).
#[must_use]
pub fn reasons(report: &RulesReport, thresholds: &Thresholds) -> Vec<Reason> {
    let mut out = Vec::new();
    for r in &report.targets {
        let Some(s) = situation_of(r) else { continue };
        if r.t_detect_s.is_none() {
            continue;
        }
        if is_give_way(s) {
            give_way_reasons(r, s, thresholds, &mut out);
        }
        if is_stand_on(s) {
            stand_on_reasons(r, thresholds, &mut out);
        }
    }
    out
}

/// The rule named for a give-way situation.
fn give_way_rule(s: Situation) -> &'static str {
    match s {
        Situation::HeadOn => "rule14_head_on",
        Situation::Overtaking => "rule13_overtaking",
        _ => "rule15_give_way",
    }
}

fn give_way_reasons(r: &TargetRules, s: Situation, th: &Thresholds, out: &mut Vec<Reason>) {
    let name = r.target.as_str();
    let acted = r.t_action_s.zip(r.t_cpa_s).is_some_and(|(a, c)| a <= c);
    if !acted {
        out.push(Reason::target(
            "rule16_action",
            name,
            r.t_cpa_s,
            format!(
                "no give-way action ({} deg to starboard or surge <= {} m/s) before the CPA",
                th.give_way_turn_deg, th.way_off_surge_m_s
            ),
        ));
    }
    if let Some(g) = r.given_up {
        out.push(Reason::target(
            "rule8_past_and_clear",
            name,
            Some(g.t_s),
            format!(
                "give-way action given up before the target was past and clear (range {:.2} m, \
                 bearing {:.0} deg)",
                g.range_m, g.bearing_deg
            ),
        ));
    }
    // Head-on, the tow's starboard alteration takes her to the target's port side
    // (Rule 14: port to port); when she lies fine on its starboard bow that is across
    // its course line ahead of it, which the rule asks for. Crossing onto its
    // starboard side is the violation.
    let crossed = if s == Situation::HeadOn {
        &r.crossed_ahead_to_starboard
    } else {
        &r.crossed_ahead
    };
    if let Some(c) = crossed {
        out.push(Reason::target(
            give_way_rule(s),
            name,
            Some(c.t_s),
            format!(
                "{} crossed ahead of the target at {:.2} m (< {} m)",
                c.vessel, c.range_m, th.cross_ahead_min_m
            ),
        ));
    }
    if s == Situation::HeadOn {
        let turn = r.starboard_turn_to_cpa_deg.unwrap_or(0.0);
        if turn < th.head_on_turn_deg {
            out.push(Reason::target(
                "rule14_head_on",
                name,
                r.t_cpa_s,
                format!(
                    "starboard alteration {turn:.1} deg before the CPA, less than {} deg",
                    th.head_on_turn_deg
                ),
            ));
        }
        if r.beta_cpa_deg.is_some_and(|b| b >= 0.0) {
            out.push(Reason::target(
                "rule14_head_on",
                name,
                r.t_cpa_s,
                "passed starboard to starboard (Rule 14: port to port)",
            ));
        }
    }
    if s == Situation::Overtaking {
        if let Some(c) = r.min_hull_clearance_m {
            if c < th.overtaking_clearance_m {
                out.push(Reason::target(
                    "rule13_overtaking",
                    name,
                    r.t_min_hull_clearance_s,
                    format!(
                        "hull clearance {c:.2} m, less than {} m",
                        th.overtaking_clearance_m
                    ),
                ));
            }
        }
    }
}

fn stand_on_reasons(r: &TargetRules, th: &Thresholds, out: &mut Vec<Reason>) {
    let name = r.target.as_str();
    if let Some(t) = r.t_stand_on_broken_s {
        let relieved = match (&r.stand_on_excused_by, r.t_stand_on_excused_s) {
            (Some(by), Some(from)) => format!(
                "; the limits widened to what her action for {by} from {from:.1} s left"
            ),
            _ => String::new(),
        };
        out.push(Reason::target(
            "rule17_stand_on",
            name,
            Some(t),
            format!(
                "course or speed not kept before Rule 17 allowed action (course change up to \
                 {:.1} deg, limit {}; speed down to {:.0} %, limit {:.0} %{relieved})",
                r.stand_on_course_change_deg.unwrap_or(0.0),
                th.stand_on_course_deg,
                100.0 * r.stand_on_speed_fraction.unwrap_or(1.0),
                100.0 * th.stand_on_speed_fraction
            ),
        ));
    }
    if let Some(p) = r.port_turn_port_target_deg {
        if p > th.port_turn_max_deg {
            out.push(Reason::target(
                "rule17_stand_on",
                name,
                r.t_port_turn_s,
                format!(
                    "turned {p:.1} deg to port for a target on the port side (Rule 17(c), \
                     limit {} deg)",
                    th.port_turn_max_deg
                ),
            ));
        }
    }
}

/// A number with one decimal, or `-`.
fn cell(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_owned(), |x| format!("{x:.1}"))
}

impl Metric for RulesTracker {
    type Section = RulesReport;

    fn new(run: &RunContext<'_>) -> Self {
        RulesTracker::new(run.geometry, run.thresholds)
    }

    /// Publishes whether a give-way encounter is open after this step (for `progress`).
    fn step(&mut self, s: &PlantStep<'_>, facts: &mut StepFacts) {
        self.push(s);
        facts.giving_way = self.give_way_open();
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<RulesReport> {
        Ok(RulesTracker::finish(self))
    }

    fn report(m: &RulesReport, _all: &Metrics) -> ReportPart {
        if m.targets.is_empty() {
            return ReportPart::default();
        }
        let rows = m
            .targets
            .iter()
            .map(|r| {
                vec![
                    r.target.clone(),
                    r.situation.clone().unwrap_or_else(|| "-".to_owned()),
                    r.situation_geometric.clone().unwrap_or_else(|| "-".to_owned()),
                    cell(r.t_detect_s),
                    r.action.clone().map_or_else(|| "-".to_owned(), |a| format!("{a} at {}", cell(r.t_action_s))),
                    r.past_and_clear.clone().map_or_else(|| "-".to_owned(), |p| format!("{p} at {}", cell(r.t_past_and_clear_s))),
                    r.given_up.map_or_else(|| "-".to_owned(), |g| format!("{:.1} s ({:.1} m, {:.0} deg)", g.t_s, g.range_m, g.bearing_deg)),
                    cell(r.r_cpa_m),
                    cell(r.beta_cpa_deg),
                ]
            })
            .collect();
        ReportPart {
            details: vec![
                Block::Heading(3, "Rule checks per target ship".to_owned()),
                Block::Table {
                    headers: [
                        "target",
                        "situation (judged)",
                        "geometric",
                        "detected (s)",
                        "give-way action",
                        "past and clear",
                        "given up",
                        "CPA range (m)",
                        "CPA bearing (deg)",
                    ]
                    .map(str::to_owned)
                    .to_vec(),
                    rows,
                },
            ],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &RulesReport, thresholds: &Thresholds) -> Vec<Reason> {
        reasons(m, thresholds)
    }
}

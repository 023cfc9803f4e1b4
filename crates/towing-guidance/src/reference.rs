//! The ship reference system: Du et al. (2022), section 3.1, eq. (8)-(11), with the
//! COLREGS policy of [`crate::colregs`] deciding which obstacles may alter the route.
//!
//! Per sample ([`ReferenceSystem::update`]):
//! 1. Every active obstacle is assessed ([`assess_obstacle`]): its range-equivalent
//!    distance to the nearest of the three vessels (ship, tug 1, tug 2; eq. (8)'s
//!    `min{d_Sj, d_1j, d_2j}`), its eq. (9) distance and eq. (14) safe distance
//!    for that vessel, and for a target ship the COLREGS encounter and policy.
//!    A target's situation is *held* from the first sample it is detected with a
//!    definite situation (not safe, not unclassified) until its encounter is over:
//!    roles are fixed when risk first exists, and Rule 13(d): "any subsequent
//!    alteration of the bearing ... shall not make the overtaking vessel a crossing
//!    vessel". Without it a target crossing ahead of a stand-on tow turns into an
//!    "overtaken" vessel on the tow's starboard bow once it has crossed.
//! 2. An obstacle *demands* the alteration when it is within its detection
//!    distance (eq. (8): `d <= d_D`) and its policy alters to starboard now: a static
//!    hazard by distance (the paper's rule) if the altered leg passes it farther
//!    than the route does ([`StaticHazardPolicy::WhenAlteringHelps`], the default;
//!    [`StaticHazardPolicy::ByDistance`] drops that test), a target ship if its
//!    action is
//!    [`Action::AlterToStarboard`] or [`Action::KeepOut`]; such a target also demands
//!    it beyond its detection distance once the CPA test of Rule 17 holds
//!    ([`crate::Rule17Settings::give_way_failed`]): the give-way tow acts no later than
//!    her failure to act would let the stand-on vessel act (Rules 16, 17(a)(ii);
//!    `docs/colregs.md`, "Acting by the CPA"). A stand-on tow keeps the
//!    route until Rule 17 allows action ([`Action::StandOnThenAct`],
//!    [`crate::Rule17Settings`]), judged by the CPA wherever the target is; it then
//!    takes the way off ([`Manoeuvre::TakeWayOff`], route kept) if the slowed tow lets
//!    the target pass clear ahead, else it demands the alteration. A way-off is held
//!    like an alteration (step 3) and reported in [`GuidanceOutput::way_off`].
//! 3. An obstacle that demanded the alteration keeps it (Rule 8(d): "until the other
//!    vessel is finally past and clear"). A static hazard keeps it until its distance
//!    exceeds its detection distance plus `release_margin`, or the alteration no longer
//!    helps (a new segment). A target ship keeps it, and a way-off likewise, until it
//!    is finally past and clear: past and clear ([`past_and_clear`]: crossed ahead by
//!    its own motion or abaft the beam, the range from every vessel of the tow opening
//!    and beyond that vessel's eq. (14) safe range plus `release_margin`) and the tow
//!    resuming her route would pass it clear ([`resume_clear`]); or until it has left
//!    (beyond the distance plus `release_margin`, not closing, clear of the resumed
//!    track, and drawing away: [`towing_model::geometry::drawing_away`]), even if its
//!    situation has meanwhile become safe. An encounter found past and clear stays
//!    over until the target leaves the encounter distance, unless it closes again
//!    into a situation in which Rule 17 would act (its TCPA and DCPA limits).
//! 4. While any obstacle keeps it, the reference is the active waypoint rotated to
//!    starboard about the previous predefined waypoint (eq. (10)-(11)); otherwise the
//!    predefined waypoint (eq. (8), `eta_Sd = eta_Sp`). An alteration whose encounters
//!    have all ended is held while the tow stands on for a target within its detection
//!    distance that is not yet past and clear (Rule 17(a)(i), 17(c): the return to the
//!    route would be a course change to port; [`keeps_course`]).
//! 5. The active waypoint advances when the ship reaches the reference waypoint
//!    (acceptance radius) or has passed it; the destination is held.

use serde::{Deserialize, Serialize};

use towing_model::geometry::starboard_offset;
use towing_model::{ObstacleKind, ObstacleSlot, Pose, MAX_OBSTACLES};

use crate::colregs::{action, classify, safe_reading, Action, Encounter, Manoeuvre, Situation};
use crate::distance::{ActiveObstacle, Ellipse};
use crate::error::InputError;
use crate::geometry::{cpa, dist, segment_distance};
use crate::params::{GuidanceParams, StaticHazardPolicy};
use crate::waypoint::{rotate_waypoint, theta_max, Route};

// [`ReferenceSystem::update`] accepts up to the interface's [`MAX_OBSTACLES`] slots and
// tracks their encounters in 64-bit masks, without allocation.
const _: () = assert!(MAX_OBSTACLES <= 64);

/// State of the tow at a sample, as the controller sees it.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TowState {
    /// Ship pose `eta_S` (m, m, rad).
    pub ship: Pose,
    /// Ship velocity over ground in NED (m/s); from body `nu` use
    /// [`crate::body_to_ned`]. Used for the CPA and the speed comparison of Rule 13.
    pub ship_vel_n: [f64; 2],
    /// Tug 1 (aft) pose; only the position is used.
    pub tug1: Pose,
    /// Tug 2 (forward) pose; only the position is used.
    pub tug2: Pose,
}

impl TowState {
    /// The ship's speed over ground along her heading (m/s).
    fn speed_ahead(&self) -> f64 {
        let (sin, cos) = self.ship.psi.sin_cos();
        self.ship_vel_n[0] * cos + self.ship_vel_n[1] * sin
    }

    fn validate(&self) -> Result<(), InputError> {
        let fields = [
            ("ship.x", self.ship.x),
            ("ship.y", self.ship.y),
            ("ship.psi", self.ship.psi),
            ("ship_vel_n[0]", self.ship_vel_n[0]),
            ("ship_vel_n[1]", self.ship_vel_n[1]),
            ("tug1.x", self.tug1.x),
            ("tug1.y", self.tug1.y),
            ("tug2.x", self.tug2.x),
            ("tug2.y", self.tug2.y),
        ];
        for (field, value) in fields {
            if !value.is_finite() {
                return Err(InputError::NonFiniteTowState { field });
            }
        }
        Ok(())
    }
}

/// One of the three vessels of the tow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TowVessel {
    /// The towed ship.
    Ship,
    /// Tug 1, aft.
    Tug1,
    /// Tug 2, forward.
    Tug2,
}

/// What the reference system found about one obstacle at one sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObstacleAssessment {
    /// Slot index in the obstacle slice.
    pub index: usize,
    /// Circle or vessel.
    pub kind: ObstacleKind,
    /// The vessel of the tow nearest to it (range-equivalent distance).
    pub nearest_vessel: TowVessel,
    /// Range-equivalent distance (m) from the nearest vessel: centre distance for
    /// a circle, half the focal sum for a ship (see [`crate::distance`]).
    pub range: f64,
    /// Eq. (9) distance (m) from the nearest vessel: centre distance or focal sum.
    pub distance_eq9: f64,
    /// Eq. (14) safe distance (m) of the nearest vessel, units of `distance_eq9`.
    pub safe_distance_eq14: f64,
    /// COLREGS encounter of the ship with this target at this sample (its
    /// `situation` from the present geometry); `None` for static hazards.
    pub encounter: Option<Encounter>,
    /// The situation the policy is taken from: the held one of the encounter if
    /// any, else the present one; `None` for static hazards.
    pub situation: Option<Situation>,
    /// The policy: for a target ship [`crate::action`] of `situation`; for a
    /// static hazard [`Action::AlterToStarboard`] (the paper's by-distance rule).
    pub action: Action,
    /// Within its detection distance (`d_D`, or the static hazards' distance), or a
    /// target the tow gives way to whose CPA meets Rule 17's test (closing, TCPA and
    /// DCPA within [`crate::Rule17Settings`]).
    pub detected: bool,
    /// Whether a starboard alteration may be asked for: for a static hazard under
    /// [`StaticHazardPolicy::WhenAlteringHelps`], true when the altered leg passes
    /// its centre farther than the route's leg; true otherwise.
    pub alteration_allowed: bool,
    /// A target ship that is past and clear (Rule 8(d)): the range from every vessel
    /// of the tow is opening and exceeds that vessel's eq. (14) safe range plus
    /// `release_margin` (see [`past_and_clear`]). Always false for a static hazard.
    pub past_and_clear: bool,
    /// The target has crossed the ship's heading line ahead of her by its own motion
    /// at this sample or earlier in the encounter ([`AssessContext::crossed`]).
    pub crossed: bool,
    /// What it asks of the reference system now (detection, Rule 17 and
    /// `past_and_clear` applied).
    pub manoeuvre: Manoeuvre,
    /// With an action held for this target (an alteration or the way off,
    /// [`AssessContext::acting`]): the tow resuming her route would pass it clear of
    /// every vessel ([`resume_clear`]). True otherwise.
    pub resume_clear: bool,
    /// A target ship the tow gives way to in a crossing, with the alteration held for
    /// it, whose track passes every vessel of the tow clear as she moves now (her
    /// velocity over ground; at rest once she has taken the way off):
    /// [`clearance_margin`] at least 0. False otherwise.
    pub passes_clear: bool,
    /// A target ship drawing away: its own velocity carries it away from the ship's
    /// heading line on the side it lies and opens the range from her
    /// ([`towing_model::geometry::drawing_away`], the analyzer's test too): its track
    /// no longer meets her heading line ahead. True for a static hazard.
    pub drawing_away: bool,
}

/// What the reference system knows beyond the obstacle and the tow.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct AssessContext {
    /// The situation held for this encounter, if any (ignored for static hazards).
    pub held: Option<Situation>,
    /// The active leg: `[W_{p-1}, W_p, W_pN]` positions (m), the previous and the
    /// active predefined waypoint and the altered one. Needed by
    /// [`StaticHazardPolicy::WhenAlteringHelps`]; without it a static hazard is
    /// judged by distance only.
    pub leg: Option<[[f64; 2]; 3]>,
    /// This target's encounter was found past and clear at an earlier sample and has
    /// not ended since (ignored for static hazards): it stays over unless the target
    /// closes again into a close-quarters situation (see [`past_and_clear`]).
    pub cleared: bool,
    /// Where the ship and this target were at the previous sample (ignored for static
    /// hazards): the line the target must cross by its own motion ([`Sighting`]).
    pub previous: Option<Sighting>,
    /// This target has crossed the ship's heading line ahead of her by its own motion
    /// since its encounter began (ignored for static hazards).
    pub crossed: bool,
    /// The tow has taken the way off for this target under Rule 17
    /// ([`Manoeuvre::TakeWayOff`]) and keeps it off: an action once taken is held,
    /// not changed into an alteration (Rule 8(a), (d)).
    pub way_off: bool,
    /// An action is held for this target: the route altered for it, or the way off
    /// ([`Self::way_off`]). Its release asks whether the resumed track passes it clear
    /// ([`ObstacleAssessment::resume_clear`]).
    pub acting: bool,
}

/// The ship's pose and a target's position at one sample: the next sample tells from
/// it whether the target crossed the ship's heading line ahead of her by its own motion
/// ([`towing_model::geometry::crossed_ahead`]: its own displacement across this
/// sample's line, held still, is at least half of the change of its side; neither the
/// tow's turn nor its sideways motion alone makes the crossing).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Sighting {
    /// Ship pose.
    pub ship: Pose,
    /// Target centre (m).
    pub target: [f64; 2],
}

impl Sighting {
    /// True when the target, now at `target_now` with the ship at `ship_now`, has crossed
    /// the ship's heading line ahead of her by its own motion since this sighting
    /// ([`towing_model::geometry::crossed_ahead`], the analyzer's test too).
    #[must_use]
    pub fn crossed_ahead(&self, ship_now: Pose, target_now: [f64; 2]) -> bool {
        towing_model::geometry::crossed_ahead(
            (self.ship.position(), self.ship.psi, self.target),
            (ship_now.position(), ship_now.psi, target_now),
        )
    }
}

/// Assesses one active obstacle for the tow (steps 1 and 2 of the module doc).
#[must_use]
pub fn assess_obstacle(
    params: &GuidanceParams,
    tow: &TowState,
    index: usize,
    obstacle: &ActiveObstacle,
    context: &AssessContext,
) -> ObstacleAssessment {
    let s = params.settings();
    let vessels = [
        (TowVessel::Ship, tow.ship.position(), s.ship_length),
        (TowVessel::Tug1, tow.tug1.position(), s.tug_length),
        (TowVessel::Tug2, tow.tug2.position(), s.tug_length),
    ];
    let (nearest, range) = nearest_vessel(obstacle, &vessels);
    let (encounter, situation, policy) = reading(params, tow, obstacle, context.held);
    let detection = s.detection_distance_for(obstacle.kind());
    // Rule 16 with 17(a)(ii): a tow that must keep out of the way acts no later than
    // the moment her failure to act would let the stand-on vessel act, judged by the
    // same CPA test (`Rule17Settings::give_way_failed`), even before the target is
    // within d_D: a fast crossing target reached d_D with too little time left for the
    // tow to let it pass clear ahead of her forward tug (`docs/colregs.md`, section 2,
    // "Acting by the CPA").
    let gives_way_late = matches!(policy, Action::AlterToStarboard | Action::KeepOut)
        && encounter.is_some_and(|enc| s.colregs.rule17.give_way_failed(&enc.cpa));
    let detected = range <= detection || gives_way_late;
    let alteration_allowed = match (obstacle, s.static_hazard_policy, context.leg) {
        (
            ActiveObstacle::Circle { centre, .. },
            StaticHazardPolicy::WhenAlteringHelps,
            Some(leg),
        ) => segment_distance(*centre, leg[0], leg[2]) > segment_distance(*centre, leg[0], leg[1]),
        _ => true,
    };
    let crossed = context.crossed
        || context
            .previous
            .is_some_and(|p| p.crossed_ahead(tow.ship, obstacle.centre()));
    let past_and_clear = encounter.zip(situation).is_some_and(|(enc, situation)| {
        (context.cleared && !s.colregs.rule17.give_way_failed(&enc.cpa))
            || past_and_clear(
                params,
                tow,
                &vessels,
                obstacle,
                (situation, crossed, enc.bearing),
            )
    });
    // Rule 17 is judged by the CPA, not by d_D: a stand-on tow acts once the give-way
    // vessel has failed to act in time, wherever the target is then.
    let rule17 = &s.colregs.rule17;
    let rule17_acts = policy == Action::StandOnThenAct
        && encounter.is_some_and(|enc| rule17.give_way_failed(&enc.cpa));
    let acts = (detected || rule17_acts) && alteration_allowed && !past_and_clear;
    let manoeuvre = match (acts, &encounter) {
        (false, _) => Manoeuvre::FollowRoute,
        (true, None) => Manoeuvre::AlterToStarboard,
        (true, Some(enc)) => match policy.manoeuvre(&enc.cpa, rule17) {
            Manoeuvre::AlterToStarboard
                if rule17_acts
                    && (context.way_off || way_off_chosen(params, tow, &vessels, obstacle)) =>
            {
                Manoeuvre::TakeWayOff
            }
            m => m,
        },
    };
    let resume_clear =
        !context.acting || resume_clear(params, tow, &vessels, obstacle, context.leg);
    let passes_clear = match obstacle {
        ActiveObstacle::Vessel(target) => {
            context.acting
                && situation == Some(Situation::CrossingGiveWay)
                && !past_and_clear
                && clearance_margin(params, &vessels, target, [0.0; 2], tow.ship_vel_n) >= 0.0
        }
        ActiveObstacle::Circle { .. } => false,
    };
    let drawing_away = match obstacle {
        ActiveObstacle::Vessel(target) => towing_model::geometry::drawing_away(
            tow.ship.position(),
            tow.ship.psi,
            target.centre,
            target.velocity(),
        ),
        ActiveObstacle::Circle { .. } => true,
    };
    ObstacleAssessment {
        index,
        kind: obstacle.kind(),
        nearest_vessel: nearest.0,
        range,
        distance_eq9: obstacle.distance_eq9(nearest.1),
        safe_distance_eq14: obstacle.safe_distance_eq14(nearest.2, s.safety_buffer),
        encounter,
        situation,
        action: policy,
        detected,
        alteration_allowed,
        past_and_clear,
        crossed,
        manoeuvre,
        resume_clear,
        passes_clear,
        drawing_away,
    }
}

/// The vessel of the tow (kind, position, length) nearest to `obstacle` by its
/// range-equivalent distance (eq. (8): `min{d_Sj, d_1j, d_2j}`), and that range (m).
fn nearest_vessel(
    obstacle: &ActiveObstacle,
    vessels: &[(TowVessel, [f64; 2], f64); 3],
) -> ((TowVessel, [f64; 2], f64), f64) {
    let mut nearest = vessels[0];
    let mut range = obstacle.range(nearest.1);
    for v in &vessels[1..] {
        let r = obstacle.range(v.1);
        if r < range {
            range = r;
            nearest = *v;
        }
    }
    (nearest, range)
}

/// The COLREGS reading of `obstacle`: for a target ship its encounter, the situation
/// the policy is taken from (`held`, else the safe reading of the present one) and that
/// policy; for a static hazard no encounter and the paper's by-distance alteration.
fn reading(
    params: &GuidanceParams,
    tow: &TowState,
    obstacle: &ActiveObstacle,
    held: Option<Situation>,
) -> (Option<Encounter>, Option<Situation>, Action) {
    let s = params.settings();
    match obstacle {
        ActiveObstacle::Circle { .. } => (None, None, Action::AlterToStarboard),
        ActiveObstacle::Vessel(target) => {
            let enc = classify(
                tow.ship,
                tow.ship_vel_n,
                target,
                &s.colregs.thresholds,
                s.colregs.risk_dcpa,
            );
            let situation = held.unwrap_or_else(|| safe_reading(&enc, &s.colregs.thresholds));
            (
                Some(enc),
                Some(situation),
                action(situation, s.colregs.tow_status),
            )
        }
    }
}

/// Whether `obstacle`, a target ship, is past and clear of the tow (false for a static
/// hazard) (COLREGS Rule 8(d): the give-way action lasts "until the other vessel is
/// finally past and clear"), judged from the target's own motion relative to the tow,
/// never from a range opened by the tow's own braking (`docs/colregs.md`, "Past and
/// clear"):
/// - where it is: in a crossing (any situation but head-on and the two overtaking ones)
///   the target has crossed the ship's heading line ahead of her by its own motion
///   (`crossed`, [`Sighting::crossed_ahead`]); in any situation it may instead be abaft
///   the ship's beam (`bearing`, the encounter's `beta`: `|beta| > 90 deg`). A head-on or
///   overtaking target moves along the tow's track, not across it, so only the second
///   applies to it;
/// - and for every vessel of the tow (position `p`, length `l`) the range is opening,
///   `(p_target - p) . (v_target - v_ship) > 0`, and the range-equivalent distance
///   exceeds the eq. (14) safe range `L + a_j + d_S0` plus `release_margin`. The tugs
///   are taken to move with the ship (they hold the formation of eq. (4)-(6)); their own
///   velocity is not among the guidance's inputs.
fn past_and_clear(
    params: &GuidanceParams,
    tow: &TowState,
    vessels: &[(TowVessel, [f64; 2], f64); 3],
    obstacle: &ActiveObstacle,
    (situation, crossed, bearing): (Situation, bool, f64),
) -> bool {
    let ActiveObstacle::Vessel(target) = obstacle else {
        return false;
    };
    let s = params.settings();
    let along_track = matches!(
        situation,
        Situation::HeadOn | Situation::Overtaking | Situation::BeingOvertaken
    );
    let abaft = bearing.abs() > std::f64::consts::FRAC_PI_2;
    if !(abaft || (crossed && !along_track)) {
        return false;
    }
    let v_target = target.velocity();
    let dv = [
        v_target[0] - tow.ship_vel_n[0],
        v_target[1] - tow.ship_vel_n[1],
    ];
    vessels.iter().all(|&(_, p, length)| {
        let dp = [target.centre[0] - p[0], target.centre[1] - p[1]];
        let opening = dp[0] * dv[0] + dp[1] * dv[1] > 0.0;
        opening
            && obstacle.range(p) > obstacle.safe_range(length, s.safety_buffer) + s.release_margin
    })
}

/// Whether Rule 17's action for `obstacle`, a target ship, is to take the way off
/// rather than to alter to starboard (false for a static hazard): the target keeps its
/// course and speed, and the tow (the tugs with the ship, as in [`past_and_clear`])
/// either goes on along the ship's heading at [`crate::Rule17Settings::way_off_speed`]
/// after the headway it carries while slowing at
/// [`crate::Rule17Settings::way_off_deceleration`], or keeps its present velocity.
/// The way-off is taken when it passes the target clear of every vessel of the tow
/// (range-equivalent distance at the closest approach above that vessel's eq. (14) safe
/// range, [`clearance_margin`]) or at least farther than keeping on would. Taking the way
/// off helps a target that crosses ahead of the slowed tow; one whose track runs over it
/// (head-on, or crossing at the tow's own position) gets the starboard alteration.
fn way_off_chosen(
    params: &GuidanceParams,
    tow: &TowState,
    vessels: &[(TowVessel, [f64; 2], f64); 3],
    obstacle: &ActiveObstacle,
) -> bool {
    let ActiveObstacle::Vessel(target) = obstacle else {
        return false;
    };
    let rule17 = &params.settings().colregs.rule17;
    let (sin, cos) = tow.ship.psi.sin_cos();
    let speed = rule17.way_off_speed;
    // The headway carried while slowing from the present speed along the heading,
    // taken at once (the tow ahead of where it will be: the safe side for a target
    // crossing ahead of it).
    let u = tow.speed_ahead();
    let headway = (u * u - speed * speed).max(0.0) / (2.0 * rule17.way_off_deceleration);
    let slowed = clearance_margin(
        params,
        vessels,
        target,
        [headway * cos, headway * sin],
        [speed * cos, speed * sin],
    );
    slowed > 0.0 || slowed > clearance_margin(params, vessels, target, [0.0; 2], tow.ship_vel_n)
}

/// [`ObstacleAssessment::resume_clear`]: the tow resuming her route, at
/// [`crate::GuidanceSettings::resume_speed`] along the active leg `W_{p-1} -> W_p` of
/// `leg` (along the ship's heading without it) from where her vessels are now, passes
/// `obstacle`, a target keeping its course and speed, clear of every vessel
/// ([`clearance_margin`] at least 0); true for a static hazard. Rule 8(d): the action
/// lasts until the other vessel is *finally* past and clear, so not while giving it up
/// would bring the tow back into a close-quarters situation with it.
fn resume_clear(
    params: &GuidanceParams,
    tow: &TowState,
    vessels: &[(TowVessel, [f64; 2], f64); 3],
    obstacle: &ActiveObstacle,
    leg: Option<[[f64; 2]; 3]>,
) -> bool {
    let ActiveObstacle::Vessel(target) = obstacle else {
        return true;
    };
    let course = leg
        .map(|[from, to, _]| (to[1] - from[1]).atan2(to[0] - from[0]))
        .unwrap_or(tow.ship.psi);
    let (sin, cos) = course.sin_cos();
    let speed = params.settings().resume_speed;
    clearance_margin(
        params,
        vessels,
        target,
        [0.0; 2],
        [speed * cos, speed * sin],
    ) >= 0.0
}

/// The smallest margin (m) over the vessels of the tow between the range-equivalent
/// distance of `target` at its closest approach (centre to centre, [`cpa`]) and that
/// vessel's eq. (14) safe range, for a tow moving at `v_own` from its vessels' positions
/// shifted by `offset`, the target keeping its course and speed.
fn clearance_margin(
    params: &GuidanceParams,
    vessels: &[(TowVessel, [f64; 2], f64); 3],
    target: &Ellipse,
    offset: [f64; 2],
    v_own: [f64; 2],
) -> f64 {
    let buffer = params.settings().safety_buffer;
    let v_target = target.velocity();
    let dv = [v_target[0] - v_own[0], v_target[1] - v_own[1]];
    vessels
        .iter()
        .map(|&(_, p, length)| {
            let p = [p[0] + offset[0], p[1] + offset[1]];
            let c = cpa(p, v_own, target.centre, v_target);
            let t = if c.tcpa.is_finite() {
                c.tcpa.max(0.0)
            } else {
                0.0
            };
            let at_cpa = ActiveObstacle::Vessel(Ellipse {
                centre: [target.centre[0] + dv[0] * t, target.centre[1] + dv[1] * t],
                ..*target
            });
            at_cpa.range(p) - at_cpa.safe_range(length, buffer)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The tow stands on for this assessment's target (see [`ReferenceSystem::stands_on`]).
fn stands_on(params: &GuidanceParams, a: &ObstacleAssessment) -> bool {
    let rule17 = &params.settings().colregs.rule17;
    let acts = |cpa: &crate::Cpa| match a.action {
        Action::StandOn => rule17.at_close_quarters(cpa),
        _ => rule17.give_way_failed(cpa),
    };
    matches!(a.action, Action::StandOn | Action::StandOnThenAct)
        && a.manoeuvre == Manoeuvre::FollowRoute
        && !a.past_and_clear
        && a.encounter.is_some_and(|e| !acts(&e.cpa))
}

/// Whether this assessment's target asks the tow to keep her present course: a target
/// ship within its detection distance for which the tow stands on (crossing stand-on,
/// being overtaken: Rule 17(a)(i), course and speed kept) and which is not past and
/// clear. An alteration in force when its own encounters end is then held, not undone:
/// the return to the route is a course change, to port after a starboard alteration,
/// and Rule 17(c) forbids a port turn for a vessel on the own port side (the stand-on
/// crossing target is always there) while 17(a)(i) asks the stand-on vessel to keep her
/// course whichever side the target is on (`docs/colregs.md`, "Course kept while standing
/// on").
fn keeps_course(a: &ObstacleAssessment) -> bool {
    a.detected
        && !a.past_and_clear
        && matches!(
            a.situation,
            Some(Situation::CrossingStandOn | Situation::BeingOvertaken)
        )
}

/// Output of one sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GuidanceOutput {
    /// Reference pose `eta_Sd = [x, y, psi]` for the controller (eq. (8)).
    pub eta_sd: Pose,
    /// While altered, the largest offset to starboard of the active segment the ship has
    /// reached since the alteration began or the segment became active (m, bounded by
    /// the offset of an altered waypoint at `theta_max` with a waterway); 0 otherwise.
    /// A point tracked on the altered leg lies no nearer the route than this
    /// (`docs/colregs.md` section 2, step 7): the tow never steers back towards the
    /// target while her action is held (Rule 8(d)).
    pub offset_held: f64,
    /// The predefined (unaltered) active waypoint `eta_Sp`.
    pub route_waypoint: Pose,
    /// Index of the active waypoint in [`Route::points`] (1 = `W_P1`; the last is
    /// the destination).
    pub active_waypoint: usize,
    /// True when `eta_Sd` is the altered waypoint `eta_Sn` (eq. (10)-(11)).
    pub altered: bool,
    /// True while the tow keeps the way off for a target under Rule 17
    /// ([`Manoeuvre::TakeWayOff`]); the route itself is kept unless `altered`.
    pub way_off: bool,
    /// Altering angle applied (rad): `min(theta, theta_max)` when altered, else 0.
    pub theta: f64,
    /// `d_ob` (m): smallest range-equivalent distance between the tow and any
    /// active obstacle (eq. (8)); `+inf` without obstacles.
    pub d_ob: f64,
    /// The governing obstacle: while altered, the nearest of those keeping the
    /// alteration (none while it is only held for a target the tow stands on: no
    /// encounter asks for the action any more); otherwise the nearest obstacle (the one
    /// giving `d_ob`).
    pub governing: Option<ObstacleAssessment>,
}

/// The ship reference system: route, active waypoint and the encounters that
/// altered it. Allocation-free per sample.
///
/// ```
/// use towing_guidance::{GuidanceParams, ReferenceSystem, Route, TowState};
/// use towing_model::{ObstacleKind, ObstacleSlot, Pose};
///
/// let mut guidance = ReferenceSystem::new(Route::paper(), GuidanceParams::default());
/// let ship = Pose::from_deg(-4.9, 7.0, 101.3);
/// let ahead = |d: f64| Pose { x: ship.x + d * ship.psi.cos(), y: ship.y + d * ship.psi.sin(), ..ship };
/// let tow = TowState { ship, ship_vel_n: [-0.02, 0.098], tug1: ahead(-2.17), tug2: ahead(2.085) };
/// // A target ship 5 m ahead of tug 2 on the reciprocal course: head-on.
/// let target = ahead(7.085);
/// let obstacles = [ObstacleSlot {
///     x: target.x, y: target.y, psi: ship.psi + std::f64::consts::PI,
///     speed: 0.07, length: 1.48, width: 0.48, kind: ObstacleKind::VesselEllipse,
/// }];
/// let out = guidance.update(&tow, &obstacles)?;
/// assert!(out.altered);
/// assert!((out.eta_sd.psi - 116.3f64.to_radians()).abs() < 1e-9); // 101.3 + 15 deg
/// # Ok::<(), towing_guidance::InputError>(())
/// ```
///
/// Serde writes what the system remembers between samples, every field but the route and
/// the parameters (which come from the configuration): the memory of a controller's FMU
/// state. A deserialized value carries a placeholder route and parameters and only serves
/// [`ReferenceSystem::restore`]. A field added here is part of that memory unless it is
/// marked `#[serde(skip)]` too.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReferenceSystem {
    #[serde(skip, default = "Route::paper")]
    route: Route,
    #[serde(skip)]
    params: GuidanceParams,
    active: usize,
    /// The offset to starboard of the active segment held while altered, m
    /// ([`GuidanceOutput::offset_held`]).
    #[serde(default)]
    offset_held: f64,
    encounters: Encounters,
}

/// What the reference system remembers of the encounters between samples, per obstacle
/// slot (bit `k` of a mask, element `k` of an array); [`ReferenceSystem::update`] builds
/// the next sample's from the last.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Encounters {
    /// Keeping the route altered.
    latched: u64,
    /// The route stays altered after every encounter that altered it has ended, because
    /// the tow stands on for a target that is not yet past and clear
    /// ([`keeps_course`]): the return to the route would be a course change (a port
    /// turn) that Rule 17(a)(i) and 17(c) forbid.
    course_held: bool,
    /// A target for which the tow has taken the way off (Rule 17).
    way_off: u64,
    /// Found past and clear, the encounter not yet over.
    cleared: u64,
    /// Crossed the ship's heading line ahead of her by its own motion: within the
    /// encounter, or before it while drawing away from that line.
    crossed: u64,
    /// Past and clear at the last sample.
    past: u64,
    /// Left out of the MPC's distance cost: the tow stands on for it (Rule 17 not yet
    /// allowing action), has taken the way off for it, gives way to it and it passes her
    /// clear ([`ObstacleAssessment::passes_clear`]), or it is over.
    standing_on: u64,
    /// The situation held for the encounter.
    held: [Option<Situation>; MAX_OBSTACLES],
    /// A target ship at the last sample (its situation given out is the held one, else
    /// [`Situation::Safe`]; [`ReferenceSystem::situation`]).
    vessels: u64,
    /// Where the ship and the target ship were at the last sample (every target ship,
    /// in an encounter or not).
    sightings: [Option<Sighting>; MAX_OBSTACLES],
}

impl Encounters {
    /// The route is altered: an encounter keeps the alteration, or it is held for a
    /// target the tow stands on.
    fn altered(&self) -> bool {
        self.latched != 0 || self.course_held
    }

    fn new() -> Self {
        Self {
            latched: 0,
            course_held: false,
            way_off: 0,
            cleared: 0,
            crossed: 0,
            past: 0,
            standing_on: 0,
            held: [None; MAX_OBSTACLES],
            vessels: 0,
            sightings: [None; MAX_OBSTACLES],
        }
    }
}

impl ReferenceSystem {
    /// A reference system at the start of `route` (active waypoint 1).
    #[must_use]
    pub fn new(route: Route, params: GuidanceParams) -> Self {
        Self {
            route,
            params,
            active: 1,
            offset_held: 0.0,
            encounters: Encounters::new(),
        }
    }

    /// Takes the memory of `saved` (every field but the route and the parameters: the
    /// active waypoint and the encounters), keeping this system's route and parameters:
    /// restoring a controller's FMU state.
    ///
    /// # Errors
    /// An active waypoint outside this route (nothing changes then).
    pub fn restore(&mut self, saved: &ReferenceSystem) -> Result<(), String> {
        let n = self.route.points().len();
        if !(1..n).contains(&saved.active) {
            return Err(format!(
                "guidance: active waypoint {} is not in 1..{n} of the route",
                saved.active
            ));
        }
        *self = ReferenceSystem {
            route: self.route.clone(),
            params: self.params,
            ..saved.clone()
        };
        Ok(())
    }

    /// Back to the start of the route, no encounter.
    pub fn reset(&mut self) {
        self.active = 1;
        self.offset_held = 0.0;
        self.encounters = Encounters::new();
    }

    /// The route.
    #[must_use]
    pub fn route(&self) -> &Route {
        &self.route
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> &GuidanceParams {
        &self.params
    }

    /// Index of the active waypoint.
    #[must_use]
    pub fn active_waypoint(&self) -> usize {
        self.active
    }

    /// The COLREGS situation of obstacle slot `slot` at the last
    /// [`update`](Self::update): the one held for its encounter (fixed when the tow
    /// detects it, or acts for it under Rule 17, module docs), [`Situation::Safe`] for a
    /// target ship before that or after its encounter (the present reading of the
    /// geometry is [`ObstacleAssessment::situation`]); `None` for static hazards, empty
    /// slots and slots beyond those given.
    #[must_use]
    pub fn situation(&self, slot: usize) -> Option<Situation> {
        let e = &self.encounters;
        (slot < MAX_OBSTACLES && e.vessels & (1 << slot) != 0)
            .then(|| e.held[slot].unwrap_or(Situation::Safe))
    }

    /// True when the target ship in slot `slot` was past and clear at the last
    /// [`update`](Self::update) ([`ObstacleAssessment::past_and_clear`]).
    #[must_use]
    pub fn past_and_clear(&self, slot: usize) -> bool {
        slot < MAX_OBSTACLES && self.encounters.past & (1 << slot) != 0
    }

    /// True when the tow stands on for the target ship in slot `slot` at the last
    /// [`update`](Self::update): its policy is to keep course and speed
    /// ([`Action::StandOn`], [`Action::StandOnThenAct`]), it is not past and clear,
    /// Rule 17 does not yet let the tow act (for [`Action::StandOnThenAct`] its action
    /// point, for [`Action::StandOn`] close quarters:
    /// [`crate::Rule17Settings::close_quarters_tcpa`]), and the route is kept for it;
    /// or the tow has taken the way off for it (its action; the MPC's distance cost
    /// leaves it out, its clearance rows stay); or she gives way to it in a crossing and
    /// its track passes her clear ([`ObstacleAssessment::passes_clear`]).
    #[must_use]
    pub fn stands_on(&self, slot: usize) -> bool {
        slot < MAX_OBSTACLES && self.encounters.standing_on & (1 << slot) != 0
    }

    /// True while an encounter keeps the route altered, or the alteration is held for a
    /// target the tow stands on ([`GuidanceOutput::altered`]).
    #[must_use]
    pub fn is_altered(&self) -> bool {
        self.encounters.altered()
    }

    /// Altering angle of segment `p`: `theta`, bounded by `theta_max` (remark on
    /// the choice of `theta`).
    fn theta(&self, p: usize) -> f64 {
        let s = self.params.settings();
        match s.waterway_half_width {
            Some(d2) => s
                .altering_angle
                .min(theta_max(self.route.segment_length(p), d2)),
            None => s.altering_angle,
        }
    }

    /// Reference waypoint of segment `p` and the angle applied.
    fn reference(&self, p: usize, altered: bool) -> (Pose, f64) {
        let points = self.route.points();
        if altered {
            let theta = self.theta(p);
            (rotate_waypoint(points[p - 1], points[p], theta), theta)
        } else {
            (points[p], 0.0)
        }
    }

    /// The ship's offset to starboard of segment `p` (her signed distance from the
    /// segment's line), bounded to `[0, r sin(theta_max)]` with a waterway (`r` the
    /// segment's length, `theta_max` the paper's bound on `theta`: the farthest an
    /// altered waypoint of the segment lies from the route, inside the waterway) and to
    /// `[0, inf)` without one.
    fn offset_to_starboard(&self, ship: [f64; 2], p: usize) -> f64 {
        let points = self.route.points();
        let (a, b) = (points[p - 1].position(), points[p].position());
        let offset = starboard_offset(a, b, ship).map_or(0.0, |(offset, _)| offset);
        let r = self.route.segment_length(p);
        let bound = match self.params.settings().waterway_half_width {
            Some(d2) => r * theta_max(r, d2).sin(),
            None => f64::INFINITY,
        };
        offset.clamp(0.0, bound)
    }

    /// Whether the ship has reached the reference waypoint `target` of segment `p`:
    /// within the acceptance radius, or (with `advance_on_passing`) past it: past the
    /// line square to the segment at `target`, or, at a turn, past the line that
    /// bisects the turn there (the one through `target` square to the sum of the
    /// two legs' unit directions). A ship that cuts inside a turn, as the
    /// lookahead leads her to, reaches the next leg short of the first line: her
    /// tracked point, placed on the next leg the lookahead beyond the waypoint,
    /// then lay abeam of her, and she lay stopped beside it (random-12-0209:
    /// 300 s, 0.25 m short of the line after an 88 deg turn). The bisector is the
    /// usual switching line of waypoint guidance where legs meet at an angle
    /// (Fossen 2021, *Handbook of Marine Craft Hydrodynamics and Motion Control*,
    /// 2nd ed., section 12.4, on the circle of acceptance and switching; the
    /// bisector is the locus of points equally far from both legs' lines). On a
    /// straight run-on both lines are one. Not on an `altered` leg: its reference
    /// waypoint is a direction the tracked point runs on past, not a turn, and a
    /// bisector at the rotated waypoint ended the alteration early (random-12-0084).
    fn reached(&self, ship: [f64; 2], p: usize, target: Pose, altered: bool) -> bool {
        let s = self.params.settings();
        if dist(ship, target.position()) <= s.acceptance_radius {
            return true;
        }
        if !s.advance_on_passing {
            return false;
        }
        let points = self.route.points();
        let unit = |from: [f64; 2], to: [f64; 2]| {
            let d = [to[0] - from[0], to[1] - from[1]];
            let r = d[0].hypot(d[1]);
            (r > 0.0).then(|| [d[0] / r, d[1] / r])
        };
        let at = target.position();
        let rel = [ship[0] - at[0], ship[1] - at[1]];
        let passed = |n: [f64; 2]| rel[0] * n[0] + rel[1] * n[1] >= 0.0;
        let Some(e1) = unit(points[p - 1].position(), at) else {
            return false;
        };
        let bisector = points
            .get(p + 1)
            .filter(|_| !altered)
            .and_then(|next| unit(at, next.position()))
            .map(|e2| [e1[0] + e2[0], e1[1] + e2[1]])
            .filter(|n| n[0].hypot(n[1]) > 1e-9);
        passed(e1) || bisector.is_some_and(passed)
    }

    /// Steps 2 and 3 of the module doc for one assessed obstacle: what the next sample
    /// remembers of its encounter (held situation, sighting, past and clear, the
    /// alteration and way-off latches, standing on), written into `next`; true when it
    /// keeps the route altered.
    fn track(
        &self,
        next: &mut Encounters,
        a: &ObstacleAssessment,
        context: &AssessContext,
        sighting: Sighting,
    ) -> bool {
        let s = self.params.settings();
        let bit = 1u64 << a.index;
        let near = a.range <= s.detection_distance_for(a.kind) + s.release_margin || a.detected;
        let slowed = context.way_off;
        if a.past_and_clear {
            next.past |= bit;
        }
        // Rule 8(d): an action (the alteration or the way off) is held until the target
        // is finally past and clear: past and clear (it has crossed ahead of the ship by
        // its own motion, or is abaft her beam, and the range is opening and safe from
        // every vessel) and the tow resuming her route would pass it clear (else she
        // would turn or run back into a close-quarters situation with it); or until the
        // target has left: beyond the encounter distance, no longer closing, clear of
        // the resumed track, and drawing away (its track no longer meets the ship's
        // heading line ahead: "not closing" is judged with the tow's own velocity, and a
        // stopped tow finds every moving target not closing). A range opened by the
        // tow's own braking or turning releases nothing while her resumed track would
        // bring her back to it.
        let closing = a.encounter.is_some_and(|e| e.cpa.is_closing());
        let finally_clear = a.past_and_clear && a.resume_clear;
        let left = !near && !closing && a.resume_clear && a.drawing_away;
        let holds = context.acting && !finally_clear && !left;
        if a.manoeuvre == Manoeuvre::TakeWayOff || (slowed && holds) {
            next.way_off |= bit;
        }
        // An action taken under Rule 17 (judged by the CPA, possibly beyond d_D) or held
        // beyond d_D keeps the encounter open, up to the sample that releases it.
        let in_encounter = near || holds || next.way_off & bit != 0;
        // The way-off is the tow's action and lets the target pass ahead: the
        // MPC's distance cost leaves the target out as for a stand-on target (its
        // clearance rows stay), so the tugs do not swing the tow's head after it; so
        // does a target she stood on once it is past and clear and her resumed track
        // passes it clear: pushed off by the cost, the resuming tow turned 14 deg to
        // port, away from a slow target that had crossed ahead (`docs/colregs.md`).
        let stood_on = context
            .held
            .is_some_and(|h| matches!(h, Situation::CrossingStandOn | Situation::BeingOvertaken));
        let over = stood_on && a.past_and_clear && a.resume_clear;
        // So does a crossing target the tow gives way to once its track passes her clear
        // as she moves now: the distance cost made the forward tug of a tow stopped for
        // such a target dodge along its track, dragging the ship's head to port.
        if in_encounter
            && (next.way_off & bit != 0 || over || a.passes_clear || stands_on(&self.params, a))
        {
            next.standing_on |= bit;
        }
        if let (true, Some(situation)) = (in_encounter, a.situation) {
            let definite = situation != Situation::Safe;
            let acting = a.detected || a.manoeuvre != Manoeuvre::FollowRoute;
            next.held[a.index] = context.held.or((acting && definite).then_some(situation));
            next.sightings[a.index] = Some(sighting);
            if a.crossed {
                next.crossed |= bit;
            }
        } else if let Some(e) = a.encounter {
            // A target ship not (or no longer) in an encounter is watched too: one that
            // crosses the ship's heading line ahead of her by its own motion before any
            // vessel of the tow is within d_D has crossed as much as one seen crossing
            // within it, for as long as it keeps drawing away from that line (its own
            // velocity across the line points to the side it is on).
            next.sightings[a.index] = Some(sighting);
            let drawing_away = e.bearing.sin() * e.course_difference.sin() > 0.0;
            if a.crossed && drawing_away && e.target_speed > 0.0 {
                next.crossed |= bit;
            }
        }
        // The situation given out (and binding the heading floor) is the held one:
        // until the encounter begins the tow has no role towards the target (the paper:
        // stand-on beyond d_D), and a reading taken then is not one (a target on the
        // starboard bow before the route's own turn to starboard is on the port bow after
        // it); `ReferenceSystem::situation` gives safe for a vessel without one.
        if a.encounter.is_some() {
            next.vessels |= bit;
        }
        // An encounter found past and clear stays over until it ends (or a new
        // close-quarters situation arises, in `assess_obstacle`): the tow's own
        // return to the route must not turn an opening range into a new encounter.
        if in_encounter && a.past_and_clear && (context.cleared || context.acting) {
            next.cleared |= bit;
        }
        let demands = a.manoeuvre == Manoeuvre::AlterToStarboard;
        let keeps = self.encounters.latched & bit != 0 && a.alteration_allowed && holds;
        if demands || keeps {
            next.latched |= bit;
        }
        demands || keeps
    }

    /// One sample: assess the obstacles (slot `k` of `obstacles` is obstacle `k`;
    /// [`ObstacleKind::None`] slots are ignored), update the encounter state and the active
    /// waypoint, and return the reference.
    ///
    /// # Errors
    /// A non-finite tow state, more than [`MAX_OBSTACLES`] slots, or an invalid
    /// active obstacle ([`ActiveObstacle::from_slot`]). The state is then unchanged.
    pub fn update(
        &mut self,
        tow: &TowState,
        obstacles: &[ObstacleSlot],
    ) -> Result<GuidanceOutput, InputError> {
        tow.validate()?;
        if obstacles.len() > MAX_OBSTACLES {
            return Err(InputError::TooManyObstacles {
                count: obstacles.len(),
                max: MAX_OBSTACLES,
            });
        }
        let mut d_ob = f64::INFINITY;
        let mut nearest: Option<ObstacleAssessment> = None;
        let mut next = Encounters::new();
        let mut nearest_latched: Option<ObstacleAssessment> = None;
        let mut course_kept = false;
        let points = self.route.points();
        let leg = [
            points[self.active - 1].position(),
            points[self.active].position(),
            self.reference(self.active, true).0.position(),
        ];
        for (index, input) in obstacles.iter().enumerate() {
            let Some(obstacle) = ActiveObstacle::from_slot(input)? else {
                continue;
            };
            let bit = 1u64 << index;
            let context = AssessContext {
                held: match obstacle {
                    ActiveObstacle::Vessel(_) => self.encounters.held[index],
                    ActiveObstacle::Circle { .. } => None,
                },
                leg: Some(leg),
                cleared: self.encounters.cleared & bit != 0,
                previous: self.encounters.sightings[index],
                crossed: self.encounters.crossed & bit != 0,
                way_off: self.encounters.way_off & bit != 0,
                acting: (self.encounters.latched | self.encounters.way_off) & bit != 0,
            };
            let a = assess_obstacle(&self.params, tow, index, &obstacle, &context);
            if a.range < d_ob {
                d_ob = a.range;
                nearest = Some(a);
            }
            let sighting = Sighting {
                ship: tow.ship,
                target: obstacle.centre(),
            };
            course_kept |= keeps_course(&a);
            let keeps_altered = self.track(&mut next, &a, &context, sighting);
            if keeps_altered && nearest_latched.is_none_or(|n| a.range < n.range) {
                nearest_latched = Some(a);
            }
        }
        next.course_held = next.latched == 0 && self.encounters.altered() && course_kept;
        let altered = next.altered();
        let way_off = next.way_off;
        self.encounters = next;

        let ship = tow.ship.position();
        let last = self.route.last_index();
        let (mut target, mut theta) = self.reference(self.active, altered);
        let before = self.active;
        while self.active < last && self.reached(ship, self.active, target, altered) {
            self.active += 1;
            (target, theta) = self.reference(self.active, altered);
        }
        // Step 7: the offset gained while altered is held (of the new segment's line
        // once the active waypoint advances).
        self.offset_held = if altered {
            let offset = self.offset_to_starboard(ship, self.active);
            if self.active == before {
                self.offset_held.max(offset)
            } else {
                offset
            }
        } else {
            0.0
        };
        Ok(GuidanceOutput {
            eta_sd: target,
            offset_held: self.offset_held,
            route_waypoint: self.route.points()[self.active],
            active_waypoint: self.active,
            altered,
            way_off: way_off != 0,
            theta,
            d_ob,
            governing: if altered { nearest_latched } else { nearest },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colregs::Situation;
    use crate::params::{GuidanceSettings, StaticHazardPolicy};
    use std::f64::consts::PI;

    /// Forward tug CG ahead of the ship CG: l_2 + l_tow2 + l_T2 (Table 2).
    const TUG2_AHEAD: f64 = 0.585 + 1.0 + 0.5;
    /// Aft tug CG astern of the ship CG: l_1 + l_tow1 + l_T1.
    const TUG1_ASTERN: f64 = 0.67 + 1.0 + 0.5;

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    /// The tow in line at `ship`, moving along its heading at `speed`.
    fn tow_at(ship: Pose, speed: f64) -> TowState {
        let (s, c) = ship.psi.sin_cos();
        let at = |d: f64| Pose::new(ship.x + d * c, ship.y + d * s, ship.psi);
        TowState {
            ship,
            ship_vel_n: [speed * c, speed * s],
            tug1: at(-TUG1_ASTERN),
            tug2: at(TUG2_AHEAD),
        }
    }

    /// Moves the ship `speed * dt` straight towards `target` (kinematic tow).
    fn step_towards(tow: &TowState, target: Pose, speed: f64, dt: f64) -> TowState {
        let d = [target.x - tow.ship.x, target.y - tow.ship.y];
        let len = d[0].hypot(d[1]);
        if len < 1e-9 {
            return tow_at(tow.ship, 0.0);
        }
        let psi = d[1].atan2(d[0]);
        let step = (speed * dt).min(len);
        tow_at(
            Pose::new(
                tow.ship.x + step * psi.cos(),
                tow.ship.y + step * psi.sin(),
                psi,
            ),
            step / dt,
        )
    }

    fn vessel(x: f64, y: f64, psi: f64, speed: f64) -> ObstacleSlot {
        ObstacleSlot {
            x,
            y,
            psi,
            speed,
            length: 1.48,
            width: 0.48,
            kind: ObstacleKind::VesselEllipse,
        }
    }

    fn circle(x: f64, y: f64, diameter: f64) -> ObstacleSlot {
        ObstacleSlot {
            x,
            y,
            length: diameter,
            width: diameter,
            kind: ObstacleKind::StaticCircle,
            ..ObstacleSlot::default()
        }
    }

    /// A northbound route (0,0) -> (30,0) -> (60,0).
    fn north_route() -> Route {
        Route::from_positions(&[[0.0, 0.0], [30.0, 0.0], [60.0, 0.0]]).unwrap()
    }

    fn moved(o: ObstacleSlot, dt: f64) -> ObstacleSlot {
        ObstacleSlot {
            x: o.x + o.speed * dt * o.psi.cos(),
            y: o.y + o.speed * dt * o.psi.sin(),
            ..o
        }
    }

    #[test]
    fn no_obstacle_follows_the_paper_route_and_advances_every_waypoint() {
        let route = Route::paper();
        let mut rs = ReferenceSystem::new(route.clone(), GuidanceParams::default());
        let mut tow = tow_at(route.points()[0], 0.0);
        let mut visited = vec![1];
        for _ in 0..1000 {
            let out = rs.update(&tow, &[ObstacleSlot::default(); 8]).unwrap();
            assert!(!out.altered);
            assert_eq!(out.theta, 0.0);
            assert_eq!(out.d_ob, f64::INFINITY);
            assert!(out.governing.is_none());
            assert_eq!(out.eta_sd, route.points()[out.active_waypoint]);
            assert_eq!(out.route_waypoint, out.eta_sd);
            if *visited.last().unwrap() != out.active_waypoint {
                visited.push(out.active_waypoint);
            }
            tow = step_towards(&tow, out.eta_sd, 0.1, 1.0);
        }
        // Every waypoint in order, none skipped, the destination held.
        assert_eq!(visited, (1..=9).collect::<Vec<_>>());
        assert_eq!(rs.active_waypoint(), 9);
        assert!(dist(tow.ship.position(), [-43.0, 40.0]) < 1e-9);
    }

    #[test]
    fn target_within_detection_ahead_alters_to_starboard() {
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        // Head-on target 6 m ahead of tug 2 (range-equivalent about 6.04 m < 7 m).
        let target = vessel(2.0 + TUG2_AHEAD + 6.0, 0.2, PI, 0.07);
        let out = rs.update(&tow, &[target]).unwrap();
        assert!(out.altered);
        let g = out.governing.unwrap();
        assert_eq!(g.index, 0);
        assert_eq!(g.nearest_vessel, TowVessel::Tug2);
        assert_eq!(g.encounter.unwrap().situation, Situation::HeadOn);
        assert_eq!(g.action, Action::AlterToStarboard);
        assert!(g.range < 7.0 && g.range > 6.0);
        assert_eq!(out.d_ob, g.range);
        assert!((g.distance_eq9 - 2.0 * g.range).abs() < 1e-12);
        assert!((g.safe_distance_eq14 - 2.0 * (0.97 + 0.74 + 0.25)).abs() < 1e-12);
        // W_1 = (30, 0) rotated 15 deg clockwise about (0, 0): to the East.
        assert!((out.theta - deg(15.0)).abs() < 1e-15);
        assert!((out.eta_sd.x - 30.0 * deg(15.0).cos()).abs() < 1e-9);
        assert!((out.eta_sd.y - 30.0 * deg(15.0).sin()).abs() < 1e-9);
        assert!((out.eta_sd.psi - deg(15.0)).abs() < 1e-12);
        assert_eq!(out.route_waypoint, Pose::new(30.0, 0.0, 0.0));

        // The same target beyond d_D, its CPA more than 55 s away (Rule 17's TCPA):
        // not altered.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let far = vessel(2.0 + TUG2_AHEAD + 7.2, 0.2, PI, 0.05);
        let out = rs.update(&tow, &[far]).unwrap();
        assert!(out.governing.unwrap().encounter.unwrap().cpa.tcpa > 55.0);
        assert!(!out.altered);
        assert_eq!(out.eta_sd, Pose::new(30.0, 0.0, 0.0));
        assert_eq!(out.governing.unwrap().manoeuvre, Manoeuvre::FollowRoute);
    }

    #[test]
    fn the_offset_gained_while_altered_is_held_and_bounded_by_the_waterway() {
        // A straight northbound route with a waypoint every 6 m (as the random
        // encounters' routes), the waterway 4.5 m wide each side: an altered waypoint of
        // a segment lies at most 6 sin(theta_max) = 6 * 0.6 = 3.6 m off the route.
        let route =
            Route::from_positions(&[[0.0, 0.0], [6.0, 0.0], [12.0, 0.0], [18.0, 0.0]]).unwrap();
        let settings = GuidanceSettings {
            waterway_half_width: Some(4.5),
            ..GuidanceSettings::default()
        };
        let mut rs = ReferenceSystem::new(route, GuidanceParams::new(settings).unwrap());
        // A slow target ahead on the same course: the tow overtakes it, keeping out of
        // its way to starboard.
        let mut at = |x: f64, y: f64| {
            let ship = Pose::new(x, y, deg(10.0));
            let target = vessel(x + TUG2_AHEAD + 4.0, 0.2, 0.0, 0.03);
            rs.update(&tow_at(ship, 0.1), &[target]).unwrap()
        };
        let out = at(2.0, 0.0);
        assert!(out.altered && out.offset_held == 0.0);
        // Gained 1.2 m, then 0.4 m given back: 1.2 m held.
        assert!((at(3.0, 1.2).offset_held - 1.2).abs() < 1e-12);
        let out = at(3.5, 0.8);
        assert!((out.offset_held - 1.2).abs() < 1e-12);
        assert_eq!(out.active_waypoint, 1);
        // Past W_1N: the next segment's offset from where she is.
        let out = at(6.5, 1.7);
        assert_eq!(out.active_waypoint, 2);
        assert!((out.offset_held - 1.7).abs() < 1e-12);
        // Never beyond the waterway's bound.
        assert!((at(8.0, 5.0).offset_held - 3.6).abs() < 1e-12);
        // Not altered: none.
        let ship = Pose::new(9.0, 1.7, 0.0);
        let gone = vessel(-40.0, 0.0, PI, 0.03);
        let out = rs.update(&tow_at(ship, 0.1), &[gone]).unwrap();
        assert!(!out.altered && out.offset_held == 0.0);
    }

    /// Rule 16 with 17(a)(ii): a give-way tow acts no later than her failure to act
    /// would let the stand-on vessel act (closing, TCPA <= 55 s, DCPA < 2.5 m), even
    /// with the target still beyond d_D; the encounter is then held as one detected
    /// within it. A target passing wide is no risk and gets no action beyond d_D.
    #[test]
    fn a_give_way_tow_acts_by_the_cpa_when_the_target_closes_fast() {
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        let ship = tow.ship.position();
        // A crossing target from starboard at 0.25 m/s, 10 m from the point 4 m ahead,
        // where the ship will be 40 s on: TCPA 40 s, DCPA about 0.
        let aim = [ship[0] + 4.0, ship[1]];
        let from = [
            aim[0] + 10.0 * deg(70.0).cos(),
            aim[1] + 10.0 * deg(70.0).sin(),
        ];
        let course = (aim[1] - from[1]).atan2(aim[0] - from[0]);
        let fast = vessel(from[0], from[1], course, 0.25);
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let out = rs.update(&tow, &[fast]).unwrap();
        let g = out.governing.unwrap();
        assert!(g.range > 7.5, "beyond d_D + release margin: {}", g.range);
        let enc = g.encounter.unwrap();
        assert_eq!(enc.situation, Situation::CrossingGiveWay);
        assert!(enc.cpa.tcpa < 55.0 && enc.cpa.dcpa < 2.5, "{:?}", enc.cpa);
        assert!(g.detected && out.altered);
        assert_eq!(g.manoeuvre, Manoeuvre::AlterToStarboard);
        assert_eq!(rs.situation(0), Some(Situation::CrossingGiveWay));
        // The next sample, the target a little nearer: still in the encounter.
        let out = rs.update(&tow, &[moved(fast, 0.1)]).unwrap();
        assert!(out.altered);

        // The same target 5 m farther ahead, passing wide (DCPA about 3.9 m): no
        // action beyond d_D.
        let wide = vessel(from[0] + 5.0, from[1], course, 0.25);
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let out = rs.update(&tow, &[wide]).unwrap();
        let g = out.governing.unwrap();
        assert!(g.encounter.unwrap().cpa.dcpa > 2.5);
        assert!(!g.detected && !out.altered);
        assert_eq!(rs.situation(0), Some(Situation::Safe));
    }

    #[test]
    fn encounter_over_returns_to_the_unaltered_route_with_hysteresis() {
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        let tug2 = tow.tug2.x;
        let at = |ahead: f64| [vessel(tug2 + ahead, 0.0, PI, 0.07)];
        // The same target turned away, running from the tow faster than she goes.
        let away = |ahead: f64| [vessel(tug2 + ahead, 0.0, 0.0, 0.2)];
        assert!(rs.update(&tow, &at(6.0)).unwrap().altered);
        // Still closing, now 7.6 m ahead, beyond d_D + 0.5 m: the resumed track would
        // run into it, so the alteration is held (Rule 8(d), finally past and clear).
        let out = rs.update(&tow, &at(7.6)).unwrap();
        let g = out.governing.unwrap();
        assert!(!g.detected && !g.past_and_clear && !g.resume_clear);
        assert!(out.altered);
        // Running away, 7.3 m ahead: outside d_D but inside d_D + 0.5 m, still
        // altered (the encounter is not over).
        let out = rs.update(&tow, &away(7.3)).unwrap();
        let g = out.governing.unwrap();
        assert_eq!(g.situation, Some(Situation::HeadOn));
        assert!(!g.detected && !g.past_and_clear && g.resume_clear);
        assert!(out.altered);
        assert!(out.eta_sd.y > 0.0);
        // 7.6 m > 7.5 m, not closing, clear of the resumed track: over, back to the
        // predefined waypoint.
        let out = rs.update(&tow, &away(7.6)).unwrap();
        assert!(!out.altered);
        assert_eq!(out.theta, 0.0);
        assert_eq!(out.eta_sd, Pose::new(30.0, 0.0, 0.0));
        // A fresh target at 7.3 m (inside the margin but outside d_D) does not alter.
        let out = rs.update(&tow, &at(7.3)).unwrap();
        assert!(!out.altered);
        assert_eq!(out.governing.unwrap().situation, Some(Situation::HeadOn));
    }

    #[test]
    fn a_give_way_alteration_is_held_until_a_target_beyond_the_distance_draws_away() {
        // The tow stopped, giving way to a target crossing from starboard
        // (random-12-0238 at its release).
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.0);
        let near = vessel(tow.tug2.x + 4.0, 3.0, -PI / 2.0, 0.1);
        let out = rs.update(&tow, &[near]).unwrap();
        assert!(out.altered);
        assert_eq!(rs.situation(0), Some(Situation::CrossingGiveWay));
        // 8 m ahead of the forward tug and 0.5 m to starboard, beyond d_D + 0.5 m, heading
        // 30 deg to port of her heading: the range opens (the tow is stopped, so not
        // closing) and her resumed track passes it clear, but its track still meets her
        // heading line ahead of her: the alteration is held.
        let crossing = vessel(tow.tug2.x + 8.0, 0.5, deg(-30.0), 0.07);
        let out = rs.update(&tow, &[crossing]).unwrap();
        let g = out.governing.unwrap();
        assert!(!g.detected && !g.past_and_clear && g.resume_clear && !g.drawing_away);
        assert!(out.altered);
        // The same target turned away to starboard, 30 deg off her heading: drawing away
        // without crossing her line, it has left.
        let away = vessel(tow.tug2.x + 8.0, 0.5, deg(30.0), 0.07);
        let out = rs.update(&tow, &[away]).unwrap();
        let g = out.governing.unwrap();
        assert!(!g.crossed && !g.past_and_clear && g.drawing_away);
        assert!(!out.altered);
    }

    #[test]
    fn the_situation_given_out_is_the_one_held_from_detection() {
        // A crossing target beyond d_D is read crossing give-way from the geometry, but the
        // tow has no role towards it yet: safe is given out. Inside d_D the situation is
        // held, and it stays although the reading changes (the tow turns).
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        // On the starboard bow (y east), heading west across the route.
        let far = vessel(tow.tug2.x + 6.0, 5.0, -PI / 2.0, 0.1);
        let g = rs.update(&tow, &[far]).unwrap().governing.unwrap();
        assert!(!g.detected);
        assert_eq!(g.situation, Some(Situation::CrossingGiveWay));
        assert_eq!(rs.situation(0), Some(Situation::Safe));
        let near = vessel(tow.tug2.x + 4.0, 3.0, -PI / 2.0, 0.1);
        let g = rs.update(&tow, &[near]).unwrap().governing.unwrap();
        assert!(g.detected);
        assert_eq!(rs.situation(0), Some(Situation::CrossingGiveWay));
        // The tow turned 140 deg to starboard: the target, now abaft her beam, is read
        // afresh as overtaking her; the held situation is still the one given out.
        let turned = tow_at(Pose::new(2.0, 0.0, deg(140.0)), 0.1);
        let mut fresh = ReferenceSystem::new(north_route(), GuidanceParams::default());
        fresh.update(&turned, &[near]).unwrap();
        assert_eq!(fresh.situation(0), Some(Situation::BeingOvertaken));
        rs.update(&turned, &[near]).unwrap();
        assert_eq!(rs.situation(0), Some(Situation::CrossingGiveWay));
    }

    #[test]
    fn a_target_past_and_clear_releases_the_alteration_inside_the_detection_distance() {
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        let ahead = [vessel(tow.tug2.x + 6.0, 0.0, PI, 0.07)];
        let astern = |behind: f64| [vessel(tow.tug1.x - behind, 0.0, PI, 0.07)];
        // Astern and opening, 2.3 m behind tug 1: inside tug 1's safe range plus the
        // margin (L_T + a_j + d_S0 + 0.5 = 0.97 + 0.74 + 0.25 + 0.5 m), so not clear.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        assert!(rs.update(&tow, &ahead).unwrap().altered);
        let out = rs.update(&tow, &astern(2.3)).unwrap();
        let g = out.governing.unwrap();
        assert_eq!(g.encounter.unwrap().situation, Situation::Safe);
        // The encounter's situation is held.
        assert_eq!(g.situation, Some(Situation::HeadOn));
        assert!(g.detected && !g.past_and_clear);
        assert!(out.altered);
        // 3.0 m behind: past (opening from all three vessels) and clear: the
        // alteration ends although the target is well inside d_D (Rule 8(d)).
        let out = rs.update(&tow, &astern(3.0)).unwrap();
        let g = out.governing.unwrap();
        assert!(g.detected && g.past_and_clear);
        assert_eq!(g.manoeuvre, Manoeuvre::FollowRoute);
        assert!(!out.altered);
        assert_eq!(out.eta_sd, Pose::new(30.0, 0.0, 0.0));
        // The same position with the target closing (overtaking the tow at 0.3 m/s)
        // is not past: the encounter's policy applies again.
        let overtaking = [vessel(tow.tug1.x - 3.0, 0.0, 0.0, 0.3)];
        let g = rs.update(&tow, &overtaking).unwrap().governing.unwrap();
        assert!(!g.past_and_clear);
    }

    #[test]
    fn an_alteration_is_held_while_the_tow_stands_on_for_another_target() {
        // The head-on target's encounter ends as in the test above, but a target
        // overtaking the tow from astern is within d_D and not past: the tow stands on
        // for it (Rule 17(a)(i)), so the return to the route, a turn to port, waits.
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        let ahead = vessel(tow.tug2.x + 6.0, 0.0, PI, 0.07);
        let past = vessel(tow.tug1.x - 3.0, 0.0, PI, 0.07);
        let overtaking = vessel(tow.tug1.x - 4.0, 0.8, 0.0, 0.3);
        let none = ObstacleSlot::default();
        // On its own, the overtaking target alters nothing: the tow stands on.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let out = rs.update(&tow, &[none, overtaking]).unwrap();
        assert!(!out.altered);
        assert_eq!(rs.situation(1), Some(Situation::BeingOvertaken));
        assert!(rs.stands_on(1));
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        assert!(rs.update(&tow, &[ahead, none]).unwrap().altered);
        let altered = rs.update(&tow, &[ahead, none]).unwrap().eta_sd;
        // The head-on target past and clear, the overtaking one coming up: held, on the
        // same altered waypoint.
        let out = rs.update(&tow, &[past, overtaking]).unwrap();
        assert!(out.governing.is_none(), "no encounter asks for the action");
        assert!(rs.past_and_clear(0) && !rs.past_and_clear(1));
        assert!(out.altered && rs.is_altered());
        assert_eq!(out.eta_sd, altered);
        assert!(rs.update(&tow, &[past, overtaking]).unwrap().altered);
        // Once nothing asks the tow to keep her course, she returns to the route.
        let out = rs.update(&tow, &[past, none]).unwrap();
        assert!(!out.altered && !rs.is_altered());
        assert_eq!(out.eta_sd, Pose::new(30.0, 0.0, 0.0));
        // And an alteration released is not taken again by a stand-on target alone.
        assert!(!rs.update(&tow, &[none, overtaking]).unwrap().altered);
    }

    #[test]
    fn a_give_way_target_that_passes_the_stopped_tow_clear_leaves_the_distance_cost() {
        // A crossing target from starboard, westbound, 4 m ahead of tug 2's track line:
        // the tow alters for it and takes the way off; at rest, the target's track passes
        // every vessel of the tow clear, so the MPC's distance cost leaves it out (its
        // clearance rows stay). One aimed at tug 2 stays in the cost.
        let moving = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        let stopped = tow_at(moving.ship, 0.0);
        let ahead = |x: f64| [vessel(moving.tug2.x + x, 4.0, -PI / 2.0, 0.07)];
        for (x, clear) in [(4.0, true), (0.0, false)] {
            let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
            let out = rs.update(&moving, &ahead(x)).unwrap();
            let g = out.governing.unwrap();
            assert!(out.altered, "{g:?}");
            assert_eq!(g.situation, Some(Situation::CrossingGiveWay));
            assert!(
                !g.passes_clear && !rs.stands_on(0),
                "not before the action is held"
            );
            let out = rs.update(&stopped, &ahead(x)).unwrap();
            let g = out.governing.unwrap();
            assert!(out.altered);
            assert_eq!((g.passes_clear, rs.stands_on(0)), (clear, clear), "x = {x}");
        }
    }

    /// A give-way tow with the way off (at rest, heading North) and a crossing target
    /// on its starboard bow whose range opens by its own motion (it heads away
    /// north-east) but which has not crossed ahead: not past (the old test, an
    /// opening range beyond the safe range, released it). Once it has crossed the
    /// ship's heading line ahead of her, westbound, it is past and clear.
    #[test]
    fn a_give_way_alteration_is_held_while_the_resumed_track_would_run_up_on_the_target() {
        // A target converging slowly from starboard, nearly on the tow's course
        // (relative course -25 deg) and slower than she goes: it crosses ahead of the
        // tow, which has slowed and turned away, but resuming the route would run up on
        // it again. The range opened by the tow's own braking ends nothing.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let mut target = vessel(4.4, 4.57, deg(-25.0), 0.06);
        let mut ship = Pose::new(0.0, 0.0, 0.0);
        for _ in 0..40 {
            let out = rs.update(&tow_at(ship, 0.1), &[target]).unwrap();
            assert!(out.altered);
            assert_eq!(
                out.governing.unwrap().situation,
                Some(Situation::CrossingGiveWay)
            );
            ship.x += 0.1;
            target = moved(target, 1.0);
        }
        // The tow, turned 15 deg to starboard, has taken the way off; the target goes on.
        let stopped = tow_at(
            Pose {
                psi: deg(15.0),
                ..ship
            },
            0.0,
        );
        // Past and clear by the old test (crossed ahead, range opening and safe) but not
        // clear of the resumed track: held; released once the resumed track clears it.
        let (mut held, mut released) = (0, None);
        for k in 1..=600 {
            target = moved(target, 1.0);
            let out = rs.update(&stopped, &[target]).unwrap();
            let g = out.governing.unwrap();
            if g.past_and_clear && !g.resume_clear {
                assert!(
                    out.altered,
                    "released at {k} s with the resumed track not clear"
                );
                held += 1;
            }
            if !out.altered && released.is_none() {
                released = Some(g);
            }
        }
        assert!(held >= 10, "held {held} s past the old release");
        let g = released.expect("released once the resumed track passes clear");
        assert!(g.past_and_clear && g.resume_clear);
    }

    /// A target that crosses the ship's heading line ahead of her by its own motion
    /// before any vessel of the tow is within d_D has crossed when the encounter begins,
    /// and is past and clear once the range opens; one that turns back towards the line
    /// before the encounter has not.
    #[test]
    fn a_crossing_seen_before_the_encounter_counts_while_the_target_draws_away() {
        let tow = tow_at(Pose::new(0.0, 0.0, 0.0), 0.0);
        let west = -PI / 2.0;
        // 12 m ahead (beyond d_D = 7 m of tug 2, 2.1 m ahead), westbound across the bow.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        rs.update(&tow, &[vessel(12.0, 0.05, west, 0.07)]).unwrap();
        rs.update(&tow, &[vessel(12.0, -0.05, west, 0.07)]).unwrap();
        // Later, 8.5 m ahead and 2 m to port, still westbound (and closing: the
        // range-equivalent distance of a westbound ellipse ahead), within d_D of tug 2.
        let near = vessel(8.5, -2.0, west, 0.07);
        let g = rs.update(&tow, &[near]).unwrap().governing.unwrap();
        assert!(g.detected && g.crossed, "{g:?}");
        // The same crossing, but the target turned back east (towards the line) before
        // the encounter: not crossed.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        rs.update(&tow, &[vessel(12.0, 0.05, west, 0.07)]).unwrap();
        rs.update(&tow, &[vessel(12.0, -0.05, west, 0.07)]).unwrap();
        rs.update(&tow, &[vessel(12.0, -0.3, PI / 2.0, 0.07)])
            .unwrap();
        let g = rs
            .update(&tow, &[vessel(8.5, -2.0, west, 0.07)])
            .unwrap()
            .governing
            .unwrap();
        assert!(g.detected && !g.crossed, "{g:?}");
    }

    #[test]
    fn a_crossing_target_is_past_only_once_it_has_crossed_ahead_by_its_own_motion() {
        let tow = tow_at(Pose::new(0.0, 0.0, 0.0), 0.0);
        let params = GuidanceParams::default();
        let mut rs = ReferenceSystem::new(north_route(), params);
        // Crossing give-way: on the starboard bow, heading West across the bow.
        let crossing = vessel(5.5, 4.0, -PI / 2.0, 0.07);
        let out = rs.update(&tow, &[crossing]).unwrap();
        assert!(out.altered);
        assert_eq!(
            out.governing.unwrap().situation,
            Some(Situation::CrossingGiveWay)
        );
        // The same target now heading away north-east: the range opens by its own
        // motion, it is beyond every safe range, but it is still forward of the beam
        // on the starboard bow and has not crossed: the alteration holds.
        let away = vessel(5.5, 4.0, PI / 4.0, 0.07);
        let out = rs.update(&tow, &[away]).unwrap();
        let g = out.governing.unwrap();
        assert!(!g.past_and_clear && !g.crossed, "{g:?}");
        assert!(out.altered);
        // Westbound across the bow: at 5.5 m ahead it goes from starboard (y = 0.05)
        // to port (y = -0.05): crossed ahead by its own motion, and clear.
        let before = vessel(6.5, 0.05, -PI / 2.0, 0.07);
        let after = vessel(6.5, -0.05, -PI / 2.0, 0.07);
        rs.update(&tow, &[before]).unwrap();
        let g = rs.update(&tow, &[after]).unwrap().governing.unwrap();
        assert!(g.crossed);
        // 6.5 m ahead of the ship is about 4.4 m ahead of tug 2: clear of every safe range.
        assert!(g.past_and_clear, "{g:?}");
    }

    /// The sectors' gap: a closing target 40 deg on the starboard bow heading straight
    /// at the ship (contact angle 0) is unclassified by the Woerner sectors; the tow
    /// acts on its safe reading, crossing give-way, and alters at once.
    #[test]
    fn an_unclassified_target_forward_of_the_beam_is_given_way_to() {
        let tow = tow_at(Pose::new(0.0, 0.0, 0.0), 0.1);
        let beta = 40f64.to_radians();
        let (x, y) = (6.0 * beta.cos(), 6.0 * beta.sin());
        let target = vessel(x, y, (-y).atan2(-x), 0.05);
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let out = rs.update(&tow, &[target]).unwrap();
        let g = out.governing.unwrap();
        assert_eq!(g.encounter.unwrap().situation, Situation::Unclassified);
        assert_eq!(g.situation, Some(Situation::CrossingGiveWay));
        assert!(out.altered);
    }

    /// A target overtaking the tow from astern: the tow stands on (Rule 17(a)(i)), so
    /// the controller leaves it out of the distance cost, until close quarters
    /// (TCPA <= 30 s and DCPA < 2.5 m), when Rule 17(b) lets the tow act.
    #[test]
    fn the_tow_stands_on_for_an_overtaking_target_until_close_quarters() {
        let tow = tow_at(Pose::new(0.0, 0.0, 0.0), 0.05);
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        // 6 m astern, 2 m to starboard, northbound at 0.12 m/s: DCPA 2 m, TCPA 86 s.
        let far = vessel(-6.0, 2.0, 0.0, 0.12);
        let out = rs.update(&tow, &[far]).unwrap();
        assert_eq!(
            out.governing.unwrap().situation,
            Some(Situation::BeingOvertaken)
        );
        assert!(!out.altered && rs.stands_on(0));
        // 2.5 m astern: TCPA 36 s, still standing on; 1.5 m astern: TCPA 21 s.
        assert!(
            !rs.update(&tow, &[vessel(-2.5, 2.0, 0.0, 0.12)])
                .unwrap()
                .altered
        );
        assert!(rs.stands_on(0));
        rs.update(&tow, &[vessel(-1.5, 2.0, 0.0, 0.12)]).unwrap();
        assert!(!rs.stands_on(0));
        assert!(!rs.stands_on(1) && !rs.stands_on(MAX_OBSTACLES));
    }

    #[test]
    fn head_on_run_passes_port_to_port_and_returns_to_the_route() {
        let route = north_route();
        let mut rs = ReferenceSystem::new(route.clone(), GuidanceParams::default());
        let mut tow = tow_at(route.points()[0], 0.0);
        let mut target = vessel(40.0, 0.5, PI, 0.07);
        let (mut was_altered, mut min_range, mut rel_at_min) = (false, f64::INFINITY, [0.0; 2]);
        let mut released_at = None;
        for t in 0..700 {
            let out = rs.update(&tow, &[target]).unwrap();
            if out.altered {
                was_altered = true;
                // Starboard of the northbound route, heading turned clockwise.
                assert!(out.eta_sd.y > 0.0 && out.eta_sd.psi > 0.0);
            } else if was_altered && released_at.is_none() {
                released_at = Some(t);
                assert_eq!(out.eta_sd, route.points()[out.active_waypoint]);
            }
            let rel = [target.x - tow.ship.x, target.y - tow.ship.y];
            let r = rel[0].hypot(rel[1]);
            if r < min_range {
                min_range = r;
                rel_at_min = rel;
            }
            tow = step_towards(&tow, out.eta_sd, 0.1, 1.0);
            target = moved(target, 1.0);
        }
        assert!(was_altered && released_at.is_some());
        // At the closest point the target (which started 0.5 m to starboard of the
        // route) is on the ship's port side: a port-to-port pass (Rule 14).
        assert!(rel_at_min[1] < 0.0, "{rel_at_min:?}");
        assert!(min_range > 2.0, "{min_range}");
        assert_eq!(rs.active_waypoint(), 2);
        assert!(dist(tow.ship.position(), [60.0, 0.0]) < 1e-9);
    }

    /// Ship northbound at 0.1 m/s along the route, open loop; target from the port
    /// side heading East at 4/60 m/s, on a collision course with the ship at
    /// (6, 0) in 60 s.
    /// A give-way target from port on a collision course with the ship's centre: it
    /// reaches `(cross_x, 0)` at `t_cross` s on `course_deg` at `speed`, as the ship
    /// does at 0.1 m/s. The tow takes the way off as the guidance asks (at the Rule 17
    /// deceleration, down to its way-off speed, and resumes 0.1 m/s once it is released).
    /// Returns per second `(t, tcpa, altered, way_off, past_and_clear, out of the
    /// distance cost)` while the encounter lasts.
    fn stand_on_run(
        seconds: u32,
        (cross_x, t_cross): (f64, f64),
        (course_deg, speed): (f64, f64),
    ) -> Vec<(f64, f64, bool, bool, bool, bool)> {
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let rule17 = GuidanceSettings::default().colregs.rule17;
        let (sin, cos) = deg(course_deg).sin_cos();
        let start = [cross_x - speed * t_cross * cos, -speed * t_cross * sin];
        let (mut x, mut u) = (0.0, 0.1);
        let mut rows = Vec::new();
        for t in 0..seconds {
            let t = f64::from(t);
            let tow = tow_at(Pose::new(x, 0.0, 0.0), u);
            let target = moved(vessel(start[0], start[1], deg(course_deg), speed), t);
            let out = rs.update(&tow, &[target]).unwrap();
            let g = out.governing.unwrap();
            if g.situation != Some(Situation::CrossingStandOn) {
                assert!(t > t_cross, "t = {t}: {g:?}");
                break;
            }
            let tcpa = g.encounter.unwrap().cpa.tcpa;
            let off = rs.stands_on(0);
            rows.push((t, tcpa, out.altered, out.way_off, g.past_and_clear, off));
            u = if out.way_off {
                (u - rule17.way_off_deceleration).max(rule17.way_off_speed)
            } else {
                0.1
            };
            x += u;
        }
        rows
    }

    #[test]
    fn stand_on_crossing_from_port_waits_for_rule_17_then_takes_the_way_off() {
        // From 10.7 m off tug 2, beyond d_D, crossing the route 6 m ahead in 60 s.
        let rows = stand_on_run(200, (6.0, 60.0), (90.0, 10.0 / 60.0));
        let tcpa = GuidanceSettings::default().colregs.rule17.tcpa;
        let first = rows.iter().find(|r| r.3).expect("the way is taken off");
        // Kept course and speed until Rule 17 allowed action, then acted at once,
        // though the target was still beyond d_D (Rule 17 is judged by the CPA).
        assert!(rows.iter().take_while(|r| !r.3).all(|r| r.1 > tcpa));
        assert!(first.1 <= tcpa && first.1 > tcpa - 1.5, "{first:?}");
        // The route is never altered: the way-off lets the target pass ahead.
        assert!(rows.iter().all(|r| !r.2));
        // Held without a break until the target is clear of the tow, then released.
        let last = rows.iter().rposition(|r| r.3).unwrap();
        assert!(rows[..=last].iter().skip_while(|r| !r.3).all(|r| r.3));
        assert!(
            rows[last + 1].4,
            "released once past and clear: {:?}",
            rows[last + 1]
        );
        assert!(rows.len() > last + 1, "released within the encounter");
        // Out of the MPC's distance cost while the way is off (its action) and, once
        // past and clear with the resumed track passing the target clear, for the rest
        // of the encounter (here 40 s).
        let from = rows.iter().position(|r| r.3).unwrap();
        assert!(rows[from..last + 40].iter().all(|r| r.5), "{rows:?}");
    }

    #[test]
    fn a_stand_on_tow_alters_when_slowing_would_not_pass_the_target_farther() {
        // A tow restricted in her ability to manoeuvre stands on for a head-on target
        // (Rule 18); the target's track runs over the tow whether she slows or not, so
        // Rule 17's action is the starboard alteration.
        use crate::colregs::TowStatus;
        let mut settings = GuidanceSettings::default();
        settings.colregs.tow_status = TowStatus::RestrictedInAbilityToManoeuvre;
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::new(settings).unwrap());
        let target = vessel(14.0, 0.0, PI, 0.1);
        let mut acted = None;
        for t in 0..20 {
            let t = f64::from(t);
            let tow = tow_at(Pose::new(0.1 * t, 0.0, 0.0), 0.1);
            let out = rs.update(&tow, &[moved(target, t)]).unwrap();
            let g = out.governing.unwrap();
            assert_eq!(g.action, Action::StandOnThenAct);
            assert!(!out.way_off, "t = {t}: {out:?}");
            if out.altered && acted.is_none() {
                acted = Some(g.encounter.unwrap().cpa.tcpa);
            }
        }
        let tcpa = acted.expect("the route is altered");
        assert!(tcpa <= settings.colregs.rule17.tcpa && tcpa > settings.colregs.rule17.tcpa - 1.5);
    }

    #[test]
    fn stand_on_keeps_the_route_when_the_give_way_vessel_passes_wide() {
        // Same crossing, but the target crosses about 3.3 m ahead of the ship.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let (mut saw_detected, mut saw_overtaking_geometry) = (false, false);
        let speed_t = 4.0 / 60.0;
        for t in 0..150 {
            let t = f64::from(t);
            let tow = tow_at(Pose::new(0.1 * t, 0.0, 0.0), 0.1);
            let target = vessel(12.0, -4.0 + speed_t * t, deg(90.0), speed_t);
            let out = rs.update(&tow, &[target]).unwrap();
            assert!(!out.altered, "t = {t}: {out:?}");
            let g = out.governing.unwrap();
            if g.detected {
                // Held from detection, while the geometry later reads
                // "overtaking" once the target has crossed ahead.
                assert_eq!(g.situation, Some(Situation::CrossingStandOn), "t = {t}");
                saw_detected = true;
            }
            if g.encounter.unwrap().situation == Situation::Overtaking {
                saw_overtaking_geometry = true;
            }
        }
        assert!(saw_detected && saw_overtaking_geometry);
    }

    #[test]
    fn port_side_targets_never_move_the_reference_to_port() {
        // Targets on the port side at many bearings and headings, within d_D,
        // close to collision course or not: the reference is the route or to its
        // starboard side, for both presets and both tow statuses.
        use crate::colregs::{ThresholdPreset, TowStatus};
        for preset in [ThresholdPreset::Woerner, ThresholdPreset::Xu] {
            for status in [
                TowStatus::PowerDriven,
                TowStatus::RestrictedInAbilityToManoeuvre,
            ] {
                let mut settings = GuidanceSettings::default();
                settings.colregs.thresholds = preset.thresholds();
                settings.colregs.tow_status = status;
                let params = GuidanceParams::new(settings).unwrap();
                let tow = tow_at(Pose::new(5.0, 0.0, 0.0), 0.1);
                for beta in (-175..0).step_by(10) {
                    for heading in (0..360).step_by(15) {
                        let mut rs = ReferenceSystem::new(north_route(), params);
                        let b = deg(f64::from(beta));
                        let target = vessel(
                            5.0 + 3.0 * b.cos(),
                            3.0 * b.sin(),
                            deg(f64::from(heading)),
                            0.07,
                        );
                        let out = rs.update(&tow, &[target]).unwrap();
                        assert!(out.eta_sd.y >= 0.0, "{beta} {heading}: {out:?}");
                        assert!(out.eta_sd.psi >= 0.0);
                    }
                }
            }
        }
    }

    #[test]
    fn d_ob_is_the_minimum_over_the_three_vessels_and_kind_0_is_ignored() {
        let tow = tow_at(Pose::new(0.0, 0.0, 0.0), 0.1);
        let cases = [
            // Beside the ship: ship nearest.
            ([0.0, -2.0], TowVessel::Ship, 2.0),
            // Astern: tug 1 nearest.
            ([-TUG1_ASTERN - 1.5, 0.0], TowVessel::Tug1, 1.5),
            // Ahead: tug 2 nearest.
            ([TUG2_AHEAD + 2.2, 0.5], TowVessel::Tug2, 2.2f64.hypot(0.5)),
        ];
        let by_distance = GuidanceParams::new(GuidanceSettings {
            static_hazard_policy: StaticHazardPolicy::ByDistance,
            ..GuidanceSettings::default()
        })
        .unwrap();
        for (pos, vessel_expected, d) in cases {
            let mut rs = ReferenceSystem::new(north_route(), by_distance);
            let empty = ObstacleSlot {
                x: f64::NAN,
                kind: ObstacleKind::None,
                ..ObstacleSlot::default()
            };
            let far = circle(-50.0, -50.0, 1.0);
            let out = rs
                .update(&tow, &[empty, far, circle(pos[0], pos[1], 1.0)])
                .unwrap();
            assert!((out.d_ob - d).abs() < 1e-12, "{out:?}");
            let g = out.governing.unwrap();
            assert_eq!(g.index, 2);
            assert_eq!(g.nearest_vessel, vessel_expected);
            assert!(g.encounter.is_none());
            // Static hazard within 2.5 m: altered by distance (the paper's rule).
            assert!(out.altered);
            assert!(g.alteration_allowed);
            let length = if vessel_expected == TowVessel::Ship {
                1.255
            } else {
                0.97
            };
            assert!((g.safe_distance_eq14 - (length + 0.5 + 0.25)).abs() < 1e-12);
        }
        // Only an empty slot sitting on the ship: nothing.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let ghost = ObstacleSlot {
            kind: ObstacleKind::None,
            ..circle(0.0, 0.0, 1.0)
        };
        let out = rs.update(&tow, &[ghost]).unwrap();
        assert_eq!(out.d_ob, f64::INFINITY);
        assert!(!out.altered && out.governing.is_none());
    }

    #[test]
    fn static_hazard_alters_only_where_altering_helps() {
        // Ship at (5, 0) on the northbound leg (0,0) -> (30,0); W_1N = (28.98, 7.76).
        let tow = tow_at(Pose::new(5.0, 0.0, 0.0), 0.1);
        let check = |params: GuidanceParams, pos: [f64; 2]| {
            let mut rs = ReferenceSystem::new(north_route(), params);
            let out = rs.update(&tow, &[circle(pos[0], pos[1], 1.0)]).unwrap();
            let g = out.governing.unwrap();
            assert!(g.detected, "{pos:?}");
            (out.altered, g.alteration_allowed)
        };
        let helps = GuidanceParams::default();
        let by_distance = GuidanceParams::new(GuidanceSettings {
            static_hazard_policy: StaticHazardPolicy::ByDistance,
            ..GuidanceSettings::default()
        })
        .unwrap();
        // Ahead on the route line and to port: the altered leg passes it farther.
        assert_eq!(check(helps, [9.0, 0.0]), (true, true));
        assert_eq!(check(helps, [6.0, -2.0]), (true, true));
        // To starboard: the altered leg would approach it; the route is kept.
        assert_eq!(check(helps, [6.0, 2.0]), (false, false));
        // Astern of W_{p-1}: both legs pass it alike; no alteration.
        let mut rs = ReferenceSystem::new(north_route(), helps);
        let near_start = tow_at(Pose::new(0.5, 0.0, 0.0), 0.1);
        assert!(
            !rs.update(&near_start, &[circle(-1.0, 0.0, 1.0)])
                .unwrap()
                .altered
        );
        // The paper's literal rule alters for all of them.
        assert_eq!(check(by_distance, [6.0, 2.0]), (true, true));
        assert_eq!(check(by_distance, [9.0, 0.0]), (true, true));
    }

    #[test]
    fn static_hazard_releases_when_a_new_leg_makes_altering_useless() {
        // Route (0,0) -> (10,0) -> (10,10). A hazard at (9, -1) lies to port of
        // leg 1 (altering helps) and behind the start of leg 2 (both legs of leg 2
        // pass it alike: altering does not help).
        let route = Route::from_positions(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]).unwrap();
        let mut rs = ReferenceSystem::new(route, GuidanceParams::default());
        let hazard = [circle(9.0, -1.0, 1.0)];
        let out = rs
            .update(&tow_at(Pose::new(8.0, 0.0, 0.0), 0.1), &hazard)
            .unwrap();
        assert!(out.altered && out.active_waypoint == 1);
        // At W_1N = (9.66, 2.59), heading East: the waypoint is reached, leg 2 is
        // active; tug 1 is 1.56 m from the hazard.
        let at_w1n = tow_at(Pose::new(9.66, 2.59, deg(90.0)), 0.1);
        let out = rs.update(&at_w1n, &hazard).unwrap();
        assert_eq!(out.active_waypoint, 2);
        // Next sample: the hazard no longer holds the alteration, although it is
        // within its distance.
        let out = rs.update(&at_w1n, &hazard).unwrap();
        assert!(!out.altered, "{out:?}");
        let g = out.governing.unwrap();
        assert!(g.detected && !g.alteration_allowed && out.d_ob < 2.5);
    }

    #[test]
    fn static_hazard_beyond_its_distance_does_not_alter() {
        // The paper's hazard c passes 2.98 m from the route: no alteration at 2.9 m.
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let tow = tow_at(Pose::new(5.0, 0.0, 0.0), 0.1);
        let out = rs.update(&tow, &[circle(5.0, -2.9, 1.0)]).unwrap();
        assert!(!out.altered);
        assert!((out.d_ob - 2.9).abs() < 1e-12);
        assert!(rs.update(&tow, &[circle(5.0, -2.4, 1.0)]).unwrap().altered);
    }

    #[test]
    fn theta_is_clamped_to_theta_max() {
        let settings = GuidanceSettings {
            waterway_half_width: Some(1.0),
            ..GuidanceSettings::default()
        };
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::new(settings).unwrap());
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        let out = rs.update(&tow, &[circle(2.0, -2.0, 1.0)]).unwrap();
        assert!(out.altered);
        let bound = (1.0f64 / 30.0).atan();
        assert!((out.theta - bound).abs() < 1e-15);
        assert!((out.eta_sd.psi - bound).abs() < 1e-15);
        assert!(out.eta_sd.y > 0.0 && out.eta_sd.y < 1.0);
    }

    #[test]
    fn passing_beside_a_waypoint_advances() {
        let route = north_route();
        let mut rs = ReferenceSystem::new(route.clone(), GuidanceParams::default());
        // 1 m beside W_1, just past its normal line.
        let out = rs
            .update(&tow_at(Pose::new(30.01, 1.0, 0.0), 0.1), &[])
            .unwrap();
        assert_eq!(out.active_waypoint, 2);
        // Without the passing rule, it does not.
        let settings = GuidanceSettings {
            advance_on_passing: false,
            ..GuidanceSettings::default()
        };
        let mut rs = ReferenceSystem::new(route, GuidanceParams::new(settings).unwrap());
        let out = rs
            .update(&tow_at(Pose::new(30.01, 1.0, 0.0), 0.1), &[])
            .unwrap();
        assert_eq!(out.active_waypoint, 1);
        // Within the acceptance radius it does.
        let out = rs
            .update(&tow_at(Pose::new(29.6, 0.3, 0.0), 0.1), &[])
            .unwrap();
        assert_eq!(out.active_waypoint, 2);
        // The destination is held, even far past it.
        let out = rs
            .update(&tow_at(Pose::new(80.0, 0.0, 0.0), 0.1), &[])
            .unwrap();
        assert_eq!(out.active_waypoint, 2);
        assert_eq!(out.eta_sd, Pose::new(60.0, 0.0, 0.0));
    }

    #[test]
    fn a_ship_cutting_inside_a_turn_advances_at_the_bisector() {
        // North 30 m, then a 90 deg turn to starboard (East) for 30 m.
        let route = Route::from_positions(&[[0.0, 0.0], [30.0, 0.0], [30.0, 30.0]]).unwrap();
        // Inside the turn, 0.5 m short of W_1's normal line and 1.4 m past its
        // bisector (the line through W_1 at 45 deg), 2.55 m from W_1: outside the
        // acceptance radius and short of the first leg's end, but nearer the second
        // leg's line than the first's.
        let ship = Pose::new(29.5, 2.5, std::f64::consts::FRAC_PI_2);
        let mut rs = ReferenceSystem::new(route.clone(), GuidanceParams::default());
        assert_eq!(
            rs.update(&tow_at(ship, 0.1), &[]).unwrap().active_waypoint,
            2
        );
        // Short of both lines (2 m short of the normal, 1.5 m inside the first leg,
        // 0.35 m short of the bisector) it does not advance yet.
        let mut rs = ReferenceSystem::new(route, GuidanceParams::default());
        let before = Pose::new(28.0, 1.5, 0.0);
        assert_eq!(
            rs.update(&tow_at(before, 0.1), &[])
                .unwrap()
                .active_waypoint,
            1
        );
    }

    #[test]
    fn bad_inputs_are_refused_and_leave_the_state_unchanged() {
        let mut rs = ReferenceSystem::new(north_route(), GuidanceParams::default());
        let tow = tow_at(Pose::new(2.0, 0.0, 0.0), 0.1);
        assert!(rs.update(&tow, &[circle(2.0, -2.0, 1.0)]).unwrap().altered);
        let bad = ObstacleSlot {
            x: f64::NAN,
            kind: ObstacleKind::VesselEllipse,
            ..ObstacleSlot::default()
        };
        assert_eq!(
            rs.update(&tow, &[bad]),
            Err(InputError::NonFiniteObstacle { field: "x" })
        );
        assert!(rs.is_altered());
        let mut nan_tow = tow;
        nan_tow.tug2.y = f64::NAN;
        assert!(matches!(
            rs.update(&nan_tow, &[]),
            Err(InputError::NonFiniteTowState { field: "tug2.y" })
        ));
        let many = [ObstacleSlot::default(); MAX_OBSTACLES + 1];
        assert!(matches!(
            rs.update(&tow, &many),
            Err(InputError::TooManyObstacles { .. })
        ));
        assert!(rs.is_altered() && rs.active_waypoint() == 1);
        rs.reset();
        assert!(!rs.is_altered());
    }

    #[test]
    fn same_inputs_give_bit_identical_outputs() {
        let run = || {
            let mut rs = ReferenceSystem::new(Route::paper(), GuidanceParams::default());
            let mut tow = tow_at(Route::paper().points()[0], 0.0);
            let mut target = vessel(-19.0, 21.0, 0.0, 0.07);
            let mut outs = Vec::new();
            for _ in 0..400 {
                let out = rs
                    .update(&tow, &[target, circle(-10.0, 15.0, 1.0)])
                    .unwrap();
                outs.push(out);
                tow = step_towards(&tow, out.eta_sd, 0.1, 1.0);
                target = moved(target, 1.0);
            }
            outs
        };
        let (a, b) = (run(), run());
        assert_eq!(a, b);
        // The paper's first encounter (target A crossing from starboard) alters the
        // route at some point.
        assert!(a.iter().any(|o| o.altered
            && o.governing.is_some_and(|g| g
                .encounter
                .is_some_and(|e| e.situation == Situation::CrossingGiveWay))));
    }
}

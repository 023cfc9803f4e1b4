//! COLREGS encounter classification (Rules 13-15), the tow's role and the policy per
//! situation (Rules 8, 13-18), including Rule 17's "act when the give-way vessel
//! does not".
//!
//! Angles (`reference/colregs.md`, signed here, radians):
//! - `beta`, the relative bearing of the target from own bow, `(-pi, pi]`,
//!   positive to starboard;
//! - `alpha`, the contact angle: the relative bearing of own ship from the
//!   target's bow, same convention;
//! - the course difference `psi_target - psi_own`, wrapped.
//!
//! A bearing is "abaft the beam" (Rule 13: "more than 22.5 degrees abaft her
//! beam") when its magnitude exceeds [`EncounterThresholds::beam_sector`]
//! (112.5 deg). Boundaries are inclusive on the side named by each threshold's doc;
//! the sector tests sit on either side of every boundary.

use serde::{Deserialize, Serialize};

use crate::distance::Ellipse;
use crate::error::ParamError;
use crate::geometry::{cpa, relative_bearing, wrap_angle, Cpa};
use towing_model::Pose;

/// COLREGS situation of own ship with respect to one target ship. Static hazards
/// have none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Situation {
    /// No risk of collision: the range is opening (TCPA <= 0), there is no relative
    /// motion, or the DCPA exceeds the optional `risk_dcpa`.
    Safe,
    /// Rule 14: reciprocal or nearly reciprocal courses.
    HeadOn,
    /// Rule 15, target on own starboard side: own ship gives way (and avoids
    /// crossing ahead).
    CrossingGiveWay,
    /// Rule 15, target on own port side: own ship stands on (Rule 17).
    CrossingStandOn,
    /// Rule 13: own ship overtakes the target (comes up from more than 22.5 deg
    /// abaft its beam) and keeps out of its way.
    Overtaking,
    /// Rule 13 seen from the other side: the target overtakes own ship, which stands
    /// on (Rule 17).
    BeingOvertaken,
    /// Closing, but the geometry lies in none of the sectors of the thresholds in
    /// use (e.g. with the Woerner-style preset, a target 20 deg on the bow heading
    /// straight at own ship, `|alpha| < 10 deg`; or a target crossing own bow,
    /// whose view and own disagree on who is on whose starboard side). Roles are
    /// unclear; Rule 7(a): risk is deemed to exist, so the tow watches the CPA and
    /// acts to starboard when it becomes short ([`Action::StandOnThenAct`]).
    Unclassified,
}

impl Situation {
    /// Integer code for logs and FMI outputs: 0 safe, 1 head-on, 2 crossing
    /// give-way, 3 crossing stand-on, 4 overtaking, 5 being overtaken,
    /// 6 unclassified.
    #[must_use]
    pub fn code(self) -> i32 {
        match self {
            Self::Safe => 0,
            Self::HeadOn => 1,
            Self::CrossingGiveWay => 2,
            Self::CrossingStandOn => 3,
            Self::Overtaking => 4,
            Self::BeingOvertaken => 5,
            Self::Unclassified => 6,
        }
    }

    /// The situation of a [`Situation::code`] (`None` for any other number).
    #[must_use]
    pub fn from_code(code: i32) -> Option<Self> {
        [
            Self::Safe,
            Self::HeadOn,
            Self::CrossingGiveWay,
            Self::CrossingStandOn,
            Self::Overtaking,
            Self::BeingOvertaken,
            Self::Unclassified,
        ]
        .into_iter()
        .find(|s| s.code() == code)
    }

    /// Text for logs and reports, e.g. `crossing give-way`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Safe => "safe",
            Self::HeadOn => "head-on",
            Self::CrossingGiveWay => "crossing give-way",
            Self::CrossingStandOn => "crossing stand-on",
            Self::Overtaking => "overtaking",
            Self::BeingOvertaken => "being overtaken",
            Self::Unclassified => "unclassified",
        }
    }

    /// The rule that defines the situation.
    #[must_use]
    pub fn rule(self) -> &'static str {
        match self {
            Self::Safe => "none",
            Self::HeadOn => "Rule 14",
            Self::CrossingGiveWay | Self::CrossingStandOn => "Rule 15",
            Self::Overtaking | Self::BeingOvertaken => "Rule 13",
            Self::Unclassified => "Rule 7(a)",
        }
    }
}

/// Angle thresholds of the classifier (radians). Build one from a
/// [`ThresholdPreset`]; custom values are checked by [`EncounterThresholds::validate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EncounterThresholds {
    /// Head-on if `|beta| <= head_on_bearing` (and the optional tests below).
    pub head_on_bearing: f64,
    /// Head-on also needs `|alpha| <= head_on_contact` (own ship nearly ahead of
    /// the target), if set.
    pub head_on_contact: Option<f64>,
    /// Head-on also needs `|pi - |course difference|| <= tolerance` (nearly
    /// reciprocal courses), if set.
    pub head_on_course_tolerance: Option<f64>,
    /// Crossing needs `crossing_min_bearing <= |beta| <= beam_sector`.
    pub crossing_min_bearing: f64,
    /// Crossing also needs own ship on the target's opposite side:
    /// `lo <= |alpha| <= hi` with `alpha` of the opposite sign to `beta`
    /// (target on own starboard sees own ship to port), if set.
    pub crossing_contact: Option<(f64, f64)>,
    /// The Rule 13 sector limit: abaft the beam means `|bearing| > beam_sector`.
    pub beam_sector: f64,
    /// Overtaking needs the overtaken vessel within this angle of the overtaking
    /// vessel's bow (`|beta| <=` when own ship overtakes, `|alpha| <=` when being
    /// overtaken), if set.
    pub overtaking_bearing: Option<f64>,
    /// Overtaking needs `|course difference| <= overtaking_course_difference`, if set.
    pub overtaking_course_difference: Option<f64>,
}

/// Named threshold sets of `reference/colregs.md`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum ThresholdPreset {
    /// Woerner-style evaluators (Woerner 2018, with Minne and Hagen):
    /// head-on `|beta| < 13` and `|alpha| < 13` deg; crossing give-way
    /// `0 <= beta <= 112.5` and `-112.5 <= alpha <= -10` deg, stand-on mirrored;
    /// overtaking `|alpha| > 112.5`, `|beta| < 45` deg, own ship faster.
    ///
    /// The default: it checks both ships' views (bearing and contact angle), so a
    /// target ahead but heading elsewhere is not head-on; it calls the paper's
    /// third encounter (target C 0.5 m beside the reciprocal track) head-on down to
    /// 2.2 m, as the paper does, where Xu's 5 deg bearing turns it into a port-side
    /// crossing inside 5.7 m; and it is the set of the compliance scoring in
    /// `reference/colregs.md`, so guidance and evaluation agree.
    #[default]
    Woerner,
    /// Xu et al.: head-on `|beta| <= 5` deg with course difference 175-185 deg;
    /// crossing starboard `beta` in `[5, 112.5]`, port `[-112.5, -5]` deg;
    /// overtaking target abaft the beam (112.5-247.5 deg), course difference
    /// <= 67.5 deg, faster.
    Xu,
}

impl ThresholdPreset {
    /// The thresholds of this preset.
    #[must_use]
    pub fn thresholds(self) -> EncounterThresholds {
        let d = f64::to_radians;
        match self {
            Self::Woerner => EncounterThresholds {
                head_on_bearing: d(13.0),
                head_on_contact: Some(d(13.0)),
                head_on_course_tolerance: None,
                crossing_min_bearing: 0.0,
                crossing_contact: Some((d(10.0), d(112.5))),
                beam_sector: d(112.5),
                overtaking_bearing: Some(d(45.0)),
                overtaking_course_difference: None,
            },
            Self::Xu => EncounterThresholds {
                head_on_bearing: d(5.0),
                head_on_contact: None,
                head_on_course_tolerance: Some(d(5.0)),
                crossing_min_bearing: d(5.0),
                crossing_contact: None,
                beam_sector: d(112.5),
                overtaking_bearing: None,
                overtaking_course_difference: Some(d(67.5)),
            },
        }
    }
}

impl Default for EncounterThresholds {
    fn default() -> Self {
        ThresholdPreset::default().thresholds()
    }
}

fn check_angle(name: &'static str, value: f64, max: f64) -> Result<(), ParamError> {
    if value.is_finite() && (0.0..=max).contains(&value) {
        Ok(())
    } else {
        Err(ParamError::OutOfRange {
            name,
            value,
            reason: "an angle in [0, pi] rad (beam_sector: [pi/2, pi])",
        })
    }
}

impl EncounterThresholds {
    /// Checks every angle: finite, in `[0, pi]`; `beam_sector` in `[pi/2, pi]`;
    /// `crossing_contact` `lo <= hi`.
    ///
    /// # Errors
    /// [`ParamError::OutOfRange`] naming the first bad field.
    pub fn validate(&self) -> Result<(), ParamError> {
        use std::f64::consts::{FRAC_PI_2, PI};
        check_angle("head_on_bearing", self.head_on_bearing, PI)?;
        if let Some(v) = self.head_on_contact {
            check_angle("head_on_contact", v, PI)?;
        }
        if let Some(v) = self.head_on_course_tolerance {
            check_angle("head_on_course_tolerance", v, PI)?;
        }
        check_angle("crossing_min_bearing", self.crossing_min_bearing, PI)?;
        if let Some((lo, hi)) = self.crossing_contact {
            check_angle("crossing_contact.lo", lo, PI)?;
            check_angle("crossing_contact.hi", hi, PI)?;
            if lo > hi {
                return Err(ParamError::OutOfRange {
                    name: "crossing_contact.lo",
                    value: lo,
                    reason: "must not exceed crossing_contact.hi",
                });
            }
        }
        check_angle("beam_sector", self.beam_sector, PI)?;
        if self.beam_sector < FRAC_PI_2 {
            return Err(ParamError::OutOfRange {
                name: "beam_sector",
                value: self.beam_sector,
                reason: "in [pi/2, pi] rad (112.5 deg in Rule 13)",
            });
        }
        if let Some(v) = self.overtaking_bearing {
            check_angle("overtaking_bearing", v, PI)?;
        }
        if let Some(v) = self.overtaking_course_difference {
            check_angle("overtaking_course_difference", v, PI)?;
        }
        Ok(())
    }
}

/// The geometry and situation of one encounter, from own ship's point of view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Encounter {
    /// The situation.
    pub situation: Situation,
    /// `beta`: bearing of the target from own bow (rad, `(-pi, pi]`, + starboard).
    pub bearing: f64,
    /// `alpha`: bearing of own ship from the target's bow (rad).
    pub contact_angle: f64,
    /// `psi_target - psi_own`, wrapped (rad).
    pub course_difference: f64,
    /// CPA of own ship's and the target's centres.
    pub cpa: Cpa,
    /// Own speed over ground (m/s).
    pub own_speed: f64,
    /// Target speed (m/s).
    pub target_speed: f64,
}

/// Classifies the encounter of own ship (pose, ground velocity `own_vel_n` in NED,
/// m/s) with a target ship (its centre, heading = course, speed), Rules 13-15.
///
/// Order: [`Situation::Safe`] if not closing (or DCPA > `risk_dcpa` when given);
/// then head-on; overtaking (Rule 13 applies "notwithstanding" Rules 4-18, so it
/// wins over crossing); being overtaken; crossing; otherwise
/// [`Situation::Unclassified`].
#[must_use]
pub fn classify(
    own: Pose,
    own_vel_n: [f64; 2],
    target: &Ellipse,
    thresholds: &EncounterThresholds,
    risk_dcpa: Option<f64>,
) -> Encounter {
    let th = thresholds;
    let target_pos = target.centre;
    let beta = relative_bearing(own.x, own.y, own.psi, target_pos);
    let alpha = relative_bearing(target_pos[0], target_pos[1], target.psi, own.position());
    let course_difference = wrap_angle(target.psi - own.psi);
    let c = cpa(own.position(), own_vel_n, target_pos, target.velocity());
    let own_speed = own_vel_n[0].hypot(own_vel_n[1]);
    let target_speed = target.speed;

    let situation = (|| {
        if !c.is_closing() || risk_dcpa.is_some_and(|d| c.dcpa > d) {
            return Situation::Safe;
        }
        let head_on = beta.abs() <= th.head_on_bearing
            && th.head_on_contact.is_none_or(|a| alpha.abs() <= a)
            && th
                .head_on_course_tolerance
                .is_none_or(|t| std::f64::consts::PI - course_difference.abs() <= t);
        if head_on {
            return Situation::HeadOn;
        }
        let course_ok = th
            .overtaking_course_difference
            .is_none_or(|t| course_difference.abs() <= t);
        let overtaking = alpha.abs() > th.beam_sector
            && own_speed > target_speed
            && th.overtaking_bearing.is_none_or(|b| beta.abs() <= b)
            && course_ok;
        if overtaking {
            return Situation::Overtaking;
        }
        let overtaken = beta.abs() > th.beam_sector
            && target_speed > own_speed
            && th.overtaking_bearing.is_none_or(|b| alpha.abs() <= b)
            && course_ok;
        if overtaken {
            return Situation::BeingOvertaken;
        }
        if beta.abs() >= th.crossing_min_bearing && beta.abs() <= th.beam_sector {
            let starboard = beta >= 0.0;
            let contact_ok = th.crossing_contact.is_none_or(|(lo, hi)| {
                // Own ship must be on the target's side opposite to `beta`'s.
                let opposite = if starboard { -alpha } else { alpha };
                (lo..=hi).contains(&opposite)
            });
            if contact_ok {
                return if starboard {
                    Situation::CrossingGiveWay
                } else {
                    Situation::CrossingStandOn
                };
            }
        }
        Situation::Unclassified
    })();

    Encounter {
        situation,
        bearing: beta,
        contact_angle: alpha,
        course_difference,
        cpa: c,
        own_speed,
        target_speed,
    }
}

/// The situation the tow acts on: the classified one, or where the sectors leave a gap
/// ([`Situation::Unclassified`]) the safe reading of it (`docs/colregs.md`, "Gaps
/// between the sectors"). Risk of collision is deemed to exist (Rule 7(a): "if there is
/// any doubt such risk shall be deemed to exist"), so a closing target never stays
/// without a situation and an action:
/// - own ship more than `beam_sector` abaft the target's beam: own ship is overtaking
///   (Rule 13(c): "when a vessel is in any doubt as to whether she is overtaking
///   another, she shall assume that this is the case");
/// - the target more than `beam_sector` abaft own beam: the target comes up from
///   astern, so own ship is being overtaken and stands on (Rules 13, 17);
/// - otherwise the target is forward of own beam: own ship gives way (Rules 15 and 16
///   give way to the vessel on the own starboard side; for one whose side is in doubt,
///   keeping out of its way by a starboard alteration and slackening is what Rule 17(c)
///   still allows and what Rule 8 asks of an action taken in doubt).
#[must_use]
pub fn safe_reading(encounter: &Encounter, thresholds: &EncounterThresholds) -> Situation {
    if encounter.situation != Situation::Unclassified {
        encounter.situation
    } else if encounter.contact_angle.abs() > thresholds.beam_sector {
        Situation::Overtaking
    } else if encounter.bearing.abs() > thresholds.beam_sector {
        Situation::BeingOvertaken
    } else {
        Situation::CrossingGiveWay
    }
}

/// How the tow counts under the COLREGS.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum TowStatus {
    /// The tow applies Rules 13-17 as an ordinary power-driven vessel: it gives way
    /// in head-on and starboard crossings by a starboard alteration. This is the
    /// paper's behaviour (section 3.1) and the default.
    #[default]
    PowerDriven,
    /// Rule 3(g)(vii): "a vessel engaged in a towing operation such as severely
    /// restricts the towing vessel and her tow in their ability to deviate from
    /// their course" is restricted in her ability to manoeuvre (RAM). By Rule
    /// 18(a)(ii) power-driven vessels keep out of her way, so the tow stands on
    /// (Rule 17) in head-on and in both crossings; Rule 13 still binds her when she
    /// overtakes (Rule 18's "except where Rules 9, 10 and 13 otherwise require").
    /// Assumes the targets are power-driven vessels not themselves RAM: the FMI
    /// inputs carry no target status.
    RestrictedInAbilityToManoeuvre,
}

/// Own ship's role in a situation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Role {
    /// Keeps out of the way (Rule 16).
    GiveWay,
    /// Keeps course and speed (Rule 17).
    StandOn,
}

/// Own ship's role, or `None` when there is no situation (safe) or the roles are
/// unclear (unclassified).
#[must_use]
pub fn role(situation: Situation, status: TowStatus) -> Option<Role> {
    use Situation as S;
    match (situation, status) {
        (S::Safe | S::Unclassified, _) => None,
        (S::Overtaking, _) => Some(Role::GiveWay),
        (S::BeingOvertaken | S::CrossingStandOn, _) => Some(Role::StandOn),
        (S::HeadOn | S::CrossingGiveWay, TowStatus::PowerDriven) => Some(Role::GiveWay),
        (S::HeadOn | S::CrossingGiveWay, TowStatus::RestrictedInAbilityToManoeuvre) => {
            Some(Role::StandOn)
        }
    }
}

/// The policy for a situation: what the tow does about it under the COLREGS.
/// No action is a turn to port: the tow never turns to port, in particular not
/// for a vessel on her own port side (Rule 17(c)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Action {
    /// No situation: follow the route.
    Proceed,
    /// Give way by a starboard alteration (Rules 8, 14, 15, 16): the waypoint
    /// altering of eq. (10)-(11).
    AlterToStarboard,
    /// Rule 13: the overtaking tow keeps out of the way. The reference system has
    /// one manoeuvre, so it keeps out by the same starboard alteration, passing the
    /// target on the tow's port side. (The paper assumes the slow tow never
    /// overtakes.)
    KeepOut,
    /// Rule 17(a)(i): keep course and speed; the reference system never acts
    /// (being overtaken: a starboard alteration does not help against a target from
    /// abaft the beam, which may pass on either side; the MPC's distance cost,
    /// eq. (13), stays the last resort).
    StandOn,
    /// Rule 17(a)(i) then (a)(ii)/(b): keep course and speed until the give-way
    /// vessel fails to act in time ([`Rule17Settings`]), then take the way off or
    /// alter to starboard (the reference system chooses, [`Manoeuvre::TakeWayOff`];
    /// Rule 17(c): never to port for a vessel on own port side). Also the policy for
    /// [`Situation::Unclassified`]: act once the CPA is short.
    StandOnThenAct,
}

/// The policy of a situation for a tow of the given status.
#[must_use]
pub fn action(situation: Situation, status: TowStatus) -> Action {
    match situation {
        Situation::Safe => Action::Proceed,
        Situation::Overtaking => Action::KeepOut,
        Situation::BeingOvertaken => Action::StandOn,
        Situation::CrossingStandOn | Situation::Unclassified => Action::StandOnThenAct,
        Situation::HeadOn | Situation::CrossingGiveWay => match role(situation, status) {
            Some(Role::StandOn) => Action::StandOnThenAct,
            _ => Action::AlterToStarboard,
        },
    }
}

/// When a stand-on tow may act (Rule 17(a)(ii), (b)): the give-way vessel has not
/// acted "in time" if, with the CPA still ahead, the DCPA is below [`Self::dcpa`]
/// when the TCPA has come down to [`Self::tcpa`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rule17Settings {
    /// TCPA (s) at or below which the stand-on tow acts if the DCPA is still
    /// short, wherever the target is (Rule 17(a)(ii): "as soon as it becomes
    /// apparent"). Assumption (the paper has none; its stand-on role simply ends at
    /// `d_D`): 55 s, 5 s inside the 60 s before which the analyzer holds the tow to
    /// its course and speed; a 5.5 m long tow at 0.1 m/s needs about that long to let
    /// a target aimed at its middle pass (`docs/colregs.md`, "Rule 17, in time").
    pub tcpa: f64,
    /// DCPA (m, ship centre to target centre) below which the give-way vessel is
    /// deemed not to have acted. Assumption: 2.5 m, about two ship lengths, just
    /// above the largest eq. (14) safe distance of the ship against the paper's
    /// targets (`L + a + d_S0 = 1.255 + 0.74 + 0.25 = 2.245 m` in range units): a
    /// give-way vessel that has acted opens the CPA beyond the safe distance.
    pub dcpa: f64,
    /// Speed (m/s) the tow keeps when it takes the way off under Rule 17
    /// ([`Manoeuvre::TakeWayOff`]): the surge the ship's plan is held to, and the speed
    /// along the ship's heading at which the guidance predicts the tow's track against
    /// the target's. Assumption: 0.01 m/s, the slowest speed at which the MPC still
    /// held the stopped tow's head in the runs examined (`docs/assumptions.md`).
    pub way_off_speed: f64,
    /// Deceleration (m/s^2) at which the tow takes the way off under Rule 17: the
    /// controller lowers the surge cap of the ship's plan by this much per second, and
    /// the guidance counts the headway the tow carries while slowing,
    /// `(u^2 - way_off_speed^2) / (2 a)`. Assumption: 0.01 m/s^2, cruise to 0.01 m/s
    /// in about 10 s with 0.5 m of headway (`docs/assumptions.md`).
    pub way_off_deceleration: f64,
    /// Close quarters (Rule 17(b)): TCPA (s) at or below which, with the DCPA under
    /// [`Self::dcpa`], a target the tow stands on without ever acting on it (being
    /// overtaken, [`Action::StandOn`]) enters the MPC's distance cost, the last resort.
    /// Assumption: 30 s, ten MPC horizons (the Rule 17 action point of the earlier
    /// versions).
    pub close_quarters_tcpa: f64,
}

impl Default for Rule17Settings {
    fn default() -> Self {
        Self {
            tcpa: 55.0,
            dcpa: 2.5,
            way_off_speed: 0.01,
            way_off_deceleration: 0.01,
            close_quarters_tcpa: 30.0,
        }
    }
}

impl Rule17Settings {
    /// True when the stand-on tow may (and does) act: closing, `TCPA <= tcpa` and
    /// `DCPA < dcpa`.
    #[must_use]
    pub fn give_way_failed(&self, cpa: &Cpa) -> bool {
        cpa.is_closing() && cpa.tcpa <= self.tcpa && cpa.dcpa < self.dcpa
    }

    /// True at close quarters (Rule 17(b)): closing, `TCPA <= close_quarters_tcpa` and
    /// `DCPA < dcpa`.
    #[must_use]
    pub fn at_close_quarters(&self, cpa: &Cpa) -> bool {
        cpa.is_closing() && cpa.tcpa <= self.close_quarters_tcpa && cpa.dcpa < self.dcpa
    }
}

/// What the reference system does now for one obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Manoeuvre {
    /// Keep the predefined route.
    FollowRoute,
    /// Alter the active waypoint to starboard (eq. (10)-(11)).
    AlterToStarboard,
    /// Rule 17(a)(ii), (b) with Rule 8(e): a stand-on tow that must act keeps the
    /// route and takes the way off, so that the give-way target passes ahead. Chosen
    /// over the starboard alteration when the target's track clears the tow held at
    /// [`Rule17Settings::way_off_speed`] (see `docs/colregs.md`, "Rule 17: which
    /// action").
    TakeWayOff,
}

impl Action {
    /// The manoeuvre this policy asks for now, given the encounter's CPA (the
    /// distance condition of eq. (8) is applied by the caller).
    #[must_use]
    pub fn manoeuvre(self, cpa: &Cpa, rule17: &Rule17Settings) -> Manoeuvre {
        match self {
            Action::AlterToStarboard | Action::KeepOut => Manoeuvre::AlterToStarboard,
            Action::StandOnThenAct if rule17.give_way_failed(cpa) => Manoeuvre::AlterToStarboard,
            Action::StandOnThenAct | Action::StandOn | Action::Proceed => Manoeuvre::FollowRoute,
        }
    }
}

/// COLREGS settings of the guidance.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ColregsSettings {
    /// Classifier thresholds (default: [`ThresholdPreset::Woerner`]).
    pub thresholds: EncounterThresholds,
    /// The tow's status (default: [`TowStatus::PowerDriven`], the paper's).
    pub tow_status: TowStatus,
    /// When a stand-on tow acts.
    pub rule17: Rule17Settings,
    /// Optional DCPA (m) above which a closing target is [`Situation::Safe`].
    /// Assumption: none by default, as in the paper, whose only test is the
    /// distance `d_ob <= d_D`.
    pub risk_dcpa: Option<f64>,
}

impl ColregsSettings {
    /// Checks thresholds, Rule 17 values (positive, finite) and `risk_dcpa`.
    ///
    /// # Errors
    /// [`ParamError::OutOfRange`] naming the first bad field.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.thresholds.validate()?;
        let positive = |name, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(ParamError::OutOfRange {
                    name,
                    value,
                    reason: "finite and > 0",
                })
            }
        };
        positive("rule17.tcpa", self.rule17.tcpa)?;
        positive("rule17.dcpa", self.rule17.dcpa)?;
        positive("rule17.way_off_speed", self.rule17.way_off_speed)?;
        positive(
            "rule17.way_off_deceleration",
            self.rule17.way_off_deceleration,
        )?;
        positive(
            "rule17.close_quarters_tcpa",
            self.rule17.close_quarters_tcpa,
        )?;
        if let Some(d) = self.risk_dcpa {
            positive("risk_dcpa", d)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OWN_SPEED: f64 = 0.1;

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    /// Own ship at the origin heading North at 0.1 m/s; a 1.48 m x 0.48 m target
    /// `range` m away at bearing `beta_deg` whose contact angle is `alpha_deg`
    /// (so its heading is `beta + 180 - alpha`), at `speed`.
    fn encounter_with(
        beta_deg: f64,
        alpha_deg: f64,
        speed: f64,
        range: f64,
        th: &EncounterThresholds,
    ) -> Encounter {
        let b = deg(beta_deg);
        let target = Ellipse {
            centre: [range * b.cos(), range * b.sin()],
            psi: wrap_angle(b + std::f64::consts::PI - deg(alpha_deg)),
            speed,
            semi_major: 0.74,
            semi_minor: 0.24,
        };
        let e = classify(Pose::default(), [OWN_SPEED, 0.0], &target, th, None);
        assert!((e.bearing - b).abs() < 1e-9);
        assert!((e.contact_angle - deg(alpha_deg)).abs() < 1e-9);
        e
    }

    fn situation(beta_deg: f64, alpha_deg: f64, speed: f64, th: &EncounterThresholds) -> Situation {
        let e = encounter_with(beta_deg, alpha_deg, speed, 5.0, th);
        // Every geometry below is constructed closing, so Safe would mean a bug
        // in the helper, not a classification.
        assert!(e.cpa.is_closing(), "{beta_deg} {alpha_deg} {speed}: {e:?}");
        e.situation
    }

    fn woerner() -> EncounterThresholds {
        ThresholdPreset::Woerner.thresholds()
    }

    fn xu() -> EncounterThresholds {
        ThresholdPreset::Xu.thresholds()
    }

    #[test]
    fn the_safe_reading_closes_every_gap_between_the_sectors() {
        let th = EncounterThresholds::default();
        let read_at = |beta: f64, alpha: f64, speed: f64| {
            let e = encounter_with(beta, alpha, speed, 5.0, &th);
            assert!(e.cpa.is_closing(), "{beta} {alpha} {speed}: {e:?}");
            (e.situation, safe_reading(&e, &th))
        };
        let read = |beta: f64, alpha: f64| read_at(beta, alpha, 0.07);
        // Heading straight at own ship from 20 deg on the starboard bow: give way.
        assert_eq!(
            read(20.0, 0.0),
            (Situation::Unclassified, Situation::CrossingGiveWay)
        );
        // The same from the port bow: in doubt, give way too.
        assert_eq!(
            read(-30.0, 9.9),
            (Situation::Unclassified, Situation::CrossingGiveWay)
        );
        // Own ship abaft the target's beam, bearing 60 deg (no overtaking sector):
        // Rule 13(c), own ship overtakes.
        assert_eq!(
            read_at(60.0, -150.0, 0.03),
            (Situation::Unclassified, Situation::Overtaking)
        );
        // The target abaft own beam, contact angle 60 deg: it is overtaking.
        assert_eq!(
            read_at(150.0, 60.0, 0.2),
            (Situation::Unclassified, Situation::BeingOvertaken)
        );
        // A classified situation is its own reading.
        let e = encounter_with(0.0, 0.0, 0.07, 5.0, &th);
        assert_eq!(safe_reading(&e, &th), e.situation);
    }

    #[test]
    fn default_preset_is_woerner() {
        assert_eq!(EncounterThresholds::default(), woerner());
        assert_eq!(ColregsSettings::default().thresholds, woerner());
        assert!(woerner().validate().is_ok() && xu().validate().is_ok());
    }

    #[test]
    fn every_situation_from_a_constructed_geometry() {
        let th = woerner();
        assert_eq!(situation(0.0, 0.0, 0.07, &th), Situation::HeadOn);
        assert_eq!(
            situation(50.0, -40.0, 0.07, &th),
            Situation::CrossingGiveWay
        );
        assert_eq!(
            situation(-50.0, 40.0, 0.07, &th),
            Situation::CrossingStandOn
        );
        // Target 10 deg on the bow, heading the same way, slower: overtaking.
        assert_eq!(situation(10.0, 170.0, 0.05, &th), Situation::Overtaking);
        // Target astern, same course, faster: being overtaken.
        assert_eq!(situation(180.0, 0.0, 0.2, &th), Situation::BeingOvertaken);
        // Target ahead moving away faster: range opening, safe.
        let e = encounter_with(0.0, 180.0, 0.2, 5.0, &th);
        assert_eq!(e.situation, Situation::Safe);
        // The Woerner gap: 20 deg on the bow, heading straight at own ship.
        assert_eq!(situation(20.0, 0.0, 0.07, &th), Situation::Unclassified);
    }

    #[test]
    fn head_on_versus_crossing_at_13_deg_bearing() {
        let th = woerner();
        assert_eq!(situation(12.9, -12.0, 0.07, &th), Situation::HeadOn);
        assert_eq!(
            situation(13.1, -12.0, 0.07, &th),
            Situation::CrossingGiveWay
        );
        assert_eq!(situation(-12.9, 12.0, 0.07, &th), Situation::HeadOn);
        assert_eq!(
            situation(-13.1, 12.0, 0.07, &th),
            Situation::CrossingStandOn
        );
    }

    #[test]
    fn head_on_versus_crossing_at_13_deg_contact_angle() {
        let th = woerner();
        assert_eq!(situation(5.0, -12.9, 0.07, &th), Situation::HeadOn);
        assert_eq!(situation(5.0, -13.1, 0.07, &th), Situation::CrossingGiveWay);
    }

    #[test]
    fn crossing_contact_angle_boundary_at_10_deg() {
        let th = woerner();
        assert_eq!(
            situation(30.0, -10.1, 0.07, &th),
            Situation::CrossingGiveWay
        );
        assert_eq!(situation(30.0, -9.9, 0.07, &th), Situation::Unclassified);
        assert_eq!(
            situation(-30.0, 10.1, 0.07, &th),
            Situation::CrossingStandOn
        );
        assert_eq!(situation(-30.0, 9.9, 0.07, &th), Situation::Unclassified);
    }

    #[test]
    fn crossing_versus_being_overtaken_at_112_5_deg_bearing() {
        let th = woerner();
        // Faster target coming up from the starboard quarter.
        assert_eq!(
            situation(112.4, -30.0, 0.2, &th),
            Situation::CrossingGiveWay
        );
        assert_eq!(situation(112.6, -30.0, 0.2, &th), Situation::BeingOvertaken);
        // Port quarter.
        assert_eq!(
            situation(-112.4, 30.0, 0.2, &th),
            Situation::CrossingStandOn
        );
        assert_eq!(situation(-112.6, 30.0, 0.2, &th), Situation::BeingOvertaken);
    }

    #[test]
    fn crossing_versus_overtaking_at_112_5_deg_contact_angle() {
        let th = woerner();
        // Own ship (faster) comes up on a slower target's port quarter.
        assert_eq!(
            situation(30.0, -112.4, 0.05, &th),
            Situation::CrossingGiveWay
        );
        assert_eq!(situation(30.0, -112.6, 0.05, &th), Situation::Overtaking);
        assert_eq!(
            situation(-30.0, 112.4, 0.05, &th),
            Situation::CrossingStandOn
        );
        assert_eq!(situation(-30.0, 112.6, 0.05, &th), Situation::Overtaking);
    }

    #[test]
    fn overtaking_sector_and_speed() {
        let th = woerner();
        assert_eq!(situation(44.9, -150.0, 0.05, &th), Situation::Overtaking);
        assert_eq!(situation(45.1, -150.0, 0.05, &th), Situation::Unclassified);
        // Abaft the beam of the target but slower: not overtaking.
        let e = encounter_with(10.0, 170.0, 0.12, 5.0, &th);
        assert_ne!(e.situation, Situation::Overtaking);
        // Being overtaken needs the target faster and own ship within 45 deg of
        // its bow.
        assert_eq!(situation(170.0, 44.9, 0.2, &th), Situation::BeingOvertaken);
        assert_eq!(situation(170.0, -44.9, 0.2, &th), Situation::BeingOvertaken);
    }

    #[test]
    fn xu_preset_boundaries() {
        let th = xu();
        // Head-on: |beta| <= 5 and course difference within 175-185 deg.
        // alpha = beta gives a course difference of exactly 180 deg.
        assert_eq!(situation(4.9, 4.9, 0.07, &th), Situation::HeadOn);
        assert_eq!(situation(5.1, 5.1, 0.07, &th), Situation::CrossingGiveWay);
        assert_eq!(situation(-5.1, -5.1, 0.07, &th), Situation::CrossingStandOn);
        // With beta = 0 the course difference is 180 - alpha.
        assert_eq!(situation(0.0, 4.9, 0.07, &th), Situation::HeadOn);
        let e = encounter_with(0.0, 5.1, 0.07, 5.0, &th);
        assert!((e.course_difference.abs().to_degrees() - 174.9).abs() < 1e-9);
        assert_eq!(e.situation, Situation::Unclassified);
        // Crossing needs no contact angle in Xu's set (Woerner's gap is covered).
        assert_eq!(situation(20.0, 0.0, 0.07, &th), Situation::CrossingGiveWay);
        assert_eq!(
            situation(112.4, -30.0, 0.2, &th),
            Situation::CrossingGiveWay
        );
        // Being overtaken: target abaft the beam, faster, course difference <= 67.5.
        // beta = 112.6, alpha = -30: heading = 112.6 + 180 + 30 = 322.6 deg,
        // course difference -37.4 deg.
        assert_eq!(situation(112.6, -30.0, 0.2, &th), Situation::BeingOvertaken);
        // beta = 150, alpha = 60: heading 270 deg, course difference -90: not
        // overtaking under Xu, unclassified.
        assert_eq!(situation(150.0, 60.0, 0.2, &th), Situation::Unclassified);
        // Overtaking: course difference 67.4 vs 67.6 deg. Target at beta 10 with
        // heading h: alpha = 190 - h.
        assert_eq!(
            situation(10.0, 190.0 - 67.4, 0.02, &th),
            Situation::Overtaking
        );
        assert_eq!(
            situation(10.0, 190.0 - 67.6, 0.02, &th),
            Situation::CrossingGiveWay
        );
    }

    #[test]
    fn risk_dcpa_makes_a_wide_pass_safe() {
        // Reciprocal course 1 m to starboard: DCPA 1 m, TCPA 50 s.
        let target = Ellipse {
            centre: [10.0, 1.0],
            psi: std::f64::consts::PI,
            speed: 0.1,
            semi_major: 0.74,
            semi_minor: 0.24,
        };
        let own = Pose::default();
        let th = woerner();
        let e = classify(own, [0.1, 0.0], &target, &th, Some(0.9));
        assert_eq!(e.situation, Situation::Safe);
        let e = classify(own, [0.1, 0.0], &target, &th, Some(1.1));
        assert_eq!(e.situation, Situation::HeadOn);
        assert!((e.cpa.dcpa - 1.0).abs() < 1e-12 && (e.cpa.tcpa - 50.0).abs() < 1e-9);
        assert_eq!(
            classify(own, [0.1, 0.0], &target, &th, None).situation,
            Situation::HeadOn
        );
    }

    #[test]
    fn policy_per_situation_and_status() {
        use Situation as S;
        let p = TowStatus::PowerDriven;
        let ram = TowStatus::RestrictedInAbilityToManoeuvre;
        assert_eq!(action(S::Safe, p), Action::Proceed);
        assert_eq!(action(S::HeadOn, p), Action::AlterToStarboard);
        assert_eq!(action(S::CrossingGiveWay, p), Action::AlterToStarboard);
        assert_eq!(action(S::CrossingStandOn, p), Action::StandOnThenAct);
        assert_eq!(action(S::Overtaking, p), Action::KeepOut);
        assert_eq!(action(S::BeingOvertaken, p), Action::StandOn);
        assert_eq!(action(S::Unclassified, p), Action::StandOnThenAct);
        assert_eq!(action(S::Unclassified, ram), Action::StandOnThenAct);
        assert_eq!(role(S::Unclassified, p), None);
        assert_eq!(action(S::HeadOn, ram), Action::StandOnThenAct);
        assert_eq!(action(S::CrossingGiveWay, ram), Action::StandOnThenAct);
        assert_eq!(action(S::Overtaking, ram), Action::KeepOut);
        assert_eq!(role(S::HeadOn, p), Some(Role::GiveWay));
        assert_eq!(role(S::HeadOn, ram), Some(Role::StandOn));
        assert_eq!(role(S::Overtaking, ram), Some(Role::GiveWay));
        assert_eq!(role(S::Safe, p), None);
    }

    #[test]
    fn rule17_threshold() {
        let r = Rule17Settings::default();
        let m = |tcpa, dcpa| Action::StandOnThenAct.manoeuvre(&Cpa { tcpa, dcpa }, &r);
        let (t, d) = (r.tcpa, r.dcpa);
        assert_eq!(m(t + 0.1, 0.0), Manoeuvre::FollowRoute);
        assert_eq!(m(t - 0.1, 0.0), Manoeuvre::AlterToStarboard);
        assert_eq!(m(t - 0.1, d - 0.01), Manoeuvre::AlterToStarboard);
        assert_eq!(m(t - 0.1, d + 0.01), Manoeuvre::FollowRoute);
        assert_eq!(m(-1.0, 0.0), Manoeuvre::FollowRoute);
        assert_eq!(
            Action::StandOn.manoeuvre(
                &Cpa {
                    tcpa: 1.0,
                    dcpa: 0.0
                },
                &r
            ),
            Manoeuvre::FollowRoute
        );
        assert_eq!(
            Action::KeepOut.manoeuvre(
                &Cpa {
                    tcpa: 1e3,
                    dcpa: 1e3
                },
                &r
            ),
            Manoeuvre::AlterToStarboard
        );
    }

    #[test]
    fn a_port_side_target_never_asks_for_a_port_turn() {
        // Every bearing on the port side, every contact angle, slower and faster
        // targets, both presets and both statuses, at any CPA: the manoeuvre is
        // to keep the route or to alter to starboard. (The waypoint altering
        // itself turns to starboard: `reference` tests check the geometry.)
        for th in [woerner(), xu()] {
            for status in [
                TowStatus::PowerDriven,
                TowStatus::RestrictedInAbilityToManoeuvre,
            ] {
                for beta in (-179..0).step_by(4) {
                    for alpha in (-178..180).step_by(7) {
                        for speed in [0.02, 0.07, 0.2] {
                            let e =
                                encounter_with(f64::from(beta), f64::from(alpha), speed, 4.0, &th);
                            let a = action(e.situation, status);
                            assert!(matches!(
                                a.manoeuvre(&e.cpa, &Rule17Settings::default()),
                                Manoeuvre::FollowRoute | Manoeuvre::AlterToStarboard
                            ));
                            if e.situation == Situation::CrossingStandOn {
                                assert_eq!(a, Action::StandOnThenAct);
                            }
                            assert_ne!(e.situation, Situation::CrossingGiveWay);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn threshold_validation() {
        let mut th = woerner();
        th.beam_sector = deg(80.0);
        assert!(th.validate().is_err());
        let mut th = woerner();
        th.crossing_contact = Some((deg(20.0), deg(10.0)));
        assert!(th.validate().is_err());
        let mut th = xu();
        th.head_on_bearing = f64::NAN;
        assert!(th.validate().is_err());
        let mut s = ColregsSettings::default();
        s.rule17.tcpa = 0.0;
        assert!(s.validate().is_err());
        let s = ColregsSettings {
            risk_dcpa: Some(-1.0),
            ..ColregsSettings::default()
        };
        assert!(s.validate().is_err());
    }
}

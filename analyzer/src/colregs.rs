//! COLREGS assessment of one target-ship encounter after the run: detection, first
//! action, course change, closest point of approach (CPA), side of the pass, a verdict from
//! binary rule checks, and the rule scores of Woerner et al. (2018) as summarised in
//! `reference/colregs.md`, with range parameters at model scale.
//!
//! Angles: bearings in `(-180, 180]` deg, positive to starboard (NED, clockwise).
//! `beta` is the bearing of the target from own bow, `alpha` the bearing of own ship from
//! the target's bow (contact angle). Own ship is the towed ship (the tow's COLREGS
//! identity, `docs/colregs.md`); its course is its heading, and a course change is the
//! heading's change less the route's own ([`EncounterSample::route_course`]).

use serde::{Deserialize, Serialize};

use crate::geometry::{course_line_crossing, relative_bearing, wrap};

/// Range and scoring parameters. The published values are full scale (e.g. `r_min`
/// 100 m, `r_nm` 50 m, `r_col` 30 m); [`ScoringParams::model_scale`] derives them from
/// the vessels' sizes with the same ratios, see `docs/analyzer.md`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScoringParams {
    /// Detection range `r_detect`, m: the controller's detection distance `d_D`.
    pub r_detect_m: f64,
    /// Range above which the pass is fully safe, `r_min`, m.
    pub r_min_m: f64,
    /// Near-miss range `r_nm`, m.
    pub r_nm_m: f64,
    /// Collision range `r_col`, m.
    pub r_col_m: f64,
    /// The same four ranges in own-ship lengths (detect, min, near miss, collision).
    pub ranges_in_ship_lengths: [f64; 4],
    /// Own (towed) ship length, m.
    pub ship_length_m: f64,
    /// Loss of the range score across `[r_nm, r_min]`.
    pub gamma_nm: f64,
    /// Loss of the range score across `[r_col, r_nm]` (`gamma_nm + gamma_col = 1`: the
    /// score reaches 0 at `r_col`).
    pub gamma_col: f64,
    /// Weight of the range part of the safety score.
    pub w_r: f64,
    /// Weight of the pose part (`w_r + w_theta = 1`).
    pub w_theta: f64,
    /// Course change that is "readily apparent" (Rule 8), deg.
    pub dchi_apparent_deg: f64,
    /// Starboard turn that fully satisfies Rule 14, deg.
    pub dchi_starboard_deg: f64,
    /// Heading change after detection that counts as the first action, deg.
    pub action_threshold_deg: f64,
    /// Heading change to port that counts as a port turn in the verdict, deg.
    pub port_turn_deg: f64,
    /// Speed over ground at or below which the tow has her way off, m/s: taking all way
    /// off is an action (Rule 8(e)), and so is keeping it off from detection on.
    pub way_off_speed_m_s: f64,
}

impl ScoringParams {
    /// Model-scale parameters for own ship length `ship_length`, a target of length
    /// `target_length`, detection distance `d_detect` and buffer `d_s0`:
    /// `r_col = (L + L_target) / 2` (the centres' range at bow-to-bow contact),
    /// `r_nm = L + L_target / 2 + d_S0` (the guidance's safe range for a ship,
    /// `docs/colregs.md` section 1), `r_min = 2 r_nm` (Woerner's `r_min / r_nm` =
    /// 100 / 50), `r_detect = d_D`; `way_off` the speed of a tow with her way off
    /// (the analyzer's `way_off_surge_m_s`).
    #[must_use]
    pub fn model_scale(
        ship_length: f64,
        target_length: f64,
        (d_detect, d_s0): (f64, f64),
        way_off: f64,
    ) -> Self {
        let r_col = (ship_length + target_length) / 2.0;
        let r_nm = ship_length + target_length / 2.0 + d_s0;
        let r_min = 2.0 * r_nm;
        ScoringParams {
            r_detect_m: d_detect,
            r_min_m: r_min,
            r_nm_m: r_nm,
            r_col_m: r_col,
            ranges_in_ship_lengths: [
                d_detect / ship_length,
                r_min / ship_length,
                r_nm / ship_length,
                r_col / ship_length,
            ],
            ship_length_m: ship_length,
            gamma_nm: 0.4,
            gamma_col: 0.6,
            w_r: 0.8,
            w_theta: 0.2,
            dchi_apparent_deg: 30.0,
            dchi_starboard_deg: 20.0,
            action_threshold_deg: 5.0,
            port_turn_deg: 10.0,
            way_off_speed_m_s: way_off,
        }
    }
}

/// One sample of an encounter: own ship and target at the same time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncounterSample {
    /// Time, s.
    pub t: f64,
    /// Own ship North, East (m), heading (rad), speed over ground (m/s).
    pub own: [f64; 4],
    /// Target North, East (m), course (rad), speed (m/s).
    pub target: [f64; 4],
    /// The controller's reference was altered at this time (`None`: no controller log).
    pub altered: Option<bool>,
    /// Smallest centre range from any vessel of the tow (ship, tugs) to the target, m:
    /// the tow detects a target by its nearest vessel (eq. (8)), which can be a tug well
    /// before the ship.
    pub tow_range: f64,
    /// The route's course at own position, rad ([`crate::geometry::RouteCourse`]; 0
    /// without a route): course changes are the heading's change less this one's (a
    /// bend of the route is no alteration).
    pub route_course: f64,
}

impl EncounterSample {
    /// Own heading off the route's course, rad.
    fn off_course(&self) -> f64 {
        self.own[2] - self.route_course
    }

    /// Bearing of the target from own bow, rad (+ starboard).
    fn bearing(&self) -> f64 {
        relative_bearing(
            [self.own[0], self.own[1]],
            self.own[2],
            [self.target[0], self.target[1]],
        )
    }

    /// Contact angle: bearing of own ship from the target's bow, rad (+ starboard).
    fn contact_angle(&self) -> f64 {
        relative_bearing(
            [self.target[0], self.target[1]],
            self.target[2],
            [self.own[0], self.own[1]],
        )
    }
}

/// The largest heading change to port (deg, >= 0) while the target bore on each side of
/// the rule checks: on the starboard side (`beta > 0`), on the port side (`beta < 0`),
/// forward of the beam (`|beta| < 90 deg`). A port turn breaks a rule only "for" a target
/// on the side the rule names, at the time of the turn (Rule 17(c): "not alter course to
/// port for a vessel on her own port side"; Rule 15's give-way vessel turning to port for
/// a target on her starboard side heads across its bow; Rule 14's port-to-port pass is
/// spoiled by a port turn while the target is still forward of the beam). Once a crossing
/// target has crossed ahead to the other side, a turn to port passes astern of it. The
/// bearing is taken from the course the tow was on at detection (the heading at
/// detection, turned with the route), not from the turned head: a turn to port brings a
/// target on the port bow onto the starboard bow of the turned head by itself.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct PortTurns {
    starboard_side: f64,
    port_side: f64,
    forward: f64,
}

impl PortTurns {
    /// Records the heading change `dev` (deg, + starboard) of sample `s` from the course
    /// at detection.
    fn record(&mut self, s: &EncounterSample, dev: f64) {
        // The target's bearing from the course at detection: from the head, turned back.
        let beta = wrap(s.bearing() + dev.to_radians());
        let port = (-dev).max(0.0);
        if beta > 0.0 {
            self.starboard_side = self.starboard_side.max(port);
        } else if beta < 0.0 {
            self.port_side = self.port_side.max(port);
        }
        if beta.abs() < std::f64::consts::FRAC_PI_2 {
            self.forward = self.forward.max(port);
        }
    }

    /// The one the `situation`'s rule checks (0 for the others: no port-turn check).
    fn for_rule(&self, situation: Option<Situation>) -> f64 {
        match situation {
            Some(Situation::HeadOn) => self.forward,
            Some(Situation::CrossingGiveWay) => self.starboard_side,
            Some(Situation::CrossingStandOn) => self.port_side,
            _ => 0.0,
        }
    }
}

/// The COLREGS situation: the guidance's (codes as the controller FMU's
/// `colregs[k].situation`, text as in the controller log).
pub use towing_guidance::Situation;

/// Woerner-style classification (`docs/colregs.md` section 3, default preset) from the
/// bearing `beta`, contact angle `alpha` (deg) and the speeds.
#[must_use]
pub fn classify(beta_deg: f64, alpha_deg: f64, own_speed: f64, target_speed: f64) -> Situation {
    if beta_deg.abs() <= 13.0 && alpha_deg.abs() <= 13.0 {
        Situation::HeadOn
    } else if alpha_deg.abs() > 112.5 && beta_deg.abs() <= 45.0 && own_speed > target_speed {
        Situation::Overtaking
    } else if beta_deg.abs() > 112.5 && alpha_deg.abs() <= 45.0 && target_speed > own_speed {
        Situation::BeingOvertaken
    } else if (0.0..=112.5).contains(&beta_deg) && (-112.5..=-10.0).contains(&alpha_deg) {
        Situation::CrossingGiveWay
    } else if (-112.5..=0.0).contains(&beta_deg) && (10.0..=112.5).contains(&alpha_deg) {
        Situation::CrossingStandOn
    } else {
        Situation::Unclassified
    }
}

/// The rule scores (each in `[0, 1]`, 1 best) and their parts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// Range part `s_r` at the CPA.
    pub s_range: f64,
    /// Pose part `s_theta = (1 - cos alpha)(1 - cos beta)` at the CPA (angles clipped at
    /// 90 deg).
    pub s_pose: f64,
    /// `S_safety = w_r s_r + w_theta s_theta`.
    pub safety: f64,
    /// Delay penalty `P_delay`.
    pub p_delay: f64,
    /// Not-readily-apparent penalty `P_na` (Rule 8).
    pub p_not_apparent: f64,
    /// Rule 14: no-starboard-turn penalty `P_nsb`.
    pub p_no_starboard: f64,
    /// Rule 14: starboard-to-starboard penalty `P_sts`.
    pub p_starboard_to_starboard: f64,
    /// Rule 15: passed ahead of the target (`-25 < alpha_cpa < 165` deg).
    pub p_ahead_rule15: f64,
    /// Rule 13: ended ahead of the target (`|alpha_cpa| < 45` deg).
    pub p_ahead_rule13: f64,
    /// Rule 17: course-change penalty `P_dchi`.
    pub p_course_change: f64,
    /// Rule 17: speed-change penalty (relative speed change, see `docs/analyzer.md`).
    pub p_speed_change: f64,
    /// Rule 16 (give-way action).
    pub rule16: f64,
    /// Rule 14 (head-on).
    pub rule14: f64,
    /// Rule 15 (crossing, give-way: do not pass ahead).
    pub rule15: f64,
    /// Rule 13 (overtaking).
    pub rule13: f64,
    /// Rule 17 (stand-on).
    pub rule17: f64,
}

/// Everything reported for one target-ship encounter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EncounterReport {
    /// Target name (scenario).
    pub target: String,
    /// Obstacle slot.
    pub slot: u32,
    /// Situation held by the controller (first definite one it reported), if logged.
    pub situation: Option<String>,
    /// The tow's role from the controller (`give-way`, `stand-on`), if logged.
    pub role: Option<String>,
    /// Every distinct situation the controller reported, in order.
    pub situations_reported: Vec<String>,
    /// This analyzer's classification from the geometry at detection.
    pub situation_geometric: Option<String>,
    /// The situation the verdict and the rule score use (the controller's, else the
    /// geometric one).
    pub situation_assessed: Option<String>,
    /// First time the range (centre to centre) is below `r_detect`, s.
    pub t_detect_s: Option<f64>,
    /// First time any vessel of the tow is within `r_detect` (the guidance's detection);
    /// the first action and the course change are looked for from here.
    pub t_detect_tow_s: Option<f64>,
    /// Time of the tow's first action after detection (the reference becoming altered,
    /// the heading changing by the action threshold, or the way off), s.
    pub t_first_action_s: Option<f64>,
    /// What the first action was.
    pub first_action: Option<String>,
    /// Range at the first action, m.
    pub r_first_action_m: Option<f64>,
    /// Largest heading change between detection and CPA (+ starboard, - port), deg.
    pub course_change_deg: Option<f64>,
    /// Largest heading change to starboard, deg.
    pub course_change_starboard_deg: Option<f64>,
    /// Largest heading change to port, deg.
    pub course_change_port_deg: Option<f64>,
    /// Largest heading change to port made while the target bore on the side the
    /// situation's rule names (crossing give-way: starboard; crossing stand-on: port, Rule
    /// 17(c); head-on: forward of the beam), deg; the verdict's port-turn check uses it
    /// (0 for the other situations).
    pub port_turn_for_rule_deg: Option<f64>,
    /// Time of the CPA (smallest range), s.
    pub t_cpa_s: f64,
    /// Range at the CPA, m.
    pub r_cpa_m: f64,
    /// Range at the CPA in own-ship lengths.
    pub r_cpa_ship_lengths: f64,
    /// Bearing of the target from own bow at the CPA, deg (+ starboard).
    pub beta_cpa_deg: f64,
    /// Bearing of own ship from the target's bow at the CPA, deg (+ starboard).
    pub alpha_cpa_deg: f64,
    /// Side of own ship the target passed on (`port` / `starboard`, sign of `beta_cpa`).
    pub side: String,
    /// `ahead` or `astern` of the target (Rule 15's test on `alpha_cpa`).
    pub passed: String,
    /// The CPA is the last sample of the target's track (the log may end before the
    /// encounter does).
    pub cpa_at_end_of_log: bool,
    /// `compliant`, `violation`, or `no encounter` (never within `r_detect`).
    pub verdict: String,
    /// Why it is a violation.
    pub reasons: Vec<String>,
    /// The rule the score is for (`13`, `14`, `15`, `16`, `17`), if any.
    pub rule: Option<u8>,
    /// That rule's score.
    pub score: Option<f64>,
    /// Every score and its parts.
    pub scores: Option<Scores>,
    /// The parameters used.
    pub params: ScoringParams,
}

/// Rule 15's "passed ahead of the target": own ship at the CPA bears from the target's
/// bow between 25 deg to port and 165 deg to starboard (`-25 < alpha_cpa < 165`,
/// reference/colregs.md), unless she got to its starboard side by crossing its course
/// line astern of it (`crossed_astern`: her last crossing of the line before the CPA
/// was abaft the target). A slow tow that passes astern of a crossing target and then
/// resumes her route towards its wake reaches her least range on the target's starboard
/// quarter, which the window alone reads as ahead (`docs/analyzer.md`).
#[must_use]
pub fn passed_ahead(alpha_cpa_deg: f64, crossed_astern: bool) -> bool {
    alpha_cpa_deg > -25.0 && alpha_cpa_deg < 165.0 && !(crossed_astern && alpha_cpa_deg > 0.0)
}

/// Range score `s_r`: 1 at or above `r_min`, falling linearly by `gamma_nm` down to
/// `r_nm` and by `gamma_col` down to `r_col`, 0 below.
#[must_use]
pub fn range_score(r: f64, p: &ScoringParams) -> f64 {
    let s = if r >= p.r_min_m {
        1.0
    } else if r >= p.r_nm_m {
        1.0 - p.gamma_nm * (p.r_min_m - r) / (p.r_min_m - p.r_nm_m)
    } else if r >= p.r_col_m {
        1.0 - p.gamma_nm - p.gamma_col * (p.r_nm_m - r) / (p.r_nm_m - p.r_col_m)
    } else {
        0.0
    };
    s.clamp(0.0, 1.0)
}

/// Scores from the encounter's key quantities (angles in deg); `ahead15`: own ship passed
/// ahead of the target ([`passed_ahead`]).
#[allow(clippy::too_many_arguments)]
#[must_use]
pub fn scores(
    r_cpa: f64,
    alpha_cpa_deg: f64,
    beta_cpa_deg: f64,
    r_manoeuvre: f64,
    dchi_starboard_deg: f64,
    dchi_port_deg: f64,
    (speed_change_rel, ahead15): (f64, bool),
    p: &ScoringParams,
) -> Scores {
    let clip = |v: f64| v.clamp(0.0, 1.0);
    let s_range = range_score(r_cpa, p);
    let a90 = alpha_cpa_deg.abs().min(90.0).to_radians();
    let b90 = beta_cpa_deg.abs().min(90.0).to_radians();
    let s_pose = (1.0 - a90.cos()) * (1.0 - b90.cos());
    let safety = p.w_r * s_range + p.w_theta * s_pose;
    let p_delay = if p.r_detect_m > r_cpa {
        clip((p.r_detect_m - r_manoeuvre) / (p.r_detect_m - r_cpa))
    } else {
        0.0
    };
    let dchi_abs = dchi_starboard_deg.max(dchi_port_deg);
    let p_na = 0.5 * (1.0 - (dchi_abs / p.dchi_apparent_deg).powi(2)).max(0.0);
    let rule16 = safety * (1.0 - p_delay) * (1.0 - p_na);
    // Rule 14. colregs.md prints P_nsb = (dchi / 20)^4 below 20 deg and 0 above, which
    // jumps from 1 to 0 at 20 deg and penalises small turns least; read as its
    // complement, continuous and falling from 1 (no starboard turn) to 0 (20 deg).
    let p_nsb = if dchi_port_deg > dchi_starboard_deg {
        1.0
    } else if dchi_starboard_deg >= p.dchi_starboard_deg {
        0.0
    } else {
        1.0 - (dchi_starboard_deg / p.dchi_starboard_deg).powi(4)
    };
    // P_sts with bearings positive to starboard: a port-to-port pass (alpha = beta =
    // -90 deg) gives 0, starboard-to-starboard (+90, +90) gives 1. colregs.md's
    // `(sin + 1) / 2` assumes bearings positive to port.
    let sa = (1.0 - alpha_cpa_deg.to_radians().sin()) / 2.0;
    let sb = (1.0 - beta_cpa_deg.to_radians().sin()) / 2.0;
    let p_sts = 1.0 - (sa * sa) * (sb * sb);
    let rule14 = clip(1.0 - 0.6 * p_nsb - 0.2 * p_delay - p_sts) * (1.0 - p_na);
    let p_ahead15 = if ahead15 { 1.0 } else { 0.0 };
    let rule15 = clip(rule16 - 0.5 * p_ahead15);
    let p_ahead13 = if alpha_cpa_deg.abs() < 45.0 { 1.0 } else { 0.0 };
    let rule13 = clip(rule16 - 0.3 * p_ahead13);
    let p_dchi = 0.5 * clip((dchi_abs - 2.0) / (30.0 - 2.0));
    let p_du = 0.5 * clip((speed_change_rel.abs() - 0.1) / (0.5 - 0.1));
    let rule17 = clip((safety - p_dchi) * (1.0 - p_du));
    Scores {
        s_range,
        s_pose,
        safety,
        p_delay,
        p_not_apparent: p_na,
        p_no_starboard: p_nsb,
        p_starboard_to_starboard: p_sts,
        p_ahead_rule15: p_ahead15,
        p_ahead_rule13: p_ahead13,
        p_course_change: p_dchi,
        p_speed_change: p_du,
        rule16,
        rule14,
        rule15,
        rule13,
        rule17,
    }
}

/// The controller's view of the encounter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ControllerView {
    /// Situation codes the controller reported for the slot, in time order.
    pub situation_codes: Vec<i32>,
    /// Role texts, parallel to `situation_codes`.
    pub roles: Vec<String>,
}

/// The heading changes and the first action from the tow's detection up to a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Window {
    /// Own heading off the route's course when the tow detected the target, rad.
    base_off_course: f64,
    /// Largest heading change to starboard so far, deg.
    stbd: f64,
    /// Largest heading change to port so far, deg.
    port: f64,
    /// The same by the side the target bore on.
    port_turns: PortTurns,
    was_altered: bool,
    /// The first action: its time, what it was, and the range then.
    action: Option<(f64, &'static str, f64)>,
}

impl Window {
    /// The window opened at the tow's detection `s`: no heading change, no action yet.
    fn at_detection(s: &EncounterSample) -> Window {
        Window {
            base_off_course: s.off_course(),
            stbd: 0.0,
            port: 0.0,
            port_turns: PortTurns::default(),
            was_altered: s.altered.unwrap_or(false),
            action: None,
        }
    }
}

/// The closest point of approach so far, with the window as it was then.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cpa {
    index: usize,
    range: f64,
    sample: EncounterSample,
    window: Option<Window>,
    /// Own ship's last crossing of the target's course line before the CPA was astern
    /// of the target ([`passed_ahead`]).
    crossed_astern: bool,
}

/// The assessment of one encounter fed one sample at a time (O(1) state, for a plant log
/// streamed by): every quantity [`assess`] needs is a first event (detection by the ship,
/// by the tow), a running extreme (the CPA), or a prefix of the window from the tow's
/// detection, whose state is kept as it was at the CPA so far.
#[derive(Debug, Clone, PartialEq)]
pub struct EncounterTracker {
    p: ScoringParams,
    samples: usize,
    /// First sample with the ship within `r_detect`.
    detect: Option<EncounterSample>,
    /// First sample with the ship or a tug within `r_detect` (the window's start).
    detect_tow: Option<EncounterSample>,
    window: Option<Window>,
    cpa: Option<Cpa>,
    /// Own ship's last non-zero side of the target's course line (+ starboard).
    side: Option<f64>,
    /// Own ship's last crossing of that line was astern of the target.
    crossed_astern: bool,
}

fn range_of(s: &EncounterSample) -> f64 {
    (s.target[0] - s.own[0]).hypot(s.target[1] - s.own[1])
}

impl EncounterTracker {
    /// A tracker with the parameters `p`.
    #[must_use]
    pub fn new(p: ScoringParams) -> Self {
        EncounterTracker {
            p,
            samples: 0,
            detect: None,
            detect_tow: None,
            window: None,
            cpa: None,
            side: None,
            crossed_astern: false,
        }
    }

    /// Samples pushed.
    #[must_use]
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The next sample (time order).
    pub fn push(&mut self, s: EncounterSample) {
        let index = self.samples;
        self.samples += 1;
        let range = range_of(&s);
        if self.detect.is_none() && range < self.p.r_detect_m {
            self.detect = Some(s);
        }
        // The tow's detection is the first sample with the ship (range) or the nearest
        // vessel (tow_range) within r_detect.
        if self.window.is_none() && (range < self.p.r_detect_m || s.tow_range < self.p.r_detect_m) {
            self.detect_tow = Some(s);
            self.window = Some(Window::at_detection(&s));
        }
        if let Some(w) = &mut self.window {
            let dev = wrap(s.off_course() - w.base_off_course).to_degrees();
            w.stbd = w.stbd.max(dev);
            w.port = w.port.max(-dev);
            w.port_turns.record(&s, dev);
            let altered = s.altered.unwrap_or(false);
            if w.action.is_none() {
                if altered && !w.was_altered {
                    w.action = Some((
                        s.t,
                        "reference altered (waypoint altering, eq. (10)-(11))",
                        range,
                    ));
                } else if s.own[3] <= self.p.way_off_speed_m_s {
                    w.action = Some((s.t, "way off (Rule 8(e))", range));
                } else if dev.abs() >= self.p.action_threshold_deg {
                    w.action = Some((
                        s.t,
                        if dev > 0.0 {
                            "heading change to starboard"
                        } else {
                            "heading change to port"
                        },
                        range,
                    ));
                }
            }
            w.was_altered = altered;
        }
        let own = [s.own[0], s.own[1]];
        if let Some(along) =
            course_line_crossing(&mut self.side, [s.target[0], s.target[1]], s.target[2], own)
        {
            self.crossed_astern = along < 0.0;
        }
        if range.is_finite() && self.cpa.is_none_or(|c| range < c.range) {
            self.cpa = Some(Cpa {
                index,
                range,
                sample: s,
                window: self.window,
                crossed_astern: self.crossed_astern,
            });
        }
    }

    /// The assessment of the samples so far (`None` without a sample of finite range).
    #[must_use]
    pub fn finish(
        &self,
        target: &str,
        slot: u32,
        controller: Option<&ControllerView>,
    ) -> Option<EncounterReport> {
        let p = &self.p;
        let cpa_rec = self.cpa?;
        let cpa = cpa_rec.sample;
        let r_cpa = cpa_rec.range;
        let det_ship = self.detect;
        let (mut report, assessed) = EncounterReport::at_cpa(
            target,
            slot,
            &cpa,
            r_cpa,
            det_ship.as_ref(),
            controller,
            (
                cpa_rec.index + 1 == self.samples && self.samples > 1,
                cpa_rec.crossed_astern,
            ),
            p,
        );
        let Some(det_ship) = det_ship else {
            report
                .reasons
                .push(format!("never within r_detect = {:.2} m", p.r_detect_m));
            return Some(report);
        };
        report.t_detect_s = Some(det_ship.t);
        // The tow detects no later than the ship, so its detection is at or before the CPA
        // too, and the window holds the heading changes from there up to the CPA.
        let det = self.detect_tow.unwrap_or(det_ship);
        report.t_detect_tow_s = Some(det.t);
        let window = cpa_rec.window.unwrap_or(Window::at_detection(&det));
        conclude(
            &mut report,
            assessed,
            (window.stbd, window.port, window.port_turns),
            window.action,
            (det.own[3], cpa.own[3]),
            p,
        );
        Some(report)
    }
}

impl EncounterReport {
    /// The report's fields known at the closest point of approach `cpa` (range `r_cpa`):
    /// bearings, side, passing, the controller's situation and role (the first definite one,
    /// the held situation, and every distinct one in order) and the geometric classification
    /// at the ship's detection `det_ship`; with the situation the verdict is assessed for.
    /// Verdict "no encounter" until [`judge`] runs.
    #[allow(clippy::too_many_arguments)]
    fn at_cpa(
        target: &str,
        slot: u32,
        cpa: &EncounterSample,
        r_cpa: f64,
        det_ship: Option<&EncounterSample>,
        controller: Option<&ControllerView>,
        (at_end, crossed_astern): (bool, bool),
        p: &ScoringParams,
    ) -> (Self, Option<Situation>) {
        let beta_cpa = cpa.bearing().to_degrees();
        let alpha_cpa = cpa.contact_angle().to_degrees();

        // Controller's situation: the first definite one (neither safe nor unclassified:
        // the one the guidance holds for the encounter, towing-guidance's reference
        // system), every distinct one in order, and the role that came with it.
        let (mut situation, mut role, mut reported) = (None, None, Vec::<String>::new());
        if let Some(c) = controller {
            for (k, &code) in c.situation_codes.iter().enumerate() {
                if let Some(s) = Situation::from_code(code) {
                    if reported.last().map(String::as_str) != Some(s.name()) {
                        reported.push(s.name().to_owned());
                    }
                    let definite = !matches!(s, Situation::Safe | Situation::Unclassified);
                    if situation.is_none() && definite {
                        situation = Some(s);
                        role = c.roles.get(k).cloned();
                    }
                }
            }
        }

        let geometric = det_ship.map(|s| {
            classify(
                s.bearing().to_degrees(),
                s.contact_angle().to_degrees(),
                s.own[3],
                s.target[3],
            )
        });
        let assessed = situation.or(geometric);

        let report = Self {
            target: target.to_owned(),
            slot,
            situation: situation.map(|s| s.name().to_owned()),
            role,
            situations_reported: reported,
            situation_geometric: geometric.map(|s| s.name().to_owned()),
            situation_assessed: assessed.map(|s| s.name().to_owned()),
            t_detect_s: None,
            t_detect_tow_s: None,
            t_first_action_s: None,
            first_action: None,
            r_first_action_m: None,
            course_change_deg: None,
            course_change_starboard_deg: None,
            course_change_port_deg: None,
            port_turn_for_rule_deg: None,
            t_cpa_s: cpa.t,
            r_cpa_m: r_cpa,
            r_cpa_ship_lengths: r_cpa / p.ship_length_m,
            beta_cpa_deg: beta_cpa,
            alpha_cpa_deg: alpha_cpa,
            side: if beta_cpa >= 0.0 { "starboard" } else { "port" }.to_owned(),
            passed: if passed_ahead(alpha_cpa, crossed_astern) {
                "ahead"
            } else {
                "astern"
            }
            .to_owned(),
            cpa_at_end_of_log: at_end,
            verdict: "no encounter".to_owned(),
            reasons: Vec::new(),
            rule: None,
            score: None,
            scores: None,
            params: *p,
        };
        (report, assessed)
    }
}

/// What the own ship did in an encounter, as the verdict needs it.
#[derive(Debug, Clone, Copy)]
struct Manoeuvre {
    /// Range at the first action (at the CPA without one), m.
    r_manoeuvre: f64,
    /// Largest heading change to starboard and to port between detection and CPA, deg.
    stbd: f64,
    port: f64,
    /// [`EncounterReport::port_turn_for_rule_deg`].
    port_for_rule: f64,
    /// Relative speed change from detection to CPA.
    speed_change: f64,
    /// Whether any action was taken between detection and CPA.
    acted: bool,
}

/// Records the heading changes `(starboard, port, port by side)` (deg) since detection and
/// the first action `(t, what, range)` in `report`, and judges it ([`judge`]) with the relative speed
/// change between `speeds` = (own speed at detection, at the CPA). `r_cpa_m` must be set.
fn conclude(
    report: &mut EncounterReport,
    assessed: Option<Situation>,
    (stbd, port, port_turns): (f64, f64, PortTurns),
    action: Option<(f64, &str, f64)>,
    (speed_detect, speed_cpa): (f64, f64),
    p: &ScoringParams,
) {
    report.course_change_starboard_deg = Some(stbd);
    report.course_change_port_deg = Some(port);
    report.course_change_deg = Some(if stbd >= port { stbd } else { -port });
    let port_for_rule = port_turns.for_rule(assessed);
    report.port_turn_for_rule_deg = Some(port_for_rule);
    if let Some((t, what, r)) = action {
        report.t_first_action_s = Some(t);
        report.first_action = Some(what.to_owned());
        report.r_first_action_m = Some(r);
    }
    let manoeuvre = Manoeuvre {
        r_manoeuvre: action.map_or(report.r_cpa_m, |(_, _, r)| r),
        stbd,
        port,
        port_for_rule,
        speed_change: (speed_cpa - speed_detect) / speed_detect.abs().max(1e-3),
        acted: action.is_some(),
    };
    judge(report, assessed, manoeuvre, p);
}

/// Scores and verdict of an encounter whose CPA fields (`r_cpa_m`, `alpha_cpa_deg`,
/// `beta_cpa_deg`) are set: the binary checks of the PSB-MPC evaluator and the rule score
/// of reference/colregs.md for the `assessed` situation.
fn judge(
    report: &mut EncounterReport,
    assessed: Option<Situation>,
    m: Manoeuvre,
    p: &ScoringParams,
) {
    let Manoeuvre {
        r_manoeuvre,
        stbd,
        port,
        port_for_rule,
        speed_change,
        acted,
    } = m;
    let (r_cpa, alpha_cpa, beta_cpa) = (report.r_cpa_m, report.alpha_cpa_deg, report.beta_cpa_deg);
    let sc = scores(
        r_cpa,
        alpha_cpa,
        beta_cpa,
        r_manoeuvre,
        stbd,
        port,
        (speed_change, report.passed == "ahead"),
        p,
    );

    // Binary checks (the PSB-MPC evaluator's, reference/colregs.md) and the rule score.
    let mut reasons = Vec::new();
    if r_cpa < p.r_col_m {
        reasons.push(format!(
            "closest range {r_cpa:.2} m below the collision range {:.2} m",
            p.r_col_m
        ));
    }
    // A port turn counts only while the target bore on the side the rule names
    // ([`PortTurns`]), and only when it was the larger turn (a starboard alteration taken
    // back is no port turn).
    let port_turn = port_for_rule >= p.port_turn_deg && port_for_rule > stbd;
    // Rule 16: a give-way vessel takes early and substantial action; none at all
    // between detection and the CPA is a violation (a small one only lowers the
    // score, P_na).
    let give_way = matches!(
        assessed,
        Some(Situation::HeadOn | Situation::CrossingGiveWay | Situation::Overtaking)
    );
    if give_way && !acted {
        reasons.push("no give-way action between detection and the CPA (Rule 16)".to_owned());
    }
    let (rule, score) = match assessed {
        Some(Situation::HeadOn) => {
            if beta_cpa > 0.0 {
                reasons.push("passed starboard to starboard (Rule 14: port to port)".to_owned());
            }
            if port_turn {
                reasons.push(format!("turned {port_for_rule:.0} deg to port (Rule 14)"));
            }
            (Some(14), Some(sc.rule14))
        }
        Some(Situation::CrossingGiveWay) => {
            if sc.p_ahead_rule15 > 0.0 {
                reasons.push("passed ahead of the target (Rule 15)".to_owned());
            }
            if port_turn {
                reasons.push(format!(
                    "turned {port_for_rule:.0} deg to port for a target on the starboard side (Rule 15)"
                ));
            }
            (Some(15), Some(sc.rule15))
        }
        Some(Situation::CrossingStandOn) => {
            if port_turn {
                reasons.push(format!(
                    "turned {port_for_rule:.0} deg to port for a vessel on own port side (Rule 17(c))"
                ));
            }
            (Some(17), Some(sc.rule17))
        }
        Some(Situation::Overtaking) => (Some(13), Some(sc.rule13)),
        Some(Situation::BeingOvertaken) => (Some(17), Some(sc.rule17)),
        Some(Situation::Unclassified) => (Some(16), Some(sc.rule16)),
        Some(Situation::Safe) | None => (None, None),
    };
    report.verdict = if reasons.is_empty() {
        "compliant"
    } else {
        "violation"
    }
    .to_owned();
    report.reasons = reasons;
    report.rule = rule;
    report.score = score;
    report.scores = Some(sc);
}

/// Assesses one encounter from its samples (time order; at least one): detection, first
/// action, course change, CPA, verdict and scores (see the module docs). The samples go
/// through an [`EncounterTracker`], as the streamed plant log's do.
#[must_use]
pub fn assess(
    target: &str,
    slot: u32,
    samples: &[EncounterSample],
    controller: Option<&ControllerView>,
    p: &ScoringParams,
) -> Option<EncounterReport> {
    let mut tracker = EncounterTracker::new(*p);
    for s in samples {
        tracker.push(*s);
    }
    tracker.finish(target, slot, controller)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The batch formula (the analyzer's former whole-series `assess`), the reference for
    /// [`EncounterTracker`].
    fn assess_batch(
        target: &str,
        slot: u32,
        samples: &[EncounterSample],
        controller: Option<&ControllerView>,
        p: &ScoringParams,
    ) -> Option<EncounterReport> {
        samples.first()?;
        let range = |s: &EncounterSample| (s.target[0] - s.own[0]).hypot(s.target[1] - s.own[1]);
        let (i_cpa, r_cpa) = samples
            .iter()
            .enumerate()
            .map(|(i, s)| (i, range(s)))
            .filter(|(_, r)| r.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let cpa = samples[i_cpa];
        let i_det = samples[..=i_cpa]
            .iter()
            .position(|s| range(s) < p.r_detect_m);
        // Own ship's side of the target's course line at each sample up to the CPA; the
        // last change of side, and where along the line it was.
        let line = |s: &EncounterSample| {
            crate::geometry::line_coordinates(
                [s.target[0], s.target[1]],
                s.target[2],
                [s.own[0], s.own[1]],
            )
        };
        let crossed_astern = samples[..=i_cpa]
            .windows(2)
            .rev()
            .find(|w| line(&w[0]).1 * line(&w[1]).1 < 0.0)
            .is_some_and(|w| line(&w[1]).0 < 0.0);
        let (mut report, assessed) = EncounterReport::at_cpa(
            target,
            slot,
            &cpa,
            r_cpa,
            i_det.map(|i| &samples[i]),
            controller,
            (
                i_cpa + 1 == samples.len() && samples.len() > 1,
                crossed_astern,
            ),
            p,
        );
        let Some(i_det) = i_det else {
            report
                .reasons
                .push(format!("never within r_detect = {:.2} m", p.r_detect_m));
            return Some(report);
        };
        report.t_detect_s = Some(samples[i_det].t);
        let i_tow = samples[..=i_cpa]
            .iter()
            .position(|s| s.tow_range < p.r_detect_m)
            .map_or(i_det, |i| i.min(i_det));
        let det = samples[i_tow];
        report.t_detect_tow_s = Some(det.t);

        // Heading change relative to the heading when the tow detected the target, up to the
        // CPA.
        let (mut stbd, mut port) = (0.0f64, 0.0f64);
        let mut port_turns = PortTurns::default();
        let mut action: Option<(usize, &str)> = None;
        let altered_at_detection = det.altered.unwrap_or(false);
        let mut was_altered = altered_at_detection;
        for (i, s) in samples.iter().enumerate().take(i_cpa + 1).skip(i_tow) {
            let dev = wrap(s.off_course() - det.off_course()).to_degrees();
            stbd = stbd.max(dev);
            port = port.max(-dev);
            port_turns.record(s, dev);
            let altered = s.altered.unwrap_or(false);
            if action.is_none() {
                if altered && !was_altered {
                    action = Some((i, "reference altered (waypoint altering, eq. (10)-(11))"));
                } else if dev.abs() >= p.action_threshold_deg {
                    action = Some((
                        i,
                        if dev > 0.0 {
                            "heading change to starboard"
                        } else {
                            "heading change to port"
                        },
                    ));
                }
            }
            was_altered = altered;
        }
        conclude(
            &mut report,
            assessed,
            (stbd, port, port_turns),
            action.map(|(i, what)| (samples[i].t, what, range(&samples[i]))),
            (det.own[3], cpa.own[3]),
            p,
        );
        Some(report)
    }

    /// The controller's view of a target it gave way to in `situation` throughout.
    fn give_way_view(situation: Situation) -> ControllerView {
        ControllerView {
            situation_codes: vec![situation.code()],
            roles: vec!["give-way".into()],
        }
    }

    fn params() -> ScoringParams {
        ScoringParams::model_scale(1.255, 1.48, (7.0, 0.25), 0.05)
    }

    #[test]
    fn model_scale_ratios() {
        let p = params();
        assert!((p.r_col_m - 1.3675).abs() < 1e-12);
        assert!((p.r_nm_m - 2.245).abs() < 1e-12);
        assert!((p.r_min_m - 4.49).abs() < 1e-12);
        assert!((range_score(10.0, &p) - 1.0).abs() < 1e-12);
        assert!((range_score(p.r_nm_m, &p) - 0.6).abs() < 1e-12);
        assert!(range_score(p.r_col_m, &p).abs() < 1e-12);
        assert_eq!(range_score(0.5, &p), 0.0);
    }

    #[test]
    fn classification_sectors() {
        assert_eq!(classify(5.0, -5.0, 0.1, 0.07), Situation::HeadOn);
        assert_eq!(classify(60.0, -60.0, 0.1, 0.07), Situation::CrossingGiveWay);
        assert_eq!(classify(-60.0, 60.0, 0.1, 0.07), Situation::CrossingStandOn);
        assert_eq!(classify(10.0, 170.0, 0.2, 0.07), Situation::Overtaking);
        assert_eq!(classify(170.0, 10.0, 0.05, 0.2), Situation::BeingOvertaken);
    }

    /// Own ship heads North at `u` from (0, 0), turning by `turn` (rad, + starboard) at
    /// `t_turn`; target from (`x0`, `y0`) on `course` at `vt`.
    #[allow(clippy::too_many_arguments)]
    fn run(
        turn: f64,
        t_turn: f64,
        x0: f64,
        y0: f64,
        course: f64,
        vt: f64,
        u: f64,
    ) -> Vec<EncounterSample> {
        let dt = 0.5;
        let (mut x, mut y) = (0.0, 0.0);
        let mut out = Vec::new();
        for k in 0..500 {
            let t = k as f64 * dt;
            let psi = if t >= t_turn { turn } else { 0.0 };
            out.push(EncounterSample {
                t,
                own: [x, y, psi, u],
                target: [
                    x0 + vt * t * course.cos(),
                    y0 + vt * t * course.sin(),
                    course,
                    vt,
                ],
                altered: Some(t >= t_turn && turn != 0.0),
                tow_range: f64::INFINITY,
                route_course: 0.0,
            });
            x += u * dt * psi.cos();
            y += u * dt * psi.sin();
        }
        out
    }

    #[test]
    fn head_on_port_to_port_beats_starboard_to_starboard() {
        let p = params();
        // Target comes South 0.5 m to port of own track (the paper's C). Own ship turns
        // 30 deg to starboard at 140 s (detection at 135 s): passes port to port. Turning
        // 30 deg to port: starboard to starboard.
        let good = run(30f64.to_radians(), 140.0, 30.0, -0.5, PI, 0.07, 0.1);
        let bad = run(-30f64.to_radians(), 140.0, 30.0, -0.5, PI, 0.07, 0.1);
        // Unclassified first (the target far off the bow), then head-on: the held
        // situation is head-on, as the guidance's.
        let view = ControllerView {
            situation_codes: vec![0, 6, 1, 1],
            roles: vec![
                "none".into(),
                "none".into(),
                "give-way".into(),
                "give-way".into(),
            ],
        };
        let g = assess("C", 6, &good, Some(&view), &p).expect("report");
        let b = assess("C", 6, &bad, Some(&view), &p).expect("report");
        assert_eq!(g.situation.as_deref(), Some("head-on"));
        assert_eq!(g.role.as_deref(), Some("give-way"));
        assert_eq!(g.situation_geometric.as_deref(), Some("head-on"));
        assert_eq!(g.side, "port");
        assert_eq!(b.side, "starboard");
        assert_eq!(g.verdict, "compliant", "{:?}", g.reasons);
        assert_eq!(b.verdict, "violation");
        assert!(b
            .reasons
            .iter()
            .any(|r| r.contains("starboard to starboard")));
        assert_eq!(g.rule, Some(14));
        let (gs, bs) = (g.score.expect("score"), b.score.expect("score"));
        assert!(
            gs > bs + 0.3,
            "port-to-port {gs} vs starboard-to-starboard {bs}"
        );
        assert!(bs < 0.05, "{bs}");
        // The first action is the alteration at 140 s.
        assert_eq!(g.t_first_action_s, Some(140.0));
        assert!((g.course_change_deg.expect("dchi") - 30.0).abs() < 1e-9);
        assert!((b.course_change_deg.expect("dchi") + 30.0).abs() < 1e-9);
    }

    #[test]
    fn an_action_when_a_tug_detects_the_target_counts() {
        let p = params();
        // The turn at 128 s comes after the forward tug (2 m ahead) is within 7 m of the
        // target (about 123.5 s) but before the ship is (135.3 s).
        let mut samples = run(30f64.to_radians(), 128.0, 30.0, -0.5, PI, 0.07, 0.1);
        let view = give_way_view(Situation::HeadOn);
        let ship_only = assess("C", 6, &samples, Some(&view), &p).expect("report");
        assert!(ship_only.t_first_action_s.is_none());
        assert_eq!(ship_only.verdict, "violation");
        for s in &mut samples {
            let r = (s.target[0] - s.own[0]).hypot(s.target[1] - s.own[1]);
            s.tow_range = r - 2.0;
        }
        let tow = assess("C", 6, &samples, Some(&view), &p).expect("report");
        assert_eq!(tow.t_first_action_s, Some(128.0));
        assert!(tow.t_detect_tow_s.expect("tow") < tow.t_detect_s.expect("ship"));
        assert_eq!(tow.verdict, "compliant", "{:?}", tow.reasons);
        // Acting before the ship's detection range: no delay penalty.
        assert_eq!(tow.scores.expect("scores").p_delay, 0.0);
    }

    #[test]
    fn crossing_give_way_astern_beats_ahead() {
        let p = params();
        // Target crosses from starboard to port (course West) ahead of own ship.
        // Passing astern: turn to starboard (towards where the target comes from, behind
        // it). Passing ahead: keep course and be faster than the target's crossing.
        let view = give_way_view(Situation::CrossingGiveWay);
        let astern = run(60f64.to_radians(), 20.0, 6.0, 4.0, -PI / 2.0, 0.07, 0.1);
        let ahead = run(0.0, 20.0, 5.0, 3.0, -PI / 2.0, 0.07, 0.25);
        let a = assess("A", 4, &astern, Some(&view), &p).expect("report");
        let h = assess("A", 4, &ahead, Some(&view), &p).expect("report");
        assert_eq!(a.passed, "astern", "alpha {}", a.alpha_cpa_deg);
        assert_eq!(h.passed, "ahead", "alpha {}", h.alpha_cpa_deg);
        assert_eq!(a.verdict, "compliant", "{:?}", a.reasons);
        assert_eq!(h.verdict, "violation");
        assert!(h.reasons.iter().any(|r| r.contains("ahead")));
        assert_eq!(a.rule, Some(15));
        assert!(a.score.expect("score") > h.score.expect("score"));
        // Geometry at detection agrees with the controller.
        assert_eq!(a.situation_geometric.as_deref(), Some("crossing give-way"));
    }

    #[test]
    fn crossing_astern_then_closing_on_the_starboard_quarter_is_no_pass_ahead() {
        // Target from the starboard bow (8 m ahead, 3 m to starboard) crosses West at
        // 0.05 m/s. Own ship (0.1 m/s) alters 75 deg to starboard at 20 s, crosses the
        // target's course line astern of it (about 143 s) after turning back 45 deg to
        // port of her route at 80 s, and reaches her least range (5.3 m, 164 s) on the
        // target's starboard quarter: alpha_cpa about 164 deg, inside the window
        // (-25, 165) that alone reads it as a pass ahead (reana of random-12-0028, -0034,
        // -0265, -0425, -0432: "passed ahead" after passing astern).
        let p = params();
        let view = give_way_view(Situation::CrossingGiveWay);
        let course = -PI / 2.0;
        let (mut x, mut y) = (0.0, 0.0);
        let mut samples = Vec::new();
        for k in 0..800 {
            let t = f64::from(k) * 0.5;
            let psi = match t {
                t if t < 20.0 => 0.0,
                t if t < 80.0 => 75f64.to_radians(),
                _ => -45f64.to_radians(),
            };
            samples.push(EncounterSample {
                t,
                own: [x, y, psi, 0.1],
                target: [8.0, 3.0 - 0.05 * t, course, 0.05],
                altered: Some(t >= 20.0),
                tow_range: f64::INFINITY,
                route_course: 0.0,
            });
            x += 0.1 * 0.5 * psi.cos();
            y += 0.1 * 0.5 * psi.sin();
        }
        let a = assess("A", 4, &samples, Some(&view), &p).expect("report");
        assert_eq!(a.situation_geometric.as_deref(), Some("crossing give-way"));
        assert!((150.0..180.0).contains(&a.t_cpa_s), "{}", a.t_cpa_s);
        assert!(
            a.alpha_cpa_deg > 90.0 && a.alpha_cpa_deg < 165.0,
            "{}",
            a.alpha_cpa_deg
        );
        assert_eq!(a.passed, "astern");
        assert!(
            !a.reasons.iter().any(|r| r.contains("ahead")),
            "{:?}",
            a.reasons
        );
        assert_eq!(a.scores.expect("scores").p_ahead_rule15, 0.0);
        // Without the crossing astern the window alone reads the same CPA as a pass ahead.
        assert!(passed_ahead(a.alpha_cpa_deg, false));
    }

    #[test]
    fn a_port_turn_counts_only_while_the_target_bears_on_the_rules_side() {
        let p = params();
        let view = give_way_view(Situation::CrossingGiveWay);
        // Target from 18 deg on the starboard bow crosses West 4 m ahead of own ship (at
        // 20 s). Own ship turns 25 deg to port at 25 s, the target then on her port bow:
        // she passes astern of it, the range still closing to the CPA at about 50 s.
        let after = run(-25f64.to_radians(), 25.0, 6.0, 2.0, -PI / 2.0, 0.1, 0.1);
        let a = assess("A", 4, &after, Some(&view), &p).expect("report");
        assert_eq!(a.situation_geometric.as_deref(), Some("crossing give-way"));
        assert!(
            a.t_cpa_s > 25.0,
            "the turn is inside the window: {}",
            a.t_cpa_s
        );
        assert!((a.course_change_port_deg.expect("port") - 25.0).abs() < 1e-9);
        assert_eq!(a.port_turn_for_rule_deg, Some(0.0));
        assert_eq!(a.passed, "astern", "alpha {}", a.alpha_cpa_deg);
        assert_eq!(a.verdict, "compliant", "{:?}", a.reasons);
        // The same turn at 10 s, the target still on the starboard bow: a port turn for a
        // target on the starboard side.
        let before = run(-25f64.to_radians(), 10.0, 6.0, 2.0, -PI / 2.0, 0.1, 0.1);
        let b = assess("A", 4, &before, Some(&view), &p).expect("report");
        assert!((b.port_turn_for_rule_deg.expect("port") - 25.0).abs() < 1e-9);
        assert_eq!(b.verdict, "violation");
        assert!(
            b.reasons
                .iter()
                .any(|r| r.contains("25 deg to port for a target on the starboard side")),
            "{:?}",
            b.reasons
        );
    }

    #[test]
    fn never_detected() {
        let p = params();
        let far = run(0.0, 20.0, 30.0, 20.0, PI, 0.07, 0.1);
        let r = assess("B", 5, &far, None, &p).expect("report");
        assert_eq!(r.verdict, "no encounter");
        assert!(r.t_detect_s.is_none());
        assert!(r.r_cpa_m > 7.0);
    }

    use crate::decimate::tests::rng;

    #[test]
    fn the_tracker_equals_the_batch_assessment_on_random_encounters() {
        let p = params();
        let mut compared = [0usize; 3];
        for seed in 0..400u64 {
            let mut r = rng(seed);
            // A random straight pass with random heading wobble, alterations and tug
            // ranges; ranges on a coarse grid now and then (ties of the CPA).
            let n = 1 + (r() * 300.0) as usize;
            let (x0, y0) = (r() * 30.0 - 5.0, r() * 16.0 - 8.0);
            let course = r() * 2.0 * PI;
            let (u, vt) = (0.05 + 0.1 * r(), 0.1 * r());
            let turn_at = (r() * n as f64) as usize;
            let turn = (r() - 0.5) * 1.2;
            let grid = r() < 0.3;
            let samples: Vec<EncounterSample> = (0..n)
                .map(|k| {
                    let t = k as f64 * 0.5;
                    let psi = if k >= turn_at { turn } else { 0.0 } + 0.05 * (r() - 0.5);
                    let mut own = [u * t, 0.0, psi, u];
                    if grid {
                        own[0] = (own[0] * 2.0).round() / 2.0;
                    }
                    let target = [
                        x0 + vt * t * course.cos(),
                        y0 + vt * t * course.sin(),
                        course,
                        vt,
                    ];
                    let range = (target[0] - own[0]).hypot(target[1] - own[1]);
                    EncounterSample {
                        t,
                        own,
                        target,
                        altered: if r() < 0.1 { None } else { Some(r() < 0.3) },
                        tow_range: if r() < 0.2 {
                            f64::INFINITY
                        } else {
                            range - 2.0 * r()
                        },
                        route_course: 0.0,
                    }
                })
                .collect();
            let view = ControllerView {
                situation_codes: (0..5).map(|_| (r() * 8.0) as i32 - 1).collect(),
                roles: (0..5).map(|k| format!("role {k}")).collect(),
            };
            let view = (r() < 0.7).then_some(&view);
            let a = assess("X", 3, &samples, view, &p);
            let b = assess_batch("X", 3, &samples, view, &p);
            assert_eq!(a, b, "seed {seed}");
            let k = match &a {
                Some(rep) if rep.t_first_action_s.is_some() => 0,
                Some(rep) if rep.t_detect_s.is_some() => 1,
                _ => 2,
            };
            compared[k] += 1;
        }
        // The cases are all exercised: an action, a detection without one, no encounter.
        assert!(compared.iter().all(|&c| c > 10), "{compared:?}");
    }
}

//! Parameters of the ship reference system, one field one unit, validated once
//! ([`GuidanceParams::new`]). Values the paper does not give are marked
//! "Assumption" with the reason; `docs/colregs.md` lists them all.

use serde::{Deserialize, Serialize};

use towing_model::ObstacleKind;

use crate::colregs::ColregsSettings;
use crate::error::ParamError;

/// When a static hazard alters the route (the hazard must be within
/// [`GuidanceSettings::static_detection_distance`] in both cases).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum StaticHazardPolicy {
    /// Only when the altered leg `W_{p-1} -> W_pN` passes the hazard's centre
    /// farther than the route's leg `W_{p-1} -> W_p`: a starboard alteration is
    /// never asked for by a hazard it would approach. The default.
    #[default]
    WhenAlteringHelps,
    /// Eq. (8) literally: whenever the hazard is within its distance.
    ByDistance,
}

/// Plain settings; turn them into [`GuidanceParams`] to use them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GuidanceSettings {
    /// Detection distance `d_D` (m), eq. (8), for target ships: the route is
    /// altered when a target whose policy is to alter to starboard is within
    /// `d_D` (range-equivalent distance, see [`crate::distance`]) of the ship or a
    /// tug.
    ///
    /// Assumption: 7 m (5.6 ship lengths). The paper says only that it is "determined
    /// by the range sensors" and larger than every safe distance of eq. (14). 7 m
    /// is where the paper's first avoidance starts: at 100 s the tow is near W_P1
    /// and its forward tug about 7 m from target A (the other two windows start
    /// when targets B and C appear (by range, 14.2 m and 19.8 m from the ship,
    /// `scenarios/paper.toml`), so they say nothing about
    /// `d_D`). It is three times the largest safe distance against
    /// the paper's targets (2.245 m, ship vs a 1.48 m target, range units), and at
    /// the paper's closing speeds (0.1 m/s tow, 0.07 m/s target) it leaves about
    /// 30 s head-on and 40 s crossing between detection and the safe distance, for
    /// a tow that needs tens of seconds to shift its track.
    pub detection_distance: f64,
    /// Detection distance for static hazards (m): the route is altered when a
    /// hazard is within this distance of the ship or a tug (the paper's
    /// by-distance rule, which has a single `d_D`).
    ///
    /// Assumption: 2.5 m. With one `d_D` of 7 m the paper's hazards a, b, c, which
    /// lie 3.43 m, 3.43 m and 2.98 m beside the route, would keep the route altered,
    /// towards them, along most of its first half, while the paper describes the
    /// tow returning to and following its route between encounters. 2.5 m lies
    /// between the largest hazard safe distance (ship: 1.255 + 0.5 + 0.25 = 2.005 m)
    /// and the closest pass of the unaltered route (2.98 m). Set it equal to
    /// `detection_distance` for the literal single-`d_D` reading.
    pub static_detection_distance: f64,
    /// Which static hazards within their distance alter the route.
    ///
    /// Assumption: [`StaticHazardPolicy::WhenAlteringHelps`]. The paper alters for
    /// any obstacle within `d_D`; for a hazard on the starboard side of the leg
    /// that turns the tow towards it, and the hazard then holds the alteration. In
    /// the paper's scenario, run with a kinematic tow, the alteration for target A
    /// leads the tow towards hazard b, which then kept the route altered and the
    /// tow passed 1.6 m from b's centre (safe distance 2.0 m).
    pub static_hazard_policy: StaticHazardPolicy,
    /// Hysteresis (m): an obstacle that altered the route keeps it altered until its
    /// distance exceeds its detection distance plus this margin; then the
    /// encounter is over and the route comes back unaltered.
    ///
    /// Assumption: 0.5 m, the relative motion of one MPC horizon
    /// (`H_P T_s = 3 s`, Table 3) at the paper's head-on closing speed
    /// (0.17 m/s): it stops the reference from chattering at the threshold. The
    /// paper's eq. (8) has no hysteresis.
    pub release_margin: f64,
    /// Speed (m/s) at which the tow is taken to resume her route when the reference
    /// system judges whether a target it acted for is finally past and clear (Rule
    /// 8(d)): the tow, at this speed along the active leg from where she is, must pass
    /// the target clear before the action ends.
    ///
    /// Assumption: 0.1 m/s, the paper's tow speed (its figures; the MPC's surge soft
    /// limit is 0.11 m/s). The speed she had when she acted is no measure: a tow that
    /// acted at the start of a run was at rest.
    pub resume_speed: f64,
    /// Buffer `d_S0` (m) of eq. (14), used for the safe distances reported.
    ///
    /// Assumption: 0.25 m (a fifth of a ship length). The paper gives none. Its
    /// distance cost is soft, so vessels come inside the safe distance anyway
    /// (Table 6: tug 2 within 1.48 m of an obstacle centre in scenario 1, where
    /// `L_T + R = 1.47 m` for a hazard); the buffer is kept small against the
    /// obstacles' own half sizes (0.5 m and 0.74 m).
    pub safety_buffer: f64,
    /// Altering angle `theta` (rad), eq. (10)-(11): 15 deg (Table 3). Must be in
    /// `(0, pi/2)`; bounded per segment by `theta_max` when a waterway is given.
    pub altering_angle: f64,
    /// Distance from the route to the edge of the waterway, `d_2` of
    /// `theta_max = arctan(d_2 / d_1)` (m); `None` means no bound.
    ///
    /// Assumption: `None` in this crate (no waterway); the paper scenario's value is
    /// 5 m (`docs/assumptions.md`), which gives `theta_max` = 31.5-40.4 deg on its
    /// segments, above 15 deg.
    pub waterway_half_width: Option<f64>,
    /// Acceptance radius (m): the active waypoint is reached when the ship's centre
    /// is within this distance of the reference waypoint (altered or not).
    ///
    /// Assumption: 0.6275 m, half the ship length, the paper's own settling
    /// tolerance at the destination (section 4, "within half its length").
    pub acceptance_radius: f64,
    /// Also advance when the ship has passed the reference waypoint: its
    /// projection on the segment from `W_{p-1}` to the reference waypoint reaches
    /// the segment's length (the ship is beyond the waypoint's normal line), or she
    /// is past the bisector of the route's turn at the waypoint
    /// (`ReferenceSystem::reached`).
    ///
    /// Assumption: `true`. After an avoidance the ship may pass beside the waypoint,
    /// outside the acceptance radius; without this it would turn back for it.
    pub advance_on_passing: bool,
    /// Ship length `L` (m) for eq. (14): 1.255 m (CyberShip II; Table 2 prints
    /// 1.225 m, a misprint: `l_1 + l_2 = 1.255 m`).
    pub ship_length: f64,
    /// Tug length `L` (m) for eq. (14): 0.97 m (TitoNeri, Table 2).
    pub tug_length: f64,
    /// COLREGS classifier, tow status and Rule 17 thresholds.
    pub colregs: ColregsSettings,
}

impl GuidanceSettings {
    /// The detection distance for an obstacle of `kind`: `static_detection_distance`
    /// for a static hazard, `d_D` (`detection_distance`) for a target ship.
    #[must_use]
    pub fn detection_distance_for(&self, kind: ObstacleKind) -> f64 {
        match kind {
            ObstacleKind::StaticCircle => self.static_detection_distance,
            _ => self.detection_distance,
        }
    }
}

impl Default for GuidanceSettings {
    fn default() -> Self {
        Self {
            detection_distance: 7.0,
            static_detection_distance: 2.5,
            static_hazard_policy: StaticHazardPolicy::WhenAlteringHelps,
            release_margin: 0.5,
            resume_speed: 0.1,
            safety_buffer: 0.25,
            altering_angle: 15f64.to_radians(),
            waterway_half_width: None,
            acceptance_radius: 0.6275,
            advance_on_passing: true,
            ship_length: 1.255,
            tug_length: 0.97,
            colregs: ColregsSettings::default(),
        }
    }
}

/// Validated [`GuidanceSettings`]. The default holds the default settings, which
/// are valid.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GuidanceParams {
    settings: GuidanceSettings,
}

fn check(name: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<(), ParamError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(ParamError::OutOfRange {
            name,
            value,
            reason,
        })
    }
}

impl GuidanceParams {
    /// Validates the settings once.
    ///
    /// ```
    /// use towing_guidance::{GuidanceParams, GuidanceSettings};
    /// let params = GuidanceParams::new(GuidanceSettings {
    ///     waterway_half_width: Some(5.0),
    ///     ..GuidanceSettings::default()
    /// })?;
    /// assert_eq!(params.settings().detection_distance, 7.0);
    /// assert!(GuidanceParams::new(GuidanceSettings { altering_angle: 0.0, ..Default::default() }).is_err());
    /// # Ok::<(), towing_guidance::ParamError>(())
    /// ```
    ///
    /// # Errors
    /// [`ParamError::OutOfRange`] for the first field out of range: distances,
    /// lengths and the acceptance radius finite and > 0; margin and buffer
    /// finite and >= 0; `theta` in `(0, pi/2)`; COLREGS settings as
    /// [`ColregsSettings::validate`].
    pub fn new(settings: GuidanceSettings) -> Result<Self, ParamError> {
        let s = &settings;
        let pos = "finite and > 0";
        check(
            "detection_distance",
            s.detection_distance,
            s.detection_distance > 0.0,
            pos,
        )?;
        check(
            "static_detection_distance",
            s.static_detection_distance,
            s.static_detection_distance > 0.0,
            pos,
        )?;
        check(
            "release_margin",
            s.release_margin,
            s.release_margin >= 0.0,
            "finite and >= 0",
        )?;
        check("resume_speed", s.resume_speed, s.resume_speed > 0.0, pos)?;
        check(
            "safety_buffer",
            s.safety_buffer,
            s.safety_buffer >= 0.0,
            "finite and >= 0",
        )?;
        check(
            "altering_angle",
            s.altering_angle,
            s.altering_angle > 0.0 && s.altering_angle < std::f64::consts::FRAC_PI_2,
            "in (0, pi/2) rad (the paper: theta > 0, clockwise)",
        )?;
        if let Some(d2) = s.waterway_half_width {
            check("waterway_half_width", d2, d2 > 0.0, pos)?;
        }
        check(
            "acceptance_radius",
            s.acceptance_radius,
            s.acceptance_radius > 0.0,
            pos,
        )?;
        check("ship_length", s.ship_length, s.ship_length > 0.0, pos)?;
        check("tug_length", s.tug_length, s.tug_length > 0.0, pos)?;
        s.colregs.validate()?;
        Ok(Self { settings })
    }

    /// The validated settings.
    #[must_use]
    pub fn settings(&self) -> &GuidanceSettings {
        &self.settings
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_documented_values() {
        let p = GuidanceParams::new(GuidanceSettings::default()).unwrap();
        assert_eq!(p, GuidanceParams::default());
        let s = p.settings();
        assert!((s.altering_angle.to_degrees() - 15.0).abs() < 1e-12);
        assert!((s.acceptance_radius - 0.5 * s.ship_length).abs() < 1e-12);
        // d_D above the safe distances of eq. (14) (range units) against the
        // paper's obstacles, as the paper requires (d_*jd < d_D).
        let ship_vs_target = s.ship_length + 0.74 + s.safety_buffer;
        let ship_vs_hazard = s.ship_length + 0.5 + s.safety_buffer;
        assert!(s.detection_distance > ship_vs_target);
        assert!(s.static_detection_distance > ship_vs_hazard);
        // ... and the hazard distance below the closest pass of the paper's route.
        assert!(s.static_detection_distance < 2.97);
    }

    #[test]
    fn each_bad_field_is_named() {
        let bad = |f: fn(&mut GuidanceSettings)| {
            let mut s = GuidanceSettings::default();
            f(&mut s);
            match GuidanceParams::new(s) {
                Err(ParamError::OutOfRange { name, .. }) => name,
                other => panic!("{other:?}"),
            }
        };
        assert_eq!(bad(|s| s.detection_distance = 0.0), "detection_distance");
        assert_eq!(
            bad(|s| s.static_detection_distance = f64::NAN),
            "static_detection_distance"
        );
        assert_eq!(bad(|s| s.release_margin = -0.1), "release_margin");
        assert_eq!(bad(|s| s.resume_speed = 0.0), "resume_speed");
        assert_eq!(bad(|s| s.safety_buffer = f64::INFINITY), "safety_buffer");
        assert_eq!(bad(|s| s.altering_angle = -0.1), "altering_angle");
        assert_eq!(bad(|s| s.altering_angle = 1.6), "altering_angle");
        assert_eq!(
            bad(|s| s.waterway_half_width = Some(0.0)),
            "waterway_half_width"
        );
        assert_eq!(bad(|s| s.acceptance_radius = 0.0), "acceptance_radius");
        assert_eq!(bad(|s| s.ship_length = -1.0), "ship_length");
        assert_eq!(bad(|s| s.tug_length = 0.0), "tug_length");
        assert_eq!(bad(|s| s.colregs.rule17.dcpa = 0.0), "rule17.dcpa");
    }
}

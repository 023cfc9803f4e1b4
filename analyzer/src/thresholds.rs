//! Thresholds of the seamanship and rule verdicts (docs/analyzer.md, "Verdict").
//!
//! Every threshold is a parameter with a documented default; `analyzer report
//! --thresholds FILE` reads a TOML file with any subset of these keys (unknown keys are
//! refused), and a campaign file's `[thresholds]` table is handed on as that file.

use serde::{Deserialize, Serialize};

use crate::error::{AnalyzerError, Result};

/// Thresholds of the verdict. Defaults: issue 12's instrument and issue 14's seamanship
/// bounds (docs/analyzer.md).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Thresholds {
    /// Progress: least advance along the route, m, that ends a stall.
    pub progress_min_m: f64,
    /// Progress: no stall is counted within this distance of the destination, m.
    pub destination_radius_m: f64,
    /// Progress: longest stall allowed, s, except while giving way to a target that is
    /// not yet past and clear.
    pub stall_max_s: f64,
    /// Arrival: within `route length / arrival_speed_m_s + arrival_margin_s` of the start,
    /// m/s.
    pub arrival_speed_m_s: f64,
    /// Arrival margin, s.
    pub arrival_margin_s: f64,
    /// Drift and cruise: the ship is under way at this speed over ground or more, m/s.
    pub under_way_speed_m_s: f64,
    /// Drift: largest drift angle (course over ground against heading) under way, deg.
    pub drift_max_deg: f64,
    /// Speed over ground: largest multiple of the cruise speed (the median speed over
    /// ground while under way).
    pub sog_max_cruise_ratio: f64,
    /// Astern: largest surge speed astern, m/s (a positive number).
    pub astern_max_m_s: f64,
    /// Waterway: tolerance beyond the half width before a hull corner counts as
    /// aground, m.
    pub waterway_tolerance_m: f64,
    /// Give-way: least course alteration to starboard that counts as action, deg.
    pub give_way_turn_deg: f64,
    /// Give-way: an action is still held while the ship's head, to starboard of its
    /// heading at detection, comes round to starboard at this yaw rate or more, deg/s
    /// (the tow gathering way as she alters: docs/analyzer.md).
    pub give_way_turn_rate_deg_s: f64,
    /// Give-way: an alteration is still held while the ship keeps the offset to
    /// starboard of her route she has gained since detection, giving back no more than
    /// this of it, and more than this remains, m (about the ship's beam, 0.29 m; the
    /// tow steadied on a track parallel to her route holds her action: docs/analyzer.md).
    pub give_way_offset_m: f64,
    /// Give-way: the way is off at this surge speed or less, m/s.
    pub way_off_surge_m_s: f64,
    /// Give-way: no vessel of the tow crosses ahead of a give-way target closer than
    /// this, m.
    pub cross_ahead_min_m: f64,
    /// Head-on: least starboard alteration, deg.
    pub head_on_turn_deg: f64,
    /// Stand-on: largest course change before Rule 17 allows action, deg.
    pub stand_on_course_deg: f64,
    /// Stand-on: least fraction of the speed at detection kept before Rule 17 allows
    /// action.
    pub stand_on_speed_fraction: f64,
    /// Stand-on: Rule 17 allows action once the TCPA is at most this, s.
    pub rule17_tcpa_s: f64,
    /// Stand-on: largest port turn for a target on the port side, deg (Rule 17(c)).
    pub port_turn_max_deg: f64,
    /// Overtaking: least hull clearance, m.
    pub overtaking_clearance_m: f64,
    /// Course changes are measured against the route's course, seen this far ahead along
    /// the route from the ship's nearest point on it, m ([`crate::geometry::RouteCourse`]):
    /// the distance in which the tow rounds a bend.
    pub route_course_lookahead_m: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            progress_min_m: 0.5,
            destination_radius_m: 2.0,
            stall_max_s: 120.0,
            arrival_speed_m_s: 0.05,
            arrival_margin_s: 300.0,
            under_way_speed_m_s: 0.05,
            drift_max_deg: 30.0,
            sog_max_cruise_ratio: 1.3,
            astern_max_m_s: 0.03,
            waterway_tolerance_m: 0.0,
            give_way_turn_deg: 10.0,
            give_way_turn_rate_deg_s: 1.0,
            give_way_offset_m: 0.3,
            way_off_surge_m_s: 0.05,
            cross_ahead_min_m: 7.0,
            head_on_turn_deg: 10.0,
            stand_on_course_deg: 15.0,
            stand_on_speed_fraction: 0.5,
            rule17_tcpa_s: 60.0,
            port_turn_max_deg: 5.0,
            overtaking_clearance_m: 0.25,
            route_course_lookahead_m: 3.5,
        }
    }
}

impl Thresholds {
    /// Every threshold with its name, in declaration order.
    #[must_use]
    pub fn entries(&self) -> [(&'static str, f64); 22] {
        [
            ("progress_min_m", self.progress_min_m),
            ("destination_radius_m", self.destination_radius_m),
            ("stall_max_s", self.stall_max_s),
            ("arrival_speed_m_s", self.arrival_speed_m_s),
            ("arrival_margin_s", self.arrival_margin_s),
            ("under_way_speed_m_s", self.under_way_speed_m_s),
            ("drift_max_deg", self.drift_max_deg),
            ("sog_max_cruise_ratio", self.sog_max_cruise_ratio),
            ("astern_max_m_s", self.astern_max_m_s),
            ("waterway_tolerance_m", self.waterway_tolerance_m),
            ("give_way_turn_deg", self.give_way_turn_deg),
            ("give_way_turn_rate_deg_s", self.give_way_turn_rate_deg_s),
            ("give_way_offset_m", self.give_way_offset_m),
            ("way_off_surge_m_s", self.way_off_surge_m_s),
            ("cross_ahead_min_m", self.cross_ahead_min_m),
            ("head_on_turn_deg", self.head_on_turn_deg),
            ("stand_on_course_deg", self.stand_on_course_deg),
            ("stand_on_speed_fraction", self.stand_on_speed_fraction),
            ("rule17_tcpa_s", self.rule17_tcpa_s),
            ("port_turn_max_deg", self.port_turn_max_deg),
            ("overtaking_clearance_m", self.overtaking_clearance_m),
            ("route_course_lookahead_m", self.route_course_lookahead_m),
        ]
    }

    /// Refuses a non-finite or negative threshold, and a zero arrival speed.
    ///
    /// # Errors
    /// [`AnalyzerError::Usage`] naming the threshold and its value.
    pub fn validate(&self) -> Result<()> {
        for (name, value) in self.entries() {
            if !value.is_finite() || value < 0.0 {
                return Err(AnalyzerError::Usage(format!(
                    "threshold {name} must be a finite number >= 0, got {value}"
                )));
            }
        }
        if self.arrival_speed_m_s <= 0.0 {
            return Err(AnalyzerError::Usage(format!(
                "threshold arrival_speed_m_s must be > 0, got {}",
                self.arrival_speed_m_s
            )));
        }
        Ok(())
    }

    /// Reads a TOML file of thresholds (any subset of the keys) and validates it.
    ///
    /// # Errors
    /// The file cannot be read, is not valid TOML, has an unknown key or a bad value.
    pub fn from_file(path: &std::path::Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            AnalyzerError::Usage(format!("thresholds {}: cannot read: {e}", path.display()))
        })?;
        let t: Thresholds = toml::from_str(&text)
            .map_err(|e| AnalyzerError::Usage(format!("thresholds {}: {e}", path.display())))?;
        t.validate()
            .map_err(|e| AnalyzerError::Usage(format!("thresholds {}: {e}", path.display())))?;
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_a_subset_file_keeps_the_rest() {
        assert!(Thresholds::default().validate().is_ok());
        let t: Thresholds = toml::from_str("drift_max_deg = 20.0").expect("parses");
        assert_eq!(t.drift_max_deg, 20.0);
        assert_eq!(t.stall_max_s, 120.0);
    }

    #[test]
    fn unknown_keys_and_negative_values_are_refused() {
        assert!(toml::from_str::<Thresholds>("drift_max = 20.0").is_err());
        let t = Thresholds {
            astern_max_m_s: -1.0,
            ..Thresholds::default()
        };
        let e = t.validate().expect_err("refused").to_string();
        assert!(e.contains("astern_max_m_s"), "{e}");
    }
}

//! The trust region of the SCP step (Conn, Gould, Toint 2000, Trust-Region
//! Methods, Algorithm 6.1.1, with the step judged on the true merit).
//!
//! The step is judged by `ratio = (J(u) - J(u + du)) / (m(0) - m(du))` with the
//! true nonlinear merit `J` (from the nonlinear rollout): accepted if
//! `ratio >= accept`, and the trust radius grows (x `grow`, up to `max_radius`)
//! when `ratio >= good`, shrinks (x `shrink`, down to `min_radius`) when
//! `ratio < poor` or the QP gave no usable solution.

/// Trust-region parameters of the SCP step (dimensionless: the radius multiplies
/// each channel's [`crate::engine::Channel::trust_scale`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScpSettings {
    /// Radius at construction.
    pub initial_radius: f64,
    /// Smallest radius.
    pub min_radius: f64,
    /// Largest radius.
    pub max_radius: f64,
    /// Accept a step when the ratio of actual to predicted decrease is at least this.
    pub accept: f64,
    /// Grow the radius when the ratio is at least this.
    pub good: f64,
    /// Shrink the radius when the ratio is below this.
    pub poor: f64,
    /// Growth factor (> 1).
    pub grow: f64,
    /// Shrink factor (in (0, 1)).
    pub shrink: f64,
    /// Whether [`TrustRegion::reopen`] reopens the region (the optimizers call it
    /// at the start of each control sample).
    pub reopen: bool,
}

impl Default for ScpSettings {
    fn default() -> Self {
        ScpSettings {
            initial_radius: 0.5,
            min_radius: 1e-4,
            max_radius: 2.0,
            accept: 0.1,
            good: 0.75,
            poor: 0.25,
            grow: 2.0,
            shrink: 0.25,
            reopen: true,
        }
    }
}

impl ScpSettings {
    /// Checks the values: radii finite with `0 < min <= initial <= max`,
    /// `0 <= accept <= poor <= good`, `grow > 1`, `0 < shrink < 1`.
    ///
    /// # Errors
    /// The first offending field and why.
    pub fn validate(&self) -> Result<(), towing_model::ParamError> {
        let bad = |field: &str, reason: String| {
            Err(towing_model::ParamError {
                field: field.to_owned(),
                reason,
            })
        };
        let s = self;
        if !(s.min_radius.is_finite() && s.min_radius > 0.0) {
            return bad(
                "min_radius",
                format!("must be finite and > 0, got {}", s.min_radius),
            );
        }
        if !(s.max_radius.is_finite() && s.max_radius >= s.min_radius) {
            return bad(
                "max_radius",
                format!("must be finite and >= min_radius, got {}", s.max_radius),
            );
        }
        if !(s.initial_radius >= s.min_radius && s.initial_radius <= s.max_radius) {
            return bad(
                "initial_radius",
                format!(
                    "must lie in [min_radius, max_radius], got {}",
                    s.initial_radius
                ),
            );
        }
        if !(s.accept >= 0.0 && s.accept <= s.poor && s.poor <= s.good && s.good.is_finite()) {
            return bad(
                "accept",
                format!(
                    "must satisfy 0 <= accept <= poor <= good (finite), got {} <= {} <= {}",
                    s.accept, s.poor, s.good
                ),
            );
        }
        if !(s.grow.is_finite() && s.grow > 1.0) {
            return bad("grow", format!("must be finite and > 1, got {}", s.grow));
        }
        if !(s.shrink > 0.0 && s.shrink < 1.0) {
            return bad("shrink", format!("must lie in (0, 1), got {}", s.shrink));
        }
        Ok(())
    }
}

/// The trust region (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrustRegion {
    settings: ScpSettings,
    radius: f64,
}

impl TrustRegion {
    /// At `settings.initial_radius`.
    #[must_use]
    pub fn new(settings: ScpSettings) -> TrustRegion {
        TrustRegion {
            settings,
            radius: settings.initial_radius,
        }
    }

    /// Current radius.
    #[must_use]
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Sets the radius (a restored state), within `[min_radius, max_radius]`.
    pub fn set_radius(&mut self, radius: f64) {
        self.radius = radius.clamp(self.settings.min_radius, self.settings.max_radius);
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &ScpSettings {
        &self.settings
    }

    /// Back to the initial radius.
    pub fn reset(&mut self) {
        self.radius = self.settings.initial_radius;
    }

    /// At least the initial radius again, with [`ScpSettings::reopen`]: a new
    /// problem (the next control sample) starts with a fresh trust region (Conn,
    /// Gould, Toint 2000, Algorithm 6.1.1, step 0), whatever the last one shrank
    /// it to.
    pub fn reopen(&mut self) {
        if self.settings.reopen {
            self.radius = self.radius.max(self.settings.initial_radius);
        }
    }

    /// Judges a step: returns `(accepted, ratio)` and updates the radius. A
    /// predicted decrease `<= 1e-12 (1 + |J|)` means the plan is (numerically)
    /// stationary in the trust region: the step is not taken (ratio 1, radius
    /// kept), so an accepted step always lowers the true cost strictly.
    pub fn judge(&mut self, cost_before: f64, cost_after: f64, predicted: f64) -> (bool, f64) {
        let s = self.settings;
        let tiny = 1e-12 * (1.0 + cost_before.abs());
        if predicted.is_nan() || predicted <= tiny {
            return (false, 1.0);
        }
        let ratio = (cost_before - cost_after) / predicted;
        let ratio = if ratio.is_finite() { ratio } else { -1.0 };
        if ratio >= s.good {
            self.radius = (self.radius * s.grow).min(s.max_radius);
        } else if ratio < s.poor {
            self.radius = (self.radius * s.shrink).max(s.min_radius);
        }
        (ratio >= s.accept && cost_after < cost_before, ratio)
    }

    /// A failed QP: shrink.
    pub fn fail(&mut self) {
        self.radius = (self.radius * self.settings.shrink).max(self.settings.min_radius);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trust_region_grows_and_shrinks() {
        let mut tr = TrustRegion::new(ScpSettings::default());
        let r0 = tr.radius();
        assert_eq!(tr.judge(10.0, 9.0, 1.0), (true, 1.0));
        assert!(tr.radius() > r0);
        let r1 = tr.radius();
        let (acc, _) = tr.judge(10.0, 11.0, 1.0);
        assert!(!acc && tr.radius() < r1);
    }

    /// A new sample's problem starts with the region open again: a radius shrunk
    /// to the minimum goes back to the initial one, a larger one is kept.
    #[test]
    fn reopen_restores_at_least_the_initial_radius() {
        let s = ScpSettings::default();
        let mut tr = TrustRegion::new(s);
        while tr.radius() > s.min_radius {
            tr.fail();
        }
        tr.reopen();
        assert_eq!(tr.radius(), s.initial_radius);
        tr.set_radius(s.max_radius);
        tr.reopen();
        assert_eq!(tr.radius(), s.max_radius);
        let mut kept = TrustRegion::new(ScpSettings { reopen: false, ..s });
        kept.set_radius(s.min_radius);
        kept.reopen();
        assert_eq!(kept.radius(), s.min_radius);
    }

    #[test]
    fn settings_are_checked() {
        assert!(ScpSettings::default().validate().is_ok());
        let d = ScpSettings::default();
        for (s, field) in [
            (
                ScpSettings {
                    min_radius: 0.0,
                    ..d
                },
                "min_radius",
            ),
            (
                ScpSettings {
                    max_radius: 1e-5,
                    ..d
                },
                "max_radius",
            ),
            (
                ScpSettings {
                    initial_radius: 5.0,
                    ..d
                },
                "initial_radius",
            ),
            (ScpSettings { accept: 0.5, ..d }, "accept"),
            (ScpSettings { grow: 1.0, ..d }, "grow"),
            (ScpSettings { shrink: 1.0, ..d }, "shrink"),
        ] {
            assert_eq!(s.validate().unwrap_err().field, field);
        }
    }
}

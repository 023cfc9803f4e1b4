//! Discretisation parameters of the prediction models.

use towing_model::ParamError;

/// Largest number of RK4 substeps per sample a model accepts (`sample_time /
/// integration_step`); more is refused by [`PredictionParams::validate`].
pub const MAX_SUBSTEPS: usize = 100_000;

/// How the continuous models (Du et al. 2022, eq. (15)-(16)) are discretised: the
/// inputs are held over one sample of `sample_time` (zero-order hold) and the
/// integral is evaluated with fixed-step classical Runge-Kutta (RK4), the sample
/// split into `n = ceil(sample_time / integration_step)` equal substeps of
/// `sample_time / n` (the rule of the plant's `World::step`, so equal settings give
/// equal substeps).
///
/// Defaults: `sample_time = 1 s` (the paper's `T_s`, Table 3) and
/// `integration_step = 0.1 s` (10 substeps). The plant integrates at 0.01 s; the
/// coarser step costs a tenth and changes a one-sample prediction by about 1e-10 m
/// and 1e-11 m/s (measured in `tests/plant_agreement.rs`), far below the effect of
/// holding the towing angles over the sample: the fastest modes of the models
/// (tug sway `m22 / d22 = 3 s`, tug yaw with damping set B `m33 / d33 = 0.6 s`)
/// are slow against 0.1 s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictionParams {
    /// Sample time `T_s` (s): one prediction step. Finite, > 0.
    pub sample_time: f64,
    /// Largest RK4 substep (s). Finite, > 0; at most [`MAX_SUBSTEPS`] substeps per
    /// sample.
    pub integration_step: f64,
}

impl Default for PredictionParams {
    /// `T_s = 1 s`, RK4 substeps of at most 0.1 s.
    fn default() -> Self {
        PredictionParams {
            sample_time: 1.0,
            integration_step: 0.1,
        }
    }
}

impl PredictionParams {
    /// Checks the values (see the fields); field names as in the struct.
    pub fn validate(&self) -> Result<(), ParamError> {
        for (field, value) in [
            ("sample_time", self.sample_time),
            ("integration_step", self.integration_step),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ParamError {
                    field: field.to_owned(),
                    reason: format!("must be finite and > 0 s, got {value} s"),
                });
            }
        }
        let ratio = self.sample_time / self.integration_step;
        if ratio > MAX_SUBSTEPS as f64 {
            return Err(ParamError {
                field: "integration_step".to_owned(),
                reason: format!(
                    "sample_time / integration_step = {ratio} exceeds {MAX_SUBSTEPS} substeps"
                ),
            });
        }
        Ok(())
    }

    /// Number of RK4 substeps per sample, `ceil(sample_time / integration_step)`
    /// with the plant's rounding tolerance (0.1 / 0.01 gives 10), at least 1.
    /// Meaningful after [`PredictionParams::validate`].
    #[must_use]
    pub fn substeps(&self) -> usize {
        let ratio = self.sample_time / self.integration_step;
        ((ratio - 1e-9).ceil() as usize).max(1)
    }

    /// The validated substep count and length.
    pub(crate) fn discretise(&self) -> Result<Substeps, ParamError> {
        self.validate()?;
        let n = self.substeps();
        Ok(Substeps {
            n,
            h: self.sample_time / n as f64,
        })
    }
}

/// `n` RK4 substeps of `h` seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Substeps {
    pub n: usize,
    pub h: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substeps_follow_the_plant_rule() {
        let p = PredictionParams::default();
        assert_eq!(p.substeps(), 10);
        let s = p.discretise().unwrap();
        assert_eq!((s.n, s.h), (10, 0.1));
        let p = PredictionParams {
            sample_time: 0.1,
            integration_step: 0.01,
        };
        assert_eq!(p.substeps(), 10);
        let p = PredictionParams {
            sample_time: 1.0,
            integration_step: 0.3,
        };
        assert_eq!(p.substeps(), 4);
        assert_eq!(p.discretise().unwrap().h, 0.25);
        let p = PredictionParams {
            sample_time: 0.05,
            integration_step: 0.1,
        };
        assert_eq!(p.substeps(), 1);
    }

    #[test]
    fn refuses_bad_values() {
        for (ts, dt, field) in [
            (0.0, 0.1, "sample_time"),
            (f64::NAN, 0.1, "sample_time"),
            (1.0, -0.1, "integration_step"),
            (1.0, f64::INFINITY, "integration_step"),
            (1.0, 1e-9, "integration_step"),
        ] {
            let p = PredictionParams {
                sample_time: ts,
                integration_step: dt,
            };
            assert_eq!(p.validate().unwrap_err().field, field, "{ts} {dt}");
        }
    }
}

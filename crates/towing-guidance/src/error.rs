//! Errors: misuse of the API (bad parameters, bad inputs). Guidance outcomes
//! (altered or not, a situation) are values, never errors.

use thiserror::Error;

/// A parameter or route refused when the guidance is built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// A parameter is out of its range (the message says which range).
    #[error("parameter `{name}` = {value} is invalid: {reason}")]
    OutOfRange {
        /// Field name.
        name: &'static str,
        /// Given value (SI units, radians).
        value: f64,
        /// Allowed range.
        reason: &'static str,
    },
    /// A route needs an origin and at least one more point.
    #[error("a route needs at least 2 points (origin and destination), got {count}")]
    RouteTooShort {
        /// Number of points given.
        count: usize,
    },
    /// A route point is not finite.
    #[error("route point {index} is not finite")]
    NonFiniteRoutePoint {
        /// Index of the point (0 = origin).
        index: usize,
    },
    /// Two consecutive route points coincide: the segment has no course.
    #[error("route points {index} and {next} coincide (segment length {length} m)")]
    DegenerateSegment {
        /// Index of the first point.
        index: usize,
        /// Index of the second point.
        next: usize,
        /// Segment length (m).
        length: f64,
    },
}

/// A per-sample input refused by [`crate::ReferenceSystem::update`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InputError {
    /// An active obstacle has a non-finite field.
    #[error("obstacle field `{field}` is not finite")]
    NonFiniteObstacle {
        /// Field name.
        field: &'static str,
    },
    /// Length not positive, width negative, or a ship wider than long.
    #[error("obstacle size invalid: length {length} m, width {width} m")]
    BadObstacleSize {
        /// Length (m).
        length: f64,
        /// Width (m).
        width: f64,
    },
    /// A target ship with negative speed.
    #[error("obstacle speed {speed} m/s is negative")]
    NegativeSpeed {
        /// Speed (m/s).
        speed: f64,
    },
    /// More obstacle slots than the reference system can track.
    #[error("{count} obstacle slots given, at most {max} are supported")]
    TooManyObstacles {
        /// Slots given.
        count: usize,
        /// [`towing_model::MAX_OBSTACLES`].
        max: usize,
    },
    /// The tow's state has a non-finite value.
    #[error("tow state field `{field}` is not finite")]
    NonFiniteTowState {
        /// Field name.
        field: &'static str,
    },
}

//! Angle helpers. Angles are radians in code; headings are kept in `(-pi, pi]`.

use std::f64::consts::{PI, TAU};

/// Wraps an angle to `(-pi, pi]` (radians).
///
/// `pi` maps to `pi` and `-pi` maps to `pi`, so a heading has exactly one
/// representation. Non-finite input gives NaN (callers check finiteness).
///
/// ```
/// use towing_model::wrap_angle;
/// use std::f64::consts::PI;
/// assert_eq!(wrap_angle(PI), PI);
/// assert_eq!(wrap_angle(-PI), PI);
/// assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
/// ```
#[must_use]
pub fn wrap_angle(angle: f64) -> f64 {
    if angle > -PI && angle <= PI {
        return angle;
    }
    // rem_euclid gives [0, 2 pi) up to rounding, so pi - rem lies in (-pi, pi].
    let wrapped = PI - (PI - angle).rem_euclid(TAU);
    if wrapped <= -PI {
        wrapped + TAU
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn boundaries() {
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert_eq!(wrap_angle(0.0), 0.0);
        assert_eq!(wrap_angle(TAU), 0.0);
        assert!((wrap_angle(-PI - 0.1) - (PI - 0.1)).abs() < 1e-12);
        assert!((wrap_angle(PI + 0.1) - (-PI + 0.1)).abs() < 1e-12);
        assert!(wrap_angle(f64::NAN).is_nan());
        assert!(wrap_angle(f64::INFINITY).is_nan());
    }

    proptest! {
        #[test]
        fn in_range_and_same_direction(a in -1.0e4f64..1.0e4) {
            let w = wrap_angle(a);
            prop_assert!(w > -PI && w <= PI, "{a} -> {w}");
            prop_assert!((w.sin() - a.sin()).abs() < 1e-9);
            prop_assert!((w.cos() - a.cos()).abs() < 1e-9);
        }
    }
}

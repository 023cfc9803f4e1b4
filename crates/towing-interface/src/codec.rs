//! The value-reference codec: how the variables of the interface contract are numbered and
//! how their values cross the FMI boundary.
//!
//! * [`obstacle_kind_code`] and [`obstacle_kind_from_code`]: the FMI Integer
//!   `obstacle[k].kind` (0 none, 1 static circle, 2 vessel ellipse) and the
//!   [`ObstacleKind`] of an [`ObstacleSlot`](towing_model::ObstacleSlot). The only place
//!   the numbers appear.

use towing_model::ObstacleKind;

/// The FMI Integer `obstacle[k].kind` of `kind`: 0 none, 1 static circle, 2 vessel ellipse
/// (DESIGN.md, "Interface contract"; the `ObstacleKind` type of the model descriptions).
#[must_use]
pub const fn obstacle_kind_code(kind: ObstacleKind) -> i32 {
    match kind {
        ObstacleKind::None => 0,
        ObstacleKind::StaticCircle => 1,
        ObstacleKind::VesselEllipse => 2,
    }
}

/// The [`ObstacleKind`] of the FMI Integer `obstacle[k].kind`.
///
/// # Errors
/// A message naming the code and the valid ones, for any code but 0, 1, 2.
pub fn obstacle_kind_from_code(code: i32) -> Result<ObstacleKind, String> {
    [
        ObstacleKind::None,
        ObstacleKind::StaticCircle,
        ObstacleKind::VesselEllipse,
    ]
    .into_iter()
    .find(|&kind| obstacle_kind_code(kind) == code)
    .ok_or_else(|| {
        format!("unknown obstacle kind {code} (0 none, 1 static circle, 2 vessel ellipse)")
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn obstacle_kinds_round_trip_and_other_codes_are_refused() {
        for code in 0..3 {
            let kind = obstacle_kind_from_code(code);
            assert_eq!(kind.map(obstacle_kind_code), Ok(code));
        }
        for code in [-1, 3, i32::MAX] {
            let e = obstacle_kind_from_code(code).unwrap_err();
            assert!(e.contains(&format!("unknown obstacle kind {code}")), "{e}");
        }
    }
}

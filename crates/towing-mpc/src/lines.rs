//! Towline loads of the prediction models, through the plant's own load function.
//!
//! A line's direction follows from its towing angle exactly as the plant defines
//! the angle (`towing_model::towline`, module docs): the angle `alpha_i` is the
//! direction of the line taken from aft to forward, relative to the ship's heading,
//! so the line's world bearing is `psi_S + alpha_i` and the unit vector from the
//! ship's attachment point to the tug's is
//!
//! - towline 2 (`line = 1`, bow to the forward tug): `(cos, sin)(psi_S + alpha_2)`;
//! - towline 1 (`line = 0`, stern to the aft tug): `-(cos, sin)(psi_S + alpha_1)`.
//!
//! The loads are then [`towing_model::towline::line_loads`] of that direction: `T e`
//! at the ship's point, `-T e` at the tug's, moments `r x F` in each body frame.
//! Since the loads are linear in the direction, their derivative w.r.t. the bearing
//! is the same function of the direction turned by +90 deg.

use towing_model::towline::{line_loads, LineGeometry, LineLoads};

/// Unit vector (NED) from the ship's attachment point to the tug's for towline
/// `line` (0 = towline 1, stern to tug 1; 1 = towline 2, bow to tug 2) whose
/// direction, taken from aft to forward, has bearing `bearing` (rad): for the
/// plant's towing angle `alpha_i`, `bearing = psi_S + alpha_i`. In the ship's body
/// frame pass `bearing = alpha_i`.
///
/// # Panics
/// If `line > 1`.
#[must_use]
pub fn line_direction(line: usize, bearing: f64) -> [f64; 2] {
    let (s, c) = bearing.sin_cos();
    match line {
        0 => [-c, -s],
        1 => [c, s],
        _ => panic!("towline index {line} out of range (0 = towline 1, 1 = towline 2)"),
    }
}

/// `direction` turned by +90 deg (clockwise seen from above in NED): the derivative
/// of a unit vector `(cos, sin)(b)` w.r.t. `b`.
#[inline]
#[must_use]
pub(crate) fn turned(direction: [f64; 2]) -> [f64; 2] {
    [-direction[1], direction[0]]
}

/// The plant's [`line_loads`] for a line along `direction` (unit, ship point to
/// tug point): only the direction of the geometry enters the loads, the points and
/// length given here are placeholders.
#[inline]
#[must_use]
pub(crate) fn loads_along(
    direction: [f64; 2],
    ship_psi: f64,
    ship_point_x: f64,
    tug_psi: f64,
    tug_point_x: f64,
    tension: f64,
) -> LineLoads {
    let geometry = LineGeometry {
        ship_point: [0.0, 0.0],
        tug_point: direction,
        length: 1.0,
        length_rate: 0.0,
        direction,
    };
    line_loads(
        &geometry,
        ship_psi,
        ship_point_x,
        tug_psi,
        tug_point_x,
        tension,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use towing_model::towline::{formation_pose, line_geometry, towing_angle};
    use towing_model::VesselData;

    /// The direction is the plant's geometry for tugs placed in formation, and the
    /// towing angle the plant reads back is the one the direction was built from.
    #[test]
    fn direction_is_the_plants_geometry() {
        let (ship, tug) = (VesselData::cybership2(), VesselData::titoneri());
        let ship_eta = [-4.9, 7.0, 101.3f64.to_radians()];
        for alpha in [-0.5, -0.1, 0.0, 0.17, 0.5] {
            for line in 0..2 {
                let tug_eta = formation_pose(line, &ship_eta, &ship, &tug, 1.0, alpha);
                let (xs, xt) = if line == 0 {
                    (ship.stern_tow_point_x, tug.bow_tow_point_x)
                } else {
                    (ship.bow_tow_point_x, tug.stern_tow_point_x)
                };
                let g = line_geometry(&ship_eta, &[0.0; 3], xs, &tug_eta, &[0.0; 3], xt);
                let e = line_direction(line, ship_eta[2] + alpha);
                assert!((e[0] - g.direction[0]).abs() < 1e-14, "{line} {alpha}");
                assert!((e[1] - g.direction[1]).abs() < 1e-14, "{line} {alpha}");
                let back = towing_angle(line, g.ship_point, g.tug_point, ship_eta[2]);
                assert!((back - alpha).abs() < 1e-14, "{line}: {back} vs {alpha}");
                // Same loads as the plant's geometry gives.
                let ours = loads_along(e, ship_eta[2], xs, tug_eta[2], xt, 2.0);
                let plant = line_loads(&g, ship_eta[2], xs, tug_eta[2], xt, 2.0);
                for k in 0..3 {
                    assert!((ours.on_ship[k] - plant.on_ship[k]).abs() < 1e-14);
                    assert!((ours.on_tug[k] - plant.on_tug[k]).abs() < 1e-14);
                }
            }
        }
    }

    /// Signs, in the ship's body frame: a forward line turned to starboard pulls the
    /// bow to starboard (positive yaw moment); an aft line turned to starboard pulls
    /// the stern to port, which also turns the bow to starboard.
    #[test]
    fn moments_follow_the_geometry() {
        let ship = VesselData::cybership2();
        let a = 0.2;
        let fwd = loads_along(
            line_direction(1, a),
            0.0,
            ship.bow_tow_point_x,
            0.0,
            -0.5,
            1.0,
        );
        assert!(fwd.on_ship[0] > 0.0 && fwd.on_ship[1] > 0.0 && fwd.on_ship[2] > 0.0);
        let aft = loads_along(
            line_direction(0, a),
            0.0,
            ship.stern_tow_point_x,
            0.0,
            0.5,
            1.0,
        );
        assert!(aft.on_ship[0] < 0.0 && aft.on_ship[1] < 0.0 && aft.on_ship[2] > 0.0);
        assert!((aft.on_ship[2] - (-ship.stern_tow_point_x) * a.sin()).abs() < 1e-15);
    }
}

//! Builders of the Foxglove messages from NED quantities.
//!
//! Foxglove's frames are z-up; the frame `world` is ENU: East = NED y, North = NED x,
//! up = -NED z, and a heading `psi` (from North, clockwise) is the ENU yaw
//! `pi/2 - psi` (from East, counter-clockwise). A top-down view then shows East to the
//! right and North up, as the paper's maps. Every function here takes NED positions
//! (x North, y East, m) and headings (rad) and does the conversion.

use crate::topics::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, Duration, FrameTransform,
    LinePrimitive, Log, Point3, Pose, Quaternion, SceneEntity, SpherePrimitive, Timestamp, Vector3,
    FRAME_WORLD,
};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Height of the hull boxes (m).
pub const HULL_HEIGHT: f64 = 0.2;

/// ENU yaw (rad, from East, counter-clockwise) of a NED heading `psi` (rad, from North,
/// clockwise): `pi/2 - psi`.
#[must_use]
pub fn yaw_enu(psi: f64) -> f64 {
    FRAC_PI_2 - psi
}

/// ENU vector of a NED position (`x` North, `y` East, m) at height `z` (m, up).
#[must_use]
pub fn enu_vector(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x: y, y: x, z }
}

/// ENU point of a NED position at height `z` (m, up).
#[must_use]
pub fn enu_point(x: f64, y: f64, z: f64) -> Point3 {
    Point3 { x: y, y: x, z }
}

/// Rotation about the ENU z axis by `yaw` (rad, counter-clockwise).
#[must_use]
pub fn yaw_quaternion(yaw: f64) -> Quaternion {
    let (s, c) = (0.5 * yaw).sin_cos();
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: s,
        w: c,
    }
}

/// ENU pose of a NED pose (`x` North, `y` East, m; `psi` from North, clockwise, rad) at
/// height `z` (m): the pose's +x axis points along the heading.
#[must_use]
pub fn enu_pose(x: f64, y: f64, psi: f64, z: f64) -> Pose {
    Pose {
        position: enu_vector(x, y, z),
        orientation: yaw_quaternion(yaw_enu(psi)),
    }
}

/// Timestamp of simulation time `t` (s) as the log times: `round(t * 1e9)` ns (0 for a
/// time that is not representable).
#[must_use]
pub fn timestamp(t: f64) -> Timestamp {
    Timestamp::from_nanos(crate::writer::time_ns(t).unwrap_or(0))
}

impl Color {
    /// Opaque colour from 0..1 components.
    #[must_use]
    pub const fn rgb(r: f64, g: f64, b: f64) -> Color {
        Color { r, g, b, a: 1.0 }
    }

    /// The same colour with opacity `a`.
    #[must_use]
    pub const fn with_alpha(self, a: f64) -> Color {
        Color { a, ..self }
    }
}

/// Colours of the scene.
pub mod colors {
    use crate::topics::Color;
    /// The towed ship.
    pub const SHIP: Color = Color::rgb(0.12, 0.47, 0.71);
    /// The tugs.
    pub const TUG: Color = Color::rgb(1.0, 0.5, 0.05);
    /// Towlines.
    pub const TOWLINE: Color = Color::rgb(0.2, 0.2, 0.2);
    /// Slack towlines.
    pub const TOWLINE_SLACK: Color = Color::rgb(0.6, 0.6, 0.6);
    /// Static hazards.
    pub const HAZARD: Color = Color::rgb(0.55, 0.34, 0.29);
    /// Safe circles.
    pub const SAFE: Color = Color::rgb(0.84, 0.15, 0.16);
    /// Target ships.
    pub const TARGET: Color = Color::rgb(0.84, 0.15, 0.16);
    /// The route and its waypoints.
    pub const ROUTE: Color = Color::rgb(0.17, 0.63, 0.17);
    /// Predicted paths.
    pub const PREDICTION: Color = Color::rgb(0.58, 0.4, 0.74);
    /// The active (altered) waypoint and the reference.
    pub const REFERENCE: Color = Color::rgb(0.89, 0.47, 0.76);
}

impl SceneEntity {
    /// An empty entity `id` in the frame `world` at simulation time `t` (s), staying until
    /// replaced (lifetime 0), not frame-locked.
    #[must_use]
    pub fn new(id: impl Into<String>, t: f64) -> SceneEntity {
        SceneEntity {
            timestamp: timestamp(t),
            frame_id: FRAME_WORLD.to_owned(),
            id: id.into(),
            lifetime: Duration::FOREVER,
            frame_locked: false,
            metadata: Vec::new(),
            arrows: Vec::new(),
            cubes: Vec::new(),
            spheres: Vec::new(),
            cylinders: Vec::new(),
            lines: Vec::new(),
            triangles: Vec::new(),
            texts: Vec::new(),
            models: Vec::new(),
        }
    }
}

impl SceneEntity {
    /// An empty entity `id` in the (moving) frame `frame` that follows that frame
    /// (`frame_locked`): published once, it moves with the frame's transforms on `/tf`.
    #[must_use]
    pub fn locked_to(id: impl Into<String>, t: f64, frame: &str) -> SceneEntity {
        SceneEntity {
            frame_id: frame.to_owned(),
            frame_locked: true,
            ..SceneEntity::new(id, t)
        }
    }
}

/// A hull as a box in its own vessel frame (x forward, y to port in Foxglove's z-up
/// frames), centred at the frame's origin, [`HULL_HEIGHT`] high, its bottom on the water
/// plane; use it in an entity [`locked_to`](SceneEntity::locked_to) the vessel's frame.
#[must_use]
pub fn hull_cube_in_vessel_frame(length: f64, width: f64, color: Color) -> CubePrimitive {
    CubePrimitive {
        pose: Pose {
            position: Vector3 {
                x: 0.0,
                y: 0.0,
                z: 0.5 * HULL_HEIGHT,
            },
            orientation: Quaternion::IDENTITY,
        },
        size: Vector3 {
            x: length,
            y: width,
            z: HULL_HEIGHT,
        },
        color,
    }
}

/// A hull as a box centred at the NED pose (`x`, `y`, `psi`), `length` along the heading,
/// `width` across, [`HULL_HEIGHT`] high, its bottom on the water plane.
#[must_use]
pub fn hull_cube(x: f64, y: f64, psi: f64, length: f64, width: f64, color: Color) -> CubePrimitive {
    CubePrimitive {
        pose: enu_pose(x, y, psi, 0.5 * HULL_HEIGHT),
        size: Vector3 {
            x: length,
            y: width,
            z: HULL_HEIGHT,
        },
        color,
    }
}

/// A line through NED points (`[x North, y East]`, m) at height `z`, `line_type`
/// [`LinePrimitive::LINE_STRIP`] or [`LinePrimitive::LINE_LOOP`], `thickness` in m.
#[must_use]
pub fn line(
    line_type: i32,
    points: impl IntoIterator<Item = [f64; 2]>,
    z: f64,
    thickness: f64,
    color: Color,
) -> LinePrimitive {
    LinePrimitive {
        line_type,
        pose: Pose::default(),
        thickness,
        scale_invariant: false,
        points: points
            .into_iter()
            .map(|[x, y]| enu_point(x, y, z))
            .collect(),
        color,
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

/// A line strip through NED points (module docs).
#[must_use]
pub fn line_strip(
    points: impl IntoIterator<Item = [f64; 2]>,
    z: f64,
    thickness: f64,
    color: Color,
) -> LinePrimitive {
    line(LinePrimitive::LINE_STRIP, points, z, thickness, color)
}

/// A circle of `radius` (m) around the NED point (`x`, `y`) as a line loop of `segments`
/// points (at least 3).
#[must_use]
pub fn circle_loop(
    x: f64,
    y: f64,
    radius: f64,
    segments: usize,
    z: f64,
    thickness: f64,
    color: Color,
) -> LinePrimitive {
    let n = segments.max(3);
    let points = (0..n).map(|k| {
        let a = TAU * k as f64 / n as f64;
        [x + radius * a.cos(), y + radius * a.sin()]
    });
    line(LinePrimitive::LINE_LOOP, points, z, thickness, color)
}

/// An upright elliptic cylinder centred at the NED pose, `length` along `psi`, `width`
/// across, `height` high, its bottom on the water plane.
#[must_use]
pub fn cylinder(
    x: f64,
    y: f64,
    psi: f64,
    length: f64,
    width: f64,
    height: f64,
    color: Color,
) -> CylinderPrimitive {
    CylinderPrimitive {
        pose: enu_pose(x, y, psi, 0.5 * height),
        size: Vector3 {
            x: length,
            y: width,
            z: height,
        },
        bottom_scale: 1.0,
        top_scale: 1.0,
        color,
    }
}

/// A sphere of `diameter` (m) at the NED point (`x`, `y`) at height `z`.
#[must_use]
pub fn sphere(x: f64, y: f64, z: f64, diameter: f64, color: Color) -> SpherePrimitive {
    SpherePrimitive {
        pose: Pose {
            position: enu_vector(x, y, z),
            orientation: Quaternion::IDENTITY,
        },
        size: Vector3 {
            x: diameter,
            y: diameter,
            z: diameter,
        },
        color,
    }
}

/// An arrow from the NED point (`x`, `y`) along the heading `psi`, `length` m long in all.
#[must_use]
pub fn arrow(x: f64, y: f64, psi: f64, z: f64, length: f64, color: Color) -> ArrowPrimitive {
    ArrowPrimitive {
        pose: enu_pose(x, y, psi, z),
        shaft_length: 0.7 * length,
        shaft_diameter: 0.05 * length,
        head_length: 0.3 * length,
        head_diameter: 0.15 * length,
        color,
    }
}

/// The transform `world` -> `child` of a vessel at the NED pose (`x`, `y`, `psi`) at
/// simulation time `t` (s).
#[must_use]
pub fn frame_transform(child: &str, t: f64, x: f64, y: f64, psi: f64) -> FrameTransform {
    let pose = enu_pose(x, y, psi, 0.0);
    FrameTransform {
        timestamp: timestamp(t),
        parent_frame_id: FRAME_WORLD.to_owned(),
        child_frame_id: child.to_owned(),
        translation: pose.position,
        rotation: pose.orientation,
    }
}

/// A Foxglove log line from `name` (the unit) at simulation time `t` (s).
#[must_use]
pub fn log_line(t: f64, level: i32, name: &str, message: impl Into<String>) -> Log {
    Log {
        timestamp: timestamp(t),
        level,
        message: message.into(),
        name: name.to_owned(),
        file: String::new(),
        line: 0,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::float_cmp)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Rotates `v` by the unit quaternion `q`.
    fn rotate(q: Quaternion, v: [f64; 3]) -> [f64; 3] {
        // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z).
        let u = [q.x, q.y, q.z];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let uv = cross(u, v);
        let uuv = cross(u, uv);
        [
            v[0] + 2.0 * (q.w * uv[0] + uuv[0]),
            v[1] + 2.0 * (q.w * uv[1] + uuv[1]),
            v[2] + 2.0 * (q.w * uv[2] + uuv[2]),
        ]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn enu_swaps_north_and_east() {
        let v = enu_vector(3.0, -2.0, 0.5);
        assert_eq!((v.x, v.y, v.z), (-2.0, 3.0, 0.5));
        let p = enu_point(-4.9, 7.0, 0.0);
        assert_eq!((p.x, p.y), (7.0, -4.9));
    }

    #[test]
    fn a_heading_maps_the_body_x_axis_onto_the_course() {
        // psi = 0 (North) -> ENU +y; psi = 90 deg (East) -> ENU +x; psi = 180 deg -> -y;
        // psi = -90 deg (West) -> -x. In general (sin psi, cos psi, 0).
        for psi in [0.0, PI / 2.0, PI, -PI / 2.0, 101.3f64.to_radians(), -2.5] {
            let q = enu_pose(0.0, 0.0, psi, 0.0).orientation;
            let norm = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
            assert!((norm - 1.0).abs() < 1e-12);
            let ahead = rotate(q, [1.0, 0.0, 0.0]);
            assert!(
                close(ahead, [psi.sin(), psi.cos(), 0.0]),
                "psi {psi}: {ahead:?}"
            );
            // Body y (starboard) points to the right of the course: (cos psi, -sin psi)
            // in ENU, i.e. a clockwise quarter turn from ahead, seen from above.
            let starboard = rotate(q, [0.0, -1.0, 0.0]);
            assert!(
                close(starboard, [psi.cos(), -psi.sin(), 0.0]),
                "psi {psi}: {starboard:?}"
            );
        }
        assert!((yaw_enu(0.0) - PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn a_hull_cube_sits_on_the_water_with_its_length_along_the_heading() {
        let c = hull_cube(-4.9, 7.0, 0.3, 1.255, 0.29, colors::SHIP);
        assert_eq!(
            (c.pose.position.x, c.pose.position.y, c.pose.position.z),
            (7.0, -4.9, 0.5 * HULL_HEIGHT)
        );
        assert_eq!((c.size.x, c.size.y, c.size.z), (1.255, 0.29, HULL_HEIGHT));
        let bow = rotate(c.pose.orientation, [0.5 * c.size.x, 0.0, 0.0]);
        assert!(close(
            bow,
            [0.5 * 1.255 * 0.3f64.sin(), 0.5 * 1.255 * 0.3f64.cos(), 0.0]
        ));
    }

    #[test]
    fn a_hull_locked_to_its_frame_sits_where_the_world_pose_puts_it() {
        let (x, y, psi) = (-4.9, 7.0, 1.2);
        let e = SceneEntity::locked_to("ship", 0.0, "ship");
        assert!(e.frame_locked);
        assert_eq!(e.frame_id, "ship");
        let body = hull_cube_in_vessel_frame(1.255, 0.29, colors::SHIP);
        let world = hull_cube(x, y, psi, 1.255, 0.29, colors::SHIP);
        // Through the transform world -> ship of the same pose, the bow of the body-frame
        // cube lands on the bow of the world-frame cube.
        let tf = frame_transform("ship", 0.0, x, y, psi);
        let bow_body = [0.5 * body.size.x, 0.0, body.pose.position.z];
        let r = rotate(tf.rotation, bow_body);
        let via_tf = [
            r[0] + tf.translation.x,
            r[1] + tf.translation.y,
            r[2] + tf.translation.z,
        ];
        let w = rotate(world.pose.orientation, [0.5 * world.size.x, 0.0, 0.0]);
        let direct = [
            w[0] + world.pose.position.x,
            w[1] + world.pose.position.y,
            w[2] + world.pose.position.z,
        ];
        assert!(close(via_tf, direct), "{via_tf:?} {direct:?}");
    }

    #[test]
    fn lines_and_circles_are_in_enu() {
        let l = line_strip([[1.0, 2.0], [3.0, 4.0]], 0.01, 0.02, colors::ROUTE);
        assert_eq!(l.line_type, LinePrimitive::LINE_STRIP);
        assert_eq!(
            (l.points[1].x, l.points[1].y, l.points[1].z),
            (4.0, 3.0, 0.01)
        );
        let c = circle_loop(-10.0, 15.0, 2.0, 48, 0.0, 0.02, colors::SAFE);
        assert_eq!(c.line_type, LinePrimitive::LINE_LOOP);
        assert_eq!(c.points.len(), 48);
        for p in &c.points {
            let r = ((p.x - 15.0).powi(2) + (p.y + 10.0).powi(2)).sqrt();
            assert!((r - 2.0).abs() < 1e-12);
        }
    }

    #[test]
    fn frame_transforms_and_timestamps() {
        let tf = frame_transform("ship", 12.3456789015, -4.9, 7.0, 0.0);
        assert_eq!(tf.parent_frame_id, "world");
        assert_eq!(tf.child_frame_id, "ship");
        assert_eq!((tf.translation.x, tf.translation.y), (7.0, -4.9));
        assert_eq!(
            tf.timestamp,
            Timestamp {
                sec: 12,
                nsec: 345_678_902
            }
        );
        assert_eq!(timestamp(-1.0), Timestamp::default());
        let e = SceneEntity::new("hulls", 0.1);
        assert_eq!(e.frame_id, "world");
        assert_eq!(e.timestamp.nsec, 100_000_000);
        assert_eq!(e.lifetime, Duration::FOREVER);
    }
}

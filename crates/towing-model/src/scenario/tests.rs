use super::*;
use crate::towline::{attachment_point, towing_angle};
use crate::traffic::ObstacleKind;

const ORIGIN: &str = "scenarios/test.toml";

/// The smallest valid scenario; tests append or replace parts of it.
const MINIMAL: &str = r#"
format_version = 1
name = "minimal"

[ship]
x = 0.0
y = 0.0
psi_deg = 0.0

[tug1]
formation = { towing_angle_deg = 0.0 }

[tug2]
formation = { towing_angle_deg = 0.0 }

[towline1]
desired_length = 1.0

[towline2]
desired_length = 1.0

[route]
origin = { x = 0.0, y = 0.0, psi_deg = 0.0 }
waypoints = [{ x = 10.0, y = 0.0, psi_deg = 0.0 }]
destination = { x = 20.0, y = 0.0, psi_deg = 0.0 }
"#;

const TARGET: &str = r#"
[[obstacles]]
name = "T"
kind = "ship"
x = 5.0
y = 5.0
length = 1.48
width = 0.48
course_deg = 90.0
speed = 0.07
activation_time = 10.0
"#;

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_toml_str(text, ORIGIN)
}

/// Asserts the text is refused with this kind, field path and reason fragment,
/// and that the message names the file, the field and the reason.
#[track_caller]
fn refused(text: &str, kind: ScenarioErrorKind, path: &str, reason: &str) -> ScenarioError {
    let e = match parse(text) {
        Ok(_) => panic!("accepted, expected a refusal of {path}"),
        Err(e) => e,
    };
    let shown = e.to_string();
    assert_eq!(e.kind, kind, "{shown}");
    assert_eq!(e.path, path, "{shown}");
    assert!(
        e.reason.contains(reason),
        "reason {:?} lacks {reason:?}",
        e.reason
    );
    assert!(shown.starts_with(ORIGIN), "{shown}");
    assert!(shown.contains(path), "{shown}");
    assert!(shown.contains(reason), "{shown}");
    e
}

#[test]
fn minimal_scenario_parses_with_documented_defaults() {
    let s = parse(MINIMAL).unwrap();
    assert_eq!(s.name, "minimal");
    assert_eq!(s.description, "");
    assert_eq!(s.ship.nu, [0.0; 3]);
    assert_eq!(s.tugs[0].nu, [0.0; 3]);
    assert!(s.waterway.is_none());
    assert!(s.obstacles.is_empty());
    assert_eq!(s.ship_data, VesselData::cybership2());
    assert_eq!(s.tug_data, [VesselData::titoneri(); 2]);
    assert_eq!(s.world_config, WorldConfig::default());
    assert_eq!(s.elastic_towline, ElasticTowlineParams::default());
}

#[test]
fn paper_scenario_parses() {
    let s = Scenario::paper().unwrap();
    assert_eq!(s.name, "paper");
    assert_eq!(s.route.waypoints.len(), 8);
    // NOTES.md: path length through all points 63.45 m.
    assert!(
        (s.route.length() - 63.45).abs() < 0.005,
        "{}",
        s.route.length()
    );
    assert!((s.route.origin.psi - 101.3f64.to_radians()).abs() < 1e-12);
    assert!((s.route.destination.psi - std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(s.waterway, Some(Waterway { half_width: 5.0 }));
    assert_eq!(s.obstacles.len(), 6);
    let names: Vec<&str> = s.obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["a", "b", "c", "A", "B", "C"]);
    // A by time from t = 0; B and C by range only (scenarios/paper.toml).
    let triggers: Vec<(f64, Option<f64>)> = s
        .obstacles
        .iter()
        .filter_map(|o| match o.shape {
            ObstacleShape::Vessel {
                activation_time,
                activation_range,
                ..
            } => Some((activation_time, activation_range)),
            ObstacleShape::Circle { .. } => None,
        })
        .collect();
    assert_eq!(
        triggers,
        [
            (0.0, None),
            (f64::INFINITY, Some(14.2)),
            (f64::INFINITY, Some(19.8))
        ]
    );
    // Activated at 405 s (by range, in a world), B moves North from its spawn.
    let b = s.obstacles[4].output_activated(405.0 + 100.0, Some(405.0));
    assert_eq!(b.kind, ObstacleKind::VesselEllipse);
    assert!((b.x - (-22.0 + 7.0)).abs() < 1e-12 && (b.y - 40.75).abs() < 1e-12);
    // The ship at the route origin, at rest.
    assert_eq!(s.ship.eta[..2], [-4.9, 7.0]);
    assert!((s.ship.eta[2] - 101.3f64.to_radians()).abs() < 1e-12);
    assert_eq!(s.world_config, WorldConfig::default());
}

/// NOTES.md section 1: tug 2 at bow + (l_tow2 + l_T2)(cos, sin)(psi_S + alpha_2),
/// tug 1 at stern - (l_tow1 + l_T1)(cos, sin)(psi_S + alpha_1), heading psi_S + alpha.
#[test]
fn paper_tugs_sit_at_the_notes_geometry() {
    let s = Scenario::paper().unwrap();
    let psi = 101.3f64.to_radians();
    let (sn, cs) = psi.sin_cos();
    // By hand: CO (-4.9, 7), bow point 0.046 + 0.585 = 0.631 m ahead, stern point
    // 0.67 - 0.046 = 0.624 m behind; l_tow + l_T = 1.5 m.
    let bow = [-4.9 + 0.631 * cs, 7.0 + 0.631 * sn];
    let stern = [-4.9 - 0.624 * cs, 7.0 - 0.624 * sn];
    let tug2 = [bow[0] + 1.5 * cs, bow[1] + 1.5 * sn];
    let tug1 = [stern[0] - 1.5 * cs, stern[1] - 1.5 * sn];
    for (k, expected) in [tug1, tug2].iter().enumerate() {
        let eta = s.tugs[k].eta;
        assert!((eta[0] - expected[0]).abs() < 1e-12, "tug{} x", k + 1);
        assert!((eta[1] - expected[1]).abs() < 1e-12, "tug{} y", k + 1);
        assert!((eta[2] - psi).abs() < 1e-12, "tug{} psi", k + 1);
        assert_eq!(
            s.tug_placement[k],
            TugPlacement::Formation { towing_angle: 0.0 }
        );
    }
    // Lines at their desired length, towing angle 0.
    let p1 = attachment_point(&s.tugs[0].eta, 0.5);
    let p2 = attachment_point(&s.tugs[1].eta, -0.5);
    assert!(((p1[0] - stern[0]).hypot(p1[1] - stern[1]) - 1.0).abs() < 1e-12);
    assert!(((p2[0] - bow[0]).hypot(p2[1] - bow[1]) - 1.0).abs() < 1e-12);
    assert!(towing_angle(0, stern, p1, psi).abs() < 1e-12);
    assert!(towing_angle(1, bow, p2, psi).abs() < 1e-12);
}

#[test]
fn formation_angle_places_tugs_on_the_turned_line() {
    let text = MINIMAL
        .replacen("towing_angle_deg = 0.0", "towing_angle_deg = -20.0", 1)
        .replacen("towing_angle_deg = 0.0", "towing_angle_deg = 25.0", 1);
    let s = parse(&text).unwrap();
    let ship = VesselData::cybership2();
    let stern = attachment_point(&s.ship.eta, ship.stern_tow_point_x);
    let bow = attachment_point(&s.ship.eta, ship.bow_tow_point_x);
    let p1 = attachment_point(&s.tugs[0].eta, 0.5);
    let p2 = attachment_point(&s.tugs[1].eta, -0.5);
    assert!((towing_angle(0, stern, p1, 0.0) - (-20f64).to_radians()).abs() < 1e-12);
    assert!((towing_angle(1, bow, p2, 0.0) - 25f64.to_radians()).abs() < 1e-12);
    assert!((s.tugs[0].eta[2] - (-20f64).to_radians()).abs() < 1e-12);
    // alpha_1 < 0: the aft tug sits to starboard (East for a ship heading North).
    assert!(s.tugs[0].eta[1] > 0.0);
    // alpha_2 > 0: the forward tug sits to starboard too.
    assert!(s.tugs[1].eta[1] > 0.0);
}

#[test]
fn explicit_tug_pose_and_velocities_in_degrees() {
    let text = MINIMAL.replacen(
        "[tug1]\nformation = { towing_angle_deg = 0.0 }",
        "[tug1]\nx = -3.0\ny = 0.5\npsi_deg = 190.0\nu = 0.1\nv = -0.02\nr_deg_s = 3.0",
        1,
    );
    let s = parse(&text).unwrap();
    assert_eq!(s.tug_placement[0], TugPlacement::Explicit);
    assert_eq!(s.tugs[0].eta[..2], [-3.0, 0.5]);
    assert!(
        (s.tugs[0].eta[2] - (-170f64).to_radians()).abs() < 1e-12,
        "wrapped"
    );
    assert_eq!(s.tugs[0].nu[..2], [0.1, -0.02]);
    assert!((s.tugs[0].nu[2] - 3f64.to_radians()).abs() < 1e-15);
}

#[test]
fn overrides_apply_on_top_of_presets() {
    let text = format!(
        "{MINIMAL}{}",
        r#"
[simulation]
hull_model = "linear_damping"
towline_model = "elastic"
integration_step = 0.005
[simulation.elastic_towline]
stiffness = 250.0
winch_speed_max = 0.1

[vessels.ship]
width = 0.3
[vessels.ship.damping]
y_r = -0.725

[vessels.tug1]
damping_set = "B"
winch_max_tension = 4.0

[vessels.tug2]
damping_set = "B"
[vessels.tug2.damping]
n_r = -0.5
"#
    );
    let s = parse(&text).unwrap();
    assert_eq!(s.world_config.hull_model, HullModel::LinearDamping);
    assert_eq!(s.world_config.integration_step, 0.005);
    let expected = ElasticTowlineParams {
        stiffness: 250.0,
        winch_speed_max: 0.1,
        ..ElasticTowlineParams::default()
    };
    assert_eq!(s.elastic_towline, expected);
    assert_eq!(s.world_config.towline_model, TowlineModel::from(expected));
    assert_eq!(s.ship_data.width, 0.3);
    assert_eq!(s.ship_data.damping.y_r, -0.725);
    assert_eq!(s.ship_data.damping.n_r, Damping::cybership2().n_r);
    assert_eq!(s.tug_data[0].damping, Damping::titoneri_set_b());
    assert_eq!(s.tug_data[0].winch_max_tension, 4.0);
    assert_eq!(s.tug_data[1].damping.n_r, -0.5);
    assert_eq!(s.tug_data[1].damping.x_u, Damping::titoneri_set_b().x_u);
}

#[test]
fn from_file_reads_and_names_the_file() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios/paper.toml");
    let s = Scenario::from_file(path).unwrap();
    assert_eq!(
        s,
        Scenario {
            origin: path.to_owned(),
            ..Scenario::paper().unwrap()
        }
    );
    let missing = concat!(env!("CARGO_MANIFEST_DIR"), "/no/such/scenario.toml");
    let e = Scenario::from_file(missing).unwrap_err();
    assert_eq!(e.kind, ScenarioErrorKind::Io);
    assert!(e.to_string().contains(missing), "{e}");
}

/// The example of docs/scenario-format.md parses.
#[test]
fn documented_example_parses() {
    let doc = include_str!("../../../../docs/scenario-format.md");
    let start = doc.find("```toml\n").expect("a ```toml block") + "```toml\n".len();
    let end = start + doc[start..].find("```").expect("closed block");
    let s = parse(&doc[start..end]).unwrap();
    assert!(!s.obstacles.is_empty());
}

// ---- refusals: syntax ----

#[test]
fn refuses_toml_syntax_error_with_line_and_column() {
    let text = MINIMAL.replace(
        "desired_length = 1.0\n\n[towline2]",
        "desired_length = = 1.0\n\n[towline2]",
    );
    let e = parse(&text).unwrap_err();
    assert_eq!(e.kind, ScenarioErrorKind::Syntax);
    let line = MINIMAL.lines().position(|l| l == "[towline1]").unwrap() + 2;
    assert_eq!(e.location.map(|l| l.0), Some(line));
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("{ORIGIN}:{line}:")), "{shown}");
    assert!(shown.contains("TOML syntax error"), "{shown}");
}

#[test]
fn refuses_duplicate_key() {
    let text = MINIMAL.replace("name = \"minimal\"", "name = \"minimal\"\nname = \"again\"");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.kind, ScenarioErrorKind::Syntax);
    assert!(e.reason.contains("duplicate key"), "{e}");
    assert_eq!(e.location.map(|l| l.0), Some(4));
}

// ---- refusals: schema ----

#[test]
fn refuses_unknown_top_level_field() {
    let text = format!("{MINIMAL}\ncolour = \"red\"\n");
    // A key after [route] belongs to the route table.
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "route.colour",
        "unknown field `colour`",
    );
    let text = format!("colour = \"red\"\n{MINIMAL}");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "colour",
        "unknown field `colour`",
    );
}

#[test]
fn refuses_unknown_nested_fields() {
    let text = MINIMAL.replace(
        "towing_angle_deg = 0.0 }",
        "towing_angle_deg = 0.0, angle = 1 }",
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "tug1.formation.angle",
        "unknown field `angle`",
    );
    let text = format!("{MINIMAL}{TARGET}heading_deg = 3.0\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].heading_deg",
        "unknown field `heading_deg`",
    );
    let text = format!("{MINIMAL}[vessels.tug2.damping]\nx_v = 1.0\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "vessels.tug2.damping.x_v",
        "unknown field `x_v`",
    );
    let text = format!("{MINIMAL}[simulation.elastic_towline]\nspring = 1.0\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "simulation.elastic_towline.spring",
        "unknown field `spring`",
    );
}

#[test]
fn refuses_missing_required_fields() {
    let text = MINIMAL.replace("format_version = 1\n", "");
    let e = refused(
        &text,
        ScenarioErrorKind::Schema,
        "format_version",
        "missing field `format_version`",
    );
    assert!(e.location.is_some());
    let text = MINIMAL.replace("x = 0.0\ny = 0.0\npsi_deg = 0.0", "x = 0.0\npsi_deg = 0.0");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "ship.y",
        "missing field `y`",
    );
    let text = MINIMAL.replace("[towline2]\ndesired_length = 1.0", "[towline2]");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "towline2.desired_length",
        "missing field `desired_length`",
    );
    let text = MINIMAL.replace(
        "{ x = 10.0, y = 0.0, psi_deg = 0.0 }",
        "{ x = 10.0, y = 0.0 }",
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "route.waypoints[0].psi_deg",
        "missing field `psi_deg`",
    );
    let text = MINIMAL.replace("[tug2]\nformation = { towing_angle_deg = 0.0 }\n", "");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "tug2",
        "missing field `tug2`",
    );
    let text = format!("{MINIMAL}{}", TARGET.replace("speed = 0.07\n", ""));
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].speed",
        "missing field `speed`",
    );
    let text =
        format!("{MINIMAL}[[obstacles]]\nname = \"a\"\nkind = \"static\"\nx = 1.0\ny = 2.0\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].diameter",
        "missing field `diameter`",
    );
    let text =
        format!("{MINIMAL}[[obstacles]]\nkind = \"static\"\nx = 1.0\ny = 2.0\ndiameter = 1.0\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].name",
        "missing field `name`",
    );
}

#[test]
fn refuses_wrong_types() {
    let text = MINIMAL.replace(
        "desired_length = 1.0\n\n[towline2]",
        "desired_length = \"1 m\"\n\n[towline2]",
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "towline1.desired_length",
        "invalid type",
    );
    let text = MINIMAL.replace("format_version = 1", "format_version = 1.5");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "format_version",
        "invalid type",
    );
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("speed = 0.07", "speed = [0.07]")
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].speed",
        "invalid type",
    );
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("kind = \"ship\"", "kind = \"boat\"")
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].kind",
        "unknown variant `boat`",
    );
    let text = format!("{MINIMAL}[simulation]\nhull_model = \"cubic\"\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "simulation.hull_model",
        "unknown variant `cubic`",
    );
    let text = format!("{MINIMAL}[vessels.tug1]\ndamping_set = \"C\"\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "vessels.tug1.damping_set",
        "unknown variant `C`",
    );
    let text = MINIMAL.replace(
        "waypoints = [{ x = 10.0, y = 0.0, psi_deg = 0.0 }]",
        "waypoints = { x = 10.0 }",
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "route.waypoints",
        "invalid type",
    );
}

#[test]
fn refuses_inconsistent_tug_placement() {
    let text = MINIMAL.replacen(
        "formation = { towing_angle_deg = 0.0 }",
        "formation = { towing_angle_deg = 0.0 }\nx = 1.0",
        1,
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "tug1.x",
        "either `formation` or an explicit pose",
    );
    let text = MINIMAL.replacen(
        "[tug2]\nformation = { towing_angle_deg = 0.0 }",
        "[tug2]\nx = 3.0\ny = 0.0",
        1,
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "tug2.psi_deg",
        "explicit tug pose needs",
    );
}

#[test]
fn refuses_kind_specific_obstacle_fields() {
    let text = format!(
        "{MINIMAL}[[obstacles]]\nname = \"a\"\nkind = \"static\"\nx = 1.0\ny = 2.0\ndiameter = 1.0\nspeed = 0.1\n"
    );
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].speed",
        "not allowed for kind = \"static\"",
    );
    let text = format!("{MINIMAL}{TARGET}diameter = 1.0\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "obstacles[0].diameter",
        "not allowed for kind = \"ship\"",
    );
}

#[test]
fn refuses_damping_set_for_the_ship() {
    let text = format!("{MINIMAL}[vessels.ship]\ndamping_set = \"A\"\n");
    refused(
        &text,
        ScenarioErrorKind::Schema,
        "vessels.ship.damping_set",
        "only the tugs",
    );
}

// ---- refusals: values ----

#[test]
fn refuses_unsupported_format_version() {
    let text = MINIMAL.replace("format_version = 1", "format_version = 2");
    let e = refused(
        &text,
        ScenarioErrorKind::Invalid,
        "format_version",
        "unsupported format version 2",
    );
    assert_eq!(e.location.map(|l| l.0), Some(2));
}

#[test]
fn refuses_empty_name() {
    let text = MINIMAL.replace("name = \"minimal\"", "name = \"  \"");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "name",
        "must not be empty",
    );
}

#[test]
fn refuses_nan_and_inf_literals() {
    let text = MINIMAL.replacen(
        "x = 0.0\ny = 0.0\npsi_deg = 0.0",
        "x = nan\ny = 0.0\npsi_deg = 0.0",
        1,
    );
    let e = refused(
        &text,
        ScenarioErrorKind::Invalid,
        "ship.x",
        "must be finite",
    );
    assert_eq!(e.location.map(|l| l.0), Some(6), "points at the value");
    let text = MINIMAL.replacen(
        "x = 0.0\ny = 0.0\npsi_deg = 0.0",
        "x = 0.0\ny = 0.0\npsi_deg = inf",
        1,
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "ship.psi_deg",
        "must be finite",
    );
    let text = MINIMAL.replacen(
        "x = 0.0\ny = 0.0\npsi_deg = 0.0",
        "x = 0.0\ny = 0.0\npsi_deg = 0.0\nu = -inf",
        1,
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "ship.u",
        "must be finite",
    );
    let text = MINIMAL.replace(
        "towing_angle_deg = 0.0 }\n\n[tug2]",
        "towing_angle_deg = nan }\n\n[tug2]",
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "tug1.formation.towing_angle_deg",
        "must be finite",
    );
    let text = MINIMAL.replace("destination = { x = 20.0", "destination = { x = +inf");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "route.destination.x",
        "must be finite",
    );
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("course_deg = 90.0", "course_deg = nan")
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].course_deg",
        "must be finite",
    );
    let text = format!("{MINIMAL}[vessels.tug1.damping]\nx_u = nan\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.tug1.damping.x_u",
        "must be finite",
    );
    let text = format!("{MINIMAL}[simulation.elastic_towline]\ndamping = inf\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "simulation.elastic_towline.damping",
        "must be finite",
    );
}

#[test]
fn refuses_non_positive_sizes_and_lengths() {
    let text = MINIMAL.replace(
        "desired_length = 1.0\n\n[route]",
        "desired_length = 0.0\n\n[route]",
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "towline2.desired_length",
        "must be > 0 m",
    );
    let text = format!("{MINIMAL}[[obstacles]]\nname = \"a\"\nkind = \"static\"\nx = 1.0\ny = 2.0\ndiameter = 0.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].diameter",
        "must be > 0 m",
    );
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("length = 1.48", "length = -1.48")
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].length",
        "must be > 0 m",
    );
    let text = format!("{MINIMAL}{}", TARGET.replace("width = 0.48", "width = 2.0"));
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].width",
        "must not exceed length",
    );
    let text = format!("{MINIMAL}[waterway]\nhalf_width = 0.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "waterway.half_width",
        "must be > 0 m",
    );
}

/// Lengths, coordinates and speeds beyond any physical size are refused by name: the
/// geometry derived from them overflows (`desired_length = 1.7976931348623157e308` gave a
/// towline of infinite length with fmi2OK).
#[test]
fn refuses_lengths_coordinates_and_speeds_beyond_any_physical_size() {
    let why = "must be at most 1e8 m in magnitude (MAX_DISTANCE";
    let text = MINIMAL.replace(
        "desired_length = 1.0\n\n[route]",
        "desired_length = 1.7976931348623157e308\n\n[route]",
    );
    let e = refused(
        &text,
        ScenarioErrorKind::Invalid,
        "towline2.desired_length",
        why,
    );
    assert!(
        e.reason.ends_with("got 1.7976931348623157e308 m"),
        "{}",
        e.reason
    );
    let text = MINIMAL.replacen("x = 0.0\ny = 0.0", "x = 0.0\ny = -2e8", 1);
    refused(&text, ScenarioErrorKind::Invalid, "ship.y", why);
    let text = MINIMAL.replace("destination = { x = 20.0", "destination = { x = 1e300");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "route.destination.x",
        why,
    );
    let text = format!("{MINIMAL}{}", TARGET.replace("x = 5.0", "x = 1e9"));
    refused(&text, ScenarioErrorKind::Invalid, "obstacles[0].x", why);
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("length = 1.48", "length = 1e9")
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].length",
        why,
    );
    let text = format!("{MINIMAL}[waterway]\nhalf_width = 1e300\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "waterway.half_width",
        why,
    );
    let text = format!("{MINIMAL}[vessels.ship]\nlength = 1e9\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.ship.length",
        why,
    );
    let speed = "must be at most 1e3 m/s in magnitude (MAX_SPEED";
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("speed = 0.07", "speed = 1e300")
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].speed",
        speed,
    );
    let text = MINIMAL.replacen(
        "x = 0.0\ny = 0.0\npsi_deg = 0.0",
        "x = 0.0\ny = 0.0\npsi_deg = 0.0\nu = 2e3",
        1,
    );
    refused(&text, ScenarioErrorKind::Invalid, "ship.u", speed);
    // At the limits: accepted.
    let text = MINIMAL
        .replace(
            "desired_length = 1.0\n\n[route]",
            "desired_length = 1e3\n\n[route]",
        )
        .replace("destination = { x = 20.0", "destination = { x = 1e8");
    parse(&text).unwrap();
}

#[test]
fn refuses_non_physical_vessel_data() {
    let text = format!("{MINIMAL}[vessels.ship]\nmass = 0.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.ship.mass",
        "must be > 0 kg",
    );
    let text = format!("{MINIMAL}[vessels.tug2]\nlength = -0.97\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.tug2.length",
        "must be > 0 m",
    );
    let text = format!("{MINIMAL}[vessels.tug1]\ny_vdot = 100.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.tug1",
        "not positive definite",
    );
    let text = format!("{MINIMAL}[vessels.tug1]\nmax_yaw_moment = -1.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.tug1.max_yaw_moment",
        "must be >= 0 N m",
    );
    let text = format!("{MINIMAL}[vessels.ship]\nstern_tow_point_x = 0.7\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "vessels.ship.stern_tow_point_x",
        "must lie aft of",
    );
}

#[test]
fn refuses_negative_speed_and_activation_time() {
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("speed = 0.07", "speed = -0.07")
    );
    let e = refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].speed",
        "must be >= 0 m/s",
    );
    let line = format!("{MINIMAL}{TARGET}")
        .lines()
        .position(|l| l == "speed = 0.07")
        .unwrap()
        + 1;
    assert_eq!(e.location.map(|l| l.0), Some(line));
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("activation_time = 10.0", "activation_time = -1.0")
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[0].activation_time",
        "must be >= 0 s",
    );
}

/// The triggers of the one target of `MINIMAL` + `TARGET` after editing its
/// `activation_time = 10.0` line into `lines`.
fn triggers_with(lines: &str) -> Result<(f64, Option<f64>), ScenarioError> {
    let text = format!(
        "{MINIMAL}{}",
        TARGET.replace("activation_time = 10.0\n", lines)
    );
    let s = parse(&text)?;
    Ok((
        s.obstacles[0].activation_time().unwrap(),
        s.obstacles[0].activation_range(),
    ))
}

#[test]
fn activation_by_time_range_or_both() {
    // Time only (as before), range only (never by time), both, neither (t = 0).
    assert_eq!(
        triggers_with("activation_time = 10.0\n").unwrap(),
        (10.0, None)
    );
    assert_eq!(
        triggers_with("activation_range = 12.5\n").unwrap(),
        (f64::INFINITY, Some(12.5))
    );
    assert_eq!(
        triggers_with("activation_time = 30.0\nactivation_range = 12\n").unwrap(),
        (30.0, Some(12.0))
    );
    assert_eq!(triggers_with("").unwrap(), (0.0, None));
}

#[test]
fn refuses_bad_activation_ranges_and_times() {
    let text = |lines: &str| {
        format!(
            "{MINIMAL}{}",
            TARGET.replace("activation_time = 10.0\n", lines)
        )
    };
    for (lines, path, reason) in [
        (
            "activation_range = 0.0\n",
            "obstacles[0].activation_range",
            "must be > 0 m",
        ),
        (
            "activation_range = -3.0\n",
            "obstacles[0].activation_range",
            "must be > 0 m",
        ),
        (
            "activation_range = nan\n",
            "obstacles[0].activation_range",
            "must be finite",
        ),
        (
            "activation_range = inf\n",
            "obstacles[0].activation_range",
            "must be finite",
        ),
        (
            "activation_time = 5.0\nactivation_range = -1.0\n",
            "obstacles[0].activation_range",
            "must be > 0 m",
        ),
        (
            "activation_time = inf\nactivation_range = 4.0\n",
            "obstacles[0].activation_time",
            "must be finite",
        ),
        (
            "activation_time = nan\nactivation_range = 4.0\n",
            "obstacles[0].activation_time",
            "must be finite",
        ),
        (
            "activation_time = -1.0\nactivation_range = 4.0\n",
            "obstacles[0].activation_time",
            "must be >= 0 s",
        ),
    ] {
        let e = refused(&text(lines), ScenarioErrorKind::Invalid, path, reason);
        // Located at the offending value's line.
        let line = text(lines)
            .lines()
            .position(|l| l.starts_with(path.rsplit('.').next().unwrap()))
            .unwrap()
            + 1;
        assert_eq!(e.location.map(|l| l.0), Some(line), "{lines}: {e}");
    }
    // Wrong type, and not allowed on a static obstacle.
    refused(
        &text("activation_range = \"near\"\n"),
        ScenarioErrorKind::Schema,
        "obstacles[0].activation_range",
        "invalid type",
    );
    refused(
        &format!(
            "{MINIMAL}[[obstacles]]\nname = \"a\"\nkind = \"static\"\nx = 1.0\ny = 2.0\n\
             diameter = 1.0\nactivation_range = 3.0\n"
        ),
        ScenarioErrorKind::Schema,
        "obstacles[0].activation_range",
        "not allowed for kind = \"static\"",
    );
}

#[test]
fn refuses_more_than_eight_obstacles() {
    let mut text = MINIMAL.to_owned();
    for i in 0..9 {
        text.push_str(&format!(
            "[[obstacles]]\nname = \"o{i}\"\nkind = \"static\"\nx = {i}.0\ny = 5.0\ndiameter = 1.0\n"
        ));
    }
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles",
        "9 obstacles given, at most 8",
    );
    // Eight are fine.
    let eight: String = text
        .split("[[obstacles]]")
        .take(9)
        .collect::<Vec<_>>()
        .join("[[obstacles]]");
    assert_eq!(parse(&eight).unwrap().obstacles.len(), 8);
}

#[test]
fn refuses_duplicate_obstacle_names() {
    let text = format!("{MINIMAL}{TARGET}{TARGET}");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "obstacles[1].name",
        "duplicate name \"T\"",
    );
}

#[test]
fn refuses_route_without_waypoints_or_with_repeated_points() {
    let text = MINIMAL.replace(
        "waypoints = [{ x = 10.0, y = 0.0, psi_deg = 0.0 }]",
        "waypoints = []",
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "route.waypoints",
        "at least one waypoint",
    );
    let text = MINIMAL.replace(
        "waypoints = [{ x = 10.0, y = 0.0, psi_deg = 0.0 }]",
        "waypoints = [{ x = 0.0, y = 0.0, psi_deg = 0.0 }]",
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "route.waypoints[0]",
        "coincides with the previous",
    );
    let text = MINIMAL.replace("destination = { x = 20.0", "destination = { x = 10.0");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "route.destination",
        "coincides with the previous",
    );
}

#[test]
fn refuses_formation_angle_at_or_beyond_90_degrees() {
    let text = MINIMAL.replace(
        "towing_angle_deg = 0.0 }\n\n[tug2]",
        "towing_angle_deg = -90.0 }\n\n[tug2]",
    );
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "tug1.formation.towing_angle_deg",
        "strictly between -90 and 90 deg",
    );
}

#[test]
fn refuses_bad_simulation_settings() {
    let text = format!("{MINIMAL}[simulation]\nintegration_step = 0.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "simulation.integration_step",
        "must be > 0 s",
    );
    let text = format!("{MINIMAL}[simulation]\nintegration_step = 0.5\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "simulation.integration_step",
        "must be at most 0.1 s",
    );
    let text = format!("{MINIMAL}[simulation]\ntowline_model = \"elastic\"\n[simulation.elastic_towline]\nstiffness = -100.0\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "simulation.elastic_towline.stiffness",
        "must be > 0 N/m",
    );
    let text = format!("{MINIMAL}[simulation.elastic_towline]\nwinch_speed_max = -0.2\n");
    refused(
        &text,
        ScenarioErrorKind::Invalid,
        "simulation.elastic_towline.winch_speed_max",
        "must be >= 0 m/s",
    );
}

#[test]
fn columns_count_characters() {
    let text = MINIMAL.replace(
        "name = \"minimal\"",
        "name = \"m\u{e9}\u{e9}\"\n\"z\u{e9}ro\" = 1",
    );
    let e = refused(
        &text,
        ScenarioErrorKind::Schema,
        "z\u{e9}ro",
        "unknown field",
    );
    assert_eq!(e.location, Some((4, 1)));
    assert_eq!(line_column("a\u{e9}b", 3), (1, 3));
    assert_eq!(line_column("a\u{e9}b", 2), (1, 2), "inside a character");
}

#[test]
fn never_panics_on_garbage() {
    for text in [
        "",
        "[",
        "a = ",
        "\u{0}",
        "format_version = 1\n[[ship]]\n",
        "[route]\nwaypoints = [1, 2]",
    ] {
        assert!(parse(text).is_err(), "{text:?}");
    }
}

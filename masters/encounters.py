"""Encounter scenarios for the tow: the built-in suites, a seeded random generator, and the
kinematic check that every target ship is on a collision course with the non-reacting tow.

Usage (from the repository root, with the project's .venv):

    .venv/bin/python masters/encounters.py imazu --out scenarios/suites/imazu
    .venv/bin/python masters/encounters.py extra --out scenarios/suites/extra
    .venv/bin/python masters/encounters.py random --seed 7 --count 20 --out /tmp/random [--hazards 0.3]
    .venv/bin/python masters/encounters.py check scenarios/suites/imazu/*.toml

`imazu` and `extra` write the committed suites (scenarios/suites/README.md) together with
their `expected.toml`; `random` writes `random-<seed>-<i:04d>.toml`; `check` prints each
target's closest approach to the non-reacting tow and exits with status 1 when any target
does not come within 1 m of the ship's centre (or never appears), 2 on a usage error.

## The non-reacting tow (the kinematic check)

The tow that does not react: the ship's centre (its body origin CO) moves along the route
polyline, origin -> waypoints -> destination, at the nominal cruise speed `CRUISE_SPEED`
from t = 0 until it reaches the destination (the check's horizon, route length / speed).
The tugs sit on the route (continued straight beyond its ends) at their formation distances
for towing angle 0 (Du et al. 2022, eq. (4)-(6); crates/towing-model `formation_pose`): the
forward tug's CO `bow_tow_point_x(ship) + l_tow2 - stern_tow_point_x(tug2)` = 0.631 + 1 +
0.5 = 2.131 m ahead of the ship's CO, the aft tug's `-stern_tow_point_x(ship) + l_tow1 +
bow_tow_point_x(tug1)` = 0.624 + 1 + 0.5 = 2.124 m behind (vessel data and line lengths read
from the scenario). Target ships move as docs/scenario-format.md says: straight at their
speed from their activation time, activated by time or by range, the range checked on the
kinematic ship's centre at t = 0 and at the end of every 0.1 s communication step (`STEP`,
the closed-loop master's default). Sampled every step, the check reports per target its
closest approach (centre distance) to the ship and to any of the three vessels, and when;
and the clearance of its spawn position from the three vessels when it appears.

## Nominal cruise speed

`CRUISE_SPEED` = 0.102 m/s, measured once (2026-12-01) on a straight 45 m route (North,
waypoint at 22.5 m, half width 5 m, no obstacles, distributed architecture, scheme I):

    cargo xtask fmu
    .venv/bin/python masters/closed_loop.py --scenario /tmp/straight45.toml \\
        --stop-time 1000 --out /tmp/cruise --quiet

The median speed over ground of the ship in out/timeseries.csv over the rows where it is
at least 0.02 m/s (under way) is 0.1020 m/s (0.1019 at 0.01 m/s, 0.1020 at 0.05 m/s); the
ship passes 10 m at 102.9 s, 40 m at 396.9 s (0.102 m/s between them) and stops at the
destination. A controller or scenario that makes the tow slower or faster meets the
range-activated targets where the kinematic tow does, only later or earlier.

## How a target is aimed

A target is given its collision point, where the kinematic ship's centre is at arc length
`s_c` along the route (time t_c = s_c / CRUISE_SPEED), its course and speed, a lead time
(how long before t_c it appears) and a miss (offset of its aim point across the route, to
starboard positive). Its spawn position is the aim point less speed x lead along its course;
so its closest approach to the ship's centre is at most |miss| by construction, and the
check confirms it from the written file. A target whose lead time reaches back to t = 0 is
present from the start (`activation_time = 0`). Otherwise it appears by RANGE when the
ship's distance to its spawn position falls monotonically up to the activation time and
the spawn position bears within 60 deg of the route's direction then (the distance falls
at least at half the ship's speed, so a tow off the route or late meets the target at the
same geometry); by TIME otherwise (a target near the beam: the range would be crossed
almost tangentially, and a tow a few cm farther off would never trigger it).

## The random generator (`random_scenarios`)

`random.Random(seed)`, one generator for the whole batch, files drawn in order (so the
first files of a longer batch equal a shorter batch's), only `random()` and `uniform()`
(stable across Python versions for int seeds); every number is written with a fixed
precision, so a file is byte-identical for the same (seed, count, options). Per file:

- route: length U(40, 50) m; straight with probability 1/2, otherwise one turn at
  U(35, 65) % of the length, of U(30, 90) deg to starboard or port (1/2 each); first leg's
  course U(-180, 180) deg; origin (0, 0); each leg split into equal segments of at most
  7.5 m (the paper's route has 5.9-8.2 m segments; d_1 <= 7.5 m keeps theta_max =
  arctan(d_2 / d_1) >= 28 deg above the 15 deg altering angle for d_2 >= 4 m);
- waterway half width U(4, 6) m;
- 1, 2 or 3 target ships (1/3 each), named A, B, C; each target independently:
  collision point U(25, 75) % of the route length; side starboard or port (1/2 each);
  relative course (target course less the route's course at the collision point)
  magnitude U(15, 180) deg, negative from starboard, positive from port (a target from
  starboard heads to the tow's port side); speed U(0.05, 0.15) m/s; lead time U(60, 160) s
  (present at t = 0 when that reaches back before t = 0); miss U(-0.3, 0.3) m. A draw
  whose spawn position is within 2 m of any vessel of the kinematic tow at activation is
  drawn again (at most 200 times);
- option `hazards` (probability, default 0): with that probability one static hazard of
  diameter 1 m, beside a target's collision point (which target U{A..}, arc offset
  U(-3, 3) m, U(2.5, 3.5) m beside the route, starboard or port 1/2 each), drawn again
  while it is nearer than 2.5 m to the route polyline (a turn's other leg).

Every target is classified at its activation (`classify`, COLREGS Rules 13-15: overtaking
when coming up more than 22.5 deg abaft the other's beam, head-on within 15 deg of ahead on
a reciprocal course within 15 deg, crossing otherwise) and the file header says the
situation, the tow's role and the expected action.
"""

import argparse
import dataclasses
import math
import pathlib
import random
import sys
import tomllib

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import tow_geometry  # noqa: E402

CRUISE_SPEED = 0.102  # m/s, measured (module docstring)
STEP = 0.1  # s, communication step at whose ends range activation is checked
TARGET_LENGTH, TARGET_WIDTH = 1.48, 0.48  # m, the paper's target ships (Table 5)
HAZARD_DIAMETER = 1.0  # m, the paper's static hazards
SEGMENT_MAX = 7.5  # m, longest route segment
CPA_LIMIT = 1.0  # m, a target must come closer than this to the ship's centre
SPAWN_CLEARANCE = 2.0  # m, least distance of a spawn position from every vessel centre
RANGE_BEARING_MAX = 60.0  # deg, widest bearing off the route for range activation
RANDOM_OPTIONS = {"hazards": 0.0}
SUITE_HEADER = "Generated by `python masters/encounters.py {cmd} --out scenarios/suites/{cmd}`: do not edit by hand."


# --------------------------------------------------------------------------- route and tow


def wrap_deg(a):
    """Angle in degrees wrapped to (-180, 180]."""
    a = math.fmod(a, 360.0)
    if a <= -180.0:
        a += 360.0
    elif a > 180.0:
        a -= 360.0
    return a


class Route:
    """The route polyline (x North, y East, m) with its arc length; `at` extends it straight
    beyond both ends (where the tugs of a tow at either end sit)."""

    def __init__(self, points):
        self.points = np.asarray(points, dtype=float)
        seg = np.diff(self.points, axis=0)
        self.lengths = np.hypot(seg[:, 0], seg[:, 1])
        self.cum = np.concatenate([[0.0], np.cumsum(self.lengths)])
        self.courses = np.arctan2(seg[:, 1], seg[:, 0])
        self.length = float(self.cum[-1])

    def at(self, s):
        """Positions (n, 2) and courses (n,) (rad) at arc lengths s (n,)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        i = np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.lengths) - 1)
        c = self.courses[i]
        ds = s - self.cum[i]
        return self.points[i] + ds[:, None] * np.stack([np.cos(c), np.sin(c)], axis=1), c

    def point(self, s):
        """(x, y, course) at one arc length s."""
        p, c = self.at([s])
        return float(p[0, 0]), float(p[0, 1]), float(c[0])

    def distance_to(self, x, y):
        """Distance of point (x, y) from the polyline (its segments, not the extensions)."""
        best = math.inf
        for a, b in zip(self.points[:-1], self.points[1:]):
            d = b - a
            u = min(1.0, max(0.0, float(np.dot([x, y] - a, d) / np.dot(d, d))))
            best = min(best, math.hypot(x - a[0] - u * d[0], y - a[1] - u * d[1]))
        return best


def polyline(origin, legs):
    """Route points from `origin` (x, y) and legs [(course_deg, length_m)], each leg split into
    equal segments of at most SEGMENT_MAX."""
    pts = [tuple(origin)]
    for course, length in legs:
        n = max(1, math.ceil(length / SEGMENT_MAX - 1e-9))
        x0, y0 = pts[-1]
        c = math.radians(course)
        pts += [(x0 + length * k / n * math.cos(c), y0 + length * k / n * math.sin(c)) for k in range(1, n + 1)]
    return pts


def tow_offsets(scenario):
    """(forward, aft) distances (m) of the tugs' COs from the ship's CO along the route, for
    formation towing angle 0 (Du et al. 2022, eq. (4)-(6); towing-model `formation_pose`)."""
    dims = tow_geometry.vessel_dims(scenario)
    l1 = scenario["towline1"]["desired_length"]
    l2 = scenario["towline2"]["desired_length"]
    forward = dims["ship"]["bow_tow_point_x"] + l2 - dims["tug2"]["stern_tow_point_x"]
    aft = -dims["ship"]["stern_tow_point_x"] + l1 + dims["tug1"]["bow_tow_point_x"]
    return forward, aft


def tow_tracks(route, times, speed, offsets):
    """{vessel: (T, 2) positions} and the ship's courses (T,) of the non-reacting tow."""
    s = np.minimum(np.asarray(times) * speed, route.length)
    ship, course = route.at(s)
    return {"ship": ship, "tug2": route.at(s + offsets[0])[0], "tug1": route.at(s - offsets[1])[0]}, course


# --------------------------------------------------------------------------- COLREGS situation


@dataclasses.dataclass(frozen=True)
class Situation:
    """A target's situation for the tow, the tow's role and the expected action."""

    situation: str  # "head-on", "crossing give-way", "crossing stand-on", "overtaking", "being overtaken"
    role: str  # "give-way" or "stand-on"
    action: str  # "give way to starboard", "take the way off" or "stand on"
    rule: str


def classify(bearing_deg, relative_course_deg, speed, own_speed=CRUISE_SPEED):
    """COLREGS situation of a target at relative bearing `bearing_deg` (from the tow's course,
    starboard positive) with course `relative_course_deg` relative to the tow's and `speed`.

    Overtaking (Rule 13(b)): coming up with another vessel from more than 22.5 deg abaft her
    beam, and faster. Head-on (Rule 14): nearly ahead (within 15 deg) on a nearly reciprocal
    course (within 15 deg). Otherwise crossing (Rule 15): give way to a target on the
    starboard side (Rule 16), stand on for one on the port side (Rule 17)."""
    b = wrap_deg(bearing_deg)
    r = wrap_deg(relative_course_deg)
    own_from_target = wrap_deg(b + 180.0 - r)  # the tow's bearing from the target's heading
    if abs(b) <= 15.0 and abs(wrap_deg(r - 180.0)) <= 15.0:
        return Situation("head-on", "give-way", "give way to starboard", "Rule 14")
    if abs(own_from_target) > 112.5 and speed < own_speed:
        return Situation("overtaking", "give-way", "give way to starboard", "Rule 13")
    if abs(b) > 112.5 and speed > own_speed:
        return Situation("being overtaken", "stand-on", "stand on", "Rules 13, 17")
    if b >= 0.0:
        return Situation("crossing give-way", "give-way", "give way to starboard", "Rules 15, 16")
    return Situation("crossing stand-on", "stand-on", "stand on", "Rules 15, 17")


# --------------------------------------------------------------------------- the kinematic check


@dataclasses.dataclass
class TargetCheck:
    """One target against the non-reacting tow."""

    name: str
    activation: str  # "time" or "range"
    t_active: float | None  # s, None: never appears within the run
    s_active: float  # m along the route of the ship at activation
    clearance: float  # m, spawn position to the nearest vessel centre at activation
    bearing_deg: float  # at activation, from the route's course, starboard positive
    relative_course_deg: float
    speed: float
    cpa_ship: float = math.inf  # m
    t_cpa_ship: float = math.nan  # s
    cpa_tow: float = math.inf  # m, to the nearest of the three vessels
    t_cpa_tow: float = math.nan  # s, the first time within 1 cm of cpa_tow
    vessel_cpa_tow: str = ""

    @property
    def ok(self):
        """Within CPA_LIMIT of the ship's centre."""
        return self.t_active is not None and self.cpa_ship < CPA_LIMIT

    @property
    def situation(self):
        """COLREGS situation at activation (`classify`)."""
        return classify(self.bearing_deg, self.relative_course_deg, self.speed)


def _activation(ob, ship, times):
    """(how, t_a) of a target ship per docs/scenario-format.md; t_a None when never."""
    t_time = ob.get("activation_time")
    r = ob.get("activation_range")
    found = []
    if t_time is not None:
        found.append((float(t_time), "time"))
    if r is not None:
        hit = np.flatnonzero(np.hypot(ship[:, 0] - ob["x"], ship[:, 1] - ob["y"]) <= r)
        if hit.size:
            found.append((float(times[hit[0]]), "range"))
    if t_time is None and r is None:
        found.append((0.0, "time"))
    if not found:
        return "range", None
    t, how = min(found)
    return how, t


def check_scenario(scenario, speed=CRUISE_SPEED):
    """TargetCheck per target ship of a scenario (dict as tomllib reads it), in file order."""
    pts = tow_geometry.route_points(scenario)
    route = Route(pts[:, :2])
    offsets = tow_offsets(scenario)
    horizon = route.length / speed
    times = np.arange(int(math.floor(horizon / STEP + 1e-9)) + 1) * STEP
    tracks, course = tow_tracks(route, times, speed, offsets)
    found = []
    for ob in scenario.get("obstacles", []):
        if ob["kind"] != "ship":
            continue
        how, t_a = _activation(ob, tracks["ship"], times)
        c = math.radians(ob["course_deg"])
        k = 0 if t_a is None else min(int(round(t_a / STEP)), len(times) - 1)
        spawn = np.array([ob["x"], ob["y"]])
        rel = spawn - tracks["ship"][k]
        chk = TargetCheck(
            name=ob["name"],
            activation=how,
            t_active=t_a,
            s_active=float(min(times[k] * speed, route.length)),
            clearance=min(float(np.hypot(*(spawn - tracks[v][k]))) for v in tow_geometry.VESSELS),
            bearing_deg=wrap_deg(math.degrees(math.atan2(rel[1], rel[0]) - course[k])),
            relative_course_deg=wrap_deg(math.degrees(c - course[k])),
            speed=float(ob["speed"]),
        )
        if t_a is not None:
            after = times >= t_a - 1e-9
            tt = times[after]
            pos = spawn + ob["speed"] * (tt - t_a)[:, None] * np.array([math.cos(c), math.sin(c)])
            dist = {v: np.hypot(*(pos - tracks[v][after]).T) for v in tow_geometry.VESSELS}
            i = int(np.argmin(dist["ship"]))
            chk.cpa_ship, chk.t_cpa_ship = float(dist["ship"][i]), float(tt[i])
            tow = np.stack([dist[v] for v in tow_geometry.VESSELS])  # (3, T)
            nearest = tow.min(axis=0)
            # The smallest distance; when and to which vessel: the first time within 1 cm of
            # it (a target on the route passes every vessel at nearly the same distance).
            j = int(np.flatnonzero(nearest <= nearest.min() + 0.01)[0])
            v = int(np.argmin(tow[:, j]))
            chk.cpa_tow, chk.t_cpa_tow, chk.vessel_cpa_tow = float(nearest.min()), float(tt[j]), tow_geometry.VESSELS[v]
        found.append(chk)
    return found


def check_report(c):
    """Two lines per target: activation and clearance; closest approaches and situation."""
    if c.t_active is None:
        return [f"{c.name} never appears within the run (its activation_range is not reached)", ""]
    return [
        f"{c.name} appears by {c.activation} at {c.t_active:.1f} s (the ship {c.s_active:.1f} m along the route), "
        f"{c.clearance:.2f} m from the nearest vessel;",
        f"closest approach {c.cpa_ship:.3f} m to the ship's centre at {c.t_cpa_ship:.1f} s, {c.cpa_tow:.3f} m to the "
        f"tow ({c.vessel_cpa_tow}) at {c.t_cpa_tow:.1f} s; {c.situation.situation}, the tow {c.situation.role}",
    ]


# --------------------------------------------------------------------------- scenario specs and writer


@dataclasses.dataclass
class TargetSpec:
    """A target ship to write, with the reasoning lines of its header comment."""

    name: str
    x: float
    y: float
    course_deg: float
    speed: float
    activation_time: float | None
    activation_range: float | None
    notes: list
    action: str | None = None  # overrides the classified action, with a reason in `notes`


@dataclasses.dataclass
class HazardSpec:
    """A static hazard (circle) to write."""

    name: str
    x: float
    y: float
    notes: list
    diameter: float = HAZARD_DIAMETER


@dataclasses.dataclass
class ScenarioSpec:
    """A whole scenario: route points, waterway, targets, hazards and the header's text."""

    name: str
    description: str
    points: list
    half_width: float
    header: list
    targets: list = dataclasses.field(default_factory=list)
    hazards: list = dataclasses.field(default_factory=list)


def num(v, digits=3):
    """Fixed-precision float literal (never "-0.000")."""
    s = f"{v:.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0.0 else s


def _pose(x, y, psi):
    return f"{{ x = {num(x)}, y = {num(y)}, psi_deg = {num(psi)} }}"


def aim(route, name, s_c, course_deg, speed, lead, miss=0.0, notes=(), action=None):
    """TargetSpec of a target on a collision course with the non-reacting tow (module
    docstring, "How a target is aimed"): at the kinematic ship's centre at arc length s_c
    (plus `miss` m to starboard across the route) at t_c = s_c / CRUISE_SPEED, appearing
    `lead` s before (on the STEP grid; present at t = 0 when t_c - lead <= 0)."""
    t_c = s_c / CRUISE_SPEED
    t_a = max(0.0, round((t_c - lead) / STEP) * STEP)
    px, py, c = route.point(s_c)
    ax, ay = px - miss * math.sin(c), py + miss * math.cos(c)
    k = math.radians(course_deg)
    # Rounded as written, so the range below is computed from the position in the file.
    x = round(ax - speed * (t_c - t_a) * math.cos(k), 3)
    y = round(ay - speed * (t_c - t_a) * math.sin(k), 3)
    spec = TargetSpec(name, x, y, wrap_deg(course_deg), speed, None, None, list(notes), action)
    if t_a == 0.0:
        spec.activation_time = 0.0
        return spec
    times = np.arange(int(round(t_a / STEP)) + 1) * STEP
    tracks, course = tow_tracks(route, times, CRUISE_SPEED, (0.0, 0.0))
    d = np.hypot(tracks["ship"][:, 0] - x, tracks["ship"][:, 1] - y)
    rel = math.degrees(math.atan2(y - tracks["ship"][-1, 1], x - tracks["ship"][-1, 0]) - course[-1])
    if np.all(np.diff(d) < 0.0) and abs(wrap_deg(rel)) <= RANGE_BEARING_MAX:
        # Rounded up to the written precision: the distance falls by more than 1 mm per step
        # (at least half the ship's 10 mm), so the range is first reached at t_a itself.
        spec.activation_range = math.ceil(float(d[-1]) * 1000.0) / 1000.0
    else:
        spec.activation_time = t_a
    return spec


def write_scenario(spec, path, speed=CRUISE_SPEED):
    """Writes `spec` as TOML to `path`, its header with the kinematic check's figures; returns
    the checks (TargetCheck per target)."""
    body = _body(spec)
    checks = check_scenario(tomllib.loads(body), speed)
    header = [*spec.header, "", "Targets (each on a collision course with the non-reacting tow: closer than"]
    header.append(f"{CPA_LIMIT:g} m to the ship's centre by the kinematic check of masters/encounters.py):")
    header += [f"  {c.name}: {c.situation.situation}, the tow {c.situation.role}" for c in checks]
    lines = [f"# {h}" if h else "#" for h in header]
    text = "\n".join(lines) + "\n\n" + body
    by_name = {c.name: c for c in checks}
    for t in spec.targets:
        c = by_name[t.name]
        s = c.situation
        block = [f"# Target {t.name}:"] + [f"#   {n}" for n in t.notes]
        block.append(f"#   Expected: {s.situation} ({s.rule}), the tow {s.role}: {t.action or s.action}.")
        first, second = check_report(c)
        block += [f"#   Kinematic check: {first}", f"#   {second}."]
        text = text.replace(f"[[obstacles]]\nname = \"{t.name}\"\n", "\n".join(block) + f"\n[[obstacles]]\nname = \"{t.name}\"\n", 1)
    for h in spec.hazards:
        block = [f"# Hazard {h.name}:"] + [f"#   {n}" for n in h.notes]
        text = text.replace(f"[[obstacles]]\nname = \"{h.name}\"\n", "\n".join(block) + f"\n[[obstacles]]\nname = \"{h.name}\"\n", 1)
    path.write_text(text)
    return checks


def _body(spec):
    """The TOML text of a scenario (without its header)."""
    pts = spec.points
    courses = [math.degrees(math.atan2(b[1] - a[1], b[0] - a[0])) for a, b in zip(pts[:-1], pts[1:])]
    poses = [_pose(x, y, courses[min(i, len(courses) - 1)]) for i, (x, y) in enumerate(pts)]
    out = [
        "format_version = 1",
        f'name = "{spec.name}"',
        f'description = """\n{spec.description}\n"""',
        "",
        "# The ship starts at rest at the route origin, both tugs in formation (towing angle 0),",
        "# desired towline lengths 1 m (as scenarios/paper.toml).",
        "[ship]",
        f"x = {num(pts[0][0])}",
        f"y = {num(pts[0][1])}",
        f"psi_deg = {num(courses[0])}",
        "",
        "[tug1]",
        "formation = { towing_angle_deg = 0.0 }",
        "",
        "[tug2]",
        "formation = { towing_angle_deg = 0.0 }",
        "",
        "[towline1]",
        "desired_length = 1.0",
        "",
        "[towline2]",
        "desired_length = 1.0",
        "",
        "[route]",
        f"origin = {poses[0]}",
        "waypoints = [",
        *[f"    {p}," for p in poses[1:-1]],
        "]",
        f"destination = {poses[-1]}",
        "",
        "[waterway]",
        f"half_width = {num(spec.half_width, 2)}",
    ]
    for h in spec.hazards:
        out += ["", "[[obstacles]]", f'name = "{h.name}"', 'kind = "static"']
        out += [f"x = {num(h.x)}", f"y = {num(h.y)}", f"diameter = {num(h.diameter, 2)}"]
    for t in spec.targets:
        out += [
            "",
            "[[obstacles]]",
            f'name = "{t.name}"',
            'kind = "ship"',
            f"x = {num(t.x)}",
            f"y = {num(t.y)}",
            f"length = {num(TARGET_LENGTH, 2)}",
            f"width = {num(TARGET_WIDTH, 2)}",
            f"course_deg = {num(t.course_deg)}",
            f"speed = {num(t.speed, 4)}",
        ]
        if t.activation_time is not None:
            out.append(f"activation_time = {num(t.activation_time, 1)}")
        if t.activation_range is not None:
            out.append(f"activation_range = {num(t.activation_range)}")
    return "\n".join(out) + "\n"


def expected_entries(filename, spec, checks):
    """Lines of expected.toml for one scenario file."""
    by_name = {c.name: c for c in checks}
    lines = []
    for t in spec.targets:
        s = by_name[t.name].situation
        lines += [
            f'["{filename}".{t.name}]',
            f'situation = "{s.situation}"',
            f'role = "{s.role}"',
            f'action = "{t.action or s.action}"',
            "",
        ]
    return lines


def write_suite(specs, out_dir, intro):
    """Writes each spec as <name>.toml and expected.toml into out_dir; returns the paths."""
    out_dir.mkdir(parents=True, exist_ok=True)
    expected = [f"# {line}" for line in intro] + [""]
    paths = []
    for spec in specs:
        path = out_dir / f"{spec.name}.toml"
        checks = write_scenario(spec, path)
        expected += expected_entries(path.name, spec, checks)
        paths.append(path)
    (out_dir / "expected.toml").write_text("\n".join(expected).rstrip("\n") + "\n")
    return paths


# --------------------------------------------------------------------------- the Imazu suite

# Imazu's 22 problems as Sawada, Sato & Majima (2021), Table 4, give them: per target
# (X, Y, course) with X (NM) along the own ship's course, Y (NM) to its starboard, course
# (deg) from the own ship's, clockwise; the own ship at (-6, 0) heading 0 at 12 kn, every
# target on a straight collision course with it at the origin after 30 min.
IMAZU = {
    1: [(6.000, 0.000, 180.0)],
    2: [(0.000, 6.000, -90.0)],
    3: [(-4.200, 0.000, 0.0)],
    4: [(-4.243, -4.243, 45.0)],
    5: [(6.000, 0.000, 180.0), (0.000, 6.000, -90.0)],
    6: [(-5.909, 1.042, -10.0), (-4.243, 4.243, -45.0)],
    7: [(-4.200, 0.000, 0.0), (-4.243, 4.243, -45.0)],
    8: [(6.000, 0.000, 180.0), (0.000, 6.000, -90.0)],
    9: [(-5.196, 3.000, -30.0), (0.000, 6.000, -90.0)],
    10: [(0.000, 6.000, -90.0), (-5.796, -1.553, 15.0)],
    11: [(0.000, -6.000, 90.0), (-5.196, 3.000, -30.0)],
    12: [(-4.243, 4.243, -45.0), (-5.909, 1.042, -10.0)],
    13: [(6.000, 0.000, 180.0), (-5.909, -1.042, 10.0), (-4.243, -4.243, 45.0)],
    14: [(-5.909, 1.042, -10.0), (-4.243, 4.243, -45.0), (0.000, 6.000, -90.0)],
    15: [(-4.200, 0.000, 0.0), (-4.243, 4.243, -45.0), (0.000, 6.000, -90.0)],
    16: [(-2.970, -2.970, 45.0), (0.000, -6.000, 90.0), (0.000, 6.000, -90.0)],
    17: [(-4.200, 0.000, 0.0), (-5.909, -1.042, 10.0), (-4.243, 4.243, -45.0)],
    18: [(4.243, 4.243, -135.0), (-5.796, 1.553, -15.0), (-5.196, 3.000, -30.0)],
    19: [(-5.796, -1.553, 15.0), (-5.796, 1.553, -15.0), (4.243, 4.243, -135.0)],
    20: [(-4.200, 0.000, 0.0), (-5.796, 1.553, -15.0), (0.000, 6.000, -90.0)],
    21: [(-5.796, 1.553, -15.0), (-5.796, -1.553, 15.0), (0.000, 6.000, -90.0)],
    22: [(-4.200, 0.000, 0.0), (-4.243, 4.243, -45.0), (0.000, 6.000, -90.0)],
}
IMAZU_LENGTH = 45.0  # m, route (North)
IMAZU_COLLISION = 25.0  # m along the route
IMAZU_LEAD = 160.0  # s from appearance to collision
IMAZU_HALF_WIDTH = 5.0  # m
NM = CRUISE_SPEED * IMAZU_LEAD / 6.0  # m per Imazu nautical mile: 6 NM = the tow's lead distance


def imazu_specs():
    """ScenarioSpec of each of Imazu's 22 problems, scaled (module docstring; README)."""
    route_pts = polyline((0.0, 0.0), [(0.0, IMAZU_LENGTH)])
    route = Route(route_pts)
    specs = []
    for case, targets in IMAZU.items():
        specs.append(
            ScenarioSpec(
                name=f"imazu-{case:02d}",
                description=f"Imazu (1987) problem {case} (Sawada et al. 2021, Table 4), scaled to model size: "
                f"{len(targets)} target ship(s) meeting the tow {IMAZU_COLLISION:g} m along a {IMAZU_LENGTH:g} m route.",
                points=route_pts,
                half_width=IMAZU_HALF_WIDTH,
                header=_imazu_header(case, len(targets)),
                targets=[_imazu_target(route, "ABC"[i], *t) for i, t in enumerate(targets)],
            )
        )
    return specs


def _imazu_target(route, name, x_nm, y_nm, course):
    distance = math.hypot(x_nm, y_nm)  # NM from the collision point: 6 (12 kn) or 4.2 (8.4 kn)
    knots = 12.0 * distance / 6.0
    speed = CRUISE_SPEED * knots / 12.0
    notes = [
        f"Imazu: (X ahead, Y to starboard) = ({x_nm:.3f}, {y_nm:.3f}) NM from the collision point,",
        f"course {course:+.0f} deg from the own ship's, {knots:.1f} kn; here {speed:.4f} m/s, {distance * NM:.2f} m away.",
    ]
    return aim(route, name, IMAZU_COLLISION, course, speed, IMAZU_LEAD, notes=notes)


def _imazu_header(case, n):
    return [
        f"Imazu problem {case} (H. Imazu 1987, the 22 standard encounter problems), {n} target ship(s).",
        "Geometry from Sawada, Sato & Majima (2021), J. Mar. Sci. Technol. 26, 509-524, Table 4",
        "(scenarios/suites/imazu/README.md says how it was sourced).",
        "",
        "Scaled to model size: in Imazu's problems the own ship is 6 NM (30 min at 12 kn) from the",
        "collision point and every target as far from it as its own speed takes it in those 30",
        "min (12 kn; 8.4 kn for a ship the own ship overtakes), all on straight collision courses.",
        f"Here the tow's centre cruises at {CRUISE_SPEED} m/s (the measured nominal speed) North along a",
        f"straight {IMAZU_LENGTH:g} m route (waypoints every 7.5 m, waterway half width {IMAZU_HALF_WIDTH:g} m) and meets",
        f"every target {IMAZU_COLLISION:g} m along it, {IMAZU_LEAD:g} s after they appear: 6 NM -> {6 * NM:.2f} m",
        f"(1 NM -> {NM:.2f} m), 12 kn -> {CRUISE_SPEED} m/s, 8.4 kn -> {0.7 * CRUISE_SPEED:.4f} m/s; targets 1.48 x 0.48 m.",
        "A target appears when the ship's centre comes within its activation_range of its spawn",
        "position (where the kinematic tow is 160 s before the collision), or, for a target near",
        "the beam, at the kinematic tow's time (activation_time): module docstring of",
        "masters/encounters.py, \"How a target is aimed\".",
        SUITE_HEADER.format(cmd="imazu"),
    ]


# --------------------------------------------------------------------------- the extra suite

EXTRA_HEADER = [
    "Scaled as the Imazu suite (scenarios/suites/README.md): the tow's centre cruises at",
    f"{CRUISE_SPEED} m/s (the measured nominal speed) from the origin of the route, waypoints every",
    "7.5 m at most; targets 1.48 x 0.48 m; a target appears by range (the ship's centre within",
    "activation_range of its spawn position), by time near the beam, or is present at t = 0",
    '(module docstring of masters/encounters.py, "How a target is aimed").',
    SUITE_HEADER.format(cmd="extra"),
]


def _beside(route, s, offset, name, notes):
    """A static hazard `offset` m to starboard (negative: port) of the route at arc length s."""
    x, y, c = route.point(s)
    return HazardSpec(name, round(x - offset * math.sin(c), 3), round(y + offset * math.cos(c), 3), notes)


def _extra(name, what, legs, half_width, make):
    """ScenarioSpec of an extra encounter: route legs [(course, length)], `make(route)` giving
    (targets, hazards)."""
    pts = polyline((0.0, 0.0), legs)
    route = Route(pts)
    targets, hazards = make(route)
    desc = f"Extra encounter {name}: {' '.join(what)}"
    return ScenarioSpec(name, desc, pts, half_width, [f"Extra encounter {name}:", *what, "", *EXTRA_HEADER], targets, hazards)


def _parallel(abeam, speed, relative=-15.0):
    """(collision arc length, note) of a target present at t = 0 `abeam` m to starboard on a
    course `relative` deg from the route's, closing the route at speed * sin(-relative)."""
    t_c = abeam / (speed * math.sin(math.radians(-relative)))
    return CRUISE_SPEED * t_c, f"closes the track at {speed * math.sin(math.radians(-relative)):.4f} m/s: meets the ship at {t_c:.0f} s"


def extra_specs():
    """ScenarioSpec of each extra encounter (scenarios/suites/extra/README.md)."""
    north = [(0.0, 45.0)]
    all_time = 1e9  # a lead longer than any run: the target is present at t = 0
    way_off = "take the way off"
    specs = [
        _extra("extra-01-overtaken", ["being overtaken by a fast target (0.15 m/s) from dead astern, present at t = 0",
               "(it reaches the aft tug about 45 s before the ship)."], north, 5.0, lambda r: ([
            aim(r, "A", 20.4, 0.0, 0.15, all_time, notes=["Same course as the tow, 0.15 m/s, starts 9.6 m behind the ship's start."])], [])),
        _extra("extra-02-hazard-starboard", ["head-on target with a static hazard 3 m to starboard of the route just past",
               "the collision point: the starboard alteration has 3 m of room before the hazard."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, 180.0, 0.10, 120.0, notes=["Reciprocal course, 0.10 m/s."])],
            [_beside(r, 27.0, 3.0, "rock", ["Diameter 1 m, 3 m to starboard of the route, 2 m past the collision point."])])),
        _extra("extra-03-hazard-port", ["crossing from starboard with a static hazard 3 m to port of the route near",
               "the collision point (a port alteration would run towards it)."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, -90.0, 0.10, 120.0, notes=["Crossing at right angles from starboard, 0.10 m/s."])],
            [_beside(r, 26.0, -3.0, "rock", ["Diameter 1 m, 3 m to port of the route, 1 m past the collision point."])])),
        _extra("extra-04-hazards-both", ["crossing from the starboard bow with static hazards 3 m beside the route on",
               "either side of the collision point."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, -135.0, 0.10, 120.0, notes=["Relative course -135 deg (from the starboard bow), 0.10 m/s."])],
            [_beside(r, 24.0, 3.0, "rock-starboard", ["Diameter 1 m, 3 m to starboard, 1 m before the collision point."]),
             _beside(r, 27.0, -3.0, "rock-port", ["Diameter 1 m, 3 m to port, 2 m past the collision point."])])),
    ]
    for abeam in (4.0, 6.0):
        s_c, note = _parallel(abeam, 0.10)
        specs.append(_extra(f"extra-{len(specs) + 1:02d}-parallel-{abeam:.0f}m", [
            f"near-parallel crossing from starboard, present at t = 0 {abeam:.0f} m abeam, relative course",
            "-15 deg, slowly converging."], north, 5.0, lambda r, s_c=s_c, note=note: ([
                aim(r, "A", s_c, -15.0, 0.10, all_time, action=way_off, notes=[
                    f"0.10 m/s on the route's course -15 deg, {abeam:.0f} m to starboard at t = 0; {note}.",
                    "Close to the beam, a starboard turn heads for it: taking the way off lets it cross ahead."])], [])))
    specs += [
        _extra("extra-07-narrow-head-on", ["head-on in a narrow waterway (half width 3 m)."], north, 3.0, lambda r: ([
            aim(r, "A", 25.0, 180.0, 0.10, 120.0, notes=["Reciprocal course, 0.10 m/s."])], [])),
        _extra("extra-08-narrow-crossing", ["crossing from starboard in a narrow waterway (half width 3 m)."], north, 3.0, lambda r: ([
            aim(r, "A", 25.0, -60.0, 0.08, 120.0, action=way_off, notes=[
                "Relative course -60 deg, 0.08 m/s; with 3 m to the bank the room to starboard is small,",
                "so taking the way off is the expected action."])], [])),
        _extra("extra-09-turn-90", ["a 90 deg starboard turn halfway (North 22.5 m, then East 22.5 m): a target",
               "crossing from port before the turn and a head-on target after it."], [(0.0, 22.5), (90.0, 22.5)], 5.0, lambda r: ([
            aim(r, "A", 12.0, 90.0, 0.08, 120.0, notes=["Crossing at right angles from port on the first leg, 0.08 m/s."]),
            aim(r, "B", 33.0, -90.0, 0.10, 60.0, notes=[
                "Reciprocal to the second leg (West), 0.10 m/s, appears once the tow is 4.4 m into the second leg."])], [])),
        _extra("extra-10-slow-crossing-port", ["a slow target (0.05 m/s) crossing from port."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, 90.0, 0.05, 160.0, notes=["Crossing at right angles from port, 0.05 m/s."])], [])),
        _extra("extra-11-fast-crossing-starboard", ["a fast target (0.15 m/s) crossing from starboard."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, -110.0, 0.15, 100.0, notes=["Relative course -110 deg (slightly from ahead), 0.15 m/s."])], [])),
        _extra("extra-12-slow-overtaking", ["overtaking a slow target (0.05 m/s) on the route ahead."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, 0.0, 0.05, 120.0, notes=["Same course as the tow, 0.05 m/s, 6.2 m ahead of the ship when it appears."])], [])),
        _extra("extra-13-fast-head-on", ["a fast target (0.15 m/s) head-on."], north, 5.0, lambda r: ([
            aim(r, "A", 25.0, 180.0, 0.15, 100.0, notes=["Reciprocal course, 0.15 m/s."])], [])),
    ]
    return specs


# --------------------------------------------------------------------------- the random generator

RANDOM_ATTEMPTS = 200


def _random_route(rng):
    """(points, legs note) of a random route (module docstring, "The random generator")."""
    length = rng.uniform(40.0, 50.0)
    course = rng.uniform(-180.0, 180.0)
    if rng.random() < 0.5:
        return polyline((0.0, 0.0), [(course, length)]), f"straight, {length:.2f} m, course {course:.1f} deg"
    first = length * rng.uniform(0.35, 0.65)
    turn = rng.uniform(30.0, 90.0) * (1.0 if rng.random() < 0.5 else -1.0)
    side = "starboard" if turn > 0 else "port"
    legs = [(course, first), (course + turn, length - first)]
    note = f"{length:.2f} m, course {course:.1f} deg, one turn of {abs(turn):.1f} deg to {side} after {first:.2f} m"
    return polyline((0.0, 0.0), legs), note


def _random_target(rng, route, name):
    """A target drawn until its spawn position keeps SPAWN_CLEARANCE from the kinematic tow."""
    offsets = tow_offsets({"towline1": {"desired_length": 1.0}, "towline2": {"desired_length": 1.0}})
    for _ in range(RANDOM_ATTEMPTS):
        fraction = rng.uniform(0.25, 0.75)
        starboard = rng.random() < 0.5
        relative = rng.uniform(15.0, 180.0) * (-1.0 if starboard else 1.0)
        speed = rng.uniform(0.05, 0.15)
        lead = rng.uniform(60.0, 160.0)
        miss = rng.uniform(-0.3, 0.3)
        s_c = fraction * route.length
        course = math.degrees(route.point(s_c)[2]) + relative
        notes = [
            f"Drawn: collision point {100 * fraction:.1f} % along the route, from {'starboard' if starboard else 'port'}, "
            f"relative course {relative:.1f} deg,",
            f"{speed:.4f} m/s, appearing {lead:.1f} s before the collision (at t = 0 if that is earlier), miss {miss:+.3f} m.",
        ]
        spec = aim(route, name, s_c, course, speed, lead, miss=miss, notes=notes)
        t_a = spec.activation_time if spec.activation_time is not None else (s_c / CRUISE_SPEED - lead)
        tracks, _ = tow_tracks(route, [max(0.0, round(t_a / STEP) * STEP)], CRUISE_SPEED, offsets)
        if min(math.hypot(spec.x - p[0, 0], spec.y - p[0, 1]) for p in tracks.values()) >= SPAWN_CLEARANCE:
            return spec, s_c
    raise RuntimeError(f"target {name}: no spawn position {SPAWN_CLEARANCE} m clear of the tow in {RANDOM_ATTEMPTS} draws")


def _random_hazard(rng, route, collision_points):
    """A static hazard beside one of the collision points, off the route polyline by >= 2.5 m."""
    for _ in range(RANDOM_ATTEMPTS):
        k = min(int(rng.random() * len(collision_points)), len(collision_points) - 1)
        s = collision_points[k] + rng.uniform(-3.0, 3.0)
        offset = rng.uniform(2.5, 3.5) * (1.0 if rng.random() < 0.5 else -1.0)
        h = _beside(route, s, offset, "hazard", [])
        if route.distance_to(h.x, h.y) >= 2.5 - 1e-3:
            side = "starboard" if offset > 0 else "port"
            near = f"near target {'ABC'[k]}'s collision point"
            h.notes = [f"Diameter 1 m, {abs(offset):.2f} m to {side} of the route at {s:.2f} m along ({near})."]
            return h
    raise RuntimeError(f"no hazard 2.5 m clear of the route in {RANDOM_ATTEMPTS} draws")


def _random_spec(rng, seed, i, hazards):
    pts, route_note = _random_route(rng)
    route = Route(pts)
    half_width = rng.uniform(4.0, 6.0)
    n = min(int(rng.random() * 3), 2) + 1
    targets, collision_points = [], []
    for name in "ABC"[:n]:
        spec, s_c = _random_target(rng, route, name)
        targets.append(spec)
        collision_points.append(s_c)
    found = [_random_hazard(rng, route, collision_points)] if rng.random() < hazards else []
    name = f"random-{seed}-{i:04d}"
    header = [
        f"Random encounter {i} of seed {seed} (masters/encounters.py `random_scenarios`, hazards = {hazards:g}):",
        f"{n} target ship(s){' and a static hazard' if found else ''}, route {route_note}, waterway half width {half_width:.2f} m.",
        "The distributions are in scenarios/suites/README.md and the module docstring; the same seed,",
        "count and options give this file byte for byte.",
    ]
    return ScenarioSpec(name, f"Random encounter {i} of seed {seed}.", pts, half_width, header, targets, found)


def random_scenarios(out_dir: pathlib.Path, seed: int, count: int, **options) -> list[pathlib.Path]:
    """Writes `count` random encounter scenarios into out_dir, named random-<seed>-<i:04d>.toml,
    byte-identical for the same (seed, count, options); returns their paths in order.
    Unknown option keys raise ValueError naming the key.

    Options: `hazards`, the probability (0..1, default 0) of one static hazard per file.
    Every target is checked (`check_scenario`) to come within CPA_LIMIT of the ship's centre
    and to appear at least SPAWN_CLEARANCE from every vessel; a file that fails raises
    RuntimeError (it cannot by construction)."""
    unknown = sorted(set(options) - set(RANDOM_OPTIONS))
    if unknown:
        raise ValueError(f"random_scenarios: unknown option {unknown[0]!r} (known: {', '.join(sorted(RANDOM_OPTIONS))})")
    opts = {**RANDOM_OPTIONS, **options}
    hazards = opts["hazards"]
    if isinstance(hazards, bool) or not isinstance(hazards, (int, float)) or not 0.0 <= hazards <= 1.0:
        raise ValueError(f"random_scenarios: option 'hazards' must be a probability in [0, 1], got {hazards!r}")
    if isinstance(count, bool) or not isinstance(count, int) or count < 0:
        raise ValueError(f"random_scenarios: count must be a non-negative integer, got {count!r}")
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise ValueError(f"random_scenarios: seed must be an integer, got {seed!r}")
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rng = random.Random(seed)
    paths = []
    for i in range(count):
        spec = _random_spec(rng, seed, i, float(hazards))
        path = out_dir / f"{spec.name}.toml"
        checks = write_scenario(spec, path)
        bad = [c for c in checks if not c.ok or c.clearance < SPAWN_CLEARANCE]
        if bad:
            raise RuntimeError(f"{path}: target {bad[0].name} fails the kinematic check: {' '.join(check_report(bad[0]))}")
        paths.append(path)
    return paths


# --------------------------------------------------------------------------- command line

IMAZU_INTRO = [
    "Expected situation, role of the tow and action per target of the Imazu suite (Imazu 1987;",
    "Sawada et al. 2021, Table 4), as classified by masters/encounters.py `classify` at each",
    "target's appearance (COLREGS Rules 13-17). Keys: file name, then target name.",
    SUITE_HEADER.format(cmd="imazu"),
]
EXTRA_INTRO = [
    "Expected situation, role of the tow and action per target of the extra suite, as classified",
    "by masters/encounters.py `classify` at each target's appearance (COLREGS Rules 13-17); the",
    "action is overridden where the file's header says why. Keys: file name, then target name.",
    SUITE_HEADER.format(cmd="extra"),
]


def _check_files(paths):
    """Prints the kinematic check of each file; returns 0 when every target passes, else 1."""
    status = 0
    for path in paths:
        try:
            scenario = tow_geometry.load_scenario(path)
            checks = check_scenario(scenario)
        except (OSError, tomllib.TOMLDecodeError, KeyError, TypeError, ValueError) as e:
            print(f"{path}: cannot be checked: {type(e).__name__}: {e}")
            status = 1
            continue
        for c in checks:
            verdict = "ok" if c.ok else f"FAIL (not within {CPA_LIMIT:g} m of the ship's centre)"
            print(f"{path}: {' '.join(check_report(c))}: {verdict}")
            status = status if c.ok else 1
        if not checks:
            print(f"{path}: no target ships")
    return status


def main(argv=None):
    parser = argparse.ArgumentParser(description="Encounter suites, random encounters and their kinematic check.")
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("imazu", "extra"):
        p = sub.add_parser(name, help=f"write the {name} suite")
        p.add_argument("--out", type=pathlib.Path, required=True)
    p = sub.add_parser("random", help="write seeded random encounters")
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--count", type=int, required=True)
    p.add_argument("--out", type=pathlib.Path, required=True)
    p.add_argument("--hazards", type=float, default=RANDOM_OPTIONS["hazards"], help="probability of a static hazard")
    p = sub.add_parser("check", help="kinematic check: each target's closest approach to the non-reacting tow")
    p.add_argument("files", nargs="+", type=pathlib.Path)
    args = parser.parse_args(argv)
    if args.command == "check":
        return _check_files(args.files)
    if args.command == "imazu":
        paths = write_suite(imazu_specs(), args.out, IMAZU_INTRO)
    elif args.command == "extra":
        paths = write_suite(extra_specs(), args.out, EXTRA_INTRO)
    else:
        try:
            paths = random_scenarios(args.out, args.seed, args.count, hazards=args.hazards)
        except ValueError as e:
            parser.error(str(e))
    print(f"wrote {len(paths)} scenario(s) to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

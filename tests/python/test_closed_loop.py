"""The closed-loop master (masters/closed_loop.py): TowingController + TowingPlant under fmpy.

- Connection discovery and the hull-overlap geometry, without FMUs.
- The master with the real plant and a stand-in controller (a Python object behind fmpy's
  FMU2Slave interface): CSV layout, warnings counted, map and summary, while the
  controller FMU is not needed.
- A short run (60 s) of the paper scenario with both FMUs.
- Model mismatch (marker `closed_loop_long`): the controller predicting with the linear
  hull model (paper's eq. (1), `mpc.hull_model` = 1) against the plant's nonlinear hull, 1500 s
  of the paper scenario: no hull overlap, commands within their bounds, settles
  (docs/swap-plant.md).
- The acceptance runs (marker `closed_loop_long`): 1200 s of the paper scenario for the
  distributed and the centralized architecture and avoidance schemes I, II and III, judged
  by the paper's criteria (../shared/paper/NOTES.md): settling at the destination, no hull
  overlaps, commands within their bounds and rate bounds, no fallbacks, and COLREGS sides
  (schemes I and II). Deselect them with `-m "not closed_loop_long"`; their outputs stay in
  out/acceptance/<case>/ for inspection.
"""

import json
import math
import re
import subprocess
import sys
from types import SimpleNamespace

import matplotlib.image
import numpy as np
import pytest

import closed_loop
import tow_geometry
from conftest import ROOT

MASTER = ROOT / "masters" / "closed_loop.py"
SHIP_LENGTH = 1.255
TENSION_MAX, TENSION_RATE = 3.0, 0.3  # N, N per 1 s sample (Du et al. 2022, Table 2 and 3)
ANGLE_MAX, ANGLE_RATE = math.radians(30.0), math.radians(5.0)  # rad, rad per sample
THRUST_MAX = 10.0  # N, N, N m
SAMPLE_TIME = 1.0  # s (Table 3)
EPS = 1e-9  # bounds: the controller clamps its outputs, so only rounding is allowed
RATE_TOL = 1e-6  # rate bounds: rows of QP constraints, met to the solver's 1e-6 tolerance


# --------------------------------------------------------------------------- helpers


def read_csv(path):
    with open(path) as f:
        header = f.readline().rstrip("\n").split(",")
    values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    assert values.shape[1] == len(header)
    return header, {name: values[:, i] for i, name in enumerate(header)}


def run_master(out, *args, timeout=3600):
    return subprocess.run(
        [sys.executable, str(MASTER), *map(str, args), "--out", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def expected_columns(plant_fmu, controller_fmu):
    import fmpy

    cols = ["time"]
    for fmu in (plant_fmu, controller_fmu):
        cols += [v.name for v in fmpy.read_model_description(fmu).modelVariables if v.causality == "output"]
    return cols


def assert_map(path, size):
    img = matplotlib.image.imread(str(path))
    assert img.shape[:2] == (size[1], size[0]), img.shape
    rgb = img[..., :3]
    # Not blank: many distinct colours and a visible spread around the background.
    assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 50
    assert float(rgb.std()) > 0.02


def assert_commands_within_bounds(d):
    for i in (1, 2):
        f = d[f"towline{i}.tension_cmd"]
        assert np.all((f >= -EPS) & (f <= TENSION_MAX + EPS)), (f.min(), f.max())
        for s in ("force_surge", "force_sway", "moment_yaw"):
            x = d[f"tug{i}.{s}"]
            assert np.all(np.abs(x) <= THRUST_MAX + EPS), (f"tug{i}.{s}", np.abs(x).max())


def sample_lag(d):
    h = d["time"][1] - d["time"][0]
    lag = int(round(SAMPLE_TIME / h))
    assert abs(lag * h - SAMPLE_TIME) < 1e-9, "the rate checks need a step dividing the sample time"
    return lag


def worst_rate(x, lag, wrap=False):
    """Largest change of x between rows one sample apart (each such pair of rows spans exactly
    one controller sample, since samples fall on multiples of T_s and rows on multiples of h)."""
    dx = x[lag:] - x[:-lag]
    if wrap:
        dx = tow_geometry.wrap_angle(dx)
    return float(np.abs(dx).max()) if dx.size else 0.0


def settling_time(d, scenario, hold=10.0):
    """First time after which the ship stays settled at the destination to the end of the run
    (paper/NOTES.md: within half its length of the destination, within 3 deg of the
    destination heading, |u|, |v| < 0.01 m/s, |r| < 0.01 rad/s). None unless it has stayed
    so for at least `hold` seconds before the end (a single settled last row proves nothing)."""
    dest = scenario["route"]["destination"]
    ok = (
        (np.hypot(d["ship.x"] - dest["x"], d["ship.y"] - dest["y"]) <= SHIP_LENGTH / 2)
        & (np.abs(tow_geometry.wrap_angle(d["ship.psi"] - math.radians(dest["psi_deg"]))) <= math.radians(3.0))
        & (np.abs(d["ship.u"]) < 0.01)
        & (np.abs(d["ship.v"]) < 0.01)
        & (np.abs(d["ship.r"]) < 0.01)
    )
    if not ok[-1]:
        return None
    bad = np.flatnonzero(~ok)
    first = 0 if bad.size == 0 else bad[-1] + 1
    t = d["time"]
    return round(float(t[first]), 6) if t[-1] - t[first] >= hold else None


def encounters(d, scenario, window=10.0):
    """Per target ship (obstacle slot with kind 2): CPA time and distance, the target's relative
    bearing from the ship at CPA (deg, NED, psi clockwise; negative = port side) and whether the
    guidance altered the route during the encounter (rows where the target is active and within
    `window` m of the ship, up to the CPA)."""
    found = []
    for k in tow_geometry.obstacle_slots(d):
        active = np.flatnonzero(d[f"obstacle[{k}].kind"] == 2)
        if active.size == 0:
            continue
        dx = d[f"obstacle[{k}].x"][active] - d["ship.x"][active]
        dy = d[f"obstacle[{k}].y"][active] - d["ship.y"][active]
        dist = np.hypot(dx, dy)
        i = int(np.argmin(dist))
        cpa = active[i]
        bearing = math.degrees(float(tow_geometry.wrap_angle(math.atan2(dy[i], dx[i]) - d["ship.psi"][cpa])))
        near = active[: i + 1][dist[: i + 1] <= window]
        altered = bool(np.any(d["guidance.altered"][near] != 0)) if "guidance.altered" in d and near.size else False
        name = closed_loop._obstacle_name(scenario, k)
        found.append(
            {
                "slot": k,
                "name": name,
                "cpa_time": float(d["time"][cpa]),
                "cpa_distance": float(dist[i]),
                "relative_bearing_deg": bearing,
                "side": "port" if -180.0 < bearing < 0.0 else "starboard",
                "altered": altered,
            }
        )
    return found


# --------------------------------------------------------------------------- without FMUs


def var(name, causality, type_="Real", vr=0, start=None):
    return SimpleNamespace(name=name, causality=causality, type=type_, valueReference=vr, start=start, variability="continuous")


def test_connections_are_discovered_by_name_and_causality():
    plant = [var("ship.x", "output"), var("obstacle[1].kind", "output", "Integer"), var("towline1.slack", "output", "Boolean"),
             var("tug1.force_surge", "input"), var("scenario", "parameter", "String")]
    ctrl = [var("ship.x", "input"), var("obstacle[1].kind", "input", "Integer"), var("tug1.force_surge", "output"),
            var("admm.iterations", "output", "Integer"), var("scenario", "parameter", "String")]
    conn = closed_loop.discover_connections(plant, ctrl)
    assert conn["to_controller"] == [("ship.x", "Real"), ("obstacle[1].kind", "Integer")]
    assert conn["to_plant"] == [("tug1.force_surge", "Real")]


def test_a_controller_input_without_plant_output_is_refused_by_name():
    plant = [var("ship.x", "output"), var("tug1.force_surge", "input")]
    ctrl = [var("ship.x", "input"), var("ship.gyro", "input"), var("tug1.force_surge", "output")]
    with pytest.raises(closed_loop.UsageError, match=r"controller input 'ship.gyro' has no plant output"):
        closed_loop.discover_connections(plant, ctrl)
    ctrl = [var("ship.x", "input", "Integer"), var("tug1.force_surge", "output")]
    with pytest.raises(closed_loop.UsageError, match=r"'ship.x' is Integer but the plant output of that name is Real"):
        closed_loop.discover_connections(plant, ctrl)


def test_hull_overlap_geometry():
    dims = tow_geometry.vessel_dims({})
    assert dims["ship"]["centre"] == pytest.approx(0.0035)
    zero = np.zeros(3)
    # Rectangles 1 x 0.3 along North: overlapping, separated along, separated across.
    a = tow_geometry.rectangle(zero, zero, zero, 1.0, 0.3)
    b = tow_geometry.rectangle([0.9, 1.1, 0.0], [0.0, 0.0, 0.31], zero, 1.0, 0.3)
    assert list(tow_geometry.polygons_overlap(a, b)) == [True, False, False]
    # A rotated square's corner reaching into a rectangle's side.
    c = tow_geometry.rectangle([0.0], [0.15 + 0.2 * math.sqrt(2) - 0.01], [math.pi / 4], 0.4, 0.4)
    assert tow_geometry.polygons_overlap(a[:1], c)[0]
    # Circles: gap to the side, to the end, inside.
    gap = tow_geometry.rectangle_circle_gap(a, [0.0, 1.0, 0.0], [0.5, 0.0, 0.0], [0.2, 0.2, 0.2])
    assert gap == pytest.approx([0.15, 0.3, -0.35])
    # Target ship ellipse 1.48 x 0.48: just clear across its beam, overlapping along its length.
    r = tow_geometry.rectangle([0.0, 0.0], [0.0, 0.0], [math.pi / 2] * 2, 1.0, 0.3)
    e = tow_geometry.ellipse([0.0, 0.0], [0.5 + 0.24 + 0.005, 0.5 + 0.74 - 0.01], [0.0, math.pi / 2], 1.48, 0.48)
    assert list(tow_geometry.polygons_overlap(r, e)) == [False, True]
    # The hull_overlaps report on a whole run: the tug driven onto hazard slot 1.
    d = {
        "ship.x": np.zeros(2), "ship.y": np.zeros(2), "ship.psi": np.zeros(2),
        "tug1.x": np.array([-2.0, -2.0]), "tug1.y": np.zeros(2), "tug1.psi": np.zeros(2),
        "tug2.x": np.array([2.0, 2.0]), "tug2.y": np.array([0.0, 3.0]), "tug2.psi": np.zeros(2),
        "obstacle[1].x": np.full(2, 2.0), "obstacle[1].y": np.full(2, 3.2), "obstacle[1].psi": np.zeros(2),
        "obstacle[1].length": np.ones(2), "obstacle[1].width": np.ones(2), "obstacle[1].kind": np.ones(2),
    }
    found = tow_geometry.hull_overlaps(d, dims)
    assert [(f[0], f[1], f[2]) for f in found] == [("tug2-obstacle[1] (static)", 1, 1)]


# --------------------------------------------------------------------------- stand-in controller

STAND_IN_OUTPUTS = {  # name: (type, value); the forward tug tows as in masters/plant_demo.py
    "tug1.force_surge": ("Real", 0.0), "tug1.force_sway": ("Real", 0.0), "tug1.moment_yaw": ("Real", 0.0),
    "tug2.force_surge": ("Real", 2.12), "tug2.force_sway": ("Real", 0.0), "tug2.moment_yaw": ("Real", 0.0),
    "towline1.tension_cmd": ("Real", 0.0), "towline2.tension_cmd": ("Real", 1.0),
    "controller.fallbacks": ("Integer", 0), "controller.compute_time": ("Real", 0.001),
    "admm.iterations": ("Integer", 7), "guidance.altered": ("Boolean", 0),
}


class StandInSlave:
    """Enough of fmpy's FMU2Slave for the master: raw fmi2Get/Set/DoStep returning statuses.
    It reports fmi2Warning from every 25th doStep, and checks the call order it sees."""

    def __init__(self, variables):
        self.component = object()
        self.values = {v.valueReference: (v.start if v.start is not None else 0) for v in variables}
        self.inputs = {v.valueReference for v in variables if v.causality == "input"}
        self.steps = []
        self.warned = 0
        self.seen_inputs = []
        self.freed = False

    def _get(self, c, vr, n, buf):
        for i in range(n):
            buf[i] = self.values[vr[i]]
        return 0

    def _set(self, c, vr, n, buf):
        for i in range(n):
            self.values[vr[i]] = buf[i]
        return 0

    fmi2GetReal = fmi2GetInteger = fmi2GetBoolean = _get
    fmi2SetReal = fmi2SetInteger = fmi2SetBoolean = _set

    def setString(self, vr, values):
        self.values[vr[0]] = values[0]

    def setInteger(self, vr, values):
        self.values[vr[0]] = values[0]

    setReal = setBoolean = setInteger

    def fmi2DoStep(self, c, t, h, no_set):
        assert not self.steps or abs(t - (self.steps[-1][0] + self.steps[-1][1])) < 1e-9
        self.steps.append((t, h))
        self.seen_inputs.append(self.values[100])  # ship.x, vr 100 as in the plant
        if len(self.steps) % 25 == 0:
            self.warned += 1
            return 1
        return 0

    def setupExperiment(self, *args):
        pass

    def enterInitializationMode(self):
        pass

    def exitInitializationMode(self):
        pass

    def terminate(self):
        pass

    def freeInstance(self):
        assert not self.freed
        self.freed = True


def test_master_with_the_plant_and_a_stand_in_controller(plant_fmu, tmp_path, monkeypatch):
    import fmpy

    plant_md = fmpy.read_model_description(plant_fmu)
    variables = [var(v.name, "input", v.type, v.valueReference) for v in plant_md.modelVariables if v.causality == "output"]
    variables += [var(name, "output", t, 5000 + i, start=value) for i, (name, (t, value)) in enumerate(STAND_IN_OUTPUTS.items())]
    variables += [var("scenario", "parameter", "String", 1, ""), var("avoidance_scheme", "parameter", "Enumeration", 2, 1),
                  var("run_id", "parameter", "String", 3, "")]
    md = SimpleNamespace(guid="{stand-in}", coSimulation=SimpleNamespace(modelIdentifier="StandIn"), modelVariables=variables)
    fake_fmu = tmp_path / "StandIn.fmu"
    fake_fmu.write_bytes(b"")
    slaves = []
    real_read, real_extract, real_slave = fmpy.read_model_description, fmpy.extract, closed_loop.FMU2Slave
    monkeypatch.setattr(fmpy, "read_model_description", lambda p, *a, **k: md if p == str(fake_fmu) else real_read(p, *a, **k))
    monkeypatch.setattr(fmpy, "extract", lambda p, d, *a, **k: d if p == str(fake_fmu) else real_extract(p, d, *a, **k))

    def make_slave(**kw):
        if kw["modelIdentifier"] == "StandIn":
            slaves.append(StandInSlave(variables))
            return SimpleNamespace(instantiate=lambda **_: None, **{n: getattr(slaves[-1], n) for n in dir(StandInSlave) if not n.startswith("__")},
                                   component=slaves[-1].component)
        return real_slave(**kw)

    monkeypatch.setattr(closed_loop, "FMU2Slave", make_slave)
    out = tmp_path / "out"
    code = closed_loop.main(["--plant", plant_fmu, "--controller", str(fake_fmu), "--stop-time", "30", "--scheme", "2",
                             "--map-size", "640x480", "--out", str(out), "--quiet", "--run-id", "stand-in run"])
    assert code == 0
    slave = slaves[0]
    assert slave.freed
    assert slave.values[2] == 2  # --scheme set avoidance_scheme
    assert slave.values[3] == "stand-in run"  # --run-id set run_id
    assert len(slave.steps) == 300 and slave.steps[0] == (0.0, pytest.approx(0.1))
    header, d = read_csv(out / "timeseries.csv")
    plant_outputs = [v.name for v in plant_md.modelVariables if v.causality == "output"]
    assert header == ["time"] + plant_outputs + list(STAND_IN_OUTPUTS)
    assert len(d["time"]) == 301 and d["time"][-1] == pytest.approx(30.0)
    # Gauss-Seidel, controller first: the controller's k-th step saw the plant at t_k.
    assert slave.seen_inputs == pytest.approx(list(d["ship.x"][:-1]), abs=0)
    # The plant was driven by the stand-in's commands: the forward tug pulled the ship.
    assert d["towline2.tension"][-1] == pytest.approx(1.0)
    assert np.hypot(d["ship.x"][-1] - d["ship.x"][0], d["ship.y"][-1] - d["ship.y"][0]) > 1.0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["warnings"] == slave.warned == 12
    assert summary["steps"] == 300 and summary["fallbacks"] == 0
    assert summary["controller_samples"] == 30
    assert summary["admm_iterations"] == {"median": 7.0, "p99": 7.0, "max": 7.0}
    assert summary["final_ship_pose"]["x"] == d["ship.x"][-1]
    assert summary["run_id"] == "stand-in run"
    assert_map(out / "map.png", (640, 480))


def test_an_enumeration_parameter_takes_its_value_or_an_items_name():
    items = [SimpleNamespace(name="distributed", value="1"), SimpleNamespace(name="centralized", value="2")]
    v = SimpleNamespace(name="architecture", declaredType=SimpleNamespace(items=items))
    assert closed_loop.enumeration_value(v, "2") == 2
    assert closed_loop.enumeration_value(v, "centralized") == 2
    with pytest.raises(ValueError, match="'central' is neither a number nor an item name \\(1 distributed, 2 centralized\\)"):
        closed_loop.enumeration_value(v, "central")


def test_generated_run_ids_differ_and_name_the_time():
    a, b = closed_loop.new_run_id(), closed_loop.new_run_id()
    assert a != b
    assert re.fullmatch(r"\d{8}T\d{6}Z-[0-9a-f]{8}", a), a


def test_master_refuses_fmus_that_do_not_connect(plant_fmu, tmp_path):
    # The plant in the controller's place: its inputs (tug forces) are no plant outputs.
    r = run_master(tmp_path, "--plant", plant_fmu, "--controller", plant_fmu, "--stop-time", "1")
    assert r.returncode == 2, r.stderr
    assert "controller input 'tug1.force_surge' has no plant output of the same name" in r.stderr
    assert not (tmp_path / "timeseries.csv").exists()


def test_master_help_documents_the_options():
    r = subprocess.run([sys.executable, str(MASTER), "--help"], capture_output=True, text=True, check=True)
    for option in ("--plant", "--controller", "--scenario", "--stop-time", "--step", "--architecture", "--scheme", "--param",
                   "--run-id", "--out", "--quiet"):
        assert option in r.stdout


# --------------------------------------------------------------------------- with the controller FMU


def test_short_closed_loop_on_the_paper_scenario(plant_fmu, controller_fmu, tmp_path):
    r = run_master(tmp_path, "--plant", plant_fmu, "--controller", controller_fmu, "--stop-time", 60, "--map-size", "800x600")
    assert r.returncode == 0, r.stdout + r.stderr
    header, d = read_csv(tmp_path / "timeseries.csv")
    assert header == expected_columns(plant_fmu, controller_fmu)
    assert len(d["time"]) == 601
    assert d["time"] == pytest.approx(np.arange(601) * 0.1)
    for name, x in d.items():
        assert np.all(np.isfinite(x)), name
    assert_commands_within_bounds(d)
    assert_map(tmp_path / "map.png", (800, 600))
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["steps"] == 600 and summary["stop_time"] == 60.0
    for key in ("wall_time_s", "fallbacks", "warnings", "compute_time_max_s", "compute_time_median_s", "compute_time_p99_s",
                "admm_iterations", "final_ship_pose"):
        assert key in summary, key


def test_a_discarded_step_stops_the_run_with_the_plants_message(plant_fmu, controller_fmu, tmp_path, paper_scenario):
    # An absurdly stiff elastic line integrated coarsely: the plant discards the step that
    # would go non-finite (as in test_plant_fmpy.py); the master must stop, say which FMU and
    # step, print the logged reason and exit non-zero without writing results.
    text = paper_scenario.read_text()
    default_sim = '[simulation]\nhull_model = "nonlinear_damping"\ntowline_model = "ideal_winch"\nintegration_step = 0.01\n'
    assert default_sim in text
    stiff = tmp_path / "stiff.toml"
    stiff.write_text(text.replace(default_sim, '[simulation]\ntowline_model = "elastic"\nintegration_step = 0.1\n'
                                                '[simulation.elastic_towline]\nstiffness = 1e9\n'))
    r = run_master(tmp_path / "out", "--plant", plant_fmu, "--controller", controller_fmu, "--scenario", stiff, "--stop-time", 100)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "plant (TowingPlant): doStep(" in r.stderr and "status 2 (discard)" in r.stderr
    assert "non-finite" in r.stderr.lower() or "not finite" in r.stderr.lower(), r.stderr
    assert not (tmp_path / "out" / "timeseries.csv").exists()


def command_problems(d):
    """Every command within its bound and rate bound (Tables 2, 3), every column finite."""
    problems = []
    lag = sample_lag(d)
    for i in (1, 2):
        f = d[f"towline{i}.tension_cmd"]
        if f.min() < -EPS or f.max() > TENSION_MAX + EPS:
            problems.append(f"towline{i}.tension_cmd outside [0, 3] N: [{f.min():.4f}, {f.max():.4f}]")
        rate = worst_rate(f, lag)
        if rate > TENSION_RATE + RATE_TOL:
            problems.append(f"towline{i}.tension_cmd changes by {rate:.4f} N in a sample (bound 0.3 N)")
        a = d[f"towline{i}.angle_desired"]
        if np.abs(a).max() > ANGLE_MAX + EPS:
            problems.append(f"towline{i}.angle_desired reaches {math.degrees(np.abs(a).max()):.2f} deg (bound 30 deg)")
        rate = worst_rate(a, lag, wrap=True)
        if rate > ANGLE_RATE + RATE_TOL:
            problems.append(f"towline{i}.angle_desired changes by {math.degrees(rate):.3f} deg in a sample (bound 5 deg)")
        for s in ("force_surge", "force_sway", "moment_yaw"):
            x = np.abs(d[f"tug{i}.{s}"]).max()
            if x > THRUST_MAX + EPS:
                problems.append(f"|tug{i}.{s}| reaches {x:.4f} (bound 10)")
    for name, x in d.items():
        if not np.all(np.isfinite(x)):
            problems.append(f"{name} is not finite at t = {d['time'][np.flatnonzero(~np.isfinite(x))[0]]:.1f} s")

    return problems


# Known, open failures of the acceptance runs, strict (xfail): the day one passes, its
# marker must go. None at present (the last two were closed in issue 3).
KNOWN_FAILURES = {}
CASES = [
    pytest.param(a, s, marks=pytest.mark.xfail(strict=True, reason=KNOWN_FAILURES[(a, s)]))
    if (a, s) in KNOWN_FAILURES
    else (a, s)
    for a in (1, 2)
    for s in (1, 2, 3)
]
CASE_IDS = [f"{'distributed' if a == 1 else 'centralized'}-scheme{s}" for a in (1, 2) for s in (1, 2, 3)]


@pytest.mark.closed_loop_long
@pytest.mark.parametrize("architecture, scheme", CASES, ids=CASE_IDS)
def test_paper_scenario_acceptance(plant_fmu, controller_fmu, paper_scenario, architecture, scheme, record_property):
    """1200 s of the paper scenario, judged by the paper's criteria. For scheme III (distance
    cost only) the side on which each target passes is recorded (record_property and the
    printed line), not asserted: the paper itself reports a port turn for scheme III in
    scenario 1 (Table 6, 'no')."""
    out = ROOT / "out" / "acceptance" / f"arch{architecture}-scheme{scheme}"
    r = run_master(out, "--plant", plant_fmu, "--controller", controller_fmu, "--architecture", architecture, "--scheme", scheme,
                   "--stop-time", 1200, "--quiet")
    assert r.returncode == 0, r.stdout + r.stderr
    _, d = read_csv(out / "timeseries.csv")
    summary = json.loads((out / "summary.json").read_text())
    scenario = tow_geometry.load_scenario(paper_scenario)
    problems = []

    settled = settling_time(d, scenario)
    dest = scenario["route"]["destination"]
    final = (f"final ship ({d['ship.x'][-1]:.2f}, {d['ship.y'][-1]:.2f}) m, {math.degrees(d['ship.psi'][-1]):.1f} deg, "
             f"{math.hypot(d['ship.x'][-1] - dest['x'], d['ship.y'][-1] - dest['y']):.2f} m from the destination, "
             f"u {d['ship.u'][-1]:.4f} v {d['ship.v'][-1]:.4f} r {d['ship.r'][-1]:.4f}")
    record_property("settling_time", settled)
    if settled is None:
        problems.append(f"the ship does not settle at the destination before 1200 s: {final}")

    overlaps = tow_geometry.hull_overlaps(d, tow_geometry.vessel_dims(scenario))
    for name, row, rows, depth in overlaps:
        problems.append(f"hull overlap {name} from t = {d['time'][row]:.1f} s, {rows} rows, {depth * 100:.1f} cm deep")

    problems += command_problems(d)
    if summary["fallbacks"] != 0:
        problems.append(f"{summary['fallbacks']} controller fallbacks ({summary['warnings']} fmi2Warning statuses)")

    found = encounters(d, scenario)
    record_property("encounters", found)
    print(f"\n{out.name}: settling time {settled}; {final}; encounters:")
    for e in found:
        print(f"  {e['name']}: CPA {e['cpa_distance']:.2f} m at {e['cpa_time']:.1f} s, bearing {e['relative_bearing_deg']:.1f} deg "
              f"({e['side']}), altered {e['altered']}")
    if scheme in (1, 2):
        assert found, "no target ship was active"
        for e in found:
            if not -180.0 < e["relative_bearing_deg"] < 0.0:
                problems.append(f"target {e['name']} passes on the ship's starboard side (bearing {e['relative_bearing_deg']:.1f} deg at "
                                f"CPA {e['cpa_distance']:.2f} m, t = {e['cpa_time']:.1f} s)")
            if not e["altered"]:
                problems.append(f"no starboard alteration (guidance.altered) during the encounter with {e['name']}")
    # Scheme III: the sides are recorded above, deliberately not asserted.

    assert not problems, f"{out.name} ({out}):\n  " + "\n  ".join(problems)


@pytest.mark.closed_loop_long
def test_linear_prediction_model_against_the_nonlinear_plant(plant_fmu, controller_fmu, paper_scenario, record_property):
    """Model mismatch (docs/swap-plant.md): the controller predicts with the linear hull
    model (constant damping, the paper's eq. (1)), the plant integrates the nonlinear one
    (Skjetne et al. 2004). The run must finish collision-free with every command within its
    bounds, and settle at the destination (1500 s simulated: it arrives later than with the
    matched model, about 1030 s against 995 s)."""
    out = ROOT / "out" / "acceptance" / "mismatch-linear-controller"
    r = run_master(out, "--plant", plant_fmu, "--controller", controller_fmu,
                   "--param", "mpc.hull_from_scenario=false", "--param", "mpc.hull_model=1",
                   "--plant-param", "model.hull_from_scenario=false", "--plant-param", "model.hull=2",
                   "--stop-time", 1500, "--quiet")
    assert r.returncode == 0, r.stdout + r.stderr
    _, d = read_csv(out / "timeseries.csv")
    scenario = tow_geometry.load_scenario(paper_scenario)
    assert d["time"][-1] == pytest.approx(1500.0)
    problems = command_problems(d)
    for name, row, rows, depth in tow_geometry.hull_overlaps(d, tow_geometry.vessel_dims(scenario)):
        problems.append(f"hull overlap {name} from t = {d['time'][row]:.1f} s, {rows} rows, {depth * 100:.1f} cm deep")
    settled = settling_time(d, scenario)
    record_property("settling_time", settled)
    if settled is None:
        problems.append("the ship does not settle at the destination within 1500 s")
    dest = scenario["route"]["destination"]
    print(f"\n{out.name}: settling time {settled}; final distance to the destination "
          f"{math.hypot(d['ship.x'][-1] - dest['x'], d['ship.y'][-1] - dest['y']):.2f} m")
    assert not problems, f"{out.name} ({out}):\n  " + "\n  ".join(problems)

"""The encounter suites and the random generator (masters/encounters.py, scenarios/suites/):

- every committed suite file passes the kinematic check (each target within 1 m of the
  non-reacting tow's ship centre, spawning at least 2 m from every vessel) and lists its
  targets in the suite's expected.toml;
- regenerating imazu/ and extra/ gives the committed files byte for byte;
- the generator is deterministic, its files pass the kinematic check and the loader's
  rules, and it refuses unknown options;
- the check can fail (a target moved off its collision course) and the situation
  classifier gives the known answers of Imazu's single-target problems;
- every suite file and a few random ones load in both packaged FMUs (one 0.1 s step, OK),
  and a broken file is refused with the loader's message.
"""

import filecmp
import math
import subprocess
import sys
import tomllib

import fmpy
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2True

import encounters
from conftest import ROOT
from fmu_logging import MessageLog

SUITES = ROOT / "scenarios" / "suites"
GENERATOR = ROOT / "masters" / "encounters.py"
SUITE_FILES = sorted(SUITES.glob("*/*-*.toml"))
SITUATIONS = {"head-on", "crossing give-way", "crossing stand-on", "overtaking", "being overtaken"}
ACTIONS = {"give way to starboard", "take the way off", "stand on"}
RANDOM_SEED = 20261201


def load(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def test_the_suites_are_committed():
    names = {p.parent.name for p in SUITE_FILES}
    assert names == {"imazu", "extra"}, names
    assert len([p for p in SUITE_FILES if p.parent.name == "imazu"]) == 22


@pytest.mark.parametrize("path", SUITE_FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_suite_file_passes_the_kinematic_check(path):
    scenario = load(path)
    checks = encounters.check_scenario(scenario)
    ships = [o for o in scenario.get("obstacles", []) if o["kind"] == "ship"]
    assert 1 <= len(checks) == len(ships) <= 3
    for c in checks:
        assert c.t_active is not None, f"{c.name} never appears"
        assert c.cpa_ship < encounters.CPA_LIMIT, encounters.check_report(c)
        assert c.cpa_tow <= c.cpa_ship
        assert c.clearance >= encounters.SPAWN_CLEARANCE, encounters.check_report(c)
    # The same figures are in the file's header (it is the generator's output).
    text = path.read_text()
    for c in checks:
        assert f"closest approach {c.cpa_ship:.3f} m to the ship's centre at {c.t_cpa_ship:.1f} s" in text


@pytest.mark.parametrize("suite", ["imazu", "extra"])
def test_expected_toml_gives_every_target_a_situation_role_and_action(suite):
    expected = load(SUITES / suite / "expected.toml")
    files = sorted(p.name for p in (SUITES / suite).glob("*-*.toml"))
    assert sorted(expected) == files
    for name in files:
        ships = [o["name"] for o in load(SUITES / suite / name).get("obstacles", []) if o["kind"] == "ship"]
        assert sorted(expected[name]) == sorted(ships), name
        for target, e in expected[name].items():
            assert e["situation"] in SITUATIONS and e["action"] in ACTIONS, (name, target, e)
            assert e["role"] == ("stand-on" if e["situation"] in {"crossing stand-on", "being overtaken"} else "give-way")
            assert (e["action"] == "stand on") == (e["role"] == "stand-on"), (name, target, e)


def test_extra_suite_covers_what_it_promises():
    files = {p.stem: load(p) for p in (SUITES / "extra").glob("*-*.toml")}
    expected = load(SUITES / "extra" / "expected.toml")
    situations = {e["situation"] for entries in expected.values() for e in entries.values()}
    assert "being overtaken" in situations
    ships = [o for s in files.values() for o in s.get("obstacles", []) if o["kind"] == "ship"]
    assert any(math.isclose(o["speed"], 0.05) for o in ships) and any(math.isclose(o["speed"], 0.15) for o in ships)
    assert any(s["waterway"]["half_width"] <= 3.0 for s in files.values())
    # Static hazards on either side of the route, about 3 m beside it.
    sides = set()
    for s in files.values():
        route = encounters.Route(encounters.tow_geometry.route_points(s)[:, :2])
        for o in s.get("obstacles", []):
            if o["kind"] == "static":
                assert 2.5 <= route.distance_to(o["x"], o["y"]) <= 3.5
                sides.add(math.copysign(1.0, o["y"]))  # the extra routes head North: y > 0 is starboard
    assert sides == {1.0, -1.0}
    # A 90 deg turn.
    turns = []
    for s in files.values():
        c = encounters.Route(encounters.tow_geometry.route_points(s)[:, :2]).courses
        turns.append(max(abs(math.degrees(b - a)) for a, b in zip(c[:-1], c[1:])) if len(c) > 1 else 0.0)
    assert any(math.isclose(t, 90.0, abs_tol=1e-6) for t in turns)
    # Near-parallel crossings from starboard present at t = 0, 4-6 m abeam, relative course -15 deg.
    parallel = [
        (o, encounters.check_scenario(s)[0])
        for s in files.values()
        for o in s["obstacles"]
        if o["kind"] == "ship" and o.get("activation_time") == 0.0 and math.isclose(o["course_deg"], -15.0)
    ]
    assert len(parallel) >= 2
    assert {round(o["y"]) for o, _ in parallel} >= {4, 6}
    assert all(c.situation.situation == "crossing give-way" and c.ok for _, c in parallel)


@pytest.mark.parametrize("suite", ["imazu", "extra"])
def test_regenerating_a_suite_gives_the_committed_files(suite, tmp_path):
    out = tmp_path / suite
    subprocess.run([sys.executable, str(GENERATOR), suite, "--out", str(out)], cwd=ROOT, check=True, capture_output=True)
    committed = sorted(p.name for p in (SUITES / suite).iterdir() if p.suffix == ".toml")
    generated = sorted(p.name for p in out.iterdir())
    assert generated == committed
    _, mismatch, errors = filecmp.cmpfiles(SUITES / suite, out, committed, shallow=False)
    assert mismatch == [] and errors == []


def test_the_generator_is_deterministic(tmp_path):
    a = encounters.random_scenarios(tmp_path / "a", RANDOM_SEED, 12, hazards=0.5)
    b = encounters.random_scenarios(tmp_path / "b", RANDOM_SEED, 12, hazards=0.5)
    c = encounters.random_scenarios(tmp_path / "c", RANDOM_SEED + 1, 12, hazards=0.5)
    assert [p.name for p in a] == [f"random-{RANDOM_SEED}-{i:04d}.toml" for i in range(12)]
    assert [p.read_bytes() for p in a] == [p.read_bytes() for p in b]
    assert all(p.read_bytes() != q.read_bytes() for p, q in zip(a, c))
    # The CLI writes the same files.
    cli = tmp_path / "cli"
    args = ["random", "--seed", str(RANDOM_SEED), "--count", "12", "--hazards", "0.5", "--out", str(cli)]
    subprocess.run([sys.executable, str(GENERATOR), *args], cwd=ROOT, check=True, capture_output=True)
    assert [p.read_bytes() for p in a] == [(cli / p.name).read_bytes() for p in a]


def test_random_files_pass_the_kinematic_check_and_the_loader_rules(tmp_path):
    paths = encounters.random_scenarios(tmp_path, RANDOM_SEED, 50, hazards=0.5)
    counts, hazards = set(), 0
    for path in paths:
        s = load(path)
        obstacles = s.get("obstacles", [])
        names = [o["name"] for o in obstacles]
        assert len(obstacles) <= 8 and len(set(names)) == len(names)
        route = encounters.Route(encounters.tow_geometry.route_points(s)[:, :2])
        assert 40.0 - 1e-3 <= route.length <= 50.0 + 1e-3
        assert 4.0 <= s["waterway"]["half_width"] <= 6.0
        assert all(seg <= encounters.SEGMENT_MAX + 1e-9 for seg in route.lengths)
        ships = [o for o in obstacles if o["kind"] == "ship"]
        counts.add(len(ships))
        for o in ships:
            assert o["width"] <= o["length"] and 0.05 <= o["speed"] <= 0.15
        for o in obstacles:
            if o["kind"] == "static":
                hazards += 1
                assert 2.5 - 2e-3 <= route.distance_to(o["x"], o["y"]) <= 3.5 + 2e-3
        for c in encounters.check_scenario(s):
            assert c.ok and c.cpa_ship < 0.3 + 0.02, (path.name, encounters.check_report(c))
            assert c.clearance >= encounters.SPAWN_CLEARANCE, (path.name, encounters.check_report(c))
    assert counts == {1, 2, 3}
    assert 10 <= hazards <= 40  # about half of 50 files (binomial, p = 0.5)


def test_no_hazards_by_default(tmp_path):
    for path in encounters.random_scenarios(tmp_path, RANDOM_SEED, 10):
        assert all(o["kind"] == "ship" for o in load(path)["obstacles"])


@pytest.mark.parametrize("options, key", [({"hazard": 0.2}, "'hazard'"), ({"hazards": 0.1, "turns": 1}, "'turns'")])
def test_unknown_option_raises_value_error_naming_it(tmp_path, options, key):
    with pytest.raises(ValueError, match=key):
        encounters.random_scenarios(tmp_path, 1, 1, **options)
    assert not list(tmp_path.glob("*.toml"))


def test_bad_option_value_is_refused(tmp_path):
    with pytest.raises(ValueError, match="hazards"):
        encounters.random_scenarios(tmp_path, 1, 1, hazards=1.5)


def test_the_check_fails_a_target_off_its_collision_course(tmp_path):
    # imazu-04's target A appears by time (near the beam); 40 s late it crosses behind the ship.
    path = SUITES / "imazu" / "imazu-04.toml"
    assert "activation_time = 85.1" in path.read_text()
    late = tmp_path / "late.toml"
    late.write_text(path.read_text().replace("activation_time = 85.1", "activation_time = 125.1", 1))
    (c,) = encounters.check_scenario(load(late))
    assert not c.ok and c.cpa_ship > 2.0, encounters.check_report(c)
    fail = subprocess.run([sys.executable, str(GENERATOR), "check", str(late)], cwd=ROOT, capture_output=True, text=True)
    assert fail.returncode == 1 and "FAIL" in fail.stdout, fail.stdout
    ok = subprocess.run([sys.executable, str(GENERATOR), "check", str(path)], cwd=ROOT, capture_output=True, text=True)
    assert ok.returncode == 0 and "ok" in ok.stdout, ok.stdout


def test_range_activation_follows_the_tow(tmp_path):
    # imazu-02's target A (crossing from starboard) appears by range: moved 2 m farther along
    # the route it appears later, when the ship is as far from it, and still meets the ship.
    path = SUITES / "imazu" / "imazu-02.toml"
    a = load(path)["obstacles"][0]
    assert "activation_range" in a
    moved = tmp_path / "moved.toml"
    moved.write_text(path.read_text().replace(f"x = {a['x']:.3f}\ny = {a['y']:.3f}", f"x = {a['x'] + 2.0:.3f}\ny = {a['y']:.3f}", 1))
    (before,) = encounters.check_scenario(load(path))
    (after,) = encounters.check_scenario(load(moved))
    assert after.t_active == pytest.approx(before.t_active + 2.0 / encounters.CRUISE_SPEED, abs=0.2)
    assert after.ok, encounters.check_report(after)


@pytest.mark.parametrize(
    "case, situation",
    [(1, "head-on"), (2, "crossing give-way"), (3, "overtaking"), (4, "crossing stand-on")],
)
def test_classify_imazu_single_target_problems(case, situation):
    ((x, y, course),) = encounters.IMAZU[case]
    speed = encounters.CRUISE_SPEED * math.hypot(x, y) / 6.0
    bearing = math.degrees(math.atan2(y, x + 6.0))  # from the own ship at (-6, 0)
    assert encounters.classify(bearing, course, speed).situation == situation


def test_classify_being_overtaken_and_head_on_bounds():
    assert encounters.classify(180.0, 0.0, 0.15).situation == "being overtaken"
    assert encounters.classify(180.0, 0.0, 0.15).action == "stand on"
    assert encounters.classify(10.0, 170.0, 0.1).situation == "head-on"
    assert encounters.classify(20.0, 170.0, 0.1).situation == "crossing give-way"
    assert encounters.classify(-20.0, 170.0, 0.1).situation == "crossing stand-on"


# --------------------------------------------------------------------------- both FMUs


@pytest.fixture(scope="module")
def unpacked(fmus, tmp_path_factory):
    """{model: (model description, unzip directory)} of both FMUs, unpacked once."""
    out = {}
    for model in ("TowingPlant", "TowingController"):
        d = tmp_path_factory.mktemp(model)
        fmpy.extract(fmus[model], str(d))
        out[model] = (fmpy.read_model_description(fmus[model]), d)
    return out


def instantiate(unpacked, model, scenario, log):
    md, unzipdir = unpacked[model]
    s = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipdir), modelIdentifier=model, instanceName=model)
    s.instantiate(callbacks=log.callbacks)
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    s.setString([vrs["scenario"]], [str(scenario)])
    s.setupExperiment(startTime=0.0)
    return s


def random_files(tmp_path_factory):
    return encounters.random_scenarios(tmp_path_factory.mktemp("random"), RANDOM_SEED, 3, hazards=1.0)


@pytest.fixture(scope="module")
def load_cases(tmp_path_factory):
    return [*SUITE_FILES, *random_files(tmp_path_factory)]


@pytest.mark.parametrize("model", ["TowingPlant", "TowingController"])
def test_every_suite_file_and_random_ones_load_in_the_fmu(unpacked, load_cases, model):
    assert len(load_cases) == len(SUITE_FILES) + 3
    for path in load_cases:
        log = MessageLog()
        s = instantiate(unpacked, model, path, log)
        try:
            s.enterInitializationMode()
            s.exitInitializationMode()
            status = s.fmi2DoStep(s.component, 0.0, 0.1, fmi2True)
            assert status == 0, f"{model} {path.name}: doStep status {status}: {log.text('WARNING')}"
            s.terminate()
        except FMICallException as e:
            pytest.fail(f"{model} refused {path}: {e}: {log.text('WARNING')}")
        finally:
            s.freeInstance()


@pytest.mark.parametrize("model", ["TowingPlant", "TowingController"])
def test_a_broken_suite_file_is_refused_with_the_loaders_message(unpacked, tmp_path, model):
    bad = tmp_path / "broken.toml"
    text = (SUITES / "imazu" / "imazu-01.toml").read_text()
    bad.write_text(text.replace("width = 0.48", "width = 1.6", 1))
    log = MessageLog()
    s = instantiate(unpacked, model, bad, log)
    with pytest.raises(FMICallException):
        s.enterInitializationMode()
    errors = log.text("ERROR")
    assert str(bad) in errors and "obstacles[0].width" in errors and "must not exceed length" in errors, errors
    s.freeInstance()


def test_the_suites_readme_gives_the_measured_speed():
    readme = (SUITES / "README.md").read_text()
    assert f"{encounters.CRUISE_SPEED} m/s" in readme

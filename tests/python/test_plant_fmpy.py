"""The packaged TowingPlant FMU under fmpy: validation, simulation, FMU state, errors."""

import math
import shutil

import fmpy
import numpy as np
import pytest
from fmpy.fmi2 import FMU2Slave, fmi2LastSuccessfulTime
from fmpy.validation import validate_fmu
from fmpy.fmi1 import FMICallException
from fmu_logging import MessageLog

PULL = {"tug2.force_surge": 3.0, "towline2.tension_cmd": 2.0}


def test_validate_fmu_reports_no_problems(plant_fmu):
    assert validate_fmu(plant_fmu) == []


def test_model_description_capabilities(plant_fmu):
    md = fmpy.read_model_description(plant_fmu)
    cs = md.coSimulation
    assert cs.modelIdentifier == "TowingPlant"
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert float(md.defaultExperiment.stepSize) == 0.1
    names = {v.name for v in md.modelVariables}
    for vessel in ("ship", "tug1", "tug2"):
        for s in "x y psi u v r".split():
            assert f"{vessel}.{s}" in names
    for k in range(1, 9):
        assert f"obstacle[{k}].kind" in names


def simulate(plant_fmu, stop_time, start_values, **kw):
    md = fmpy.read_model_description(plant_fmu)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    return fmpy.simulate_fmu(plant_fmu, stop_time=stop_time, output_interval=0.1, start_values=start_values, output=outputs, **kw)


def test_forward_tug_tows_the_ship(plant_fmu):
    r = simulate(plant_fmu, 60.0, PULL)
    psi0 = math.radians(101.3)
    heading = np.array([math.cos(psi0), math.sin(psi0)])
    moved = np.array([r["ship.x"][-1] - r["ship.x"][0], r["ship.y"][-1] - r["ship.y"][0]])
    # The ship is pulled forward along its heading, by metres in a minute.
    assert moved @ heading > 2.0
    # Ideal winch: the applied tension is the command while the line is taut.
    assert r["towline2.tension"][-1] == pytest.approx(2.0)
    assert not r["towline2.slack"][-1]
    # The aft line has no command: slack, no force.
    assert r["towline1.tension"][-1] == 0.0 and r["towline1.slack"][-1]
    # Obstacle A (slot 4) moves North at 0.07 m/s from t = 0. B (slot 5) appears by range:
    # at the first output at which the ship's centre is within 14.2 m of B's spawn point
    # (-22, 40.75) (scenarios/paper.toml), not before; the 2 N tow brings it there in a minute.
    assert r["obstacle[4].kind"][-1] == 2
    assert r["obstacle[4].x"][-1] - r["obstacle[4].x"][0] == pytest.approx(0.07 * 60.0, rel=1e-9)
    range_b = np.hypot(r["ship.x"] + 22.0, r["ship.y"] - 40.75)
    active_b = np.flatnonzero(r["obstacle[5].kind"] == 2)
    assert active_b.size > 0
    first = active_b[0]
    assert range_b[first] <= 14.2 < range_b[first - 1]
    assert np.all(r["obstacle[5].kind"][:first] == 0)
    assert (r["obstacle[5].x"][first], r["obstacle[5].y"][first]) == (-22.0, 40.75)
    assert r["obstacle[1].kind"][0] == 1 and r["obstacle[1].length"][0] == 1.0


def test_two_runs_are_bit_identical(plant_fmu):
    a = simulate(plant_fmu, 20.0, PULL)
    b = simulate(plant_fmu, 20.0, PULL)
    for name in ("ship.x", "ship.y", "ship.psi", "tug1.x", "tug2.v", "towline2.length"):
        assert np.array_equal(a[name], b[name])


def slave(plant_fmu, tmp_path, log, name="plant"):
    md = fmpy.read_model_description(plant_fmu)
    unzipdir = tmp_path / name
    if not unzipdir.exists():
        fmpy.extract(plant_fmu, str(unzipdir))
    s = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipdir), modelIdentifier="TowingPlant", instanceName=name)
    s.instantiate(callbacks=log.callbacks)
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    return s, vrs


def start(s, vrs, stop_time=None):
    s.setupExperiment(startTime=0.0, stopTime=stop_time)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([vrs[k] for k in PULL], list(PULL.values()))


def run_steps(s, vrs, t0, n, names=("ship.x", "ship.y", "ship.psi", "tug2.u", "towline2.length")):
    rows = []
    t = t0
    for _ in range(n):
        s.doStep(t, 0.1)
        t += 0.1
        rows.append(s.getReal([vrs[k] for k in names]))
    return rows, t


def test_fmu_state_get_set_and_serialize_reproduce_a_trajectory(plant_fmu, tmp_path):
    log = MessageLog()
    s, vrs = slave(plant_fmu, tmp_path, log)
    start(s, vrs)
    _, t = run_steps(s, vrs, 0.0, 50)
    state = s.getFMUstate()
    serialized = s.serializeFMUstate(state)
    first, _ = run_steps(s, vrs, t, 50)

    s.setFMUstate(state)
    again, _ = run_steps(s, vrs, t, 50)
    assert again == first

    # A fresh instance (its own unpacked copy) restores the serialized state.
    fresh, _ = slave(plant_fmu, tmp_path, log, name="fresh")
    fresh.setupExperiment(startTime=0.0)
    restored = fresh.deSerializeFMUstate(serialized)
    fresh.setFMUstate(restored)
    third, _ = run_steps(fresh, vrs, t, 50)
    assert third == first
    s.freeFMUstate(state)
    fresh.freeFMUstate(restored)
    for x in (s, fresh):
        x.terminate()
        x.freeInstance()


@pytest.mark.parametrize(
    "text, field, reason",
    [
        ("this is = not toml [", "", "syntax"),
        ("[ship]\nbogus = 1\n", "bogus", "unknown field"),
    ],
)
def test_bad_scenario_is_refused_with_a_message(plant_fmu, tmp_path, paper_scenario, text, field, reason):
    bad = tmp_path / "bad scenario.toml"
    bad.write_text(text if "[ship]" not in text else paper_scenario.read_text().replace("[ship]", text.rstrip("\n"), 1))
    log = MessageLog()
    s, vrs = slave(plant_fmu, tmp_path, log)
    s.setString([vrs["scenario"]], [str(bad)])
    s.setupExperiment(startTime=0.0)
    with pytest.raises(FMICallException):
        s.enterInitializationMode()
    errors = log.text("ERROR")
    assert str(bad) in errors, errors
    assert field in errors and reason in errors.lower(), errors
    s.freeInstance()


def test_non_finite_input_is_refused_and_names_the_variable(plant_fmu, tmp_path):
    log = MessageLog()
    s, vrs = slave(plant_fmu, tmp_path, log)
    start(s, vrs)
    with pytest.raises(FMICallException):
        s.setReal([vrs["tug1.moment_yaw"]], [float("nan")])
    assert "tug1.moment_yaw" in log.text("ERROR")
    assert s.getReal([vrs["tug1.moment_yaw"]]) == [0.0]
    s.freeInstance()


STIFF_LINE = """
[simulation]
towline_model = "elastic"
integration_step = 0.1
[simulation.elastic_towline]
stiffness = 1e9
"""


def test_discarded_step_keeps_last_successful_time(plant_fmu, tmp_path, paper_scenario):
    # A user scenario with an absurdly stiff elastic line and a coarse integration step:
    # RK4 is unstable for it, the state grows without bound, and the plant must discard the
    # step that would make it non-finite instead of handing out inf or NaN.
    stiff = tmp_path / "stiff.toml"
    text = paper_scenario.read_text()
    default_sim = '[simulation]\nhull_model = "nonlinear_damping"\ntowline_model = "ideal_winch"\nintegration_step = 0.01\n'
    assert default_sim in text
    stiff.write_text(text.replace(default_sim, STIFF_LINE))
    log = MessageLog()
    s, vrs = slave(plant_fmu, tmp_path, log)
    s.setString([vrs["scenario"]], [str(stiff)])
    start(s, vrs)
    t = 0.0
    with pytest.raises(FMICallException) as e:
        for _ in range(1000):
            s.doStep(t, 0.1)
            t += 0.1
    assert e.value.status == 2  # fmi2Discard
    assert 0.0 < t < 100.0
    assert s.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(t, abs=1e-9)
    assert all(math.isfinite(v) for v in s.getReal([vrs["ship.x"], vrs["tug2.u"], vrs["towline2.tension"]]))
    assert "non-finite" in log.text("DISCARD").lower() or "not finite" in log.text("DISCARD").lower(), log.text()
    s.terminate()
    s.freeInstance()


RESTORE_IN_ANOTHER_PROCESS = r"""
import json, sys
import fmpy
from fmpy.fmi2 import FMU2Slave
fmu, state_file, unzipdir, t = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
md = fmpy.read_model_description(fmu)
vrs = {v.name: v.valueReference for v in md.modelVariables}
s = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="TowingPlant", instanceName="other")
s.instantiate()
s.setupExperiment(startTime=0.0)
state = s.deSerializeFMUstate(open(state_file, "rb").read())
s.setFMUstate(state)
rows = []
for _ in range(50):
    s.doStep(t, 0.1)
    t += 0.1
    rows.append(s.getReal([vrs[k] for k in ("ship.x", "ship.y", "ship.psi", "tug2.u", "towline2.length")]))
print(json.dumps([[v.hex() for v in r] for r in rows]))
"""


def test_serialized_state_restores_in_another_process(plant_fmu, tmp_path):
    import json
    import subprocess
    import sys

    log = MessageLog()
    s, vrs = slave(plant_fmu, tmp_path, log)
    start(s, vrs)
    _, t = run_steps(s, vrs, 0.0, 50)
    state = s.getFMUstate()
    (tmp_path / "state.bin").write_bytes(s.serializeFMUstate(state))
    expected, _ = run_steps(s, vrs, t, 50)
    other_dir = tmp_path / "other"
    fmpy.extract(plant_fmu, str(other_dir))
    out = subprocess.run(
        [sys.executable, "-c", RESTORE_IN_ANOTHER_PROCESS, plant_fmu, str(tmp_path / "state.bin"), str(other_dir), repr(t)],
        check=True,
        capture_output=True,
        text=True,
    )
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got == [[v.hex() for v in r] for r in expected]
    s.freeFMUstate(state)
    s.terminate()
    s.freeInstance()

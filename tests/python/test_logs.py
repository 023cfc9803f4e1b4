"""The MCAP logs of both FMUs (docs/logging.md), written by a closed loop under fmpy
(masters/closed_loop.py --log-dir) and read with the Python `mcap` package:

- message counts per topic match the run (plant: one per step plus one at the start, the
  Foxglove topics `/tf` and `/plant/scene` one per `log.scene_interval` = 0.5 s plus one at
  the start; controller: one per control sample);
- every message validates against its channel's JSON schema (jsonschema);
- log times never decrease within a file, and equal the `t` the messages carry;
- the `run` metadata and the `scenario.toml` attachment are there, and both logs carry the
  run id the master generated (`run_id`);
- a truncated copy of a log still yields its first messages with NonSeekingReader
  (log_time_order=False), and a cut never raises anything but a Python exception.
"""

import json
import re
import subprocess
import sys

import jsonschema
import numpy as np
import pytest
from mcap.reader import NonSeekingReader, make_reader

from conftest import ROOT

MASTER = ROOT / "masters" / "closed_loop.py"
STOP_TIME = 60.0

PLANT_TOPICS = [
    "/plant/ship",
    "/plant/tug1",
    "/plant/tug2",
    "/plant/towline1",
    "/plant/towline2",
    "/plant/obstacles",
    "/plant/inputs",
]
# Written at the start and then every `log.scene_interval` (0.5 s by default, 5 steps).
PLANT_SCENE_TOPICS = ["/tf", "/plant/scene"]
CONTROLLER_TOPICS = [
    "/controller/reference",
    "/controller/colregs",
    "/controller/command",
    "/controller/solver",
    "/controller/prediction",
    "/controller/scene",
]


@pytest.fixture(scope="module")
def logged_run(plant_fmu, controller_fmu, tmp_path_factory):
    """A 60 s closed loop of the paper scenario with --log-dir; returns (log dir, summary)."""
    base = tmp_path_factory.mktemp("logged-run")
    logs = base / "logs"
    out = base / "out"
    r = subprocess.run(
        [
            sys.executable,
            str(MASTER),
            "--plant",
            plant_fmu,
            "--controller",
            controller_fmu,
            "--stop-time",
            str(STOP_TIME),
            "--quiet",
            "--log-dir",
            str(logs),
            "--out",
            str(out),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=1800,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    summary = json.loads((out / "summary.json").read_text())
    return logs, summary, out


def read_all(path):
    """Every message in file order: (topic, schema name, schema data, log_time, publish_time,
    payload)."""
    rows = []
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
            rows.append((channel.topic, schema.name, schema.data, message.log_time, message.publish_time, message.data))
    return rows


def counts(rows):
    out = {}
    for topic, *_ in rows:
        out[topic] = out.get(topic, 0) + 1
    return out


def test_the_master_reports_both_log_files(logged_run):
    logs, summary, _ = logged_run
    assert summary["log_files"] == {
        "plant": str((logs / "plant.mcap").resolve()),
        "controller": str((logs / "controller.mcap").resolve()),
    }


def test_message_counts_match_the_run(logged_run):
    logs, summary, _ = logged_run
    steps = summary["steps"]
    samples = summary["controller_samples"]
    assert steps == round(STOP_TIME / 0.1)
    plant = counts(read_all(logs / "plant.mcap"))
    for topic in PLANT_TOPICS:
        assert plant.get(topic) == steps + 1, (topic, plant)
    for topic in PLANT_SCENE_TOPICS:
        assert plant.get(topic) == steps // 5 + 1, (topic, plant)
    assert plant.get("/plant/scene_static") == 1
    ctrl = counts(read_all(logs / "controller.mcap"))
    for topic in CONTROLLER_TOPICS:
        assert ctrl.get(topic) == samples, (topic, ctrl)
    assert ctrl.get("/controller/log", 0) == summary["fallbacks"]
    # Every channel of the contract exists, with or without messages.
    for name, expected in (("plant.mcap", PLANT_TOPICS + PLANT_SCENE_TOPICS + ["/plant/scene_static", "/plant/log"]),
                           ("controller.mcap", CONTROLLER_TOPICS + ["/controller/log"])):
        with open(logs / name, "rb") as f:
            channels = {c.topic for c in make_reader(f).get_summary().channels.values()}
        assert channels == set(expected), (name, channels)


@pytest.mark.parametrize("name", ["plant.mcap", "controller.mcap"])
def test_every_message_validates_against_its_schema_and_times_never_decrease(logged_run, name):
    logs, _, _ = logged_run
    rows = read_all(logs / name)
    assert rows
    validators = {}
    last = 0
    for topic, schema_name, schema_data, log_time, publish_time, data in rows:
        assert log_time >= last, (topic, log_time, last)
        last = log_time
        assert publish_time == log_time
        if schema_name not in validators:
            schema = json.loads(schema_data)
            cls = jsonschema.validators.validator_for(schema)
            cls.check_schema(schema)
            validators[schema_name] = cls(schema)
        message = json.loads(data)
        validators[schema_name].validate(message)
        if schema_name.startswith("towing."):
            assert log_time == round(message["t"] * 1e9), (topic, message["t"], log_time)
        elif schema_name == "foxglove.FrameTransforms":
            ts = message["transforms"][0]["timestamp"]
            assert ts["sec"] * 1_000_000_000 + ts["nsec"] == log_time
    assert last == round(STOP_TIME * 1e9) if name == "plant.mcap" else last <= round(STOP_TIME * 1e9)
    expected = {
        "plant.mcap": {"towing.VesselState", "towing.TowlineState", "towing.Obstacles", "towing.PlantInputs",
                       "foxglove.FrameTransforms", "foxglove.SceneUpdate"},
        "controller.mcap": {"towing.Reference", "towing.Colregs", "towing.Command", "towing.Solver",
                            "towing.Prediction", "foxglove.SceneUpdate"},
    }[name]
    assert expected <= set(validators), set(validators)


def test_the_logs_agree_with_the_time_series(logged_run):
    logs, _, out = logged_run
    with open(out / "timeseries.csv") as f:
        header = f.readline().rstrip("\n").split(",")
    data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1, ndmin=2)
    col = {n: i for i, n in enumerate(header)}
    ships = [json.loads(d) for topic, *_, d in read_all(logs / "plant.mcap") if topic == "/plant/ship"]
    assert len(ships) == data.shape[0]
    for k in (0, len(ships) // 2, len(ships) - 1):
        assert ships[k]["t"] == pytest.approx(data[k, col["time"]], abs=1e-9)
        assert ships[k]["x"] == data[k, col["ship.x"]]
        assert ships[k]["psi"] == data[k, col["ship.psi"]]


@pytest.mark.parametrize("name,unit", [("plant.mcap", "TowingPlant"), ("controller.mcap", "TowingController")])
def test_run_metadata_and_scenario_attachment(logged_run, name, unit):
    logs, _, _ = logged_run
    with open(logs / name, "rb") as f:
        reader = make_reader(f)
        metadata = list(reader.iter_metadata())
        attachments = list(reader.iter_attachments())
    assert [m.name for m in metadata] == ["run"]
    run = metadata[0].metadata
    assert run["unit"] == unit
    assert run["epoch"] == "simulation time 0 s"
    assert run["scenario"] == "bundled paper scenario"
    assert run["scenario_name"] == "paper"
    assert float(run["start_time"]) == 0.0
    assert run["guid"].startswith("{") and run["version"]
    params = json.loads(run["parameters"])
    assert params["log_file"] == str((logs / name).resolve())
    # The master gave both FMUs the same generated run id.
    assert run["run_id"] == params["run_id"] == logged_run[1]["run_id"]
    assert re.fullmatch(r"\d{8}T\d{6}Z-[0-9a-f]{8}", run["run_id"]), run["run_id"]
    choice = "architecture" if unit == "TowingController" else "model.hull"
    assert isinstance(params[choice], int), "an Enumeration is logged as its item's value"
    assert [(a.name, a.media_type) for a in attachments] == [("scenario.toml", "application/toml")]
    assert attachments[0].data.decode() == (ROOT / "scenarios" / "paper.toml").read_text()


def read_truncated(data):
    """Messages NonSeekingReader yields from `data` before it stops; the exception (if any)."""
    import io

    n, last, error = 0, 0, None
    try:
        for _, _, message in NonSeekingReader(io.BytesIO(data)).iter_messages(log_time_order=False):
            assert message.log_time >= last
            last = message.log_time
            n += 1
    except Exception as e:  # noqa: BLE001 - any Python exception is a clean stop
        error = e
    return n, last, error


@pytest.mark.parametrize("name", ["plant.mcap", "controller.mcap"])
def test_a_truncated_log_is_readable_up_to_its_last_complete_chunk(logged_run, name):
    logs, _, _ = logged_run
    data = (logs / name).read_bytes()
    total, _, error = read_truncated(data)
    assert error is None and total == len(read_all(logs / name))
    previous = 0
    for fraction in (0.05, 0.25, 0.5, 0.75, 0.9, 0.999):
        cut = int(len(data) * fraction)
        n, last, _ = read_truncated(data[:cut])
        assert previous <= n <= total, (fraction, n)
        previous = n
        if fraction >= 0.5:
            # Chunks close every 10 s of simulated time: a cut loses at most the chunk it
            # falls in, so more than half the file keeps messages.
            assert n > 0 and last > 0, (fraction, cut, n)

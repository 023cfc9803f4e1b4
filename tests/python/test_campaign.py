"""Campaigns (`cargo xtask campaign`, masters/campaign.py, docs/campaigns.md): a 4-run
campaign locally, the same on a Dask cluster started here on loopback (identical verdicts
and metrics), --resume, a broken scenario and a hung run failing alone, and the campaign
file's checks."""

import json
import os
import pathlib
import shutil
import socket
import subprocess
import sys
import time

import pyarrow.parquet as pq
import pytest

import campaign
import campaign_report
from conftest import ROOT, target_dir

VENV_BIN = pathlib.Path(sys.executable).parent
PAPER = ROOT / "scenarios" / "paper.toml"
HALF_WIDTH = "[waterway]\nhalf_width = 5.0\n"


def strip_timing(value):
    """`value` without the measured fields (campaign_report.MEASURED_FIELDS: times, log sizes)."""
    if isinstance(value, dict):
        return {k: strip_timing(v) for k, v in value.items() if k not in campaign_report.MEASURED_FIELDS}
    if isinstance(value, list):
        return [strip_timing(v) for v in value]
    return value


def xtask_campaign(file, out, *options):
    r = subprocess.run(["cargo", "xtask", "campaign", str(file), "--out", str(out), *map(str, options)], cwd=ROOT,
                       capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return r


@pytest.fixture(scope="module")
def analyzer(fmus):
    """Built by the fixture's `cargo xtask fmu` (the one workspace build every command uses)."""
    return target_dir() / "release" / "analyzer"


def master(campaign_file, out, fmus, analyzer, *options):
    """masters/campaign.py directly (the xtask's preparation already done by the fixtures)."""
    return subprocess.run([sys.executable, str(ROOT / "masters" / "campaign.py"), str(campaign_file), "--out", str(out), "--plant",
                           fmus["TowingPlant"], "--controller", fmus["TowingController"], "--analyzer", str(analyzer),
                           *map(str, options)], capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def four_runs(tmp_path_factory):
    """A campaign of 2 scenarios (the paper's, and a copy with a 4 m half width) x
    architecture [1, 2], 60 s each, its file in its own folder."""
    d = tmp_path_factory.mktemp("campaign")
    (d / "scenarios").mkdir()
    shutil.copy(PAPER, d / "scenarios" / "paper.toml")
    text = PAPER.read_text()
    assert HALF_WIDTH in text
    (d / "scenarios" / "narrow.toml").write_text(text.replace(HALF_WIDTH, "[waterway]\nhalf_width = 4.0\n"))
    f = d / "four.toml"
    f.write_text('name = "four"\nscenarios = ["scenarios/*.toml"]\nstop_time = 60\n[parameters]\narchitecture = [1, 2]\n')
    return f


@pytest.fixture(scope="module")
def local(four_runs, fmus):
    out = four_runs.parent / "local"
    r = xtask_campaign(four_runs, out, "--workers", 2)
    return out, r


def test_a_local_campaign_runs_every_scenario_with_every_configuration(local):
    out, r = local
    assert "campaign: 4/4 runs" in r.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["total"] == 4 and summary["passed"] == sum(run["passed"] for run in summary["runs"])
    runs = summary["runs"]
    # Scenarios sorted from the glob, outer; the architectures inner, in the file's order.
    assert [(run["scenario"], run["parameters"]) for run in runs] == [
        ("scenarios/narrow.toml", {"architecture": 1}), ("scenarios/narrow.toml", {"architecture": 2}),
        ("scenarios/paper.toml", {"architecture": 1}), ("scenarios/paper.toml", {"architecture": 2})]
    assert len({run["id"] for run in runs}) == 4 and all(len(run["id"]) == 64 for run in runs)
    for run in runs:
        m = run["metrics"]
        assert m is not None, run["reasons"]
        assert m["collisions"] == 0 and m["truncated"] is False
        assert "thresholds" in m, "the analyzer's metrics.json names the thresholds of its verdict"
        assert all(x["message"] != "analyzer gave no verdict" for x in run["reasons"]), run["reasons"]
        assert run["passed"] == (not run["reasons"]), run
        for x in run["reasons"]:
            assert set(x) >= {"metric", "target", "t_s", "message"}
        stored = json.loads((out / "runs" / run["id"] / "result.json").read_text())
        assert stored["passed"] == run["passed"] and stored["metrics"] == m
    table = pq.read_table(out / "runs.parquet").to_pydict()
    assert table["id"] == [run["id"] for run in runs]
    assert table["metrics.collisions"] == [0, 0, 0, 0]
    assert table["parameters.architecture"] == [1, 2, 1, 2]
    md = (out / "report.md").read_text()
    assert "| scenario | architecture=1 | architecture=2 |" in md
    assert f"{summary['passed']} of 4 runs passed" in md
    html = (out / "report.html").read_text()
    assert html.count("<svg") >= 1 and "<table>" in html
    assert "src=" not in html  # self-contained: the plots are inline


@pytest.fixture
def dask_cluster(tmp_path_factory):
    """`dask scheduler` and two `dask worker` processes of the venv on loopback, each in a
    folder of its own outside the repository and without the repository on its path."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    procs, dirs = [], []
    try:
        for i, cmd in enumerate([["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                                 ["worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"],
                                 ["worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"]]):
            d = tmp_path_factory.mktemp(f"dask{i}")
            assert ROOT not in d.parents
            dirs.append(d)
            extra = ["--local-directory", str(d)] if cmd[0] == "worker" else []
            log = open(d / "log.txt", "w")
            procs.append(subprocess.Popen([str(VENV_BIN / "dask"), *cmd, *extra], cwd=d, env=env, stdout=log, stderr=subprocess.STDOUT))
            log.close()
        from distributed import Client

        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
            # The workers cannot import the campaign's modules: everything must travel.
            found = client.run(lambda: __import__("importlib.util").util.find_spec("campaign_task") is not None)
            assert list(found.values()) == [False, False]
        yield address, dirs[1:]
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def test_the_same_campaign_on_a_dask_cluster_gives_identical_results(local, four_runs, dask_cluster, fmus, analyzer):
    address, worker_dirs = dask_cluster
    out = four_runs.parent / "cluster"
    r = master(four_runs, out, fmus, analyzer, "--scheduler", address)
    assert r.returncode == 0, r.stderr[-3000:]
    assert f"cluster {address}" in r.stderr
    here = json.loads((local[0] / "summary.json").read_text())
    there = json.loads((out / "summary.json").read_text())
    assert strip_timing(there) == strip_timing(here)
    # The bundle (FMUs, analyzer, task code) arrived in the workers' own folders.
    for d in worker_dirs:
        assert list(d.rglob("towing-campaign-*/TowingPlant.fmu")), f"nothing written in {d}"


def test_resume_skips_every_finished_run(local, four_runs, fmus, analyzer):
    out, _ = local
    results = sorted((out / "runs").glob("*/result.json"))
    assert len(results) == 4
    before = {p: p.stat().st_mtime_ns for p in results}
    summary = (out / "summary.json").read_text()
    r = master(four_runs, out, fmus, analyzer, "--workers", 1, "--resume")
    assert r.returncode == 0, r.stderr[-3000:]
    assert "4 runs (4 already finished, skipped)" in r.stderr
    assert {p: p.stat().st_mtime_ns for p in results} == before
    assert (out / "summary.json").read_text() == summary


def test_a_broken_scenario_fails_its_run_with_the_loaders_message(fmus, analyzer, tmp_path):
    shutil.copy(PAPER, tmp_path / "paper.toml")
    (tmp_path / "broken.toml").write_text(PAPER.read_text().replace(HALF_WIDTH, "[waterway]\nhalf_width = -1.0\n"))
    f = tmp_path / "broken-campaign.toml"
    f.write_text('name = "broken"\nscenarios = ["broken.toml", "paper.toml"]\nstop_time = 30\n')
    r = master(f, tmp_path / "out", fmus, analyzer, "--workers", 2)
    assert r.returncode == 0, r.stderr
    broken, paper = json.loads((tmp_path / "out" / "summary.json").read_text())["runs"]
    assert broken["passed"] is False and broken["metrics"] is None
    [reason] = broken["reasons"]
    assert reason["metric"] == "closed loop"
    assert "broken.toml:" in reason["message"] and "waterway.half_width: must be > 0 m, got -1" in reason["message"], reason
    assert str(tmp_path) not in reason["message"]
    assert paper["metrics"] is not None and paper["metrics"]["collisions"] == 0


def test_a_run_past_its_wall_time_limit_fails_and_names_the_limit(fmus, analyzer, tmp_path):
    shutil.copy(PAPER, tmp_path / "paper.toml")
    f = tmp_path / "slow.toml"
    # 20000 s simulated take the closed loop over 10 s on any machine we know of: the limit,
    # not the machine's speed, decides in which phase the run stops.
    f.write_text('name = "slow"\nscenarios = ["paper.toml"]\nstop_time = 20000\nwall_time_limit_s = 1.5\n')
    start = time.monotonic()
    r = master(f, tmp_path / "out", fmus, analyzer, "--workers", 1)
    assert r.returncode == 0, r.stderr
    [run] = json.loads((tmp_path / "out" / "summary.json").read_text())["runs"]
    assert run["reasons"] == [{"metric": "wall time", "target": None, "t_s": None,
                               "message": "wall-time limit 1.5 s exceeded (closed loop)"}]
    assert time.monotonic() - start < 60


# --------------------------------------------------------------------------- the campaign file


def write(tmp_path, text):
    shutil.copy(PAPER, tmp_path / "paper.toml")
    f = tmp_path / "c.toml"
    f.write_text('name = "c"\nscenarios = ["paper.toml"]\n' + text)
    return f


@pytest.mark.parametrize("text, message", [
    ("colour = 1\n", "unknown key(s) 'colour'"),
    ("stop_time = \"never\"\n", "'stop_time'"),
    ("step = -0.1\n", "'step' must be a positive finite number"),
    ("keep_logs = 1\n", "'keep_logs' must be true or false"),
    ("[parameters]\narchitecture = 1\n", "[parameters] architecture: must be a non-empty list"),
    ("[parameters]\nscenario = [\"x\"]\n", "[parameters] scenario: set by the campaign itself"),
    ("[parameters]\n\"plant.run_id\" = [\"x\"]\n", "[parameters] plant.run_id: set by the campaign itself"),
    ("[thresholds]\ndrift_max_deg = \"big\"\n", "[thresholds]: 'drift_max_deg' must be a finite number"),
    ("[random]\nseed = 1\n", "[random] 'count' must be an integer >= 1"),
])
def test_a_bad_campaign_file_is_refused_naming_the_key(tmp_path, text, message):
    with pytest.raises(campaign.CampaignError) as e:
        campaign.load_campaign(write(tmp_path, text))
    assert message in str(e.value)


def test_parameters_and_globs_are_checked_before_anything_runs(tmp_path, fmus):
    c = campaign.load_campaign(write(tmp_path, "[parameters]\nnonsense = [1]\n"))
    with pytest.raises(campaign.CampaignError, match="the controller FMU has no parameter 'nonsense'"):
        campaign.check_parameters(c, fmus["TowingPlant"], fmus["TowingController"])
    c = campaign.load_campaign(write(tmp_path, "[parameters]\narchitecture = [1.5]\n"))
    with pytest.raises(campaign.CampaignError, match="controller parameter 'architecture' is Enumeration, got 1.5"):
        campaign.check_parameters(c, fmus["TowingPlant"], fmus["TowingController"])
    c = campaign.load_campaign(write(tmp_path, "[parameters]\narchitecture = [1, 3]\n"))
    with pytest.raises(campaign.CampaignError,
                       match=r"controller parameter 'architecture' must be one of 1 distributed, 2 centralized \(its modelDescription\), got 3"):
        campaign.check_parameters(c, fmus["TowingPlant"], fmus["TowingController"])
    c = campaign.load_campaign(write(tmp_path, "[parameters]\n\"admm.max_iterations\" = [0]\n"))
    with pytest.raises(campaign.CampaignError, match=r"controller parameter 'admm.max_iterations' must be in \[1, 100\] .*, got 0"):
        campaign.check_parameters(c, fmus["TowingPlant"], fmus["TowingController"])
    c = campaign.load_campaign(write(tmp_path, "[parameters]\n\"plant.model.hull\" = [1, 2]\narchitecture = [1, 2]\n"))
    campaign.check_parameters(c, fmus["TowingPlant"], fmus["TowingController"])
    assert campaign.configurations(c) == [{"plant.model.hull": 1, "architecture": 1}, {"plant.model.hull": 1, "architecture": 2},
                                          {"plant.model.hull": 2, "architecture": 1}, {"plant.model.hull": 2, "architecture": 2}]
    # dotted keys as TOML writes them (nested tables) are the same grouped names
    c = campaign.load_campaign(write(tmp_path, "[parameters]\nplant.model.hull = [2]\nadmm.rho = [1.0, 2.0]\n"))
    campaign.check_parameters(c, fmus["TowingPlant"], fmus["TowingController"])
    assert campaign.configurations(c) == [{"plant.model.hull": 2, "admm.rho": 1.0}, {"plant.model.hull": 2, "admm.rho": 2.0}]
    c = campaign.load_campaign(write(tmp_path, ""))
    c["scenarios"] = ["suites/*.toml"]
    with pytest.raises(campaign.CampaignError, match="'scenarios' entry 'suites/\\*.toml' matches no file"):
        campaign.scenario_files(c, tmp_path / "out")


def test_thresholds_are_checked_by_the_analyzer_before_anything_runs(tmp_path, analyzer):
    c = campaign.load_campaign(write(tmp_path, "[thresholds]\ndrift_max = 45\n"))
    with pytest.raises(campaign.CampaignError, match="unknown field `drift_max`"):
        campaign.check_thresholds(c, analyzer)
    campaign.check_thresholds(campaign.load_campaign(write(tmp_path, "[thresholds]\ndrift_max_deg = 45\n")), analyzer)


def test_the_arrival_stop_time_follows_the_route_and_the_thresholds(tmp_path):
    c = campaign.load_campaign(write(tmp_path, ""))
    # The paper's route: 63.45 m (scenarios/paper.toml) at 0.05 m/s, plus 300 s.
    assert campaign.stop_time(c, PAPER) == pytest.approx(63.45 / 0.05 + 300.0, abs=0.5)
    c = campaign.load_campaign(write(tmp_path, "[thresholds]\narrival_speed_m_s = 0.1\narrival_margin_s = 0\n"))
    assert campaign.stop_time(c, PAPER) == pytest.approx(63.45 / 0.1, abs=0.5)


def test_run_ids_are_content_hashes(tmp_path):
    bundle = {"TowingPlant.fmu": b"p", "TowingController.fmu": b"c"}
    c = campaign.load_campaign(write(tmp_path, ""))
    a = campaign.run_id(bundle, b"scenario", {"architecture": 1}, 60.0, c)
    assert a == campaign.run_id(dict(reversed(bundle.items())), b"scenario", {"architecture": 1}, 60.0, c)
    others = {campaign.run_id({**bundle, "TowingPlant.fmu": b"q"}, b"scenario", {"architecture": 1}, 60.0, c),
              campaign.run_id(bundle, b"scenario2", {"architecture": 1}, 60.0, c),
              campaign.run_id(bundle, b"scenario", {"architecture": 2}, 60.0, c),
              campaign.run_id(bundle, b"scenario", {"architecture": 1}, 61.0, c)}
    assert a not in others and len(others) == 4


def test_random_scenarios_come_from_the_generator_into_the_output_folder(tmp_path):
    c = campaign.load_campaign(write(tmp_path, "[random]\nseed = 7\ncount = 3\nhazards = 0.5\n[parameters]\narchitecture = [1, 2]\n"))
    bundle = {"TowingPlant.fmu": b"p"}
    runs = campaign.plan(c, tmp_path / "out", bundle)
    assert [(r["scenario"], r["parameters"]["architecture"]) for r in runs] == [
        (name, a) for name in ["paper.toml", *(f"scenarios/random/random-7-{i:04d}.toml" for i in range(3))] for a in (1, 2)]
    written = {p.name: p.read_bytes() for p in (tmp_path / "out" / "scenarios" / "random").iterdir()}
    assert len(written) == 3
    # The same seed, count and options: the same files, hence the same run ids.
    again = campaign.plan(c, tmp_path / "again", bundle)
    assert [r["id"] for r in again] == [r["id"] for r in runs]
    assert {p.name: p.read_bytes() for p in (tmp_path / "again" / "scenarios" / "random").iterdir()} == written
    c["random"]["colour"] = "red"
    with pytest.raises(campaign.CampaignError, match="colour"):
        campaign.plan(c, tmp_path / "bad", bundle)

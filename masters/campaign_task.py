"""One run of a campaign, as a Dask task (docs/campaigns.md).

This module is what travels to the workers: `masters/campaign.py` registers it with
cloudpickle to be pickled by value, so a worker that has only the project's Python
environment (no repository on its path) can call `execute`. Everything else a run needs
travels as bytes in a *bundle* (the two FMUs, the analyzer binary, this module's source and
the closed-loop master's sources) scattered once to every worker, plus the scenario file's
bytes with each task. `execute` writes the bundle into a directory of its own under the
worker's local directory (once per bundle), then runs

1. the closed loop (`closed_loop.run` of masters/closed_loop.py: fmpy, Gauss-Seidel,
   controller first) with MCAP logs, in a child process: `python campaign_task.py
   simulate SPEC.json`;
2. `analyzer report -q --out REPORT [--thresholds FILE] plant.mcap controller.mcap`,

both within one wall-time limit, and returns the verdict, the metrics and (with keep_logs)
the run's report and log files as bytes. A child process makes an FMU crash (a signal), an
FMU error or a hang fail this run only: the reason is recorded and the worker goes on.
"""

import hashlib
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import time

# Files of the bundle besides the FMUs and the analyzer: the master and this module.
SOURCES = ("campaign_task.py", "closed_loop.py", "fmu_logging.py", "tow_geometry.py")
PLANT, CONTROLLER, ANALYZER = "TowingPlant.fmu", "TowingController.fmu", "analyzer"
STDERR_TAIL = 2000  # characters of a failed child's standard error kept in the reason


def bundle_digest(bundle):
    """sha256 over the bundle's names and contents (the key of its directory on a worker)."""
    h = hashlib.sha256()
    for name in sorted(bundle):
        h.update(name.encode() + b"\0" + hashlib.sha256(bundle[name]).digest())
    return h.hexdigest()


def _local_root():
    """The Dask worker's own local directory, else (outside a worker) the temp directory."""
    try:
        from distributed import get_worker

        return pathlib.Path(get_worker().local_directory)
    except (ImportError, ValueError):
        return pathlib.Path(tempfile.gettempdir())


def materialise(bundle):
    """Writes the bundle into `<local root>/towing-campaign-<digest>/` unless already there;
    returns that directory. Files appear atomically (written aside, then renamed)."""
    base = _local_root() / f"towing-campaign-{bundle_digest(bundle)[:16]}"
    base.mkdir(parents=True, exist_ok=True)
    for name, data in bundle.items():
        path = base / name
        if path.is_file():  # complete: files only appear by rename
            continue
        tmp = path.with_name(f".{name}.{os.getpid()}.tmp")
        tmp.write_bytes(data)
        tmp.chmod(0o755 if name == ANALYZER else 0o644)
        tmp.replace(path)
    return base


def _reason(metric, message):
    return {"metric": metric, "target": None, "t_s": None, "message": message}


def _run_child(cmd, cwd, deadline, limit, what):
    """Runs `cmd` in its own process group until `deadline` (time.monotonic()); returns None
    on success, else the reason it failed (the child's own message, its signal, or the
    wall-time limit)."""
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        _, err = proc.communicate(timeout=max(deadline - time.monotonic(), 0.0))
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return _reason("wall time", f"wall-time limit {limit:g} s exceeded ({what})")
    if proc.returncode == 0:
        return None
    err = err.strip()[-STDERR_TAIL:] or "(no message)"
    if proc.returncode < 0:
        name = signal.Signals(-proc.returncode).name
        return _reason(what, f"{what} killed by signal {name}: {err}")
    return _reason(what, f"{what} failed (exit status {proc.returncode}): {err}")


def execute(spec, bundle, scenario_bytes):
    """Runs one campaign run (see the module documentation) and returns its result:
    {"id", "passed", "reasons", "metrics", "master", "wall_time_s", "files"}.

    `spec`: {"id", "scenario_name", "parameters" (FMI name or plant.NAME -> value),
    "stop_time", "step", "thresholds" (dict or None), "wall_time_limit_s", "keep_logs"}."""
    start = time.monotonic()
    limit = float(spec["wall_time_limit_s"])
    deadline = start + limit
    base = materialise(bundle)
    (base / "runs").mkdir(exist_ok=True)
    run_dir = pathlib.Path(tempfile.mkdtemp(prefix=f"{spec['id'][:16]}-", dir=base / "runs"))
    try:
        scenario = run_dir / spec["scenario_name"]
        scenario.write_bytes(scenario_bytes)
        (run_dir / "spec.json").write_text(json.dumps({**spec, "scenario": str(scenario), "base": str(base)}))
        result = {"id": spec["id"], "passed": False, "reasons": [], "metrics": None, "master": None, "files": {}}
        reason = _run_child([sys.executable, str(base / "campaign_task.py"), "simulate", str(run_dir / "spec.json")], run_dir,
                            deadline, limit, "closed loop")
        if reason is None:
            result["master"] = json.loads((run_dir / "master.json").read_text())
            cmd = [str(base / ANALYZER), "report", "-q", "--out", str(run_dir / "report")]
            if spec["thresholds"] is not None:
                (run_dir / "thresholds.toml").write_text(thresholds_toml(spec["thresholds"]))
                cmd += ["--thresholds", str(run_dir / "thresholds.toml")]
            cmd += [str(run_dir / "logs" / "plant.mcap"), str(run_dir / "logs" / "controller.mcap")]
            reason = _run_child(cmd, run_dir, deadline, limit, "analyzer")
        # The worker's own directories out of what comes back: the same run says the same on
        # every worker (the loader names `paper.toml:61:14: ...`, the analyzer `logs/plant.mcap`).
        local = lambda text: text.replace(f"{run_dir}/", "").replace(f"{base}/", "")  # noqa: E731
        if reason is None:
            judge(result, json.loads(local((run_dir / "report" / "metrics.json").read_text())))
        else:
            reason["message"] = local(reason["message"])
            result["reasons"] = [reason]
        if spec["keep_logs"]:
            result["files"] = collect_files(run_dir)
        result["wall_time_s"] = time.monotonic() - start
        return result
    finally:
        shutil.rmtree(run_dir, ignore_errors=True)


def judge(result, metrics):
    """The analyzer's verdict into `result`; metrics without a verdict fail the run."""
    verdict = metrics.pop("verdict", None)
    result["metrics"] = metrics
    if not isinstance(verdict, dict) or "passed" not in verdict:
        result["reasons"] = [_reason("verdict", "analyzer gave no verdict")]
        return
    result["passed"] = bool(verdict["passed"])
    result["reasons"] = list(verdict.get("reasons", []))


def collect_files(run_dir):
    """The run's report (as `report.html`, ... at the top) and its logs (`logs/...`) as bytes."""
    files = {}
    for sub, prefix in ((run_dir / "report", ""), (run_dir / "logs", "logs/")):
        if sub.is_dir():
            for path in sorted(p for p in sub.rglob("*") if p.is_file()):
                files[prefix + path.relative_to(sub).as_posix()] = path.read_bytes()
    return files


def thresholds_toml(thresholds):
    """The [thresholds] table of a campaign as the analyzer's thresholds file (numbers only)."""
    return "".join(f"{k} = {float(v)!r}\n" for k, v in sorted(thresholds.items()))


def fmi_text(value):
    """A parameter value as closed_loop.py's NAME=VALUE text (floats exact, booleans true/false)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def simulate(spec_path):
    """Child process: the closed loop of masters/closed_loop.py on the spec, with MCAP logs in
    RUN/logs/ and the master's summary in RUN/master.json. Exit status 1 on an FMU error
    (the message and the FMUs' logged messages on stderr), 2 on a usage error."""
    spec = json.loads(pathlib.Path(spec_path).read_text())
    run_dir = pathlib.Path(spec_path).parent
    sys.path.insert(0, spec["base"])
    import closed_loop
    from fmu_logging import MessageLog

    argv = ["--plant", str(pathlib.Path(spec["base"]) / PLANT), "--controller", str(pathlib.Path(spec["base"]) / CONTROLLER),
            "--scenario", spec["scenario"], "--stop-time", repr(float(spec["stop_time"])), "--step", repr(float(spec["step"])),
            "--log-dir", str(run_dir / "logs"), "--run-id", spec["id"], "--quiet"]
    for name, value in spec["parameters"].items():
        if name.startswith("plant."):
            argv += ["--plant-param", f"{name[len('plant.'):]}={fmi_text(value)}"]
        else:
            argv += ["--param", f"{name}={fmi_text(value)}"]
    args = closed_loop.build_parser().parse_args(argv)
    log = MessageLog()
    workdir = None
    try:
        _, _, summary, _, workdir = closed_loop.run(args, log)
    except closed_loop.UsageError as e:
        print(f"{e}\n{log.text('WARNING')}".strip(), file=sys.stderr)
        return 2
    except (closed_loop.FmuError, closed_loop.FMICallException) as e:
        text = log.text("WARNING")
        print(f"{e}" + (f"\nmessages logged by the FMUs: {text}" if text else ""), file=sys.stderr)
        return 1
    finally:
        if workdir:
            shutil.rmtree(workdir, ignore_errors=True)
    (run_dir / "master.json").write_text(json.dumps(summary))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] != "simulate":
        print("usage: campaign_task.py simulate SPEC.json (a child process of a campaign task)", file=sys.stderr)
        sys.exit(2)
    sys.exit(simulate(sys.argv[2]))

"""Campaigns: many closed-loop runs judged by the analyzer, on Dask (docs/campaigns.md).

    .venv/bin/python masters/campaign.py CAMPAIGN.toml --out DIR --plant FMU --controller FMU
        --analyzer BIN [--workers N] [--scheduler tcp://HOST:PORT] [--resume]

(`cargo xtask campaign` packages the FMUs, builds the analyzer and calls this.) The
campaign file names scenarios and controller/plant parameter values; every scenario runs
with every combination of the values. Each run is one Dask task (masters/campaign_task.py):
the FMUs in closed loop under fmpy, then `analyzer report` on the logs, in child processes
with a wall-time limit. The tasks run on an embedded LocalCluster of N worker processes, or
on an existing cluster (--scheduler) whose workers need only the project's Python
environment: the task module, the FMUs, the analyzer and the scenarios travel with the
tasks, results come back here. Writes DIR/runs/<id>/result.json as each run returns, and
at the end DIR/summary.json, DIR/runs.parquet, DIR/report.html and DIR/report.md.

Exit status: 0 when the campaign ran (whether or not its runs passed), 2 on a bad campaign
file or command line, 1 when the cluster failed.
"""

import argparse
import glob
import hashlib
import itertools
import json
import logging
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import time
import tomllib
import xml.etree.ElementTree as ET
import zipfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import campaign_report  # noqa: E402
import campaign_task  # noqa: E402
import tow_geometry  # noqa: E402

MASTERS = pathlib.Path(__file__).resolve().parent
KEYS = {"name", "scenarios", "parameters", "random", "stop_time", "thresholds", "step", "wall_time_limit_s", "keep_logs"}
DEFAULTS = {"stop_time": "arrival", "step": 0.1, "wall_time_limit_s": 600.0, "keep_logs": False}
# The "arrival" stop time: route length / ARRIVAL_SPEED + ARRIVAL_MARGIN, the analyzer's
# arrival verdict (its thresholds arrival_speed_m_s and arrival_margin_s, which a
# [thresholds] table may change, and then changes here too).
ARRIVAL_SPEED, ARRIVAL_MARGIN = 0.05, 300.0
# Parameters the campaign sets itself on both FMUs (run_id: the run's id, in both logs).
RESERVED = {"scenario", "log_file", "run_id"}
FMI_TYPES = ("Real", "Integer", "Enumeration", "Boolean", "String")


class CampaignError(Exception):
    """A bad campaign file or command line (exit status 2), naming the key and the reason."""


# --------------------------------------------------------------------------- the file


def _number(table, key, where, positive=True):
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or (positive and value <= 0):
        raise CampaignError(f"{where}: '{key}' must be a {'positive ' if positive else ''}finite number, got {value!r}")
    return float(value)


def load_campaign(path):
    """The campaign file, validated, with defaults filled in (see docs/campaigns.md)."""
    path = pathlib.Path(path)
    try:
        with open(path, "rb") as f:
            raw = tomllib.load(f)
    except OSError as e:
        raise CampaignError(f"{path}: cannot read: {e}") from None
    except tomllib.TOMLDecodeError as e:
        raise CampaignError(f"{path}: not valid TOML: {e}") from None
    unknown = sorted(set(raw) - KEYS)
    if unknown:
        raise CampaignError(f"{path}: unknown key(s) {', '.join(map(repr, unknown))} (known: {', '.join(sorted(KEYS))})")
    c = {**DEFAULTS, **raw, "file": path.resolve()}
    if not isinstance(c.get("name"), str) or not c["name"].strip():
        raise CampaignError(f"{path}: 'name' must be a non-empty string, got {c.get('name')!r}")
    scenarios = c.setdefault("scenarios", [])
    if not isinstance(scenarios, list) or not all(isinstance(s, str) and s for s in scenarios):
        raise CampaignError(f"{path}: 'scenarios' must be a list of paths or globs (strings), got {scenarios!r}")
    if not scenarios and "random" not in c:
        raise CampaignError(f"{path}: no 'scenarios' and no [random] table: the campaign has nothing to run")
    c["parameters"] = _parameters(c.get("parameters", {}), path)
    if c["stop_time"] != "arrival":
        c["stop_time"] = _number(c, "stop_time", f"{path}: 'stop_time' is \"arrival\" or a number of seconds;")
    c["step"] = _number(c, "step", str(path))
    c["wall_time_limit_s"] = _number(c, "wall_time_limit_s", str(path))
    if not isinstance(c["keep_logs"], bool):
        raise CampaignError(f"{path}: 'keep_logs' must be true or false, got {c['keep_logs']!r}")
    c["thresholds"] = _thresholds(c.get("thresholds"), path)
    c["random"] = _random(c.get("random"), path)
    return c


def _flatten(table, prefix=""):
    """A TOML table whose dotted keys (`admm.rho = [...]`, `plant.model.hull = [...]`) TOML
    nests, as one level of dotted names: parameter names are grouped `group.name`."""
    flat = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, f"{name}."))
        else:
            flat[name] = value
    return flat


def _parameters(table, path):
    if not isinstance(table, dict):
        raise CampaignError(f"{path}: [parameters] must be a table of NAME = [values], got {table!r}")
    table = _flatten(table)
    for name, values in table.items():
        where = f"{path}: [parameters] {name}"
        if not isinstance(values, list) or not values:
            raise CampaignError(f"{where}: must be a non-empty list of values, got {values!r}")
        for v in values:
            if not isinstance(v, (bool, int, float, str)) or (isinstance(v, float) and not math.isfinite(v)):
                raise CampaignError(f"{where}: value {v!r} is not a finite number, a boolean or a string")
        if len({json.dumps(v) for v in values}) != len(values):
            raise CampaignError(f"{where}: repeated value in {values!r}")
        if name.removeprefix("plant.") in RESERVED:
            raise CampaignError(f"{where}: set by the campaign itself (the scenario file, the run's logs and id)")
    return dict(table)


def _thresholds(table, path):
    if table is None:
        return None
    if not isinstance(table, dict):
        raise CampaignError(f"{path}: [thresholds] must be a table of NAME = number")
    for key in table:
        _number(table, key, f"{path}: [thresholds]", positive=False)
        if table[key] < 0:
            raise CampaignError(f"{path}: [thresholds] '{key}' must be >= 0, got {table[key]!r}")
    return {k: float(v) for k, v in table.items()}


def _random(table, path):
    if table is None:
        return None
    if not isinstance(table, dict):
        raise CampaignError(f"{path}: [random] must be a table with 'seed', 'count' and generator options")
    for key in ("seed", "count"):
        v = table.get(key)
        if isinstance(v, bool) or not isinstance(v, int) or v < (1 if key == "count" else 0):
            raise CampaignError(f"{path}: [random] '{key}' must be an integer >= {1 if key == 'count' else 0}, got {v!r}")
    return dict(table)


# --------------------------------------------------------------------------- the runs


def scenario_files(c, out):
    """The campaign's scenario files in order: each entry of `scenarios` (globs sorted,
    repeats dropped), then the [random] ones written into OUT/scenarios/random/."""
    base = c["file"].parent
    files, seen = [], set()
    for entry in c["scenarios"]:
        pattern = entry if os.path.isabs(entry) else str(base / entry)
        matches = sorted(glob.glob(pattern, recursive=True)) if glob.has_magic(entry) else [pattern]
        if not matches:
            raise CampaignError(f"{c['file']}: 'scenarios' entry {entry!r} matches no file")
        for m in matches:
            p = pathlib.Path(m).resolve()
            if not p.is_file():
                raise CampaignError(f"{c['file']}: 'scenarios' entry {entry!r}: {p} is not a file")
            if p not in seen:
                seen.add(p)
                files.append(p)
    if c["random"] is not None:
        files += random_files(c, out)
    return files


def random_files(c, out):
    try:
        import encounters
    except ImportError as e:
        raise CampaignError(f"{c['file']}: [random] needs the generator masters/encounters.py: {e}") from None
    options = {k: v for k, v in c["random"].items() if k not in ("seed", "count")}
    try:
        paths = encounters.random_scenarios(out / "scenarios" / "random", c["random"]["seed"], c["random"]["count"], **options)
    except (ValueError, TypeError) as e:
        raise CampaignError(f"{c['file']}: [random]: {e}") from None
    return [pathlib.Path(p).resolve() for p in paths]


def fmu_parameters(fmu):
    """{name: (FMI type, min, max, items)} of the FMU's parameters, from the
    modelDescription.xml inside it (min and max None when not given; items, for an
    Enumeration, the [(value, name)] of its declared type, FMI 2.0 section 2.2.3)."""
    try:
        with zipfile.ZipFile(fmu) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
    except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as e:
        raise CampaignError(f"{fmu}: cannot read its modelDescription.xml: {e}") from None
    enumerations = {
        t.get("name"): [(int(i.get("value")), i.get("name")) for i in t.iter("Item")]
        for t in root.iter("SimpleType") if t.find("Enumeration") is not None
    }
    out = {}
    for v in root.iter("ScalarVariable"):
        if v.get("causality") == "parameter":
            types = [child for child in v if child.tag in FMI_TYPES]
            bound = lambda key: float(types[0].get(key)) if types and types[0].get(key) is not None else None  # noqa: E731
            items = enumerations.get(types[0].get("declaredType")) if types and types[0].tag == "Enumeration" else None
            out[v.get("name")] = (types[0].tag if types else None, bound("min"), bound("max"), items)
    return out


def check_parameters(c, plant, controller):
    """Every [parameters] name against the FMUs' parameters and their types."""
    fmus = {"controller": fmu_parameters(controller), "plant": fmu_parameters(plant)}
    for name, values in c["parameters"].items():
        side, fmi = ("plant", name[len("plant."):]) if name.startswith("plant.") else ("controller", name)
        kind, low, high, items = fmus[side].get(fmi, ("missing", None, None, None))
        if kind == "missing":
            raise CampaignError(f"{c['file']}: [parameters] {name}: the {side} FMU has no parameter '{fmi}' "
                                f"(its parameters: {', '.join(sorted(fmus[side]))})")
        ok = {
            "Real": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
            "Integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
            "Enumeration": lambda v: isinstance(v, int) and not isinstance(v, bool),
            "Boolean": lambda v: isinstance(v, bool),
            "String": lambda v: isinstance(v, str),
        }.get(kind, lambda v: False)
        bad = [v for v in values if not ok(v)]
        if bad:
            raise CampaignError(f"{c['file']}: [parameters] {name}: {side} parameter '{fmi}' is {kind}, got {bad[0]!r}")
        if items is not None:
            unknown = [v for v in values if v not in {value for value, _ in items}]
            if unknown:
                choices = ", ".join(f"{value} {name}" for value, name in items)
                raise CampaignError(f"{c['file']}: [parameters] {name}: {side} parameter '{fmi}' must be one of {choices} "
                                    f"(its modelDescription), got {unknown[0]!r}")
        outside = [v for v in values if not isinstance(v, (bool, str)) and ((low is not None and v < low) or (high is not None and v > high))]
        if outside:
            raise CampaignError(f"{c['file']}: [parameters] {name}: {side} parameter '{fmi}' must be in [{'-inf' if low is None else f'{low:g}'}, {'inf' if high is None else f'{high:g}'}] "
                                f"(its modelDescription), got {outside[0]!r}")


def check_thresholds(c, analyzer):
    """The [thresholds] table against the analyzer's own thresholds, before anything runs:
    the analyzer reads the thresholds file before the logs, so a run on two missing logs
    fails on the thresholds when they are bad (naming the key), else on the logs."""
    if c["thresholds"] is None:
        return
    with tempfile.TemporaryDirectory(prefix="campaign-thresholds-") as d:
        path = pathlib.Path(d) / "thresholds.toml"
        path.write_text(campaign_task.thresholds_toml(c["thresholds"]))
        r = subprocess.run([str(analyzer), "report", "-q", "--thresholds", str(path), "--out", str(pathlib.Path(d) / "out"),
                            str(pathlib.Path(d) / "none-plant.mcap"), str(pathlib.Path(d) / "none-controller.mcap")],
                           capture_output=True, text=True, timeout=60)
    if f"thresholds {path}" in r.stderr:
        raise CampaignError(f"{c['file']}: [thresholds]: {r.stderr.strip().replace(str(path), 'the table')}")


def configurations(c):
    """The cartesian product of the [parameters] values: file order of the names, list order
    of the values (the first name varies slowest). One empty configuration without any."""
    names = list(c["parameters"])
    return [dict(zip(names, combo)) for combo in itertools.product(*(c["parameters"][n] for n in names))]


def configuration_label(parameters):
    return ", ".join(f"{k}={v}" for k, v in parameters.items()) or "defaults"


def stop_time(c, scenario):
    """The run's stop time, s: a number, or "arrival" = route length / arrival speed +
    arrival margin (origin, waypoints, destination), rounded up to a whole step."""
    if c["stop_time"] != "arrival":
        return c["stop_time"]
    t = c["thresholds"] or {}
    route = tow_geometry.route_points(tow_geometry.load_scenario(scenario))
    length = float(sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(route[:-1], route[1:])))
    raw = length / t.get("arrival_speed_m_s", ARRIVAL_SPEED) + t.get("arrival_margin_s", ARRIVAL_MARGIN)
    return round(math.ceil(raw / c["step"] - 1e-9) * c["step"], 9)


def sha256(data):
    return hashlib.sha256(data).hexdigest()


def bundle_for(plant, controller, analyzer):
    """What travels to every worker once: the FMUs, the analyzer, the task and master sources."""
    bundle = {campaign_task.PLANT: pathlib.Path(plant).read_bytes(), campaign_task.CONTROLLER: pathlib.Path(controller).read_bytes(),
              campaign_task.ANALYZER: pathlib.Path(analyzer).read_bytes()}
    for name in campaign_task.SOURCES:
        bundle[name] = (MASTERS / name).read_bytes()
    return bundle


def run_id(bundle, scenario_bytes, parameters, stop, c):
    """sha256 of the canonical JSON (sorted keys, no spaces) of everything a run's result
    depends on: the bundle's file hashes (FMUs, analyzer, master and task sources), the
    scenario file's hash, the parameters, the stop time, the step and the thresholds."""
    doc = {"files": {name: sha256(data) for name, data in sorted(bundle.items())}, "scenario": sha256(scenario_bytes),
           "parameters": parameters, "stop_time": stop, "step": c["step"], "thresholds": c["thresholds"]}
    return sha256(json.dumps(doc, sort_keys=True, separators=(",", ":")).encode())


def display_name(path, c, out):
    """A scenario's name in the outputs: relative to DIR for the generated ones, else
    relative to the campaign file's folder (`../scenarios/suites/imazu/imazu-01.toml`)."""
    try:
        return path.relative_to(out.resolve()).as_posix()
    except ValueError:
        return pathlib.Path(os.path.relpath(path, c["file"].parent)).as_posix()


def plan(c, out, bundle):
    """The campaign's runs in its deterministic order: scenarios (in file order) outer,
    configurations inner. A scenario whose route cannot be read for the "arrival" stop time
    becomes a run that failed before it started (`error`)."""
    runs = []
    configs = configurations(c)
    for path in scenario_files(c, out):
        data = path.read_bytes()
        try:
            stop, error = stop_time(c, path), None
        except (OSError, KeyError, TypeError, ValueError, IndexError, tomllib.TOMLDecodeError) as e:
            stop, error = None, f"stop time \"arrival\": cannot read the route of {path}: {type(e).__name__}: {e}"
        for params in configs:
            runs.append({"id": run_id(bundle, data, params, stop, c), "scenario": display_name(path, c, out), "path": path,
                         "bytes": data, "parameters": params, "configuration": configuration_label(params), "stop_time": stop,
                         "error": error})
    return runs


# --------------------------------------------------------------------------- running


def spec_of(run, c):
    """What a task needs to know about its run (plain JSON)."""
    return {"id": run["id"], "scenario_name": run["path"].name, "parameters": run["parameters"], "stop_time": run["stop_time"],
            "step": c["step"], "thresholds": c["thresholds"], "wall_time_limit_s": c["wall_time_limit_s"], "keep_logs": c["keep_logs"]}


def failed_result(run, metric, message):
    return {"id": run["id"], "passed": False, "metrics": None, "master": None, "files": {}, "wall_time_s": 0.0,
            "reasons": [{"metric": metric, "target": None, "t_s": None, "message": message}]}


def store(out, run, result):
    """DIR/runs/<id>/result.json (the run's record) and, when kept, its report and logs."""
    d = out / "runs" / run["id"]
    d.mkdir(parents=True, exist_ok=True)
    for name, data in result.pop("files", {}).items():
        (d / name).parent.mkdir(parents=True, exist_ok=True)
        (d / name).write_bytes(data)
    record = {"id": run["id"], "scenario": run["scenario"], "configuration": run["configuration"], "parameters": run["parameters"],
              "stop_time_s": run["stop_time"], **{k: v for k, v in result.items() if k != "id"}}
    tmp = d / "result.json.tmp"
    tmp.write_text(json.dumps(record, indent=1) + "\n")  # key order kept: summaries rebuilt from it read the same
    tmp.replace(d / "result.json")
    return record


def finished(out, run):
    """The stored record of `run` if DIR/runs/<id>/result.json holds it, else None."""
    try:
        record = json.loads((out / "runs" / run["id"] / "result.json").read_text())
    except (OSError, ValueError):
        return None
    return record if record.get("id") == run["id"] else None


class Progress:
    """done / total, failures so far and the time left on stderr: one rewritten line on a
    terminal, else a line every EVERY runs (and the last)."""

    EVERY = 10

    def __init__(self, total, skipped):
        self.total, self.done, self.failed = total, skipped, 0
        self.start, self.base = time.monotonic(), skipped
        self.tty = sys.stderr.isatty()

    def update(self, record):
        self.done += 1
        self.failed += not record["passed"]
        ran = self.done - self.base
        left = (time.monotonic() - self.start) / ran * (self.total - self.done)
        line = f"campaign: {self.done}/{self.total} runs, {self.failed} failed, about {left:.0f} s left"
        if self.tty:
            print("\r" + line, end="\n" if self.done == self.total else "", file=sys.stderr, flush=True)
        elif ran % self.EVERY == 0 or self.done == self.total:
            print(line, file=sys.stderr, flush=True)


def start_client(args):
    """A Dask client: of the cluster at --scheduler, else of an embedded LocalCluster."""
    from distributed import Client, LocalCluster

    if args.scheduler:
        return Client(args.scheduler, timeout="30s"), None
    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


class ByValue:
    """A function that pickles as its code (cloudpickle, by value), for a scheduler and
    workers that cannot import its module. Dask pickles a task graph with plain pickle when
    it can, which writes a module function as a reference by name, whatever cloudpickle's
    registry says; this wrapper's __reduce__ hands pickle the function's cloudpickle bytes
    and `cloudpickle.loads` (importable wherever Dask is) to rebuild it."""

    def __init__(self, fn):
        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[fn.__module__])
        self.fn = fn
        self.payload = cloudpickle.dumps(fn)

    def __call__(self, *args, **kwargs):
        return self.fn(*args, **kwargs)

    def __reduce__(self):
        import cloudpickle

        return cloudpickle.loads, (self.payload,)


def execute_all(todo, c, bundle, args, out, on_record):
    """Submits every run of `todo` as a task and stores each result as it returns."""
    from distributed import as_completed

    # The workers may not have the repository: the task module goes with the tasks by value.
    task = ByValue(campaign_task.execute)
    client, cluster = start_client(args)
    try:
        [bundle_future] = client.scatter([bundle], broadcast=True)
        futures = {}
        for run in todo:
            f = client.submit(task, spec_of(run, c), bundle_future, run["bytes"], key=f"run-{run['id']}", pure=False)
            futures[f] = run
        for f in as_completed(futures):
            run = futures[f]
            try:
                result = f.result()
            except Exception as e:  # noqa: BLE001 - a lost worker or a task error fails this run only
                result = failed_result(run, "task", f"the task failed on the worker: {type(e).__name__}: {e}")
            on_record(store(out, run, result))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_campaign(args):
    """Plans, runs (or resumes) and reports the campaign; returns the records in plan order."""
    c = load_campaign(args.campaign)
    out = pathlib.Path(args.out)
    for name, p in (("--plant", args.plant), ("--controller", args.controller), ("--analyzer", args.analyzer)):
        if not pathlib.Path(p).is_file():
            raise CampaignError(f"{name}: {p} is not a file")
    check_parameters(c, args.plant, args.controller)
    check_thresholds(c, args.analyzer)
    out.mkdir(parents=True, exist_ok=True)
    bundle = bundle_for(args.plant, args.controller, args.analyzer)
    runs = plan(c, out, bundle)
    records = {}
    for run in runs:
        if args.resume and run["id"] not in records and (record := finished(out, run)) is not None:
            records[run["id"]] = record
    unique = list({r["id"]: r for r in runs if r["id"] not in records}.values())
    print(f"campaign {c['name']}: {len(runs)} runs ({len(records)} already finished, skipped), "
          f"{'cluster ' + args.scheduler if args.scheduler else f'{args.workers} local workers'}", file=sys.stderr, flush=True)
    progress = Progress(len(records) + len(unique), len(records))

    def on_record(record):
        records[record["id"]] = record
        progress.update(record)

    for run in [r for r in unique if r["error"]]:
        on_record(store(out, run, failed_result(run, "scenario", run["error"])))
    todo = [r for r in unique if not r["error"]]
    if todo:
        execute_all(todo, c, bundle, args, out, on_record)
    ordered = [{**records[r["id"]], "scenario": r["scenario"], "configuration": r["configuration"]} for r in runs]
    campaign_report.write_all(out, c["name"], ordered, keep_logs=c["keep_logs"])
    passed = sum(r["passed"] for r in ordered)
    print(f"campaign {c['name']}: {passed}/{len(ordered)} runs passed; {out / 'report.html'}", file=sys.stderr)
    return ordered


def build_parser():
    p = argparse.ArgumentParser(prog="campaign.py", description=__doc__.split("\n\n")[0])
    p.add_argument("campaign", metavar="FILE", help="campaign TOML (docs/campaigns.md)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--plant", required=True, metavar="FMU", help="TowingPlant.fmu")
    p.add_argument("--controller", required=True, metavar="FMU", help="TowingController.fmu")
    p.add_argument("--analyzer", required=True, metavar="BIN", help="the analyzer binary (target/release/analyzer)")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1, metavar="N", help="local worker processes (default: the cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, tcp://HOST:PORT (then --workers is unused)")
    p.add_argument("--resume", action="store_true", help="skip runs already finished in DIR (same run id)")
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    if args.workers < 1:
        print("campaign.py: error: --workers must be >= 1", file=sys.stderr)
        return 2
    try:
        run_campaign(args)
    except CampaignError as e:
        print(f"campaign.py: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"campaign.py: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

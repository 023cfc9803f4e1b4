"""Closed loop of TowingController and TowingPlant under fmpy (FMI 2.0 Co-Simulation).

Loads both FMUs with fmpy's FMU2Slave, connects them by name and steps them with a fixed
communication step h in Gauss-Seidel order, the controller first:

    for t = 0, h, 2h, ... < stop time:
        plant outputs(t)        -> controller inputs
        controller.doStep(t, h)
        controller outputs      -> plant inputs
        plant.doStep(t, h)

or, with --coupling jacobi, in Jacobi order (as libcosim and fmpy's SSP runner do; the plant
then applies over (t, t + h] the commands the controller computed in the step before):

    for t = 0, h, 2h, ... < stop time:
        plant outputs(t)        -> controller inputs
        controller outputs(t)   -> plant inputs
        controller.doStep(t, h), plant.doStep(t, h)

Connections are discovered from the two modelDescriptions, never listed by hand: every
controller input takes the plant output of the same name, every plant input takes the
controller output of the same name (the interface contract of DESIGN.md and
docs/interface.md). A controller input without a plant output, a plant input without a
controller output, or a pair of different types stops the run before it starts, naming the
variables. Controller outputs without a plant input (diagnostics) are only recorded.

Usage (from the repository root, with the project's .venv):

    .venv/bin/python masters/closed_loop.py                       # paper scenario, 1200 s
    .venv/bin/python masters/closed_loop.py --architecture 2 --scheme 3 --out out/central-3
    .venv/bin/python masters/closed_loop.py --stop-time 60 --param admm.rho=2.0 --quiet

Options:
    --plant FMU, --controller FMU   default target/fmu/TowingPlant.fmu, TowingController.fmu
    --scenario PATH                 set as `scenario` on both FMUs; default empty = the
                                    plant's bundled paper scenario
    --stop-time S (1200), --step H (0.1)
    --architecture {1,2}            1 distributed (ADMM), 2 centralized
    --scheme {1,2,3}                avoidance scheme I, II, III of Du et al. (2022)
    --param NAME=VALUE              any controller parameter, typed from its
                                    modelDescription (repeatable); an Enumeration takes
                                    its value or an item's name (architecture=centralized)
    --plant-param NAME=VALUE        the same for the plant (e.g. model.hull_from_scenario=false)
    --coupling {gauss-seidel,jacobi}  order of a communication step (default gauss-seidel)
    --log-dir DIR                   MCAP logs (docs/logging.md): sets `log_file` to
                                    DIR/plant.mcap and DIR/controller.mcap (created)
    --run-id ID                     set as `run_id` on both FMUs, so both logs name the
                                    same run (default: a new one, UTC time + random hex)
    --out DIR (out/closed-loop), --map-size WxH (pixels, 1400x1200), --quiet

Writes:
    DIR/timeseries.csv  header `time` + every plant output + every controller output (the
                        diagnostics included), in modelDescription order; one row at t = 0
                        after initialization and one row per communication step. Row k
                        (t_k = k h) holds the plant outputs at t_k and the controller outputs
                        after controller.doStep(t_{k-1}, h), i.e. the commands the plant
                        applied over (t_{k-1}, t_k] (with --coupling jacobi, over
                        (t_k, t_{k+1}]). Booleans are written as 0/1.
    DIR/map.png         East horizontal, North vertical, equal aspect: route, ship and tug
                        tracks, static hazards and target ships at real size, vessel
                        outlines every ~100 s, start and end markers.
    DIR/summary.json    stop time, wall time (and the master thread's CPU time) of the
                        stepping loop, steps, fallbacks, warnings, compute time and
                        ADMM iteration statistics over the controller samples, final ship pose,
                        the run id, the log files (with --log-dir).
    LOG/plant.mcap, LOG/controller.mcap   with --log-dir LOG; open both in Foxglove
                        (docs/foxglove.md).

fmpy's FMU2Slave raises FMICallException for every status above fmi2Warning and returns
warnings silently; this master calls fmi2DoStep itself to see the status, counts warnings
(an MPC fallback is fmi2OK, counted in the controller's `controller.fallbacks`; fmi2Warning
only with --param fmi.warning_on_fallback=true) and stops on anything worse, printing the
messages both FMUs logged. Exit status: 0 on success, 1 on an FMU error, 2 on a usage or
connection error.
"""

import argparse
import json
import math
import pathlib
import shutil
import sys
import tempfile
import time
import uuid

import fmpy
import numpy as np
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2Boolean, fmi2Integer, fmi2Real, fmi2True, fmi2ValueReference

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import tow_geometry  # noqa: E402
from fmu_logging import MessageLog  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
DEFAULT_PLANT = ROOT / "target" / "fmu" / "TowingPlant.fmu"
DEFAULT_CONTROLLER = ROOT / "target" / "fmu" / "TowingController.fmu"
PROGRESS_EVERY = 100.0  # simulated seconds between progress lines
OUTLINE_EVERY = 100.0  # simulated seconds between vessel outlines on the map

# FMI base type of a variable -> (ctypes element type, get function, set function).
CTYPES = {
    "Real": (fmi2Real, "fmi2GetReal", "fmi2SetReal"),
    "Integer": (fmi2Integer, "fmi2GetInteger", "fmi2SetInteger"),
    "Boolean": (fmi2Boolean, "fmi2GetBoolean", "fmi2SetBoolean"),
}
TYPES = tuple(CTYPES)

# Names of controller diagnostics the summary uses (interface of TowingController).
FALLBACKS = "controller.fallbacks"
COMPUTE_TIME = "controller.compute_time"
ITERATIONS = "admm.iterations"
SAMPLES = "controller.samples"


class UsageError(Exception):
    """Bad command line or FMUs that cannot be connected (exit status 2)."""


class FmuError(Exception):
    """An FMU returned fmi2Discard, fmi2Error or fmi2Fatal (exit status 1)."""


def base_type(var):
    return "Integer" if var.type == "Enumeration" else var.type


# --------------------------------------------------------------------------- connections


def discover_connections(plant_vars, controller_vars):
    """Pairs (plant output -> controller input) and (controller output -> plant input) by name.

    `*_vars` are modelDescription variables (anything with .name, .causality, .type). Returns
    {"to_controller": [(name, type)], "to_plant": [(name, type)]} in the receiver's
    modelDescription order. Raises UsageError naming every input that cannot be fed."""
    plant_out = {v.name: v for v in plant_vars if v.causality == "output"}
    ctrl_out = {v.name: v for v in controller_vars if v.causality == "output"}
    problems = []
    to_controller, to_plant = [], []
    for receiver, sender_outputs, sender, pairs, vars_ in (
        ("controller", plant_out, "plant", to_controller, controller_vars),
        ("plant", ctrl_out, "controller", to_plant, plant_vars),
    ):
        for v in vars_:
            if v.causality != "input":
                continue
            src = sender_outputs.get(v.name)
            if src is None:
                problems.append(f"{receiver} input '{v.name}' has no {sender} output of the same name")
            elif base_type(src) != base_type(v):
                problems.append(f"{receiver} input '{v.name}' is {v.type} but the {sender} output of that name is {src.type}")
            elif base_type(v) not in CTYPES:
                problems.append(f"{receiver} input '{v.name}' has type {v.type}, which this master does not connect")
            else:
                pairs.append((v.name, base_type(v)))
    if problems:
        raise UsageError("cannot connect the FMUs by name:\n  " + "\n  ".join(problems))
    return {"to_controller": to_controller, "to_plant": to_plant}


class Unit:
    """One FMU instance with preallocated value-reference and value buffers."""

    def __init__(self, name, fmu_path, log, workdir):
        self.name = name
        self.path = str(fmu_path)
        if not pathlib.Path(self.path).is_file():
            raise UsageError(f"{name} FMU not found: {self.path}")
        self.md = fmpy.read_model_description(self.path)
        if self.md.coSimulation is None:
            raise UsageError(f"{self.path} is not a Co-Simulation FMU")
        self.unzipdir = fmpy.extract(self.path, str(pathlib.Path(workdir) / name))
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.slave = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=self.unzipdir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.slave.instantiate(callbacks=log.callbacks)
        self.component = self.slave.component
        # Every output, grouped by type, read with one call per type per step.
        self.outputs = [v for v in self.md.modelVariables if v.causality == "output"]
        self.out_names = {t: [v.name for v in self.outputs if base_type(v) == t] for t in TYPES}
        self.out_vr = {t: _vr_array([self.vars[n].valueReference for n in self.out_names[t]]) for t in TYPES}
        self.out_buf = {t: (CTYPES[t][0] * len(self.out_names[t]))() for t in TYPES}
        self.out_np = {t: np.ctypeslib.as_array(self.out_buf[t]) if self.out_names[t] else np.zeros(0) for t in TYPES}
        self._get = {t: getattr(self.slave, CTYPES[t][1]) for t in TYPES}
        self._set = {t: getattr(self.slave, CTYPES[t][2]) for t in TYPES}
        self.in_vr, self.in_buf, self.in_np = {}, {}, {}
        self.freed = False
        self.fatal = False

    def failed(self, e, what):
        """An FMICallException of this instance as an FmuError that names the instance."""
        self.fatal = self.fatal or getattr(e, "status", 0) == 4
        return FmuError(f"{self.name} ({self.md.coSimulation.modelIdentifier}): {what}: {e}")

    def prepare_inputs(self, names_by_type):
        for t in TYPES:
            names = names_by_type.get(t, [])
            self.in_vr[t] = _vr_array([self.vars[n].valueReference for n in names])
            self.in_buf[t] = (CTYPES[t][0] * len(names))()
            self.in_np[t] = np.ctypeslib.as_array(self.in_buf[t]) if names else np.zeros(0)

    def read_outputs(self):
        """One fmi2Get<Type> per type into the output buffers; returns the number of warnings."""
        warnings = 0
        try:
            for t in TYPES:
                n = len(self.out_vr[t])
                if n:
                    warnings += self._get[t](self.component, self.out_vr[t], n, self.out_buf[t]) == 1
        except FMICallException as e:
            raise self.failed(e, "reading outputs") from None
        return warnings

    def write_inputs(self):
        warnings = 0
        try:
            for t in TYPES:
                n = len(self.in_vr[t])
                if n:
                    warnings += self._set[t](self.component, self.in_vr[t], n, self.in_buf[t]) == 1
        except FMICallException as e:
            raise self.failed(e, "setting inputs") from None
        return warnings

    def do_step(self, t, h):
        """fmi2DoStep; returns 1 for fmi2Warning, 0 for fmi2OK, raises above warning."""
        try:
            return int(self.slave.fmi2DoStep(self.component, t, h, fmi2True) == 1)
        except FMICallException as e:
            raise self.failed(e, f"doStep(t = {t:.9g} s, h = {h:.9g} s)") from None

    def call(self, what, fn, *args):
        """A life-cycle call (setupExperiment, ...) with errors naming the instance."""
        try:
            return fn(*args)
        except FMICallException as e:
            raise self.failed(e, what) from None

    def set_parameter(self, name, text):
        """Sets parameter `name` from its command-line text, typed from the modelDescription."""
        v = self.vars.get(name)
        if v is None or v.causality != "parameter":
            params = sorted(n for n, x in self.vars.items() if x.causality == "parameter")
            raise UsageError(f"{self.name} has no parameter '{name}' (parameters: {', '.join(params)})")
        vr = [v.valueReference]
        try:
            if v.type == "Real":
                self.slave.setReal(vr, [float(text)])
            elif v.type == "Integer":
                self.slave.setInteger(vr, [int(text)])
            elif v.type == "Enumeration":
                self.slave.setInteger(vr, [enumeration_value(v, text)])
            elif v.type == "Boolean":
                low = str(text).lower()
                if low not in ("true", "false", "1", "0"):
                    raise ValueError(f"not a Boolean: {text!r}")
                self.slave.setBoolean(vr, [low in ("true", "1")])
            elif v.type == "String":
                self.slave.setString(vr, [str(text)])
            else:
                raise UsageError(f"{self.name} parameter '{name}' has unsupported type {v.type}")
        except ValueError as e:
            raise UsageError(f"{self.name} parameter '{name}' ({v.type}): {e}") from None
        except FMICallException as e:
            raise self.failed(e, f"setting parameter {name} = {text!r}") from None

    def free(self, terminate):
        """terminate (after a successful run) and fmi2FreeInstance, once; not after fmi2Fatal."""
        if self.freed:
            return
        self.freed = True
        if self.fatal:
            return
        try:
            if terminate:
                self.slave.terminate()
        finally:
            self.slave.freeInstance()


def _vr_array(vrs):
    return (fmi2ValueReference * len(vrs))(*vrs)


# --------------------------------------------------------------------------- the run


def parse_assignments(items):
    out = []
    for item in items or []:
        if "=" not in item:
            raise UsageError(f"--param expects NAME=VALUE, got {item!r}")
        name, value = item.split("=", 1)
        out.append((name.strip(), value))
    return out


def run(args, log):
    """Runs the closed loop; returns (column names, data array, summary dict, plant unzipdir)."""
    h = float(args.step)
    stop = float(args.stop_time)
    if not (h > 0 and math.isfinite(h)):
        raise UsageError(f"--step must be > 0, got {args.step}")
    if not (stop > 0 and math.isfinite(stop)):
        raise UsageError(f"--stop-time must be > 0, got {args.stop_time}")
    n_steps = int(math.ceil(stop / h - 1e-9))
    times = np.minimum(np.arange(n_steps + 1) * h, stop)

    workdir = tempfile.mkdtemp(prefix="closed-loop-")
    units = []
    try:
        plant = Unit("plant", args.plant, log, workdir)
        units.append(plant)
        ctrl = Unit("controller", args.controller, log, workdir)
        units.append(ctrl)
        conn = discover_connections(plant.md.modelVariables, ctrl.md.modelVariables)

        # Inputs of each side in type groups; gather index of each input in the sender's outputs.
        for receiver, sender, pairs in ((ctrl, plant, conn["to_controller"]), (plant, ctrl, conn["to_plant"])):
            by_type = {t: [n for n, ty in pairs if ty == t] for t in TYPES}
            receiver.prepare_inputs(by_type)
            receiver.gather = {t: np.array([sender.out_names[t].index(n) for n in by_type[t]], dtype=np.intp) for t in TYPES}

        # Parameters: scenario and run_id on both, architecture and scheme on the controller,
        # then --param.
        scenario = str(pathlib.Path(args.scenario).resolve()) if args.scenario else ""
        run_id = args.run_id if args.run_id is not None else new_run_id()
        for u in (plant, ctrl):
            if "scenario" in u.vars:
                u.set_parameter("scenario", scenario)
            if "run_id" in u.vars:
                u.set_parameter("run_id", run_id)
        if args.architecture is not None:
            ctrl.set_parameter("architecture", str(args.architecture))
        if args.scheme is not None:
            ctrl.set_parameter("avoidance_scheme", str(args.scheme))
        for name, value in parse_assignments(args.param):
            ctrl.set_parameter(name, value)
        for name, value in parse_assignments(args.plant_param):
            plant.set_parameter(name, value)
        log_files = {}
        if args.log_dir:
            log_dir = pathlib.Path(args.log_dir).resolve()
            log_dir.mkdir(parents=True, exist_ok=True)
            for u, file_name in ((plant, "plant.mcap"), (ctrl, "controller.mcap")):
                if "log_file" not in u.vars:
                    raise UsageError(f"{u.name} has no parameter 'log_file' (needed by --log-dir)")
                log_files[u.name] = str(log_dir / file_name)
                u.set_parameter("log_file", log_files[u.name])

        # Columns: time, plant outputs, controller outputs (modelDescription order).
        columns = ["time"] + [v.name for v in plant.outputs] + [v.name for v in ctrl.outputs]
        col = {n: i for i, n in enumerate(columns)}
        dup = [v.name for v in ctrl.outputs if v.name in {p.name for p in plant.outputs}]
        if dup:
            raise UsageError(f"plant and controller both have outputs named {dup}")
        for u in (plant, ctrl):
            u.cols = {t: np.array([col[n] for n in u.out_names[t]], dtype=np.intp) for t in TYPES}
        data = np.empty((n_steps + 1, len(columns)))
        data[:, 0] = times

        def record(k):
            row = data[k]
            for u in (plant, ctrl):
                for t in TYPES:
                    if u.cols[t].size:
                        row[u.cols[t]] = u.out_np[t]

        def transfer(sender, receiver):
            w = 0
            for t in TYPES:
                if receiver.gather[t].size:
                    receiver.in_np[t][:] = sender.out_np[t][receiver.gather[t]]
            w += receiver.write_inputs()
            return w

        warnings = 0
        # Initialization: the plant first (its outputs are the controller's initial inputs).
        plant.call("setupExperiment", plant.slave.setupExperiment, None, 0.0, stop)
        plant.call("enterInitializationMode", plant.slave.enterInitializationMode)
        plant.call("exitInitializationMode", plant.slave.exitInitializationMode)
        ctrl.call("setupExperiment", ctrl.slave.setupExperiment, None, 0.0, stop)
        ctrl.call("enterInitializationMode", ctrl.slave.enterInitializationMode)
        warnings += plant.read_outputs()
        warnings += transfer(plant, ctrl)
        ctrl.call("exitInitializationMode", ctrl.slave.exitInitializationMode)
        warnings += ctrl.read_outputs()
        warnings += transfer(ctrl, plant)
        record(0)

        fallback_col = col.get(FALLBACKS)
        wall0 = time.perf_counter()
        cpu0 = time.thread_time()
        next_progress = PROGRESS_EVERY
        for k in range(n_steps):
            t = times[k]
            step = times[k + 1] - t
            # plant outputs(t) are in plant.out_np (read after the previous step)
            warnings += transfer(plant, ctrl)
            if args.coupling == "jacobi":
                # controller outputs(t) are in ctrl.out_np (read after the previous step)
                warnings += transfer(ctrl, plant)
                warnings += ctrl.do_step(t, step)
                warnings += plant.do_step(t, step)
                warnings += ctrl.read_outputs()
            else:
                warnings += ctrl.do_step(t, step)
                warnings += ctrl.read_outputs()
                warnings += transfer(ctrl, plant)
                warnings += plant.do_step(t, step)
            warnings += plant.read_outputs()
            record(k + 1)
            if not args.quiet and times[k + 1] >= next_progress - 1e-9:
                next_progress += PROGRESS_EVERY
                r = data[k + 1]
                fb = f", fallbacks {int(r[fallback_col])}" if fallback_col is not None else ""
                print(
                    f"t = {times[k + 1]:7.1f} s: ship x {r[col['ship.x']]:7.2f} m, y {r[col['ship.y']]:6.2f} m, "
                    f"psi {math.degrees(r[col['ship.psi']]):7.1f} deg, u {r[col['ship.u']]:5.3f} m/s; "
                    f"warnings {warnings}{fb}; wall {time.perf_counter() - wall0:.1f} s",
                    flush=True,
                )
        wall = time.perf_counter() - wall0
        summary = make_summary(columns, data, stop, wall, n_steps, warnings, log, ctrl, h)
        # CPU time of the master's thread over the stepping loop: the FMUs' own work and the
        # master's, without other threads (e.g. the FMUs' log writers) and other processes.
        summary["loop_thread_cpu_time_s"] = time.thread_time() - cpu0
        summary["architecture"] = args.architecture if args.architecture is not None else _start(ctrl, "architecture")
        summary["avoidance_scheme"] = args.scheme if args.scheme is not None else _start(ctrl, "avoidance_scheme")
        summary["coupling"] = args.coupling
        summary["run_id"] = run_id
        if log_files:
            summary["log_files"] = log_files
        for u in units:
            u.free(terminate=True)
        return columns, data, summary, plant.unzipdir, workdir
    except BaseException:
        for u in units:
            try:
                u.free(terminate=False)
            except Exception:  # noqa: BLE001 - the original error matters more
                pass
        shutil.rmtree(workdir, ignore_errors=True)
        raise


def enumeration_value(var, text):
    """The FMI value of the Enumeration parameter `var` (FMI 2.0 section 2.2.3; set with
    fmi2SetInteger) from its text: a value (`2`) or the name of an item of its declared type
    (`centralized`). Raises ValueError naming the items otherwise; whether a number is an
    item's value the FMU checks."""
    try:
        return int(text)
    except ValueError:
        pass
    items = getattr(getattr(var, "declaredType", None), "items", None) or []
    for item in items:
        if item.name == text:
            return int(item.value)
    names = ", ".join(f"{int(i.value)} {i.name}" for i in items)
    raise ValueError(f"{text!r} is neither a number nor an item name ({names})")


def new_run_id():
    """A run id no other run has: the UTC time and 32 random bits, e.g.
    `20250101T120000Z-1a2b3c4d`."""
    return time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()) + "-" + uuid.uuid4().hex[:8]


def _start(unit, name):
    v = unit.vars.get(name)
    try:
        return int(v.start)
    except (AttributeError, TypeError, ValueError):
        return None


def sample_rows(ctrl, columns, data, h):
    """Rows holding the outputs of a new controller sample: where the controller's sample
    counter `controller.samples` went up; without that output, the rows after the doSteps that
    start at a multiple of the controller's `sample_time` parameter (else 1 s)."""
    if SAMPLES in columns:
        counter = data[:, columns.index(SAMPLES)]
        return np.flatnonzero(np.diff(counter) > 0) + 1
    ts = 1.0
    for v in ctrl.md.modelVariables:
        if v.causality == "parameter" and (v.name == "Ts" or v.name.endswith("sample_time")) and v.start:
            ts = float(v.start)
            break
    starts = data[:-1, 0]
    phase = np.abs(starts / ts - np.round(starts / ts))
    return np.flatnonzero(phase < 0.5 * h / ts) + 1


def make_summary(columns, data, stop, wall, steps, warnings, log, ctrl, h):
    col = {n: i for i, n in enumerate(columns)}
    rows = sample_rows(ctrl, columns, data, h)

    def stats(name, qs):
        if name not in col or rows.size == 0:
            return {q: None for q in qs}
        x = data[rows, col[name]]
        out = {}
        for q in qs:
            out[q] = float(np.max(x)) if q == "max" else float(np.percentile(x, {"median": 50, "p99": 99}[q]))
        return out

    last = data[-1]
    ct = stats(COMPUTE_TIME, ("median", "p99", "max"))
    it = stats(ITERATIONS, ("median", "p99", "max"))
    return {
        "stop_time": float(data[-1, 0]),
        "requested_stop_time": stop,
        "step": h,
        "steps": steps,
        "wall_time_s": wall,
        "fallbacks": int(last[col[FALLBACKS]]) if FALLBACKS in col else None,
        "warnings": int(warnings),
        "logged_warnings": sum(1 for s, _, _ in log.messages if s == "WARNING"),
        "controller_samples": int(rows.size),
        "compute_time_s": ct,
        "compute_time_max_s": ct["max"],
        "compute_time_median_s": ct["median"],
        "compute_time_p99_s": ct["p99"],
        "admm_iterations": it,
        "final_ship_pose": {
            "x": float(last[col["ship.x"]]),
            "y": float(last[col["ship.y"]]),
            "psi_deg": math.degrees(float(last[col["ship.psi"]])),
            "u": float(last[col["ship.u"]]),
            "v": float(last[col["ship.v"]]),
            "r": float(last[col["ship.r"]]),
        },
    }


# --------------------------------------------------------------------------- outputs


def write_csv(path, columns, data):
    """Header of variable names, then one row per recorded time (repr-exact floats, integers
    for Integer/Boolean columns)."""
    integral = np.all(data == np.round(data), axis=0)
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n")
        fmt = [("%d" if integral[j] and j > 0 else "%.17g") for j in range(len(columns))]
        np.savetxt(f, data, delimiter=",", fmt=fmt)


def parse_size(text):
    try:
        w, h = (int(x) for x in text.lower().split("x"))
        if w < 100 or h < 100:
            raise ValueError
        return w, h
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels (>= 100), got {text!r}") from None


def draw_map(path, columns, data, scenario, size, title):
    """The map: East horizontal, North vertical, equal aspect, everything at real size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Polygon

    d = {n: data[:, i] for i, n in enumerate(columns)}
    t = d["time"]
    dims = tow_geometry.vessel_dims(scenario)
    dpi = 100
    fig = plt.figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    ax = fig.add_axes([0.08, 0.07, 0.88, 0.86])

    if scenario and "route" in scenario:
        route = tow_geometry.route_points(scenario)
        ax.plot(route[:, 1], route[:, 0], color="0.55", ls="--", lw=1, marker="o", ms=3, label="route", zorder=1)
        ax.plot(route[-1, 1], route[-1, 0], marker="*", ms=16, color="gold", mec="k", ls="none", label="destination", zorder=6)

    colors = {"ship": "tab:red", "tug1": "tab:green", "tug2": "tab:blue"}
    outline_rows = np.unique(np.concatenate([np.flatnonzero(np.isclose(np.mod(t + 1e-9, OUTLINE_EVERY), 0, atol=1e-6)), [len(t) - 1]]))
    for v in tow_geometry.VESSELS:
        ax.plot(d[f"{v}.y"], d[f"{v}.x"], color=colors[v], lw=1.2, label=f"{v} track", zorder=3)
        dm = dims[v]
        outline = tow_geometry.hull_outline(
            d[f"{v}.x"][outline_rows], d[f"{v}.y"][outline_rows], d[f"{v}.psi"][outline_rows], dm["length"], dm["width"], dm["centre"]
        )
        for poly in outline:
            ax.add_patch(Polygon(poly[:, ::-1], closed=True, fc=colors[v], ec="k", lw=0.4, alpha=0.55, zorder=4))
    ax.plot(d["ship.y"][0], d["ship.x"][0], marker="o", ms=9, mfc="none", mec="k", mew=1.5, ls="none", label="ship start", zorder=7)
    ax.plot(d["ship.y"][-1], d["ship.x"][-1], marker="X", ms=10, color="k", ls="none", label=f"ship at {t[-1]:g} s", zorder=7)

    static_done = False
    target_done = False
    for k in tow_geometry.obstacle_slots(d):
        kind = d[f"obstacle[{k}].kind"]
        static = np.flatnonzero(kind == 1)
        target = np.flatnonzero(kind == 2)
        if static.size:
            i = static[0]
            ax.add_patch(
                Circle(
                    (d[f"obstacle[{k}].y"][i], d[f"obstacle[{k}].x"][i]),
                    d[f"obstacle[{k}].length"][i] / 2,
                    fc="0.35",
                    ec="k",
                    label=None if static_done else "static hazard",
                    zorder=2,
                )
            )
            static_done = True
        if target.size:
            ax.plot(
                d[f"obstacle[{k}].y"][target],
                d[f"obstacle[{k}].x"][target],
                color="purple",
                ls=":",
                lw=1.2,
                label=None if target_done else "target ship track",
                zorder=2,
            )
            rows = np.intersect1d(outline_rows, target)
            rows = np.unique(np.concatenate([rows, [target[0], target[-1]]]))
            polys = tow_geometry.ellipse(
                d[f"obstacle[{k}].x"][rows],
                d[f"obstacle[{k}].y"][rows],
                d[f"obstacle[{k}].psi"][rows],
                d[f"obstacle[{k}].length"][rows],
                d[f"obstacle[{k}].width"][rows],
                n=48,
                circumscribed=False,
            )
            for poly in polys:
                ax.add_patch(Polygon(poly[:, ::-1], closed=True, fc="plum", ec="purple", lw=0.5, alpha=0.6, zorder=2))
            name = _obstacle_name(scenario, k)
            ax.annotate(name, (d[f"obstacle[{k}].y"][target[0]], d[f"obstacle[{k}].x"][target[0]]), fontsize=8, color="purple",
                        xytext=(4, -10), textcoords="offset points")
            target_done = True

    # View: the route, the tow's tracks and the static hazards with a margin; target ships come
    # from far away and leave far away, so their tracks are cut at the edge.
    east = [d[f"{v}.y"] for v in tow_geometry.VESSELS]
    north = [d[f"{v}.x"] for v in tow_geometry.VESSELS]
    if scenario and "route" in scenario:
        east.append(route[:, 1])
        north.append(route[:, 0])
    for k in tow_geometry.obstacle_slots(d):
        static = d[f"obstacle[{k}].kind"] == 1
        if static.any():
            east.append(d[f"obstacle[{k}].y"][static][:1])
            north.append(d[f"obstacle[{k}].x"][static][:1])
    east, north = np.concatenate(east), np.concatenate(north)
    margin = 3.0
    e0, e1 = np.nanmin(east) - margin, np.nanmax(east) + margin
    n0, n1 = np.nanmin(north) - margin, np.nanmax(north) + margin
    box = ax.get_position()
    ratio = (box.height * size[1]) / (box.width * size[0])  # axes height / width in pixels
    if (n1 - n0) < ratio * (e1 - e0):  # widen North to the axes' shape (equal aspect)
        grow = (ratio * (e1 - e0) - (n1 - n0)) / 2
        n0, n1 = n0 - grow, n1 + grow
    else:
        grow = ((n1 - n0) / ratio - (e1 - e0)) / 2
        e0, e1 = e0 - grow, e1 + grow
    ax.set_xlim(e0, e1)
    ax.set_ylim(n0, n1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("East y (m)")
    ax.set_ylabel("North x (m)")
    ax.set_title(title)
    ax.grid(True, lw=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def _obstacle_name(scenario, k):
    try:
        return scenario["obstacles"][k - 1]["name"]
    except (KeyError, IndexError, TypeError):
        return f"obstacle[{k}]"


def build_parser():
    doc = __doc__.strip()
    p = argparse.ArgumentParser(
        prog="closed_loop.py",
        description=doc[: doc.index("\nOptions:")],
        epilog=doc[doc.index("Writes:") :],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--plant", default=str(DEFAULT_PLANT), metavar="FMU", help="TowingPlant FMU (default: target/fmu/TowingPlant.fmu)")
    p.add_argument("--controller", default=str(DEFAULT_CONTROLLER), metavar="FMU", help="TowingController FMU (default: target/fmu/TowingController.fmu)")
    p.add_argument("--scenario", default="", metavar="PATH", help="scenario TOML, set as the `scenario` parameter of both FMUs (default: empty = the bundled paper scenario)")
    p.add_argument("--stop-time", type=float, default=1200.0, metavar="S", help="simulated time in s (default: 1200)")
    p.add_argument("--step", type=float, default=0.1, metavar="H", help="fixed communication step h in s (default: 0.1)")
    p.add_argument("--architecture", type=int, choices=(1, 2), help="controller `architecture`: 1 distributed (ADMM), 2 centralized (default: the FMU's start value)")
    p.add_argument("--scheme", type=int, choices=(1, 2, 3), help="controller `avoidance_scheme`: scheme I, II or III of Du et al. (2022) (default: the FMU's start value)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE", default=[], help="set any controller parameter, typed from its modelDescription (repeatable)")
    p.add_argument("--plant-param", action="append", metavar="NAME=VALUE", default=[], help="set a plant parameter, e.g. model.hull=1 (repeatable)")
    p.add_argument(
        "--coupling",
        choices=("gauss-seidel", "jacobi"),
        default="gauss-seidel",
        help="gauss-seidel: the controller steps first and the plant applies its new commands in the same step (default); "
        "jacobi: both step on the other's outputs at the step's start, as libcosim and fmpy's SSP runner do",
    )
    p.add_argument("--log-dir", default=None, metavar="DIR", help="write MCAP logs DIR/plant.mcap and DIR/controller.mcap (the FMUs' `log_file` parameters; default: no logs)")
    p.add_argument("--run-id", default=None, metavar="ID", help="the run's id, set as `run_id` on both FMUs and written into both logs (default: a new one from the UTC time and random hex)")
    p.add_argument("--out", default="out/closed-loop", metavar="DIR", help="output directory (default: out/closed-loop)")
    p.add_argument("--map-size", type=parse_size, default=(1400, 1200), metavar="WxH", help="size of map.png in pixels (default: 1400x1200)")
    p.add_argument("--quiet", action="store_true", help="no progress lines (one every 100 s of simulated time otherwise)")
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)
    log = MessageLog()
    out = pathlib.Path(args.out)
    workdir = None
    try:
        columns, data, summary, plant_dir, workdir = run(args, log)
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / "timeseries.csv", columns, data)
        scenario_file = tow_geometry.scenario_path_for_plant(args.scenario, pathlib.Path(plant_dir) / "resources")
        scenario = tow_geometry.load_scenario(scenario_file)
        arch = {1: "distributed", 2: "centralized"}.get(summary["architecture"], f"architecture {summary['architecture']}")
        scheme = {1: "scheme I", 2: "scheme II", 3: "scheme III"}.get(summary["avoidance_scheme"], f"scheme {summary['avoidance_scheme']}")
        title = f"Closed loop under fmpy: {scenario.get('name', scenario_file.name)} scenario, {arch}, {scheme}, {summary['stop_time']:g} s"
        draw_map(out / "map.png", columns, data, scenario, args.map_size, title)
        summary["scenario"] = str(pathlib.Path(args.scenario).resolve()) if args.scenario else "(bundled paper scenario)"
        (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    except UsageError as e:
        print(f"closed_loop.py: error: {e}", file=sys.stderr)
        return 2
    except (FmuError, FMICallException) as e:
        print(f"closed_loop.py: FMU call failed: {e}", file=sys.stderr)
        text = log.text("WARNING")
        print("messages logged by the FMUs (warning and above):\n" + (text or "(none)"), file=sys.stderr)
        return 1
    finally:
        if workdir:
            shutil.rmtree(workdir, ignore_errors=True)
    if not args.quiet:
        print(
            f"{summary['steps']} steps to t = {summary['stop_time']:g} s in {summary['wall_time_s']:.1f} s wall; "
            f"warnings {summary['warnings']}, fallbacks {summary['fallbacks']}; "
            f"wrote {out / 'timeseries.csv'}, {out / 'map.png'}, {out / 'summary.json'}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())

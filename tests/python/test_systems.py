"""The system descriptions in systems/ (built by `cargo xtask ssp`) and the cross-check of the
masters (docs/masters.md).

- systems/towing.ssp (SSP 1.0) and systems/OspSystemStructure.xml with the two
  <Model>_OspModelDescription.xml (OSP-IS variable groups): their connections are exactly the
  connections by name of masters/closed_loop.py (its own discover_connections), and the
  committed OSP files equal the generated ones (`cargo xtask ssp` fails otherwise).
- The same closed loop (paper scenario, 0.1 s, STOP_TIME s) under every master: fmpy
  (masters/closed_loop.py, both couplings), the Rust importer (fmi-rs, tests/examples/
  closed_loop_csv.rs, both couplings), libcosim from OspSystemStructure.xml and from
  towing.ssp (Jacobi), and fmpy's SSP runner on towing.ssp. The FMUs are deterministic, so
  masters with the same coupling must give the same ship trajectory to the bit (and at most
  TOLERANCE apart, which the assertion message reports), and the two couplings must differ.
- fmpy's SSP runner is Jacobi too, but starts every connector at 0.0 and never exchanges the
  initial outputs; its trajectory is another one, and equals to the bit the Rust importer's
  Jacobi loop with zero initial inputs (which shows that this, and nothing else, is the
  difference).
"""

import csv
import io
import pathlib
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile

import fmpy
import numpy as np
import pytest
from fmpy.ssp.simulation import simulate_ssp
from fmpy.ssp.ssd import read_ssd
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver

import closed_loop
from conftest import ROOT, target_dir

SYSTEMS = ROOT / "systems"
MASTER = ROOT / "masters" / "closed_loop.py"
INSTANCES = {"plant": "TowingPlant", "controller": "TowingController"}
STOP_TIME = 120.0  # s of the paper scenario (120 controller samples)
STEP = 0.1  # s, the FMUs' DefaultExperiment step
STEPS = 1200
NS = 1_000_000_000
SHIP = ["ship.x", "ship.y", "ship.psi"]
TOLERANCE = 1e-9  # the bound; the assertions below demand bit equality
COUPLINGS_DIFFER_BY = 1e-6  # at least, in m or rad, somewhere on the trajectory
OSP_MD = "https://open-simulation-platform.com/OspModelDescription/1.0.0"
OSP_SS = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
# OSP-IS 1.0: the order of the child elements in a Generic group and in VariableGroups.
OSP_ORDER = ["Variable", "Generic", "Force", "Torque", "Voltage", "Pressure", "LinearVelocity", "AngularVelocity",
             "Current", "VolumeFlowRate", "LinearDisplacement", "AngularDisplacement"]


# --------------------------------------------------------------------------- the files


@pytest.fixture(scope="session")
def xtask_ssp():
    """`cargo xtask ssp`: packages the FMUs, writes systems/towing.ssp and systems/fmu/, and
    fails when the committed OSP files differ from the generated ones."""
    return subprocess.run(["cargo", "xtask", "ssp"], cwd=ROOT, capture_output=True, text=True)


@pytest.fixture(scope="session")
def systems(xtask_ssp):
    if xtask_ssp.returncode != 0:
        pytest.fail(f"cargo xtask ssp failed:\n{xtask_ssp.stderr[-3000:]}")
    return {
        "ssp": SYSTEMS / "towing.ssp",
        "osp": SYSTEMS / "OspSystemStructure.xml",
        "plant": SYSTEMS / "fmu" / "TowingPlant.fmu",
        "controller": SYSTEMS / "fmu" / "TowingController.fmu",
    }


@pytest.fixture(scope="session")
def by_name(systems):
    """The connections of masters/closed_loop.py: {(sender, receiver, name)}."""
    mds = {i: fmpy.read_model_description(str(systems[i])) for i in INSTANCES}
    conn = closed_loop.discover_connections(mds["plant"].modelVariables, mds["controller"].modelVariables)
    pairs = {("plant", "controller", n) for n, _ in conn["to_controller"]}
    pairs |= {("controller", "plant", n) for n, _ in conn["to_plant"]}
    assert len(conn["to_plant"]) == 8 and len(conn["to_controller"]) >= 18 + 7 * 8
    return pairs, mds


def test_committed_osp_files_equal_the_generated_ones(xtask_ssp):
    assert xtask_ssp.returncode == 0, xtask_ssp.stderr[-3000:]
    assert "OSP files up to date" in xtask_ssp.stderr


def test_fmus_in_systems_are_the_packaged_ones(systems):
    with zipfile.ZipFile(systems["ssp"]) as z:
        assert sorted(z.namelist()) == ["SystemStructure.ssd", "resources/TowingController.fmu", "resources/TowingPlant.fmu"]
        for instance, model in INSTANCES.items():
            packaged = (target_dir() / "fmu" / f"{model}.fmu").read_bytes()
            assert z.read(f"resources/{model}.fmu") == packaged
            assert systems[instance].read_bytes() == packaged


def test_ssd_is_valid_ssp_1_0_and_connects_exactly_by_name(systems, by_name):
    pairs, mds = by_name
    ssd = read_ssd(str(systems["ssp"]), validate=True)  # fmpy's check against the SSP 1.0 schema
    assert {c.name: c.source for c in ssd.system.elements} == {i: f"resources/{m}.fmu" for i, m in INSTANCES.items()}
    connections = {(c.startElement, c.endElement, c.startConnector) for c in ssd.system.connections}
    assert all(c.startConnector == c.endConnector for c in ssd.system.connections)
    assert len(connections) == len(ssd.system.connections)
    assert connections == pairs
    # Every connector names a variable of its component with that causality and type.
    ns = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription"}
    root = ET.fromstring(zipfile.ZipFile(systems["ssp"]).read("SystemStructure.ssd"))
    for component in root.iterfind(".//ssd:Component", ns):
        variables = {v.name: v for v in mds[component.get("name")].modelVariables}
        for connector in component.iterfind("ssd:Connectors/ssd:Connector", ns):
            v = variables[connector.get("name")]
            assert connector.get("kind") == v.causality
            assert connector[0].tag.split("}")[1] == closed_loop.base_type(v)
            if v.type == "Real":
                assert connector[0].get("unit") == v.unit
    step = root.find(".//{http://opensimulationplatform.com/SSP/OSPAnnotations}FixedStepAlgorithm")
    assert float(step.get("baseStepSize")) == STEP == float(mds["plant"].defaultExperiment.stepSize)


def osp_groups(path, md):
    """The variable groups of an OspModelDescription, {name: element}, after checking the
    OSP-IS 1.0 rules a schema validator and the OSP-IS validator would: namespace and version,
    child order, at most three variables in a typed group, unique names, every reference a
    variable of the model with the unit of its modelDescription, one causality per group."""
    root = ET.parse(path).getroot()
    assert root.tag == f"{{{OSP_MD}}}OspModelDescription" and root.get("version") == "1.0"
    variables = {v.name: v for v in md.modelVariables}
    groups = {}

    def local(el):
        return el.tag.split("}")[1]

    def walk(el, top):
        kinds = [local(c) for c in el]
        assert kinds == sorted(kinds, key=OSP_ORDER.index), f"{el.get('name')}: children out of schema order: {kinds}"
        causalities = set()
        for child in el:
            if local(child) == "Variable":
                v = variables[child.get("ref")]
                if child.get("unit") is not None or local(el) != "Generic":
                    assert child.get("unit") == v.unit, child.get("ref")
                causalities.add(v.causality)
                continue
            name = child.get("name")
            assert name not in groups, f"duplicate group name {name}"
            groups[name] = child
            if local(child) != "Generic":
                assert 1 <= len(child) <= 3 and all(local(c) == "Variable" for c in child), name
            causalities |= walk(child, False)
        assert top or len(causalities) == 1, f"{el.get('name')}: causalities {causalities}"
        return causalities

    top = root.find(f"{{{OSP_MD}}}VariableGroups")
    walk(top, True)
    return groups


def expand(a, b):
    """Variable pairs of a group connection, as libcosim expands it: sub-groups by position
    (same type), then the group's own variables by position."""
    subs = [[c for c in g if not c.tag.endswith("}Variable")] for g in (a, b)]
    refs = [[c.get("ref") for c in g if c.tag.endswith("}Variable")] for g in (a, b)]
    assert a.tag == b.tag and len(subs[0]) == len(subs[1]) and len(refs[0]) == len(refs[1])
    pairs = [p for x, y in zip(*subs) for p in expand(x, y)]
    return pairs + list(zip(*refs))


def test_osp_system_structure_connects_exactly_by_name_through_variable_groups(systems, by_name):
    pairs, mds = by_name
    root = ET.parse(systems["osp"]).getroot()
    q = lambda tag: f"{{{OSP_SS}}}{tag}"  # noqa: E731
    assert root.tag == q("OspSystemStructure") and root.get("version") == "0.1"
    assert root.findtext(q("Algorithm")) == "fixedStep"
    assert float(root.findtext(q("BaseStepSize"))) == STEP
    sims = {s.get("name"): s.get("source") for s in root.iter(q("Simulator"))}
    assert sims == {i: f"fmu/{m}.fmu" for i, m in INSTANCES.items()}
    assert all((SYSTEMS / s).is_file() for s in sims.values())
    groups = {i: osp_groups(SYSTEMS / f"{m}_OspModelDescription.xml", mds[i]) for i, m in INSTANCES.items()}
    causality = {i: {v.name: v.causality for v in mds[i].modelVariables} for i in INSTANCES}
    found = []

    def add(sa, va, sb, vb):
        # libcosim connects output -> input whichever is written first; here the sender first.
        assert causality[sa][va] == "output" and causality[sb][vb] == "input", (sa, va, sb, vb)
        assert va == vb, f"{sa}.{va} -> {sb}.{vb}: not a connection by name"
        found.append((sa, sb, va))

    connections = root.find(q("Connections"))
    kinds = [c.tag for c in connections]
    assert kinds == sorted(kinds, key=[q("VariableConnection"), q("VariableGroupConnection")].index)
    for c in connections.iter(q("VariableConnection")):
        (sa, va), (sb, vb) = [(v.get("simulator"), v.get("name")) for v in c]
        add(sa, va, sb, vb)
    n_groups = 0
    for c in connections.iter(q("VariableGroupConnection")):
        (sa, ga), (sb, gb) = [(v.get("simulator"), v.get("name")) for v in c]
        for va, vb in expand(groups[sa][ga], groups[sb][gb]):
            add(sa, va, sb, vb)
        n_groups += 1
    assert len(found) == len(set(found)), "a variable connected twice"
    assert set(found) == pairs
    # The vessels, the tugs' thrust and the obstacles connect as whole groups.
    whole = {(c[0].get("name"), c[1].get("name")) for c in connections.iter(q("VariableGroupConnection"))}
    for obj in ["ship", "tug1", "tug2"] + [f"obstacle[{k}]" for k in range(1, 9)]:
        assert (f"{obj}.out", f"{obj}.in") in whole, obj
    for tug in ["tug1", "tug2"]:
        assert (f"{tug}.out", f"{tug}.in") in whole
        thrust = groups["controller"][f"{tug}.out"]
        assert [c.tag.split("}")[1] for c in thrust] == ["Force", "Torque"]
    assert n_groups > 0


# --------------------------------------------------------------------------- the masters


def ship_columns(header, rows):
    index = [header.index(n) for n in SHIP]
    return np.array([[float(r[i]) for i in index] for r in rows])


@pytest.fixture(scope="session")
def script(systems, tmp_path_factory):
    """masters/closed_loop.py: ship (x, y, psi) rows at t = 0, h, ..., STOP_TIME."""
    runs = {}

    def run(coupling):
        if coupling not in runs:
            out = tmp_path_factory.mktemp(f"script-{coupling}")
            p = subprocess.run(
                [sys.executable, str(MASTER), "--plant", str(systems["plant"]), "--controller", str(systems["controller"]),
                 "--stop-time", str(STOP_TIME), "--step", str(STEP), "--coupling", coupling, "--quiet", "--out", str(out)],
                cwd=ROOT, capture_output=True, text=True, timeout=1800,
            )
            assert p.returncode == 0, p.stderr[-3000:]
            with open(out / "timeseries.csv") as f:
                rows = list(csv.reader(f))
            runs[coupling] = ship_columns(rows[0], rows[1:])
        return runs[coupling]

    return run


@pytest.fixture(scope="session")
def rust(systems):
    """The Rust importer (tests/examples/closed_loop_csv.rs, e2e_tests::closed_loop)."""
    runs = {}

    def run(coupling, initial_inputs="exchanged"):
        key = (coupling, initial_inputs)
        if key not in runs:
            p = subprocess.run(
                [str(target_dir() / "release" / "examples" / "closed_loop_csv"),
                 "--plant", str(systems["plant"]), "--controller", str(systems["controller"]), "--coupling", coupling,
                 "--initial-inputs", initial_inputs, "--stop-time", str(STOP_TIME), "--step", str(STEP)],
                cwd=ROOT, capture_output=True, text=True, timeout=3600,
            )
            assert p.returncode == 0, p.stderr[-3000:]
            rows = list(csv.reader(io.StringIO(p.stdout)))
            runs[key] = ship_columns(rows[0], rows[1:])
        return runs[key]

    return run


def run_libcosim(execution):
    """Steps a libcosim execution STEPS times; ship rows at t = h, ..., STOP_TIME."""
    log_output_level(CosimLogLevel.WARNING)  # libcosim traces every FMI call otherwise
    assert execution.num_slaves() == 2
    plant = execution.slave_index_from_instance_name("plant")
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(plant)}
    observer = CosimObserver.create_last_value()
    assert execution.add_observer(observer)
    rows = []
    for _ in range(STEPS):
        assert execution.step(), "libcosim step failed"
        rows.append(observer.last_real_values(plant, [refs[n] for n in SHIP]))
    assert execution.status().current_time == round(STOP_TIME * NS)
    return np.array(rows)


@pytest.fixture(scope="session")
def libcosim(systems):
    runs = {}

    def run(source):
        if source not in runs:
            if source == "osp":
                execution = CosimExecution.from_osp_config_file(str(systems["osp"]))
            else:  # the .ssp, with the step of its libcosim annotation
                execution = CosimExecution.from_ssp_file(str(systems["ssp"]))
            runs[source] = run_libcosim(execution)
        return runs[source]

    return run


@pytest.fixture(scope="session")
def fmpy_ssp(systems):
    """fmpy.ssp.simulate_ssp: row k holds the connector values after the step from k h (its
    time column is the step's start). Its time is a running sum of the step, so the stop time
    sits half a step before STOP_TIME to make exactly STEPS steps."""
    result = simulate_ssp(str(systems["ssp"]), stop_time=STOP_TIME - STEP / 2, step_size=STEP)
    assert len(result) == STEPS
    return np.column_stack([result[f"plant.{n}"] for n in SHIP])


def largest_difference(a, b):
    assert a.shape == b.shape, (a.shape, b.shape)
    return float(np.max(np.abs(a - b)))


JACOBI_MASTERS = {
    "rust": lambda r, c, l: r("jacobi")[1:],
    "libcosim-osp": lambda r, c, l: l("osp"),
    "libcosim-ssp": lambda r, c, l: l("ssp"),
}


def test_rust_importer_agrees_with_the_script_in_gauss_seidel(script, rust):
    reference, other = script("gauss-seidel"), rust("gauss-seidel")
    d = largest_difference(reference, other)
    assert d <= TOLERANCE and np.array_equal(reference, other), f"max |delta| = {d:.3g}"


@pytest.mark.parametrize("master", sorted(JACOBI_MASTERS))
def test_jacobi_masters_agree_with_the_script_in_jacobi(master, script, rust, libcosim):
    reference = script("jacobi")[1:]  # rows at h, ..., STOP_TIME (libcosim has no row at 0)
    other = JACOBI_MASTERS[master](rust, script, libcosim)
    d = largest_difference(reference, other)
    assert d <= TOLERANCE and np.array_equal(reference, other), f"{master}: max |delta| = {d:.3g}"


def test_the_two_couplings_differ(script, rust):
    gauss_seidel, jacobi = script("gauss-seidel"), script("jacobi")
    assert np.array_equal(gauss_seidel[0], jacobi[0]), "same initial state"
    d = largest_difference(gauss_seidel, jacobi)
    assert COUPLINGS_DIFFER_BY < d < 1.0, f"Gauss-Seidel vs Jacobi: max |delta| = {d:.3g}"
    assert largest_difference(rust("gauss-seidel"), rust("jacobi")) == d


def test_fmpy_ssp_runner_is_jacobi_from_zero_inputs(fmpy_ssp, rust, libcosim):
    """fmpy's SSP runner sets every connector to 0.0 before the first step and never reads the
    outputs after initialization, so at t = 0 the controller sees the ship, the tugs and every
    obstacle at zero and the plant gets zero towline tension: another trajectory than
    libcosim's, and exactly the Rust importer's Jacobi loop with zero initial inputs."""
    d_libcosim = largest_difference(fmpy_ssp, libcosim("ssp"))
    assert d_libcosim > COUPLINGS_DIFFER_BY, f"fmpy SSP vs libcosim: max |delta| = {d_libcosim:.3g}"
    emulated = rust("jacobi", "zero")[1:]
    d = largest_difference(fmpy_ssp, emulated)
    assert d <= TOLERANCE and np.array_equal(fmpy_ssp, emulated), f"max |delta| = {d:.3g}"

"""The packaged TowingController FMU under fmpy: validation, capabilities, refused inputs."""

import fmpy
import pytest
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu
from fmu_logging import MessageLog


def test_validate_fmu_reports_no_problems(controller_fmu):
    assert validate_fmu(controller_fmu) == []


def test_model_description_capabilities(controller_fmu):
    md = fmpy.read_model_description(controller_fmu)
    cs = md.coSimulation
    assert cs.modelIdentifier == "TowingController"
    # The FMU state (plans, multipliers, guidance memory, clock) is copied and serialized;
    # the solvers are rebuilt on restore (test_fmu_state.py).
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    names = {v.name: v for v in md.modelVariables}
    for p in ("architecture", "avoidance_scheme", "scenario", "mpc.sample_time", "admm.rho",
              "admm.max_iterations", "guidance.detection_distance", "guidance.safety_buffer",
              "waterway.from_scenario", "waterway.half_width", "mpc.ship.weight_position",
              "mpc.ship.weight_surge", "mpc.ship.weight_distance", "mpc.tug.weight_position",
              "mpc.tug.weight_surge", "mpc.tug.weight_distance", "admm.eps_abs", "admm.eps_rel",
              "guidance.altering_angle", "mpc.sample_time_budget"):
        assert names[p].causality == "parameter", p
    assert names["architecture"].start == "1" and names["avoidance_scheme"].start == "1"
    assert float(names["mpc.sample_time"].start) == 1.0
    # Every Real parameter declares its unit.
    for v in md.modelVariables:
        if v.causality == "parameter" and v.type == "Real":
            assert v.unit, v.name


def instantiate(controller_fmu, tmp_path, name):
    unzipdir = fmpy.extract(controller_fmu, str(tmp_path / name))
    md = fmpy.read_model_description(controller_fmu)
    log = MessageLog()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="TowingController", instanceName=name)
    fmu.instantiate(callbacks=log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return fmu, vr, log


def test_nan_input_is_refused_naming_the_variable(controller_fmu, tmp_path):
    fmu, vr, log = instantiate(controller_fmu, tmp_path, "nan")
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        fmu.setReal([vr["tug2.v"]], [float("nan")])
    assert "tug2.v" in log.text(), log.text()
    fmu.freeInstance()


def test_bad_architecture_is_refused_naming_the_items(controller_fmu, tmp_path):
    fmu, vr, log = instantiate(controller_fmu, tmp_path, "arch")
    fmu.setupExperiment(startTime=0.0)
    with pytest.raises(FMICallException):
        fmu.setInteger([vr["architecture"]], [3])
    assert "parameter `architecture`: must be one of 1 distributed, 2 centralized, got 3" in log.text(), log.text()
    fmu.freeInstance()


def test_enumerations_and_run_id_in_the_model_description(controller_fmu, tmp_path):
    md = fmpy.read_model_description(controller_fmu)
    names = {v.name: v for v in md.modelVariables}
    for name, type_name, items in (("architecture", "Architecture", ["distributed", "centralized"]),
                                   ("avoidance_scheme", "AvoidanceScheme", ["alter_and_cost", "alter_only", "cost_only"]),
                                   ("mpc.hull_model", "HullModel", ["linear_damping", "nonlinear_damping"])):
        v = names[name]
        assert v.type == "Enumeration" and v.declaredType.name == type_name, name
        assert [i.name for i in v.declaredType.items] == items
        assert [int(i.value) for i in v.declaredType.items] == list(range(1, len(items) + 1))
    run_id = names["run_id"]
    assert (run_id.type, run_id.valueReference, run_id.causality) == ("String", 3, "parameter")
    # Set and read through fmi2SetInteger/fmi2GetInteger and fmi2SetString/fmi2GetString.
    fmu, vr, log = instantiate(controller_fmu, tmp_path, "enum")
    fmu.setupExperiment(startTime=0.0)
    fmu.setInteger([vr["architecture"]], [2])
    fmu.setString([vr["run_id"]], ["fmpy run"])
    fmu.enterInitializationMode()
    assert fmu.getInteger([vr["architecture"]]) == [2]
    assert fmu.getString([vr["run_id"]]) == [b"fmpy run"]
    fmu.exitInitializationMode()
    fmu.terminate()
    fmu.freeInstance()

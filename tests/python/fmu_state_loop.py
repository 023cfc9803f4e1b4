"""The closed loop of both packaged FMUs under fmpy's FMU2Slave, connected by name as
`masters/closed_loop.py` connects them (Gauss-Seidel, controller first, 0.1 s steps), whose
two FMU states can be serialized to files and restored into fresh instances: the test of
issue 15, item 9 (`test_fmu_state.py`), which runs the restored half in a process of its own
through this file's command line:

    python fmu_state_loop.py PLANT.fmu CONTROLLER.fmu STATE_DIR FIRST_STEP LAST_STEP STOP OUT.npy

restores both instances from STATE_DIR, steps FIRST_STEP..LAST_STEP and saves the bits of
every output after each step (numpy uint64) to OUT.npy.
"""

import pathlib
import sys
import tempfile

import fmpy
import numpy as np
from fmpy.fmi2 import FMU2Slave

H = 0.1
STATE_FILES = {"plant": "plant.state", "controller": "controller.state"}


def base_type(v):
    return "Integer" if v.type == "Enumeration" else v.type


class Unit:
    def __init__(self, name, path, workdir):
        self.name = name
        self.md = fmpy.read_model_description(path)
        unzipdir = fmpy.extract(path, str(pathlib.Path(workdir) / name))
        self.slave = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.slave.instantiate()
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.outputs = [v for v in self.md.modelVariables if v.causality == "output"]
        self.inputs = [v for v in self.md.modelVariables if v.causality == "input"]

    def get(self, v):
        t = base_type(v)
        vr = [v.valueReference]
        if t == "Real":
            return self.slave.getReal(vr)[0]
        if t == "Integer":
            return self.slave.getInteger(vr)[0]
        return self.slave.getBoolean(vr)[0]

    def set(self, v, value):
        t = base_type(v)
        vr = [v.valueReference]
        if t == "Real":
            self.slave.setReal(vr, [value])
        elif t == "Integer":
            self.slave.setInteger(vr, [int(value)])
        else:
            self.slave.setBoolean(vr, [bool(value)])

    def take_inputs(self, sender):
        for v in self.inputs:
            self.set(v, sender.get(sender.vars[v.name]))

    def output_bits(self, skip=()):
        values = [float(self.get(v)) for v in self.outputs if v.name not in skip]
        return np.array(values, dtype=np.float64).view(np.uint64)

    def serialize(self):
        state = self.slave.getFMUstate()
        data = self.slave.serializeFMUstate(state)
        self.slave.freeFMUstate(state)
        return data

    def restore(self, data):
        state = self.slave.deSerializeFMUstate(data)
        self.slave.setFMUstate(state)
        self.slave.freeFMUstate(state)


class Loop:
    """Both FMUs instantiated in `workdir`."""

    def __init__(self, plant_fmu, controller_fmu, workdir):
        self.plant = Unit("plant", plant_fmu, workdir)
        self.ctrl = Unit("controller", controller_fmu, workdir)

    def initialize(self, architecture, stop):
        p, c = self.plant, self.ctrl
        c.slave.setInteger([c.vars["architecture"].valueReference], [architecture])
        p.slave.setupExperiment(startTime=0.0, stopTime=stop)
        p.slave.enterInitializationMode()
        p.slave.exitInitializationMode()
        c.slave.setupExperiment(startTime=0.0, stopTime=stop)
        c.slave.enterInitializationMode()
        c.take_inputs(p)
        c.slave.exitInitializationMode()
        p.take_inputs(c)

    def run(self, first, last, record=True):
        """Steps first..last; the bits of every output (but the wall-clock compute time)
        after each step, one row per step."""
        rows = []
        for k in range(first, last):
            t = k * H
            self.ctrl.take_inputs(self.plant)
            self.ctrl.slave.doStep(t, H)
            self.plant.take_inputs(self.ctrl)
            self.plant.slave.doStep(t, H)
            if record:
                rows.append(np.concatenate([
                    self.plant.output_bits(),
                    self.ctrl.output_bits(skip=("controller.compute_time",)),
                ]))
        return np.array(rows)

    def save(self, folder):
        for unit in (self.plant, self.ctrl):
            (pathlib.Path(folder) / STATE_FILES[unit.name]).write_bytes(unit.serialize())

    def restore(self, folder, stop):
        for unit in (self.plant, self.ctrl):
            unit.slave.setupExperiment(startTime=0.0, stopTime=stop)
            unit.restore((pathlib.Path(folder) / STATE_FILES[unit.name]).read_bytes())

    def free(self):
        for unit in (self.plant, self.ctrl):
            unit.slave.terminate()
            unit.slave.freeInstance()


def main(argv):
    plant, controller, folder, first, last, stop, out = argv
    with tempfile.TemporaryDirectory() as work:
        loop = Loop(plant, controller, work)
        loop.restore(folder, float(stop))
        rows = loop.run(int(first), int(last))
        loop.free()
    np.save(out, rows)


if __name__ == "__main__":
    main(sys.argv[1:])

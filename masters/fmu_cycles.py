"""Scale of use (issue 15, item 10): N load / instantiate / initialise / step / reset / free /
unload cycles of one FMU in one process, the resident set size (RSS) after cycle 1 and every
`every` cycles.

    .venv/bin/python masters/fmu_cycles.py target/fmu/TowingPlant.fmu 10000

fmpy loads the library in `FMU2Slave()` and unloads it in `freeInstance()`, so every cycle
also loads and unloads the shared library. Prints `cycle rss_kib` lines and the growth from
the first report after the warm-up (`every`) to the last.
"""
import argparse
import logging

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave


def rss_kib():
    """VmRSS of this process (KiB), from /proc/self/status."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def cycles(path, n, every=1000, steps=3, step_size=0.1):
    """Runs the cycles; returns the curve [(cycle, rss_kib)]."""
    md = read_model_description(path)
    unzipped = extract(path)
    curve = []
    for i in range(1, n + 1):
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="cycle")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        for k in range(steps):
            fmu.doStep(currentCommunicationPoint=k * step_size, communicationStepSize=step_size)
        fmu.reset()
        fmu.freeInstance()
        if i == 1 or i % every == 0:
            curve.append((i, rss_kib()))
    return curve


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("fmu")
    p.add_argument("cycles", type=int)
    p.add_argument("--every", type=int, default=1000)
    a = p.parse_args()
    logging.disable(logging.WARNING)
    curve = cycles(a.fmu, a.cycles, a.every)
    for i, rss in curve:
        print(i, rss)
    if len(curve) > 2:
        print(f"growth from cycle {curve[1][0]} to {curve[-1][0]}: {curve[-1][1] - curve[1][1]} KiB")


if __name__ == "__main__":
    main()

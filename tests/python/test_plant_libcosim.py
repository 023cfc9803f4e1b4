"""The packaged TowingPlant FMU as a single slave in libcosim (Open Simulation Platform)."""

import math

from libcosimpy.CosimEnums import CosimVariableType
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

NS = 1_000_000_000


def test_plant_steps_in_libcosim(plant_fmu):
    execution = CosimExecution.from_step_size(step_size=NS // 10)
    index = execution.add_local_slave(CosimLocalSlave(fmu_path=plant_fmu, instance_name="plant"))
    assert index == 0
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    assert execution.real_initial_value(index, refs["tug2.force_surge"], 3.0)
    assert execution.real_initial_value(index, refs["towline2.tension_cmd"], 2.0)
    observer = CosimObserver.create_last_value()
    assert execution.add_observer(observer)
    assert execution.simulate_until(target_time=30 * NS)
    names = ["ship.x", "ship.y", "towline2.tension", "obstacle[4].x"]
    x, y, tension, ax = observer.last_real_values(index, [refs[n] for n in names])
    psi0 = math.radians(101.3)
    along = (x + 4.9) * math.cos(psi0) + (y - 7.0) * math.sin(psi0)
    assert along > 0.5
    assert tension == 2.0
    assert abs(ax - (-19.0 + 0.07 * 30.0)) < 1e-9
    kinds = observer.last_integer_values(index, [refs["obstacle[1].kind"], refs["obstacle[5].kind"]])
    assert kinds == [1, 0]
    assert CosimVariableType.REAL.value == 0

"""Closing the loop between a plant FMU and a controller FMU in fmpy (a test extra): the
co-simulation master a user would write, at a fixed communication step. At each point the
plant's outputs go to the controller's inputs, the controller's command to the plant's
inputs, then both step. Returns the record as arrays (time, the plant's outputs, the command)."""
from __future__ import annotations

import shutil
import tempfile

import numpy as np


class _Slave:
    def __init__(self, path, parameters=None):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave
        self.folder = extract(str(path), tempfile.mkdtemp(prefix="mbc_fmu_"))
        md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.inputs = [v.name for v in md.modelVariables if v.causality == "input"]
        self.outputs = [v.name for v in md.modelVariables if v.causality == "output"]
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.folder,
                             modelIdentifier=md.coSimulation.modelIdentifier,
                             instanceName=md.coSimulation.modelIdentifier)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for name, value in (parameters or {}).items():
            self.fmu.setReal([self.vr[name]], [float(value)])
        self.fmu.exitInitializationMode()

    def get(self, names):
        return np.asarray(self.fmu.getReal([self.vr[n] for n in names]))

    def set(self, names, values):
        self.fmu.setReal([self.vr[n] for n in names], [float(v) for v in values])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.folder, ignore_errors=True)


def closed_loop(plant_fmu, controller_fmu, *, duration: float, step: float,
                plant_parameters=None, controller_parameters=None) -> dict:
    """Co-simulate the two FMUs for `duration` s at communication step `step` s.

    The plant FMU steps internally at `step` unless plant_parameters sets its "dt" (a
    divisor of `step`). Returns {"time": (n+1,), "outputs": names, "y": (n+1, ny) plant
    outputs, "commands": names, "u": (n, nu) the command held over each step}."""
    plant = _Slave(plant_fmu, {"dt": step, **(plant_parameters or {})})
    ctrl = _Slave(controller_fmu, controller_parameters)
    try:
        n = int(round(duration / step))
        ys, us = [], []
        for k in range(n):
            t = k * step
            y = plant.get(plant.outputs)
            ys.append(y)
            ctrl.set(ctrl.inputs, [y[plant.outputs.index(name)] for name in ctrl.inputs])
            u = ctrl.get(ctrl.outputs)
            us.append(u)
            plant.set(ctrl.outputs, u)
            plant.fmu.doStep(t, step)
            ctrl.fmu.doStep(t, step)
        ys.append(plant.get(plant.outputs))
        return {"time": np.arange(n + 1) * step, "outputs": plant.outputs, "y": np.array(ys),
                "commands": ctrl.outputs, "u": np.array(us)}
    finally:
        plant.close()
        ctrl.close()

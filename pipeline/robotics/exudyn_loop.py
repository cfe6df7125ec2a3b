"""Exudyn under a sampled-data controller: one Python call per control period, not per integration step.

The implicit solver (generalized-α, index-3 constraints, so closed loops stay closed to Newton tolerance)
is initialised once and then advanced period by period with `SolveSteps`; between two calls the controller
reads the state and changes actuator parameters (zero-order hold). Sensors with `storeInternal=True` record
the fine-step signals inside Exudyn, so the Python side never sees an individual integration step.
"""

from __future__ import annotations

import numpy as np


def quiet_settings(step: float, sensor_period: float, spectral_radius: float, newton_tolerance: float):
    """SimulationSettings for fast, silent closed-loop runs: no files, dense solver (small systems),
    modified Newton (the Jacobian is reused while it converges), sensors recorded every `sensor_period`."""
    import exudyn as exu

    s = exu.SimulationSettings()
    s.solution.file.write = False
    s.solution.sensors.writePeriod = sensor_period
    s.show.statistics = False
    s.show.computationTime = False
    s.linearSolver.solverType = exu.LinearSolverType.EigenDense
    s.parallel.numberOfThreads = 1
    ti = s.timeIntegration
    ti.verboseMode = 0
    ti.stepInformation = 0
    ti.adaptiveStep = False
    ti.newton.useModifiedNewton = True
    ti.newton.relativeTolerance = newton_tolerance
    ti.generalizedAlpha.spectralRadius = spectral_radius
    ti.endTime = step   # replaced per period by SampledDataSolver
    ti.numberOfSteps = 1
    return s


class SampledDataSolver:
    """Advance an assembled Exudyn system one control period at a time."""

    def __init__(self, mbs, settings, period: float, step: float):
        import exudyn as exu

        from pipeline.core.runlog import SimulationFailed

        self._failed = SimulationFailed
        self._exu = exu
        steps = round(period / step)
        if steps < 1 or abs(steps * step - period) > 1e-12 * period:
            raise ValueError(f"the control period {period} s must be a whole number of steps of {step} s")
        self.mbs, self.settings, self.period = mbs, settings, period
        settings.timeIntegration.numberOfSteps = steps
        settings.timeIntegration.endTime = period
        self.solver = exu.MainSolverImplicitSecondOrder()
        if not self.solver.InitializeSolver(mbs, settings):
            raise SimulationFailed(f"Exudyn could not initialise: {self.solver.GetErrorString()}")
        self.periods = 0

    @property
    def time(self) -> float:
        return self.periods * self.period

    def advance(self) -> None:
        """Integrate over the next period with whatever the actuators hold now.

        Every period restarts from the current state with accelerations consistent with the new actuator
        values: generalized-α otherwise carries the previous period's acceleration into the first step,
        which smears each torque jump over one step and makes the global error first order in the step."""
        data, configuration = self.mbs.systemData, self._exu.ConfigurationType
        ti = self.settings.timeIntegration
        ti.startTime, ti.endTime = self.time, self.time + self.period
        data.SetSystemState(data.GetSystemState(configuration.Current), configuration=configuration.Initial)
        try:
            self.solver.InitializeSolverInitialConditions(self.mbs, self.settings)
            ok = self.solver.SolveSteps(self.mbs, self.settings)
        except Exception as err:  # Exudyn raises on a singular Jacobian or a NaN residual
            raise self._failed(f"Exudyn failed at t = {self.time:.4g} s: {str(err).splitlines()[0]}") from None
        if not ok:
            raise self._failed(f"Exudyn did not converge at t = {self.time:.4g} s: {self.solver.GetErrorString()}")
        self.periods += 1

    def finish(self) -> None:
        self.solver.FinalizeSolver(self.mbs, self.settings)


def stored_sensor(mbs, sensor, step: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, values) recorded by a `storeInternal` sensor, one row per integration step: each period writes
    its first instant again (with a time that may differ in the last bits), the repeat is dropped."""
    data = np.asarray(mbs.GetSensorStoredData(sensor))
    _, first = np.unique(np.rint(data[:, 0] / step).astype(np.int64), return_index=True)
    return data[first, 0], data[first, 1:]

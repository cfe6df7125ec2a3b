"""One closed-loop run: a plant (Exudyn or the reduced Lagrangian), the sampled controller, the set-point.

The loop runs once per control period: sample (θ, θ̇), compute τ, hold it for the period (zero-order
hold, no computation delay, spec §3). The plant integrates the period in one call and keeps its fine-step
samples, which the metrics are evaluated on.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from pipeline.core.runlog import SimulationFailed
from pipeline.papers.scara_half_derivative.arm import Arm
from pipeline.papers.scara_half_derivative.controller import CartesianController
from pipeline.papers.scara_half_derivative.setpoint import Motion

DIVERGED_ERROR = 0.5   # m and rad: an error of x, y, z or θ this large means the loop is unstable, not tracking


def divergence(error: np.ndarray, t: float) -> str | None:
    """Why a tracking error (x, y, z, θ) means the loop diverged, or None (NaN diverges too)."""
    worst = int(np.argmax(np.where(np.isfinite(error), np.abs(error), np.inf)))
    if np.abs(error[worst]) < DIVERGED_ERROR:
        return None
    return f"unstable: {'xyzθ'[worst]} error {abs(error[worst]):.3g} {'rad' if worst == 3 else 'm'} at t = {t:.4g} s"


class Plant(Protocol):
    dt: float

    def state(self) -> tuple[np.ndarray, np.ndarray]: ...
    def advance(self, tau: np.ndarray) -> None: ...
    def fine(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@dataclass(frozen=True)
class PlantSettings:
    kind: str                 # exudyn | lagrange
    dt: float                 # integration step (s)
    spectral_radius: float    # generalized-α ρ∞ (Exudyn)
    newton_tolerance: float   # relative Newton tolerance (Exudyn)


def make_plant(settings: PlantSettings, arm: Arm, q0, qd0, period: float, periods: int) -> Plant:
    if settings.kind == "exudyn":
        from pipeline.papers.scara_half_derivative.multibody import ExudynPlant

        return ExudynPlant(arm, q0, qd0, period, settings.dt, settings.spectral_radius, settings.newton_tolerance)
    if settings.kind == "lagrange":
        from pipeline.papers.scara_half_derivative.lagrange import LagrangePlant

        substeps = round(period / settings.dt)
        if substeps < 1 or abs(substeps * settings.dt - period) > 1e-12:
            raise ValueError(f"the control period {period} s must be a whole number of steps of {settings.dt} s")
        return LagrangePlant(arm, q0, qd0, period, substeps, periods)
    raise ValueError(f"unknown plant '{settings.kind}': exudyn or lagrange")


@dataclass
class ClosedLoopRun:
    """What one closed-loop run produced: per control period and per integration step."""

    t_control: np.ndarray     # (K,) control instants
    tau: np.ndarray           # (K, 4) torques held over each period
    controller_s: np.ndarray  # (K,) wall time of each controller call
    t: np.ndarray             # (N,) integration steps
    q: np.ndarray             # (N, 4)
    qd: np.ndarray            # (N, 4)
    loop_residual: np.ndarray | None = None   # (K,) Exudyn's loop-closure gap at each control instant
    tau_fine: np.ndarray | None = None        # (N−1, 4) torques over each integration step, when they are
                                              # not held over the period (the `continuous` implementation)


def run_closed_loop(plant: Plant, controller: CartesianController, motion: Motion, duration: float,
                    period: float) -> ClosedLoopRun:
    periods = round(duration / period)
    t_control = np.arange(periods) * period
    x_d, xd_d, _ = motion(t_control)
    tau = np.empty((periods, 4))
    wall = np.empty(periods)
    residual_of = getattr(plant, "loop_residual", None)
    residual = np.empty(periods) if residual_of is not None else None
    clock = time.perf_counter_ns
    for k in range(periods):
        q, qd = plant.state()
        start = clock()
        tau[k] = controller(q, qd, x_d[k], xd_d[k])
        wall[k] = clock() - start
        why = divergence(controller.error, t_control[k])
        if why or not np.isfinite(tau[k]).all():
            raise SimulationFailed(why or f"unstable: non-finite torque at t = {t_control[k]:.4g} s")
        if residual is not None:
            residual[k] = residual_of()
        plant.advance(tau[k])
    t, q, qd = plant.fine()
    return ClosedLoopRun(t_control, tau, wall * 1e-9, t, q, qd, residual)


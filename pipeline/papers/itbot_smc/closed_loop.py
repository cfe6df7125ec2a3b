"""One closed-loop run: a plant (analytic or MuJoCo), the joint sensor, the sliding-mode controller, the
reference of the passive exercise.

Each control tick: sample the plant, measure (quantise, estimate the velocity), compute τ (eq. 5), clip it to
the drives' limit, hold it for the period. The run keeps the true and the measured states, the sliding
variable, the torques and each controller call's wall time, one row per tick.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from pipeline.core.runlog import SimulationFailed
from pipeline.papers.itbot_smc.controller import JointSensor, SlidingModeController
from pipeline.papers.itbot_smc.plants import Plant

DIVERGED = math.radians(45.0)   # a joint error this large means the loop has lost the arm, not tracking


@dataclass(frozen=True)
class Reference:
    """θ_d(t) = start + amplitude (1 − cos(2π t / period)) / 2 per joint, for `cycles` periods (rad, s)."""

    start: np.ndarray
    amplitude: np.ndarray
    period: float
    cycles: int

    @classmethod
    def from_config(cls, reference) -> Reference:
        return cls(np.radians(np.asarray(list(reference.start_deg), dtype=float)),
                   np.radians(np.asarray(list(reference.amplitude_deg), dtype=float)),
                   float(reference.period), int(reference.cycles))

    @property
    def duration(self) -> float:
        return self.period * self.cycles

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(N, 2) position, velocity and acceleration at times t (s)."""
        w = 2 * np.pi / self.period
        phase = w * np.asarray(t, dtype=float)[:, None]
        half = self.amplitude / 2
        return (self.start + half * (1 - np.cos(phase)), half * w * np.sin(phase), half * w * w * np.cos(phase))


@dataclass
class ClosedLoopRun:
    """One row per control tick k (t_k = k T)."""

    t: np.ndarray             # (K,) s
    q: np.ndarray             # (K, 2) true joint angles at the tick (rad)
    qd: np.ndarray            # (K, 2) true joint rates (rad/s)
    q_measured: np.ndarray    # (K, 2) what the controller saw
    qd_measured: np.ndarray
    v: np.ndarray             # (K, 2) sliding variable (rad/s), eq. (3)
    tau: np.ndarray           # (K, 2) torque applied over [t_k, t_k+1) (N m)
    controller_s: np.ndarray  # (K,) wall time of each controller call
    hand_force: np.ndarray    # (K, 2) force of the hand on the handle at the tick (frame 0, N)


def run_closed_loop(plant: Plant, controller: SlidingModeController, sensor: JointSensor, reference: Reference,
                    period: float, torque_limit) -> ClosedLoopRun:
    ticks = round(reference.duration / period)
    t = np.arange(ticks) * period
    q_d, qd_d, qdd_d = reference(t)
    limit = (float(torque_limit[0]), float(torque_limit[1]))
    rows = {name: np.empty((ticks, 2)) for name in ("q", "qd", "q_measured", "qd_measured", "v", "tau")}
    wall = np.empty(ticks)
    clock = time.perf_counter_ns
    reference = [tuple(map(tuple, x.tolist())) for x in (q_d, qd_d, qdd_d)]   # floats: the controller's arithmetic
    times = t.tolist()
    for k in range(ticks):
        q, qd = plant.state()
        q_m, qd_m = sensor(q, qd)
        start = clock()
        tau = controller(times[k], q_m, qd_m, reference[0][k], reference[1][k], reference[2][k])
        wall[k] = clock() - start
        error = max(abs(q[0] - reference[0][k][0]), abs(q[1] - reference[0][k][1]))
        if not (error < DIVERGED and math.isfinite(tau[0] + tau[1])):   # NaN fails the comparison too
            raise SimulationFailed(f"lost the arm: joint error {math.degrees(error):.3g}° at t = {times[k]:.4g} s")
        tau = (min(max(tau[0], -limit[0]), limit[0]), min(max(tau[1], -limit[1]), limit[1]))
        rows["q"][k], rows["qd"][k], rows["q_measured"][k], rows["qd_measured"][k] = q, qd, q_m, qd_m
        rows["v"][k], rows["tau"][k] = controller.v, tau
        plant.advance(tau)
    force = plant.hand_forces(rows["q"], rows["qd"], rows["tau"])
    return ClosedLoopRun(t=t, controller_s=wall * 1e-9, hand_force=force, **rows)

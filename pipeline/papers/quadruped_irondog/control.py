"""The controllers of the MuJoCo experiments, each a function (t, IMU roll/pitch/yaw) -> joint references (4, 3).

- `BodyPose`: body IK about a nominal stance (Sec. 3.2, Fig. 18): the feet stay, the trunk moves.
- `Levelling`: Sec. 4.3's PID on the IMU's roll and pitch, its output a body rotation through body IK (the trunk
  "always lies flat", Fig. 19e; roll is met by the coxa angles, Fig. 20e).
- `TrotController`: stand in the Table 5 pose, rise to the gait's stance, then trot (Sec. 3.3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.quadruped_irondog.gait import Trot
from pipeline.papers.quadruped_irondog.kinematics import Layout, Leg, body_ik, feet_in_body, fk, ik


def smoothstep(x) -> np.ndarray:
    """Minimum-jerk 0 -> 1 over x ∈ [0, 1] (clipped outside)."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    return x ** 3 * (10 - 15 * x + 6 * x * x)


class BodyPose:
    """Joint angles for a trunk pose (position offset, roll/pitch/yaw) relative to the nominal stance q_nominal,
    the feet fixed where the nominal stance puts them."""

    def __init__(self, leg: Leg, layout: Layout, q_nominal: np.ndarray):
        self.leg, self.layout = leg, layout
        self.feet = feet_in_body(leg, layout, q_nominal)

    def __call__(self, position, rpy) -> np.ndarray:
        return body_ik(self.leg, self.layout, self.feet, position, rpy)


@dataclass
class PoseSchedule:
    """Fig. 18's scenarios in turn: each ramps to its (x, y, z, roll, pitch, yaw) offset, holds, and returns."""

    offsets: np.ndarray     # (S, 6) m and rad
    ramp: float             # s
    hold: float             # s
    start: float = 0.0      # s, the first ramp begins here

    @property
    def slot(self) -> float:
        return 2 * self.ramp + self.hold

    @property
    def duration(self) -> float:
        return self.start + len(self.offsets) * self.slot

    def __call__(self, t) -> np.ndarray:
        """(..., 6) commanded offset at times t."""
        t = np.asarray(t, dtype=float) - self.start
        k = np.clip((t // self.slot).astype(int), 0, len(self.offsets) - 1)
        local = t - k * self.slot
        weight = np.where(local < self.ramp + self.hold, smoothstep(local / self.ramp),
                          1.0 - smoothstep((local - self.ramp - self.hold) / self.ramp))
        weight = np.where((t < 0) | (t >= len(self.offsets) * self.slot), 0.0, weight)
        return self.offsets[k] * weight[..., None]

    def holding(self, t) -> np.ndarray:
        """(...,) scenario index (0-based) while its pose is held, −1 elsewhere."""
        t = np.asarray(t, dtype=float) - self.start
        k = (t // self.slot).astype(int)
        local = t - k * self.slot
        held = (t >= 0) & (k < len(self.offsets)) & (local >= self.ramp) & (local < self.ramp + self.hold)
        return np.where(held, k, -1)


class Levelling:
    """PID on the trunk's roll and pitch (target: level), its output the body rotation commanded through body IK,
    evaluated at the control rate; `enabled = False` holds the nominal stance (the open-loop comparison)."""

    def __init__(self, pose: BodyPose, kp: float, ki: float, kd: float, limit: float, dt: float,
                 enabled: bool = True):
        self.pose, self.kp, self.ki, self.kd, self.limit, self.dt = pose, kp, ki, kd, limit, dt
        self.enabled = enabled
        self.integral = np.zeros(2)
        self.previous: np.ndarray | None = None
        self.output = np.zeros(2)

    def __call__(self, t: float, rpy: np.ndarray) -> np.ndarray:
        if self.enabled:
            error = -np.asarray(rpy[:2], dtype=float)
            derivative = np.zeros(2) if self.previous is None else (error - self.previous) / self.dt
            self.previous = error
            # the integral stops where the output saturates (anti-windup)
            trial = self.integral + error * self.dt
            output = self.kp * error + self.ki * trial + self.kd * derivative
            if (np.abs(output) <= self.limit).all():
                self.integral = trial
            else:
                output = self.kp * error + self.ki * self.integral + self.kd * derivative
            self.output = np.clip(output, -self.limit, self.limit)
        return self.pose(np.zeros(3), np.array([self.output[0], self.output[1], 0.0]))


@dataclass
class TrotController:
    """Stand (Table 5) for `settle` s; rise over `rise` s to the trot's first stance (stride 0); trot, the stride
    ramping from 0 to `stride_scale` over `ramp` s so the feet leave the Table 5 spot without sliding."""

    leg: Leg
    trot: Trot
    q_stand: np.ndarray
    settle: float
    rise: float
    ramp: float
    stride_scale: float

    def __post_init__(self):
        self._stand = fk(self.leg, self.q_stand)          # the Table 5 feet, and the trot's first ones
        self._first = self.trot.feet(0.0, 0.0)[0]

    @property
    def start(self) -> float:
        """s, when the trot begins."""
        return self.settle + self.rise

    def stride(self, t) -> np.ndarray:
        return self.stride_scale * np.clip((np.asarray(t, dtype=float) - self.start) / self.ramp, 0.0, 1.0)

    def feet(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(..., 4, 3) desired foot positions in the leg frames at times t (...), and (..., 4) swing flags."""
        t = np.asarray(t, dtype=float)
        w = smoothstep((t - self.settle) / self.rise)[..., None, None]
        p, swing = self.trot.feet(np.maximum(t - self.start, 0.0), self.stride(t))
        trotting = (t >= self.start)[..., None, None]
        return np.where(trotting, p, self._stand + (self._first - self._stand) * w), swing & trotting[..., 0]

    def __call__(self, t: float, rpy: np.ndarray) -> np.ndarray:
        return ik(self.leg, self.feet(t)[0])

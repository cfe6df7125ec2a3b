"""The 6-phase set-point motion of Sec. 4 (Figs. 4-5).

From x_ref the set-point moves a distance d along +x, +y, +z, −x, −y, −z in turn; each phase goes out in
t_mov, stops t_stop, comes back in t_mov and stops t_stop, so the motion lasts 12 (t_mov + t_stop). Each
move has a trapezoidal velocity profile (the paper's "s-curve": acceleration for α t_mov, constant velocity,
deceleration for α t_mov). The orientation θ stays constant. Motion starts at t = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from omegaconf import DictConfig

from pipeline.robotics.profiles import trapezoid


@dataclass(frozen=True)
class Motion:
    home: np.ndarray            # x_ref = [x, y, z, θ]
    distance: float             # d
    t_move: float               # t_mov
    t_stop: float               # t_stop
    accel_fraction: float       # α
    directions: np.ndarray      # (phases, 3) unit directions of the moves

    @classmethod
    def from_config(cls, motion: DictConfig, home: np.ndarray) -> Motion:
        return cls(home=np.asarray(home, dtype=float), distance=motion.distance, t_move=motion.t_move,
                   t_stop=motion.t_stop, accel_fraction=motion.accel_fraction,
                   directions=np.asarray(motion.directions, dtype=float))

    @property
    def duration(self) -> float:
        return 2 * len(self.directions) * (self.t_move + self.t_stop)

    @property
    def v_max(self) -> float:
        return self.distance / ((1 - self.accel_fraction) * self.t_move)

    @property
    def a_max(self) -> float:
        return self.v_max / (self.accel_fraction * self.t_move)

    def __call__(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x_d, ẋ_d, ẍ_d), each (len(t), 4)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = [np.zeros((len(t), 4)) for _ in range(3)]
        out[0][:] = self.home
        phase = 2 * (self.t_move + self.t_stop)
        back = self.t_move + self.t_stop
        for k, direction in enumerate(self.directions):
            go = trapezoid(t - k * phase, self.distance, self.t_move, self.accel_fraction)
            ret = trapezoid(t - k * phase - back, self.distance, self.t_move, self.accel_fraction)
            for total, g, r in zip(out, go, ret, strict=True):
                total[:, :3] += np.outer(g - r, direction)
        return out[0], out[1], out[2]

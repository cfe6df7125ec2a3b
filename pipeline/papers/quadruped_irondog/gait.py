"""The 14-point Bezier swing (Sec. 3.3, eqs. 41-44, Table 3) and the trot built from it.

The swing is B(s), s ∈ [0, 1] over the swing time; the stance (not given in the paper) is the straight line from
B(1) back to B(0) at constant speed (spec §3.3). A trot moves the diagonal pairs half a period apart, FL + BR
first (Sec. 3.3).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.special import comb

from pipeline.papers.quadruped_irondog.kinematics import LEGS


def bernstein(s, degree: int) -> np.ndarray:
    """(..., degree + 1) Bernstein basis b_K(s) = f(N, K) (1 − s)^(N−K) s^K of eq. (42), N = degree; f(N, K) is the
    binomial coefficient (eq. 41 prints d!/(K!(d − l)!) for N!/(K!(N − K)!))."""
    s = np.asarray(s, dtype=float)[..., None]
    k = np.arange(degree + 1)
    return _binomials(degree) * (1.0 - s) ** (degree - k) * s ** k


@functools.cache
def _binomials(degree: int) -> np.ndarray:
    return comb(degree, np.arange(degree + 1))


def bezier(points, s) -> np.ndarray:
    """(..., dim) points of the Bezier curve with control points (n, dim) at s (...): eqs. (43)-(44)."""
    points = np.asarray(points, dtype=float)
    return bernstein(s, len(points) - 1) @ points


def bezier_derivative(points, s) -> np.ndarray:
    """(..., dim) dB/ds: the degree N − 1 curve of the differences N (P_{K+1} − P_K)."""
    points = np.asarray(points, dtype=float)
    return bezier((len(points) - 1) * np.diff(points, axis=0), s)


def de_casteljau(points, s: float) -> np.ndarray:
    """B(s) by repeated linear interpolation: an independent evaluation of the same curve."""
    p = np.asarray(points, dtype=float)
    while len(p) > 1:
        p = (1.0 - s) * p[:-1] + s * p[1:]
    return p[0]


# Trot: the phase each leg starts at (FL + BR swing first, Sec. 3.3)
TROT_OFFSET = {"FR": 0.5, "FL": 0.0, "BR": 0.0, "BL": 0.5}


@dataclass(frozen=True)
class Trot:
    """The Table 3 swing and a straight stance, as foot positions in each leg frame.

    control_points: (14, 2) (a, d) in m; a is the fore-aft coordinate, d the vertical one. The foot's forward
    coordinate is `a_sign · a · stride_scale`, its lateral one the coxa offset L1 (θ1 = 0 under the femur).
    """

    control_points: np.ndarray
    swing_time: float
    stance_time: float
    a_sign: float
    lateral: float
    offsets: tuple[float, ...] = tuple(TROT_OFFSET[leg] for leg in LEGS)

    @property
    def period(self) -> float:
        return self.swing_time + self.stance_time

    @property
    def swing_fraction(self) -> float:
        return self.swing_time / self.period

    def phase(self, t) -> np.ndarray:
        """(..., 4) gait phase in [0, 1) of each leg at times t (...): swing while phase < swing_fraction."""
        return np.mod(np.asarray(t, dtype=float)[..., None] / self.period + np.asarray(self.offsets), 1.0)

    def curve(self, phase) -> np.ndarray:
        """(..., 2) (a, d) of the foot at gait phase (...): Bezier swing, then the straight stance back."""
        phase = np.asarray(phase, dtype=float)
        f = self.swing_fraction
        swing = phase < f
        s = np.where(swing, phase / f, (phase - f) / (1.0 - f))
        P = self.control_points
        on_swing = bezier(P, np.where(swing, s, 0.0))
        on_stance = P[-1] + s[..., None] * (P[0] - P[-1])
        return np.where(swing[..., None], on_swing, on_stance)

    def feet(self, t, stride_scale) -> tuple[np.ndarray, np.ndarray]:
        """(..., 4, 3) foot positions in each leg frame at times t (...), and (..., 4) swing flags; `stride_scale`
        (scalar or (...)) scales the fore-aft coordinate (a ramp from 0 starts the gait in place)."""
        phase = self.phase(t)
        ad = self.curve(phase)
        scale = np.asarray(stride_scale, dtype=float)[..., None]
        forward = self.a_sign * ad[..., 0] * scale
        p = np.stack([np.full_like(forward, self.lateral), ad[..., 1], forward], axis=-1)
        return p, phase < self.swing_fraction

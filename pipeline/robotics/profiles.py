"""Point-to-point motion profiles shared by every paper (vectorized over time)."""

from __future__ import annotations

import numpy as np


def trapezoid(t: np.ndarray, distance: float, duration: float, accel_fraction: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Trapezoidal velocity profile from 0 to `distance` in `duration`: constant acceleration for
    accel_fraction·duration, constant velocity, then the mirror deceleration (piecewise-constant
    acceleration, infinite jerk). Returns position, velocity, acceleration at `t`; before 0 the profile
    rests at 0, after `duration` at `distance`."""
    if not 0 < accel_fraction <= 0.5:
        raise ValueError(f"accel_fraction={accel_fraction} must be in (0, 0.5]")
    t = np.asarray(t, dtype=float)
    ta = accel_fraction * duration
    v_max = distance / (duration - ta)
    a_max = v_max / ta
    tc = np.clip(t, 0.0, duration)
    rising, falling = tc < ta, tc > duration - ta
    s = np.where(rising, 0.5 * a_max * tc ** 2,
                 np.where(falling, distance - 0.5 * a_max * (duration - tc) ** 2, v_max * (tc - 0.5 * ta)))
    v = np.where(rising, a_max * tc, np.where(falling, a_max * (duration - tc), v_max))
    a = np.where(rising, a_max, np.where(falling, -a_max, 0.0))
    moving = (t > 0) & (t < duration)
    return s, np.where(moving, v, 0.0), np.where(moving, a, 0.0)


# Peaks of |s'|, |s''|, |s'''| of `septic` over τ ∈ [0, 1]
SEPTIC_PEAKS = (2.1875, 7.513188404399293, 52.5)


def septic(tau: np.ndarray) -> np.ndarray:
    """(4, ...): s = 35τ⁴ − 84τ⁵ + 70τ⁶ − 20τ⁷ and its first three τ-derivatives, the 7th-order rest-to-rest
    blend from 0 to 1 with zero velocity, acceleration and jerk at both ends. τ outside [0, 1] holds the end."""
    tau = np.asarray(tau, dtype=float)
    t = np.clip(tau, 0.0, 1.0)
    inside = (tau > 0) & (tau < 1)
    s = t ** 4 * (35 - 84 * t + 70 * t ** 2 - 20 * t ** 3)
    d1 = 140 * t ** 3 * (1 - t) ** 3
    d2 = 420 * t ** 2 * (1 - t) ** 2 * (1 - 2 * t)
    d3 = 840 * t * (1 - t) * (1 - 5 * t + 5 * t ** 2)
    return np.stack([s, d1 * inside, d2 * inside, d3 * inside])


def interpolate(t: np.ndarray, times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Rows of `values` (N, ...) sampled at increasing `times` (N,), linearly interpolated at each of `t` and
    held outside [times[0], times[-1]]: np.interp for every column at once (its values at the samples exactly)."""
    t, times, values = np.asarray(t, dtype=float), np.asarray(times, dtype=float), np.asarray(values, dtype=float)
    if len(times) == 1:
        return np.repeat(values, len(t), axis=0)
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    w = np.clip((t - times[k]) / (times[k + 1] - times[k]), 0.0, 1.0).reshape(-1, *(1,) * (values.ndim - 1))
    return (1 - w) * values[k] + w * values[k + 1]

"""Algorithm 1 assembled: at every sample, IK at α = 0, the nearest obstacle point, the imminent-collision
test, α_c, the critically damped filter and IK at α_f; and the circle task of Sec. 5.

Lines 3-47 of Algorithm 1 depend only on the α = 0 posture and the obstacle at sample n (the paper tests the
α = 0 chain, not the executed one), so `plan` runs them for all samples at once; only the filter (line 48)
is sequential, and SciPy runs it. `Online` runs the same functions one sample at a time, as a controller
would (the per-iteration compute time is measured on it, and it must give the same motion).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.srs_collision_avoidance import avoidance, swivel_filter
from pipeline.papers.srs_collision_avoidance.avoidance import Forms, SafetyVolume, Selection
from pipeline.papers.srs_collision_avoidance.humans import nearest_obstacle_point
from pipeline.papers.srs_collision_avoidance.kinematics import Geometry, Unreachable, ik, pose, rot_x


@dataclass(frozen=True)
class Settings:
    geometry: Geometry
    volume: SafetyVolume
    forms: Forms
    filter: swivel_filter.Coefficients | None   # None: α_f = α_c (unfiltered ablation)
    avoidance: bool = True                        # False: α_f = 0 throughout (the task alone)
    obstacle: str = "capsules"                    # capsules | points: what P_c is taken from
    initial_alpha: float = 0.0                    # α_c, α_f at n = −1, −2 (rad)
    shoulder_sign: float = 1.0
    wrist_sign: float = 1.0


@dataclass(frozen=True)
class Plan:
    """Everything Algorithm 1 computed, per sample."""

    poses: np.ndarray        # (N, 4, 4) desired tool poses
    q0: np.ndarray           # (N, 7) IK at α = 0 (line 3)
    points0: np.ndarray      # (N, 3, 3) P_s, P_e, P_w at α = 0 (line 4)
    P_c: np.ndarray          # (N, 3) nearest obstacle point (line 6)
    obstacle_distance: np.ndarray   # (N,) its distance to the α = 0 links (m)
    obstacle_owner: np.ndarray      # (N,) index of the human capsule it lies on
    selection: Selection     # lines 10-40
    g: np.ndarray            # (N,) side of plane π2 (eq. 19), NaN where nothing was found
    alpha_c: np.ndarray      # (N,) rad (lines 41-47)
    alpha_f: np.ndarray      # (N,) rad (line 48)
    q: np.ndarray            # (N, 7) IK at α_f (line 49), each joint unwrapped along the samples
    points: np.ndarray       # (N, 3, 3) P_s, P_e, P_w executed


def circle_poses(centre, radius: float, rides: float, samples: int, start_phase: float = 0.0,
                 direction: float = 1.0, tool_axis: str = "down") -> np.ndarray:
    """(N, 4, 4) Sec. 5's task: O_e rides a circle in the plane y_b = centre_y, z_e normal to x_b z_b
    (−y_b for `down`, +y_b for `up`), x_e = x_b; φ_n = start_phase + direction·2π·rides·n/N."""
    n = np.arange(samples)
    phi = start_phase + direction * 2 * np.pi * rides * n / samples
    p = np.asarray(centre, dtype=float) + radius * np.stack([np.cos(phi), np.zeros_like(phi), np.sin(phi)], -1)
    R = rot_x(np.pi / 2 if tool_axis == "down" else -np.pi / 2)
    return pose(np.broadcast_to(R, (samples, 3, 3)), p)


def _keep_previous(alpha_c: np.ndarray, blind: np.ndarray, initial: float) -> np.ndarray:
    """Where a collision is imminent but P_c lies in plane π2 (g = 0, eqs. 20-21: no direction to turn), keep
    the previous α_c (the paper gives no rule)."""
    if not blind.any():
        return alpha_c
    index = np.where(blind, 0, np.arange(1, len(alpha_c) + 1))
    return np.r_[initial, alpha_c][np.maximum.accumulate(index)]


def plan(poses: np.ndarray, start: np.ndarray, end: np.ndarray, radius: np.ndarray, s: Settings) -> Plan:
    """Algorithm 1 at every sample; the obstacle is the capsules (start, end: (N, m, 3); radius (m,))."""
    g = s.geometry
    zero = ik(poses, 0.0, g, s.shoulder_sign, s.wrist_sign)                                  # line 3
    if not np.isfinite(zero.q).all():
        bad = int(np.argmax(~np.isfinite(zero.q).all(axis=1)))
        raise Unreachable(f"the tool pose of sample {bad} is out of reach: wrist centre "
                          f"{np.round(zero.P_w[bad], 4).tolist()} m")
    points0 = np.stack([zero.P_s, zero.P_e, zero.P_w], axis=1)
    P_c, distance, owner = nearest_obstacle_point((zero.P_s, zero.P_e, zero.P_w), start, end, radius,
                                                  s.obstacle)                                 # line 6
    sel = avoidance.select(P_c, zero.P_s, zero.P_e, zero.P_w, s.volume, s.forms)             # lines 10-40
    alpha_c, side = avoidance.avoidance_angle(P_c, sel, zero.P_s, zero.P_e, zero.P_w, s.forms.alpha_c)
    alpha_c = _keep_previous(alpha_c, sel.find & (side == 0), s.initial_alpha)
    if not s.avoidance:
        alpha_c = np.zeros_like(alpha_c)
    if s.filter is None:
        alpha_f = alpha_c.copy()
    else:
        alpha_f = swivel_filter.apply(s.filter, alpha_c, s.initial_alpha)                     # line 48
    executed = ik(poses, alpha_f, g, s.shoulder_sign, s.wrist_sign)                          # line 49
    return Plan(poses=poses, q0=zero.q, points0=points0, P_c=P_c, obstacle_distance=distance,
                obstacle_owner=owner, selection=sel, g=side, alpha_c=alpha_c, alpha_f=alpha_f,
                q=np.unwrap(executed.q, axis=0),
                points=np.stack([executed.P_s, executed.P_e, executed.P_w], axis=1))


class Online:
    """Algorithm 1 one iteration at a time (what runs in a controller every T)."""

    def __init__(self, s: Settings):
        self.s = s
        self.alpha_c = [s.initial_alpha, s.initial_alpha]   # α_c(n−1), α_c(n−2)
        self.alpha_f = [s.initial_alpha, s.initial_alpha]

    def step(self, T: np.ndarray, start: np.ndarray, end: np.ndarray, radius: np.ndarray) -> np.ndarray:
        """Joint vector (7,) for tool pose T (4, 4) and the obstacle capsules (m, 3), (m, 3), (m,) at this sample."""
        s, g = self.s, self.s.geometry
        zero = ik(T[None], 0.0, g, s.shoulder_sign, s.wrist_sign)                            # lines 3-4
        P_c, _, _ = nearest_obstacle_point((zero.P_s, zero.P_e, zero.P_w), start[None], end[None], radius,
                                           s.obstacle)                                        # line 6
        sel = avoidance.select(P_c, zero.P_s, zero.P_e, zero.P_w, s.volume, s.forms)         # lines 10-40
        alpha, side = avoidance.avoidance_angle(P_c, sel, zero.P_s, zero.P_e, zero.P_w, s.forms.alpha_c)
        alpha_c = float(alpha[0]) if not (sel.find[0] and side[0] == 0) else self.alpha_c[0]
        if not s.avoidance:
            alpha_c = 0.0
        if s.filter is None:
            alpha_f = alpha_c
        else:
            alpha_f = s.filter.step(self.alpha_c, self.alpha_f)                               # line 48, eq. (3)
        self.alpha_c = [alpha_c, self.alpha_c[0]]
        self.alpha_f = [alpha_f, self.alpha_f[0]]
        return ik(T, alpha_f, g, s.shoulder_sign, s.wrist_sign).q                             # line 49

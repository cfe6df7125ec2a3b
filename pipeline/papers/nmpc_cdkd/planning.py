"""Sec. 3.1: the 7th-order joint polynomial (7)-(8) and the automatic configuration selection (6), (9)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.nmpc_cdkd import kinematics as kin
from pipeline.papers.nmpc_cdkd.kinematics import Arm
from pipeline.robotics.profiles import SEPTIC_PEAKS, septic


@dataclass(frozen=True)
class JointPolynomial:
    """γ(t) of (7)-(8): q0 at t ≤ t0, q1 at t ≥ t0 + T, the septic blend in between (zero velocity,
    acceleration and jerk at both ends; the paper states zero acceleration and jerk, rest is implied)."""

    q0: np.ndarray
    q1: np.ndarray
    t0: float
    T: float

    def __call__(self, t: np.ndarray, order: int = 0) -> np.ndarray:
        """(len(t), n): the `order`-th time derivative (0..3) of γ."""
        s = septic((np.asarray(t, dtype=float) - self.t0) / self.T)[order]
        scale = 1.0 if order == 0 else self.T ** -order
        base = self.q0 if order == 0 else np.zeros_like(self.q0)
        return base + np.multiply.outer(s * scale, self.q1 - self.q0)


def transition_time(q0: np.ndarray, q1: np.ndarray, velocity: np.ndarray, acceleration: float, jerk: float,
                    margin: float, t_min: float) -> float:
    """The shortest T ≥ t_min for which the polynomial uses at most `margin` of the speed, acceleration and
    jerk limits ("T must be chosen so that the dynamic joint limits are not violated", Sec. 3.1)."""
    dq = np.abs(q1 - q0)
    return float(max(t_min, np.max(SEPTIC_PEAKS[0] * dq / (margin * velocity)),
                     np.sqrt(np.max(SEPTIC_PEAKS[1] * dq) / (margin * acceleration)),
                     np.cbrt(np.max(SEPTIC_PEAKS[2] * dq) / (margin * jerk))))


@dataclass(frozen=True)
class Selection:
    q_start: np.ndarray
    q_goal: np.ndarray
    candidates: int        # start × goal pairs inside the joint limits (6)
    jump_free: int         # of those, pairs without a jump
    margin: float          # eq. (9) value of the selected pair, rad


def _flags(arm: Arm, path: np.ndarray, wrist_band: float) -> np.ndarray:
    """Branch flags along a path; a wrist within `wrist_band` of q5 = 0 has no defined wrist flag (0)."""
    flags = kin.branch_flags(arm, path)
    flags[..., 2] = np.where(np.abs(np.sin(path[..., 4])) < np.sin(wrist_band), 0.0, flags[..., 2])
    return flags


def _has_jump(flags: np.ndarray) -> bool:
    """A change of a defined flag between any two samples (an undefined flag, 0, matches both)."""
    defined = flags != 0
    ref = np.where(defined.any(axis=0), flags[np.argmax(defined, axis=0), np.arange(flags.shape[1])], 0)
    return bool(np.any(defined & (flags != ref)))


def select_configuration(arm: Arm, T_start: np.ndarray, T_goal: np.ndarray, samples: int, wrist_band: float,
                         tie_tol: float = 1e-6) -> Selection:
    """Start and goal joint sets for a point-to-point move (Sec. 3.1).

    Every start/goal pair of IK solutions inside Q (6) is joined by the polynomial and sampled; pairs whose
    shoulder, elbow or wrist configuration changes along the way (a "jump") are dropped; of the rest, eq. (9)
    picks the pair whose smallest joint-limit margin over all joints and samples is largest. Pairs within
    `tie_tol` of it are broken by the least joint displacement ("preselection of the closest solution",
    Table 1). The paper starts from the robot's current joints; choosing the start jointly is our assumption."""
    starts = [q for q in kin.ik(arm, T_start) if kin.within_limits(arm, q)]
    goals = [q for q in kin.ik(arm, T_goal) if kin.within_limits(arm, q)]
    s = septic(np.linspace(0.0, 1.0, samples))[0]
    scored = []
    for q0 in starts:
        for q1 in goals:
            path = q0 + np.multiply.outer(s, q1 - q0)
            if _has_jump(_flags(arm, path, wrist_band)):
                continue
            scored.append((float(kin.limit_margin(arm, path).min()), float(np.abs(q1 - q0).sum()), q0, q1))
    if not scored:
        raise ValueError("no jump-free pair of IK solutions inside the joint limits joins the two poses")
    best = max(m for m, *_ in scored)
    margin, _, q0, q1 = min((x for x in scored if x[0] >= best - tie_tol), key=lambda x: x[1])
    return Selection(q0, q1, len(starts) * len(goals), len(scored), margin)

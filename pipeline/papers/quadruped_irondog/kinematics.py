"""Leg and body kinematics of Iron Dog Mini (Sec. 3.1), vectorised over leading axes.

Leg frame (spec §3.1), origin at the coxa joint: x lateral (outward, along the coxa offset), y up, z forward.
θ1 turns the coxa (roll), θ2 the femur, θ3 the tibia (knee); all zero puts the leg straight down, the foot at
(L1, −(L2 + L3), 0). θ3 > 0 bends the knee with the foot moving forward (the knee points backward).

Body frame: x forward, y left, z up, origin at the centre of the four hips. Legs are ordered as in the paper's
Table 5: FR, FL, BR, BL. A right leg is the mirror image of a left leg (its leg frame has x = −y_body), so the same
joint angles give mirrored poses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LEGS = ("FR", "FL", "BR", "BL")
SIDE = np.array([-1.0, 1.0, -1.0, 1.0])     # +1: left leg (its lateral axis is +y_body)
FRONT = np.array([1.0, 1.0, -1.0, -1.0])
JOINTS = ("coxa", "femur", "tibia")
JOINT_NAMES = [f"{leg}_{joint}" for leg in LEGS for joint in JOINTS]


@dataclass(frozen=True)
class Leg:
    """Link lengths (m): L1 coxa offset, L2 femur, L3 tibia; `printed` selects eq. (40) as printed."""

    L1: float
    L2: float
    L3: float
    printed: bool = False


def fk(leg: Leg, q) -> np.ndarray:
    """(..., 3) foot positions in the leg frame for joint angles q (..., 3); the explicit form of T_0^4 (eq. 1)
    that eqs. (38)-(40) invert (spec §3.1)."""
    q = np.asarray(q, dtype=float)
    t1, t2, t3 = q[..., 0], q[..., 1], q[..., 2]
    reach = leg.L2 * np.cos(t2) + leg.L3 * np.cos(t2 + t3)     # in the leg plane, from the femur joint down
    x = leg.L1 * np.cos(t1) + reach * np.sin(t1)
    y = leg.L1 * np.sin(t1) - reach * np.cos(t1)
    z = leg.L2 * np.sin(t2) + leg.L3 * np.sin(t2 + t3)
    return np.stack([x, y, z], axis=-1)


def ik(leg: Leg, p) -> np.ndarray:
    """(..., 3) joint angles of eqs. (38)-(40) for foot positions p (..., 3) in the leg frame, on the θ3 ≥ 0 branch;
    NaN where the point is out of reach (x² + y² < L1², or the knee cosine outside [−1, 1])."""
    p = np.asarray(p, dtype=float)
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    L1, L2, L3 = leg.L1, leg.L2, leg.L3
    with np.errstate(invalid="ignore"):
        reach = np.sqrt(x * x + y * y - L1 * L1)             # AB of Figs. 7-8, eqs. (3), (17)
        # eq. (40) corrected: AC² = AB² + z² = x² + y² − L1² + z² (eq. 34 prints +L1² inside the root, and
        # eqs. (36), (37), (40) carry it as −L1² in the numerator)
        l1_term = -L1 * L1 if leg.printed else L1 * L1
        cos_alpha = (L2 * L2 + L3 * L3 - x * x - y * y + l1_term - z * z) / (2 * L2 * L3)
        t3 = np.pi - np.arccos(cos_alpha)                                         # eq. (40)
        t1 = np.arctan2(reach, L1) - np.arctan2(-y, x)                            # eq. (38)
        t2 = -np.arctan2(L3 * np.sin(t3), L2 + L3 * np.cos(t3)) - np.arctan2(-z, reach)   # eq. (39)
    return np.stack([t1, t2, t3], axis=-1)


def leg_jacobian(leg: Leg, q) -> np.ndarray:
    """(..., 3, 3) ∂fk/∂q in the leg frame."""
    q = np.asarray(q, dtype=float)
    t1, t2, t3 = q[..., 0], q[..., 1], q[..., 2]
    reach = leg.L2 * np.cos(t2) + leg.L3 * np.cos(t2 + t3)
    d_reach = np.stack([np.zeros_like(t1), -leg.L2 * np.sin(t2) - leg.L3 * np.sin(t2 + t3),
                        -leg.L3 * np.sin(t2 + t3)], axis=-1)
    dz = np.stack([np.zeros_like(t1), leg.L2 * np.cos(t2) + leg.L3 * np.cos(t2 + t3),
                   leg.L3 * np.cos(t2 + t3)], axis=-1)
    dx = np.sin(t1)[..., None] * d_reach
    dy = -np.cos(t1)[..., None] * d_reach
    dx[..., 0] = -leg.L1 * np.sin(t1) + reach * np.cos(t1)
    dy[..., 0] = leg.L1 * np.cos(t1) + reach * np.sin(t1)
    return np.stack([dx, dy, dz], axis=-2)


@dataclass(frozen=True)
class Layout:
    """Where the hips sit on the trunk: (±length/2, ±width/2, 0) in the body frame."""

    length: float
    width: float

    @property
    def hips(self) -> np.ndarray:
        """(4, 3) hip (coxa joint) positions in the body frame, order FR, FL, BR, BL."""
        return np.column_stack([FRONT * self.length / 2, SIDE * self.width / 2, np.zeros(4)])


def leg_to_body(p_leg) -> np.ndarray:
    """(..., 4, 3) leg-frame vectors of each leg -> body-frame vectors (directions; add the hip for points)."""
    p = np.asarray(p_leg, dtype=float)
    return np.stack([p[..., 2], SIDE * p[..., 0], p[..., 1]], axis=-1)


def body_to_leg(p_body) -> np.ndarray:
    """Inverse of `leg_to_body` (the map is its own transpose up to the side sign)."""
    p = np.asarray(p_body, dtype=float)
    return np.stack([SIDE * p[..., 1], p[..., 2], p[..., 0]], axis=-1)


def rpy_matrix(rpy) -> np.ndarray:
    """(..., 3, 3) R = Rz(yaw) Ry(pitch) Rx(roll) for (..., 3) roll, pitch, yaw (rad)."""
    rpy = np.asarray(rpy, dtype=float)
    cr, sr = np.cos(rpy[..., 0]), np.sin(rpy[..., 0])
    cp, sp = np.cos(rpy[..., 1]), np.sin(rpy[..., 1])
    cy, sy = np.cos(rpy[..., 2]), np.sin(rpy[..., 2])
    return np.stack([
        np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], axis=-1),
        np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], axis=-1),
        np.stack([-sp, cp * sr, cp * cr], axis=-1)], axis=-2)


def body_ik(leg: Leg, layout: Layout, feet, position, rpy) -> np.ndarray:
    """Body IK (Sec. 3.2, Fig. 18): joint angles (..., 4, 3) that put the trunk at `position` (..., 3) with
    orientation `rpy` (..., 3) while the feet stay at `feet` (4, 3), all in the stance frame (the frame the feet
    stand in; its z is the trunk's z when level)."""
    R = rpy_matrix(rpy)
    rel = np.asarray(feet, dtype=float) - np.asarray(position, dtype=float)[..., None, :]
    in_body = rel @ R                    # Rᵀ (foot − trunk) for each foot: row vectors times R
    return ik(leg, body_to_leg(in_body - layout.hips))


def feet_in_body(leg: Leg, layout: Layout, q) -> np.ndarray:
    """(..., 4, 3) foot positions in the body frame for joint angles q (..., 4, 3)."""
    return layout.hips + leg_to_body(fk(leg, q))

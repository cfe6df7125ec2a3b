"""Stäubli TX2-90 kinematics from Table 2, decomposed as in Sec. 2: the arm (q1..q3) places the wrist point,
the spherical wrist (q4..q6) orients the flange relative to the elbow frame {m} = frame 3.

Everything is NumPy, batched over leading axes, SI units. Frames are expressed in {w} (the URDF `base`,
0.478 m above the base plane): row w of Table 2 is the fixed transform `base`, row e the tool `tool`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from pipeline.robotics import dh as dhk
from pipeline.robotics.dh import DH

JOINTS = [f"joint{i}" for i in range(1, 7)]
BRANCHES = 8  # shoulder front/back × elbow ± × wrist ± (Sec. 2.1)


def _translation_z(d: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = d
    return T


def _rows(dh: DH, rows: slice) -> DH:
    return DH(dh.alpha[rows], dh.a[rows], dh.d[rows], dh.theta_offset[rows])


@dataclass(frozen=True)
class Arm:
    """Table 2 and the joint limits. `dh` holds rows 1, 2, 3/m, 4, 5, f; `wrist_dh` rows 1, 2, ζ."""

    dh: DH
    wrist_dh: DH
    base: np.ndarray          # A_w, (4, 4)
    tool: np.ndarray          # A_e, (4, 4): the black rod, d_e along z_f
    lower: np.ndarray         # rad, (6,)
    upper: np.ndarray         # rad, (6,)
    velocity: np.ndarray      # rad/s, (6,)

    @classmethod
    def from_config(cls, system: Mapping) -> Arm:
        table, limits = system["dh"], system["joint_limits"]
        dh = DH.from_config(table)
        wrist = DH(np.r_[dh.alpha[:2], 0.0], np.r_[dh.a[:2], table["wrist_a"]], np.r_[dh.d[:2], table["wrist_d"]],
                   np.r_[dh.theta_offset[:2], 0.0])  # row ζ: θ = q3, α = 0
        return cls(dh, wrist, _translation_z(table["base_d"]), _translation_z(table["tool_d"]),
                   *(np.asarray(limits[k], dtype=float) for k in ("lower", "upper", "velocity")))

    @property
    def elbow_dh(self) -> DH:
        """Rows 1, 2, 3/m: {w} -> {m}."""
        return _rows(self.dh, slice(0, 3))

    @property
    def hand_dh(self) -> DH:
        """Rows 4, 5, f: {m} -> {f}."""
        return _rows(self.dh, slice(3, 6))

    @property
    def d_f(self) -> float:
        """Wrist point -> flange along z_f: d of row f (100 mm)."""
        return float(self.dh.d[5])

    @property
    def safety_radius(self) -> float:
        """d_f + sqrt(a_e² + d_e²) of eq. (10f): the wrist-centred sphere that holds the whole tool."""
        return self.d_f + float(np.hypot(self.tool[0, 3], self.tool[2, 3]))


# -- forward kinematics -------------------------------------------------------------------------------------


def frames(arm: Arm, q: np.ndarray) -> np.ndarray:
    """(..., 7, 4, 4): poses in {w} of DH frames 0..6 (frame 3 = {m}, frames 4, 5 at the wrist point, 6 = {f})."""
    return arm.base @ dhk.frames(arm.dh, q)


def tool_pose(arm: Arm, q: np.ndarray) -> np.ndarray:
    """(..., 4, 4): H_w^e, the tool point of the black rod."""
    return arm.base @ dhk.fk(arm.dh, q) @ arm.tool


def wrist_point(arm: Arm, q_m: np.ndarray) -> np.ndarray:
    """(..., 3): p_w^ζ from rows w, 1, 2, ζ (depends on q1..q3 only)."""
    return (arm.base @ dhk.fk(arm.wrist_dh, q_m))[..., :3, 3]


def wrist_jacobian(arm: Arm, q_m: np.ndarray) -> np.ndarray:
    """(..., 3, 3): J_{w,trans}^ζ(q_m), the NMPC's model (10d)."""
    return arm.base[:3, :3] @ dhk.geometric_jacobian(arm.wrist_dh, q_m)[..., :3, :]


def elbow_rotation(arm: Arm, q_m: np.ndarray) -> np.ndarray:
    """(..., 3, 3): R_w^m."""
    return arm.base[:3, :3] @ dhk.fk(arm.elbow_dh, q_m)[..., :3, :3]


def hand_rotation(arm: Arm, q_o: np.ndarray) -> np.ndarray:
    """(..., 3, 3): R_m^f(q_o), the flange orientation in {m}."""
    return dhk.fk(arm.hand_dh, q_o)[..., :3, :3]


def hand_jacobian(arm: Arm, q_o: np.ndarray) -> np.ndarray:
    """(..., 3, 3): J_{m,rot}^f(q_o), angular velocity of {f} in {m} (columns z3, z4, z5 in {m})."""
    return dhk.geometric_jacobian(arm.hand_dh, q_o)[..., 3:, :]


# -- inverse kinematics (Sec. 2.1, eqs. 1-3) --------------------------------------------------------------


def wrap(x: np.ndarray) -> np.ndarray:
    """Angles into [−π, π)."""
    return np.remainder(np.asarray(x) + np.pi, 2 * np.pi) - np.pi


def wrist_target(arm: Arm, T_e: np.ndarray) -> np.ndarray:
    """Desired tool pose -> wrist point: (1) H_w^f = H_e (H_f^e)^-1, then (2) p^ζ = p^f − d_f z_f."""
    T_f = T_e @ np.linalg.inv(arm.tool)
    return T_f[..., :3, 3] - arm.d_f * T_f[..., :3, 2]


def shoulder_radius(arm: Arm, q_m: np.ndarray) -> np.ndarray:
    """Signed distance of the wrist point from the J1 axis along the arm plane (< 0: shoulder 'back')."""
    phi2 = q_m[..., 1] + arm.dh.theta_offset[1]
    return arm.dh.a[0] + arm.dh.a[1] * np.cos(phi2) + arm.wrist_dh.a[2] * np.cos(phi2 + q_m[..., 2])


def branch_flags(arm: Arm, q: np.ndarray) -> np.ndarray:
    """(..., 3) signs (shoulder, elbow, wrist): a change along a path is a 'jump' of Sec. 3.1."""
    q = np.asarray(q, dtype=float)
    return np.sign(np.stack([shoulder_radius(arm, q[..., :3]), np.sin(q[..., 2]), np.sin(q[..., 4])], axis=-1))


def ik(arm: Arm, T_e: np.ndarray) -> np.ndarray:
    """(8, 6) joint solutions of a tool pose, NaN rows where a branch is unreachable.

    Row b = 4·shoulder + 2·elbow + wrist with bit 0 = front / elbow q3 ≥ 0 / wrist q5 ≥ 0. Joint limits are
    not applied here (the planner does that, eq. 6)."""
    T_e = np.asarray(T_e, dtype=float)
    p = wrist_target(arm, T_e)
    a1, L2, L3 = arm.dh.a[0], arm.dh.a[1], arm.wrist_dh.a[2]
    lateral = arm.dh.d[1] + arm.wrist_dh.d[2]          # offset along z1 (row ζ: 50 mm)
    height = arm.base[2, 3] + arm.dh.d[0]              # J2 axis height in {w}
    off2 = arm.dh.theta_offset[1]
    out = np.full((BRANCHES, 6), np.nan)
    radial_sq = p[0] ** 2 + p[1] ** 2 - lateral ** 2
    if radial_sq < 0:
        return out
    for shoulder, r in enumerate((np.sqrt(radial_sq), -np.sqrt(radial_sq))):
        q1 = np.arctan2(p[1], p[0]) - np.arctan2(lateral, r)
        # the arm plane: x1 along the radial, y1 = −z_w (α1 = −π/2)
        X, Y = r - a1, height - p[2]
        c3 = (X * X + Y * Y - L2 * L2 - L3 * L3) / (2 * L2 * L3)
        if abs(c3) > 1 + 1e-12:
            continue
        for elbow, q3 in enumerate((np.arccos(np.clip(c3, -1, 1)), -np.arccos(np.clip(c3, -1, 1)))):
            phi2 = np.arctan2(Y, X) - np.arctan2(L3 * np.sin(q3), L2 + L3 * np.cos(q3))
            q_m = np.array([q1, phi2 - off2, q3])
            # (3) rotation correction R_m^f = (R_w^m)^T R_w^f, solved as ZYZ (α4 = −π/2, α5 = π/2)
            R = elbow_rotation(arm, q_m).T @ T_e[:3, :3] @ arm.tool[:3, :3].T
            s5 = np.hypot(R[0, 2], R[1, 2])
            for wrist, sign in enumerate((1.0, -1.0)):
                q5 = np.arctan2(sign * s5, R[2, 2])
                if s5 > 1e-12:
                    q4 = np.arctan2(sign * R[1, 2], sign * R[0, 2])
                    q6 = np.arctan2(sign * R[2, 1], -sign * R[2, 0])
                else:  # wrist singular: only q4 + q6 is defined; put it all on q6
                    q4, q6 = 0.0, np.arctan2(R[1, 0], R[0, 0])
                out[4 * shoulder + 2 * elbow + wrist] = wrap(np.r_[q_m, q4, q5, q6])
    return out


def within_limits(arm: Arm, q: np.ndarray) -> np.ndarray:
    """Eq. (6): q in Q (NaN rows are outside)."""
    return np.all((q >= arm.lower) & (q <= arm.upper), axis=-1)


def limit_margin(arm: Arm, q: np.ndarray) -> np.ndarray:
    """(...): the smallest distance of any joint to its bound (the inner min of eq. 9)."""
    return np.minimum(q - arm.lower, arm.upper - q).min(axis=-1)


# -- orientation error (Sec. 3.3, eqs. 11-12) ------------------------------------------------------------


def skew(s: np.ndarray) -> np.ndarray:
    """Eq. (12)."""
    s = np.asarray(s, dtype=float)
    z = np.zeros(s.shape[:-1])
    return np.stack([np.stack([z, -s[..., 2], s[..., 1]], -1), np.stack([s[..., 2], z, -s[..., 0]], -1),
                     np.stack([-s[..., 1], s[..., 0], z], -1)], -2)


def quaternion(R: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternion [η, ε], η ≥ 0, of rotation matrices (Shepperd's method: the largest of
    4η², 4ε_i² is taken from the diagonal, the rest from the off-diagonal sums; the paper cites [83])."""
    R = np.asarray(R, dtype=float)
    d = np.stack([np.trace(R, axis1=-2, axis2=-1), R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]], axis=-1)
    k = np.argmax(np.stack([d[..., 0], 2 * d[..., 1] - d[..., 0], 2 * d[..., 2] - d[..., 0],
                            2 * d[..., 3] - d[..., 0]], axis=-1), axis=-1)
    s21, s02, s10 = R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]
    a01, a02, a12 = R[..., 0, 1] + R[..., 1, 0], R[..., 0, 2] + R[..., 2, 0], R[..., 1, 2] + R[..., 2, 1]
    cases = np.stack([  # 4·x_k·q for the pivot k = η, ε_x, ε_y, ε_z
        np.stack([1 + d[..., 0], s21, s02, s10], -1),
        np.stack([s21, 1 + 2 * d[..., 1] - d[..., 0], a01, a02], -1),
        np.stack([s02, a01, 1 + 2 * d[..., 2] - d[..., 0], a12], -1),
        np.stack([s10, a02, a12, 1 + 2 * d[..., 3] - d[..., 0]], -1)], axis=-2)
    q = np.take_along_axis(cases, k[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def orientation_error(q_des: np.ndarray, q_cur: np.ndarray) -> np.ndarray:
    """Eq. (11): ẽ = η ε_d − η_d ε − S(ε_d) ε, desired [η_d, ε_d], current [η, ε].

    The two quaternions are put on the same hemisphere first (q and −q are one rotation; the paper does not
    say how it picks the sign), so ẽ is the error of the shorter rotation."""
    q_des, q_cur = np.asarray(q_des, dtype=float), np.asarray(q_cur, dtype=float)
    q_cur = np.where((np.sum(q_des * q_cur, axis=-1) < 0)[..., None], -q_cur, q_cur)
    eta_d, eps_d, eta, eps = q_des[..., :1], q_des[..., 1:], q_cur[..., :1], q_cur[..., 1:]
    return eta * eps_d - eta_d * eps - np.cross(eps_d, eps)

"""SRS-type 7R arm of Sec. 3 (LBR iiwa lengths): direct kinematics implied by eqs. (6), (10), (13), and the
closed-form inverse kinematics of Sec. 3.2 parameterised by the swivel angle α (eqs. 4-14).

Frames as in the paper's Fig. 1: the base y_b axis is joint 1 (vertical, y-up); at q = 0 the arm is
stretched along +x_b. Joints 1-3 are YZX Tait-Bryan angles at the shoulder P_s, joint 4 turns about z3 at
the elbow P_e, joints 5-7 are XZX proper Euler angles at the wrist P_w. Everything is NumPy, batched over
leading axes, SI units.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

JOINTS = [f"joint{i}" for i in range(1, 8)]


class Unreachable(ValueError):
    """A tool pose whose wrist centre the arm cannot reach."""


def rot_x(a) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(a) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(a) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def rodrigues(u: np.ndarray, angle) -> np.ndarray:
    """Rotation by `angle` about the unit axis u (..., 3): the matrix R_u of eq. (5)."""
    u = np.asarray(u, dtype=float)
    c, s = np.cos(angle)[..., None, None], np.sin(angle)[..., None, None]
    x, y, z = u[..., 0], u[..., 1], u[..., 2]
    zero = np.zeros_like(x)
    K = np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], -2)
    return c * np.eye(3) + s * K + (1 - c) * (u[..., :, None] * u[..., None, :])


def rotate(u: np.ndarray, angle, v: np.ndarray) -> np.ndarray:
    """R_u(angle) v, the product of eq. (5) without building the matrix (Rodrigues' vector form)."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    return c * v + s * cross(u, v) + (1 - c) * dot(u, v)[..., None] * u


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis (NumPy's `cross` costs 10x more on short batches)."""
    a0, a1, a2, b0, b1, b2 = a[..., 0], a[..., 1], a[..., 2], b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0], out[..., 1], out[..., 2] = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return out


def norm(v: np.ndarray) -> np.ndarray:
    return np.sqrt(dot(v, v))


def unit(v: np.ndarray) -> np.ndarray:
    return v / norm(v)[..., None]


@dataclass(frozen=True)
class Geometry:
    """Sec. 3.1: a0 = |O_b P_s|, a1 = |P_s P_e|, a2 = |P_e P_w|, a3 = |P_w O_e| (m); the tool frame 7T_e."""

    a0: float
    a1: float
    a2: float
    a3: float
    tool_rotation_y: float = np.pi / 2   # 7R_e = Ry(·), 7p_e = [a3, 0, 0] (not given in the paper)

    @property
    def shoulder(self) -> np.ndarray:
        return np.array([0.0, self.a0, 0.0])

    @property
    def tool(self) -> np.ndarray:
        """7T_e of eq. (4)."""
        T = np.eye(4)
        T[:3, :3] = rot_y(self.tool_rotation_y)
        T[0, 3] = self.a3
        return T

    @functools.cached_property
    def tool_inverse(self) -> np.ndarray:
        return np.linalg.inv(self.tool)


IIWA = Geometry(a0=0.34, a1=0.4, a2=0.4, a3=0.126)


# -- direct kinematics --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Chain:
    """Frames of a configuration, all in the base frame: R3 = bR3 (eq. 6), R4 = bR4 (eq. 10), R7 = bR7 (eq. 13)."""

    P_s: np.ndarray
    P_e: np.ndarray
    P_w: np.ndarray
    R3: np.ndarray
    R4: np.ndarray
    R7: np.ndarray


def chain(q: np.ndarray, g: Geometry = IIWA) -> Chain:
    q = np.asarray(q, dtype=float)
    R3 = rot_y(q[..., 0]) @ rot_z(q[..., 1]) @ rot_x(q[..., 2])                  # eq. (6)
    R4 = R3 @ rot_z(q[..., 3])                                                     # eq. (10)
    R7 = R4 @ rot_x(q[..., 4]) @ rot_z(q[..., 5]) @ rot_x(q[..., 6])               # eq. (13)
    P_s = np.broadcast_to(g.shoulder, R3.shape[:-1])
    P_e = P_s + g.a1 * R3[..., :, 0]          # the upper arm lies along x3
    P_w = P_e + g.a2 * R4[..., :, 0]          # the forearm along x4 (= x5, joint 5's axis)
    return Chain(P_s, P_e, P_w, R3, R4, R7)


def pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.zeros((*R.shape[:-2], 4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = R, p, 1.0
    return T


def fk(q: np.ndarray, g: Geometry = IIWA) -> np.ndarray:
    """(..., 4, 4) bT_e: tool pose in the base frame (eq. 11: bT_e = bT_7 · 7T_e)."""
    c = chain(q, g)
    return pose(c.R7, c.P_w) @ g.tool


def link_frames(q: np.ndarray, g: Geometry = IIWA) -> np.ndarray:
    """(..., 8, 4, 4) poses of links 1..7 and the tool in the base frame, each at its joint (the frames the
    generated MuJoCo model and /tf use): link1 at P_s turned by θ1, link2 by θ1θ2, link3 = frame 3 at P_s,
    link4 = frame 4 at P_e, link5 at P_e, link6 and link7 at P_w, tool at O_e."""
    q = np.asarray(q, dtype=float)
    c = chain(q, g)
    R1 = rot_y(q[..., 0])
    R2 = R1 @ rot_z(q[..., 1])
    R5 = c.R4 @ rot_x(q[..., 4])
    R6 = R5 @ rot_z(q[..., 5])
    frames = [pose(R1, c.P_s), pose(R2, c.P_s), pose(c.R3, c.P_s), pose(c.R4, c.P_e), pose(R5, c.P_e),
              pose(R6, c.P_w), pose(c.R7, c.P_w)]
    frames.append(frames[-1] @ g.tool)
    return np.stack(frames, axis=-3)


# -- inverse kinematics (Sec. 3.2) ----------------------------------------------------------------------------


def wrist_centre(T: np.ndarray, g: Geometry = IIWA) -> tuple[np.ndarray, np.ndarray]:
    """(bR7, P_w) of a tool pose: bT_7 = bT_e · (7T_e)⁻¹ (eq. 4, with the frames as the text means them)."""
    T7 = np.asarray(T, dtype=float) @ g.tool_inverse
    return T7[..., :3, :3], T7[..., :3, 3]


def elbow_reference(P_w: np.ndarray, g: Geometry = IIWA) -> tuple[np.ndarray, np.ndarray]:
    """The θ3 = 0 sub-problem of Sec. 3.2 (elbow up): (θ4, P_e0), with P_e0 the elbow at α = 0.

    θ1 turns the vertical arm plane onto the wrist, θ2 = elevation of P_w plus the triangle angle at the
    shoulder, θ4 = −(π − elbow angle): negative, as z3 = u × v of eq. (8) requires for this elbow."""
    a1, a2 = g.a1, g.a2
    w = P_w - g.shoulder
    L = norm(w)
    theta1 = np.arctan2(-P_w[..., 2], P_w[..., 0])
    phi = np.arctan2(w[..., 1], np.hypot(P_w[..., 0], P_w[..., 2]))
    with np.errstate(invalid="ignore"):  # out of reach: NaN, which the caller reports
        psi = np.arccos((a1 * a1 + L * L - a2 * a2) / (2 * a1 * L))
        eps = np.arccos((a1 * a1 + a2 * a2 - L * L) / (2 * a1 * a2))
    theta2 = phi + psi
    theta4 = -(np.pi - eps)
    P_e0 = g.shoulder + a1 * np.stack([np.cos(theta1) * np.cos(theta2), np.sin(theta2),
                                       -np.sin(theta1) * np.cos(theta2)], -1)
    return theta4, P_e0


@dataclass(frozen=True)
class Solution:
    q: np.ndarray        # (..., 7), NaN where the wrist centre is out of reach
    P_s: np.ndarray
    P_e: np.ndarray
    P_w: np.ndarray


def ik(T: np.ndarray, alpha, g: Geometry = IIWA, shoulder_sign: float = 1.0, wrist_sign: float = 1.0) -> Solution:
    """Joint vector for tool pose(s) T (..., 4, 4) and swivel angle(s) α (Sec. 3.2, eqs. 4-14).

    `shoulder_sign` is sign(θ2) of eq. (9) (really the sign of cos θ2: +1 keeps θ2 in (−π/2, π/2)),
    `wrist_sign` is sign(θ6) of eq. (14) (+1: θ6 in (0, π)). A scalar or per-sample array each."""
    R7, P_w = wrist_centre(T, g)
    alpha = np.broadcast_to(np.asarray(alpha, dtype=float), P_w.shape[:-1])
    s2, s6 = np.asarray(shoulder_sign, dtype=float), np.asarray(wrist_sign, dtype=float)
    theta4, P_e0 = elbow_reference(P_w, g)
    P_s = np.broadcast_to(g.shoulder, P_w.shape)
    u = unit(P_w - P_s)
    P_e = P_s + rotate(u, alpha, P_e0 - P_s)                                            # eq. (5)
    P_eu = P_s + dot(P_e - P_s, u)[..., None] * u                                       # eqs. (7)-(8)
    x3 = unit(P_e - P_s)
    z3 = unit(cross(u, P_e - P_eu))
    y3 = cross(z3, x3)
    r11, r21, r31 = x3[..., 0], x3[..., 1], x3[..., 2]
    r22, r23 = y3[..., 1], z3[..., 1]
    theta1 = np.arctan2(-s2 * r31, s2 * r11)                                            # eq. (9)
    theta2 = np.arctan2(r21, s2 * np.hypot(r31, r11))
    theta3 = np.arctan2(-s2 * r23, s2 * r22)
    c4, s4 = np.cos(theta4)[..., None], np.sin(theta4)[..., None]
    x4, y4 = c4 * x3 + s4 * y3, c4 * y3 - s4 * x3                                       # eq. (10): bR4 = bR3 Rz(θ4)
    # eq. (12): n_ij = (bR4ᵀ bR7)_ij, with bR7 = bR_e 7R_eᵀ; eq. (14) needs n11, n12, n13, n21, n31
    n1 = np.einsum("...i,...ij->...j", x4, R7)
    n21, n31 = dot(y4, R7[..., :, 0]), dot(z3, R7[..., :, 0])
    theta5 = np.arctan2(s6 * n31, s6 * n21)                                             # eq. (14)
    theta6 = np.arctan2(s6 * np.hypot(n1[..., 1], n1[..., 2]), n1[..., 0])
    theta7 = np.arctan2(s6 * n1[..., 2], -s6 * n1[..., 1])
    q = np.stack([theta1, theta2, theta3, theta4, theta5, theta6, theta7], axis=-1)
    return Solution(q, P_s, P_e, P_w)


def swivel_angle(q: np.ndarray, g: Geometry = IIWA) -> np.ndarray:
    """α of a configuration: the signed angle about u = (P_w − P_s)/‖·‖ from the α = 0 elbow (plane π1) to the
    actual elbow (plane π2), the inverse of `ik`'s parameterisation."""
    c = chain(q, g)
    _, P_e0 = elbow_reference(c.P_w, g)
    u = unit(c.P_w - c.P_s)
    v0 = P_e0 - c.P_s - dot(P_e0 - c.P_s, u)[..., None] * u
    v = c.P_e - c.P_s - dot(c.P_e - c.P_s, u)[..., None] * u
    return np.arctan2(dot(u, cross(v0, v)), dot(v0, v))

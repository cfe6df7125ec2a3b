"""The iTbot arm: kinematics of Table 2 and the dynamic model of Appendix A.2, eqs. (A7)-(A12).

Frame 0 is the base: joint 1 turns about z0, and at θ = (0, 0) link 1 points along +y0 and link 2 folds back
down it (the MDH offsets π/2 and π of Table 2). In the vertical configuration y0 points up (gravity along
−y0, which is what the gravity vector of eq. (A10) implies); in the horizontal one gravity is normal to the
plane and G ≡ 0.

    x = −l1 sin θ1 + l2 sin(θ1+θ2),   y = l1 cos θ1 − l2 cos(θ1+θ2)

The dynamic terms are written once, as arithmetic on a `lib` that provides cos and sin (`math` for the
controller's per-step call, NumPy for batches, CasADi for the plant's integrator, SymPy for the tests).
The hand load (the 11 lb weight and the forearm) is a point mass at the hand: it only changes link 2's
mass, first and second moment, so the same (A8)-(A10) hold with `Links.with_point_mass`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from pipeline.robotics.dh import modified_link_transforms

JOINTS = ("joint1", "joint2")
FRAMES = ("link1", "link2", "hand")   # MDH frames 1, 2, 3 (x along each link; the hand turns with link 2)


@dataclass(frozen=True)
class Links:
    """The link parameters of eqs. (A8)-(A10) (SI)."""

    l1: float      # m, link lengths (not given: ASSUMPTION)
    l2: float
    lc1: float     # m, joint-to-CoG distances along the links (Table 1: X1, X2)
    lc2: float
    m1: float      # kg (Table 1)
    m2: float
    iz1: float     # kg m², about each CoG (not given: ASSUMPTION)
    iz2: float
    gravity: float  # m/s² along −y0; 0 in the horizontal configuration

    @classmethod
    def from_config(cls, system) -> Links:
        link, inertia = system.links, system.inertia
        g = float(system.gravity) if system.configuration == "vertical" else 0.0
        return cls(l1=float(link.l1), l2=float(link.l2), lc1=float(link.lc1), lc2=float(link.lc2),
                   m1=float(link.m1), m2=float(link.m2), iz1=float(inertia[0]), iz2=float(inertia[1]), gravity=g)

    def with_point_mass(self, mass: float) -> Links:
        """Link 2 carrying a point mass at the hand (distance l2 from joint 2): the same total mass, first and
        second moment about joint 2, so (A8)-(A10) hold unchanged."""
        if mass == 0:
            return self
        m2 = self.m2 + mass
        lc2 = (self.m2 * self.lc2 + mass * self.l2) / m2
        iz2 = self.iz2 + self.m2 * self.lc2 ** 2 + mass * self.l2 ** 2 - m2 * lc2 ** 2
        return replace(self, m2=m2, lc2=lc2, iz2=iz2)

    def scaled(self, mass_scale: float) -> Links:
        """Masses and inertias times `mass_scale` (a controller model with a mass error)."""
        return replace(self, m1=self.m1 * mass_scale, m2=self.m2 * mass_scale, iz1=self.iz1 * mass_scale,
                       iz2=self.iz2 * mass_scale)


    @functools.cached_property
    def coefficients(self) -> tuple[float, float, float, float, float]:
        """The constants of (A8)-(A10): m2 l1 lc2, m2 lc2² + Iz2, m2 l1² + m1 lc1² + Iz1, m2 lc2 g,
        (m1 lc1 + m2 l1) g."""
        return (self.m2 * self.l1 * self.lc2, self.m2 * self.lc2 ** 2 + self.iz2,
                self.m2 * self.l1 ** 2 + self.m1 * self.lc1 ** 2 + self.iz1, self.m2 * self.lc2 * self.gravity,
                (self.m1 * self.lc1 + self.m2 * self.l1) * self.gravity)


def dynamics_terms(p: Links, q1, q2, qd1, qd2, lib: Any = math) -> tuple:
    """(M11, M12, M22, V1, V2, G1, G2) of eqs. (A8)-(A10), with g restored in G as (A10) prints it."""
    h, m22, m11_rest, g2_coef, g1_coef = p.coefficients
    c2, s2 = lib.cos(q2), lib.sin(q2)
    m12 = m22 - h * c2                                          # κ2 = M21, eq. (A8)
    m11 = m11_rest + m22 - 2 * h * c2                           # κ1
    hs2 = h * s2
    v1 = hs2 * qd2 * qd2 + 2 * hs2 * qd1 * qd2                  # eq. (A9)
    v2 = -hs2 * qd1 * qd1
    g2 = g2_coef * lib.sin(q1 + q2)                             # eq. (A10)
    g1 = g2 - g1_coef * lib.sin(q1)
    return m11, m12, m22, v1, v2, g1, g2


def mass_matrix(p: Links, q: np.ndarray) -> np.ndarray:
    """(..., 2, 2) M(θ), eq. (A8)."""
    q = np.asarray(q, dtype=float)
    m11, m12, m22, *_ = dynamics_terms(p, q[..., 0], q[..., 1], 0.0, 0.0, np)
    m11, m12, m22 = np.broadcast_arrays(m11, m12, m22)
    return np.stack([np.stack([m11, m12], -1), np.stack([m12, m22], -1)], -2)


def coriolis(p: Links, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """(..., 2) V(θ, θ̇), eq. (A9)."""
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    _, _, _, v1, v2, _, _ = dynamics_terms(p, q[..., 0], q[..., 1], qd[..., 0], qd[..., 1], np)
    return np.stack(np.broadcast_arrays(v1, v2), -1)


def gravity_torque(p: Links, q: np.ndarray) -> np.ndarray:
    """(..., 2) G(θ), eq. (A10)."""
    q = np.asarray(q, dtype=float)
    *_, g1, g2 = dynamics_terms(p, q[..., 0], q[..., 1], 0.0, 0.0, np)
    return np.stack(np.broadcast_arrays(g1, g2), -1)


def potential_energy(p: Links, q: np.ndarray) -> np.ndarray:
    """P(θ) = g [m1 lc1 cos θ1 + m2 (l1 cos θ1 − lc2 cos(θ1+θ2))]: G = ∂P/∂θ."""
    q = np.asarray(q, dtype=float)
    c1, c12 = np.cos(q[..., 0]), np.cos(q[..., 0] + q[..., 1])
    return p.gravity * (p.m1 * p.lc1 * c1 + p.m2 * (p.l1 * c1 - p.lc2 * c12))


# -- kinematics ---------------------------------------------------------------------------------------------


def mdh_table(p: Links) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Table 2: α_{i−1}, a_{i−1}, d_i and the joint-angle offsets of frames 1, 2, 3 (the hand)."""
    return (np.zeros(3), np.array([0.0, p.l1, p.l2]), np.zeros(3), np.array([np.pi / 2, np.pi, 0.0]))


def mdh_frames(p: Links, q: np.ndarray) -> np.ndarray:
    """(..., 3, 4, 4): ^0T_1, ^0T_2, ^0T_3 by multiplying the Table 2 link transforms, eqs. (A1)-(A4)
    (with (A3)'s first entry read as a_{i−1}, the link length, not the twist α_{i−1})."""
    q = np.asarray(q, dtype=float)
    alpha, a, d, offset = mdh_table(p)
    theta = np.concatenate([q, np.zeros((*q.shape[:-1], 1))], axis=-1) + offset
    links = modified_link_transforms(alpha, a, d, theta)
    out = np.empty_like(links)
    out[..., 0, :, :] = links[..., 0, :, :]
    for i in (1, 2):
        out[..., i, :, :] = out[..., i - 1, :, :] @ links[..., i, :, :]
    return out


def fk(p: Links, q: np.ndarray) -> np.ndarray:
    """(..., 2) hand position (x, y) in frame 0 (closed form of Table 2)."""
    q = np.asarray(q, dtype=float)
    q1, q12 = q[..., 0], q[..., 0] + q[..., 1]
    return np.stack([-p.l1 * np.sin(q1) + p.l2 * np.sin(q12), p.l1 * np.cos(q1) - p.l2 * np.cos(q12)], -1)


def jacobian(p: Links, q: np.ndarray) -> np.ndarray:
    """(..., 2, 2) ∂(x, y)/∂θ; det J = −l1 l2 sin θ2."""
    q = np.asarray(q, dtype=float)
    c1, s1 = np.cos(q[..., 0]), np.sin(q[..., 0])
    c12, s12 = np.cos(q[..., 0] + q[..., 1]), np.sin(q[..., 0] + q[..., 1])
    row_x = np.stack([-p.l1 * c1 + p.l2 * c12, p.l2 * c12], -1)
    row_y = np.stack([-p.l1 * s1 + p.l2 * s12, p.l2 * s12], -1)
    return np.stack([row_x, row_y], -2)


def hand_acceleration(p: Links, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """(..., 2) ẍ = J θ̈ + J̇ θ̇ of the hand."""
    q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
    q1, q12 = q[..., 0], q[..., 0] + q[..., 1]
    w1, w12 = qd[..., 0], qd[..., 0] + qd[..., 1]
    a1, a12 = qdd[..., 0], qdd[..., 0] + qdd[..., 1]
    ax = -p.l1 * (np.cos(q1) * a1 - np.sin(q1) * w1 ** 2) + p.l2 * (np.cos(q12) * a12 - np.sin(q12) * w12 ** 2)
    ay = -p.l1 * (np.sin(q1) * a1 + np.cos(q1) * w1 ** 2) + p.l2 * (np.sin(q12) * a12 + np.cos(q12) * w12 ** 2)
    return np.stack([ax, ay], -1)


def ik(p: Links, xy: np.ndarray, elbow: int = 1) -> np.ndarray:
    """(..., 2) joint angles reaching (x, y); `elbow` = ±1 picks the branch by the sign of sin θ2."""
    xy = np.asarray(xy, dtype=float)
    r2 = (xy ** 2).sum(-1)
    # |p|² = l1² + l2² − 2 l1 l2 cos θ2 (link 2 folds back at θ2 = 0)
    c2 = np.clip((p.l1 ** 2 + p.l2 ** 2 - r2) / (2 * p.l1 * p.l2), -1.0, 1.0)
    q2 = elbow * np.arccos(c2)
    # p = R(θ1) [l2 sin θ2, l1 − l2 cos θ2]  (x and y of the arm at θ1 = 0, turned by θ1)
    u, w = p.l2 * np.sin(q2), p.l1 - p.l2 * c2
    q1 = np.arctan2(xy[..., 1], xy[..., 0]) - np.arctan2(w, u)
    return np.stack([np.remainder(q1 + np.pi, 2 * np.pi) - np.pi, q2], -1)


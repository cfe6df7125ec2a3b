"""UR5 closed-form kinematics of Villalobos, Sanchez, Martell (Robotics 2022, 11, 137).

Forward kinematics (eqs. 1–13), the closed-form IK of their ref. [8] (eqs. 14–30), the geometric
Jacobian (eqs. 33–45) and its determinant (eq. 46). SI units: lengths in m, so det J is in m³
(the paper's mm³ = 1e9 · m³). All angles in rad.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import cos, pi, sin

import numpy as np

TWO_PI = 2.0 * pi


@dataclass(frozen=True)
class Geometry:
    """The non-zero DH lengths of a UR/TM-type arm (Table 1; α = π/2, 0, 0, π/2, −π/2, 0)."""

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float

    @property
    def dh(self) -> dict[str, list[float]]:
        return {"alpha": [pi / 2, 0.0, 0.0, pi / 2, -pi / 2, 0.0], "a": [0.0, self.a2, self.a3, 0.0, 0.0, 0.0],
                "d": [self.d1, 0.0, 0.0, self.d4, self.d5, self.d6]}


# Table 1, converted from mm.
UR5 = Geometry(d1=0.0892, a2=0.425, a3=0.392, d4=0.1093, d5=0.09475, d6=0.0825)


def fk(q, g: Geometry = UR5, printed: bool = False) -> np.ndarray:
    """^0_6T of eqs. (2)–(13). `printed=True` keeps the misprint c234·a3 / s234·a3 of eqs. (11)–(13)
    (erratum 1: the DH product has c23·a3 / s23·a3)."""
    q1, q2, q3, q4, q5, q6 = (float(x) for x in q)
    c1, s1, c5, s5, c6, s6 = cos(q1), sin(q1), cos(q5), sin(q5), cos(q6), sin(q6)
    c2, s2 = cos(q2), sin(q2)
    c23, s23 = cos(q2 + q3), sin(q2 + q3)
    c234, s234 = cos(q2 + q3 + q4), sin(q2 + q3 + q4)
    r11 = c1 * c234 * c5 * c6 + c6 * s1 * s5 - c1 * s234 * s6          # eq. (2)
    r21 = c234 * c5 * c6 * s1 - c1 * c6 * s5 - s1 * s234 * s6          # eq. (3)
    r31 = c5 * c6 * s234 + c234 * s6                                    # eq. (4)
    r12 = -c1 * c234 * c5 * s6 - s1 * s5 * s6 - c1 * c6 * s234          # eq. (5)
    r22 = -c234 * c5 * s1 * s6 + c1 * s5 * s6 - c6 * s1 * s234         # eq. (6)
    r32 = -c5 * s234 * s6 + c234 * c6                                   # eq. (7)
    r13 = -c1 * c234 * s5 + c5 * s1                                     # eq. (8)
    r23 = -c234 * s1 * s5 - c1 * c5                                     # eq. (9)
    r33 = -s234 * s5                                                    # eq. (10)
    ca3, sa3 = (c234, s234) if printed else (c23, s23)
    reach = s234 * g.d5 + ca3 * g.a3 + c2 * g.a2
    px = r13 * g.d6 + c1 * reach + s1 * g.d4                            # eq. (11), corrected
    py = r23 * g.d6 + s1 * reach - c1 * g.d4                            # eq. (12), corrected
    pz = r33 * g.d6 - c234 * g.d5 + sa3 * g.a3 + s2 * g.a2 + g.d1       # eq. (13), corrected
    return np.array([[r11, r12, r13, px], [r21, r22, r23, py], [r31, r32, r33, pz], [0.0, 0.0, 0.0, 1.0]])


def jacobian(q, g: Geometry = UR5) -> np.ndarray:
    """6×6 geometric Jacobian [J_L; J_A] of the flange, eqs. (33)–(45)."""
    T = fk(q, g)
    q1, q2, q3, q4, q5, _ = (float(x) for x in q)
    c1, s1, c5, s5 = cos(q1), sin(q1), cos(q5), sin(q5)
    c23, s23 = cos(q2 + q3), sin(q2 + q3)
    c234, s234 = cos(q2 + q3 + q4), sin(q2 + q3 + q4)
    r13, r23, r33 = T[0, 2], T[1, 2], T[2, 2]
    px, py, pz = T[0, 3], T[1, 3], T[2, 3]
    j3 = s234 * s5 * g.d6 + c234 * g.d5
    JL = np.array([
        [-py, -c1 * (pz - g.d1), c1 * (j3 - s23 * g.a3), c1 * j3, -g.d6 * (s1 * s5 + c1 * c234 * c5), 0.0],
        [px, -s1 * (pz - g.d1), s1 * (j3 - s23 * g.a3), s1 * j3, g.d6 * (c1 * s5 - c234 * c5 * s1), 0.0],
        [0.0, s1 * py + c1 * px, -c234 * s5 * g.d6 + s234 * g.d5 + c23 * g.a3,
         -c234 * s5 * g.d6 + s234 * g.d5, -c5 * s234 * g.d6, 0.0],
    ])                                                                  # eqs. (40)–(45)
    JA = np.array([[0.0, s1, s1, s1, c1 * s234, r13],
                   [0.0, -c1, -c1, -c1, s1 * s234, r23],
                   [1.0, 0.0, 0.0, 0.0, -c234, r33]])                   # eq. (33)
    return np.vstack([JL, JA])


def shoulder_term(q, g: Geometry = UR5):
    """c2·a2 + c23·a3 + s234·d5: zero at a shoulder singularity (works on arrays)."""
    q = np.asarray(q, dtype=float)
    q2, q3, q4 = q[..., 1], q[..., 2], q[..., 3]
    return np.cos(q2) * g.a2 + np.cos(q2 + q3) * g.a3 + np.sin(q2 + q3 + q4) * g.d5


def det_j(q, g: Geometry = UR5):
    """det J = s3·s5·a2·a3·(c2·a2 + c23·a3 + s234·d5), eq. (46), in m³ (works on arrays)."""
    q = np.asarray(q, dtype=float)
    return np.sin(q[..., 2]) * np.sin(q[..., 4]) * g.a2 * g.a3 * shoulder_term(q, g)

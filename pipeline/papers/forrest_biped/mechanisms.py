"""The knee and ankle drives of Secs. 3-4: speed, torque and stiffness against the joint angles (Figs. 8, 10-12).

Knee (eqs. 1-9): a ball screw between A on the thigh and B on the calf; B turns with the knee. The moment arm h
of the screw about the knee O is the height of the triangle A O B* (Heron, eq. 5), so the knee speed, torque and
stiffness are n_m p / (60 h), 2π τ_m h / p and k_s h |J_AB| with J_AB = d‖AB*‖/dq4 (= ±h: the moment-arm
identity). Knee flexion θ turns B by −θ in eq. (2) (paper.yaml, erratum K1): only then is h largest at 60°.

Ankle (eqs. 10-17): two rods of length L from A1, A2 on the foot (turned by R_y(q11) R_z(q12), eq. 11) to the
sliders B1, B2 on the calf (eq. 12: B slides along x). The slider coordinates q25 = 0.405 − x_B1*, q28 = 0.405 −
x_B2* (eq. 13) give the Jacobian J = ∂(q25, q28)/∂(q11, q12) (eq. 14); joint speed J⁻¹ v (eq. 15), joint torque
Jᵀ f (eq. 16), stiffness Jᵀ K_s J (eq. 17) for slider speeds v, forces f and spring stiffnesses K_s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Knee:
    A: np.ndarray            # (2,) m, eq. (1), on the thigh
    B: np.ndarray            # (2,) m, on the calf at q4 = 0
    pitch: float             # m per revolution of the ball screw
    spring: float            # N/m
    motor_torque: float      # N m (not given: derived from Table 2, see the config)
    motor_speed: float       # rpm

    @classmethod
    def from_config(cls, c: Mapping[str, Any]) -> Knee:
        return cls(np.asarray(c["A"], float), np.asarray(c["B"], float), c["pitch"], c["spring"],
                   c["motor_torque"], c["motor_speed"])


def knee_points(knee: Knee, flexion: np.ndarray) -> np.ndarray:
    """B* (n, 2) for knee flexion angles θ (rad): eq. (2) with q4 = −θ."""
    q4 = -np.asarray(flexion, dtype=float)
    c, s = np.cos(q4), np.sin(q4)
    return np.stack([c * knee.B[0] - s * knee.B[1], s * knee.B[0] + c * knee.B[1]], axis=-1)


def knee_arm(knee: Knee, flexion: np.ndarray) -> np.ndarray:
    """Moment arm h (m) of the screw about the knee, by Heron's formula (eq. 5)."""
    B = knee_points(knee, flexion)
    oa, ob, ab = np.linalg.norm(knee.A), np.linalg.norm(B, axis=-1), np.linalg.norm(knee.A - B, axis=-1)
    s = (oa + ob + ab) / 2
    eta = np.sqrt(np.maximum(s * (s - oa) * (s - ob) * (s - ab), 0.0))
    return 2 * eta / ab


def knee_screw_length(knee: Knee, flexion: np.ndarray) -> np.ndarray:
    """‖AB*‖ (m)."""
    return np.linalg.norm(knee.A - knee_points(knee, flexion), axis=-1)


def knee_passive(knee: Knee, flexion: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The passive joints at the screw ends, eqs. (3)-(4) (rad)."""
    B = knee_points(knee, flexion)
    q19 = np.arctan2(knee.A[0] - B[..., 0], knee.A[1] - B[..., 1])
    return q19, q19 + np.asarray(flexion)        # q20 = q19 − q4, q4 = −θ


def knee_curves(knee: Knee, flexion: np.ndarray, dq: float = 1e-6) -> dict[str, np.ndarray]:
    """Fig. 8: maximum speed (rad/s), maximum torque (N m) and stiffness (N m/rad) against flexion (eqs. 6-9)."""
    h = knee_arm(knee, flexion)
    J_ab = (knee_screw_length(knee, flexion + dq) - knee_screw_length(knee, flexion - dq)) / (2 * dq)   # eq. (9)
    return {"h": h, "J_AB": J_ab,
            "speed": knee.motor_speed * knee.pitch / (60 * h),                  # eq. (6)
            "torque": 2 * np.pi * knee.motor_torque * h / knee.pitch,          # eq. (7)
            "stiffness": knee.spring * h * np.abs(J_ab)}                       # eq. (8): k_s h / J_AB⁻¹


@dataclass(frozen=True)
class Ankle:
    A: np.ndarray            # (2, 3) m, A1 and A2 on the foot (eq. 10)
    B_yz: np.ndarray         # (2, 2) m, the sliders' fixed y and z
    rod: float               # L, m
    calf: float              # m, the slider coordinate is measured from the knee (eq. 13: 0.405 − x)
    spring: float            # N/m per slider (K_s of eq. 17)
    slider_force: float      # N, maximum (not given: derived from Table 2, see the config)
    slider_speed: float      # m/s, maximum

    @classmethod
    def from_config(cls, c: Mapping[str, Any]) -> Ankle:
        return cls(np.asarray(c["A"], float), np.asarray(c["B_yz"], float), c["rod"], c["calf"], c["spring"],
                   c["slider_force"], c["slider_speed"])


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def ankle_points(ankle: Ankle, q11: np.ndarray, q12: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A* (..., 2, 3) by eq. (11) and B* (..., 2, 3) by eq. (12)."""
    R = _ry(np.asarray(q11, float)) @ _rz(np.asarray(q12, float))
    A = np.einsum("...ij,kj->...ki", R, ankle.A)
    dy, dz = A[..., 1] - ankle.B_yz[:, 0], A[..., 2] - ankle.B_yz[:, 1]
    xb = A[..., 0] + np.sqrt(ankle.rod**2 - dy**2 - dz**2)
    B = np.stack([xb, np.broadcast_to(ankle.B_yz[:, 0], xb.shape), np.broadcast_to(ankle.B_yz[:, 1], xb.shape)], -1)
    return A, B


def ankle_sliders(ankle: Ankle, q11: np.ndarray, q12: np.ndarray) -> np.ndarray:
    """(q25, q28) of eq. (13), m."""
    return ankle.calf - ankle_points(ankle, q11, q12)[1][..., 0]


def ankle_jacobian(ankle: Ankle, q11: np.ndarray, q12: np.ndarray) -> np.ndarray:
    """J of eq. (14), (..., 2, 2) m/rad, analytic: ∂x_B/∂q = ∂x_A/∂q − (Δy ∂y_A/∂q + Δz ∂z_A/∂q)/√(L² − Δy² − Δz²)."""
    q11, q12 = np.asarray(q11, float), np.asarray(q12, float)
    Ry, Rz = _ry(q11), _rz(q12)
    Sy = np.array([[0.0, 0, 1], [0, 0, 0], [-1, 0, 0]])        # d/da R_y(a) = R_y(a) S_y
    Sz = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 0]])
    A = np.einsum("...ij,kj->...ki", Ry @ Rz, ankle.A)
    dA = [np.einsum("...ij,kj->...ki", Ry @ Sy @ Rz, ankle.A), np.einsum("...ij,kj->...ki", Ry @ Rz @ Sz, ankle.A)]
    dy, dz = A[..., 1] - ankle.B_yz[:, 0], A[..., 2] - ankle.B_yz[:, 1]
    root = np.sqrt(ankle.rod**2 - dy**2 - dz**2)
    cols = [-(d[..., 0] - (dy * d[..., 1] + dz * d[..., 2]) / root) for d in dA]   # q = calf − x_B
    return np.stack(cols, axis=-1)


def ankle_curves(ankle: Ankle, q11: np.ndarray, q12: np.ndarray) -> dict[str, np.ndarray]:
    """Figs. 10-12 on a grid: the joint speeds (rad/s) and torques (N m) with both sliders at their limit in the
    same or in opposite directions, and the joint stiffnesses (N m/rad)."""
    J = ankle_jacobian(ankle, q11, q12)
    Jinv = np.linalg.inv(J)
    v, f = ankle.slider_speed, ankle.slider_force
    same, opposite = np.array([1.0, 1.0]), np.array([1.0, -1.0])
    speed_same, speed_opp = Jinv @ (v * same), Jinv @ (v * opposite)                           # eq. (15)
    torque_same = np.einsum("...ji,j->...i", J, f * same)                                        # eq. (16)
    torque_opp = np.einsum("...ji,j->...i", J, f * opposite)
    K = np.einsum("...ji,...jk->...ik", J, ankle.spring * J)                                    # eq. (17)
    return {"speed_same_q11": np.abs(speed_same[..., 0]), "speed_same_q12": np.abs(speed_same[..., 1]),
            "speed_opposite_q11": np.abs(speed_opp[..., 0]), "speed_opposite_q12": np.abs(speed_opp[..., 1]),
            "torque_same_q11": np.abs(torque_same[..., 0]), "torque_same_q12": np.abs(torque_same[..., 1]),
            "torque_opposite_q11": np.abs(torque_opp[..., 0]), "torque_opposite_q12": np.abs(torque_opp[..., 1]),
            "stiffness_q11": K[..., 0, 0], "stiffness_q12": K[..., 1, 1]}


def spring_energy(stiffness: float, max_force: float) -> float:
    """Energy (J) a linear spring stores at its maximum force: F²/(2k)."""
    return max_force**2 / (2 * stiffness)


def speed_for_energy(energy: float, mass: float) -> float:
    """Speed (m/s) of `mass` whose kinetic energy is `energy`: sqrt(2E/m)."""
    return float(np.sqrt(2 * energy / mass))

"""The analytic plant: eqs. (A7)-(A12) with the harmonic-drive actuation and the hand load, integrated by
fixed-step RK4 with the torque held over each control period. The MuJoCo plant (mujoco_arm.py) is the
independent second model of the same arm.

    (M(θ) + N² J_r) θ̈ = τ − V(θ, θ̇) − G(θ) − F(θ̇) + Jᵀ(θ) F_h                   (A12) + drive + hand
    M, V, G of links whose link 2 carries the hand load (point mass m_L at the hand, `Links.with_point_mass`)
    F = c tanh(θ̇/ε)                                         Coulomb friction (A11), smoothed over ε
    F_h = −b ẋ + s m_L g ŷ                                   the subject's passive damping and the share s
                                                            of the load's weight the subject carries

The force the hand exerts on the handle (what the end-effector force sensor reads, Fig. 11) is
F = m_L (g⃗ − ẍ) + F_h, g⃗ = (0, −g).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from pipeline.papers.itbot_smc.model import Links, dynamics_terms, hand_acceleration, jacobian


@dataclass(frozen=True)
class Drive:
    """Maxon EC-45 flat motors through 100:1 Harmonic Drives (Sec. 5.1)."""

    gear_ratio: float
    rotor_inertia: tuple[float, float]    # kg m², motor side
    friction: tuple[float, float]         # N m, Coulomb friction at the joints (c of eq. A11)
    friction_velocity: float              # rad/s, ε of the analytic plant's tanh(θ̇/ε)
    torque_limit: tuple[float, float]     # N m at the joints

    @classmethod
    def from_config(cls, drive) -> Drive:
        return cls(gear_ratio=float(drive.gear_ratio), rotor_inertia=_pair(drive.rotor_inertia),
                   friction=_pair(drive.friction), friction_velocity=float(drive.friction_velocity),
                   torque_limit=_pair(drive.torque_limit))

    @property
    def armature(self) -> tuple[float, float]:
        """Reflected rotor inertia N² J_r at each joint (kg m²)."""
        return (self.gear_ratio ** 2 * self.rotor_inertia[0], self.gear_ratio ** 2 * self.rotor_inertia[1])


@dataclass(frozen=True)
class HandLoad:
    """The subject's hand on the handle with the extra weight (Sec. 5.2)."""

    weight: float      # kg, the 11 lb weight on the hand
    arm: float         # kg, the forearm and hand as a point mass at the handle
    damping: float     # N s/m, the relaxed arm's passive resistance to hand velocity
    support: float     # share of the load's weight (weight + arm) the subject carries, 0…1

    @classmethod
    def from_config(cls, load) -> HandLoad:
        return cls(weight=float(load.weight), arm=float(load.arm), damping=float(load.damping),
                   support=float(load.support))

    @property
    def mass(self) -> float:
        return self.weight + self.arm


def _pair(values) -> tuple[float, float]:
    a, b = (float(x) for x in values)
    return a, b


@dataclass(frozen=True)
class PlantModel:
    """Everything the plant's equations of motion use, resolved once: the links carrying the hand load, the
    reflected rotor inertias, friction, and the hand's damping and supported weight."""

    links: Links              # with the load as a point mass at the hand
    armature: tuple[float, float]
    friction: tuple[float, float]
    friction_velocity: float
    damping: float            # N s/m at the hand
    support_force: float      # N, upward (+y0) at the hand

    @classmethod
    def of(cls, links: Links, drive: Drive, load: HandLoad) -> PlantModel:
        return cls(links.with_point_mass(load.mass), drive.armature, drive.friction, drive.friction_velocity,
                   load.damping, load.support * load.mass * links.gravity)


def joint_accelerations(m: PlantModel, q1, q2, w1, w2, tau1, tau2, lib: Any = math) -> tuple:
    """θ̈ of the plant for torques τ (arithmetic on `lib`: math, NumPy, CasADi)."""
    p = m.links
    m11, m12, m22, v1, v2, g1, g2 = dynamics_terms(p, q1, q2, w1, w2, lib)
    m11, m22 = m11 + m.armature[0], m22 + m.armature[1]
    c1, s1 = lib.cos(q1), lib.sin(q1)
    c12, s12 = lib.cos(q1 + q2), lib.sin(q1 + q2)
    j11, j12 = -p.l1 * c1 + p.l2 * c12, p.l2 * c12
    j21, j22 = -p.l1 * s1 + p.l2 * s12, p.l2 * s12
    fx = -m.damping * (j11 * w1 + j12 * w2)
    fy = -m.damping * (j21 * w1 + j22 * w2) + m.support_force
    eps = m.friction_velocity
    b1 = tau1 + j11 * fx + j21 * fy - v1 - g1 - m.friction[0] * lib.tanh(w1 / eps)
    b2 = tau2 + j12 * fx + j22 * fy - v2 - g2 - m.friction[1] * lib.tanh(w2 / eps)
    det = m11 * m22 - m12 * m12
    return (m22 * b1 - m12 * b2) / det, (m11 * b2 - m12 * b1) / det


def hand_force(links: Links, load: HandLoad, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """(..., 2) force of the hand on the handle in frame 0: m_L (g⃗ − ẍ) − b ẋ + s m_L g ŷ."""
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    acc = hand_acceleration(links, q, qd, qdd)
    vel = (jacobian(links, q) @ qd[..., None])[..., 0]
    force = -load.mass * acc - load.damping * vel
    force[..., 1] -= (1.0 - load.support) * load.mass * links.gravity
    return force


class Plant(Protocol):
    """What the closed loop needs of a plant: the state at the current tick, one period with τ held, and
    the hand force at every tick so far (with that tick's torque)."""

    name: str

    def state(self) -> tuple[Sequence[float], Sequence[float]]: ...
    def advance(self, tau: Sequence[float]) -> None: ...
    def hand_forces(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray: ...


class AnalyticPlant:
    """Eqs. (A7)-(A12) + drive + hand load, RK4 with `substeps` steps per control period."""

    name = "analytic"

    def __init__(self, links: Links, drive: Drive, load: HandLoad, period: float, substeps: int, q0, qd0):
        self.links, self.load = links, load
        self.model = PlantModel.of(links, drive, load)
        self.h = period / substeps
        self.substeps = substeps
        self._x = (float(q0[0]), float(q0[1]), float(qd0[0]), float(qd0[1]))

    def state(self) -> tuple[tuple[float, float], tuple[float, float]]:
        x = self._x
        return x[:2], x[2:]

    def _rate(self, x: tuple, tau1: float, tau2: float) -> tuple:
        a1, a2 = joint_accelerations(self.model, x[0], x[1], x[2], x[3], tau1, tau2)
        return x[2], x[3], a1, a2

    def advance(self, tau: Sequence[float]) -> None:
        tau1, tau2 = float(tau[0]), float(tau[1])
        h, x = self.h, self._x
        for _ in range(self.substeps):
            k1 = self._rate(x, tau1, tau2)
            k2 = self._rate(tuple(a + h / 2 * b for a, b in zip(x, k1, strict=True)), tau1, tau2)
            k3 = self._rate(tuple(a + h / 2 * b for a, b in zip(x, k2, strict=True)), tau1, tau2)
            k4 = self._rate(tuple(a + h * b for a, b in zip(x, k3, strict=True)), tau1, tau2)
            x = tuple(a + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4,
                                                                                              strict=True))
        self._x = x

    def accelerations(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """(..., 2) θ̈ at states (θ, θ̇) under torques τ (vectorized)."""
        a1, a2 = joint_accelerations(self.model, q[..., 0], q[..., 1], qd[..., 0], qd[..., 1], tau[..., 0],
                                     tau[..., 1], np)
        return np.stack([a1, a2], -1)

    def hand_forces(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return hand_force(self.links, self.load, q, qd, self.accelerations(q, qd, tau))


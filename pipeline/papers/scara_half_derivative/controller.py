"""Cartesian-space position control of the arm, sampled every T_s: KD (eq. 11) and KDHD (eqs. 14-17).

    e = x_d − x(θ),  ė = ẋ_d − J(θ) θ̇
    τ = Jᵀ(θ) [ K' e + D ė + HD e^(1/2) ] + τ_g(θ3)                                       (11), (17)
    K' = K − (Σ w_j / T_s^(1/2)) HD   (stiffness compensation, eq. 17; K' = K for eq. 14 and for KD)
    e^(1/2)(kT_s) = T_s^(−1/2) Σ_{j=0..n} w_j e((k−j)T_s)                                 (15), (16)

K, D, HD are diagonal: [k_xyz, k_xyz, k_xyz, k_θ] and alike. KD is the same law without the half-derivative
term: its controller skips the filter altogether (so its compute time is KD's own). With `difference=True`
the first derivative is the backward difference of the sampled errors, ė_k = (e_k − e_{k−1})/T_s, instead of
ẋ_d − J(θ)θ̇ (the `sampled-difference` implementation of batch.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pipeline.papers.scara_half_derivative.arm import Arm, fk_jacobian
from pipeline.robotics.fractional import GrunwaldLetnikov, gl_dc_gain

HALF = 0.5


@dataclass(frozen=True)
class Gains:
    """Diagonal gains of one controller (SI: N/m, N s/m, N s^½/m and the rotational N m/rad, …)."""

    k_xyz: float
    k_theta: float
    d_xyz: float
    d_theta: float
    hd_xyz: float = 0.0
    hd_theta: float = 0.0

    @property
    def K(self) -> np.ndarray:
        return np.array([self.k_xyz] * 3 + [self.k_theta])

    @property
    def D(self) -> np.ndarray:
        return np.array([self.d_xyz] * 3 + [self.d_theta])

    @property
    def HD(self) -> np.ndarray:
        return np.array([self.hd_xyz] * 3 + [self.hd_theta])

    @property
    def fractional(self) -> bool:
        return bool(self.HD.any())


class CartesianController:
    """One instance per run: it keeps the error history of the half-derivative filter."""

    def __init__(self, arm: Arm, gains: Gains, period: float, gl_terms: int, compensate_stiffness: bool = True,
                 difference: bool = False):
        self.arm, self.gains, self.period, self.difference = arm, gains, period, difference
        self.D, self.HD = gains.D, gains.HD
        self.filter = GrunwaldLetnikov(HALF, gl_terms, period, width=4) if gains.fractional else None
        compensation = gl_dc_gain(HALF, gl_terms, period) if (gains.fractional and compensate_stiffness) else 0.0
        self.K = gains.K - compensation * self.HD   # eq. (17)
        self.k3, self.theta3p, self.weight = arm.k3, arm.theta3p, arm.moment * arm.gravity
        self.error = np.zeros(4)

    def __call__(self, q: np.ndarray, qd: np.ndarray, x_d: np.ndarray, xd_d: np.ndarray) -> np.ndarray:
        """Joint torques for the sampled state (θ, θ̇) and the set-point (x_d, ẋ_d) of this period."""
        x, J = fk_jacobian(self.arm, q)
        e = x_d - x
        rate = (e - self.error) / self.period if self.difference else xd_d - J @ qd
        self.error = e
        force = self.K * e + self.D * rate
        if self.filter is not None:
            force += self.HD * self.filter.push(e)
        tau = J.T @ force
        theta3 = float(q[2])
        tau[2] += self.k3 * (theta3 - self.theta3p) - self.weight * math.cos(theta3)   # τ_g,3, eq. (12)
        return tau

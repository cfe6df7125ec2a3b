"""Exact rolling of spheres without slip or spin: the kinematic plant, independent of the paper's model.

It starts from the no-slip condition itself and works in rotation matrices, not the paper's quaternion
bookkeeping. For joint i (spheres l_{i-1} = a below, l_i = b above, contact normal n in B_{i-1}):

    the contact point of B_i is at rest relative to B_{i-1}:   v = b ω × n,   ṅ = b/(a+b) ω × n
    no spin:                                                  ω · n = 0
    the tangent frame P_i (z = n) does not spin either:       ω_P = n × ṅ = b/(a+b) ω

so the rate of B_i relative to P_i, Ω^B = R_Pᵀ(ω − ω_P), gives ω = (a+b)/a R_P Ω^B. For Ω^B held constant
over a step, ω is constant in B_{i-1} (P turns about ω itself), so one exponential per step is exact.
A FreeBOT drives Ω^B with its trolley: the shell turns at u_f / r_out about the axis perpendicular to the
trolley heading φ in the tangent plane (eqs. 48, 50, 85).
"""

from __future__ import annotations

import numpy as np

from pipeline.papers.src_joint.model import quaternion_of, skew


def exp_so3(rotvec: np.ndarray) -> np.ndarray:
    """Rodrigues: rotation matrices (..., 3, 3) of rotation vectors (..., 3)."""
    theta2 = np.sum(rotvec * rotvec, axis=-1)[..., None, None]
    half = np.sinc(np.sqrt(theta2) / (2 * np.pi))          # sin(θ/2) / (θ/2), = 1 at θ = 0
    a = half * np.cos(np.sqrt(theta2) / 2)                  # sin θ / θ
    b = 0.5 * half * half                                   # (1 − cos θ) / θ²
    # K² = v vᵀ − θ² I
    return (1.0 - b * theta2) * np.eye(3) + a * skew(rotvec) + b * (rotvec[..., :, None] * rotvec[..., None, :])


def trolley_rates(u_forward: np.ndarray, heading: np.ndarray, r_out: float) -> np.ndarray:
    """Ω^B (n, 2) of shells whose trolleys move forward at u_f (arc speed at r_out) with heading φ in P:
    the contact-point velocity u_f [cos φ, sin φ] and no slip (eq. 50) give Ω^B = u_f / r_out [−sin φ, cos φ]."""
    rate = np.asarray(u_forward) / r_out
    return np.stack([-rate * np.sin(heading), rate * np.cos(heading)], axis=-1)


class RollingChain:
    """n spheres rolling on each other, base B_0 fixed; `radii` l_0 … l_n (the plant's effective radii)."""

    def __init__(self, radii):
        self.radii = np.asarray(radii, dtype=float)
        self.n = len(self.radii) - 1
        self.relative = np.tile(np.eye(3), (self.n, 1, 1))   # ^{B_{i-1}}R_{B_i}
        self.tangent = np.tile(np.eye(3), (self.n, 1, 1))    # ^{B_{i-1}}R_{P_i}; column 2 is the contact normal
        lower, upper = self.radii[:-1], self.radii[1:]
        self._omega_per_rate = ((lower + upper) / lower)[:, None]
        self._plane_share = (upper / (lower + upper))[:, None]

    def relative_velocity(self, omega_b: np.ndarray) -> np.ndarray:
        """^{B_{i-1}}ω_{B_i} (n, 3) in B_{i-1} for tangent-plane rates Ω^B (n, 2)."""
        return self._omega_per_rate * np.einsum("nij,nj->ni", self.tangent[:, :, :2], omega_b)

    def roll(self, omega_b: np.ndarray, dt: float, turn_rate: np.ndarray | None = None) -> None:
        """Advance by dt from tangent-plane rates Ω^B (n, 2) that keep their size and turn about the contact
        normal at `turn_rate` (rad/s, per joint; a trolley steering while it drives). Exact.

        The frame of the trolley (P_i turned by its heading) then turns at the constant Λ = l_i/(l_i+l_{i-1}) ω
        + u_s n, so T(t) = Exp(Λt) T(0); in it ω − Λ is constant, hence R(t) = Exp(Λt) Exp((ω − Λ)t) R(0) and
        R_P(t) = Exp(Λt) R_P(0) Rz(−u_s t). With u_s = 0 both reduce to Exp(ωt), Exp(l_i/(l_i+l_{i-1}) ωt)."""
        omega = self.relative_velocity(omega_b)
        steer = np.zeros(self.n) if turn_rate is None else np.asarray(turn_rate, dtype=float)
        lam = self._plane_share * omega + steer[:, None] * self.tangent[:, :, 2]
        spin = np.zeros((self.n, 3))
        spin[:, 2] = -steer
        turn = exp_so3(np.concatenate([lam, omega - lam, spin]) * dt)
        frame, rest, heading = turn[:self.n], turn[self.n:2 * self.n], turn[2 * self.n:]
        self.relative = frame @ rest @ self.relative
        self.tangent = frame @ self.tangent @ heading

    def frames(self) -> tuple[np.ndarray, np.ndarray]:
        """(positions (n+1, 3), rotations (n+1, 3, 3)) of the sphere centres and body frames in ΣI."""
        span = self.radii[:-1] + self.radii[1:]
        pos = np.zeros((self.n + 1, 3))
        rot = np.empty((self.n + 1, 3, 3))
        rot[0] = np.eye(3)
        for i in range(self.n):
            pos[i + 1] = pos[i] + span[i] * (rot[i] @ self.tangent[i, :, 2])
            rot[i + 1] = rot[i] @ self.relative[i]
        return pos, rot

    def model_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The same configuration in the paper's variables: (q_{i,1}, q_{i-1,2}), each (n, 4)."""
        q2 = quaternion_of(np.swapaxes(self.tangent, -1, -2))              # ^{P}R_{B_{i-1}} = R_Pᵀ
        q1 = quaternion_of(np.swapaxes(self.tangent, -1, -2) @ self.relative)  # ^{P}R_{B_i}
        return q1, q2

"""FreeBOT drive of an SRC joint (Sec. IV): trolley path planning, the two control laws, wheel speeds.

Per joint the trolley has a heading φ in the tangent plane P_i (φ = 0 along x̂ of P_i, eq. 48) and a
forward arc distance s; φ̇ = u_s (eq. 49), ṡ = u_f. Arrays are per joint, shape (n,).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AZIMUTHS = ("corrected", "printed")


def wrap(angle: np.ndarray) -> np.ndarray:
    return np.remainder(np.asarray(angle) + np.pi, 2 * np.pi) - np.pi


@dataclass(frozen=True)
class FreeBot:
    """Shell and trolley geometry (Table II, Fig. 5)."""

    r_in: float           # inner shell radius (m)
    r_out: float          # outer shell radius (m)
    wheel_radius: float   # r_w (m)
    wheel_interval: float  # l_w (m)

    @property
    def forward_gain(self) -> float:
        """u_f per (ω_r + ω_l): r_out r_w / sqrt(4 r_in² − l_w²), eq. (64) (= eq. 85 through r', eq. 83)."""
        return self.r_out * self.wheel_radius / np.sqrt(4 * self.r_in ** 2 - self.wheel_interval ** 2)

    @property
    def steering_gain(self) -> float:
        """u_s per (ω_r − ω_l): r_w / l_w, eq. (64) (= eq. 87)."""
        return self.wheel_radius / self.wheel_interval

    def wheel_speeds(self, u_forward: np.ndarray, u_steer: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(ω_r, ω_l) that give the trolley speeds (u_f, u_s), eq. (65)."""
        forward = np.asarray(u_forward) / (2 * self.forward_gain)
        steer = np.asarray(u_steer) / (2 * self.steering_gain)
        return forward + steer, forward - steer

    def trolley_speeds(self, right: np.ndarray, left: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(u_f, u_s) of wheel speeds (ω_r, ω_l), eq. (64)."""
        return self.forward_gain * (right + left), self.steering_gain * (right - left)


def equivalent_radius(lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """l'_i = l_i l_{i-1} / (l_i + l_{i-1}), defined under eq. (51) (which prints l_i where l'_i is meant)."""
    return lower * upper / (lower + upper)


def velocity_plan(w_ref: np.ndarray, radius_eq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(u_f^r, φ^r) that produce the joint velocities w^r (n, 2), eq. (52)."""
    return radius_eq * np.linalg.norm(w_ref, axis=-1), np.arctan2(-w_ref[:, 0], w_ref[:, 1])


def joint_velocity(u_forward: np.ndarray, heading: np.ndarray, radius_eq: np.ndarray) -> np.ndarray:
    """The joint velocities (n, 2) a trolley makes, eq. (51) solved for w: (u_f / l') [−sin φ, cos φ]."""
    rate = np.asarray(u_forward) / radius_eq
    return np.stack([-rate * np.sin(heading), rate * np.cos(heading)], axis=-1)


def position_plan(tangent_now: np.ndarray, tangent_ref: np.ndarray, lower: np.ndarray,
                  azimuth: str = "corrected") -> tuple[np.ndarray, np.ndarray]:
    """(s^r, φ^r): the arc and its azimuth in P_i that bring the contact point from where the tangent frame
    ^{B_{i-1}}R_{P_i} (n, 3, 3) puts it now to where the reference one does, eqs. (53)-(55)."""
    contact_ref = tangent_ref[:, :, 2] * lower[:, None]                          # eq. (53): R^r [0, 0, l_{i-1}]
    contact_now = tangent_now[:, :, 2] * lower[:, None]
    p = np.einsum("nji,nj->ni", tangent_now, contact_ref - contact_now)          # eq. (54), in P_i
    arc = lower * np.arccos(np.clip((lower - np.abs(p[:, 2])) / lower, -1.0, 1.0))  # eq. (55)
    if azimuth == "corrected":
        heading = np.arctan2(p[:, 1], p[:, 0])   # eq. (55) corrected: φ = 0 is x̂ of P_i (eq. 48)
    else:
        heading = np.arctan2(p[:, 0], p[:, 1])   # eq. (55) as printed: atan2(p_x / p_y)
    return arc, heading


@dataclass(frozen=True)
class Gains:
    k_s: float       # forward gain, eq. (63)
    k_phi1: float    # steering gain, eq. (56)
    k_phi2: float    # steering gain, eq. (57)


def steer_then_forward(heading: np.ndarray, heading_ref: np.ndarray, arc_error: np.ndarray, forward: np.ndarray,
                       g: Gains, steer_tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward-and-steering independent control (Sec. IV-C2): steer with (56) until |φ_e| < steer_tol, then
    move forward with (63), ṡ^r = 0, u_f = k_s (s^r − s), while (56) holds the heading. `forward` (bool, n)
    says which trolleys have switched (they never switch back); returns (u_f, u_s, forward)."""
    error = wrap(heading_ref - heading)
    forward = forward | (np.abs(error) < steer_tol)
    return np.where(forward, g.k_s * arc_error, 0.0), g.k_phi1 * error, forward   # eqs. (63), (56) with φ̇^r = 0


def steer_while_forward(heading: np.ndarray, heading_ref: np.ndarray, heading_ref_rate: np.ndarray,
                        u_forward_ref: np.ndarray, g: Gains) -> tuple[np.ndarray, np.ndarray]:
    """Forward-and-steering dependent control, eqs. (56)-(57): returns (u_f, u_s)."""
    error = wrap(heading_ref - heading)
    u_steer_ref = heading_ref_rate + g.k_phi1 * error            # eq. (56)
    return u_forward_ref * np.cos(error), u_steer_ref + g.k_phi2 * u_forward_ref * np.sin(error)  # eq. (57)

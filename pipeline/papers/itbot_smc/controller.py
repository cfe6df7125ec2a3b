"""The sampled sliding-mode controller of eq. (5) and the joint sensing of the hardware (Hall sensors).

Per control tick (1 kHz, torque held until the next tick):

    e = θ − θ_d,  ė = θ̇ − θ̇_d,  v = ė + λ e                                    (3)
    τ = M̂(θ) [θ̈_d − λ ė + r(v, t)] + V̂(θ, θ̇) + Ĝ(θ) + F̂(θ̇)                     (5), v̇ replaced by r
    r: the reaching law of the controller (reaching.py)

M̂, V̂, Ĝ are eqs. (A8)-(A10) with the controller's own link parameters (the nominal ones, optionally with
the hand load, the reflected rotor inertia and a mass error); F̂ = ĉ sgn(θ̇) is its friction estimate (0:
the paper gives no c). A known upward force f at the hand (the share of the load the subject carries, as the
handle's force sensor reads it at rest) enters as −Jᵀ(0, f).
"""

from __future__ import annotations

import math

from pipeline.papers.itbot_smc.model import Links, dynamics_terms
from pipeline.papers.itbot_smc.reaching import REACHING_LAWS, LawGains, sign


class SlidingModeController:
    """One instance per run. Per-joint arithmetic on floats (two joints: faster than NumPy). `v` holds the
    sliding variable of the last call (rad/s)."""

    def __init__(self, law: str, gains: LawGains, lam, model: Links, armature=(0.0, 0.0), friction=(0.0, 0.0),
                 hand_support: float = 0.0):
        if law not in REACHING_LAWS:
            raise ValueError(f"unknown reaching law '{law}': one of {', '.join(REACHING_LAWS)}")
        self.law = REACHING_LAWS[law]
        self.gains = (gains.joint(0), gains.joint(1))
        self.lam = tuple(float(x) for x in lam)
        self.model = model
        self.armature = tuple(float(a) for a in armature)
        self.friction = tuple(float(c) for c in friction)
        self.hand_support = float(hand_support)
        self.v = (0.0, 0.0)

    def __call__(self, t: float, q, qd, q_d, qd_d, qdd_d) -> tuple[float, float]:
        """Torques (N m) for the measured (θ, θ̇) and the reference (θ_d, θ̇_d, θ̈_d) at time t (s)."""
        law, (g1, g2), (lam1, lam2) = self.law, self.gains, self.lam
        q1, q2, w1, w2 = float(q[0]), float(q[1]), float(qd[0]), float(qd[1])
        ed1, ed2 = w1 - qd_d[0], w2 - qd_d[1]
        v1, v2 = ed1 + lam1 * (q1 - q_d[0]), ed2 + lam2 * (q2 - q_d[1])          # eq. (3)
        self.v = (v1, v2)
        a1 = qdd_d[0] - lam1 * ed1 + law(v1, t, g1, math)                       # eq. (5)
        a2 = qdd_d[1] - lam2 * ed2 + law(v2, t, g2, math)
        m11, m12, m22, c1, c2, gr1, gr2 = dynamics_terms(self.model, q1, q2, w1, w2, math)
        f1, f2 = self.friction
        tau1 = (m11 + self.armature[0]) * a1 + m12 * a2 + c1 + gr1 + f1 * sign(w1)
        tau2 = m12 * a1 + (m22 + self.armature[1]) * a2 + c2 + gr2 + f2 * sign(w2)
        if self.hand_support:
            lift = self.hand_support * self.model.l2 * math.sin(q1 + q2)     # Jᵀ (0, f)
            tau1 -= lift - self.hand_support * self.model.l1 * math.sin(q1)
            tau2 -= lift
        return tau1, tau2


class JointSensor:
    """What the controller sees of (θ, θ̇): positions quantised to the Hall-sensor resolution, velocities
    exact, or a backward difference of the measured positions, optionally low-passed (first order, cutoff
    f_c, discretised exactly for the sample period)."""

    KINDS = ("exact", "difference", "filtered")

    def __init__(self, resolution: float, velocity: str, cutoff_hz: float, period: float, qd0=(0.0, 0.0)):
        if velocity not in self.KINDS:
            raise ValueError(f"velocity estimate '{velocity}': one of {', '.join(self.KINDS)}")
        self.resolution, self.velocity, self.period = resolution, velocity, period
        self.smoothing = 1.0 if velocity == "difference" else 1.0 - math.exp(-2 * math.pi * cutoff_hz * period)
        self._previous: tuple[float, float] | None = None
        self._estimate = (float(qd0[0]), float(qd0[1]))

    def position(self, q) -> tuple[float, float]:
        r = self.resolution
        if r <= 0:
            return float(q[0]), float(q[1])
        return round(q[0] / r) * r, round(q[1] / r) * r

    def __call__(self, q, qd) -> tuple[tuple[float, float], tuple[float, float]]:
        q_m = self.position(q)
        if self.velocity == "exact":
            return q_m, (float(qd[0]), float(qd[1]))
        if self._previous is not None:
            a, (p1, p2), (e1, e2) = self.smoothing, self._previous, self._estimate
            self._estimate = (e1 + a * ((q_m[0] - p1) / self.period - e1), e2 + a * ((q_m[1] - p2) / self.period - e2))
        self._previous = q_m
        return q_m, self._estimate

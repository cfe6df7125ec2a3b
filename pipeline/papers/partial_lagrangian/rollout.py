"""Time integration of the AD dynamics under joint PID control, a whole run in one CasADi call.

The controller acts on every coordinate with its own gains (zero gains = free joint):
τ = Kp (r − q) + Ki ∫(r − q) dt − Kd q̇ (derivative on the measurement; radians or metres, no gravity
compensation: spec §3 assumptions). The step is built symbolically and repeated with `mapaccum`, so the
loop runs in CasADi's virtual machine, not in Python.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from pipeline.papers.partial_lagrangian.chain import Chain
from pipeline.papers.partial_lagrangian.lagrangian import Dynamics, dynamics, listing_a1_step

INTEGRATORS = ("semi-implicit-euler", "rk4")


@dataclass(frozen=True)
class Gains:
    """Per-coordinate reference (rad or m) and PID gains; a coordinate with all gains 0 is free."""

    reference: np.ndarray
    kp: np.ndarray
    ki: np.ndarray
    kd: np.ndarray

    @classmethod
    def free(cls, n: int) -> Gains:
        zero = np.zeros(n)
        return cls(zero, zero, zero, zero)

    @property
    def controlled(self) -> np.ndarray:
        return (self.kp != 0) | (self.ki != 0) | (self.kd != 0)


@dataclass(frozen=True)
class Trajectory:
    t: np.ndarray        # (N+1,) s, t[0] = 0 is the initial state
    q: np.ndarray        # (N+1, n)
    qd: np.ndarray       # (N+1, n)
    tau: np.ndarray      # (N+1, n) control torque/force applied from t on (last row repeats)


def _control(q, qd, z, g: Gains):
    return ca.DM(g.kp) * (ca.DM(g.reference) - q) + ca.DM(g.ki) * z - ca.DM(g.kd) * qd


def step_function(dyn: Dynamics, n: int, gains: Gains, dt: float, integrator: str) -> ca.Function:
    """x = (q, q̇, ∫e) -> (x after dt, τ applied during the step)."""
    x = ca.SX.sym("x", 3 * n)
    q, qd, z = x[:n], x[n:2 * n], x[2 * n:]

    def f(q, qd, z):
        tau = _control(q, qd, z, gains)
        return qd, dyn.forward(q, qd, tau), ca.DM(gains.reference) - q, tau

    if integrator == "semi-implicit-euler":   # spec §3.3 (the listing's order): q̇ first, then q with the new q̇
        _, qdd, e, tau = f(q, qd, z)
        qd_next = qd + dt * qdd
        x_next = ca.vertcat(q + dt * qd_next, qd_next, z + dt * e)
    elif integrator == "rk4":
        k1 = f(q, qd, z)
        k2 = f(q + dt / 2 * k1[0], qd + dt / 2 * k1[1], z + dt / 2 * k1[2])
        k3 = f(q + dt / 2 * k2[0], qd + dt / 2 * k2[1], z + dt / 2 * k2[2])
        k4 = f(q + dt * k3[0], qd + dt * k3[1], z + dt * k3[2])
        x_next = x + dt / 6 * ca.vertcat(*(a + 2 * b + 2 * c + d for a, b, c, d in zip(k1[:3], k2[:3], k3[:3],
                                                                                        k4[:3], strict=True)))
        tau = k1[3]
    else:
        raise ValueError(f"integrator must be one of {INTEGRATORS}, got {integrator!r}")
    return ca.Function("step", [x], [x_next, tau])


def simulate(chain: Chain, q0, qd0, gains: Gains, dt: float, duration: float, *, form: str = "partial",
             integrator: str = "semi-implicit-euler") -> Trajectory:
    """Integrate from (q0, q̇0) for `duration` s in steps of dt."""
    n, steps = chain.n, round(duration / dt)
    step = step_function(dynamics(chain, form), n, gains, dt, integrator)
    x0 = np.concatenate([q0, qd0, np.zeros(n)])
    xs, taus = step.mapaccum("run", steps)(x0)
    xs = np.column_stack([x0, np.asarray(xs)]).T
    taus = np.asarray(taus).T
    return Trajectory(np.arange(steps + 1) * dt, xs[:, :n], xs[:, n:2 * n], np.vstack([taus, taus[-1:]]))


def simulate_listing_a1(chain: Chain, q0, qd0, gains: Gains, dt: float, duration: float) -> Trajectory:
    """The paper's Listing A1 scheme (one DoF), stepped as written, with the same PD law; acc starts at 0."""
    steps = round(duration / dt)
    step = listing_a1_step(chain)
    theta, omega, acc = ca.SX.sym("theta"), ca.SX.sym("omega"), ca.SX.sym("acc")
    tau = _control(theta, omega, 0.0, gains)   # PD: the listing has no integral state
    nxt = step(theta, omega, acc, tau, dt)
    run = ca.Function("listing", [ca.vertcat(theta, omega, acc)], [ca.vertcat(*nxt), tau]).mapaccum("run", steps)
    x0 = np.array([q0[0], qd0[0], 0.0])
    xs, taus = run(x0)
    xs = np.column_stack([x0, np.asarray(xs)]).T
    taus = np.asarray(taus).T
    return Trajectory(np.arange(steps + 1) * dt, xs[:, :1], xs[:, 1:2], np.vstack([taus, taus[-1:]]))

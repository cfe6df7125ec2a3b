"""The second plant: the arm's reduced-coordinate Lagrangian (spec §6), 4 DOF, integrated by fixed-step RK4.

Because of the parallelogram, the coupler 5 translates with yaw θ1+θ2, the bars 3 and 4 share the angular
velocity (θ̇1+θ̇2) z + θ̇3 n (n the joint-3 axis) and bar 4's CoM moves like bar 3's. With a = θ1,
b = θ1+θ2, ψ = θ1+θ2+θ4 the kinetic energy is

    2T = A ȧ² + B(θ3) ḃ² + C θ̇3² + 2 l2 S (c2 c3 ȧ ḃ − s2 s3 ȧ θ̇3) + I6z ψ̇²
    A = I1z + m1 lG1² + l2² (m2 + … + m6),   S = m3 lG3 + m4 lG4 + l3 (m5 + m6)
    B = I2z + I5z + c3² (m3 lG3² + m4 lG4² + l3² (m5 + m6) + I3w + I4w) + s3² (I3a + I4a)
    C = m3 lG3² + m4 lG4² + l3² (m5 + m6) + I3n + I4n

(bar inertias: a about the bar, n about the joint-3 axis, w the third axis), and V = −S g s3 +
½ k3 (θ3 − θ3p)². CasADi derives the equations of motion from T and V (Lagrange, eq. 8 with F = 0) and
compiles one control period of RK4 steps into a single call, so the Python loop runs once per period.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from pipeline.papers.scara_half_derivative.arm import Arm


def energy_expressions(arm: Arm, q: ca.SX, qd: ca.SX) -> tuple[ca.SX, ca.SX]:
    """(T, V) of the arm as CasADi expressions of θ and θ̇."""
    m1, m2, m3, m4, m5, m6 = arm.masses
    (_, _, i1z), (_, _, i2z), (i3a, i3n, i3w), (i4a, i4n, i4w), (_, _, i5z), (_, _, i6z) = arm.inertia
    l2, l3 = arm.l2, arm.l3
    c2, s2, c3, s3 = ca.cos(q[1]), ca.sin(q[1]), ca.cos(q[2]), ca.sin(q[2])
    a_dot, b_dot, t3_dot, psi_dot = qd[0], qd[0] + qd[1], qd[2], qd[0] + qd[1] + qd[3]
    bars = m3 * arm.lG3 ** 2 + m4 * arm.lG4 ** 2 + l3 ** 2 * (m5 + m6)
    A = i1z + m1 * arm.lG1 ** 2 + l2 ** 2 * (m2 + m3 + m4 + m5 + m6)
    B = i2z + i5z + c3 ** 2 * (bars + i3w + i4w) + s3 ** 2 * (i3a + i4a)
    C = bars + i3n + i4n
    S = arm.moment
    T = 0.5 * (A * a_dot ** 2 + B * b_dot ** 2 + C * t3_dot ** 2 + i6z * psi_dot ** 2) \
        + l2 * S * (c2 * c3 * a_dot * b_dot - s2 * s3 * a_dot * t3_dot)
    V = -S * arm.gravity * s3 + 0.5 * arm.k3 * (q[2] - arm.theta3p) ** 2
    return T, V


def dynamics(arm: Arm) -> ca.Function:
    """f(x = [θ, θ̇], τ) -> ẋ: M θ̈ = τ − (∂²T/∂θ̇∂θ) θ̇ + ∂T/∂θ − ∂V/∂θ."""
    q, qd, tau = ca.SX.sym("q", 4), ca.SX.sym("qd", 4), ca.SX.sym("tau", 4)
    T, V = energy_expressions(arm, q, qd)
    p = ca.gradient(T, qd)
    M = ca.jacobian(p, qd)
    rhs = tau - ca.jacobian(p, q) @ qd + ca.gradient(T, q) - ca.gradient(V, q)
    return ca.Function("arm_dynamics", [ca.vertcat(q, qd), tau], [ca.vertcat(qd, ca.solve(M, rhs))])


def energy_functions(arm: Arm) -> tuple[ca.Function, ca.Function]:
    """(mass matrix M(θ), total energy E(θ, θ̇) = T + V) as CasADi functions."""
    q, qd = ca.SX.sym("q", 4), ca.SX.sym("qd", 4)
    T, V = energy_expressions(arm, q, qd)
    return (ca.Function("mass_matrix", [q], [ca.jacobian(ca.gradient(T, qd), qd)]),
            ca.Function("energy", [q, qd], [T + V]))


def rk4_period(arm: Arm, period: float, substeps: int) -> ca.Function:
    """One control period with the torque held: x_k, τ -> the `substeps` states at the ends of the RK4
    steps (8 × substeps; the last column is x_{k+1})."""
    f = dynamics(arm)
    x0, tau = ca.SX.sym("x", 8), ca.SX.sym("tau", 4)
    h = period / substeps
    x, states = x0, []
    for _ in range(substeps):
        k1 = f(x, tau)
        k2 = f(x + h / 2 * k1, tau)
        k3 = f(x + h / 2 * k2, tau)
        k4 = f(x + h * k3, tau)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(x)
    return ca.Function("arm_period", [x0, tau], [ca.horzcat(*states)])


class LagrangePlant:
    """The reduced plant behind the same interface as the Exudyn plant: `state()` at the current control
    instant, `advance(τ)` over one period with τ held, `fine()` the samples at every integration step."""

    def __init__(self, arm: Arm, q0, qd0, period: float, substeps: int, periods: int):
        self._step = rk4_period(arm, period, substeps)
        self._x = np.concatenate([q0, qd0]).astype(float)
        self._fine = np.empty((periods * substeps + 1, 8))
        self._fine[0] = self._x
        self._k = 0
        self._substeps = substeps
        self.dt = period / substeps

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        return self._x[:4], self._x[4:]

    def advance(self, tau: np.ndarray) -> None:
        block = self._step(self._x, tau).full().T
        start = 1 + self._k * self._substeps
        self._fine[start:start + self._substeps] = block
        self._x = block[-1]
        self._k += 1

    def fine(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, θ, θ̇) at every RK4 step so far, from t = 0."""
        n = 1 + self._k * self._substeps
        return np.arange(n) * self.dt, self._fine[:n, :4], self._fine[:n, 4:]

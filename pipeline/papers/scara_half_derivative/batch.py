"""Many closed-loop runs of the reduced plant at once: the tunings of a map (Fig. 6), of a path (Fig. 7) or of
a sensitivity sweep advance together, one control period at a time. The controller is vectorized over the
tunings in NumPy and the plant is one CasADi call for all of them (`Function.map`), so a 9 × 9 map costs
about what a handful of single runs do. With the `sampled` implementation this is the law and plant of
`closed_loop.run_closed_loop` + `lagrange.LagrangePlant` (a test checks they agree to round-off).

How the paper's Simscape controller was implemented is not stated ("sampling time T_s = 5 ms ... suitable
for a real discrete-time implementation"); three readings (`system.control.implementation`):

    sampled             θ, θ̇ sampled every T_s, ė = ẋ_d − J(θ)θ̇, the torque of eq. (11)/(17) held (ZOH)
    sampled-difference  the same, but ė by backward difference of the sampled errors, (e_k − e_{k−1})/T_s,
                        the first-order sibling of the Grünwald–Letnikov half-derivative (eq. 15)
    continuous          K, D and τ_g act in continuous time (evaluated in every RK4 stage, as Simulink
                        blocks in a continuous model would); only the half-derivative is sampled every T_s
                        and its force HD·e^(1/2) held
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from pipeline.papers.scara_half_derivative.arm import Arm, fk, jacobian
from pipeline.papers.scara_half_derivative.closed_loop import DIVERGED_ERROR, ClosedLoopRun, divergence
from pipeline.papers.scara_half_derivative.controller import HALF, Gains
from pipeline.papers.scara_half_derivative.lagrange import dynamics, rk4_period
from pipeline.papers.scara_half_derivative.setpoint import Motion
from pipeline.robotics.fractional import GrunwaldLetnikov, gl_dc_gain

IMPLEMENTATIONS = ("sampled", "sampled-difference", "continuous")


def fk_jacobian_sx(arm: Arm, q: ca.SX) -> tuple[ca.SX, ca.SX]:
    """Eqs. (3)-(7) as CasADi expressions (the NumPy forms are `arm.fk`, `arm.jacobian`; tests compare)."""
    t1, t2, t3, t4 = q[0], q[1], q[2], q[3]
    s1, c1, s3, c3 = ca.sin(t1), ca.cos(t1), ca.sin(t3), ca.cos(t3)
    s12, c12 = ca.sin(t1 + t2), ca.cos(t1 + t2)
    l2, l3 = arm.l2, arm.l3
    r = l3 * c3
    x = ca.vertcat(l2 * c1 + r * c12, l2 * s1 + r * s12, arm.l1 - l3 * s3 - arm.l4, t1 + t2 + t4)
    J = ca.vertcat(ca.horzcat(-l2 * s1 - r * s12, -r * s12, -l3 * s3 * c12, 0),
                   ca.horzcat(l2 * c1 + r * c12, r * c12, -l3 * s3 * s12, 0),
                   ca.horzcat(0, 0, -r, 0),
                   ca.horzcat(1, 1, 0, 1))
    return x, J


def continuous_period(arm: Arm, period: float, substeps: int) -> ca.Function:
    """One control period of RK4 with K, D and τ_g inside every stage (the `continuous` implementation).

    (x_k, F_held, K', D, setpoint) -> (states at the ends of the substeps, torque at the start of each
    substep): `F_held` is the held half-derivative force HD·e^(1/2) (Cartesian), `setpoint` the 8 × (2·substeps
    + 1) values [x_d; ẋ_d] at the RK4 stage times t_k + i·h/2."""
    f = dynamics(arm)
    h = period / substeps
    x0, held, K, D = ca.SX.sym("x", 8), ca.SX.sym("F_held", 4), ca.SX.sym("K", 4), ca.SX.sym("D", 4)
    setpoint = ca.SX.sym("setpoint", 8, 2 * substeps + 1)
    q, qd = ca.SX.sym("q", 4), ca.SX.sym("qd", 4)
    xd, xd_dot = ca.SX.sym("x_d", 4), ca.SX.sym("xd_d", 4)
    x, J = fk_jacobian_sx(arm, q)
    tau = J.T @ (K * (xd - x) + D * (xd_dot - J @ qd) + held)                          # eqs. (11), (17)
    tau[2] += arm.k3 * (q[2] - arm.theta3p) - arm.moment * arm.gravity * ca.cos(q[2])   # τ_g,3, eq. (12)
    law = ca.Function("law", [q, qd, xd, xd_dot, held, K, D], [tau])

    def torque(state, i):
        return law(state[:4], state[4:], setpoint[:4, i], setpoint[4:, i], held, K, D)

    state, states, torques = x0, [], []
    for s in range(substeps):
        i = 2 * s
        tau0 = torque(state, i)
        k1 = f(state, tau0)
        mid = state + h / 2 * k1
        k2 = f(mid, torque(mid, i + 1))
        mid = state + h / 2 * k2
        k3 = f(mid, torque(mid, i + 1))
        end = state + h * k3
        k4 = f(end, torque(end, i + 2))
        state = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(state)
        torques.append(tau0)
    return ca.Function("arm_period_continuous", [x0, held, K, D, setpoint],
                       [ca.horzcat(*states), ca.horzcat(*torques)])


@dataclass
class BatchResult:
    """One entry per tuning: its run (None if it diverged) or why it failed."""

    runs: list[ClosedLoopRun | None]
    failures: list[str | None]


def _stack(gains: list[Gains], name: str) -> np.ndarray:
    return np.array([getattr(g, name) for g in gains])


def simulate(arm: Arm, gains: list[Gains], motion: Motion, q0: np.ndarray, duration: float, period: float,
             substeps: int, gl_terms: int, implementation: str = "sampled",
             compensate_stiffness: bool = True) -> BatchResult:
    """Every tuning of `gains` over the set-point `motion` from rest at q0, in one pass."""
    if implementation not in IMPLEMENTATIONS:
        raise ValueError(f"implementation must be one of {IMPLEMENTATIONS}, not {implementation!r}")
    n, periods, h = len(gains), round(duration / period), period / substeps
    continuous = implementation == "continuous"
    HD = _stack(gains, "HD")
    fractional = HD.any(axis=1)
    compensation = gl_dc_gain(HALF, gl_terms, period) if compensate_stiffness else 0.0
    K = _stack(gains, "K") - compensation * HD * fractional[:, None]                   # eq. (17)
    D = _stack(gains, "D")
    half = GrunwaldLetnikov(HALF, gl_terms, period, width=4 * n)                        # eqs. (15)-(16)
    if continuous:
        step = continuous_period(arm, period, substeps).map(n)
        stages = np.arange(periods)[:, None] * period + np.arange(2 * substeps + 1)[None, :] * h / 2
        x_s, xd_s, _ = motion(stages.ravel())
        setpoints = np.concatenate([x_s, xd_s], axis=1).reshape(periods, 2 * substeps + 1, 8).transpose(0, 2, 1)
    else:
        step = rk4_period(arm, period, substeps).map(n)
    t_control = np.arange(periods) * period
    x_d, xd_d, _ = motion(t_control)
    rest = np.concatenate([q0, np.zeros(4)])
    state = np.tile(rest, (n, 1))
    fine = np.empty((periods * substeps + 1, n, 8))
    fine[0] = state
    fine_tau = np.empty((periods * substeps, n, 4)) if continuous else None
    tau = np.zeros((periods, n, 4))
    alive = np.ones(n, dtype=bool)
    failures: list[str | None] = [None] * n
    previous_error = np.zeros((n, 4))           # the arm starts at rest on the set-point: e(−T_s) = 0
    for k in range(periods):
        q, qd = state[:, :4], state[:, 4:]
        J = jacobian(arm, q)
        error = x_d[k] - fk(arm, q)
        if implementation == "sampled-difference":
            rate = (error - previous_error) / period
        else:
            rate = xd_d[k] - np.einsum("nij,nj->ni", J, qd)
        previous_error = error
        held = HD * half.push(error.ravel()).reshape(n, 4)
        bad = alive & ~(np.abs(error).max(axis=1) < DIVERGED_ERROR)   # NaN fails the comparison too
        for i in np.flatnonzero(bad):
            failures[i] = divergence(error[i], t_control[k])
        alive &= ~bad
        state[bad] = rest                       # a diverged tuning is parked at rest; the others go on
        if continuous:
            out = step(state.T, held.T, K.T, D.T, setpoints[k])
            block, torques = (np.asarray(o).reshape(-1, n, substeps).transpose(2, 1, 0) for o in out)
            fine_tau[k * substeps:(k + 1) * substeps] = torques
            tau[k] = torques[0]
        else:
            force = K * error + D * rate + held
            tau[k] = np.einsum("nji,nj->ni", J, force)
            tau[k, :, 2] += arm.k3 * (q[:, 2] - arm.theta3p) - arm.moment * arm.gravity * np.cos(q[:, 2])  # (12)
            block = np.asarray(step(state.T, tau[k].T)).reshape(8, n, substeps).transpose(2, 1, 0)
        block[:, ~alive] = rest
        fine[1 + k * substeps:1 + (k + 1) * substeps] = block
        state = block[-1]
    t = np.arange(periods * substeps + 1) * h
    runs = [ClosedLoopRun(t_control, tau[:, i], np.full(periods, np.nan), t, fine[:, i, :4], fine[:, i, 4:],
                          tau_fine=None if fine_tau is None else fine_tau[:, i]) if alive[i] else None
            for i in range(n)]
    return BatchResult(runs, failures)

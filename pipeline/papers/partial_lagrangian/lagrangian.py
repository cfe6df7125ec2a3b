"""Equations of motion by automatic differentiation (CasADi SX), of the full Lagrangian and of the
partial Lagrangians (Sect. 2.1, Table 1), and the one-DoF scheme of the paper's Listing A1.

The only system-specific code is the geometric constraint p_i(q) (Listing A1 item 1); AD does the rest:
ṗ_i = ∂p_i/∂q q̇ (forward mode, the listing's ∂x/∂t), L_i = K_i − P_i (eqs. 15-16, 21-22), and the
balance D L + ∂R/∂q̇ = τ (eq. 3 with Rayleigh dissipation, Listing A1 item 3). The balance is linear in q̈,
so M = ∂τ/∂q̈ and b = τ(q, q̇, 0) (the listing's "I = acc.grad"), and q̈ = M⁻¹(τ − b).

- `full`: AD of the whole L = K − P over all n coordinates (the usual Lagrange method, row by row), the
  kinematics of all links computed once (p_i = p_{i−1} + l_i e_i).
- `partial`: column i of Table 1 is its own graph: L_i depends on q_1..q_i only, so τ_ki = D_k L_i is
  formed for k ≤ i (eq. 5) and the columns are summed (eq. 4). Each column is independent of the others,
  which is what lets the paper reuse, replace (eqs. 6-9) or parallelise them.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from pipeline.papers.partial_lagrangian.chain import REVOLUTE, Chain

FORMS = ("partial", "full")


def geometric_constraints(chain: Chain, q: ca.SX, last: int) -> list[ca.SX]:
    """p_1..p_last with p_i = p_{i−1} + l_i e(θ_1+…+θ_i) (eqs. 11, 17), from q_1..q_last."""
    phi, p, tips = 0.0, ca.SX.zeros(2), []
    for j in range(last + 1):
        revolute = chain.joints[j] == REVOLUTE
        phi = phi + (q[j] if revolute else chain.angle[j])
        p = p + (chain.length[j] if revolute else q[j]) * ca.vertcat(ca.cos(phi), ca.sin(phi))
        tips.append(p)
    return tips


def partial_lagrangian(chain: Chain, i: int, q: ca.SX, qd: ca.SX, p: ca.SX | None = None) -> tuple[ca.SX, ca.SX]:
    """(L_i, R_i) of link i in the coordinates q, q̇ it depends on (q_1..q_i). A module builds its own
    geometric constraint p_i unless one is handed in (the whole system's, shared by all links)."""
    if p is None:
        p = geometric_constraints(chain, q, i)[-1]
    v = ca.jtimes(p, q[: i + 1], qd[: i + 1])                       # ṗ_i (eqs. 12, 18)
    kinetic = 0.5 * chain.mass[i] * ca.dot(v, v)                    # eq. (15), (21)
    potential = 0.5 * chain.stiffness[i] * ca.dot(p, p) + chain.mass[i] * chain.gravity * p[1]  # eq. (16), (22)
    if chain.damping_model == "cartesian":
        rayleigh = 0.5 * chain.damping[i] * ca.dot(v, v)            # Listing A1: R = ½ c (dx² + dy²)
    else:
        rayleigh = 0.5 * chain.damping[i] * qd[i] ** 2
    return kinetic - potential, rayleigh


def balance(lagrangian: ca.SX, rayleigh: ca.SX, q: ca.SX, qd: ca.SX, qdd: ca.SX) -> ca.SX:
    """τ = d/dt ∂L/∂q̇ − ∂L/∂q + ∂R/∂q̇ (eq. 3 plus dissipation), the time derivative by forward AD."""
    momentum = ca.gradient(lagrangian, qd)
    return (ca.jtimes(momentum, ca.vertcat(q, qd), ca.vertcat(qd, qdd)) - ca.gradient(lagrangian, q)
            + ca.gradient(rayleigh, qd))


def column(chain: Chain, i: int, q: ca.SX, qd: ca.SX, qdd: ca.SX) -> ca.SX:
    """Column i of Table 1: (τ_1i, …, τ_ii) = D_k L_i for k ≤ i; the rows k > i are zero (eq. 5)."""
    lagrangian, rayleigh = partial_lagrangian(chain, i, q, qd)
    k = slice(0, i + 1)
    return balance(lagrangian, rayleigh, q[k], qd[k], qdd[k])


def inverse_dynamics(chain: Chain, form: str, q: ca.SX, qd: ca.SX, qdd: ca.SX) -> ca.SX:
    """τ(q, q̇, q̈) of the whole chain: the usual Lagrange method (one L = K − P of the whole system, its
    kinematics computed once for all links), or the sum of Table 1's independent columns (eq. 4)."""
    n = chain.n
    if form == "full":
        tips = geometric_constraints(chain, q, n - 1)
        parts = [partial_lagrangian(chain, i, q, qd, tips[i]) for i in range(n)]
        return balance(sum(p[0] for p in parts), sum(p[1] for p in parts), q, qd, qdd)
    if form == "partial":
        tau = ca.SX.zeros(n)
        for i in range(n):
            tau[: i + 1] += column(chain, i, q, qd, qdd)
        return tau
    raise ValueError(f"form must be one of {FORMS}, got {form!r}")


def _symbols(n: int) -> tuple[ca.SX, ca.SX, ca.SX]:
    return ca.SX.sym("q", n), ca.SX.sym("qd", n), ca.SX.sym("qdd", n)


def mass_and_bias(tau: ca.SX, qdd: ca.SX) -> tuple[ca.SX, ca.SX]:
    """τ = M q̈ + b: M = ∂τ/∂q̈ (the listing's acc.grad, here per entry), b = τ at q̈ = 0."""
    return ca.jacobian(tau, qdd), ca.substitute(tau, qdd, ca.SX.zeros(qdd.numel()))


def _terms(chain: Chain, form: str) -> tuple[ca.SX, ...]:
    q, qd, qdd = _symbols(chain.n)
    tau = inverse_dynamics(chain, form, q, qd, qdd)
    return (q, qd, qdd, tau, *mass_and_bias(tau, qdd))


def equations_of_motion(chain: Chain, form: str = "partial") -> ca.Function:
    """(q, q̇) -> (M, b): the coefficients of the equations of motion, what the paper's AD computes per step."""
    q, qd, _, _, M, b = _terms(chain, form)
    return ca.Function(f"equations_of_motion_{form}", [q, qd], [M, b])


@dataclass(frozen=True)
class Dynamics:
    """Compiled AD dynamics of one chain in one form."""

    forward: ca.Function      # (q, q̇, τ) -> q̈
    mass_bias: ca.Function    # (q, q̇) -> (M, b), τ = M q̈ + b
    inverse: ca.Function      # (q, q̇, q̈) -> τ


def dynamics(chain: Chain, form: str = "partial") -> Dynamics:
    q, qd, qdd, tau, M, b = _terms(chain, form)
    u = ca.SX.sym("tau", chain.n)
    return Dynamics(forward=ca.Function(f"forward_{form}", [q, qd, u], [ca.solve(M, u - b)]),
                    mass_bias=ca.Function(f"mass_bias_{form}", [q, qd], [M, b]),
                    inverse=ca.Function(f"inverse_{form}", [q, qd, qdd], [tau]))


def column_mass_bias(chain: Chain, i: int) -> ca.Function:
    """Column i alone as a function of its own coordinates: (q_1..i, q̇_1..i) -> (M_i, b_i), what one
    thread computes when the columns run in parallel (Sect. 4.1)."""
    q, qd, qdd = _symbols(i + 1)
    M, b = mass_and_bias(column(chain, i, q, qd, qdd), qdd)
    return ca.Function(f"column{i + 1}", [q, qd], [M, b])


# -- Listing A1 ----------------------------------------------------------------------------------------


def listing_a1_step(chain: Chain) -> ca.Function:
    """One step of the paper's Listing A1 (one DoF), with PyTorch's graph semantics kept:
    (θ0, ω0, acc_prev, τ, dt) -> (θ, ω, acc).

    The listing registers ω = ω0 + acc·dt and θ = θ0 + ω·dt as graph nodes, takes ẋ as ∂x/∂dt, and
    `autograd.grad(L, node)` is the adjoint of that node: the partial through every path downstream of it.
    Here the nodes θ, ω, acc, dt are symbols and the two registered relations are applied by hand as
    the chain rule autograd would apply. What this reproduces (spec §3.2): I = ∂T/∂acc ≈ 2 m l², so the
    stored acc is about half of θ̈, and ω is advanced by (acc_prev + acc)·dt.
    """
    if chain.n != 1 or chain.joints[0] != REVOLUTE:
        raise ValueError("Listing A1 is written for one revolute DoF (its acc.grad is not a mass matrix for more)")
    th, om, acc, dt, th0, om0, acc_prev, tau = (ca.SX.sym(s) for s in
                                                ("theta", "omega", "acc", "dt", "theta0", "omega0", "acc_prev", "tau"))
    d_th_d_dt = om + dt * acc               # θ = θ0 + ω dt, ω = ω0 + acc dt: ∂θ/∂dt through the graph
    p = geometric_constraints(chain, th, 0)[0]  # 1. x = l cos θ, y = l sin θ
    v = ca.jacobian(p, th) * d_th_d_dt      # dx, dy = autograd.grad(x, dt)
    m, k, c, g = chain.mass[0], chain.stiffness[0], chain.damping[0], chain.gravity
    lagrangian = 0.5 * m * ca.dot(v, v) - (0.5 * k * ca.dot(p, p) + m * g * p[1])  # 2. K − P
    rayleigh = 0.5 * c * ca.dot(v, v)

    def adjoint(expr: ca.SX, node: str) -> ca.SX:
        """autograd.grad(expr, node): the partial plus every path through the nodes registered after it."""
        if node == "theta":
            return ca.jacobian(expr, th)
        if node == "omega":                 # θ = θ0 + ω dt
            return ca.jacobian(expr, om) + ca.jacobian(expr, th) * dt
        if node == "acc":                   # ω = ω0 + acc dt, θ = θ0 + ω dt
            return ca.jacobian(expr, acc) + ca.jacobian(expr, om) * dt + ca.jacobian(expr, th) * dt ** 2
        # the leaf dt: direct, through ω = ω0 + acc dt and through θ = θ0 + ω dt
        return ca.jacobian(expr, dt) + ca.jacobian(expr, om) * acc + ca.jacobian(expr, th) * d_th_d_dt

    dl_dth = adjoint(lagrangian, "theta")   # 3.
    dl_domega = adjoint(lagrangian, "omega")
    dl_dt = adjoint(dl_domega, "dt")
    dr_domega = adjoint(rayleigh, "omega")
    lacc = dl_dth - dr_domega + tau         # the control input written into the generalized force
    balance_ = dl_dt - lacc                 # T
    inertia = adjoint(balance_, "acc")      # 4.-5. T.backward(); I = acc.grad
    omega_node = om0 + acc_prev * dt        # 0. the registered nodes, at the stored acc
    theta_node = th0 + omega_node * dt
    acc_value = ca.substitute(lacc / inertia, ca.vertcat(th, om, acc), ca.vertcat(theta_node, omega_node, acc_prev))
    return ca.Function("listing_a1_step", [th0, om0, acc_prev, tau, dt],
                       [theta_node, omega_node + acc_value * dt, acc_value])  # acc = lacc / I; omega += acc * dt

"""The two NMPCs of Sec. 4.1 as CasADi NLPs solved by IPOPT: direct multiple shooting (Sec. 3.2), k intervals
of Δt, piecewise-constant joint velocities u, one integrator step per interval.

- `decomposed` (Sec. 3.2, eqs. 10a-g): states [p_w^ζ; q_m], inputs q̇_m ∈ R³, model J_{w,trans}^ζ(q_m).
- `full` (Sec. 4.1 / spec §3.7): states [p_w^e; Q_w^e; q], inputs q̇ ∈ R⁶, model J_w^e(q); (10c) extended by
  an orientation term. The paper gives only its inputs and model; the rest is the spec's assumption.

Positions enter the NLP in `length_unit` (mm by default, the unit the weights μ are for); the interface is SI.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from pipeline.papers.nmpc_cdkd import kinematics as kin
from pipeline.papers.nmpc_cdkd.kinematics import Arm
from pipeline.robotics import dh_casadi

MODELS = ("decomposed", "full")


@dataclass(frozen=True)
class OcpSettings:
    model: str                 # decomposed | full
    horizon_steps: int         # k
    dt: float                  # s, shooting interval
    mu: tuple[float, float, float]   # μ_u, μ_q̈, μ_p of (10c)
    length_unit: float         # m per NLP length unit
    acceleration: float        # rad/s², (10e)
    jerk: float                # rad/s³, (10e)
    obstacles: int = 0         # ν spheres in (10f)
    height_band: bool = False  # (10g) rows present
    integrator: str = "rk4"
    cost_quadrature: bool = True
    orientation_lever: float = 0.25   # m, full model only: μ_o = μ_p (2·lever/unit)²
    tol: float = 1e-8
    acceptable_obj_change_tol: float = 1e-6
    max_iter: int = 3000


@dataclass(frozen=True)
class Solution:
    x: np.ndarray              # (k+1, nx) in NLP units
    u: np.ndarray              # (k, nu), rad/s
    seconds: float             # wall time of the solver call
    solver_seconds: float      # CasADi's own total (`t_wall_total`)
    iterations: int
    success: bool
    status: str
    cost: float


def _rk4(f: ca.Function, x, u, h: float):
    k1 = f(x, u)
    k2 = f(x + h / 2 * k1, u)
    k3 = f(x + h / 2 * k2, u)
    k4 = f(x + h * k3, u)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


class Nmpc:
    """One OCP structure (model, k, ν, band), built once and solved many times."""

    def __init__(self, arm: Arm, s: OcpSettings):
        if s.model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, not {s.model!r}")
        self.arm, self.s = arm, s
        self.scale = 1.0 / s.length_unit
        self.nu = 3 if s.model == "decomposed" else 6
        self.nx = 6 if s.model == "decomposed" else 13
        self.joint_slice = slice(3, 6) if s.model == "decomposed" else slice(7, 13)
        self.nref = 3 if s.model == "decomposed" else 7
        self._build()

    # -- model -----------------------------------------------------------------------------------------
    def _dynamics(self) -> tuple[ca.Function, ca.Function]:
        """(f(x, u) = ẋ, wrist(x) = p^ζ in NLP units)."""
        arm, S = self.arm, self.scale
        x, u = ca.SX.sym("x", self.nx), ca.SX.sym("u", self.nu)
        if self.s.model == "decomposed":
            q_m = x[3:6]
            J = dh_casadi.geometric_jacobian(arm.wrist_dh, q_m, arm.base)[:3, :]
            xdot = ca.vertcat(S * (J @ u), u)                        # (10d)
            wrist = x[0:3]
        else:
            q = x[7:13]
            J = dh_casadi.geometric_jacobian(arm.dh, q, arm.base, arm.tool)
            omega = J[3:, :] @ u
            eta, eps = x[3], x[4:7]
            quat_dot = 0.5 * ca.vertcat(-ca.dot(eps, omega), eta * omega + ca.cross(omega, eps))  # ω in {w}
            xdot = ca.vertcat(S * (J[:3, :] @ u), quat_dot, u)
            wrist = S * dh_casadi.frames(arm.wrist_dh, q[0:3], arm.base)[-1][:3, 3]
        return ca.Function("f", [x, u], [xdot]), ca.Function("wrist", [x], [wrist])

    def _stage_cost(self, x_next, u, acc, ref):
        mu_u, mu_acc, mu_p = self.s.mu
        cost = mu_u * ca.sumsqr(u) + mu_acc * ca.sumsqr(acc) + mu_p * ca.sumsqr(ref[0:3] - x_next[0:3])  # (10c)
        if self.s.model == "full":
            mu_o = mu_p * (2 * self.s.orientation_lever * self.scale) ** 2
            eta_d, eps_d, eta, eps = ref[3], ref[4:7], x_next[3], x_next[4:7]
            e_o = eta * eps_d - eta_d * eps - ca.cross(eps_d, eps)  # eq. (11) in {w}
            cost += mu_o * ca.sumsqr(e_o)
        return cost

    def _build(self) -> None:
        s, k, nx, nu, h = self.s, self.s.horizon_steps, self.nx, self.nu, self.s.dt
        f, wrist = self._dynamics()
        step = (lambda x, u: _rk4(f, x, u, h)) if s.integrator == "rk4" else (lambda x, u: x + h * f(x, u))
        X, U = ca.SX.sym("X", nx, k + 1), ca.SX.sym("U", nu, k)
        ref = ca.SX.sym("ref", self.nref, k)
        u_prev = ca.SX.sym("u_prev", nu, 2)          # u_{-1}, u_{-2}: the last two applied inputs
        centres = ca.SX.sym("c", 3, s.obstacles * k)  # p_{w,i}^v(τ_κ), node-major
        radii = ca.SX.sym("R", s.obstacles)           # r_i + d_f + sqrt(a_e² + d_e²)
        cost, g = 0, []
        for j in range(k):
            u1 = U[:, j - 1] if j >= 1 else u_prev[:, 0]
            u2 = U[:, j - 2] if j >= 2 else u_prev[:, 1 - j]
            acc = (U[:, j] - u1) / h                  # q̈ and q⃛ as differences of u (spec §3.4, §10.3)
            jerk = (U[:, j] - 2 * u1 + u2) / h ** 2
            cost += (h if s.cost_quadrature else 1.0) * self._stage_cost(X[:, j + 1], U[:, j], acc, ref[:, j])
            g += [X[:, j + 1] - step(X[:, j], U[:, j]), acc, jerk]
            p = wrist(X[:, j + 1])
            g += [ca.norm_2(p - centres[:, j * s.obstacles + i]) - radii[i] for i in range(s.obstacles)]  # (10f)
            if s.height_band:
                g.append(p[2])                                                                           # (10g)
        self._w = ca.vertcat(ca.vec(X), ca.vec(U))
        params = ca.vertcat(ca.vec(ref), ca.vec(u_prev), ca.vec(centres), radii)
        options = {"ipopt.tol": s.tol, "ipopt.acceptable_obj_change_tol": s.acceptable_obj_change_tol,
                   "ipopt.max_iter": s.max_iter, "ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False}
        cost, constraints = ca.cse([cost, ca.vertcat(*g)])   # shared subexpressions once: the same NLP, cheaper
        self._solver = ca.nlpsol(f"nmpc_{s.model}_{k}", "ipopt",
                                 {"x": self._w, "f": cost, "g": constraints, "p": params}, options)
        rows = nx + 2 * nu + s.obstacles + int(s.height_band)
        self._rows_per_node = rows
        lower, upper = np.zeros(rows), np.zeros(rows)
        lower[nx:nx + nu], upper[nx:nx + nu] = -s.acceleration, s.acceleration
        lower[nx + nu:nx + 2 * nu], upper[nx + nu:nx + 2 * nu] = -s.jerk, s.jerk
        lower[nx + 2 * nu:nx + 2 * nu + s.obstacles], upper[nx + 2 * nu:nx + 2 * nu + s.obstacles] = 0.0, np.inf
        self._lbg, self._ubg = np.tile(lower, k), np.tile(upper, k)
        joints = np.arange(nx)[self.joint_slice]
        lbx, ubx = np.full((k + 1, nx), -np.inf), np.full((k + 1, nx), np.inf)
        lbx[1:, joints], ubx[1:, joints] = self.arm.lower[:nu], self.arm.upper[:nu]  # (10e), nodes 1..k
        vel = self.arm.velocity[:nu]
        self._lbx = np.r_[lbx.ravel(), np.tile(-vel, k)]                              # (10a)
        self._ubx = np.r_[ubx.ravel(), np.tile(vel, k)]

    def dimensions(self) -> dict[str, int]:
        """Size of the NLP IPOPT solves: variables, constraints, nonzeros of the constraint Jacobian and of the
        Lagrangian's Hessian (upper triangle)."""
        solver = self._solver
        return {"variables": solver.size1_in("x0"), "constraints": solver.size1_in("lbg"),
                "jacobian_nonzeros": solver.get_function("nlp_jac_g").sparsity_out(1).nnz(),
                "hessian_nonzeros": solver.get_function("nlp_hess_l").sparsity_out(0).nnz()}

    # -- NLP data from joint angles --------------------------------------------------------------------
    def state(self, q: np.ndarray) -> np.ndarray:
        """(..., nx): NLP state of joint vectors q (..., 6)."""
        q = np.asarray(q, dtype=float)
        if self.s.model == "decomposed":
            return np.concatenate([kin.wrist_point(self.arm, q[..., :3]) * self.scale, q[..., :3]], axis=-1)
        T = kin.tool_pose(self.arm, q)
        return np.concatenate([T[..., :3, 3] * self.scale, kin.quaternion(T[..., :3, :3]), q], axis=-1)

    def reference(self, q_ref: np.ndarray, quat_sign_of: np.ndarray | None = None) -> np.ndarray:
        """(k, nref) per-node reference of (10c) from the joint reference γ at nodes 1..k; the desired
        quaternions of the full model are put on the hemisphere of `quat_sign_of` (the current Q)."""
        x = self.state(q_ref)
        if self.s.model == "decomposed":
            return x[:, :3]
        quat = x[:, 3:7]
        if quat_sign_of is not None:
            quat = np.where((quat @ quat_sign_of < 0)[:, None], -quat, quat)
        return np.concatenate([x[:, :3], quat], axis=1)

    def solve(self, x0: np.ndarray, ref: np.ndarray, u_prev: np.ndarray, guess_x: np.ndarray, guess_u: np.ndarray,
              centres: np.ndarray | None = None, radii: np.ndarray | None = None,
              band: tuple[float, float] | None = None) -> Solution:
        """One OCP: x0 (nx) NLP state, ref (k, nref), u_prev (2, nu) = [u_{-1}, u_{-2}], guesses (k+1, nx) and
        (k, nu); obstacle centres (k, ν, 3) and total radii (ν,) in metres; wrist height band (m)."""
        s, k = self.s, self.s.horizon_steps
        lbx, ubx = self._lbx.copy(), self._ubx.copy()
        lbx[:self.nx] = ubx[:self.nx] = x0                     # the initial value of (10d)
        lbg, ubg = self._lbg, self._ubg
        if s.height_band:
            lbg, ubg = lbg.copy(), ubg.copy()
            lbg[self._rows_per_node - 1::self._rows_per_node] = band[0] * self.scale
            ubg[self._rows_per_node - 1::self._rows_per_node] = band[1] * self.scale
        c = np.zeros((k, 0, 3)) if centres is None else np.asarray(centres)
        r = np.zeros(0) if radii is None else np.asarray(radii)
        params = np.r_[ref.ravel(), u_prev.ravel(), (c * self.scale).ravel(), r * self.scale]
        w0 = np.r_[guess_x.ravel(), guess_u.ravel()]
        w0[:self.nx] = x0
        start = time.perf_counter()
        out = self._solver(x0=w0, p=params, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
        seconds = time.perf_counter() - start
        stats = self._solver.stats()
        w = np.asarray(out["x"]).ravel()
        nxk = self.nx * (k + 1)
        return Solution(x=w[:nxk].reshape(k + 1, self.nx), u=w[nxk:].reshape(k, self.nu), seconds=seconds,
                        solver_seconds=float(stats.get("t_wall_total", np.nan)), iterations=int(stats["iter_count"]),
                        success=bool(stats["success"]), status=str(stats["return_status"]), cost=float(out["f"]))

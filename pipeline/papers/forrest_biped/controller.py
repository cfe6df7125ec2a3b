"""The walking controller of Sec. 6 (Fig. 17), one call per 1 ms cycle, on MuJoCo's model of the robot.

1. CP control (eqs. 49-50): p^c = p^d + (1 + k/ω)(ξ − ξ_d), clamped to the support polygon (assumption);
2. feedforward (eq. 51): ẍ_c^f = ω²(x_c^d − p^c) (printed: the desired CoM; `measured` uses x_c);
3. Cartesian PD (eq. 52) for the CoM, the base orientation and both feet;
4. the desired wrench on the CoM (eq. 53), with the weight added (the paper omits gravity);
5. the contact wrench distribution QP (eqs. 54-56), solved by DAQP, a dual active-set solver;
6. the optimized CoM acceleration, the joint accelerations from the 18 × 18 task Jacobian (eq. 57, with J̇q̇);
7. floating-base inverse dynamics with the optimized foot wrenches (eq. 58), saturated at Table 2's torques.

Every matrix comes from the controller's own MuJoCo model of Table 4 (mass matrix, bias forces, Jacobians),
evaluated at the measured joint state; the simulated robot is a separate model that may differ (`system.plant`).

The QP's variables are the two foot wrenches [f; τ] at the sole centres, in the sole frames (constraints stay
constant). With the horizontal moments zero about the CoP (eq. 54) the printed problem is bilinear in the CoP;
the equivalent linear form bounds the moments instead: −d_x f_z ≤ −τ_y ≤ d_x f_z, −d_y f_z ≤ τ_x ≤ d_y f_z. The
CoP is recovered as (−τ_y/f_z, τ_x/f_z). A swing foot's wrench is fixed at zero.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import daqp
import numpy as np

from pipeline.papers.forrest_biped.generator import DOUBLE, LEFT, RIGHT
from pipeline.papers.forrest_biped.model import Biped
from pipeline.papers.forrest_biped.support import clamp

INF = 1e30
FOOT_ROWS = 11          # f_z ≥ f_min, friction pyramid (4), CoP (4), yaw moment (2)


def orientation_error(R: np.ndarray) -> np.ndarray:
    """½ Σ_i r_i × e_i, R a rotation matrix (or MuJoCo's row-major 9-vector): the rotation (rad, world axes)
    that takes R to the identity; its norm is the sine of the angle."""
    R = np.ravel(R)
    return 0.5 * np.array([R[5] - R[7], R[6] - R[2], R[1] - R[3]])


@dataclass(frozen=True)
class Gains:
    """K_p per task (1/s²); K_d = 2 sqrt(K_p) (critical damping)."""

    com: np.ndarray
    base: np.ndarray
    foot: np.ndarray

    @classmethod
    def from_config(cls, c: Mapping[str, Any]) -> Gains:
        s = float(c["gain_scale"])
        return cls(np.asarray(c["kp_com"], float) * s, np.asarray(c["kp_base"], float) * s,
                   np.asarray(c["kp_foot"], float) * s)


def foot_constraints(mu: float, f_min: float, half_x: float, half_y: float) -> tuple[np.ndarray, np.ndarray]:
    """A w ≤ b on one foot's wrench w = [f_x f_y f_z τ_x τ_y τ_z] in its sole frame (FOOT_ROWS rows)."""
    A = np.zeros((FOOT_ROWS, 6))
    b = np.zeros(FOOT_ROWS)
    A[0, 2], b[0] = -1.0, -f_min                       # f_z ≥ f_min
    for r, (i, s) in enumerate(((0, 1), (0, -1), (1, 1), (1, -1)), start=1):
        A[r, i], A[r, 2] = s, -mu / np.sqrt(2)         # |f_x|, |f_y| ≤ μ f_z / √2: the pyramid inside the cone
    A[5, 4], A[5, 2] = -1.0, -half_x                   # CoP x = −τ_y / f_z ≤ d_x
    A[6, 4], A[6, 2] = 1.0, -half_x                    # CoP x ≥ −d_x
    A[7, 3], A[7, 2] = 1.0, -half_y                    # CoP y = τ_x / f_z ≤ d_y
    A[8, 3], A[8, 2] = -1.0, -half_y
    torsion = mu * min(half_x, half_y)                 # |τ_z| ≤ μ f_z min(d_x, d_y): the corners' friction
    A[9, 5], A[9, 2] = 1.0, -torsion
    A[10, 5], A[10, 2] = -1.0, -torsion
    return A, b


class WrenchQP:
    """Eqs. (54)-(56): min (F_d − G w)ᵀ W (F_d − G w) + ε‖w‖² over both foot wrenches, per support state."""

    def __init__(self, mu: float, f_min: float, half_x: float, half_y: float, weights: np.ndarray, eps: float):
        A1, b1 = foot_constraints(mu, f_min, half_x, half_y)
        self.A = np.zeros((2 * FOOT_ROWS, 12))
        self.A[:FOOT_ROWS, :6], self.A[FOOT_ROWS:, 6:] = A1, A1
        self.W = np.asarray(weights, dtype=float)
        self.eps = eps
        self.upper, self.lower = {}, {}
        for state, active in ((DOUBLE, (True, True)), (LEFT, (True, False)), (RIGHT, (False, True))):
            bounds_u = np.concatenate([np.full(6, INF if a else 0.0) for a in active])
            rows_u = np.concatenate([b1 if a else np.full(FOOT_ROWS, INF) for a in active])
            self.upper[state] = np.r_[bounds_u, rows_u]
            self.lower[state] = np.r_[-bounds_u, np.full(2 * FOOT_ROWS, -INF)]
        self.sense = np.zeros(12 + 2 * FOOT_ROWS, dtype=np.int32)
        self.iterations = 0
        self.seconds = 0.0

    def solve(self, G: np.ndarray, F_d: np.ndarray, state: int) -> tuple[np.ndarray, int]:
        """w (12,) and DAQP's exit flag (1: optimal)."""
        GW = G.T * self.W
        H = GW @ G
        H[np.diag_indices(12)] += self.eps
        start = time.perf_counter_ns()
        w, _, flag, info = daqp.solve(H, -(GW @ F_d), self.A, self.upper[state], self.lower[state], self.sense)
        self.seconds = (time.perf_counter_ns() - start) * 1e-9
        self.iterations = info["iterations"]
        return np.asarray(w), int(flag)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b of two 3-vectors (np.cross costs ten times more on single vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@dataclass
class CycleOut:
    """What one cycle decided, for the log (arrays owned by the controller: copy to keep)."""

    tau: np.ndarray          # (12,) N m
    zmp_cmd: np.ndarray      # (3,) p^c (after the clamp)
    wrench: np.ndarray       # (12,) QP foot wrenches [f τ]_l [f τ]_r, world axes, at the sole centres
    F_d: np.ndarray          # (6,) desired CoM wrench (eq. 53 + weight)
    F_opt: np.ndarray        # (6,) optimized CoM wrench (eq. 56)
    qp_flag: int
    qp_iterations: int


class WalkingController:
    """Sec. 6 on the controller's own MuJoCo model: `cycle(qpos, qvel, ref, i, state)` returns the joint torques
    for the measured state at cycle i of the pattern `ref`.

    The cycle is written for speed (about 60 NumPy calls): preallocated matrices filled in place, 3-vector algebra
    by hand, LAPACK called directly, the QP's constraint matrix and bounds built once per support state, the ZMP
    clamp only when p^c leaves the polygon."""

    def __init__(self, biped: Biped, c: Mapping[str, Any], omega: float, gravity: float, mu: float,
                 polygons: list):
        import mujoco
        from scipy.linalg.lapack import dgesv

        self.mj, self.gesv = mujoco, dgesv
        self.m = model = mujoco.MjModel.from_xml_string(biped.xml)
        self.d = mujoco.MjData(model)
        mass, foot_half, torque_limit = biped.mass, biped.foot_half, biped.torque_limit
        self.omega = omega
        self.cp_gain = 1 + float(c["cp_gain"]) / omega                    # eq. (50)
        self.mass = mass
        self.g = np.array([0.0, 0.0, -gravity])
        self.measured_ff = c["feedforward_com"] == "measured"
        self.clamp = bool(c["clamp_zmp"])
        self.hold_stance = c["stance_foot"] == "hold"
        self.polygons = polygons
        gains = Gains.from_config(c)
        self.kp = dict(vars(gains))
        self.kd = {k: 2 * np.sqrt(v) for k, v in vars(gains).items()}
        margin = float(c["polygon_margin"])
        self.qp = WrenchQP(mu, float(c["min_normal_force"]), foot_half[0] - margin, foot_half[1] - margin,
                           np.asarray(c["weights"], float), float(c["regularization"]))
        self.limit = torque_limit
        self.inv_dt = 1.0 / float(c["dt"])
        self.base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
        self.sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_sole") for s in ("l", "r")]
        nv = model.nv
        self.J = np.zeros((18, nv))           # rows: CoM, base rotation, left foot (lin, rot), right foot
        self.J_prev = np.zeros((18, nv))
        self.first = True
        self.anchor: list[np.ndarray | None] = [None, None]   # where each stance foot was planted
        self.model_seconds = 0.0
        self.M = np.zeros((nv, nv))
        self.G = np.zeros((6, 12))
        self.rhs = np.zeros(18)
        self.F_d = np.zeros(6)
        self.Rs = np.zeros((2, 3, 3))        # the sole rotations of the current cycle
        self.inertia = np.eye(3)
        self.inertia_inv = np.eye(3)

    def start(self, qpos: np.ndarray) -> None:
        """Fix I_c of eq. (53) at the initial pose."""
        self.d.qpos[:] = qpos
        self.mj.mj_forward(self.m, self.d)
        self.inertia = self.centroidal_inertia()
        self.inertia_inv = np.linalg.inv(self.inertia)

    def centroidal_inertia(self) -> np.ndarray:
        """Composite inertia of the whole robot about its CoM (I_c of eq. 53), at the current pose."""
        d, m = self.d, self.m
        com = d.subtree_com[self.base]
        inertia = np.zeros((3, 3))
        for b in range(self.base, m.nbody):
            R = d.ximat[b].reshape(3, 3)
            r = d.xipos[b] - com
            inertia += R @ np.diag(m.body_inertia[b]) @ R.T + m.body_mass[b] * (r @ r * np.eye(3) - np.outer(r, r))
        return inertia

    def cycle(self, qpos: np.ndarray, qvel: np.ndarray, ref, i: int, state: int) -> CycleOut:
        """The torques for the measured state (qpos, qvel) at cycle i of the pattern `ref`."""
        mj, m, d, J = self.mj, self.m, self.d, self.J
        kp, kd = self.kp, self.kd
        start = time.perf_counter_ns()
        d.qpos[:], d.qvel[:] = qpos, qvel
        mj.mj_fwdPosition(m, d)          # the controller's own model: kinematics, CoM, mass matrix
        mj.mj_fwdVelocity(m, d)          # bias forces
        self.model_seconds = (time.perf_counter_ns() - start) * 1e-9
        mj.mj_jacSubtreeCom(m, d, J[0:3], self.base)
        mj.mj_jacBody(m, d, None, J[3:6], self.base)
        mj.mj_jacSite(m, d, J[6:9], J[9:12], self.sites[0])
        mj.mj_jacSite(m, d, J[12:15], J[15:18], self.sites[1])
        rhs = self.rhs
        if self.first:                   # J̇q̇ by a backward difference over one cycle
            rhs[:] = 0.0
            self.first = False
        else:
            np.dot(self.J_prev - J, qvel * self.inv_dt, out=rhs)
        self.J_prev[:] = J
        v = J @ qvel
        com = d.subtree_com[self.base].copy()
        com_vel = v[0:3]
        xi = com + com_vel / self.omega
        # eqs. (49)-(51)
        p_c = ref.zmp[i] + self.cp_gain * (xi - ref.cp[i])
        if self.clamp:
            A, b = self.polygons[i]
            if (A @ p_c[:2] > b).any():
                p_c[:2] = clamp(p_c[:2], self.polygons[i])
        a_com = (self.omega**2 * ((com if self.measured_ff else ref.com[i]) - p_c)
                 + kp["com"] * (ref.com[i] - com) + kd["com"] * (ref.com_vel[i] - com_vel))
        # eq. (52): base orientation (upright), swing foot; a stance foot: zero acceleration
        R = d.xmat[self.base]
        w_base = v[3:6]
        dw_base = kp["base"] * orientation_error(R) - kd["base"] * w_base
        swing = -1 if state == DOUBLE else (1 if state == LEFT else 0)
        for f in (0, 1):                 # eq. (52) for both feet; a stance foot holds where it was planted
            site, r0 = self.sites[f], 6 + 6 * f
            if f != swing and not self.hold_stance:
                continue                 # the stance foot's acceleration: zero
            if f == swing:
                self.anchor[f] = None
                target = ref.feet[f, i]
            elif self.anchor[f] is None:
                target = self.anchor[f] = d.site_xpos[site].copy()
            else:
                target = self.anchor[f]
            e = np.concatenate([target - d.site_xpos[site], orientation_error(d.site_xmat[site])])
            ev = -v[r0:r0 + 6]
            if f == swing:
                ev[:3] += ref.feet_vel[f, i]
                rhs[r0:r0 + 3] += ref.feet_acc[f, i]
            rhs[r0:r0 + 6] += kp["foot"] * e + kd["foot"] * ev
        # eq. (53), with the weight
        inertia = self.inertia
        gyro = cross(w_base, inertia @ w_base)
        F_d = self.F_d
        F_d[:3] = self.mass * (a_com - self.g)
        F_d[3:] = inertia @ dw_base + gyro
        # eqs. (54)-(56)
        G = self.G
        xmat = d.site_xmat
        self.Rs = xmat[self.sites].reshape(2, 3, 3)
        for f, site in enumerate(self.sites):
            Rf = self.Rs[f]
            r = d.site_xpos[site] - com
            G[0:3, 6 * f:6 * f + 3] = Rf
            G[3:6, 6 * f + 3:6 * f + 6] = Rf
            G[3:6, 6 * f:6 * f + 3] = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]]) @ Rf
        w_local, flag = self.qp.solve(G, F_d, state)
        F_opt = G @ w_local
        # the foot wrenches in world axes: each foot's [f τ] turned by its sole rotation
        wrench = (self.Rs[:, None] @ w_local.reshape(2, 2, 3, 1)).reshape(12)
        # the optimized CoM accelerations, then eq. (57): J q̈ = a − J̇q̇
        rhs[0:3] += F_opt[:3] / self.mass + self.g
        rhs[3:6] += self.inertia_inv @ (F_opt[3:] - gyro)
        qacc = self.gesv(J, rhs)[2]      # LAPACK directly: np.linalg.solve's checks cost as much as the solve
        # eq. (58): τ = (M q̈ + h − J_lᵀ W_l − J_rᵀ W_r) on the actuated rows
        mj.mj_fullM(m, d, self.M)
        tau = (self.M[6:] @ qacc + d.qfrc_bias[6:] - wrench @ J[6:, 6:])
        np.minimum(tau, self.limit, out=tau)
        np.maximum(tau, -self.limit, out=tau)
        return CycleOut(tau, p_c, wrench, F_d, F_opt, flag, self.qp.iterations)

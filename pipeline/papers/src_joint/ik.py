"""Inverse kinematics of the SRC joint manipulator (Sec. III-B) and the obstacle-avoiding QP of Sec. V-C.

- `dls`: adaptive damped least squares, eqs. (39)-(44).
- `reference_twist`: closed-loop end-effector references, eqs. (45)-(47), set points (ṙ^d = ω^d = 0).
- `solve_ik`: "joint reference velocity integration using the SRC joint model" until the pose is reached.
- `DamperQP`: velocity dampers [34] as inequality constraints on the joint velocities, solved as the
  two-level hierarchy of [35] (inequalities first, then the pose task in the least-squares sense), with
  CasADi's qpOASES.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from dataclasses import dataclass

import numpy as np

from pipeline.papers.src_joint.model import Chain, quaternion_error


@dataclass(frozen=True)
class IkGains:
    xi: float           # size of the singular region, eq. (44)
    lambda_max: float   # largest damping, eq. (44)
    kp: float           # K_p = kp I_3, eq. (45)
    ka: float           # K_a = ka I_3, eq. (46)


def dls(J: np.ndarray, twist: np.ndarray, xi: float, lambda_max: float) -> tuple[np.ndarray, float]:
    """(ω, σ_min): ω = V Σ* Uᵀ ẋ with σ*_k = σ_k / (σ_k² + λ²), eqs. (42)-(43).

    λ² = 0 if σ_min(6,2n) ≥ ξ, else (1 − (σ_min/ξ)²) λ_max², eq. (44). The paper writes σ_r (smallest
    positive σ) in the second branch; σ_min is the same for a full-rank J and keeps λ² ≥ 0 otherwise."""
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    sigma_min = s[-1]
    lam2 = 0.0 if sigma_min >= xi else (1.0 - (sigma_min / xi) ** 2) * lambda_max ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(s > 0.0, s / (s * s + lam2), 0.0)
    return Vt.T @ (inv * (U.T @ twist)), float(sigma_min)


def pose_error(position: np.ndarray, q: np.ndarray, r_desired: np.ndarray,
               q_desired: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(r^d − r, δ of eq. 47), with q signed so that q · q^d ≥ 0."""
    return r_desired - position, quaternion_error(q if q @ q_desired >= 0 else -q, q_desired)


def reference_twist(e_p: np.ndarray, delta: np.ndarray, g: IkGains) -> np.ndarray:
    """[v^r; ω^r] for a set point (ṙ^d = ω^d = 0), eqs. (45)-(46)."""
    return np.concatenate([g.kp * e_p, g.ka * delta])


@dataclass
class IkResult:
    chain: Chain                 # the model at the solution: q^r_i, and q^r_{i-1,2} for the position planner
    times: np.ndarray            # (k,) s of IK integration
    joint_velocity: np.ndarray   # (k, 2n)
    position_error: np.ndarray   # (k, 3) m
    orientation_error: np.ndarray  # (k, 3) δ of eq. (47)
    sigma_min: np.ndarray        # (k,)
    seconds: np.ndarray          # (k,) wall time of each FK + Jacobian + SVD-DLS iteration
    converged: bool


def solve_ik(chain: Chain, r_desired: np.ndarray, q_desired: np.ndarray, g: IkGains, dt: float,
             duration: float, tol_position: float, tol_orientation: float, stall_time: float = np.inf,
             stall_change: float = 0.0) -> IkResult:
    """Integrate the DLS joint velocities through the joint model until the pose error is below tolerance,
    or has changed by less than `stall_change` (relative) over `stall_time` of IK time (an unreachable
    pose), or `duration` of IK time has passed. `chain` is advanced in place and returned in the result."""
    steps = round(duration / dt)
    window = round(stall_time / dt) if np.isfinite(stall_time) else steps + 1
    n2 = 2 * chain.n
    w_log, ep_log, eo_log = np.zeros((steps + 1, n2)), np.zeros((steps + 1, 3)), np.zeros((steps + 1, 3))
    sig, secs, norms = np.zeros(steps + 1), np.zeros(steps + 1), np.zeros((steps + 1, 2))
    converged = False
    k = 0
    for k in range(steps + 1):
        start = time.perf_counter()
        Jv, Jw, pos, _ = chain.jacobians()
        e_p, delta = pose_error(pos[-1], chain.orientation(), r_desired, q_desired)
        w, sig[k] = dls(np.vstack([Jv[-1], Jw[-1]]), reference_twist(e_p, delta, g), g.xi, g.lambda_max)
        secs[k] = time.perf_counter() - start
        w_log[k], ep_log[k], eo_log[k] = w, e_p, delta
        norms[k] = np.linalg.norm(e_p), np.linalg.norm(delta)
        if norms[k, 0] < tol_position and norms[k, 1] < tol_orientation:
            converged = True
            break
        if k >= window and (np.abs(norms[k] - norms[k - window]) <= stall_change * norms[k]).all():
            break
        if k < steps:
            chain.move(w.reshape(chain.n, 2), dt)
    end = k + 1
    return IkResult(chain, np.arange(end) * dt, w_log[:end], ep_log[:end], eo_log[:end], sig[:end], secs[:end],
                    converged)


# -- obstacles and the velocity-damper QP (Sec. V-C) ------------------------------------------------------


@contextlib.contextmanager
def _stdout_silenced():
    """File descriptor 1 to /dev/null: silences what C++ libraries print."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)


@dataclass(frozen=True)
class Bars:
    """Straight bars (infinite cylinders) through `points` (m, 3) along unit `axis`, radius `radius`."""

    points: np.ndarray
    axis: np.ndarray
    radius: float

    def clearance(self, centres: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(d (k, m), n̂ (k, m, 3)): surface distance of k spheres to m bars and the unit normal from the
        bar axis to each sphere centre. A sphere's closest point always lies on that normal."""
        rel = centres[:, None, :] - self.points[None, :, :]
        radial = rel - (rel @ self.axis)[..., None] * self.axis
        dist = np.linalg.norm(radial, axis=-1)
        return dist - radii[:, None] - self.radius, radial / dist[..., None]


@dataclass(frozen=True)
class Damper:
    safety: float      # d_s (m): the clearance never to go below (paper: 0.01 m)
    influence: float   # d_i (m): constraints act below this clearance
    gain: float        # ξ_d (1/s)
    regularization: float  # μ, weight of ‖ω‖² in the pose task


class DamperQP:
    """Joint velocities of the pose task under velocity dampers [34], as a two-level hierarchy [35].

    Level 1 (inequalities): min ‖s‖² s.t. −n̂ᵀ J_{B_j v} ω ≤ ξ_d (d − d_s)/(d_i − d_s) + s, for every
    (link j, bar) closer than d_i. Level 2 (pose): min ‖J ω − ẋ^r‖² + μ‖ω‖² s.t. the same rows with s*.
    ω = 0 satisfies every row while d ≥ d_s, so level 1 is solved only when some clearance is below d_s."""

    def __init__(self, n_vars: int, n_rows: int, damper: Damper):
        import casadi

        self.damper, self.n_vars, self.n_rows = damper, n_vars, n_rows
        opts = {"printLevel": "none", "error_on_fail": False}
        n_all = n_vars + n_rows
        with _stdout_silenced():  # qpOASES prints its licence banner on stdout when the plugin loads
            self._pose = casadi.conic("pose", "qpoases", {"h": casadi.Sparsity.dense(n_vars, n_vars),
                                                          "a": casadi.Sparsity.dense(n_rows, n_vars)}, opts)
            self._slack = casadi.conic("slack", "qpoases", {"h": casadi.Sparsity.dense(n_all, n_all),
                                                            "a": casadi.Sparsity.dense(n_rows, n_all)}, opts)

    def rows(self, Jv_links: np.ndarray, clearance: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(A, b) of the damper rows A ω ≤ b; rows farther than d_i get b = +inf."""
        d = self.damper
        A = -np.einsum("kmi,kij->kmj", normals, Jv_links).reshape(self.n_rows, -1)
        b = (d.gain * (clearance - d.safety) / (d.influence - d.safety)).reshape(-1)
        return A, np.where(clearance.reshape(-1) < d.influence, b, np.inf)

    def solve(self, J: np.ndarray, twist: np.ndarray, A: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
        """(ω, largest level-1 slack)."""
        slack = np.zeros(self.n_rows)
        if (b < 0).any():
            eye = np.eye(self.n_rows)
            H = np.block([[self.damper.regularization * np.eye(self.n_vars), np.zeros((self.n_vars, self.n_rows))],
                          [np.zeros((self.n_rows, self.n_vars)), eye]])
            sol = self._slack(h=H, g=np.zeros(self.n_vars + self.n_rows), a=np.hstack([A, -eye]),
                              lba=-np.inf, uba=b)
            slack = np.maximum(np.asarray(sol["x"]).ravel()[self.n_vars:], 0.0)
        H = J.T @ J + self.damper.regularization * np.eye(self.n_vars)
        sol = self._pose(h=H, g=-J.T @ twist, a=A, lba=-np.inf, uba=b + slack)
        return np.asarray(sol["x"]).ravel(), float(slack.max())


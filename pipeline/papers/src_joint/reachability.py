"""Which end-effector poses a chain of equal SRC joints can reach at all, and how close it comes to the others:
the floor under Sec. V-B's targets A and B.

For equal spheres (l_{i-1} = l_i, k_A = 1) a joint rolled from identity has the model state q_{i,1} = exp(r),
q_{i-1,2} = exp(−r) for a rotation vector r in P_i (eqs. 2, 5), so its rotation is q_i = exp(2r) (eq. 6) and
its contact normal in B_{i-1} is R(exp(r)) e_z (eqs. 7, 10). The two joint-update modes differ only in which r
can occur:

    incremental (eq. 5 per step = exact rolling)   r in the tangent plane, r_z = 0: two equal spheres rolling
                                                   without spin are mirror images (the rolling constraint is
                                                   integrable), 2 DOF per joint, and ε_z of q_i is 0
    global (eq. 5 on the displacement since t_0)   any r: rolling round a loop leaves a twist about the normal
                                                   (ε_z ≠ 0), 3 DOF per joint

`fk` is that closed form, batched over configurations; `floor` minimises a weighted pose error over it from
many starts at once (Levenberg-Marquardt with forward-difference Jacobians, every start in one array).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.src_joint.model import qexp
from pipeline.papers.src_joint.rolling import exp_so3

MODES = ("incremental", "global")   # ModelForm.joint_update
READINGS = ("printed", "scalar-last", "conjugate")   # how Table II's quaternion [η, ε] may be read


def rotvecs(x: np.ndarray, mode: str, n: int) -> np.ndarray:
    """Per-joint rotation vectors r (K, n, 3) from optimisation variables x (K, 2n or 3n)."""
    if mode == "incremental":
        r = np.zeros((x.shape[0], n, 3))
        r[..., :2] = x.reshape(-1, n, 2)
        return r
    return x.reshape(-1, n, 3)


def fk(r: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(positions (K, n+1, 3), rotations (K, n+1, 3, 3)) of B_0 … B_n of equal-sphere chains with joint rotation
    vectors r (K, n, 3): B_i's centre 2l along R(exp(r_i)) e_z from B_{i-1}'s, its frame turned by exp(2 r_i)."""
    k, n = r.shape[:2]
    normal = exp_so3(r)[..., :, 2]
    turn = exp_so3(2 * r)
    pos = np.zeros((k, n + 1, 3))
    rot = np.empty((k, n + 1, 3, 3))
    rot[:, 0] = np.eye(3)
    for i in range(n):
        pos[:, i + 1] = pos[:, i] + 2 * radius * np.einsum("kij,kj->ki", rot[:, i], normal[:, i])
        rot[:, i + 1] = rot[:, i] @ turn[:, i]
    return pos, rot


def model_state(r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q_{i,1}, q_{i-1,2}) of one configuration r (n, 3): the paper's variables, for its Chain."""
    return qexp(r), qexp(-r)


def read_quaternion(q: np.ndarray, reading: str) -> np.ndarray:
    """A target quaternion printed as [η, ε], read as printed, with the scalar last, or conjugated."""
    q = np.asarray(q, dtype=float) / np.linalg.norm(q)
    if reading == "printed":
        return q
    if reading == "scalar-last":
        return np.roll(q, 1)
    if reading == "conjugate":
        return q * np.array([1.0, -1.0, -1.0, -1.0])
    raise ValueError(f"reading={reading!r}: one of {READINGS}")


def rotation_error(R: np.ndarray, R_desired: np.ndarray) -> np.ndarray:
    """Rotation vectors (K, 3) of R_d Rᵀ (rad): zero when the orientation is reached."""
    E = R_desired @ np.swapaxes(R, -1, -2)
    cos = np.clip((np.trace(E, axis1=-2, axis2=-1) - 1) / 2, -1.0, 1.0)
    angle = np.arccos(cos)
    axis = np.stack([E[:, 2, 1] - E[:, 1, 2], E[:, 0, 2] - E[:, 2, 0], E[:, 1, 0] - E[:, 0, 1]], -1)
    sin = np.sin(angle)
    return axis * np.where(sin > 1e-9, angle / (2 * np.where(sin > 1e-9, sin, 1.0)), 0.5)[:, None]


@dataclass(frozen=True)
class Floor:
    """The best configuration a search found for one weighting: its pose errors and joint rotation vectors."""

    weight: float             # m per rad of orientation error in the cost
    position_error: float     # m
    orientation_error: float  # rad
    rotvecs: np.ndarray       # (n, 3)


def floors(r_desired: np.ndarray, R_desired: np.ndarray, radius: float, n: int, mode: str, weights, starts: int,
           iterations: int, rng: np.random.Generator) -> list[Floor]:
    """Minimise ‖e_p‖² + (w ‖e_R‖)² (m, rad) over the configurations `mode` allows, for each weight w in
    increasing order, every one from the solutions of the one before (a continuation from "position first"
    to "orientation first", which escapes the local minima a large weight alone falls into), from `starts`
    random starts (joint angles up to π/2) and `iterations` Levenberg-Marquardt steps per weight."""
    d = (2 if mode == "incremental" else 3) * n
    x = rng.uniform(-np.pi / 2, np.pi / 2, (starts, d))
    out = []
    for weight in weights:
        def residual(x: np.ndarray, weight=weight) -> np.ndarray:
            pos, rot = fk(rotvecs(x, mode, n), radius)
            return np.concatenate([r_desired - pos[:, -1], weight * rotation_error(rot[:, -1], R_desired)], axis=-1)

        x, res = _levenberg_marquardt(residual, x, iterations)
        best = int(np.argmin(np.sum(res ** 2, axis=-1)))
        out.append(Floor(float(weight), float(np.linalg.norm(res[best, :3])),
                         float(np.linalg.norm(res[best, 3:]) / weight), rotvecs(x[best:best + 1], mode, n)[0]))
    return out


def _levenberg_marquardt(residual, x: np.ndarray, iterations: int, step: float = 1e-7) -> tuple[np.ndarray, np.ndarray]:
    """Levenberg-Marquardt on every row of x at once (forward-difference Jacobians, one batched residual call
    per iteration); returns the final x and residuals."""
    starts, d = x.shape
    mu = np.full(starts, 1e-3)
    res = residual(x)
    cost = np.sum(res ** 2, axis=-1)
    for _ in range(iterations):
        probes = x[:, None, :] + step * np.eye(d)[None]
        J = (residual(probes.reshape(-1, d)).reshape(starts, d, -1) - res[:, None, :]) / step   # (K, d, 6)
        JtJ = J @ np.swapaxes(J, -1, -2)
        scale = np.eye(d) * (1.0 + np.diagonal(JtJ, axis1=-2, axis2=-1))[:, :, None]
        trial = x - np.linalg.solve(JtJ + mu[:, None, None] * scale, J @ res[..., None])[..., 0]
        trial_res = residual(trial)
        trial_cost = np.sum(trial_res ** 2, axis=-1)
        better = trial_cost < cost
        x = np.where(better[:, None], trial, x)
        res = np.where(better[:, None], trial_res, res)
        cost = np.where(better, trial_cost, cost)
        mu = np.clip(np.where(better, mu / 3, mu * 4), 1e-12, 1e8)
    return x, res

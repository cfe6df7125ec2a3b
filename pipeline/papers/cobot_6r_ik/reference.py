"""The independent reference for completeness (spec §7–8): multi-start damped least squares on the flange
pose from random joint vectors, converged solutions de-duplicated. It shares only FK with the algebraic
solver (checked against MuJoCo in the tests), nothing of the polynomial elimination."""

from __future__ import annotations

import numba
import numpy as np

from pipeline.papers.cobot_6r_ik import ik
from pipeline.papers.cobot_6r_ik.kinematics import CRX10IAL, Geometry

MAX_FOUND = 32


@numba.njit(cache=True)
def _multistart(T: np.ndarray, geo: np.ndarray, starts: np.ndarray, iterations: int, tol: float, duplicate: float,
                out: np.ndarray) -> int:
    J = np.empty((6, 6))
    e = np.empty(6)
    work = np.empty((4, 4))
    q = np.empty(6)
    found = 0
    for s in range(starts.shape[0]):
        q[:] = starts[s]
        mu = 1e-3
        err = 1e9
        for _ in range(iterations):
            ik.pose_residual(q, geo, T, J, e)
            err = np.sqrt(np.sum(e * e))
            if err < tol:
                break
            A = J.T @ J
            for i in range(6):
                A[i, i] += mu
            step = np.linalg.solve(A, J.T @ e)
            q_new = q + step
            ik.pose_residual(q_new, geo, T, J, e)
            if np.sqrt(np.sum(e * e)) < err:
                q[:] = q_new
                mu = max(mu * 0.3, 1e-12)
            else:
                mu *= 10.0
        for j in range(6):
            q[j] = ik._wrap(q[j])
        ep, er = ik.polish_pose(q, geo, T, 3, 1e-12, 1e-12, work)
        if ep > 1e-9 or er > 1e-9:
            continue
        new = True
        for k in range(found):
            same = True
            for j in range(6):
                if abs(ik._wrap(out[k, j] - q[j])) >= duplicate:
                    same = False
                    break
            if same:
                new = False
                break
        if new and found < MAX_FOUND:
            out[found] = q
            found += 1
    return found


def multistart(T, starts: int, rng: np.random.Generator, g: Geometry = CRX10IAL, iterations: int = 60,
               duplicate: float = 1e-6) -> np.ndarray:
    """Distinct solutions of pose T found from `starts` uniform random joint vectors in (−π, π]^6: (k, 6)."""
    out = np.empty((MAX_FOUND, 6))
    q0 = rng.uniform(-np.pi, np.pi, (starts, 6))
    k = _multistart(np.ascontiguousarray(T, dtype=float), g.array, q0, iterations, 1e-10, duplicate, out)
    return out[:k].copy()

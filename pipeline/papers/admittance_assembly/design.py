"""Admittance selection (ours, spec §6): an A that satisfies condition (2) at the corner configurations of
the two-point contact state with the largest worst-case margin, found by SLSQP; and random admittances for
testing the abstract's claim on many A.

A is symmetric positive definite (assumption: the paper's fragment does not say). It is searched in units
scaled by the peg length ℓ, A = a_t·S·Â·S with S = diag(1 for translations, 1/ℓ for rotations), so that a
lateral force and the moment ℓ·force produce motions of one size. Condition (2) does not depend on the
scale of A (λ scales by 1/k when A scales by k, so v = v0 + AWλ is unchanged), so Â is normalised to
trace n, with every eigenvalue ≥ `min_eigenvalue` (a realisable, finite damping in every direction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from pipeline.papers.admittance_assembly import geometry, quasistatic
from pipeline.papers.admittance_assembly.geometry import PegInHole


@dataclass(frozen=True)
class StateSamples:
    """Configurations of the two-point state and what condition (2) needs at each: W (N, n, 2),
    d (N, n), v0 (N, n), ‖δ‖ (N,), and whether the configuration is geometrically valid."""

    coords: np.ndarray
    W: np.ndarray
    d: np.ndarray
    v0: np.ndarray
    error: np.ndarray
    valid: np.ndarray

    def margin(self, A: np.ndarray, speed: float, contacts: slice = slice(None)) -> np.ndarray:
        """-dᵀv / (‖δ‖·speed): the closing rate of the error as a fraction of the nominal speed (> 0 when
        (2) holds). `contacts` keeps some of the two contacts (a single-PC model of the same configuration)."""
        _, _, v = quasistatic.contact_response(A, self.W[..., contacts], self.v0)
        return quasistatic.closing_rate(self.d, v, self.error) / speed


def state_samples(g: PegInHole, coords: np.ndarray, speed: float, gap_tol: float = 1e-9) -> StateSamples:
    """Chart coordinates -> the data of condition (2). A configuration is valid when both designated
    contacts lie on their features and no other candidate penetrates by more than `gap_tol`."""
    R, p, clearance = geometry.chart_poses(g, coords)
    c = geometry.contacts(g, R, p, clearance)
    pair = list(geometry.designated_pair(g))
    W = geometry.unit_wrenches(g, R, p, c.point[:, pair], c.normal[:, pair])
    others = np.delete(np.arange(len(c.names)), pair)
    valid = c.valid[:, pair].all(axis=1) & ~((c.gap[:, others] < -gap_tol) & c.valid[:, others]).any(axis=1)
    return StateSamples(np.atleast_2d(coords), W, geometry.line_vector(g, R, p), geometry.nominal_twist(g, R, speed),
                        np.linalg.norm(geometry.error_vector(g, R, p), axis=1), valid)


def scaling(g: PegInHole) -> np.ndarray:
    """Diagonal of S for the case's dofs."""
    return np.where(geometry.TRANSLATION[g.dofs], 1.0, 1.0 / g.length)


def physical(g: PegInHole, A_hat: np.ndarray, translational: float) -> np.ndarray:
    """A = a_t·S·Â·S (SI: m/(N·s), rad/(N·m·s) and the couplings)."""
    s = scaling(g)
    return translational * s[:, None] * A_hat * s[None, :]


def normalised(L: np.ndarray, min_eigenvalue: float) -> np.ndarray:
    """Â = (1 - κ)·n·LLᵀ/tr(LLᵀ) + κ·I: trace n, eigenvalues ≥ κ."""
    n = L.shape[-1]
    P = L @ np.swapaxes(L, -1, -2)
    trace = np.trace(P, axis1=-2, axis2=-1)[..., None, None]
    return (1.0 - min_eigenvalue) * n * P / trace + min_eigenvalue * np.eye(n)


@dataclass(frozen=True)
class Design:
    A_hat: np.ndarray
    corner_margin: float      # worst margin over the corners (> 0: (2) holds at every corner)
    starts: int
    iterations: int


def design_admittance(g: PegInHole, corners: StateSamples, speed: float, *, min_eigenvalue: float, restarts: int,
                      seed: int, max_iterations: int = 200) -> Design:
    """Maximise t subject to margin_k(Â) ≥ t at every corner k (SLSQP on the Cholesky-like factor L, from the
    scaled identity and `restarts` random starts); the best local optimum wins."""
    n = g.n
    rng = np.random.default_rng(seed)
    tril = np.tril_indices(n)
    ones = np.eye(n)[tril]
    starts = [ones] + [rng.standard_normal(len(ones)) for _ in range(restarts)]
    step = 1e-6

    def margins(X: np.ndarray) -> np.ndarray:
        """(P, corners) margins of the admittances of P parameter vectors, in one batched solve."""
        L = np.zeros((len(X), n, n))
        L[:, tril[0], tril[1]] = X
        A = physical(g, normalised(L, min_eigenvalue), 1.0)
        return corners.margin(A[:, None], speed)

    def constraint(z: np.ndarray) -> np.ndarray:
        return margins(z[None, :-1])[0] - z[-1]

    def constraint_jacobian(z: np.ndarray) -> np.ndarray:
        x = z[:-1]
        m = margins(np.vstack([x, x + step * np.eye(len(x))]))  # forward differences, one call
        return np.column_stack([((m[1:] - m[0]) / step).T, -np.ones(m.shape[1])])

    best, iterations = None, 0
    for x0 in starts:
        z0 = np.r_[x0, margins(x0[None])[0].min()]
        result = minimize(lambda z: -z[-1], z0, method="SLSQP", jac=lambda z: -np.eye(len(z))[-1],
                          constraints=[{"type": "ineq", "fun": constraint, "jac": constraint_jacobian}],
                          options={"maxiter": max_iterations, "ftol": 1e-10})
        iterations += result.nit
        worst = float(margins(result.x[None, :-1])[0].min())
        if best is None or worst > best[1]:
            best = (result.x[:-1], worst)
    L = np.zeros((n, n))
    L[tril] = best[0]
    return Design(normalised(L, min_eigenvalue), best[1], len(starts), iterations)


def random_admittances(n: int, count: int, min_eigenvalue: float, rng: np.random.Generator) -> np.ndarray:
    """(count, n, n) scaled admittances Â = normalised(G) for G with standard normal entries: a Wishart
    distribution of directions, every one positive definite."""
    return normalised(rng.standard_normal((count, n, n)), min_eigenvalue)

"""Frictionless quasi-static contact under the admittance law (1) and the error-reduction condition (2).

With contact wrench w = W λ (W: unit wrenches as columns, λ ≥ 0 the normal force magnitudes), the law
v = v0 + A w makes the gap rates ġ = Wᵀv = Wᵀv0 + (WᵀAW) λ. Rigid frictionless contact is the linear
complementarity problem ġ ≥ 0, λ ≥ 0, λᵀġ = 0 (spec §3), unique in λ when WᵀAW ≻ 0 (A symmetric
positive definite, W of full column rank). One or two contacts (the condition checks, batched) are solved in
closed form over the active sets {}, {1}, {2}, {1, 2}; more (during an insertion) as a convex QP.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

REGULARISATION = 1e-12


def solve_lcp(M: np.ndarray, q: np.ndarray) -> np.ndarray:
    """λ (..., k) with λ ≥ 0, Mλ + q ≥ 0, λᵀ(Mλ + q) = 0 for M (..., k, k) symmetric positive semidefinite."""
    M, q = np.asarray(M, float), np.asarray(q, float)
    batch = np.broadcast_shapes(M.shape[:-2], q.shape[:-1])
    k = q.shape[-1]
    M, q = np.broadcast_to(M, (*batch, k, k)), np.broadcast_to(q, (*batch, k))
    if k <= 2:
        return _solve_lcp_small(M, q)
    lam = np.empty((*batch, k))
    for i in np.ndindex(batch):
        lam[i] = _solve_lcp_nnls(M[i], q[i])
    return lam


def _solve_lcp_nnls(M: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The LCP as the convex QP min ½λᵀMλ + qᵀλ, λ ≥ 0, written as non-negative least squares with
    M + εI = LLᵀ: ½‖Lᵀλ + L⁻¹q‖² differs by a constant. ε (1e-12 of the largest diagonal) makes a degenerate
    W (more contacts than independent constraints, e.g. a face on a wall) pick one force split; the motion
    v = v0 + AWλ is the same for every split."""
    eps = REGULARISATION * max(float(np.max(np.diag(M))), 1e-300)
    M_reg = 0.5 * (M + M.T) + eps * np.eye(len(q))
    L = np.linalg.cholesky(M_reg)
    lam = nnls(L.T, -np.linalg.solve(L, q))[0]
    active = lam > 0
    sub = M[np.ix_(active, active)]
    if active.any() and np.linalg.cond(sub) < 1e12:
        # polish on NNLS's active set: complementarity to round-off rather than to NNLS's tolerance and ε
        exact = np.linalg.solve(sub, -q[active])
        if (exact >= 0).all():
            lam[active] = exact
    return lam


def _solve_lcp_small(M: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Closed form for one or two contacts (the batched hot path of the condition checks)."""
    if q.shape[-1] == 0:
        return np.zeros(q.shape)
    if q.shape[-1] == 1:
        return np.maximum(-q / M[..., 0], 0.0)
    m11, m12, m21, m22 = M[..., 0, 0], M[..., 0, 1], M[..., 1, 0], M[..., 1, 1]
    q1, q2 = q[..., 0], q[..., 1]
    det = m11 * m22 - m12 * m21
    with np.errstate(divide="ignore", invalid="ignore"):
        both = np.stack([(m12 * q2 - m22 * q1) / det, (m21 * q1 - m11 * q2) / det], -1)
        only1, only2 = np.maximum(-q1 / m11, 0.0), np.maximum(-q2 / m22, 0.0)
    lam = np.zeros(q.shape)
    # {1}: contact 2 must not be pulled into penetration; {2} likewise; else both (λ ≥ 0 when M ≻ 0)
    ok1 = (only1 > 0) & (q2 + m21 * only1 >= 0)
    ok2 = ~ok1 & (only2 > 0) & (q1 + m12 * only2 >= 0)
    need_both = ~ok1 & ~ok2 & ((q1 < 0) | (q2 < 0))
    lam[..., 0] = np.where(ok1, only1, 0.0)
    lam[..., 1] = np.where(ok2, only2, 0.0)
    lam[need_both] = np.maximum(both[need_both], 0.0)
    return lam


def contact_response(A: np.ndarray, W: np.ndarray, v0: np.ndarray, bias: np.ndarray | None = None):
    """Quasi-static response at configurations (W (..., n, k), v0 (..., n)) under admittance A (n, n) or
    (..., n, n): (λ (..., k), w = Wλ (..., n), v = v0 + A w (..., n)) — eq. (1). `bias` (..., k) is added to
    the gap rates (time stepping: gap/dt, so that no gap closes past zero in one step)."""
    AW = np.einsum("...ij,...jk->...ik", A, W)
    M = np.einsum("...ji,...jk->...ik", W, AW)
    q = np.einsum("...ji,...j->...i", W, v0)
    if bias is not None:
        q = q + bias
    lam = solve_lcp(M, q)
    w = np.einsum("...ik,...k->...i", W, lam)
    v = v0 + np.einsum("...ij,...j->...i", A, w)
    return lam, w, v


def closing_rate(d: np.ndarray, v: np.ndarray, error_norm: np.ndarray) -> np.ndarray:
    """-dᵀv / ‖δ‖ = -d‖δ‖/dt (m/s): positive when the motion reduces the misalignment, eq. (2)."""
    return -np.einsum("...i,...i->...", d, v) / error_norm


def reduces_error(d: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Condition (2): dᵀv < 0."""
    return np.einsum("...i,...i->...", d, v) < 0.0

"""Quasi-static insertion (spec §6): the peg moves with v = v0 + A·w, w the frictionless contact wrench of
the complementarity problem at each step, contacts re-detected from the geometry every step.

Time stepping: a candidate within `active_gap` of contact enters the problem with its gap as a bias on the
gap rate (ġ + gap/dt ≥ 0): no gap closes past zero in one step, and drift out of contact is corrected.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.core.runlog import SimulationFailed
from pipeline.papers.admittance_assembly import geometry, quasistatic
from pipeline.papers.admittance_assembly.geometry import PegInHole


@dataclass
class Trajectory:
    """Samples at t (N,): pose R (N,3,3), p (N,3); body twist v (N,n); contact wrench w (N,n) in the body
    frame; every candidate's force λ (N,K) and gap (N,K); error δ (N,3); dᵀv (N,); how the run ended."""

    t: np.ndarray
    R: np.ndarray
    p: np.ndarray
    v: np.ndarray
    w: np.ndarray
    lam: np.ndarray
    gap: np.ndarray
    delta: np.ndarray
    d_dot_v: np.ndarray
    outcome: str


def predicted_response(g: PegInHole, A: np.ndarray, R: np.ndarray, p: np.ndarray, speed: float, active_gap: float,
                       dt: float | None = None, v0: np.ndarray | None = None):
    """Quasi-static response at one pose: (λ (K,), w (n,), v (n,), contacts). v0 is the nominal insertion
    twist at `speed` unless given (body frame). With dt, the gaps bias the gap rates (time stepping);
    without, the prediction is the rigid one at this configuration."""
    c = geometry.contacts(g, R, p)
    active = np.flatnonzero(c.valid[0] & (c.gap[0] < active_gap))
    W = geometry.unit_wrenches(g, R, p, c.point[:, active], c.normal[:, active])[0]
    if v0 is None:
        v0 = geometry.nominal_twist(g, R, speed)[0]
    bias = None if dt is None else c.gap[0, active] / dt
    lam_active, w, v = quasistatic.contact_response(A, W, v0, bias)
    lam = np.zeros(len(c.names))
    lam[active] = lam_active
    return lam, w, v, c


def insert(g: PegInHole, A: np.ndarray, R0: np.ndarray, p0: np.ndarray, *, speed: float, dt: float, duration: float,
           active_gap: float) -> Trajectory:
    """Run from pose (R0, p0) until the selected point reaches its mated depth ('inserted'), the tip leaves
    the hole ('left the hole') or `duration` passes ('timeout')."""
    steps = round(duration / dt)
    n, K = g.n, len(g.names)
    R_log, p_log = np.empty((steps + 1, 3, 3)), np.empty((steps + 1, 3))
    v_log, w_log = np.zeros((steps + 1, n)), np.zeros((steps + 1, n))
    lam_log, gap_log = np.zeros((steps + 1, K)), np.zeros((steps + 1, K))
    R, p = np.array(R0, float), np.array(p0, float)
    outcome, k = "timeout", 0
    for k in range(steps + 1):
        lam, w, v, c = predicted_response(g, A, R, p, speed, active_gap, dt)
        R_log[k], p_log[k], v_log[k], w_log[k], lam_log[k], gap_log[k] = R, p, v, w, lam, c.gap[0]
        if not np.isfinite(v).all():
            raise SimulationFailed(f"non-finite twist at t = {k * dt:.4g} s")
        if (R @ g.selected_point + p)[2] <= g.mated_point[2]:
            outcome = "inserted"
            break
        if (R @ np.array([0.0, 0.0, -g.ref_height]) + p)[2] > 0.0:
            outcome = "left the hole"
            break
        if k < steps:
            R, p = geometry.se3_step(R, p, geometry.full_twist(g, v), dt)
    end = k + 1
    R_log, p_log = R_log[:end], p_log[:end]
    delta = geometry.error_vector(g, R_log, p_log)
    d = geometry.line_vector(g, R_log, p_log)
    return Trajectory(np.arange(end) * dt, R_log, p_log, v_log[:end], w_log[:end], lam_log[:end], gap_log[:end],
                      delta, np.einsum("ni,ni->n", d, v_log[:end]), outcome)

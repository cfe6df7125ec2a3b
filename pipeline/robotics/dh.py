"""Denavit–Hartenberg kinematics, vectorized over any leading batch shape.

    standard (distal):         ^{i-1}T_i = Rz(θ_i + θ_offset_i) · Tz(d_i) · Tx(a_i) · Rx(α_i)
    modified (proximal, Craig): ^{i-1}T_i = Rx(α_{i-1}) · Tx(a_{i-1}) · Rz(θ_i) · Tz(d_i)   (link transform only)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DH:
    alpha: np.ndarray
    a: np.ndarray
    d: np.ndarray
    theta_offset: np.ndarray

    @classmethod
    def from_config(cls, table: Mapping) -> DH:
        """From a config node with equal-length lists `alpha`, `a`, `d` (and optional `theta_offset`)."""
        alpha, a, d = (np.asarray(table[k], dtype=float) for k in ("alpha", "a", "d"))
        offset = np.asarray(table.get("theta_offset") or np.zeros_like(a), dtype=float)
        if not (alpha.shape == a.shape == d.shape == offset.shape and alpha.ndim == 1):
            raise ValueError("DH table: alpha, a, d, theta_offset must be lists of equal length")
        return cls(alpha, a, d, offset)

    @property
    def n(self) -> int:
        return len(self.a)


def link_transforms(dh: DH, q: np.ndarray) -> np.ndarray:
    """(..., n, 4, 4): ^{i-1}T_i for every joint."""
    q = np.asarray(q, dtype=float)
    theta = q + dh.theta_offset
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(dh.alpha), np.sin(dh.alpha)
    ca, sa, a, d = (np.broadcast_to(x, theta.shape) for x in (ca, sa, dh.a, dh.d))
    T = np.zeros((*theta.shape, 4, 4))
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 2], T[..., 0, 3] = ct, -st * ca, st * sa, a * ct
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st, ct * ca, -ct * sa, a * st
    T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa, ca, d
    T[..., 3, 3] = 1.0
    return T


def frames(dh: DH, q: np.ndarray) -> np.ndarray:
    """(..., n+1, 4, 4): ^0T_i for i = 0 … n (frame 0 is the identity)."""
    # ^0T_i = ^0T_{i-1} · Rz(θ) Tz(d) Tx(a) Rx(α), applied to the columns (x, y, z, p) of ^0T_{i-1}:
    #   x' = c x + s y,  y' = cα (c y − s x) + sα z,  z' = cα z − sα (c y − s x),  p' = p + d z + a x'.
    # Columns are (3, N) rows of samples: a dozen array operations per joint, 2× faster than 4×4 matmuls.
    q = np.asarray(q, dtype=float)
    theta = np.ascontiguousarray((q + dh.theta_offset).reshape(-1, dh.n).T)
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(dh.alpha), np.sin(dh.alpha)
    out = np.empty((dh.n + 1, 4, 4, theta.shape[1]))  # frame, row, column, sample
    out[0] = np.eye(4)[..., None]
    out[1:, 3] = np.array([0.0, 0.0, 0.0, 1.0])[:, None]
    for i in range(dh.n):
        x, y, z, p = (out[i, :3, k] for k in range(4))
        x1, y1, z1, p1 = (out[i + 1, :3, k] for k in range(4))
        c, s = ct[i], st[i]
        np.multiply(x, c, out=x1)
        x1 += y * s
        turned = y * c
        turned -= x * s
        np.multiply(turned, ca[i], out=y1)
        y1 += z * sa[i]
        np.multiply(z, ca[i], out=z1)
        z1 -= turned * sa[i]
        np.multiply(x1, dh.a[i], out=p1)
        p1 += z * dh.d[i]
        p1 += p
    return np.moveaxis(out, -1, 0).reshape(*q.shape[:-1], dh.n + 1, 4, 4)


def fk(dh: DH, q: np.ndarray) -> np.ndarray:
    """(..., 4, 4): the last frame."""
    return frames(dh, q)[..., -1, :, :]


def geometric_jacobian(dh: DH, q: np.ndarray) -> np.ndarray:
    """(..., 6, n): [linear; angular] velocity of the last frame's origin, all joints revolute.

    Column i = [z_{i-1} × (p_e − p_{i-1}); z_{i-1}]."""
    F = frames(dh, q)
    z = F[..., :-1, :3, 2]
    p = F[..., :-1, :3, 3]
    p_e = F[..., -1:, :3, 3]
    J = np.concatenate([np.cross(z, p_e - p), z], axis=-1)  # (..., n, 6)
    return np.swapaxes(J, -1, -2)


def modified_link_transforms(alpha: np.ndarray, a: np.ndarray, d: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """(..., n, 4, 4): ^{i-1}T_i of a modified (proximal, Craig) DH table, broadcast over leading axes of `theta`.

        ^{i-1}T_i = Rx(α_{i-1}) · Tx(a_{i-1}) · Rz(θ_i) · Tz(d_i)

    Row i holds α_{i-1}, a_{i-1}, d_i and the full joint angle θ_i (offsets included)."""
    theta = np.asarray(theta, dtype=float)
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    ca, sa, a, d = (np.broadcast_to(np.asarray(x, dtype=float), theta.shape) for x in (ca, sa, a, d))
    T = np.zeros((*theta.shape, 4, 4))
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 3] = ct, -st, a
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st * ca, ct * ca, -sa, -sa * d
    T[..., 2, 0], T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = st * sa, ct * sa, ca, ca * d
    T[..., 3, 3] = 1.0
    return T

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
    # joint index first, every operand contiguous: NumPy's matmul over strided stacks is 2.5× slower
    links = np.ascontiguousarray(np.moveaxis(link_transforms(dh, q), -3, 0))
    out = np.empty((dh.n + 1, *links.shape[1:]))
    out[0] = np.eye(4)
    for i in range(dh.n):
        np.matmul(out[i], links[i], out=out[i + 1])
    return np.moveaxis(out, 0, -3)


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

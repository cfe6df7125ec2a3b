"""Rotation helpers shared by every paper (batched over leading axes)."""

from __future__ import annotations

import numpy as np


def rotation_angle(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Geodesic angle (rad) between rotation matrices, batched: atan2(sin, cos) of M = R_aᵀ R_b, with sin from
    M's skew part and cos from its trace, accurate near 0 and near π alike (the arccos of the trace alone gives
    2e-8 rad for matrices equal to round-off)."""
    M = np.swapaxes(R_a, -1, -2) @ R_b
    skew = np.stack([M[..., 2, 1] - M[..., 1, 2], M[..., 0, 2] - M[..., 2, 0], M[..., 1, 0] - M[..., 0, 1]], -1)
    cos = (np.trace(M, axis1=-2, axis2=-1) - 1.0) / 2.0
    return np.arctan2(np.linalg.norm(skew, axis=-1) / 2.0, cos)


def quaternion_wxyz(R: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z) of rotation matrices, batched.

    The numbers of SciPy's `Rotation.from_matrix(R).as_quat(scalar_first=True)`, bit for bit (a test holds
    them equal): the same Shepperd branch (the largest of the diagonal and the trace), the same sums in the
    same order, then the same normalization, in a few NumPy passes instead of SciPy's per-call overhead (a third
    of the time for a few thousand frames). Matrices that are not rotations to 1e-12, which SciPy projects onto
    the nearest rotation (or refuses), are left to SciPy."""
    R = np.asarray(R, dtype=float)
    m = R.reshape(-1, 3, 3)
    if not _rotations(m):
        from scipy.spatial.transform import Rotation  # deferred: SciPy costs every process 0.2 s to import

        return Rotation.from_matrix(m).as_quat(scalar_first=True).reshape(*R.shape[:-2], 4)
    d0, d1, d2 = m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]
    trace = d0 + d1 + d2
    branch = np.argmax(np.stack([d0, d1, d2, trace], axis=1), axis=1)
    q = np.empty((len(m), 4))  # x, y, z, w
    q[:, 0] = m[:, 2, 1] - m[:, 1, 2]
    q[:, 1] = m[:, 0, 2] - m[:, 2, 0]
    q[:, 2] = m[:, 1, 0] - m[:, 0, 1]
    q[:, 3] = 1 + trace
    for i in range(3):  # the largest diagonal entry is x, y or z's: build from that component
        rows = np.flatnonzero(branch == i)
        if len(rows):
            j, k = (i + 1) % 3, (i + 2) % 3
            s = m[rows]
            q[rows, i] = 1 - trace[rows] + 2 * s[:, i, i]
            q[rows, j] = s[:, j, i] + s[:, i, j]
            q[rows, k] = s[:, k, i] + s[:, i, k]
            q[rows, 3] = s[:, k, j] - s[:, j, k]
    q /= np.sqrt(q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] + q[:, 2] * q[:, 2] + q[:, 3] * q[:, 3])[:, None]
    return q[:, [3, 0, 1, 2]].reshape(*R.shape[:-2], 4)


def _rotations(m: np.ndarray) -> bool:
    """Whether every (3, 3) matrix of `m` (N, 3, 3) is a rotation as SciPy's from_matrix tests it: its Gram
    matrix within 1e-12 of the identity (np.isclose's tolerances), and a positive determinant."""
    (a, b, c), (d, e, f), (g, h, i) = (tuple(m[:, r, k] for k in range(3)) for r in range(3))
    off = np.abs(np.stack([a * d + b * e + c * f, a * g + b * h + c * i, d * g + e * h + f * i]))
    diagonal = np.abs(np.stack([a * a + b * b + c * c, d * d + e * e + f * f, g * g + h * h + i * i]) - 1)
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return bool((off <= 1e-12).all() and (diagonal <= 1e-12 + 1e-5).all() and (det > 0).all())

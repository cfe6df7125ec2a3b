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
    """(..., 4) unit quaternions (w, x, y, z) of rotation matrices, batched."""
    from scipy.spatial.transform import Rotation  # deferred: SciPy costs every process 0.2 s to import

    R = np.asarray(R, dtype=float)
    quat = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    return quat.reshape(*R.shape[:-2], 4)

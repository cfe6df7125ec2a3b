"""Rotation helpers shared by every paper (batched over leading axes)."""

from __future__ import annotations

import numpy as np


def rotation_angle(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """Geodesic angle (rad) between rotation matrices, batched."""
    cos = (np.trace(np.swapaxes(R_a, -1, -2) @ R_b, axis1=-2, axis2=-1) - 1.0) / 2.0
    return np.arccos(np.clip(cos, -1.0, 1.0))


def quaternion_wxyz(R: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z) of rotation matrices, batched."""
    from scipy.spatial.transform import Rotation  # deferred: SciPy costs every process 0.2 s to import

    R = np.asarray(R, dtype=float)
    quat = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    return quat.reshape(*R.shape[:-2], 4)

"""The regional structure of an arm: its first joints and the point of interest P_w (Sec. 1.3.1).

An arm is a standard-DH table (rows of the regional joints) plus the offset of P_w along the last z axis:
for a spherical wrist, P_w is the wrist centre, d4 along z3 (PUMA 560); for a planar 2R, P_w is the tip.
Everything is vectorised over a leading batch of configurations: the graph maps whole C-space grids.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from pipeline.robotics.dh import DH


@dataclass(frozen=True)
class RegionalArm:
    name: str
    dh: DH                  # the regional joints' rows
    wrist_offset: float     # m: P_w = ^0T_n · [0, 0, wrist_offset]
    lower: np.ndarray       # rad, joint limits
    upper: np.ndarray
    task_dims: int          # 2: planar (x, y) | 3: spatial
    link_radius: float      # m: capsule radius of every link (collision, drawing)

    @classmethod
    def from_config(cls, name: str, node: Mapping) -> RegionalArm:
        """From a `system.<arm>` node: `dh` (alpha, a, d[, theta_offset]), `wrist_offset`, `lower`, `upper`,
        `task_dims`, `link_radius`. Only the first `joints` rows are the regional structure."""
        n = int(node["joints"])
        table = {k: list(node["dh"][k])[:n] for k in ("alpha", "a", "d")}
        if node["dh"].get("theta_offset") is not None:
            table["theta_offset"] = list(node["dh"]["theta_offset"])[:n]
        lower, upper = (np.asarray(node[k], dtype=float)[:n] for k in ("lower", "upper"))
        if not (lower < upper).all():
            raise ValueError(f"{name}: every joint needs lower < upper, got {lower} and {upper}")
        return cls(name, DH.from_config(table), float(node["wrist_offset"]), lower, upper, int(node["task_dims"]),
                   float(node["link_radius"]))

    @property
    def n(self) -> int:
        return self.dh.n

    def _chain(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Origins (..., n + 2, 3) of DH frames 0..n and P_w, and z axes (..., n + 1, 3) of frames 0..n."""
        q = np.asarray(q, dtype=float)
        theta = q + self.dh.theta_offset
        ct, st = np.cos(theta)[..., None], np.sin(theta)[..., None]
        batch = q.shape[:-1]
        origins = np.zeros((*batch, self.n + 2, 3))
        axes = np.zeros((*batch, self.n + 1, 3))
        # the columns x, y, z of the running rotation
        x, y, z = (np.broadcast_to(np.eye(3)[k], (*batch, 3)) for k in range(3))
        axes[..., 0, :] = z
        for i in range(self.n):
            a, d, ca, sa = self.dh.a[i], self.dh.d[i], np.cos(self.dh.alpha[i]), np.sin(self.dh.alpha[i])
            c, s = ct[..., i, :], st[..., i, :]
            # ^{i-1}T_i = Rz(θ) Tz(d) Tx(a) Rx(α): the origin moves by a·(c x + s y) + d z; the new axes are
            # x' = c x + s y, y' = ca (−s x + c y) + sa z, z' = −sa (−s x + c y) + ca z
            turned = c * x + s * y
            normal = c * y - s * x
            origins[..., i + 1, :] = origins[..., i, :] + a * turned + d * z
            x, y, z = turned, ca * normal + sa * z, ca * z - sa * normal
            axes[..., i + 1, :] = z
        origins[..., -1, :] = origins[..., -2, :] + self.wrist_offset * z
        return origins, axes

    def points(self, q: np.ndarray) -> np.ndarray:
        """(..., n + 2, 3): the critical points of the arm, the origins of DH frames 0..n and P_w. Consecutive
        points bound the links (for the 2R: base, elbow, tip, tip)."""
        return self._chain(q)[0]

    def position(self, q: np.ndarray) -> np.ndarray:
        """(..., task_dims): P_w, the forward kinematics 𝒦 : C -> T."""
        return self._chain(q)[0][..., -1, : self.task_dims]

    def position_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """P_w (..., task_dims) and its positional Jacobian (..., task_dims, n), columns z_{i-1} × (P_w − o_{i-1})."""
        origins, axes = self._chain(q)
        J = np.cross(axes[..., :-1, :], origins[..., -1:, :] - origins[..., :-2, :])   # (..., n, 3)
        return origins[..., -1, : self.task_dims], np.swapaxes(J, -1, -2)[..., : self.task_dims, :]

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        return self.position_jacobian(q)[1]

    def manipulability(self, q: np.ndarray) -> np.ndarray:
        """μ = sqrt(|J Jᵀ|), eq. (10), of the positional Jacobian of P_w."""
        J = self.jacobian(q)
        return np.sqrt(np.clip(np.linalg.det(J @ np.swapaxes(J, -1, -2)), 0.0, None))

"""FANUC CRX-10iA/L kinematics of Carbonari, Palpacelli, Callegari (Robotics 2023, 12, 36).

Table 1 in SI units (m, rad), standard DH (eq. 1), FK as the product of eq. (2), the Cayley map of
eqs. (4)–(6) and its inverse. The arm's structure is fixed by Table 1's twist angles; the method needs
d2 = d3 (Sec. 3.1: the y4 axis then always meets z0), and the lengths are config values.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import pi

import numba
import numpy as np

ALPHA = (pi / 2, -pi, -pi / 2, -pi / 2, pi / 2, 0.0)   # Table 1, rad


@dataclass(frozen=True)
class Geometry:
    """The non-zero DH lengths of Table 1 (m); a1 = a3 = … = a6 = 0."""

    d1: float
    a2: float
    d2: float
    d3: float
    d4: float
    d5: float
    d6: float

    def __post_init__(self) -> None:
        if abs(self.d2 - self.d3) > 1e-12:
            raise ValueError(f"the method needs d2 = d3 (Sec. 3.1), got d2={self.d2} m, d3={self.d3} m")

    @property
    def dh(self) -> dict[str, list[float]]:
        return {"alpha": list(ALPHA), "a": [0.0, self.a2, 0.0, 0.0, 0.0, 0.0],
                "d": [self.d1, self.d2, self.d3, self.d4, self.d5, self.d6]}

    @property
    def array(self) -> np.ndarray:
        """(d1, a2, d2, d3, d4, d5, d6): what the compiled kernels take."""
        return np.array([self.d1, self.a2, self.d2, self.d3, self.d4, self.d5, self.d6])


# Table 1 (mm -> m). The numerical example (eqs. 31-33, Table 2) implies d1 = 245.0 mm instead (spec §2).
CRX10IAL = Geometry(d1=0.2503, a2=0.710, d2=0.2604, d3=0.2604, d4=0.540, d5=0.150, d6=0.160)
JOINT_LIMITS = np.array([pi, pi, 1.5 * pi, 1.06 * pi, pi, 1.25 * pi])   # Table 1 motion range, ± rad


@numba.njit(cache=True)
def _link(T: np.ndarray, theta: float, d: float, a: float, alpha: float) -> None:
    """T <- T · Rz(θ) Tz(d) Tx(a) Rx(α), eq. (1), in place."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    for r in range(3):
        t0, t1, t2 = T[r, 0], T[r, 1], T[r, 2]
        x = t0 * ct + t1 * st
        y = -t0 * st + t1 * ct
        T[r, 3] += x * a + t2 * d
        T[r, 0] = x
        T[r, 1] = y * ca + t2 * sa
        T[r, 2] = -y * sa + t2 * ca


@numba.njit(cache=True)
def fk_into(q: np.ndarray, geo: np.ndarray, T: np.ndarray) -> None:
    """^0T_6 of eq. (2) written into T (4, 4)."""
    T[:] = 0.0
    for i in range(4):
        T[i, i] = 1.0
    d = (geo[0], geo[2], geo[3], geo[4], geo[5], geo[6])
    a = (0.0, geo[1], 0.0, 0.0, 0.0, 0.0)
    for i in range(6):
        _link(T, q[i], d[i], a[i], ALPHA[i])


@numba.njit(cache=True)
def _fk_many(q: np.ndarray, geo: np.ndarray) -> np.ndarray:
    out = np.empty((q.shape[0], 4, 4))
    for k in range(q.shape[0]):
        fk_into(q[k], geo, out[k])
    return out


def fk(q, g: Geometry = CRX10IAL) -> np.ndarray:
    """Flange pose ^0T_6 (eq. 2) of joints q (6,) or (N, 6) -> (4, 4) or (N, 4, 4); m, rad."""
    q = np.asarray(q, dtype=float)
    if q.shape[-1] != 6 or q.ndim > 2:
        raise ValueError(f"q must have shape (6,) or (N, 6), got {q.shape}")
    out = _fk_many(np.ascontiguousarray(q.reshape(-1, 6)), g.array)
    return out[0] if q.ndim == 1 else out


def twin(q) -> np.ndarray:
    """The other configuration with the same flange pose and the same frame {4} (spec §2, verified):
    (q1 + π, π − q2, π − q3, q4 + π, q5, q6), wrapped to (−π, π]."""
    q = np.array(q, dtype=float)
    q[..., 0] += pi
    q[..., 1] = pi - q[..., 1]
    q[..., 2] = pi - q[..., 2]
    q[..., 3] += pi
    return wrap(q)


def wrap(x):
    """Angles into (−π, π]."""
    return pi - np.remainder(pi - np.asarray(x, dtype=float), 2 * pi)


def cayley(c) -> np.ndarray:
    """^0R_4 = (I + C)(I − C)^{-1} with C = skew(c), in the closed form of eq. (6); c (..., 3)."""
    c = np.asarray(c, dtype=float)
    c1, c2, c3 = c[..., 0], c[..., 1], c[..., 2]
    M = np.stack([np.stack([c1 * c1 - c2 * c2 - c3 * c3 + 1, 2 * c1 * c2 - 2 * c3, 2 * c2 + 2 * c1 * c3], -1),
                  np.stack([2 * c3 + 2 * c1 * c2, -c1 * c1 + c2 * c2 - c3 * c3 + 1, 2 * c2 * c3 - 2 * c1], -1),
                  np.stack([2 * c1 * c3 - 2 * c2, 2 * c1 + 2 * c2 * c3, -c1 * c1 - c2 * c2 + c3 * c3 + 1], -1)], -2)
    return M / (1 + c1 * c1 + c2 * c2 + c3 * c3)[..., None, None]


def cayley_params(R) -> np.ndarray:
    """Inverse of eq. (5): c = vee((R − I)(R + I)^{-1}); singular at a rotation by π (trace R = −1)."""
    R = np.asarray(R, dtype=float)
    eye = np.eye(3)
    C = np.linalg.solve(np.swapaxes(R + eye, -1, -2), np.swapaxes(R - eye, -1, -2))
    C = np.swapaxes(C, -1, -2)
    return np.stack([C[..., 2, 1], C[..., 0, 2], C[..., 1, 0]], -1)

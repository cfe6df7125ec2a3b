"""Andersson's discretization of a continuous curve (IEEE T-RO 24(2), 2008): the algorithm of Sec. IV.

Subproblem 1 (Sec. IV-A): the joint positions on the curve, by a forward search along the curve parameter
in steps of `dt`, then bisection of the bracket to `tol`. Subproblem 2 (Sec. IV-B): the joint angles in
closed form, eqs. (15)-(17), O(n), as a function of the free roll θ_x0 of the first frame.

Indexing (spec §3.3; the paper mixes t_0…t_N with joints 1…N): joints m = 1…N sit at P_m; link m joins
joint m to joint m+1; odd links have the segment lengths, even links are 0, so P_{2i} = P_{2i+1} (a 2-DOF
joint). N joints make n = N // 2 segments with n + 1 distinct points Q_0 = P_1, Q_i = P_{2i} (i ≥ 1).
Odd joints turn about their local z, even joints about local y (eq. 10); frame m's x points along link m.

The kernels are compiled by numba: the search is sequential (segment i+1 starts where segment i ends), so
NumPy cannot batch it. `<kernel>.py_func` runs the same code interpreted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import comb

import numpy as np
from numba import njit

# Curve kinds the compiled kernels evaluate (`Curve.kind`); `params` is a flat float array.
POLYNOMIAL = 0       # power-basis coefficients, highest degree first, 3 per degree: (x, y, z)
TRAVELLING_WAVE = 1  # (a_y, a_z, k, phase, phase_z): p(u) = (u, a_y sin(ku − phase), a_z sin(ku − phase + phase_z))


class CurveTooShort(ValueError):
    """The chain is longer than the curve: Subproblem 1 ran past the end of the parameter range."""


@dataclass(frozen=True)
class Curve:
    """A parametrized space curve p_d(t), t_start ≤ t ≤ t_end."""

    kind: int
    params: np.ndarray
    t_start: float
    t_end: float

    def __call__(self, t) -> np.ndarray:
        """(k, 3) points at parameters t (k,)."""
        return _points(self.kind, self.params, np.atleast_1d(np.asarray(t, dtype=float)))


def bezier(control_points) -> Curve:
    """Eq. (19): p_d(t) = Σ_k p_{d,k} C(d, k) t^k (1 − t)^(d−k), 0 ≤ t ≤ 1, in power basis for Horner."""
    p = np.asarray(control_points, dtype=float)
    d = len(p) - 1
    # a_j = C(d, j) Σ_{k≤j} (−1)^(j−k) C(j, k) p_k  (Bernstein -> monomial t^j)
    power = np.array([comb(d, j) * sum((-1) ** (j - k) * comb(j, k) * p[k] for k in range(j + 1))
                      for j in range(d + 1)])
    return Curve(POLYNOMIAL, np.ascontiguousarray(power[::-1]).ravel(), 0.0, 1.0)


def travelling_wave(amplitude_y: float, amplitude_z: float, wavelength: float, phase: float, phase_z: float,
                    length: float) -> Curve:
    """A shape primitive for lateral undulation (a_z = 0) or sidewinding (a_z ≠ 0, phase_z = π/2):
    p(u) = (u, a_y sin(ku − phase), a_z sin(ku − phase + phase_z)), k = 2π/wavelength, 0 ≤ u ≤ length.
    `phase` = ωt makes it travel along +u."""
    k = 2.0 * math.pi / wavelength
    return Curve(TRAVELLING_WAVE, np.array([amplitude_y, amplitude_z, k, phase, phase_z]), 0.0, length)


@dataclass(frozen=True)
class Chain:
    """N joints with 2-DOF joints: segment i (link 2i+1) has length segment_lengths[i], i < N // 2."""

    joints: int
    segment_lengths: np.ndarray

    @classmethod
    def uniform(cls, joints: int, length: float) -> Chain:
        if joints < 2:
            raise ValueError(f"a chain needs at least 2 joints (one segment), got {joints}")
        return cls(joints, np.full(joints // 2, float(length)))

    @property
    def segments(self) -> int:
        return len(self.segment_lengths)

    def link_lengths(self) -> np.ndarray:
        """L_1 … L_{N−1}: the segment lengths on odd links, 0 on even links."""
        links = np.zeros(self.joints - 1)
        links[::2] = self.segment_lengths
        return links


# -- compiled kernels ------------------------------------------------------------------------------------


@njit(cache=True)
def _point(kind, params, t):
    if kind == POLYNOMIAL:
        x = y = z = 0.0
        for k in range(0, params.size, 3):  # Horner
            x = x * t + params[k]
            y = y * t + params[k + 1]
            z = z * t + params[k + 2]
        return x, y, z
    s = params[2] * t - params[3]
    return t, params[0] * math.sin(s), params[1] * math.sin(s + params[4])


@njit(cache=True)
def _points(kind, params, ts):
    out = np.empty((ts.size, 3))
    for i in range(ts.size):
        out[i, 0], out[i, 1], out[i, 2] = _point(kind, params, ts[i])
    return out


@njit(cache=True)
def _gap(kind, params, cx, cy, cz, length_sq, t):
    """‖p_d(t) − c‖² − L²: negative before the crossing (the sign is all the search needs)."""
    x, y, z = _point(kind, params, t)
    return (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2 - length_sq


@njit(cache=True)
def _search(kind, params, t_start, t_end, lengths, dt, tol, increments):
    """Subproblem 1: parameters and points of Q_0 … Q_n (NaN past the end of the curve), curve evaluations used.

    Cold (increments.size == 0), Sec. IV-A: march t = t_i + dt, t_i + 2dt, … until ‖p_d(t) − p_d(t_i)‖ ≥ L_i,
    then bisect the last step. Warm (Sec. IV-D's suggestion, our implementation): start at
    t_i + increments[i] (the previous solution's step) and march forward or back to the crossing."""
    n = lengths.size
    t = np.full(n + 1, np.nan)
    points = np.full((n + 1, 3), np.nan)
    t[0] = t_start
    evaluations = 0
    for i in range(n):
        ti = t[i]
        cx, cy, cz = _point(kind, params, ti)
        points[i, 0], points[i, 1], points[i, 2] = cx, cy, cz
        length_sq = lengths[i] * lengths[i]
        evaluations += 1
        a, b = ti, math.nan
        if increments.size:
            guess = min(ti + max(increments[i], 0.0), t_end)
            evaluations += 1
            if _gap(kind, params, cx, cy, cz, length_sq, guess) >= 0.0:
                b = guess  # past the crossing: step back until before it, never behind t_i (gap(t_i) = −L²)
                a = max(b - dt, ti)
                while a > ti:
                    evaluations += 1
                    if _gap(kind, params, cx, cy, cz, length_sq, a) < 0.0:
                        break
                    b, a = a, max(a - dt, ti)
            else:
                a = guess
        if math.isnan(b):  # forward march from a: steps 1-3 of Sec. IV-A
            while True:
                if a >= t_end:
                    return t, points, evaluations  # the chain is longer than the curve
                b = min(a + dt, t_end)
                evaluations += 1
                if _gap(kind, params, cx, cy, cz, length_sq, b) >= 0.0:
                    break
                a = b
        while b - a > tol:  # bisection of [a, b]: gap(a) < 0 ≤ gap(b)
            m = 0.5 * (a + b)
            evaluations += 1
            if _gap(kind, params, cx, cy, cz, length_sq, m) >= 0.0:
                b = m
            else:
                a = m
        t[i + 1] = 0.5 * (a + b)
    points[n, 0], points[n, 1], points[n, 2] = _point(kind, params, t[n])
    return t, points, evaluations + 1


@njit(cache=True)
def _rotate_rows(M, i, j, c, s):
    """Rows i, j of M <- (c·r_i − s·r_j, s·r_i + c·r_j): left-multiplication by a plane rotation."""
    for k in range(3):
        ri, rj = M[i, k], M[j, k]
        M[i, k] = c * ri - s * rj
        M[j, k] = s * ri + c * rj


@njit(cache=True)
def _angles(Q, theta_x0, joints):
    """Subproblem 2: θ_z0, θ_y0 (eq. 16), R_w1 (eq. 15) and θ_1 … θ_N (eq. 17; θ_1 = 0, trailing joints
    without a following segment 0)."""
    theta = np.zeros(joints)
    dx, dy, dz = Q[1, 0] - Q[0, 0], Q[1, 1] - Q[0, 1], Q[1, 2] - Q[0, 2]
    theta_z0 = math.atan2(dy, dx)                      # eq. (16a)
    theta_y0 = math.atan2(-dz, math.hypot(dx, dy))     # eq. (16b)
    # R_w1 = Rz(θ_z0) Ry(θ_y0) Rx(θ_x0), eq. (15); its inverse Rx(−θ_x0) Ry(−θ_y0) Rz(−θ_z0), built from the right
    R_inv = np.eye(3)
    _rotate_rows(R_inv, 1, 0, math.cos(theta_z0), math.sin(theta_z0))   # Rz(−θ_z0)
    _rotate_rows(R_inv, 0, 2, math.cos(theta_y0), math.sin(theta_y0))   # Ry(−θ_y0)·
    _rotate_rows(R_inv, 2, 1, math.cos(theta_x0), math.sin(theta_x0))   # Rx(−θ_x0)·
    R_w1 = R_inv.T.copy()
    for i in range(1, Q.shape[0] - 1):  # the 2-DOF joint (2i, 2i+1) at Q_i; Thm 4.2 with j = 2i + 2
        ex, ey, ez = Q[i + 1, 0] - Q[i, 0], Q[i + 1, 1] - Q[i, 1], Q[i + 1, 2] - Q[i, 2]
        px = R_inv[0, 0] * ex + R_inv[0, 1] * ey + R_inv[0, 2] * ez   # Δp_j = R_{w,j−3}^{-1}(P_j − P_{j−2})
        py = R_inv[1, 0] * ex + R_inv[1, 1] * ey + R_inv[1, 2] * ez
        pz = R_inv[2, 0] * ex + R_inv[2, 1] * ey + R_inv[2, 2] * ez
        a = math.atan2(-pz, px)                  # θ_{j−2}, eq. (17a), about y
        b = math.atan2(py, math.hypot(px, pz))   # θ_{j−1}, eq. (17b), about z
        theta[2 * i - 1], theta[2 * i] = a, b
        # R_{w,j−1}^{-1} = Rz(−θ_{j−1}) Ry(−θ_{j−2}) R_{w,j−3}^{-1}: no inverse needed (Sec. IV-B)
        _rotate_rows(R_inv, 0, 2, math.cos(a), math.sin(a))
        _rotate_rows(R_inv, 1, 0, math.cos(b), math.sin(b))
    return theta_z0, theta_y0, R_w1, theta


# -- the algorithm -----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Search:
    """Subproblem 1's result: the distinct joint points Q_0 … Q_n on the curve."""

    t: np.ndarray       # (n+1,) curve parameters
    points: np.ndarray  # (n+1, 3) Q_i = p_d(t_i)
    evaluations: int   # curve evaluations: a cost measure that does not depend on the machine


@dataclass(frozen=True)
class Angles:
    """Subproblem 2's result."""

    theta_z0: float
    theta_y0: float
    R_w1: np.ndarray   # orientation of the first frame, eq. (15)
    theta: np.ndarray  # θ_1 … θ_N (rad)


def joint_parameters(curve: Curve, chain: Chain, dt: float, tol: float, increments: np.ndarray | None = None) -> Search:
    """Subproblem 1 (Sec. IV-A): forward search in steps of dt, then bisection to tol (both in curve-parameter
    units). `increments` (n,) warm-starts each segment's search at the previous solution's t_{i+1} − t_i."""
    warm = np.empty(0) if increments is None else np.asarray(increments, dtype=float)
    t, points, evaluations = _search(curve.kind, curve.params, curve.t_start, curve.t_end, chain.segment_lengths,
                                     dt, tol, warm)
    if np.isnan(t[-1]):
        done = int(np.isnan(t).argmax()) - 1
        raise CurveTooShort(f"segment {done + 1} of {chain.segments} does not fit: the chain "
                            f"({chain.segment_lengths.sum():g}) is longer than the curve allows")
    return Search(t, points, evaluations)


def joint_angles(points: np.ndarray, theta_x0: float, joints: int) -> Angles:
    """Subproblem 2 (Sec. IV-B): Theorems 4.1 and 4.2 on the distinct joint points Q_0 … Q_n."""
    return Angles(*_angles(points, float(theta_x0), joints))


def discretize(curve: Curve, chain: Chain, theta_x0: float, dt: float, tol: float,
               increments: np.ndarray | None = None) -> tuple[Search, Angles]:
    """Both stages: the joint positions on the curve and the joint angles for roll θ_x0."""
    search = joint_parameters(curve, chain, dt, tol, increments)
    return search, joint_angles(search.points, theta_x0, chain.joints)


def joint_positions(points: np.ndarray, joints: int) -> np.ndarray:
    """(N, 3) P_1 … P_N from the distinct points: P_1 = Q_0, P_{2i} = P_{2i+1} = Q_i."""
    return points[np.arange(1, joints + 1) // 2]


# -- forward kinematics: the checks of the solution ------------------------------------------------------


def _axis_rotation(axis: int, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def joint_axis(m: int) -> int:
    """Eq. (10): odd joints about z (2), even joints about y (1)."""
    return 2 if m % 2 else 1


def forward_kinematics(p1: np.ndarray, R_w1: np.ndarray, theta: np.ndarray, chain: Chain) -> np.ndarray:
    """(N, 4, 4) g_{w,m}, sequentially: R_{w,m} = R_{w,m−1} Rot_axis(m)(θ_m), p_{m+1} = p_m + R_{w,m} [L_m, 0, 0]."""
    links = chain.link_lengths()
    frames = np.tile(np.eye(4), (chain.joints, 1, 1))
    R, p = np.asarray(R_w1, dtype=float), np.asarray(p1, dtype=float)
    for m in range(1, chain.joints + 1):
        R = R @ _axis_rotation(joint_axis(m), theta[m - 1])
        frames[m - 1, :3, :3], frames[m - 1, :3, 3] = R, p
        if m < chain.joints:
            p = p + R[:, 0] * links[m - 1]
    return frames


def hat(w: np.ndarray) -> np.ndarray:
    """Eq. (2): the skew-symmetric matrix of w."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def twist_hat(xi: np.ndarray, printed: bool = False) -> np.ndarray:
    """Eq. (3): ξ = (v, ω) -> [[ω̂, v], [0, 0]] ∈ se(3). The paper prints v̂ in the top-left block (erratum);
    `printed=True` builds it as printed."""
    v, w = xi[:3], xi[3:]
    out = np.zeros((4, 4))
    out[:3, :3] = hat(v if printed else w)
    out[:3, 3] = v
    return out


def poe_forward_kinematics(p1: np.ndarray, theta_z0: float, theta_y0: float, theta_x0: float, theta: np.ndarray,
                           chain: Chain, printed_twist_hat: bool = False) -> np.ndarray:
    """(N, 4, 4) g_{w,m} by the product of exponentials: eq. (15) for g_{w,1}, then eq. (8) with the twists of
    eqs. (4), (11), (12) and g_{1,m}(0) of eq. (9), every exponential by expm of eq. (3)."""
    from scipy.linalg import expm  # 0.1 s to import: only this check needs it, not the snake's runs

    p1 = np.asarray(p1, dtype=float)
    distance = float(np.linalg.norm(p1))
    x, y, z = np.eye(3)
    # eq. (15): a prismatic joint along p_d(t_0) (ξ = (v, 0)), then revolute z, y, x through that point
    g_w1 = expm(twist_hat(np.r_[p1 / distance if distance else x, 0, 0, 0], printed_twist_hat) * distance)
    for axis, angle in ((z, theta_z0), (y, theta_y0), (x, theta_x0)):
        g_w1 = g_w1 @ expm(twist_hat(np.r_[np.zeros(3), axis], printed_twist_hat) * angle)
    offsets = np.r_[0.0, np.cumsum(chain.link_lengths())]  # S_m = Σ_{k<m} L_k, eq. (11)
    frames = np.empty((chain.joints, 4, 4))
    product = g_w1
    for m in range(1, chain.joints + 1):
        w = np.eye(3)[joint_axis(m)]
        q = np.array([offsets[m - 1], 0.0, 0.0])
        xi = np.r_[-np.cross(w, q), w]  # eq. (4); eq. (12) written out
        product = product @ expm(twist_hat(xi, printed_twist_hat) * theta[m - 1])
        g_1m0 = np.eye(4)
        g_1m0[0, 3] = offsets[m - 1]  # eq. (9)
        frames[m - 1] = product @ g_1m0
    return frames

"""Kinematics of a sphere rolling without slip on a height field z = f(x, y) (Sec. 3), and the velocity maps
of the four robot classes (Sec. 4). Vectorized over any leading batch shape; vectors are stacked on the
LAST axis (..., 3).

Frames: world {W}; tangent {T}, the minimal rotation taking world Z onto the robot-side normal n̂ (eq. 23);
local {L} = {T} turned by ψ about n̂, with axes ĥ (heading), l̂ (lateral), n̂ (eqs. 25-27).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# eq. (25) as printed turns the heading clockwise about n̂ for ψ > 0; the corrected form is the standard
# counter-clockwise R_z(ψ) that the controllers (55)-(57) and the cone relation (44) assume (erratum 1).
HEADING_SIGN = {"corrected": 1.0, "printed": -1.0}


@dataclass(frozen=True)
class CosineTerrain:
    """eq. (59): f(x, y) = a (cos ωx + cos ωy − 2); a = 0 is the flat plane z = 0."""

    amplitude: float = 0.2   # a, m
    frequency: float = 2.0   # ω, rad/m

    def height(self, x, y):
        a, w = self.amplitude, self.frequency
        return a * (np.cos(w * x) + np.cos(w * y) - 2.0)

    def gradient(self, x, y):
        """(f_x, f_y)."""
        a, w = self.amplitude, self.frequency
        return -a * w * np.sin(w * x), -a * w * np.sin(w * y)

    def hessian(self, x, y):
        """(f_xx, f_xy, f_yy)."""
        a, w = self.amplitude, self.frequency
        return -a * w * w * np.cos(w * x), np.zeros_like(np.asarray(x, dtype=float)), -a * w * w * np.cos(w * y)

    @property
    def max_curvature(self) -> float:
        """Largest principal curvature |κ| (1/m): a ω² at the peaks and pits."""
        return self.amplitude * self.frequency ** 2


def normal(fx, fy) -> np.ndarray:
    """eq. (10): robot-side unit normal n̂ = s_n [−f_x, −f_y, 1] (upward)."""
    s_n = 1.0 / np.sqrt(1.0 + fx * fx + fy * fy)  # eq. (7)
    return np.stack([-s_n * fx, -s_n * fy, s_n * np.ones_like(fx)], axis=-1)


def tangent_components(fx, fy) -> tuple[tuple, tuple, tuple]:
    """Columns (î_T, ĵ_T, n̂) of R_TTr, eq. (23), as component triples (fast path of the integrator).

    eq. (23) has c = s²(1 − s_n) with s = 1/‖∇f‖, singular on flat spots; c = s_n²/(1 + s_n) is the same
    number and smooth everywhere (R_T = I where ∇f = 0, the γ = 0 branch of eq. 16)."""
    s_n = 1.0 / np.sqrt(1.0 + fx * fx + fy * fy)   # eq. (7)
    c = s_n * s_n / (1.0 + s_n)
    cxy = -c * fx * fy
    return (1.0 - c * fx * fx, cxy, s_n * fx), (cxy, 1.0 - c * fy * fy, s_n * fy), (-s_n * fx, -s_n * fy, s_n)


def local_components(fx, fy, psi, heading: str = "corrected") -> tuple[tuple, tuple, tuple]:
    """(ĥ, l̂, n̂), the columns of F_LW (eqs. 26-27), as component triples.

    printed eq. (25): ĥ = Cψ î_T − Sψ ĵ_T (clockwise); corrected: ĥ = Cψ î_T + Sψ ĵ_T."""
    i_t, j_t, n = tangent_components(fx, fy)
    c, s = np.cos(psi), HEADING_SIGN[heading] * np.sin(psi)
    h = tuple(c * i + s * j for i, j in zip(i_t, j_t, strict=True))
    lat = tuple(c * j - s * i for i, j in zip(i_t, j_t, strict=True))
    return h, lat, n


def _stacked(*vectors: tuple) -> tuple[np.ndarray, ...]:
    return tuple(np.stack(np.broadcast_arrays(*v), axis=-1) for v in vectors)


def tangent_axes(fx, fy) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(î_T, ĵ_T, n̂) of eq. (23), each (..., 3)."""
    return _stacked(*tangent_components(np.asarray(fx, dtype=float), np.asarray(fy, dtype=float)))


def tangent_rotation(fx, fy) -> np.ndarray:
    """R_TTr of eq. (23), (..., 3, 3)."""
    return np.stack(tangent_axes(fx, fy), axis=-1)


def local_axes(fx, fy, psi, heading: str = "corrected") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ĥ, l̂, n̂) of eqs. (26-27), each (..., 3)."""
    fx, fy, psi = (np.asarray(v, dtype=float) for v in (fx, fy, psi))
    return _stacked(*local_components(fx, fy, psi, heading))


def local_rotation(fx, fy, psi, heading: str = "corrected") -> np.ndarray:
    """F_LW rotation block [ĥ l̂ n̂], (..., 3, 3)."""
    return np.stack(local_axes(fx, fy, psi, heading), axis=-1)


def world_velocity(h: np.ndarray, lat: np.ndarray, u, v) -> np.ndarray:
    """eq. (31): ^W V = F_LW [u, v, 0, 0]^T = u ĥ + v l̂."""
    return np.asarray(u)[..., None] * h + np.asarray(v)[..., None] * lat


def local_velocity(robot: str, theta_dot, phi_dot, phi=0.0, radius: float = 0.2) -> tuple:
    """(u, v) of ^L V per class: 3R eq. (33), 2R eq. (36) (= 3R with ψ̇ = 0), RT eq. (38) (φ̇ = 0),
    RS eq. (48) with θ̇ read as α̇ and φ its tilt."""
    if robot in ("3r", "2r"):
        return radius * np.asarray(theta_dot), -radius * np.asarray(phi_dot)
    if robot == "rt":
        return radius * np.asarray(theta_dot), np.zeros_like(np.asarray(theta_dot, dtype=float))
    if robot == "rs":
        return radius * np.asarray(theta_dot) * np.cos(phi), -radius * np.asarray(phi_dot)
    raise ValueError(f"unknown robot class {robot!r}: one of 3r, 2r, rt, rs")


def sphere_center(p0: np.ndarray, n: np.ndarray, radius: float) -> np.ndarray:
    """eq. (51): O_Sp = P0 + R n̂."""
    return p0 + radius * n


def contact_xy_velocity(terrain, x, y, center_velocity: np.ndarray, radius: float) -> np.ndarray:
    """(ẋ, ẏ) of the contact point (x, y, f(x, y)) of a sphere in contact whose centre moves at
    `center_velocity` (..., 3).

    The centre is c = p + R n̂(p), so ċ_xy = (I + R ∂n̂_xy/∂(x, y)) ṗ_xy. Rolling without slip moves the centre
    at ω × R n̂; the paper's model (eq. 31) moves the contact point at that velocity instead, i.e. it drops
    R ∂n̂/∂p: exact on planes, off by 1/(1 + R κ) along a principal direction of curvature κ (spec §10-A8)."""
    fx, fy = terrain.gradient(x, y)
    fxx, fxy, fyy = terrain.hessian(x, y)
    s_n = 1.0 / np.sqrt(1.0 + fx * fx + fy * fy)
    # n̂_xy = −s_n ∇f: its Jacobian is −s_n (H − s_n² ∇f ∇fᵀ H)
    g = np.stack([fx, fy], axis=-1)
    hess = np.stack([np.stack([fxx, fxy], axis=-1), np.stack([fxy, fyy], axis=-1)], axis=-2)
    gh = np.einsum("...i,...ij->...j", g, hess)
    dn = -s_n[..., None, None] * (hess - (s_n * s_n)[..., None, None] * g[..., :, None] * gh[..., None, :])
    m = np.eye(2) + radius * dn
    return np.linalg.solve(m, center_velocity[..., :2, None])[..., 0]

"""Spherical robots on 3-D terrain: the frames of Sec. 3 against independent constructions, the printed
equations where they are right, the class kinematics in their closed-form limits (spec §8)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pipeline.papers.spherical_terrain import (
    CosineTerrain,
    contact_xy_velocity,
    local_axes,
    local_rotation,
    local_velocity,
    normal,
    sphere_center,
    tangent_rotation,
    world_velocity,
)

RNG = np.random.default_rng(7)
TERRAIN = CosineTerrain(0.2, 2.0)
R = 0.2


@dataclass(frozen=True)
class InclinedPlane:
    """f = x tan β (spec §8.5)."""

    slope: float

    def height(self, x, y):
        return np.tan(self.slope) * np.asarray(x, dtype=float)

    def gradient(self, x, y):
        x = np.asarray(x, dtype=float)
        return np.full_like(x, np.tan(self.slope)), np.zeros_like(x)

    def hessian(self, x, y):
        zero = np.zeros_like(np.asarray(x, dtype=float))
        return zero, zero, zero


def random_gradients(n=200):
    x, y = RNG.uniform(-3, 3, (2, n))
    return TERRAIN.gradient(x, y)


def test_terrain_facts_of_the_spec():
    assert TERRAIN.height(2.0, 0.0) == pytest.approx(-0.33073, abs=1e-5)          # the path's start
    assert TERRAIN.height(np.pi / 2, np.pi / 2) == pytest.approx(-0.8)           # pits
    fx, fy = TERRAIN.gradient(np.pi / 4, np.pi / 4)
    assert np.degrees(np.arctan(np.hypot(fx, fy))) == pytest.approx(29.5, abs=0.05)   # steepest slope
    assert R * TERRAIN.max_curvature == pytest.approx(0.16)                     # assumption 3 holds
    h = 1e-6
    x, y = RNG.uniform(-3, 3, (2, 20))
    fx, fy = TERRAIN.gradient(x, y)
    assert np.allclose(fx, (TERRAIN.height(x + h, y) - TERRAIN.height(x - h, y)) / (2 * h), atol=1e-8)
    fxx, fxy, fyy = TERRAIN.hessian(x, y)
    assert np.allclose(fxx, (TERRAIN.gradient(x + h, y)[0] - TERRAIN.gradient(x - h, y)[0]) / (2 * h), atol=1e-7)
    assert np.allclose(fyy, (TERRAIN.gradient(x, y + h)[1] - TERRAIN.gradient(x, y - h)[1]) / (2 * h), atol=1e-7)
    assert np.all(fxy == 0)


def test_tangent_rotation_is_the_minimal_rotation_of_z_onto_the_normal():
    fx, fy = random_gradients()
    rot = tangent_rotation(fx, fy)
    n = normal(fx, fy)
    assert np.allclose(rot @ np.swapaxes(rot, -1, -2), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(rot), 1.0)
    assert np.allclose(rot[..., :, 2], n)                           # R_T e_z = n̂ (eq. 10)
    # Rodrigues about ê (eq. 13) by γ = atan‖∇f‖ (eq. 16), computed by scipy (spec §8.2)
    s = 1.0 / np.hypot(fx, fy)
    axis = np.stack([s * fy, -s * fx, np.zeros_like(fx)], axis=-1)
    gamma = np.arctan(np.hypot(fx, fy))
    assert np.allclose(rot, Rotation.from_rotvec(axis * gamma[:, None]).as_matrix(), atol=1e-14)


def test_eq23_as_printed_with_s_equals_the_smooth_form_and_flat_spots_give_identity():
    fx, fy = random_gradients()
    s2 = 1.0 / (fx * fx + fy * fy)
    s_n = 1.0 / np.sqrt(1.0 + fx * fx + fy * fy)
    printed = np.stack([np.stack([1 - s2 * fx ** 2 * (1 - s_n), -s2 * fx * fy * (1 - s_n), -s_n * fx], -1),
                        np.stack([-s2 * fx * fy * (1 - s_n), 1 - s2 * fy ** 2 * (1 - s_n), -s_n * fy], -1),
                        np.stack([s_n * fx, s_n * fy, s_n], -1)], axis=-2)        # eq. (23), rows as printed
    assert np.allclose(printed, tangent_rotation(fx, fy), atol=1e-14)
    assert np.array_equal(tangent_rotation(0.0, 0.0), np.eye(3))


def test_eq27_as_printed_is_the_printed_heading_rotation():
    fx, fy = random_gradients(50)
    psi = RNG.uniform(-np.pi, np.pi, 50)
    s2 = 1.0 / (fx * fx + fy * fy)
    s_n = 1.0 / np.sqrt(1.0 + fx * fx + fy * fy)
    c, s_ = np.cos(psi), np.sin(psi)
    k = s2 * (1 - s_n)
    a11 = (1 - k * fx ** 2) * c + k * fx * fy * s_
    a12 = (1 - k * fx ** 2) * s_ - k * fx * fy * c
    a21 = -k * fx * fy * c - (1 - k * fy ** 2) * s_
    a22 = -k * fx * fy * s_ + (1 - k * fy ** 2) * c
    a31 = s_n * fx * c - s_n * fy * s_
    a32 = s_n * fx * s_ + s_n * fy * c
    printed = local_rotation(fx, fy, psi, "printed")
    for (i, j), a in {(0, 0): a11, (0, 1): a12, (1, 0): a21, (1, 1): a22, (2, 0): a31, (2, 1): a32}.items():
        assert np.allclose(printed[:, i, j], a, atol=1e-14)
    assert np.allclose(printed[:, :, 2], normal(fx, fy))                      # a13, a23, a33


def test_frames_are_orthonormal_and_headings_turn_opposite_ways():
    fx, fy = random_gradients(100)
    psi = RNG.uniform(-np.pi, np.pi, 100)
    for form in ("corrected", "printed"):
        rot = local_rotation(fx, fy, psi, form)
        assert np.allclose(rot @ np.swapaxes(rot, -1, -2), np.eye(3), atol=1e-14)
        assert np.allclose(np.linalg.det(rot), 1.0)
    h0, _, n = local_axes(fx, fy, np.zeros(100))
    for form, sign in (("corrected", 1.0), ("printed", -1.0)):
        h, _, _ = local_axes(fx, fy, np.full(100, 0.1), form)
        assert np.all(sign * np.sum(np.cross(h0, h) * n, axis=-1) > 0)   # corrected: counter-clockwise about n̂


def test_world_velocity_is_tangent_and_keeps_its_length():
    fx, fy = random_gradients(100)
    psi = RNG.uniform(-np.pi, np.pi, 100)
    h, lat, n = local_axes(fx, fy, psi)
    u, v = RNG.normal(size=(2, 100))
    w = world_velocity(h, lat, u, v)
    assert np.allclose(np.sum(w * n, axis=-1), 0.0, atol=1e-15)
    assert np.allclose(w[:, 2], fx * w[:, 0] + fy * w[:, 1], atol=1e-15)     # ż = f_x ẋ + f_y ẏ (spec §8.3)
    assert np.allclose(np.linalg.norm(w, axis=-1), np.hypot(u, v))


def test_local_velocity_of_each_class():
    assert local_velocity("3r", 2.0, 1.0, radius=R) == pytest.approx((0.4, -0.2))     # eq. (33)
    assert local_velocity("2r", 2.0, 1.0, radius=R) == pytest.approx((0.4, -0.2))     # eq. (36)
    assert local_velocity("rt", 2.0, 1.0, radius=R) == pytest.approx((0.4, 0.0))      # eq. (38)
    assert local_velocity("rs", 2.0, 1.0, phi=np.pi / 3, radius=R) == pytest.approx((0.2, -0.2))   # eq. (48)
    with pytest.raises(ValueError):
        local_velocity("4r", 1.0, 1.0)


def _roll(terrain, robot, rates, phi, psi0, duration=10.0, dt=1e-3, xy0=(0.0, 0.0)):
    """Integrate the class kinematics open loop: rates = (θ̇ or α̇, φ̇, ψ̇); RS turns by eq. (44)."""
    x, y = xy0
    z = float(terrain.height(x, y))
    psi, path = psi0, []
    for _ in range(round(duration / dt)):
        fx, fy = terrain.gradient(x, y)
        h, lat, _ = local_axes(np.array(fx), np.array(fy), np.array(psi))
        u, v = local_velocity(robot, rates[0], rates[1], phi, R)
        w = world_velocity(h, lat, u, v)
        x, y, z = x + dt * w[0], y + dt * w[1], z + dt * w[2]
        psi += dt * (-rates[0] * np.sin(phi) if robot == "rs" else rates[2])
        path.append((x, y, z))
    return np.array(path)


def test_flat_rt_is_a_unicycle_and_rs_turns_on_a_circle_of_radius_r_cot_phi():
    flat = CosineTerrain(0.0, 2.0)
    path = _roll(flat, "rt", (2.0, 0.0, 0.5), 0.0, 0.0)        # circle of radius Rθ̇/ψ̇ = 0.8 m about (0, 0.8)
    assert np.allclose(np.hypot(path[:, 0], path[:, 1] - 0.8), 0.8, atol=2e-3)
    assert np.allclose(path[:, 2], 0.0)
    phi = 0.4
    path = _roll(flat, "rs", (3.0, 0.0, 0.0), phi, 0.0, duration=8.0)
    # ψ̇ = −α̇ sin φ: clockwise, centre at (0, −R cot φ), speed R α̇ cos φ (spec §8.4: 0.47304 m)
    assert R / np.tan(phi) == pytest.approx(0.47304, abs=1e-5)
    assert np.allclose(np.hypot(path[:, 0], path[:, 1] + R / np.tan(phi)), R / np.tan(phi), atol=2e-3)
    speed = np.linalg.norm(np.diff(path, axis=0), axis=1) / 1e-3
    assert np.allclose(speed, R * 3.0 * np.cos(phi), rtol=1e-9)


def test_rt_heading_up_an_inclined_plane():
    beta = 0.3
    plane = InclinedPlane(beta)
    assert np.allclose(tangent_rotation(*plane.gradient(np.array([0.0, 5.0]), np.zeros(2)))[0],
                       tangent_rotation(*plane.gradient(np.array([5.0]), np.zeros(1)))[0])
    path = _roll(plane, "rt", (2.0, 0.0, 0.0), 0.0, 0.0, duration=1.0)   # ψ = 0: ĥ points up the slope
    speed = np.diff(path, axis=0) / 1e-3
    assert np.allclose(speed[:, 2], R * 2.0 * np.sin(beta))
    assert np.allclose(np.hypot(speed[:, 0], speed[:, 1]), R * 2.0 * np.cos(beta))


def test_sphere_centre_is_r_above_the_contact_along_the_normal():
    x, y = RNG.uniform(-3, 3, (2, 30))
    p0 = np.stack([x, y, TERRAIN.height(x, y)], axis=-1)
    n = normal(*TERRAIN.gradient(x, y))
    center = sphere_center(p0, n, R)                                     # eq. (51)
    assert np.allclose(np.sum((center - p0) * n, axis=-1), R)
    # on a convex-enough surface (R κ < 1) no other surface point is closer to the centre than R
    grid = np.linspace(-0.5, 0.5, 201)
    for c, p in zip(center[:5], p0[:5], strict=True):
        gx, gy = np.meshgrid(p[0] + grid, p[1] + grid)
        d = np.sqrt((gx - c[0]) ** 2 + (gy - c[1]) ** 2 + (TERRAIN.height(gx, gy) - c[2]) ** 2)
        assert d.min() >= R - 1e-9


def test_rigid_rolling_differs_from_the_paper_by_the_curvature_factor():
    v = np.array([1.0, 0.0, 0.0])
    # planes: the contact point moves with the centre
    plane = InclinedPlane(0.3)
    assert np.allclose(contact_xy_velocity(plane, 1.0, 2.0, v, R), v[:2])
    # peak (κ = −aω² along x): 1/(1 + Rκ_n) with Rκ_n = 0.16 -> 0.862; pit: 1/(1 − 0.16) = 1.19
    assert contact_xy_velocity(TERRAIN, 0.0, 0.0, v, R) == pytest.approx([1 / 1.16, 0.0])
    assert contact_xy_velocity(TERRAIN, np.pi / 2, np.pi / 2, v, R) == pytest.approx([1 / 0.84, 0.0])
    # anywhere: it inverts c(p) = p + R n̂(p) (finite differences)
    x, y, h = 0.7, -0.4, 1e-6

    def center(px, py):
        return np.array([px, py, TERRAIN.height(px, py)]) + R * normal(*TERRAIN.gradient(px, py))

    jac = np.column_stack([(center(x + h, y) - center(x - h, y)) / (2 * h),
                           (center(x, y + h) - center(x, y - h)) / (2 * h)])
    p_dot = np.array([0.3, -0.2])
    assert np.allclose(contact_xy_velocity(TERRAIN, x, y, jac @ p_dot, R), p_dot, atol=1e-8)


def test_appendix_quaternion_matrix_standard_form_gives_eq20_printed_does_not():
    fx, fy = 0.3, -0.25
    s = 1.0 / np.hypot(fx, fy)
    gamma = np.arctan(np.hypot(fx, fy))
    qr, qi, qj, qk = np.cos(gamma / 2), s * fy * np.sin(gamma / 2), -s * fx * np.sin(gamma / 2), 0.0
    standard = np.array([[1 - 2 * (qj ** 2 + qk ** 2), 2 * (qi * qj - qk * qr), 2 * (qi * qk + qj * qr)],
                         [2 * (qi * qj + qk * qr), 1 - 2 * (qi ** 2 + qk ** 2), 2 * (qj * qk - qi * qr)],
                         [2 * (qi * qk - qj * qr), 2 * (qj * qk + qi * qr), 1 - 2 * (qi ** 2 + qj ** 2)]])
    assert np.allclose(standard, tangent_rotation(fx, fy), atol=1e-15)
    printed = np.array([[1 - 2 * qj ** 2, 2 * qi * qj, -2 * qi * qr],                 # eq. (A.6) as printed
                        [2 * qi * qj, 1 - 2 * qi ** 2, -2 * qi * qr],
                        [-2 * qi * qr, -2 * qi * qr, 1 - 2 * (qi ** 2 + qj ** 2)]])
    assert not np.allclose(printed @ printed.T, np.eye(3), atol=1e-3)                 # not even a rotation

"""itbot-smc kinematics and dynamics (checks 1-3 and 8 of the paper's reproduction plan): Table 2's MDH product
against the closed form, FK/IK round trips, the Jacobian, M symmetric positive definite, V from M's Christoffel
symbols, Ṁ − 2C skew-symmetric, G = ∂P/∂θ, energy conservation, and the static gravity values."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy import integrate

from pipeline.papers.itbot_smc.model import (
    Links,
    coriolis,
    dynamics_terms,
    fk,
    gravity_torque,
    hand_acceleration,
    ik,
    jacobian,
    mass_matrix,
    mdh_frames,
    potential_energy,
)
from pipeline.papers.itbot_smc.plants import Drive, HandLoad, PlantModel, joint_accelerations

LINKS = Links(l1=0.325, l2=0.225, lc1=0.26, lc2=0.15, m1=1.79, m2=0.65, iz1=0.015756, iz2=0.0027422, gravity=9.81)
RNG = np.random.default_rng(7)


def random_states(n: int = 50) -> tuple[np.ndarray, np.ndarray]:
    return RNG.uniform(-math.pi, math.pi, (n, 2)), RNG.normal(0, 2, (n, 2))


def test_mdh_product_is_the_closed_form():
    q, _ = random_states(200)
    frames = mdh_frames(LINKS, q)
    assert np.abs(frames[:, 2, :2, 3] - fk(LINKS, q)).max() < 1e-12
    assert np.abs(frames[:, 2, 2, 3]).max() < 1e-15   # planar
    # the folded pose: link 1 up +y0, link 2 back down it
    assert np.allclose(fk(LINKS, np.zeros(2)), [0.0, LINKS.l1 - LINKS.l2], atol=1e-15)
    frames = mdh_frames(LINKS, np.zeros(2))
    assert np.allclose(frames[0, :3, 0], [0, 1, 0], atol=1e-15)     # link 1 along +y0
    assert np.allclose(frames[1, :3, 0], [0, -1, 0], atol=1e-15)    # link 2 back down


@pytest.mark.parametrize("elbow", [1, -1])
def test_fk_ik_round_trip_on_both_branches(elbow):
    q, _ = random_states(200)
    q[:, 1] = elbow * np.abs(np.remainder(q[:, 1], 2 * np.pi) - np.pi).clip(0.05, np.pi - 0.05)
    p = fk(LINKS, q)
    q_back = ik(LINKS, p, elbow)
    assert np.abs(fk(LINKS, q_back) - p).max() < 1e-12
    assert np.abs(np.remainder(q_back - q + np.pi, 2 * np.pi) - np.pi).max() < 1e-9


def test_jacobian_matches_finite_differences_and_its_determinant():
    q, qd = random_states(50)
    h = 1e-6
    numeric = np.stack([(fk(LINKS, q + h * e) - fk(LINKS, q - h * e)) / (2 * h) for e in np.eye(2)], axis=-1)
    J = jacobian(LINKS, q)
    assert np.abs(J - numeric).max() < 1e-9
    assert np.allclose(np.linalg.det(J), -LINKS.l1 * LINKS.l2 * np.sin(q[:, 1]), atol=1e-14)
    # ẍ = J θ̈ + J̇ θ̇: against a finite difference of J(θ(t)) θ̇(t) along θ(t) = q + qd t + qdd t²/2
    qdd = RNG.normal(0, 1, q.shape)
    velocity = lambda s: (jacobian(LINKS, q + qd * s + qdd * s * s / 2) @ (qd + qdd * s)[..., None])[..., 0]  # noqa: E731
    assert np.abs(hand_acceleration(LINKS, q, qd, qdd) - (velocity(h) - velocity(-h)) / (2 * h)).max() < 1e-6


def test_mass_matrix_is_symmetric_positive_definite():
    q, _ = random_states(500)
    M = mass_matrix(LINKS, q)
    assert np.allclose(M, np.swapaxes(M, -1, -2))
    assert (np.linalg.eigvalsh(M) > 0).all()


def _symbolic() -> tuple:
    """θ, θ̇ as CasADi symbols and M, V, G of the model as expressions of them (exact derivatives by AD)."""
    q, w = ca.SX.sym("q", 2), ca.SX.sym("w", 2)
    m11, m12, m22, v1, v2, g1, g2 = dynamics_terms(LINKS, q[0], q[1], w[0], w[1], ca)
    return q, w, ca.vertcat(ca.horzcat(m11, m12), ca.horzcat(m12, m22)), ca.vertcat(v1, v2), ca.vertcat(g1, g2)


def _max_at_random_states(q, w, expression) -> float:
    f = ca.Function("f", [q, w], [expression])
    qs, ws = random_states(100)
    return max(float(np.abs(f(a, b).full()).max()) for a, b in zip(qs, ws, strict=True))


def test_coriolis_is_the_christoffel_term_and_mdot_minus_2c_is_skew():
    q, w, M, V, _ = _symbolic()
    # Christoffel symbols of the first kind: C_ij = Σ_k ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) w_k
    dM = [ca.jacobian(M[:, :], q[k]).reshape((2, 2)) for k in range(2)]   # ∂M/∂q_k

    def c(i: int, j: int):
        return sum(0.5 * (dM[k][i, j] + dM[j][i, k] - dM[i][j, k]) * w[k] for k in range(2))

    C = ca.vertcat(ca.horzcat(c(0, 0), c(0, 1)), ca.horzcat(c(1, 0), c(1, 1)))
    assert _max_at_random_states(q, w, C @ w - V) < 1e-12
    M_dot = sum(dM[k] * w[k] for k in range(2))
    N = M_dot - 2 * C
    assert _max_at_random_states(q, w, N + N.T) < 1e-12


def test_gravity_is_the_gradient_of_the_potential():
    q, w, _, _, G = _symbolic()
    P = LINKS.gravity * (LINKS.m1 * LINKS.lc1 * ca.cos(q[0])
                         + LINKS.m2 * (LINKS.l1 * ca.cos(q[0]) - LINKS.lc2 * ca.cos(q[0] + q[1])))
    assert _max_at_random_states(q, w, ca.gradient(P, q) - G) < 1e-12
    qs, _ = random_states(20)
    assert np.allclose(potential_energy(LINKS, qs), [float(ca.Function("P", [q], [P])(x)) for x in qs], atol=1e-12)


def test_static_gravity_values():
    g, p = LINKS.gravity, LINKS
    G = gravity_torque(LINKS, np.radians([90.0, 180.0]))   # arm horizontal, extended
    assert np.allclose(G, [-g * (p.m1 * p.lc1 + p.m2 * p.l1 + p.m2 * p.lc2), -g * p.m2 * p.lc2], atol=1e-12)
    for q in ([0.0, 0.0], [0.0, 180.0]):                     # arm vertical
        assert np.abs(gravity_torque(LINKS, np.radians(q))).max() < 1e-12
    # holding θ with τ = G(θ): no acceleration
    model = PlantModel.of(LINKS, Drive(100, (1.81e-5, 0.925e-5), (0.0, 0.0), 0.01, (40, 25)),
                          HandLoad(0.0, 0.0, 0.0, 0.0))
    q, _ = random_states(20)
    tau = gravity_torque(LINKS, q)
    acc = joint_accelerations(model, q[:, 0], q[:, 1], 0 * q[:, 0], 0 * q[:, 1], tau[:, 0], tau[:, 1], np)
    assert np.abs(np.stack(acc)).max() < 1e-12


def test_a_point_mass_at_the_hand_is_m_jt_j_and_its_weight():
    m = 5.59
    q, qd = random_states(50)
    loaded = LINKS.with_point_mass(m)
    J = jacobian(LINKS, q)
    assert np.abs(mass_matrix(loaded, q) - mass_matrix(LINKS, q) - m * np.swapaxes(J, -1, -2) @ J).max() < 1e-12
    weight = (np.swapaxes(J, -1, -2) @ np.array([0.0, m * LINKS.gravity]))
    assert np.abs(gravity_torque(loaded, q) - gravity_torque(LINKS, q) - weight).max() < 1e-12
    # V: the point mass's m Jᵀ J̇ θ̇
    h = 1e-6
    J_dot = (jacobian(LINKS, q + h * qd) - jacobian(LINKS, q - h * qd)) / (2 * h)
    extra = m * (np.swapaxes(J, -1, -2) @ (J_dot @ qd[..., None]))[..., 0]
    assert np.abs(coriolis(loaded, q, qd) - coriolis(LINKS, q, qd) - extra).max() < 1e-7


def test_energy_is_conserved_without_torque_friction_and_damping():
    model = PlantModel.of(LINKS, Drive(100, (1.81e-5, 0.925e-5), (0.0, 0.0), 0.01, (40, 25)),
                          HandLoad(4.99, 0.6, 0.0, 0.0))
    links, armature = model.links, np.diag(model.armature)

    def rate(t, x):
        return [x[2], x[3], *joint_accelerations(model, x[0], x[1], x[2], x[3], 0.0, 0.0)]

    def energy(x):
        q, qd = x[:2], x[2:]
        return 0.5 * qd @ (mass_matrix(links, q) + armature) @ qd + potential_energy(links, q)

    x0 = np.array([0.3, 1.2, 0.5, -1.0])
    sol = integrate.solve_ivp(rate, (0, 2.0), x0, method="DOP853", rtol=1e-12, atol=1e-12)
    e = np.array([energy(x) for x in sol.y.T])
    assert abs(sol.y[0, -1] - x0[0]) > 0.1                      # it did move
    assert np.abs(e - e[0]).max() / abs(e[0]) < 1e-8

"""SRC joint model and manipulator kinematics (Secs. II, III-A) against independent references: SciPy rotations,
the printed quaternion ODE, the exact rolling integrator, the mirror symmetry of equal spheres, finite
differences and the rolling pivot form of the Jacobian."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from pipeline.papers.src_joint import Chain, ModelForm, RollingChain, quaternion_error, rotation
from pipeline.papers.src_joint import trolley as tr
from pipeline.papers.src_joint.model import CORRECTED, qconj, qexp, qmul, quaternion_of

RNG = np.random.default_rng(3)
PRINTED_RADIUS = ModelForm(radius_convention="printed")


def unit(q):
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def angle_between(Ra, Rb):
    return np.linalg.norm(Rotation.from_matrix(Ra.T @ Rb).as_rotvec())


def random_inputs(steps, joints, scale=0.2):
    """A smooth, time-varying tangent-plane rate per joint: the rolling direction keeps turning."""
    t = np.arange(steps)[:, None, None] * 0.01
    phase = RNG.uniform(0, 2 * np.pi, (1, joints, 2))
    return scale * np.sin(0.7 * t + phase) + 0.5 * scale * np.cos(0.23 * t + 2 * phase)


def roll_both(radii, inputs, form=CORRECTED, dt=0.01):
    model, plant = Chain(radii, form), RollingChain(radii)
    for rates in inputs:
        model.roll(rates, dt)
        plant.roll(rates, dt)
    return model, plant


def test_rotation_matrix_eq74_and_tangent_frame_eqs75_77():
    q = unit(RNG.normal(size=(50, 4)))
    assert np.allclose(rotation(q), Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix(), atol=1e-14)
    chain = Chain([0.04, 0.03], q2=q[:1])
    eta, (e1, e2, e3) = q[0, 0], q[0, 1:]
    f1 = [1 - 2 * (e2 ** 2 + e3 ** 2), 2 * (e1 * e2 - eta * e3), 2 * (e1 * e3 + eta * e2)]    # eq. (75)
    f2 = [2 * (e1 * e2 + eta * e3), 1 - 2 * (e1 ** 2 + e3 ** 2), 2 * (e2 * e3 - eta * e1)]    # eq. (76)
    f3 = [2 * (e1 * e3 - eta * e2), 2 * (e2 * e3 + eta * e1), 1 - 2 * (e1 ** 2 + e2 ** 2)]    # eq. (77)
    assert np.allclose(chain.tangent_frames()[0], np.column_stack([f1, f2, f3]), atol=1e-14)
    assert np.allclose(quaternion_of(rotation(q)), np.where(q[:, :1] < 0, -q, q), atol=1e-12)


def test_joint_update_solves_the_printed_quaternion_ode_eq2():
    omega = np.array([-0.3, 0.7, 0.0])

    def ode(_, q):  # eq. (2)
        eta, eps = q[0], q[1:]
        return np.r_[-0.5 * omega @ eps, 0.5 * (eta * omega - np.cross(eps, omega))]

    q0 = unit(RNG.normal(size=4))
    ref = solve_ivp(ode, (0, 5), q0, rtol=1e-12, atol=1e-12).y[:, -1]
    chain = Chain([0.03, 0.03], q1=q0[None])
    chain.roll(omega[None, :2], 5.0)
    assert np.allclose(chain.q1[0], ref, atol=1e-9)


def test_corrected_model_equals_exact_rolling_and_printed_does_not():
    radii = [0.04, 0.03]                      # Sec. V-A
    inputs = random_inputs(3000, 1)
    model, plant = roll_both(radii, inputs)
    pos_m, rot_m = model.frames()
    pos_p, rot_p = plant.frames()
    assert np.degrees(angle_between(rot_m[1], rot_p[1])) < 1e-9
    assert np.linalg.norm(pos_m[1] - pos_p[1]) < 1e-12
    printed, _ = roll_both(radii, inputs, PRINTED_RADIUS)
    assert np.degrees(angle_between(printed.frames()[1][1], rot_p[1])) > 1.0
    # the literal whole-displacement eq. (5) is exact only while the rolling direction stays put
    literal, _ = roll_both(radii, inputs, ModelForm(joint_update="global"))
    assert np.degrees(angle_between(literal.frames()[1][1], rot_p[1])) > 1.0
    straight = np.tile([[-0.1, -0.05]], (3000, 1, 1))
    literal, plant = roll_both(radii, straight, ModelForm(joint_update="global"))
    assert np.degrees(angle_between(literal.frames()[1][1], plant.frames()[1][1])) < 1e-9


def roll_contact_to(chain: Chain, normal: np.ndarray) -> None:
    """One straight trolley run of 1 s, planned by eqs. (53)-(55), taking joint 1's contact normal to `normal`."""
    target = np.tile(np.eye(3), (1, 1, 1))
    target[0, :, 2] = normal
    lower, upper = chain.radii[:1], chain.radii[1:2]
    arc, heading = tr.position_plan(chain.tangent_frames(), target, lower)
    chain.move(tr.joint_velocity(arc, heading, tr.equivalent_radius(lower, upper)), 1.0)


def test_rolling_while_steering_is_integrated_exactly():
    """One step of a trolley that turns while it drives equals many small steps of the same motion."""
    radii = [0.04, 0.03, 0.05]
    rates, turn = np.array([[0.3, -0.5], [-0.2, 0.4]]), np.array([2.0, -3.0])
    one, fine = RollingChain(radii), RollingChain(radii)
    one.roll(rates, 0.2, turn)
    steps = 20000
    for k in range(steps):
        heading = turn * (k + 0.5) * 0.2 / steps            # Ω^B turns about the normal at the trolley's rate
        c, s = np.cos(heading), np.sin(heading)
        fine.roll(np.stack([c * rates[:, 0] - s * rates[:, 1], s * rates[:, 0] + c * rates[:, 1]], -1), 0.2 / steps)
    assert np.allclose(one.relative, fine.relative, atol=1e-9) and np.allclose(one.tangent, fine.tangent, atol=1e-9)


def test_equal_spheres_behave_as_an_ordinary_joint():
    """Equal radii: B_i is B_{i-1}'s mirror image in the tangent plane, R(q_i) = Rot(e_z × n, 2∠(e_z, n)),
    whatever the path — the joint's pose depends on its configuration only. Unequal radii do not."""
    chain = Chain([0.034, 0.034])
    for rates in random_inputs(2000, 1, scale=1.0):
        chain.roll(rates, 0.01)
    q = chain.joint_quaternions()[0]
    n = chain.tangent_frames()[0][:, 2]
    axis = np.cross([0, 0, 1], n)
    mirror = Rotation.from_rotvec(axis / np.linalg.norm(axis) * 2 * np.arccos(n[2])).as_matrix()
    assert abs(q[3]) < 1e-12 and np.allclose(rotation(q), mirror, atol=1e-12)
    assert np.allclose(chain.frames()[0][1], 0.068 * n, atol=1e-15)
    # the contact point around a spherical triangle and back: no net rotation for equal spheres,
    # a net twist about the normal for unequal ones (the joint is then nonholonomic)
    for radii, twisted in (([0.034, 0.034], False), ([0.04, 0.03], True)):
        c = Chain(radii)
        for corner in ([np.sin(0.8), 0.0, np.cos(0.8)], [0.0, np.sin(0.8), np.cos(0.8)], [0.0, 0.0, 1.0]):
            roll_contact_to(c, np.array(corner))
        net = np.degrees(angle_between(np.eye(3), rotation(c.joint_quaternions()[0])))
        assert np.allclose(c.tangent_frames()[0][:, 2], [0, 0, 1], atol=1e-12)
        assert (net > 1.0) if twisted else (net < 1e-9)
    # the printed and corrected forms are the same joint when the spheres are equal
    inputs = random_inputs(500, 2)
    a, _ = roll_both([0.034] * 3, inputs)
    b, _ = roll_both([0.034] * 3, inputs, PRINTED_RADIUS)
    assert np.allclose(a.joint_quaternions(), b.joint_quaternions(), atol=1e-14)


def configured_chain(radii, form=CORRECTED):
    chain = Chain(radii, form)
    for rates in random_inputs(300, len(radii) - 1, scale=1.5):
        chain.roll(rates, 0.01)
    return chain


@pytest.mark.parametrize("radii", [[0.034] * 4, [0.034] * 5, [0.05, 0.03, 0.045, 0.02]])
def test_jacobian_equals_finite_differences_and_the_rolling_pivot_form(radii):
    chain = configured_chain(radii)
    n = chain.n
    J = chain.jacobian()
    pos, rot = chain.frames()
    h, J_fd = 1e-6, np.zeros_like(J)
    for j in range(2 * n):
        w = np.zeros(2 * n)
        w[j] = 1.0
        plus, minus = chain.copy(), chain.copy()
        plus.move(w.reshape(n, 2), h)
        minus.move(-w.reshape(n, 2), h)
        (pp, rp), (pm, rm) = plus.frames(), minus.frames()
        dR = (rp[-1] - rm[-1]) / (2 * h) @ rot[-1].T
        J_fd[:, j] = np.r_[(pp[-1] - pm[-1]) / (2 * h), dR[2, 1], dR[0, 2], dR[1, 0]]
    assert np.abs(J - J_fd).max() < 1e-8
    # a joint velocity turns everything above the joint about its contact point p_i
    F = chain.tangent_frames()
    for i in range(n):
        contact = pos[i] + radii[i] * rot[i] @ F[i, :, 2]
        axes = rot[i] @ F[i, :, :2]
        assert np.allclose(J[:3, 2 * i:2 * i + 2], np.cross(axes.T, pos[-1] - contact).T, atol=1e-15)
        assert np.allclose(axes.T @ axes, np.eye(2), atol=1e-14)   # J_ω blocks: orthonormal pairs
    # the sign of Table I's free modes breaks the linear Jacobian
    printed = Chain(radii, ModelForm(free_mode_sign="printed"), chain.q1, chain.q2)
    assert np.abs(printed.jacobian()[:3] - J_fd[:3]).max() > 1e-3


def test_free_modes_give_the_centre_velocity_of_rolling():
    """Φ_i w of eq. (8) is the velocity of B_i's centre relative to B_{i-1}: b ω × n (contact point at rest)."""
    radii = [0.04, 0.03]
    chain = configured_chain(radii)
    w = np.array([0.3, -0.8])
    nu = chain.free_modes()[0] @ w
    F = chain.tangent_frames()[0]
    omega = F[:, :2] @ w
    assert np.allclose(nu[:3], omega, atol=1e-15)
    assert np.allclose(nu[3:], radii[1] * np.cross(omega, F[:, 2]), atol=1e-15)
    assert np.allclose(chain.free_modes()[0][3:, 0], -radii[1] * F[:, 1])   # w = (1, 0): centre along −f2


def test_forward_kinematics_invariants():
    radii = np.array([0.05, 0.03, 0.045, 0.02])
    chain = configured_chain(radii)
    pos, rot = chain.frames()
    assert np.allclose(np.linalg.norm(np.diff(pos, axis=0), axis=1), radii[:-1] + radii[1:], atol=1e-15)
    assert np.allclose(rotation(chain.orientation()), rot[-1], atol=1e-14)   # eq. (17)


def test_quaternion_error_eq47_is_the_vector_part_of_the_relative_rotation():
    q, qd = unit(RNG.normal(size=4)), unit(RNG.normal(size=4))
    assert np.allclose(quaternion_error(q, qd), qmul(qd, qconj(q))[1:], atol=1e-15)
    assert np.allclose(quaternion_error(qd, qd), 0.0, atol=1e-15)
    assert np.allclose(qmul(qexp(np.array([0.0, 0.0, np.pi])), qexp(np.array([0.0, 0.0, np.pi])))[0], -1.0)

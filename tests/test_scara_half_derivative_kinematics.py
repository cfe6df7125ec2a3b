"""scara-half-derivative: kinematics (eqs. 3-7), spring balance (eqs. 12-13) and the set-point generator
against closed-form values (spec §8 checks 1, 2, 6)."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.core.checks import compose_config
from pipeline.papers.scara_half_derivative.arm import (
    end_effector,
    fk,
    fk_jacobian,
    gravity_torque,
    ik,
    jacobian,
    link_frames,
    potential_energy,
)
from pipeline.papers.scara_half_derivative.experiments import arm_of, home, motion_of
from pipeline.robotics.profiles import trapezoid


@pytest.fixture(scope="module")
def cfg():
    return compose_config(["experiment=scara-half-derivative/table2"])


@pytest.fixture(scope="module")
def arm(cfg):
    return arm_of(cfg)


def test_reference_pose_and_spring_balance(cfg, arm):
    np.testing.assert_allclose(fk(arm, home(cfg)), [0.466690, 0.0, 0.513, 0.0], atol=5e-7)   # Table 1 x_ref
    assert np.rad2deg(arm.theta3p) == pytest.approx(-15.0, abs=0.01)                         # eq. (13), Table 1
    assert gravity_torque(arm, 0.0) == pytest.approx(0.0, abs=1e-12)                         # balanced at θ3 = 0
    assert arm.moment == pytest.approx(6.6)
    theta3 = np.linspace(-0.6, 0.6, 7)   # τ_g,3 = dV/dθ3 (eq. 12 is the gradient of gravity + spring)
    numeric = (potential_energy(arm, theta3 + 1e-6) - potential_energy(arm, theta3 - 1e-6)) / 2e-6
    np.testing.assert_allclose(gravity_torque(arm, theta3), numeric, atol=1e-6)
    # spec §2.3: with E lowered by 0.15 m (θ3 = +27.04°) the compensation torque is +123.8 Nm, raised −109.6 Nm
    t3 = np.arcsin(0.15 / arm.l3)
    assert gravity_torque(arm, t3) == pytest.approx(123.8, abs=0.1)
    assert gravity_torque(arm, -t3) == pytest.approx(-109.6, abs=0.1)


def test_jacobian_is_the_derivative_of_fk(arm):
    rng = np.random.default_rng(1)
    for q in rng.uniform(-1.2, 1.2, (5, 4)):
        numeric = np.stack([(fk(arm, q + 1e-6 * e) - fk(arm, q - 1e-6 * e)) / 2e-6 for e in np.eye(4)], axis=1)
        np.testing.assert_allclose(jacobian(arm, q), numeric, atol=1e-8)
        x, J = fk_jacobian(arm, q)   # the controller's single-pose form equals the batched one
        np.testing.assert_array_equal(x, fk(arm, q))
        np.testing.assert_allclose(J, jacobian(arm, q), atol=1e-15)


def test_fk_equals_the_link_chain(arm):
    """Eqs. (3)-(6) and the link frames composed joint by joint put E at the same point."""
    q = np.random.default_rng(2).uniform(-1.2, 1.2, (50, 4))
    np.testing.assert_allclose(end_effector(arm, link_frames(arm, q)), fk(arm, q)[:, :3], atol=1e-15)


def test_ik_round_trips_on_the_whole_motion(cfg, arm):
    motion = motion_of(cfg, arm)
    x_d = motion(np.arange(0.0, motion.duration, 1e-3))[0]
    q = ik(arm, x_d)
    np.testing.assert_allclose(fk(arm, q), x_d, atol=1e-12)
    np.testing.assert_allclose(ik(arm, fk(arm, q)), q, atol=1e-12)
    assert np.rad2deg(q[:, 1].min()) == pytest.approx(41.7, abs=0.05)          # +x extreme (spec §4)
    assert np.rad2deg(np.abs(q[:, 2]).max()) == pytest.approx(27.04, abs=0.01)  # ±z extremes


def test_setpoint_generator(cfg, arm):
    motion = motion_of(cfg, arm)
    assert motion.duration == pytest.approx(15.6)
    assert motion.v_max == pytest.approx(0.625) and motion.a_max == pytest.approx(10.41667, rel=1e-5)
    dt = 1e-4
    t = np.arange(0.0, motion.duration + dt / 2, dt)
    x, v, a = motion(t)
    assert np.abs(v).max() == pytest.approx(0.625, rel=1e-9)
    assert set(np.round(np.unique(np.abs(a[:, :3])), 6)) == {0.0, 10.416667}   # piecewise constant
    np.testing.assert_allclose(x[0], x[-1], atol=1e-15)                        # back to x_ref
    assert np.abs(np.diff(x, axis=0)).max() <= 0.625 * dt * (1 + 1e-9)       # continuous position
    assert np.abs(np.diff(v, axis=0)).max() <= 10.42 * dt                      # continuous velocity
    np.testing.assert_allclose(x[:, 3], 0.0)                                   # constant orientation
    # each move covers d: ∫ v dt over the first move (+x)
    first = t <= motion.t_move
    assert np.trapezoid(v[first, 0], t[first]) == pytest.approx(0.15, rel=1e-6)
    # the phases in order: +x, +y, +z, −x, −y, −z, each reached after t_mov and held for t_stop
    phase = 2 * (motion.t_move + motion.t_stop)
    held = [motion(k * phase + motion.t_move + 0.5)[0][0, :3] - motion.home[:3] for k in range(6)]
    np.testing.assert_allclose(held, 0.15 * np.asarray(cfg.system.motion.directions), atol=1e-15)


def test_trapezoid_profile():
    t = np.linspace(-0.1, 1.1, 1201)
    s, v, a = trapezoid(t, 2.0, 1.0, 0.25)
    assert s[0] == 0 and s[-1] == 2.0 and v.max() == pytest.approx(2.0 / 0.75)
    assert np.trapezoid(a, t) == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError):
        trapezoid(t, 1.0, 1.0, 0.6)


def test_mujoco_model_is_the_same_arm(arm):
    """The attached MJCF (what a viewer draws) is the arm: its bodies at link_frames, E at eq. (3)-(6), the
    parallelogram's constraint closed, and its mass matrix and holding torque (gravity and spring, reduced by
    the loop map) equal to the link model's and eq. (12)."""
    import mujoco

    from pipeline.papers.scara_half_derivative import mujoco_model
    from pipeline.papers.scara_half_derivative.arm import LINKS, gravity_torque, mass_matrix_from_links

    model = mujoco.MjModel.from_xml_string(mujoco_model.model_xml(arm))
    data = mujoco.MjData(model)
    assert tuple(model.joint(j).name for j in range(model.njnt)) == mujoco_model.QPOS_JOINTS
    bodies = [model.body(name).id for name in LINKS]
    loop = mujoco_model.qpos(np.eye(4))   # (4, 6): d qpos / d θ
    M = np.zeros((model.nv, model.nv))
    for q in np.random.default_rng(4).uniform(-1.2, 1.2, (6, 4)):
        data.qpos[:] = mujoco_model.qpos(q)
        mujoco.mj_forward(model, data)
        frames = link_frames(arm, q)
        np.testing.assert_allclose(data.xpos[bodies], frames[:, :3, 3], atol=1e-12)
        np.testing.assert_allclose(data.xmat[bodies].reshape(-1, 3, 3), frames[:, :3, :3], atol=1e-12)
        np.testing.assert_allclose(data.site("E").xpos, fk(arm, q)[:3], atol=1e-12)
        np.testing.assert_allclose(data.efc_pos[:data.ne], 0.0, atol=1e-12)
        mujoco.mj_fullM(model, data, M)
        np.testing.assert_allclose(loop @ M @ loop.T, mass_matrix_from_links(arm, q), rtol=1e-9, atol=1e-12)
        holding = loop @ (data.qfrc_bias - data.qfrc_passive)
        np.testing.assert_allclose(holding, [0, 0, gravity_torque(arm, q[2]), 0], atol=1e-9)

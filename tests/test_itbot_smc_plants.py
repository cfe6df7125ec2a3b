"""itbot-smc's two plants agree (check 4 of the reproduction plan): the MJCF generated from the paper's
parameters has the mass matrix and bias forces of eqs. (A8)-(A10) with the drive's armature and the hand
load, the two swing alike open loop, and MuJoCo's force sensor reads the analytic hand force."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pipeline.core.checks import compose_config
from pipeline.papers.itbot_smc.experiments import Setup
from pipeline.papers.itbot_smc.model import coriolis, gravity_torque, jacobian, mass_matrix
from pipeline.papers.itbot_smc.mujoco_arm import MujocoPlant, arm_mjcf
from pipeline.papers.itbot_smc.plants import AnalyticPlant, Drive, HandLoad

mujoco = pytest.importorskip("mujoco")

RNG = np.random.default_rng(3)


@pytest.fixture(scope="module")
def setup() -> Setup:
    return Setup.of(compose_config(["experiment=itbot-smc/tracking"]).system)


def _mjcf(setup: Setup, drive: Drive, load: HandLoad, timestep: float, configuration: str = "vertical") -> str:
    s = setup.system
    return arm_mjcf(setup.links, drive, load, configuration=configuration, drawing=s.drawing, z2=float(s.links.z2),
                    joint_limits=None, timestep=timestep, gravity=float(s.gravity))


@pytest.mark.parametrize("configuration", ["vertical", "horizontal"])
def test_mass_matrix_and_bias_forces_equal_the_paper_model(setup, configuration):
    links = setup.links if configuration == "vertical" else dataclasses.replace(setup.links, gravity=0.0)
    model = mujoco.MjModel.from_xml_string(_mjcf(setup, setup.drive, setup.load, 1e-3, configuration))
    data = mujoco.MjData(model)
    loaded = links.with_point_mass(setup.load.mass)
    for _ in range(20):
        q, qd = RNG.uniform(-np.pi, np.pi, 2), RNG.normal(0, 2, 2)
        data.qpos[:], data.qvel[:] = q, qd
        mujoco.mj_forward(model, data)
        M = np.zeros((2, 2))
        mujoco.mj_fullM(model, data, M)
        assert np.abs(M - mass_matrix(loaded, q) - np.diag(setup.drive.armature)).max() < 1e-9   # 1e-10 point inertia
        assert np.abs(data.qfrc_bias - coriolis(loaded, q, qd) - gravity_torque(loaded, q)).max() < 1e-11


def _swing(setup: Setup) -> tuple:
    drive = Drive(setup.drive.gear_ratio, setup.drive.rotor_inertia, (0.0, 0.0), 0.01, (1e3, 1e3))
    q0, qd0, tau = np.array([0.3, 1.2]), np.array([0.5, -1.0]), (3.0, -1.0)
    return drive, q0, qd0, tau


def test_the_plants_swing_alike_open_loop(setup):
    """A free swing under a constant torque and the subject's constant support, without friction or damping:
    MuJoCo's RK4 and the analytic plant's RK4 at 1 ms agree to round-off over 1 s."""
    load = HandLoad(setup.load.weight, setup.load.arm, damping=0.0, support=0.4)
    drive, q0, qd0, tau = _swing(setup)
    analytic = AnalyticPlant(setup.links, drive, load, 1e-3, 1, q0, qd0)
    model = mujoco.MjModel.from_xml_string(_mjcf(setup, drive, load, 1e-3).replace(
        'integrator="implicitfast"', 'integrator="RK4"'))
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:], data.ctrl[:] = q0, qd0, tau
    hand = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hand")
    data.xfrc_applied[hand, 2] = load.support * load.mass * 9.81      # +y0 is world +z (vertical configuration)
    gap = 0.0
    for _ in range(1000):
        analytic.advance(tau)
        mujoco.mj_step(model, data)
        gap = max(gap, np.abs(np.subtract(analytic.state()[0], data.qpos)).max())
    assert np.abs(np.subtract(analytic.state()[0], q0)).max() > 0.5   # it swung
    assert gap < 1e-8                                                  # rad (MuJoCo's 1e-10 point inertia)


def test_the_pipeline_mujoco_plant_converges_to_the_analytic_one(setup):
    """The pipeline's MuJoCo plant (semi-implicit Euler): its gap to the analytic plant over 0.3 s of the swing
    shrinks in proportion to its step (first order). (The subject's damping, held per tick in MuJoCo, adds a gap
    of the order of the control period; the force-sensor test covers it at one state.)"""
    load = HandLoad(setup.load.weight, setup.load.arm, damping=0.0, support=0.4)
    drive, q0, qd0, tau = _swing(setup)
    gaps = []
    for step in (1e-4, 1e-5):
        analytic = AnalyticPlant(setup.links, drive, load, 1e-3, 10, q0, qd0)
        mj = MujocoPlant(_mjcf(setup, drive, load, step), setup.links, load, "vertical", 1e-3, q0, qd0)
        gap = 0.0
        for _ in range(300):
            analytic.advance(tau)
            mj.advance(tau)
            gap = max(gap, np.abs(np.subtract(analytic.state()[0], mj.state()[0])).max())
        gaps.append(gap)
    assert gaps[1] < 5e-5 and 8 < gaps[0] / gaps[1] < 12


def test_the_force_sensor_reads_the_hand_force(setup):
    """At the same state and torque, MuJoCo's force sensor (link 2 on the hand body) is the analytic
    m_L (g⃗ − ẍ) − b ẋ + s m_L g ŷ."""
    load = HandLoad(setup.load.weight, setup.load.arm, damping=5.0, support=0.3)
    drive = Drive(setup.drive.gear_ratio, setup.drive.rotor_inertia, (0.0, 0.0), 0.01, (1e3, 1e3))
    q, qd = np.array([[0.2, 1.4], [-0.5, 2.0], [0.7, -1.0]]), np.array([[0.5, -1.0], [0.0, 0.0], [-2.0, 1.0]])
    tau = np.array([[3.0, -1.0], [0.0, 0.0], [10.0, 4.0]])
    analytic = AnalyticPlant(setup.links, drive, load, 1e-3, 1, q[0], qd[0])
    expected = analytic.hand_forces(q, qd, tau)
    for k in range(len(q)):
        mj = MujocoPlant(_mjcf(setup, drive, load, 1e-3), setup.links, load, "vertical", 1e-3, q[k], qd[k])
        mj.advance(tau[k])
        assert np.abs(mj.hand_forces(q, qd, tau)[0] - expected[k]).max() < 1e-7   # 1e-10 kg m² point inertia
    # held at rest, the handle carries the share of the load's weight the subject does not
    held = gravity_torque(setup.links.with_point_mass(load.mass), q) - (
        np.swapaxes(jacobian(setup.links, q), -1, -2) @ np.array([0.0, load.support * load.mass * setup.links.gravity]))
    assert np.abs(analytic.hand_forces(q, 0 * qd, held) - [0.0, -(1 - load.support) * load.mass * 9.81]).max() < 1e-9


def test_one_rk4_step_per_period_is_converged(setup):
    """The analytic plant's default (one RK4 step per 1 ms period) against ten, under the exercise's torques
    (nSMERL on the reference, exact states) for 4 s: the joint angles agree to < 1e-5 rad (6e-4°; a sign
    switch flipped by a round-off-sized difference now and then)."""
    from pipeline.papers.itbot_smc.closed_loop import Reference, run_closed_loop

    reference = Reference(setup.reference.start, setup.reference.amplitude, 4.0, 1)
    runs = [run_closed_loop(setup.plant("analytic", n), setup.controller("nsmerl"), setup.sensor(), reference,
                            setup.period, setup.drive.torque_limit) for n in (1, 10)]
    assert np.abs(runs[0].q - runs[1].q).max() < 1e-5


def test_tf_frames_are_the_mujoco_body_frames(setup):
    """What /tf publishes (the MDH frames placed in the world) is where MuJoCo has the bodies the /markers
    entities are attached to, so the robot draws right in Foxglove."""
    from pipeline.papers.itbot_smc.experiments import TF_FRAMES, frames_in_world

    model = mujoco.MjModel.from_xml_string(setup.mjcf())
    data = mujoco.MjData(model)
    q = RNG.uniform(-1.4, 1.4, (5, 2))
    frames = frames_in_world(setup, q, np.zeros(len(q)))
    for k in range(len(q)):
        data.qpos[:] = q[k]
        mujoco.mj_kinematics(model, data)
        for i, name in enumerate(TF_FRAMES[:4]):
            body = model.body(name).id
            assert np.allclose(frames[k, i, :3, 3], data.xpos[body], atol=1e-12), name
            assert np.allclose(frames[k, i, :3, :3], data.xmat[body].reshape(3, 3), atol=1e-12), name

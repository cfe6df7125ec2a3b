"""The generated MuJoCo Iron Dog Mini against independent models (spec §8.3-§8.5): its mass against Table 2, its
feet against the closed-form FK, the standing servo torques and foot loads against the hand statics, the servo's
saturation and no-load speed against their closed forms, and a fall reported as a failure."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
import yaml

from pipeline.core.experiment import CONF_DIR
from pipeline.papers.quadruped_irondog import kinematics as kin
from pipeline.papers.quadruped_irondog.model import GRAVITY, Indices, Robot, Scene, mjcf
from pipeline.papers.quadruped_irondog.simulation import Fall, Plant, quat_rpy, simulate
from pipeline.papers.quadruped_irondog.statics import static_torques

SYSTEM = yaml.safe_load((CONF_DIR / "system/quadruped-irondog.yaml").read_text())
ROBOT = Robot.from_config(SYSTEM)
STAND = np.tile(np.radians([0.0, -45.0, 90.0]), (4, 1))
FALL = Fall(0.08, np.radians(45))


def test_mass_is_table2s_total():
    model = mujoco.MjModel.from_xml_string(mjcf(ROBOT))
    assert mujoco.mj_getTotalmass(model) == pytest.approx(2.5722, abs=1e-12) == ROBOT.mass
    with_payload = mujoco.MjModel.from_xml_string(mjcf(ROBOT, Scene(payload=7.5)))
    assert mujoco.mj_getTotalmass(with_payload) == pytest.approx(10.0722, abs=1e-12)


def test_feet_match_the_closed_form_fk_for_any_trunk_pose():
    model = mujoco.MjModel.from_xml_string(mjcf(ROBOT))
    data = mujoco.MjData(model)
    idx = Indices.of(model)
    rng = np.random.default_rng(2)
    for _ in range(20):
        q = rng.uniform(ROBOT.ranges[:, 0], ROBOT.ranges[:, 1], (4, 3))
        rpy = rng.uniform(-0.5, 0.5, 3)
        R = kin.rpy_matrix(rpy)
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, R.ravel())
        data.qpos[:7] = [*rng.uniform(-1, 1, 3), *quat]
        data.qpos[idx.qpos] = q.ravel()
        mujoco.mj_kinematics(model, data)
        expected = data.qpos[:3] + kin.feet_in_body(ROBOT.leg, ROBOT.layout, q) @ R.T
        assert np.abs(data.site_xpos[idx.feet] - expected).max() < 1e-12
        assert np.allclose(quat_rpy(data.qpos[3:7]), rpy)


def test_standing_torques_and_loads_match_the_hand_statics():
    plant = Plant(ROBOT, Scene())
    plant.place(STAND)
    trace = simulate(plant, lambda t, rpy: STAND, 2.5, 0.02, 0.01, FALL)
    assert trace.failure is None
    q, rpy = trace.q[-1].reshape(4, 3), trace.rpy[-1]
    tau, loads = static_torques(ROBOT, q, rpy=rpy)
    # N·m, of up to 1.08: the hand statics leave out the feet's small friction forces
    assert np.abs(trace.tau[-1].reshape(4, 3) - tau).max() < 0.01
    assert np.abs(trace.contact_force[-1, :, 2] - loads).max() < 0.01              # N, of 4-9
    assert trace.contact_force[-1, :, 2].sum() == pytest.approx(ROBOT.mass * GRAVITY, rel=1e-4)
    assert np.abs(trace.qd[-1]).max() < 1e-3 and (trace.contact[-1] == 1).all()
    # symmetric robot: the left and right legs carry alike, the rear legs more (feet 35 mm ahead of the hips)
    assert np.allclose(loads[0], loads[1]) and np.allclose(loads[2], loads[3]) and loads[2] > loads[0]


def test_servo_saturates_at_the_stall_torque_and_runs_at_the_no_load_speed():
    # the trunk welded to the world, no gravity: a leg's joint driven far away accelerates to ω0 = τ_stall / b
    xml = mjcf(ROBOT).replace('<freejoint name="trunk"/>', "").replace('integrator="implicitfast"',
                                                                         'integrator="implicitfast" gravity="0 0 0"')
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    idx = Indices.of(model)
    joint = kin.JOINT_NAMES.index("FR_femur")
    data.ctrl[joint] = ROBOT.ranges[1, 1]
    speed = []
    for _ in range(400):
        mujoco.mj_step(model, data)
        speed.append(data.qvel[idx.dof[joint]])
        assert abs(data.actuator_force[joint]) <= ROBOT.stall_torque + 1e-12
    assert max(speed) == pytest.approx(ROBOT.no_load_speed, rel=0.01)


def test_a_collapse_is_a_failure_with_its_reason():
    plant = Plant(ROBOT, Scene(payload=7.5))
    plant.place(STAND)
    trace = simulate(plant, lambda t, rpy: STAND, 1.0, 0.02, 0.01, FALL)
    assert trace.failure and trace.failure.startswith("fell at t = ") and "BR_tibia" in trace.failure
    assert trace.t[-1] < 1.0                         # stopped where it fell, the trace kept up to there
    tau, _ = static_torques(ROBOT, STAND, payload=7.5)
    assert np.abs(tau).max() > ROBOT.stall_torque     # the hand statics say why: the rear tibias need more


def test_the_bench_tilts_the_ground():
    plant = Plant(ROBOT, Scene(platform=True))
    plant.place(STAND)
    tilt = np.radians(9.0)
    trace = simulate(plant, lambda t, rpy: STAND, 2.0, 0.02, 0.01, FALL,
                     platform=lambda t: np.array([tilt * min(t, 1.0), 0.0]))
    bench = trace.qpos[-1, plant.idx.platform_qpos]
    assert bench[0] == pytest.approx(tilt, abs=2e-3) and abs(bench[1]) < 1e-3
    assert trace.rpy[-1, 1] == pytest.approx(tilt, abs=np.radians(1.5))   # open loop: the trunk tilts with it


def test_an_unreachable_reference_stops_the_run_with_its_reason():
    plant = Plant(ROBOT, Scene())
    plant.place(STAND)
    far = kin.ik(ROBOT.leg, np.tile([ROBOT.leg.L1, -0.4, 0.0], (4, 1)))      # 0.4 m below a 0.29 m leg
    trace = simulate(plant, lambda t, rpy: STAND if t < 0.1 else far, 0.5, 0.02, 0.01, FALL)
    assert trace.failure == "no IK solution at t = 0.10 s: the feet of BL, BR, FL, FR are out of reach"

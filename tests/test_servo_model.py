"""A stage's servo model: runs set their tuned gains on one model instead of compiling their own text, and must
simulate exactly what the text compiles to."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.papers.ur5_ik_fsm import UR5
from pipeline.robotics import dh as dhk
from pipeline.robotics import mjcf

mujoco = pytest.importorskip("mujoco")

DYN = mjcf.ArmDynamics(masses=[3.7, 8.4, 2.3, 1.2, 1.2, 0.2], link_radius=0.04, armature=[0.1] * 6,
                       damping=[0.5] * 6, torque_limit=[150.0] * 6)
DH = dhk.DH.from_config(UR5.dh)
T = np.arange(201) * 1e-3
Q_REF = np.sin(np.outer(T, [1.0, -2.0, 1.5, 3.0, -1.0, 2.0]))
QD_REF = np.gradient(Q_REF, 1e-3, axis=0)


def _arm(kp, kv, *, flange_xml: str = "") -> str:
    return mjcf.serial_arm("ur5", DH, DYN, timestep=1e-3, kp=list(kp), kv=list(kv), flange_xml=flange_xml)


@pytest.mark.parametrize("q0", [np.zeros(6), np.array([0.3, -1.2, 1.0, 0.4, -0.7, 2.0])])
def test_gains_set_on_the_servo_model_simulate_what_the_text_compiles_to(q0):
    mjcf._SERVOS.clear()
    xml = mjcf.with_servo_gains(_arm, q0, 20.0, 1.0)
    assert isinstance(xml, mjcf.ServoMJCF) and mjcf._SERVOS[xml.zero].linear
    served = mjcf.servo_rollout(xml, Q_REF, QD_REF, T)
    model = mjcf._SERVOS[xml.zero].model
    assert np.array_equal(mjcf._saved(model), mjcf._saved(mujoco.MjModel.from_xml_string(str(xml))))
    compiled = mjcf.servo_rollout(str(xml), Q_REF, QD_REF, T)  # a plain text: compiled as it is
    assert all(np.array_equal(a, b) for a, b in zip(served, compiled, strict=True))


def test_a_second_run_gets_its_own_gains_not_the_last_ones():
    mjcf._SERVOS.clear()
    first = mjcf.with_servo_gains(_arm, np.zeros(6), 20.0, 1.0)
    second = mjcf.with_servo_gains(_arm, np.array([0.0, -1.5, 1.5, 0.0, 0.0, 0.0]), 20.0, 1.0)
    assert first.zero == second.zero and not np.array_equal(first.kp, second.kp)
    mjcf.servo_rollout(second, Q_REF, QD_REF, T)
    again = mjcf.servo_rollout(first, Q_REF, QD_REF, T)
    assert all(np.array_equal(a, b) for a, b in zip(again, mjcf.servo_rollout(str(first), Q_REF, QD_REF, T),
                                                     strict=True))


def test_a_text_whose_gains_change_more_than_the_servo_is_compiled_instead():
    def build(kp, kv) -> str:  # the gain also sizes a flange geom: not a linear servo any more
        return _arm(kp, kv, flange_xml=f'<geom type="sphere" size="{0.01 + 1e-6 * kp[0]:.17g}" mass="0.1"/>')

    mjcf._SERVOS.clear()
    xml = mjcf.with_servo_gains(build, np.zeros(6), 20.0, 1.0)
    assert not mjcf._SERVOS[xml.zero].linear
    served = mjcf.servo_rollout(xml, Q_REF, QD_REF, T)
    assert all(np.array_equal(a, b) for a, b in zip(served, mjcf.servo_rollout(str(xml), Q_REF, QD_REF, T),
                                                     strict=True))

"""UR5 forward kinematics, Jacobian and det J: the paper's closed forms against the DH product, finite
differences and MuJoCo's own Jacobian of the model generated from Table 1."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.papers.ur5_ik_fsm import UR5, det_j, fk, jacobian
from pipeline.robotics import dh as dhk
from pipeline.robotics.mjcf import ArmDynamics, serial_arm

RNG = np.random.default_rng(7)
Q = RNG.uniform(-np.pi, np.pi, (200, 6))
DH = dhk.DH.from_config(UR5.dh)


def test_closed_form_fk_equals_dh_product():
    assert np.abs(np.array([fk(q) for q in Q]) - dhk.fk(DH, Q)).max() < 1e-14


def test_printed_fk_misprint_is_wrong_by_centimetres():
    # erratum 1: eqs. (11)-(13) print c234*a3 / s234*a3
    err = np.array([np.linalg.norm(fk(q, printed=True)[:3, 3] - fk(q)[:3, 3]) for q in Q])
    assert np.median(err) > 0.1


def test_jacobian_closed_form_equals_geometric_and_finite_differences():
    J = np.array([jacobian(q) for q in Q[:50]])
    assert np.abs(J - dhk.geometric_jacobian(DH, Q[:50])).max() < 1e-14
    h = 1e-7
    for q, Jq in zip(Q[:10], J[:10], strict=True):
        for i in range(6):
            dq = np.zeros(6)
            dq[i] = h
            T1, T0 = fk(q + dq), fk(q - dq)
            dp = (T1[:3, 3] - T0[:3, 3]) / (2 * h)
            dR = (T1[:3, :3] - T0[:3, :3]) / (2 * h) @ fk(q)[:3, :3].T
            omega = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
            assert np.allclose(Jq[:, i], np.r_[dp, omega], atol=1e-7)


def test_det_eq46_equals_numeric_determinant():
    J = np.array([jacobian(q) for q in Q])
    d = det_j(Q)
    assert np.allclose(np.linalg.det(J), d, rtol=1e-9, atol=1e-15)


def test_threshold_arithmetic_of_sec_2_4():
    # the det J values the paper derives for its zero thresholds, in mm^3
    a2, a3, d5 = UR5.a2 * 1e3, UR5.a3 * 1e3, UR5.d5 * 1e3
    assert 1e-12 * a2 * a3 * (a2 + a3 + d5) == pytest.approx(1.5190e-4, rel=1e-4)
    assert 1e-9 * a2 * a3 == pytest.approx(1.6660e-4, rel=1e-4)


def test_mujoco_model_matches_dh_fk_and_jacobian():
    mujoco = pytest.importorskip("mujoco")
    dyn = ArmDynamics(masses=[1.0] * 6, link_radius=0.04, armature=[0.1] * 6, damping=[0.0] * 6,
                      torque_limit=[100.0] * 6)
    model = mujoco.MjModel.from_xml_string(serial_arm("ur5", DH, dyn, timestep=1e-3, kp=[1.0] * 6, kv=[1.0] * 6))
    data = mujoco.MjData(model)
    site = model.site("flange").id
    jacp, jacr = np.zeros((3, 6)), np.zeros((3, 6))
    for q in Q[:20]:
        data.qpos[:] = q
        mujoco.mj_forward(model, data)
        T = fk(q)
        assert np.allclose(data.site_xpos[site], T[:3, 3], atol=1e-12)
        assert np.allclose(data.site_xmat[site].reshape(3, 3), T[:3, :3], atol=1e-12)
        mujoco.mj_jacSite(model, data, jacp, jacr, site)
        assert np.allclose(np.vstack([jacp, jacr]), jacobian(q), atol=1e-12)

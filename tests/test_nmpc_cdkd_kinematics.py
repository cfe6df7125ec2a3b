"""TX2-90 kinematics of Table 2: the decomposition's identities, IK round trips over all 8 branches, Jacobians
against finite differences, the MuJoCo model against the DH chain, the polynomial's closed-form values, the
quaternion error (11) and the Jacobian-transpose controller's Lyapunov function (14)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import yaml

from pipeline.core.experiment import CONF_DIR
from pipeline.papers.nmpc_cdkd import kinematics as kin
from pipeline.papers.nmpc_cdkd import planning
from pipeline.robotics import dh as dhk
from pipeline.robotics import dh_casadi
from pipeline.robotics.profiles import SEPTIC_PEAKS, septic

SYSTEM = yaml.safe_load((CONF_DIR / "system/nmpc-cdkd.yaml").read_text())
ARM = kin.Arm.from_config(SYSTEM)
RNG = np.random.default_rng(3)
Q = RNG.uniform(ARM.lower, ARM.upper, (300, 6))
TOOL_DOWN = np.diag([-1.0, 1.0, -1.0])


def _pose(p, R=TOOL_DOWN) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def test_table2_geometry():
    # spec §2.2: q = 0 points the arm up; wrist point (50, 50, 850) mm, flange (50, 50, 950) mm in {w}
    F = kin.frames(ARM, np.zeros(6))
    assert np.allclose(F[4, :3, 3], [0.05, 0.05, 0.85], atol=1e-15)
    assert np.allclose(F[6, :3, 3], [0.05, 0.05, 0.95], atol=1e-15)
    assert ARM.safety_radius == pytest.approx(0.25)


def test_row_zeta_is_the_wrist_point_and_the_wrist_joints_do_not_move_it():
    assert np.abs(kin.wrist_point(ARM, Q[:, :3]) - kin.frames(ARM, Q)[:, 4, :3, 3]).max() < 1e-14
    moved = Q.copy()
    moved[:, 3:] = RNG.uniform(-np.pi, np.pi, (len(Q), 3))
    assert np.abs(kin.frames(ARM, moved)[:, 4, :3, 3] - kin.frames(ARM, Q)[:, 4, :3, 3]).max() < 1e-14


def test_ik_round_trip_on_all_eight_branches():
    branches_seen = np.zeros(8, bool)
    for q in Q[:150]:
        T = kin.tool_pose(ARM, q)
        sols = kin.ik(ARM, T)
        ok = ~np.isnan(sols).any(axis=1)
        branches_seen |= ok
        assert np.abs(kin.tool_pose(ARM, sols[ok]) - T).max() < 1e-12
        # the generating joints are one of the solutions (angles mod 2π)
        d = np.abs(np.remainder(sols[ok] - q + np.pi, 2 * np.pi) - np.pi).max(axis=1)
        assert d.min() < 1e-9
        # flags of each branch: bit 2 shoulder (front = +), bit 1 elbow (q3 ≥ 0), bit 0 wrist (q5 ≥ 0)
        flags = kin.branch_flags(ARM, sols[ok])
        idx = np.flatnonzero(ok)
        assert (flags[:, 0] == np.where(idx & 4, -1, 1)).all()
        assert (flags[:, 1] == np.where(idx & 2, -1, 1)).all()
        assert (flags[:, 2] == np.where(idx & 1, -1, 1)).all()
    assert branches_seen.all()


def test_ik_of_the_papers_poses():
    # Fig. 3 start: 4 of 8 solutions inside the limits; the goal is only reachable with the shoulder in front
    start = kin.ik(ARM, _pose([0.11, -0.35, -0.405]))
    goal = kin.ik(ARM, _pose([0.78, 0.39, -0.405]))
    assert kin.within_limits(ARM, start).sum() == 4
    assert np.isnan(goal[4:]).all() and not np.isnan(goal[:4]).any()
    assert np.allclose(kin.wrist_target(ARM, _pose([0.78, 0.39, -0.405])), [0.78, 0.39, -0.155])


def test_jacobians_against_finite_differences():
    h = 1e-6
    for q in Q[:40]:
        J = kin.wrist_jacobian(ARM, q[:3])
        fd = np.stack([(kin.wrist_point(ARM, q[:3] + h * e) - kin.wrist_point(ARM, q[:3] - h * e)) / (2 * h)
                       for e in np.eye(3)], axis=1)
        assert np.abs(J - fd).max() < 1e-8
        # J_{m,rot}^f: ω of R_m^f(q_o) in {m}, from S(ω) = Ṙ Rᵀ
        Jo = kin.hand_jacobian(ARM, q[3:])
        R = kin.hand_rotation(ARM, q[3:])
        for i, e in enumerate(np.eye(3)):
            S = (kin.hand_rotation(ARM, q[3:] + h * e) - kin.hand_rotation(ARM, q[3:] - h * e)) / (2 * h) @ R.T
            assert np.abs(np.array([S[2, 1], S[0, 2], S[1, 0]]) - Jo[:, i]).max() < 1e-8


def test_casadi_dh_equals_numpy_dh():
    q = ca.SX.sym("q", 6)
    frames = ca.Function("F", [q], dh_casadi.frames(ARM.dh, q, ARM.base))
    jac = ca.Function("J", [q], [dh_casadi.geometric_jacobian(ARM.dh, q, ARM.base, ARM.tool)])
    for qi in Q[:20]:
        F = np.array([np.array(x) for x in frames(qi)])
        assert np.abs(F - kin.frames(ARM, qi)).max() < 1e-14
        J = dhk.geometric_jacobian(ARM.dh, qi)
        J[:3] += np.cross(J[3:].T, (kin.frames(ARM, qi)[6, :3, :3] @ ARM.tool[:3, 3])).T  # shift to the tool point
        assert np.abs(np.array(jac(qi)) - J).max() < 1e-14


def test_mujoco_model_matches_the_dh_chain():
    import mujoco

    from pipeline.papers.nmpc_cdkd.plant import model_xml

    model = mujoco.MjModel.from_xml_string(model_xml(ARM, SYSTEM["plant"], 0.01, np.zeros(6), np.array([0.05])))
    data = mujoco.MjData(model)
    flange = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "flange")
    tool = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "tool")
    for q in Q[:30]:
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        F = kin.frames(ARM, q)[6]
        assert np.abs(data.site_xpos[flange] - F[:3, 3]).max() < 1e-12
        assert np.abs(data.site_xmat[flange].reshape(3, 3) - F[:3, :3]).max() < 1e-12
        # the tool capsule runs from the wrist point to the tool tip
        tip = kin.tool_pose(ARM, q)[:3, 3]
        centre = (kin.wrist_point(ARM, q[:3]) + tip) / 2
        assert np.abs(data.geom_xpos[tool] - centre).max() < 1e-12


def test_septic_polynomial_closed_form():
    tau = np.linspace(0, 1, 200001)
    s = septic(tau)
    assert s[0, 0] == 0 and s[0, -1] == 1 and septic(0.5)[0] == pytest.approx(0.5)
    assert np.abs(s[1:, [0, -1]]).max() == 0          # (8): velocity, acceleration, jerk zero at both ends
    assert np.abs(s[1:]).max(axis=1) == pytest.approx(SEPTIC_PEAKS, rel=1e-6)
    for order in (1, 2, 3):  # derivatives are derivatives
        assert np.abs(np.gradient(s[order - 1], tau)[1:-1] - s[order][1:-1]).max() < 1e-3


def test_configuration_selection_keeps_the_tool_vertical_on_fig3():
    sel = planning.select_configuration(ARM, _pose([0.11, -0.35, -0.405]), _pose([0.78, 0.39, -0.405]), 151,
                                        SYSTEM["planning"]["wrist_band"])
    assert sel.q_start[3] == pytest.approx(0, abs=1e-9) and sel.q_goal[3] == pytest.approx(0, abs=1e-9)
    poly = planning.JointPolynomial(sel.q_start, sel.q_goal, 0.5, 1.5)
    T = kin.tool_pose(ARM, poly(np.linspace(0, 2.5, 251)))
    assert np.abs(T[:, :3, 2] - [0, 0, -1]).max() < 1e-12      # spec §3.3: q2 + q3 + q5 stays constant
    assert kin.within_limits(ARM, poly(np.linspace(0.5, 2.0, 151))).all()
    assert T[-1, :3, 3] == pytest.approx([0.78, 0.39, -0.405], abs=1e-12)


def test_quaternion_matches_scipy_on_all_pivots():
    from scipy.spatial.transform import Rotation

    R = Rotation.random(5000, random_state=11)
    reference = R.as_quat(scalar_first=True)
    reference *= np.where(reference[:, :1] < 0, -1, 1)
    assert np.abs(kin.quaternion(R.as_matrix()) - reference).max() < 1e-14
    for diag in ([1, -1, -1], [-1, 1, -1], [-1, -1, 1]):  # half turns: η = 0, one ε_i pivots
        q = kin.quaternion(np.diag(diag))
        assert np.abs(q).max() == 1 and q[0] == 0


def test_orientation_error_is_zero_only_for_equal_orientations_and_half_the_small_angle():
    R = kin.hand_rotation(ARM, Q[:50, 3:])
    q = kin.quaternion(R)
    assert np.abs(kin.orientation_error(q, q)).max() < 1e-15
    assert np.abs(kin.orientation_error(q, -q)).max() < 1e-15         # q and −q are one rotation
    axis = np.array([0.3, -0.5, 0.81])
    axis /= np.linalg.norm(axis)
    angle = 1e-4
    dq = np.r_[np.cos(angle / 2), np.sin(angle / 2) * axis]
    e = kin.orientation_error(np.array([1.0, 0, 0, 0]), dq)   # current = small rotation, desired = identity
    assert e == pytest.approx(-angle / 2 * axis, rel=1e-6)


def test_jacobian_transpose_controller_decreases_its_lyapunov_function():
    # (13)-(14): fixed desired orientation, fine steps; V = (η_d − η)² + ‖ε_d − ε‖² never increases
    q_o = np.array([0.4, 1.1, -0.7])
    desired = kin.quaternion(kin.hand_rotation(ARM, np.array([-0.5, 0.6, 0.9])))
    K, dt = 20.0, 1e-3
    V = []
    for _ in range(3000):
        current = kin.quaternion(kin.hand_rotation(ARM, q_o))
        current = current if current @ desired >= 0 else -current
        V.append(np.sum((desired - current) ** 2))
        q_o = q_o + kin.hand_jacobian(ARM, q_o).T @ (K * kin.orientation_error(desired, current)) * dt
    V = np.array(V)
    assert (np.diff(V) <= 1e-15).all() and V[-1] < 1e-3 * V[0]

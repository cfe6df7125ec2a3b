"""FreeBOT drive, IK and obstacle QP of the SRC manipulator (Secs. III-B, IV, V-C), and the MuJoCo joint of
Sec. V-A: closed-form constants, round trips, the rolling plant as the reference, and MuJoCo's own geometry."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pipeline.papers.src_joint import (
    Bars,
    Chain,
    Damper,
    DamperQP,
    FreeBot,
    Gains,
    IkGains,
    RollingChain,
    dls,
    solve_ik,
)
from pipeline.papers.src_joint import trolley as tr
from pipeline.papers.src_joint.rolling import trolley_rates

BOT = FreeBot(r_in=0.032, r_out=0.034, wheel_radius=0.005, wheel_interval=0.046)   # Table II
RNG = np.random.default_rng(11)


def test_wheel_speed_constants_and_round_trip():
    # eq. (64): u_f = 0.0038205 (ω_r + ω_l), u_s = 0.108696 (ω_r − ω_l); eq. (65) inverts it
    assert BOT.forward_gain == pytest.approx(0.0038205, rel=1e-4)
    assert BOT.steering_gain == pytest.approx(0.108696, rel=1e-5)
    right, left = BOT.wheel_speeds(1.0, 0.0)
    assert right == pytest.approx(130.874, rel=1e-5) and left == pytest.approx(130.874, rel=1e-5)
    right, left = BOT.wheel_speeds(0.0, 1.0)
    assert right == pytest.approx(4.6) and left == pytest.approx(-4.6)
    u = RNG.normal(size=(2, 20))
    assert np.allclose(BOT.trolley_speeds(*BOT.wheel_speeds(*u)), u, atol=1e-12)
    # eq. (85) through r' of eq. (83) is the same map as eq. (64)
    r_prime = np.sqrt(BOT.r_in ** 2 - (BOT.wheel_interval / 2) ** 2)
    assert BOT.forward_gain == pytest.approx(BOT.r_out * BOT.wheel_radius / r_prime / 2, rel=1e-14)


@pytest.mark.parametrize("radii", [[0.034, 0.034], [0.04, 0.03]])
def test_velocity_plan_eq52_makes_the_plant_roll_at_the_reference(radii):
    """A trolley at (u_f^r, φ^r) of eq. (52) makes the exact rolling plant turn at w^r: eq. (51) with
    l' = l_i l_{i-1} / (l_i + l_{i-1}), for unequal spheres too."""
    lower, upper = np.array(radii[:1]), np.array(radii[1:])
    plant = RollingChain(radii)
    plant.roll(np.array([[0.4, -0.9]]), 1.0)        # somewhere off the start
    for w_ref in RNG.normal(size=(10, 1, 2)):
        u_forward, heading = tr.velocity_plan(w_ref, tr.equivalent_radius(lower, upper))
        omega = plant.relative_velocity(trolley_rates(u_forward, heading, upper))   # shell radius r_out = l_i
        w = plant.tangent[0].T @ omega[0]
        assert np.allclose(w[:2], w_ref[0], atol=1e-14) and abs(w[2]) < 1e-15
        assert np.allclose(tr.joint_velocity(u_forward, heading, tr.equivalent_radius(lower, upper)), w_ref)


def test_position_plan_eqs53_55_lands_on_the_contact_point_and_the_printed_azimuth_does_not():
    radii = np.array([0.034, 0.034])
    lower, upper = radii[:1], radii[1:]
    start = Chain(radii)
    start.move(np.array([[0.5, 0.2]]), 1.0)
    for _ in range(10):
        target = Chain(radii)
        target.move(RNG.normal(size=(1, 2)), 1.0)
        for azimuth, lands in (("corrected", True), ("printed", False)):
            chain = start.copy()
            arc, heading = tr.position_plan(chain.tangent_frames(), target.tangent_frames(), lower, azimuth)
            chain.move(tr.joint_velocity(arc, heading, tr.equivalent_radius(lower, upper)), 1.0)   # one straight roll
            miss = np.linalg.norm(chain.tangent_frames()[0][:, 2] - target.tangent_frames()[0][:, 2])
            assert (miss < 1e-12) if lands else (miss > 1e-3)


def test_steering_laws_are_stable():
    """(56)+(57) with constant u_f^r: V = 1 − cos φ_e never increases; steer-then-forward reaches s^r."""
    g = Gains(k_s=3.0, k_phi1=6.0, k_phi2=1.0)
    heading, dt = np.array([3.0, -2.5, 0.3]), 1e-3
    ref = np.zeros(3)
    V_prev = 1 - np.cos(tr.wrap(ref - heading))
    for _ in range(2000):
        _, u_steer = tr.steer_while_forward(heading, ref, np.zeros(3), np.full(3, 0.05), g)
        heading = heading + u_steer * dt
        V = 1 - np.cos(tr.wrap(ref - heading))
        assert (V <= V_prev + 1e-15).all()
        V_prev = V
    assert np.abs(tr.wrap(heading)).max() < 1e-4
    heading, arc, forward = np.array([1.0, -1.0]), np.zeros(2), np.zeros(2, dtype=bool)
    arc_ref, heading_ref = np.array([0.05, 0.08]), np.array([-0.5, 2.0])
    for _ in range(10000):
        u_forward, u_steer, forward = tr.steer_then_forward(heading, heading_ref, arc_ref - arc, forward, g, 0.01)
        assert (u_forward[~forward] == 0).all()            # no forward motion before the heading is right
        heading, arc = heading + u_steer * dt, arc + u_forward * dt
    assert np.allclose(arc, arc_ref, atol=1e-9) and np.allclose(heading, heading_ref, atol=1e-9)


@pytest.mark.parametrize("n", [3, 4])
def test_dls_is_the_pseudoinverse_away_from_singularities_and_damped_near_them(n):
    J = RNG.normal(size=(6, 2 * n))
    x = RNG.normal(size=6)
    w, sigma_min = dls(J, x, xi=0.01, lambda_max=0.01)
    assert sigma_min >= 0.01
    assert np.allclose(w, np.linalg.inv(J) @ x if n == 3 else np.linalg.pinv(J) @ x, atol=1e-12)
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    s[-1] = 0.004                                       # inside the singular region
    J_near = U @ np.diag(s) @ Vt
    lam2 = (1 - (0.004 / 0.01) ** 2) * 0.01 ** 2        # eq. (44)
    expected = Vt.T @ np.diag(s / (s ** 2 + lam2)) @ U.T @ x   # eq. (43)
    assert np.allclose(dls(J_near, x, 0.01, 0.01)[0], expected, atol=1e-12)
    s[-1] = 0.0                                         # exactly singular: finite, no division by zero
    assert np.isfinite(dls(U @ np.diag(s) @ Vt, x, 0.01, 0.01)[0]).all()


def test_closed_loop_ik_decays_at_the_gain_and_converges():
    """Away from singularities J ω = ẋ^r holds exactly, so |e_p| decays like e^{−K_p t} (eqs. 45, 42); the
    quaternion error of eq. (47) like e^{−K_a t / 2}."""
    radii = [0.034] * 4
    start = Chain(radii)
    start.move(np.array([[1.8, 1.3], [-0.9, 2.2], [1.8, -0.6]]), 1.0)     # σ_min(J) = 0.024 > ξ
    goal = start.copy()
    goal.move(np.array([[0.05, 0.02], [-0.03, 0.04], [0.02, -0.05]]), 1.0)
    r_goal = goal.frames()[0][-1]
    result = solve_ik(start.copy(), r_goal, goal.orientation(), IkGains(xi=0.01, lambda_max=0.01, kp=2.0, ka=2.0),
                      dt=0.005, duration=20.0, tol_position=1e-9, tol_orientation=1e-7)
    assert result.converged and (result.sigma_min > 0.01).all()
    e = np.linalg.norm(result.position_error, axis=1)
    k = round(0.5 / 0.005)
    assert e[k] / e[0] == pytest.approx(np.exp(-2.0 * 0.5), rel=0.02)
    assert np.allclose(result.chain.frames()[0][-1], r_goal, atol=1e-9)


def test_damper_qp_keeps_the_rows_and_otherwise_solves_the_pose_task():
    n = 4
    chain = Chain([0.034] * (n + 1))
    chain.move(np.array([[0.8, -0.3], [-0.6, 0.9], [0.4, 0.7], [0.2, 0.1]]), 1.0)
    Jv, Jw, pos, _ = chain.jacobians()
    J = np.vstack([Jv[-1], Jw[-1]])
    twist = RNG.normal(size=6)
    damper = Damper(safety=0.01, influence=0.04, gain=0.5, regularization=1e-4)
    qp = DamperQP(2 * n, n, damper)
    free, _ = qp.solve(J, twist, np.zeros((n, 2 * n)), np.full(n, np.inf))
    assert np.allclose(free, np.linalg.solve(J.T @ J + 1e-4 * np.eye(2 * n), J.T @ twist), atol=1e-8)
    # a bar 2 mm outside the safety distance of link 3, normal to the chain there, the pose task pushing into it
    u = np.cross(pos[3] - pos[2], pos[4] - pos[3])
    u /= np.linalg.norm(u)
    axis = (pos[4] - pos[2]) / np.linalg.norm(pos[4] - pos[2])
    bars = Bars(points=(pos[3] + (0.034 + 0.005 + 0.012) * u)[None], axis=axis, radius=0.005)
    clearance, normals = bars.clearance(pos[1:], np.full(n, 0.034))
    A, b = qp.rows(Jv[1:], clearance, normals)
    assert (b >= 0).all() and np.isfinite(b[2])
    w, slack = qp.solve(J, np.r_[0.5 * u, 0.0, 0.0, 0.0], A, b)
    assert (A @ w <= b + 1e-9).all() and slack == 0.0 and A[2] @ w == pytest.approx(b[2], rel=1e-6)
    assert clearance[2, 0] == pytest.approx(0.012, abs=1e-12)


def test_clearance_equals_mujoco_geometry_distance():
    pytest.importorskip("mujoco")
    from pipeline.papers.src_joint.physics import mujoco_clearance, scene_xml

    points, axis = np.array([[0.0948, 0.0985, 0.0467], [0.0948, 0.2107, 0.0467]]), np.array([1.0, 0.0, 0.0])
    bars = Bars(points, axis, 0.005)
    radii = np.full(3, 0.034)
    centres = RNG.uniform([-0.1, 0.0, 0.0], [0.2, 0.3, 0.2], (20, 3, 3))
    analytic, _ = bars.clearance(centres.reshape(-1, 3), np.tile(radii, 20))
    measured = mujoco_clearance(scene_xml(radii, points, axis, 0.005, 0.5), centres)
    assert np.allclose(analytic.reshape(20, 3, 2), measured, atol=1e-9)


def test_mujoco_joint_follows_the_corrected_model_not_the_printed_one():
    """Sec. V-A in short: B_i (0.03 m) rolling on B_{i-1} (0.04 m) in MuJoCo at the commanded Ω^B. What is left
    of the model error comes from the soft contact: it falls with the square of the contact time constant."""
    pytest.importorskip("mujoco")
    from pipeline.papers.src_joint.experiments import model_beside
    from pipeline.papers.src_joint.model import ModelForm
    from pipeline.papers.src_joint.physics import ContactPhysics, contact_paths, roll_in_mujoco

    peak = {}
    for timeconst in (0.002, 0.004):
        physics = ContactPhysics(dt=0.001, mass=0.1, magnet_force=5.0, friction=[1.0, 0.02, 0.0],
                                 solref=[timeconst, 1.0], solimp=[0.9999, 0.9999, 0.001], noslip_iterations=20,
                                 noslip_tolerance=1e-6, gravity=[0.0, 0.0, -9.81], servo_bandwidth_hz=20.0,
                                 settle_time=0.2)
        plant, _ = roll_in_mujoco(0.04, 0.03, np.array([-0.1, -0.05]), 2.0, 0.01, physics)
        assert np.linalg.norm(plant.rates[-1, :2] - [-0.1, -0.05]) < 2e-3     # the servo holds the command
        assert np.abs(plant.rates[:, 2]).max() < 1e-9                         # no spin
        on_lower, on_upper = contact_paths(0.04, 0.03, plant.tangent, plant.rotation)
        assert on_lower[-1] > 0.005 and abs(on_lower[-1] - on_upper[-1]) < 1e-6 * on_lower[-1]  # no slip
        for form in (ModelForm(), ModelForm(radius_convention="printed")):
            model = model_beside(plant, 0.04, 0.03, form)
            R = np.swapaxes(model["rotation"], -1, -2) @ plant.rotation
            peak[timeconst, form.radius_convention] = np.linalg.norm(Rotation.from_matrix(R).as_rotvec(), axis=1).max()
    assert np.degrees(peak[0.002, "corrected"]) < 1e-5 and np.degrees(peak[0.002, "printed"]) > 1.0
    assert peak[0.004, "corrected"] / peak[0.002, "corrected"] == pytest.approx(4.0, rel=0.2)

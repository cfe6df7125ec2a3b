"""Andersson's curve discretization: the algorithm against independent root finding, the paper's closed forms
(eqs. 13, 14, 16, 17), three forward kinematics (sequential, POE, MuJoCo), planar and straight curves, the
roll invariance of Thm 4.1, the warm start, and the reference values of the Sec. IV-C example."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import brentq
from scipy.special import comb

from pipeline.core.checks import BadInput, preflight
from pipeline.papers.curve_discretization import (
    Chain,
    CurveTooShort,
    bezier,
    discretize,
    forward_kinematics,
    joint_parameters,
    joint_positions,
    poe_forward_kinematics,
    travelling_wave,
)
from pipeline.papers.curve_discretization import algorithm as dc
from pipeline.papers.curve_discretization import snake as sn

from .conftest import simulate_case

CONTROL_POINTS = np.array([[4, 4, 0], [4, -4, 0], [-4, -4, 0], [-4, 4, 0], [0, 0, 4], [4, -4, 6], [4, 4, 8]], float)
CURVE = bezier(CONTROL_POINTS)
FIG2 = Chain.uniform(30, 1.25)
DT, TOL = 1e-3, 1e-12
RNG = np.random.default_rng(11)


def bernstein(t) -> np.ndarray:
    """Eq. (19) as printed: Σ_k p_k C(6, k) t^k (1 − t)^(6−k)."""
    t = np.atleast_1d(t)[:, None]
    return sum(CONTROL_POINTS[k] * comb(6, k) * t ** k * (1 - t) ** (6 - k) for k in range(7))


def brentq_parameters(points_of, lengths, step=1e-4) -> np.ndarray:
    """Subproblem 1 independently: a fine grid for the first crossing, then Brent's method."""
    t = [0.0]
    for length in lengths:
        grid = np.arange(t[-1], 1.0 + step, step).clip(max=1.0)
        start = points_of(t[-1])[0]
        gap = np.linalg.norm(points_of(grid) - start, axis=1) - length
        k = int(np.argmax(gap >= 0))
        t.append(brentq(lambda s, c=start, L=length: np.linalg.norm(points_of(s)[0] - c) - L, grid[k - 1], grid[k],
                        xtol=1e-15))
    return np.array(t)


def test_bezier_is_eq19():
    t = np.linspace(0, 1, 101)
    assert np.abs(CURVE(t) - bernstein(t)).max() < 1e-13
    assert np.allclose(CURVE([0.0, 1.0]), CONTROL_POINTS[[0, -1]])


def test_joint_points_equal_independent_root_finding():
    search = joint_parameters(CURVE, FIG2, DT, TOL)
    reference = brentq_parameters(bernstein, FIG2.segment_lengths)
    assert np.abs(search.t - reference).max() < 1e-11
    distinct = np.linalg.norm(np.diff(search.points, axis=0), axis=1)
    assert np.abs(distinct - 1.25).max() < 1e-10
    assert len(search.points) == 16  # 30 joints: P_1, P_2 = P_3, …, P_28 = P_29, P_30


def test_sec4c_example_reference_values():
    # spec §5, computed with dt = 1e-4 and tol = 1e-13; the first crossing must not depend on dt
    search, angles = discretize(CURVE, FIG2, math.pi / 4, DT, TOL)
    spec_t = [0, 0.027925, 0.060374, 0.098939, 0.145858, 0.203953, 0.276859, 0.374085, 0.504726, 0.596740,
              0.666516, 0.728767, 0.789875, 0.851717, 0.906852, 0.949014]
    assert np.abs(search.t - spec_t).max() < 1e-6
    assert angles.theta_z0 == pytest.approx(-1.640281, abs=1e-6)
    assert angles.theta_y0 == pytest.approx(-2.806e-5, abs=1e-8)
    assert np.allclose(search.points[-1], [3.85463, 1.98885, 7.38364], atol=1e-5)
    assert angles.theta[1:3] == pytest.approx([-0.1138, -0.1124], abs=1e-4)
    assert np.abs(angles.theta).max() == pytest.approx(0.884, abs=1e-3)
    coarse = joint_parameters(CURVE, FIG2, 1e-2, TOL)  # a coarser march finds the same first crossings
    assert np.abs(coarse.t - search.t).max() < 1e-11


def test_eq16_and_first_frame():
    search, angles = discretize(CURVE, FIG2, 0.3, DT, TOL)
    d = search.points[1] - search.points[0]
    # proof of Thm 4.1: p_{1,0} = L_1 (cθz cθy, sθz cθy, −sθy)
    cz, sz, cy, sy = (math.cos(angles.theta_z0), math.sin(angles.theta_z0), math.cos(angles.theta_y0),
                      math.sin(angles.theta_y0))
    assert np.allclose(d, 1.25 * np.array([cz * cy, sz * cy, -sy]), atol=1e-12)
    R = dc._axis_rotation(2, angles.theta_z0) @ dc._axis_rotation(1, angles.theta_y0) @ dc._axis_rotation(0, 0.3)
    assert np.abs(R - angles.R_w1).max() < 1e-14  # eq. (15)
    assert angles.theta[0] == 0.0


@pytest.mark.parametrize("theta_x0", [0.0, math.pi / 4, 1.0, -2.5])
def test_three_forward_kinematics_put_every_joint_on_the_curve(theta_x0):
    search, angles = discretize(CURVE, FIG2, theta_x0, DT, TOL)
    P = joint_positions(search.points, FIG2.joints)
    sequential = forward_kinematics(search.points[0], angles.R_w1, angles.theta, FIG2)
    poe = poe_forward_kinematics(search.points[0], angles.theta_z0, angles.theta_y0, theta_x0, angles.theta, FIG2)
    assert np.abs(sequential[:, :3, 3] - P).max() < 1e-10
    assert np.abs(poe - sequential).max() < 1e-12
    # Thm 4.2 identity: Δp_j = L (cθ_{j−2} cθ_{j−1}, sθ_{j−1}, −sθ_{j−2} cθ_{j−1}) in frame j − 3
    for j in range(4, FIG2.joints + 1, 2):
        dp = sequential[j - 4, :3, :3].T @ (P[j - 1] - P[j - 3])
        a, b = angles.theta[j - 3], angles.theta[j - 2]
        assert np.allclose(dp, 1.25 * np.array([math.cos(a) * math.cos(b), math.sin(b), -math.sin(a) * math.cos(b)]),
                           atol=1e-10)
    mujoco = pytest.importorskip("mujoco")
    assert mujoco
    frames, points = sn.segment_frames(sn.chain_mjcf(FIG2), sn.configuration(search.points, angles.R_w1, angles.theta),
                                       FIG2)   # the model a Fig. 2 run draws
    assert np.abs(points[0] - search.points).max() < 1e-10
    assert np.abs(frames[0] - sequential[::2][:FIG2.segments]).max() < 1e-10


def test_closed_form_screws_eq13_eq14_and_the_eq3_misprint():
    for m, S, theta in ((3, 2.5, 0.7), (4, 1.25, -1.1)):
        w = np.eye(3)[dc.joint_axis(m)]
        xi = np.r_[-np.cross(w, [S, 0, 0]), w]
        c, s = math.cos(theta), math.sin(theta)
        if m % 2:   # eq. (13)
            closed = np.array([[c, -s, 0, S * (1 - c)], [s, c, 0, -S * s], [0, 0, 1, 0], [0, 0, 0, 1]])
        else:       # eq. (14)
            closed = np.array([[c, 0, s, S * (1 - c)], [0, 1, 0, 0], [-s, 0, c, S * s], [0, 0, 0, 1]])
        assert np.abs(expm(dc.twist_hat(xi) * theta) - closed).max() < 1e-12
    search, angles = discretize(CURVE, FIG2, math.pi / 4, DT, TOL)
    printed = poe_forward_kinematics(search.points[0], angles.theta_z0, angles.theta_y0, math.pi / 4, angles.theta,
                                     FIG2, printed_twist_hat=True)
    assert np.abs(printed[:, :3, 3] - joint_positions(search.points, FIG2.joints)).max() > 1.0


def test_fig2_run_draws_the_chain_where_its_tf_puts_the_joints(tmp_path):
    """A Fig. 2 run carries the chain as a robot (the URDF of the same Chain's MuJoCo model). Moved by the run's
    /joint_states, link segment i + 1 is the run's /tf frame joint(2i + 1), position and orientation, and every
    joint m sits on the chain: P_2i = P_2i+1 = Q_i at segment i + 1's origin, P_N at the last segment's end."""
    yourdfpy = pytest.importorskip("yourdfpy")
    from scipy.spatial.transform import Rotation

    run = simulate_case(tmp_path, "curve-discretization/bezier-fig2", ["scenario.roll_variants=[]"], "paper")
    urdf = yourdfpy.URDF.load(io.StringIO(run["/robot_description"]["data"].iloc[0]), load_meshes=False,
                              load_collision_meshes=False)
    [state] = run["/joint_states"].filter(like=".position").to_dict("records")
    urdf.update_cfg({k.removeprefix("joints.").removesuffix(".position"): v for k, v in state.items()})
    [tf] = run["/tf"].to_dict("records")
    end = np.eye(4)
    end[0, 3] = FIG2.segment_lengths[-1]
    for m in range(1, FIG2.joints + 1):
        i = m // 2   # P_m = Q_i
        link = urdf.get_transform(f"{urdf.robot.name}/segment{min(i, FIG2.segments - 1) + 1}", "world")
        drawn = link if i < FIG2.segments else link @ end
        frame = f"transforms.joint{m}"
        assert np.allclose(drawn[:3, 3], [tf[f"{frame}.translation.{a}"] for a in "xyz"], atol=1e-9), m
        if m % 2:
            logged = Rotation.from_quat([tf[f"{frame}.rotation.{a}"] for a in "xyzw"]).as_matrix()
            assert np.allclose(drawn[:3, :3], logged, atol=1e-9), m


def test_roll_invariance_thm41():
    base_search, base = discretize(CURVE, FIG2, math.pi / 4, DT, TOL)
    base_fk = forward_kinematics(base_search.points[0], base.R_w1, base.theta, FIG2)[:, :3, 3]
    for roll in RNG.uniform(-math.pi, math.pi, 5):
        search, angles = discretize(CURVE, FIG2, roll, DT, TOL)
        fk = forward_kinematics(search.points[0], angles.R_w1, angles.theta, FIG2)[:, :3, 3]
        assert np.abs(fk - base_fk).max() < 1e-10
        assert np.abs(angles.theta - base.theta).max() > 1e-3


def test_planar_curve_bends_only_the_joints_normal_to_its_plane():
    planar = bezier(RNG.uniform(-3, 3, (5, 3)) * [1, 1, 0])
    chain = Chain.uniform(12, 0.6)
    search, flat = discretize(planar, chain, 0.0, DT, TOL)
    chords = np.diff(search.points, axis=0)
    turn = np.arctan2(np.cross(chords[:-1], chords[1:])[:, 2], np.einsum("ij,ij->i", chords[:-1], chords[1:]))
    assert np.abs(flat.theta[1:-2:2]).max() < 1e-12           # even joints (about y) stay straight
    assert np.allclose(flat.theta[2:-1:2], turn, atol=1e-12)  # odd joints (about z) take the turning angles
    _, rolled = discretize(planar, chain, math.pi / 2, DT, TOL)
    assert np.abs(rolled.theta[2:-1:2]).max() < 1e-12
    assert np.allclose(np.abs(rolled.theta[1:-2:2]), np.abs(turn), atol=1e-12)


def test_straight_line_has_zero_angles_and_even_spacing():
    line = bezier([[0, 0, 0], [1, 2, 3]])
    search, angles = discretize(line, Chain.uniform(10, 0.5), 0.0, DT, TOL)
    assert np.abs(angles.theta).max() < 1e-12
    assert np.allclose(np.diff(search.t), 0.5 / math.sqrt(14), atol=1e-11)


def test_warm_start_finds_the_same_crossings_with_fewer_evaluations():
    chain = Chain.uniform(30, 0.1)
    previous = joint_parameters(travelling_wave(0.08, 0.03, 1.0, 0.0, math.pi / 2, 2.0), chain, DT, TOL)
    for phase in (0.03, 0.3, 2.0):  # small and large changes of the curve since the previous solution
        curve = travelling_wave(0.08, 0.03, 1.0, phase, math.pi / 2, 2.0)
        cold = joint_parameters(curve, chain, DT, TOL)
        warm = joint_parameters(curve, chain, DT, TOL, np.diff(previous.t))
        assert np.abs(warm.t - cold.t).max() < 2 * TOL
        assert warm.evaluations < cold.evaluations


def test_compiled_and_interpreted_kernels_agree():
    args = (CURVE.kind, CURVE.params, 0.0, 1.0, FIG2.segment_lengths, DT, 1e-10, np.empty(0))
    compiled, interpreted = dc._search(*args), dc._search.py_func(*args)
    assert np.array_equal(compiled[0], interpreted[0]) and compiled[2] == interpreted[2]
    points = compiled[1]
    a, b = dc._angles(points, 0.4, 30), dc._angles.py_func(points, 0.4, 30)
    assert np.abs(a[3] - b[3]).max() < 1e-14 and np.abs(a[2] - b[2]).max() < 1e-14


def test_a_chain_longer_than_the_curve_is_refused():
    with pytest.raises(CurveTooShort, match="longer than the curve"):
        joint_parameters(CURVE, Chain.uniform(100, 1.25), DT, TOL)


def test_shape_fit_recovers_a_rigid_motion():
    target = RNG.normal(size=(2, 16, 3))
    angle = 0.7
    R = dc._axis_rotation(2, angle) @ dc._axis_rotation(0, -0.3)
    body = target @ R.T + [1.0, -2.0, 0.5]
    placed, distance = sn.shape_fit(body, target)
    assert distance.max() < 1e-12 and np.abs(placed - body).max() < 1e-12
    body[1, 5] += [0.0, 0.0, 0.1]
    assert sn.shape_fit(body, target)[1][1].max() > 0.05


@pytest.mark.parametrize(("override", "message"), [
    ("system.search.tol=0", "system.search.tol=0 is out of range"),
    ("system.chain.joints=1", "system.chain.joints=1 is out of range"),
    ("system.theta_x0=9", "system.theta_x0=9 is out of range"),
])
def test_bad_parameters_are_refused(override, message):
    with pytest.raises(BadInput, match=message):
        preflight(["experiment=curve-discretization/bezier-fig2", override])

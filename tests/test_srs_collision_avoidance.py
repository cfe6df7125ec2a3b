"""srs-collision-avoidance: the closed-form IK by swivel angle (round trips, the paper's rotation matrices, swivel
invariants, MuJoCo's FK of the generated model), the critically damped filter against SciPy, the geometry of
the safety volume against brute force, eq. (19)'s exact variant, the printed listing's misprints, the online
Algorithm 1 against the batch one, MuJoCo's distance query against ours, and bad input refused."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import cont2discrete, lfilter
from scipy.spatial.transform import Rotation

from pipeline.core.checks import BadInput, compose_config, preflight
from pipeline.core.runlog import SimulationFailed
from pipeline.papers.srs_collision_avoidance import (
    IIWA,
    Coefficients,
    Forms,
    Online,
    SafetyVolume,
    circle_poses,
    fk,
    ik,
    mujoco_replay,
    plan,
    swivel_angle,
    swivel_filter,
)
from pipeline.papers.srs_collision_avoidance import experiments as ex
from pipeline.papers.srs_collision_avoidance.avoidance import ELBOW, FOREARM, UPPER_ARM, avoidance_angle, select
from pipeline.papers.srs_collision_avoidance.clearance import capsule_clearance, link_segments
from pipeline.papers.srs_collision_avoidance.humans import closest_on_segments
from pipeline.papers.srs_collision_avoidance.kinematics import chain, cross, rodrigues, rotate, unit

RNG = np.random.default_rng(11)
EXPERIMENT = "experiment=srs-collision-avoidance/circle"


def random_configurations(n: int) -> np.ndarray:
    """Elbow-up configurations of the branch the IK returns: θ2 in (−π/2, π/2), θ4 < 0, θ6 in (0, π)."""
    q = RNG.uniform(-np.pi, np.pi, (n, 7))
    q[:, 1] = RNG.uniform(-1.5, 1.5, n)
    q[:, 3] = -RNG.uniform(0.05, 3.0, n)
    q[:, 5] = RNG.uniform(0.05, 3.09, n)
    return q


def wrapped(x: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * x))


# -- kinematics -----------------------------------------------------------------------------------------------


def test_paper_rotation_matrices_are_yzx_and_xzx_euler_angles():
    q = random_configurations(300)
    c = chain(q)
    assert np.abs(c.R3 - Rotation.from_euler("YZX", q[:, :3]).as_matrix()).max() < 1e-14        # eq. (6)
    R47 = np.swapaxes(c.R4, -1, -2) @ c.R7
    assert np.abs(R47 - Rotation.from_euler("XZX", q[:, 4:]).as_matrix()).max() < 1e-14          # eq. (13)


def test_ik_inverts_fk_and_the_swivel_angle():
    q = random_configurations(2000)
    T = fk(q)
    sol = ik(T, swivel_angle(q))
    assert np.abs(wrapped(sol.q - q)).max() < 1e-10
    assert np.abs(fk(sol.q) - T).max() < 1e-12


def test_every_swivel_angle_keeps_the_tool_pose_along_the_task():
    poses = circle_poses([0.4, 0.2, 0.2], 0.2, 5, 1000)
    for alpha in np.linspace(-np.pi, np.pi, 9):
        sol = ik(poses, alpha)
        assert np.abs(fk(sol.q) - poses).max() < 1e-12                        # null-space motion
        assert np.abs(wrapped(swivel_angle(sol.q) - alpha)).max() < 1e-10


def test_swivel_invariants():
    poses = circle_poses([0.4, 0.2, 0.2], 0.2, 1, 50)
    alphas = np.linspace(-3, 3, 13)
    radii = []
    for alpha in alphas:
        s = ik(poses, alpha)
        assert np.allclose(np.linalg.norm(s.P_e - s.P_s, axis=1), IIWA.a1, atol=1e-13)
        assert np.allclose(np.linalg.norm(s.P_w - s.P_e, axis=1), IIWA.a2, atol=1e-13)
        u = unit(s.P_w - s.P_s)
        radii.append(np.linalg.norm(np.cross(s.P_e - s.P_s, u), axis=1))      # P_e stays on one circle
        assert (np.abs(s.q[:, 2]) < 1e-12).all() == (alpha == 0)              # α = 0 ⇔ θ3 = 0
    assert np.ptp(radii, axis=0).max() < 1e-13


def test_rodrigues_vector_form_equals_the_printed_matrix():
    u, v, a = unit(RNG.normal(size=(100, 3))), RNG.normal(size=(100, 3)), RNG.uniform(-4, 4, 100)
    assert np.abs(rotate(u, a, v) - np.einsum("nij,nj->ni", rodrigues(u, a), v)).max() < 1e-14     # eq. (5)
    assert np.abs(cross(u, v) - np.cross(u, v)).max() == 0


def test_generated_mujoco_model_has_the_same_kinematics():
    import mujoco

    arms = ex.humans(compose_config([EXPERIMENT]))
    xml = mujoco_replay.model_xml(IIWA, ex.dynamics(compose_config([EXPERIMENT])), np.tile(arms.radius, 2),
                                  np.tile([arms.upper_length, arms.fore_length], 2), timestep=0.001,
                                  kp=np.zeros(7), kv=np.zeros(7))
    model, q = mujoco.MjModel.from_xml_string(xml), random_configurations(50)
    data = mujoco.MjData(model)
    tool = model.site("tool").id
    for qk, T in zip(q, fk(q), strict=True):
        data.qpos[:] = qk
        mujoco.mj_kinematics(model, data)
        R_base = mujoco_replay.R_WORLD_BASE.T
        assert np.abs(R_base @ data.site_xpos[tool] - T[:3, 3]).max() < 1e-12
        assert np.abs(R_base @ data.site_xmat[tool].reshape(3, 3) - T[:3, :3]).max() < 1e-12


# -- the critically damped filter ------------------------------------------------------------------------------


@pytest.mark.parametrize(("p", "T"), [(0.2, 0.06), (2.0, 0.06), (20.0, 0.01)])
def test_filter_coefficients_are_scipys_zoh_discretisation(p, T):
    c = Coefficients.zoh(p, T)
    num, den, _ = cont2discrete(([p * p], [1.0, 2 * p, p * p]), T, method="zoh")
    assert np.allclose(np.ravel(num), c.numerator, rtol=0, atol=1e-15)
    assert np.allclose(den, c.denominator, rtol=0, atol=1e-15)
    assert c.dc_gain == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(np.roots(c.denominator), np.exp(-p * T), atol=1e-7)    # a double pole at e^{−m}


def test_filter_step_response_is_exact_and_matches_lfilter():
    p, T = 0.2, 0.06
    c = Coefficients.zoh(p, T)
    t = np.arange(1000) * T
    step = swivel_filter.apply(c, np.ones(1000))
    assert np.abs(step - (1 - (1 + p * t) * np.exp(-p * t))).max() < 1e-12   # ZOH is exact for a step
    assert step[0] == 0.0 and step[1] == pytest.approx(c.h1, abs=1e-18)
    x = RNG.normal(size=1000)
    assert np.abs(swivel_filter.apply(c, x) - lfilter(c.numerator, c.denominator, x)).max() < 1e-12
    assert np.abs(swivel_filter.apply(c, x + 0.3, initial=0.3) - 0.3 - lfilter(c.numerator, c.denominator, x)
                  ).max() < 1e-12


# -- geometry of Sec. 4 ----------------------------------------------------------------------------------------


def test_closest_points_of_segments_match_brute_force():
    rng = np.random.default_rng(7)   # its own stream: the shared one depends on which tests ran before
    A, B, C, D = (rng.normal(size=(200, 3)) for _ in range(4))
    P, Q = closest_on_segments(A, B, C, D)
    s = np.linspace(0, 1, 401)
    grid = np.linalg.norm((A[:, None, None] + s[None, :, None, None] * (B - A)[:, None, None])
                          - (C[:, None, None] + s[None, None, :, None] * (D - C)[:, None, None]), axis=-1)
    ours, sampled = np.linalg.norm(P - Q, axis=1), grid.min(axis=(1, 2))
    assert np.all(ours <= sampled + 1e-12)
    # the distance is Lipschitz in (s, t) with constant |AB| + |CD|: the grid's minimum lies within half a step of
    # the true one times that constant (the brute force can be that far off where the minimum sits on an edge)
    bound = (s[1] / 2) * (np.linalg.norm(B - A, axis=1) + np.linalg.norm(D - C, axis=1))
    assert np.all(sampled - ours <= bound)


def test_safety_margin_matches_sampled_cones():
    volume = SafetyVolume(0.02, 0.15)
    P_s, P_e, P_w = np.zeros(3), np.array([0.4, 0.0, 0.0]), np.array([0.6, -0.3, 0.1])
    X = RNG.uniform(-0.3, 0.9, (3000, 3))
    inside_paper = volume.margin(X, P_s, P_e, P_w) < 0
    # brute force on 10^4 points per link: the paper's rule, a point is inside a cone if its foot falls on the
    # segment within the local radius, or inside the elbow sphere
    t = np.linspace(0, 1, 10_001)
    inside = np.linalg.norm(X - P_e, axis=1) < volume.d_cmax
    for A, B, r0, r1 in ((P_s, P_e, volume.d_cmin, volume.d_cmax), (P_e, P_w, volume.d_cmax, volume.d_cmin)):
        points = A + t[:, None] * (B - A)
        nearest = np.argmin(np.linalg.norm(X[:, None] - points[None], axis=-1), axis=1)
        foot = t[nearest]
        d = np.linalg.norm(X - points[nearest], axis=1)
        inside |= (foot > 0) & (foot < 1) & (d < (1 - foot) * r0 + foot * r1)
    assert (inside_paper != inside).mean() < 2e-3                            # only at the sampled boundary


def _one(x) -> np.ndarray:
    return np.asarray(x, dtype=float)[None]


def test_exact_alpha_c_puts_p_col_at_the_allowed_distance():
    g, volume = IIWA, SafetyVolume(0.0, 0.15)
    poses = circle_poses([0.4, 0.2, 0.2], 0.2, 1, 40)
    zero = ik(poses, 0.0, g)
    checked = 0
    for k in range(len(poses)):
        P_s, P_e, P_w = zero.P_s[k], zero.P_e[k], zero.P_w[k]
        for point in (P_s + 0.7 * (P_e - P_s), P_e + 0.4 * (P_w - P_e)):
            P_c = point + 0.05 * unit(np.cross(P_w - P_s, P_e - P_s) + RNG.normal(scale=0.2, size=3))
            sel = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume)
            if not sel.find[0]:
                continue
            alpha, _ = avoidance_angle(_one(P_c), sel, _one(P_s), _one(P_e), _one(P_w), "exact")
            moved = P_s + rotate(unit(P_w - P_s), alpha[0], sel.P_col[0] - P_s)
            assert np.linalg.norm(moved - P_c) == pytest.approx(sel.d_mc[0], abs=1e-12)
            checked += 1
    assert checked > 40


def test_g_vanishes_where_eq20_says_avoidance_is_blind():
    P_s, P_e, P_w = np.zeros(3), np.array([0.3, 0.25, 0.0]), np.array([0.6, 0.0, 0.0])
    volume = SafetyVolume(0.0, 0.15)
    n_p = np.cross(unit(P_e - P_s), unit(P_w - P_e))                            # eq. (21)
    for offset in (0.0, 0.04):
        P_c = P_s + 0.6 * (P_e - P_s) + np.array([0.0, -0.03, 0.0]) + offset * unit(n_p)
        D = abs(np.dot(P_c - P_s, n_p)) / np.linalg.norm(n_p)                   # eq. (20)
        sel = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume)
        assert sel.case[0] == UPPER_ARM
        _, g = avoidance_angle(_one(P_c), sel, _one(P_s), _one(P_e), _one(P_w))
        assert (abs(g[0]) < 1e-15) == (D < 1e-15)


def test_printed_listing_changes_the_selection():
    P_s, P_e, P_w = np.zeros(3), np.array([0.4, 0.0, 0.0]), np.array([0.4, -0.4, 0.0])
    volume = SafetyVolume(0.0, 0.15)
    # near the forearm just below P_e: the cone is 0.12 wide there (eq. 17), 0.03 by line 21's misprint
    P_c = np.array([0.46, -0.08, 0.0])
    assert select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume).case[0] == FOREARM
    printed = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume, Forms(d_m2="printed"))
    assert printed.case[0] == ELBOW and printed.d_mc[0] == 0.15
    # in reach of both links: line 19's elseif never looks at the forearm
    P_c = np.array([0.38, -0.03, 0.02])
    both = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume)
    elseif = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume, Forms(link_checks="elseif"))
    assert both.case[0] == FOREARM and elseif.case[0] == UPPER_ARM
    # the elbow sphere alone: printed, d_mc is the distance P_c already has, so the exact α_c is 0
    P_c = np.array([0.45, 0.1, 0.06])
    allowed = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume)
    actual = select(_one(P_c), _one(P_s), _one(P_e), _one(P_w), volume, Forms(sphere_distance="printed"))
    assert allowed.case[0] == actual.case[0] == ELBOW and actual.d_mc[0] == pytest.approx(allowed.actual[0])
    a_allowed, _ = avoidance_angle(_one(P_c), allowed, _one(P_s), _one(P_e), _one(P_w), "exact")
    a_actual, _ = avoidance_angle(_one(P_c), actual, _one(P_s), _one(P_e), _one(P_w), "exact")
    assert abs(a_allowed[0]) > 0.1 and abs(a_actual[0]) < 1e-7


# -- Algorithm 1 on the task --------------------------------------------------------------------------------------


def test_online_algorithm_1_equals_the_batch_plan():
    cfg = compose_config([EXPERIMENT, "system.task.samples=300"])
    _, poses = ex.task(cfg)
    _, start, end, radius = ex.obstacles(cfg, ex.humans(cfg))
    for case in ("avoid", "avoid-printed", "avoid-exact", "avoid-capsules", "avoid-unfiltered"):
        s = ex.settings(cfg, case)
        batch = plan(poses, start, end, radius, s)
        online = Online(s)
        q = np.array([online.step(T, a, b, radius) for T, a, b in zip(poses, start, end, strict=True)])
        assert np.abs(wrapped(q - batch.q)).max() < 1e-12, case
        assert batch.selection.find.any()


def test_mujoco_distance_query_agrees_with_our_capsule_clearance():
    cfg = compose_config([EXPERIMENT, "system.task.samples=120"])
    arms = ex.humans(cfg)
    _, plan_, _, (start, end, radius) = ex.plan_case(cfg, "avoid")
    xml = ex.replay_model(cfg, arms, plan_.q[0])
    ours = capsule_clearance(*link_segments(plan_.points, fk(plan_.q)[:, :3, 3]), cfg.system.dynamics.link_radius,
                             start, end, radius)
    theirs = mujoco_replay.capsule_distances(xml, plan_.q, start, end)
    assert np.abs(theirs - ours).max() < 1e-9
    assert (ours < 0).any() and (ours > 0).any()    # both overlapping and separated pairs were compared


def test_unreachable_task_is_a_failed_run():
    cfg = compose_config([EXPERIMENT, "system.task.radius=0.9", "system.task.samples=50"])
    with pytest.raises(SimulationFailed, match="out of reach"):
        ex.plan_case(cfg, "avoid")


@pytest.mark.parametrize("override", [
    "system.filter.p=-0.2", "system.filter.p=nan", "system.filter.dt=0", "system.task.samples=1000000000",
    "system.algorithm.d_m2=bogus", "system.algorithm.link_checks=elsif", "system.ik.wrist_sign=0",
    "scenario.cases=[avoid,foo]", "replay.dt=1e-9", "system.safety.d_cmax=-1", "system.humans.plane=yz",
    "system.humans.base_turns=[5,1e9]", "system.task.rides=abc", "system.humans.base=[[0.1,0.5]]",
    "system.humans.radius=0.05", "system.safety.d_cmin=0.2",
])
def test_bad_input_is_refused_in_one_line(override):
    with pytest.raises(BadInput) as err:
        preflight([EXPERIMENT, override])
    message = str(err.value)
    assert "\n" not in message and len(message) < 300 and override.split("=")[0] in message

"""UR5 IK: round trips, the paper's Tables 3-6, the FSM's state traces, scalar vs batched."""

from __future__ import annotations

from math import pi

import numpy as np
import pytest

from pipeline.papers.ur5_ik_fsm import UR5, det_j, fk, ik, ik_all, ik_batch, ik_fsm, ik_min_displacement
from pipeline.papers.ur5_ik_fsm.experiments import angle

RNG = np.random.default_rng(3)
TABLE2 = [["pi", "pi/4", "pi/2", "pi/2", 0, "pi/5"], ["pi", "-pi/2", 0, "pi", "pi/3", 0],
          ["pi", 0, "pi/2", "pi", "pi", 0], ["pi/2", "pi/2", 0, "-pi/2", "pi/3", "pi"],
          ["pi/2", 0, "pi/4", "pi", "-pi", 0], ["-pi/3", "3*pi/4", 0, "pi", "-pi", 0],
          ["pi/3", "pi/3", "pi/2", "pi/4", "pi/3", 0], ["pi/5", "pi/2", "pi/2", "pi/2", "pi", "pi/2"],
          ["-pi", "pi/3", "-pi/2", "pi/2", "pi/6", "pi/2"], ["-pi/2", "pi/2", 0, "pi", "-pi", "pi/2"]]
POSES = [fk([angle(x) for x in row]) for row in TABLE2]
# The paper's Tables 3 and 4 (rad, 4 decimals)
TABLE3 = [[2.3815, 0.7054, 1.6608, 0.7755, 0.7601, 1.4137], [-1.7132, -2.0438, 0.5154, 2.5800, 1.4998, 1.4473],
          [-0.6392, 1.4741, 1.9941, -0.3266, 0.6392, -1.5708], [1.5708, 0.9088, 1.3914, 0.8414, -1.0472, 0],
          [-1.9116, 2.2113, 1.1655, -0.2352, 0.3408, -0.7854], [2.4303, 0.2367, 0.7022, 2.2027, -0.3359, -2.3562],
          [1.0472, 1.0472, 1.5708, 0.7854, 1.0472, 0], [-2.0715, -0.1327, 1.5357, 1.7386, -0.4418, 0],
          [3.1416, -0.4429, 1.5708, -0.0807, 0.5236, 1.5708], [-2.9992, 0.9905, 0.9407, 1.2104, -1.7132, 0]]
TABLE4 = [*TABLE3[:6], [-0.8445, 0.5569, 1.3797, 2.0214, 2.8289, 0.9248],
          [-2.0715, 0.3281, 1.0257, -1.3537, 0.4418, 3.1416], [-0.3414, 2.5392, 0.8718, -1.9651, 2.6900, -2.2975],
          TABLE3[9]]
TABLE5 = {1: 4.9919e6, 2: -7.7601e6, 3: -2.9926e7, 5: -3.2505e7, 6: -2.2865e7, 7: (-2.1859e7, 0.7623e7),
          8: (-3.4649e7, 2.9645e7), 9: (5.2815e7, -3.5288e7), 10: -1.2625e7}
TABLE6 = [3.4792, 4.2870, 3.0888, 2.6521, 3.2697, 4.1197, (2.5247, 3.9838), (3.1441, 4.1651), (3.9091, 4.8683),
          3.9066]


def wrapped(a, b):
    return np.abs(np.remainder(np.asarray(a) - np.asarray(b) + pi, 2 * pi) - pi)


def test_round_trip_every_branch_and_eight_solutions():
    q = RNG.uniform(-pi, pi, (300, 6))
    counts = []
    for qi in q:
        T = fk(qi)
        sols = ik_all(T)
        counts.append(len(sols))
        for s in sols:
            assert np.abs(fk(s) - T).max() < 1e-12
        assert wrapped(sols, qi).max(axis=1).min() < 1e-9  # the generating vector is among them
    # 8 for most poses; fewer where a branch's wrist point is out of reach (they come in ± pairs)
    assert max(counts) == 8 and set(counts) <= {2, 4, 6, 8}


@pytest.mark.parametrize("k", range(10))
def test_tables_3_to_6(k):
    a1, a2 = ik_min_displacement(POSES[k], np.zeros(6)), ik_fsm(POSES[k], np.zeros(6))
    assert wrapped(a1, TABLE3[k]).max() < 5.1e-5
    assert wrapped(a2, TABLE4[k]).max() < 5.1e-5
    t6 = TABLE6[k] if isinstance(TABLE6[k], tuple) else (TABLE6[k], TABLE6[k])
    assert np.linalg.norm(a1) == pytest.approx(t6[0], abs=5.1e-5)
    assert np.linalg.norm(a2) == pytest.approx(t6[1], abs=5.1e-5)
    if k + 1 == 4:  # the shoulder-singular test: only |det| is meaningful (spec §6)
        assert abs(det_j(a2)) * 1e9 < 1.0
    else:
        t5 = TABLE5[k + 1] if isinstance(TABLE5[k + 1], tuple) else (TABLE5[k + 1],) * 2
        assert det_j(a1) * 1e9 == pytest.approx(t5[0], rel=1e-4)
        assert det_j(a2) * 1e9 == pytest.approx(t5[1], rel=1e-4)


def test_agreement_is_7_of_10_and_differs_on_7_8_9():
    differ = [k + 1 for k, T in enumerate(POSES)
              if wrapped(ik_min_displacement(T, np.zeros(6)), ik_fsm(T, np.zeros(6))).max() > 1e-6]
    assert differ == [7, 8, 9]


def test_fsm_state_traces():
    # traces follow from the state rules of Sec. 2.4.2 (spec §5 lists the same)
    expected = {1: "1-5-6-3-24", 2: "1-5-6-3-24", 3: "1-5-6-3-24", 4: "1-5-6-3-6-3-24", 5: "1-5-5-6-3-24",
                6: "1-5-5-6-3-6-3-24", 7: "1-5-6-3-24", 8: "1-5-5-6-3-24", 9: "1-5-6-3-24", 10: "1-5-5-6-3-6-3-24"}
    for k, T in enumerate(POSES, start=1):
        assert ik.fsm(T, np.zeros(6)).trace == expected[k]


def test_tie_break_matters():
    # erratum 5: with a strict comparison (no tolerance) float noise picks the '−' option on some tests
    strict = ik.Conventions(tie_tol=-1e-15)
    changed = [k + 1 for k, T in enumerate(POSES)
               if wrapped(ik.fsm(T, np.zeros(6), UR5, strict).q, ik_fsm(T, np.zeros(6))).max() > 1e-6]
    assert changed


def test_unsigned_s3_misprint_breaks_the_minus_branch():
    # erratum 11: eq. (29) printed with s3 = +sqrt(1 - c3^2)
    printed = ik.Conventions(signed_s3=False)
    T = fk(RNG.uniform(-pi, pi, 6))
    errors = [np.abs(fk(q) - T).max() for _, q, ok in ik.branches(T, UR5, printed) if ok]
    assert max(errors) > 1e-3 and min(errors) < 1e-12


def _poses_with_singular_ones(n: int) -> np.ndarray:
    q = RNG.uniform(-pi, pi, (n, 6))
    q[: n // 4, 4] = 0.0  # wrist-singular generating vectors
    q[n // 4: n // 2, 4] = pi
    return np.array([fk(x) for x in q])


@pytest.mark.parametrize("algorithm", ["alg1", "alg2"])
def test_batched_equals_scalar(algorithm):
    poses = _poses_with_singular_ones(2000)
    previous = RNG.uniform(-pi, pi, (len(poses), 6))
    batch = ik_batch(poses, previous, algorithm)
    solve = ik.min_displacement if algorithm == "alg1" else ik.fsm
    for T, p, b in zip(poses, previous, batch, strict=True):
        s = solve(T, p).q
        if s is None:
            assert np.isnan(b).all()
        else:
            assert np.abs(np.array(s) - b).max() < 1e-9


def test_batched_blocks_cover_all_poses():
    poses = _poses_with_singular_ones(ik.BLOCK + 17)
    q, branch = ik.solve_batch(poses, np.zeros(6), "alg2")
    assert q.shape == (len(poses), 6) and ((branch >= 0) == ~np.isnan(q).any(axis=1)).all()

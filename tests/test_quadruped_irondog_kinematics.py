"""Iron Dog Mini's leg kinematics and gait (spec §8.1, §8.2): the Bezier basis, its endpoints, de Casteljau and the
spec's regression table, the gait path's continuity; IK/FK round trips of eqs. (38)-(40) both ways, the printed
misprint's error, a numerical IK as an independent solver, the leg Jacobian, and body IK."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from scipy.optimize import least_squares

from pipeline.core.experiment import CONF_DIR
from pipeline.papers.quadruped_irondog import gait
from pipeline.papers.quadruped_irondog import kinematics as kin

SYSTEM = yaml.safe_load((CONF_DIR / "system/quadruped-irondog.yaml").read_text())
P = np.asarray(SYSTEM["gait"]["control_points_mm"], dtype=float)
LEG = kin.Leg(SYSTEM["leg"]["L1"], SYSTEM["leg"]["L2"], SYSTEM["leg"]["L3"])
PRINTED = kin.Leg(LEG.L1, LEG.L2, LEG.L3, printed=True)
LAYOUT = kin.Layout(SYSTEM["body"]["length"], SYSTEM["body"]["hip_width"])
RNG = np.random.default_rng(7)


def _branch_poses(n: int) -> np.ndarray:
    """Leg poses on the IK's branch: θ3 ∈ (0, π) and the foot below the femur joint in the leg plane."""
    q = RNG.uniform([-1.0, -1.5, 0.05], [1.0, 1.5, 3.0], (4 * n, 3))
    below = kin.fk(kin.Leg(0.0, LEG.L2, LEG.L3), q)[:, 1] < -0.02
    return q[below][:n]


def test_bernstein_basis_is_a_partition_of_unity():
    s = np.linspace(0, 1, 201)
    basis = gait.bernstein(s, 13)
    assert np.abs(basis.sum(axis=1) - 1).max() < 1e-14 and (basis >= 0).all()


def test_bezier_endpoints_and_de_casteljau():
    assert np.allclose(gait.bezier(P, 0.0), P[0], atol=1e-12) and np.allclose(gait.bezier(P, 1.0), P[-1], atol=1e-12)
    for s in np.linspace(0, 1, 37):
        assert np.abs(gait.bezier(P, s) - gait.de_casteljau(P, s)).max() < 1e-10


def test_bezier_against_the_specs_regression_table():
    # spec §3.3 (derived with numpy, printed to 0.01 mm)
    a = [100.00, 116.26, 128.80, 109.71, 60.56, 2.43, -50.83, -95.98, -121.47, -113.42, -90.00]
    d = [-252.40, -241.15, -212.69, -182.52, -160.63, -153.09, -159.66, -177.09, -205.90, -240.57, -260.00]
    curve = gait.bezier(P, np.linspace(0, 1, 11))
    assert np.abs(curve - np.column_stack([a, d])).max() < 0.006


def test_bezier_derivative_is_the_curve_of_differences():
    s, h = np.linspace(0.05, 0.95, 19), 1e-6
    fd = (gait.bezier(P, s + h) - gait.bezier(P, s - h)) / (2 * h)
    assert np.abs(gait.bezier_derivative(P, s) - fd).max() < 1e-4
    # endpoint tangents: N (P1 − P0) and N (P13 − P12)
    assert np.allclose(gait.bezier_derivative(P, 0.0), 13 * (P[1] - P[0]))
    assert np.allclose(gait.bezier_derivative(P, 1.0), 13 * (P[-1] - P[-2]))


def test_trot_path_is_continuous_and_the_diagonals_alternate():
    trot = gait.Trot(P * 1e-3, swing_time=0.25, stance_time=0.25, a_sign=-1.0, lateral=LEG.L1)
    t = np.linspace(0, 2.0, 40001)
    feet, swing = trot.feet(t, 1.0)
    step = np.abs(np.diff(feet, axis=0)).max()
    assert step < 2e-4                                     # no jump anywhere, at lift-off and touch-down included
    fr, fl, br, bl = (swing[:, i] for i in range(4))
    assert (fl == br).all() and (fr == bl).all() and (fl != fr).all()
    assert fl[0] and not fr[0]                             # FL + BR swing first (Sec. 3.3)
    # the swing moves the foot forward, the stance back: the robot walks toward +x
    first = t < 0.25
    assert feet[first, 1, 2][-1] > feet[first, 1, 2][0]
    assert np.isclose(feet[0, 1, 2], -0.1) and np.isclose(feet[first, 1, 1][0], -0.2524)


def test_ik_inverts_fk_both_ways():
    q = _branch_poses(3000)
    p = kin.fk(LEG, q)
    assert np.abs(kin.ik(LEG, p) - q).max() < 1e-9            # IK(FK(q)) = q on the θ3 > 0 branch
    targets = kin.fk(LEG, RNG.uniform([-1.0, -2.0, 0.0], [1.0, 2.0, np.pi], (3000, 3)))
    assert np.nanmax(np.linalg.norm(kin.fk(LEG, kin.ik(LEG, targets)) - targets, axis=1)) < 1e-12


def test_printed_eq40_misplaces_the_foot():
    p = kin.fk(LEG, _branch_poses(500))
    error = np.linalg.norm(kin.fk(LEG, kin.ik(PRINTED, p)) - p, axis=1)
    assert np.nanmin(error) > 1e-3                             # every reachable pose is off by more than 1 mm


def test_ik_agrees_with_a_numerical_ik():
    for q in _branch_poses(20):
        p = kin.fk(LEG, q)
        guess = np.clip(q + RNG.normal(0, 0.2, 3), [-3, -3, 0.01], [3, 3, 3.1])
        numeric = least_squares(lambda x, p=p: kin.fk(LEG, x) - p, guess, bounds=([-3, -3, 0.0], [3, 3, np.pi]),
                                xtol=1e-15, ftol=1e-15, gtol=1e-15).x       # on the same branch: θ3 ≥ 0
        assert np.abs(kin.fk(LEG, numeric) - p).max() < 1e-10
        assert np.abs(kin.ik(LEG, p) - numeric).max() < 1e-6


def test_out_of_reach_is_nan():
    assert np.isnan(kin.ik(LEG, [LEG.L1, -0.5, 0.0])).any()            # beyond L2 + L3
    assert np.isnan(kin.ik(LEG, [0.01, 0.0, 0.1])).any()               # inside the coxa offset


def test_leg_jacobian_against_finite_differences():
    h = 1e-7
    for q in _branch_poses(30):
        fd = np.stack([(kin.fk(LEG, q + h * e) - kin.fk(LEG, q - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
        assert np.abs(kin.leg_jacobian(LEG, q) - fd).max() < 1e-7


def test_body_ik_moves_the_trunk_over_fixed_feet():
    q0 = np.tile(np.radians([0.0, -45.0, 90.0]), (4, 1))
    feet = kin.feet_in_body(LEG, LAYOUT, q0)
    assert np.allclose(kin.body_ik(LEG, LAYOUT, feet, np.zeros(3), np.zeros(3)), q0, atol=1e-12)
    position, rpy = np.array([0.02, -0.01, -0.015]), np.radians([5.0, -8.0, 10.0])
    q = kin.body_ik(LEG, LAYOUT, feet, position, rpy)
    # the feet, seen from the moved trunk, are where they were in the stance frame
    R = kin.rpy_matrix(rpy)
    assert np.abs(kin.feet_in_body(LEG, LAYOUT, q) @ R.T + position - feet).max() < 1e-12


def test_right_legs_mirror_left_legs():
    q = RNG.uniform(-0.5, 0.5, (4, 3))
    q[:, 2] = np.abs(q[:, 2])
    q[0], q[2] = q[1], q[3]                       # FR = FL, BR = BL
    feet = kin.feet_in_body(LEG, LAYOUT, q)
    mirror = np.array([1.0, -1.0, 1.0])
    assert np.allclose(feet[0], feet[1] * mirror) and np.allclose(feet[2], feet[3] * mirror)


@pytest.mark.parametrize("state", ["ideal", "standing"])
def test_table5_poses(state):
    t5 = SYSTEM["table5"][f"{state}_deg"]
    q = np.radians(np.column_stack([t5["coxa"], np.asarray(t5["femur"]) * SYSTEM["table5"]["femur_sign"],
                                    t5["tibia"]]))
    feet = kin.fk(LEG, q)
    if state == "ideal":                          # legs straight down
        assert np.allclose(feet, [LEG.L1, -(LEG.L2 + LEG.L3), 0.0])
    else:                                         # femur −45°, knee 90°: (L2 + L3)/√2 below, (L3 − L2)/√2 ahead
        assert np.allclose(feet[:, 1], -(LEG.L2 + LEG.L3) / np.sqrt(2), atol=1e-15)
        assert np.allclose(feet[:, 2], (LEG.L3 - LEG.L2) / np.sqrt(2), atol=1e-15)
        assert np.allclose(feet[:, 0], LEG.L1)

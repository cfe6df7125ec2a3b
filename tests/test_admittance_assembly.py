"""admittance-assembly: contact geometry against finite differences and the classical two-point relation,
the complementarity solver, condition (2) on hand-checked configurations, the admittance design, and
quasi-static insertions (no penetration, mirror symmetry)."""

from __future__ import annotations

import numpy as np
import pytest

from pipeline.core.checks import BadInput, preflight
from pipeline.papers.admittance_assembly import design, geometry, insertion, quasistatic
from pipeline.papers.admittance_assembly.geometry import PegInHole

DEG = np.pi / 180
RNG = np.random.default_rng(11)
PLANAR = PegInHole(True, (0.005, 0.005), 0.05, 0.035, (1e-4, 3e-4), 0.025)
SPATIAL = PegInHole(False, (0.005, 0.005), 0.05, 0.035, (1e-4, 3e-4), 0.025)
BOX = {True: np.array([[0.8 * DEG, 2 * DEG], [5e-5, 1.5e-4]]),
       False: np.array([[0.8 * DEG, 2 * DEG], [-0.3 * DEG, 0.3 * DEG], [0.1 * DEG, 0.3 * DEG], [-5e-5, 5e-5],
                        [5e-5, 1.5e-4]])}
SPEED = 0.005


def box_points(g: PegInHole, n: int) -> np.ndarray:
    bounds = BOX[g.planar]
    return bounds[:, 0] + RNG.random((n, len(bounds))) * np.ptp(bounds, axis=1)


def random_spd(n: int) -> np.ndarray:
    X = RNG.standard_normal((n, n))
    return X @ X.T + 0.1 * np.eye(n)


# -- geometry -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("g", [PLANAR, SPATIAL], ids=["planar", "spatial"])
def test_chart_puts_the_designated_pair_in_contact_and_nothing_else(g):
    coords = np.vstack([geometry.box_corners(BOX[g.planar]), box_points(g, 200)])
    R, p, clearance = geometry.chart_poses(g, coords)
    c = geometry.contacts(g, R, p, clearance)
    pair = list(geometry.designated_pair(g))
    assert np.abs(c.gap[:, pair]).max() < 1e-15 and c.valid[:, pair].all()
    others = np.delete(np.arange(len(g.names)), pair)
    assert (c.gap[:, others][c.valid[:, others]] > 0).all()


def test_planar_chart_obeys_the_classical_two_point_relation():
    # a peg of width 2b tilted by θ touching one wall with its tip corner and the opposite rim with its side,
    # the rim contact a distance ℓ from the tip: ℓ·sinθ + 2b·cosθ = 2B (B the hole's half-width)
    coords = box_points(PLANAR, 50)
    R, p, clearance = geometry.chart_poses(PLANAR, coords)
    c = geometry.contacts(PLANAR, R, p, clearance)
    rim = c.point[:, geometry.designated_pair(PLANAR)[1]]
    local = np.einsum("nji,nj->ni", R, rim - p)
    ell = local[:, 2] + PLANAR.ref_height
    theta, B = coords[:, 0], PLANAR.half_width[0] + clearance
    assert np.allclose(ell * np.sin(theta) + 2 * PLANAR.half_width[0] * np.cos(theta), 2 * B, rtol=0, atol=1e-15)
    # the tip centre by hand: the corner (-b, -h) sits on x = -B, the centre is b·(cos θ, -sin θ) from it
    tip = np.column_stack([-B + PLANAR.half_width[0] * np.cos(theta), np.zeros(50),
                           p[:, 2] - PLANAR.ref_height * np.cos(theta)])
    assert np.allclose(geometry.error_vector(PLANAR, R, p), tip - PLANAR.mated_point, atol=1e-15)


@pytest.mark.parametrize("g", [PLANAR, SPATIAL], ids=["planar", "spatial"])
def test_gap_rates_and_line_vector_equal_finite_differences(g):
    # ġ_i = w_iᵀv (the unit wrench is the gap's gradient: power identity) and dᵀv = δ·ṗ_sel (spec §8.1-8.2)
    R, p, _ = geometry.chart_poses(g, box_points(g, 20))
    h = 1e-5  # s: central differences, truncation ~h², round-off ~1e-16·|p|/h
    for Ri, pi in zip(R, p, strict=True):
        v = RNG.standard_normal(g.n) * np.where(geometry.TRANSLATION[g.dofs], 1e-3, 1e-2)
        c0 = geometry.contacts(g, Ri, pi)
        R1, p1 = geometry.se3_step(Ri, pi, geometry.full_twist(g, v), h)
        Rm, pm = geometry.se3_step(Ri, pi, geometry.full_twist(g, v), -h)
        c1, cm = geometry.contacts(g, R1, p1), geometry.contacts(g, Rm, pm)
        ok = c0.valid[0] & c1.valid[0] & cm.valid[0]
        W = geometry.unit_wrenches(g, Ri, pi, c0.point, c0.normal)[0]
        rate = (c1.gap[0] - cm.gap[0]) / (2 * h)
        assert np.allclose((W.T @ v)[ok], rate[ok], rtol=1e-6, atol=1e-12)
        d = geometry.line_vector(g, Ri, pi)[0]
        delta = geometry.error_vector(g, Ri, pi)[0]
        fd = (geometry.error_vector(g, R1, p1)[0] - geometry.error_vector(g, Rm, pm)[0]) / (2 * h)
        assert d @ v == pytest.approx(delta @ fd, rel=1e-6, abs=1e-15)


def test_se3_step_composes_and_inverts():
    R, p = geometry.rotation(0.3, -0.2, 0.7)[0], np.array([0.1, -0.2, 0.3])
    v = np.array([0.01, -0.02, 0.03, 0.4, -0.5, 0.6])
    R1, p1 = geometry.se3_step(*geometry.se3_step(R, p, v, 0.1), v, 0.2)
    R2, p2 = geometry.se3_step(R, p, v, 0.3)
    assert np.allclose(R1, R2, atol=1e-14) and np.allclose(p1, p2, atol=1e-14)
    R3, p3 = geometry.se3_step(R2, p2, v, -0.3)
    assert np.allclose(R3, R, atol=1e-14) and np.allclose(p3, p, atol=1e-14)


# -- complementarity -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_lcp_solutions_are_complementary(k):
    W = RNG.standard_normal((200, 6, k))
    M = np.einsum("nji,njk->nik", W, W) + 1e-3 * np.eye(k)
    q = RNG.standard_normal((200, k))
    lam = quasistatic.solve_lcp(M, q)
    rate = np.einsum("nij,nj->ni", M, lam) + q
    scale = np.abs(q).max()
    assert (lam >= 0).all() and (rate > -1e-9 * scale).all()
    assert np.abs(np.einsum("ni,ni->n", lam, rate)).max() < 1e-12 * scale ** 2  # spec §8.3


def test_two_contact_closed_form_equals_the_qp():
    W = RNG.standard_normal((300, 6, 2))
    M = np.einsum("nji,njk->nik", W, W) + 1e-2 * np.eye(2)
    q = RNG.standard_normal((300, 2))
    closed = quasistatic.solve_lcp(M, q)
    assert np.allclose(closed, [quasistatic._solve_lcp_nnls(Mi, qi) for Mi, qi in zip(M, q, strict=True)],
                       atol=1e-8)


def test_single_contact_closed_form_and_dissipation():
    # spec §8.5: one active contact, λ = -(w1ᵀv0)/(w1ᵀAw1) when w1ᵀv0 < 0
    A, w1, v0 = random_spd(6), RNG.standard_normal(6), RNG.standard_normal(6)
    v0 -= (max(w1 @ v0, 0.0) + 0.1) * w1 / (w1 @ w1)  # approaching
    lam, w, v = quasistatic.contact_response(A, w1[:, None], v0)
    assert lam[0] == pytest.approx(-(w1 @ v0) / (w1 @ A @ w1), rel=1e-12)
    assert w1 @ v == pytest.approx(0.0, abs=1e-12)  # it slides: no penetration, no separation
    assert w @ (v - v0) == pytest.approx(w @ A @ w) and w @ A @ w > 0  # the admittance only dissipates (§8.4)
    lam_away, _, v_away = quasistatic.contact_response(A, w1[:, None], -v0)
    assert lam_away[0] == 0 and np.allclose(v_away, -v0)


# -- condition (2) on hand-checked configurations -----------------------------------------------------------------


def test_condition_in_a_v_wedge_by_hand():
    # planar (v_x, v_z, ω_y): two contacts at x = ∓1 on faces of a 90° V, normals (±1, 1)/√2, A = I, v0 = -z.
    # Moments about y: m = z f_x - x f_z = ±1/√2. Symmetry: λ1 = λ2 = λ with W λ = (0, √2 λ, 0) = -v0,
    # so λ = 1/√2 and the body stops: v = 0, dᵀv = 0, and (2) (strict) fails for any d.
    s = 1 / np.sqrt(2)
    W = np.array([[s, -s], [s, s], [s, -s]])
    lam, _, v = quasistatic.contact_response(np.eye(3), W, np.array([0.0, -1.0, 0.0]))
    assert np.allclose(lam, [s, s]) and np.allclose(v, 0, atol=1e-15)
    assert not quasistatic.reduces_error(np.array([0.0, 1.0, 0.2]), v)


def test_condition_on_a_floor_with_a_coupled_admittance_by_hand():
    # pushed down onto a floor (normal +z at the origin), A couples z-force into x-motion: λ = 1,
    # v = v0 + A(0, 1, 0) = (0.5, 0, 0). It slides +x: error-reducing if the point is displaced to -x.
    A = np.array([[1.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 1.0]])
    lam, _, v = quasistatic.contact_response(A, np.array([[0.0], [1.0], [0.0]]), np.array([0.0, -1.0, 0.0]))
    assert lam[0] == pytest.approx(1.0) and np.allclose(v, [0.5, 0.0, 0.0])
    assert quasistatic.reduces_error(np.array([-1.0, 0.0, 0.0]), v)          # dᵀv = -0.5
    assert not quasistatic.reduces_error(np.array([1.0, 0.0, 0.0]), v)       # dᵀv = +0.5


def test_condition_in_the_planar_peg_by_hand():
    # At one two-point configuration, W and d written out by hand (R = Ry(θ)):
    #   contact 1: tip corner (-b, -h), body normal Rᵀ(1, 0) = (cos θ, sin θ), moment -h cos θ + b sin θ;
    #   contact 2: rim on the +x face at body height z2, body normal (-1, 0), moment -z2;
    #   d = (δ_x, δ_z, z_s δ_x - x_s δ_z) with δ_b = Rᵀδ and the tip centre at (x_s, z_s) = (0, -h).
    theta, clear = 1.4 * DEG, 1e-4
    R, p, _ = geometry.chart_poses(PLANAR, [theta, clear])
    b, h = PLANAR.half_width[0], PLANAR.ref_height
    ell = 2 * (b + clear - b * np.cos(theta)) / np.sin(theta)  # the classical relation
    W = np.array([[np.cos(theta), -1.0], [np.sin(theta), 0.0], [-h * np.cos(theta) + b * np.sin(theta), -(ell - h)]])
    c = geometry.contacts(PLANAR, R, p)
    pair = list(geometry.designated_pair(PLANAR))
    assert np.allclose(geometry.unit_wrenches(PLANAR, R, p, c.point[:, pair], c.normal[:, pair])[0], W, atol=1e-12)
    delta_b = R[0].T @ geometry.error_vector(PLANAR, R, p)[0]
    d = np.array([delta_b[0], delta_b[2], -h * delta_b[0]])
    assert np.allclose(geometry.line_vector(PLANAR, R, p)[0], d, atol=1e-15)
    # both contacts push (λ > 0): v is v0 projected on null(Wᵀ) in A⁻¹'s metric
    A = design.physical(PLANAR, np.eye(3), 2e-3)
    v0 = np.array([SPEED * np.sin(theta), -SPEED * np.cos(theta), 0.0])  # Rᵀ(0, 0, -s) in (x, z)
    lam = -np.linalg.solve(W.T @ A @ W, W.T @ v0)
    v = v0 + A @ W @ lam
    got_lam, _, got_v = quasistatic.contact_response(A, W, geometry.nominal_twist(PLANAR, R, SPEED)[0])
    assert (lam > 0).all() and np.allclose(got_lam, lam, rtol=1e-10) and np.allclose(got_v, v, atol=1e-15)
    assert abs(W.T @ v).max() < 1e-15  # it slides on both contacts
    assert d @ v < 0  # the tip is 19 mm above its mated point and goes down: (2) holds


# -- design ------------------------------------------------------------------------------------------------------


def test_designed_admittance_satisfies_the_corners_and_is_realisable():
    corners = design.state_samples(PLANAR, geometry.box_corners(BOX[True]), SPEED)
    result = design.design_admittance(PLANAR, corners, SPEED, min_eigenvalue=0.05, restarts=1, seed=0)
    eig = np.linalg.eigvalsh(result.A_hat)
    assert np.allclose(result.A_hat, result.A_hat.T) and eig.min() >= 0.05 - 1e-12
    assert np.trace(result.A_hat) == pytest.approx(3.0)
    margins = corners.margin(design.physical(PLANAR, result.A_hat, 1.0), SPEED)
    assert margins.min() == pytest.approx(result.corner_margin) and result.corner_margin > 0
    isotropic = corners.margin(design.physical(PLANAR, np.eye(3), 1.0), SPEED).min()
    assert result.corner_margin >= isotropic - 1e-9  # the scaled identity is one of the starts
    # condition (2) does not depend on A's scale
    assert np.allclose(corners.margin(design.physical(PLANAR, result.A_hat, 7.0), SPEED), margins)


# -- insertions -----------------------------------------------------------------------------------------------------


def test_planar_insertion_reaches_the_mated_depth_without_penetration_or_error_growth():
    R, p, _ = geometry.chart_poses(PLANAR, [1.4 * DEG, 1e-4])
    A = design.physical(PLANAR, np.eye(3), 2e-3)
    tr = insertion.insert(PLANAR, A, R[0], p[0], speed=SPEED, dt=0.004, duration=6.0, active_gap=2e-5)
    assert tr.outcome == "inserted"
    assert tr.gap.min() > -1e-9  # the time stepping never lets a gap close past zero
    error = np.linalg.norm(tr.delta, axis=1)[:-1]  # the last sample is past the mated depth
    assert (np.diff(error) <= 1e-12).all()
    assert error[-1] < 2 * 1e-4  # only the lateral play is left


def test_mirror_image_starts_give_mirror_image_insertions():
    # spec §8.6: reflect x -> -x; the isotropic A is mirror-symmetric, so the trajectories must be mirrored
    R, p, _ = geometry.chart_poses(SPATIAL, [1.2 * DEG, 0.0, 0.0, 0.0, 1e-4])
    M = np.diag([-1.0, 1.0, 1.0])
    A = design.physical(SPATIAL, np.eye(6), 2e-3)
    kw = {"speed": SPEED, "dt": 0.004, "duration": 1.0, "active_gap": 2e-5}
    a = insertion.insert(SPATIAL, A, R[0], p[0], **kw)
    b = insertion.insert(SPATIAL, A, M @ R[0] @ M, M @ p[0], **kw)
    assert len(a.t) == len(b.t)
    assert np.allclose(b.p, a.p @ M, atol=1e-10) and np.allclose(b.R, M @ a.R @ M, atol=1e-10)


def test_bad_physical_input_is_refused():
    for override in ("system.hole.clearance=[0,1e-4]", "system.admittance.min_eigenvalue=1.5",
                     "system.state.planar.tilt=[0.01,7]", "scenario.trials=0"):
        with pytest.raises(BadInput):
            preflight(["experiment=admittance-assembly/insertion", override])

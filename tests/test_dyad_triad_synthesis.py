"""dyad-triad-synthesis: Table 5 and the worked example from the algorithm, the cofactor
expansion, rank at every solution, agreement with an independent Burmester solve and with every complex root,
synthetic round trips of dyads and triads, Burmester curves through the poles, Table 1's counts, the closed-form
four-bar against Exudyn, and refusals of impossible problems."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import yaml

from analysis.core.targets import paper_value
from analysis.papers.dyad_triad_synthesis.metrics import PRINTED_TABLE5
from pipeline.papers.dyad_triad_synthesis import burmester, fourbar, multibody, synthetic
from pipeline.papers.dyad_triad_synthesis.compatibility import (
    Compatibility,
    isotropic_roots,
    loop_table,
    synthesize,
)
from pipeline.papers.dyad_triad_synthesis.standard_form import dyad, link_vectors, loops, system_rank, triad, turns

from .conftest import ROOT

SLUG = "dyad-triad-synthesis"
SYSTEM = yaml.safe_load((ROOT / "conf/system/dyad-triad-synthesis.yaml").read_text())
# Table 5 as printed (paper units, read from targets.csv): the target the algorithm is compared with
TABLE5 = {name: complex(paper_value(SLUG, f"T5.{key}.re"), paper_value(SLUG, f"T5.{key}.im"))
          for name, key in PRINTED_TABLE5.items()}


@pytest.fixture(scope="module")
def table4():
    unit = SYSTEM["length_unit"]
    points = np.array([complex(x, y) for x, y in SYSTEM["table4"]["points"]]) * unit
    return points, np.radians(SYSTEM["table4"]["alpha_deg"]), unit


@pytest.fixture(scope="module")
def worked(table4):
    points, alpha, _ = table4
    chain = dyad(points, alpha)
    return chain, synthesize(chain)


def test_table5_and_the_alignment_rotation_from_table4(table4):
    points, alpha, unit = table4
    delta = loop_table(loops(dyad(points, alpha)))
    assert list(delta) == list(TABLE5)
    for name, printed in TABLE5.items():
        assert abs(delta[name] / unit - printed) < 1e-3, name
    rotation = math.degrees(np.angle(delta["Δ2"]) - np.angle(delta["Δ2'"]))
    assert rotation == pytest.approx(paper_value(SLUG, "S2.5.alignment"), abs=0.005)
    bar = (delta["Δ2'"] * np.exp(1j * math.radians(rotation)) - delta["Δ2"]) / unit
    printed_bar = complex(paper_value(SLUG, "S2.5.parallelogram.re"), paper_value(SLUG, "S2.5.parallelogram.im"))
    assert abs(bar - printed_bar) < 2e-3          # Sec. 2.5's "Δ2 − Δ2'" is this vector


def test_compatibility_equation_is_the_cofactor_expansion_of_the_determinant():
    """det [e^{iβ}−1 | e^{iα}−1 | δ] over rows (2,3,m) equals Δ1 + Σ Δ_j e^{iβ_j} for any β (eqs. 7-8, 14-19);
    the triad's 4×4 determinant likewise (A1-A3)."""
    rng = np.random.default_rng(3)
    pts = rng.normal(size=5) + 1j * rng.normal(size=5)
    al = np.concatenate([[0], rng.uniform(0.1, 1.0, 4)])
    chain = dyad(pts, al)
    for _ in range(3):
        beta = np.concatenate([[0], rng.uniform(-math.pi, math.pi, 4)])
        a = np.column_stack([turns(beta)[1:] - 1, turns(al)[1:] - 1, pts[1:] - pts[0]])
        for loop in loops(chain):
            rows = [0, 1, loop.position - 2]
            assert np.linalg.det(a[rows]) == pytest.approx(loop.residual(beta), abs=1e-12)
    t = synthetic.random_triad(rng, 6, ungrounded=True)
    chain = triad(t.points, t.alpha, t.gamma, t.h)
    beta = np.concatenate([[0], rng.uniform(-math.pi, math.pi, 5)])
    a = np.column_stack([turns(t.alpha)[1:] - 1, turns(beta)[1:] - 1, turns(t.gamma)[1:] - 1, chain.rhs[1:]])
    for loop in loops(chain):
        assert np.linalg.det(a[[0, 1, 2, loop.position - 2]]) == pytest.approx(loop.residual(beta), abs=1e-12)
    one, two = loops(chain)
    assert one.last == two.last                             # the shared last link ("Δ4 used twice")
    assert one.fixed + one.shared.sum() + one.last == pytest.approx(0, abs=1e-15)


def test_worked_example_two_dyads_rank_two_and_independent_checks(table4, worked):
    points, alpha, _ = table4
    chain, found = worked
    labels = sorted(f.label for f in found)
    assert labels == ["solution", "solution", "special", "trivial"]
    dyads = [f for f in found if f.label == "solution"]
    for f in found:
        a = np.column_stack([chain.matrix(f.beta), chain.rhs[1:]])
        s = np.linalg.svd(a, compute_uv=False)
        assert s[2] < 1e-12 * s[0]                          # every 3×3 minor vanishes: rank ≤ 2
        for rows in itertools.combinations(range(4), 3):
            assert abs(np.linalg.det(a[list(rows)])) < 1e-14
    for f in dyads:                                         # each dyad moves the tracer through all five poses
        w, z = f.vectors
        ground = points[0] - z - w
        for j in range(5):
            assert abs(ground + w * np.exp(1j * f.beta[j]) + z * np.exp(1j * alpha[j]) - points[j]) < 1e-13
    # the Burmester circle-point condition by least squares, without cofactors
    direct = burmester.least_squares_dyads(points, alpha, 60, np.random.default_rng(0))
    assert len(direct) == 2
    for f in dyads:
        assert min(abs(w - f.vectors[0]) + abs(z - f.vectors[1]) for w, z in direct) < 1e-9
    # all six complex roots of the two compatibility equations; the real ones are the four found
    z = isotropic_roots(loops(chain))
    assert len(z) == 6
    real = z[np.abs(np.abs(z) - 1).max(axis=1) < 1e-9]
    assert len(real) == len(found)
    for f in found:
        assert np.abs(np.angle(real) - f.beta[1:3]).max(axis=1).min() < 1e-8


def test_beta2_range_the_paper_reads_is_where_both_loops_close(worked):
    chain, _ = worked
    compat = Compatibility(chain)
    beta2 = np.radians(np.arange(-179.5, 180, 0.5))
    closes = [np.isfinite(compat.evaluate(beta2[:, None], b)[1][:, 0]) for b in (1, -1)]
    loop2 = loops(chain)[1]
    inner, outer = abs(abs(loop2.shared[1]) - abs(loop2.last)), abs(loop2.shared[1]) + abs(loop2.last)
    second = np.abs(loop2.fixed + loop2.shared[0] * np.exp(1j * beta2))
    both = (closes[0] | closes[1]) & (second >= inner) & (second <= outer)
    assert math.degrees(beta2[both].max()) == pytest.approx(115.2, abs=0.5)
    assert math.degrees(beta2[both].min()) == pytest.approx(-28.1, abs=0.5)
    assert (closes[0] | closes[1]).mean() > both.mean()     # the Δ loop is the less limiting one


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_dyad_round_trip_from_a_four_bar(seed):
    s = synthetic.random_four_bar(np.random.default_rng(seed))
    truth = [np.array(d) for d in s.dyads()]
    scale = max(np.abs(t).max() for t in truth)
    found = [f.vectors for f in synthesize(dyad(s.points, s.alpha)) if f.label == "solution"]
    for t in truth:
        assert min(np.abs(v - t).max() for v in found) < 1e-9 * scale
    # four positions: the true dyad sits on the centre-point curve at its own β2
    chain4 = dyad(s.points[:4], s.alpha[:4])
    for t, beta in zip(truth, (s.beta_a, s.beta_b), strict=True):
        got = [f.vectors for f in synthesize(chain4, {2: beta[1]}) if f.label == "solution"]
        assert min(np.abs(v - t).max() for v in got) < 1e-9 * scale
        assert abs(burmester.center_point_condition(s.points, s.alpha, s.points[0] - t[1] - t[0])) < 1e-12
        assert abs(burmester.circle_point_condition(s.points, s.alpha, s.points[0] - t[1])) < 1e-12


@pytest.mark.parametrize(("n", "ungrounded"), [(5, False), (6, True), (7, False), (7, True)])
def test_triad_round_trip(n, ungrounded):
    rng = np.random.default_rng(10 + n)
    t = synthetic.random_triad(rng, n, ungrounded)
    chain = triad(t.points, t.alpha, t.gamma, t.h)
    free = {5: {2: t.beta[1], 5: t.beta[4]}, 6: {2: t.beta[1]}, 7: {}}[n]
    for loop in loops(chain):                                # the true β satisfy (20), (A2)-(A3), (A5)-(A7)
        assert abs(loop.residual(t.beta)) < 1e-13
    found = synthesize(chain, free, grid_2d=121)
    best = min(found, key=lambda f: np.abs(np.angle(np.exp(1j * (f.beta - t.beta)))).max())
    assert np.abs(np.angle(np.exp(1j * (best.beta - t.beta)))).max() < 1e-9
    assert np.abs(link_vectors(chain, best.beta).vectors - t.vectors).max() < 1e-9   # eq. (A4)
    assert best.label == "solution"


def test_triad_7pp_grid_finds_what_random_newton_finds():
    rng = np.random.default_rng(7)
    t = synthetic.random_triad(rng, 7, ungrounded=True)
    chain = triad(t.points, t.alpha, t.gamma, t.h)
    compat = Compatibility(chain)
    grid = [r.beta for r in compat.roots(grid_2d=121)]
    starts = np.zeros((1500, 7))
    starts[:, 1:] = rng.uniform(-math.pi, math.pi, (1500, 6))
    beta = compat.newton(starts)
    for b in beta[compat.converged(beta)]:
        assert min(np.abs(np.angle(np.exp(1j * (b - g)))).max() for g in grid) < 1e-6


def test_table1_free_choices_and_table3_delta_counts():
    rng = np.random.default_rng(0)
    for n, free in ((3, 2), (4, 1), (5, 0)):
        s = synthetic.random_four_bar(rng, n)
        equations, unknowns, rank = system_rank(dyad(s.points, s.alpha), np.array(s.dyads()[0]), s.beta_a)
        assert (equations, unknowns, unknowns - rank) == (2 * (n - 1), 4 + n - 1, free)
    for n, free, deltas in ((5, 2, 5), (6, 1, 9), (7, 0, 13)):
        t = synthetic.random_triad(rng, n, ungrounded=False)
        chain = triad(t.points, t.alpha, t.gamma, t.h)
        equations, unknowns, rank = system_rank(chain, t.vectors, t.beta)
        assert unknowns - rank == free == chain.free_choices
        assert len(loop_table(loops(chain))) == deltas


def test_burmester_curves_pass_through_poles_and_pi_points(table4):
    points, alpha, _ = table4
    p, a = points[:4], alpha[:4]
    poles = burmester.poles(p, a)
    assert max(abs(burmester.center_point_condition(p, a, v)) for v in poles.values()) < 1e-12
    circle = [poles[k] for k in ("P12", "P13", "P14")] + list(burmester.image_poles(p, a).values())
    assert max(abs(burmester.circle_point_condition(p, a, v)) for v in circle) < 1e-12
    assert min(abs(burmester.circle_point_condition(p, a, poles[k])) for k in ("P23", "P24", "P34")) > 1e-5
    pis = burmester.pi_points(p, a)
    assert max(abs(burmester.center_point_condition(p, a, v)) for v in pis.values()) < 1e-12
    images = burmester.pi_points(p, a, burmester.PI_IMAGE_LINES)
    assert max(abs(burmester.circle_point_condition(p, a, v)) for v in images.values()) < 1e-12
    assert np.isnan(burmester.pi_points(p, a, burmester.PI_LINES_PRINTED)["Π12"])      # eq. (23) as printed


def test_real_dyads_of_five_positions_come_in_zero_two_or_four():
    rng = np.random.default_rng(1)
    for _ in range(12):
        chain = dyad(rng.uniform(-1, 1, 5) + 1j * rng.uniform(-1, 1, 5),
                     np.concatenate([[0], np.cumsum(rng.uniform(0.05, 0.8, 4))]))
        found = synthesize(chain, grid=1801)
        assert sum(f.label == "solution" for f in found) in (0, 2, 4)
        assert sum(f.label in ("trivial", "special") for f in found) == 2
        assert len(isotropic_roots(loops(chain))) == 6


def test_wrong_number_of_free_choices_is_refused(table4):
    points, alpha, _ = table4
    with pytest.raises(ValueError, match="1 free choice"):
        Compatibility(dyad(points[:4], alpha[:4]))
    with pytest.raises(ValueError, match="at most 5"):
        dyad(np.ones(6), np.zeros(6))
    with pytest.raises(ValueError, match="6 precision points but 5"):
        dyad(np.ones(6), np.zeros(5))


# -- the four-bar --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def paper_four_bar(table4, worked):
    points, alpha, _ = table4
    _, found = worked
    a, b = sorted((f for f in found if f.label == "solution"), key=lambda f: abs(f.vectors[0]))
    fb = fourbar.FourBar.from_dyads(points[0], tuple(a.vectors), tuple(b.vectors))
    poses = [{"crank_A": a.beta[j], "coupler": alpha[j], "rocker_B": b.beta[j]} for j in range(5)]
    return fb, poses


def test_closed_form_four_bar_reaches_the_poses_and_has_a_branch_defect(table4, paper_four_bar):
    points = table4[0]
    fb, poses = paper_four_bar
    assert fb.grashof_margin() < 0                          # a triple rocker: one circuit
    for driver, link in (("A", "crank_A"), ("B", "rocker_B")):
        branches = [int(fb.branch_at(driver, p[link], p["coupler"])[0]) for p in poses]
        assert 0 not in branches
        for p, b, target in zip(poses, branches, points, strict=True):
            c = fb.solve(driver, p[link], b)
            assert abs(complex(c["p"]) - target) < 1e-12
        assert fourbar.cyclic_order_kept(fourbar.circuit_order(fb, driver, poses))
    assert [int(fb.branch_at("B", p["rocker_B"], p["coupler"])[0]) for p in poses] == [1, -1, -1, -1, -1]
    assert [fourbar.leg(fb, "B", poses[j], poses[j + 1]).toggles for j in range(4)] == [1, 0, 0, 0]
    assert [fourbar.leg(fb, "A", poses[j], poses[j + 1]).toggles for j in range(4)] == [0, 1, 0, 0]


def test_exudyn_closed_loop_agrees_with_the_closed_form(paper_four_bar):
    """Drive the rocker from pose 2 towards pose 3 in Exudyn: tracer and coupler equal the closed-form
    analysis at the rocker's rotation, the joints stay closed."""
    fb, poses = paper_four_bar
    leg = fourbar.leg(fb, "B", poses[1], poses[2])
    model = multibody.ExudynFourBar(fb, 1.0, 1e-3, 1e-3, 0.8, 1e-8, start=fb.solve("B", leg.start, leg.branches[0]))
    model.drive("B")
    for x in np.linspace(leg.start, leg.end, 101)[1:]:
        model.advance(x)
    model.finish()
    _, q, _ = model.fine()
    assert multibody.joint_gaps(model, q).max() < 1e-10
    tracer = multibody.points_of(model.bodies, q, 1, fb.p)
    closed = fb.solve("B", q[:, 2, 2], leg.branches[0])
    assert np.abs(tracer - closed["p"]).max() < 1e-10
    assert np.abs(q[:, 1, 2] - closed["coupler"]).max() < 1e-10
    assert q[-1, 2, 2] == pytest.approx(leg.end, abs=1e-12)


def test_reduced_inertia_matches_the_work_done_in_exudyn(paper_four_bar):
    """A constant rocker torque from rest at pose 3: ½ J(θ) θ̇² from the closed-form model equals the work
    τ (θ − θ0) that Exudyn's closed loop has absorbed (no gravity, no friction)."""
    fb, poses = paper_four_bar
    leg = fourbar.leg(fb, "B", poses[2], poses[3])
    branch = leg.branches[0]
    model = multibody.ExudynFourBar(fb, 1.0, 1e-4, 1e-3, 1.0, 1e-10, start=fb.solve("B", leg.start, branch))
    torque = 5.0
    for _ in range(300):
        model.advance(torque=torque)
    model.finish()
    q, qd = model.state()
    theta, rate = q[2, 2], qd[2, 2]
    j, _ = multibody.reduced_inertia(fb, model.bodies, "B", np.array([theta]), branch)
    assert 0.5 * j[0] * rate ** 2 == pytest.approx(torque * (theta - leg.start), rel=1e-3)

"""Partial Lagrangian: AD dynamics against closed forms and MuJoCo, the structure of Table 1 (eqs. 5, 7, 9),
energy, the PD rest postures of spec §8.5, the Listing A1 scheme, and the experiments end to end."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from analysis.papers.partial_lagrangian.metrics import _decay_rate, paper_term_counts, slope, static_equilibrium
from pipeline.papers.partial_lagrangian import Gains, MujocoChain, column_mass_bias, dynamics, energies, simulate
from pipeline.papers.partial_lagrangian.chain import PRISMATIC, REVOLUTE, double_pendulum, gravity_torque, planar_chain
from pipeline.papers.partial_lagrangian.lagrangian import FORMS, column, listing_a1_step, partial_lagrangian

from .conftest import run_cli

MASS, LENGTH = [3.0, 1.0] + [1.0] * 8, [2.0, 1.0] + [1.0] * 8   # the paper's links 1-2, links 3-10 assumed
RNG = np.random.default_rng(7)


def paper_chain(n: int, damping: float = 1.0, model: str = "cartesian", joints=None, angle=None):
    return planar_chain(n, MASS, LENGTH, [damping] * 10, [0.0] * 10, 9.8, model, joints, angle)


def slider_chain(damping: float = 1.0):
    return paper_chain(3, damping, joints=[REVOLUTE, PRISMATIC, REVOLUTE], angle=[0.0, 0.4, 0.0])


def random_state(chain, rng=RNG):
    q, qd, tau = rng.uniform(-np.pi, np.pi, chain.n), rng.uniform(-3, 3, chain.n), rng.uniform(-30, 30, chain.n)
    if PRISMATIC in chain.joints:
        q[chain.joints.index(PRISMATIC)] = rng.uniform(0.1, 1.5)
    return q, qd, tau


def mass_bias(dyn, q, qd):
    M, b = dyn.mass_bias(q, qd)
    return np.array(M), np.array(b).ravel()


def rel(a, b) -> float:
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


# -- closed forms ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("form", FORMS)
def test_double_pendulum_closed_form(form):
    chain = paper_chain(2, damping=0.0)
    dyn = dynamics(chain, form)
    for _ in range(20):
        q, qd, _ = random_state(chain)
        M, b = mass_bias(dyn, q, qd)
        M_c, b_c = double_pendulum(chain, q, qd)
        assert rel(M, M_c) < 1e-13 and rel(b, b_c) < 1e-12


@pytest.mark.parametrize("model, generalized", [("cartesian", 1.0 * 2.0 ** 2), ("joint", 1.0)])
def test_single_pendulum_closed_form(model, generalized):
    """M = m l², b = m g l cos θ + c θ̇ with c = d l² (Cartesian damping at the mass) or d (joint)."""
    chain = paper_chain(1, model=model)
    M, b = mass_bias(dynamics(chain), [0.3], [0.7])
    assert M[0, 0] == pytest.approx(3.0 * 4.0)
    assert b[0] == pytest.approx(3.0 * 9.8 * 2.0 * np.cos(0.3) + generalized * 0.7)


# -- full = partial, and Table 1's structure -----------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 3, 6, 10])
def test_partial_equals_full(n):
    chain = paper_chain(n)
    full, part = dynamics(chain, "full"), dynamics(chain, "partial")
    for _ in range(10):
        q, qd, tau = random_state(chain)
        a_full, a_part = (np.array(d.forward(q, qd, tau)).ravel() for d in (full, part))
        assert rel(a_part, a_full) < 1e-9


def test_partial_lagrangian_holds_only_the_root_side_coordinates():
    """Eq. (5): L_i does not contain q_k, q̇_k for k > i, so τ_ki = 0 for i < k."""
    import casadi as ca

    chain = paper_chain(5)
    q, qd = ca.SX.sym("q", 5), ca.SX.sym("qd", 5)
    for i in range(5):
        lagrangian, rayleigh = partial_lagrangian(chain, i, q, qd)
        for k in range(5):
            depends = ca.depends_on(lagrangian, q[k]) or ca.depends_on(lagrangian, qd[k])
            assert depends == (k <= i), (i, k)
            assert ca.depends_on(rayleigh, qd[k]) == (k <= i)


def _inverse(chain, q, qd, qdd):
    return np.array(dynamics(chain).inverse(q, qd, qdd)).ravel()


def _column(chain, i, q, qd, qdd):
    import casadi as ca

    qs, qds, qdds = ca.SX.sym("q", i + 1), ca.SX.sym("qd", i + 1), ca.SX.sym("qdd", i + 1)
    f = ca.Function("c", [qs, qds, qdds], [column(chain, i, qs, qds, qdds)])
    return np.array(f(q[:i + 1], qd[:i + 1], qdd[:i + 1])).ravel()


def test_extension_adds_one_column():
    """Eq. (7): τ of the chain extended by link n+1 = τ of the n-link chain (reused) + D_k L_{n+1}."""
    big = paper_chain(4)
    q, qd, qdd = (RNG.normal(size=4) for _ in range(3))
    tau_small = _inverse(big.prefix(3), q[:3], qd[:3], qdd[:3])
    tau_big = _inverse(big, q, qd, qdd)
    new = _column(big, 3, q, qd, qdd)
    assert np.allclose(tau_big[:3], tau_small + new[:3], rtol=0, atol=1e-10)
    assert tau_big[3] == pytest.approx(new[3], abs=1e-10)


def test_changing_the_last_link_replaces_one_column():
    """Eq. (9): a new link n changes τ by D_k L_{n,new} − D_k L_{n,old} only."""
    old = paper_chain(3)
    new = planar_chain(3, [3.0, 1.0, 2.5], [2.0, 1.0, 0.6], [1.0, 1.0, 0.3], [0.0, 0.0, 4.0], 9.8)
    q, qd, qdd = (RNG.normal(size=3) for _ in range(3))
    change = _inverse(new, q, qd, qdd) - _inverse(old, q, qd, qdd)
    assert np.allclose(change, _column(new, 2, q, qd, qdd) - _column(old, 2, q, qd, qdd), rtol=0, atol=1e-10)


def test_column_function_is_the_last_columns_mass_and_bias():
    """column_mass_bias(i) is the share of M and b that L_i contributes (timed as one thread's work)."""
    chain = paper_chain(3)
    q, qd, _ = random_state(chain)
    M, b = mass_bias(dynamics(chain), q, qd)
    M2, b2 = mass_bias(dynamics(chain.prefix(2)), q[:2], qd[:2])
    Mc, bc = (np.array(x) for x in column_mass_bias(chain, 2)(q, qd))
    assert np.allclose(M - np.pad(M2, ((0, 1), (0, 1))), Mc, atol=1e-12)
    assert np.allclose(b - np.r_[b2, 0.0], bc.ravel(), atol=1e-10)


# -- against MuJoCo ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("chain", [paper_chain(1), paper_chain(3), paper_chain(10), paper_chain(4, model="joint"),
                                   slider_chain()], ids=["n1", "n3", "n10", "n4-joint-damping", "slider"])
def test_agrees_with_mujoco(chain):
    """M, b and q̈ of the AD dynamics equal MuJoCo's model of the same chain (up to its 1e-10 point inertia)."""
    dyn, mj = dynamics(chain), MujocoChain(chain)
    for _ in range(10):
        q, qd, tau = random_state(chain)
        M, b = mass_bias(dyn, q, qd)
        M_mj, b_mj = mj.mass_bias(q, qd)
        assert rel(M, M_mj) < 1e-8 and rel(b, b_mj) < 1e-10
        assert rel(np.array(dyn.forward(q, qd, tau)).ravel(), mj.forward(q, qd, tau)) < 1e-7


def test_trajectory_agrees_with_mujoco():
    chain = paper_chain(3)
    traj = simulate(chain, np.zeros(3), np.zeros(3), Gains.free(3), 1e-3, 1.0)
    q_mj, _ = MujocoChain(chain, 1e-3).rollout(np.zeros(3), np.zeros(3), 1000)
    assert np.abs(traj.q[1:] - q_mj).max() < 1e-8


def test_gravity_by_statics_matches_the_dynamics():
    for chain in (paper_chain(4), slider_chain()):
        q, _, _ = random_state(chain)
        _, b = mass_bias(dynamics(chain), q, np.zeros(chain.n))
        assert np.allclose(gravity_torque(chain, q), b, atol=1e-10)


# -- energy --------------------------------------------------------------------------------------------------


def test_energy_is_conserved_without_damping():
    chain = paper_chain(3, damping=0.0)
    traj = simulate(chain, np.zeros(3), np.zeros(3), Gains.free(3), 1e-3, 2.0, integrator="rk4")
    total = energies(chain, traj.q, traj.qd)["total"]
    scale = np.sum(np.asarray(MASS[:3]) * 9.8 * np.cumsum(LENGTH[:3]))
    assert np.abs(total - total[0]).max() / scale < 1e-9


@pytest.mark.parametrize("model", ["cartesian", "joint"])
def test_damping_dissipates_twice_the_rayleigh_function(model):
    """dH/dt = τ·q̇ − 2R along the AD dynamics (central difference of H along q̈)."""
    chain = paper_chain(3, model=model)
    dyn, h = dynamics(chain), 1e-6
    q, qd, tau = random_state(chain)
    qdd = np.array(dyn.forward(q, qd, tau)).ravel()
    H = lambda s: energies(chain, q + s * qd, qd + s * qdd)["total"]  # noqa: E731
    rayleigh = energies(chain, q, qd)["rayleigh"]
    assert (H(h) - H(-h)) / (2 * h) == pytest.approx(tau @ qd - 2 * rayleigh, rel=1e-6)


# -- closed-form behaviour of the paper's runs (spec §8) -------------------------------------------------------


@pytest.mark.parametrize("model, rate", [("cartesian", 1.0 / 6.0), ("joint", 1.0 / 24.0)])
def test_one_link_small_oscillation_decay(model, rate):
    """About the hanging rest, the envelope decays at c/(2 m l²): 0.1667 1/s (Cartesian), 0.0417 1/s (joint)."""
    chain = paper_chain(1, model=model)
    traj = simulate(chain, [-np.pi / 2 + 0.05], [0.0], Gains.free(1), 1e-3, 30.0, integrator="rk4")
    assert _decay_rate(traj.t, traj.q[:, 0]) == pytest.approx(rate, rel=0.01)


def _config(n: int) -> dict:
    return {"system": {"links": {"mass": MASS, "length": LENGTH, "damping": [1.0] * 10, "stiffness": [0.0] * 10},
                       "gravity": 9.8, "damping_model": "cartesian"}}


@pytest.mark.parametrize("n, reference, kp, rest_deg", [
    (1, [110.0], [200.0], [117.88]),                       # spec §8.5
    (2, [80.0, 30.0], [100.0, 50.0], [49.71, 27.52]),       # spec §8.5
])
def test_pd_rest_posture(n, reference, kp, rest_deg):
    """The PD law without gravity compensation rests at Kp (θref − θ) = ∂P/∂θ; the simulated run gets there."""
    rest = static_equilibrium(_config(n), n, np.radians(reference), np.asarray(kp))
    assert np.degrees(rest) == pytest.approx(rest_deg, abs=0.005)
    gains = Gains(np.radians(reference), np.asarray(kp), np.zeros(n), np.asarray([50.0, 20.0][:n]))
    traj = simulate(paper_chain(n), np.zeros(n), np.zeros(n), gains, 1e-3, 15.0)
    assert np.degrees(traj.q[-1]) == pytest.approx(rest_deg, abs=0.02)


# -- Listing A1 --------------------------------------------------------------------------------------------------


def test_listing_a1_stores_half_the_acceleration():
    chain = paper_chain(1)
    theta, omega = 0.4, -0.8
    true = float(dynamics(chain).forward(theta, omega, 0.0))
    _, _, acc = (float(x) for x in listing_a1_step(chain)(theta, omega, 0.0, 0.0, 1e-6))
    assert acc == pytest.approx(true / 2, rel=1e-4)


def test_listing_a1_converges_to_the_lagrange_equations_at_first_order():
    from pipeline.papers.partial_lagrangian.rollout import simulate_listing_a1

    chain = paper_chain(1)
    deviation = []
    for dt in (2e-3, 1e-3):
        listing = simulate_listing_a1(chain, [0.0], [0.0], Gains.free(1), dt, 3.0)
        exact = simulate(chain, [0.0], [0.0], Gains.free(1), dt / 10, 3.0, integrator="rk4")
        deviation.append(np.abs(listing.q[:, 0] - exact.q[::10, 0]).max())
    assert deviation[0] / deviation[1] == pytest.approx(2.0, rel=0.1)


def test_listing_a1_refuses_more_than_one_dof():
    with pytest.raises(ValueError, match="one revolute DoF"):
        listing_a1_step(paper_chain(2))


# -- the paper's complexity model and our slope fit ----------------------------------------------------------------


def test_term_counts_and_slope():
    eq28, eq29 = paper_term_counts(np.array([1, 2, 3, 10]))
    assert list(eq28) == [3, 24, 90, 6600] and list(eq29) == [3, 16, 45, 1200]   # spec §5 table
    n = np.arange(1, 11)
    assert slope(n, 2e-6 * n ** 3.0) == pytest.approx(3.0)


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_symbolic_counts_are_the_terms_of_the_expanded_equations(n):
    """The ring count of each link equals expanding the usual L and its τ_k with sympy.expand: no term of one
    link merges with another's, so τ_k has the terms of Table 1's row k summed."""
    from pipeline.papers.partial_lagrangian.symbolic import expanded_counts, link_counts

    links = [link_counts(i) for i in range(n)]
    lagrangian, taus = expanded_counts(n)
    assert lagrangian == sum(link.lagrangian for link in links)
    assert taus == [sum(link.tau[k] for link in links[k:]) for k in range(n)]


def test_symbolic_counts_of_one_link_and_their_structure():
    """One link: L = ½ m l² θ̇² − ½ k l² − m g l sin θ (3 terms), τ = m l² θ̈ + m g l cos θ (2). Every link has
    as many derivatives as coordinates, and the counts of a link do not depend on the links after it."""
    from pipeline.papers.partial_lagrangian.symbolic import link_counts

    one = link_counts(0)
    assert (one.lagrangian, one.d_angle, one.d_rate, one.tau) == (3, [1], [1], [2])
    third = link_counts(2)
    assert len(third.tau) == len(third.d_angle) == len(third.d_rate) == 3
    assert all(t > 0 for t in third.tau) and third.tau[0] == max(third.tau)


# -- end to end ------------------------------------------------------------------------------------------------------


def test_slider_and_compute_time_end_to_end(data_dir):
    for args in (["experiment=partial-lagrangian/slider"],
                 ["experiment=partial-lagrangian/compute-time", "scenario.links=[1,2,3,4]", "scenario.states=10",
                  "scenario.eval_repeats=3", "scenario.build_repeats=1"],
                 ["experiment=partial-lagrangian/term-counts", "scenario.links=[1,2,3,4]"]):
        proc = run_cli("pipeline", *args, f"data_dir={data_dir}", "progress=false")
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr
    targets = pd.read_csv(data_dir / "report/targets.csv").set_index("target_id")
    assert targets.loc["F4.l2", "status"] == "match"
    page = (data_dir / "report/partial-lagrangian.md").read_text()
    assert "Compute time by number of links" in page and "Measured on" in page
    assert "Terms of the symbolic equations of motion" in page
    # a chain of n links is links 1..n: all its τ_ki are the columns summed
    counts = pd.read_parquet(data_dir / "metrics/partial-lagrangian/term-counts.parquet").set_index("metric")["value"]
    assert counts["sym.all_tau.n4"] == sum(counts[f"sym.column.n{n}"] for n in (1, 2, 3, 4))
    assert counts["eq28.n4"] == 240 and counts["sym.ratio.n4"] == counts["sym.all_tau.n4"] / counts["sym.column.n4"]
    assert list((data_dir / "figures/partial-lagrangian/slider").glob("*.png"))


@pytest.mark.parametrize(("override", "says"), [
    ("scenario.links=[1,11]", "out of range"), ("system.links.mass=[0,1,1,1,1,1,1,1,1,1]", "out of range"),
    ("system.simulation.integrator=euler", "must be one of semi-implicit-euler, rk4"),
])
def test_bad_input_is_refused(override, says):
    experiment = "compute-time" if override.startswith("scenario.links") else "two-link"
    proc = run_cli("pipeline", f"experiment=partial-lagrangian/{experiment}", override, "data_dir=/nonexistent")
    assert proc.returncode == 2 and says in proc.stderr and len(proc.stderr.strip().splitlines()) == 1

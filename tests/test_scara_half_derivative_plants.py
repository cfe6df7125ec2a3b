"""scara-half-derivative: the two plants are the same arm. The Exudyn closed chain (KinematicTree + exact
loop constraint) and the reduced Lagrangian model (CasADi, RK4) agree on the kinetic energy, on rest,
on energy conservation and on open- and closed-loop trajectories (spec §8 checks 2-4)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from pipeline.core.checks import compose_config
from pipeline.papers.scara_half_derivative.arm import mass_matrix_from_links
from pipeline.papers.scara_half_derivative.closed_loop import PlantSettings, make_plant, run_closed_loop
from pipeline.papers.scara_half_derivative.controller import CartesianController
from pipeline.papers.scara_half_derivative.experiments import arm_of, gains, home, motion_of
from pipeline.papers.scara_half_derivative.lagrange import LagrangePlant, energy_functions
from pipeline.papers.scara_half_derivative.multibody import ExudynPlant

TS = 0.005
FINE_EXUDYN = 5e-5        # s: generalized-α is second order; at 50 µs its error here is ~2e-9 rad
RK4_SUBSTEPS = 50         # 0.1 ms RK4 steps: error far below the Exudyn one


@pytest.fixture(scope="module")
def cfg():
    return compose_config(["experiment=scara-half-derivative/table2"])


@pytest.fixture(scope="module")
def arm(cfg):
    return arm_of(cfg)


def _random_states(cfg, count: int, seed: int):
    rng = np.random.default_rng(seed)
    q = home(cfg) + rng.uniform(-0.4, 0.4, (count, 4))
    qd = rng.uniform(-1.0, 1.0, (count, 4))
    return q, qd


def _exudyn(arm, q, qd, step=FINE_EXUDYN, spectral_radius=0.9):
    return ExudynPlant(arm, q, qd, TS, step, spectral_radius, 1e-10)


def test_kinetic_energy_agrees(cfg, arm):
    """½ θ̇ᵀ M θ̇: the CasADi Lagrangian, the link Jacobians and Exudyn's own link velocities."""
    mass_matrix, _ = energy_functions(arm)
    for q, qd in zip(*_random_states(cfg, 4, seed=5), strict=True):
        M = mass_matrix(q).full()
        np.testing.assert_allclose(M, mass_matrix_from_links(arm, q), atol=1e-12)
        kinetic_exudyn = _exudyn(arm, q, qd).energy() - _exudyn(arm, q, np.zeros(4)).energy()
        assert kinetic_exudyn == pytest.approx(0.5 * qd @ M @ qd, rel=1e-12, abs=1e-12)


def test_balanced_arm_stays_at_rest(cfg, arm):
    """With zero torque at θ_ref the spring holds gravity exactly (eq. 13), in both plants."""
    q0 = home(cfg)
    for plant in (_exudyn(arm, q0, np.zeros(4), step=1e-3), LagrangePlant(arm, q0, np.zeros(4), TS, 5, 200)):
        for _ in range(200):
            plant.advance(np.zeros(4))
        q, qd = plant.state()
        np.testing.assert_allclose(q, q0, atol=1e-12)
        np.testing.assert_allclose(qd, 0.0, atol=1e-12)


def test_energy_is_conserved_without_control(cfg, arm):
    """τ = 0 from a moving state: gravity + spring + kinetic energy stays constant for 1 s; Exudyn's loop
    closure stays closed."""
    (q0,), (qd0,) = _random_states(cfg, 1, seed=7)
    _, energy = energy_functions(arm)
    lagrange = LagrangePlant(arm, q0, qd0, TS, 10, 200)
    exudyn = _exudyn(arm, q0, qd0, step=2.5e-4, spectral_radius=1.0)
    e_lagrange, e_exudyn = float(energy(q0, qd0)), exudyn.energy()
    gap = 0.0
    for _ in range(200):
        lagrange.advance(np.zeros(4))
        exudyn.advance(np.zeros(4))
        gap = max(gap, exudyn.loop_residual())
    assert float(energy(*lagrange.state())) == pytest.approx(e_lagrange, abs=1e-9 * abs(e_lagrange) + 1e-9)
    assert exudyn.energy() == pytest.approx(e_exudyn, rel=1e-8)   # trapezoidal rule (ρ∞ = 1), 0.25 ms
    assert gap < 1e-9


def test_open_loop_trajectories_agree(cfg, arm):
    """Random held torques every period for 0.2 s: the two plants agree to < 1e-8 rad."""
    (q0,), (qd0,) = _random_states(cfg, 1, seed=11)
    tau = np.random.default_rng(12).normal(0.0, 5.0, (40, 4))
    lagrange = LagrangePlant(arm, q0, qd0, TS, RK4_SUBSTEPS, len(tau))
    exudyn = _exudyn(arm, q0, qd0)
    for t in tau:
        lagrange.advance(t)
        exudyn.advance(t)
    np.testing.assert_allclose(exudyn.state()[0], lagrange.state()[0], atol=1e-8)


def test_closed_loop_trajectories_agree(cfg, arm):
    """KDHD (K = 8e4, the Table 2 intermediate tuning) through the first move of the set-point: < 1e-8 rad."""
    motion, q0 = motion_of(cfg, arm), home(cfg)
    _, g = gains(cfg, 8e4, 2500.0, 23600.0)
    runs = []
    for settings in (PlantSettings("exudyn", FINE_EXUDYN, 0.9, 1e-10),
                     PlantSettings("lagrange", TS / RK4_SUBSTEPS, 0.9, 1e-10)):
        plant = make_plant(settings, arm, q0, np.zeros(4), TS, 80)
        runs.append(run_closed_loop(plant, CartesianController(arm, g, TS, 10), motion, 0.4, TS))
    exudyn, lagrange = runs
    assert np.abs(exudyn.q[-1] - q0).max() > 0.1   # it really moved
    np.testing.assert_allclose(exudyn.tau, lagrange.tau, atol=1e-5)
    stride = round(lagrange.t[1] / exudyn.t[1]) if lagrange.t[1] > exudyn.t[1] else 1
    np.testing.assert_allclose(exudyn.q[::stride], lagrange.q, atol=1e-8)


def test_production_plants_give_the_same_metrics(cfg, arm):
    """The settings the experiments use (Exudyn at 1 ms for Table 2, RK4 at 1 ms for the maps) give the
    same Table 2 indexes on the whole 15.6 s motion, so the maps may run on the faster plant."""
    motion, q0 = motion_of(cfg, arm), home(cfg)
    _, g = gains(cfg, 8e4, 5000.0, 0.0)
    periods = round(motion.duration / TS)
    out = []
    for kind in ("exudyn", "lagrange"):
        plant = make_plant(PlantSettings(kind, 1e-3, 0.9, 1e-8), arm, q0, np.zeros(4), TS, periods)
        run = run_closed_loop(plant, CartesianController(arm, g, TS, 10), motion, motion.duration, TS)
        from pipeline.papers.scara_half_derivative.arm import fk

        e = motion(run.t)[0][:, :3] - fk(arm, run.q)[:, :3]
        out.append((np.abs(e).max(axis=0), np.abs(e).mean(axis=0), np.trapezoid((e ** 2).sum(axis=1), run.t),
                    (run.tau ** 2).sum() * TS))
    for exudyn, lagrange in zip(*out, strict=True):
        np.testing.assert_allclose(exudyn, lagrange, rtol=1e-3)


# -- the batched closed loop (maps, paths and sweeps) ---------------------------------------------------------


def _single(cfg, arm, g, duration, difference=False):
    motion, q0 = motion_of(cfg, arm), home(cfg)
    plant = make_plant(PlantSettings("lagrange", 1e-3, 0.9, 1e-8), arm, q0, np.zeros(4), TS, round(duration / TS))
    return run_closed_loop(plant, CartesianController(arm, g, TS, 10, difference=difference), motion, duration, TS)


@pytest.mark.parametrize("implementation", ["sampled", "sampled-difference"])
def test_batch_equals_single_runs(cfg, arm, implementation):
    """Many tunings in one mapped CasADi call give, tuning by tuning, the single closed loop to round-off."""
    from pipeline.papers.scara_half_derivative.batch import simulate

    tunings = [gains(cfg, 8e4, d, hd)[1] for d, hd in ((5000.0, 0.0), (2500.0, 23600.0), (0.0, 47200.0))]
    out = simulate(arm, tunings, motion_of(cfg, arm), home(cfg), 0.6, TS, 5, 10, implementation)
    assert out.failures == [None, None, None]
    for g, run in zip(tunings, out.runs, strict=True):
        single = _single(cfg, arm, g, 0.6, difference=implementation == "sampled-difference")
        assert np.abs(single.q[-1] - home(cfg)).max() > 0.05          # it moved
        np.testing.assert_allclose(run.q, single.q, atol=1e-12)
        np.testing.assert_allclose(run.tau, single.tau, atol=1e-8)


def test_continuous_law_is_eq_11_at_every_step(cfg, arm):
    """The `continuous` implementation evaluates eq. (11) + τ_g inside the integrator: the torque it reports at
    each integration step equals the law computed in NumPy from that step's state and set-point (KD: no held
    half-derivative), and it differs from the sampled run's held torque within a period."""
    from pipeline.papers.scara_half_derivative.arm import fk, gravity_torque, jacobian
    from pipeline.papers.scara_half_derivative.batch import fk_jacobian_sx, simulate

    q = home(cfg) + np.random.default_rng(3).uniform(-0.3, 0.3, (5, 4))
    sym = ca.SX.sym("q", 4)
    x_sx, J_sx = fk_jacobian_sx(arm, sym)
    symbolic = ca.Function("fkj", [sym], [x_sx, J_sx])
    for qi in q:
        x, J = (v.full() for v in symbolic(qi))
        np.testing.assert_allclose(x.ravel(), fk(arm, qi), atol=1e-14)
        np.testing.assert_allclose(J, jacobian(arm, qi), atol=1e-14)

    _, g = gains(cfg, 8e4, 5000.0, 0.0)
    motion = motion_of(cfg, arm)
    run = simulate(arm, [g], motion, home(cfg), 0.4, TS, 5, 10, "continuous").runs[0]
    t, state = run.t[:-1], np.concatenate([run.q, run.qd], axis=1)[:-1]
    x_d, xd_d, _ = motion(t)
    J = jacobian(arm, state[:, :4])
    force = g.K * (x_d - fk(arm, state[:, :4])) + g.D * (xd_d - np.einsum("nij,nj->ni", J, state[:, 4:]))
    law = np.einsum("nji,nj->ni", J, force)
    law[:, 2] += gravity_torque(arm, state[:, 2])
    np.testing.assert_allclose(run.tau_fine, law, atol=1e-9)
    assert np.abs(np.diff(run.tau_fine[:5], axis=0)).max() > 1e-3     # not held over the period


def test_a_diverging_tuning_fails_alone(cfg, arm):
    """In a batch, a tuning whose loop diverges is a failure with its reason; the others are unaffected."""
    from pipeline.papers.scara_half_derivative.batch import simulate

    stable, unstable = gains(cfg, 8e4, 5000.0, 0.0)[1], gains(cfg, 8e5, 5000.0, 0.0)[1]   # 8e5: unstable here
    out = simulate(arm, [stable, unstable], motion_of(cfg, arm), home(cfg), 0.6, TS, 5, 10, "sampled-difference")
    assert out.runs[1] is None and out.failures[1].startswith("unstable:")
    np.testing.assert_allclose(out.runs[0].q, _single(cfg, arm, stable, 0.6, difference=True).q, atol=1e-12)

"""itbot-smc's reaching laws and controller (checks 5-7 of the reproduction plan): reaching times in closed form,
eq. (7) and the Γ identity (15), Proposition 1's threshold where it is exact, the closed-loop identity v̇ = r,
the exponential sliding phase, and the Hall-sensor model."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from omegaconf import OmegaConf
from scipy import integrate

from pipeline.core.checks import compose_config
from pipeline.papers.itbot_smc import reaching
from pipeline.papers.itbot_smc.closed_loop import Reference, run_closed_loop
from pipeline.papers.itbot_smc.controller import JointSensor
from pipeline.papers.itbot_smc.experiments import Setup
from pipeline.papers.itbot_smc.plants import AnalyticPlant, joint_accelerations
from pipeline.papers.itbot_smc.reaching import LawGains

TABLE3 = LawGains(K=2.0, phi=0.1, alpha=2.0, p=0.5, power=0.25, smc_K=2.0, boundary_layer=0.0)   # joint 1


@pytest.fixture(scope="module")
def setup() -> Setup:
    return Setup.of(compose_config(["experiment=itbot-smc/tracking"]).system)


@pytest.mark.parametrize("v0", [0.05, 1.0, 40.0])
def test_smc_reaches_in_v0_over_k_and_erl_in_eq7(v0):
    assert reaching.reaching_time(reaching.smc, v0, TABLE3) == pytest.approx(v0 / TABLE3.smc_K, rel=1e-8)
    assert reaching.reaching_time(reaching.smc, -v0, TABLE3) == pytest.approx(v0 / TABLE3.smc_K, rel=1e-8)
    eq7 = reaching.erl_reaching_time(v0, TABLE3.K, TABLE3.phi, TABLE3.alpha, TABLE3.p)
    assert reaching.reaching_time(reaching.smerl, v0, TABLE3) == pytest.approx(eq7, rel=1e-7)


@pytest.mark.parametrize("v0", [0.05, 2.0, 60.0])
def test_the_fast_reaching_times_equal_direct_integration(v0):
    fast = reaching.reaching_times(v0, TABLE3)
    for name, law in (("smc", reaching.smc), ("smerl", reaching.smerl), ("nsmerl", reaching.nsmerl),
                      ("nsmerl_no_switching", lambda v, t, g, lib=np: reaching.nsmerl(v, t, g, lib, switching=False))):
        assert fast[name] == pytest.approx(reaching.reaching_time(law, v0, TABLE3), rel=1e-6), name


def test_bound_14_needs_p_at_least_1():
    """(14) bounds eq. (7) by Γ(1 + 1/p) ≤ 1, true for p ≥ 1 only: Table 3's p = 0.5 breaks it at large |v0|."""
    for v0 in np.geomspace(0.01, 100, 30):
        assert reaching.erl_reaching_time(v0, 2.0, 0.1, 2.0, 1.5) <= reaching.erl_bound(v0, 2.0, 0.1, 2.0, 1.5)
    assert reaching.erl_reaching_time(50.0, 2.0, 0.1, 2.0, 0.5) > reaching.erl_bound(50.0, 2.0, 0.1, 2.0, 0.5)


def test_threshold_27_is_the_crossover_in_the_proofs_limit():
    """With α → ∞ the ERL gain is K/φ off the surface and eq. (6) without its ω-term gives
    T = φ|v0|^(1−ϕ)/(K(1−ϕ)) against ERL's φ|v0|/K: equal exactly at |v0| = (1 − ϕ)^(−1/ϕ)."""
    g = dataclasses.replace(TABLE3, alpha=1e6)
    for v0 in (0.5, 3.0, 30.0):
        times = reaching.reaching_times(v0, g)
        assert times["smerl"] == pytest.approx(g.phi * v0 / g.K, rel=1e-6)
        assert times["nsmerl_no_switching"] == pytest.approx(g.phi * v0 ** 0.75 / (g.K * 0.75), rel=1e-6)
    threshold = reaching.proposition_threshold(0.25)
    assert threshold == pytest.approx(0.75 ** -4)
    assert reaching.crossover(g, (0.05, 100.0), switching=False) == pytest.approx(threshold, rel=1e-6)


def test_gamma_identity_15():
    for v0 in (0.1, 1.0, 10.0):
        numeric, _ = integrate.quad(lambda v: math.exp(-2.0 * v ** 0.5) * v ** -0.25, 0, v0)
        assert reaching.gamma_integral(v0, 2.0, 0.5, 0.25) == pytest.approx(numeric, rel=1e-8)


@pytest.mark.parametrize("law", reaching.LAWS)
def test_every_law_decreases_the_lyapunov_function(law):
    v = np.concatenate([-np.geomspace(1e-6, 1e3, 50), np.geomspace(1e-6, 1e3, 50)])
    for t in (0.0, 0.3, 5.0, 100.0):
        for g in (TABLE3, dataclasses.replace(TABLE3, boundary_layer=0.1)):
            assert (v * reaching.REACHING_LAWS[law](v, t, g) < 0).all()
    assert reaching.REACHING_LAWS[law](0.0, 0.0, TABLE3, math) == 0.0   # sign(0) = 0


@pytest.mark.parametrize("law", reaching.LAWS)
def test_closed_loop_gives_vdot_equal_r_with_a_perfect_model(setup, law):
    """Eq. (5) with the plant's own model (no drive, friction or hand damping mismatch): at a tick, the plant's
    θ̈ under the computed τ makes v̇ = θ̈ − θ̈_d + λ(θ̇ − θ̇_d) equal the reaching law r(v, t) to round-off."""
    from pipeline.papers.itbot_smc.controller import SlidingModeController
    from pipeline.papers.itbot_smc.plants import Drive, HandLoad, PlantModel

    load = HandLoad(setup.load.weight, setup.load.arm, 0.0, 0.3)
    drive = Drive(100.0, setup.drive.rotor_inertia, (0.0, 0.0), 0.01, (1e3, 1e3))
    model = PlantModel.of(setup.links, drive, load)
    gains = LawGains.from_config(setup.system.control)
    controller = SlidingModeController(law, gains, (40.0, 50.0), model.links, armature=drive.armature,
                                       hand_support=model.support_force)
    rng = np.random.default_rng(1)
    for _ in range(20):
        t = float(rng.uniform(0, 3))
        q, qd, q_d, qd_d, qdd_d = (rng.normal(0, 0.5, 2) + c for c in ([0.2, 1.5], 0, [0.2, 1.5], 0, 0))
        tau = controller(t, q, qd, q_d, qd_d, qdd_d)
        qdd = np.array(joint_accelerations(model, *q, *qd, *tau))
        v_dot = qdd - qdd_d + np.array([40.0, 50.0]) * (qd - qd_d)
        r = [reaching.REACHING_LAWS[law](v, t, gains.joint(i), math) for i, v in enumerate(controller.v)]
        assert np.abs(v_dot - r).max() < 1e-9 * max(1.0, np.abs(r).max())


def test_on_the_surface_the_error_decays_as_exp_minus_lambda_t(setup):
    """With r ≡ 0 (SMC with K = 0) and v(0) = 0 (ė(0) = −λ e(0)), exact states and a matched model, the error
    follows e(t) = e(0) exp(−λ t), up to the sampling (10 kHz here: the held torque leaves ~λT/2 of e(0))."""
    system = OmegaConf.merge(setup.system, {"control": {"smc": {"gain_scale": 1e-12}, "model": {"armature": True},
                                                        "rate_hz": 10_000.0},
                                            "drive": {"friction": [0.0, 0.0]}, "hand": {"damping": 0.0}})
    s = Setup.of(system)
    s = dataclasses.replace(s, reference=Reference(s.reference.start, 0 * s.reference.amplitude, 1.0, 1))
    lam = np.array([40.0, 50.0])
    e0 = np.radians([0.5, -0.5])
    plant = AnalyticPlant(s.links, s.drive, s.load, s.period, 1, s.reference.start + e0, -lam * e0)   # v(0) = 0
    run = run_closed_loop(plant, s.controller("smc"), s.sensor(), s.reference, s.period, s.drive.torque_limit)
    e = run.q - s.reference(run.t)[0]
    expected = e0 * np.exp(-lam * run.t[:, None])
    assert np.abs(e - expected).max() < 5e-3 * np.abs(e0).max()
    assert np.abs(run.v).max() < 5e-3 * np.abs(lam * e0).max()


def test_hall_sensor_quantises_and_estimates_velocity():
    period, resolution = 1e-3, math.radians(0.075)
    sensor = JointSensor(resolution, "difference", 20.0, period)
    rate = 0.3                                                        # rad/s, a ramp
    estimates = []
    for k in range(2000):
        q = np.array([rate * k * period, -rate * k * period])
        q_m, qd_m = sensor(q, None)
        assert np.abs(np.subtract(q_m, q)).max() <= resolution / 2 + 1e-15
        estimates.append(qd_m)
    # the backward difference of quantised positions averages to the true rate
    assert np.mean(estimates[1:], axis=0) == pytest.approx([rate, -rate], rel=2e-3)
    filtered = JointSensor(resolution, "filtered", 20.0, period)
    noisy, smooth = [], []
    for k in range(2000):
        q = np.array([rate * k * period, 0.0])
        noisy.append(sensor(q, None)[1][0])
        smooth.append(filtered(q, None)[1][0])
    assert np.std(smooth[500:]) < 0.3 * np.std(noisy[500:])
    assert np.mean(smooth[500:]) == pytest.approx(rate, rel=5e-2)
    exact = JointSensor(0.0, "exact", 20.0, period)
    assert exact(np.array([0.1, 0.2]), np.array([0.3, 0.4])) == ((0.1, 0.2), (0.3, 0.4))

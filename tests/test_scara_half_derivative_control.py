"""scara-half-derivative: the Grünwald–Letnikov half-derivative (eqs. 15-16), the stiffness compensation
(eq. 17) and the sign conventions of the control law (spec §8 checks 5 and 8)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import binom, gamma

from pipeline.core.checks import compose_config
from pipeline.core.runlog import SimulationFailed
from pipeline.papers.scara_half_derivative.closed_loop import PlantSettings, make_plant, run_closed_loop
from pipeline.papers.scara_half_derivative.controller import CartesianController, Gains
from pipeline.papers.scara_half_derivative.experiments import arm_of, gains, home, motion_of
from pipeline.robotics.fractional import GrunwaldLetnikov, gl_dc_gain, gl_frequency_response, gl_weights
from pipeline.robotics.profiles import trapezoid

TS, N = 0.005, 10


def test_gl_coefficients_closed_form():
    w = gl_weights(0.5, N)
    np.testing.assert_allclose(w[:4], [1.0, -0.5, -0.125, -0.0625])                      # eq. (16)
    np.testing.assert_allclose(w, [(-1) ** j * binom(0.5, j) for j in range(N + 1)], rtol=1e-13)
    np.testing.assert_allclose(w[1:], [gamma(j - 0.5) / (gamma(-0.5) * gamma(j + 1)) for j in range(1, N + 1)],
                               rtol=1e-12)
    assert w.sum() == pytest.approx(gamma(N + 0.5) / (gamma(0.5) * gamma(N + 1)), rel=1e-13)
    assert w.sum() == pytest.approx(0.176197052, abs=1e-9)
    assert gl_dc_gain(0.5, N, TS) == pytest.approx(2.491803, abs=1e-6)   # Σw/√Ts of eq. (17)


def test_full_memory_gl_converges_to_riemann_liouville():
    """D^½[t] = 2√(t/π), D^½[1] = 1/√(πt), with memory n = t/T (not the short-memory filter)."""
    T, t = 1e-4, 0.5
    n = round(t / T)
    w = gl_weights(0.5, n)
    samples = (t - np.arange(n + 1) * T)   # f((k − j) T) for f(t) = t
    assert w @ samples / math.sqrt(T) == pytest.approx(2 * math.sqrt(t / math.pi), rel=1e-3)
    assert w.sum() / math.sqrt(T) == pytest.approx(1 / math.sqrt(math.pi * t), rel=1e-3)


def test_gl_frequency_response():
    """With long memory the filter is (jω)^½ between 1/L and π/T: gain √ω, phase 45°; √2/√T at Nyquist."""
    T, n = 1e-3, 200_000
    omega = np.array([2.0, 10.0, 50.0])
    G = gl_frequency_response(0.5, n, T, omega)
    np.testing.assert_allclose(np.abs(G), np.sqrt(omega), rtol=0.02)
    np.testing.assert_allclose(np.angle(G, deg=True), 45.0, atol=1.0)
    nyquist = gl_frequency_response(0.5, n, T, np.array([math.pi / T]))[0]
    assert abs(nyquist) == pytest.approx(math.sqrt(2 / T), rel=1e-3)
    # the paper's short filter: its DC gain is the compensated Σw/√T
    assert gl_frequency_response(0.5, N, TS, np.array([0.0]))[0].real == pytest.approx(gl_dc_gain(0.5, N, TS))


def test_streaming_filter_is_the_convolution():
    rng = np.random.default_rng(3)
    e = rng.normal(size=(40, 4))
    f = GrunwaldLetnikov(0.5, N, TS, width=4)
    out = np.array([f.push(x) for x in e])
    padded = np.vstack([np.zeros((N, 4)), e])   # zero history before the first sample
    w = gl_weights(0.5, N) / math.sqrt(TS)
    direct = np.array([w @ padded[k + N - np.arange(N + 1)] for k in range(len(e))])
    np.testing.assert_allclose(out, direct, atol=1e-12)


@pytest.fixture(scope="module")
def cfg():
    return compose_config(["experiment=scara-half-derivative/table2"])


def test_stiffness_compensation_keeps_the_static_stiffness(cfg):
    """Eq. (17): a constant error e0 gives F = K e0 once the filter's memory is full (eq. 14 does not)."""
    arm = arm_of(cfg)
    q = home(cfg)
    g = Gains(k_xyz=8e4, k_theta=500.0, d_xyz=2500.0, d_theta=3.75, hd_xyz=23600.0, hd_theta=24.0)
    from pipeline.papers.scara_half_derivative.arm import fk, jacobian

    e0 = np.array([1e-3, -2e-3, 5e-4, 1e-3])
    J = jacobian(arm, q)
    for compensate, expected in ((True, g.K), (False, g.K + gl_dc_gain(0.5, N, TS) * g.HD)):
        controller = CartesianController(arm, g, TS, N, compensate_stiffness=compensate)
        for _ in range(N + 1):
            tau = controller(q, np.zeros(4), fk(arm, q) + e0, np.zeros(4))
        force = np.linalg.solve(J.T, tau)   # τ_g,3 is zero at the balanced pose
        np.testing.assert_allclose(force, expected * e0, rtol=1e-12)


def _single_axis_lag(k: float, d: float, hd: float, compensate: bool, mass: float) -> tuple[float, float, float]:
    """A mass under the sampled law F = K' e + D ė + HD e^½ (ZOH at 5 ms, exact integration of each
    period) following a trapezoidal profile: (mean error and acceleration while accelerating, largest error
    at constant velocity)."""
    accel_time, duration = 0.5, 3.0
    f = GrunwaldLetnikov(0.5, N, TS, width=1)
    k_eff = k - (gl_dc_gain(0.5, N, TS) * hd if compensate else 0.0)
    x = v = 0.0
    t = np.arange(round(duration / TS)) * TS
    s, sv, sa = trapezoid(t, 1.0, duration, accel_time / duration)
    errors = np.empty(len(t))
    for i in range(len(t)):
        e = s[i] - x
        errors[i] = e
        force = k_eff * e + d * (sv[i] - v) + hd * f.push(np.array([e]))[0]
        a = force / mass
        x, v = x + v * TS + 0.5 * a * TS ** 2, v + a * TS
    accelerating = (t > 0.35) & (t < accel_time)            # the transient (time constant 0.05 s) has settled
    cruising = (t > accel_time + 0.7) & (t < duration - accel_time)
    return errors[accelerating].mean(), sa[accelerating].mean(), np.abs(errors[cruising]).max()


@pytest.mark.parametrize("hd, compensate", [(0.0, True), (600.0, True), (600.0, False)])
def test_single_axis_lag_is_m_a_over_k(hd, compensate):
    """Spec §8.8: constant acceleration a gives the steady lag m a / K (the compensated KDHD keeps K; eq. 14
    stiffens the axis by 2.49 HD); constant velocity gives no lag, since ė uses ẋ_d."""
    mass, k = 20.0, 2.0e4
    lag, accel, cruise_error = _single_axis_lag(k, 800.0, hd, compensate, mass)
    stiffness = k if compensate else k + gl_dc_gain(0.5, N, TS) * hd
    assert lag == pytest.approx(mass * accel / stiffness, rel=2e-3)
    assert cruise_error < 1e-3 * lag


def test_printed_hd_theta_destabilises_the_rotation(cfg):
    """hd_θ = 2.4e4 as printed makes k_θ − 2.49 hd_θ < 0: the rotation diverges; the assumed 24 holds it."""
    arm = arm_of(cfg)
    motion = motion_of(cfg, arm)
    q0 = home(cfg) + np.array([0.0, 0.0, 0.0, 0.01])   # 0.01 rad off in θ4 only: rotation alone is excited
    _, g = gains(cfg, 8e4, 2500.0, 23600.0)
    settings = PlantSettings("lagrange", 1e-3, 0.9, 1e-8)
    for hd_theta, stable in ((g.hd_theta, True), (2.4e4, False)):
        gains_ = Gains(**{**vars(g), "hd_theta": hd_theta})
        plant = make_plant(settings, arm, q0, np.zeros(4), TS, 100)
        controller = CartesianController(arm, gains_, TS, N)
        if stable:
            run = run_closed_loop(plant, controller, motion, 0.5, TS)
            assert abs(run.q[-1, [0, 1, 3]].sum()) < 1e-3   # the end-effector's yaw θ = θ1+θ2+θ4 returns to 0
        else:
            with pytest.raises(SimulationFailed):
                run_closed_loop(plant, controller, motion, 0.5, TS)

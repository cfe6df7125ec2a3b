"""forrest-biped: the capture-point generators (Sec. 5) and the LIP under CP control, against closed forms and an
independent integrator."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from pipeline.papers.forrest_biped import generator as gen
from pipeline.papers.forrest_biped import lipm
from pipeline.papers.forrest_biped.support import support_polygons

from .conftest import ROOT

SYSTEM = yaml.safe_load((ROOT / "conf/system/forrest-biped.yaml").read_text())
WALK = SYSTEM["walk"]
OMEGA = float(np.sqrt(SYSTEM["gravity"] / WALK["z_c"]))
HALF = (SYSTEM["model"]["foot_length"] / 2, SYSTEM["model"]["foot_width"] / 2)


def rk4_lip(seg: gen.Segments, x0: np.ndarray, v0: np.ndarray, omega: float, t_end: float, dt: float) -> np.ndarray:
    """ẍ = ω²(x − p(t)) by classical RK4 (independent of the closed form); the knots lie on the step grid, and p is
    taken inside the step (its left limit at the step's end), so each step sees one linear piece."""
    x, v = x0.astype(float), v0.astype(float)
    for k in range(round(t_end / dt)):
        t = k * dt

        def f(tt, xx, vv, t=t):
            inside = min(max(tt, t + 1e-12), t + dt - 1e-12)
            return vv, omega**2 * (xx - seg.zmp(np.array([inside]))[0])

        k1 = f(t, x, v)
        k2 = f(t + dt / 2, x + dt / 2 * k1[0], v + dt / 2 * k1[1])
        k3 = f(t + dt / 2, x + dt / 2 * k2[0], v + dt / 2 * k2[1])
        k4 = f(t + dt, x + dt * k3[0], v + dt * k3[1])
        x = x + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return np.concatenate([x, v])


def test_closed_form_matches_rk4_on_a_random_piecewise_linear_zmp():
    rng = np.random.default_rng(1)
    knots = np.array([0.0, 0.2, 0.35, 0.7, 1.0])
    seg = gen.Segments(knots, rng.uniform(-0.1, 0.1, (4, 3)), rng.uniform(-0.5, 0.5, (4, 3)))
    x0, v0 = rng.uniform(-0.05, 0.05, 3), rng.uniform(-0.2, 0.2, 3)
    x, v, a, xi = gen.lip_response(seg, x0, v0, OMEGA, np.array([1.0]))
    reference = rk4_lip(seg, x0, v0, OMEGA, 1.0, 1e-4)
    assert np.abs(np.r_[x[0], v[0]] - reference).max() < 1e-9
    assert np.abs(xi - (x + v / OMEGA)).max() < 1e-12                      # eqs. (41), (46)
    assert np.abs(a - OMEGA**2 * (x - seg.zmp(np.array([1.0])))).max() < 1e-12


@pytest.mark.parametrize("P0, P2", [(0.0, 0.2), (0.12, -0.12), (0.75, 0.72), (-0.3, 0.05)])
def test_corrected_eq48_brings_the_cp_onto_P2(P0, P2):
    T1, T3 = WALK["T1"], WALK["T3"]
    T2 = WALK["step_time"] - T1 - T3
    P1 = gen.p1_corrected(P0, P0, P2, OMEGA, T1, T2, T3)
    assert gen.cp_at_end(P0, P0, P1, P2, OMEGA, T1, T2, T3) == pytest.approx(P2, abs=1e-12)     # eq. (47)
    # and by propagating the three phases of eq. (46)
    seg = gen.Segments(np.array([0, T1, T1 + T2, T1 + T2 + T3]), np.array([[P0] * 3, [P1] * 3, [P1] * 3]),
                       np.array([[(P1 - P0) / T1] * 3, [0.0] * 3, [(P2 - P1) / T3] * 3]))
    xi = gen.lip_response(seg, np.full(3, P0), np.zeros(3), OMEGA, np.array([T1 + T2 + T3 - 1e-12]))[3]
    assert xi[0, 0] == pytest.approx(P2, abs=1e-9)
    printed = gen.p1_printed(P0, P0, P2, OMEGA, T1, T2, T3)
    if np.isfinite(printed):
        assert abs(gen.cp_at_end(P0, P0, printed, P2, OMEGA, T1, T2, T3) - P2) > 1e-3


def test_the_paper_example_of_P1():
    """T1 = T3 = 0.1 s, T2 = 0.8 s, z_c = 0.8 m: P1 just behind the support foot (x) and outside it (y)."""
    w = np.sqrt(9.81 / 0.8)
    assert gen.p1_corrected(0.0, 0.0, 0.2, w, 0.1, 0.8, 0.1) == pytest.approx(-0.00894, abs=1e-5)
    assert gen.p1_corrected(0.12, 0.12, -0.12, w, 0.1, 0.8, 0.1) == pytest.approx(0.13073, abs=1e-5)


@pytest.mark.parametrize("kind", ["extended", "traditional"])
def test_pattern_is_consistent_and_its_zmp_stays_in_the_support_polygon(kind):
    p = gen.pattern(WALK, kind, OMEGA, 1e-3)
    assert np.abs(p.cp - (p.com + p.com_vel / OMEGA)).max() < 1e-12
    assert np.abs(np.diff(p.com, axis=0)).max() < 1e-3                     # CoM continuous
    assert np.abs(np.diff(p.com_vel, axis=0)).max() < 5e-3                 # and its velocity
    polygons = support_polygons(p, HALF, 0.0)
    outside = [float((A @ z[:2] - b).max()) for (A, b), z in zip(polygons, p.zmp, strict=True)]
    assert max(outside) < 1e-9
    assert p.support.tolist().count(gen.LEFT) == p.support.tolist().count(gen.RIGHT) == 900


def test_extended_zmp_is_continuous_and_meets_the_cp_at_every_step_end():
    p = gen.pattern(WALK, "extended", OMEGA, 1e-3)
    assert np.abs(np.diff(p.zmp, axis=0)).max() < 0.0025                    # ramps: ≤ 0.24 m / 0.1 s per ms
    for t0, P2 in zip(p.steps.t0, p.steps.P2, strict=True):
        end = round((t0 + p.steps.T) * 1e3)
        assert np.abs(p.cp[end] - P2).max() < 1e-9
    trad = gen.pattern(WALK, "traditional", OMEGA, 1e-3)
    jump = np.abs(np.diff(trad.com_acc, axis=0)).max()
    assert jump == pytest.approx(OMEGA**2 * WALK["foot_spacing"], rel=0.02)   # ω² |Δp| at a foot switch


def test_footsteps_alternate_and_advance_by_the_step_length():
    s = gen.walk_steps(WALK)
    assert s.support.tolist() == [gen.DOUBLE, gen.LEFT, gen.RIGHT, gen.DOUBLE]
    assert np.allclose(s.swing_to[1:3, 0], [0.2, 0.4]) and np.allclose(s.swing_to[1:3, 1], [-0.12, 0.12])
    assert np.allclose(s.P2[-1], [0.3, 0.0, WALK["z_c"]])


def test_cp_error_decays_like_exp_minus_kt_on_the_ideal_lip():
    """Eq. (49): with p^c of eq. (50) the CP error obeys ė = −k e. Standing reference, initial CP offset."""
    k, dt, n = 5.0, 1e-4, 10001
    t = np.arange(n) * dt
    still = np.zeros((n, 3))
    ref = gen.Pattern("still", OMEGA, t, still, still, still, still, still, np.zeros((2, n, 3)),
                      np.zeros((2, n, 3)), np.zeros((2, n, 3)), np.zeros(n, dtype=int), None, None)
    x0 = np.array([0.01, -0.02, 0.0])
    r = lipm.simulate(ref, k, None, dt, x0=x0, v0=np.zeros(3))
    expected = x0 * np.exp(-k * t[:, None])
    assert np.abs(r.cp - expected).max() < 2e-3 * np.abs(x0).max()        # the hold: O(k dt)
    # and each held cycle exactly: e_{j+1} = e_j (1 + k/ω − (k/ω) e^{ω dt})
    factor = 1 + k / OMEGA - k / OMEGA * np.exp(OMEGA * dt)
    assert np.allclose(r.cp[1:, :2], r.cp[:-1, :2] * factor, rtol=1e-9, atol=1e-15)


def test_lip_clamps_the_zmp_into_the_polygon():
    p = gen.pattern(WALK, "extended", OMEGA, 1e-3)
    polygons = support_polygons(p, HALF, 0.01)
    r = lipm.simulate(p, 5.0, polygons, 1e-3, x0=p.com[0] + np.array([0.05, 0.0, 0.0]))
    outside = [float((A @ z[:2] - b).max()) for (A, b), z in zip(polygons, r.zmp_cmd, strict=True)]
    assert max(outside) < 1e-9

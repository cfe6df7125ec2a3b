"""Spherical robots on 3-D terrain: the paths of Sec. 6, the pursuit laws (55)-(58) in their closed-form
limits, the printed signs against the corrected ones, and the integrator against its own step."""

from __future__ import annotations

import numpy as np
import pytest
from omegaconf import OmegaConf

from analysis.papers.spherical_terrain.metrics import convergence_time
from pipeline.core.checks import compose_config
from pipeline.papers.spherical_terrain import CosineTerrain, GainTable, Model, circle, controls, diamond, simulate
from pipeline.papers.spherical_terrain.experiments import run_batch
from pipeline.papers.spherical_terrain.paths import on_surface, vertex_times
from pipeline.papers.spherical_terrain.tracking import start_states

R = 0.2
FLAT = CosineTerrain(0.0, 2.0)
UNIT = OmegaConf.create({"class_3r": {"k_theta": 1, "k_phi1": 1, "k_phi2": 1, "k_psi": 1},
                         "class_2r": {"k_theta1": 1, "k_theta2": 1, "k_phi1": 1, "k_phi2": 1},
                         "class_rt": {"k_theta": 1, "k_psi": 1}, "class_rs": {"k_alpha": 1, "k_phi": 1}})


def make_model(classes, terrain=FLAT, gains=UNIT, k_e=1.0, heading="corrected", eq58="corrected"):
    return Model(terrain, R, k_e, np.pi / 3, GainTable.build(classes, gains, 1.0, eq58), heading)


def line(t, speed=0.1, k=1):
    """Target on the x axis moving at `speed`, starting 1 m ahead (flat ground)."""
    p = np.zeros((len(t), k, 3))
    p[:, :, 0] = 1.0 + speed * t[:, None]
    v = np.zeros_like(p)
    v[:, :, 0] = speed
    return p, v


def test_circle_and_diamond_of_sec6():
    t = np.linspace(0, 130, 2601)
    xy, v = circle(t)
    assert np.allclose(np.hypot(*xy.T), 2.0) and np.allclose(np.hypot(*v.T), 0.1)
    assert np.allclose(xy[0], [2, 0]) and np.allclose(np.gradient(xy, t, axis=0)[5:-5], v[5:-5], atol=1e-5)
    printed, _ = circle(t, form="printed")
    assert np.allclose(printed[:, 0], printed[:, 1])              # eq. (60) as printed: the line y = x
    xy, v = diamond(t)
    assert np.allclose(np.abs(xy).sum(axis=1), 2.0)               # |x| + |y| = 2: diagonals of 4 m
    assert np.allclose(np.hypot(*v.T), 0.1)
    assert np.allclose(vertex_times(130.0)[:3], [0.0, 20 * np.sqrt(2), 40 * np.sqrt(2)])
    p, p_dot = on_surface(CosineTerrain(), xy, v)
    fx, fy = CosineTerrain().gradient(xy[:, 0], xy[:, 1])
    assert np.allclose(p[:, 2], CosineTerrain().height(xy[:, 0], xy[:, 1]))
    assert np.allclose(p_dot[:, 2], fx * v[:, 0] + fy * v[:, 1])


def test_signed_deviation_angle_and_the_direction_each_law_turns():
    """Target to the left (ζ = +π/2) of a robot heading +x on flat ground."""
    state = np.zeros((1, 6))
    target, speed = np.array([[0.0, 1.0, 0.0]]), np.array([0.1])
    for heading, turn_sign in (("corrected", 1.0), ("printed", -1.0)):
        c = controls(make_model(["3r"], heading=heading), state, target, speed)
        assert c["zeta"][0] == pytest.approx(np.pi / 2)
        assert c["turn"][0] > 0                                    # ψ̇ = k_ψ ζ ...
        h_next = np.cos(0.01 * c["turn"][0]) * np.array([1, 0]) + turn_sign * np.sin(0.01 * c["turn"][0]) * np.array(
            [0, 1])
        assert np.sign(h_next[1]) == turn_sign                     # ... turns toward the target only if corrected
        assert c["v"][0] > 0                                       # φ̇ < 0 rolls left, toward the target
    for eq58, toward in (("corrected", True), ("printed", False)):
        c = controls(make_model(["rs"], eq58=eq58), state, target, speed)
        tilt = c["tilt"][0]
        assert (c["v"][0] > 0) == toward                           # lateral term −R φ̇ l̂
        after = controls(make_model(["rs"], eq58=eq58), np.array([[0, 0, 0, 0, 0.01 * tilt, 0]]), target, speed)
        assert (after["turn"][0] > 0) == toward                    # eq. (44) with the tilt it built


def test_2r_steady_state_error_closed_form():
    """Spec §8.6: a 2R-SR chasing a target on a straight line at v_d settles where R(k1 g + k2) = v_d:
    g* = (v_d/R − k2)/k1, e_ss = k_e g*/(1 − g*). Three gain sets, one robot each (k_e per robot)."""
    k1, k2, k_e = np.array([1.0, 2.0, 1.0]), np.array([0.2, 0.1, 0.4]), np.array([1.0, 0.5, 0.3])
    expected = [0.42857, 0.125, 0.033333]
    zero = np.zeros(3)
    gains = GainTable(roll_g=k1, roll_0=k2, feedforward=zero, lat_g=k1, lat_0=k2, tilt=zero, turn=zero,
                      steering=np.zeros(3, dtype=bool))
    dt = 0.01
    t = np.arange(20001) * dt
    p_d, v_d = line(t, k=3)
    traj = simulate(Model(FLAT, R, k_e, np.pi / 3, gains), dt, p_d, v_d, start_states(FLAT, 3, 0, 0, 0), 1000)
    error = np.linalg.norm(traj.p_d - traj.state[..., :3], axis=-1)[-1]
    g = (0.1 / R - k2) / k1
    assert k_e * g / (1 - g) == pytest.approx(expected, rel=1e-4)
    assert error == pytest.approx(expected, rel=1e-4)


def test_feed_forward_classes_close_the_gap_on_a_line():
    """Spec §8.7: 3R, RT, RS carry the bias ‖ṗ_d‖/R, so on a straight path the error goes to ~0."""
    dt = 0.005
    t = np.arange(round(40 / dt) + 1) * dt
    p_d, v_d = line(t, k=3)
    traj = simulate(make_model(["3r", "rt", "rs"]), dt, p_d, v_d, start_states(FLAT, 3, 0, 0.5, 0), 200)
    error = np.linalg.norm(traj.p_d - traj.state[..., :3], axis=-1)
    assert error[0].min() > 0.9 and (error[-1] < 5e-3).all()


def test_printed_heading_never_converges_for_3r_and_rt():
    dt = 0.005
    t = np.arange(round(60 / dt) + 1) * dt
    p_d, v_d = line(t, k=2)
    traj = simulate(make_model(["3r", "rt"], heading="printed"), dt, p_d, v_d, start_states(FLAT, 2, 0, 0.5, 0),
                    200)
    assert (np.linalg.norm(traj.p_d - traj.state[..., :3], axis=-1)[-1] > 0.5).all()


def test_rs_tilt_never_passes_its_limit_and_z_stays_on_the_surface():
    dt = 0.005
    fast_tilt = OmegaConf.merge(UNIT, {"class_rs": {"k_phi": 10.0}})
    model = make_model(["rs", "3r"], terrain=CosineTerrain(), gains=fast_tilt)
    t = np.arange(round(40 / dt) + 1) * dt
    p_d = np.zeros((len(t), 2, 3))
    p_d[:, :, :] = [0.5, 2.3, CosineTerrain().height(0.5, 2.3)]   # a target to the left: the tilt saturates
    traj = simulate(model, dt, p_d, np.zeros_like(p_d), start_states(CosineTerrain(), 2, 0.5, 0.3, 0.0), 20)
    assert np.abs(traj.state[:, 0, 4]).max() == pytest.approx(np.pi / 3)
    assert np.allclose(traj.state[..., 2], CosineTerrain().height(traj.state[..., 0], traj.state[..., 1]))


def test_default_runs_are_converged_in_the_step():
    """Errors at the default dt = 5 ms agree with half the step (RS on the diamond excluded: it is chaotic
    after the third vertex, the assumption on dt says so)."""
    base = ["experiment=spherical-terrain/paths", "scenario.classes=[3r,2r,rt]", "scenario.paths=[diamond]",
            "system.duration=35"]
    runs = {}
    for dt in (0.005, 0.0025):
        _, pairs, traj = run_batch(compose_config([*base, f"system.dt={dt}"]))
        runs[dt] = np.linalg.norm(traj.p_d - traj.state[..., :3], axis=-1)
    coarse, fine = runs[0.005], runs[0.0025]
    assert np.abs(coarse - fine).max() < 0.01
    assert len(pairs) == 3


def test_convergence_time_is_the_last_entry_into_the_band():
    t = np.linspace(0.0, 10.0, 10001)
    assert convergence_time(t, np.exp(-t), 0.1) == pytest.approx(np.log(10.0), abs=1e-3)
    bump = np.exp(-t) + 0.2 * (np.abs(t - 6.0) < 0.5)               # leaves the band once more at 5.5-6.5 s
    assert convergence_time(t, bump, 0.1) == pytest.approx(6.5, abs=1e-3)
    assert np.isnan(convergence_time(t, np.full_like(t, 0.2), 0.1))


def test_gain_table_builds_the_four_laws():
    table = GainTable.build(["3r", "2r", "rt", "rs"], UNIT, 2.0, "corrected")
    assert table.feedforward.tolist() == [1, 0, 1, 1] and table.steering.tolist() == [False, False, False, True]
    assert table.roll_0.tolist() == [0, 2, 0, 0] and table.turn.tolist() == [2, 0, 2, 0]
    assert table.tilt.tolist() == [0, 0, 0, -2] and GainTable.build(["rs"], UNIT, 1.0, "printed").tilt[0] == 1
    with pytest.raises(ValueError):
        GainTable.build(["4r"], UNIT)

"""Spherical robots on 3-D terrain: the MuJoCo height field is the paper's surface, and a physical ball
confirms the no-slip model on planes and the curvature correction on the terrain (two independent models)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from pipeline.core.checks import compose_config
from pipeline.papers.spherical_terrain import CosineTerrain, normal
from pipeline.papers.spherical_terrain.experiments import model, robots
from pipeline.papers.spherical_terrain.physics import closed_loop, contact_point, rolling_check, terrain_mjcf

R = 0.2


def config(*overrides):
    return compose_config(["experiment=spherical-terrain/physics-check", *overrides])


def test_height_field_samples_the_terrain():
    cfg = config()
    terrain = CosineTerrain()
    m = mujoco.MjModel.from_xml_string(terrain_mjcf(terrain, R, cfg.system.physics, np.array([[0, 0, R]])))
    nrow, ncol = m.hfield_nrow[0], m.hfield_ncol[0]
    rx, ry, elevation, _ = m.hfield_size[0]
    heights = m.geom_pos[0, 2] + elevation * m.hfield_data.reshape(nrow, ncol)    # row i at y_i, column j at x_j
    x, y = np.meshgrid(np.linspace(-rx, rx, ncol), np.linspace(-ry, ry, nrow))
    assert np.abs(heights - terrain.height(x, y)).max() < 1e-6


def test_contact_point_inverts_the_sphere_centre():
    terrain = CosineTerrain()
    rng = np.random.default_rng(2)
    xy = rng.uniform(-3, 3, (50, 2))
    p = np.column_stack([xy, terrain.height(*xy.T)])
    center = p + R * normal(*terrain.gradient(*xy.T))
    assert np.abs(contact_point(terrain, center, R, iterations=12) - p).max() < 1e-9


def _rolling(*overrides):
    """The balls' rolling check and the median relative velocity error of each model while moving."""
    cfg = config(*overrides)
    m = model(cfg, [c for c, _ in robots(cfg)])
    check = rolling_check(m.terrain, closed_loop(cfg, m, [p for _, p in robots(cfg)]), R)
    moving = np.linalg.norm(check["paper"], axis=-1) > 0.05
    relative = {name: np.median(np.linalg.norm(check["actual"] - check[name], axis=-1)[moving]
                                / np.linalg.norm(check["paper"], axis=-1)[moving]) for name in ("paper", "rigid")}
    return check, relative


def test_on_a_plane_the_ball_rolls_as_the_paper_says():
    check, relative = _rolling("system.terrain.amplitude=0", "scenario.classes=[rt]", "system.duration=8")
    assert relative["paper"] < 0.01 and relative["rigid"] == pytest.approx(relative["paper"])
    assert np.abs(check["gap"]).max() < 2e-3                        # stays on the ground
    assert np.median(check["slip"]) < 2e-3


def test_on_the_terrain_rigid_rolling_predicts_the_ball_better_than_eq31():
    _, relative = _rolling("scenario.classes=[rt]", "system.duration=20")
    assert relative["rigid"] < 0.02                                 # slip and the field's facets
    assert relative["paper"] > 0.05 > 5 * relative["rigid"]         # the curvature term the paper drops

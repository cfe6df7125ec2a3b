"""`spherical-terrain`: Moazami, Zargarzadeh, Palanki — Kinematics of Spherical Robots Rolling over 3D
Terrains (Complexity 2019, 7543969).

The importable API (SI units):

    CosineTerrain(a, ω)                        eq. (59): height, gradient, hessian
    tangent_rotation(f_x, f_y) -> (..., 3, 3)  R_TTr, eq. (23)
    local_axes(f_x, f_y, ψ) -> (ĥ, l̂, n̂)       the columns of F_LW, eqs. (25)-(27)
    local_velocity(class, θ̇, φ̇[, φ]) -> (u, v)  ^L V of eqs. (33), (36), (38), (48)
    world_velocity(ĥ, l̂, u, v)                 eq. (31)
    GainTable, Model, controls, simulate       the pursuit laws (55)-(58) and their integration
    circle, diamond                            the paths of Sec. 6
"""

from __future__ import annotations

import math

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Rule
from pipeline.papers.spherical_terrain.kinematics import (
    CosineTerrain,
    contact_xy_velocity,
    local_axes,
    local_rotation,
    local_velocity,
    normal,
    sphere_center,
    tangent_rotation,
    world_velocity,
)
from pipeline.papers.spherical_terrain.paths import circle, diamond
from pipeline.papers.spherical_terrain.tracking import CLASSES, GainTable, Model, controls, simulate

__all__ = [
    "CLASSES",
    "CosineTerrain",
    "GainTable",
    "Model",
    "circle",
    "contact_xy_velocity",
    "controls",
    "diamond",
    "local_axes",
    "local_rotation",
    "local_velocity",
    "normal",
    "simulate",
    "sphere_center",
    "tangent_rotation",
    "world_velocity",
]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and the MCAP writer; the kinematics API above does not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.spherical_terrain import experiments, physics

        return {"paths": experiments.tracking, "printed": experiments.tracking, "sweep": experiments.tracking,
                "gain-search": experiments.tracking, "physics-check": physics.physics_check}
    raise AttributeError(name)


_GAIN = NON_NEGATIVE
FORM = OneOf(("corrected", "printed"))
LIMITS = {
    "scenario.classes": (Length(1, 4), OneOf(("3r", "2r", "rt", "rs"))),
    "scenario.paths": (Length(1, 2), OneOf(("circle", "diamond"))),
    "system.form.eq25": FORM, "system.form.eq58": FORM, "system.form.eq60": FORM,
    "system.dt": Range(ge=1e-4, le=0.05), "system.duration": Range(gt=0, le=1000),
    # a coarser field than 1 cm...0.5 m misses the terrain's 3.1 m wavelength or grows past 400k samples
    "system.physics.grid": Range(ge=0.01, le=0.5), "system.physics.timestep": Range(ge=1e-4, le=0.01),
    "system.terrain.amplitude": NON_NEGATIVE, "system.terrain.frequency": NON_NEGATIVE,
    "system.radius": POSITIVE, "system.tilt_limit": Range(gt=0, le=math.pi / 2),
    "system.paths.circle.radius": POSITIVE, "system.paths.circle.rate": Range(ge=-10, le=10),
    "system.paths.diamond.diagonal": POSITIVE, "system.paths.diamond.speed": POSITIVE,
    "system.controller.k_e": POSITIVE, "system.controller.gain_scale": NON_NEGATIVE,
    **{f"system.controller.class_{c}.{k}": _GAIN for c, keys in
       {"3r": ("k_theta", "k_phi1", "k_phi2", "k_psi"), "2r": ("k_theta1", "k_theta2", "k_phi1", "k_phi2"),
        "rt": ("k_theta", "k_psi"), "rs": ("k_alpha", "k_phi")}.items() for k in keys},
    "system.start.heading": Range(ge=-2 * math.pi, le=2 * math.pi),
    "system.physics.friction": POSITIVE, "system.physics.half_extent": Range(gt=0, le=20),
    "system.physics.servo_gain": POSITIVE, "system.physics.torque_limit": POSITIVE,
}
RULES = (
    Rule(("system.physics.timestep", "system.dt"),
         lambda step, dt: step <= dt and abs(dt / step - round(dt / step)) < 1e-9,
         "system.physics.timestep={0:g} s must divide the controller period system.dt={1:g} s"),
    Rule(("system.log_dt", "system.duration"), lambda log_dt, T: log_dt <= T / 10,
         "system.log_dt={0:g} s leaves fewer than 10 samples of the {1:g} s run"),
)
_STEPS = Budget("steps", lambda c: len(c.scenario.classes) * len(c.scenario.paths) * c.system.duration
                 / c.system.physics.timestep, 2e7, "fewer classes or paths, or a shorter system.duration")
BUDGETS = dict.fromkeys(("paths", "printed", "sweep", "gain-search", "physics-check"), _STEPS)

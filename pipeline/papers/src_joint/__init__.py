"""`src-joint`: Zong, Liang, Lam — Kinematics Modeling and Control of Spherical Rolling Contact Joint and
Manipulator (IEEE T-RO 39(1), 2023).

The importable API (SI units, quaternions scalar first [η, ε]):

    Chain(radii, form)                 the paper's SRC joint model and manipulator kinematics (Secs. II, III-A):
      .move(w, dt) / .roll(Ω^B, dt)    joint update, eqs. (1)-(6); .frames() FK, eqs. (17), (26);
      .jacobians(), .jacobian()        eqs. (24)-(38) (typos corrected); .free_modes() Φ_i, eq. (16)
    ModelForm(radius_convention, free_mode_sign, joint_update)   printed or corrected forms
    RollingChain(radii)                exact rolling without slip or spin (the independent plant)
    dls(J, twist, xi, lambda_max)      adaptive damped least squares, eqs. (39)-(44)
    solve_ik(chain, r_d, q_d, ...)     closed-loop IK, eqs. (45)-(47)
    FreeBot, position_plan, velocity_plan, steer_then_forward, steer_while_forward   Sec. IV
"""

from __future__ import annotations

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Rule
from pipeline.papers.src_joint.ik import Bars, Damper, DamperQP, IkGains, dls, solve_ik
from pipeline.papers.src_joint.model import Chain, ModelForm, quaternion_error, rotation
from pipeline.papers.src_joint.rolling import RollingChain
from pipeline.papers.src_joint.trolley import (
    FreeBot,
    Gains,
    position_plan,
    steer_then_forward,
    steer_while_forward,
    velocity_plan,
)

__all__ = ["Bars", "Chain", "Damper", "DamperQP", "FreeBot", "Gains", "IkGains", "ModelForm", "RollingChain", "dls",
           "position_plan", "quaternion_error", "rotation", "solve_ik", "steer_then_forward", "steer_while_forward",
           "velocity_plan"]


def __getattr__(name: str):
    # The experiments pull in MuJoCo, CasADi and the logging; the kinematics API above does not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.src_joint import experiments

        return {"joint-model": experiments.joint_model, "reach-poses": experiments.reach_poses,
                "reach-floor": experiments.reach_floor, "avoid-obstacles": experiments.avoid_obstacles}
    raise AttributeError(name)


RADIUS = Range(gt=0, le=1.0)   # m: spheres of a desk-size robot
FORMS = OneOf(("corrected", "printed"))
STEP = Range(ge=1e-4, le=0.1)
LIMITS = {
    "system.model.radius_convention": FORMS, "system.model.free_mode_sign": FORMS,
    "system.model.joint_update": OneOf(("incremental", "global")), "system.trolley.azimuth": FORMS,
    "scenario.plants": (Length(1, 2), OneOf(("mujoco", "exact"))),
    "scenario.cases": (Length(1, 2), OneOf(("avoid", "unconstrained"))),
    "scenario.variants.printed-radius.radius_convention": FORMS, "scenario.variants.printed-sign.free_mode_sign": FORMS,
    **{f"scenario.plants.{plant}.sensing": OneOf(("measured", "encoders"))
       for plant in ("nominal", "encoders", "eva-1mm", "slip-2pct", "eva-1mm-slip-2pct")},
    "scenario.hardware_targets": (Length(0, 2), OneOf(("A", "B"))),
    "scenario.floor.modes": (Length(1, 2), OneOf(("incremental", "global"))),
    "scenario.floor.readings": (Length(1, 3), OneOf(("printed", "scalar-last", "conjugate"))),
    "scenario.floor.weights": (Length(1, 10), Range(gt=0, le=1e6)), "scenario.floor.starts": Range(ge=1, le=4096),
    "scenario.floor.iterations": Range(ge=1, le=1000),
    "scenario.loop.rate": Range(gt=0, le=100), "scenario.loop.side": Range(gt=0, le=100),
    "scenario.bars.points": Range(ge=-1, le=1), "scenario.duration": Range(gt=0, le=300),
    "system.ik.dt": STEP, "system.control.dt": STEP, "physics.dt": Range(ge=1e-5, le=0.01),
    "physics.noslip_iterations": Range(ge=0, le=1000), "physics.settle_time": Range(ge=0, le=10),
    "system.ik.duration": Range(gt=0, le=300), "scenario.random_targets": Range(ge=0, le=100),
    "system.freebot.r_in": RADIUS, "system.freebot.r_out": RADIUS, "system.freebot.radius": RADIUS,
    "system.freebot.wheel_radius": RADIUS, "system.freebot.wheel_interval": RADIUS,
    "system.ik.xi": POSITIVE, "system.ik.lambda_max": NON_NEGATIVE, "system.ik.kp": POSITIVE,
    "system.ik.ka": POSITIVE, "system.ik.tol_position": POSITIVE, "system.ik.tol_orientation": POSITIVE,
    "system.ik.stall_time": POSITIVE, "system.ik.stall_change": NON_NEGATIVE,
    "system.trolley.k_s": POSITIVE, "system.trolley.k_phi1": POSITIVE, "system.trolley.k_phi2": NON_NEGATIVE,
    "system.trolley.heading0": Range(ge=-3.1416, le=3.1416), "system.trolley.steer_tol": POSITIVE,
    "system.trolley.min_rate": NON_NEGATIVE,
    "scenario.lower_radius": RADIUS, "scenario.upper_radius": RADIUS,
    "scenario.joints": Range(ge=1, le=12),
    "scenario.random_tilt": Range(ge=0, le=3.1416),
    "scenario.bars.radius": POSITIVE, "scenario.bars.half_length": POSITIVE,
    "scenario.damper.safety": NON_NEGATIVE, "scenario.damper.influence": POSITIVE, "scenario.damper.gain": POSITIVE,
    "scenario.damper.regularization": POSITIVE,
    "physics.magnet_force": NON_NEGATIVE, "physics.friction": NON_NEGATIVE, "physics.solref": POSITIVE,
    "physics.solimp": Range(gt=0, le=1), "physics.noslip_tolerance": POSITIVE, "physics.servo_bandwidth_hz": POSITIVE,
}
RULES = (
    Rule(("physics.dt", "scenario.log_dt"), lambda dt, log_dt: dt <= log_dt,
         "physics.dt={0:g} s exceeds the log period scenario.log_dt={1:g} s"),
    Rule(("scenario.log_dt", "scenario.duration"), lambda log_dt, T: log_dt <= T / 10,
         "scenario.log_dt={0:g} s leaves fewer than 10 samples of the {1:g} s run"),
)
BUDGETS = {
    "joint-model": Budget("physics steps", lambda c: len(c.scenario.plants) * len(c.scenario.variants)
                          * (c.scenario.duration + c.physics.settle_time) / c.physics.dt, 5e6,
                          "a shorter scenario.duration or a longer physics.dt"),
    "reach-poses": Budget("IK and control steps", lambda c: (2 + c.scenario.random_targets) * len(c.scenario.plants)
                          * (c.system.ik.duration / c.system.ik.dt + c.scenario.duration / c.system.control.dt),
                          2e6, "fewer scenario.random_targets or shorter durations"),
    "reach-floor": Budget("configurations evaluated", lambda c: len(c.scenario.floor.modes)
                          * len(c.scenario.floor.readings) * len(c.scenario.floor.weights) * c.scenario.floor.iterations
                          * c.scenario.floor.starts * (3 * c.scenario.joints + 2), 5e6,
                          "fewer scenario.floor.starts or iterations"),
    "avoid-obstacles": Budget("IK steps", lambda c: len(c.scenario.cases) * c.scenario.duration / c.system.ik.dt,
                              1e6, "a shorter scenario.duration or a longer system.ik.dt"),
}

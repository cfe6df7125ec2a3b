"""`curve-discretization`: Andersson — Discretization of a Continuous Curve (IEEE T-RO 24(2), 2008).

The importable API (lengths in the curve's units, angles in rad):

    bezier(control_points) -> Curve, travelling_wave(...) -> Curve        p_d(t): eq. (19), a gait primitive
    Chain.uniform(joints, link_length)                                    odd links L, even links 0
    joint_parameters(curve, chain, dt, tol[, increments]) -> Search      Subproblem 1: forward search + bisection
    joint_angles(points, theta_x0, joints) -> Angles                      Subproblem 2: eqs. (15)-(17), O(n)
    discretize(curve, chain, theta_x0, dt, tol) -> (Search, Angles)      both
    forward_kinematics(...), poe_forward_kinematics(...)                  the checks: sequential and eq. (8)
"""

from __future__ import annotations

from pipeline.core.experiment import ANGLE, NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Rule
from pipeline.papers.curve_discretization.algorithm import (
    Angles,
    Chain,
    Curve,
    CurveTooShort,
    Search,
    bezier,
    discretize,
    forward_kinematics,
    joint_angles,
    joint_parameters,
    joint_positions,
    poe_forward_kinematics,
    travelling_wave,
)

__all__ = ["Angles", "Chain", "Curve", "CurveTooShort", "Search", "bezier", "discretize", "forward_kinematics",
           "joint_angles", "joint_parameters", "joint_positions", "poe_forward_kinematics", "travelling_wave"]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and the run log; the algorithm above does not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.curve_discretization import experiments

        return {"bezier-fig2": experiments.bezier_fig2, "timing-fig3": experiments.timing_fig3,
                "snake-gait": experiments.snake_gait}
    raise AttributeError(name)


AT_LEAST_TWO = Range(ge=2)
GAIT_LIMITS = {"amplitude_y": Range(ge=-1, le=1), "amplitude_z": Range(ge=-1, le=1), "wavelength": POSITIVE,
               "frequency": NON_NEGATIVE, "phase_z": ANGLE}
JOINTS = Range(ge=2, le=1000)  # a snake of 1000 joints is far past any robot the paper considers
# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"timing-fig3", "snake-gait"})
LIMITS = {
    "system.curve.control_points": Range(ge=-1000, le=1000), "system.twist_hat": OneOf(("corrected", "printed")),
    "system.chain.joints": JOINTS, "system.chain.link_length": POSITIVE, "system.theta_x0": ANGLE,
    "system.search.tol": POSITIVE, "system.search.dt": Range(ge=1e-6, le=0.1),
    "scenario.roll_variants": (Length(0, 20), ANGLE), "scenario.curve_samples": Range(ge=2, le=100_000),
    "scenario.joint_counts.first": JOINTS, "scenario.joint_counts.last": JOINTS,
    "scenario.joint_counts.step": Range(ge=1, le=1000), "scenario.chain_length": POSITIVE,
    "scenario.warmup": Range(ge=0, le=10_000), "scenario.repeats": Range(ge=1, le=10_000),
    "scenario.angle_batch": Range(ge=1, le=10_000),
    "scenario.gaits": (Length(1, 2), OneOf(("lateral-undulation", "sidewinding"))),
    "scenario.joints": Range(ge=2, le=200), "scenario.segment_length": POSITIVE, "scenario.curve_length": POSITIVE,
    "scenario.duration": Range(gt=0, le=120), "control.dt": Range(ge=1e-4, le=0.5),
    "scenario.theta_x0": ANGLE,
    **{f"scenario.{gait}.{key}": r for gait in ("lateral-undulation", "sidewinding") for key, r in GAIT_LIMITS.items()},
    "snake.radius": POSITIVE, "snake.segment_mass": POSITIVE, "snake.armature": NON_NEGATIVE,
    "snake.damping": NON_NEGATIVE, "snake.torque_limit": POSITIVE, "snake.friction": NON_NEGATIVE,
    "control.physics_dt": Range(ge=1e-5, le=0.01), "control.kp": POSITIVE, "control.kv": NON_NEGATIVE,
}
RULES = (
    Rule(("control.physics_dt", "control.dt"), lambda physics_dt, dt: physics_dt <= dt,
         "control.physics_dt={0:g} s exceeds the control period control.dt={1:g} s: no physics step would run"),
    Rule(("scenario.joint_counts.first", "scenario.joint_counts.last"), lambda first, last: first <= last,
         "scenario.joint_counts.first={0} exceeds scenario.joint_counts.last={1}"),
    Rule(("control.tf_dt", "scenario.duration"), lambda tf_dt, T: tf_dt <= T / 10,
         "control.tf_dt={0:g} s leaves fewer than 10 frames of the {1:g} s gait"),
)
BUDGETS = {
    "snake-gait": Budget("joint-steps", lambda c: len(c.scenario.gaits) * c.scenario.joints * c.scenario.duration
                         / c.control.physics_dt, 1e8, "fewer scenario.joints, a shorter scenario.duration or a "
                         "longer control.physics_dt"),
    "timing-fig3": Budget("joint-stage calls", lambda c: (c.scenario.repeats * (1 + c.scenario.angle_batch)
                          + c.scenario.warmup) * c.scenario.joint_counts.last ** 2 / c.scenario.joint_counts.step,
                          1e10, "fewer scenario.repeats or scenario.angle_batch"),
}

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

from pipeline.core.experiment import ANGLE, NON_NEGATIVE, POSITIVE, Range
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
LIMITS: dict[str, Range] = {
    "system.chain.joints": AT_LEAST_TWO, "system.chain.link_length": POSITIVE, "system.theta_x0": ANGLE,
    "system.search.tol": POSITIVE,
    "scenario.roll_variants": ANGLE, "scenario.curve_samples": AT_LEAST_TWO,
    "scenario.joint_counts.first": AT_LEAST_TWO, "scenario.joint_counts.last": AT_LEAST_TWO,
    "scenario.joint_counts.step": Range(ge=1), "scenario.chain_length": POSITIVE, "scenario.warmup": NON_NEGATIVE,
    "scenario.joints": AT_LEAST_TWO, "scenario.segment_length": POSITIVE, "scenario.curve_length": POSITIVE,
    "scenario.theta_x0": ANGLE,
    **{f"scenario.{gait}.{key}": r for gait in ("lateral-undulation", "sidewinding") for key, r in GAIT_LIMITS.items()},
    "snake.radius": POSITIVE, "snake.segment_mass": POSITIVE, "snake.armature": NON_NEGATIVE,
    "snake.damping": NON_NEGATIVE, "snake.torque_limit": POSITIVE, "snake.friction": NON_NEGATIVE,
    "control.physics_dt": POSITIVE, "control.kp": POSITIVE, "control.kv": NON_NEGATIVE, "control.tf_dt": POSITIVE,
}

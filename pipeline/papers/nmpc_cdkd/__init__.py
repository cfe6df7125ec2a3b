"""`nmpc-cdkd`: Reinhold, Baumann, Meurer — Constrained-Differential-Kinematics-Decomposition-Based NMPC for
Online Manipulator Control with Low Computational Costs (Robotics 2023, 12, 7).

The importable API (SI units, the Stäubli TX2-90 of Table 2):

    Arm.from_config(system)                       Table 2 + joint limits (conf/system/nmpc-cdkd.yaml)
    tool_pose(arm, q), wrist_point(arm, q_m)      forward kinematics of the tool and of the wrist point
    wrist_jacobian(arm, q_m), hand_jacobian(arm, q_o)   the decomposed Jacobians of Sec. 2.2
    ik(arm, T) -> (8, 6)                          the 8 analytic IK branches (Sec. 2.1), NaN where unreachable
    select_configuration(arm, T0, T1, ...)        Sec. 3.1, eqs. (6), (9); JointPolynomial: eqs. (7)-(8)
    orientation_error(q_des, q_cur)               eq. (11)
    Nmpc(arm, OcpSettings(model=...))             the decomposed (10a-g) and the full-model NMPC (CasADi + IPOPT)
"""

from __future__ import annotations

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, PROBABILITY, Budget, Length, OneOf, Range, Rule, Text
from pipeline.papers.nmpc_cdkd.kinematics import (
    Arm,
    hand_jacobian,
    ik,
    orientation_error,
    tool_pose,
    wrist_jacobian,
    wrist_point,
)
from pipeline.papers.nmpc_cdkd.planning import JointPolynomial, select_configuration

__all__ = ["Arm", "JointPolynomial", "hand_jacobian", "ik", "orientation_error", "select_configuration", "tool_pose",
           "wrist_jacobian", "wrist_point"]


def __getattr__(name: str):
    # The experiments pull in CasADi and MuJoCo; the kinematics above do not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.nmpc_cdkd import experiments

        return {"compute-time": experiments.compute_time, "tracking": experiments.tracking,
                "fixed-obstacles": experiments.fixed_obstacles, "moving-obstacles": experiments.moving_obstacles}
    if name in ("Nmpc", "OcpSettings"):
        from pipeline.papers.nmpc_cdkd import nmpc

        return getattr(nmpc, name)
    raise AttributeError(name)


# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"compute-time", "tracking", "fixed-obstacles", "moving-obstacles"})
LIMITS = {
    "system.dt": Range(ge=1e-3, le=0.1), "system.planning.sample_dt": Range(ge=1e-3, le=0.1),
    "system.plant.physics_dt": Range(ge=1e-5, le=0.01), "system.scene.obstacles.names": Text(),
    "scenario.t1": Range(gt=0, le=30), "scenario.settle": Range(ge=0, le=10), "scenario.duration": Range(gt=0, le=30),
    "scenario.moves": Range(ge=1, le=1000), "scenario.tool_lengths": (Length(1, 5), NON_NEGATIVE),
    "scenario.sampling": OneOf(("states", "closed-loop")), "scenario.samples_per_move": Range(ge=1, le=100),
    "scenario.probe_inside": Range(ge=0, le=0.1), "scenario.probe_solves": Range(ge=1, le=20),
    "scenario.horizons": (Length(1, 5), Range(ge=2, le=200)),
    "system.nmpc.integrator": OneOf(("rk4", "euler")), "system.nmpc.warm_start": OneOf(("shift", "reference")),
    "system.nmpc.obstacle_prediction": OneOf(("constant_velocity", "frozen")),
    "system.nmpc.on_failure": OneOf(("solver_iterate", "previous_plan")),
    "system.nmpc.initial_state": OneOf(("command", "measured")),
    "system.orientation.desired_from": OneOf(("command", "measured")),
    "system.plant.kind": OneOf(("mujoco", "kinematic")),
    "scenario.models": (Length(1, 2), OneOf(("decomposed", "full"))),
    "scenario.cases": (Length(1, 3), OneOf(("no-obstacle", "obstacle", "obstacle-height", "a", "b", "A", "B"))),
    "system.dh.a": NON_NEGATIVE, "system.dh.d": Range(ge=-2, le=2), "system.dh.wrist_a": POSITIVE,
    "system.dh.wrist_d": NON_NEGATIVE, "system.dh.tool_d": NON_NEGATIVE,
    "system.joint_limits.velocity": POSITIVE, "system.joint_limits.acceleration": POSITIVE,
    "system.joint_limits.jerk": POSITIVE,
    "system.nmpc.horizon_steps": Range(ge=2, le=200), "system.nmpc.control_steps": Range(ge=1, le=200),
    "system.nmpc.mu": NON_NEGATIVE, "system.nmpc.length_unit": POSITIVE, "system.nmpc.tol": POSITIVE,
    "system.nmpc.acceptable_obj_change_tol": POSITIVE, "system.nmpc.max_iter": Range(ge=1, le=100_000),
    "system.full.orientation_lever": NON_NEGATIVE, "system.orientation.gain": NON_NEGATIVE,
    "system.planning.wrist_band": Range(ge=0, le=1.5708),
    "system.planning.limit_margin": Range(gt=0, le=1),
    "system.plant.bandwidth_hz": POSITIVE,
    "system.plant.damping_ratio": POSITIVE, "system.plant.link_radius": POSITIVE,
    "system.plant.armature": NON_NEGATIVE, "system.plant.damping": NON_NEGATIVE,
    "system.plant.torque_limit": POSITIVE,
    "system.scene.obstacles.radii": POSITIVE,
    "scenario.t0": NON_NEGATIVE,
    "scenario.min_transition_time": Range(gt=0, le=30), "scenario.wrist_radius": POSITIVE,
    "scenario.azimuth_change": Range(gt=0, le=3.1416), "scenario.obstacle.radius": POSITIVE,
    "scenario.obstacle.drop": Range(ge=0, le=1), "scenario.obstacle.offset": PROBABILITY,
    "scenario.obstacle.clearance": NON_NEGATIVE,
}
RULES = (
    Rule(("system.plant.physics_dt", "system.dt"), lambda physics_dt, dt: physics_dt <= dt,
         "system.plant.physics_dt={0:g} s exceeds the robot update system.dt={1:g} s"),
    Rule(("scenario.t0", "scenario.t1"), lambda t0, t1: t0 < t1, "scenario.t0={0:g} s must come before scenario.t1"),
    Rule(("scenario.t1", "scenario.duration"), lambda t1, T: t1 <= T,
         "scenario.t1={0:g} s must not come after the end of the run, scenario.duration={1:g} s"),
    Rule(("system.nmpc.control_steps", "system.nmpc.horizon_steps"), lambda m, n: m <= n,
         "system.nmpc.control_steps={0} exceeds the prediction horizon system.nmpc.horizon_steps={1}"),
)
_SOLVES = 2e5  # OCP solves of one experiment (a few ms each)


def _solves_per_move(c) -> float:
    """A two-OCP probe per sampled update, or every update of the closed loop (at most 2 T_min + t0 + settle)."""
    if c.scenario.sampling == "states":
        return c.scenario.probe_solves * c.scenario.samples_per_move
    return (c.scenario.t0 + 2 * c.scenario.min_transition_time + c.scenario.settle) / c.system.dt
BUDGETS = {
    "compute-time": Budget("OCP solves", lambda c: c.scenario.moves * len(c.scenario.models) * len(c.scenario.cases)
                           * len(c.scenario.horizons) * _solves_per_move(c), _SOLVES,
                           "fewer scenario.moves or scenario.samples_per_move"),
    **{name: Budget("OCP solves", lambda c: len(c.scenario.get("cases", [0])) * len(c.scenario.get("models", [0]))
                    * len(c.scenario.get("tool_lengths", [0])) * c.scenario.duration / c.system.dt, _SOLVES,
                    "a shorter scenario.duration or a longer system.dt")
       for name in ("tracking", "fixed-obstacles", "moving-obstacles")},
}

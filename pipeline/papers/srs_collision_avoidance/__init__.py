"""`srs-collision-avoidance`: Simas, Di Gregorio — Collision Avoidance for Redundant 7-DOF Robots Using a
Critically Damped Dynamic Approach (Robotics 2022, 11, 93).

The importable API (SI units, the paper's y-up base frame, LBR iiwa lengths by default):

    fk(q) -> (..., 4, 4)                          tool pose, eqs. (6), (10), (13)
    ik(T, alpha) -> Solution(q, P_s, P_e, P_w)   closed-form IK at swivel angle α, Sec. 3.2 (batched)
    swivel_angle(q) -> α                          the inverse of ik's parameterisation
    Coefficients.zoh(p, T)                        the critically damped filter, eqs. (1)-(3)
    plan(poses, start, end, radius, Settings)     Algorithm 1 over a task; Online(Settings).step(...) one iteration
"""

from __future__ import annotations

from pipeline.core.experiment import ANGLE, Budget, Length, OneOf, Range, Rule
from pipeline.papers.srs_collision_avoidance.avoidance import Forms, SafetyVolume
from pipeline.papers.srs_collision_avoidance.kinematics import IIWA, Geometry, Unreachable, fk, ik, swivel_angle
from pipeline.papers.srs_collision_avoidance.planner import Online, Plan, Settings, circle_poses, plan
from pipeline.papers.srs_collision_avoidance.swivel_filter import Coefficients

__all__ = ["IIWA", "Coefficients", "Forms", "Geometry", "Online", "Plan", "SafetyVolume", "Settings",
           "Unreachable", "circle_poses", "fk", "ik", "plan", "swivel_angle"]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and the run-file machinery; the API above does not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.srs_collision_avoidance import experiments

        return {"circle": experiments.circle, "ablation": experiments.ablation,
                "compute-time": experiments.compute_time}
    raise AttributeError(name)


LENGTH = Range(gt=0, le=5.0)        # m
POSITION = Range(ge=-5.0, le=5.0)   # m
SIGN = OneOf((1, -1))
TURNS = Range(ge=0, le=1000)        # cycles over a run
# Beside the robot in Foxglove and Rerun: the replay's joint error, α_f (Fig. 7) and the human points' margins to
# the safety volume (negative inside: what Algorithm 1 acts on).
VIEW_PLOTS = ["/tracking_error.norm", "/swivel.alpha_f_rad", "/clearance/volume.distance_m[:]"]
# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"compute-time", "circle"})
LIMITS = {
    "system.geometry.a0": LENGTH, "system.geometry.a1": LENGTH, "system.geometry.a2": LENGTH,
    "system.geometry.a3": LENGTH, "system.geometry.tool_rotation_y": ANGLE,
    "system.ik.shoulder_sign": SIGN, "system.ik.wrist_sign": SIGN,
    "system.filter.p": Range(gt=0, le=1e4), "system.filter.dt": Range(ge=1e-3, le=1.0),
    "system.filter.initial_alpha": ANGLE,
    "system.safety.d_cmin": Range(ge=0, le=2.0), "system.safety.d_cmax": Range(gt=0, le=2.0),
    "system.algorithm.obstacle": OneOf(("points", "capsules")),
    "system.algorithm.alpha_c": OneOf(("paper", "exact")),
    "system.algorithm.link_checks": OneOf(("both", "elseif")),
    "system.algorithm.d_m2": OneOf(("eq17", "printed")),
    "system.algorithm.sphere_distance": OneOf(("allowed", "printed")),
    "system.humans.base": POSITION, "system.humans.base_radius": Range(ge=0, le=2.0),
    "system.humans.base_turns": TURNS, "system.humans.shoulder_range": ANGLE,
    "system.humans.shoulder_offset": ANGLE, "system.humans.shoulder_turns": TURNS,
    "system.humans.elbow_range": ANGLE, "system.humans.elbow_offset": ANGLE, "system.humans.elbow_turns": TURNS,
    "system.humans.upper_length": LENGTH, "system.humans.fore_length": LENGTH,
    "system.humans.radius": Range(ge=0, le=0.5), "system.humans.plane": OneOf(("xy", "xz")),
    "system.humans.range_is": OneOf(("amplitude", "peak_to_peak")),
    "system.task.centre": POSITION, "system.task.radius": Range(ge=0, le=2.0), "system.task.rides": TURNS,
    "system.task.samples": Range(ge=3, le=20_000), "system.task.start_phase": ANGLE,
    "system.task.direction": SIGN, "system.task.tool_axis": OneOf(("down", "up")),
    "system.dynamics.masses": Range(gt=0, le=100.0), "system.dynamics.link_radius": Range(gt=0, le=0.5),
    "system.dynamics.armature": Range(ge=0, le=100.0), "system.dynamics.damping": Range(ge=0, le=1e3),
    "system.dynamics.torque_limit": Range(gt=0, le=1e4),
    "scenario.cases": (Length(1, 6), OneOf(("no-avoid", "avoid", "avoid-unfiltered", "avoid-printed",
                                            "avoid-exact", "avoid-capsules"))),
    "scenario.repeats": Range(ge=1, le=100), "scenario.warmup": Range(ge=0, le=100_000),
    "scenario.batch_repeats": Range(ge=1, le=1000),
    "replay.dt": Range(ge=2e-4, le=0.01), "replay.bandwidth_hz": Range(gt=0, le=100.0),
    "replay.damping_ratio": Range(gt=0, le=10.0), "replay.log_dt": Range(ge=2e-4, le=1.0),
}
RULES = (
    Rule(("system.safety.d_cmin", "system.safety.d_cmax"), lambda lo, hi: lo <= hi,
         "system.safety.d_cmin={0:g} m must not exceed system.safety.d_cmax={1:g} m (the cones widen at the elbow)"),
    Rule(("replay.dt", "system.filter.dt"), lambda dt, T: dt <= T,
         "replay.dt={0:g} s must not exceed the sample time system.filter.dt={1:g} s"),
    Rule(("replay.log_dt", "replay.dt"), lambda log_dt, dt: log_dt >= dt,
         "replay.log_dt={0:g} s is shorter than the physics step replay.dt={1:g} s"),
)
BUDGETS = {
    "circle": Budget("physics steps", lambda c: len(c.scenario.cases) * c.system.task.samples * c.system.filter.dt
                     / c.replay.dt, 5e6, "fewer scenario.cases or system.task.samples, or a longer replay.dt"),
    "ablation": Budget("planned samples", lambda c: len(c.scenario.cases) * c.system.task.samples, 1e6,
                       "fewer system.task.samples"),
    "compute-time": Budget("Algorithm 1 iterations", lambda c: c.system.task.samples
                           * (2 + c.scenario.repeats + c.scenario.batch_repeats) + c.scenario.warmup, 2e6,
                           "fewer system.task.samples, scenario.repeats or scenario.batch_repeats"),
}

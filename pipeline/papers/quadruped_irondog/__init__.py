"""`quadruped-irondog`: Rahman, Alam, Mou, Uddin, Hasan — A Dynamic Approach to Low-Cost Design, Development, and
Computational Simulation of a 12DoF Quadruped Robot (Robotics 2023, 12, 28).

The importable API (SI units; legs FR, FL, BR, BL; leg frame x lateral, y up, z forward):

    Leg(L1, L2, L3, printed=False)            link lengths; `printed` runs eq. (40) as printed
    fk(leg, q), ik(leg, p)                    a leg's FK and the closed-form IK of eqs. (38)-(40), vectorised
    body_ik(leg, layout, feet, position, rpy) joint angles for a trunk pose over fixed feet (Fig. 18)
    bezier(points, s), Trot(...)              the Table 3 swing (eqs. 41-44) and the trot built from it
    Robot.from_config(system), mjcf(robot)    the MuJoCo robot generated from Table 2
    static_torques(robot, q)                  the hand statics of a standing pose
"""

from __future__ import annotations

from pipeline.core.experiment import Budget, Length, OneOf, Range, Rule, Text
from pipeline.papers.quadruped_irondog.gait import Trot, bezier, de_casteljau
from pipeline.papers.quadruped_irondog.kinematics import Layout, Leg, body_ik, fk, ik
from pipeline.papers.quadruped_irondog.model import Robot, Scene, mjcf
from pipeline.papers.quadruped_irondog.statics import static_torques

__all__ = ["Layout", "Leg", "Robot", "Scene", "Trot", "bezier", "body_ik", "de_casteljau", "fk", "ik", "mjcf",
           "static_torques"]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and the run files; the kinematics above do not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.quadruped_irondog import experiments as ex

        return {"tables": ex.tables, "kinematics": ex.kinematics, "stand": ex.stand, "body-poses": ex.body_poses,
                "self-levelling": ex.self_levelling, "trot": ex.trot}
    raise AttributeError(name)


LENGTH = Range(gt=0, le=1.0)          # m, any dimension of this 30 cm robot
PART_MASS = Range(ge=0, le=10.0)      # kg
ANGLE_DEG = Range(ge=-180, le=180)
SECONDS = Range(ge=0, le=60)
TRUNK_PARTS = ("base", "head", "back_shell", "pitch_mounts", "coxa_servos", "battery", "other", "screws")

LIMITS = {
    **{f"system.leg.{k}": LENGTH for k in ("L1", "L2", "L3")},
    "system.leg.ik_form": OneOf(("corrected", "printed")),
    **{f"system.body.{k}": LENGTH for k in ("length", "hip_width", "height", "link_width", "link_thickness",
                                            "foot_radius")},
    **{f"system.masses.trunk.{k}": PART_MASS for k in TRUNK_PARTS},
    **{f"system.masses.{k}": PART_MASS for k in ("coxa", "femur", "tibia")},
    "system.servo.stall_torque": Range(gt=0, le=100), "system.servo.no_load_speed": Range(gt=0, le=100),
    "system.servo.kp": Range(gt=0, le=1e4), "system.servo.armature": Range(ge=0, le=1),
    **{f"system.servo.range_deg.{j}": ANGLE_DEG for j in ("coxa", "femur", "tibia")},
    **{f"system.table5.{state}_deg.{j}": ANGLE_DEG for state in ("ideal", "standing")
       for j in ("coxa", "femur", "tibia")},
    "system.table5.femur_sign": Range(ge=-1, le=1),
    "system.gait.control_points_mm": Range(ge=-1000, le=1000),
    "system.gait.cycle_time": Range(ge=0.1, le=5), "system.gait.duty_factor": Range(gt=0, lt=1),
    "system.gait.a_points": OneOf(("backward", "forward")), "system.gait.stride_scale": Range(ge=0, le=2),
    "system.physics.timestep": Range(ge=1e-4, le=0.01), "system.physics.friction": Range(gt=0, le=5),
    "system.control.rate_hz": Range(ge=1, le=1000),
    "system.balance.kp": Range(ge=0, le=10), "system.balance.ki": Range(ge=0, le=100),
    "system.balance.kd": Range(ge=0, le=10), "system.balance.limit_deg": Range(gt=0, le=45),
    "system.fall.min_height": Range(ge=0, le=1), "system.fall.max_tilt_deg": Range(gt=0, le=90),
    "system.log.rate_hz": Range(ge=1, le=1000), "system.log.tf_rate_hz": Range(ge=1, le=1000),
    # kinematics
    "scenario.bezier_samples": Range(ge=2, le=100_000), "scenario.workspace_samples": Range(ge=1, le=1_000_000),
    "scenario.timing_calls": Range(ge=1, le=100_000),
    # stand, self-levelling
    "scenario.duration": Range(gt=0, le=60), "scenario.payloads": (Length(1, 10), Range(ge=0, le=50)),
    "scenario.window": Range(gt=0, le=60),
    # body-poses
    "scenario.settle": Range(ge=0, le=10), "scenario.ramp": Range(gt=0, le=10), "scenario.hold": Range(gt=0, le=10),
    "scenario.translation": Range(ge=-0.1, le=0.1), "scenario.rotation_deg": Range(ge=-30, le=30),
    "scenario.reach": Range(gt=0, le=1),
    # self-levelling
    "scenario.axes": (Length(1, 2), OneOf(("pitch", "roll"))), "scenario.tilt_deg": Range(ge=-30, le=30),
    "scenario.tilt_start": SECONDS, "scenario.tilt_ramp": Range(gt=0, le=60),
    "scenario.level_band_deg": Range(gt=0, le=10),
    # trot
    "scenario.cycle_times": (Length(1, 20), Range(ge=0.1, le=5)), "scenario.rise": Range(gt=0, le=10),
    "scenario.ramp_cycles": Range(gt=0, le=20), "scenario.cycles": Range(ge=1, le=200),
    "scenario.skip_cycles": Range(ge=0, le=100),
    # tables: the paper's numbers as printed
    "scenario.tables": Text(), "scenario.text.gravity_m_s2": Range(gt=0, le=20),
}
RULES = (
    Rule(("system.physics.timestep", "system.control.rate_hz"), lambda dt, hz: dt <= 1 / hz,
         "system.physics.timestep={0:g} s must not exceed the control period 1/system.control.rate_hz={1:g} Hz"),
    Rule(("system.log.rate_hz", "system.physics.timestep"), lambda hz, dt: 1 / hz >= dt,
         "system.log.rate_hz={0:g} Hz logs more often than the physics step system.physics.timestep={1:g} s"),
    Rule(("scenario.window", "scenario.duration"), lambda window, duration: window <= duration,
         "scenario.window={0:g} s is longer than the run (scenario.duration={1:g} s)"),
)
STEPS = "physics steps"
FEWER = "a longer system.physics.timestep or a shorter run"
BUDGETS = {
    "kinematics": Budget("IK and Bezier evaluations", lambda c: c.scenario.bezier_samples * 3
                         + c.scenario.workspace_samples * 3 + c.scenario.timing_calls * 3, 1e7,
                         "fewer scenario.workspace_samples or scenario.timing_calls"),
    "stand": Budget(STEPS, lambda c: len(c.scenario.payloads) * c.scenario.duration / c.system.physics.timestep,
                    2e6, f"fewer scenario.payloads, {FEWER}"),
    "body-poses": Budget(STEPS, lambda c: (2 * c.scenario.settle + 11 * (2 * c.scenario.ramp + c.scenario.hold))
                         / c.system.physics.timestep, 2e6, FEWER),
    "self-levelling": Budget(STEPS, lambda c: 2 * len(c.scenario.axes) * c.scenario.duration
                             / c.system.physics.timestep, 2e6, f"fewer scenario.axes, {FEWER}"),
    "trot": Budget(STEPS, lambda c: sum(c.scenario.settle + c.scenario.rise + c.scenario.cycles * t
                                        for t in c.scenario.cycle_times) / c.system.physics.timestep, 2e6,
                   f"fewer scenario.cycle_times or scenario.cycles, {FEWER}"),
}

"""`gripper-force-control`: Romanov, Gyrichidi, Romanov — A Novel Gripper with Integrated Rotary Unit and
Force Control for Pick and Place Applications (Robotics 2022, 11, 155).

The importable API (SI units, prototype v.1 of Sect. 5 from conf/system/gripper-force-control.yaml):

    gripper(system_cfg) -> Gripper                 parameters, gear ratios (eqs. 1-4), eq. (9)'s gains
    gearbox(geometry, g_pf_form, coupling)         the gear ratios alone
    schedule(p, duration, force, moves) -> Schedule  set value generator + differentiator, eqs. (10)-(12)
    static_grasp(p, force) -> Start                the held grasp at F_set (eq. 8)
    simulate_lumped(p, schedule, start, log_every) -> Trace      drive + lumped NumPy plant
    MujocoGripper(p, contact_cfg).simulate(...) -> (Trace, poses)  drive + MuJoCo plant (contact force)
"""

from __future__ import annotations

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Rule, Text
from pipeline.papers.gripper_force_control.drive import Drive, Schedule, move_duration, schedule, trapezoid
from pipeline.papers.gripper_force_control.lumped import Start, Trace, static_grasp
from pipeline.papers.gripper_force_control.lumped import simulate as simulate_lumped
from pipeline.papers.gripper_force_control.model import Gearbox, Gripper, gearbox, gripper

__all__ = ["Drive", "Gearbox", "Gripper", "MujocoGripper", "Schedule", "Start", "Trace", "gearbox", "gripper",
           "move_duration", "schedule", "simulate_lumped", "static_grasp", "trapezoid"]


def __getattr__(name: str):
    # MuJoCo and the experiments are imported only when used
    if name == "MujocoGripper":
        from pipeline.papers.gripper_force_control.mujoco_plant import MujocoGripper

        return MujocoGripper
    if name == "EXPERIMENTS":
        from pipeline.papers.gripper_force_control import experiments

        return {"force-sag": experiments.force_sag, "force-sag-friction": experiments.force_sag,
                "force-error-surface": experiments.force_error_surface,
                "pick-and-place": experiments.pick_and_place, "steady-state": experiments.steady_state,
                "tables": experiments.tables}
    raise AttributeError(name)


_G = "system.geometry."
PLANTS = ("mujoco", "lumped")
COUPLINGS = ("eq5", "eq9", "unity")
FEEDFORWARDS = ("model", "printed")
LIMITS = {
    "system.gearbox.g_pf_form": OneOf(("pf_over_ps2", "ps2_over_pf")), "system.gearbox.coupling": OneOf(COUPLINGS),
    "system.motors.back_emf": OneOf(("printed", "torque_constant")),
    "system.controller.feedforward": OneOf(FEEDFORWARDS),
    "system.controller.dt": Range(ge=1e-6, le=1e-3), "system.controller.velocity_dt": Range(ge=1e-6, le=1e-2),
    "system.controller.position_dt": Range(ge=1e-6, le=1e-2),
    "scenario.plant": OneOf(PLANTS), "scenario.plants": (Length(1, 2), OneOf(PLANTS)),
    "scenario.forms": Length(0, 10), "scenario.forms.plant": OneOf(PLANTS),
    "scenario.forms.coupling": OneOf(COUPLINGS), "scenario.forms.feedforward": OneOf(FEEDFORWARDS),
    "scenario.tables": Text(), "scenario.forces": (Length(1, 20), Range(gt=0, le=200)),
    "scenario.grasps": Range(ge=1, le=1000), "scenario.duration": Range(gt=0, le=10),
    "log_dt": Range(ge=1e-5, le=0.1), "tf_dt": Range(ge=1e-5, le=0.1), "mujoco.settle": Range(ge=0, le=1),
    **{_G + k: POSITIVE for k in ("D_pd", "D_pu", "D_pf", "D_ps1", "D_ps2", "D_pc", "l_f")},
    _G + "h_pc": NON_NEGATIVE,
    **{f"system.motors.{k}": POSITIVE for k in ("R", "L", "K_t", "K_e", "J_M1", "J_M2", "voltage_limit",
                                                "current_limit")},
    **{f"system.controller.{k}": POSITIVE for k in ("velocity_dt", "position_dt", "K_c1", "K_c2", "T_c1", "T_c2",
                                                    "K_v", "K_p", "T", "omega_max", "epsilon_max", "speed_limit",
                                                    "speed_gain", "speed_integral_time")},
    **{f"system.contact.{k}": POSITIVE for k in ("stiffness", "pad_mass", "object_radius", "object_mass")},
    "system.contact.damping": NON_NEGATIVE,
    **{f"system.friction.{k}": NON_NEGATIVE for k in ("m1_coulomb", "m1_viscous", "rotation_coulomb",
                                                       "rotation_viscous")},
    "scenario.force": Range(gt=0, le=200), "scenario.tomato_force": Range(gt=0, le=200),
    "scenario.angle": Range(gt=0, le=6.2832), "scenario.omega": POSITIVE, "scenario.epsilon": POSITIVE,
    "scenario.start": NON_NEGATIVE, "scenario.after": NON_NEGATIVE, "scenario.pause": NON_NEGATIVE,
    "scenario.stroke": POSITIVE, "scenario.stop_margin": NON_NEGATIVE, "scenario.rotate_at": NON_NEGATIVE,
    "scenario.open_at": NON_NEGATIVE,
    "scenario.gap": POSITIVE, "scenario.friction_scale": NON_NEGATIVE, "scenario.window": POSITIVE,
    "scenario.cases.tomato.speed_limit": POSITIVE, "scenario.cases.no-speed-limit.speed_limit": POSITIVE,
}
RULES = (
    Rule(("system.controller.velocity_dt", "system.controller.dt"), lambda v, dt: v >= dt,
         "system.controller.velocity_dt={0:g} s is shorter than the current-loop step system.controller.dt={1:g} s"),
    Rule(("system.controller.position_dt", "system.controller.velocity_dt"), lambda p, v: p >= v,
         "system.controller.position_dt={0:g} s is shorter than system.controller.velocity_dt={1:g} s"),
    Rule(("log_dt", "system.controller.dt"), lambda log_dt, dt: log_dt >= dt,
         "log_dt={0:g} s is shorter than the simulation step system.controller.dt={1:g} s"),
    Rule(("scenario.window", "scenario.duration"), lambda window, T: window < T,
         "scenario.window={0:g} s must be shorter than scenario.duration={1:g} s"),
    Rule(("scenario.open_at", "scenario.duration"), lambda t, T: t < T,
         "scenario.open_at={0:g} s must come before the end of the run, scenario.duration={1:g} s"),
    Rule(("scenario.rotate_at", "scenario.open_at"), lambda rotate, open_: rotate < open_,
         "scenario.rotate_at={0:g} s must come before scenario.open_at={1:g} s"),
)
_STEPS = 2e7  # controller ticks of one experiment: about 100 s of wall time
BUDGETS = {
    "steady-state": Budget("controller ticks", lambda c: len(c.scenario.forces) * c.scenario.grasps
                           * c.scenario.duration / c.system.controller.dt, _STEPS,
                           "fewer scenario.grasps or a shorter scenario.duration"),
}

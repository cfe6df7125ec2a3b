"""`itbot-smc`: Khan, Swapnil, Ahmed, Rahman, Islam, Brahmi, Fareh, Rahman — Development of an End-Effector Type
Therapeutic Robot with Sliding Mode Control for Upper-Limb Rehabilitation (Robotics 2022, 11, 98).

The importable API (SI units, Table 1 and Table 3 plus the stated assumptions of conf/system/itbot-smc.yaml):

    Links.from_config(cfg.system)                 the link parameters of eqs. (A8)-(A10)
    fk, jacobian, ik, mdh_frames                  kinematics of Table 2
    mass_matrix, coriolis, gravity_torque         M, V, G of eqs. (A8)-(A10)
    smc, smerl, nsmerl                            the reaching laws (nSMERL: eq. 6)
    reaching_time, erl_reaching_time, proposition_threshold    Sec. 4, eqs. (7), (14), (27)
    SlidingModeController, JointSensor            eq. (5) at 1 kHz; Hall-sensor quantisation, velocity filter
    AnalyticPlant, MujocoPlant, arm_mjcf          the two plants (eqs. A7-A12 + drive + hand load; MuJoCo)
"""

from __future__ import annotations

from pipeline.core.experiment import PROBABILITY, Budget, Length, Limit, OneOf, Range, Rule
from pipeline.papers.itbot_smc.controller import JointSensor, SlidingModeController
from pipeline.papers.itbot_smc.model import Links, coriolis, fk, gravity_torque, ik, jacobian, mass_matrix, mdh_frames
from pipeline.papers.itbot_smc.plants import AnalyticPlant, Drive, HandLoad
from pipeline.papers.itbot_smc.reaching import (
    erl_reaching_time,
    nsmerl,
    proposition_threshold,
    reaching_time,
    smc,
    smerl,
)

SYSTEM_ATTACHMENT = "system.yaml"   # each run's own system config (a case may change the experiment's)

__all__ = ["SYSTEM_ATTACHMENT", "AnalyticPlant", "Drive", "HandLoad", "JointSensor", "Links", "MujocoPlant",
           "SlidingModeController", "arm_mjcf", "coriolis", "erl_reaching_time", "fk", "gravity_torque", "ik",
           "jacobian", "mass_matrix", "mdh_frames", "nsmerl", "proposition_threshold", "reaching_time", "smc",
           "smerl"]


def __getattr__(name: str):
    # MuJoCo and the MCAP writer are imported only when used
    if name in ("MujocoPlant", "arm_mjcf"):
        from pipeline.papers.itbot_smc import mujoco_arm

        return getattr(mujoco_arm, name)
    if name == "EXPERIMENTS":
        from pipeline.papers.itbot_smc import experiments

        return {"tracking": experiments.tracking, "smc-sweep": experiments.smc_sweep,
                "load-support": experiments.load_support, "reaching-time": experiments.reaching_time}
    raise AttributeError(name)


_S, _C = "system.", "system.control."
LAWS = OneOf(("nsmerl", "smerl", "smc"))
PLANTS = OneOf(("analytic", "mujoco"))
GROUPS = ("analytic", "mujoco", "hall", "ms")
PAIR = Length(2, 2)
LIMITS: dict[str, Limit | tuple[Limit, ...]] = {
    _S + "configuration": OneOf(("vertical", "horizontal")), _S + "gravity": Range(ge=0, le=20),
    **{_S + f"links.{k}": Range(gt=0, le=2) for k in ("l1", "l2", "lc1", "lc2")},
    **{_S + f"links.{k}": Range(gt=0, le=100) for k in ("m1", "m2")},
    _S + "links.z2": Range(ge=-1, le=1), _S + "inertia": Range(gt=0, le=10),
    _S + "joint_limits_deg": Range(gt=0, le=180),
    _S + "drive.gear_ratio": Range(ge=1, le=1000), _S + "drive.rotor_inertia": Range(ge=0, le=1e-2),
    _S + "drive.friction": Range(ge=0, le=50), _S + "drive.friction_velocity": Range(gt=0, le=10),
    _S + "drive.torque_limit": Range(gt=0, le=1000),
    _S + "hand.weight": Range(ge=0, le=50), _S + "hand.arm": Range(ge=0, le=20),
    _S + "hand.damping": Range(ge=0, le=1000), _S + "hand.support": PROBABILITY,
    _S + "sensing.model": OneOf(("ideal", "hall")), _S + "sensing.velocity": OneOf(("difference", "filtered")),
    _S + "sensing.resolution_deg": Range(ge=0, le=5), _S + "sensing.velocity_cutoff_hz": Range(gt=0, le=10_000),
    _C + "rate_hz": Range(ge=100, le=10_000), _C + "lambda": Range(gt=0, le=10_000),
    _C + "K": Range(gt=0, le=1e5), _C + "phi": Range(gt=0, lt=1), _C + "alpha": Range(gt=0, le=1e7),
    _C + "p": Range(gt=0, le=10), _C + "power": Range(gt=0, lt=1), _C + "omega_rate": Range(gt=0, le=1e6),
    _C + "smc.gain_scale": Range(gt=0, le=1e4), _C + "smc.boundary_layer": Range(ge=0, le=100),
    _C + "model.mass_scale": Range(gt=0, le=10), _C + "model.friction": Range(ge=0, le=50),
    # a run is at most 10 cycles of 60 s at 10 kHz (6e6 control ticks); BUDGETS bound a whole experiment
    _S + "reference.start_deg": Range(ge=-180, le=180), _S + "reference.amplitude_deg": Range(ge=-180, le=180),
    _S + "reference.period": Range(ge=0.1, le=60), _S + "reference.cycles": Range(ge=1, le=10),
    _S + "reference.initial_error_deg": Range(ge=-30, le=30),
    **{_S + f"drawing.{k}": Range(gt=0, le=1) for k in ("link_width", "link_thickness", "base_size", "motor_radius",
                                                       "motor_length", "handle_radius", "handle_length",
                                                       "weight_radius")},
    "scenario.laws": (Length(1, 3), LAWS), "scenario.paper_model_laws": (Length(0, 3), LAWS), "scenario.law": LAWS,
    "scenario.plant": PLANTS,
    **{f"scenario.groups.{g}.{k}": allowed for g in GROUPS for k, allowed in (
        ("plant", PLANTS), ("sensing", OneOf(("ideal", "hall"))), ("omega_rate", Range(gt=0, le=1e6)),
        ("laws", (Length(0, 3), LAWS)))},
    "scenario.v0_min": Range(gt=0, le=1e4), "scenario.v0_max": Range(gt=0, le=1e4),
    "scenario.points": Range(ge=2, le=1000), "scenario.joints": (Length(1, 2), Range(ge=1, le=2)),
    "scenario.alphas": (Length(1, 10), Range(gt=0, le=1e7)),
    "execute.substeps": Range(ge=1, le=100), "execute.log_dt": Range(ge=1e-3, le=1),
    "execute.tf_dt": Range(ge=1e-3, le=10),
}
RULES = (
    Rule(("execute.log_dt", "system.control.rate_hz"), lambda log_dt, rate: log_dt * rate >= 1 - 1e-9,
         "execute.log_dt={0:g} s is shorter than the control period 1/system.control.rate_hz = 1/{1:g} s"),
    Rule(("scenario.v0_min", "scenario.v0_max"), lambda lo, hi: lo < hi,
         "scenario.v0_min={0:g} must be below scenario.v0_max={1:g}"),
)


def _ticks_per_run(cfg) -> float:
    reference = cfg.system.reference
    return float(reference.period) * float(reference.cycles) * float(cfg.system.control.rate_hz)


_TICKS = 5e6  # control ticks of one experiment: ~30,000 per wall second
_HINT = "a shorter system.reference.period, fewer cycles or a lower system.control.rate_hz"
BUDGETS = {
    "tracking": Budget("control ticks", lambda c: _ticks_per_run(c) * sum(
        len(g.laws) or len(c.scenario.laws) for g in c.scenario.groups.values()), _TICKS, _HINT),
    "smc-sweep": Budget("control ticks", _ticks_per_run, _TICKS, _HINT),
    "load-support": Budget("control ticks", lambda c: _ticks_per_run(c) * (
        1 + len(c.scenario.paper_model_laws) * (float(c.system.hand.support) == 1.0)), _TICKS, _HINT),
    "reaching-time": Budget("reaching times", lambda c: 4.0 * c.scenario.points * len(c.scenario.joints)
                            * len(c.scenario.alphas), 2e4, "fewer scenario.points, joints or alphas"),
}

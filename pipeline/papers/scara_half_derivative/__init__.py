"""`scara-half-derivative`: Bruzzone, Nodehi — Application of Half-Derivative Damping to Cartesian Space
Position Control of a SCARA-like Manipulator (Robotics 2022, 11, 152).

The importable API (SI units, Table 1 plus the stated assumptions of conf/system/scara-half-derivative.yaml):

    Arm.from_config(cfg.system)                  the RRFbR arm
    fk(arm, θ) -> x,  jacobian(arm, θ) -> J       eqs. (3)-(7); ik(arm, x) -> θ
    gravity_torque(arm, θ3)                       eq. (12);  balanced_theta3p(...) eq. (13)
    Motion.from_config(...)(t) -> x_d, ẋ_d, ẍ_d   the 6-phase set-point of Sec. 4
    CartesianController(arm, Gains(...), T_s, n)  KD (eq. 11) / KDHD (eq. 17), one call per period
    gl_weights(1/2, n)                            eq. (16) (pipeline.robotics.fractional)
    the plants: multibody.ExudynPlant (closed chain), lagrange.LagrangePlant (reduced model)
"""

from __future__ import annotations

from omegaconf import ListConfig

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, PROBABILITY, Budget, Length, OneOf, Range, Rule
from pipeline.papers.scara_half_derivative.arm import Arm, balanced_theta3p, fk, gravity_torque, ik, jacobian
from pipeline.papers.scara_half_derivative.controller import CartesianController, Gains
from pipeline.papers.scara_half_derivative.setpoint import Motion
from pipeline.robotics.fractional import gl_weights

__all__ = ["Arm", "CartesianController", "Gains", "Motion", "balanced_theta3p", "fk", "gl_weights",
           "gravity_torque", "ik", "jacobian"]


def __getattr__(name: str):
    # The experiments pull in CasADi, Exudyn and the MCAP writer; the API above needs none of them.
    if name == "EXPERIMENTS":
        from pipeline.papers.scara_half_derivative import experiments

        return {"setpoint": experiments.setpoint, "table2": experiments.table2, "maps": experiments.maps,
                "locus": experiments.locus, "table2-sensitivity": experiments.table2,
                "maps-sensitivity": experiments.maps, "stiffness": experiments.table2,
                "locus-sensitivity": experiments.locus}
    raise AttributeError(name)


STEP = Range(ge=1e-5, le=0.05)
LIMITS = {
    "scenario.controllers": (Length(1, 3), OneOf(("kd", "kdhd", "khd"))),
    "execute.plant": OneOf(("exudyn", "lagrange")), "system.control.dt": Range(ge=1e-4, le=0.05),
    "system.control.implementation": OneOf(("sampled", "sampled-difference", "continuous")),
    "system.inertia_scale": Range(gt=0, le=100),
    "execute.dt": STEP, "scenario.dt": STEP, "scenario.k_xyz": (Length(1, 10), POSITIVE),
    "scenario.d_xyz": (Length(1, 50), NON_NEGATIVE),
    **{f"system.geometry.{k}": POSITIVE for k in ("l1", "l2", "l3", "l4", "lG1", "lG3", "lG4", "h")},
    "system.inertia": POSITIVE, "system.gravity": NON_NEGATIVE, "system.spring.k3": POSITIVE,
    "system.spring.theta3p_deg": Range(ge=-90, le=90), "system.home_deg": Range(ge=-180, le=180),
    "system.motion.distance": Range(gt=0, le=0.3), "system.motion.t_move": POSITIVE,
    "system.motion.t_stop": NON_NEGATIVE, "system.motion.accel_fraction": Range(gt=0, le=0.5),
    "system.motion.directions": Range(ge=-1, le=1),
    "system.control.gl_terms": Range(ge=1, le=10_000),
    "system.control.k_theta": NON_NEGATIVE,
    **{f"system.control.rotation.{law}.{k}": NON_NEGATIVE for law in ("kd", "kdhd") for k in ("d_theta", "hd_theta")},
    "scenario.duration": Range(gt=0, le=600), "scenario.hd_xyz": (Length(1, 50), NON_NEGATIVE),
    **{f"scenario.tunings.{c}.{k}": NON_NEGATIVE for c in ("kd", "kdhd", "khd") for k in ("d_xyz", "hd_xyz")},
    "execute.spectral_radius": PROBABILITY, "execute.newton_tolerance": Range(gt=0, lt=1),
}


def _whole(period: float, step: float) -> bool:
    return step <= period and abs(period / step - round(period / step)) < 1e-9


RULES = (
    Rule(("system.control.dt", "execute.dt"), _whole,
         "execute.dt={1:g} s must divide the control period system.control.dt={0:g} s (torques are held over it)"),
    Rule(("execute.log_dt", "execute.dt"), lambda log_dt, dt: log_dt >= dt,
         "execute.log_dt={0:g} s is shorter than the integration step execute.dt={1:g} s"),
    Rule(("system.control.implementation", "execute.plant"),
         lambda implementation, plant: implementation != "continuous" or plant == "lagrange",
         "system.control.implementation=continuous runs on the reduced plant only: add execute.plant=lagrange"),
)
_STEPS = 5e6  # integration steps of one experiment: Exudyn runs ~7000 per wall second, the batched reduced
#               plant ~40000


def _count(value) -> int:
    return len(value) if isinstance(value, ListConfig) else 1


def _runs_steps(runs) -> Budget:
    return Budget("integration steps", lambda c: runs(c) * c.scenario.duration / c.execute.dt, _STEPS,
                  "fewer runs, a shorter scenario.duration or a longer execute.dt")


_TABLE2 = _runs_steps(lambda c: len(c.scenario.controllers) * len(c.scenario.k_xyz))
_LOCUS = _runs_steps(lambda c: len(c.scenario.k_xyz) * len(c.scenario.d_xyz))
_MAPS = _runs_steps(lambda c: _count(c.scenario.k_xyz) * len(c.scenario.d_xyz) * len(c.scenario.hd_xyz))
BUDGETS = {"table2": _TABLE2, "table2-sensitivity": _TABLE2, "stiffness": _TABLE2, "maps": _MAPS,
           "maps-sensitivity": _MAPS, "locus": _LOCUS, "locus-sensitivity": _LOCUS}

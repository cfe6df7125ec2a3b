"""`partial-lagrangian`: Kusaka, Tanaka — Partial Lagrangian for Efficient Extension and Reconstruction
of Multi-DoF Systems and Efficient Analysis Using Automatic Differentiation (Robotics 2022, 11, 149).

The importable API (SI units; planar chains of point masses, angles from +x, relative after link 1):

    planar_chain(n, mass, length, damping, stiffness, gravity, ...) -> Chain
    dynamics(chain, form="partial"|"full") -> Dynamics      CasADi functions: forward (q, q̇, τ) -> q̈,
                                                             mass_bias (q, q̇) -> (M, b), inverse (q, q̇, q̈) -> τ
    equations_of_motion(chain, form) -> Function            (q, q̇) -> (M, b) only
    column_mass_bias(chain, i) -> Function                  column i of Table 1 alone (eq. 5)
    listing_a1_step(chain) -> Function                      one step of the paper's Listing A1 (one DoF)
    simulate(chain, q0, q̇0, gains, dt, duration) -> Trajectory   PID-controlled run (rollout.Gains)
    MujocoChain(chain)                                       the same chain in MuJoCo (independent check)
"""

from __future__ import annotations

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Rule
from pipeline.papers.partial_lagrangian.chain import (
    DAMPING_MODELS,
    PRISMATIC,
    REVOLUTE,
    Chain,
    double_pendulum,
    energies,
    gravity_torque,
    planar_chain,
)
from pipeline.papers.partial_lagrangian.lagrangian import (
    FORMS,
    column_mass_bias,
    dynamics,
    equations_of_motion,
    listing_a1_step,
)
from pipeline.papers.partial_lagrangian.rollout import INTEGRATORS, Gains, Trajectory, simulate

__all__ = ["Chain", "Gains", "Trajectory", "column_mass_bias", "double_pendulum", "dynamics", "energies",
           "equations_of_motion", "gravity_torque", "listing_a1_step", "planar_chain", "simulate"]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and the MCAP writer; the dynamics above need only CasADi and NumPy.
    if name == "EXPERIMENTS":
        from pipeline.papers.partial_lagrangian import experiments as ex

        return {"one-link": ex.pendulum, "two-link": ex.pendulum, "three-link": ex.pendulum,
                "ten-link": ex.pendulum, "slider": ex.slider, "compute-time": ex.compute_time,
                "term-counts": ex.term_counts, "checks": ex.checks}
    if name == "MujocoChain":
        from pipeline.papers.partial_lagrangian.mujoco_chain import MujocoChain

        return MujocoChain
    raise AttributeError(name)


LINKS = Range(ge=1, le=10)   # the configured parameter lists hold 10 links (Sect. 4: up to 10 DoF)
DURATION = Range(gt=0, le=600)
LIMITS = {
    "system.damping_model": OneOf(DAMPING_MODELS), "system.simulation.formulation": OneOf(FORMS),
    "system.simulation.integrator": OneOf(INTEGRATORS), "scenario.joints": OneOf((REVOLUTE, PRISMATIC)),
    "scenario.cases": (Length(1, 2), OneOf(("free", "pd"))),
    "scenario.energy_integrators": (Length(1, 2), OneOf(INTEGRATORS)),
    # explicit schemes on these chains (periods ~1 s, ten links stiffer) are stable well below 10 ms
    "system.simulation.dt": Range(ge=1e-5, le=0.01),
    "system.gravity": NON_NEGATIVE, "system.links.mass": POSITIVE, "system.links.length": POSITIVE,
    "system.links.damping": NON_NEGATIVE, "system.links.stiffness": NON_NEGATIVE,
    "scenario.links": (Length(1, 10), LINKS), "scenario.slider_angle_deg": Range(ge=-360, le=360),
    "scenario.free.duration": DURATION, "scenario.pd.duration": DURATION, "scenario.duration": DURATION,
    "scenario.pd.kp": NON_NEGATIVE, "scenario.pd.kd": NON_NEGATIVE, "scenario.pd.reference_deg": Range(ge=-360, le=360),
    "scenario.pid.kp": NON_NEGATIVE, "scenario.pid.ki": NON_NEGATIVE, "scenario.pid.kd": NON_NEGATIVE,
    "scenario.pid.reference": POSITIVE, "scenario.states": Range(ge=1, le=100_000),
    "scenario.eval_repeats": Range(ge=1, le=10_000), "scenario.build_repeats": Range(ge=1, le=1000),
    "scenario.warmup": Range(ge=0, le=1000), "scenario.batch_instructions": Range(ge=1, le=10_000_000),
    "scenario.mujoco_batch": Range(ge=1, le=100_000),
    "scenario.trajectory_duration": DURATION, "scenario.energy_duration": DURATION,
}
RULES = (
    Rule(("system.logging.log_dt", "system.simulation.dt"), lambda log_dt, dt: log_dt >= dt,
         "system.logging.log_dt={0:g} s is shorter than the step system.simulation.dt={1:g} s"),
)


def _simulated_seconds(c) -> float:
    sc = c.scenario
    return sum(sc[case].duration for case in sc.get("cases", ()) if case in sc) + sc.get("duration", 0.0)


BUDGETS = {
    **{name: Budget("integration steps", lambda c: _simulated_seconds(c) / c.system.simulation.dt, 2e6,
                    "a shorter duration or a longer system.simulation.dt")
       for name in ("one-link", "two-link", "three-link", "ten-link", "slider")},
    "checks": Budget("integration steps", lambda c: len(c.scenario.links) * (
        c.scenario.trajectory_duration + 2 * c.scenario.energy_duration) / c.system.simulation.dt, 2e6,
        "shorter durations or a longer system.simulation.dt"),
    "compute-time": Budget("timed evaluations", lambda c: len(c.scenario.links) * (
        c.scenario.eval_repeats * (c.scenario.batch_instructions / 1000 + c.scenario.mujoco_batch)
        + c.scenario.build_repeats * 100), 1e7, "fewer repeats or smaller batches"),
}

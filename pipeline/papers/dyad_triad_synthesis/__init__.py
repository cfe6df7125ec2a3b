"""`dyad-triad-synthesis`: Mather, Erdman — Reformulation of Theories of Kinematic Synthesis for Planar Dyads
and Triads (Robotics 2023, 12, 22).

The importable API (planar vectors as complex numbers, SI units):

    dyad(points, alpha), triad(points, alpha, gamma, h)     the standard form, eqs. (1)-(2)
    loops(chain) -> [Loop]                                  the compatibility equations' Δ vectors (eqs. 7-21, A1-A10)
    synthesize(chain, free) -> [Synthesized]                roots of the compatibility linkage and their link vectors
    Compatibility(chain, free)                              the linkage itself: evaluate, roots, newton
    isotropic_roots(loops)                                  every complex root of a dyad in 5 PP (Sec. 2.3's six sets)
    FourBar.from_dyads(P1, (W_A, Z_A), (W_B, Z_B))          closed-form position analysis and defects
    burmester: poles, Π-points, centre-/circle-point conditions, least-squares dyads (independent of cofactors)
"""

from __future__ import annotations

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, PROBABILITY, Budget, Length, OneOf, Range, Rule
from pipeline.papers.dyad_triad_synthesis.compatibility import Compatibility, Synthesized, isotropic_roots, synthesize
from pipeline.papers.dyad_triad_synthesis.fourbar import FourBar
from pipeline.papers.dyad_triad_synthesis.standard_form import Chain, Loop, dyad, link_vectors, loops, triad

__all__ = ["Chain", "Compatibility", "FourBar", "Loop", "Synthesized", "dyad", "isotropic_roots", "link_vectors",
           "loops", "synthesize", "triad"]


def __getattr__(name: str):
    # The experiments pull in Exudyn and the MCAP writer; the synthesis API above needs neither.
    if name == "EXPERIMENTS":
        from pipeline.papers.dyad_triad_synthesis import experiments

        return {"table5": experiments.table5, "burmester-curves": experiments.burmester_curves,
                "round-trips": experiments.round_trips, "four-bar": experiments.four_bar,
                "compute-time": experiments.compute_time}
    raise AttributeError(name)


def _count(upper: int) -> Range:
    return Range(ge=1, le=upper)


LIMITS = {
    "system.length_unit": Range(gt=0, le=1000), "system.table4.points": Range(ge=-1e6, le=1e6),
    "system.table4.alpha_deg": Range(ge=-360, le=360),
    "system.search.grid": Range(ge=11, le=1_000_001), "system.search.grid_2d": Range(ge=11, le=2001),
    "system.search.same_root": Range(gt=0, lt=0.1), "system.search.special_tol": Range(gt=0, lt=0.1),
    "system.search.conditioning": Range(gt=0, lt=1),
    "system.linkage.line_density": Range(gt=0, le=1e4), "system.linkage.link_radius": POSITIVE,
    "scenario.sweep_samples": Range(ge=3, le=1_000_001), "scenario.cross_check_starts": _count(100_000),
    "scenario.rounding.samples": _count(100_000), "scenario.rounding.position": NON_NEGATIVE,
    "scenario.rounding.alpha_deg": NON_NEGATIVE, "scenario.positions": Range(ge=1, le=5),
    "scenario.samples": Range(ge=3, le=1_000_001), "scenario.four_bars": _count(10_000),
    "scenario.triads": _count(10_000), "scenario.count_problems": _count(100_000),
    "scenario.newton_starts": _count(1_000_000), "scenario.problems": Range(ge=0, le=1000),
    "scenario.repeats": _count(10_000), "scenario.least_squares_starts": _count(100_000),
    "scenario.leg_duration": Range(gt=0, le=600), "scenario.move_duration": Range(gt=0, le=600),
    "scenario.hold_duration": Range(ge=0, le=600),
    "scenario.controllers": (Length(1, 2), OneOf(("computed-torque", "pd"))),
    "execute.dt": Range(ge=1e-5, le=0.1), "execute.servo_dt": Range(ge=1e-5, le=0.1),
    "execute.control_dt": Range(ge=1e-4, le=1),
    "execute.bandwidth_hz": Range(gt=0, le=1000), "execute.damping_ratio": POSITIVE,
    "execute.spectral_radius": PROBABILITY, "execute.newton_tolerance": Range(gt=0, lt=1),
    "execute.log_dt": Range(ge=1e-4, le=10), "execute.tf_dt": Range(ge=1e-4, le=10),
}
RULES = (
    Rule(("execute.servo_dt", "execute.control_dt"), lambda step, period: step <= period,
         "execute.servo_dt={0:g} s must not exceed the servo period execute.control_dt={1:g} s"),
    Rule(("execute.log_dt", "execute.dt"), lambda log_dt, dt: log_dt >= dt,
         "execute.log_dt={0:g} s is shorter than the replay's step execute.dt={1:g} s"),
    Rule(("execute.tf_dt", "execute.dt"), lambda tf_dt, dt: tf_dt >= dt,
         "execute.tf_dt={0:g} s is shorter than the replay's step execute.dt={1:g} s"),
)


def _round_trips(c) -> float:
    """Compatibility-linkage evaluations: 1-D sweeps per synthesis, the 7 PP triads' 2-D sweep, Newton starts."""
    grid, sc = c.system.search.grid, c.scenario
    return (sc.four_bars * 3 + sc.count_problems + sc.triads * 2) * grid \
        + sc.triads * c.system.search.grid_2d ** 2 + sc.triads * sc.newton_starts


BUDGETS = {
    "table5": Budget("compatibility evaluations", lambda c: c.scenario.sweep_samples + 2 * c.system.search.grid
                     + c.scenario.cross_check_starts + c.scenario.rounding.samples * 10, 1e7,
                     "fewer scenario.rounding.samples or a coarser system.search.grid"),
    "burmester-curves": Budget("compatibility evaluations", lambda c: c.scenario.samples + c.system.search.grid,
                               2e6, "fewer scenario.samples"),
    "round-trips": Budget("compatibility evaluations", _round_trips, 5e7,
                          "fewer scenario.four_bars, scenario.triads or scenario.count_problems"),
    "four-bar": Budget("Exudyn steps", lambda c: 4 * c.scenario.leg_duration / c.execute.dt
                       + len(c.scenario.controllers) * (c.scenario.move_duration + c.scenario.hold_duration)
                       / c.execute.servo_dt, 2e6,
                       "shorter durations or longer execute.dt, execute.servo_dt"),
    "compute-time": Budget("solver evaluations", lambda c: (c.scenario.problems + 1) * (c.scenario.repeats + 2)
                           * (c.scenario.least_squares_starts + c.scenario.newton_starts + c.system.search.grid), 1e7,
                           "fewer scenario.problems, scenario.repeats or random starts"),
}

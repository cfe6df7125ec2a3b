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

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, PROBABILITY, OneOf, Range
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


LIMITS: dict[str, Range | OneOf] = {
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
    "scenario.hold_duration": Range(ge=0, le=600), "scenario.controllers": OneOf(("computed-torque", "pd")),
    "execute.dt": Range(gt=0, le=0.1), "execute.servo_dt": Range(gt=0, le=0.1), "execute.control_dt": Range(gt=0, le=1),
    "execute.bandwidth_hz": Range(gt=0, le=1000), "execute.damping_ratio": POSITIVE,
    "execute.spectral_radius": PROBABILITY, "execute.newton_tolerance": Range(gt=0, lt=1),
    "execute.log_dt": Range(gt=0, le=10), "execute.tf_dt": Range(gt=0, le=10),
}

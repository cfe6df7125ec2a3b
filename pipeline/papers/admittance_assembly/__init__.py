"""`admittance-assembly`: Huang, Schimmels — Admittance Selection Conditions for Frictionless Force-Guided
Assembly of Polyhedral Parts in Two Single-Point Principal Contacts (IEEE T-RO 2008).

The paper's text is truncated after its introduction: what survives is the admittance law v = v0 + A·w (1)
and the error-reduction condition dᵀ(v0 + A·w) < 0 (2). This package is the demonstrator of the spec: a
square peg in a square hole, frictionless and quasi-static, in the two-point contact state (planar and
spatial). The importable API (SI units, body-frame twists [v; ω] and wrenches [f; m]):

    PegInHole(planar, half_width, length, ref_height, clearance, depth)   the geometry of one case
    contacts(g, R, p) -> Contacts                 every candidate contact: gap, point, normal
    unit_wrenches(g, R, p, points, normals)       the columns of W (w = W λ), body frame
    line_vector(g, R, p)                          d of eq. (2)
    contact_response(A, W, v0) -> (λ, w, v)       the frictionless complementarity problem under eq. (1)
    solve_lcp(M, q)                               λ ≥ 0, Mλ + q ≥ 0, λᵀ(Mλ + q) = 0
    state_samples(g, coords, speed).margin(A, speed)   condition (2) over chart coordinates of the state
    design_admittance(...)                        an A that maximises the worst margin at given configurations
    insert(g, A, R0, p0, ...)                     a quasi-static insertion
"""

from __future__ import annotations

from pipeline.core.experiment import ANGLE, POSITIVE, Budget, Length, OneOf, Range, Rule
from pipeline.papers.admittance_assembly.design import design_admittance, state_samples
from pipeline.papers.admittance_assembly.geometry import PegInHole, contacts, line_vector, unit_wrenches
from pipeline.papers.admittance_assembly.insertion import insert
from pipeline.papers.admittance_assembly.quasistatic import contact_response, solve_lcp

__all__ = ["PegInHole", "contact_response", "contacts", "design_admittance", "insert", "line_vector", "solve_lcp",
           "state_samples", "unit_wrenches"]


def __getattr__(name: str):
    # the experiments pull in MuJoCo, Hydra's config objects and the run writer
    if name == "EXPERIMENTS":
        from pipeline.papers.admittance_assembly import experiments

        return {"corner-conditions": experiments.corner_conditions, "insertion": experiments.insertion_runs,
                "mujoco-crosscheck": experiments.mujoco_crosscheck}
    raise AttributeError(name)


_BOX = {"tilt": ANGLE, "tilt_x": ANGLE, "twist": ANGLE, "lateral": Range(ge=-0.01, le=0.01),
        "clearance": Range(gt=0, le=0.01)}
CASES = ("planar", "spatial")
# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"corner-conditions"})
LIMITS = {
    "scenario.cases": (Length(1, 2), OneOf(CASES)), "scenario.runs": (Length(1, 2), OneOf(("static", "insertion"))),
    "scenario.admittances": (Length(1, 2), OneOf(("designed", "isotropic"))),
    "scenario.admittance": OneOf(("designed", "isotropic")),
    "mujoco.integrator": OneOf(("discrete", "implicit", "implicitfast", "Euler", "RK4")),
    "scenario.duration": Range(gt=0, le=60), "scenario.dt": Range(ge=1e-4, le=0.05),
    "scenario.insertion_dt": Range(ge=1e-4, le=0.05), "mujoco.timestep": Range(ge=1e-5, le=0.01),
    "system.peg.half_width": Range(gt=0, le=1.0), "system.peg.length": Range(gt=0, le=2.0),
    "system.peg.ref_height": Range(ge=-2.0, le=2.0), "system.hole.clearance": Range(gt=0, le=0.01),
    "system.hole.depth": POSITIVE, "system.selected_height": Range(ge=-2.0, le=2.0),
    "system.nominal_speed": POSITIVE, "system.admittance.translational": POSITIVE,
    "system.admittance.min_eigenvalue": Range(gt=0, lt=1), "system.admittance.restarts": Range(ge=0, le=50),
    **{f"system.state.{case}.{key}": r for case in ("planar", "spatial") for key, r in _BOX.items()},
    "scenario.interior_samples": Range(ge=1, le=1_000_000), "scenario.random_admittances": Range(ge=1, le=100_000),
    "scenario.random_interior_samples": Range(ge=1, le=1_000_000), "scenario.timing_repeats": Range(ge=1, le=100_000),
    "scenario.trials": Range(ge=1, le=100),
    "scenario.active_gap": POSITIVE, "scenario.predict_gap": POSITIVE,
    "scenario.static_duration": Range(gt=0, le=10), "scenario.settle": Range(ge=0, le=10),
    "scenario.static_forces": Range(gt=0, le=1000),
    "mujoco.solref": POSITIVE, "mujoco.solimp": Range(ge=0, le=10),
}
RULES = (
    Rule(("scenario.settle", "scenario.static_duration"), lambda settle, duration: settle < duration,
         "scenario.settle={0:g} s must be shorter than scenario.static_duration={1:g} s"),
    Rule(("scenario.log_dt", "scenario.dt"), lambda log_dt, dt: log_dt >= dt,
         "scenario.log_dt={0:g} s is shorter than the step scenario.dt={1:g} s"),
    Rule(("scenario.log_dt", "scenario.duration"), lambda log_dt, T: log_dt <= T / 10,
         "scenario.log_dt={0:g} s leaves fewer than 10 samples of the {1:g} s run"),
    Rule(("scenario.random_interior_samples", "scenario.interior_samples"), lambda used, drawn: used <= drawn,
         "scenario.random_interior_samples={0} exceeds the {1} interior samples drawn"),
)
BUDGETS = {
    "corner-conditions": Budget("condition checks", lambda c: len(c.scenario.cases) * (
        c.scenario.interior_samples + c.scenario.random_admittances * c.scenario.random_interior_samples
        + c.scenario.timing_repeats), 1e8, "fewer samples or random admittances"),
    "insertion": Budget("quasi-static steps", lambda c: len(c.scenario.cases) * len(c.scenario.admittances)
                        * c.scenario.trials * c.scenario.duration / c.scenario.dt, 1e6,
                        "fewer scenario.trials, a shorter scenario.duration or a longer scenario.dt"),
    "mujoco-crosscheck": Budget("physics steps", lambda c: len(c.scenario.cases) * (
        c.scenario.static_duration + c.scenario.duration) / c.mujoco.timestep, 5e6,
        "a shorter scenario.duration or a longer mujoco.timestep"),
}

"""`cobot-6r-ik`: Carbonari, Palpacelli, Callegari — Inverse Kinematics of a Class of 6R Collaborative
Robots with Non-Spherical Wrist (Robotics 2023, 12, 36).

The importable API (SI units, the paper's Table 1 DH; FANUC CRX-10iA/L):

    fk(q) -> (4, 4) or (N, 4, 4)          forward kinematics, eq. (2)
    ik_all(T) -> (k, 6)                   every solution (k ≤ 16), angles in (−π, π], from Λ(c1) of eq. (25)
                                          (method="octic": from Λ's genuine degree-8 factor, ours)
    ik_batch(T (N, 4, 4)) -> (q (N, 16, 6) NaN-padded, counts (N,))
    ik_diagnose(T) -> Diagnostics         the 16 roots of Λ and what became of each real one (Tables 2–3)
    twin(q)                               the other configuration sharing frame {4} (q2 / π − q2)
    cayley(c), cayley_params(R)           eqs. (4)–(6) and their inverse

Every angle within (−π, π] lies inside Table 1's motion ranges (±π, ±π, ±1.5π, ±1.06π, ±π, ±1.25π), so
no solution is dropped for joint limits.
"""

from __future__ import annotations

import numpy as np

from pipeline.core.experiment import Budget, Length, OneOf, Range, Rule
from pipeline.papers.cobot_6r_ik import ik
from pipeline.papers.cobot_6r_ik.ik import DEFAULT, Diagnostics, Tolerances
from pipeline.papers.cobot_6r_ik.kinematics import CRX10IAL, Geometry, cayley, cayley_params, fk, twin, wrap
from pipeline.robotics.mjcf import SERVO_RULES

__all__ = ["CRX10IAL", "DEFAULT", "Diagnostics", "Geometry", "Tolerances", "cayley", "cayley_params", "fk",
           "ik_all", "ik_batch", "ik_diagnose", "twin", "wrap"]


def ik_all(T, g: Geometry = CRX10IAL, tol: Tolerances = DEFAULT, method: str = "lambda16") -> np.ndarray:
    """Every joint set reaching flange pose T (4, 4): shape (k, 6), rad. method "lambda16" is the paper's
    Λ with the FK filter; "octic" roots only Λ's genuine factor (ours: faster, better conditioned)."""
    return ik.solve(T, g, tol, method)


def ik_batch(T, g: Geometry = CRX10IAL, tol: Tolerances = DEFAULT,
             method: str = "lambda16") -> tuple[np.ndarray, np.ndarray]:
    """Many poses in one call: T (N, 4, 4) -> (q (N, 16, 6), NaN rows past counts[i]; counts (N,))."""
    return ik.solve_batch(T, g, tol, method)


def ik_diagnose(T, g: Geometry = CRX10IAL, tol: Tolerances = DEFAULT, method: str = "lambda16") -> Diagnostics:
    """ik_all with every root of Λ (or G) and every candidate it produced."""
    return ik.diagnose(T, g, tol, method)


def __getattr__(name: str):
    # The experiments pull in MuJoCo and Hydra; the kinematics API above does not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.cobot_6r_ik import experiments

        return {"tables": experiments.tables, "completeness": experiments.completeness,
                "compute-time": experiments.compute_time, "trajectory": experiments.trajectory}
    raise AttributeError(name)


_LENGTH = Range(gt=0, le=5.0)   # m
# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"compute-time"})
LIMITS: dict[str, Range | OneOf] = {
    **{f"system.geometry.{k}": _LENGTH for k in ("d1", "a2", "d2", "d3", "d4", "d5", "d6")},
    "system.method": OneOf(ik.METHODS), "system.tolerances.imag": Range(ge=0, le=1),
    "system.tolerances.newton": Range(ge=0, le=20),
    "system.tolerances.polish_position": Range(ge=0, le=1), "system.tolerances.polish_rotation": Range(ge=0, le=1),
    "system.tolerances.pose_newton": Range(ge=0, le=20), "system.tolerances.position": Range(gt=0, le=1e-2),
    "system.tolerances.rotation": Range(gt=0, le=1e-2), "system.tolerances.duplicate": Range(gt=0, le=0.1),
    "system.dynamics.masses": Range(gt=0, le=100), "system.dynamics.link_radius": Range(gt=0, le=0.5),
    "system.dynamics.armature": Range(ge=0, le=10), "system.dynamics.damping": Range(ge=0, le=1000),
    "system.dynamics.torque_limit": Range(gt=0, le=1e4), "system.dynamics.velocity_limit": Range(gt=0, le=100),
    "scenario.d1_example": _LENGTH, "scenario.poses": Range(ge=1, le=100_000),
    "scenario.reference_starts": Range(ge=0, le=100_000), "scenario.reference_poses": Range(ge=0, le=10_000),
    "scenario.warmup": Range(ge=0, le=10_000), "scenario.batch_repeats": Range(ge=1, le=1000),
    "scenario.batch_chunk": Range(ge=1, le=10_000),
    "scenario.peer_poses": Range(ge=0, le=10_000), "scenario.peer_starts": Range(ge=1, le=10_000),
    "scenario.near_singular_c": Range(gt=0, le=1e12),
    "scenario.duration": Range(gt=0, le=120), "scenario.ik_dt": Range(ge=1e-4, le=1),
    "scenario.paths.line.length": Range(gt=0, le=2), "scenario.paths.circle.radius": Range(gt=0, le=1),
    "scenario.paths.circle-branch-end.radius": Range(gt=0, le=1),
    **{f"scenario.paths.{p}.kind": OneOf(("line", "circle")) for p in ("line", "circle", "circle-branch-end")},
    "scenario.cases": (Length(1, 3), OneOf(("line", "circle", "circle-branch-end"))),
    "execute.dt": Range(ge=1e-4, le=0.01), "execute.bandwidth_hz": Range(gt=0, le=100),
    "execute.damping_ratio": Range(gt=0, le=10), "execute.log_dt": Range(ge=1e-4, le=1),
    "execute.tf_dt": Range(ge=1e-4, le=1), "execute.jump_threshold": Range(ge=0, le=6.3),
    "execute.settle": Range(ge=0, le=10),
    "scenario.q_deg": Range(ge=-360, le=360), "scenario.q_start_deg": Range(ge=-360, le=360),
}
RULES = (
    *SERVO_RULES,
    Rule(("scenario.reference_poses", "scenario.poses"), lambda n_ref, n: n_ref <= n,
         "scenario.reference_poses={0:g} exceeds scenario.poses={1:g}"),
)
BUDGETS = {
    "tables": Budget("least-squares starts", lambda c: 2 * c.scenario.reference_starts, 1e6,
                     "fewer scenario.reference_starts"),
    "completeness": Budget("IK calls and least-squares starts", lambda c: 2 * c.scenario.poses
                           + c.scenario.reference_poses * c.scenario.reference_starts, 2e7,
                           "fewer scenario.poses, reference_poses or reference_starts"),
    "compute-time": Budget("IK calls", lambda c: c.scenario.poses * (6 + 2 * c.scenario.batch_repeats)
                           + c.scenario.warmup + 1000 * c.scenario.peer_poses * c.scenario.peer_starts, 5e7,
                           "fewer scenario.poses, batch_repeats, peer_poses or peer_starts"),
    "trajectory": Budget("physics steps", lambda c: len(c.scenario.cases) * (c.scenario.duration + c.execute.settle)
                         / c.execute.dt, 5e6, "fewer paths, a shorter scenario.duration or a longer execute.dt"),
}

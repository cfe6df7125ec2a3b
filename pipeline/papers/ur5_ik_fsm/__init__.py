"""`ur5-ik-fsm`: Villalobos, Sanchez, Martell — Singularity Analysis and Complete Methods to Compute the
Inverse Kinematics for a 6-DOF UR/TM-Type Robot (Robotics 2022, 11, 137).

The importable API (SI units, the paper's Table 1 DH):

    fk(q) -> (4, 4)                              forward kinematics, eqs. (1)-(13)
    ik_all(T) -> (k, 6)                          every valid solution, paper branch order
    ik_min_displacement(T, q_prev) -> (6,)|None  Algorithm 1
    ik_fsm(T, q_prev) -> (6,)|None               Algorithm 2 (finite-state machine)
    ik_batch(T (N,4,4), q_prev, algorithm) -> (N, 6), NaN rows where no valid set
    jacobian(q) -> (6, 6), det_j(q)              eqs. (33)-(46)
"""

from __future__ import annotations

import numpy as np

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Text
from pipeline.papers.ur5_ik_fsm import ik
from pipeline.papers.ur5_ik_fsm.ik import PAPER, Conventions
from pipeline.papers.ur5_ik_fsm.kinematics import UR5, Geometry, det_j, fk, jacobian, shoulder_term
from pipeline.robotics.mjcf import SERVO_RULES

__all__ = ["PAPER", "UR5", "Conventions", "Geometry", "det_j", "fk", "ik_all", "ik_batch", "ik_fsm",
           "ik_min_displacement", "jacobian", "shoulder_term"]


def ik_all(T, g: Geometry = UR5, c: Conventions = PAPER) -> np.ndarray:
    """Every valid joint set for pose T, in the paper's branch order; shape (k, 6), k ≤ 8."""
    return np.array([q for _, q, ok in ik.branches(np.asarray(T, dtype=float), g, c) if ok]).reshape(-1, 6)


def ik_min_displacement(T, q_prev, g: Geometry = UR5, c: Conventions = PAPER) -> np.ndarray | None:
    """Algorithm 1: the valid set closest to q_prev (Euclidean, eq. 48); None if there is none."""
    q = ik.min_displacement(np.asarray(T, dtype=float), q_prev, g, c).q
    return None if q is None else np.array(q)


def ik_fsm(T, q_prev, g: Geometry = UR5, c: Conventions = PAPER) -> np.ndarray | None:
    """Algorithm 2: the finite-state machine's set; None if there is none."""
    q = ik.fsm(np.asarray(T, dtype=float), q_prev, g, c).q
    return None if q is None else np.array(q)


def ik_batch(T, q_prev, algorithm: str = "alg2", g: Geometry = UR5, c: Conventions = PAPER) -> np.ndarray:
    """Many poses in one call: T (N, 4, 4), q_prev (6,) or (N, 6) -> (N, 6), NaN rows where none."""
    return ik.solve_batch(T, q_prev, algorithm, g, c)[0]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and Hydra; the kinematics API above does not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.ur5_ik_fsm import experiments

        return {"tables": experiments.tables, "singular-paths": experiments.singular_paths,
                "random-paths": experiments.singular_paths, "compute-time": experiments.compute_time}
    raise AttributeError(name)


STEP = Range(ge=1e-5, le=0.1)   # s: time steps and log periods
PATHS = ("wrist", "shoulder", "elbow")
# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"compute-time"})
LIMITS = {
    "system.fk_form": OneOf(("corrected", "printed")),
    "system.conventions.sqrt_negative": OneOf(("abs", "clamp", "reject")),
    "scenario.table2": Text(), "scenario.cases": (Length(1, 2), OneOf(("independent", "sequential"))),
    "scenario.previous": OneOf(("random", "zero")),
    "scenario.paths": (Length(1, 3), OneOf(PATHS)), "scenario.algorithms": (Length(1, 2), OneOf(("alg1", "alg2"))),
    "scenario.crossings": (Length(1, 2), OneOf(("near", "through"))),
    "scenario.duration": Range(gt=0, le=60), "scenario.ik_dt": STEP, "execute.dt": Range(ge=1e-4, le=0.02),
    "execute.log_dt": STEP, "execute.tf_dt": STEP,
    "scenario.poses": Range(ge=1, le=1_000_000), "scenario.warmup": Range(ge=0, le=100_000),
    "scenario.batch_repeats": Range(ge=1, le=1000),
    "system.geometry.d1": POSITIVE, "system.geometry.a2": POSITIVE, "system.geometry.a3": POSITIVE,
    "system.geometry.d4": POSITIVE, "system.geometry.d5": POSITIVE, "system.geometry.d6": POSITIVE,
    "system.conventions.snap_tol": NON_NEGATIVE, "system.conventions.s5_min": NON_NEGATIVE,
    "system.conventions.s3_min": NON_NEGATIVE, "system.conventions.shoulder_min": NON_NEGATIVE,
    "system.conventions.sqrt_negative_tol": NON_NEGATIVE, "system.conventions.tie_tol": NON_NEGATIVE,
    "system.conventions.pi_sign": Range(ge=-1, le=1),
    "system.dynamics.link_radius": POSITIVE, "system.dynamics.armature": NON_NEGATIVE,
    "system.dynamics.damping": NON_NEGATIVE, "system.dynamics.torque_limit": POSITIVE,
    "system.dynamics.velocity_limit": POSITIVE,
    "execute.bandwidth_hz": Range(gt=0, le=100), "execute.damping_ratio": POSITIVE, "scenario.near_gap": NON_NEGATIVE,
    "scenario.wrist.length": POSITIVE, "scenario.shoulder.length": POSITIVE, "scenario.elbow.length": POSITIVE,
}
RULES = SERVO_RULES


def _path_steps(c) -> float:
    return len(c.scenario.paths) * len(c.scenario.algorithms) * len(c.scenario.crossings) * c.scenario.duration \
        / c.execute.dt


BUDGETS = {
    "singular-paths": Budget("physics steps", _path_steps, 5e6,
                             "fewer paths, a shorter scenario.duration or a longer execute.dt"),
    # per episode, summed over episodes.count: 1e8 steps is 25,000 episodes of 4 s, about an hour on 2 cores
    "random-paths": Budget("physics steps", _path_steps, 1e8, "a shorter scenario.duration or a longer execute.dt"),
    "compute-time": Budget("IK calls", lambda c: c.scenario.poses * (2 + c.scenario.batch_repeats)
                           + c.scenario.warmup, 5e7, "fewer scenario.poses or scenario.batch_repeats"),
}

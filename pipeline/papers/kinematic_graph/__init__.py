"""`kinematic-graph`: Corves, Shahidi — Kinematic Graph for Motion Planning of Robotic Manipulators (Robotics 2022,
11, 105).

The importable API (SI units):

    RegionalArm.from_config(name, node)          the first joints of a DH arm and its point of interest P_w
    graph.build(arm, c_res, t_res) -> KinematicGraph    Algorithm 1, vectorised (NumPy + SciPy sparse)
    graph.grid_graph(arm, c_res, t_res)          the plain C-space grid graph (the baseline)
    Planner(Space.of(graph, mu_max)).plan(metric, Query(q_i, P_w_goal), blocked)   A* with the paper's metrics
    TaskSpacePlanner(kg).plan(query, blocked)    planning with T-space information only, realised by IK
"""

from __future__ import annotations

import math

from pipeline.core.experiment import Budget, Length, Limit, OneOf, Range, Rule, Text
from pipeline.papers.kinematic_graph.arms import RegionalArm
from pipeline.papers.kinematic_graph.search import METRICS, Planner, Query, Space, TaskSpacePlanner

__all__ = ["METRICS", "Planner", "Query", "RegionalArm", "Space", "TaskSpacePlanner"]


def __getattr__(name: str):
    # The experiments pull in MuJoCo and the run files; the graph and the search do not need them.
    if name == "EXPERIMENTS":
        from pipeline.papers.kinematic_graph import experiments

        return {"table1": experiments.table1, "search": experiments.search, "spatial": experiments.spatial}
    raise AttributeError(name)


_ARM = {"joints": Range(ge=1, le=6), "dh.a": Range(ge=-5, le=5), "dh.d": Range(ge=-5, le=5),
        "dh.alpha": Range(ge=-3.1416, le=3.1416), "dh.theta_offset": Range(ge=-6.2832, le=6.2832),
        "wrist_offset": Range(ge=-5, le=5), "lower": Range(ge=-6.2832, le=6.2832),
        "upper": Range(ge=-6.2832, le=6.2832), "task_dims": Range(ge=2, le=3), "link_radius": Range(gt=0, le=0.5),
        "masses": Range(gt=0, le=1000), "armature": Range(ge=0, le=100), "damping": Range(ge=0, le=1000),
        "torque_limit": Range(gt=0, le=1e4)}

# Experiments whose compute times are results: their runs have the machine to themselves.
TIMED = frozenset({"table1", "search"})
LIMITS: dict[str, Limit | tuple[Limit, ...]] = {
    **{f"system.{arm}.{key}": r for arm in ("planar", "puma") for key, r in _ARM.items()},
    # sizes: the grid's node count is bounded when the experiment makes its cases (graph.check_size)
    "scenario.c_res_deg": (Length(1, 6), Range(ge=0.25, le=90)),
    "scenario.t_res": (Length(1, 10), Range(ge=0.005, le=1)),
    "scenario.branching_dims": (Length(1, 6), Range(ge=1, le=6)),
    "graph.c_res_deg": Range(ge=0.25, le=90), "graph.t_res": Range(ge=0.005, le=1),
    "search.pairs": Range(ge=1, le=1000), "search.metrics": (Length(1, 4), OneOf(METRICS)),
    "search.baseline": (Length(0, 4), OneOf(METRICS)),
    "search.limit_factor": Range(ge=1, le=100), "search.margin": Range(ge=0, le=0.5),
    "search.dense_step_deg": Range(ge=0.05, le=10),
    "scenario.scenes": (Length(1, 2), OneOf(("free", "obstacle"))),
    "scenario.showcase_metrics": (Length(0, 4), OneOf(METRICS)),
    "scenario.obstacles.names": (Length(0, 50), Text(40)),
    "scenario.obstacles.centre": (Length(0, 50), Range(ge=-10, le=10)),
    "scenario.obstacles.half": (Length(0, 50), Range(gt=0, le=5)),
    **{f"scenario.showcase{scene}.q_start_deg": Range(ge=-360, le=360) for scene in ("", ".free", ".obstacle")},
    **{f"scenario.showcase{scene}.goal": Range(ge=-5, le=5) for scene in ("", ".free", ".obstacle")},
    "execute.dt": Range(ge=1e-4, le=0.01), "execute.speed": Range(ge=0.1, le=10),
    "execute.accel_fraction": Range(gt=0, le=0.5), "execute.settle": Range(ge=0, le=10),
    "execute.bandwidth_hz": Range(gt=0, le=100), "execute.damping_ratio": Range(gt=0, le=5),
    "execute.log_dt": Range(ge=1e-4, le=1), "execute.tf_dt": Range(ge=1e-4, le=1),
}
RULES = (
    Rule(("execute.log_dt", "execute.dt"), lambda log_dt, dt: log_dt >= dt,
         "execute.log_dt={0:g} s is shorter than the physics step execute.dt={1:g} s"),
    Rule(("execute.tf_dt", "execute.dt"), lambda tf_dt, dt: tf_dt >= dt,
         "execute.tf_dt={0:g} s is shorter than the physics step execute.dt={1:g} s"),
)


def _searches(cfg) -> float:
    """Worst-case A* expansions of a benchmark: every search on the C-grid stopped at its limit."""
    arm = "puma" if "obstacles" in cfg.scenario and "scenes" not in cfg.scenario else "planar"
    nodes = math.prod(math.floor((hi - lo) / math.radians(cfg.graph.c_res_deg) + 1e-9) + 1
                      for lo, hi in zip(cfg.system[arm].lower, cfg.system[arm].upper, strict=True))
    scenes = len(cfg.scenario.scenes) if "scenes" in cfg.scenario else 1
    per_search = cfg.search.limit_factor * nodes
    return scenes * cfg.search.pairs * (len(cfg.search.baseline) + len(cfg.search.metrics)) * per_search


BUDGETS = {name: Budget("A* expansions (worst case)", _searches, 5e8,
                        "fewer search.pairs, fewer search.baseline metrics or a coarser graph.c_res_deg")
           for name in ("search", "spatial")}

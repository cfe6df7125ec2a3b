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

from pipeline.core.experiment import OneOf, Range
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

LIMITS: dict[str, Range | OneOf] = {
    **{f"system.{arm}.{key}": r for arm in ("planar", "puma") for key, r in _ARM.items()},
    # sizes: a 2-joint grid at 0.1° is 13 M nodes, a 3-joint one at 1° is 47 M: the bounds keep a run in memory
    "scenario.c_res_deg": Range(ge=0.25, le=90), "scenario.t_res": Range(ge=0.005, le=1),
    "scenario.branching_dims": Range(ge=1, le=6),
    "graph.c_res_deg": Range(ge=0.25, le=90), "graph.t_res": Range(ge=0.005, le=1),
    "search.pairs": Range(ge=1, le=1000), "search.metrics": OneOf(METRICS), "search.baseline": OneOf(METRICS),
    "search.limit_factor": Range(ge=1, le=100), "search.margin": Range(ge=0, le=0.5),
    "search.dense_step_deg": Range(ge=0.05, le=10),
    "scenario.showcase_metrics": OneOf(METRICS),
    "scenario.scenes": OneOf(("free", "obstacle")), "scenario.obstacles.centre": Range(ge=-10, le=10),
    "scenario.obstacles.half": Range(gt=0, le=5),
    **{f"scenario.showcase{scene}.q_start_deg": Range(ge=-360, le=360) for scene in ("", ".free", ".obstacle")},
    **{f"scenario.showcase{scene}.goal": Range(ge=-5, le=5) for scene in ("", ".free", ".obstacle")},
    "execute.dt": Range(ge=1e-4, le=0.01), "execute.speed": Range(ge=0.1, le=10),
    "execute.accel_fraction": Range(gt=0, le=0.5), "execute.settle": Range(ge=0, le=10),
    "execute.bandwidth_hz": Range(gt=0, le=100), "execute.damping_ratio": Range(gt=0, le=5),
    "execute.log_dt": Range(ge=1e-4, le=1), "execute.tf_dt": Range(ge=1e-4, le=1),
}

"""`src-joint`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.src_joint.figures import (
    _floor_figure,
    _joint_figures,
    _obstacle_figures,
    _pose_figure,
    _random_figure,
)
from analysis.papers.src_joint.metrics import (
    REACHED_ANGLE,
    REACHED_POSITION,
    _bars,
    _final_errors,
    _joint_metrics,
    _reach_metrics,
    _time_below,
    floor_metrics,
    loop_metrics,
)
from pipeline.core.runlog import Run


def analyze_joint_model(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_id = {}
    for run in runs:
        m.add_run(run, _joint_metrics(run))
        by_id[run.run_id] = run
    for plant in ("mujoco", "exact"):
        if f"{plant}-corrected" in by_id:
            _joint_figures(plant, {k.removeprefix(f"{plant}-"): r for k, r in by_id.items() if k.startswith(plant)},
                           figures, velocities=plant == "mujoco")
    return m.frame()


def analyze_reach_poses(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case = {r.metadata["case"]: r for r in runs}
    for run in runs:
        values = _reach_metrics(run)
        target, _, plant = run.metadata["case"].partition("-")
        nominal = by_case.get(f"{target}-nominal")
        if plant != "nominal" and nominal is not None:
            # what the plant's defects alone did: the final pose against FreeBOT-SIM's final pose
            e_p, e_o = _final_errors(run)[:2]
            e_p_nominal, e_o_nominal = _final_errors(nominal)[:2]
            dp = e_p_nominal - e_p                                   # r − r_nominal, as both aim at r^d
            values |= {f"deviation.position.{a}": (dp[k], "m") for k, a in enumerate("xyz")}
            values["deviation.position"] = (float(np.linalg.norm(dp)), "m")
            turn = Rotation.from_euler("XYZ", e_o).inv() * Rotation.from_euler("XYZ", e_o_nominal)  # R Rᵀ_nominal
            values["deviation.orientation"] = (float(turn.magnitude()), "rad")
        m.add_run(run, values)
    reachable = [r for case, r in by_case.items() if case.startswith("random") and case.endswith("-nominal")]
    if reachable:
        finals = np.array([_final_errors(r)[2:] for r in reachable])
        m.add("random", "final.position_error_max", finals[:, 0].max(), "m")
        m.add("random", "final.orientation_error_max", finals[:, 1].max(), "rad")
        reached = (finals[:, 0] < REACHED_POSITION) & (finals[:, 1] < REACHED_ANGLE)
        m.add("random", "claim.reached", float(reached.all()), "bool")
    for target in ("A", "B"):
        if f"{target}-nominal" in by_case:
            _pose_figure(target, {c.partition("-")[2]: r for c, r in by_case.items() if c.startswith(f"{target}-")},
                         figures)
    if reachable:
        _random_figure(reachable, figures)
    return m.frame()


def analyze_reach_floor(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """The floor under targets A and B per model form and reading, and the loop that twists a joint."""
    m = MetricTable()
    for run in runs:
        m.add_run(run, loop_metrics(run) if run.metadata["case"] == "eq5-loop" else floor_metrics(run))
    _floor_figure({run.metadata["case"]: run for run in runs}, figures)
    return m.frame()


def analyze_avoid_obstacles(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        clearance, check = run["/clearance"], run["/clearance/mujoco"]
        _, _, p_norm, angle = _final_errors(run)
        values = {"final.position_error": (p_norm, "m"), "final.orientation_error": (angle, "rad"),
                  "time_to_1mm": (_time_below(run, 1e-3), "s"),
                  "claim.reached": (float(p_norm < REACHED_POSITION and angle < REACHED_ANGLE), "bool"),
                  "clearance.min": (clearance.to_numpy().min(), "m"),
                  "clearance.mujoco_min": (check.to_numpy().min(), "m"),
                  "clearance.mujoco_difference_max": (np.abs(clearance.to_numpy() - check.to_numpy()).max(), "m"),
                  "qp.slack_max": (run["/qp"]["value.slack"].max(), "m/s")}
        for bar in _bars(clearance):
            values[f"clearance.{bar}.min"] = (clearance.filter(like=bar).to_numpy().min(), "m")
        ct = run["/compute_time"]
        for name in ("qp", "model"):
            values |= timing_metrics(name, ct[f"seconds.{name}"].to_numpy())
        values["wheel_speed_max"] = (np.abs(run["/command"].drop(columns="kind").to_numpy()).max(), "rad/s")
        m.add_run(run, values)
    by_id = {r.run_id: r for r in runs}
    if "avoid" in by_id:
        _obstacle_figures(by_id, figures)
    return m.frame()


ANALYSES = {"joint-model": analyze_joint_model, "reach-poses": analyze_reach_poses,
            "reach-floor": analyze_reach_floor, "avoid-obstacles": analyze_avoid_obstacles}

"""`nmpc-cdkd`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import itertools

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.nmpc_cdkd.figures import (
    _components_figure,
    _fig3,
    _paths_figure,
    _snapshots_figure,
    _table3_figure,
)
from analysis.papers.nmpc_cdkd.metrics import (
    ARRIVAL_POSITION,
    _obstacle_metrics,
    _solve_metrics,
    _trajectory_metrics,
    case_config,
    orientation_lag_model,
)
from analysis.papers.nmpc_cdkd.table3 import per_seed, table3, timed_solves
from pipeline.core.runlog import Run


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Per run: its timed solves; `table3`: the cells pooled over the seeds with bootstrap intervals of every
    ratio (table3.py); `table3__seed=<s>`: each seed's own ratios; the NLP sizes of each cell."""
    m = MetricTable()
    for run in runs:
        values = _solve_metrics(run["/nmpc/solve"])
        if "/nmpc/problem" in run.topic_names:
            problem = run["/nmpc/problem"].iloc[0]
            values |= {f"nlp.{c.removeprefix('value.')}": (float(problem[c]), "count")
                       for c in problem.index if c.startswith("value.")}
        m.add_run(run, values)
    solves = timed_solves(runs)
    for metric, (value, unit) in table3(solves).items():
        m.add("table3", metric, value, unit)
    for seed, values in per_seed(solves).items():
        for metric, value in values.items():
            m.add(f"table3__seed={seed}", metric, value, "fraction" if "growth" in metric else "ratio")
    frame = m.frame()
    _table3_figure(frame, figures)
    return frame


def analyze_tracking(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    tool_error = {}
    for run in runs:
        values = _trajectory_metrics(run)
        ref_z = run["/reference/tool"]["position.z"]
        dip = (ref_z - ref_z.iloc[0]).abs()
        values["reference.z_deviation_max"] = (dip.max(), "m")
        values["reference.z_deviation_time"] = (float(dip.idxmax()), "s")
        values["claim.no_stationary_error"] = (float(values["tool_error.final"][0] < ARRIVAL_POSITION), "bool")
        values["claim.lag_from_orientation"] = (
            float(values["wrist_error.max"][0] < 0.1 * values["tool_error.max"][0]), "bool")
        values |= orientation_lag_model(run)
        m.add_run(run, values)
        tool_error[run.metadata["case"]] = (case_config(run)["system"]["dh"]["tool_d"], values["tool_error.max"][0])
        _fig3(run, figures)
    for model in ("decomposed", "full"):  # Sec. 4.2: a shorter d_e gives smaller amplitudes in Fig. 3b
        pairs = sorted(v for case, v in tool_error.items() if case.split("-de")[0] == model)
        if len(pairs) > 1:
            m.add("all", f"claim.shorter_tool_smaller_error.{model}",
                  float(all(a[1] < b[1] for a, b in itertools.pairwise(pairs))), "bool")
    return m.frame()


def analyze_fixed_obstacles(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case = {}
    for run in runs:
        values = _trajectory_metrics(run) | _obstacle_metrics(run)
        m.add_run(run, values)
        by_case[run.metadata["case"]] = values
    if {"a", "b"} <= set(by_case):
        a, b = by_case["a"], by_case["b"]
        m.add("all", "claim.a_swerves_up_b_stays_in_band",
              float(a["wrist.z_max"][0] > b["wrist.z_max"][0] + 0.02 and b["wrist.band_violation_upper"][0] < 1e-3),
              "bool")
        m.add("all", "claim.b_detours_more_in_xy",
              float(b["wrist.xy_deviation_max"][0] > a["wrist.xy_deviation_max"][0]), "bool")
    ordered = sorted(runs, key=lambda r: r.run_id)
    _paths_figure(ordered, figures, "fig4-paths", "Fig. 4: tool paths (a: lower height bound only, b: height band)")
    _components_figure(ordered, figures, "fig5-components", "Fig. 5: tool position vs time with four fixed obstacles")
    return m.frame()


def analyze_moving_obstacles(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _trajectory_metrics(run) | _obstacle_metrics(run))
    ordered = sorted(runs, key=lambda r: r.run_id)
    for run in ordered:
        _snapshots_figure(run, figures)
    _components_figure(ordered, figures, "fig7-components", "Fig. 7: tool position vs time with moving obstacles")
    return m.frame()


ANALYSES = {"compute-time": analyze_compute_time, "tracking": analyze_tracking,
            "fixed-obstacles": analyze_fixed_obstacles, "moving-obstacles": analyze_moving_obstacles}

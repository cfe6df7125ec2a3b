"""`curve-discretization`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.curve_discretization.figures import _fig2, _fig3, _snake_figure
from analysis.papers.curve_discretization.metrics import (
    LINEAR_SPREAD,
    STAGES,
    _chain_values,
    _gait_values,
    fit_scaling,
    per_call,
    xyz,
)
from pipeline.core.runlog import Run


def analyze_bezier(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _chain_values(run))
    by_case = {r.metadata["case"]: r for r in runs}
    paper = by_case.get("paper")
    rolls = [r for case, r in by_case.items() if case != "paper"]
    if paper is not None and rolls:
        fk, P = xyz(paper["/chain/fk"]), xyz(paper["/chain/curve"])
        theta = paper["/joint_state"].filter(like="position.").iloc[0].to_numpy()
        m.add("all", "roll_invariance.fk_position", max(np.abs(xyz(r["/chain/fk"]) - fk).max() for r in rolls), "m")
        m.add("all", "roll_invariance.curve_points", max(np.abs(xyz(r["/chain/curve"]) - P).max() for r in rolls),
              "m")
        m.add("all", "roll_invariance.angle_change",
              max(np.abs(r["/joint_state"].filter(like="position.").iloc[0].to_numpy() - theta).max() for r in rolls),
              "rad")
    if paper is not None:
        _fig2(paper, [paper, *rolls], figures)
    return m.frame()


def analyze_timing(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    rows = []
    for run in runs:
        info = run["/chain/search"].iloc[0]
        values = {"joints": (info["value.joints"], "count"), "evaluations": (info["value.evaluations"], "count"),
                  "segment_length": (info["value.segment_length"], "m")}
        for stage in STAGES:
            seconds = per_call(run, stage)
            values |= timing_metrics(stage, seconds)
            values[f"{stage}.p10"] = (float(np.percentile(seconds, 10)), "s")
        values["search_share"] = (values["search.median"][0] / values["total.median"][0], "fraction")
        m.add_run(run, values)
        rows.append({k: v for k, (v, _) in values.items()})
    table = pd.DataFrame(rows).sort_values("joints")
    fits = {}
    if len(table) >= 3:
        for stage in STAGES:
            fits[stage] = fit_scaling(table["joints"].to_numpy(float), table[f"{stage}.median"].to_numpy())
            m.add("all", f"{stage}.exponent", fits[stage]["exponent"], "")
            m.add("all", f"{stage}.per_joint", fits[stage]["per_joint"], "s")
            m.add("all", f"{stage}.linear_r2", fits[stage]["r2"], "")
            m.add("all", f"{stage}.linear_spread", fits[stage]["spread"], "fraction")
        # linearity is judged on the least-disturbed samples (10th percentile per N), robust to machine noise
        angles = fit_scaling(table["joints"].to_numpy(float), table["angles.p10"].to_numpy())
        m.add("all", "angles.p10.linear_spread", angles["spread"], "fraction")
        m.add("all", "angles.linear", float(angles["robust_slope"] > 0 and angles["spread"] <= LINEAR_SPREAD), "bool")
        m.add("all", "evaluations.exponent",
              np.polyfit(np.log(table["joints"]), np.log(table["evaluations"]), 1)[0], "")
        _fig3(table, fits, figures)
    return m.frame()


def analyze_snake(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    all_values = []
    for run in runs:
        values = _gait_values(run)
        m.add_run(run, values)
        all_values.append(values)
        _snake_figure(run, values, figures)
    if all_values:
        for key in ("realtime_ratio", "ratio.warm_cold_search"):
            m.add("all", key, max(v[key][0] for v in all_values), "ratio")
    return m.frame()


ANALYSES = {"bezier-fig2": analyze_bezier, "timing-fig3": analyze_timing, "snake-gait": analyze_snake}

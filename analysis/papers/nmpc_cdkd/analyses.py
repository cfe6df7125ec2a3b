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
    CASE_LABELS,
    _combo,
    _obstacle_metrics,
    _solve_metrics,
    _trajectory_metrics,
)
from pipeline.core.runlog import Run


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    mean, std = {}, {}
    for run in runs:
        values = _solve_metrics(run["/nmpc/solve"])
        m.add_run(run, values)
        mean[_combo(run.run_id)], std[_combo(run.run_id)] = values["solve.mean"][0], values["solve.std"][0]
    cases = sorted({c for _, c, _ in mean}, key=list(CASE_LABELS).index)
    horizons = sorted({k for *_, k in mean})
    table = {}
    for case in cases:
        for k in horizons:
            if ("decomposed", case, k) in mean and ("full", case, k) in mean:
                table[f"ratio.{case}.k{k}"] = (mean["decomposed", case, k] / mean["full", case, k], "ratio")
                table[f"sigma_ratio.{case}.k{k}"] = (std["decomposed", case, k] / std["full", case, k], "ratio")
        for model in ("decomposed", "full"):
            if len(horizons) == 2 and all((model, case, k) in mean for k in horizons):
                table[f"growth.{model}.{case}"] = (mean[model, case, horizons[1]] / mean[model, case, horizons[0]] - 1,
                                                   "fraction")
    for model in ("decomposed", "full"):
        for k in horizons:
            if (model, "no-obstacle", k) in mean and (model, "obstacle-height", k) in mean:
                table[f"complexity.{model}.k{k}"] = (mean[model, "obstacle-height", k] / mean[model, "no-obstacle", k],
                                                     "ratio")
    ratios = [v for key, (v, _) in table.items() if key.startswith("ratio.")]
    sigma = [v for key, (v, _) in table.items() if key.startswith("sigma_ratio.")]
    if ratios:
        table["claim.ratio_max"] = (max(ratios), "ratio")
        table["claim.ratio_min"] = (min(ratios), "ratio")
        table["claim.sigma_lower_everywhere"] = (float(all(v < 1 for v in sigma)), "bool")
    for model in ("decomposed", "full"):
        growth = [v for key, (v, _) in table.items() if key.startswith(f"growth.{model}.")]
        if growth:
            table[f"claim.growth_max.{model}"] = (max(growth), "fraction")
    complexity = [(table.get(f"complexity.full.k{k}"), table.get(f"complexity.decomposed.k{k}")) for k in horizons]
    if all(f and d for f, d in complexity):
        table["claim.full_grows_with_complexity_more"] = (float(all(f[0] > d[0] for f, d in complexity)), "bool")
    for metric, (value, unit) in table.items():
        m.add("table3", metric, value, unit)
    _table3_figure(mean, std, figures)
    return m.frame()


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
        m.add_run(run, values)
        tool_error[run.metadata["case"]] = (run.config["system"]["dh"]["tool_d"], values["tool_error.max"][0])
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

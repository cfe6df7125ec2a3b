"""`spherical-terrain`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.errors import error_stats
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.spherical_terrain.figures import (
    _controls,
    _errors,
    _gain_search_figure,
    _paths_3d,
    _physics_figure,
    _sweep_figure,
    _tilt,
    _xyz_vs_time,
)
from analysis.papers.spherical_terrain.metrics import (
    MOVING,
    WINDOWS,
    _agility,
    _case,
    _per_run,
    _reference_metrics,
    convergence_summary,
    convergence_time,
    gain_search,
)
from pipeline.core.runlog import Run


def analyze_paths(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m, by_case, table = _per_run(runs)
    for name, (value, unit) in (_reference_metrics(by_case) | _agility(table) | convergence_summary(table)).items():
        m.add("all", name, value, unit)
    _paths_3d(by_case, "circle", "Fig. 6 regenerated: circular path on the terrain", figures, "fig06-circle-3d")
    _paths_3d(by_case, "diamond", "Fig. 7 regenerated: diamond path on the terrain", figures, "fig07-diamond-3d")
    _xyz_vs_time(by_case, "circle", "Fig. 8 regenerated: smooth path, X/Y/Z vs time", figures, "fig08-circle-xyz")
    _xyz_vs_time(by_case, "diamond", "Fig. 9 regenerated: non-smooth path, X/Y/Z vs time", figures,
                 "fig09-diamond-xyz")
    _controls(by_case, "2r", "Fig. 10 regenerated: 2R-SR control signals", figures, "fig10-2r-controls")
    _controls(by_case, "rt", "Fig. 11 regenerated: RT-SR control signals", figures, "fig11-rt-controls")
    _controls(by_case, "rs", "Fig. 12(a) regenerated: RS-SR control signals", figures, "fig12a-rs-controls")
    _tilt(by_case, figures, "fig12b-rs-tilt")
    _errors(by_case, "Tracking error, corrected equations", figures, "tracking-error")
    return m.frame()


def analyze_printed(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m, by_case, _ = _per_run(runs)
    _errors(by_case, "Tracking error with eqs. (25), (58), (60) as printed", figures, "printed-tracking-error")
    _paths_3d(by_case, "diamond", "Diamond path with eqs. (25), (58) as printed", figures, "printed-diamond-3d")
    return m.frame()


def analyze_sweep(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Per-run metrics of every sweep run on disk (swept params as columns) and a convergence-time chart."""
    m, _, _ = _per_run(runs)
    frame = m.frame()
    tc = frame[frame["metric"] == "tc_0.1"]
    if len(tc) and len(tc.columns) > 4:
        params = [c for c in tc.columns if c not in ("run_id", "metric", "value", "unit")]
        tc = tc.assign(case=tc["run_id"].str.split("__").str[0],
                       setting=tc[params].astype(str).agg(", ".join, axis=1))
        pivot = tc.pivot_table(index="case", columns="setting", values="value", aggfunc="first", dropna=False)
        _sweep_figure(pivot, params, figures)
    return frame


def analyze_gain_search(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """The disclosed RS-SR gain search: every run's metrics (each is the band of the `paths` RS-SR targets), and
    per gain pair whether it converges on both paths; the stated rule's pick and the best pair as `search`."""
    m, _, _ = _per_run(runs)
    frame = m.frame()
    table = gain_search(frame, {run.run_id: run for run in runs})
    if table.empty:
        return frame
    m.add("search", "pairs", len(table), "count")
    m.add("search", "pairs_converging_both", int(table["converges_both"].sum()), "count")
    for pick in ("chosen", "best"):
        for row in table[table[pick]].to_dict("records"):
            for column, value in row.items():
                if column.startswith(("k_", "circle", "diamond")):
                    unit = "s" if "tc_" in column else "m" if "error" in column else "1"
                    m.add("search", f"{pick}.{column}", value, unit)
    _gain_search_figure(table, figures)
    return m.frame()


def analyze_physics(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """The ball on the MuJoCo height field against the paper's no-slip model (eq. 31) and exact rigid
    rolling, both fed the ball's own measured ω; and closed-loop tracking against the kinematic model."""
    m = MetricTable()
    traces = []
    for run in runs:
        robot, _ = _case(run)
        phys = run["/physics"]
        t = phys.index.to_numpy()
        actual, paper = phys["value.actual_speed"].to_numpy(), phys["value.paper_speed"].to_numpy()
        moving = paper > MOVING
        ratio = actual[moving] / paper[moving]
        error_paper = phys["value.paper_model_error"].to_numpy()
        error_rigid = phys["value.rigid_model_error"].to_numpy()
        e, e_kin = run["/tracking_error"]["norm"].to_numpy(), run["/tracking_error/kinematic_model"]["norm"]
        window = t >= WINDOWS[0]
        if window.any():
            m.add_run(run, error_stats(t[window], e[window], "error_after_40s", "m")
                      | {f"kinematic.{k}": v for k, v in error_stats(t[window], e_kin.to_numpy()[window],
                                                                     "error_after_40s", "m").items()})
        m.add_run(run, {
            "paper_model_error.weighted": (error_paper.sum() / paper.sum(), "fraction"),
            "paper_model_error.median": (float(np.median(error_paper[moving] / paper[moving])), "fraction"),
            "rigid_model_error.weighted": (error_rigid.sum() / paper.sum(), "fraction"),
            "rigid_model_error.median": (float(np.median(error_rigid[moving] / paper[moving])), "fraction"),
            "speed_ratio.p05": (float(np.percentile(ratio, 5)), "ratio"),
            "speed_ratio.p95": (float(np.percentile(ratio, 95)), "ratio"),
            "slip.median": (float(np.median(phys["value.slip_speed"])), "m/s"),
            "slip.mean": (float(phys["value.slip_speed"].mean()), "m/s"),
            "gap.max_penetration": (max(0.0, -float(phys["value.gap"].min())), "m"),
            "drive.omega_error_median": (float(np.median(phys["value.omega_error"])), "rad/s"),
            "tc_0.1": (convergence_time(t, e, 0.1), "s"),
            "kinematic.tc_0.1": (convergence_time(t, e_kin.to_numpy(), 0.1), "s"),
        })
        traces.append((robot, t, moving, ratio, phys["value.slip_speed"], e, e_kin))
    _physics_figure(traces, figures)
    return m.frame()


ANALYSES = {"paths": analyze_paths, "printed": analyze_printed, "sweep": analyze_sweep,
            "gain-search": analyze_gain_search, "physics-check": analyze_physics}

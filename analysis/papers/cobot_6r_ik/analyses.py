"""The analyze stage of `cobot-6r-ik`, one analysis per experiment: runs -> tidy metrics, figures on the side."""

from __future__ import annotations

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.cobot_6r_ik import figures as fig
from analysis.papers.cobot_6r_ik.metrics import (
    TIMED,
    completeness_metrics,
    compute_time_metrics,
    peers,
    tables_metrics,
    trajectory_metrics,
)
from pipeline.core.runlog import Run


def analyze_tables(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, tables_metrics(run))
        fig.roots_figure(run, figures)
        fig.configurations_figure(run, figures)
    return m.frame()


def analyze_completeness(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, completeness_metrics(run))
        fig.completeness_figure(run, figures)
    return m.frame()


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, compute_time_metrics(run))
        for name, info in peers(run).items():   # the peer's name, version and why it is missing, for the report
            m.add(run.run_id, f"{name}.available", float(info["available"]), "bool",
                  {"label": info["label"], "reason": info["reason"], "all_solutions": info["all_solutions"]})
        fig.per_pose_figure(run, list(TIMED), figures)
    return m.frame()


def analyze_trajectory(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, trajectory_metrics(run))
        fig.trajectory_figure(run, figures)
    return m.frame()


ANALYSES = {"tables": analyze_tables, "completeness": analyze_completeness, "compute-time": analyze_compute_time,
            "trajectory": analyze_trajectory}

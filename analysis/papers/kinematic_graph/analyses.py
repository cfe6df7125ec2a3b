"""The analysis of each experiment of `kinematic-graph`: its metrics (metrics.py) and its figures (figures.py)."""

from __future__ import annotations

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.kinematic_graph import figures as fig
from analysis.papers.kinematic_graph.metrics import analyze_benchmarks, paper_consistency, table1_metrics
from pipeline.core.runlog import Run


def analyze_table1(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, table1_metrics(run) | paper_consistency())
    frame = m.frame()
    if "table1" in set(frame["run_id"]):
        fig.table1_figure(frame[frame["run_id"] == "table1"], figures)
    return frame


def analyze_search(runs: list[Run], figures: Figures) -> pd.DataFrame:
    frame = analyze_benchmarks(runs, "m^2").frame()
    by_id = {r.run_id: r for r in runs}
    fig.planar_plans_figure(by_id, "free", figures, "fig2-free")
    fig.planar_plans_figure(by_id, "obstacle", figures, "fig4-obstacle")
    if "free-manipulability" in by_id:
        fig.heuristic_figure(by_id["free-manipulability"], figures)
    if "obstacle-manipulability" in by_id:
        fig.searched_kg_figure(by_id["obstacle-manipulability"], figures, "fig5-searched-kg")
    for run in runs:
        if run.metadata["case"].startswith("benchmark"):
            fig.benchmark_figure(run, figures, run.run_id, "Fig2" if run.run_id == "benchmark-free" else None)
    for scene in ("free", "obstacle"):
        fig.execution_figure([r for r in runs if r.metadata["case"].startswith(f"{scene}-")], figures,
                             f"execution-{scene}")
    return frame


def analyze_spatial(runs: list[Run], figures: Figures) -> pd.DataFrame:
    frame = analyze_benchmarks(runs, "m^3").frame()
    by_id = {r.run_id: r for r in runs}
    fig.spatial_figure(by_id, figures)
    if "benchmark" in by_id:
        fig.benchmark_figure(by_id["benchmark"], figures, "benchmark", "Fig6")
    fig.execution_figure([r for r in runs if not r.metadata["case"].startswith("benchmark")], figures, "execution")
    return frame

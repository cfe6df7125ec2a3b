"""The analyze stage of `dyad-triad-synthesis`, one analysis per experiment: its figures, then its metrics."""

from __future__ import annotations

import pandas as pd

from analysis.core.figures import Figures
from analysis.papers.dyad_triad_synthesis import figures, metrics
from pipeline.core.runlog import Run


def analyze_table5(runs: list[Run], figs: Figures) -> pd.DataFrame:
    figures.table5(runs, figs)
    return metrics.table5(runs).frame()


def analyze_burmester_curves(runs: list[Run], figs: Figures) -> pd.DataFrame:
    figures.burmester_curves(runs, figs)
    return metrics.burmester_curves(runs).frame()


def analyze_round_trips(runs: list[Run], figs: Figures) -> pd.DataFrame:
    figures.round_trips(runs, figs)
    return metrics.round_trips(runs).frame()


def analyze_four_bar(runs: list[Run], figs: Figures) -> pd.DataFrame:
    figures.four_bar(runs, figs)
    return metrics.four_bar(runs).frame()


def analyze_compute_time(runs: list[Run], figs: Figures) -> pd.DataFrame:
    figures.compute_time(runs, figs)
    return metrics.compute_time(runs).frame()


ANALYSES = {"table5": analyze_table5, "burmester-curves": analyze_burmester_curves,
            "round-trips": analyze_round_trips, "four-bar": analyze_four_bar, "compute-time": analyze_compute_time}

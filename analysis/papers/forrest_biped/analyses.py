"""One analysis per experiment: the runs of an experiment -> its tidy metrics table and its figures."""

from __future__ import annotations

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable, metric_value
from analysis.papers.forrest_biped import figures as fig
from analysis.papers.forrest_biped.metrics import (
    analyze_walking_metrics,
    generator_metrics,
    mechanism_metrics,
    pair_metrics,
    scenario_window,
    sweep_pairs,
    walk_errors,
)
from pipeline.core.runlog import Run


def analyze_mechanisms(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, mechanism_metrics(run))
        fig.knee_figure(run, figures)
        fig.ankle_figures(run, figures)
    return m.frame()


def analyze_pattern_generator(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, generator_metrics(run))
    fig.generator_figures({r.run_id: r for r in runs}, figures)
    return m.frame()


def analyze_walking(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Metrics of every run and pair; the figures of the default runs (or, without them, of the first group)."""
    m, errors = analyze_walking_metrics(runs)
    frame = m.frame()
    groups = sweep_pairs(runs)
    shown = "default" if "default" in groups else sorted(groups)[0]
    pair_id = "all" if shown == "default" else f"all__{shown}"
    shares = {axis: metric_value(frame, pair_id, f"share.{axis}.window") for axis in ("x", "y")}
    fig.walking_figures(groups[shown], errors[shown], shares, figures)
    return frame


def analyze_robustness(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Per sweep job: the Eq. (59) shares of its two walks; then the band [min, max] over the jobs (run `band`)."""
    m = MetricTable()
    rows = {}
    for job, pair in sorted(sweep_pairs(runs).items()):
        if set(pair) < {"extended", "traditional"}:
            continue
        errors = {g: walk_errors(r) for g, r in pair.items()}
        values = pair_metrics(errors, scenario_window(pair["extended"]), "")
        params = pair["extended"].params
        for key, (value, unit) in values.items():
            m.add(job, key, value, unit, params)
        rows[job] = {"share.x": values["share.x.window"][0], "share.y": values["share.y.window"][0],
                     "not_significant": values["claim.not_significant"][0]}
    if rows:
        table = pd.DataFrame.from_dict(rows, orient="index")
        for axis in ("x", "y"):
            m.add("band", f"share.{axis}.min", table[f"share.{axis}"].min(), "fraction")
            m.add("band", f"share.{axis}.max", table[f"share.{axis}"].max(), "fraction")
        m.add("band", "jobs", len(table), "count")
        m.add("band", "claim.not_significant.holds", table["not_significant"].sum(), "count")
        fig.robustness_figure(table, figures)
    return m.frame()


ANALYSES = {"mechanisms": analyze_mechanisms, "pattern-generator": analyze_pattern_generator,
            "walking": analyze_walking, "robustness": analyze_robustness}

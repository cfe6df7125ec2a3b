"""The analyze stage of each `srs-collision-avoidance` experiment: runs -> tidy metrics and figures."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.srs_collision_avoidance import figures as fig
from analysis.papers.srs_collision_avoidance.metrics import compute_time_metrics, ratio, read, run_metrics
from pipeline.core.runlog import Run


def analyze_circle(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case, values = {}, {}
    for run in runs:
        s = read(run)
        values[run.run_id] = run_metrics(s)
        m.add_run(run, values[run.run_id])
        if not run.params:                   # the default runs draw the paper's figures
            by_case[run.metadata["case"]] = s
    # the paper's claims, as ratios between the default runs
    for name, a, b, metric in (
            ("ratio.peak_joint_acceleration.filtered_vs_unfiltered", "avoid", "avoid-unfiltered",
             "joint.acceleration.max_abs"),
            ("ratio.peak_joint_rate.filtered_vs_unfiltered", "avoid", "avoid-unfiltered", "joint.rate.max_abs"),
            ("ratio.peak_joint_acceleration.avoid_vs_task", "avoid", "no-avoid", "joint.acceleration.max_abs"),
            ("ratio.peak_joint_rate.avoid_vs_task", "avoid", "no-avoid", "joint.rate.max_abs"),
            ("ratio.intrusion.avoid_vs_task", "avoid", "no-avoid", "volume.intrusion_fraction"),
            ("ratio.intrusion.unfiltered_vs_task", "avoid-unfiltered", "no-avoid", "volume.intrusion_fraction")):
        m.add("all", name, ratio(values, a, b, metric), "ratio")
    if "avoid" in by_case:
        s = by_case["avoid"]
        fig.fig07_swivel(by_case, figures)
        fig.fig08_09_swivel_rates(s, figures)
        fig.fig10_11_joints(by_case, figures)
        fig.fig12_13_joint_ranges(by_case, figures)
        fig.fig14_distances(s, figures)
        fig.fig05_06_scenes(s, figures)
    if by_case:
        fig.clearance_by_case(by_case, figures)
        fig.mujoco_audit(by_case, figures)
    return m.frame()


def analyze_ablation(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        params = {"system.filter.p": float(run.config["system"]["filter"]["p"]),
                  "system.algorithm.alpha_c": run.config["system"]["algorithm"]["alpha_c"]}
        for metric, (value, unit) in run_metrics(read(run)).items():
            m.add(run.run_id, metric, value, unit, params)
    frame = m.frame()
    if len(runs) > 1:
        fig.ablation_tradeoff(frame, figures)
    return frame


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, compute_time_metrics(run))
        ct = run["/compute_time"]
        fig.compute_time_histogram(np.asarray(ct["seconds.algorithm1"].dropna()), figures)
    return m.frame()


ANALYSES = {"circle": analyze_circle, "ablation": analyze_ablation, "compute-time": analyze_compute_time}

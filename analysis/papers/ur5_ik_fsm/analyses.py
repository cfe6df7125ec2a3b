"""`ur5-ik-fsm`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.ur5_ik_fsm.figures import _episodes_figure, _path_figure, _per_call_figure, _table6_figure
from analysis.papers.ur5_ik_fsm.metrics import AGREE_TOL, ALGORITHMS, JOINT_COLUMNS, _nonsingular, _path_metrics, wrap
from pipeline.core.runlog import Run


def analyze_tables(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        sel = {alg: run[f"/ik/{alg}"] for alg in ALGORITHMS}
        q = {alg: sel[alg][JOINT_COLUMNS].to_numpy() for alg in ALGORITHMS}
        for alg in ALGORITHMS:
            df = sel[alg]
            for k in range(len(df)):
                test = f"{alg}.test{k + 1}"
                values = {f"{test}.theta{i + 1}": (q[alg][k, i], "rad") for i in range(6)}
                values |= {f"{test}.det_j": (df["det_j"].iloc[k], "m^3"),
                           f"{test}.abs_det_j": (abs(df["det_j"].iloc[k]), "m^3"),
                           f"{test}.diff": (df["diff"].iloc[k], "rad"),
                           f"{test}.valid_sets": (df["valid_sets"].iloc[k], "count"),
                           f"{test}.fk_error": (df["fk_error_position"].iloc[k], "m")}
                m.add_run(run, values)
        same = np.abs(wrap(q["alg1"] - q["alg2"])).max(axis=1) < AGREE_TOL
        m.add_run(run, {f"agreement.test{k + 1}": (float(s), "bool") for k, s in enumerate(same)})
        m.add_run(run, {"agreement.count": (same.sum(), "count")})
        generating = run["/ik/generating"][JOINT_COLUMNS].to_numpy()
        m.add_run(run, {"generating.nonsingular_count": (_nonsingular(generating, run.config).sum(), "count")})
        dets = np.abs(np.concatenate([sel[a]["det_j"].to_numpy() for a in ALGORITHMS]))
        m.add_run(run, {"selected.min_abs_det_j": (np.nanmin(dets), "m^3"),
                        "selected.max_fk_error": (max(sel[a]["fk_error_position"].max() for a in ALGORITHMS), "m")})
    frame = m.frame()
    _table6_figure(frame, figures)
    return frame


def analyze_singular_paths(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_path: dict[str, dict[str, tuple[dict, np.ndarray, np.ndarray, Run]]] = {}
    for run in runs:
        values, q, t = _path_metrics(run)
        m.add_run(run, values)
        path, alg = run.metadata["case"].rsplit("-", 1)
        key = run.run_id.replace(run.metadata["case"], path)
        by_path.setdefault(key, {})[alg] = (values, q, t, run)
    no_larger_jump, nonsingular = [], []
    for key, algs in sorted(by_path.items()):
        nonsingular += [v[0]["all_selected_nonsingular"][0] for v in algs.values()]
        if set(algs) != set(ALGORITHMS):
            continue
        (v1, q1, _, run1), (v2, q2, _, _) = algs["alg1"], algs["alg2"]
        agree = (np.abs(wrap(q1 - q2)).max(axis=1) < AGREE_TOL)
        m.add(key, "agreement", agree.mean(), "fraction", run1.params)
        no_larger_jump.append(v2["max_joint_jump"][0] <= v1["max_joint_jump"][0] + 1e-9)
        _path_figure(key, algs, figures)
    if no_larger_jump:
        m.add("all", "claim.alg2_no_larger_jump", float(all(no_larger_jump)), "bool")
    if nonsingular:
        m.add("all", "claim.all_selected_nonsingular", float(all(nonsingular)), "bool")
    return m.frame()


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        ct = run["/compute_time"]
        counts = run["/ik/counts"]
        values, stats = {}, {}
        for alg in ALGORITHMS:
            for name in (alg, f"{alg}_batch"):
                per_item = ct[f"seconds.{name}"].dropna().to_numpy() / ct[f"calls.{name}"].dropna().to_numpy()
                stats[name] = per_item
                values |= timing_metrics(name, per_item)
            values[f"{alg}.sets_evaluated_mean"] = (counts[f"value.{alg}_sets_evaluated"].mean(), "count")
        values["valid_sets.max"] = (counts["value.valid_sets"].max(), "count")
        values["valid_sets.fraction_8"] = ((counts["value.valid_sets"] == 8).mean(), "fraction")
        values["ratio.sets_evaluated"] = (values["alg2.sets_evaluated_mean"][0] / values["alg1.sets_evaluated_mean"][0],
                                          "ratio")
        values["ratio.median_time"] = (values["alg2.median"][0] / values["alg1.median"][0], "ratio")
        m.add_run(run, values)
        _per_call_figure(run.run_id, stats, figures)
    return m.frame()


def analyze_random_paths(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Randomized episodes (our dataset generator): the singular-paths metrics of each, with what was drawn."""
    m = MetricTable()
    for run in runs:
        values, _, _ = _path_metrics(run)
        path, crossing, alg = run.metadata["case"].split("-")
        for metric, (value, unit) in values.items():
            m.add(run.run_id, metric, value, unit, {**run.params, "path": path, "crossing": crossing,
                                                     "algorithm": alg})
    frame = m.frame()
    if not frame.empty:
        _episodes_figure(frame, figures)
    return frame


ANALYSES = {"tables": analyze_tables, "singular-paths": analyze_singular_paths,
            "random-paths": analyze_random_paths, "compute-time": analyze_compute_time}

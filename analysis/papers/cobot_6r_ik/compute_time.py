"""Compute time of ik_all, scalar and batched, beside the peers timed in the same run, and how their
solution sets compare with ours."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run

TIMED = ("lambda16", "lambda16_batch", "octic", "octic_batch", "crx", "ik_geo", "eaik", "rtb")


def per_item(run: Run, name: str) -> np.ndarray:
    ct = run["/compute_time"]
    if f"seconds.{name}" not in ct:
        return np.zeros(0)
    return (ct[f"seconds.{name}"] / ct[f"calls.{name}"]).dropna().to_numpy()


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        values: dict[str, tuple[float, str]] = {}
        stats = {}
        for name in TIMED:
            t = per_item(run, name)
            if len(t):
                stats[name] = t
                values |= timing_metrics(name, t)
        peers = json.loads(run.metadata.get("peers", "{}"))
        for name in peers:
            topic = f"/peers/{name}"
            if topic not in run.topic_names:
                continue
            p = run[topic]
            values |= {f"{name}.poses": (len(p), "count"), f"{name}.solutions": (p["value.solutions"].sum(), "count")}
            for method in ("lambda16", "octic"):
                agree = (p[f"value.{method}.ours_only"] == 0) & (p[f"value.{method}.peer_only"] == 0)
                values |= {f"{name}.{method}.{k}": (p[f"value.{method}.{k}"].sum(), "count")
                           for k in ("common", "ours_only", "peer_only")}
                values[f"{name}.{method}.agree_fraction"] = (agree.mean(), "fraction")
        for name in ("crx", "ik_geo", "rtb"):
            for ours in ("lambda16", "lambda16_batch", "octic", "octic_batch"):
                if f"{name}.median" in values and f"{ours}.median" in values:
                    values[f"ratio.{ours}_to_{name}"] = (values[f"{ours}.median"][0] / values[f"{name}.median"][0],
                                                         "ratio")
        same = run["/ik/octic_vs_lambda16"]
        values["octic.extra_over_lambda16"] = (same["value.octic_only"].sum(), "count")
        values["octic.missing_from_lambda16"] = (same["value.lambda16_only"].sum(), "count")
        m.add_run(run, values)
        for name, info in peers.items():   # the peer's name, version and why it is missing, for the report
            m.add(run.run_id, f"{name}.available", float(info["available"]), "bool",
                  {"label": info["label"], "reason": info["reason"], "all_solutions": info["all_solutions"]})
        fig, ax = plt.subplots(figsize=(7, 3.4))
        names = list(stats)
        med = [np.median(stats[n]) * 1e6 for n in names]
        p95 = [np.percentile(stats[n], 95) * 1e6 for n in names]
        ax.bar(names, med, color=["C0" if n.startswith(("lambda16", "octic")) else "C7" for n in names])
        ax.errorbar(names, med, yerr=[np.zeros(len(med)), np.subtract(p95, med)], fmt="none", ecolor="k", capsize=4)
        ax.set_yscale("log")
        ax.tick_params(axis="x", labelrotation=30)
        ax.set_ylabel("time per pose [µs] (median, bar to p95)")
        ax.set_title(f"{run.run_id}: all solutions of one pose")
        figures.save(fig, f"{run.run_id}-per-pose")
    return m.frame()

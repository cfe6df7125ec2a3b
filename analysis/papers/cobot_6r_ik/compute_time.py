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

TIMED = ("ours", "ours_batch", "crx", "ik_geo", "eaik", "rtb")


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
            agree = (p["value.ours_only"] == 0) & (p["value.peer_only"] == 0)
            values |= {f"{name}.poses": (len(p), "count"), f"{name}.solutions": (p["value.solutions"].sum(), "count"),
                       f"{name}.common": (p["value.common"].sum(), "count"),
                       f"{name}.ours_only": (p["value.ours_only"].sum(), "count"),
                       f"{name}.peer_only": (p["value.peer_only"].sum(), "count"),
                       f"{name}.agree_fraction": (agree.mean(), "fraction")}
        for name in ("crx", "ik_geo", "rtb"):
            if f"{name}.median" in values:
                values[f"ratio.ours_to_{name}"] = (values["ours.median"][0] / values[f"{name}.median"][0], "ratio")
                values[f"ratio.ours_batch_to_{name}"] = (values["ours_batch.median"][0] / values[f"{name}.median"][0],
                                                         "ratio")
        m.add_run(run, values)
        for name, info in peers.items():   # the peer's name, version and why it is missing, for the report
            m.add(run.run_id, f"{name}.available", float(info["available"]), "bool",
                  {"label": info["label"], "reason": info["reason"], "all_solutions": info["all_solutions"]})
        fig, ax = plt.subplots(figsize=(7, 3.4))
        names = list(stats)
        med = [np.median(stats[n]) * 1e6 for n in names]
        p95 = [np.percentile(stats[n], 95) * 1e6 for n in names]
        ax.bar(names, med, color=["C0" if n.startswith("ours") else "C7" for n in names])
        ax.errorbar(names, med, yerr=[np.zeros(len(med)), np.subtract(p95, med)], fmt="none", ecolor="k", capsize=4)
        ax.set_yscale("log")
        ax.set_ylabel("time per pose [µs] (median, bar to p95)")
        ax.set_title(f"{run.run_id}: all solutions of one pose")
        figures.save(fig, f"{run.run_id}-per-pose")
    return m.frame()

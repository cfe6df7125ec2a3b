"""Compute-time tables, one format for every paper: median and p95 per algorithm, the machine they were
measured on, and the paper's own figure beside ours."""

from __future__ import annotations

import json

import pandas as pd

from analysis.core.sections import Section, Table
from analysis.core.units import convert


def timing_metrics(name: str, seconds_per_item, unit: str = "s") -> dict[str, tuple[float, str]]:
    """`<name>.median` and `<name>.p95` of per-call (or per-item) times in seconds."""
    s = pd.Series(seconds_per_item, dtype=float).dropna()
    return {f"{name}.median": (float(s.median()), unit), f"{name}.p95": (float(s.quantile(0.95)), unit)}


def machine_of(runs: pd.DataFrame, experiment: str) -> str:
    """The machine recorded in the runs of an experiment (report's `runs` table)."""
    rows = runs.loc[runs["experiment"] == experiment, "machine"] if "machine" in runs else []
    if not len(rows):
        return "unknown machine"
    m = json.loads(rows.iloc[0])
    return f"{m.get('cpu', '?')}, {m.get('logical_cores', '?')} logical cores, {m.get('system', '?')}"


def compute_time_section(title: str, metrics: pd.DataFrame, run_id: str, rows: list[tuple[str, str, str]],
                         machine: str, unit: str = "us", note: str = "") -> Section:
    """A report section with one row per (label, metric name, paper's figure as text), placed with the
    compute-time targets."""
    def value(metric: str) -> float:
        hit = metrics[(metrics["run_id"] == run_id) & (metrics["metric"] == metric)]
        return convert(float(hit["value"].iloc[0]), hit["unit"].iloc[0], unit) if not hit.empty else float("nan")

    table = pd.DataFrame([{"algorithm": label, f"median [{unit}]": value(f"{name}.median"),
                           f"p95 [{unit}]": value(f"{name}.p95"), "paper": paper} for label, name, paper in rows])
    return Section(title, Table(table, ".3g"),
                   f"Measured on {machine}, single thread, after warm-up (median and p95 over every timed call)."
                   + (f" {note}" if note else ""), category="compute times")

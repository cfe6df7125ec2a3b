"""A paper's reported numbers as data, and how a pipeline value is judged against each.

Each paper has `analysis/papers/<module>/targets.csv` with one row per reported number:

    target_id, category, quantity, where, value, unit, mode, op, tolerance, experiment, run, metric, note

- `category`: trajectories | tracking errors | force errors | compute times (the report's summary columns)
- `mode`: exact | relative | bound | qualitative | not reproducible
- `op`: how `value` is compared: `==` (within tolerance), or `<`, `<=`, `>`, `>=` (a bound or ranking)
- `tolerance`: `<x>` absolute, `<x> rel` relative, `<x> wrap` absolute on angles modulo 2π (±π equal);
  for an inequality, the margin within which a miss counts as close
- `experiment`, `run`, `metric`: where the pipeline's value is found in data/metrics/<slug>/<experiment>.parquet;
  `metric` is in SI; `unit` is the paper's, and the pipeline value is converted to it for the comparison
- `qualitative` targets compare a metric that is 1 when the stated rule holds, 0 when not

Status: match (within tolerance / inequality holds), close (within CLOSE_FACTOR × tolerance, or within the
margin of the bound), miss, not-reproducible. A target whose metric is absent (run failed or missing) is a
miss, and says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from analysis.core.units import convert

CATEGORIES = ("trajectories", "tracking errors", "force errors", "compute times")
MODES = ("exact", "relative", "bound", "qualitative", "not reproducible")
OPS = ("==", "<", "<=", ">", ">=")
STATUSES = ("match", "close", "miss", "not-reproducible")
CLOSE_FACTOR = 10.0
COLUMNS = ["target_id", "category", "quantity", "where", "value", "unit", "mode", "op", "tolerance",
           "experiment", "run", "metric", "note"]


@dataclass(frozen=True)
class Tolerance:
    value: float = 0.0
    relative: bool = False
    wrap: bool = False

    @classmethod
    def parse(cls, text: str) -> Tolerance:
        parts = str(text).split() if isinstance(text, str) and text.strip() else []
        if not parts:
            return cls()
        return cls(float(parts[0]), relative="rel" in parts[1:], wrap="wrap" in parts[1:])

    def __str__(self) -> str:
        if not self.value:
            return ""
        return f"{self.value:g}" + (" rel" if self.relative else "") + (" (mod 2π)" if self.wrap else "")


def load_targets(path: Path) -> pd.DataFrame:
    targets = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#")
    missing = [c for c in COLUMNS if c not in targets.columns]
    if missing:
        raise ValueError(f"{path}: missing columns {missing}")
    for col, allowed in (("category", CATEGORIES), ("mode", MODES)):
        bad = sorted(set(targets[col]) - set(allowed))
        if bad:
            raise ValueError(f"{path}: {col} {bad} not in {allowed}")
    bad_ops = sorted(set(targets.loc[targets["mode"] != "not reproducible", "op"]) - set(OPS))
    if bad_ops:
        raise ValueError(f"{path}: op {bad_ops} not in {OPS}")
    dupes = targets["target_id"][targets["target_id"].duplicated()].tolist()
    if dupes:
        raise ValueError(f"{path}: duplicate target ids {dupes}")
    return targets


def _difference(pipeline: float, paper: float, tol: Tolerance) -> float:
    d = pipeline - paper
    if tol.wrap:
        d = math.remainder(d, 2 * math.pi)
    return abs(d)


def judge(pipeline: float, paper: float, op: str, tol: Tolerance) -> str:
    """match / close / miss of one value."""
    if math.isnan(pipeline):
        return "miss"
    if op == "==":
        allowed = tol.value * (abs(paper) if tol.relative else 1.0)
        d = _difference(pipeline, paper, tol)
        if d <= allowed:
            return "match"
        return "close" if d <= CLOSE_FACTOR * allowed else "miss"
    holds = {"<": pipeline < paper, "<=": pipeline <= paper, ">": pipeline > paper, ">=": pipeline >= paper}[op]
    if holds:
        return "match"
    margin = tol.value * (abs(paper) if tol.relative else 1.0)
    return "close" if abs(pipeline - paper) <= margin else "miss"


def evaluate(slug: str, targets: pd.DataFrame, metrics: dict[str, pd.DataFrame],
             runs: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per target with the pipeline's value (in the paper's unit) and a status.

    `metrics` maps experiment name -> its tidy metrics table (run_id, metric, value, unit, ...); `runs` (the
    report's run list: experiment, run_id, status) lets a target whose run failed say why."""
    failed = {} if runs is None or runs.empty else {
        (r.experiment, r.run_id): r.status for r in runs.itertuples() if r.status != "ok"}
    rows = []
    for t in targets.itertuples(index=False):
        tol = Tolerance.parse(t.tolerance)
        row = {"slug": slug, "target_id": t.target_id, "category": t.category, "quantity": t.quantity,
               "where": t.where, "paper_value": t.value, "pipeline_value": float("nan"), "unit": t.unit,
               "mode": t.mode, "op": t.op, "tolerance": str(tol), "status": "not-reproducible", "note": t.note}
        if t.mode != "not reproducible":
            table = metrics.get(t.experiment)
            found = pd.DataFrame()
            if table is not None:
                found = table[(table["metric"] == t.metric) & (table["run_id"] == t.run)]
            if found.empty:
                row["status"] = "miss"
                why = failed.get((t.experiment, t.run))
                why = f"run {t.experiment}/{t.run} {why}" if why else \
                    f"no pipeline value ({t.experiment}/{t.run}: {t.metric})"
                row["note"] = "; ".join(x for x in (t.note, why) if x)
            else:
                value = convert(float(found["value"].iloc[0]), found["unit"].iloc[0], t.unit)
                row["pipeline_value"] = value
                row["status"] = judge(value, float(t.value), t.op, tol)
        rows.append(row)
    return pd.DataFrame(rows)

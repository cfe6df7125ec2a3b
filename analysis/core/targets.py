"""A paper's reported numbers as data, and how a pipeline value is judged against each.

Each paper has `analysis/papers/<module>/targets.csv` with one row per reported number:

    target_id, category, quantity, where, value, unit, mode, op, tolerance, basis, cause,
    experiment, run, metric, note

- `category`: trajectories | tracking errors | force errors | compute times (the report's summary columns)
- `mode`: exact | relative | bound | qualitative | consistency | not reproducible. `consistency` checks the
  paper against itself (its printed numbers against each other): never a reproduction.
- `op`: how `value` is compared: `==` (within tolerance), or `<`, `<=`, `>`, `>=` (a bound or ranking)
- `tolerance`: `<x>` absolute, `<x> rel` relative, `<x> wrap` absolute on angles modulo 2π (±π equal);
  for an inequality, the margin within which a miss counts as close
- `basis`: what the pipeline value is computed from: `simulation` (a simulated system), `algorithm` (the
  paper's algorithm run on its inputs: IK, synthesis, planning, …) or `paper` (arithmetic on the paper's
  own printed numbers). A `paper` basis goes with mode `consistency`, and only with it.
- `cause`: why a target misses or is only close, when known: paper-inconsistent | parameter-missing |
  hardware-only | model-limitation | open. The note names the numbers, parameter or missing model part.
  A miss or close without a stated cause is reported as `open` (not yet understood).
- `experiment`, `run`, `metric`: where the pipeline's value is found in data/metrics/<slug>/<experiment>.parquet;
  `metric` is in SI; `unit` is the paper's, and the pipeline value is converted to it for the comparison
- `qualitative` targets compare a metric that is 1 when the stated rule holds, 0 when not

Statuses of a reproduction (modes exact, relative, bound, qualitative):
  match       within the tolerance, or the inequality holds
  close       outside the tolerance but within CLOSE_FACTOR × it (an inequality: within its margin)
  consistent  the paper's value lies inside the band the pipeline value spans over a disclosed sweep of a
              parameter the paper omits (never merged with match)
  miss        farther off, or no pipeline value although the experiment ran (a failed run says why)
  not run     the target's experiment has no runs in this data_dir
Statuses of a `consistency` row: agrees / disagrees (the same rule as match / miss), or not run.
A `not reproducible` row (hardware only) has status not-reproducible; if it names the experiment, run and metric of
its closest simulated stand-in, that value is shown as its pipeline value, beside the paper's, and not judged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from analysis.core.units import convert

CATEGORIES = ("trajectories", "tracking errors", "force errors", "compute times")
MODES = ("exact", "relative", "bound", "qualitative", "consistency", "not reproducible")
OPS = ("==", "<", "<=", ">", ">=")
BASES = ("simulation", "algorithm", "paper")
CAUSES = ("paper-inconsistent", "parameter-missing", "hardware-only", "model-limitation", "open")
STATUSES = ("match", "close", "consistent", "miss", "not run", "not-reproducible")
CONSISTENCY_STATUSES = ("agrees", "disagrees", "not run")
CLOSE_FACTOR = 2.0  # `close`: outside the tolerance, within twice it
COLUMNS = ["target_id", "category", "quantity", "where", "value", "unit", "mode", "op", "tolerance", "basis",
           "cause", "experiment", "run", "metric", "note"]


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
    live = targets["mode"] != "not reproducible"
    for col, allowed, rows in (("category", CATEGORIES, targets), ("mode", MODES, targets),
                               ("op", OPS, targets[live]), ("basis", BASES, targets[live]),
                               ("cause", ("", *CAUSES), targets)):
        bad = sorted(set(rows[col]) - set(allowed))
        if bad:
            raise ValueError(f"{path}: {col} {bad} not in {allowed}")
    mixed = targets[live & ((targets["basis"] == "paper") != (targets["mode"] == "consistency"))]
    if not mixed.empty:
        raise ValueError(f"{path}: {mixed['target_id'].tolist()}: basis `paper` goes with mode `consistency`, "
                         "and only with it (arithmetic on printed numbers is not a reproduction)")
    dupes = targets["target_id"][targets["target_id"].duplicated()].tolist()
    if dupes:
        raise ValueError(f"{path}: duplicate target ids {dupes}")
    return targets


def deviation(pipeline: float, paper: float, tol: Tolerance) -> float:
    """pipeline − paper (modulo 2π for angles that wrap)."""
    d = pipeline - paper
    return math.remainder(d, 2 * math.pi) if tol.wrap else d


def judge(pipeline: float, paper: float, op: str, tol: Tolerance) -> str:
    """match / close / miss of one value."""
    if math.isnan(pipeline):
        return "miss"
    if op == "==":
        allowed = tol.value * (abs(paper) if tol.relative else 1.0)
        d = abs(deviation(pipeline, paper, tol))
        if d <= allowed:
            return "match"
        return "close" if d <= CLOSE_FACTOR * allowed else "miss"
    holds = {"<": pipeline < paper, "<=": pipeline <= paper, ">": pipeline > paper, ">=": pipeline >= paper}[op]
    if holds:
        return "match"
    margin = tol.value * (abs(paper) if tol.relative else 1.0)
    return "close" if abs(pipeline - paper) <= margin else "miss"


SELF_CHECK = {"match": "agrees", "close": "disagrees", "miss": "disagrees"}


def _stand_in(table: pd.DataFrame | None, t) -> float | None:
    """The value a `not reproducible` row names as its simulated stand-in, in the row's unit (None if absent)."""
    if table is None:
        return None
    found = table[(table["metric"] == t.metric) & (table["run_id"] == t.run)]
    return None if found.empty else convert(float(found["value"].iloc[0]), found["unit"].iloc[0], t.unit)


def evaluate(slug: str, targets: pd.DataFrame, metrics: dict[str, pd.DataFrame],
             runs: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per target with the pipeline's value (in the paper's unit), its deviation and a status.

    `metrics` maps experiment name -> its tidy metrics table (run_id, metric, value, unit, ...); `runs` (the
    report's run list: experiment, run_id, status) tells which experiments ran, and lets a target whose run
    failed say why."""
    runs = pd.DataFrame(columns=["experiment", "run_id", "status"]) if runs is None else runs
    ran = set(runs["experiment"]) | set(metrics)
    failed = {(r.experiment, r.run_id): r.status for r in runs.itertuples() if r.status != "ok"}
    rows = []
    for t in targets.itertuples(index=False):
        tol = Tolerance.parse(t.tolerance)
        row = {"slug": slug, "target_id": t.target_id, "category": t.category, "quantity": t.quantity,
               "where": t.where, "paper_value": t.value, "op": t.op, "pipeline_value": float("nan"),
               "deviation": float("nan"), "relative_deviation": float("nan"), "unit": t.unit, "mode": t.mode,
               "basis": t.basis, "tolerance": str(tol), "status": "not-reproducible", "cause": "", "note": t.note,
               "experiment": t.experiment, "run": t.run}
        if t.mode == "not reproducible":
            row["cause"] = t.cause or "hardware-only"
            stand_in = _stand_in(metrics.get(t.experiment), t) if t.metric else None
            if stand_in is not None:  # shown beside the paper's value, never judged
                row["pipeline_value"] = stand_in
        elif t.experiment not in ran:
            row["status"] = "not run"
        else:
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
                paper = float(t.value)
                row["pipeline_value"] = value
                row["deviation"] = deviation(value, paper, tol)
                row["relative_deviation"] = row["deviation"] / abs(paper) if paper else float("nan")
                row["status"] = judge(value, paper, t.op, tol)
            if t.mode == "consistency":
                row["status"] = SELF_CHECK[row["status"]]
            elif row["status"] in ("miss", "close"):
                row["cause"] = t.cause or "open"
        rows.append(row)
    return pd.DataFrame(rows)

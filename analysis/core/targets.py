"""A paper's reported numbers as data, and how a pipeline value is judged against each.

Each paper has `analysis/papers/<module>/targets.csv` with one row per reported number:

    target_id, category, quantity, where, value, unit, mode, op, tolerance, basis, cause,
    experiment, run, metric, band, note

- `target_id`: unique in the paper (letters, digits, `.`, `-`, `_`); the report anchors each row by it
- `category`: trajectories | tracking errors | force errors | compute times (the report's summary columns)
- `quantity`, `where`: what the number is, and where the paper prints it (Table 2, KD; Fig. 9; Sec. 5)
- `value`, `unit`: the paper's number as printed, in the paper's unit (mm, deg, ms, %, ...)
- `mode`: exact | relative | bound | qualitative | consistency | not reproducible. `consistency` checks the
  paper against itself (its printed numbers against each other): never a reproduction.
- `op`: how `value` is compared: `==` (within tolerance), or `<`, `<=`, `>`, `>=` (a bound or ranking)
- `tolerance`: `<x>` absolute, `<x> rel` relative, `<x> wrap` absolute on angles modulo 2π (±π equal);
  for an inequality, the margin by which it may fail and still count as close; `ci` (with `==`): the analysis
  writes an interval beside the metric, `<metric>.ci_low` and `<metric>.ci_high` (e.g. a bootstrap 95 %
  confidence interval), and the target is a match when the paper's value lies inside it, a miss when the
  interval excludes it (no close); the pipeline value is the metric itself (e.g. the bootstrap median)
- `basis`: what the pipeline value is computed from: `simulation` (a simulated system), `algorithm` (the
  paper's algorithm run on its inputs: IK, synthesis, planning, …) or `paper` (arithmetic on the paper's
  own printed numbers). A `paper` basis goes with mode `consistency`, and only with it.
- `cause`: why a target misses or is only close (declare it for every target you know to miss or be close):
    paper-inconsistent  the paper's own numbers contradict each other (the note names them)
    parameter-missing   the value depends on a parameter the paper does not give (the note names it)
    hardware-only       only the authors' hardware can give it
    model-limitation    our model lacks something the value depends on (the note names what)
    open                not yet understood
  A miss or close without a declared cause is reported as `open`.
- `experiment`, `run`, `metric`: where the pipeline's value is found in data/metrics/<slug>/<experiment>.parquet
  (`run` is a run id, or the id of an aggregate the analysis writes, e.g. `surface`); `metric` is in SI;
  `unit` is the paper's, and the pipeline value is converted to it for the comparison
- `band`: empty, or the name of an experiment of the same paper whose runs are a disclosed sweep of a parameter
  the paper omits (a Hydra `-m` sweep in its DVC stages; see "Sensitivity bands" below)
- `note`: the rule, assumption or evidence behind the row; for a miss or close, the evidence for its cause
- `qualitative` targets compare a metric that is 1 when the stated rule holds, 0 when not

Statuses (STATUS_MEANING says each in one sentence; the report prints them):
  match        within the tolerance, or the inequality holds
  close        outside the tolerance but within CLOSE_FACTOR × it (an inequality: fails by at most its margin)
  consistent   the default run misses or is close, and the paper's value lies inside the band the pipeline value
               spans over a disclosed sweep of a parameter the paper omits (never merged with match)
  miss         farther off, or no pipeline value although its run was made (a failed run says why)
  not run      the target's run is not in this data_dir (its experiment, or that run of it, was not run)
  not-reproducible  hardware only: nothing to compute
Statuses of a `consistency` row: agrees / disagrees (the same rule as match / miss), or not run.

Sensitivity bands. Where a reported number depends on a parameter the paper omits, we sweep it:
- the sweep is an experiment of its own (`<name>: "-m key=a,b,c ..."` in stages/<slug>/experiments.yaml); its run
  ids are `<case>__k=v,…` (pipeline/core/runner.py: run_id);
- the target names that experiment in `band`. Its band is [min, max] of the target's `metric` (converted to the
  target's unit) over every row of the band experiment whose run id is the target's `run` or starts with
  `<run>__` (band_runs), the rows of failed runs left out: the ok runs, and the aggregates the analysis writes
  per sweep point (e.g. a fit over a map, `k80000__<sweep point>`); band_min, band_max are NaN when none is on
  disk;
- the default run (`experiment`, `run`) stays the pipeline value and is judged as above. If it is a miss or a
  close (a default that did not fail but has no value, e.g. a fit with nothing to fit, counts as a miss) and the
  band reaches the paper's value, the status is `consistent` (the declared cause is kept: usually
  `parameter-missing`). "Reaches": some value in the band would be a match: for `==` the band's point nearest
  the paper's value is within the tolerance of it; for `<`, `<=` the claim holds at the band's min, for `>`,
  `>=` at its max (some parameter in the range satisfies it);
- if the band cannot reach the paper's value, the status stays as judged and the declared cause must be
  `model-limitation` or `paper-inconsistent` with the reason in the note (BAND_CAUSES): the parameter the paper
  omits does not explain the gap. `self_check` lists every target that breaks this rule; the report stage prints
  them and fails;
- the paper's `paper.yaml` declares every band experiment under `bands:` as {experiment, parameter, range, why}:
  the range fixed from physics, datasheets or the paper's own hints before looking at the result (`why` says
  so, and the range is never adjusted afterwards). The report shows [min, max] beside the default value and
  lists the bands with their justification. A default is never tuned to hit a paper number.
"""

from __future__ import annotations

import functools
import math
import re
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
BAND_CAUSES = ("model-limitation", "paper-inconsistent")  # of a banded miss or close: the band cannot reach
CLOSE_FACTOR = 2.0  # `close`: outside the tolerance, within twice it
STATUS_MEANING = {
    "match": "the pipeline's value is within the tolerance of the paper's, or the paper's inequality holds.",
    "close": f"outside the tolerance but within {CLOSE_FACTOR:g}× it (an inequality: fails by at most its margin).",
    "consistent": "the paper's value lies inside the band our value spans over a disclosed sweep of a parameter "
                  "the paper omits.",
    "miss": f"farther off than {CLOSE_FACTOR:g}× the tolerance, or no value although the run was made "
            "(a failed run says why).",
    "not run": "the run this target needs is not in this data_dir; run its experiment to judge it.",
    "not-reproducible": "only the authors' hardware can give this number; nothing to compute.",
    "agrees": "a consistency check: the paper's printed numbers agree with each other (not a reproduction).",
    "disagrees": "a consistency check: the paper's printed numbers contradict each other (not a reproduction).",
}
CAUSE_MEANING = {
    "paper-inconsistent": "the paper's own numbers contradict each other",
    "parameter-missing": "the value depends on a parameter the paper does not give",
    "hardware-only": "only the authors' hardware can give it",
    "model-limitation": "our model lacks something the value depends on",
    "open": "not yet understood",
}
COLUMNS = ["target_id", "category", "quantity", "where", "value", "unit", "mode", "op", "tolerance", "basis",
           "cause", "experiment", "run", "metric", "band", "note"]


INTERVAL = "ci"                           # the tolerance of a target judged by the interval the analysis writes
INTERVAL_BOUNDS = (".ci_low", ".ci_high")  # suffixes of that interval's metrics


@dataclass(frozen=True)
class Tolerance:
    value: float = 0.0
    relative: bool = False
    wrap: bool = False
    interval: bool = False

    @classmethod
    def parse(cls, text: str) -> Tolerance:
        parts = str(text).split() if isinstance(text, str) and text.strip() else []
        if not parts:
            return cls()
        if parts == [INTERVAL]:
            return cls(interval=True)
        return cls(float(parts[0]), relative="rel" in parts[1:], wrap="wrap" in parts[1:])

    def __str__(self) -> str:
        if self.interval:
            return "95% CI"
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
    banded = targets[(targets["band"] != "") & ~targets["mode"].isin(["exact", "relative", "bound", "qualitative"])]
    if not banded.empty:
        raise ValueError(f"{path}: {banded['target_id'].tolist()}: a band belongs to a reproduction target "
                         "(not to a consistency or not-reproducible row)")
    odd_interval = targets[(targets["tolerance"] == INTERVAL) & (targets["op"] != "==")]
    if not odd_interval.empty:
        raise ValueError(f"{path}: {odd_interval['target_id'].tolist()}: the tolerance `{INTERVAL}` judges `==` "
                         "(the paper's value inside the interval)")
    dupes = targets["target_id"][targets["target_id"].duplicated()].tolist()
    if dupes:
        raise ValueError(f"{path}: duplicate target ids {dupes}")
    odd = [t for t in targets["target_id"] if not re.fullmatch(r"[A-Za-z0-9._-]+", t)]
    if odd:
        raise ValueError(f"{path}: target ids {odd} may hold only letters, digits, '.', '-', '_'")
    return targets


@functools.cache
def _paper_targets(slug: str) -> pd.DataFrame:
    path = Path(__file__).resolve().parents[1] / "papers" / slug.replace("-", "_") / "targets.csv"
    return load_targets(path).set_index("target_id")


def paper_value(slug: str, target_id: str, unit: str | None = None) -> float:
    """The value a paper prints for one of its targets (in `unit`, default the paper's): what a figure draws
    beside the pipeline's curve, labelled "paper", read from targets.csv so that it is never retyped."""
    row = _paper_targets(slug).loc[target_id]
    value = float(row["value"])
    return convert(value, row["unit"], unit) if unit is not None else value


def deviation(pipeline: float, paper: float, tol: Tolerance) -> float:
    """pipeline − paper (modulo 2π for angles that wrap)."""
    d = pipeline - paper
    return math.remainder(d, 2 * math.pi) if tol.wrap else d


def judge_interval(low: float, high: float, paper: float) -> str:
    """match when the paper's value lies in the pipeline's interval [low, high], else miss (no interval: miss)."""
    return "match" if low <= paper <= high else "miss"   # NaN bounds fail both comparisons


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


def band_runs(run_ids: pd.Series, run: str) -> pd.Series:
    """Which run ids belong to the band of a target whose default run is `run`: `run` itself and its sweep
    runs `<run>__k=v,…` (a run named `<run>-x` or `<run>x` is another case)."""
    return (run_ids == run) | run_ids.str.startswith(f"{run}__")


def band(table: pd.DataFrame | None, failed_runs: set[str], run: str, metric: str, unit: str) -> tuple[float, float]:
    """[min, max] of `metric` (in `unit`) over the rows of a band experiment that belong to `run`, but for the
    rows of its failed runs (ok runs and the analysis's aggregates count); NaN, NaN when none is on disk."""
    if table is None or table.empty:
        return math.nan, math.nan
    rows = table[band_runs(table["run_id"].astype(str), run) & (table["metric"] == metric)
                 & ~table["run_id"].astype(str).isin(failed_runs)]
    values = [convert(float(v), u, unit) for v, u in zip(rows["value"], rows["unit"], strict=True)]
    values = [v for v in values if not math.isnan(v)]
    return (min(values), max(values)) if values else (math.nan, math.nan)


def reaches(low: float, high: float, paper: float, op: str, tol: Tolerance = Tolerance()) -> bool:
    """Whether a band [low, high] reaches the paper's value, i.e. some value in it would be a match: for `==` the
    band's point nearest the paper's value is within the tolerance; for an inequality, the claim holds at the
    band's favourable end."""
    if math.isnan(low) or math.isnan(high):
        return False
    if op == "==":
        return judge(min(max(paper, low), high), paper, op, tol) == "match"
    return {"<": low < paper, "<=": low <= paper, ">": high > paper, ">=": high >= paper}[op]


def self_check(evaluated: pd.DataFrame) -> list[str]:
    """What the report must refuse: a target with a band (on disk) that misses or is close although its band
    cannot reach the paper's value, and whose cause is not one of BAND_CAUSES (a missing parameter that does
    not explain the gap is not the cause)."""
    if "band" not in evaluated:
        return []
    bad = evaluated[(evaluated["band"] != "") & evaluated["status"].isin(["miss", "close"])
                    & evaluated["band_min"].notna() & ~evaluated["cause"].isin(BAND_CAUSES)]
    return [f"{r.slug}:{r.target_id}: {r.status} with cause `{r.cause}`, and its band {r.band} "
            f"[{r.band_min:.4g}, {r.band_max:.4g}] {r.unit} does not reach the paper's {r.op} {r.paper_value}: "
            f"declare {' or '.join(BAND_CAUSES)} with the reason" for r in bad.itertuples()]


def _metric_of(of_run: pd.DataFrame, metric: str, unit: str) -> float:
    """One metric of one run's rows, in `unit`; NaN if absent."""
    hit = of_run[of_run["metric"] == metric]
    return convert(float(hit["value"].iloc[0]), hit["unit"].iloc[0], unit) if not hit.empty else float("nan")


def evaluate(slug: str, targets: pd.DataFrame, metrics: dict[str, pd.DataFrame],
             runs: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per target with the pipeline's value (in the paper's unit), its deviation and a status.

    `metrics` maps experiment name -> its tidy metrics table (run_id, metric, value, unit, ...); `runs` (the
    report's run list: experiment, run_id, status) tells which experiments ran, and lets a target whose run
    failed say why."""
    runs = pd.DataFrame(columns=["experiment", "run_id", "status"]) if runs is None else runs
    made = {(r.experiment, r.run_id) for r in runs.itertuples()}
    failed = {(r.experiment, r.run_id): r.status for r in runs.itertuples() if r.status != "ok"}
    failed_runs: dict[str, set[str]] = {}
    for experiment, run_id in failed:
        failed_runs.setdefault(experiment, set()).add(str(run_id))
    rows = []
    for t in targets.itertuples(index=False):
        tol = Tolerance.parse(t.tolerance)
        row = {"slug": slug, "target_id": t.target_id, "category": t.category, "quantity": t.quantity,
               "where": t.where, "paper_value": t.value, "op": t.op, "pipeline_value": float("nan"),
               "deviation": float("nan"), "relative_deviation": float("nan"), "unit": t.unit, "mode": t.mode,
               "basis": t.basis, "tolerance": str(tol), "status": "not-reproducible", "cause": "", "note": t.note,
               "experiment": t.experiment, "run": t.run, "band": getattr(t, "band", ""),
               "band_min": math.nan, "band_max": math.nan}
        if t.mode == "not reproducible":
            row["cause"] = t.cause   # as declared: the hardware, a missing parameter, ...
        else:
            table = metrics.get(t.experiment)
            of_run = pd.DataFrame() if table is None else table[table["run_id"] == t.run]
            found = of_run[of_run["metric"] == t.metric] if not of_run.empty else of_run
            failed_here = {r: s for (e, r), s in failed.items() if e == t.experiment}
            # neither a recorded run nor an aggregate of that id, and nothing failed: e.g. only a sweep of the
            # experiment is on disk
            if of_run.empty and (t.experiment, t.run) not in made and not failed_here:
                row["status"] = "not run"
            elif found.empty:
                row["status"] = "miss"
                why = failed.get((t.experiment, t.run))
                if why:
                    why = f"run {t.experiment}/{t.run} {why}"
                else:
                    why = f"no pipeline value ({t.experiment}/{t.run}: {t.metric})" + "".join(
                        f"; run {t.experiment}/{r} {s}" for r, s in failed_here.items())
                row["note"] = "; ".join(x for x in (t.note, why) if x)
            else:
                value = convert(float(found["value"].iloc[0]), found["unit"].iloc[0], t.unit)
                paper = float(t.value)
                row["pipeline_value"] = value
                row["deviation"] = deviation(value, paper, tol)
                row["relative_deviation"] = row["deviation"] / abs(paper) if paper else float("nan")
                row["status"] = judge(value, paper, t.op, tol)
                if tol.interval:
                    low, high = (_metric_of(of_run, t.metric + suffix, t.unit) for suffix in INTERVAL_BOUNDS)
                    row["status"] = judge_interval(low, high, paper)
                    row["note"] = "; ".join(x for x in (t.note, f"our 95 % interval [{low:.4g}, {high:.4g}]") if x)
            if row["band"]:
                low, high = band(metrics.get(row["band"]), failed_runs.get(row["band"], set()), t.run, t.metric,
                                 t.unit)
                row["band_min"], row["band_max"] = low, high
                if row["status"] in ("miss", "close") and (t.experiment, t.run) not in failed and reaches(
                        low, high, float(t.value), t.op, tol):
                    row["status"] = "consistent"
                    row["cause"] = t.cause
            if t.mode == "consistency":
                row["status"] = SELF_CHECK.get(row["status"], row["status"])
                if row["status"] == "disagrees":
                    row["cause"] = t.cause or "paper-inconsistent"
            elif row["status"] in ("miss", "close"):
                row["cause"] = t.cause or "open"
        rows.append(row)
    return pd.DataFrame(rows)

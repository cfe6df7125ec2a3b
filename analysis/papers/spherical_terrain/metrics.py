"""`spherical-terrain`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.errors import error_stats
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run
from pipeline.papers.spherical_terrain.kinematics import CosineTerrain
from pipeline.papers.spherical_terrain.paths import vertex_times
from pipeline.papers.spherical_terrain.tracking import CLASSES

SLUG = "spherical-terrain"
LABEL = {"3r": "3R-SR", "2r": "2R-SR", "rt": "RT-SR", "rs": "RS-SR"}


COLOR = {"3r": "C0", "2r": "C1", "rt": "C2", "rs": "C3"}


EPSILONS = (0.05, 0.1, 0.2)      # m, convergence thresholds


WINDOWS = (40.0, 30.0)           # s, start of the steady-state window


VERTEX_HALF_WIDTH = 5.0          # s, error near a vertex: within ±5 s of the target passing it


CLAIM_TIME = 45.0                # s, "converges in approximately 30 s": t_c(0.1 m) ≤ 1.5 × 30 s


def convergence_time(t: np.ndarray, e: np.ndarray, eps: float) -> float:
    """t_c(ε) = inf{t : e(τ) ≤ ε for all τ ≥ t}; NaN if the last sample is above ε."""
    above = np.flatnonzero(e > eps)
    if not len(above):
        return float(t[0])
    return float(t[above[-1] + 1]) if above[-1] + 1 < len(t) else float("nan")


def _case(run: Run) -> tuple[str, str]:
    robot, path = run.metadata["case"].split("-", 1)
    return robot, path


def _terrain(run: Run) -> CosineTerrain:
    t = run.config["system"]["terrain"]
    return CosineTerrain(t["amplitude"], t["frequency"])


def tracking_metrics(run: Run) -> dict[str, tuple[float, str]]:
    """Spec §7 for one tracking run."""
    robot, path = _case(run)
    err = run["/tracking_error"]
    t, e = err.index.to_numpy(), err["norm"].to_numpy()
    values: dict[str, tuple[float, str]] = {}
    for eps in EPSILONS:
        values[f"tc_{eps:g}"] = (convergence_time(t, e, eps), "s")
    entered = np.flatnonzero(e <= 0.1)
    values["first_entry_0.1"] = (float(t[entered[0]]) if len(entered) else float("nan"), "s")
    for start in WINDOWS:  # a run shorter than the window has no steady-state statistics
        window = t >= start
        if window.any():
            values |= error_stats(t[window], e[window], f"error_after_{start:g}s", "m")
    window = t >= WINDOWS[0]
    if window.any():
        zeta = np.abs(run["/pursuit"]["value.zeta"].to_numpy()[window])
        values["zeta.mean_abs"], values["zeta.max_abs"] = (float(zeta.mean()), "rad"), (float(zeta.max()), "rad")
    if path == "diamond":
        d = run.config["system"]["paths"]["diamond"]
        passes = vertex_times(t[-1], d["diagonal"], d["speed"])
        passes = passes[passes >= WINDOWS[0]]
        near = np.zeros_like(t, dtype=bool)
        for tv in passes:
            near |= np.abs(t - tv) <= VERTEX_HALF_WIDTH
        if near.any():
            values["vertex.max"] = (float(e[near].max()), "m")
            values["vertex.mean"] = (float(e[near].mean()), "m")
    command = run["/command"]
    for column in command.columns:
        if column.startswith("value."):
            u = command[column].to_numpy()
            name = column.removeprefix("value.")
            values[f"effort.{name}.rms"] = (float(np.sqrt(np.mean(u * u))), "rad/s")
            values[f"effort.{name}.max"] = (float(np.abs(u).max()), "rad/s")
    if robot == "rs":
        phi = run["/joint_state"]["position.phi"].to_numpy()
        values["tilt.max_abs"] = (float(np.abs(phi).max()), "rad")
        values["tilt.saturated_fraction"] = (float(run["/pursuit"]["value.tilt_saturated"].mean()), "fraction")
    values["claim.converges"] = (float(values["tc_0.1"][0] <= CLAIM_TIME), "bool")
    return values


def _reference_metrics(runs: dict[str, Run]) -> dict[str, tuple[float, str]]:
    """The reference paths as generated, measured from the logs (radius, rate, diagonals)."""
    values = {}
    circle = next((r for k, r in runs.items() if k.endswith("-circle")), None)
    if circle is not None:
        ref = circle["/reference"]
        x, y = ref["position.x"].to_numpy(), ref["position.y"].to_numpy()
        angle = np.unwrap(np.arctan2(y, x))
        values["circle.radius"] = (float(np.hypot(x, y).mean()), "m")
        values["circle.rate"] = (float(np.polyfit(ref.index.to_numpy(), angle, 1)[0]), "rad/s")
    diamond = next((r for k, r in runs.items() if k.endswith("-diamond")), None)
    if diamond is not None:
        ref = diamond["/reference"]
        values["diamond.diagonal_x"] = (float(np.ptp(ref["position.x"])), "m")
        values["diamond.diagonal_y"] = (float(np.ptp(ref["position.y"])), "m")
    return values


def _agility(table: pd.DataFrame) -> dict[str, tuple[float, str]]:
    """Sec. 6: '3R and 2R-SRs outperform RT and RS-SRs in tracking the nonsmooth trajectory', as ratios
    worst(3R, 2R) / best(RT, RS) on the diamond (< 1 when the claim holds)."""
    values = {}
    for metric, name in (("vertex.max", "claim.vertex_error_ratio"), ("error_after_40s.rms", "claim.rms_error_ratio")):
        got = {r: table.get((f"{r}-diamond", metric)) for r in CLASSES}
        if all(v is not None for v in got.values()):
            values[name] = (max(got["3r"], got["2r"]) / min(got["rt"], got["rs"]), "ratio")
    return values


def convergence_summary(table: dict) -> dict[str, tuple[float, str]]:
    """The median t_c(0.1 m) of the runs that converge (Sec. 6: 'in approximately 30 s')."""
    tc = [v for (case, metric), v in table.items() if metric == "tc_0.1" and np.isfinite(v)]
    return {"tc_0.1.median": (float(np.median(tc)), "s")} if tc else {}


def _per_run(runs: list[Run]) -> tuple[MetricTable, dict[str, Run], dict]:
    """Metrics of every run; the run of each case drawn in the figures and compared across classes (the one
    without overrides if there is one); and those runs' metrics as {(case, metric): value}."""
    m = MetricTable()
    by_case: dict[str, Run] = {}
    values_of = {}
    for run in runs:
        values_of[run.run_id] = tracking_metrics(run)
        m.add_run(run, values_of[run.run_id])
        case = run.metadata["case"]
        if case not in by_case or (by_case[case].params and not run.params):
            by_case[case] = run
    table = {(case, k): v for case, run in by_case.items() for k, (v, _) in values_of[run.run_id].items()}
    return m, by_case, table


MOVING = 0.02   # m/s: samples where the paper's model moves the contact point slower than this are left out


RUN_COLUMNS = {"tc_0.1": "t_c(0.1 m) [s]", "tc_0.05": "t_c(0.05 m) [s]", "first_entry_0.1": "first ≤ 0.1 m [s]",
               "error_after_40s.mean": "mean e (t≥40) [m]", "error_after_40s.rms": "RMS e (t≥40) [m]",
               "error_after_40s.max": "max e (t≥40) [m]", "vertex.max": "max e near vertices [m]",
               "tilt.max_abs": "max |φ| [rad]", "tilt.saturated_fraction": "tilt saturated [fraction]"}


GAINS = ("k_alpha", "k_phi")   # RS-SR's gains (eq. 58), searched by the gain-search experiment
SEARCH_METRICS = ("tc_0.1", "error_after_40s.rms", "error_after_40s.max")


def gain_search(frame: pd.DataFrame, runs: dict[str, Run]) -> pd.DataFrame:
    """One row per RS-SR gain pair on disk: its gains (from the runs' configs), SEARCH_METRICS on each path,
    whether it converges on both (t_c(0.1 m) ≤ CLAIM_TIME); `chosen`: the disclosed rule's pick (among the
    pairs that converge on both paths, the smallest diamond RMS error after 40 s, then the smaller gains);
    `best`: the smallest diamond RMS error of all pairs (what the search found, converging or not)."""
    rows = {}
    for run_id, run in runs.items():
        gains = run.config["system"]["controller"]["class_rs"]
        key = tuple(float(gains[g]) for g in GAINS)
        _, path = _case(run)
        row = rows.setdefault(key, dict(zip(GAINS, key, strict=True)))
        for metric in SEARCH_METRICS:
            hit = frame[(frame["run_id"] == run_id) & (frame["metric"] == metric)]["value"]
            row[f"{path}.{metric}"] = float(hit.iloc[0]) if len(hit) else float("nan")
    table = pd.DataFrame(list(rows.values()))
    if table.empty:
        return table
    for column in (f"{path}.{metric}" for path in ("circle", "diamond") for metric in SEARCH_METRICS):
        if column not in table:
            table[column] = np.nan
    table["converges_both"] = (table["circle.tc_0.1"] <= CLAIM_TIME) & (table["diamond.tc_0.1"] <= CLAIM_TIME)
    table = table.sort_values(list(GAINS)).reset_index(drop=True)
    order = ["diamond.error_after_40s.rms", *GAINS]
    table["chosen"] = table.index.isin(table[table["converges_both"]].sort_values(order).index[:1])
    table["best"] = table.index.isin(table.dropna(subset=[order[0]]).sort_values(order).index[:1])
    return table

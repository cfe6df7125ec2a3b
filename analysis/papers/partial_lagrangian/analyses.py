"""`partial-lagrangian`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.partial_lagrangian.figures import _chain_figure, _compute_time_figure, _term_count_figure
from analysis.papers.partial_lagrangian.metrics import (
    _control_metrics,
    _damped_oscillation,
    _decay_rate,
    _energy_balance,
    _linear_decay_rate,
    _positions,
    _timing_table,
    energy_scale,
    slope,
    static_equilibrium,
    term_count_metrics,
)
from pipeline.core.runlog import Run


def analyze_pendulum(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_case = {r.metadata["case"]: r for r in runs}
    for run in runs:
        case = run.metadata["case"]
        t, q, names = _positions(run)
        n = len(names)
        scale = energy_scale(run.config, n)
        values = {"energy_balance.max_error": (_energy_balance(run, scale), "fraction")}
        energy = run["/energy"]["value.total"].to_numpy()
        if case.startswith("free"):
            values |= _damped_oscillation(t, q[:, 0], energy)
            if n == 1:
                values["decay_rate"] = (_decay_rate(t, q[:, 0]), "1/s")
                values["decay_rate.linear_theory"] = (_linear_decay_rate(run.config), "1/s")
        if case.startswith("pd"):
            values |= _control_metrics(run, names)
            pd_cfg = run.config["scenario"]["pd"]
            reference, kp = np.radians(pd_cfg["reference_deg"]), np.asarray(pd_cfg["kp"], dtype=float)
            q_eq = static_equilibrium(run.config, n, reference, kp)
            for j, name in enumerate(names):
                values[f"{name}.equilibrium"] = (q_eq[j], "rad")
                values[f"{name}.final_minus_equilibrium"] = (values[f"{name}.final"][0] - q_eq[j], "rad")
        if case.endswith("-listing") and case.removesuffix("-listing") in by_case:
            _, q_std, _ = _positions(by_case[case.removesuffix("-listing")])
            values["listing_deviation.max"] = (float(np.abs(q - q_std).max()), "rad")
        m.add_run(run, values)
        if not case.endswith("-listing"):
            twin = by_case.get(f"{case}-listing")
            label = {"free": "damped oscillation", "pd": "PD control"}.get(case, case)
            _chain_figure(run, f"{n} link{'s' if n > 1 else ''}: {label} (AD, partial Lagrangian)", figures, twin)
    return m.frame()


def analyze_slider(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        _, _, names = _positions(run)
        scale = energy_scale(run.config, len(names))
        m.add_run(run, _control_metrics(run, names) | {"energy_balance.max_error": (_energy_balance(run, scale),
                                                                                     "fraction")})
        _chain_figure(run, "Link 2 changed to a slider, l2: 1 → 0.1 m under PID (Fig. 4)", figures,
                      views=(("(a) side view (y against t)", 0.0, 0.0), ("(b) front view (along t)", 0.0, -90.0)))
    return m.frame()


def analyze_compute_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Median and p95 per (kind, method, n); log-log slopes of the medians and of the graph sizes (the
    deterministic operation counts eqs. 28-29 model); the full − column-n slope gap (the claimed O(n⁴) →
    O(n³)); ratios at the largest n."""
    m = MetricTable()
    for run in runs:
        table = _timing_table(run["/compute_time"])
        values = {}
        curves: dict[tuple[str, str], pd.Series] = {}
        for (kind, method), group in table.groupby(["kind", "method"]):
            for n, g in group.groupby("n"):
                values |= timing_metrics(f"{kind}.{method}.n{n}", g["seconds"])
            curves[kind, method] = group.groupby("n")["seconds"].median()
        sizes = run["/graph_size"]
        for method in ("full", "partial", "column"):
            curves["ops", method] = sizes[f"value.terms.{method}"].set_axis(sizes.index.astype(int))
            values |= {f"ops.{method}.n{n}": (v, "count") for n, v in curves["ops", method].items()}
        for (kind, method), curve in curves.items():
            values[f"slope.{kind}.{method}"] = (slope(curve.index.to_numpy(), curve.to_numpy()), "")
        for kind in ("terms", "build", "ops"):
            full, column = curves[kind, "full"], curves[kind, "column"]
            top = full.index.max()
            values[f"slope_gap.{kind}"] = (values[f"slope.{kind}.full"][0] - values[f"slope.{kind}.column"][0], "")
            values[f"ratio.{kind}.full_over_column.n{top}"] = (full[top] / column[top], "ratio")
        for kind in ("eval", "terms", "build", "ops"):
            full, partial = curves[kind, "full"], curves[kind, "partial"]
            values[f"ratio.{kind}.partial_over_full.n{full.index.max()}"] = (partial.iloc[-1] / full.iloc[-1], "ratio")
        ops_ratio = sizes["value.inverse.partial"] / sizes["value.inverse.full"]
        values |= {f"ops.inverse.partial_over_full.n{n:.0f}": (r, "ratio") for n, r in ops_ratio.items()}
        m.add_run(run, values)
        _compute_time_figure(curves, figures, run.run_id)
    return m.frame()


def analyze_term_counts(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        values = term_count_metrics(run)
        m.add_run(run, values)
        _term_count_figure(values, figures)
    return m.frame()


def analyze_checks(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    worst: dict[str, float] = {}
    for run in runs:
        states = run["/check/random_states"]
        values = {f"{c.removeprefix('value.')}.max_rel": (states[c].max(), "fraction") for c in states.columns
                  if states[c].notna().any()}
        _, q, names = _positions(run)
        mj = run["/joint_state/mujoco"][[f"position.{n}" for n in names]].to_numpy()
        values["trajectory_vs_mujoco.max"] = (float(np.abs(q - mj).max()), "rad")
        scale = energy_scale(run.config, len(names))
        for topic in run.topic_names:
            if topic.startswith("/energy/"):
                total = run[topic]["value.total"].to_numpy()
                values[f"energy_drift.{topic.removeprefix('/energy/')}"] = (np.abs(total - total[0]).max() / scale,
                                                                            "fraction")
        m.add_run(run, values)
        for key, (value, _) in values.items():
            worst[key] = max(worst.get(key, 0.0), value)
    for key, value in worst.items():
        m.add("all", key, value, "fraction" if "trajectory" not in key else "rad")
    return m.frame()


ANALYSES = {"one-link": analyze_pendulum, "two-link": analyze_pendulum, "three-link": analyze_pendulum,
            "ten-link": analyze_pendulum, "slider": analyze_slider, "compute-time": analyze_compute_time,
            "term-counts": analyze_term_counts, "checks": analyze_checks}

"""The analysis of each `itbot-smc` experiment: runs on disk -> tidy metrics and figures."""

from __future__ import annotations

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.itbot_smc import figures as fig
from analysis.papers.itbot_smc.metrics import (
    LAWS,
    claims,
    closed_loop_metrics,
    group_of,
    law_of,
    plant_agreement,
    reaching_metrics,
    system_of,
)
from pipeline.core.runlog import Run

FIGURE_GROUP = "analytic"    # the runs drawn as Figs. 6-11: analytic plant, exact joint states
WHERE = {"analytic": "analytic plant, exact joint states", "mujoco": "MuJoCo plant, exact joint states",
         "hall": "analytic plant, Hall-sensor measurement", "ms": "nSMERL with t_i of ω in ms"}


def analyze_tracking(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    groups: dict[tuple[str, str], dict[str, Run]] = {}   # (group, overrides suffix) -> law -> run
    for run in runs:
        group, _ = group_of(run)
        m.add_run(run, closed_loop_metrics(run, detail=group == FIGURE_GROUP))   # timing: the analytic runs
        groups.setdefault(group_of(run), {})[law_of(run)] = run
    frame = m.frame()
    for (group, suffix), laws in groups.items():
        claims(m, frame, group, None if set(laws) >= set(LAWS) else FIGURE_GROUP, suffix)
    for suffix in {suffix for _, suffix in groups}:
        plant_agreement(m, frame, suffix)
    # the figures: the runs without overrides if there are any, else the first set of overrides
    suffix = "" if any(s == "" for _, s in groups) else min(s for _, s in groups) if groups else ""
    ordered = {group: {law: laws[law] for law in LAWS if law in laws}
               for (group, s), laws in groups.items() if s == suffix}
    if FIGURE_GROUP in ordered:
        runs_ = ordered[FIGURE_GROUP]
        fig.hand_figures(runs_, figures, WHERE[FIGURE_GROUP])
        fig.joint_figures(runs_, figures, WHERE[FIGURE_GROUP])
        fig.torque_figure(runs_, figures, WHERE[FIGURE_GROUP], "fig10-torques")
        fig.force_figure(runs_, figures, WHERE[FIGURE_GROUP])
    if "hall" in ordered:
        fig.torque_figure(ordered["hall"], figures, WHERE["hall"], "fig10-torques-hall-sensing", "10 (variant)")
    if "nsmerl" in ordered.get("ms", {}) and FIGURE_GROUP in ordered:
        fig.torque_figure({**ordered[FIGURE_GROUP], "nsmerl": ordered["ms"]["nsmerl"]}, figures,
                          "nSMERL with t_i of ω in ms; SMERL and SMC as in Fig. 10", "fig10-torques-omega-ms",
                          "10 (variant)")
    if "nsmerl" in ordered.get("analytic", {}) and "nsmerl" in ordered.get("mujoco", {}):
        fig.plant_figure(ordered["analytic"]["nsmerl"], ordered["mujoco"]["nsmerl"], figures, "nsmerl")
    return m.frame()


def analyze_smc_sweep(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    rows = []
    for run in runs:
        control = system_of(run)["control"]
        smc = control["smc"]
        params = {"gain_scale": float(smc["gain_scale"]), "boundary_layer": float(smc["boundary_layer"])}
        values = closed_loop_metrics(run, detail=False, forces=False)
        for metric, (value, unit) in values.items():
            m.add(run.run_id, metric, value, unit, params)
        rows.append({**params, "K1": float(control["K"][0]) * params["gain_scale"],
                     **{k: v for k, (v, _) in values.items()}})
    if rows:
        fig.sweep_figure(pd.DataFrame(rows).drop_duplicates(["gain_scale", "boundary_layer"]), figures)
    return m.frame()


def analyze_load_support(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Per run its metrics with the share it was run at (the band of the force targets is the core's: every
    `<law>-<plant>__system.hand.support=s` run); the figure draws the peaks against the share."""
    m = MetricTable()
    rows = []
    for run in runs:
        values = closed_loop_metrics(run, detail=False)
        support = float(system_of(run)["hand"]["support"])
        for metric, (value, unit) in values.items():
            m.add(run.run_id, metric, value, unit, {**run.params, "support": support})
        if not run.metadata["case"].startswith("paper-model-"):
            rows.append({"support": support, **{k: v for k, (v, _) in values.items()}})
    if rows:
        fig.support_figure(pd.DataFrame(rows).drop_duplicates("support").sort_values("support"), figures)
    return m.frame()


def analyze_reaching_time(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, reaching_metrics(run))
    if runs:
        fig.reaching_figure({run.metadata["case"]: run for run in runs}, figures)
    return m.frame()


ANALYSES = {"tracking": analyze_tracking, "smc-sweep": analyze_smc_sweep, "load-support": analyze_load_support,
            "reaching-time": analyze_reaching_time}

"""`gripper-force-control`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    sag = metrics.get("force-sag")
    if sag is not None and not sag.empty:
        rows = []
        for run_id in sorted(set(sag.loc[sag["metric"] == "force_error.sag", "run_id"])):
            rows.append({"run": run_id, "sag [%]": 100 * metric_value(sag, run_id, "force_error.sag"),
                         "max |F − F_set| [N]": metric_value(sag, run_id, "force_error.max"),
                         "RMS [N]": metric_value(sag, run_id, "force_error.rms"),
                         "max rotation error [°]": np.rad2deg(metric_value(sag, run_id, "rotation_error.max"))})
        pairs = sorted(set(sag.loc[sag["metric"] == "plants.max_force_difference", "run_id"]))
        agree = [{"case": c, "max |F_mujoco − F_lumped| [N]": metric_value(sag, c, "plants.max_force_difference"),
                  "RMS [N]": metric_value(sag, c, "plants.rms_force_difference")} for c in pairs]
        sections.append(Section(
            "Fig. 8: force sag, every run", "F_set = 5 N, 40° at ω_max = 5.9 rad/s, ε_max = 73.3 rad/s²; the "
            "window runs from the rotation's start to 0.1 s after its set point stops. `coupling_eq9` runs a plant "
            "with k_g = 1 + g_ps (eq. 9); `ff_printed` the feed-forward gains as eq. (9) prints them.",
            Table(pd.DataFrame(rows), ".3f"), "The two plants (MuJoCo contact force vs the lumped pad force):",
            Table(pd.DataFrame(agree), ".4f"), category="force errors"))
    surface = metrics.get("force-error-surface")
    if surface is not None and not surface.empty:
        points = surface[surface["run_id"] != "surface"].pivot(index="run_id", columns="metric", values="value")
        if {"omega", "epsilon", "force_error.max"} <= set(points.columns):
            grid = points.pivot_table(index="omega", columns="epsilon", values="force_error.max")
            grid.index = [f"ω = {w:g}" for w in grid.index]
            grid.columns = [f"ε = {e:g}" for e in grid.columns]
            sections.append(Section("Fig. 9: max |F_f − F_set| [N] per grid point (ω in rad/s, ε in rad/s²)",
                                    Table(grid, ".3f", index=True), category="force errors"))
    pnp = metrics.get("pick-and-place")
    if pnp is not None and not pnp.empty:
        names = {"closing_time": "closing [ms]", "rotation_time": "rotation 45° [ms]",
                 "rotation_profile_time": "set-point profile [ms]", "opening_time": "opening [ms]",
                 "cycle_time": "cycle [ms]", "rate": "P&P/min", "finger_speed.max": "finger speed [m/s]",
                 "impact_force.max": "peak force at impact [N]",
                 "grasp_error.before_rotation": "force error held [N]"}
        table = pnp[pnp["metric"].isin(names)].pivot(index="run_id", columns="metric", values="value")
        for col in ("closing_time", "rotation_time", "rotation_profile_time", "opening_time", "cycle_time"):
            if col in table:
                table[col] *= 1e3
        sections.append(Section("Pick and place (tomato, F_set = 8.2 N, 98 mm travel, 45°)",
                                "Paper: open/close 92 ms, lift + rotate 45° 130 ms, cycle 314 ms (191 per minute).",
                                Table(table.rename(columns=names), ".3g", index=True), category="trajectories"))
    mc = metrics.get("steady-state")
    if mc is not None and not mc.empty:
        forces = sorted({float(x.rsplit("F", 1)[1]) for x in mc["metric"] if x.startswith("steady_error.max.F")})
        rows = [{"F_set [N]": f, "max |error| [N]": metric_value(mc, "grasps", f"steady_error.max.F{f:g}"),
                 "mean error [N]": metric_value(mc, "grasps", f"steady_error.mean.F{f:g}")} for f in forces]
        sections.append(Section(
            "Fig. 7 stand-in: Monte-Carlo steady-state error (not the hardware result)",
            f"{metric_value(mc, 'grasps', 'grasps'):.0f} grasps on the lumped plant, closing from a random 2-20 mm gap "
            "with M1's Coulomb friction drawn from 0.5-1.5 × the calibrated value; error = mean force over the "
            "last 50 ms − F_set. Paper (strain gauge, 50 grasps per set point): never above 0.8 N, mostly below "
            f"0.5 N. Here: max {metric_value(mc, 'grasps', 'steady_error.max'):.2f} N, "
            f"{100 * metric_value(mc, 'grasps', 'steady_error.fraction_below_0.5N'):.0f} % below 0.5 N.",
            Table(pd.DataFrame(rows), ".3f"), category="force errors"))
    tables = metrics.get("tables")
    if tables is not None and not tables.empty:
        model = tables[tables["metric"].str.startswith("model.")]
        sections.append(Section(
            "Model constants (derived from Sect. 5's parameters)",
            Table(model.assign(metric=model["metric"].str.removeprefix("model."))[["metric", "value"]], ".5g"),
            "Bandwidths in rad/s, times in s, speeds in m/s, K_eps in A/(rad/s²), K_omega in V/(rad/s), "
            "force_per_amp in N/A."))
    if "wall_time_s" in runs:
        speed = [{"experiment": e, "runs": len(g), "wall time [s]": g["wall_time_s"].sum()}
                 for e, g in runs.groupby("experiment")]
        per_plant = []
        for name in ("force-sag",):
            frame = metrics.get(name)
            if frame is None:
                continue
            ratio = frame[frame["metric"] == "simulation.wall_per_simulated_s"]
            for plant in ("mujoco", "lumped"):
                part = ratio[ratio["run_id"].str.contains(f"-{plant}")]["value"]
                if not part.empty:
                    per_plant.append({"plant": plant, "wall s per simulated s (median)": part.median()})
        machine = json.loads(runs["machine"].dropna().iloc[0]) if "machine" in runs and runs["machine"].notna().any() \
            else {}
        sections.append(Section(
            "Simulation cost (not in the paper)",
            f"50 µs ticks, the drive in Python, measured on {machine.get('cpu', 'an unknown machine')}.",
            Table(pd.DataFrame(speed), ".2f"), *([Table(pd.DataFrame(per_plant), ".3f")] if per_plant else [])))
    return sections

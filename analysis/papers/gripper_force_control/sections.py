"""`gripper-force-control`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd

from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.core.targets import paper_value
from analysis.papers.gripper_force_control.metrics import SLUG


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
    band = metrics.get("force-sag-friction")
    if band is not None and not band.empty:
        sections.append(_friction_band_section(band))
    surface = metrics.get("force-error-surface")
    if surface is not None and not surface.empty:
        points = surface[surface["run_id"] != "surface"].pivot(index="run_id", columns="metric", values="value")
        if {"omega", "epsilon", "force_set", "force_error.max"} <= set(points.columns):
            grid = points.pivot_table(index=["force_set", "omega"], columns="epsilon", values="force_error.max")
            grid.index = [f"F_set = {f:g} N, ω = {w:g}" for f, w in grid.index]
            grid.columns = [f"ε = {e:g}" for e in grid.columns]
            sections.append(Section("Fig. 9: max |F_f − F_set| [N] per grid point (ω in rad/s, ε in rad/s²)",
                                    "The paper held F_set constant at some value of 3-5.7 N in each experiment; "
                                    "we run both ends of that range.",
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
            "with M1's Coulomb friction drawn from 0.5-1.5 × the default; error = mean force over the "
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


def _friction_band_section(band: pd.DataFrame) -> Section:
    """The sag of both friction cases at every swept friction, and the friction each needs for the paper's sag
    (interpolated along the sweep, where the sweep brackets it)."""
    sag = band[band["metric"] == "force_error.sag"].assign(case=lambda f: f["run_id"].str.split("__").str[0])
    coulomb = band[band["metric"] == "m1_coulomb"].set_index("run_id")["value"]
    sag = sag.assign(m1_coulomb=sag["run_id"].map(coulomb)).sort_values("m1_coulomb")
    table = sag.pivot_table(index="m1_coulomb", columns="case", values="value") * 100
    table.index = [f"{1e3 * c:g}" for c in table.index]
    table.index.name = "M1 Coulomb friction [mN m]"
    needed = []
    for case, target in (("friction-mujoco", "F8.friction"), ("no-feedforward-mujoco", "F8.no-ff")):
        part = sag[sag["case"] == case]
        paper = paper_value(SLUG, target, "fraction")
        inside = not part.empty and part["value"].min() <= paper <= part["value"].max()
        at = float(np.interp(paper, part["value"], part["m1_coulomb"])) if inside else float("nan")
        needed.append({"case": case, "paper's sag [%]": 100 * paper,
                       "band [%]": f"{100 * part['value'].min():.1f}-{100 * part['value'].max():.1f}",
                       "friction that gives it [mN m]": 1e3 * at})
    low, high = sorted(row["friction that gives it [mN m]"] for row in needed)
    if math.isnan(low) or math.isnan(high):
        verdict = "At least one of Fig. 8's friction sags lies outside its band."
    elif high > 1.25 * low:
        verdict = (f"Each friction sag of Fig. 8 lies in its band, but they need different frictions ({low:.0f} and "
                   f"{high:.0f} mN m): no single friction gives both, so the paper's no-feed-forward case ran with "
                   "more friction than its friction case, or its drive without feed-forward differs from ours.")
    else:
        verdict = f"A single friction of about {(low + high) / 2:.0f} mN m gives both of Fig. 8's friction sags."
    return Section(
        "Fig. 8 band: the sags over M1's plausible Coulomb friction",
        "The paper gives no friction. We sweep M1's Coulomb friction over 0.01-0.045 N m, a range fixed from the "
        "drive train's class before looking at the result (Sensitivity bands, below); the default 0.02 N m is "
        "that range's centre. Sag in % of F_set = 5 N, MuJoCo plant, feed-forward on (friction) and off "
        "(no-feedforward):",
        Table(table.reset_index(), ".1f"),
        "Where the paper's sag falls in the band, the friction that gives it (linear between swept points). "
        + verdict,
        Table(pd.DataFrame(needed), ".1f"), category="force errors")

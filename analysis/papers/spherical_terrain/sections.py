"""`spherical-terrain`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import pandas as pd

from analysis.core.sections import Section, Table
from analysis.papers.spherical_terrain.metrics import CLAIM_TIME, RUN_COLUMNS


def _run_table(frame: pd.DataFrame) -> pd.DataFrame:
    default = frame[~frame["run_id"].str.contains("__") & (frame["run_id"] != "all")]
    table = default[default["metric"].isin(RUN_COLUMNS)].pivot(index="run_id", columns="metric", values="value")
    effort = default[default["metric"].str.match(r"effort\..*\.rms")]
    effort = effort.assign(rate=effort["metric"].str.split(".").str[1]).groupby("run_id").apply(
        lambda g: ", ".join(f"{r} {v:.3g}" for r, v in zip(g["rate"], g["value"], strict=True)),
        include_groups=False)
    table = table.reindex(columns=[c for c in RUN_COLUMNS if c in table.columns]).rename(columns=RUN_COLUMNS)
    table["RMS rates [rad/s]"] = effort
    return table.reset_index()


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    for name, title, text in (
            ("paths", "Tracking runs, corrected equations", "Default gains (all 1, k_e = 1 m), start at the "
             "origin with ψ0 = 0, forward Euler at 200 Hz. Steady-state errors of a few mm are the chattering "
             "of the pursuit law around the target at this step (they halve with the step)."),
            ("printed", "Tracking runs, eqs. (25), (58), (60) as printed", "The same gains and start. With eq. "
             "(25) as printed the heading laws of 3R and RT turn them away from the target, and with eq. (58) as "
             "printed the RS-SR's tilt rolls it away sideways; 2R-SR (ψ ≡ 0) is unaffected. Eq. (60) as printed "
             "is a segment of the line y = x, traversed back and forth, so 'circle' here is that segment.")):
        frame = metrics.get(name)
        if frame is not None and not frame.empty:
            sections.append(Section(title, text, Table(_run_table(frame), ".4g"), category="tracking errors"))
    sweep = metrics.get("sweep")
    if sweep is not None and not sweep.empty:
        params = [c for c in sweep.columns if c not in ("run_id", "metric", "value", "unit")]
        rows = sweep[sweep["metric"].isin(["tc_0.1", "error_after_40s.mean", "vertex.max"])].copy()
        rows["case"] = rows["run_id"].str.split("__").str[0]
        table = rows.pivot_table(index=["case", *params], columns="metric", values="value", aggfunc="first",
                                 dropna=False).reset_index()
        converged = sweep[sweep["metric"] == "claim.converges"]
        share = f"{int(converged['value'].sum())}/{len(converged)}"
        sections.append(Section("Gain and start sweep", f"Every sweep run on disk ({len(converged)} runs; swept: "
                        f"{', '.join(params) or 'nothing'}). Runs with t_c(0.1 m) ≤ {CLAIM_TIME:g} s: {share}. "
                        "An empty t_c means the error is above 0.1 m at the end.",
                                Table(table, ".4g"), category="tracking errors"))
    physics = metrics.get("physics-check")
    if physics is not None and not physics.empty:
        keep = {"paper_model_error.median": "vs paper model (median)", "rigid_model_error.median":
                "vs rigid rolling (median)", "paper_model_error.weighted": "vs paper model (weighted)",
                "rigid_model_error.weighted": "vs rigid rolling (weighted)", "speed_ratio.p05": "speed ratio p5",
                "speed_ratio.p95": "speed ratio p95",
                "slip.median": "slip median [m/s]", "drive.omega_error_median": "|ω − ω_cmd| median [rad/s]",
                "tc_0.1": "t_c(0.1 m) [s]", "kinematic.tc_0.1": "t_c kinematic [s]",
                "error_after_40s.mean": "mean e (t≥40) [m]", "kinematic.error_after_40s.mean": "kinematic [m]",
                "error_after_40s.max": "max e (t≥40) [m]"}
        table = physics[physics["metric"].isin(keep)].pivot(index="run_id", columns="metric", values="value")
        table = table.reindex(columns=[k for k in keep if k in table.columns]).rename(columns=keep)
        sections.append(Section(
            "Physics check (not in the paper)", "Each robot is a 2 kg ball on a MuJoCo height field of eq. "
            "(59), driven by torque-limited velocity actuators to the ω the paper's controller asks for, in closed "
            "loop at 100 Hz; the kinematic model runs beside it with the same controller and step. Model errors "
            "compare the ball's contact-point velocity v with two models fed the ball's measured ω, relative to "
            "‖v_paper‖: the median over samples while moving, and Σ‖v − v_model‖ / Σ‖v_paper‖ (weighted, which "
            "the drive's transients dominate). 'paper model' is eq. (31) (ω × R n̂), 'rigid rolling' adds the "
            "curvature term the paper drops "
            "(the difference of the two columns is the curvature effect; what remains against rigid rolling is "
            "slip, soft contact and the field's facets). Speed ratio: MuJoCo contact speed over the paper "
            "model's, 5th/95th percentile while moving (the curvature bound is 1/(1 ± Rκ) = 0.86…1.19).",
            Table(table, ".4g", index=True)))
    return sections

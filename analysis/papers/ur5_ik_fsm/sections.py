"""`ur5-ik-fsm`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.papers.ur5_ik_fsm.metrics import ALGORITHMS


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    tables = metrics.get("tables")
    if tables is not None and "sequential" in set(tables["run_id"]):
        rows = [{"test": k, **{f"diff Alg {a[-1]} [rad]": metric_value(tables, "sequential", f"{a}.test{k}.diff")
                               for a in ALGORITHMS},
                 "same set": bool(metric_value(tables, "sequential", f"agreement.test{k}"))} for k in range(1, 11)]
        sections.append(Section(
            "Sequential variant (our extension)", "The 10 poses in order, each algorithm starting from its own "
            f"previous selection instead of 0. Agreement: {metric_value(tables, 'sequential', 'agreement.count'):.0f}"
            "/10.", Table(pd.DataFrame(rows), ".4f"), category="trajectories"))
    paths = metrics.get("singular-paths")
    if paths is not None:
        per_run = paths[paths["metric"].isin(["max_joint_jump", "jumps", "branch_switches", "rejected_samples",
                                              "min_abs_det_j", "max_joint_error", "max_flange_error",
                                              "max_flange_rotation_error", "saturated_fraction"])]
        table = per_run.pivot(index="run_id", columns="metric", values="value")
        table["min_abs_det_j"] = table["min_abs_det_j"] * 1e9
        table["max_flange_error"] = table["max_flange_error"] * 1e3
        table = table.rename(columns={"min_abs_det_j": "min |det J| [mm³]", "max_flange_error": "max flange err [mm]",
                                      "max_joint_jump": "max jump [rad]", "max_joint_error": "max joint err [rad]",
                                      "max_flange_rotation_error": "max flange rot err [rad]"})
        agree = paths[paths["metric"] == "agreement"].set_index("run_id")["value"]
        sections.append(Section(
            "Singular paths (our extension)", "IK at 500 Hz along each flange path, previous = last selection; then "
            "executed by the MuJoCo UR5 (joint PD + gravity compensation at 1 kHz). 'near' passes 0.1 mm from the "
            "singular pose, 'through' puts a sample on it. A jump is a step > 0.5 rad between samples.",
            Table(table, ".4g", index=True),
            "Agreement of the two algorithms per path (fraction of samples with the same set):",
            Table(agree.to_frame("agreement"), ".3f", index=True), category="trajectories"))
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        rows = [(f"Algorithm {name[3]}" + (" (batched, per pose)" if "batch" in name else " (per call)"), name,
                 "not reported") for name in ("alg1", "alg2", "alg1_batch", "alg2_batch")]
        sets = ", ".join(f"Algorithm {a[-1]} {metric_value(ct, 'random-poses', f'{a}.sets_evaluated_mean'):.2f}"
                         for a in ALGORITHMS)
        sections.append(compute_time_section(
            "Compute time", ct, "random-poses", rows, machine_of(runs, "compute-time"),
            note=f"Python + NumPy; the paper reports no times (MATLAB R2021a). Complete sets built per call: {sets}."))
    return sections

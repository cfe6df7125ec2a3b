"""`scara-half-derivative`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.papers.scara_half_derivative.metrics import SCALE, paper_table2


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    table2 = metrics.get("table2")
    if table2 is not None and not table2.empty:
        for k in sorted({rid.rsplit("-k", 1)[1] for rid in table2["run_id"] if "-k" in rid}, key=float):
            rows = []
            for metric, paper in paper_table2().items():
                scale = SCALE.get(metric.split(".")[0], 1.0)
                row = {"index": metric}
                for name, printed in zip(("kd", "kdhd", "khd"), paper, strict=True):
                    value = metric_value(table2, f"{name}-k{k}", metric) * scale
                    pct = metric_value(table2, f"{name}-k{k}", f"pct.{metric}")
                    row[f"{name.upper()}"] = f"{value:.4g}" + (f" ({100 * pct:+.1f}%)" if np.isfinite(pct) else "")
                    row[f"paper {name.upper()}"] = printed
                rows.append(row)
            sections.append(Section(f"Table 2 as reproduced, K = {float(k):g} N/m (Exudyn closed chain)",
                                    "Errors in mm, torques in Nm, ISE in m²s; percentages vs KD. A KHD column of "
                                    "NaN means the run failed (unstable, see Runs).", Table(pd.DataFrame(rows)),
                                    category="tracking errors"))
        sections.append(compute_time_section(
            "Compute time per control step (not reported by the paper)", table2, "all",
            [("KD, eq. (11)", "controller.kd", "not reported"),
             ("KDHD/KHD, eq. (17)", "controller.kdhd", "not reported")],
            machine_of(runs, "table2"),
            note="One call = FK, Jacobian and the control law (plus the 11-tap half-derivative filter for KDHD) in "
                 "Python/NumPy, timed inside the closed loop over every step of every table2 run."))
    maps = metrics.get("maps")
    if maps is not None and not maps.empty:
        rows = []
        for sid in sorted({r for r in maps["run_id"] if r.startswith("k") and "-" not in r}):
            rows.append({"stiffness": sid, "ICE of KD [N²m²s]": metric_value(maps, sid, "ice.kd"),
                         "points": metric_value(maps, sid, "locus.points"),
                         "slope [s^-½]": metric_value(maps, sid, "locus.slope"),
                         "intercept [Ns^½/m]": metric_value(maps, sid, "locus.intercept"),
                         "paper (eq. 20)": "−9.44, 47,200"})
        lonely = [r["stiffness"] for r in rows if r["points"] < 2]
        sections.append(Section(
            "Equal-ICE locus fitted from the maps (Fig. 6, eq. 20)", "For each hd_xyz of the grid, the d_xyz at "
            "which ICE equals KD's (linear interpolation along d), then a least-squares line through these points.",
            Table(pd.DataFrame(rows), ".5g"),
            ("With a single point (" + ", ".join(lonely) + ") the only grid point at KD's ICE is KD itself: ICE "
             "grows in every direction around it on the grid, so this model has no equal-ICE line through KD to "
             "fit." if lonely else ""), category="trajectories"))
    locus = metrics.get("locus")
    if locus is not None and not locus.empty:
        points = locus[locus["metric"].isin(["ise", "ice", "tau1.max", "tau2.max", "tau3.max"])]
        table = points.pivot_table(index=["k_xyz", "d_xyz", "hd_xyz"], columns="metric", values="value")
        sections.append(Section("Along eq. (20) (Fig. 7)", Table(table.reset_index().sort_values(
            ["k_xyz", "d_xyz"], ascending=[True, False]), ".5g"), category="trajectories"))
    return sections

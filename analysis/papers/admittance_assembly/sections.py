"""`admittance-assembly`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.sections import Section, Table
from analysis.papers.admittance_assembly.metrics import CASES


def _pivot(frame: pd.DataFrame, metrics: dict[str, str], runs: list[str] | None = None) -> pd.DataFrame:
    part = frame[frame["metric"].isin(metrics)]
    if runs is not None:
        part = part[part["run_id"].isin(runs)]
    table = part.pivot(index="run_id", columns="metric", values="value")
    return table[[k for k in metrics if k in table]].rename(columns=metrics)


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = [Section("What can be reproduced",
                        "The paper's text ends inside Sec. I. What survives is the admittance "
                "law v = v0 + A·w (1), the error-reduction condition dᵀ(v0 + A·w) < 0 (2) and the abstract's claim "
                "that an admittance satisfying the conditions at a finite number of configurations of a bounded "
                "contact state satisfies them in between. Every result beyond that (the conditions themselves, "
                "proofs, examples) is **not reproducible**. The runs are our demonstrator: a frictionless, "
                "quasi-static square peg in a square hole in the two-point contact state (a tip vertex on one wall, "
                "the opposite rim against the peg), planar and spatial, with condition (2) itself checked at the "
                "corners of a box of configurations and on a dense interior sample.")]
    cc = metrics.get("corner-conditions")
    if cc is not None and not cc.empty:
        table = _pivot(cc, {"corners.count": "corners", "corners.min_margin": "min margin, corners",
                            "interior.count": "interior points", "interior.satisfied_fraction": "satisfied inside",
                            "interior.min_margin": "min margin inside",
                            "interior.satisfied_fraction_isotropic": "satisfied inside (Â = I)",
                            "interior.max_force": "max λ inside [N]"}, list(CASES))
        rand = _pivot(cc, {"random.count": "random A", "random.corner_satisfied": "(2) at all corners",
                           "random.counterexamples": "...but fails inside",
                           "random.interior_min_below_corner_min": "inside min < corner min",
                           "random.single_ok_two_fail": "single-PC ok, two-PC fails",
                           "random.two_ok_single_fail": "two-PC ok, single-PC fails"}, list(CASES))
        sections.append(Section("Condition (2) over the two-point state", "Margin = −dᵀv / (‖δ‖·|v0|): the rate at "
                        "which the tip's misalignment closes, as a fraction of the nominal speed (> 0: (2) holds). "
                        "The designed A maximises the worst margin at the box corners (SLSQP).",
                        Table(table, ".4g", index=True),
                        "Random admittances (Wishart, trace-normalised) checked at the corners and inside; "
                        "'single-PC' evaluates (2) with each contact alone at the same configurations (Sec. I: the "
                        "two single-PC condition sets are not equivalent to the two-PC set).",
                        Table(rand, ".4g", index=True), category="tracking errors"))
        if "spatial" in set(cc["run_id"]) or "planar" in set(cc["run_id"]):
            sections.append(compute_time_section(
                "Compute time", cc, "spatial" if "spatial" in set(cc["run_id"]) else "planar",
                [("condition (2) at one configuration (LCP + law + check)", "condition_check", "not reported"),
                 ("batched, per configuration", "condition_check_batch", "not reported")],
                machine_of(runs, "corner-conditions"), note="Python + NumPy; the paper reports no times."))
    ins = metrics.get("insertion")
    if ins is not None and not ins.empty:
        groups = sorted(r for r in set(ins["run_id"]) if r.count("-") == 1)
        table = _pivot(ins, {"runs": "runs", "success_rate": "inserted", "monotone_fraction": "‖δ‖ never grows",
                             "claim.error_never_increases_in_two_point_state": "never grows in the two-point state",
                             "mean_insertion_time": "mean time [s]", "max_contact_force": "max λ [N]"}, groups)
        sections.append(Section("Quasi-static insertions", "From the box centre and random starts of the box in the "
                        "real hole (0.1 mm clearance per side), until the tip reaches the mated depth; the last sample "
                        "(past the mated depth) is not counted.",
                        Table(table, ".4g", index=True), category="trajectories"))
    mj = metrics.get("mujoco-crosscheck")
    if mj is not None and not mj.empty:
        cols = {}
        for c in ("c1", "c2"):
            cols |= {f"force_error.{c}.max": f"{c} max [N]", f"force_error.{c}.mean": f"{c} mean [N]",
                     f"force_error.{c}.rms": f"{c} RMS [N]", f"force_error.{c}.sag": f"{c} sag [fraction]",
                     f"force_error.{c}.reference_mean": f"{c} mean λ [N]"}
        cols |= {"wrench_error.force.max": "‖ΔF‖ max [N]", "wrench_error.force.rms": "‖ΔF‖ RMS [N]",
                 "wrench_error.torque.rms": "‖ΔM‖ RMS [N·m]", "contact_state_agreement": "same contact state",
                 "max_penetration": "max penetration [m]",
                 "trajectory_difference.max": "max |Δ‖δ‖| [m]"}
        sections.append(Section(
                        "Force errors: MuJoCo against the quasi-static prediction",
                        "Measured = MuJoCo's frictionless soft contacts on the peg, summed per hole feature (each "
                        "MuJoCo contact attributed to the nearest candidate); reference = the rigid quasi-static "
                        "force on the same feature at MuJoCo's pose under the same v0 and A (per feature, because "
                        "when a peg face lies flat on a wall only the sum over its contacts is unique). Statistics "
                        "of |F_measured − F_reference| after the settling time (analysis.core.errors."
                        "force_error_stats); sag = largest drop below the reference as a fraction of it. c1: the −x "
                        "wall (the tip's contact), c2: the +x rim: the two principal contacts of the two-point state. "
                        "ΔF, ΔM: the total contact wrench on the peg. These are model-consistency numbers, not "
                        "paper results.", Table(_pivot(mj, cols), ".3g", index=True), category="force errors"))
    return sections

"""`nmpc-cdkd`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import pandas as pd

from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.core.targets import load_targets
from analysis.papers.nmpc_cdkd.metrics import CASE_LABELS, TARGETS, TRAJECTORY_COLUMNS, paper_table3
from analysis.papers.nmpc_cdkd.table3 import cell_of

RATIOS = [(f"ratio.{case}.k{k}", f"Tab3.{case}.N{n}.ratio", f"t̄ dec / t̄ full, {CASE_LABELS[case]}, N{n}")
          for case in CASE_LABELS for n, k in ((1, 10), (2, 20))] + [
    (f"sigma_ratio.{case}.k{k}", f"Tab3.{case}.N{n}.sigma_ratio", f"σ dec / σ full, {CASE_LABELS[case]}, N{n}")
    for case in CASE_LABELS for n, k in ((1, 10), (2, 20))] + [
    (f"growth.{model}.{case}", f"Tab3.{case}.growth.{short}", f"N1→N2 growth of t̄, {model}, {CASE_LABELS[case]}")
    for model, short in (("decomposed", "dec"), ("full", "full")) for case in CASE_LABELS]


def _table3_sections(ct: pd.DataFrame) -> list[Section]:
    value = lambda metric: metric_value(ct, "table3", metric)  # noqa: E731
    rows = []
    for case in CASE_LABELS:
        for n, k in ((1, 10), (2, 20)):
            for model in ("decomposed", "full"):
                cell = f"{model}.{case}.k{k}"
                paper = paper_table3().get((model, case, k))
                rows.append({
                    "movement": CASE_LABELS[case], "horizon": f"N{n}", "model": model,
                    "t̄ [ms] (95 % interval)": f"{value(f'mean.{cell}') * 1e3:.1f} "
                                              f"({value(f'mean.{cell}.ci_low') * 1e3:.1f}–"
                                              f"{value(f'mean.{cell}.ci_high') * 1e3:.1f})",
                    "σ [ms] (95 % interval)": f"{value(f'std.{cell}') * 1e3:.1f} "
                                              f"({value(f'std.{cell}.ci_low') * 1e3:.1f}–"
                                              f"{value(f'std.{cell}.ci_high') * 1e3:.1f})",
                    "paper t̄ ± σ [ms]": f"{paper[0]:g} ± {paper[1]:g}" if paper else "",
                    "median [ms]": value(f"median.{cell}") * 1e3, "p95 [ms]": value(f"p95.{cell}") * 1e3,
                    "IPOPT iterations": value(f"iterations.{cell}"), "failed": value(f"failures.{cell}"),
                    "> 40 ms": value(f"over_control_horizon.{cell}"), "solves": value(f"samples.{cell}")})
    ratio_rows = []
    for metric, target, label in RATIOS:
        median, low, high = value(metric), value(f"{metric}.ci_low"), value(f"{metric}.ci_high")
        printed = float(load_targets(TARGETS).set_index("target_id").loc[target, "value"])
        ratio_rows.append({"ratio": label, "ours: median": median, "95 % interval": f"{low:.3f}–{high:.3f}",
                           "paper": printed, "paper inside": "yes" if low <= printed <= high else "no"})
    seeds = sorted({r.split("=", 1)[1] for r in ct["run_id"] if r.startswith("table3__seed=")}, key=int)
    seed_rows = [{"ratio": label, **{f"seed {s}": metric_value(ct, f"table3__seed={s}", metric) for s in seeds}}
                 for metric, _, label in RATIOS]
    moves = int(value("moves"))
    return [Section(
        "Table 3: OCP solve time per step",
        f"{moves} seeded random point-to-point moves per cell ({len(seeds)} seeds pooled), ideal kinematic plant. "
        "At one randomly drawn OCP update of each move's closed loop, every cell solves a probe of two OCPs from "
        "the feasible path there (the reference, its wrist kept out of the obstacle's safety sphere and inside the "
        "height band): the first, cold, warms the second up, which is the OCP the closed loop would solve next (its "
        "state the first plan's prediction, its guess the first solution shifted by the control horizon); only the "
        "second is timed (wall time of the IPOPT call). The twelve cells take their solves in turn, so machine "
        "load falls on all alike. t̄ and σ pool every timed solve; their intervals and those of every ratio below "
        "come from 2000 bootstrap resamples of the moves (the same resample for every cell: the design is paired). "
        "Every closed-loop OCP instead: `scenario.sampling=closed-loop` (about 25 times the solves).",
        Table(pd.DataFrame(rows), ".3g"),
        "Every ratio as the median of its bootstrap distribution with the 95 % interval; a target is a match when "
        "the paper's value lies inside the interval, a miss when the interval excludes it:",
        Table(pd.DataFrame(ratio_rows), ".3f"),
        "Each seed's own moves (point estimates): how far one seed's draw moves a ratio.",
        Table(pd.DataFrame(seed_rows), ".3f"), category="compute times")]


def _baseline_section(ct: pd.DataFrame) -> Section:
    rows = []
    for run_id in sorted({r for r in ct["run_id"] if not r.startswith("table3")}):
        model, case, k = cell_of(run_id)
        if any(row["model"] == model and row["case"] == case and row["k"] == k for row in rows):
            continue
        rows.append({"model": model, "case": case, "k": k, **{
            label: metric_value(ct, run_id, f"nlp.{name}") for name, label in (
                ("variables", "variables"), ("constraints", "constraints"),
                ("jacobian_nonzeros", "Jacobian nonzeros"), ("hessian_nonzeros", "Hessian nonzeros"))}})
    rows.sort(key=lambda r: (list(CASE_LABELS).index(r["case"]), r["k"], r["model"]))
    return Section(
        "How the full-model baseline is built",
        "Sec. 4.1 gives the full-model NMPC only its inputs (all six joint rates) and its model (J_w^e(q) of "
        "eq. 5, translation and orientation), and says its objective (10c) is extended by the orientation. The "
        "rest is ours (paper.yaml assumptions), chosen to solve the same task as the decomposed NMPC with the same "
        "transcription, so that the time ratio measures the model, not the solver set-up: states [p_w^e (mm), the "
        "unit quaternion Q_w^e, q] (13), inputs q̇ (6); Q̇ = ½ [0, ω] ⊗ Q with ω = J_rot q̇ in {w}; the same one RK4 "
        "step per 10 ms interval, multiple shooting, k = 10 or 20; stage cost (10c) on p^e plus μ_o ‖ẽ‖² with ẽ "
        "of eq. (11) and μ_o = μ_p (2 · 250 mm)² (1 rad of orientation error costs like 250 mm of tool-tip error); "
        "(10a) and (10e) on all six joints; (10f) and (10g) on its wrist point, computed from q1..q3; the same "
        "IPOPT options (tol 1e-8, acceptable_obj_change_tol 1e-6, MUMPS, exact Hessian), the same warm start "
        "(the previous solution shifted). Its sizes against the decomposed NLP's:",
        Table(pd.DataFrame(rows), ".0f"),
        "The ratio t̄_dec/t̄_full depends on this choice: a cheaper orientation term (e.g. on the rotation "
        "matrix, or a smaller state without the quaternion) or looser tolerances on the full model would move it.",
        category="compute times")


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty and "table3" in set(ct["run_id"]):
        sections += [*_table3_sections(ct), _baseline_section(ct)]
    for name, title in (("tracking", "Tracking (Fig. 3)"), ("fixed-obstacles", "Fixed obstacles (Figs. 4-5)"),
                        ("moving-obstacles", "Moving obstacles (Figs. 6-7)")):
        frame = metrics.get(name)
        if frame is None or frame.empty:
            continue
        shown = frame[frame["run_id"] != "all"]
        present = [c for c in TRAJECTORY_COLUMNS if c[0] in set(shown["metric"])]
        table = shown.pivot(index="run_id", columns="metric", values="value")
        table = pd.DataFrame({label: table[metric] * factor for metric, label, factor in present})
        sections.append(Section(title, Table(table, ".4g", index=True), category="trajectories"))
    return sections

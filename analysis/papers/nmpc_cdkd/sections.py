"""`nmpc-cdkd`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.papers.nmpc_cdkd.metrics import CASE_LABELS, TRAJECTORY_COLUMNS, _combo, paper_table3


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        rows, combos = [], [r for r in ct["run_id"].unique() if r != "table3"]
        for run_id in sorted(combos, key=lambda r: (list(CASE_LABELS).index(_combo(r)[1]), _combo(r)[2], r)):
            model, case, k = _combo(run_id)
            paper = paper_table3().get((model, case, k))
            rows.append({"movement": CASE_LABELS[case], "horizon": f"N{1 if k == 10 else 2} (k = {k})", "model": model,
                         "t̄ ± σ [ms]": f"{metric_value(ct, run_id, 'solve.mean') * 1e3:.1f} ± "
                                       f"{metric_value(ct, run_id, 'solve.std') * 1e3:.1f}",
                         "paper t̄ ± σ [ms]": f"{paper[0]:g} ± {paper[1]:g}" if paper else "",
                         "median [ms]": metric_value(ct, run_id, "solve.median") * 1e3,
                         "p95 [ms]": metric_value(ct, run_id, "solve.p95") * 1e3,
                         "IPOPT iterations": metric_value(ct, run_id, "solve.iterations_mean"),
                         "failed solves": int(metric_value(ct, run_id, "solve.failures")),
                         "> 40 ms": metric_value(ct, run_id, "solve.over_control_horizon"),
                         "samples": int(metric_value(ct, run_id, "solve.samples"))})
        ratio_rows = [{"movement": CASE_LABELS[c],
                       **{f"dec/full N{i + 1}": metric_value(ct, "table3", f"ratio.{c}.k{k}")
                                                       for i, k in enumerate((10, 20))},
                       "growth N1→N2 dec": metric_value(ct, "table3", f"growth.decomposed.{c}"),
                       "growth N1→N2 full": metric_value(ct, "table3", f"growth.full.{c}")} for c in CASE_LABELS]
        sections.append(Section(
            "Table 3: OCP solve time per step", "Each NMPC runs its own closed loop (ideal kinematic plant) over "
            "the same seeded random point-to-point moves; the 12 loops advance one solve each in turn, so machine "
            "load falls on all alike. Every solve is one sample (wall time of the IPOPT call, warm-started); failed "
            "solves are counted, not dropped. More moves: `scenario.moves=10`.", Table(pd.DataFrame(rows), ".3g"),
            "Ratios (paper: 0.13–0.20; growth dec +15/+22/+24 %, full +66/+37/+23 %):",
            Table(pd.DataFrame(ratio_rows), ".3f"), category="compute times"))
        merged = ct.assign(metric=ct["run_id"] + "/" + ct["metric"], run_id="all")
        sections.append(compute_time_section(
            "Compute time per OCP step (median and p95)", merged, "all",
            [(f"{_combo(r)[0]}, {CASE_LABELS[_combo(r)[1]]}, k = {_combo(r)[2]}", f"{r}/solve",
              "t̄ ± σ = {:g} ± {:g} ms".format(*paper_table3()[_combo(r)])) for r in sorted(combos)],
            machine_of(runs, "compute-time"), unit="ms",
            note="Python + CasADi + IPOPT (MUMPS), no code generation; the paper: MATLAB R2020a + CasADi + IPOPT "
                 "on an i7-8550U."))
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

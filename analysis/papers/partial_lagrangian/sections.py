"""`partial-lagrangian`: the report's extra sections (tables beside the targets)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.papers.partial_lagrangian.metrics import KINDS, METHODS, SLOPE_FROM, paper_term_counts


def _pd_section(metrics: dict[str, pd.DataFrame]) -> Section | None:
    rows = []
    for experiment in ("one-link", "two-link", "three-link"):
        frame = metrics.get(experiment)
        if frame is None or "pd" not in set(frame["run_id"]):
            continue
        finals = frame[(frame["run_id"] == "pd") & frame["metric"].str.match(r"theta\d+\.final$")]
        for metric in finals["metric"]:
            joint = metric.split(".")[0]
            value = {key: metric_value(frame, "pd", f"{joint}.{key}") for key in
                     ("final", "steady_error", "equilibrium", "settling_time", "overshoot")}
            final, steady = np.degrees(value["final"]), np.degrees(value["steady_error"])
            rows.append({"experiment": experiment, "joint": joint, "reference [°]": final + steady,
                         "simulated rest [°]": final, "closed-form rest [°]": np.degrees(value["equilibrium"]),
                         "rest − reference [°]": -steady, "settling time [s]": value["settling_time"],
                         "overshoot [%]": value["overshoot"]})
    if not rows:
        return None
    return Section(
        "PD control: where the chains come to rest", "The paper's PD law τ = Kp (θref − θ) − Kd θ̇ (radians, "
            "no gravity compensation: nothing else is stated) holds the chain where the spring torque balances "
            "gravity, not at the reference. The closed-form rest solves Kp (θref − θ) = ∂P/∂θ by statics.",
        Table(pd.DataFrame(rows), ".3f"), category="tracking errors")


def _per_n_table(ct: pd.DataFrame, run_id: str, ns: list[int], columns: list[tuple[str, str]]) -> Table:
    """Median (p95) in µs of each (kind, method) by n."""
    rows = []
    for n in ns:
        row = {"n": n}
        for kind, method in columns:
            med, p95 = (metric_value(ct, run_id, f"{kind}.{method}.n{n}.{stat}") * 1e6 for stat in ("median", "p95"))
            row[f"{kind} {method}"] = f"{med:.3g} ({p95:.3g})"
        rows.append(row)
    return Table(pd.DataFrame(rows))


def _compute_time_sections(ct: pd.DataFrame, runs: pd.DataFrame) -> list[Section]:
    run_id = "chains"
    ns = sorted({int(x.split(".n")[1].split(".")[0]) for x in ct["metric"] if x.startswith("eval.full.n")})
    top = max(ns)
    rows = [(f"{KINDS[kind]}: {METHODS[method]}, n = {top}", f"{kind}.{method}.n{top}",
             "Fig. 5b: plotted only (i5-10400, PyTorch)")
            for kind, methods in (("eval", ("full", "partial", "mujoco")), ("terms", ("full", "partial", "column")),
                                  ("build", ("full", "partial", "column"))) for method in methods]
    main = compute_time_section(
        "Compute time (Fig. 5b)", ct, run_id, rows, machine_of(runs, "compute-time"),
        note="Evaluations are per state, from short batches of random states in one CasADi call; MuJoCo's from "
             "`rollout` of one mj_step per state. The paper prints no times (Fig. 5b is an image); its own model of "
             "the figure is the term counts of eqs. (28)-(29), beside ours below.")
    eq28, eq29 = paper_term_counts(np.array(ns))
    ops = pd.DataFrame({"n": ns, **{f"ops {m}": [f"{metric_value(ct, run_id, f'ops.{m}.n{n}'):.0f}" for n in ns]
                                   for m in ("full", "partial", "column")},
                        "eq. 28": [f"{x:.0f}" for x in eq28], "eq. 29": [f"{x:.0f}" for x in eq29]})
    slopes = pd.DataFrame([{"quantity": label,
                             **{METHODS[m]: metric_value(ct, run_id, f"slope.{kind}.{m}") for m in METHODS}}
                           for kind, label in KINDS.items()])
    text = Section(
        "Compute time by number of links", "Median (p95) in µs per call, one thread. `eval`: q̈ by AD of "
            "the full Lagrangian, of the summed partial Lagrangians, and by MuJoCo. `terms`: the coefficients (M, b) "
            "of the equations of motion; `column` is column n of Table 1 alone, the work of the slowest thread if "
            "the n columns ran in parallel (an ideal bound: no thread overhead, no summation). `build`: generating and "
            "differentiating the graph of those terms, which the paper's define-by-run code repeats every step.",
        _per_n_table(ct, run_id, ns, [("eval", "full"), ("eval", "partial"), ("eval", "mujoco"),
                                      ("terms", "full"), ("terms", "partial"), ("terms", "column")]),
        _per_n_table(ct, run_id, ns, [("build", "full"), ("build", "partial"), ("build", "column")]),
        "Operations in the graphs of the terms (CasADi instructions) beside the paper's term counts "
            "without (eq. 28) and with (eq. 29) partial Lagrangians on n threads:", Table(ops),
        f"Log-log slopes over n = {SLOPE_FROM}..{top} (the paper: 4 without dividing, 3 with partial "
        "Lagrangians on n threads):", Table(slopes, ".2f"), category="compute times")
    return [main, text]


def _checks_section(checks: pd.DataFrame) -> Section:
    columns = {"mass_matrix.max_rel": "M vs MuJoCo", "bias.max_rel": "b vs MuJoCo", "qdd_mujoco.max_rel": "q̈ vs MuJoCo",
               "qdd_full_partial.max_rel": "q̈ full vs partial", "closed_form.max_rel": "closed form (n = 2)",
               "trajectory_vs_mujoco.max": "trajectory vs MuJoCo [rad]",
               "energy_drift.semi-implicit-euler": "energy drift, semi-implicit Euler",
               "energy_drift.rk4": "energy drift, RK4"}
    table = checks[checks["metric"].isin(columns)].pivot(index="run_id", columns="metric", values="value")
    table = table.reindex(columns=[c for c in columns if c in table.columns]).rename(columns=columns)
    order = sorted(table.index, key=lambda r: (r == "all", r == "slider", int(r[1:]) if r[1:].isdigit() else 0))
    return Section(
        "Checks of the AD dynamics (not in the paper)", "Per chain: largest relative error over random states "
            "of the mass matrix, the bias force (Coriolis, gravity, damping) and q̈ against MuJoCo's model of the same "
            "chain; full against partial Lagrangian; the closed-form double pendulum (eqs. 17-24 corrected); the "
            "largest joint-angle difference from MuJoCo over the free damped motion (same Euler step); the largest "
            "energy change of the undamped chain over the run, relative to Σ m g r (the energy from horizontal to "
            "hanging).",
        Table(table.loc[order], ".2g", index=True))


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    pd_text = _pd_section(metrics)
    if pd_text:
        sections.append(pd_text)
    one = metrics.get("one-link")
    if one is not None and "free-listing" in set(one["run_id"]):
        free, pd_ = (np.degrees(metric_value(one, f"{case}-listing", "listing_deviation.max"))
                     for case in ("free", "pd"))
        decay, theory = (metric_value(one, "free", key) for key in ("decay_rate", "decay_rate.linear_theory"))
        sections.append(Section(
            "One link (Fig. 1): decay, and Listing A1 against the Lagrange equations",
            f"The free link's swing decays at {decay:.4f} 1/s over its later swings (linear theory {theory:.4f} 1/s, "
            "paper.yaml errata). "
            "The listing's step stores about half of θ̈ as `acc` (I = acc.grad ≈ 2 m l²) and advances ω "
            "by (acc_prev + acc)·dt, which nearly cancels: largest angle difference from the standard AD dynamics "
            f"{free:.3f}° (free) and {pd_:.3f}° (PD), same dt.", category="trajectories"))
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        sections += _compute_time_sections(ct, runs)
    checks = metrics.get("checks")
    if checks is not None and not checks.empty:
        sections.append(_checks_section(checks))
    return sections

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
        note="Our extension: the paper's claims count symbolic terms (section 'Terms of the symbolic equations of "
             "motion'), these are AD times and operations. Evaluations are per state, from short batches of random "
             "states in one CasADi call; MuJoCo's from `rollout` of one mj_step per state. The paper prints no times "
             "(Fig. 5b is an image).")
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
        "Operations in the AD graphs of the terms (CasADi instructions, which share subexpressions instead of "
            "expanding them) beside the paper's term counts without (eq. 28) and with (eq. 29) partial Lagrangians "
            "on n threads:", Table(ops),
        f"Log-log slopes over n = {SLOPE_FROM}..{top} (the paper: 4 without dividing, 3 with partial "
        "Lagrangians on n threads):", Table(slopes, ".2f"), category="compute times")
    return [main, text]


def _term_count_section(counts: pd.DataFrame) -> Section:
    ns = sorted(int(x.rsplit(".n", 1)[1]) for x in counts["metric"] if x.startswith("sym.all_tau.n"))
    value = lambda name: metric_value(counts, "chains", name)   # noqa: E731
    rows = [{"n": n, "terms of L": value(f"sym.lagrangian.n{n}"), "all τ_ki": value(f"sym.all_tau.n{n}"),
             "eq. (28)": value(f"eq28.n{n}"), "column n": value(f"sym.column.n{n}"), "eq. (29)": value(f"eq29.n{n}"),
             "largest τ_ki": value(f"sym.tau_max.n{n}"), "n² + 2n": n * n + 2 * n,
             "work partial / usual": value(f"sym.half.n{n}"), "Table 1 entries": value(f"sym.entries.n{n}"),
             "counting link n [s]": value(f"sym.seconds.link{n}")} for n in ns]
    slopes = ", ".join(f"{label} {value(f'slope.{name}'):.2f}" for name, label in (
        ("all_tau", "all τ_ki"), ("eq28", "eq. (28)"), ("column", "column n"), ("eq29", "eq. (29)"),
        ("tau_max", "largest τ_ki")))
    return Section(
        "Terms of the symbolic equations of motion (eqs. 28-29, 'about half')",
        "Each link's partial Lagrangian in the paper's postural-operator form (eqs. 15-22 generalised to link i: "
        "cos of relative angle sums, every mass, length, stiffness and g a symbol), expanded with SymPy (products "
        "multiplied out, trigonometric functions kept), and τ_ki = D_k L_i (eq. 5). No term of one link merges "
        "with another's, so the usual Lagrangian's τ_k hold exactly the terms of Table 1's entries summed (tested "
        "against expanding L itself). `work partial / usual`: terms × coordinates differentiated, Σ_i 2i·|L_i| "
        "over 2n·|L|; `Table 1 entries`: n(n+1)/2 of n². Counting all ten links takes "
        f"{value('sym.seconds'):.2f} s (a polynomial ring: the same counts as expanding, about 100× faster).",
        Table(pd.DataFrame(rows), ".3g"),
        f"Log-log slopes over n = {SLOPE_FROM}..{ns[-1]}: {slopes}. The paper's formulas fitted over the same n "
        "fall short of their own asymptotic 4 and 3; ours grow faster than both, and the gap between all τ_ki and "
        f"column n, {value('slope_gap.sym'):.2f}, is smaller than eq. (28)/(29)'s: the last column holds most terms.",
        category="compute times")


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
    counts = metrics.get("term-counts")
    if counts is not None and not counts.empty:
        sections.append(_term_count_section(counts))
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        sections += _compute_time_sections(ct, runs)
    checks = metrics.get("checks")
    if checks is not None and not checks.empty:
        sections.append(_checks_section(checks))
    return sections

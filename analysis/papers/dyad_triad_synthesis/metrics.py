"""Metrics of `dyad-triad-synthesis`, one function per experiment: runs -> (run, metric, value, unit) rows.

Lengths in m, angles in rad (the targets convert to the paper's units). Quantities derived from the logged
Δ vectors (the alignment rotation, the parallelogram vector) are arithmetic on the algorithm's own output.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.metrics import MetricTable
from analysis.core.targets import paper_value
from pipeline.core.runlog import Run
from pipeline.papers.dyad_triad_synthesis import burmester

SLUG = "dyad-triad-synthesis"
PRIME = {"": "", "'": "p"}
# Table 5's Δ vectors as printed (targets.csv, in the paper's units) -> their target ids
PRINTED_TABLE5 = {"Δ1": "delta1", "Δ2": "delta2", "Δ3": "delta3", "Δ4": "delta4", "Δ1'": "delta1p",
                  "Δ2'": "delta2p", "Δ3'": "delta3p"}
TOL_ON_CURVE = 1e-9          # |implicit condition| below this: the point lies on the curve (a random point: ~1e-2)
UNIT_CIRCLE = 1e-7           # | |z| − 1 | below this: a complex root is a real rotation


def case(run: Run) -> str:
    """The experiment case a run is of (its run id without the overrides' suffix)."""
    return run.metadata.get("case", run.run_id)


def vectors(run: Run, topic: str) -> dict[str, complex]:
    """A PlanarVectors record -> {name: x + iy}."""
    row = run[topic].iloc[0]
    names = [c.removeprefix("x.") for c in row.index if c.startswith("x.")]
    return {n: complex(row[f"x.{n}"], row[f"y.{n}"]) for n in names}


def scalars(run: Run, topic: str) -> pd.DataFrame:
    """A Scalars topic with its `value.` prefix dropped."""
    frame = run[topic]
    return frame.rename(columns=lambda c: c.removeprefix("value.")).drop(columns=[c for c in frame if
                                                                                 not c.startswith("value.")])


def roots(run: Run, topic: str = "/synthesis/roots") -> pd.DataFrame:
    """One row per logged root: label, branch, β list (rad) and link vectors (complex, m)."""
    frame = run[topic]
    rows = []
    for _, r in frame.iterrows():
        beta = np.array([r[c] for c in frame.columns if c.startswith("beta[")], dtype=float)
        xs = [c for c in frame.columns if c.startswith("x.")]
        links = {c.removeprefix("x."): complex(r[c], r["y." + c.removeprefix("x.")]) for c in xs}
        rows.append({"label": r["label"], "branch": int(r.get("branch", 0)), "beta": beta, **links,
                     "residual": float(r.get("residual", 0.0)), "conditioning": float(r["conditioning"])})
    return pd.DataFrame(rows)


def delta_name(name: str) -> str:
    """'Δ2'' -> 'delta2p' (metric names are ASCII)."""
    return "delta" + name.removeprefix("Δ").replace("'", "p")


# -- table5 ------------------------------------------------------------------------------------------------


def table5(runs: list[Run]) -> MetricTable:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _table5(run))
    return m


def _table5(run: Run) -> dict[str, tuple[float, str]]:
    out: dict[str, tuple[float, str]] = {}

    def add(name: str, value: float, unit: str) -> None:
        out[name] = (float(value), unit)

    delta = vectors(run, "/synthesis/delta")
    for name, z in delta.items():
        add(f"{delta_name(name)}.re", z.real, "m")
        add(f"{delta_name(name)}.im", z.imag, "m")
    # the Δ' loop turned about the head of Δ1 until Δ2' lies along Δ2 (Sec. 2.5)
    rotation = math.remainder(np.angle(delta["Δ2"]) - np.angle(delta["Δ2'"]), 2 * math.pi)
    add("alignment_rotation", rotation, "rad")
    bar = delta["Δ2'"] * np.exp(1j * rotation) - delta["Δ2"]
    add("parallelogram.re", bar.real, "m")
    add("parallelogram.im", bar.imag, "m")
    literal = delta["Δ2"] - delta["Δ2'"]
    add("difference.re", literal.real, "m")
    add("difference.im", literal.imag, "m")
    # Table 5 under the rounding of Table 4's printed digits: the largest change of any component
    spread = run["/synthesis/delta_rounding"]
    base = np.array([[z.real, z.imag] for z in delta.values()]).ravel()
    cols = [c for n in delta for c in (f"x.{n}", f"y.{n}")]
    add("delta.rounding_spread", float(np.abs(spread[cols].to_numpy() - base).max()), "m")
    # β2 ranges: the closing intervals of each loop and of both (the six-bar compatibility linkage)
    ranges = scalars(run, "/synthesis/beta2_range").iloc[0]
    measure = {}
    for loop in ("delta", "delta_prime", "both"):
        lo = [v for k, v in ranges.items() if k.startswith(f"{loop}.") and k.endswith(".lo")]
        hi = [v for k, v in ranges.items() if k.startswith(f"{loop}.") and k.endswith(".hi")]
        measure[loop] = sum(b - a for a, b in zip(lo, hi, strict=True))
        for i, (a, b) in enumerate(zip(lo, hi, strict=True)):
            add(f"beta2_range.{loop}.{i}.lo", a, "rad")
            add(f"beta2_range.{loop}.{i}.hi", b, "rad")
        add(f"beta2_range.{loop}.lower", min(lo), "rad")
        add(f"beta2_range.{loop}.upper", max(hi), "rad")
        add(f"beta2_range.{loop}.measure", measure[loop], "rad")
    add("delta_loop_more_limiting", float(measure["delta"] < measure["delta_prime"]), "bool")
    # the paper against itself: Table 5 as printed closes eqs. (13) and (19) and gives Sec. 2.5's rotation
    unit = run.config["system"]["length_unit"]
    printed = {name: complex(paper_value(SLUG, f"T5.{key}.re"), paper_value(SLUG, f"T5.{key}.im")) * unit
               for name, key in PRINTED_TABLE5.items()}
    add("printed.eq13_residual", abs(printed["Δ1"] + printed["Δ2"] + printed["Δ3"] + printed["Δ4"]), "m")
    add("printed.eq19_residual", abs(printed["Δ1'"] + printed["Δ2'"] + printed["Δ3'"] + printed["Δ4"]), "m")
    turn = math.remainder(np.angle(printed["Δ2"]) - np.angle(printed["Δ2'"]), 2 * math.pi)
    add("printed.alignment_rotation", turn, "rad")
    bar = printed["Δ2'"] * np.exp(1j * turn) - printed["Δ2"]
    add("printed.parallelogram.re", bar.real, "m")
    add("printed.parallelogram.im", bar.imag, "m")
    # the roots
    found = roots(run)
    dyads = found[found["label"] == "solution"].sort_values("W", key=lambda s: s.abs()).reset_index(drop=True)
    add("roots.real", len(found), "count")
    add("roots.special", int(found["label"].isin(["trivial", "special"]).sum()), "count")
    add("dyads", len(dyads), "count")
    add("roots.max_residual", float(found.loc[found["label"] == "solution", "residual"].max()), "m")
    for k, d in dyads.iterrows():
        name = "AB"[k] if k < 2 else str(k)
        for j, b in enumerate(d["beta"][1:], start=2):
            add(f"dyad{name}.beta{j}", b, "rad")
        point = complex(run.config["system"]["table4"]["points"][0][0],
                        run.config["system"]["table4"]["points"][0][1]) * run.config["system"]["length_unit"]
        for part, z in (("W", d["W"]), ("Z", d["Z"]), ("ground", point - d["Z"] - d["W"]),
                        ("moving", point - d["Z"])):
            add(f"dyad{name}.{part}.x", z.real, "m")
            add(f"dyad{name}.{part}.y", z.imag, "m")
    # least-squares Burmester solve: the same dyads?
    direct = vectors(run, "/synthesis/least_squares")
    pairs = [(direct[f"{k}.W"], direct[f"{k}.Z"]) for k in range(len(direct) // 2)]
    add("least_squares.dyads", len(pairs), "count")
    if len(dyads):
        worst = max(min(abs(w - d["W"]) + abs(z - d["Z"]) for w, z in pairs) if pairs else math.inf
                    for _, d in dyads.iterrows())
        add("least_squares.max_difference", worst, "m")
    # every complex root (isotropic coordinates)
    z = np.array(list(vectors(run, "/synthesis/isotropic_roots").values())).reshape(-1, 2)
    add("complex_roots", len(z), "count")
    add("complex_roots.real", int((np.abs(np.abs(z) - 1).max(axis=1) < UNIT_CIRCLE).sum()), "count")
    return out


# -- burmester-curves -------------------------------------------------------------------------------------


def burmester_curves(runs: list[Run]) -> MetricTable:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _burmester_curves(run))
    return m


def _burmester_curves(run: Run) -> dict[str, tuple[float, str]]:
    out: dict[str, tuple[float, str]] = {}

    def add(name: str, value: float, unit: str) -> None:
        out[name] = (float(value), unit)

    points = np.array(list(vectors(run, "/burmester/positions").values()))
    alpha = scalars(run, "/burmester/alpha").iloc[0].to_numpy(dtype=float)
    poles = vectors(run, "/burmester/poles")
    images = vectors(run, "/burmester/image_poles")
    on_center = {k: abs(float(burmester.center_point_condition(points, alpha, v))) for k, v in poles.items()}
    circle_set = {k: poles[k] for k in ("P12", "P13", "P14")} | images
    on_circle = {k: abs(float(burmester.circle_point_condition(points, alpha, v))) for k, v in circle_set.items()}
    pis = vectors(run, "/burmester/pi_points")
    image_pis = vectors(run, "/burmester/image_pi_points")
    pi_center = [abs(float(burmester.center_point_condition(points, alpha, v))) for v in pis.values()]
    pi_circle = [abs(float(burmester.circle_point_condition(points, alpha, v))) for v in image_pis.values()]
    add("poles_on_center_curve", float(max(on_center.values()) < TOL_ON_CURVE), "bool")
    add("poles.max_condition", max(on_center.values()), "")
    add("circle_poles_on_circle_curve", float(max(on_circle.values()) < TOL_ON_CURVE), "bool")
    add("circle_poles.max_condition", max(on_circle.values()), "")
    add("pi_points_on_center_curve", float(max(pi_center) < TOL_ON_CURVE), "bool")
    add("pi_points.max_condition", max(pi_center), "")
    add("image_pi_points_on_circle_curve", float(max(pi_circle) < TOL_ON_CURVE), "bool")
    add("image_pi_points.max_condition", max(pi_circle), "")
    printed = vectors(run, "/burmester/pi_points_printed")["Π12"]
    add("pi12_printed_defined", float(np.isfinite(printed.real)), "bool")
    # a control: the other poles P23, P24, P34 are not circle points
    control = [abs(float(burmester.circle_point_condition(points, alpha, poles[k]))) for k in ("P23", "P24", "P34")]
    add("control.min_condition", min(control), "")
    # the sampled curves satisfy the implicit equations (away from the degenerate special roots)
    curves = scalars(run, "/burmester/curves")
    worst_c, worst_m = 0.0, 0.0
    for b in ("+1", "-1"):
        ok = curves[f"conditioning.branch{b}"] > 1e-6
        c = curves.loc[ok, f"center.x.branch{b}"] + 1j * curves.loc[ok, f"center.y.branch{b}"]
        mv = curves.loc[ok, f"circle.x.branch{b}"] + 1j * curves.loc[ok, f"circle.y.branch{b}"]
        worst_c = max(worst_c, float(np.abs(burmester.center_point_condition(points, alpha, c.to_numpy())).max()))
        worst_m = max(worst_m, float(np.abs(burmester.circle_point_condition(points, alpha, mv.to_numpy())).max()))
    add("curve.max_center_condition", worst_c, "")
    add("curve.max_circle_condition", worst_m, "")
    return out


# -- round-trips -------------------------------------------------------------------------------------------


def round_trips(runs: list[Run]) -> MetricTable:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _round_trips(run))
    return m


def _round_trips(run: Run) -> dict[str, tuple[float, str]]:
    out: dict[str, tuple[float, str]] = {}

    def add(name: str, value: float, unit: str) -> None:
        out[name] = (float(value), unit)

    if case(run) == "table1":
        for name, v in scalars(run, "/table1").iloc[0].items():
            add(name, v, "count")
    elif case(run) == "four-bars":
        d = scalars(run, "/round_trip")
        for k in ("dyad5.error_A", "dyad5.error_B", "dyad4.error_A", "dyad4.error_B"):
            add(f"{k}.max_relative", float((d[k] / d["scale"]).max()), "ratio")
        add("dyad5.recovered", float(((d["dyad5.error_A"] < 1e-8 * d["scale"])
                                      & (d["dyad5.error_B"] < 1e-8 * d["scale"])).mean()), "fraction")
        add("dyad4.recovered", float(((d["dyad4.error_A"] < 1e-8 * d["scale"])
                                      & (d["dyad4.error_B"] < 1e-8 * d["scale"])).mean()), "fraction")
        conditions = d.filter(like="_condition_").to_numpy()
        add("dyad4.pivots_on_curves", float((conditions.max(axis=1) < TOL_ON_CURVE).mean()), "fraction")
        add("dyad5.solutions.min", float(d["dyad5.solutions"].min()), "count")
        add("dyad5.solutions.max", float(d["dyad5.solutions"].max()), "count")
        add("cases", len(d), "count")
    elif case(run).startswith("triad-"):
        d = scalars(run, "/round_trip")
        add("recovered", float(((d["beta_error"] < 1e-8) & (d["vector_error"] < 1e-8 * d["scale"])).mean()),
            "fraction")
        add("beta_error.max", float(d["beta_error"].max()), "rad")
        add("vector_error.max_relative", float((d["vector_error"] / d["scale"]).max()), "ratio")
        add("compatibility_residual.max_relative", float((d["compatibility_residual"] / d["scale"]).max()),
            "ratio")
        add("solutions.min", float(d["solutions"].min()), "count")
        add("solutions.max", float(d["solutions"].max()), "count")
        add("solutions_in_0246", float(d["solutions"].isin([0, 2, 4, 6]).mean()), "fraction")
        add("solutions_odd", float((d["solutions"] % 2 == 1).mean()), "fraction")
        if "newton_roots" in d:
            add("missed_by_grid", float(d["missed_by_grid"].sum()), "count")
            add("newton_roots.max", float(d["newton_roots"].max()), "count")
        add("cases", len(d), "count")
    elif case(run) == "solution-counts":
        d = scalars(run, "/solution_count")
        add("dyads_in_024", float(d["real_dyads"].isin([0, 2, 4]).mean()), "fraction")
        for n in (0, 2, 4):
            add(f"dyads_{n}", float((d["real_dyads"] == n).sum()), "count")
        add("complex_roots_six", float((d["complex_roots"] == 6).mean()), "fraction")
        add("sweep_finds_every_real_root", float((d["real_roots"] == d["complex_roots_real"]).mean()), "fraction")
        add("two_special_roots", float((d["real_roots"] - d["real_dyads"] == 2).mean()), "fraction")
        add("cases", len(d), "count")
    return out


# -- four-bar ----------------------------------------------------------------------------------------------


def four_bar(runs: list[Run]) -> MetricTable:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _four_bar(run))
    return m


def _four_bar(run: Run) -> dict[str, tuple[float, str]]:
    out: dict[str, tuple[float, str]] = {}

    def add(name: str, value: float, unit: str) -> None:
        out[name] = (float(value), unit)

    if case(run) == "defects":
        for name, v in scalars(run, "/defects").iloc[0].items():
            unit = "rad" if ("range" in name or "transmission" in name) else (
                "m" if ("length" in name or "margin" in name) else "")
            add(name, v, unit)
        return out
    gaps = scalars(run, "/joint_gap")
    add("joint_gap.max", float(gaps.to_numpy().max()), "m")
    closed = run["/tracking_error/closed_form"]
    add("closed_form.position.max", float(closed["norm"].max()), "m")
    add("closed_form.coupler.max", float(closed["error.coupler"].abs().max()), "rad")
    if "/precision_position" in run.topic_names:
        pp = scalars(run, "/precision_position")
        e_pos = np.hypot(pp["sim.x"] - pp["target.x"], pp["sim.y"] - pp["target.y"])
        e_ang = np.abs(np.remainder(pp["sim.alpha"] - pp["target.alpha"] + math.pi, 2 * math.pi) - math.pi)
        e_cf = np.hypot(pp["sim.x"] - pp["closed_form.x"], pp["sim.y"] - pp["closed_form.y"])
        for j, ep, ea in zip(pp["position"].astype(int), e_pos, e_ang, strict=True):
            add(f"position{j}.error", ep, "m")
            add(f"position{j}.angle_error", ea, "rad")
        add("positions.max_error", float(e_pos.max()), "m")
        add("positions.max_angle_error", float(e_ang.max()), "rad")
        add("positions.max_closed_form_difference", float(e_cf.max()), "m")
    if "/passage" in run.topic_names:
        err = run["/tracking_error"]
        t = err.index.to_numpy()
        out.update(error_stats(t, err["error.driver"].to_numpy(), "tracking", "rad"))
        passage = scalars(run, "/passage")
        add("passage.max_distance", float(passage["distance"].max()), "m")
        add("passage.max_coupler_error", float(passage["coupler_error"].abs().max()), "rad")
        add("torque.max", float(run["/command"]["value.rocker_B"].abs().max()), "N*m")
    return out


# -- compute-time ------------------------------------------------------------------------------------------


METHODS = ("compatibility_sweep", "least_squares", "random_newton")


def compute_time(runs: list[Run]) -> MetricTable:
    m = MetricTable()
    for run in runs:
        times = run["/compute_time"]
        solvers = scalars(run, "/solvers")
        for method in METHODS:
            cols = [c for c in times.columns if c.startswith(f"seconds.{method}.")]
            per_problem = times[cols]
            m.add_run(run, timing_metrics(method, per_problem.to_numpy(dtype=float).ravel()))
            m.add_run(run, timing_metrics(f"{method}.table4", per_problem[f"seconds.{method}.table4"].dropna()))
            found = solvers[f"{method}.found_of_reference"].sum() / solvers["reference_dyads"].sum()
            m.add(run.run_id, f"{method}.found_fraction", float(found), "fraction", run.params)
            m.add(run.run_id, f"{method}.problems_complete",
                  float((solvers[f"{method}.found_of_reference"] == solvers["reference_dyads"]).mean()), "fraction",
                  run.params)
        m.add(run.run_id, "problems", len(solvers), "count", run.params)
    return m

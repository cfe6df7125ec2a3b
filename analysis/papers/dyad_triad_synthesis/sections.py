"""Report sections of `dyad-triad-synthesis`: what the paper shows only as figures or not at all (the
roots and dyads of the worked example, the four-bar's defects, the Exudyn runs, the round trips, the solvers'
compute time). Lengths in the units of Table 4 (the assumption 1 unit = 1 cm), angles in degrees."""

from __future__ import annotations

import math

import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of
from analysis.core.metrics import metric_value
from analysis.core.sections import Section, Table
from analysis.papers.dyad_triad_synthesis.metrics import METHODS

CM = 100.0          # m -> Table 4 units (1 unit = 1 cm, assumed)
DEG = 180.0 / math.pi


def _worked_example(m: pd.DataFrame) -> Section:
    run = m["run_id"].iloc[0]

    def v(name: str) -> float:
        return metric_value(m, run, name)

    rows = []
    for name in "AB":
        if math.isnan(v(f"dyad{name}.beta2")):
            continue
        rows.append({"dyad": name, **{f"β{j} [deg]": v(f"dyad{name}.beta{j}") * DEG for j in range(2, 6)},
                     **{f"{part}": f"{v(f'dyad{name}.{key}.x') * CM:.4f} {v(f'dyad{name}.{key}.y') * CM:+.4f}i"
                        for part, key in (("W", "W"), ("Z", "Z"), ("ground pivot", "ground"),
                                          ("moving pivot", "moving"))}})
    def arcs(key: str) -> str:
        out = []
        for i in range(8):
            lo, hi = v(f"beta2_range.{key}.{i}.lo"), v(f"beta2_range.{key}.{i}.hi")
            if not math.isnan(lo):
                out.append(f"[{lo * DEG:.2f}, {hi * DEG:.2f}]")
        return " ∪ ".join(out)

    ranges = pd.DataFrame([{"loop": label, "closes on β2 ∈ [deg]": arcs(key),
                            "in all [deg]": v(f"beta2_range.{key}.measure") * DEG}
                           for label, key in (("Δ loop", "delta"), ("Δ' loop", "delta_prime"),
                                              ("both (the six-bar)", "both"))])
    return Section(
        "The worked example (Sec. 2.5): roots, dyads and the β2 range",
        f"Real roots of the two compatibility equations: {v('roots.real'):.0f} (of {v('complex_roots'):.0f} "
            f"complex, {v('complex_roots.real'):.0f} of them on the unit circle); {v('roots.special'):.0f} special "
            f"(β ≡ 0 and β ≡ α), {v('dyads'):.0f} dyads; linear-solve residual ≤ {v('roots.max_residual'):.1e} m. "
            f"The least-squares Burmester solve (no cofactors) finds {v('least_squares.dyads'):.0f} dyads, "
            f"≤ {v('least_squares.max_difference'):.1e} m from these. Table 5 moves by at most "
            f"{v('delta.rounding_spread') * CM:.1e} units when Table 4's inputs move within their printed "
            "rounding.", Table(pd.DataFrame(rows), ".4f"),
        "Where the loops close as β2 turns (the paper reads +116° / −27° off Fig. 12):", Table(ranges, ".2f"),
        category="trajectories")


def _defects(m: pd.DataFrame) -> Section:
    def v(name: str) -> float:
        return metric_value(m, "defects", name)

    lengths = ", ".join(f"{k} {v(f'length.{k}') * CM:.3f}" for k in ("ground", "crank_A", "coupler", "rocker_B"))
    rows = []
    for d in "AB":
        for j in range(1, 5):
            leg = f"{d}.leg{j}{j + 1}"
            rows.append({"driver": d, "leg": f"{j}→{j + 1}",
                         "assemblies": f"{v(f'{d}.branch.{j}'):+.0f} → {v(f'{d}.branch.{j + 1}'):+.0f}",
                         "toggles": v(f"{leg}.toggles"), "tracer path": v(f"{leg}.path_length") * CM,
                         "transmission min [deg]": v(f"{leg}.transmission.min") * DEG,
                         "transmission max [deg]": v(f"{leg}.transmission.max") * DEG,
                         "coupler turns one way": bool(v(f"{leg}.coupler_monotonic"))})
    ranges = "; ".join(f"driver {d} moves over [{v(f'{d}.range.lo') * DEG:.3f}°, {v(f'{d}.range.hi') * DEG:.3f}°]"
                       f", order of the poses on the circuit {'kept' if v(f'{d}.order_kept') else 'broken'}"
                       for d in "AB")
    return Section(
        "The four-bar of dyads A and B: defects (closed-form position analysis)",
        f"Link lengths: {lengths}. Grashof margin p + q − s − l = {v('grashof_margin') * CM:.3f} "
            f"({'Grashof' if v('grashof_margin') >= 0 else 'non-Grashof: a triple rocker, one circuit'}). {ranges}. "
            "A leg whose poses lie on different assemblies of its driver needs a toggle (a dead centre of that "
            "driver): the linkage cannot be driven through 1→2→3→4→5 by one input (a branch defect), though it "
            "visits them in order on its single circuit.", Table(pd.DataFrame(rows), ".3f"), category="trajectories")


def _exudyn(m: pd.DataFrame) -> Section:
    rows = []
    replay = "replay-1to5"
    if replay in set(m["run_id"]):
        for j in range(1, 6):
            rows.append({"position": str(j), "|tracer − P_j| [m]": metric_value(m, replay, f"position{j}.error"),
                         "|coupler − α_j| [rad]": metric_value(m, replay, f"position{j}.angle_error")})
    servo = [r for r in sorted(set(m["run_id"])) if r.startswith("servo-")]
    servo_rows = [{"controller": r.removeprefix("servo-2to5-"),
                   "rocker error RMS [deg]": metric_value(m, r, "tracking.rms") * DEG,
                   "max [deg]": metric_value(m, r, "tracking.max") * DEG,
                   "max torque [N m]": metric_value(m, r, "torque.max"),
                   "tracer vs closed form, max [m]": metric_value(m, r, "closed_form.position.max"),
                   "joint gap, max [m]": metric_value(m, r, "joint_gap.max")} for r in servo]
    return Section(
        "Exudyn: the four-bar as a closed loop",
        "Kinematic replay 1→5 (crank drives 1→2, rocker 2→5; a coordinate constraint on the driver, updated "
            f"every 1 ms step): the tracer differs from the closed-form analysis by at most "
            f"{metric_value(m, replay, 'closed_form.position.max'):.1e} m along the whole path, the joints stay "
            f"closed to {metric_value(m, replay, 'joint_gap.max'):.1e} m.", Table(pd.DataFrame(rows), ".2e"),
        "Servo runs 2→5 (rocker torque, 1 kHz, 4 Hz bandwidth, quintic over 2 s then 0.5 s held, no gravity; "
        "assumed rods of 1 kg/m):", Table(pd.DataFrame(servo_rows), ".3g"), category="tracking errors")


def _round_trips(m: pd.DataFrame) -> Section:
    def v(run: str, name: str) -> float:
        return metric_value(m, run, name)

    rows = [{"case": "dyad, 5 PP (random four-bars)", "recovered": v("four-bars", "dyad5.recovered"),
             "worst relative error": max(v("four-bars", "dyad5.error_A.max_relative"),
                                         v("four-bars", "dyad5.error_B.max_relative")),
             "cases": v("four-bars", "cases"), "real solutions": f"{v('four-bars', 'dyad5.solutions.min'):.0f}–"
                                                                 f"{v('four-bars', 'dyad5.solutions.max'):.0f}"},
            {"case": "dyad, 4 PP at the true β2", "recovered": v("four-bars", "dyad4.recovered"),
             "worst relative error": max(v("four-bars", "dyad4.error_A.max_relative"),
                                         v("four-bars", "dyad4.error_B.max_relative")),
             "cases": v("four-bars", "cases"), "real solutions": "2 per β2"}]
    for n in (5, 6, 7):
        run = f"triad-{n}pp"
        rows.append({"case": f"triad, {n} PP" + (" (free β2, β5 true)" if n == 5 else " (free β2 true)" if n == 6
                                                  else " (no free choice)"),
                     "recovered": v(run, "recovered"), "worst relative error": v(run, "vector_error.max_relative"),
                     "cases": v(run, "cases"), "real solutions": f"{v(run, 'solutions.min'):.0f}–"
                                                                 f"{v(run, 'solutions.max'):.0f}"})
    return Section(
        "Synthetic round trips",
        "Build a linkage, sample its precision positions, re-synthesise: the share of cases whose own links "
            "come back among the solutions (to 1e-8 of their size). Triads alternate grounded and ungrounded "
            f"(h_j ≠ 0). The 7 PP grid search missed {v('triad-7pp', 'missed_by_grid'):.0f} of the roots that "
            "Newton from random starts on all three equations found.", Table(pd.DataFrame(rows), ".3g"),
        category="trajectories")


def _compute_time(m: pd.DataFrame, runs: pd.DataFrame) -> list[Section]:
    run = m["run_id"].iloc[0]
    rows = [(f"{method.replace('_', ' ')}", method, "not reported") for method in METHODS]
    found = pd.DataFrame([{"method": method.replace("_", " "),
                           "dyads found (of the sweep's)": metric_value(m, run, f"{method}.found_fraction"),
                           "problems with every dyad": metric_value(m, run, f"{method}.problems_complete")}
                          for method in METHODS])
    timing = compute_time_section("Compute time: three solvers of the dyad in 5 PP (our extension)", m, run, rows,
                                  machine_of(runs, "compute-time"), unit="ms",
                                  note=f"Over Table 4 and {metric_value(m, run, 'problems') - 1:.0f} random four-bar "
                                       "problems. Timings on a shared machine are noisy: medians.")
    return [timing, Section("The three solvers: dyads found", Table(found, ".2f"), category="compute times")]


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    sections = []
    if "table5" in metrics and not metrics["table5"].empty:
        sections.append(_worked_example(metrics["table5"]))
    four = metrics.get("four-bar")
    if four is not None and "defects" in set(four["run_id"]):
        sections.append(_defects(four))
        sections.append(_exudyn(four))
    trips = metrics.get("round-trips")
    if trips is not None and {"four-bars", "triad-7pp"} <= set(trips["run_id"]):
        sections.append(_round_trips(trips))
    ct = metrics.get("compute-time")
    if ct is not None and not ct.empty:
        sections += _compute_time(ct, runs)
    return sections

"""Analysis of `admittance-assembly`: condition (2) over the two-point state (corners vs interior, random
admittances, single-PC vs two-PC), the quasi-static insertions, and MuJoCo's contact forces against the
quasi-static prediction (force errors)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.errors import error_stats, force_error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run

CASES = ("planar", "spatial")
FORCE = ["force_x", "force_y", "force_z"]
TORQUE = ["torque_x", "torque_y", "torque_z"]
CONTACT_FORCE_ON = 1e-3  # N: a hole feature carries force above this (contact-state agreement)


def _scalars(run: Run, topic: str) -> pd.DataFrame:
    frame = run[topic]
    return frame.rename(columns=lambda c: c.removeprefix("value."))


def _vectors(frame: pd.DataFrame, parts: list[str], name: str) -> np.ndarray:
    return frame[[f"{p}.{name}" for p in parts]].to_numpy()


# -- corner-conditions -------------------------------------------------------------------------------------


def analyze_corner_conditions(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    disagreements = 0
    for run in runs:
        corners, interior = _scalars(run, "/conditions/corners"), _scalars(run, "/conditions/interior")
        interior = interior[interior["valid"] > 0]
        random = _scalars(run, "/conditions/random")
        ok_corner, ok_inside = random["corner_min"] > 0, random["interior_min"] > 0
        ok_single = (random["single_1_min"] > 0) & (random["single_2_min"] > 0)
        ok_two = ok_corner & ok_inside  # the two-PC condition over every sampled configuration
        corners_ok = bool((corners["margin_designed"] > 0).all())
        inside_ok = bool((interior["margin_designed"] > 0).all())
        values = {
            "corners.count": (len(corners), "count"),
            "corners.valid_fraction": (corners["valid"].mean(), "fraction"),
            "corners.satisfied_fraction": ((corners["margin_designed"] > 0).mean(), "fraction"),
            "corners.min_margin": (corners["margin_designed"].min(), "ratio"),
            "corners.min_margin_isotropic": (corners["margin_isotropic"].min(), "ratio"),
            "interior.count": (len(interior), "count"),
            "interior.satisfied_fraction": ((interior["margin_designed"] > 0).mean(), "fraction"),
            "interior.min_margin": (interior["margin_designed"].min(), "ratio"),
            "interior.satisfied_fraction_isotropic": ((interior["margin_isotropic"] > 0).mean(), "fraction"),
            "interior.min_margin_isotropic": (interior["margin_isotropic"].min(), "ratio"),
            "interior.max_force": (interior[["force_1", "force_2"]].to_numpy().max(), "N"),
            "random.count": (len(random), "count"),
            "random.corner_satisfied": (ok_corner.sum(), "count"),
            "random.interior_satisfied": (ok_inside.sum(), "count"),
            "random.counterexamples": ((ok_corner & ~ok_inside).sum(), "count"),
            "random.interior_min_below_corner_min": ((random["interior_min"] < random["corner_min"]).sum(), "count"),
            "random.single_ok_two_fail": ((ok_single & ~ok_two).sum(), "count"),
            "random.two_ok_single_fail": ((ok_two & ~ok_single).sum(), "count"),
            "claim.designed_interior_satisfied": (float(corners_ok and inside_ok), "bool"),
            "claim.no_interior_counterexample": (float(ok_corner.any() and not (ok_corner & ~ok_inside).any()), "bool"),
        }
        disagreements += int(values["random.single_ok_two_fail"][0] + values["random.two_ok_single_fail"][0])
        ct = run["/compute_time"]
        values |= timing_metrics("condition_check", ct["seconds.condition_check"].dropna())
        batch = ct["seconds.condition_check_batch"].dropna() / ct["calls.condition_check_batch"].dropna()
        values |= timing_metrics("condition_check_batch", batch)
        m.add_run(run, values)
        _conditions_figure(run, corners, interior, random, figures)
    if runs:
        m.add("all", "claim.single_pc_not_equivalent", float(disagreements > 0), "bool")
    return m.frame()


def _conditions_figure(run: Run, corners: pd.DataFrame, interior: pd.DataFrame, random: pd.DataFrame,
                       figures: Figures) -> None:
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    sc = ax1.scatter(np.degrees(interior["tilt"]), interior["clearance"] * 1e3, c=interior["margin_designed"], s=3,
                     cmap="viridis")
    ax1.scatter(np.degrees(corners["tilt"]), corners["clearance"] * 1e3, c=corners["margin_designed"], s=60,
                marker="s", edgecolors="k", cmap="viridis", vmin=sc.get_clim()[0], vmax=sc.get_clim()[1])
    fig.colorbar(sc, ax=ax1, label="margin −dᵀv / (‖δ‖·|v0|)")
    ax1.set_xlabel("tilt [deg]")
    ax1.set_ylabel("x clearance per side [mm]")
    ax1.set_title(f"designed A: {(interior['margin_designed'] > 0).mean():.1%} of {len(interior)} interior "
                  "points satisfy (2) (squares: corners)", fontsize=8)
    ok = random["corner_min"] > 0
    ax2.scatter(random["corner_min"][ok], random["interior_min"][ok], s=6, label="(2) holds at every corner")
    ax2.scatter(random["corner_min"][~ok], random["interior_min"][~ok], s=6, c="C3", label="fails at a corner")
    lo = min(random["corner_min"].min(), random["interior_min"].min(), 0.0)
    hi = max(random["corner_min"].max(), random["interior_min"].max(), 0.0)
    pad = 0.05 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    ax2.plot([lo, hi], [lo, hi], "k:", lw=1, label="interior min = corner min")
    ax2.axhline(0, color="k", lw=0.8)
    ax2.axvline(0, color="k", lw=0.8)
    ax2.fill_between([0, hi], lo, 0, color="C3", alpha=0.08, label="counterexamples to the claim")
    ax2.set_xlim(lo, hi)
    ax2.set_ylim(lo, hi)
    ax2.set_xlabel("worst margin at the corners")
    ax2.set_ylabel("worst margin inside")
    ax2.set_title(f"{len(random)} random admittances", fontsize=8)
    ax2.legend(fontsize=7, loc="upper left")
    fig.suptitle(f"{run.run_id}: condition (2) over the two-point contact state")
    figures.save(fig, f"{run.run_id}-conditions")


# -- insertion ------------------------------------------------------------------------------------------------


def _insertion_metrics(run: Run) -> dict:
    err = run["/tracking_error"]["norm"]
    state = _scalars(run, "/assembly")
    contacts = run["/wrench/contacts"]
    forces = np.linalg.norm(np.stack([contacts[[c for c in contacts if c.startswith(f"{f}.")]].to_numpy()
                                      for f in FORCE], axis=-1), axis=-1)
    wrench = run["/wrench"]
    inserted = run.metadata["outcome"] == "inserted"
    two = state["two_point_state"] > 0
    # an inserted run's last sample lies past the mated depth, where ‖δ‖ grows again by construction
    before_end = np.arange(len(state)) < len(state) - (1 if inserted else 0)
    growing = state["d_dot_v"] > 0
    return {
        "inserted": (float(inserted), "bool"),
        "insertion_time": (err.index[-1] if inserted else np.nan, "s"),
        "initial_error": (err.iloc[0], "m"),
        "final_error": (err.iloc[-1], "m"),
        "increasing_steps": (int((growing & before_end).sum()), "count"),
        "increasing_steps_two_point": (int((growing & two & before_end).sum()), "count"),
        "two_point_fraction": (two[before_end].mean(), "fraction"),
        "min_closing_rate_two_point": (state["closing_rate"][two & before_end].min() if (two & before_end).any()
                                       else np.nan, "m/s"),
        "max_contact_force": (np.nanmax(forces) if forces.size else 0.0, "N"),
        "max_total_force": (np.linalg.norm(_vectors(wrench, FORCE, "peg"), axis=1).max(), "N"),
    }


def analyze_insertion(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    groups: dict[str, list[tuple[Run, dict]]] = {}
    for run in runs:
        values = _insertion_metrics(run)
        m.add_run(run, values)
        case, kind, _ = run.metadata["case"].split("-")
        groups.setdefault(f"{case}-{kind}", []).append((run, values))
    for group, items in sorted(groups.items()):
        vals = [v for _, v in items]
        params = items[0][0].params
        m.add(group, "runs", len(items), "count", params)
        m.add(group, "success_rate", np.mean([v["inserted"][0] for v in vals]), "fraction", params)
        m.add(group, "monotone_fraction", np.mean([v["increasing_steps"][0] == 0 for v in vals]), "fraction", params)
        m.add(group, "mean_insertion_time", np.nanmean([v["insertion_time"][0] for v in vals]), "s", params)
        m.add(group, "max_contact_force", max(v["max_contact_force"][0] for v in vals), "N", params)
        m.add(group, "claim.error_never_increases_in_two_point_state",
              float(all(v["increasing_steps_two_point"][0] == 0 for v in vals)), "bool", params)
    for case in CASES:
        runs_of_case = [(r, v) for group, items in groups.items() if group.startswith(case) for r, v in items]
        _insertion_figure(case, runs_of_case, figures)
    return m.frame()


def _insertion_figure(case: str, items: list[tuple[Run, dict]], figures: Figures) -> None:
    if not items:
        return
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
    for run, _ in items:
        kind, trial = run.metadata["case"].split("-")[1:]
        err = run["/tracking_error"]["norm"]
        ax1.plot(err.index, err * 1e3, ls="-" if kind == "designed" else "--", color=f"C{int(trial)}", lw=1.1,
                 label=f"{kind}, start {trial}")
    ax1.set_xlabel("time [s]")
    ax1.set_ylabel("misalignment ‖δ‖ of the tip centre [mm]")
    ax1.legend(fontsize=7, ncol=2)
    first = next((r for r, _ in items if r.metadata["case"] == f"{case}-designed-0"), items[0][0])
    contacts = first["/wrench/contacts"]
    for name in [c.removeprefix("force_x.") for c in contacts if c.startswith("force_x.")]:
        f = np.linalg.norm(_vectors(contacts, FORCE, name), axis=1)
        ax2.plot(contacts.index, f, lw=1.1, label=name)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("contact force λ [N]")
    ax2.set_title(f"{first.run_id}", fontsize=8)
    ax2.legend(fontsize=7)
    fig.suptitle(f"{case}: quasi-static insertions under v = v0 + A·w")
    figures.save(fig, f"{case}-insertions")


# -- mujoco-crosscheck ---------------------------------------------------------------------------------------------


def _contact_forces(run: Run, topic: str) -> tuple[list[str], np.ndarray]:
    frame = run[topic]
    names = [c.removeprefix("force_x.") for c in frame if c.startswith("force_x.")]
    return names, np.linalg.norm(np.stack([_vectors(frame, FORCE, n) for n in names], axis=1), axis=-1)


def analyze_mujoco_crosscheck(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        settle = float(run.config["scenario"]["settle"])
        measured, predicted = run["/wrench"], run["/wrench/predicted"]
        t = measured.index.to_numpy()
        after = t >= settle
        names, f_meas = _contact_forces(run, "/wrench/contacts")
        _, f_pred = _contact_forces(run, "/wrench/contacts/predicted")
        values = {}
        for i in range(2):  # |F_MuJoCo| on a hole feature against the quasi-static one, the reference force
            label = f"c{i + 1}"
            values |= force_error_stats(t[after], f_meas[after, i], f_pred[after, i], f"force_error.{label}")
            values[f"force_error.{label}.reference_mean"] = (f_pred[after, i].mean(), "N")
        dF = np.linalg.norm(_vectors(measured, FORCE, "peg") - _vectors(predicted, FORCE, "peg"), axis=1)
        dM = np.linalg.norm(_vectors(measured, TORQUE, "peg") - _vectors(predicted, TORQUE, "peg"), axis=1)
        values |= {k: v for k, v in error_stats(t[after], dF[after], "wrench_error.force", "N").items()
                   if not k.endswith(".ise")}
        values |= {k: v for k, v in error_stats(t[after], dM[after], "wrench_error.torque", "N*m").items()
                   if not k.endswith(".ise")}
        state_meas, state_pred = f_meas > CONTACT_FORCE_ON, f_pred > CONTACT_FORCE_ON
        values["contact_state_agreement"] = ((state_meas == state_pred).all(axis=1)[after].mean(), "fraction")
        assembly = _scalars(run, "/assembly")
        values["max_penetration"] = (assembly["penetration"].max(), "m")
        values["max_law_residual"] = (assembly["law_residual"][after].max(), "m/s")
        values["contacts"] = (len(names), "count")
        if "/tracking_error/quasi_static" in run.topic_names:
            mj, qs = run["/tracking_error"]["norm"], run["/tracking_error/quasi_static"]["norm"]
            common = mj.index[mj.index <= qs.index[-1]]
            diff = np.abs(mj.loc[common].to_numpy() - np.interp(common, qs.index, qs.to_numpy()))
            values["trajectory_difference.max"] = (diff.max(), "m")
            values["insertion_time.mujoco"] = (mj.index[-1] if run.metadata["outcome"] == "inserted" else np.nan, "s")
            values["insertion_time.quasi_static"] = (qs.index[-1] if run.metadata["quasi_static_outcome"] == "inserted"
                                                     else np.nan, "s")
        m.add_run(run, values)
        _mujoco_figure(run, names, t, f_meas, f_pred, settle, figures)
    return m.frame()


def _mujoco_figure(run: Run, names: list[str], t, f_meas, f_pred, settle: float, figures: Figures) -> None:
    insertion = "/tracking_error/quasi_static" in run.topic_names
    fig, axes = plt.subplots(1, 2 if insertion else 1, figsize=(10 if insertion else 5.5, 3.6), squeeze=False)
    ax = axes[0, 0]
    for i, name in enumerate(names):
        ax.plot(t, f_meas[:, i], color=f"C{i}", lw=1.2, label=f"{name} MuJoCo")
        ax.plot(t, f_pred[:, i], color=f"C{i}", lw=1.0, ls="--", label=f"{name} quasi-static")
    ax.axvline(settle, color="k", ls=":", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("contact force [N]")
    ax.legend(fontsize=6)
    if insertion:
        mj, qs = run["/tracking_error"]["norm"], run["/tracking_error/quasi_static"]["norm"]
        axes[0, 1].plot(mj.index, mj * 1e3, label="MuJoCo")
        axes[0, 1].plot(qs.index, qs * 1e3, ls="--", label="quasi-static")
        axes[0, 1].set_xlabel("time [s]")
        axes[0, 1].set_ylabel("misalignment ‖δ‖ [mm]")
        axes[0, 1].legend()
    fig.suptitle(f"{run.run_id}: MuJoCo contact forces vs the quasi-static prediction at MuJoCo's pose")
    figures.save(fig, run.run_id)


ANALYSES = {"corner-conditions": analyze_corner_conditions, "insertion": analyze_insertion,
            "mujoco-crosscheck": analyze_mujoco_crosscheck}


# -- extra report tables -----------------------------------------------------------------------------------------


def _pivot(frame: pd.DataFrame, metrics: dict[str, str], runs: list[str] | None = None) -> pd.DataFrame:
    part = frame[frame["metric"].isin(metrics)]
    if runs is not None:
        part = part[part["run_id"].isin(runs)]
    table = part.pivot(index="run_id", columns="metric", values="value")
    return table[[k for k in metrics if k in table]].rename(columns=metrics)


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = ["## What can be reproduced\n\nThe paper's text ends inside Sec. I. What survives is the admittance "
                "law v = v0 + A·w (1), the error-reduction condition dᵀ(v0 + A·w) < 0 (2) and the abstract's claim "
                "that an admittance satisfying the conditions at a finite number of configurations of a bounded "
                "contact state satisfies them in between. Every result beyond that (the conditions themselves, "
                "proofs, examples) is **not reproducible**. The runs are the spec's demonstrator: a frictionless, "
                "quasi-static square peg in a square hole in the two-point contact state (a tip vertex on one wall, "
                "the opposite rim against the peg), planar and spatial, with condition (2) itself checked at the "
                "corners of a box of configurations and on a dense interior sample."]
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
        sections.append("## Condition (2) over the two-point state\n\nMargin = −dᵀv / (‖δ‖·|v0|): the rate at "
                        "which the tip's misalignment closes, as a fraction of the nominal speed (> 0: (2) holds). "
                        "The designed A maximises the worst margin at the box corners (SLSQP).\n\n"
                        + table.reset_index().to_markdown(index=False, floatfmt=".4g")
                        + "\n\nRandom admittances (Wishart, trace-normalised) checked at the corners and inside; "
                        "'single-PC' evaluates (2) with each contact alone at the same configurations (Sec. I: the "
                        "two single-PC condition sets are not equivalent to the two-PC set).\n\n"
                        + rand.reset_index().to_markdown(index=False, floatfmt=".4g"))
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
        sections.append("## Quasi-static insertions\n\nFrom the box centre and random starts of the box in the "
                        "real hole (0.1 mm clearance per side), until the tip reaches the mated depth; the last sample "
                        "(past the mated depth) is not counted.\n\n"
                        + table.reset_index().to_markdown(index=False, floatfmt=".4g"))
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
        sections.append("## Force errors: MuJoCo against the quasi-static prediction\n\n"
                        "Measured = MuJoCo's frictionless soft contacts on the peg, summed per hole feature (each "
                        "MuJoCo contact attributed to the nearest candidate); reference = the rigid quasi-static "
                        "force on the same feature at MuJoCo's pose under the same v0 and A (per feature, because "
                        "when a peg face lies flat on a wall only the sum over its contacts is unique). Statistics "
                        "of |F_measured − F_reference| after the settling time (analysis.core.errors."
                        "force_error_stats); sag = largest drop below the reference as a fraction of it. c1: the −x "
                        "wall (the tip's contact), c2: the +x rim: the two principal contacts of the two-point state. "
                        "ΔF, ΔM: the total contact wrench on the peg. These are model-consistency numbers, not "
                        "paper results.\n\n"
                        + _pivot(mj, cols).reset_index().to_markdown(index=False, floatfmt=".3g"))
    return sections

"""`admittance-assembly`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats, force_error_stats
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.admittance_assembly.figures import _conditions_figure, _insertion_figure, _mujoco_figure
from analysis.papers.admittance_assembly.metrics import (
    CASES,
    CONTACT_FORCE_ON,
    FORCE,
    TORQUE,
    _contact_forces,
    _insertion_metrics,
    _scalars,
    _vectors,
)
from pipeline.core.runlog import Run


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


ANALYSES = {"corner-conditions": analyze_corner_conditions, "insertion": analyze_insertion,
            "mujoco-crosscheck": analyze_mujoco_crosscheck}

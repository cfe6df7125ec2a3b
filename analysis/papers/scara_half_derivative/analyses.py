"""`scara-half-derivative`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.scara_half_derivative.figures import (
    _error_figures,
    _map_figure,
    _maps_bands_figure,
    _path_figure,
    _setpoint_figures,
    _stiffness_figure,
    _table2_bands_figure,
)
from analysis.papers.scara_half_derivative.metrics import (
    AXES,
    KD_DAMPING,
    TABLE2,
    _config_node,
    _model,
    _monotonic,
    _percentages,
    _ringing,
    _stiffness_id,
    _tuning,
    aggregate_id,
    equal_ice_locus,
    grid_frame,
    ice_argmin,
    rising_fraction,
    stiffness_bound,
    tuning_metrics,
)
from pipeline.core.runlog import Run
from pipeline.papers.scara_half_derivative.arm import Arm


def analyze_setpoint(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        ref = run["/reference"]
        t = ref.index.to_numpy()
        v = ref[[f"velocity.{a}" for a in AXES]].to_numpy()
        a = ref[[f"acceleration.{a}" for a in AXES]].to_numpy()
        dt = float(t[1] - t[0])
        joints = run["/reference/joints"]
        q = joints[[f"position.theta{i}" for i in range(1, 5)]].to_numpy()
        arm = Arm.from_config(_config_node(run))
        values = {
            "v_max": (float(np.abs(v).max()), "m/s"), "a_max": (float(np.abs(a).max()), "m/s^2"),
            "accel_time": (float(t[np.argmax((t > 0) & (a[:, 0] <= 0))]), "s"),   # the first move is along +x
            "duration": (float(t[np.flatnonzero(np.abs(v).max(axis=1) > 0)[-1]] + dt
                               + run.config["system"]["motion"]["t_stop"]), "s"),
            "theta3p": (arm.theta3p, "rad"), "theta2.min": (float(q[:, 1].min()), "rad"),
            "theta3.max": (float(np.abs(q[:, 2]).max()), "rad"),
            "fk_ik_error.max": (float(run["/setpoint/check"]["value.fk_ik_error"].max()), "m"),
        }
        values |= {f"home.{c}": (float(ref[f"position.{c}"].iloc[0]), "m" if c != "theta" else "rad")
                   for c in (*AXES, "theta")}
        values["table2.stiffness_bound"] = (stiffness_bound(arm, q), "N/m")
        m.add_run(run, values)
        _setpoint_figures(ref, joints, figures)
    return m.frame()


def _table2_metrics(runs: list[Run], m: MetricTable) -> dict[str, dict[str, tuple[Run, dict]]]:
    """Table 2's indexes of every run, the percentages vs KD and the oscillation claim per stiffness and sweep
    point (aggregate id k80000, or k80000__<sweep point>); returns the runs by that id and controller."""
    groups: dict[str, dict[str, tuple[Run, dict]]] = {}
    for run in runs:
        name = run.metadata["case"].rsplit("-k", 1)[0]
        values = tuning_metrics(run) | {"ringing": (_ringing(run), "count")}
        m.add_run(run, values)
        groups.setdefault(aggregate_id(_stiffness_id(_tuning(run)["k_xyz"]), run), {})[name] = (run, values)
    for group, controllers in groups.items():
        if "kd" in controllers:
            reference = controllers["kd"][1]
            for name, (run, values) in controllers.items():
                if name != "kd":
                    _percentages(m, reference, values, run.run_id, run.params, [*TABLE2, "ice"])
        ringing = {name: v["ringing"][0] for name, (_, v) in controllers.items()}
        if {"kd", "kdhd", "khd"} <= set(ringing):
            more = ringing["khd"] > max(ringing["kd"], ringing["kdhd"])
            m.add(group, "claim.khd_more_oscillatory", float(more), "bool")
    return groups


def analyze_table2(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    groups = _table2_metrics(runs, m)
    timings: dict[str, list[np.ndarray]] = {}
    for run in runs:
        law = _model(run)["law"]
        if "/compute_time" in run.topic_names:
            timings.setdefault(law, []).append(run["/compute_time"][f"seconds.{law}"].dropna().to_numpy())
    for law, samples in timings.items():   # every control step of every run of the law
        for metric, (value, unit) in timing_metrics(f"controller.{law}", np.concatenate(samples)).items():
            m.add("all", metric, value, unit)
    for group, controllers in groups.items():
        _error_figures(_tuning(next(iter(controllers.values()))[0])["k_xyz"], controllers, figures, group)
    return m.frame()


def analyze_table2_sensitivity(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    _table2_metrics(runs, m)
    frame = m.frame()
    _table2_bands_figure(frame, figures)
    return frame


def analyze_stiffness(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    _table2_metrics(runs, m)
    frame = m.frame()
    _stiffness_figure(frame, figures)
    return frame


def _maps_metrics(grid: pd.DataFrame, m: MetricTable) -> None:
    """ICE and ISE of every grid point; per stiffness and sweep point: KD's ICE, the equal-ICE line through it
    (eq. 20), where ICE is least along KD's row, and the claims of Sec. 5."""
    for row in grid.to_dict("records"):
        params = {key: row[key] for key in ("k_xyz", "d_xyz", "hd_xyz")}
        m.add(row["run_id"], "ise", row["ise"], "m^2*s", params)
        m.add(row["run_id"], "ice", row["ice"], "N^2*m^2*s", params)
    for group, part in grid.groupby("group"):
        k = float(part["k_xyz"].iloc[0])
        level, points = equal_ice_locus(part)
        m.add(group, "ice.kd", level, "N^2*m^2*s", {"k_xyz": k})
        m.add(group, "ice.argmin_d", ice_argmin(part), "Ns/m", {"k_xyz": k})
        m.add(group, "ice.rising_fraction", rising_fraction(part, "ice"), "fraction", {"k_xyz": k})
        m.add(group, "locus.points", len(points), "count", {"k_xyz": k})
        if len(points) >= 2:
            d, hd = np.array(points).T
            slope, intercept = np.polyfit(d, hd, 1)
            m.add(group, "locus.slope", slope, "s^-0.5", {"k_xyz": k})
            m.add(group, "locus.intercept", intercept, "Ns^0.5/m", {"k_xyz": k})
        m.add(group, "claim.ice_increases", float(_monotonic(part, "ice", +1)), "bool", {"k_xyz": k})
        m.add(group, "claim.ise_decreases", float(_monotonic(part, "ise", -1)), "bool", {"k_xyz": k})


def analyze_maps(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    grid = grid_frame(runs)
    _maps_metrics(grid, m)
    for group, part in grid.groupby("group"):
        _map_figure(float(part["k_xyz"].iloc[0]), part, *equal_ice_locus(part), figures, group)
    return m.frame()


def analyze_maps_sensitivity(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    grid = grid_frame(runs)
    _maps_metrics(grid, m)
    _maps_bands_figure(grid, figures)
    return m.frame()


def analyze_locus(runs: list[Run], figures: Figures | None) -> pd.DataFrame:
    """Fig. 7 per stiffness (and sweep point); `figures` None draws none (the sensitivity sweep)."""
    m = MetricTable()
    grid = grid_frame(runs)
    for row in grid.to_dict("records"):
        params = {key: row[key] for key in ("k_xyz", "d_xyz", "hd_xyz")}
        for name, unit in (("ise", "m^2*s"), ("ice", "N^2*m^2*s"), *((f"tau{i}.max", "Nm") for i in range(1, 5))):
            m.add(row["run_id"], name, row[name], unit, params)
    for sid, path in grid.groupby("group"):   # per stiffness (and sweep point)
        k = float(path["k_xyz"].iloc[0])
        path = path.sort_values("d_xyz", ascending=False)
        kd = path[np.isclose(path["d_xyz"], KD_DAMPING)]
        if kd.empty:
            continue
        ref = kd.iloc[0]
        torques = [f"tau{i}.max" for i in range(1, 4)]
        ratio = path[["ise", "ice", *torques]] / ref[["ise", "ice", *torques]].astype(float)
        m.add(sid, "claim.ise_decreases_along_path", float((np.diff(path["ise"].to_numpy()) < 0).all()), "bool")
        m.add(sid, "ice.max_deviation", float((ratio["ice"] - 1).abs().max()), "fraction")
        middle = path[np.isclose(path["d_xyz"], KD_DAMPING / 2)]
        if not middle.empty:
            change = (ratio.loc[middle.index[0], torques] - 1).abs().max()
            m.add(sid, "middle.max_torque_change", float(change), "fraction")
        if figures is not None:
            _path_figure(k, path, ratio, figures, sid)
    return m.frame()


ANALYSES = {"setpoint": analyze_setpoint, "table2": analyze_table2, "maps": analyze_maps, "locus": analyze_locus,
            "table2-sensitivity": analyze_table2_sensitivity, "maps-sensitivity": analyze_maps_sensitivity,
            "stiffness": analyze_stiffness, "locus-sensitivity": lambda runs, figures: analyze_locus(runs, None)}

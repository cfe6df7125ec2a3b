"""`scara-half-derivative`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.compute_time import timing_metrics
from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.scara_half_derivative.figures import _error_figures, _map_figure, _path_figure, _setpoint_figures
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
    equal_ice_locus,
    grid_frame,
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
        m.add_run(run, values)
        _setpoint_figures(ref, joints, figures)
    return m.frame()


def analyze_table2(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    by_stiffness: dict[float, dict[str, tuple[Run, dict]]] = {}
    timings: dict[str, list[np.ndarray]] = {}
    for run in runs:
        name = run.metadata["case"].rsplit("-k", 1)[0]
        values = tuning_metrics(run) | {"ringing": (_ringing(run), "count")}
        m.add_run(run, values)
        by_stiffness.setdefault(_tuning(run)["k_xyz"], {})[name] = (run, values)
        law = _model(run)["law"]
        timings.setdefault(law, []).append(run["/compute_time"][f"seconds.{law}"].dropna().to_numpy())
    for law, samples in timings.items():   # every control step of every run of the law
        for metric, (value, unit) in timing_metrics(f"controller.{law}", np.concatenate(samples)).items():
            m.add("all", metric, value, unit)
    for k, controllers in by_stiffness.items():
        if "kd" in controllers:
            reference = controllers["kd"][1]
            for name, (run, values) in controllers.items():
                if name != "kd":
                    _percentages(m, reference, values, run.run_id, run.params, [*TABLE2, "ice"])
        ringing = {name: v["ringing"][0] for name, (_, v) in controllers.items()}
        if {"kd", "kdhd", "khd"} <= set(ringing):
            more = ringing["khd"] > max(ringing["kd"], ringing["kdhd"])
            m.add(_stiffness_id(k), "claim.khd_more_oscillatory", float(more), "bool")
        _error_figures(k, controllers, figures)
    return m.frame()


def analyze_maps(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    grid = grid_frame(runs)
    for row in grid.to_dict("records"):
        params = {key: row[key] for key in ("k_xyz", "d_xyz", "hd_xyz")}
        m.add(row["run_id"], "ise", row["ise"], "m^2*s", params)
        m.add(row["run_id"], "ice", row["ice"], "N^2*m^2*s", params)
    for k, part in grid.groupby("k_xyz"):
        sid = _stiffness_id(k)
        level, points = equal_ice_locus(part)
        m.add(sid, "ice.kd", level, "N^2*m^2*s", {"k_xyz": k})
        m.add(sid, "locus.points", len(points), "count", {"k_xyz": k})
        if len(points) >= 2:
            d, hd = np.array(points).T
            slope, intercept = np.polyfit(d, hd, 1)
            m.add(sid, "locus.slope", slope, "s^-0.5", {"k_xyz": k})
            m.add(sid, "locus.intercept", intercept, "Ns^0.5/m", {"k_xyz": k})
        m.add(sid, "claim.ice_increases", float(_monotonic(part, "ice", +1)), "bool", {"k_xyz": k})
        m.add(sid, "claim.ise_decreases", float(_monotonic(part, "ise", -1)), "bool", {"k_xyz": k})
        _map_figure(k, part, level, points, figures)
    return m.frame()


def analyze_locus(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    grid = grid_frame(runs)
    for row in grid.to_dict("records"):
        params = {key: row[key] for key in ("k_xyz", "d_xyz", "hd_xyz")}
        for name, unit in (("ise", "m^2*s"), ("ice", "N^2*m^2*s"), *((f"tau{i}.max", "Nm") for i in range(1, 5))):
            m.add(row["run_id"], name, row[name], unit, params)
    for k, path in grid.groupby("k_xyz"):
        sid = _stiffness_id(k)
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
        _path_figure(k, path, ratio, figures)
    return m.frame()


ANALYSES = {"setpoint": analyze_setpoint, "table2": analyze_table2, "maps": analyze_maps, "locus": analyze_locus}

"""`gripper-force-control`: one analysis per experiment: runs -> tidy metrics, and its figures (ANALYSES)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.papers.gripper_force_control.figures import (
    _cycle_figure,
    _friction_band_figure,
    _sag_figure,
    _steady_figure,
    _surface_figure,
)
from analysis.papers.gripper_force_control.metrics import (
    OURS,
    SAG_CASES,
    SAG_WINDOW,
    STEADY_BELOW,
    SURFACE_WINDOW,
    _config,
    competitor_ratios,
    cycle_times,
    error_ratios,
    grasp_forces,
    motion_window,
    simulated_speed,
    slug,
    tomato_force_limit,
    window_stats,
)
from pipeline.core.runlog import Run
from pipeline.papers.gripper_force_control.drive import move_duration


def analyze_force_sag(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    traces = {}
    for run in runs:
        start, end = motion_window(run)
        m.add_run(run, window_stats(run, start, end + SAG_WINDOW) | simulated_speed(run))
        traces[run.run_id] = grasp_forces(run)
    for case in SAG_CASES:   # the two plants, for every set of overrides that ran both
        for run in runs:
            if run.metadata["case"] != f"{case}-mujoco":
                continue
            overrides = run.run_id.removeprefix(run.metadata["case"])
            lumped = traces.get(f"{case}-lumped{overrides}")
            if lumped is None or len(lumped[0]) != len(traces[run.run_id][0]):
                continue
            difference = np.abs(traces[run.run_id][1] - lumped[1])
            m.add(case + overrides, "plants.max_force_difference", difference.max(), "N", run.params)
            m.add(case + overrides, "plants.rms_force_difference", np.sqrt(np.mean(difference ** 2)), "N", run.params)
    frame = m.frame()
    _sag_figure([run for run in runs if not run.params] or runs, figures)
    return frame


def analyze_friction_band(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Fig. 8's friction cases over M1's Coulomb friction (a sweep): each run's sag, as force-sag measures it."""
    m = MetricTable()
    points = []
    for run in runs:
        start, end = motion_window(run)
        stats = window_stats(run, start, end + SAG_WINDOW)
        coulomb = float(_config(run, "system", "friction", "m1_coulomb"))
        m.add_run(run, stats | {"m1_coulomb": (coulomb, "N m")})
        points.append((run.metadata["case"], coulomb, stats["force_error.sag"][0]))
    sweep = pd.DataFrame(points, columns=["case", "m1_coulomb", "sag"])
    if not sweep.empty:
        _friction_band_figure(sweep, figures)
    return m.frame()


def analyze_force_error_surface(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """One max |F_f − F_set| per (ω_max, ε_max, F_set) run; the surface's maximum over every point on disk
    (Fig. 9 mixes forces of 3-5.7 N), and per force."""
    m = MetricTable()
    points = []
    for run in runs:
        sc = _config(run, "scenario")
        omega, epsilon, force = float(sc["omega"]), float(sc["epsilon"]), float(sc["force"])
        # forward and backward rotation, as the experiment scheduled them (reading /reference costs more)
        move = move_duration(sc["angle"], omega, epsilon)
        end = sc["start"] + 2 * move + sc["pause"]
        stats = window_stats(run, sc["start"], end + SURFACE_WINDOW, tracking=False) | simulated_speed(run)
        m.add_run(run, stats | {"omega": (omega, "rad/s"), "epsilon": (epsilon, "rad/s^2"),
                                "force_set": (force, "N")})
        points.append((omega, epsilon, force, stats["force_error.max"][0]))
    grid = pd.DataFrame(points, columns=["omega", "epsilon", "force", "max_error"])
    if not grid.empty:
        top = grid.loc[grid["max_error"].idxmax()]
        m.add("surface", "force_error.max", top["max_error"], "N")
        m.add("surface", "force_error.max_at_omega", top["omega"], "rad/s")
        m.add("surface", "force_error.max_at_epsilon", top["epsilon"], "rad/s^2")
        m.add("surface", "force_error.max_at_force", top["force"], "N")
        m.add("surface", "force_error.min", grid["max_error"].min(), "N")
        m.add("surface", "points", len(grid), "count")
        for force, part in grid.groupby("force"):
            m.add("surface", f"force_error.max.F{force:g}", part["max_error"].max(), "N")
        for metric, (value, unit) in error_ratios(top["max_error"]).items():
            m.add("surface", metric, value, unit)
        middle = np.median(np.unique(grid["omega"]))
        if (grid["omega"] > middle).any():
            low = grid[grid["omega"] <= middle]["max_error"].max()
            high = grid[grid["omega"] > middle]["max_error"].max()
            m.add("surface", "claim.peaks_at_low_and_medium_velocity", float(low >= high), "bool")
        _surface_figure(grid, figures)
    return m.frame()


def analyze_pick_and_place(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        start, end = motion_window(run)
        times, rotation = cycle_times(run), window_stats(run, start, end)
        m.add_run(run, times | rotation | simulated_speed(run)
                  | competitor_ratios(times["finger_speed.max"][0], times["closing_time"][0])
                  | {"tomato.force_limit": tomato_force_limit(rotation["force_error.max"][0])})
    _cycle_figure(runs, figures)
    return m.frame()


def analyze_steady_state(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        t, measured, commanded = grasp_forces(run)
        window = float(_config(run, "scenario", "window"))
        last = t >= t[-1] - window
        error = measured[last].mean(axis=0) - commanded[-1]
        f_set = commanded[-1]
        values = {"steady_error.max": (np.abs(error).max(), "N"), "steady_error.mean": (error.mean(), "N"),
                  "steady_error.std": (error.std(), "N"),
                  "steady_error.fraction_below_0.5N": ((np.abs(error) < STEADY_BELOW).mean(), "fraction"),
                  "grasps": (error.size, "count")}
        for force in np.unique(f_set):
            values[f"steady_error.max.F{force:g}"] = (np.abs(error[f_set == force]).max(), "N")
            values[f"steady_error.mean.F{force:g}"] = (error[f_set == force].mean(), "N")
        m.add_run(run, values)
        _steady_figure(f_set, error, figures)
    return m.frame()


def analyze_tables(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        rows = run["/tables"]
        values = {}
        speed = rows[rows["table"] == "table3"].set_index("gripper")["value.finger_speed"]
        # the paper's own arithmetic (consistency): its printed speed over each competitor's
        values |= {f"table3.{slug(g)}.printed_arithmetic": (speed[OURS] / v, "ratio")
                   for g, v in speed.drop(OURS).items()}
        text = pd.Series({row.gripper: row[f"value.{row.gripper}"]
                          for _, row in rows[rows["table"] == "text"].iterrows()})
        cycle = 2 * text["open_close_time"] + text["lift_rotate_time"]
        values |= {"text.cycle_time": (cycle, "s"), "text.rate": (60.0 / text["cycle_time"], "1/min"),
                   "text.tomato_force_limit": tomato_force_limit(text["force_error"])}
        model = run["/model"].iloc[0]
        values |= {f"model.{k.removeprefix('value.')}": (float(v), "") for k, v in model.items()
                   if k.startswith("value.")}
        m.add_run(run, values)
    return m.frame()


ANALYSES = {"force-sag": analyze_force_sag, "force-sag-friction": analyze_friction_band,
            "force-error-surface": analyze_force_error_surface,
            "pick-and-place": analyze_pick_and_place, "steady-state": analyze_steady_state,
            "tables": analyze_tables}

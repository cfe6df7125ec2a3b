"""`nmpc-cdkd`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from analysis.core.targets import load_targets
from pipeline.core.runlog import Run
from pipeline.papers.nmpc_cdkd.kinematics import JOINTS, Arm, elbow_rotation

XYZ = ("x", "y", "z")


ARRIVAL_POSITION = 1e-3            # m


ARRIVAL_ANGLE = np.deg2rad(0.5)    # rad


FINAL_WINDOW = 0.5                 # s: "final error" = mean over the last 0.5 s


CONTROL_HORIZON = 0.04             # s: 4 × 10 ms; solves longer than this delay the robot (Sec. 4.2)


TARGETS = Path(__file__).with_name("targets.csv")


SLUG = "nmpc-cdkd"


CASE_LABELS = {"no-obstacle": "without obstacles", "obstacle": "with obstacle",
               "obstacle-height": "with obstacle and height constraints"}


@cache
def paper_table3() -> dict[tuple[str, str, int], tuple[float, float]]:
    """(model, case, k) -> Table 3's (t̄, σ) in ms, from targets.csv."""
    t = load_targets(TARGETS).set_index("target_id")["value"]
    row = "Tab3.{}.N{}.{}.{}".format
    return {(model, case, k): (float(t[row(case, n, short, "mean")]), float(t[row(case, n, short, "std")]))
            for model, short in (("decomposed", "dec"), ("full", "full")) for case in CASE_LABELS
            for n, k in ((1, 10), (2, 20))}


def _xyz(frame: pd.DataFrame, field: str) -> np.ndarray:
    return frame[[f"{field}.{a}" for a in XYZ]].to_numpy()


def _solve_metrics(solves: pd.DataFrame) -> dict[str, tuple[float, str]]:
    """Statistics of the timed solves (a probe's warm-up solve is not timed)."""
    if "timed" in solves:
        solves = solves[solves["timed"].astype(bool)]
    s = solves["seconds"].to_numpy()
    values = {"solve.mean": (s.mean(), "s"), "solve.std": (s.std(), "s"), **timing_metrics("solve", s),
              "solve.samples": (len(s), "count"), "solve.iterations_mean": (solves["iterations"].mean(), "count"),
              "solve.iterations_max": (solves["iterations"].max(), "count"),
              "solve.failures": (int((~solves["success"].astype(bool)).sum()), "count"),
              "solve.over_control_horizon": ((s > CONTROL_HORIZON).mean(), "fraction"),
              "solve.casadi_mean": (solves["solver_seconds"].mean(), "s")}
    return values


def _arrival(run: Run) -> float:
    """First time from which the tool stays within 1 mm of the goal and 0.5° of the desired orientation (the
    angle from the logged quaternion error: |ẽ| = sin(angle / 2))."""
    ref, tool, orient = run["/reference/tool"], run["/tracking_error"], run["/tracking_error/orientation"]
    goal = _xyz(ref, "position")[-1]
    position = _xyz(ref, "position") - _xyz(tool, "error")
    angle = 2 * np.arcsin(np.clip(orient["norm"].to_numpy(), 0, 1))
    inside = (np.linalg.norm(position - goal, axis=1) < ARRIVAL_POSITION) & (angle < ARRIVAL_ANGLE)
    if not inside[-1]:
        return float("nan")
    outside = np.flatnonzero(~inside)
    return float(tool.index[outside[-1] + 1] if len(outside) else tool.index[0])


def _trajectory_metrics(run: Run) -> dict[str, tuple[float, str]]:
    sc = run.config["scenario"]
    tool, wrist, orient = run["/tracking_error"], run["/tracking_error/wrist"], run["/tracking_error/orientation"]
    moving = tool.index >= sc["t0"]
    t = tool.index.to_numpy()[moving]
    final = tool.index.to_numpy() >= tool.index[-1] - FINAL_WINDOW
    values = {**error_stats(t, tool["norm"].to_numpy()[moving], "tool_error", "m"),
              **error_stats(t, wrist["norm"].to_numpy()[moving], "wrist_error", "m"),
              "tool_error.final": (tool["norm"].to_numpy()[final].mean(), "m"),
              "wrist_error.final": (wrist["norm"].to_numpy()[final].mean(), "m"),
              "orientation_error.max_component": (np.abs(_xyz(orient, "error")).max(), "1"),
              **{f"tool_error.max_{a}": (np.abs(tool[f"error.{a}"]).max(), "m") for a in XYZ}}
    arrival = _arrival(run)
    values["arrival"] = (arrival, "s")
    values["arrival_delay"] = (arrival - sc["t1"], "s")
    values |= timing_metrics("planning", run["/compute_time"]["seconds.planning"].dropna())
    values |= _solve_metrics(run["/nmpc/solve"])
    return values


def _obstacle_metrics(run: Run) -> dict[str, tuple[float, str]]:
    clearance = run["/clearance"]
    band = run.config["system"]["scene"]["band"]
    wrist = run["/reference/wrist"]
    ref = _xyz(wrist, "position")
    actual = ref - _xyz(run["/tracking_error/wrist"], "error")
    cols = lambda prefix: [c for c in clearance.columns if c.startswith(f"value.{prefix}.")]  # noqa: E731
    values = {"clearance.margin_min": (clearance[cols("margin")].to_numpy().min(), "m"),
              "clearance.command_margin_min": (clearance[cols("command_margin")].to_numpy().min(), "m"),
              "clearance.tool_min": (clearance[cols("tool")].to_numpy().min(), "m"),
              "wrist.z_rise_max": ((actual[:, 2] - ref[:, 2]).max(), "m"),
              "wrist.z_max": (actual[:, 2].max(), "m"),
              "wrist.xy_deviation_max": (np.linalg.norm(actual[:, :2] - ref[:, :2], axis=1).max(), "m"),
              "wrist.band_violation_upper": (max(0.0, actual[:, 2].max() - band[1]), "m"),
              "wrist.band_violation_lower": (max(0.0, band[0] - actual[:, 2].min()), "m")}
    if cols("mujoco"):
        values["clearance.mujoco_min"] = (clearance[cols("mujoco")].to_numpy().min(), "m")
    for column in cols("margin") + cols("tool"):  # per obstacle: value.margin.I_v -> clearance.margin_min.I_v
        kind, name = column.removeprefix("value.").split(".", 1)
        values[f"clearance.{kind}_min.{name}"] = (clearance[column].min(), "m")
    return values


def _obstacle_layout(run: Run) -> tuple[list[str], np.ndarray, pd.DataFrame]:
    scene = run.config["system"]["scene"]
    return list(scene["obstacles"]["names"]), np.asarray(scene["obstacles"]["radii"]), run["/obstacles"]


TRAJECTORY_COLUMNS = [  # (metric, column, factor from SI)
    ("tool_error.max", "max ‖p̃‖ [mm]", 1e3), ("tool_error.rms", "RMS ‖p̃‖ [mm]", 1e3),
    ("tool_error.final", "final ‖p̃‖ [mm]", 1e3), ("wrist_error.max", "max wrist error [mm]", 1e3),
    ("orientation_error.max_component", "max |ẽ_i|", 1.0), ("arrival_delay", "arrival − t1 [s]", 1.0),
    ("clearance.margin_min", "min (10f) margin [mm]", 1e3),
    ("clearance.command_margin_min", "min (10f) margin, commanded [mm]", 1e3),
    ("clearance.tool_min", "min tool clearance [mm]", 1e3),
    ("clearance.mujoco_min", "min MuJoCo clearance [mm]", 1e3), ("wrist.z_max", "max wrist z [mm]", 1e3),
    ("wrist.xy_deviation_max", "max wrist xy deviation [mm]", 1e3), ("solve.mean", "t̄ solve [ms]", 1e3),
    ("solve.failures", "failed solves", 1.0), ("planning.median", "planning, median [ms]", 1e3)]


def case_config(run: Run) -> dict:
    """The config the run's case simulated (a case may change the experiment's, e.g. the rod length)."""
    attached = run.attachments.get("case_config.yaml")
    return yaml.safe_load(attached) if attached else run.config


def orientation_lag_model(run: Run) -> dict[str, tuple[float, str]]:
    """What eq. (13) itself implies for this move: near alignment ẽ ≈ (θ/2)·n, so q̇_o = J^T K ẽ turns the hand
    at (K/2)·θ toward a desired orientation that {m} carries along at ω_m(t) (the elbow frame of the reference
    joints): the lag settles at θ = 2 ω_m / K. At the lever d_f + d_e it moves the tool tip by 2 sin(θ/2)·lever."""
    system = case_config(run)["system"]
    arm = Arm.from_config(system)
    ref = run["/reference"]
    q_m = ref[[f"position.{j}" for j in JOINTS[:3]]].to_numpy()
    t = ref.index.to_numpy()
    R = elbow_rotation(arm, q_m)
    spin = np.einsum("nji,njk->nik", R, np.gradient(R, t, axis=0))   # Rᵀ Ṙ = S(ω) in {m}
    omega = np.linalg.norm(np.stack([spin[:, 2, 1], spin[:, 0, 2], spin[:, 1, 0]], axis=1), axis=1).max()
    lag = 2 * omega / float(np.min(system["orientation"]["gain"]))
    return {"lag_model.omega_max": (omega, "rad/s"), "lag_model.angle": (lag, "rad"),
            "lag_model.orientation_max": (float(np.sin(lag / 2)), "1"),
            "lag_model.tool_error_max": (float(2 * np.sin(lag / 2) * arm.safety_radius), "m")}

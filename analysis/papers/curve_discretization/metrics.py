"""`curve-discretization`: constants, what is read from a run, and the metrics computed from it."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation
from scipy.stats import theilslopes

from analysis.core.compute_time import timing_metrics
from analysis.core.errors import error_stats
from pipeline.core.runlog import Run

CHECKS = {"on_curve": "/chain/fk", "poe_on_curve": "/chain/poe", "mujoco_on_curve": "/chain/mujoco"}


STAGES = ("search", "angles", "total")


LINEAR_SPREAD = 0.05  # "increases linearly" (our rule for Fig. 3): a robust line fits within 5 % of the median time


PAPER_MACHINE = "MATLAB 7.1, Apple Mac Pro (2008), OS X 10.4.11, 3 GB RAM"


def xyz(frame: pd.DataFrame) -> np.ndarray:
    """(k, 3) points of a CurvePoints record (the first message)."""
    row = frame.iloc[0]
    return np.column_stack([row[[c for c in frame.columns if c.startswith((f"{a}.", f"{a}["))]].to_numpy(float)
                            for a in "xyz"])


def polyline_distance(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Distance of each point to the polyline through `vertices`."""
    a, b = vertices[:-1], vertices[1:]
    ab = b - a
    s = np.einsum("kij,ij->ki", points[:, None] - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    nearest = a + np.clip(s, 0.0, 1.0)[..., None] * ab
    return np.linalg.norm(points[:, None] - nearest, axis=2).min(axis=1)


def _chain_values(run: Run) -> dict:
    P = xyz(run["/chain/curve"])
    t = run["/chain/curve"].filter(like="parameter.").iloc[0].to_numpy(float)
    link = run.config["system"]["chain"]["link_length"]
    distinct = P[np.r_[0, np.arange(1, len(P), 2)]]
    values = {name: (np.linalg.norm(xyz(run[topic]) - P, axis=1).max(), "m") for name, topic in CHECKS.items()}
    tf = run["/tf"].iloc[0]
    q = [tf[f"transforms.joint1.rotation.{c}"] for c in "xyzw"]
    x_axis = Rotation.from_quat(q).as_matrix()[:, 0]
    first = (P[1] - P[0]) / np.linalg.norm(P[1] - P[0])
    curve = xyz(run["/curve"])
    samples = curve[run["/curve"].filter(like="parameter[").iloc[0].to_numpy(float) <= t[-1]]
    sag = polyline_distance(samples, distinct)
    frame = run["/chain/first_frame"].iloc[0]
    values |= {
        "segment_length_error.max": (np.abs(np.linalg.norm(np.diff(distinct, axis=0), axis=1) - link).max(), "m"),
        "first_axis_angle": (np.arctan2(np.linalg.norm(np.cross(x_axis, first)), x_axis @ first), "rad"),
        "tip_parameter": (t[-1], ""),
        "distinct_points": (len(distinct), "count"),
        "theta_z0": (frame["value.theta_z0"], "rad"), "theta_y0": (frame["value.theta_y0"], "rad"),
        "max_abs_theta": (run["/joint_state"].filter(like="position.").abs().to_numpy().max(), "rad"),
        "evaluations": (frame["value.evaluations"], "count"),
        "shape_deviation.max": (sag.max(), "m"), "shape_deviation.rms": (np.sqrt(np.mean(sag ** 2)), "m"),
    }
    return values


def per_call(run: Run, name: str) -> np.ndarray:
    """Seconds per call of one timed algorithm from a run's /compute_time."""
    ct = run["/compute_time"]
    return (ct[f"seconds.{name}"] / ct[f"calls.{name}"]).dropna().to_numpy()


def fit_scaling(joints: np.ndarray, seconds: np.ndarray) -> dict[str, float]:
    """Exponent b of T ∝ N^b (log-log least squares), the affine fit T = a + c·N with its R², and the
    Theil–Sen line with the median |residual| relative to the median time (a few outlying counts, e.g. from a
    burst of load on a shared machine, do not move it; they do move R²)."""
    exponent = np.polyfit(np.log(joints), np.log(seconds), 1)[0]
    c, a = np.polyfit(joints, seconds, 1)
    residual = seconds - (a + c * joints)
    r2 = 1.0 - residual @ residual / np.sum((seconds - seconds.mean()) ** 2)
    slope, intercept, _, _ = theilslopes(seconds, joints)
    spread = np.median(np.abs(seconds - (intercept + slope * joints))) / np.median(seconds)
    return {"exponent": exponent, "per_joint": c, "intercept": a, "r2": r2, "robust_slope": slope, "spread": spread}


def _gait_values(run: Run) -> dict:
    t = run["/tracking_error/shape"].index.to_numpy()
    shape = run["/tracking_error/shape"].filter(like="error.").to_numpy()
    joint = np.abs(run["/tracking_error"].filter(like="error.").to_numpy()).max(axis=1)
    control_dt = run.config["control"]["dt"]
    values = error_stats(t, shape.max(axis=1), "shape_error", "m")
    values["shape_error.tip_max"] = (shape[:, -1].max(), "m")
    values |= error_stats(t, joint, "joint_error", "rad")
    seconds = {name: per_call(run, name) for name in ("search", "angles", "search_warm", "search_cold")}
    seconds["total"] = seconds["search"] + seconds["angles"]
    for name, s in seconds.items():
        values |= timing_metrics(name, s)
    search = run["/search"]
    tau = run["/joint_state"].filter(like="effort.").to_numpy()
    tf = run["/tf"]
    head = tf[["transforms.segment1.translation.x", "transforms.segment1.translation.y"]].to_numpy()
    values |= {
        "ratio.warm_cold_search": (values["search_warm.median"][0] / values["search_cold.median"][0], "ratio"),
        "realtime_ratio": (values["total.p95"][0] / control_dt, "ratio"),
        "evaluations_warm.mean": (search["value.evaluations_warm"].mean(), "count"),
        "evaluations_cold.mean": (search["value.evaluations_cold"].mean(), "count"),
        "warm_cold_gap.max": (search["value.warm_cold_gap"].max(), ""),
        "torque.max_ratio": (np.abs(tau).max() / run.config["snake"]["torque_limit"], "ratio"),
        "head_travel": (np.linalg.norm(head[-1] - head[0]), "m"),
    }
    return values

"""Analysis of `curve-discretization`: the Fig. 2 chain and its checks, the Fig. 3 timing sweep with scaling
exponents, and the MuJoCo snake's shape error and per-step compute time."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation
from scipy.stats import theilslopes

from analysis.core.compute_time import compute_time_section, machine_of, timing_metrics
from analysis.core.errors import error_stats
from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable, metric_value
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


# -- Fig. 2 ------------------------------------------------------------------------------------------------


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


def analyze_bezier(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        m.add_run(run, _chain_values(run))
    by_case = {r.metadata["case"]: r for r in runs}
    paper = by_case.get("paper")
    rolls = [r for case, r in by_case.items() if case != "paper"]
    if paper is not None and rolls:
        fk, P = xyz(paper["/chain/fk"]), xyz(paper["/chain/curve"])
        theta = paper["/joint_state"].filter(like="position.").iloc[0].to_numpy()
        m.add("all", "roll_invariance.fk_position", max(np.abs(xyz(r["/chain/fk"]) - fk).max() for r in rolls), "m")
        m.add("all", "roll_invariance.curve_points", max(np.abs(xyz(r["/chain/curve"]) - P).max() for r in rolls),
              "m")
        m.add("all", "roll_invariance.angle_change",
              max(np.abs(r["/joint_state"].filter(like="position.").iloc[0].to_numpy() - theta).max() for r in rolls),
              "rad")
    if paper is not None:
        _fig2(paper, [paper, *rolls], figures)
    return m.frame()


def _fig2(paper: Run, runs: list[Run], figures: Figures) -> None:
    fig = plt.figure(figsize=(10, 4.2))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    curve, fk, P = xyz(paper["/curve"]), xyz(paper["/chain/fk"]), xyz(paper["/chain/curve"])
    ax.plot(*curve.T, color="0.5", lw=1, label="Bézier curve (19)")
    ax.plot(*fk.T, color="C0", lw=2, label="discrete curve (forward kinematics)")
    ax.scatter(*P.T, color="C3", s=12, label="joint points $p_d(t_j)$")
    ax.set_box_aspect(np.ptp(curve, axis=0))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    ax.set_title(f"Fig. 2: {len(P)} joints, θ_x0 = π/4", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax2 = fig.add_subplot(1, 2, 2)
    for run in runs:
        theta = run["/joint_state"].filter(like="position.").iloc[0].to_numpy()
        roll = run["/chain/first_frame"]["value.theta_x0"].iloc[0]
        ax2.plot(np.arange(1, len(theta) + 1), theta, marker=".", lw=1, label=f"θ_x0 = {roll:.3g}")
    ax2.set_xlabel("joint")
    ax2.set_ylabel("joint angle [rad]")
    ax2.set_title("the angles depend on θ_x0, the joint positions do not (Thm 4.1)", fontsize=9)
    ax2.legend(fontsize=7)
    figures.save(fig, "fig2-bezier-chain")


# -- Fig. 3 ------------------------------------------------------------------------------------------------


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


def analyze_timing(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    rows = []
    for run in runs:
        info = run["/chain/search"].iloc[0]
        values = {"joints": (info["value.joints"], "count"), "evaluations": (info["value.evaluations"], "count"),
                  "segment_length": (info["value.segment_length"], "m")}
        for stage in STAGES:
            seconds = per_call(run, stage)
            values |= timing_metrics(stage, seconds)
            values[f"{stage}.p10"] = (float(np.percentile(seconds, 10)), "s")
        values["search_share"] = (values["search.median"][0] / values["total.median"][0], "fraction")
        m.add_run(run, values)
        rows.append({k: v for k, (v, _) in values.items()})
    table = pd.DataFrame(rows).sort_values("joints")
    fits = {}
    if len(table) >= 3:
        for stage in STAGES:
            fits[stage] = fit_scaling(table["joints"].to_numpy(float), table[f"{stage}.median"].to_numpy())
            m.add("all", f"{stage}.exponent", fits[stage]["exponent"], "")
            m.add("all", f"{stage}.per_joint", fits[stage]["per_joint"], "s")
            m.add("all", f"{stage}.linear_r2", fits[stage]["r2"], "")
            m.add("all", f"{stage}.linear_spread", fits[stage]["spread"], "fraction")
        # linearity is judged on the least-disturbed samples (10th percentile per N), robust to machine noise
        angles = fit_scaling(table["joints"].to_numpy(float), table["angles.p10"].to_numpy())
        m.add("all", "angles.p10.linear_spread", angles["spread"], "fraction")
        m.add("all", "angles.linear", float(angles["robust_slope"] > 0 and angles["spread"] <= LINEAR_SPREAD), "bool")
        m.add("all", "evaluations.exponent",
              np.polyfit(np.log(table["joints"]), np.log(table["evaluations"]), 1)[0], "")
        _fig3(table, fits, figures)
    return m.frame()


def _fig3(table: pd.DataFrame, fits: dict, figures: Figures) -> None:
    n = table["joints"].to_numpy(float)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for stage, color in zip(STAGES, ("C0", "C1", "k"), strict=True):
        us = table[f"{stage}.median"] * 1e6
        axes[0].plot(n, us, color=color, label=f"{stage} (median; exponent {fits[stage]['exponent']:.2f})")
        axes[0].fill_between(n, us, table[f"{stage}.p95"] * 1e6, color=color, alpha=0.15, lw=0)
    axes[0].set_xlabel("number of joints")
    axes[0].set_ylabel("time per call [µs]")
    axes[0].set_title("Fig. 3 (paper: < 35 ms at 100 joints in MATLAB 7.1); band: median to p95", fontsize=9)
    axes[0].legend(fontsize=7)
    f = fits["angles"]
    axes[1].plot(n, table["angles.median"] * 1e6, "C1.", label="angles (median)")
    axes[1].plot(n, (f["intercept"] + f["per_joint"] * n) * 1e6, "k--", lw=1,
                 label=f"{f['intercept'] * 1e6:.2f} µs + {f['per_joint'] * 1e9:.1f} ns × N (R² {f['r2']:.3f})")
    axes[1].set_xlabel("number of joints")
    axes[1].set_ylabel("time per call [µs]")
    axes[1].set_title("angle stage, eqs. (16)-(17): linear in N", fontsize=9)
    axes[1].legend(fontsize=7)
    figures.save(fig, "fig3-time-vs-joints")


# -- the snake -------------------------------------------------------------------------------------------------


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


def analyze_snake(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    all_values = []
    for run in runs:
        values = _gait_values(run)
        m.add_run(run, values)
        all_values.append(values)
        _snake_figure(run, values, figures)
    if all_values:
        for key in ("realtime_ratio", "ratio.warm_cold_search"):
            m.add("all", key, max(v[key][0] for v in all_values), "ratio")
    return m.frame()


def _snake_figure(run: Run, values: dict, figures: Figures) -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    tf = run["/tf"]
    segments = [*sorted({c.split(".")[1] for c in tf.columns if c.startswith("transforms.segment")},
                        key=lambda s: int(s.removeprefix("segment"))), "tip"]
    targets = [c.split(".")[1] for c in tf.columns if c.startswith("transforms.curve/") and c.endswith("translation.x")]
    picks = np.linspace(0, len(tf) - 1, 5).round().astype(int)
    for k, color in zip(picks, plt.cm.viridis(np.linspace(0, 0.9, len(picks))), strict=True):
        row = tf.iloc[k]
        body = np.array([[row[f"transforms.{s}.translation.{a}"] for a in "xy"] for s in segments])
        curve = np.array([[row[f"transforms.{p}.translation.{a}"] for a in "xy"] for p in targets])
        axes[0].plot(*curve.T, color=color, lw=3, alpha=0.35)
        axes[0].plot(*body.T, ".-", color=color, lw=1, ms=4, label=f"t = {tf.index[k]:.1f} s")
    axes[0].set_aspect("equal")
    axes[0].set_title("top view: body (dots) and the curve's joint points fitted to it (wide)", fontsize=9)
    axes[0].legend(fontsize=6, loc="best")
    shape = run["/tracking_error/shape"]
    axes[1].plot(shape.index, shape.filter(like="error.").max(axis=1) * 1e3, label="max over joint points")
    axes[1].plot(shape.index, shape.filter(like="error.").iloc[:, -1] * 1e3, label="tail")
    axes[1].set_xlabel("time [s]")
    axes[1].set_ylabel("shape error [mm]")
    axes[1].set_title(f"body vs curve, best rigid fit (max {values['shape_error.max'][0] * 1e3:.1f} mm)",
                      fontsize=9)
    axes[1].legend(fontsize=7)
    ct = run["/compute_time"]
    for name, label in (("search_cold", "search from scratch (replay)"),
                        ("search_warm", "search warm-started (replay)"),
                        ("search", "search in the control loop"), ("angles", "angles in the control loop")):
        s = ct[f"seconds.{name}"].dropna()
        axes[2].plot(s.index, s * 1e6, lw=0.8, label=label)
    axes[2].set_yscale("log")
    axes[2].set_xlabel("time [s]")
    axes[2].set_ylabel("compute time per control step [µs]")
    axes[2].set_title(f"realtime: p95 total / control period = {values['realtime_ratio'][0]:.4f}", fontsize=9)
    axes[2].legend(fontsize=7)
    fig.suptitle(f"snake, {run.run_id}")
    figures.save(fig, run.run_id)


ANALYSES = {"bezier-fig2": analyze_bezier, "timing-fig3": analyze_timing, "snake-gait": analyze_snake}


# -- extra report tables ------------------------------------------------------------------------------------



def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[str]:
    sections = []
    fig2 = metrics.get("bezier-fig2")
    if fig2 is not None and not fig2.empty:
        checks = fig2[fig2["metric"].isin([*CHECKS, "segment_length_error.max", "first_axis_angle",
                                           "shape_deviation.max", "evaluations"])]
        table = checks[checks["run_id"] != "all"].pivot(index="run_id", columns="metric", values="value")
        sections.append(
            "## Fig. 2 checks\n\nJoint points on the curve against three forward kinematics of the solved angles "
            "(sequential rotations, the POE of eq. (8), MuJoCo's kinematics of the snake model), in curve units. "
            "`shape_deviation` is the chord sag: the largest distance from the curve to the chain.\n\n"
            + table.reset_index().to_markdown(index=False, floatfmt=".3g"))
    fig3 = metrics.get("timing-fig3")
    if fig3 is not None and not fig3.empty:
        machine = machine_of(runs, "timing-fig3")
        sections.append(compute_time_section(
            "Compute time at 100 joints (Fig. 3)", fig3, "joints-100",
            [("search, Subproblem 1 (forward search + bisection)", "search", "most of the total"),
             ("angles, Subproblem 2 (eqs. 15-17)", "angles", "the rest; linear in N"),
             ("total", "total", f"< 35 ms ({PAPER_MACHINE})")], machine,
            note="Compiled Python (numba), dt = 1e-3, tol = 1e-10 in t, chain of total length 14 (link 0.28); "
                 "our goal was ≤ 1 ms at 100 joints. "
                 "The paper's MATLAB times on a 2008 machine are a bound, not a figure to match: the ratio of our "
                 "total to its 35 ms mixes a 15-year hardware gap with interpreted vs compiled code."))
        wanted = [4, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100]
        rows = []
        for n in wanted:
            rid = f"joints-{n:03d}"
            if metric_value(fig3, rid, "joints") != n:
                continue
            rows.append({"joints": n, "link": metric_value(fig3, rid, "segment_length"),
                         "curve evaluations": metric_value(fig3, rid, "evaluations"),
                         **{f"{s} median [µs]": metric_value(fig3, rid, f"{s}.median") * 1e6 for s in STAGES},
                         "total p95 [µs]": metric_value(fig3, rid, "total.p95") * 1e6})
        fits = ", ".join(f"{s} {metric_value(fig3, 'all', f'{s}.exponent'):.2f}" for s in STAGES)
        sections.append(
            "## Time against the number of joints (Fig. 3)\n\n" + pd.DataFrame(rows).to_markdown(index=False,
                                                                                                floatfmt=".3g")
            + f"\n\nScaling exponents b of T ∝ N^b over 4-100 joints: {fits}; curve evaluations "
            f"{metric_value(fig3, 'all', 'evaluations.exponent'):.2f}. Affine fit of the angle stage: "
            f"{metric_value(fig3, 'all', 'angles.per_joint') * 1e9:.1f} ns per joint, R² "
            f"{metric_value(fig3, 'all', 'angles.linear_r2'):.3f}; the Theil–Sen line through the 10th percentiles "
            f"fits them within {metric_value(fig3, 'all', 'angles.p10.linear_spread'):.1%} (median |residual|). "
            "The search's cost is the forward march over the "
            "whole curve (about 1/dt evaluations whatever N) plus ~24 bisection steps per segment, so it grows "
            "less than linearly from a large constant.")
    snake = metrics.get("snake-gait")
    if snake is not None and not snake.empty:
        keys = {"shape_error.max": ("max shape error [mm]", 1e3), "shape_error.rms": ("rms shape error [mm]", 1e3),
                "joint_error.max": ("max joint error [rad]", 1), "total.median": ("per step, median [µs]", 1e6),
                "total.p95": ("per step, p95 [µs]", 1e6), "ratio.warm_cold_search": ("warm / cold search", 1),
                "evaluations_warm.mean": ("curve evals, warm", 1), "evaluations_cold.mean": ("curve evals, cold", 1),
                "torque.max_ratio": ("max torque / limit", 1), "head_travel": ("head travel [m]", 1)}
        gaits = [r for r in snake["run_id"].unique() if r != "all"]
        rows = [{"gait": g, **{label: metric_value(snake, g, k) * scale for k, (label, scale) in keys.items()}}
                for g in gaits]
        sections.append(
            "## Snake robot in MuJoCo (the paper's motivating application)\n\nA 30-joint snake (15 segments of "
            "0.1 m, 14 2-DOF joints) on a floor; at 100 Hz the algorithm turns the travelling wave of that instant "
            "into joint references (warm-started from the previous step), hinge servos track them at 1 kHz. "
            "Shape error: the distance of each joint point of the body from the curve's joint point, the curve "
            "placed on the body by the best rigid motion (least squares).\n\n"
            + pd.DataFrame(rows).to_markdown(index=False, floatfmt=".4g"))
        if "lateral-undulation" in gaits:
            sections.append(compute_time_section(
                "Compute time per control step (snake, lateral undulation)", snake, "lateral-undulation",
                [("search, in the control loop (warm-started)", "search", "not reported"),
                 ("angles, in the control loop", "angles", "not reported"),
                 ("total, in the control loop", "total", "'fast enough to be implemented in real time' (Sec. V)"),
                 ("search warm-started, replayed", "search_warm", "'could be reduced significantly' (Sec. IV-D)"),
                 ("search from scratch, replayed", "search_cold", "")],
                machine_of(runs, "snake-gait"),
                note="In the loop: one call per control step between MuJoCo steps (caches shared with the "
                     "simulation). Replayed: the same searches again after the run, warm-started and from scratch "
                     "alike (time_calls), for a fair comparison."))
    return sections

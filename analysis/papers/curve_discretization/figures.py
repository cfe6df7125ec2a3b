"""`curve-discretization`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.core.targets import paper_value
from analysis.papers.curve_discretization.metrics import STAGES, xyz
from pipeline.core.runlog import Run


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


def _fig3(table: pd.DataFrame, fits: dict, figures: Figures) -> None:
    n = table["joints"].to_numpy(float)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for stage, color in zip(STAGES, ("C0", "C1", "k"), strict=True):
        us = table[f"{stage}.median"] * 1e6
        axes[0].plot(n, us, color=color, label=f"{stage} (median; exponent {fits[stage]['exponent']:.2f})")
        axes[0].fill_between(n, us, table[f"{stage}.p95"] * 1e6, color=color, alpha=0.15, lw=0)
    axes[0].set_xlabel("number of joints")
    axes[0].set_ylabel("time per call [µs]")
    bound = paper_value("curve-discretization", "fig3.total_100", "us")
    axes[0].plot([100], [bound], marker="v", ms=7, ls="none", color="crimson",
                 label=f"paper: < {bound / 1e3:g} ms at 100 joints (MATLAB 7.1, 2008)")
    axes[0].set_yscale("log")   # ours are µs, the paper's bound ms
    axes[0].set_title("Fig. 3: time against the number of joints; band: median to p95", fontsize=9)
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

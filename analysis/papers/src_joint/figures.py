"""`src-joint`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
from matplotlib.patches import Patch

from analysis.core.figures import Figures, paper_hline, plt
from analysis.core.targets import paper_value
from analysis.papers.src_joint.metrics import EULER, SIX, SLUG, _bars
from pipeline.core.runlog import Run


def _joint_figures(plant: str, runs: dict[str, Run], figures: Figures, velocities: bool) -> None:
    """Fig. 9 (rotation error), and with `velocities` Figs. 8 and 10."""
    label = {"mujoco": "MuJoCo", "exact": "exact rolling"}[plant]
    base = runs["corrected"]
    fig, ax = plt.subplots(figsize=(6, 3.2))
    err = base["/tracking_error"]
    for axis in EULER:
        ax.plot(err.index, np.degrees(err[f"error.{axis}"]), label=axis)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("rotation error [deg]")
    peak = paper_value(SLUG, "V-A.peak")   # deg, the paper's bound on the peak (Fig. 9)
    paper_hline(ax, peak, label=f"paper: |peak| < {peak:g}°")
    paper_hline(ax, -peak, label=None)
    ax.set_yscale("symlog", linthresh=1e-6)   # our error (~1e-5°) and the paper bound (0.02°) both readable
    ax.set_title(f"R(q_i) (corrected model) vs {label}: XYZ Euler angles of R_modelᵀ R", fontsize=8)
    ax.legend(fontsize=7)
    figures.save(fig, f"fig9-rotation-error-{plant}")
    if not velocities:
        return
    # Fig. 8: joint velocity, model (1) vs measured
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2), sharex=True)
    measured = base["/joint_state"]
    for ax, axis in zip(axes, "xy", strict=True):
        ax.plot(measured.index, measured[f"velocity.{axis}"], "k", lw=2.5, alpha=0.4, label=f"measured ({label})")
        for variant, run in runs.items():
            if variant != "printed-sign":
                model = run["/joint_state/model"]
                ax.plot(model.index, model[f"velocity.{axis}"], "--", lw=1.2, label=f"eq. (1), {variant}")
        ax.set_title(f"joint velocity ω_{axis} in P_i")
        ax.set_xlabel("t [s]")
    axes[0].set_ylabel("[rad/s]")
    axes[0].legend(fontsize=7)
    figures.save(fig, f"fig8-joint-velocity-{plant}")
    # Fig. 10: spatial velocity, Φ_i w vs measured
    fig, axes = plt.subplots(2, 3, figsize=(10, 5), sharex=True)
    nu = base["/spatial_velocity"]
    for ax, axis in zip(axes.ravel(), SIX, strict=True):
        ax.plot(nu.index, nu[f"value.{axis}"], "k", lw=2.5, alpha=0.4, label=f"measured ({label})")
        for variant in ("corrected", "printed-sign"):
            if variant in runs:
                model = runs[variant]["/spatial_velocity/model"]
                ax.plot(model.index, model[f"value.{axis}"], "--", lw=1.2, label=f"Φ_i w, {variant}")
        ax.set_title(f"{axis} [{'rad/s' if axis[0] == 'w' else 'm/s'}]")
    axes[0, 0].legend(fontsize=7)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    figures.save(fig, f"fig10-spatial-velocity-{plant}")


def _pose_figure(target: str, runs: dict[str, Run], figures: Figures) -> None:
    """Figs. 13/14: end-effector position and orientation errors vs time."""
    fig, axes = plt.subplots(2, 2, figsize=(10, 5.5), sharex=True)
    for col, plant in enumerate(("nominal", "eva-1mm-slip-2pct")):
        if plant not in runs:
            continue
        p, o = runs[plant]["/tracking_error"], runs[plant]["/tracking_error/orientation"]
        for axis in "xyz":
            axes[0, col].plot(p.index, p[f"error.{axis}"] * 1e3, label=axis)
        for axis in EULER:
            axes[1, col].plot(o.index, np.degrees(o[f"error.{axis}"]), label=axis)
        axes[0, col].set_title(f"target {target}, plant {plant}" + (" (FreeBOT-SIM)" if plant == "nominal"
                                                                    else " (hardware stand-in)"))
        axes[1, col].set_xlabel("t [s]")
    axes[0, 0].set_ylabel("position error r^d − r [mm]")
    axes[1, 0].set_ylabel("orientation error, XYZ of R_d Rᵀ [deg]")
    axes[0, 0].legend(fontsize=7)
    axes[1, 0].legend(fontsize=7)
    figures.save(fig, f"fig{13 if target == 'A' else 14}-target-{target}")


def _random_figure(runs: list[Run], figures: Figures) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.2), sharex=True)
    for run in runs:
        label = run.metadata["case"].removesuffix("-nominal")
        p, o = run["/tracking_error"], run["/tracking_error/orientation"]
        axes[0].semilogy(p.index, np.maximum(p["norm"] * 1e3, 1e-6), label=label)
        axes[1].semilogy(o.index, np.maximum(np.degrees(o["norm"]), 1e-6), label=label)
    axes[0].set_ylabel("|r^d − r| [mm]")
    axes[1].set_ylabel("orientation error [deg]")
    for ax in axes:
        ax.set_xlabel("t [s]")
    axes[0].legend(fontsize=7)
    fig.suptitle("targets made by FK of random configurations: convergence of the whole loop (IK, planning, trolleys)")
    figures.save(fig, "reachable-targets")


def _obstacle_figures(runs: dict[str, Run], figures: Figures) -> None:
    run = runs["avoid"]
    # Fig. 16: pose errors
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.2), sharex=True)
    p, o = run["/tracking_error"], run["/tracking_error/orientation"]
    for axis in "xyz":
        axes[0].plot(p.index, p[f"error.{axis}"] * 1e3, label=axis)
    for axis in EULER:
        axes[1].plot(o.index, np.degrees(o[f"error.{axis}"]), label=axis)
    axes[0].set_ylabel("position error [mm]")
    axes[1].set_ylabel("orientation error, XYZ [deg]")
    for ax in axes:
        ax.set_xlabel("t [s]")
        ax.legend(fontsize=7)
    fig.suptitle("target C with velocity-damper avoidance")
    figures.save(fig, "fig16-target-C-errors")
    # Fig. 17: closest distance to each bar
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for case, style in (("avoid", "-"), ("unconstrained", ":")):
        if case not in runs:
            continue
        clearance, check = runs[case]["/clearance"], runs[case]["/clearance/mujoco"]
        for k, bar in enumerate(_bars(clearance)):
            ax.plot(clearance.index, clearance.filter(like=bar).min(axis=1) * 1e3, style, color=f"C{k}",
                    label=f"{bar}, {case}")
            if case == "avoid":
                every = check.iloc[::50]
                ax.plot(every.index, every.filter(like=bar).min(axis=1) * 1e3, "o", ms=3, mfc="none", color=f"C{k}",
                        label=f"{bar}, MuJoCo mj_geomDistance")
    paper_hline(ax, paper_value(SLUG, "V-C.clearance.bar1", "mm"), label="paper: safety distance 10 mm")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("closest distance [mm]")
    ax.legend(fontsize=7, ncol=2)
    figures.save(fig, "fig17-clearance")


def _floor_figure(runs: dict[str, Run], figures: Figures) -> None:
    """Left: the position floor under A and B with the orientation matched, per joint-update mode and reading
    of the target; right: |ε_z| of a joint rolled round a closed loop, literal eq. (5) against exact rolling."""
    fig, (ax, ax_loop) = plt.subplots(1, 2, figsize=(11, 3.8), width_ratios=[1.3, 1])
    bars = [(name, mode, reading, rows) for name in ("A", "B") if name in runs
            for (mode, reading), rows in runs[name]["/reach/floor"].groupby(["mode", "reading"], sort=False)]
    colors = {"incremental": "C0", "global": "C1"}
    for k, (_, mode, _, rows) in enumerate(bars):
        value = 1e3 * rows.loc[rows["weight_m_per_rad"].idxmax(), "position_error_m"]
        ax.bar(k, value, color=colors[mode], edgecolor="k", lw=0.5)
        ax.text(k, value, f"{value:.1f}", ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(bars)), [f"{name}, {reading}, {'exact' if mode == 'incremental' else 'literal'}"
                                     for name, mode, reading, _ in bars], rotation=40, ha="right", fontsize=7)
    ax.legend(handles=[Patch(color=colors["incremental"], label="exact rolling (eq. 5 per step)"),
                       Patch(color=colors["global"], label="eq. 5 read literally (twist allowed)")], fontsize=7)
    ax.set_ylabel("closest position [mm], orientation matched")
    ax.set_title("The floor under Table II's targets A, B per reading of its quaternion (0: reachable)", fontsize=9)
    if "eq5-loop" in runs:
        q = runs["eq5-loop"]["/eq5/joint_quaternion"]
        for mode, style in (("plant", "k-"), ("incremental", "C0--"), ("global", "C1-")):
            ax_loop.plot(q.index, np.abs(q[f"value.{mode}.qz"]), style, label={"plant": "exact rolling plant",
                         "incremental": "model, eq. 5 per step", "global": "model, eq. 5 literal"}[mode])
        ax_loop.set_xlabel("time [s] (Ω^B round a square: +x, +y, −x, −y)")
        ax_loop.set_ylabel("|ε_z| of the joint quaternion q_i")
        ax_loop.set_title("One joint rolled round a closed loop", fontsize=9)
        ax_loop.legend(fontsize=7)
    figures.save(fig, "reach-floor")

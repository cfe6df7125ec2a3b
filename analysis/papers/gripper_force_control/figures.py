"""`gripper-force-control`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import yaml

from analysis.core.figures import Figures, paper_hline, paper_vline, plt
from analysis.core.targets import paper_value
from analysis.papers.gripper_force_control.metrics import SAG_CASES, SLUG, STEADY_BELOW, _config, grasp_forces
from pipeline.core.experiment import CONF_DIR
from pipeline.core.runlog import Run


def _sag_figure(runs: list[Run], figures: Figures) -> None:
    by_case = {run.metadata["case"]: run for run in runs}
    fig, (ax, ax_phi) = plt.subplots(2, 1, figsize=(10, 6), sharex=True, height_ratios=[2, 1])
    for i, case in enumerate(SAG_CASES):
        for plant, style in (("mujoco", "-"), ("lumped", "--")):
            run = by_case.get(f"{case}-{plant}")
            if run is None:
                continue
            t, measured, commanded = grasp_forces(run)
            ax.plot(t * 1e3, measured, style, color=f"C{i}", lw=1.3 if plant == "mujoco" else 1.0,
                    label=f"{case} ({plant})")
    any_run = next(iter(by_case.values()))
    t, _, commanded = grasp_forces(any_run)
    ax.plot(t * 1e3, commanded, "k:", lw=1, label="F_set")
    for i, target in enumerate(("F8.ideal", "F8.friction", "F8.no-ff")):   # the paper's sags, as force floors
        sag = paper_value(SLUG, target, "fraction")
        ax.axhline(commanded[0] * (1 - sag), color=f"C{i}", ls=(0, (6, 3)), lw=0.9, alpha=0.8,
                   label=f"paper: {SAG_CASES[i]} sag {100 * sag:g} %")
    ax.set_ylabel("grasping force F_f [N]")
    ax.set_title("Fig. 8: grasping force during a 40° rotation (MuJoCo: contact force; lumped: pad force)")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))   # beside the traces, not on them
    ref = any_run["/reference"]
    joints = any_run["/joint_state"]
    ax_phi.plot(ref.index * 1e3, np.rad2deg(ref["position.gripper"]), "k:", label="φ_sr")
    ax_phi.plot(joints.index * 1e3, np.rad2deg(joints["position.gripper"]), label="φ_g")
    ax_phi.set_ylabel("gripper angle [°]")
    ax_phi.set_xlabel("time [ms]")
    ax_phi.legend()
    figures.save(fig, "fig8-force-sag")


def _surface_figure(grid: pd.DataFrame, figures: Figures) -> None:
    """The surface (at each (ε, ω) the largest error over the forces run there, as Fig. 9 mixes forces of
    3-5.7 N) and one map per F_set."""
    worst = grid.groupby(["epsilon", "omega"], as_index=False)["max_error"].max()
    table = worst.pivot_table(index="epsilon", columns="omega", values="max_error")
    bound = paper_value(SLUG, "F9.max")
    low, vmax = grid["max_error"].min(), max(bound, grid["max_error"].max())
    forces = sorted(grid["force"].unique())
    fig = plt.figure(figsize=(5.5 + 4.2 * len(forces), 4.4))
    panels = 1 + len(forces)
    if table.shape[0] >= 2 and table.shape[1] >= 2 and not table.isna().any().any():
        ax = fig.add_subplot(1, panels, 1, projection="3d")
        W, E = np.meshgrid(table.columns.to_numpy(), table.index.to_numpy())
        ax.plot_surface(E, W, table.to_numpy(), cmap="viridis", vmin=low, vmax=vmax, edgecolor="k", lw=0.3)
        ax.plot_surface(E, W, np.full_like(E, bound), color="crimson", alpha=0.15)   # the paper's maximum
        ax.set_xlabel("ε_max [rad/s²]")
        ax.set_ylabel("ω_max [rad/s]")
        ax.set_zlabel("max |F_f − F_set| [N]", labelpad=8)
        ax.set_title(f"worst over F_set = {', '.join(f'{f:g}' for f in forces)} N;\nred plane: paper's max "
                     f"{bound:g} N", fontsize=9)
    for k, force in enumerate(forces):
        part = grid[grid["force"] == force]
        ax2 = fig.add_subplot(1, panels, 2 + k)
        sc = ax2.scatter(part["epsilon"], part["omega"], c=part["max_error"], cmap="viridis", s=90, vmin=low,
                         vmax=vmax)
        for row in part.itertuples():
            ax2.annotate(f"{row.max_error:.2f}", (row.epsilon, row.omega), fontsize=6, ha="center", va="bottom",
                         xytext=(0, 5), textcoords="offset points")
        ax2.set_xlabel("ε_max [rad/s²]")
        ax2.set_ylabel("ω_max [rad/s]")
        ax2.set_title(f"F_set = {force:g} N: {len(part)} grid points, max {part['max_error'].max():.2f} N",
                      fontsize=9)
    bar = fig.colorbar(sc, ax=fig.axes[-1], label="max |F_f − F_set| [N]", pad=0.02)
    bar.ax.axhline(bound, color="crimson", lw=2)
    bar.ax.text(1.6, bound, "paper", color="crimson", fontsize=7, va="center", transform=bar.ax.get_yaxis_transform())
    fig.subplots_adjust(left=0.02, right=0.95, bottom=0.12, top=0.88, wspace=0.3)
    figures.save(fig, "fig9-force-error-surface", tight=False)


def _friction_band_figure(sweep: pd.DataFrame, figures: Figures) -> None:
    """Fig. 8's sags over M1's Coulomb friction: the band each friction case spans, the paper's sags, the
    default friction."""
    fig, ax = plt.subplots(figsize=(7, 3.8))
    for i, (case, target) in enumerate((("friction", "F8.friction"), ("no-feedforward", "F8.no-ff"))):
        part = sweep[sweep["case"] == f"{case}-mujoco"].sort_values("m1_coulomb")
        if part.empty:
            continue
        color = f"C{i + 1}"   # the colours of fig8-force-sag
        ax.plot(part["m1_coulomb"] * 1e3, 100 * part["sag"], "o-", color=color,
                label=f"{case} (MuJoCo): band {100 * part['sag'].min():.1f}-{100 * part['sag'].max():.1f} %")
        paper_hline(ax, paper_value(SLUG, target), label=f"paper: {case} {paper_value(SLUG, target):g} %",
                    color=color)
    default = float(yaml.safe_load((CONF_DIR / "system" / f"{SLUG}.yaml").read_text())["friction"]["m1_coulomb"])
    ax.axvline(default * 1e3, color="k", ls=":", lw=1, label=f"default {default * 1e3:g} mN m")
    ax.set_xlabel("M1 Coulomb friction [mN m] (the swept range, fixed from the drive train's class)")
    ax.set_ylabel("force sag [% of F_set]")
    ax.set_title("Fig. 8 band: sag during a 40° rotation over the plausible friction range", fontsize=9)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    figures.save(fig, "fig8-friction-band")


def _cycle_figure(runs: list[Run], figures: Figures) -> None:
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for i, run in enumerate(runs):
        t, measured, commanded = grasp_forces(run)
        joints = run["/joint_state"]
        l_f = float(_config(run, "system", "geometry", "l_f"))
        label = run.metadata["case"]
        axes[0].plot(joints.index * 1e3, joints["velocity.finger"] * l_f, color=f"C{i}", label=label)
        axes[1].plot(t * 1e3, measured, color=f"C{i}", label=label)
        axes[2].plot(joints.index * 1e3, np.rad2deg(joints["position.gripper"]), color=f"C{i}", label=label)
        if i == 0:
            axes[1].plot(t * 1e3, commanded, "k:", label="F_set")
    axes[0].set_ylabel("finger-end speed [m/s]")
    axes[1].set_ylabel("grasping force [N]")
    axes[1].set_yscale("symlog", linthresh=10)
    axes[2].set_ylabel("gripper angle [°]")
    axes[2].set_xlabel("time [ms]")
    for ax in axes:
        ax.legend(fontsize=7)
    axes[0].set_title("Pick and place: close at 8.2 N, turn 45°, open (MuJoCo)")
    figures.save(fig, "pick-and-place")


def _steady_figure(f_set: np.ndarray, error: np.ndarray, figures: Figures) -> None:
    fig, (ax, ax_h) = plt.subplots(1, 2, figsize=(9, 3.4))
    jitter = np.random.default_rng(0).uniform(-0.6, 0.6, f_set.size)
    ax.scatter(f_set + jitter, error, s=8, alpha=0.6)
    bound = paper_value(SLUG, "F7.max")
    paper_hline(ax, bound, label=f"paper: |error| ≤ {bound:g} N (hardware)")
    paper_hline(ax, -bound, label=None)
    ax.set_xlabel("F_set [N]")
    ax.set_ylabel("steady-state error [N]")
    ax.legend(fontsize=7)
    ax.set_title("Fig. 7a stand-in: Monte-Carlo grasps (lumped plant)", fontsize=9)
    ax_h.hist(np.abs(error), bins=20)
    paper_vline(ax_h, STEADY_BELOW, label=f"paper: mostly below {STEADY_BELOW:g} N")
    ax_h.legend(fontsize=7)
    ax_h.set_xlabel("|steady-state error| [N]")
    ax_h.set_ylabel("grasps")
    ax_h.set_title("Fig. 7b stand-in", fontsize=9)
    figures.save(fig, "fig7-monte-carlo")

"""`admittance-assembly`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.papers.admittance_assembly.metrics import FORCE, _vectors
from pipeline.core.runlog import Run


def _conditions_figure(run: Run, corners: pd.DataFrame, interior: pd.DataFrame, random: pd.DataFrame,
                       figures: Figures) -> None:
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    sc = ax1.scatter(np.degrees(interior["tilt"]), interior["clearance"] * 1e3, c=interior["margin_designed"], s=3,
                     cmap="viridis")
    ax1.scatter(np.degrees(corners["tilt"]), corners["clearance"] * 1e3, c=corners["margin_designed"], s=60,
                marker="s", edgecolors="k", cmap="viridis", vmin=sc.get_clim()[0], vmax=sc.get_clim()[1])
    fig.colorbar(sc, ax=ax1, label="margin −dᵀv / (‖δ‖·|v0|)")
    ax1.set_xlabel("tilt [deg]")
    ax1.set_ylabel("x clearance per side [mm]")
    ax1.set_title(f"designed A: {(interior['margin_designed'] > 0).mean():.1%} of {len(interior)} interior "
                  "points satisfy (2) (squares: corners)", fontsize=8)
    ok = random["corner_min"] > 0
    ax2.scatter(random["corner_min"][ok], random["interior_min"][ok], s=6, label="(2) holds at every corner")
    ax2.scatter(random["corner_min"][~ok], random["interior_min"][~ok], s=6, c="C3", label="fails at a corner")
    lo = min(random["corner_min"].min(), random["interior_min"].min(), 0.0)
    hi = max(random["corner_min"].max(), random["interior_min"].max(), 0.0)
    pad = 0.05 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    ax2.plot([lo, hi], [lo, hi], "k:", lw=1, label="interior min = corner min")
    ax2.axhline(0, color="k", lw=0.8)
    ax2.axvline(0, color="k", lw=0.8)
    ax2.fill_between([0, hi], lo, 0, color="C3", alpha=0.08, label="counterexamples to the claim")
    ax2.set_xlim(lo, hi)
    ax2.set_ylim(lo, hi)
    ax2.set_xlabel("worst margin at the corners")
    ax2.set_ylabel("worst margin inside")
    ax2.set_title(f"{len(random)} random admittances", fontsize=8)
    ax2.legend(fontsize=7, loc="upper left")
    fig.suptitle(f"{run.run_id}: condition (2) over the two-point contact state")
    figures.save(fig, f"{run.run_id}-conditions")


def _insertion_figure(case: str, items: list[tuple[Run, dict]], figures: Figures) -> None:
    if not items:
        return
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
    for run, _ in items:
        kind, trial = run.metadata["case"].split("-")[1:]
        err = run["/tracking_error"]["norm"]
        ax1.plot(err.index, err * 1e3, ls="-" if kind == "designed" else "--", color=f"C{int(trial)}", lw=1.1,
                 label=f"{kind}, start {trial}")
    ax1.set_xlabel("time [s]")
    ax1.set_ylabel("misalignment ‖δ‖ of the tip centre [mm]")
    ax1.legend(fontsize=7, ncol=2)
    first = next((r for r, _ in items if r.metadata["case"] == f"{case}-designed-0"), items[0][0])
    contacts = first["/wrench/contacts"]
    for name in [c.removeprefix("force_x.") for c in contacts if c.startswith("force_x.")]:
        f = np.linalg.norm(_vectors(contacts, FORCE, name), axis=1)
        ax2.plot(contacts.index, f, lw=1.1, label=name)
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel("contact force λ [N]")
    ax2.set_title(f"{first.run_id}", fontsize=8)
    ax2.legend(fontsize=7)
    fig.suptitle(f"{case}: quasi-static insertions under v = v0 + A·w")
    figures.save(fig, f"{case}-insertions")


def _mujoco_figure(run: Run, names: list[str], t, f_meas, f_pred, settle: float, figures: Figures) -> None:
    insertion = "/tracking_error/quasi_static" in run.topic_names
    fig, axes = plt.subplots(1, 2 if insertion else 1, figsize=(10 if insertion else 5.5, 3.6), squeeze=False)
    ax = axes[0, 0]
    for i, name in enumerate(names):
        ax.plot(t, f_meas[:, i], color=f"C{i}", lw=1.2, label=f"{name} MuJoCo")
        ax.plot(t, f_pred[:, i], color=f"C{i}", lw=1.0, ls="--", label=f"{name} quasi-static")
    ax.axvline(settle, color="k", ls=":", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("contact force [N]")
    ax.legend(fontsize=6)
    if insertion:
        mj, qs = run["/tracking_error"]["norm"], run["/tracking_error/quasi_static"]["norm"]
        axes[0, 1].plot(mj.index, mj * 1e3, label="MuJoCo")
        axes[0, 1].plot(qs.index, qs * 1e3, ls="--", label="quasi-static")
        axes[0, 1].set_xlabel("time [s]")
        axes[0, 1].set_ylabel("misalignment ‖δ‖ [mm]")
        axes[0, 1].legend()
    fig.suptitle(f"{run.run_id}: MuJoCo contact forces vs the quasi-static prediction at MuJoCo's pose")
    figures.save(fig, run.run_id)

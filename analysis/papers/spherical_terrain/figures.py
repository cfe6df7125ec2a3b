"""`spherical-terrain`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np

from analysis.core.figures import Figures, plt
from analysis.papers.spherical_terrain.metrics import COLOR, LABEL, _terrain
from pipeline.core.runlog import Run
from pipeline.papers.spherical_terrain.kinematics import CosineTerrain
from pipeline.papers.spherical_terrain.tracking import CLASSES


def _surface(ax, terrain: CosineTerrain, extent: float = 2.6) -> None:
    grid = np.linspace(-extent, extent, 41)
    x, y = np.meshgrid(grid, grid)
    ax.plot_wireframe(x, y, terrain.height(x, y), rstride=2, cstride=2, color="0.75", lw=0.4)



def _paths_3d(runs: dict[str, Run], path: str, title: str, figures: Figures, name: str) -> None:
    fig = plt.figure(figsize=(7, 5.5))
    ax = fig.add_subplot(projection="3d")
    some = next(iter(runs.values()))
    _surface(ax, _terrain(some))
    drew_reference = False
    for robot in CLASSES:
        run = runs.get(f"{robot}-{path}")
        if run is None:
            continue
        tf = run["/tf"]
        p = tf[[f"transforms.contact.translation.{a}" for a in "xyz"]].to_numpy()
        ax.plot(*p.T, color=COLOR[robot], lw=1.2, label=LABEL[robot])
        if not drew_reference:
            ref = run["/reference"][[f"position.{a}" for a in "xyz"]].to_numpy()
            ax.plot(*ref.T, "k--", lw=1.0, label="desired")
            drew_reference = True
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_zlabel("Z [m]")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=7)
    figures.save(fig, name)



def _xyz_vs_time(runs: dict[str, Run], path: str, title: str, figures: Figures, name: str) -> None:
    fig, axes = plt.subplots(3, 1, figsize=(8, 6.5), sharex=True)
    for k, axis in enumerate("xyz"):
        drew = False
        for robot in CLASSES:
            run = runs.get(f"{robot}-{path}")
            if run is None:
                continue
            err, ref = run["/tracking_error"], run["/reference"]
            actual = ref[f"position.{axis}"] - err[f"error.{axis}"]
            axes[k].plot(actual.index, actual, color=COLOR[robot], lw=1.0, label=LABEL[robot])
            if not drew:
                axes[k].plot(ref.index, ref[f"position.{axis}"], "k--", lw=1.0, label="desired")
                drew = True
        axes[k].set_ylabel(f"{axis.upper()} [m]")
    axes[0].legend(ncol=5, fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    figures.save(fig, name)



def _controls(runs: dict[str, Run], robot: str, title: str, figures: Figures, name: str) -> None:
    series = [(p, runs[f"{robot}-{p}"]["/command"]) for p in ("circle", "diamond") if f"{robot}-{p}" in runs]
    if not series:
        return
    columns = [c for c in series[0][1].columns if c.startswith("value.")]
    fig, axes = plt.subplots(len(columns), 1, figsize=(8, 2.2 * len(columns)), sharex=True)
    for ax, column in zip(np.atleast_1d(axes), columns, strict=True):
        for path, command in series:
            ax.plot(command.index, command[column], lw=0.8, label=path)
        ax.set_ylabel(column.removeprefix("value.").replace("_dot", " rate") + " [rad/s]")
    np.atleast_1d(axes)[0].legend()
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    fig.suptitle(title)
    figures.save(fig, name)



def _tilt(runs: dict[str, Run], figures: Figures, name: str) -> None:
    fig, ax = plt.subplots(figsize=(8, 2.8))
    limit = None
    for path in ("circle", "diamond"):
        run = runs.get(f"rs-{path}")
        if run is None:
            continue
        phi = run["/joint_state"]["position.phi"]
        ax.plot(phi.index, phi, lw=0.9, label=path)
        limit = run.config["system"]["tilt_limit"]
    if limit is not None:
        for sign in (-1, 1):
            ax.axhline(sign * limit, color="k", ls=":", lw=1)
    ax.set_ylabel("RS-SR tilt φ [rad]")
    ax.set_xlabel("time [s]")
    ax.set_title("Fig. 12(b) regenerated: tilting angle, limit ±π/3 dotted")
    ax.legend()
    figures.save(fig, name)



def _errors(runs: dict[str, Run], title: str, figures: Figures, name: str) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.4), sharey=True)
    for ax, path in zip(axes, ("circle", "diamond"), strict=True):
        for robot in CLASSES:
            run = runs.get(f"{robot}-{path}")
            if run is None:
                continue
            e = run["/tracking_error"]["norm"]
            ax.semilogy(e.index, np.maximum(e, 1e-5), color=COLOR[robot], lw=0.9, label=LABEL[robot])
        ax.axhline(0.1, color="k", ls=":", lw=1)
        ax.axvline(30.0, color="0.5", ls="--", lw=1)
        ax.set_title(path)
        ax.set_xlabel("time [s]")
    axes[0].set_ylabel("‖e_t‖ [m]  (dotted: 0.1 m, dashed: 30 s)")
    axes[0].legend(fontsize=7)
    fig.suptitle(title)
    figures.save(fig, name)

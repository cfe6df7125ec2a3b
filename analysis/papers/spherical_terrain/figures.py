"""`spherical-terrain`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, paper_hline, paper_vline, plt
from analysis.core.targets import paper_value
from analysis.papers.spherical_terrain.metrics import CLAIM_TIME, COLOR, LABEL, SLUG, _terrain
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
    # The pursuit law switches at the control rate: drawn as one line it fills a solid band of ink. One panel
    # per path and rate, the raw command thin and light, its 1 s running mean on top.
    fig, axes = plt.subplots(len(columns), len(series), figsize=(5 * len(series), 2.1 * len(columns)),
                             sharex=True, sharey="row", squeeze=False)
    for row, column in enumerate(columns):
        for col, (path, command) in enumerate(series):
            ax = axes[row, col]
            values = command[column]
            window = max(1, round(1.0 / float(np.median(np.diff(command.index)))))
            ax.plot(command.index, values, lw=0.3, color=f"C{col}", alpha=0.35, label="command")
            ax.plot(command.index, values.rolling(window, center=True, min_periods=1).mean(), lw=1.4,
                    color=f"C{col}", label="1 s running mean")
            if row == 0:
                ax.set_title(path)
            if col == 0:
                ax.set_ylabel(column.removeprefix("value.").replace("_dot", " rate") + " [rad/s]")
    axes[0, 0].legend(fontsize=7, loc="lower right")
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
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
        paper_vline(ax, paper_value(SLUG, "converge.time"), label="paper: converges in ≈ 30 s")
        ax.set_title(path)
        ax.set_xlabel("time [s]")
    axes[0].set_ylabel("‖e_t‖ [m]  (dotted: 0.1 m)")
    axes[0].legend(fontsize=7)
    fig.suptitle(title)
    figures.save(fig, name)


def _sweep_figure(pivot, params: list[str], figures: Figures) -> None:
    """Convergence time of every case per swept setting (x: never within the run)."""
    fig, ax = plt.subplots(figsize=(9, 3.6))
    width = 0.8 / max(1, pivot.shape[1])
    x = np.arange(len(pivot))
    for j, setting in enumerate(pivot.columns):
        values = pivot[setting].to_numpy(dtype=float)
        ax.bar(x + j * width, np.nan_to_num(values, nan=0.0), width, label=setting)
        ax.plot(x[np.isnan(values)] + j * width, np.full(np.isnan(values).sum(), 1.0), "kx")
    paper_hline(ax, paper_value(SLUG, "converge.time"), label="paper: ≈ 30 s")
    ax.set_xticks(x + 0.4 - width / 2, pivot.index, rotation=30, fontsize=7)
    ax.set_ylabel("t_c(0.1 m) [s]  (x: never)")
    ax.set_title(f"Sweep over {', '.join(params)}")
    ax.legend(fontsize=6, ncol=2)
    figures.save(fig, "sweep-convergence-time")


def _gain_search_figure(table: pd.DataFrame, figures: Figures) -> None:
    """RS-SR over the searched gains: convergence time on the circle, and on the diamond the largest error
    after 40 s (the vicinity it stays in), with the unit default and the search's best pair outlined."""
    panels = (("circle", "tc_0.1", "t_c(0.1 m) [s] (x: never)", "{:.0f}", (0, 2 * CLAIM_TIME)),
              ("diamond", "error_after_40s.max", "max error after 40 s [m]", "{:.2f}", (0, None)))
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.9), sharey=True)
    for ax, (path, metric, label, fmt, (low, high)) in zip(axes, panels, strict=True):
        grid = table.pivot_table(index="k_phi", columns="k_alpha", values=f"{path}.{metric}", dropna=False)
        values = grid.to_numpy(dtype=float)
        image = ax.imshow(np.ma.masked_invalid(values), origin="lower", cmap="viridis_r", vmin=low, vmax=high,
                          aspect="auto")
        for (i, j), value in np.ndenumerate(values):
            ax.text(j, i, "x" if np.isnan(value) else fmt.format(value), ha="center", va="center", fontsize=8,
                    color="k", bbox={"fc": "w", "ec": "none", "alpha": 0.7, "pad": 1})
        ax.set_xticks(range(grid.shape[1]), [f"{v:g}" for v in grid.columns])
        ax.set_yticks(range(grid.shape[0]), [f"{v:g}" for v in grid.index])
        ax.set_xlabel("k_α")
        ax.set_title(f"RS-SR, {path}: {label}", fontsize=9)
        ax.grid(False)
        fig.colorbar(image, ax=ax, shrink=0.85)
        for mark, rows, style in (("unit default", table[(table["k_alpha"] == 1) & (table["k_phi"] == 1)],
                                   {"edgecolor": "k", "ls": ":"}),
                                  ("best of the search", table[table["best"]], {"edgecolor": "crimson", "ls": "-"})):
            for row in rows.itertuples():
                j, i = list(grid.columns).index(row.k_alpha), list(grid.index).index(row.k_phi)
                ax.add_patch(plt.Rectangle((j - 0.48, i - 0.48), 0.96, 0.96, fill=False, lw=2, label=mark, **style))
    axes[0].set_ylabel("k_φ")
    axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(0, -0.15), ncol=2)
    fig.suptitle(f"Disclosed RS-SR gain search ({len(table)} pairs; converges: t_c(0.1 m) ≤ {CLAIM_TIME:g} s on "
                 "both paths)", fontsize=10)
    figures.save(fig, "gain-search")


def _physics_figure(traces: list, figures: Figures) -> None:
    """Contact speed against the paper's model, slip, and tracking error against the kinematic model."""
    fig, axes = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    for robot, t, moving, ratio, slip, e, e_kin in traces:
        axes[0].plot(t[moving], ratio, ".", ms=1, color=COLOR[robot], label=LABEL[robot])
        axes[1].semilogy(t, np.maximum(slip, 1e-6), color=COLOR[robot], lw=0.6)
        axes[2].semilogy(t, np.maximum(e, 1e-5), color=COLOR[robot], lw=0.9, label=f"{LABEL[robot]} MuJoCo")
        axes[2].semilogy(e_kin.index, np.maximum(e_kin, 1e-5), color=COLOR[robot], lw=0.7, ls=":")
    axes[0].set_ylabel("contact speed:\nMuJoCo / paper model")
    axes[0].set_ylim(0.5, 1.5)
    axes[0].legend(fontsize=7, markerscale=8)
    axes[1].set_ylabel("slip speed [m/s]")
    axes[2].set_ylabel("‖e_t‖ [m]\n(dotted: kinematic)")
    axes[2].set_xlabel("time [s]")
    fig.suptitle("Physics check: ball on a MuJoCo height field, the paper's controller in closed loop")
    figures.save(fig, "physics-check")

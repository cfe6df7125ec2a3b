"""`nmpc-cdkd`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import PAPER_STYLE, Figures, plt
from analysis.core.metrics import metric_value
from analysis.core.targets import paper_value
from analysis.papers.nmpc_cdkd.metrics import CASE_LABELS, SLUG, XYZ, _obstacle_layout, _xyz
from pipeline.core.runlog import Run


def _interval(frame: pd.DataFrame, metric: str) -> tuple[float, float, float]:
    """(median, low, high) of a `table3` metric with its 95 % interval."""
    return tuple(metric_value(frame, "table3", name) for name in (metric, f"{metric}.ci_low", f"{metric}.ci_high"))


def _with_interval(ax, x: float, values: tuple[float, float, float], color: str, label: str | None,
                   scale: float = 1.0) -> None:
    median, low, high = (v * scale for v in values)
    ax.errorbar([x], [median], yerr=[[median - low], [high - median]], fmt="o", color=color, ms=4, capsize=3,
                label=label)


def _table3_figure(frame: pd.DataFrame, figures: Figures) -> None:
    """Table 3 as intervals: t̄ per cell, the time ratio, the σ ratio and the N1→N2 growth, ours (median and 95 %
    bootstrap interval over the moves) beside the paper's."""
    if frame.empty or "table3" not in set(frame["run_id"]):
        return
    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    cells = [(case, k) for case in CASE_LABELS for k in (10, 20)]
    labels = [f"{case.replace('obstacle', 'obst')} N{1 if k == 10 else 2}" for case, k in cells]
    x = np.arange(len(cells))
    for offset, model, color in ((-0.12, "decomposed", "C0"), (0.12, "full", "C1")):
        for i, (case, k) in enumerate(cells):
            _with_interval(axes[0, 0], i + offset, _interval(frame, f"mean.{model}.{case}.k{k}"), color,
                           model if i == 0 else None, 1e3)
    axes[0, 0].set_ylabel("t̄ per OCP step [ms] (ours)")
    axes[0, 0].set_title("(a) mean solve time, 95 % interval")
    for ax, name, title in ((axes[0, 1], "ratio", "(b) t̄ decomposed / t̄ full"),
                            (axes[1, 0], "sigma_ratio", "(c) σ decomposed / σ full")):
        for i, (case, k) in enumerate(cells):
            _with_interval(ax, i, _interval(frame, f"{name}.{case}.k{k}"), "C0", "ours" if i == 0 else None)
            ax.plot(i, paper_value(SLUG, f"Tab3.{case}.N{1 if k == 10 else 2}.{name}"), "x", ms=7,
                    **{k: v for k, v in PAPER_STYLE.items() if k == "color"}, label="paper" if i == 0 else None)
        ax.set_title(title)
        ax.set_ylabel("ratio")
    for ax in (axes[0, 0], axes[0, 1], axes[1, 0]):
        ax.set_xticks(x, labels, rotation=30, ha="right", fontsize=7)
        ax.legend(fontsize=7)
    growth = [(model, case) for model in ("decomposed", "full") for case in CASE_LABELS]
    for i, (model, case) in enumerate(growth):
        _with_interval(axes[1, 1], i, _interval(frame, f"growth.{model}.{case}"), "C0" if model == "decomposed"
                       else "C1", "ours" if i == 0 else None, 100)
        short = "dec" if model == "decomposed" else "full"
        axes[1, 1].plot(i, 100 * paper_value(SLUG, f"Tab3.{case}.growth.{short}"), "x", ms=7,
                        color=PAPER_STYLE["color"], label="paper" if i == 0 else None)
    axes[1, 1].set_xticks(range(len(growth)), [f"{m[:4]} {c.replace('obstacle', 'obst')}" for m, c in growth],
                          rotation=30, ha="right", fontsize=7)
    axes[1, 1].set_ylabel("t̄(N2) / t̄(N1) − 1 [%]")
    axes[1, 1].set_title("(d) growth from N1 = 100 ms to N2 = 200 ms")
    axes[1, 1].legend(fontsize=7)
    moves = int(metric_value(frame, "table3", "moves"))
    fig.suptitle(f"Table 3 over {moves} moves per cell (bootstrap over moves, 95 % intervals)")
    figures.save(fig, "table3-solve-times")


def _components_figure(runs: list[Run], figures: Figures, name: str, title: str) -> None:
    """Figs. 5 and 7: tool position components vs time, reference dashed."""
    fig, axes = plt.subplots(1, len(runs), figsize=(4.2 * len(runs), 3.2), sharey=True, squeeze=False)
    for ax, run in zip(axes[0], runs, strict=True):
        ref = run["/reference/tool"]
        actual = _xyz(ref, "position") - _xyz(run["/tracking_error"], "error")
        for i, a in enumerate(XYZ):
            ax.plot(ref.index, actual[:, i] * 1e3, color=f"C{i}", label=f"$p_{a}$")
            ax.plot(ref.index, ref[f"position.{a}"] * 1e3, color=f"C{i}", ls="--", lw=1, label=f"$p_{{{a},des}}$")
        ax.set_title(run.run_id)
        ax.set_xlabel("t [s]")
    axes[0, 0].set_ylabel("tool position [mm]")
    axes[0, 0].legend(ncol=2, fontsize=7)
    fig.suptitle(title)
    figures.save(fig, name)


def _fig3(run: Run, figures: Figures) -> None:
    tool, orient, ref = run["/tracking_error"], run["/tracking_error/orientation"], run["/reference/tool"]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2))
    actual = _xyz(ref, "position") - _xyz(tool, "error")
    for i, a in enumerate(XYZ):
        axes[0].plot(ref.index, actual[:, i] * 1e3, color=f"C{i}", label=f"$p_{a}$")
        axes[0].plot(ref.index, ref[f"position.{a}"] * 1e3, color=f"C{i}", ls="--", lw=1)
        axes[1].plot(tool.index, tool[f"error.{a}"] * 1e3, color=f"C{i}", label=f"$\\tilde p_{a}$")
        axes[2].plot(orient.index, orient[f"error.{a}"], color=f"C{i}", label=f"$\\tilde e_{a}$")
    axes[1].plot(tool.index, tool["norm"] * 1e3, "k", label="$\\|\\tilde p\\|$")
    for ax, ylabel, title in zip(axes, ("tool position [mm]", "tool position error [mm]", "quaternion error (11)"),
                                 ("(a) tracking, dashed: des", "(b) $p_{des} - p$", "(c) orientation error"),
                                 strict=True):
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.legend(fontsize=7)
    fig.suptitle(f"Fig. 3 ({run.run_id}, d_e = {run.config['system']['dh']['tool_d'] * 1e3:g} mm): no obstacles, "
                 "t0 = 0.5 s, t1 = 2 s")
    figures.save(fig, f"fig3-{run.run_id}")


def _paths_figure(runs: list[Run], figures: Figures, name: str, title: str) -> None:
    fig = plt.figure(figsize=(6.5, 5))
    ax = fig.add_subplot(projection="3d")
    ref = runs[0]["/reference/tool"]
    ax.plot(*(ref[f"position.{a}"] * 1e3 for a in XYZ), "b--", label="reference")
    for i, run in enumerate(runs):
        tool = _xyz(run["/reference/tool"], "position") - _xyz(run["/tracking_error"], "error")
        ax.plot(*(tool.T * 1e3), color=("C1", "C3", "C2")[i % 3], label=f"case {run.run_id}")
    names, radii, centres = _obstacle_layout(runs[0])
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 16), np.linspace(0, np.pi, 9))
    for n, r in zip(names, radii, strict=True):
        c = np.array([centres[f"value.{n}.{a}"].iloc[0] for a in XYZ]) * 1e3
        ax.plot_surface(c[0] + r * 1e3 * np.cos(u) * np.sin(v), c[1] + r * 1e3 * np.sin(u) * np.sin(v),
                        c[2] + r * 1e3 * np.cos(v), color="g", alpha=0.5)
        ax.text(*c, n)
    ax.set_box_aspect(np.ptp(np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()]), axis=1) * [1, 1, 3])
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("z [mm] (stretched 3×)")
    ax.set_zticks(np.round(np.linspace(*ax.get_zlim(), 3), -1))
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    figures.save(fig, name)


def _snapshots_figure(run: Run, figures: Figures, count: int = 7) -> None:
    """Fig. 6: the obstacles (green), their safety spheres at the wrist height (orange), the tool path so far."""
    names, radii, centres = _obstacle_layout(run)
    ref = run["/reference/tool"]
    tool = _xyz(ref, "position") - _xyz(run["/tracking_error"], "error")
    wrist = _xyz(run["/reference/wrist"], "position") - _xyz(run["/tracking_error/wrist"], "error")
    safety = radii + float(run.config["system"]["dh"]["d"][5]) + float(run.config["system"]["dh"]["tool_d"])
    times = ref.index.to_numpy()
    picks = np.linspace(0, len(times) - 1, count).round().astype(int)
    fig, axes = plt.subplots(1, count, figsize=(2.3 * count, 2.8), sharex=True, sharey=True)
    for ax, j in zip(axes, picks, strict=True):
        ax.plot(ref["position.x"] * 1e3, ref["position.y"] * 1e3, "b--", lw=0.8)
        ax.plot(tool[:j + 1, 0] * 1e3, tool[:j + 1, 1] * 1e3, color="C1")
        for n, r, s in zip(names, radii, safety, strict=True):
            c = np.array([centres[f"value.{n}.{a}"].iloc[j] for a in XYZ])
            height = abs(wrist[j, 2] - c[2])
            ax.add_patch(plt.Circle(c[:2] * 1e3, r * 1e3, color="g"))
            if height < s:
                ax.add_patch(plt.Circle(c[:2] * 1e3, np.sqrt(s * s - height * height) * 1e3, color="orange",
                                        fill=False))
        ax.set_aspect("equal")
        ax.set_title(f"t = {times[j]:.2f} s", fontsize=8)
    axes[0].set_ylabel("y [mm]")
    fig.suptitle(f"Fig. 6, case {run.run_id}: obstacles (green), safety sphere at the wrist height (orange)")
    figures.save(fig, f"fig6-{run.run_id}")

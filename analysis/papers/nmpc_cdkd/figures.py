"""`nmpc-cdkd`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np

from analysis.core.figures import Figures, plt
from analysis.papers.nmpc_cdkd.metrics import XYZ, _obstacle_layout, _xyz, paper_table3
from pipeline.core.runlog import Run


def _table3_figure(mean: dict, std: dict, figures: Figures) -> None:
    if not mean:
        return
    keys = [k for k in paper_table3() if k in mean]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    x = np.arange(len(keys))
    labels = [f"{'dec' if m == 'decomposed' else 'full'} {c.replace('obstacle', 'obst')} N{1 if k == 10 else 2}"
              for m, c, k in keys]
    for ax, (title, values) in zip(axes, (("pipeline", {k: (mean[k] * 1e3, std[k] * 1e3) for k in keys}),
                                          ("paper, Table 3 (i7-8550U, MATLAB)", paper_table3())), strict=True):
        colors = ["C0" if k[0] == "decomposed" else "C1" for k in keys]
        ax.bar(x, [values[k][0] for k in keys], yerr=[values[k][1] for k in keys], color=colors, capsize=3)
        ax.set_xticks(x, labels, rotation=60, ha="right", fontsize=7)
        ax.set_ylabel("OCP solve time t̄ ± σ [ms]")
        ax.set_title(title)
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

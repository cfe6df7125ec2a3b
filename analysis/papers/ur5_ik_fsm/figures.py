"""`ur5-ik-fsm`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.core.targets import load_targets
from analysis.papers.ur5_ik_fsm.metrics import ALGORITHMS, JUMP_THRESHOLD, TARGETS, wrap


def _table6_figure(metrics: pd.DataFrame, figures: Figures) -> None:
    targets = load_targets(TARGETS)
    paper = targets[targets["target_id"].str.startswith("T6.")]
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2), sharey=True)
    for ax, case in zip(axes, ("independent", "sequential"), strict=True):
        ours = metrics[metrics["run_id"] == case]
        if ours.empty:
            continue
        tests = np.arange(1, 11)
        for j, alg in enumerate(ALGORITHMS):
            vals = [ours.loc[ours["metric"] == f"{alg}.test{k}.diff", "value"].iloc[0] for k in tests]
            ax.bar(tests + (j - 0.5) * 0.38, vals, width=0.38, label=f"Algorithm {alg[-1]} (pipeline)")
        if case == "independent":
            for t in paper.itertuples():
                k = int(t.target_id.split(".")[1])
                alg = t.metric.split(".")[0]
                shift = (ALGORITHMS.index(alg) - 0.5) * 0.38 if t.target_id.count(".") == 2 else 0.0
                ax.plot(k + shift, float(t.value), "k_", ms=12, mew=2)
            ax.plot([], [], "k_", ms=12, mew=2, label="paper (Table 6)")
        ax.set_title(f"previous joints: {'0 (paper)' if case == 'independent' else 'last selection (ours)'}")
        ax.set_xlabel("test")
        ax.set_xticks(tests)
    axes[0].set_ylabel("joint displacement, eq. (48) [rad]")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="upper center", ncol=3)   # above the bars, not on them
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    figures.save(fig, "table6-displacement", tight=False)


def _path_figure(key: str, algs: dict, figures: Figures) -> None:
    fig, axes = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    for ax, alg in zip(axes[:2], ALGORITHMS, strict=True):
        values, q, t, _ = algs[alg]
        for i in range(6):
            ax.plot(t, q[:, i], lw=1.2, label=f"θ{i + 1}")
        qf = np.where(np.isnan(q), np.nan, q)
        steps = np.abs(wrap(np.diff(qf, axis=0))).max(axis=1)
        for k in np.flatnonzero(steps > JUMP_THRESHOLD):
            ax.axvline(t[k + 1], color="r", ls="--", lw=1)
        ax.set_ylabel(f"Algorithm {alg[-1]}\nIK joints [rad]")
        ax.set_title(f"max jump {values['max_joint_jump'][0]:.3f} rad, {values['branch_switches'][0]} branch "
                     "switches (red: jumps > 0.5 rad)", fontsize=8)
    axes[0].legend(ncol=6, fontsize=7, loc="upper right")
    for alg in ALGORITHMS:
        _, _, t, run = algs[alg]
        det = np.abs(run["/singularity"]["value.det_j"].to_numpy()) * 1e9
        axes[2].semilogy(t, np.maximum(det, 1e-6), label=f"Algorithm {alg[-1]}")
        flange = run["/tracking_error/flange"]
        axes[3].plot(flange.index, flange["norm"] * 1e3, label=f"Algorithm {alg[-1]}")
    axes[2].set_ylabel("|det J| [mm³]")
    axes[2].legend()
    axes[3].set_ylabel("executed flange\nposition error [mm]")
    axes[3].set_xlabel("time [s]")
    axes[3].legend()
    fig.suptitle(f"{key}: IK selection and MuJoCo execution")
    figures.save(fig, key)


def _per_call_figure(run_id: str, stats: dict[str, np.ndarray], figures: Figures) -> None:
    """Median and p95 time per pose of each algorithm, scalar and batched (the paper reports no times)."""
    fig, ax = plt.subplots(figsize=(6, 3.2))
    names = list(stats)
    med = [np.median(stats[n]) * 1e6 for n in names]
    p95 = [np.percentile(stats[n], 95) * 1e6 for n in names]
    ax.bar(names, med, color=["C0", "C0", "C1", "C1"], alpha=0.8, label="median")
    ax.errorbar(names, med, yerr=[np.zeros(len(med)), np.subtract(p95, med)], fmt="none", ecolor="k",
                capsize=4, label="p95")
    ax.set_yscale("log")
    ax.set_ylabel("time per pose [µs]")
    ax.set_title(f"{run_id}: scalar (per call) and batched (per pose)")
    ax.legend()
    figures.save(fig, f"{run_id}-per-call")


def _episodes_figure(metrics: pd.DataFrame, figures: Figures) -> None:
    """Per randomized episode: the executed flange error against the servo bandwidth drawn for it, by path
    (colour) and algorithm (marker), and the largest IK joint jump."""
    wide = metrics.pivot_table(index=["run_id", "path", "algorithm", "execute.bandwidth_hz"], columns="metric",
                               values="value").reset_index()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    colours = {"wrist": "tab:blue", "shoulder": "tab:orange", "elbow": "tab:green"}
    for (path, alg), group in wide.groupby(["path", "algorithm"]):
        style = {"color": colours.get(path, "grey"), "marker": "o" if alg == "alg1" else "^", "ls": "none",
                 "ms": 4, "alpha": 0.75, "label": f"{path}, {alg}"}
        axes[0].plot(group["execute.bandwidth_hz"], group["max_flange_error"] * 1e3, **style)
        axes[1].plot(group["execute.bandwidth_hz"], group["max_joint_jump"], **style)
    axes[0].set(xlabel="servo bandwidth drawn (Hz)", ylabel="max flange error (mm)", yscale="log",
                title="executed path error per episode")
    axes[1].axhline(JUMP_THRESHOLD, color="k", lw=0.8, ls=":", label=f"jump threshold {JUMP_THRESHOLD} rad")
    axes[1].set(xlabel="servo bandwidth drawn (Hz)", ylabel="max IK joint jump (rad)", title="IK selection")
    axes[1].legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    figures.save(fig, "episodes")

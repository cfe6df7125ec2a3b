"""Figures of `cobot-6r-ik`: Λ's roots against Table 2's, the solutions of eq. (32) as stick figures (the paper's
Fig. 3 is an image only), completeness on random poses, compute time per pose beside the peers, and the
Cartesian paths executed in MuJoCo."""

from __future__ import annotations

import numpy as np

from analysis.core.figures import Figures, plt
from analysis.core.targets import paper_value
from analysis.papers.cobot_6r_ik.metrics import METHODS, SLUG, generating_found, geometry, per_item, roots, solutions
from pipeline.core.runlog import Run
from pipeline.robotics import dh as dhk


def _paper_roots() -> tuple[list[float], list[float]]:
    """Table 2's 16 roots of Λ (real and imaginary parts; a real root has no imaginary target)."""
    re, im = [], []
    for k in range(1, 17):
        re.append(paper_value(SLUG, f"T2.root{k:02d}.re"))
        try:
            im.append(paper_value(SLUG, f"T2.root{k:02d}.im"))
        except KeyError:
            im.append(0.0)
    return re, im


def roots_figure(run: Run, figures: Figures) -> None:
    re, im = roots(run)
    paper_re, paper_im = _paper_roots()
    cands = run["/ik/candidates"]
    genuine = {round(c, 6) for c, a in zip(cands["c1"], cands["accepted[0]"], strict=True) if a >= 1}
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), gridspec_kw={"width_ratios": [2, 1]})
    for ax, xlim in zip(axes, (None, (-0.75, 0.05)), strict=True):
        ax.scatter(paper_re, paper_im, s=90, facecolors="none", edgecolors="crimson", label="paper, Table 2")
        is_gen = np.array([any(abs(x - gv) < 1e-3 for gv in genuine) and abs(y) < 1e-9 for x, y in
                           zip(re, im, strict=True)])
        ax.scatter(re[is_gen], im[is_gen], s=22, color="C2", label="ours: real root, genuine (a solution)")
        ax.scatter(re[~is_gen], im[~is_gen], s=22, color="C3", marker="x", label="ours: extraneous or complex")
        ax.set_xlabel("Re c1")
        if xlim:
            ax.set_xlim(*xlim)
            ax.set_title("zoom near 0")
    axes[0].set_ylabel("Im c1")
    axes[0].legend(fontsize=7)
    axes[0].set_title(f"{run.run_id}: the 16 roots of Λ (eq. 25)")
    figures.save(fig, f"{run.run_id}-roots")


def configurations_figure(run: Run, figures: Figures) -> None:
    """The solutions as stick figures (the paper's Fig. 3 is an image only)."""
    q = solutions(run)
    F = dhk.frames(dhk.DH.from_config(geometry(run).dh), q)
    fig = plt.figure(figsize=(10, 5))
    for k in range(len(q)):
        ax = fig.add_subplot(2, (len(q) + 1) // 2, k + 1, projection="3d")
        p = F[k, :, :3, 3]
        ax.plot(p[:, 0], p[:, 1], p[:, 2], "-o", ms=3, lw=2)
        ax.plot([0, 0], [0, 0], [0, p[1, 2]], "k-", lw=3)
        ax.set_xlim(-1, 1)
        ax.set_ylim(-1, 1)
        ax.set_zlim(0, 1.6)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_zticks([])
        ax.set_title(np.array2string(np.rad2deg(q[k]), precision=0, separator=",", suppress_small=True), fontsize=6)
    fig.suptitle(f"{run.run_id}: the {len(q)} solutions of eq. (32) (the paper's Fig. 3 shows 16 rows of Table 3)")
    figures.save(fig, f"{run.run_id}-configurations")


def completeness_figure(run: Run, figures: Figures) -> None:
    found_by = generating_found(run)
    near_c = float(run.config["scenario"]["near_singular_c"])
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
    for k, method in enumerate(METHODS):
        n = run[f"/completeness/{method}"]["value.solutions"].to_numpy()
        axes[0].hist(n + (k - 0.5) * 0.35, bins=np.arange(-0.5, 17.5, 0.35), alpha=0.8,
                     label=f"{method} ({100 * found_by[method].mean():.2f} % generating found)")
    axes[0].set_xlabel("solutions found per pose")
    axes[0].set_ylabel("poses")
    axes[0].legend(fontsize=7)
    axes[0].set_title(f"{len(n)} random reachable poses")
    c = run["/completeness/lambda16"]["value.c_generating"].to_numpy()
    for k, method in enumerate(METHODS):
        f = found_by[method]
        axes[1].semilogx(c[f], np.full(f.sum(), k), "|", color="C2", ms=12)
        axes[1].semilogx(c[~f], np.full((~f).sum(), k) + 0.25, "v", color="C3", ms=7, zorder=3)
    axes[1].plot([], [], "|", color="C2", label="generating joints found")
    axes[1].plot([], [], "v", color="C3", label="missed")
    axes[1].axvline(near_c, color="k", ls="--", lw=1, label=f"|c| = {near_c:g} (near a half-turn)")
    axes[1].set_yticks(range(len(METHODS)), METHODS)
    axes[1].set_ylim(-0.7, len(METHODS) - 0.3)
    axes[1].set_xlabel("|c| of the generating frame {4} (Cayley parameters)")
    axes[1].legend(fontsize=7, loc="upper left")
    figures.save(fig, f"{run.run_id}-completeness")


def per_pose_figure(run: Run, names: list[str], figures: Figures) -> None:
    stats = {n: per_item(run, n) for n in names}
    stats = {n: t for n, t in stats.items() if len(t)}
    fig, ax = plt.subplots(figsize=(7, 3.4))
    med = [np.median(t) * 1e6 for t in stats.values()]
    p95 = [np.percentile(t, 95) * 1e6 for t in stats.values()]
    ax.bar(list(stats), med, color=["C0" if n.startswith(("lambda16", "octic")) else "C7" for n in stats])
    ax.errorbar(list(stats), med, yerr=[np.zeros(len(med)), np.subtract(p95, med)], fmt="none", ecolor="k",
                capsize=4)
    ax.set_yscale("log")
    ax.tick_params(axis="x", labelrotation=30)
    ax.set_ylabel("time per pose [µs] (median, bar to p95)")
    ax.set_title(f"{run.run_id}: all solutions of one pose")
    figures.save(fig, f"{run.run_id}-per-pose")


def trajectory_figure(run: Run, figures: Figures) -> None:
    s = run["/ik/samples"]
    flange = run["/tracking_error/flange"]
    threshold = float(run.config["execute"]["jump_threshold"])
    fig, axes = plt.subplots(4, 1, figsize=(8, 8.5), sharex=True)
    t = s.index.to_numpy()
    q = s.filter(like="followed").to_numpy()
    for j in range(6):
        axes[0].plot(t, q[:, j], lw=1.2, label=f"q{j + 1}")
    axes[0].set_ylabel("followed branch\n[rad]")
    axes[0].legend(ncol=6, fontsize=7)
    axes[1].step(t, s["count"], where="post")
    axes[1].set_ylabel("solutions")
    axes[2].semilogy(t[1:], np.maximum(s["jump"].to_numpy()[1:], 1e-12))
    axes[2].axhline(threshold, color="r", ls="--", lw=1)
    axes[2].set_ylabel("joint step per\nsample [rad]")
    axes[3].plot(flange.index, flange["norm"] * 1e3, label="MuJoCo flange position error")
    axes[3].set_ylabel("executed flange\nerror [mm]")
    axes[3].set_xlabel("time [s]")
    fig.suptitle(f"{run.run_id}: all solutions per sample, branch by continuity, MuJoCo execution")
    figures.save(fig, run.run_id)

"""`partial-lagrangian`: the figures (PNG + SVG under data/figures/<slug>/<experiment>/, declared in paper.yaml)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from analysis.core.figures import Figures, paper_hline, plt
from analysis.papers.partial_lagrangian.metrics import (
    KINDS,
    METHODS,
    SNAPSHOT_DT,
    _is_angle,
    _positions,
    _tips,
    paper_term_counts,
)
from pipeline.core.runlog import Run


def _chain_figure(run: Run, title: str, figures: Figures, twin: Run | None = None,
                  views: tuple[tuple[str, float, float], ...] = (("", 20.0, -60.0),)) -> None:
    """q(t) (angles in degrees; a slider's length in metres on the right axis), and the chain drawn every
    SNAPSHOT_DT against time, coloured by time, with the path of the last mass in red."""
    t, q, names = _positions(run)
    fig = plt.figure(figsize=(4.6 + 3.6 * len(views), 3.6))
    ax = fig.add_subplot(1, 1 + len(views), 1)
    axes = {True: ax, False: None}
    ref = run["/reference"] if "/reference" in run.topic_names else pd.DataFrame()
    twin_q = _positions(twin) if twin is not None else None
    for j, name in enumerate(names):
        angle = _is_angle(name)
        if axes[angle] is None:
            axes[angle] = ax.twinx()
            axes[angle].set_ylabel("length [m]")
        scale = 180 / np.pi if angle else 1.0
        line, = axes[angle].plot(t, q[:, j] * scale, lw=1.2, color=f"C{j}", label=name)
        if f"position.{name}" in ref:
            axes[angle].axhline(ref[f"position.{name}"].iloc[0] * scale, color=line.get_color(), ls=":", lw=1)
        if twin_q is not None:
            axes[angle].plot(twin_q[0], twin_q[1][:, j] * scale, "k--", lw=0.8, label="Listing A1")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("angle [°]")
    handles = [h for a in axes.values() if a is not None for h in a.get_legend_handles_labels()[0]]
    ax.legend(handles=handles, fontsize=7, loc="best")
    t_tf, xy = _tips(run)
    every = max(1, round(SNAPSHOT_DT / (t_tf[1] - t_tf[0]))) if len(t_tf) > 1 else 1
    t_snap, xy_snap = t_tf[::every], xy[::every]
    pts = np.concatenate([np.zeros((len(t_snap), 1, 2)), xy_snap], axis=1)   # (snapshots, base + n tips, 2)
    segments = np.stack([pts[..., 0], np.broadcast_to(t_snap[:, None], pts.shape[:2]), pts[..., 1]], axis=-1)
    reach = np.abs(pts).max() * 1.05
    for k, (view, elev, azim) in enumerate(views, start=2):
        ax3 = fig.add_subplot(1, 1 + len(views), k, projection="3d")
        ax3.add_collection3d(Line3DCollection(segments, colors=plt.cm.viridis(np.linspace(0, 1, len(t_snap))),
                                              lw=0.8))
        ax3.plot(xy[:, -1, 0], t_tf, xy[:, -1, 1], color="r", lw=0.6)
        ax3.set(xlim=(-reach, reach), ylim=(t_tf[0], t_tf[-1]), zlim=(-reach, reach), xlabel="x [m]",
                ylabel="t [s]", zlabel="y [m]")
        ax3.view_init(elev=elev, azim=azim)
        if view:
            ax3.set_title(view, fontsize=8)
    fig.suptitle(title, fontsize=9)
    figures.save(fig, run.run_id)


def _compute_time_figure(curves: dict, figures: Figures, name: str) -> None:
    fig, axes = plt.subplots(1, len(KINDS), figsize=(16, 3.8))
    n = np.arange(1, 11)
    eq28, eq29 = paper_term_counts(n)
    for ax, (kind, title) in zip(axes, KINDS.items(), strict=True):
        scale = 1.0 if kind == "ops" else 1e6
        for k, (method, label) in enumerate(METHODS.items()):
            curve = curves.get((kind, method))
            if curve is not None:
                ax.loglog(curve.index, curve.to_numpy() * scale, "o-", color=f"C{k}", ms=3, label=label)
        if kind != "eval":
            anchor = curves[kind, "full"].iloc[-1] * scale
            ax.loglog(n, eq28 / eq28[-1] * anchor, "k--", lw=0.8, label="eq. (28), O(n⁴), scaled to full at n = 10")
            ax.loglog(n, eq29 / eq28[-1] * anchor, "k:", lw=0.8, label="eq. (29), O(n³), same scale")
        ax.set_xlabel("links n")
        ax.set_ylabel("operations" if kind == "ops" else "time per call [µs]")
        ax.set_title(title, fontsize=8)
        ax.legend(fontsize=6)
    fig.suptitle("Fig. 5b: cost against the number of links (medians over repeats, one thread)", fontsize=9)
    figures.save(fig, f"{name}-cost")


def _term_count_figure(values: dict, figures: Figures) -> None:
    """Terms of the expanded symbolic equations of motion against n, beside eqs. (28)-(29) and n² + 2n."""
    links = sorted(int(k.rsplit(".n", 1)[1]) for k in values if k.startswith("sym.all_tau.n"))
    n = np.array(links)
    curve = {name: np.array([values[f"{name}.n{k}"][0] for k in links]) for name in
             ("sym.all_tau", "sym.column", "sym.tau_max", "eq28", "eq29", "sym.half", "sym.entries")}
    fig, (ax, ax_half) = plt.subplots(1, 2, figsize=(11, 4), width_ratios=[1.4, 1])
    for k, (ours, paper, label, paper_label) in enumerate((
            ("sym.all_tau", "eq28", "all τ_ki (= the usual Lagrangian's τ_k)", "paper: eq. (28)"),
            ("sym.column", "eq29", "column n alone (one of n threads)", "paper: eq. (29)"))):
        ax.loglog(n, curve[ours], "o-", color=f"C{k}", ms=4, label=label)
        ax.loglog(n, curve[paper], "--", color=f"C{k}", lw=1, label=paper_label)
    ax.loglog(n, curve["sym.tau_max"], "o-", color="C2", ms=4, label="largest τ_ki (τ_1n)")
    ax.loglog(n, n * n + 2.0 * n, "--", color="C2", lw=1, label="paper: n² + 2n terms per τ_ki")
    ax.set_xlabel("links n")
    ax.set_ylabel("terms (expanded, symbolic parameters)")
    ax.set_title("Terms of the equations of motion (SymPy)", fontsize=9)
    ax.legend(fontsize=7)
    ax_half.plot(n, curve["sym.half"], "o-", label="differentiation work, partial / usual (terms × coordinates)")
    ax_half.plot(n, curve["sym.entries"], "s-", label="non-zero entries of Table 1, n(n+1)/2 of n²")
    paper_hline(ax_half, 0.5, label="paper: 'about half'")
    ax_half.set_ylim(0, 1.05)
    ax_half.set_xlabel("links n")
    ax_half.set_ylabel("partial / usual")
    ax_half.set_title("'About half' (Sect. 4.2)", fontsize=9)
    ax_half.legend(fontsize=7, loc="lower left")
    figures.save(fig, "term-counts")

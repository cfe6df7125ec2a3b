"""The paper's Figs. 5-14 redrawn from the runs, and the figures of our additions (clearance by case, the MuJoCo
audit and replay, the filter ablation, compute time). The x axis is the iteration, counted from 1 as the paper
counts it."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, paper_vline, plt
from analysis.core.targets import paper_value
from analysis.papers.srs_collision_avoidance.metrics import SNAPSHOTS, Signals, differences
from pipeline.papers.srs_collision_avoidance.kinematics import link_frames

CASE_STYLE = {"no-avoid": ("0.45", "task alone (α = 0)"), "avoid": ("C0", "avoidance, p = 0.2 s⁻¹ (paper)"),
              "avoid-unfiltered": ("C3", "avoidance, unfiltered α"), "avoid-exact": ("C2", "avoidance, exact α_c"),
              "avoid-printed": ("C1", "avoidance, printed listing"), "avoid-capsules": ("C4", "P_c on capsules")}


def _iterations(s: Signals, skip: int = 0) -> np.ndarray:
    return np.arange(skip + 1, len(s.t) + 1)


def fig07_swivel(by_case: dict[str, Signals], figures: Figures) -> None:
    s = by_case["avoid"]
    fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    axes[0].plot(_iterations(s), s.alpha_c, color="0.55", lw=0.8, label="α_c (computed, eq. 19)")
    axes[0].plot(_iterations(s), s.alpha_f, color="C0", lw=1.8, label="α_f (filtered, eq. 3)")
    axes[0].set_ylabel("swivel angle [rad]")
    axes[0].set_title("Fig. 7: computed and filtered α, p = 0.2 s⁻¹, T = 0.06 s")
    axes[0].legend(loc="upper right")
    for case, other in by_case.items():
        if case != "no-avoid":
            color, label = CASE_STYLE[case]
            axes[1].plot(_iterations(other), other.alpha_f, color=color, lw=1.0, label=label)
    axes[1].set_ylabel("α_f [rad]")
    axes[1].set_xlabel("iteration")
    axes[1].set_title("α_f of every variant (the unfiltered one is α_c itself)")
    axes[1].legend(fontsize=7, ncol=2, loc="upper right")
    figures.save(fig, "fig07-swivel-angle")


def fig08_09_swivel_rates(s: Signals, figures: Figures) -> None:
    for order, name, unit, title in ((1, "fig08-swivel-rate", "rad/s", "Fig. 8: rate of change of α_f"),
                                     (2, "fig09-swivel-acceleration", "rad/s²", "Fig. 9: rate of change of α̇_f")):
        fig, ax = plt.subplots(figsize=(8, 3))
        ax.plot(_iterations(s, order), differences(s.alpha_f, s.dt, order), color="C0", lw=1.2)
        ax.set_ylabel(f"{'Δα_f / T' if order == 1 else 'Δ²α_f / T²'} [{unit}]")
        ax.set_xlabel("iteration")
        ax.set_title(f"{title} (p = 0.2 s⁻¹)")
        figures.save(fig, name)


def fig10_11_joints(by_case: dict[str, Signals], figures: Figures) -> None:
    s, task = by_case["avoid"], by_case.get("no-avoid")
    for joints, name in ((range(0, 3), "fig10-joints-1-3"), (range(3, 7), "fig11-joints-4-7")):
        fig, ax = plt.subplots(figsize=(8.8, 3.6))
        for j in joints:
            ax.plot(_iterations(s), s.q[:, j], color=f"C{j}", lw=1.4, label=f"θ{j + 1}")
            if task is not None:
                ax.plot(_iterations(task), task.q[:, j], color=f"C{j}", lw=0.8, ls=":")
        ax.set_ylabel("joint angle [rad]")
        ax.set_xlabel("iteration")
        first = joints[0] + 1
        ax.set_title(f"Fig. {10 if first == 1 else 11}: IK joints {first}-{joints[-1] + 1} with avoidance "
                     "(dotted: the task alone)")
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
        figures.save(fig, name)


def fig12_13_joint_ranges(by_case: dict[str, Signals], figures: Figures) -> None:
    shown = [c for c in ("avoid", "avoid-unfiltered") if c in by_case]
    for order, name, unit, what in ((1, "fig12-joint-rate-range", "rad/s", "Fig. 12: joint rates"),
                                    (2, "fig13-joint-acceleration-range", "rad/s²", "Fig. 13: joint accelerations")):
        fig, axes = plt.subplots(len(shown), 1, figsize=(8, 2.8 * len(shown)), squeeze=False)
        for ax, case in zip(axes[:, 0], shown, strict=True):
            s = by_case[case]
            d = differences(s.q, s.dt, order)
            it = _iterations(s, order)
            ax.fill_between(it, d.min(axis=1), d.max(axis=1), color=CASE_STYLE[case][0], alpha=0.25, lw=0)
            ax.plot(it, d.max(axis=1), color=CASE_STYLE[case][0], lw=1.0, label="max over the 7 joints")
            ax.plot(it, d.min(axis=1), color=CASE_STYLE[case][0], lw=1.0, ls="--", label="min over the 7 joints")
            ax.set_ylabel(f"[{unit}]")
            ax.set_title(f"{what}, {CASE_STYLE[case][1]}", fontsize=9)
            ax.legend(loc="upper right", fontsize=7)
        axes[-1, 0].set_xlabel("iteration")
        figures.save(fig, name)


def fig14_distances(s: Signals, figures: Figures) -> None:
    fig, ax = plt.subplots(figsize=(8, 3.4))
    it = _iterations(s)
    ax.plot(it, s.d_mc * 1e3, color="C3", lw=1.2, label="d_mc: allowed distance aimed at (0 when no collision is "
                                                         "imminent)")
    ax.plot(it, s.actual * 1e3, "o", color="C0", ms=2, label="distance of P_c from P_col under imminent collision")
    ax.set_ylabel("distance [mm]")
    ax.set_xlabel("iteration")
    ax.set_title("Fig. 14: distances of Algorithm 1 (at the α = 0 posture), p = 0.2 s⁻¹")
    ax.legend(loc="upper right", fontsize=7)
    figures.save(fig, "fig14-distances")


def _draw_scene(ax, s: Signals, n: int) -> None:
    """The arm (link capsules as thick lines), the two human arms, P_c (red if a collision is imminent) and the
    safety cones' widest circle at P_e, at sample n, in the paper's frame drawn y-up."""
    frames = link_frames(s.q[n], s.geometry)
    points = np.vstack([[0.0, 0.0, 0.0], frames[[0, 3, 5, 7], :3, 3]])   # O_b, P_s, P_e, P_w, O_e

    def plot(xyz, *args, **kw):
        xyz = np.atleast_2d(xyz)
        ax.plot(xyz[:, 0], xyz[:, 2], xyz[:, 1], *args, **kw)   # matplotlib's z up = the paper's y_b

    plot(points, "-o", color="C1", lw=5, ms=6, solid_capstyle="round")
    for arm in (s.humans[n, :3], s.humans[n, 3:]):
        plot(arm, "-", color="tan", lw=4)
        plot(arm[0], "o", color="C0", ms=7)          # shoulders blue, elbows and hands green, as in Fig. 5
        plot(arm[1:], "o", color="C2", ms=6, ls="")
    plot(s.P_c[n], "o", color="C3" if s.find[n] else "k", ms=8)
    ring = np.linspace(0, 2 * np.pi, 60)
    radius = s.config["system"]["safety"]["d_cmax"]
    axis = frames[4, :3, :3]
    circle = points[2] + radius * (np.cos(ring)[:, None] * axis[:, 1] + np.sin(ring)[:, None] * axis[:, 2])
    plot(circle, color="C0", lw=0.8, alpha=0.6)
    ax.set_xlim(-0.3, 0.8)
    ax.set_ylim(-0.5, 0.6)
    ax.set_zlim(0.0, 1.0)
    ax.set_xlabel("x_b [m]")
    ax.set_ylabel("z_b [m]")
    ax.set_zlabel("y_b [m]")
    ax.set_title(f"iteration {n + 1}" + (" (collision imminent)" if s.find[n] else ""), fontsize=9)
    ax.view_init(elev=22, azim=-60)


def fig05_06_scenes(s: Signals, figures: Figures) -> None:
    """The paper's snapshot iterations that the run has (a shortened run may have none)."""
    if SNAPSHOTS[2] <= len(s.t):
        fig = plt.figure(figsize=(5.5, 5))
        _draw_scene(fig.add_subplot(projection="3d"), s, SNAPSHOTS[2] - 1)
        fig.suptitle("Fig. 5: the scene at iteration 390 (blue: shoulders, green: elbows and hands, red: P_c)",
                     fontsize=8)
        figures.save(fig, "fig05-scene-390")
    frames = [k for k in (SNAPSHOTS[0], SNAPSHOTS[1], SNAPSHOTS[3]) if k <= len(s.t)]
    if frames:
        fig = plt.figure(figsize=(4 * len(frames), 4.2))
        for k, iteration in enumerate(frames):
            _draw_scene(fig.add_subplot(1, len(frames), k + 1, projection="3d"), s, iteration - 1)
        fig.suptitle(f"Fig. 6: frames at iterations {', '.join(map(str, frames))} (avoidance, p = 0.2 s⁻¹)",
                     fontsize=9)
        figures.save(fig, "fig06-frames")


def clearance_by_case(by_case: dict[str, Signals], figures: Figures) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for case, s in by_case.items():
        color, label = CASE_STYLE[case]
        lw = 1.6 if case in ("no-avoid", "avoid") else 0.9
        axes[0].plot(_iterations(s), s.volume.min(axis=1) * 1e3, color=color, lw=lw, label=label)
        axes[1].plot(_iterations(s), s.capsules.min(axis=1) * 1e3, color=color, lw=lw, label=label)
    for ax in axes:
        ax.axhline(0, color="k", lw=0.8)
    axes[0].set_ylabel("margin of the human points\noutside the safety volume [mm]")
    axes[0].set_title("Nearest human point to the safety volume (cones + elbow sphere; < 0: inside)")
    axes[0].legend(fontsize=7, ncol=2, loc="lower left")
    axes[1].set_ylabel("human capsules to\nlink capsules [mm]")
    axes[1].set_title("Bodies: human arm capsules against the arm's link capsules (< 0: overlapping)")
    axes[1].set_xlabel("iteration")
    figures.save(fig, "clearance-by-case")


def mujoco_audit(by_case: dict[str, Signals], figures: Figures) -> None:
    s = by_case.get("avoid")
    if s is None or s.capsules_mujoco is None:
        return
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    it = _iterations(s)
    axes[0].plot(it, s.capsules.min(axis=1) * 1e3, color="C0", lw=2.5, label="ours (segment distance − radii)")
    axes[0].plot(it, s.capsules_mujoco.min(axis=1) * 1e3, color="C1", lw=1, label="MuJoCo mj_geomDistance")
    axes[0].plot(it, s.capsules_replay.min(axis=1) * 1e3, color="C2", lw=0.8, ls="--",
                 label="MuJoCo, at the joints the replay reached")
    axes[0].axhline(0, color="k", lw=0.8)
    axes[0].set_ylabel("min body clearance [mm]")
    axes[0].legend(fontsize=7)
    axes[0].set_title("Clearance of the bodies (avoidance, p = 0.2 s⁻¹): ours against MuJoCo's distance query")
    for case, other in by_case.items():
        if other.capsules_mujoco is not None:
            gap = np.abs(other.capsules_mujoco - other.capsules).max(axis=1)
            axes[1].semilogy(_iterations(other), np.maximum(gap, 1e-18), color=CASE_STYLE[case][0], lw=0.7,
                             label=CASE_STYLE[case][1])
    axes[1].set_ylabel("max |ours − MuJoCo|\nover the 16 pairs [m]")
    axes[1].legend(fontsize=6, ncol=3)
    t = s.replay.index.to_numpy() / s.dt + 1
    axes[2].plot(t, s.replay["norm"].to_numpy() * 1e3, color="C2", lw=0.8, label="joint error norm [mrad]")
    axes[2].plot(t, s.replay_tool["norm"].to_numpy() * 1e3, color="C3", lw=0.8, label="tool position error [mm]")
    axes[2].set_ylabel("replay tracking")
    axes[2].set_xlabel("iteration")
    axes[2].legend(fontsize=7)
    figures.save(fig, "mujoco-audit-and-replay")


def ablation_tradeoff(metrics: pd.DataFrame, figures: Figures) -> None:
    """Clearance against smoothness over the filter pole p, for both readings of α_c."""
    wide = metrics.pivot_table(index=["system.algorithm.alpha_c", "system.filter.p"], columns="metric",
                               values="value").reset_index()
    wide["p"] = wide["system.filter.p"].astype(float)
    panels = (("volume.intrusion_fraction", 100, "samples with a human point\ninside the safety volume [%]"),
              ("volume.min_margin", 1e3, "min margin of the human points\noutside the safety volume [mm]"),
              ("joint.rate.max_abs", 1, "peak |joint rate| [rad/s]"),
              ("joint.acceleration.max_abs", 1, "peak |joint acceleration| [rad/s²]"))
    fig, axes = plt.subplots(2, 2, figsize=(9, 6.5), sharex=True)
    for ax, (metric, scale, label) in zip(axes.ravel(), panels, strict=True):
        for form, part in wide.groupby("system.algorithm.alpha_c"):
            part = part.sort_values("p")
            ax.plot(part["p"], part[metric] * scale, "o-", label=f"α_c: {form}")
        if metric.startswith("volume.") and f"{metric}_alpha0" in wide:
            ax.axhline(wide[f"{metric}_alpha0"].iloc[0] * scale, color="0.5", ls=":", label="task alone (α = 0)")
        ax.axvline(0.2, color="k", lw=0.8, ls="--")
        ax.set_xscale("log")
        if metric.startswith("joint."):
            ax.set_yscale("log")
        ax.set_ylabel(label)
    for ax in axes[1]:
        ax.set_xlabel("filter pole p [1/s]")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Ablation: the critically damped filter trades clearance for smoothness\n"
                 "(dashed: the paper's p = 0.2 1/s; p = 1000 1/s is α_c unfiltered, one sample late)", fontsize=10)
    figures.save(fig, "ablation-tradeoff")


def compute_time_histogram(per_iteration_s: np.ndarray, figures: Figures) -> None:
    fig, ax = plt.subplots(figsize=(6.5, 3.2))
    ms, paper_ms = per_iteration_s * 1e3, paper_value("srs-collision-avoidance", "CT.iteration", "ms")
    ax.hist(ms, bins=np.geomspace(ms.min(), max(ms.max(), paper_ms * 1.2), 60), color="C0", alpha=0.8)
    ax.axvline(np.median(ms), color="C0", ls="--", label=f"median {np.median(ms):.3f} ms (ours)")
    paper_vline(ax, paper_ms, label=f"paper: {paper_ms:g} ms per iteration (MATLAB, i7 2.7 GHz)")
    ax.set_xscale("log")
    ax.set_xlabel("time per Algorithm 1 iteration [ms]")
    ax.set_ylabel("iterations")
    ax.legend(fontsize=7)
    figures.save(fig, "compute-time-per-iteration")

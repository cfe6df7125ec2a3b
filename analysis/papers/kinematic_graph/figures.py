"""Figures of `kinematic-graph`: Table 1 against the paper, the planar plans of Figs. 2 and 4, the heuristic field of
Fig. 3, the searched KG of Fig. 5, the spatial plans of Fig. 6, the benchmarks and the executed motions."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, paper_point, plt
from analysis.core.targets import paper_value
from analysis.papers.kinematic_graph.metrics import PAPER_METRICS, SLUG
from pipeline.core.runlog import Run
from pipeline.papers.kinematic_graph.arms import RegionalArm

LABELS = {"cspace": "C-space distance", "tspace": "T-space distance",
          "manipulability": "T-space × (μ_max − μ), eqs. (11)-(12)",
          "manipulability-admissible": "admissible variant of (11)-(12)", "tspace-only": "T-space only (voxels + IK)"}
STATE_COLORS = {0: "#d9d9d9", 1: "#f2c500", 2: "#3aa655", 3: "#d62728", 4: "#111111"}   # Fig. 5's colours
STATE_NAMES = {0: "not met", 1: "queued (yellow)", 2: "expanded (green)", 3: "path (red)", 4: "colliding (black)"}


def arm_of(run: Run, name: str) -> RegionalArm:
    return RegionalArm.from_config(name, run.config["system"][name])


def boxes_of(node) -> list[tuple[np.ndarray, np.ndarray]]:
    """(centre, half sizes) of each box of a config's `obstacles` node (none for None)."""
    if not node:
        return []
    return list(zip(np.asarray(node["centre"], dtype=float), np.asarray(node["half"], dtype=float), strict=True))


# -- Table 1 -------------------------------------------------------------------------------------------------------


def table1_figure(metrics: pd.DataFrame, figures: Figures) -> None:
    ours = metrics.set_index("metric")["value"]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    t_res = [0.1, 0.05, 0.03, 0.01]
    for k, c in enumerate(("C2", "C1", "C0.5")):
        for ax, what in zip(axes[:2], ("vertices", "edges"), strict=True):
            ax.plot(t_res, [ours[f"{c}_T{t:g}.{what}"] for t in t_res], "o-", color=f"C{k}",
                    label=f"pipeline, {c[1:]}°")
            ax.plot(t_res, [paper_value(SLUG, f"T1.{c}_T{t:g}.{what}") for t in t_res], "kx", ms=7,
                    label="paper, Table 1" if k == 0 else None)
        for what, marker in (("vertices", "o"), ("edges", "s")):
            dev = [100 * (ours[f"{c}_T{t:g}.{what}"] / paper_value(SLUG, f"T1.{c}_T{t:g}.{what}") - 1) for t in t_res]
            axes[2].plot(t_res, dev, marker + "-", color=f"C{k}", label=f"|V_k|, {c[1:]}°" if what == "vertices"
                         else f"|E_k|, {c[1:]}°")
    for ax, title in zip(axes[:2], ("|V_k| (KG vertices)", "|E_k| (KG edges)"), strict=True):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("T_res [m]")
        ax.set_title(title)
    axes[0].legend(fontsize=7)
    axes[2].axhspan(-1, 1, color="0.9", label="±1 % (tolerance)")
    axes[2].set_xscale("log")
    axes[2].set_xlabel("T_res [m]")
    axes[2].set_ylabel("pipeline / paper − 1 [%]")
    axes[2].set_title("deviation from Table 1")
    axes[2].legend(fontsize=6, ncol=2, loc="lower right")
    figures.save(fig, "table1-sizes")


# -- planar plans (Figs. 2, 4) ------------------------------------------------------------------------------------


def _draw_boxes_2d(ax, boxes) -> None:
    for c, h in boxes:
        ax.add_patch(plt.Rectangle(c[:2] - h[:2], 2 * h[0], 2 * h[1], color="#d9822b", alpha=0.8, zorder=3))


def _draw_plan(ax, arm: RegionalArm, run: Run, boxes) -> None:
    path = run["/kg/path"]
    q = path.filter(like="value.q.").to_numpy()
    q_start = np.radians(np.asarray(run.config["scenario"]["showcase"][run.metadata["case"].split("-")[0]]
                                    ["q_start_deg"], dtype=float))
    joints = np.vstack([q_start[None], q])
    points = arm.points(joints)[..., :2]
    reach = float(np.abs(arm.dh.a).sum())
    ax.add_patch(plt.Circle((0, 0), reach, fill=False, ls=":", color="0.6"))
    ax.add_patch(plt.Circle((0, 0), abs(arm.dh.a[0] - arm.dh.a[1]), fill=False, ls=":", color="0.6"))
    _draw_boxes_2d(ax, boxes)
    colours = plt.cm.Greens_r(np.linspace(0.15, 0.75, len(points)))
    for k in range(0, len(points), max(1, len(points) // 8)):
        ax.plot(points[k, :, 0], points[k, :, 1], "-", color=colours[k], lw=1.5, alpha=0.8)
    ax.plot(points[-1, :, 0], points[-1, :, 1], "-", color=colours[-1], lw=2)
    ax.plot(points[0, :, 0], points[0, :, 1], "-", color="#1b7837", lw=2.5)
    ax.scatter(points[:, -1, 0], points[:, -1, 1], c=np.linspace(0, 1, len(points)), cmap="Greens_r", s=10, zorder=4)
    goal = np.asarray(run.config["scenario"]["showcase"][run.metadata["case"].split("-")[0]]["goal"], dtype=float)
    ax.plot(*goal, "*", color="#d62728", ms=12, zorder=5)
    record = run["/kg/search"].iloc[0]
    ax.set_title(f"{LABELS[run.metadata['case'].split('-', 1)[1]]}\n{record['explored_pct']:.2f} % explored, "
                 f"{len(joints) - 1} vertices", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlim(-reach - 0.05, reach + 0.05)
    ax.set_ylim(-reach - 0.05, reach + 0.05)


def planar_plans_figure(runs: dict[str, Run], scene: str, figures: Figures, name: str) -> None:
    cases = [c for c in ("tspace", "cspace", "manipulability", "tspace-only") if f"{scene}-{c}" in runs]
    if not cases:
        return
    first = runs[f"{scene}-{cases[0]}"]
    arm = arm_of(first, "planar")
    boxes = boxes_of(first.config["scenario"]["obstacles"] if scene == "obstacle" else None)
    fig, axes = plt.subplots(1, len(cases), figsize=(3.3 * len(cases), 3.6))
    for ax, case in zip(np.atleast_1d(axes), cases, strict=True):
        _draw_plan(ax, arm, runs[f"{scene}-{case}"], boxes)
    figures.save(fig, name)


def heuristic_figure(run: Run, figures: Figures) -> None:
    """Fig. 3: eq. (12) over the KG for the showcase goal, in T-space and in C-space, with the path."""
    v = run["/kg/vertices"]
    pos, q = v.filter(like="value.pos.").to_numpy(), v.filter(like="value.q.").to_numpy()
    mu_max = run["/kg/goal"]["value.mu_max"].iloc[0]
    goal = np.asarray(run.config["scenario"]["showcase"]["free"]["goal"], dtype=float)
    h = np.sum((pos - goal) ** 2, axis=1) * np.clip(mu_max - v["value.mu"].to_numpy(), 0, None)   # eq. (12)
    path = run["/kg/path"]
    from matplotlib.colors import LogNorm

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    norm = LogNorm(vmin=max(float(np.percentile(h[h > 0], 1)), 1e-9), vmax=float(h.max()))
    for ax, xy, xl, yl in ((axes[0], pos, "x [m]", "y [m]"), (axes[1], np.degrees(q), "θ1 [°]", "θ2 [°]")):
        sc = ax.scatter(xy[:, 0], xy[:, 1], c=np.maximum(h, norm.vmin), s=4, cmap="viridis", norm=norm)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
    axes[0].plot(path["value.pos.x"], path["value.pos.y"], "r.-", lw=1)
    axes[0].plot(*goal, "r*", ms=12)
    axes[0].set_aspect("equal")
    axes[1].plot(np.degrees(path["value.q.joint1"]), np.degrees(path["value.q.joint2"]), "r.-", lw=1)
    fig.colorbar(sc, ax=axes[1], label="ℋ of eq. (12) [m⁴] (log)")
    axes[0].set_title("(a) T-space", fontsize=9)
    axes[1].set_title("(b) C-space", fontsize=9)
    fig.suptitle("Heuristic field of eqs. (11)-(12) for the free-scene goal (Fig. 3)", fontsize=9)
    figures.save(fig, "fig3-heuristic")


def searched_kg_figure(run: Run, figures: Figures, name: str) -> None:
    """Fig. 5: every KG vertex coloured by its state in the search, in T-space (overlapping vertices of one voxel
    spread by a small offset) and in C-space."""
    v = run["/kg/vertices"]
    pos, q = v.filter(like="value.pos.").to_numpy(), v.filter(like="value.q.").to_numpy()
    state = v["value.state"].to_numpy().astype(int)
    t_res = float(run.config["graph"]["t_res"])
    voxel = np.round(pos / t_res).astype(int)
    _, inverse, counts = np.unique(voxel, axis=0, return_inverse=True, return_counts=True)
    rank = np.zeros(len(pos), dtype=int)
    seen: dict[int, int] = {}
    for i, group in enumerate(inverse.ravel()):
        rank[i] = seen.get(group, 0)
        seen[group] = rank[i] + 1
    angle = 2 * np.pi * rank / np.maximum(counts[inverse.ravel()], 1)
    spread = pos + 0.012 * np.where(counts[inverse.ravel()] > 1, 1, 0)[:, None] * np.column_stack(
        [np.cos(angle), np.sin(angle)])
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    for ax, xy in ((axes[0], spread), (axes[1], np.degrees(q))):
        for s in (0, 4, 1, 2, 3):
            pick = state == s
            ax.scatter(xy[pick, 0], xy[pick, 1], s=3 if s == 0 else 6, color=STATE_COLORS[s], label=STATE_NAMES[s])
    path = run["/kg/path"]
    axes[0].plot(path["value.pos.x"], path["value.pos.y"], "-", color=STATE_COLORS[3], lw=1)
    axes[1].plot(np.degrees(path["value.q.joint1"]), np.degrees(path["value.q.joint2"]), "-", color=STATE_COLORS[3],
                 lw=1)
    axes[0].set_aspect("equal")
    axes[0].set_xlabel("x [m]")
    axes[0].set_ylabel("y [m]")
    axes[1].set_xlabel("θ1 [°]")
    axes[1].set_ylabel("θ2 [°]")
    axes[0].set_title("(a) KG in T-space (cluster means, overlaps spread)", fontsize=9)
    axes[1].set_title("(b) KG in C-space (cluster means C.q)", fontsize=9)
    axes[1].legend(fontsize=7, markerscale=2, loc="upper right")
    figures.save(fig, name)


# -- benchmarks -------------------------------------------------------------------------------------------------


def benchmark_figure(run: Run, figures: Figures, name: str, paper_figure: str | None = None) -> None:
    """Per query: vertices expanded, planning time, the share of the KG explored (beside the share the paper
    prints for its one query of `paper_figure`, Fig2 or Fig6), and how many plans are found and collision-free."""
    df = run["/kg/search"]
    groups = [(g, m) for g in ("kg", "grid", "tonly") for m in (*PAPER_METRICS, "manipulability-admissible")
              if ((df["graph"] == g) & (df["metric"] == m)).any()]
    labels = [f"{g}\n{m.replace('manipulability', 'manip.')}" for g, m in groups]
    pick = {gm: df[(df["graph"] == gm[0]) & (df["metric"] == gm[1])] for gm in groups}
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    axes[0].boxplot([pick[gm]["expanded"].to_numpy() for gm in groups], showfliers=False)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("vertices expanded per query")
    axes[1].boxplot([pick[gm]["seconds"].to_numpy() * 1e3 for gm in groups], showfliers=False)
    axes[1].set_yscale("log")
    axes[1].set_ylabel("planning time per query [ms]")
    kg = [m for m in PAPER_METRICS if ("kg", m) in pick]
    axes[2].boxplot([pick[("kg", m)]["explored_pct"].to_numpy() for m in kg], whis=(5, 95), showfliers=True)
    if paper_figure:
        for k, m in enumerate(kg):
            paper_point(axes[2], k + 1, paper_value(SLUG, f"{paper_figure}.explored.{m}"),
                        label=f"paper ({paper_figure.replace('Fig', 'Fig. ')}, one query)" if k == 0 else None)
        axes[2].legend(fontsize=7, loc="upper left")
    axes[2].set_yscale("log")
    axes[2].set_ylabel("share of the KG explored per query [%]\n(whiskers: 5th-95th percentile)")
    axes[2].set_xticks(np.arange(1, len(kg) + 1), [m.replace("manipulability", "manip.") for m in kg], fontsize=7)
    width = 0.4
    x = np.arange(len(groups))
    axes[3].bar(x - width / 2, [pick[gm]["found"].mean() for gm in groups], width, label="found")
    axes[3].bar(x + width / 2, [(pick[gm]["found"] & pick[gm]["collision_free"]).mean() for gm in groups], width,
                label="found and collision-free (dense check)")
    axes[3].set_ylim(0, 1.05)
    axes[3].legend(fontsize=7, loc="lower left")
    for ax in (axes[0], axes[1]):
        ax.set_xticks(np.arange(1, len(groups) + 1), labels, fontsize=6, rotation=60)
    axes[3].set_xticks(x, labels, fontsize=6, rotation=60)
    fig.suptitle(f"{run.run_id}: {df['query'].nunique()} seeded queries (kg: kinematic graph, grid: plain C-grid, "
                 "tonly: T-space voxels + IK)", fontsize=9)
    figures.save(fig, name)


def execution_figure(runs: list[Run], figures: Figures, name: str) -> None:
    if not runs:
        return
    has_clearance = all("/clearance" in r.topic_names for r in runs)
    fig, axes = plt.subplots(1, 3 if has_clearance else 2, figsize=(12 if has_clearance else 8, 3.4))
    for k, run in enumerate(runs):
        label = LABELS[run.metadata["case"].split("-", 1)[-1]] if "-" in run.metadata["case"] else \
            LABELS[run.metadata["case"]]
        joint, pw = run["/tracking_error"], run["/tracking_error/pw"]
        axes[0].plot(joint.index, np.degrees(joint["norm"]), color=f"C{k}", label=label)
        axes[1].plot(pw.index, pw["norm"] * 1e3, color=f"C{k}")
        if has_clearance:
            c = run["/clearance"]
            axes[2].plot(c.index, c["value.executed.min"] * 1e3, color=f"C{k}")
            axes[2].plot(c.index, c["value.reference.min"] * 1e3, ":", color=f"C{k}")
    axes[0].set_ylabel("joint tracking error ‖e_q‖ [°]")
    axes[1].set_ylabel("P_w tracking error [mm]")
    axes[0].legend(fontsize=7)
    if has_clearance:
        axes[2].axhline(0, color="k", lw=0.8)
        axes[2].set_ylabel("min clearance to obstacles [mm]\n(solid: executed, dotted: reference)")
    for ax in axes:
        ax.set_xlabel("time [s]")
    fig.suptitle("Planned paths executed by the MuJoCo arm under a joint PD servo", fontsize=9)
    figures.save(fig, name)


# -- spatial (Fig. 6) ----------------------------------------------------------------------------------------------


def spatial_figure(runs: dict[str, Run], figures: Figures) -> None:
    cases = [c for c in PAPER_METRICS if c in runs]
    if not cases:
        return
    first = runs[cases[0]]
    arm = arm_of(first, "puma")
    boxes = boxes_of(first.config["scenario"]["obstacles"])
    fig = plt.figure(figsize=(11, 5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    for c, h in boxes:
        if h[0] > 1.0:   # the floor: draw its outline only
            continue
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h + c
        for i, j in ((0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)):
            ax.plot(*corners[[i, j]].T, color="#d9822b", lw=1)
    colours = {"cspace": "#1b5e20", "tspace": "#81c784", "manipulability": "#ef6c00"}   # Fig. 6a's colours
    for case in cases:
        path = runs[case]["/kg/path"]
        p = path.filter(like="value.pos.").to_numpy()
        explored = runs[case]["/kg/search"]["explored_pct"].iloc[0]
        ax.plot(*p.T, ".-", color=colours[case], label=f"{LABELS[case]} ({explored:.2f} %)")
    q_start = np.radians(np.asarray(first.config["scenario"]["showcase"]["q_start_deg"], dtype=float))
    start_arm = arm.points(q_start)
    ax.plot(*start_arm.T, "k-", lw=3, alpha=0.6)
    goal = np.asarray(first.config["scenario"]["showcase"]["goal"], dtype=float)
    ax.plot(*goal, "r*", ms=12)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title("(a) P_w paths of the three metrics (arm at the start)", fontsize=9)
    ax.legend(fontsize=6, loc="upper left")
    ax2 = fig.add_subplot(1, 2, 2)
    for case in cases:
        path = runs[case]["/kg/path"]
        ax2.plot(path.index, path["value.mu"], ".-", color=colours[case], label=case)
    ax2.set_xlabel("time the reference reaches the vertex [s]")
    ax2.set_ylabel("μ = |det J| of P_w [m³]")
    ax2.set_title("(b) manipulability along the executed plans", fontsize=9)
    ax2.legend(fontsize=7)
    figures.save(fig, "fig6-spatial")

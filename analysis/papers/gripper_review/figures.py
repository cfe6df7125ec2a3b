"""`gripper-review`'s figure: the grasp forces and payloads Sect. 2 quotes, by class and actuation, with
Table 3's per-class load claims."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import PAPER_STYLE, Figures, plt
from analysis.core.targets import paper_value
from analysis.papers.gripper_review.metrics import slug
from pipeline.papers.gripper_review.curated import ACTUATIONS, CLASSES

MARKERS = dict(zip(ACTUATIONS, "o s ^ D v P X * h".split(), strict=True))
COLORS = dict(zip(ACTUATIONS, plt.get_cmap("tab10").colors, strict=False))
BOUND_MARKERS = {"<=": "$\\downarrow$", "<": "$\\downarrow$", ">": "$\\uparrow$", ">=": "$\\uparrow$"}


def force_payload_figure(grippers: pd.DataFrame, gravity: float, figures: Figures) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6), sharey=True)
    spread = np.linspace(-0.42, 0.42, len(ACTUATIONS))
    for ax, column, title in ((axes[0], "grasp_force", "grasp force"), (axes[1], "payload", "payload (weight)")):
        quoted = grippers.dropna(subset=[f"{column}_n"]).sort_values(f"{column}_n")
        for actuation, rows in quoted.groupby("actuation"):
            x = rows["gripper_class"].map({c: i for i, c in enumerate(CLASSES)}) + spread[
                ACTUATIONS.index(actuation)]
            ax.scatter(x, rows[f"{column}_n"], marker=MARKERS[actuation], color=COLORS[actuation], s=46,
                       label=actuation, zorder=3)
            for k, (xi, row) in enumerate(zip(x, rows.itertuples(), strict=True)):
                value = getattr(row, f"{column}_n")
                bound = BOUND_MARKERS.get(getattr(row, f"{column}_qualifier"), "")
                ax.annotate(f"[{row.ref}]{bound}", (xi, value), xytext=(5, 2 if k % 2 else -8),
                            textcoords="offset points", fontsize=7)  # alternate: close values stay legible
        ax.set_xticks(range(len(CLASSES)), [c.replace(" ", "\n") for c in CLASSES])
        ax.set_xlim(-0.6, len(CLASSES) - 0.4)
        ax.set_yscale("log")
        ax.set_ylim(5e-3, 300)
        ax.set_title(f"{title} quoted in Sect. 2")
    # Table 3's load claims, as printed in kg, drawn as weights
    for target, cls, text in (("T3.cc.load", 0, "> 10 kg"), ("T3.uc.load", 1, "≤ 5 kg")):
        weight = paper_value(slug, target) * gravity
        axes[1].hlines(weight, cls - 0.45, cls + 0.45, **PAPER_STYLE,
                       label="paper, Table 3 load capacity" if cls == 0 else None)
        axes[1].annotate(text, (cls - 0.45, weight), xytext=(0, 3), textcoords="offset points", fontsize=7,
                         color=PAPER_STYLE["color"])
    axes[0].set_ylabel("force [N] (log)")
    handles, labels = axes[1].get_legend_handles_labels()
    more = axes[0].get_legend_handles_labels()
    seen = dict(zip(labels, handles, strict=True)) | dict(zip(more[1], more[0], strict=True))
    fig.legend(seen.values(), seen.keys(), loc="lower center", ncol=4, fontsize=8, bbox_to_anchor=(0.5, 0.03))
    fig.text(0.99, 0.01, "↓ up to, ↑ more than (as the review states it)", fontsize=7, ha="right")
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    figures.save(fig, "force-payload", tight=False)

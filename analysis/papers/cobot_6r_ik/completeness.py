"""Completeness on random reachable poses: the generating joints and their twin found, the multi-start
reference's solutions found, the roots the FK filter rejects, and which misses sit near the Cayley
singularity."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run


def analyze_completeness(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        poses = run["/completeness/poses"]
        ref = run["/completeness/reference"]
        near_c = float(run.config["scenario"]["near_singular_c"])
        n = poses["value.solutions"].to_numpy()
        found = poses["value.generating_found"].to_numpy() > 0.5
        twin = poses["value.twin_found"].to_numpy() > 0.5
        near = poses["value.c_generating"].to_numpy() > near_c
        agree = (ref["value.ours_only"] == 0) & (ref["value.reference_only"] == 0)
        values = {
            "poses": (len(n), "count"),
            "solutions.mean": (n.mean(), "count"), "solutions.max": (n.max(), "count"),
            "solutions.min": (n.min(), "count"), "solutions.odd_poses": (int((n % 2 == 1).sum()), "count"),
            "generating_found.fraction": (found.mean(), "fraction"),
            "twin_found.fraction": (twin.mean(), "fraction"),
            "missed_poses": (int((~found).sum()), "count"),
            "near_singular.poses": (int(near.sum()), "count"),
            "near_singular.missed": (int((near & ~found).sum()), "count"),
            "missed_not_near_singular": (int((~near & ~found).sum()), "count"),
            "real_roots.mean": (poses["value.real_roots"].mean(), "count"),
            "rejected_roots.mean": (poses["value.rejected_roots"].mean(), "count"),
            "reference.poses": (len(ref), "count"),
            "reference.solutions": (ref["value.reference"].sum(), "count"),
            "reference.found_by_ours": (ref["value.common"].sum() / max(1, ref["value.reference"].sum()), "fraction"),
            "reference.ours_only": (ref["value.ours_only"].sum(), "count"),
            "reference.agree_fraction": (agree.mean(), "fraction"),
            "claim.all_found": (float(found.all() and agree.all()), "bool"),
        }
        m.add_run(run, values)
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
        axes[0].hist(n, bins=np.arange(-0.5, 17.5, 1), color="C0")
        axes[0].set_xlabel("solutions found per pose")
        axes[0].set_ylabel("poses")
        axes[0].set_title(f"{len(n)} random reachable poses")
        c = poses["value.c_generating"].to_numpy()
        axes[1].semilogx(c[found], np.zeros(found.sum()) + 1, "|", color="C2", ms=20, label="generating joints found")
        axes[1].semilogx(c[~found], np.zeros((~found).sum()), "|", color="C3", ms=20, label="missed")
        axes[1].axvline(near_c, color="k", ls="--", lw=1, label=f"|c| = {near_c:g} (near a half-turn)")
        axes[1].set_yticks([0, 1], ["missed", "found"])
        axes[1].set_ylim(-0.5, 1.5)
        axes[1].set_xlabel("|c| of the generating frame {4} (Cayley parameters)")
        axes[1].legend(fontsize=7, loc="center left")
        figures.save(fig, f"{run.run_id}-completeness")
    return m.frame()

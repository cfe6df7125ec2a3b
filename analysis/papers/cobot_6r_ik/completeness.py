"""Completeness on random reachable poses: the generating joints and their twin found, the multi-start
reference's solutions found, the roots the FK filter rejects, and which misses sit near the Cayley
singularity."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.core.figures import Figures, plt
from analysis.core.metrics import MetricTable
from pipeline.core.runlog import Run

METHODS = ("lambda16", "octic")


def analyze_completeness(runs: list[Run], figures: Figures) -> pd.DataFrame:
    """Metrics per method: `lambda16.*` the paper's Λ with the FK filter, `octic.*` its genuine factor (ours)."""
    m = MetricTable()
    for run in runs:
        ref = run["/completeness/reference"]
        near_c = float(run.config["scenario"]["near_singular_c"])
        values: dict[str, tuple[float, str]] = {}
        found_by = {}
        for method in METHODS:
            poses = run[f"/completeness/{method}"]
            n = poses["value.solutions"].to_numpy()
            found = poses["value.generating_found"].to_numpy() > 0.5
            twin = poses["value.twin_found"].to_numpy() > 0.5
            near = poses["value.c_generating"].to_numpy() > near_c
            agree = (ref[f"value.{method}.ours_only"] == 0) & (ref[f"value.{method}.reference_only"] == 0)
            found_by[method] = found
            values |= {f"{method}.{k}": v for k, v in {
                "poses": (len(n), "count"),
                "solutions.mean": (n.mean(), "count"), "solutions.max": (n.max(), "count"),
                "solutions.odd_poses": (int((n % 2 == 1).sum()), "count"),
                "generating_found.fraction": (found.mean(), "fraction"),
                "twin_found.fraction": (twin.mean(), "fraction"),
                "missed_poses": (int((~found).sum()), "count"),
                "near_singular.poses": (int(near.sum()), "count"),
                "near_singular.missed": (int((near & ~found).sum()), "count"),
                "real_roots.mean": (poses["value.real_roots"].mean(), "count"),
                "rejected_roots.mean": (poses["value.rejected_roots"].mean(), "count"),
                "reference.found_by_ours": (ref[f"value.{method}.common"].sum() / max(1, ref["value.reference"].sum()),
                                            "fraction"),
                "reference.ours_only": (ref[f"value.{method}.ours_only"].sum(), "count"),
                "reference.agree_fraction": (agree.mean(), "fraction"),
                "claim.all_found": (float(found.all() and agree.all()), "bool"),
            }.items()}
        values["reference.poses"] = (len(ref), "count")
        values["reference.solutions"] = (ref["value.reference"].sum(), "count")
        m.add_run(run, values)
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
    return m.frame()

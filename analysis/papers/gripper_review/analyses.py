"""`gripper-review`: the one analysis: the run read back and typed, its counts and checks as metrics, the
dataset exported (dataset.py) and the figure drawn (ANALYSES)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import MetricTable
from analysis.core.report import load_paper_info
from analysis.papers.gripper_review import dataset
from analysis.papers.gripper_review.figures import force_payload_figure
from analysis.papers.gripper_review.metrics import counts, read_review, table2_size_checks, table3_checks
from pipeline.core.runlog import Run

PACKAGE = Path(__file__).resolve().parent


def analyze_dataset(runs: list[Run], figures: Figures) -> pd.DataFrame:
    m = MetricTable()
    for run in runs:
        review = read_review(run)
        gravity = float(run.config["system"]["gravity"])
        found = counts(review)
        checks = table3_checks(review)
        for key in [k for k in checks if k.endswith("payload_max")]:  # Table 3 prints loads as masses
            checks[f"{key}_mass"] = (checks[key][0] / gravity, "kg")
        sizes = table2_size_checks(review)
        m.add_run(run, {**found, **checks, **sizes})
        for row in review.grippers.astype(object).where(review.grippers.notna(), None).itertuples():
            params = {"gripper": f"[{row.ref}] {row.name or ''}".strip(), "gripper_class": row.gripper_class or "",
                      "actuation": row.actuation or "", "parallel_jaw": bool(row.parallel_jaw)}
            for quantity in ("grasp_force", "payload"):
                value = getattr(row, f"{quantity}_n")
                if value is not None:
                    m.add(f"ref-{row.ref}", f"{quantity}", value, "N",
                          {**params, "qualifier": getattr(row, f"{quantity}_qualifier")})
        data_dir = run.path.parents[3]   # <data_dir>/runs/<slug>/<experiment>/<run>.mcap
        dataset.export(review, data_dir, load_paper_info(PACKAGE), run.config, found,
                       run.metadata.get("git_revision", "unknown"))
        force_payload_figure(review.grippers, gravity, figures)
    return m.frame()


ANALYSES = {"dataset": analyze_dataset}

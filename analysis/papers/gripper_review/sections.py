"""`gripper-review`'s report sections: the dataset's counts, the forces and payloads it quotes, and which of
them gripper-force-control's model could be set to."""

from __future__ import annotations

import pandas as pd

from analysis.core.sections import Section, Table
from analysis.papers.gripper_review.metrics import GFC_FORCE_RANGE, SHORT
from pipeline.papers.gripper_review.curated import ACTUATIONS, CLASSES


def _counts(frame: pd.DataFrame) -> Section:
    values = frame.set_index("metric")["value"]
    grid = pd.DataFrame(0, index=pd.Index(CLASSES, name="class"), columns=list(ACTUATIONS))
    for cls in CLASSES:
        for actuation in ACTUATIONS:
            grid.loc[cls, actuation] = int(values.get(f"count.class_actuation.{SHORT[cls]}.{actuation}", 0))
    grid = grid.loc[:, grid.sum() > 0]
    grid["all"] = grid.sum(axis=1)
    per_class = pd.DataFrame({
        "class": list(CLASSES),
        "grippers Sect. 2 describes": [int(values.get(f"count.class.{SHORT[c]}", 0)) for c in CLASSES],
        "references Table 1 lists (reconstructed)": [int(values.get(f"count.table1.class.{SHORT[c]}", 0))
                                                     for c in CLASSES]})
    return Section(
        "The dataset",
        f"{int(values['count.grippers'])} cited grippers, {int(values['count.described'])} described in Sect. 2 "
        "(the others are only listed in Tables 1-2), exported to `data/datasets/gripper-review/` as Parquet and "
        "CSV (`grippers`, `cells` with the provenance of every cell, `table1`, `table1_printed`, `table2`, "
        "`table3`) with a dataset card (`README.md`, Hugging Face metadata header). Every value is quoted by the "
        "review from the cited work; none is measured here. Grippers of Sect. 2 per class (as the prose places "
        "them) and actuation (as the prose describes it):",
        Table(grid, index=True),
        f"Table 1 lists {int(values['count.table1_refs'])} distinct references, Tables 1-2 together "
        f"{int(values['count.tables_refs'])}; {int(values['count.table1.reconstructed_refs'])} of Table 1's "
        "placements had to be reconstructed from the prose (its printed row-spans are shifted: read as printed, "
        f"{int(values['count.table1_printed_vs_prose.class_differs'])} grippers would change class).",
        Table(per_class))


def _quoted(frame: pd.DataFrame) -> Section:
    quoted = frame[frame["run_id"].str.startswith("ref-")].copy()
    quoted["sort"] = quoted["run_id"].str.removeprefix("ref-").astype(int)
    shown = quoted.sort_values(["metric", "sort"])[["metric", "gripper", "gripper_class", "actuation",
                                                    "qualifier", "value"]]
    shown.columns = ["quantity", "gripper", "class", "actuation", "stated as", "value [N]"]
    return Section(
        "Grasp forces and payloads the review quotes",
        "Payloads printed as a mass are weights (× standard gravity); `stated as`: = exactly, ~ about, <= up to, "
        "> more than. These are the points of the figure above.", Table(shown, ".3g"), category="force errors")


def _link(frame: pd.DataFrame) -> Section:
    quoted = frame[(frame["run_id"].str.startswith("ref-")) & (frame["metric"] == "grasp_force")]
    low, high = GFC_FORCE_RANGE
    parallel = quoted[quoted["parallel_jaw"].astype(bool)]
    fits = parallel[parallel["value"].between(low, high)]
    rows = parallel[["gripper", "qualifier", "value"]].assign(
        **{f"in {low:g}-{high:g} N": parallel["value"].between(low, high)})
    rows.columns = ["gripper", "stated as", "grasp force [N]", rows.columns[-1]]
    forces = ",".join(f"{v:g}" for v in fits["value"])
    return Section(
        "Link to gripper-force-control",
        "The parallel-jaw designs the review quotes a grasp force for, against the range "
        f"[gripper-force-control](gripper-force-control.md) verifies ({low:g}-{high:g} N): its model (one finger "
        "closed on an object by motor current, the force measured at the contact) can be set to these forces, "
        "e.g. `python -m pipeline experiment=gripper-force-control/steady-state "
        f"scenario.forces=[{forces}]`. That run would show that drive's force accuracy at these set points, "
        "not these grippers' (their mechanisms and motors are not in the review); no simulation is built or "
        "run for this paper.", Table(rows.reset_index(drop=True), ".3g"), category="force errors")


def report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]:
    frame = metrics.get("dataset")
    if frame is None or frame.empty:
        return []
    review = frame[frame["run_id"] == "review"]
    return [_counts(review), _quoted(frame), _link(frame)]

"""`gripper-review`: the dataset read back from its run, typed, and the counts and checks the targets use.

Every number here is arithmetic on the review's own printed numbers (basis `paper`): counts of what its
tables and prose list, and its Table 3 claims set against the per-gripper numbers its Sect. 2 quotes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from pipeline.core.runlog import Run
from pipeline.papers.gripper_review.curated import CLASSES, COLUMNS, expand_refs

slug = "gripper-review"
# gripper-force-control's grasp-force range (its abstract: "3-48 N"): a force the review quotes for a
# parallel-jaw design inside it is one that model can be set to (sections.py)
GFC_FORCE_RANGE = (3.0, 48.0)
SHORT = {"completely constrained": "cc", "underconstrained": "uc", "deformable": "def"}


@dataclass(frozen=True)
class Review:
    grippers: pd.DataFrame   # one row per gripper, COLUMNS with their dtypes
    cells: pd.DataFrame      # provenance, one row per transcribed cell
    tables: dict[str, pd.DataFrame]  # table name -> its rows (text as printed)


def typed(frame: pd.DataFrame) -> pd.DataFrame:
    """The gripper columns with their declared dtypes (counts as nullable integers, empty text as missing)."""
    out = pd.DataFrame(index=range(len(frame)))
    for name, column in COLUMNS.items():
        values = frame[name].reset_index(drop=True)
        if column.dtype == "string":
            values = values.replace("", pd.NA)
        elif column.dtype == "Int64":
            values = values.round()
        out[name] = values.astype(column.dtype)
    return out


def read_review(run: Run) -> Review:
    tables_topic = run["/review_tables"].reset_index(drop=True)
    tables = {}
    for name, rows in tables_topic.groupby("table", sort=False):
        rows = rows.dropna(axis=1, how="all").drop(columns=["table"])
        tables[name] = rows.rename(columns=lambda c: c.removeprefix("value.")).reset_index(drop=True)
    cells = run["/cells"].reset_index(drop=True).astype({"ref": "int64"})
    return Review(typed(run["/grippers"]), cells, tables)


def expand(tables: dict[str, pd.DataFrame], name: str) -> pd.DataFrame:
    """A table with one row per reference of its `refs` cell (row-spans of the printed Table 1 carried down)."""
    frame = tables[name].copy()
    if name == "table1_printed":
        frame[["class", "design", "actuation"]] = frame[["class", "design", "actuation"]].replace("", np.nan).ffill()
    frame["ref"] = frame["refs"].map(expand_refs)
    return frame.explode("ref").astype({"ref": "int64"})


def counts(review: Review) -> dict[str, tuple[float, str]]:
    """Counts of the dataset and of the review's tables (name -> (value, unit))."""
    g = review.grippers
    t1, t1p, t2 = (expand(review.tables, n) for n in ("table1", "table1_printed", "table2"))
    out = {"count.grippers": (len(g), "count"), "count.described": (int(g["where"].notna().sum()), "count"),
           "count.table1_refs": (t1["ref"].nunique(), "count"),
           "count.table1_printed_refs": (t1p["ref"].nunique(), "count"),
           "count.table2_refs": (t2["ref"].nunique(), "count"),
           "count.tables_refs": (len(set(t1["ref"]) | set(t2["ref"])), "count"),
           "count.table1.classes": (t1["class"].nunique(), "count"),
           "count.table1_printed.classes": (t1p["class"].nunique(), "count"),
           "count.table1.reconstructed_refs": (int((t1["reading"] == "reconstructed").sum()), "count")}
    for cls in CLASSES:
        designs = t1.loc[(t1["class"] == cls) & (t1["design"] != ""), "design"]
        out[f"count.table1.designs.{SHORT[cls]}"] = (designs.nunique(), "count")
        out[f"count.table1.class.{SHORT[cls]}"] = (int((t1["class"] == cls).sum()), "count")
        out[f"count.class.{SHORT[cls]}"] = (int((g["gripper_class"] == cls).sum()), "count")
    for actuation, n in g["actuation"].value_counts().items():
        out[f"count.actuation.{actuation}"] = (int(n), "count")
    for (cls, actuation), n in g.groupby(["gripper_class", "actuation"]).size().items():
        out[f"count.class_actuation.{SHORT[cls]}.{actuation}"] = (int(n), "count")
    # Table 1 against the prose: references both place, in another class
    both = g.dropna(subset=["gripper_class", "table1_class"])
    out["count.table1_vs_prose.class_differs"] = (int((both["gripper_class"] != both["table1_class"]).sum()), "count")
    printed = g.dropna(subset=["gripper_class", "table1_printed_class"])
    out["count.table1_printed_vs_prose.class_differs"] = (
        int((printed["gripper_class"] != printed["table1_printed_class"].str.lower()).sum()), "count")
    return out


def table3_checks(review: Review) -> dict[str, tuple[float, str]]:
    """Table 3's per-class load and range against what Sect. 2 quotes for the grippers of each class."""
    g = review.grippers
    out = {}
    for cls in CLASSES:
        of = g[g["gripper_class"] == cls]
        k = SHORT[cls]
        out[f"table3.{k}.payload_max"] = (of["payload_n"].max(), "N")
        out[f"table3.{k}.opening_max"] = (of["opening_max_m"].max(), "m")
        out[f"table3.{k}.opening_min"] = (of["opening_max_m"].min(), "m")
        out[f"table3.{k}.object_size_min"] = (of["object_size_min_m"].min(), "m")
        out[f"table3.{k}.object_size_max"] = (of["object_size_max_m"].max(), "m")
    return out


def table2_size_checks(review: Review) -> dict[str, tuple[float, str]]:
    """Table 2's size classes against the object sizes Sect. 2 quotes for the grippers it places in them: a
    placement is outside when the quoted sizes do not overlap the class's interval."""
    sizes = review.tables["table2_sizes"].set_index("size")[["min_m", "max_m"]].astype(float)
    t2 = expand(review.tables, "table2")
    placed = t2[t2["type1"] == "Size"].merge(review.grippers[["ref", "object_size_min_m", "object_size_max_m"]],
                                             on="ref")
    placed = placed.dropna(subset=["object_size_min_m", "object_size_max_m"], how="all").copy()
    low = placed["object_size_min_m"].fillna(placed["object_size_max_m"])
    high = placed["object_size_max_m"].fillna(placed["object_size_min_m"])
    placed["class_min_m"] = placed["type2"].map(sizes["min_m"])
    placed["class_max_m"] = placed["type2"].map(sizes["max_m"])
    placed["outside"] = (high < placed["class_min_m"]) | (low > placed["class_max_m"])
    return {"table2.size_checked": (len(placed), "count"),
            "table2.size_outside": (int(placed["outside"].sum()), "count")}

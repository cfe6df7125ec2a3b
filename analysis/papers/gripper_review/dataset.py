"""Export of the review's dataset: Parquet + CSV per table and a dataset card, under
<data_dir>/datasets/gripper-review/, each file published atomically (pipeline.core.files).

    grippers.{parquet,csv}        one row per cited gripper (curated.COLUMNS; SI units, named in the column)
    cells.{parquet,csv}           provenance of every transcribed cell: where in the review, printed value
                                  and unit, the sentence quoted
    table1.{parquet,csv}          Table 1 reconstructed (reading: verbatim | reconstructed)
    table1_printed.{…}, table2.{…}, table3.{…}   the tables as printed (text)
    README.md                     the card, with the metadata header the Hugging Face hub reads

`read_csv` types a CSV back with the declared dtypes: read_csv(csv) equals the Parquet table.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from jinja2 import Environment, FileSystemLoader, StrictUndefined

from analysis.papers.gripper_review.metrics import Review
from pipeline.core import files
from pipeline.papers.gripper_review.curated import COLUMNS

TEMPLATES = Path(__file__).resolve().parent
TABLES = ("table1", "table1_printed", "table2", "table3")


def dataset_dir(data_dir: Path) -> Path:
    return Path(data_dir) / "datasets" / "gripper-review"


def frames(review: Review) -> dict[str, pd.DataFrame]:
    out = {"grippers": review.grippers, "cells": review.cells.astype(str).astype("string").assign(
        ref=review.cells["ref"].astype("int64"))}
    for name in TABLES:
        table = review.tables[name].drop(columns=["row"])
        out[name] = table.astype("string")
    return out


def read_csv(path: Path) -> pd.DataFrame:
    """A CSV of this dataset with its declared dtypes (grippers: COLUMNS; other tables: text, `ref` integer)."""
    path = Path(path)
    if path.stem == "grippers":
        frame = pd.read_csv(path, dtype={n: c.dtype for n, c in COLUMNS.items() if c.dtype not in ("boolean",)},
                            keep_default_na=False, na_values={n: [""] for n in COLUMNS})
        return frame.astype({n: c.dtype for n, c in COLUMNS.items()})[list(COLUMNS)]
    frame = pd.read_csv(path, dtype="string", keep_default_na=False)
    return frame.astype({"ref": "int64"}) if "ref" in frame else frame


def card(review: Review, info: dict, config: dict, counts: dict, revision: str) -> str:
    env = Environment(loader=FileSystemLoader(TEMPLATES), undefined=StrictUndefined, keep_trailing_newline=True)
    return env.get_template("card.md.j2").render(
        info=info, columns=COLUMNS, n_grippers=len(review.grippers), n_cells=len(review.cells), counts=counts,
        config=config, revision=revision, tables=TABLES)


def export(review: Review, data_dir: Path, info: dict, config: dict, counts: dict, revision: str) -> list[Path]:
    """Every table as Parquet and CSV, and the card; `revision` is the code revision that made the run."""
    out = dataset_dir(data_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, frame in frames(review).items():
        for suffix, write in ((".parquet", lambda f, p: f.to_parquet(p, index=False)),
                              (".csv", lambda f, p: f.to_csv(p, index=False))):
            with files.atomic_path(out / f"{name}{suffix}") as tmp:
                write(frame, tmp)
            written.append(out / f"{name}{suffix}")
    written.append(files.write_text(out / "README.md", card(review, info, config, counts, revision)))
    return written

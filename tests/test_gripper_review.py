"""gripper-review: the transcription is typed and checked, its quotes are the review's, the exported dataset
round-trips, its counts recomputed from the exported rows are the review's or are declared disagreements,
and a malformed entry is refused in one line."""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import pandas as pd
import pytest
import yaml

from analysis.core.targets import load_targets
from analysis.papers.gripper_review.dataset import read_csv
from pipeline.core.checks import BadInput, preflight
from pipeline.papers.gripper_review.curated import (
    COLUMNS,
    GRIPPERS_FILE,
    MalformedEntry,
    curate,
    expand_refs,
    load_tables,
    load_yaml,
    table1_rows,
)

from .conftest import ROOT, run_cli

PAPER = Path("/work/shared/papers/gripper-review.md")  # the review's text, where this machine has it
G = 9.80665


@pytest.fixture(scope="module")
def entries() -> list[dict]:
    return load_yaml(GRIPPERS_FILE)


@pytest.fixture(scope="module")
def tables() -> dict:
    return load_tables()


@pytest.fixture(scope="module")
def rows(entries, tables) -> dict[int, dict]:
    return {r["ref"]: r for r in curate(entries, tables, G).rows}


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> Path:
    data_dir = tmp_path_factory.mktemp("review") / "data"
    for module in ("pipeline", "analysis"):
        done = run_cli(module, "experiment=gripper-review/dataset", f"data_dir={data_dir}", "progress=false"
                       if module == "pipeline" else "stage=all", timeout=120)
        assert done.returncode == 0, done.stderr[-2000:]
    return data_dir


def test_values_are_converted_to_si_with_their_printed_form_kept(rows):
    assert rows[12]["grasp_force_n"] == 8.9 and rows[12]["grasp_force_tol_n"] == 0.35
    assert rows[12]["opening_min_m"] == 0 and rows[12]["opening_max_m"] == pytest.approx(0.103)
    assert rows[32]["grasp_force_n"] == pytest.approx(0.016) and rows[32]["opening_max_m"] == pytest.approx(2.2e-3)
    assert rows[33]["payload_n"] == pytest.approx(5 * G) and rows[33]["payload_qualifier"] == "<="
    assert rows[39]["payload_n"] == pytest.approx(0.8 * G)                     # 800 g
    assert rows[50]["object_size_min_m"] == pytest.approx(0.15) and rows[50]["object_size_max_m"] == 0.5
    assert rows[13]["motion_min_rad"] == pytest.approx(math.radians(-34.4))
    assert rows[73]["pressure_max_pa"] == pytest.approx(10e6)
    assert rows[60]["grasp_force_qualifier"] == ">"
    assert all(set(r) == set(COLUMNS) for r in rows.values())


def test_every_quote_is_the_reviews_own_sentence(entries):
    if not PAPER.exists():
        pytest.skip(f"the review's text is not at {PAPER}")

    def normal(text: str) -> str:
        for tex, char in (("^\\circ", "°"), ("\\pm", "±"), ("\\phi", "φ"), ("\\times", "×"), ("$", "")):
            text = text.replace(tex, char)
        return re.sub(r"\s+", " ", text)

    paper = normal(PAPER.read_text())
    missing = [(e["ref"], field, spec["quote"]) for e in entries for field, spec in e.items()
               if isinstance(spec, dict) and normal(spec["quote"]) not in paper]
    assert not missing


def test_table1_reconstruction_moves_references_and_loses_none(tables):
    printed = [r["ref"] for r in table1_rows(tables, "printed")]
    rebuilt = [r["ref"] for r in table1_rows(tables, "reconstructed")]
    assert sorted(printed) == sorted(rebuilt) and len(set(rebuilt)) == len(rebuilt) == 61
    assert expand_refs("[5,9,12,13,55–62]") == [5, 9, 12, 13, 55, 56, 57, 58, 59, 60, 61, 62]


def test_every_cited_gripper_is_one_row(rows, tables):
    listed = {r["ref"] for r in table1_rows(tables)} | {r for row in tables["table2"] for r in expand_refs(row[3])}
    assert listed <= set(rows) and len(rows) == 70


MALFORMED = [
    (lambda e: e[0].pop("quote", None) or e[0]["fingers"].pop("quote"), "gripper [6]: fingers must be a mapping with"),
    (lambda e: e[0].update(**{"class": "soft"}), "gripper [6]: class='soft' is not one of"),
    (lambda e: e[4]["grasp_force"].update(unit="lbf"), "gripper [32]: grasp_force.unit='lbf' is not one of"),
    (lambda e: e[4]["grasp_force"].update(value="16 mN"), "gripper [32]: grasp_force.value='16 mN' is not a finite"),
    (lambda e: e[4]["grasp_force"].update(unit="mm"), "gripper [32]: grasp_force in mm is not a N quantity"),
    (lambda e: e.append(copy.deepcopy(e[0])), "gripper [6] is listed twice"),
    (lambda e: e[0].update(fingerz=3), "gripper [6]: unknown fields ['fingerz']"),
    (lambda e: e[0]["fingers"].update(value=2.5), "gripper [6]: fingers=2.5 must be a positive whole number"),
]


@pytest.mark.parametrize("spoil, says", MALFORMED)
def test_a_malformed_entry_is_refused_in_one_line(entries, tables, spoil, says):
    spoiled = copy.deepcopy(entries)
    spoil(spoiled)
    with pytest.raises(MalformedEntry) as err:
        curate(spoiled, tables, G)
    message = str(err.value)
    assert message.startswith(says) and "\n" not in message and len(message) < 300


def test_a_bad_parameter_is_refused_before_anything_runs():
    with pytest.raises(BadInput, match="table2_large_unit='km' is not allowed"):
        preflight(["experiment=gripper-review/dataset", "scenario.table2_large_unit=km"])
    with pytest.raises(BadInput, match=r"system\.gravity=98"):
        preflight(["experiment=gripper-review/dataset", "system.gravity=98"])


def test_export_round_trips_and_keeps_the_declared_dtypes(exported):
    folder = exported / "datasets" / "gripper-review"
    names = {p.stem for p in folder.glob("*.parquet")}
    assert names == {"grippers", "cells", "table1", "table1_printed", "table2", "table3"}
    for name in names:
        parquet = pd.read_parquet(folder / f"{name}.parquet")
        pd.testing.assert_frame_equal(read_csv(folder / f"{name}.csv"), parquet)
    grippers = pd.read_parquet(folder / "grippers.parquet")
    assert {n: str(t) for n, t in grippers.dtypes.items()} == {n: c.dtype for n, c in COLUMNS.items()}
    assert not list(folder.glob(".*"))          # no temporary left behind


def test_card_has_the_hub_header_and_every_column(exported):
    text = (exported / "datasets" / "gripper-review" / "README.md").read_text()
    header = yaml.safe_load(text.split("---")[1])
    assert header["license"] == "cc-by-4.0" and header["configs"][0]["data_files"] == "grippers.parquet"
    assert all(f"| `{name}` | {c.dtype} | {c.unit} |" in text for name, c in COLUMNS.items())


def test_counts_from_the_exported_rows_are_the_reviews_or_declared_disagreements(exported):
    folder = exported / "datasets" / "gripper-review"
    table1 = read_csv(folder / "table1.csv")
    table1["ref"] = table1["refs"].map(expand_refs)
    table1 = table1.explode("ref")
    stated = load_tables()["stated"]
    # recomputed from the exported rows, independently of the analysis
    recomputed = {"S2.classes": table1["class"].nunique(),
                  "AppA.studies.table1": table1["ref"].nunique()}
    for cls, target in (("completely constrained", "S2.1.designs"), ("underconstrained", "S2.3.designs"),
                        ("deformable", "S2.4.designs")):
        recomputed[target] = table1.loc[(table1["class"] == cls) & (table1["design"] != ""), "design"].nunique()
    targets = load_targets(ROOT / "analysis/papers/gripper_review/targets.csv").set_index("target_id")
    report = pd.read_csv(exported / "report" / "targets.csv")
    report = report[report["slug"] == "gripper-review"].set_index("target_id")
    assert stated["studies_reviewed"] == float(targets.loc["AppA.studies.table1", "value"])
    for target, value in recomputed.items():
        assert report.loc[target, "pipeline_value"] == value
        agrees = value == float(targets.loc[target, "value"])
        assert report.loc[target, "status"] == ("agrees" if agrees else "disagrees")
        assert agrees or targets.loc[target, "cause"] == "paper-inconsistent", target
    # every disagreement is declared, with the evidence in its note
    disagree = report[report["status"] == "disagrees"]
    assert (targets.loc[disagree.index, "cause"] == "paper-inconsistent").all()
    assert set(report["status"]) <= {"agrees", "disagrees"}
    assert (exported / "figures" / "gripper-review" / "dataset" / "force-payload.png").stat().st_size > 10_000

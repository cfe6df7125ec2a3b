"""simulate -> analyze -> report on a temporary data_dir: the report's files, its CSV contract, and the
statuses the reproduction must reach."""

from __future__ import annotations

import pandas as pd

from analysis.core import stages
from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli
from .test_report import assert_tables_whole, markdown_rows_whole


def test_pipeline_to_report(data_dir):
    for args in (["experiment=ur5-ik-fsm/tables"],
                 ["experiment=ur5-ik-fsm/compute-time"],  # targets point at the default run
                 ["experiment=ur5-ik-fsm/singular-paths", "scenario.paths=[wrist]", "scenario.duration=1.0"]):
        proc = run_cli("pipeline", *args, f"data_dir={data_dir}", "progress=false")
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    report = data_dir / "report"
    for name in ("index.md", "index.html", "ur5-ik-fsm.md", "ur5-ik-fsm.html", "targets.csv"):
        assert (report / name).is_file(), name
    targets = pd.read_csv(report / "targets.csv")
    assert list(targets.columns) == ["slug", "target_id", "category", "quantity", "where", "paper_value", "op",
                                     "pipeline_value", "band_min", "band_max", "deviation", "relative_deviation",
                                     "unit", "mode", "basis", "tolerance", "status", "cause", "note", "experiment",
                                     "run"]
    assert set(targets["status"]) <= {"match", "close", "consistent", "miss", "not run", "not-reproducible",
                                      "agrees", "disagrees"}
    targets = targets[targets["slug"] == "ur5-ik-fsm"]   # other papers' targets have no runs here
    status = targets.set_index("target_id")["status"]
    tables = status[status.index.str.match(r"T[346]\.")]
    assert len(tables) >= 60 + 60 + 10 and (tables == "match").all()
    assert status["agreement"] == "match" and status["T5.4"] == "match"
    assert status["T5.4.printed"] == "not-reproducible"
    # the paper's smoothness claim fails on the wrist path: Algorithm 2 flips the wrist
    assert status["claim.smooth"] == "miss"
    ur5 = targets[targets["slug"] == "ur5-ik-fsm"]  # other papers have no runs in this data_dir
    assert ur5.loc[ur5["status"] != "not-reproducible", "pipeline_value"].notna().all()
    assert "ur5-ik-fsm" in (report / "index.md").read_text()
    assert list((data_dir / "figures/ur5-ik-fsm/singular-paths").glob("*.png"))
    assert list((data_dir / "figures/ur5-ik-fsm/singular-paths").glob("*.svg"))
    # every page of the report: every table row has as many cells as its header, nothing cites the spec
    pages = sorted(report.glob("*.html"))
    assert len(pages) >= 10
    for page in pages:
        html = page.read_text()
        assert_tables_whole(html, page.name)
        markdown_rows_whole(page.with_suffix(".md").read_text(), page.with_suffix(".md").name)
        assert "spec §" not in html
    index = (report / "index.html").read_text()
    assert all(s in index for s in ("match", "close", "not run", "misses still open", "self-consistency"))

    # the experiments were analysed side by side (one process per core): one process gives the same metrics
    metrics = {p.name: pd.read_parquet(p) for p in sorted((data_dir / "metrics/ur5-ik-fsm").glob("*.parquet"))}
    assert len(metrics) == 3 and stages.run(data_dir, "ur5-ik-fsm", "analyze", workers=1) == 0
    for name, frame in metrics.items():
        pd.testing.assert_frame_equal(pd.read_parquet(data_dir / "metrics/ur5-ik-fsm" / name), frame)

    run = read_run(run_files(data_dir / "runs/ur5-ik-fsm/singular-paths")[0])
    assert run.metadata["slug"] == "ur5-ik-fsm" and run.metadata["git_revision"]
    assert "model.xml" in run.attachments and "config.yaml" in run.attachments
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/tf"} <= set(run.topic_names)


def test_analysis_of_missing_runs_says_what_to_do(data_dir):
    data_dir.mkdir()
    proc = run_cli("analysis", "experiment=ur5-ik-fsm/tables", f"data_dir={data_dir}")
    assert proc.returncode == 1 and "python -m pipeline experiment=ur5-ik-fsm/tables" in proc.stderr

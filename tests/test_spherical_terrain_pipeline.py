"""Spherical robots on 3-D terrain, end to end: simulate (short runs) -> analyze -> report, bad input."""

from __future__ import annotations

import pandas as pd

from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli


def test_paths_and_a_short_physics_check_to_report(data_dir):
    for args in (["experiment=spherical-terrain/paths"],
                 ["experiment=spherical-terrain/physics-check", "system.duration=2", "scenario.classes=[rt,rs]"],
                 ["-m", "experiment=spherical-terrain/gain-search", "scenario.paths=[diamond]",
                  "system.controller.class_rs.k_alpha=1,4"]):
        proc = run_cli("pipeline", *args, f"data_dir={data_dir}", "progress=false")
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")         # every experiment with runs, then the report
    assert proc.returncode == 0, proc.stderr
    targets = pd.read_csv(data_dir / "report" / "targets.csv")
    mine = targets[targets["slug"] == "spherical-terrain"].set_index("target_id")
    assert mine.loc[mine["mode"] != "not reproducible", "pipeline_value"].notna().all()
    status = mine["status"]
    assert (status[status.index.str.startswith("path.")] == "match").all()
    assert status["converge.3r-circle"] == "match" and status["agility.vertex"] == "match"
    assert "Physics check" in (data_dir / "report" / "spherical-terrain.md").read_text()
    # the gain search is the band of the RS-SR targets; its unit-gain run is the default run, batched alone
    search = pd.read_parquet(data_dir / "metrics/spherical-terrain/gain-search.parquet")
    paths = pd.read_parquet(data_dir / "metrics/spherical-terrain/paths.parquet")
    unit = search[search["run_id"].str.startswith("rs-diamond__") & search["run_id"].str.contains("k_alpha=1")]
    default = paths[paths["run_id"] == "rs-diamond"]
    for metric in ("error_after_40s.rms", "tilt.max_abs"):
        assert unit.loc[unit["metric"] == metric, "value"].item() == default.loc[default["metric"] == metric,
                                                                                 "value"].item()
    assert search.loc[search["metric"] == "pairs", "value"].item() == 2
    band = mine.loc["converge.rs-diamond"]
    assert band["band_min"] <= band["pipeline_value"] <= band["band_max"]
    runs = run_files(data_dir / "runs/spherical-terrain/paths")
    assert len(runs) == 8
    run = read_run(runs[0])
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/tf", "/pursuit"} <= set(run.topic_names)
    physics = read_run(run_files(data_dir / "runs/spherical-terrain/physics-check")[0])
    assert physics.ok and "model.xml" in physics.attachments
    assert list((data_dir / "figures/spherical-terrain/paths").glob("fig12b-rs-tilt.png"))


def test_bad_input_is_refused(data_dir):
    for bad in ("system.tilt_limit=2", "system.controller.class_rs.k_phi=-1"):
        proc = run_cli("pipeline", "experiment=spherical-terrain/paths", bad, f"data_dir={data_dir}")
        assert proc.returncode == 2 and bad.split("=")[0] in proc.stderr, (bad, proc.stderr)

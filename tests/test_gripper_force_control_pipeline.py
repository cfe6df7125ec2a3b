"""gripper-force-control end to end, as a user runs it: every experiment (the surface as a Hydra sweep of two
points, the friction band at the ends of its range, the Monte-Carlo shortened), the analysis, and the statuses
the report must reach."""

from __future__ import annotations

import pandas as pd
import pytest

from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli

SLUG = "gripper-force-control"


def test_experiments_to_report(data_dir):
    runs = (
        ["experiment=gripper-force-control/tables"],
        ["experiment=gripper-force-control/force-sag"],
        ["-m", "experiment=gripper-force-control/force-sag-friction", "system.friction.m1_coulomb=0.01,0.045"],
        ["-m", "experiment=gripper-force-control/force-error-surface", "scenario.omega=0.9,5.6"],
        ["experiment=gripper-force-control/pick-and-place"],
        ["experiment=gripper-force-control/steady-state", "scenario.grasps=3", "scenario.duration=0.15"],
    )
    for args in runs:   # sweep_dir=data_dir: the band sweeps beside the default runs, as their DVC stages run them
        proc = run_cli("pipeline", *args, f"data_dir={data_dir}", f"sweep_dir={data_dir}", "progress=false")
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    targets = pd.read_csv(data_dir / "report/targets.csv")
    targets = targets[targets["slug"] == SLUG].set_index("target_id")
    status = targets["status"]
    assert status["F8.ideal"] == "match"                       # the genuine check of Fig. 8
    assert status["T3.schunk"] == "miss" and status["T3.schunk.printed"] == "disagrees"   # Table 3's misprint
    assert (status[status.index.str.startswith("text.")] == "agrees").all()     # the paper's own arithmetic
    # Tables 3-5's ratios and the tomato bound come from the simulation; only the paper's arithmetic is `paper`
    simulated = targets[targets.index.str.match(r"(T[345]\.|tomato\.force$)") & (targets["mode"] != "not reproducible")
                        & ~targets.index.str.endswith(".printed")]
    assert len(simulated) >= 17 and (simulated["basis"] == "simulation").all()
    assert set(targets.loc[targets["basis"] == "paper", "mode"]) == {"consistency"}
    assert status["tomato.rotate"] != "match"                  # 45° cannot take 130 ms at the stated limits
    live = targets[targets["mode"] != "not reproducible"]
    assert live["pipeline_value"].notna().all(), live[live["pipeline_value"].isna()].index.tolist()
    # the friction band: more friction, more sag, in both cases; the default run lies inside its band
    band = pd.read_parquet(data_dir / f"metrics/{SLUG}/force-sag-friction.parquet")
    sag = band[band["metric"] == "force_error.sag"].set_index("run_id")["value"]
    for case in ("friction-mujoco", "no-feedforward-mujoco"):
        low, high = (sag[f"{case}__system.friction.m1_coulomb={c}"] for c in ("0.01", "0.045"))
        assert high > 2 * low
        row = targets[targets["run"] == case].iloc[0]
        assert (row["band_min"], row["band_max"]) == pytest.approx((100 * low, 100 * high))
        assert row["band_min"] < row["pipeline_value"] < row["band_max"]
    assert status["F8.no-ff"] in ("match", "consistent")       # never merged: a band makes it consistent
    surface = pd.read_parquet(data_dir / f"metrics/{SLUG}/force-error-surface.parquet")
    assert surface.loc[surface["metric"] == "points", "value"].item() == 2    # both sweep points assembled
    for figure in ("force-sag/fig8-force-sag", "force-error-surface/fig9-force-error-surface",
                   "steady-state/fig7-monte-carlo", "pick-and-place/pick-and-place"):
        assert (data_dir / f"figures/{SLUG}/{figure}.png").is_file(), figure

    run = read_run(data_dir / f"runs/{SLUG}/force-sag/ideal-mujoco.mcap")
    assert {"/wrench", "/wrench/commanded", "/joint_state", "/reference", "/command", "/tracking_error",
            "/tf"} <= set(run.topic_names)
    assert "model.xml" in run.attachments
    assert len(run_files(data_dir / f"runs/{SLUG}/force-error-surface")) == 2


def test_bad_input_is_refused(data_dir):
    proc = run_cli("pipeline", "experiment=gripper-force-control/force-sag", "scenario.force=-1",
                   f"data_dir={data_dir}")
    assert proc.returncode == 2 and "scenario.force" in proc.stderr
    assert not (data_dir / "runs").exists()

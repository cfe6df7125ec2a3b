"""scara-half-derivative end to end through the CLIs: the set-point, a two-point Hydra sweep of the maps and
the report built from them; the runs' MCAP contract."""

from __future__ import annotations

import pandas as pd
import pytest

from pipeline.core.runlog import read_runs

from .conftest import run_cli

SLUG = "scara-half-derivative"


@pytest.mark.slow
def test_setpoint_and_a_maps_sweep_to_report(data_dir):
    proc = run_cli("pipeline", f"experiment={SLUG}/setpoint", f"data_dir={data_dir}", "progress=false")
    assert proc.returncode == 0, proc.stderr
    # a real multirun (joblib): two grid points, shortened to the first move
    proc = run_cli("pipeline", "-m", f"experiment={SLUG}/maps", f"data_dir={data_dir}", "progress=false",
                   "scenario.d_xyz=4000,5000", "scenario.k_xyz=80000", "scenario.duration=0.5")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    runs = read_runs(data_dir / "runs" / SLUG / "maps")
    assert len(runs) == 2 and all(r.ok for r in runs)
    assert {r.params["scenario.d_xyz"] for r in runs} == {4000, 5000}   # typed from the resolved config
    run = runs[0]
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/compute_time", "/tf"} <= set(run.topic_names)
    assert "model.yaml" in run.attachments and "config.yaml" in run.attachments

    grid = pd.read_parquet(data_dir / "metrics" / SLUG / "maps.parquet")
    ice = grid[grid["metric"] == "ice"].set_index("d_xyz")["value"]
    assert sorted(ice.index) == [4000.0, 5000.0] and (ice > 0).all()
    targets = pd.read_csv(data_dir / "report" / "targets.csv").set_index("target_id")
    for target in ("setpoint.v_max", "setpoint.a_max", "x_ref.x", "x_ref.z", "theta3p"):
        assert targets.loc[target, "status"] == "match", target
    assert targets.loc["T2.tau4_max.kd.k8e5", "status"] == "not-reproducible"
    assert (data_dir / "figures" / SLUG / "maps" / "fig6-maps-k80000.png").is_file()

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
    # a real multirun (joblib) over the stiffness, each job a 2 × 2 grid simulated together, shortened
    proc = run_cli("pipeline", "-m", f"experiment={SLUG}/maps", f"data_dir={data_dir}", "progress=false",
                   "scenario.d_xyz=[4000,5000]", "scenario.hd_xyz=[0,8500]", "scenario.k_xyz=80000,10000",
                   "scenario.duration=0.5")
    assert proc.returncode == 0, proc.stderr
    # a sensitivity sweep point: its runs and aggregates carry the sweep's suffix
    proc = run_cli("pipeline", "-m", f"experiment={SLUG}/maps-sensitivity", f"data_dir={data_dir}", "progress=false",
                   "scenario.d_xyz=[4000,5000]", "scenario.hd_xyz=[0,8500]", "scenario.k_xyz=[80000]",
                   "scenario.duration=0.5", "system.control.implementation=continuous")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    runs = read_runs(data_dir / "runs" / SLUG / "maps")
    assert len(runs) == 8 and all(r.ok for r in runs)
    assert {r.params["scenario.k_xyz"] for r in runs} == {"80000", "10000"}
    run = runs[0]
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/tf"} <= set(run.topic_names)
    assert "model.yaml" in run.attachments and "config.yaml" in run.attachments

    grid = pd.read_parquet(data_dir / "metrics" / SLUG / "maps.parquet")
    ice = grid[(grid["metric"] == "ice") & (grid["k_xyz"] == 80000)].set_index(["d_xyz", "hd_xyz"])["value"]
    assert sorted(ice.index) == [(4000.0, 0.0), (4000.0, 8500.0), (5000.0, 0.0), (5000.0, 8500.0)] and (ice > 0).all()
    # each stiffness has its aggregates, named like its runs by the other overrides (here the short duration)
    assert {"k80000__scenario.duration=0.5", "k10000__scenario.duration=0.5"} <= set(grid["run_id"])
    swept = pd.read_parquet(data_dir / "metrics" / SLUG / "maps-sensitivity.parquet")
    assert "k80000__scenario.duration=0.5,system.control.implementation=continuous" in set(swept["run_id"])
    continuous = read_runs(data_dir / "runs" / SLUG / "maps-sensitivity")[0]
    # continuous K and D: the torque is logged at every 2.5 ms integration step, not once per 5 ms period
    assert len(continuous["/command"]) == 2 * (len(continuous["/tracking_error"]) - 1)
    targets = pd.read_csv(data_dir / "report" / "targets.csv").set_index("target_id")
    for target in ("setpoint.v_max", "setpoint.a_max", "x_ref.x", "x_ref.z", "theta3p"):
        assert targets.loc[target, "status"] == "match", target
    assert targets.loc["T2.tau4_max.kd.k8e5", "status"] == "not-reproducible"
    assert (data_dir / "figures" / SLUG / "maps" / "fig6-maps-k80000__scenario.duration=0.5.png").is_file()

"""scara-half-derivative end to end through the CLIs: the set-point, a two-point Hydra sweep of the maps and
the report built from them; the runs' MCAP contract."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from analysis.core.errors import error_stats
from pipeline.core.runlog import read_runs

from .conftest import run_cli

SLUG = "scara-half-derivative"


@pytest.mark.slow
def test_setpoint_and_a_maps_sweep_to_report(data_dir):
    proc = run_cli("pipeline", f"experiment={SLUG}/setpoint", f"data_dir={data_dir}", "progress=false")
    assert proc.returncode == 0, proc.stderr
    # a real multirun (joblib) over the stiffness, each job a 2 × 2 grid simulated together, shortened
    proc = run_cli("pipeline", "-m", f"experiment={SLUG}/maps", f"data_dir={data_dir}", f"sweep_dir={data_dir}",
                   "progress=false", "scenario.d_xyz=[4000,5000]", "scenario.hd_xyz=[0,8500]",
                   "scenario.k_xyz=80000,10000", "scenario.duration=0.5", "execute.log_dt=0.0025")
    assert proc.returncode == 0, proc.stderr
    # a sensitivity sweep point: its runs and aggregates carry the sweep's suffix
    proc = run_cli("pipeline", "-m", f"experiment={SLUG}/maps-sensitivity", f"data_dir={data_dir}",
                   f"sweep_dir={data_dir}", "progress=false",
                   "scenario.d_xyz=[4000,5000]", "scenario.hd_xyz=[0,8500]", "scenario.k_xyz=[80000]",
                   "scenario.duration=0.5", "system.control.implementation=continuous", "execute.log_dt=0.0025")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    runs = read_runs(data_dir / "runs" / SLUG / "maps")
    assert len(runs) == 8 and all(r.ok for r in runs)
    assert {r.params["scenario.k_xyz"] for r in runs} == {80000, 10000}
    run = runs[0]
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/tf"} <= set(run.topic_names)
    assert "model.yaml" in run.attachments and "config.yaml" in run.attachments

    grid = pd.read_parquet(data_dir / "metrics" / SLUG / "maps.parquet")
    ice = grid[(grid["metric"] == "ice") & (grid["k_xyz"] == 80000)].set_index(["d_xyz", "hd_xyz"])["value"]
    assert sorted(ice.index) == [(4000.0, 0.0), (4000.0, 8500.0), (5000.0, 0.0), (5000.0, 8500.0)] and (ice > 0).all()
    # each stiffness has its aggregates, named like its runs by the other overrides (here the short duration)
    suffix = "execute.log_dt=0.0025,scenario.duration=0.5"
    assert {f"k80000__{suffix}", f"k10000__{suffix}"} <= set(grid["run_id"])
    swept = pd.read_parquet(data_dir / "metrics" / SLUG / "maps-sensitivity.parquet")
    assert f"k80000__{suffix},system.control.implementation=continuous" in set(swept["run_id"])
    continuous = read_runs(data_dir / "runs" / SLUG / "maps-sensitivity")[0]
    # continuous K and D: the torque is logged at every 2.5 ms integration step, not once per 5 ms period
    assert len(continuous["/command"]) == len(continuous["/tracking_error"]) - 1 == 2 * len(runs[0]["/command"])
    # the indexes a run computes on its steps are those of its logged signals (logged at every step here)
    for run in (runs[0], continuous):
        err, command = run["/tracking_error"], run["/command"]
        indexes = run["/closed_loop/indexes"].iloc[0]
        t = err.index.to_numpy()
        for i, axis in enumerate("xyz"):
            stats = error_stats(t, err[f"error.{axis}"].to_numpy(), "e", "m")
            assert indexes[f"e_max_m[{i}]"] == pytest.approx(stats["e.max"][0], rel=1e-12)
            assert indexes[f"e_mean_m[{i}]"] == pytest.approx(stats["e.mean"][0], rel=1e-12)
        ise = sum(error_stats(t, err[f"error.{a}"].to_numpy(), "e", "m")["e.ise"][0] for a in "xyz")
        assert indexes["ise_m2s"] == pytest.approx(ise, rel=1e-9)
        tau = command[[f"value.theta{i}" for i in range(1, 5)]].to_numpy()
        assert indexes["ice_N2m2s"] == pytest.approx((tau ** 2).sum() * np.diff(command.index).mean(), rel=1e-9)
    targets = pd.read_csv(data_dir / "report" / "targets.csv").set_index("target_id")
    for target in ("setpoint.v_max", "setpoint.a_max", "x_ref.x", "x_ref.z", "theta3p"):
        assert targets.loc[target, "status"] == "match", target
    assert targets.loc["T2.tau4_max.kd.k8e5", "status"] == "not-reproducible"
    assert (data_dir / "figures" / SLUG / "maps" / f"fig6-maps-k80000__{suffix}.png").is_file()

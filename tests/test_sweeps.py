"""Sweeps beyond one process: a cluster launcher (Submitit's local executor standing in for SLURM) that runs
several sweep points per job, into the sweep's own folder, which the analysis reads like the default data."""

from __future__ import annotations

import pandas as pd
import pytest

from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli

ONE_RUN = ["experiment=spherical-terrain/paths", "scenario.classes=[2r]", "scenario.paths=[circle]"]


def test_a_cluster_sweep_runs_chunks_of_points_per_job_into_its_own_folder(data_dir):
    pytest.importorskip("hydra_plugins.hydra_submitit_launcher", reason="the [slurm] extra is not installed")
    sweep = data_dir / "sweeps" / "gains"
    proc = run_cli("pipeline", "-m", *ONE_RUN, "system.controller.gain_scale=0.5,1,2", "hydra/launcher=slurm_local",
                   "hydra.launcher.configs_per_job=2", f"data_dir={data_dir}", f"sweep_dir={sweep}")
    assert proc.returncode == 0, proc.stderr
    assert "3 sweep points in 2 jobs of up to 2" in proc.stdout + proc.stderr
    runs = [read_run(p) for p in run_files(sweep / "runs/spherical-terrain/paths")]
    assert sorted(r.params["system.controller.gain_scale"] for r in runs) == ["0.5", "1", "2"]
    assert all(r.ok for r in runs)
    jobs = sorted(p.name for p in (sweep / ".hydra/.submitit").iterdir() if p.name.isdigit())
    assert len(jobs) == 2                                        # two processes, the first ran two points
    assert {r.config["data_dir"] for r in runs} == {str(sweep)}     # each run records where it was written
    assert not (data_dir / "runs").exists()                      # nothing beside the default runs

    proc = run_cli("analysis", f"data_dir={sweep}", "experiment=spherical-terrain/paths")
    assert proc.returncode == 0, proc.stderr
    metrics = pd.read_parquet(sweep / "metrics/spherical-terrain/paths.parquet")
    assert metrics.loc[metrics["run_id"] != "all", "run_id"].nunique() == 3
    targets = pd.read_csv(sweep / "report/targets.csv")
    ur5 = set(targets.loc[targets["slug"] == "ur5-ik-fsm", "status"])    # a paper this sweep did not run
    assert "not run" in ur5 and ur5 <= {"not run", "not-reproducible"}
    assert (sweep / "summary/status.json").is_file()


def test_a_sweep_without_the_extra_is_refused_in_one_line(data_dir, monkeypatch):
    from pipeline.core import checks
    from pipeline.core.checks import BadInput, preflight

    monkeypatch.setattr(checks.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(BadInput, match=r"hydra/launcher=slurm needs its extra: pip install -e '\.\[slurm\]'"):
        preflight([*ONE_RUN, "system.controller.gain_scale=0.5,1", "hydra/launcher=slurm", f"data_dir={data_dir}"])

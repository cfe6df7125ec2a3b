"""Sweeps beyond one process: a cluster launcher (Submitit's local executor standing in for SLURM) that runs
several sweep points per job, into the sweep's own folder, which the analysis reads like the default data."""

from __future__ import annotations

import pandas as pd
import pytest

from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli

TABLES = "experiment=ur5-ik-fsm/tables"   # two runs of milliseconds per point: the launcher is what is tested


def test_a_cluster_sweep_runs_chunks_of_points_per_job_into_its_own_folder(data_dir):
    pytest.importorskip("hydra_plugins.hydra_submitit_launcher", reason="the [slurm] extra is not installed")
    sweep = data_dir / "sweeps" / "seeds"
    proc = run_cli("pipeline", "-m", TABLES, "seed=0,1,2", "hydra/launcher=slurm_local",
                   "hydra.launcher.configs_per_job=2", f"data_dir={data_dir}", f"sweep_dir={sweep}")
    assert proc.returncode == 0, proc.stderr
    assert "3 sweep points in 2 jobs of up to 2" in proc.stdout + proc.stderr
    runs = [read_run(p) for p in run_files(sweep / "runs/ur5-ik-fsm/tables")]
    assert sorted(r.params["seed"] for r in runs) == [0, 0, 1, 1, 2, 2]  # typed
    assert all(r.ok for r in runs)
    jobs = sorted(p.name for p in (sweep / ".hydra/.submitit").iterdir() if p.name.isdigit())
    assert len(jobs) == 2                                        # two processes, the first ran two points
    assert {r.config["data_dir"] for r in runs} == {str(sweep)}     # each run records where it was written
    assert not (data_dir / "runs").exists()                      # nothing beside the default runs

    proc = run_cli("analysis", f"data_dir={sweep}", "experiment=ur5-ik-fsm/tables")
    assert proc.returncode == 0, proc.stderr
    metrics = pd.read_parquet(sweep / "metrics/ur5-ik-fsm/tables.parquet")
    assert set(metrics["seed"].dropna()) == {0, 1, 2}                    # the swept parameter, a column
    targets = pd.read_csv(sweep / "report/targets.csv")
    other = set(targets.loc[targets["slug"] == "spherical-terrain", "status"])    # a paper this sweep did not run
    assert "not run" in other and other <= {"not run", "not-reproducible"}
    assert (sweep / "summary/status.json").is_file()


def test_a_sweep_without_the_extra_is_refused_in_one_line(data_dir, monkeypatch):
    from pipeline.core import checks
    from pipeline.core.checks import BadInput, preflight

    monkeypatch.setattr(checks.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(BadInput, match=r"hydra/launcher=slurm needs its extra: pip install -e '\.\[slurm\]'"):
        preflight([TABLES, "seed=0,1", "hydra/launcher=slurm", f"data_dir={data_dir}"])

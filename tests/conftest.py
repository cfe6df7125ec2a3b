"""Shared helpers: run the CLIs the way a user does, on a temporary data_dir."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# CI set: Rerun's tools send no usage analytics (its only switch that leaves the user's config alone)
ENV = {**os.environ, "CI": "1", "PYTHONHASHSEED": "0"}


def run_cli(module: str, *args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", module, *args], cwd=ROOT, env=ENV, capture_output=True,
                          text=True, timeout=timeout)


@pytest.fixture
def data_dir(tmp_path: Path) -> Path:
    return tmp_path / "data"


def simulate_experiment(data_dir: Path, experiment: str, overrides: list[str] = (), sweep: list[str] = ()) -> None:
    """An experiment's runs written under `data_dir` by the simulate stage's own code, in this process (no CLI
    start-up); `sweep` are a sweep point's overrides, which name its runs as `-m` names them."""
    from pipeline.core.checks import compose_config
    from pipeline.core.runner import simulate

    cfg = compose_config([f"experiment={experiment}", f"data_dir={data_dir}", "progress=false", *overrides, *sweep])
    assert simulate(cfg, experiment, list(sweep)) == 0


def simulate_case(directory: Path, experiment: str, overrides: list[str] = (), case_id: str | None = None):
    """One case of `experiment` ("slug/name"; the first case unless `case_id` names one) simulated in this
    process (no CLI start-up), written to `directory`/<case>.mcap and read back."""
    from pipeline.core.checks import compose_config
    from pipeline.core.experiment import resolve
    from pipeline.core.runlog import RunWriter, read_run

    cases = resolve(experiment).fn(compose_config([f"experiment={experiment}", *overrides]))
    case = next(c for c in cases if case_id is None or c.id == case_id)
    path = directory / f"{case.id}.mcap"
    with RunWriter(path, {"run_id": case.id, "slug": experiment.split("/")[0]}) as w:
        case.simulate(w)
        w.close("ok")
    return read_run(path)

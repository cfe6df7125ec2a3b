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

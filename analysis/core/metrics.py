"""Tidy metric tables: one row per (run, metric) with value, unit and the run's swept parameters."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import pandas as pd

from pipeline.core.files import atomic_path
from pipeline.core.runlog import Run

COLUMNS = ["run_id", "metric", "value", "unit"]


class MetricTable:
    def __init__(self) -> None:
        self._rows: list[dict] = []

    def add(self, run_id: str, metric: str, value: float, unit: str, params: dict | None = None) -> None:
        self._rows.append({"run_id": run_id, "metric": metric, "value": float(value), "unit": unit,
                           **(params or {})})

    def add_run(self, run: Run, values: dict[str, tuple[float, str]]) -> None:
        for metric, (value, unit) in values.items():
            self.add(run.run_id, metric, value, unit, run.params)

    def frame(self) -> pd.DataFrame:
        frame = pd.DataFrame(self._rows)
        return frame if not frame.empty else pd.DataFrame(columns=COLUMNS)


def metric_value(frame: pd.DataFrame, run_id: str, metric: str) -> float:
    """One metric of one run from a tidy table; NaN if absent."""
    hit = frame[(frame["run_id"] == run_id) & (frame["metric"] == metric)]
    return float(hit["value"].iloc[0]) if not hit.empty else float("nan")


def write_metrics(frame: pd.DataFrame, path: Path) -> None:
    with atomic_path(path) as tmp:
        frame.to_parquet(tmp, index=False)


def read_metrics(paths: Iterable[Path]) -> dict[str, pd.DataFrame]:
    """experiment name -> metrics table."""
    return {p.name.removesuffix(".parquet"): pd.read_parquet(p) for p in paths}

"""How long each stage process took, so the slowest stages of a pipeline run are visible.

Every `python -m pipeline`, `python -m analysis` and `python -m pipeline.dataset` process that succeeds appends
one JSON line to `<data_dir>/.stages.jsonl` when it ends: what it ran, its wall and CPU time, and (simulate) how
long it took from process start to the first simulated step. Lines are short and appended in one write, so processes
running at once do not interleave them. `python -m pipeline.benchmark stages` prints the newest line of each
stage, slowest first.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

JOURNAL = ".stages.jsonl"
_CLOCK_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
_IMPORTED = time.monotonic()
_marks: dict[str, float] = {}


def process_age() -> float:
    """Seconds since this process started (Linux: from /proc, so interpreter start-up counts too)."""
    try:
        started = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19]) / _CLOCK_TICKS
        return float(Path("/proc/uptime").read_text().split()[0]) - started
    except (OSError, IndexError, ValueError):
        return time.monotonic() - _IMPORTED


def mark(event: str) -> None:
    """Remember when `event` first happened in this process: `<event>_s` wall seconds since it started and
    `<event>_cpu_s` CPU seconds (which a busy machine does not inflate); recorded with the stage."""
    if f"{event}_s" not in _marks:
        cpu = os.times()
        _marks[f"{event}_s"] = round(process_age(), 3)
        _marks[f"{event}_cpu_s"] = round(cpu.user + cpu.system, 3)


def argument(overrides: list[str], key: str, default: str | None = None) -> str | None:
    """The value of `key=...` among command-line overrides."""
    for o in overrides:
        k, eq, v = o.partition("=")
        if eq and k.lstrip("+~") == key:
            return v
    return default


def record(data_dir: str | Path, stage: str, experiment: str | None, **extra: Any) -> None:
    """Append this process's line to the journal."""
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        return
    cpu = os.times()
    line = json.dumps({"stage": stage, "experiment": experiment,
                       "wall_s": round(process_age(), 3), "cpu_s": round(cpu.user + cpu.system, 3),
                       "children_cpu_s": round(cpu.children_user + cpu.children_system, 3),
                       **_marks, "finished": time.time(), **extra}) + "\n"
    with open(data_dir / JOURNAL, "a", encoding="utf-8") as f:
        f.write(line)


def read(data_dir: str | Path) -> list[dict[str, Any]]:
    """The newest line of each (stage, experiment), slowest first."""
    path = Path(data_dir) / JOURNAL
    if not path.is_file():
        return []
    newest: dict[tuple, dict] = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            entry = json.loads(line)
        except json.JSONDecodeError:
            continue
        newest[(entry.get("stage"), entry.get("experiment"), json.dumps(entry.get("params")))] = entry
    return sorted(newest.values(), key=lambda e: -e.get("wall_s", 0.0))

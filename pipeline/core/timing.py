"""Compute time, measured the same way for every algorithm a paper times.

Warm-up calls first (caches, lazy imports, branch predictors), garbage collection off while timing,
one `perf_counter_ns` pair around each call, every sample kept: the report shows median and p95, and
the samples go to the `/compute_time` channel. Runs single-threaded (the pipeline runs one process per
core); the machine goes into the run metadata.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from pipeline.core.runlog import RunWriter


@dataclass(frozen=True)
class Timing:
    name: str
    seconds: np.ndarray          # one entry per timed call
    items_per_call: int = 1      # poses per call for batched forms: per-item time = seconds / items

    @property
    def median(self) -> float:
        return float(np.median(self.seconds))

    @property
    def p95(self) -> float:
        return float(np.percentile(self.seconds, 95))

    def summary_us(self) -> dict[str, float]:
        per_item = self.seconds / self.items_per_call * 1e6
        return {"median_us": float(np.median(per_item)), "p95_us": float(np.percentile(per_item, 95))}


def best_of(fn: Callable[[], Any], repeats: int = 3, clock: Callable[[], float] = time.perf_counter) -> float:
    """Shortest time (s) of `repeats` calls: for whole runs, where the minimum is the least disturbed. Wall time
    by default; `clock=time.process_time` gives this process's CPU time, which other processes on a busy
    machine disturb less."""
    best = float("inf")
    for _ in range(repeats):
        start = clock()
        fn()
        best = min(best, clock() - start)
    return best


def time_calls(name: str, fn: Callable[..., Any], inputs: Sequence[tuple], *, warmup: int = 100,
               repeats: int = 1, items_per_call: int = 1) -> Timing:
    """Time `fn(*args)` for each args tuple in `inputs`, `repeats` passes, after `warmup` calls."""
    if not inputs:
        raise ValueError("time_calls needs at least one input")
    for k in range(warmup):
        fn(*inputs[k % len(inputs)])
    clock = time.perf_counter_ns
    samples = np.empty(len(inputs) * repeats)
    enabled = gc.isenabled()
    gc.disable()
    try:
        k = 0
        for _ in range(repeats):
            for args in inputs:
                start = clock()
                fn(*args)
                samples[k] = clock() - start
                k += 1
    finally:
        if enabled:
            gc.enable()
    return Timing(name, samples * 1e-9, items_per_call)


def log_timings(log: RunWriter, timings: Sequence[Timing], start: float = 0.0, spacing: float = 1e-3) -> float:
    """Every sample of each Timing on `/compute_time`, one message per timed call, `spacing` s apart on the log's
    time axis from `start` (timed calls are a sequence, not a trajectory). Returns the time after the last."""
    t = start
    for timing in timings:
        times = t + np.arange(len(timing.seconds)) * spacing
        log.log_series("/compute_time", times, name=[timing.name], calls=[timing.items_per_call],
                       seconds=timing.seconds[:, None])
        t = float(times[-1]) + spacing
    return t


def time_interleaved(calls: Mapping[str, tuple[Callable[..., Any], tuple, int]], *, warmup: int = 1,
                     repeats: int = 1, clock: Callable[[], int] = time.perf_counter_ns,
                     collect: bool = False) -> dict[str, Timing]:
    """Time several calls in rounds, each round calling every one once in turn, so that a change of load
    on a shared machine during the measurement falls on all of them alike (what ratios between
    algorithms and scaling fits need). `calls` maps name -> (fn, args, items_per_call). Wall time by
    default (`clock=time.process_time_ns`: this process's CPU time); garbage collection is off unless
    `collect` (whole runs, which collect as the pipeline does)."""
    for fn, args, _ in calls.values():
        for _ in range(warmup):
            fn(*args)
    samples = {name: np.empty(repeats) for name in calls}
    enabled = gc.isenabled()
    if not collect:
        gc.disable()
    try:
        for r in range(repeats):
            for name, (fn, args, _) in calls.items():
                start = clock()
                fn(*args)
                samples[name][r] = clock() - start
    finally:
        if enabled:
            gc.enable()
    return {name: Timing(name, samples[name] * 1e-9, items) for name, (_, _, items) in calls.items()}

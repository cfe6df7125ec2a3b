"""The shared timing helpers: what they call, how often, in which order (never how fast)."""

from __future__ import annotations

from pipeline.core.timing import time_calls, time_interleaved


def test_time_calls_counts():
    seen = []
    timing = time_calls("f", seen.append, [(1,), (2,)], warmup=3, repeats=2, items_per_call=5)
    assert seen == [1, 2, 1, 1, 2, 1, 2] and len(timing.seconds) == 4 and timing.items_per_call == 5


def test_time_interleaved_runs_rounds():
    order = []
    timings = time_interleaved({"a": (order.append, ("a",), 1), "b": (order.append, ("b",), 7)}, warmup=1, repeats=3)
    assert order == ["a", "b"] + ["a", "b"] * 3          # warm-up each, then one call of each per round
    assert {k: len(t.seconds) for k, t in timings.items()} == {"a": 3, "b": 3}
    assert timings["b"].items_per_call == 7 and (timings["a"].seconds > 0).all()

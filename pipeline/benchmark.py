"""Benchmark command: how fast each system simulates and each timed algorithm runs, on this machine.

    python -m pipeline.benchmark                 every paper that has a benchmark
    python -m pipeline.benchmark ur5-ik-fsm      one paper

A paper opts in with `pipeline/papers/<module>/benchmark.py` exposing `benchmark() -> list[dict]` (rows with
what, measure, value, unit, and optionally p95, goal, paper). Timing lives here, never in the tests.
"""

# ruff: noqa: E402  (the BLAS thread count must be set before NumPy is imported)
from __future__ import annotations

import os

# One BLAS thread, as in the pipeline (pipeline/__main__.py): the timings are single-threaded.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import importlib
import math
import sys
from pathlib import Path

import pandas as pd

from pipeline.core import provenance
from pipeline.core.experiment import module_name

PAPERS = Path(__file__).parent / "papers"


def main(argv: list[str]) -> int:
    available = sorted(p.parent.name.replace("_", "-") for p in PAPERS.glob("*/benchmark.py"))
    slugs = argv or available
    unknown = [s for s in slugs if s not in available]
    if unknown:
        print(f"error: no benchmark for {', '.join(unknown)}; available: {', '.join(available)}", file=sys.stderr)
        return 2
    m = provenance.machine()
    print(f"machine: {m['cpu']}, {m['logical_cores']} logical cores, {m['system']}, Python {m['python']}")
    for slug in slugs:
        rows = importlib.import_module(f"pipeline.papers.{module_name(slug)}.benchmark").benchmark()
        table = pd.DataFrame(rows).reindex(columns=["what", "measure", "value", "p95", "unit", "goal", "paper"])
        table["value"] = table["value"].map(lambda v: "" if math.isnan(v) else f"{v:.3g}")
        table["p95"] = table["p95"].map(lambda v: "" if pd.isna(v) else f"{v:.3g}")
        print(f"\n## {slug}\n")
        print(table.fillna("").to_markdown(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Benchmark command: how fast each system simulates and each timed algorithm runs, on this machine.

    python -m pipeline.benchmark                 every paper that has a benchmark
    python -m pipeline.benchmark ur5-ik-fsm      one paper
    python -m pipeline.benchmark stages [DIR]    each stage of the last pipeline run under DIR (default data),
                                                 slowest first: wall, CPU, start-up to the first simulated step

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


def stage_times(data_dir: Path) -> int:
    from pipeline.core import stages

    entries = stages.read(data_dir)
    if not entries:
        print(f"error: no stage has run under {data_dir} (run the pipeline: python -m dvc repro)", file=sys.stderr)
        return 2
    table = pd.DataFrame(entries).reindex(columns=["stage", "experiment", "wall_s", "cpu_s", "children_cpu_s",
                                                   "first_step_s", "first_step_cpu_s"])
    table["cpu_s"] = table["cpu_s"] + table["children_cpu_s"].fillna(0)  # a stage's workers count too
    table = table.drop(columns="children_cpu_s")
    m = provenance.machine()
    print(f"machine: {m['cpu']}, {m['logical_cores']} logical cores; {len(table)} stages under {data_dir}")
    print(f"total: wall {table.wall_s.sum():.1f} s (stages one after another), CPU {table.cpu_s.sum():.1f} s; "
          f"start-up to the first simulated step: median {table.first_step_s.median():.2f} s wall, "
          f"{table.first_step_cpu_s.median():.2f} s CPU\n")
    print(table.astype(object).where(table.notna(), "").to_markdown(index=False, floatfmt=".2f"))
    return 0


def main(argv: list[str]) -> int:
    if argv[:1] == ["stages"]:
        return stage_times(Path(argv[1] if len(argv) > 1 else "data"))
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

"""The analyze and report stages, paper-agnostic.

A paper's analysis package `analysis.papers.<module>` holds `paper.yaml` (title, assumptions, errata),
`targets.csv` (its reported numbers, see analysis/core/targets.py) and exports

    ANALYSES: dict[str, Callable[[list[Run], Figures], pd.DataFrame]]   # experiment name -> tidy metrics
    report_sections(metrics: dict[str, pd.DataFrame], runs: pd.DataFrame) -> list[Section]   # optional extras

Its `__init__.py` only imports and names these; the work lives in modules named for what they do:
`metrics.py` (constants, what is read from a run, metric computations), `figures.py` (plots; a value the paper
prints is drawn from targets.csv with analysis.core.targets.paper_value, labelled "paper"), `analyses.py` (one
analysis per experiment, and ANALYSES) and `sections.py` (report_sections: `Section`s of prose and `Table`s,
analysis/core/sections.py). The figures each analysis saves are declared in paper.yaml with their caption, the
paper figure they regenerate and their place on the page (analysis/core/report.py says how).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path
from types import ModuleType

import pandas as pd

from analysis.core import report
from analysis.core.figures import Figures
from analysis.core.metrics import read_metrics, write_metrics
from analysis.core.targets import evaluate, load_targets
from pipeline.core.experiment import available_experiments, module_name
from pipeline.core.runlog import read_run, run_files

PAPERS_DIR = Path(__file__).resolve().parents[1] / "papers"


def paper_package(slug: str) -> ModuleType:
    return importlib.import_module(f"analysis.papers.{module_name(slug)}")


def analyzed_slugs() -> list[str]:
    """Papers that have an analysis package (paper.yaml + targets.csv)."""
    return sorted(p.parent.name.replace("_", "-") for p in PAPERS_DIR.glob("*/paper.yaml"))


def analyze(experiment_id: str, data_dir: Path) -> Path | None:
    """Runs on disk -> metrics parquet, run list and figures. None if there are no runs."""
    slug, _, name = experiment_id.partition("/")
    files = run_files(data_dir / "runs" / slug / name)
    if not files:
        return None
    runs = [read_run(p) for p in files]
    run_list = pd.DataFrame([{"run_id": r.run_id, "status": r.status, "ok": r.ok,
                              "wall_time_s": float(r.metadata.get("wall_time_s", "nan")),
                              "machine": r.metadata.get("machine", "{}"), **r.params} for r in runs])
    ok = [r for r in runs if r.ok]
    figures = Figures(data_dir / "figures" / slug / name)
    analysis = paper_package(slug).ANALYSES[name]
    metrics = analysis(ok, figures) if ok else pd.DataFrame(columns=["run_id", "metric", "value", "unit"])
    out = data_dir / "metrics" / slug / f"{name}.parquet"
    write_metrics(metrics, out)
    run_list.to_csv(out.with_suffix(".runs.csv"), index=False)
    return out


def _runs_table(metrics_dir: Path) -> pd.DataFrame:
    frames = [pd.read_csv(p).assign(experiment=p.name.removesuffix(".runs.csv"))
              for p in sorted(metrics_dir.glob("*.runs.csv"))]
    if not frames:
        return pd.DataFrame(columns=["experiment", "run_id", "status", "ok"])
    return pd.concat(frames, ignore_index=True)


def write_report(data_dir: Path) -> Path:
    report_dir = data_dir / "report"
    pages, all_evaluated = [], []
    for slug in analyzed_slugs():
        package = paper_package(slug)
        package_dir = Path(package.__file__).parent
        info = report.load_paper_info(package_dir)
        metrics_dir = data_dir / "metrics" / slug
        metrics = read_metrics(sorted(metrics_dir.glob("*.parquet")))
        runs = _runs_table(metrics_dir)
        evaluated = evaluate(slug, load_targets(package_dir / "targets.csv"), metrics, runs)
        sections = package.report_sections(metrics, runs) if hasattr(package, "report_sections") and metrics else []
        figures = sorted((data_dir / "figures" / slug).glob("*/*.png"))
        report.write_paper_pages(report_dir, report.paper_context(info, evaluated, runs, sections, figures,
                                                                  data_dir, report_dir))
        pages.append((info, evaluated, runs))
        all_evaluated.append(evaluated)
    report.write_targets_csv(all_evaluated, report_dir / "targets.csv")
    return report.write_index(report_dir, report.index_context(pages))


def run(data_dir: Path, experiment: str | None, stage: str) -> int:
    experiments = [experiment] if experiment else [e for e in available_experiments()
                                                   if e.split("/")[0] in analyzed_slugs()]
    if stage in ("analyze", "all"):
        for experiment_id in experiments:
            out = analyze(experiment_id, data_dir)
            if out is None:
                print(f"{experiment_id}: no runs under {data_dir / 'runs' / experiment_id}; "
                      f"run: python -m pipeline experiment={experiment_id}", file=sys.stderr)
                if experiment:
                    return 1
            else:
                print(f"wrote {out}", file=sys.stderr)
    if stage in ("report", "all"):
        print(f"wrote {write_report(data_dir)}", file=sys.stderr)
    return 0

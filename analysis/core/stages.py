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

import functools
import importlib
import sys
from pathlib import Path
from types import ModuleType

import pandas as pd

from analysis.core.figures import Figures
from analysis.core.metrics import read_metrics, write_metrics
from analysis.core.targets import evaluate, load_targets, self_check
from pipeline.core import files, parallel
from pipeline.core.experiment import available_experiments, module_name
from pipeline.core.runlog import Run, read_run, run_files

PAPERS_DIR = Path(__file__).resolve().parents[1] / "papers"


def paper_package(slug: str) -> ModuleType:
    return importlib.import_module(f"analysis.papers.{module_name(slug)}")


def analyzed_slugs() -> list[str]:
    """Papers that have an analysis package (paper.yaml + targets.csv)."""
    return sorted(p.parent.name.replace("_", "-") for p in PAPERS_DIR.glob("*/paper.yaml"))


def _read(path: Path, slug: str, name: str) -> tuple[Run | None, dict]:
    """A run file and its row of the run list; a damaged file or another experiment's run is listed with the
    reason and left out of the analysis (the rest is analysed)."""
    try:
        run = read_run(path).verify()
    except Exception as err:  # truncated, byte-flipped, empty, not MCAP at all
        reason = str(err).splitlines()[0] if str(err) else type(err).__name__
        return None, {"run_id": path.stem, "status": f"unreadable: {reason}"[:200], "ok": False}
    row = {"run_id": run.run_id, "status": run.status, "ok": run.ok,
           "wall_time_s": float(run.metadata.get("wall_time_s", "nan")),
           "machine": run.metadata.get("machine", "{}"), **run.params}
    where = (run.metadata.get("slug"), run.metadata.get("experiment"))
    if where != (slug, name):
        return None, {**row, "run_id": path.stem, "status": f"foreign: a run of {where[0]}/{where[1]}", "ok": False}
    return run, row


def analyze(experiment_id: str, data_dir: Path) -> Path | None:
    """Runs on disk -> metrics parquet, run list and figures. None if there are no runs."""
    slug, _, name = experiment_id.partition("/")
    paths = run_files(data_dir / "runs" / slug / name)
    if not paths:
        return None
    read = [_read(p, slug, name) for p in paths]
    run_list = pd.DataFrame([row for _, row in read])
    runs = [run for run, _ in read if run is not None]
    ok = [r for r in runs if r.ok]
    figures = Figures(data_dir / "figures" / slug / name)
    analysis = paper_package(slug).ANALYSES[name]
    metrics = analysis(ok, figures) if ok else pd.DataFrame(columns=["run_id", "metric", "value", "unit"])
    out = data_dir / "metrics" / slug / f"{name}.parquet"
    write_metrics(metrics, out)
    files.write_text(out.with_suffix(".runs.csv"), run_list.to_csv(index=False))
    return out


def _runs_table(metrics_dir: Path) -> pd.DataFrame:
    frames = [pd.read_csv(p).assign(experiment=p.name.removesuffix(".runs.csv"))
              for p in sorted(metrics_dir.glob("*.runs.csv"))]
    if not frames:
        return pd.DataFrame(columns=["experiment", "run_id", "status", "ok"])
    return pd.concat(frames, ignore_index=True)


def write_report(data_dir: Path) -> tuple[Path, list[str]]:
    """Every page, the index and targets.csv; and the report's self-check: what its declarations get wrong (a
    band paper.yaml does not justify, a banded miss whose cause the band rules out: targets.self_check)."""
    from analysis.core import report  # the page templates (jinja2, markdown): not needed to analyze

    report_dir = data_dir / "report"
    pages, all_evaluated, problems = [], [], []
    for slug in analyzed_slugs():
        package = paper_package(slug)
        package_dir = Path(package.__file__).parent
        info = report.load_paper_info(package_dir)
        metrics_dir = data_dir / "metrics" / slug
        metrics = read_metrics(sorted(metrics_dir.glob("*.parquet")))
        runs = _runs_table(metrics_dir)
        evaluated = evaluate(slug, load_targets(package_dir / "targets.csv"), metrics, runs)
        try:
            sections = package.report_sections(metrics, runs) if hasattr(package, "report_sections") and metrics else []
        except Exception as err:  # one paper's extra tables must not cost the report: its page goes without them
            sections = []
            problems.append(f"{slug}: its report sections failed: {type(err).__name__}: {err}")
        figures = sorted((data_dir / "figures" / slug).glob("*/*.png"))
        report.write_paper_pages(report_dir, report.paper_context(info, evaluated, runs, sections, figures,
                                                                  data_dir, report_dir))
        pages.append((info, evaluated, runs))
        all_evaluated.append(evaluated)
        problems += report.undeclared_bands(info, evaluated) + self_check(evaluated)
    report.write_summary(report.write_targets_csv(all_evaluated, report_dir / "targets.csv"), data_dir / "summary")
    context = report.index_context(pages, report.dataset_rows(data_dir, report_dir))
    return report.write_index(report_dir, context), problems


def _analyze_or_say_why(experiment_id: str, data_dir: Path) -> tuple[Path | None, str | None]:
    try:
        return analyze(experiment_id, data_dir), None
    except Exception as err:  # a bug in one paper's analysis: say so, analyse the others
        return None, f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"


def run(data_dir: Path, experiment: str | None, stage: str, workers: int = 0) -> int:
    """Analyze the experiments that have runs (`experiment`: one `<slug>/<name>`, every experiment of a paper
    `<slug>`, or None: all) on `workers` processes (0: one per core), then write the report; 1 if nothing could
    be analysed, an experiment's analysis failed (the others are still analysed) or the report's self-check found
    a problem (the report is still written, with every problem named on stderr)."""
    one = experiment is not None and "/" in experiment
    experiments = [experiment] if one else [e for e in available_experiments() if e.split("/")[0] in analyzed_slugs()
                                            and (experiment is None or e.split("/")[0] == experiment)]
    failed = 0
    if stage in ("analyze", "all"):
        for slug in sorted({e.split("/")[0] for e in experiments}):
            paper_package(slug)   # imported once, before the workers fork
        outcomes = parallel.imap(functools.partial(_analyze_or_say_why, data_dir=data_dir), experiments, workers,
                                 chunksize=1)
        analysed = 0
        for experiment_id, (out, error) in zip(experiments, outcomes, strict=True):
            if error:
                failed += 1
                print(f"error: the analysis of {experiment_id} failed: {error}"[:280], file=sys.stderr)
                continue
            if out is None:
                if one:
                    print(f"error: no runs under {data_dir / 'runs' / experiment_id}; "
                          f"run: python -m pipeline experiment={experiment_id} data_dir={data_dir}", file=sys.stderr)
                    return 1
            else:
                analysed += 1
                print(f"wrote {out}", file=sys.stderr)
        if not analysed and not failed:
            print(f"error: no runs under {data_dir / 'runs'}: run an experiment first, e.g. "
                  f"python -m pipeline experiment={experiments[0]} data_dir={data_dir}", file=sys.stderr)
            return 1
    if stage in ("report", "all"):
        if not any((data_dir / "metrics").glob("*/*.parquet")):
            print(f"error: no metrics under {data_dir / 'metrics'}: python -m analysis data_dir={data_dir} "
                  "analyses the runs first", file=sys.stderr)
            return 1
        index, problems = write_report(data_dir)
        print(f"wrote {index}", file=sys.stderr)
        for problem in problems:
            print(f"error: report self-check: {problem}"[:600], file=sys.stderr)
        failed += len(problems)
    return 1 if failed else 0

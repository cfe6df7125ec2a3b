"""The report: one summary over all papers, one page per paper, every target in one CSV.

    <data_dir>/report/index.html + index.md     papers × {trajectories, tracking errors, force errors, compute
                                                times}: targets per status; misses still `open`; the papers'
                                                self-consistency checks apart; what every status means
    <data_dir>/report/<slug>.html + .md         paper vs pipeline per category with its figures, the paper against
                                                itself, runs and the commands that regenerate them, the paper's
                                                report sections, assumptions, errata
    <data_dir>/report/targets.csv               every target: TARGETS_CSV_COLUMNS (below)
    <data_dir>/summary/status.json              DVC metrics: per paper (and `all`), targets per status (`not run`
                                                as not_run) and self-consistency checks; `dvc metrics diff`
    <data_dir>/summary/comparison.csv           DVC plots: every target with a number on both sides,
                                                paper_value vs pipeline_value (SUMMARY_COLUMNS); `dvc plots show`

Pages are rendered from the Jinja2 templates in analysis/core/templates/: HTML escapes every value by
construction, Markdown cells go through the `cell` filter (a `|` or a line break cannot break a row).

What a paper declares for its page, in `analysis/papers/<module>/paper.yaml`:

    slug, title, authors, venue, doi (bare, e.g. 10.3390/robotics11060137), summary
    assumptions: list of {what, choice, config}        what the paper leaves out, and what we chose
    errata:      list of {where, printed, corrected, config}
    bands:       list of {experiment, parameter, range, why}   every sensitivity band its targets.csv names
                 (analysis/core/targets.py): the sweep experiment, the parameter the paper omits, the range
                 swept, and why that range (physics, datasheet, the paper's hints), fixed before the result
    figures:                                           every figure its analysis saves, keyed by
      <experiment>/<file stem>:                        the path under data/figures/<slug>/ without extension
        paper: Fig. 8                                  the paper figure or table it regenerates (null: none)
        caption: Grasping force during a 40° rotation  one or two sentences: what is drawn, what to look for
        section: force errors                          a target category (the figure is placed after that
                                                       category's targets) or `further results`
    The key may be a glob (`singular-paths/*-near`); the first matching key wins, and `{name}` in a caption is
    the file stem. An undeclared figure is shown under "Further results" and named on stderr.

The columns of targets.csv (one row per target of every paper):

    slug, target_id, category, quantity, where   the paper and the target (analysis/core/targets.py)
    paper_value, op                              the paper's printed value and how it is compared
    pipeline_value                               the pipeline's value in the paper's unit (empty: none)
    band_min, band_max                           the band of a target with a sensitivity band (targets.py), in
                                                 the paper's unit (empty: no band, or its sweep is not on disk)
    deviation, relative_deviation                pipeline − paper, and that over |paper|
    unit, mode, basis, tolerance                 as declared in the paper's targets.csv
    status                                       match | close | consistent | miss | not run | not-reproducible,
                                                 or agrees | disagrees for a consistency row
    cause                                        of a miss, close or disagreement (targets.py: CAUSE_MEANING)
    note                                         the rule, assumption or evidence (+ why a value is absent)
    experiment, run                              where the pipeline value comes from (data/runs/<slug>/...)
"""

from __future__ import annotations

import fnmatch
import json
import math
import os
import re
import sys
from collections import Counter
from functools import cache
from pathlib import Path

import pandas as pd
import yaml
from jinja2 import Environment, PackageLoader, StrictUndefined
from markdown_it import MarkdownIt
from markupsafe import Markup

from analysis.core.sections import Section
from analysis.core.targets import CATEGORIES, CAUSE_MEANING, CAUSES, STATUS_MEANING, STATUSES
from pipeline.core import files, provenance

TARGETS_CSV_COLUMNS = ["slug", "target_id", "category", "quantity", "where", "paper_value", "op", "pipeline_value",
                       "band_min", "band_max", "deviation", "relative_deviation", "unit", "mode", "basis",
                       "tolerance", "status", "cause", "note", "experiment", "run"]
SUMMARY_COLUMNS = ["target", "slug", "quantity", "unit", "paper_value", "pipeline_value", "ratio", "status"]
FURTHER = "further results"
SELF_STATUSES = ("agrees", "disagrees", "not run")
ROOT = Path(__file__).resolve().parents[2]
OP_SIGN = {"==": "", "<": "< ", "<=": "≤ ", ">": "> ", ">=": "≥ "}
STATUS_RANK = {s: i for i, s in enumerate(("miss", "disagrees", "close", "consistent", "not run", "match", "agrees",
                                           "not-reproducible"))}


# -- rendering ---------------------------------------------------------------------------------------------------


def _md_cell(value) -> str:
    """A Markdown table cell: a `|` would end the cell and a line break the row."""
    return re.sub(r"\s*\n\s*", " ", str(value)).replace("|", "\\|")


_prose = MarkdownIt("commonmark", {"html": False}).enable("table")


@cache
def _environments() -> tuple[Environment, Environment]:
    html = Environment(loader=PackageLoader("analysis.core", "templates"), autoescape=True, undefined=StrictUndefined,
                       trim_blocks=False, lstrip_blocks=False)
    html.filters["markdown"] = lambda text: Markup(_prose.render(text).replace('.md"', '.html"'))
    md = Environment(loader=PackageLoader("analysis.core", "templates"), autoescape=False,
                     undefined=StrictUndefined, keep_trailing_newline=True)
    md.filters["cell"] = _md_cell
    return html, md


def render(template: str, **context) -> str:
    """Render `<template>.html.j2` or `<template>.md.j2` (by the name's suffix)."""
    html, md = _environments()
    env = html if template.endswith(".html.j2") else md
    text = env.get_template(template).render(cause_meaning=CAUSE_MEANING, **context)
    return re.sub(r"\n{3,}", "\n\n", text) if env is md else text


# -- values --------------------------------------------------------------------------------------------------------


def _fmt(x) -> str:
    if isinstance(x, float):
        return "" if math.isnan(x) else f"{x:.6g}"
    return str(x)


def _signed(x: float, relative: bool = False) -> str:
    if isinstance(x, float) and math.isnan(x):
        return ""
    return f"{100 * x:+.3g} %" if relative else f"{x:+.4g}"


def anchor(*parts: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", "-".join(parts)).strip("-")


def counts(evaluated: pd.DataFrame) -> dict[str, dict[str, int]]:
    """category -> status -> count of reproduction targets (consistency rows apart)."""
    live = evaluated[evaluated["mode"] != "consistency"]
    return {cat: {s: int(((live["category"] == cat) & (live["status"] == s)).sum()) for s in STATUSES}
            for cat in CATEGORIES}


# -- commands and run files -----------------------------------------------------------------------------------------


@cache
def stage_vars() -> dict[str, dict]:
    """slug -> the vars of its DVC stages (stages/<slug>/experiments.yaml): `experiments`, each name with the extra
    arguments of its simulate stage (a sweep's grid), and `datasets`, what its export stage writes."""
    return {p.parent.name: yaml.safe_load(p.read_text()) for p in sorted((ROOT / "stages").glob("*/experiments.yaml"))}


def simulate_args() -> dict[str, str]:
    """experiment id -> the extra arguments of its simulate stage (a sweep's grid)."""
    return {f"{slug}/{name}": args for slug, v in stage_vars().items() for name, args in v["experiments"].items()}


def commands(experiment_id: str) -> tuple[str, str]:
    """The commands that regenerate an experiment's runs, then its metrics and figures (and the report)."""
    args = simulate_args().get(experiment_id, "")
    multirun = "-m " if args.startswith("-m ") else ""
    simulate = f"python -m pipeline {multirun}experiment={experiment_id} {args.removeprefix('-m ')}".strip()
    return simulate, f"python -m analysis experiment={experiment_id}"


def _run_href(data_dir: Path, report_dir: Path, slug: str, experiment: str, run: str) -> str:
    folder = data_dir / "runs" / slug / experiment
    file = folder / f"{run}.mcap"
    return os.path.relpath(file if file.is_file() else folder, report_dir)


# -- one paper ------------------------------------------------------------------------------------------------------


def load_paper_info(package_dir: Path) -> dict:
    return yaml.safe_load((package_dir / "paper.yaml").read_text())


def _target_rows(part: pd.DataFrame, data_dir: Path, report_dir: Path) -> list[dict]:
    rows = []
    for t in part.itertuples(index=False):
        paper = t.paper_value
        rows.append({
            "target_id": t.target_id, "anchor": anchor("t", t.target_id), "status": t.status,
            "status_rank": STATUS_RANK.get(t.status, 99), "cause": t.cause, "quantity": t.quantity, "where": t.where,
            "paper": f"{OP_SIGN.get(t.op, '')}{paper}" if paper != "" else "", "paper_sort": paper,
            "pipeline": _fmt(t.pipeline_value), "pipeline_sort": _fmt(t.pipeline_value),
            "band": _band_text(t), "band_anchor": anchor("band", t.band) if getattr(t, "band", "") else "",
            "deviation": _signed(t.deviation), "relative": _signed(t.relative_deviation, relative=True),
            "relative_sort": "" if math.isnan(t.relative_deviation) else f"{abs(t.relative_deviation):.6g}",
            "unit": t.unit, "tolerance": t.tolerance, "basis": t.basis, "mode": t.mode, "note": t.note,
            "experiment": t.experiment, "run": t.run,
            "run_href": _run_href(data_dir, report_dir, t.slug, t.experiment, t.run) if t.experiment else "",
            "command_anchor": anchor("run", t.experiment) if t.experiment else ""})
    return rows


def _band_text(t) -> str:
    """`[min, max]` of a target's band, `not run` if its sweep is not on disk, empty without a band."""
    if not getattr(t, "band", ""):
        return ""
    if math.isnan(t.band_min):
        return "not run"
    return f"[{t.band_min:.4g}, {t.band_max:.4g}]"


def band_entries(info: dict, evaluated: pd.DataFrame) -> list[dict]:
    """The bands paper.yaml declares, each with the targets that read it and their [min, max]."""
    entries = []
    for b in info.get("bands") or []:
        of = evaluated[evaluated["band"] == b["experiment"]] if "band" in evaluated else evaluated.iloc[:0]
        entries.append({**{k: str(b.get(k, "")) for k in ("experiment", "parameter", "range", "why")},
                        "anchor": anchor("band", b["experiment"]), "run_anchor": anchor("run", b["experiment"]),
                        "targets": [{"target_id": t.target_id, "anchor": anchor("t", t.target_id),
                                     "band": _band_text(t), "unit": t.unit, "status": t.status}
                                    for t in of.itertuples(index=False)]})
    return entries


def undeclared_bands(info: dict, evaluated: pd.DataFrame) -> list[str]:
    """Bands a paper's targets name that its paper.yaml does not justify under `bands:`."""
    declared = {b.get("experiment") for b in info.get("bands") or []}
    named = sorted(set(evaluated["band"]) - {""} - declared) if "band" in evaluated else []
    return [f"{info['slug']}: band {b} is named in targets.csv but not declared in paper.yaml (bands: experiment, "
            "parameter, range, why)" for b in named]


def figure_entries(info: dict, figures: list[Path], report_dir: Path) -> list[dict]:
    """Each saved figure with its declaration from paper.yaml (paper figure, caption, section)."""
    declared = info.get("figures") or {}
    entries = []
    for png in figures:
        key = f"{png.parent.name}/{png.stem}"
        spec = next((v for k, v in declared.items() if fnmatch.fnmatchcase(key, k)), None)
        if spec is None:
            print(f"report: {info['slug']}: figure {key} is not declared in paper.yaml (figures:)", file=sys.stderr)
            spec = {"paper": None, "caption": "(not declared in paper.yaml)", "section": FURTHER}
        svg = png.with_suffix(".svg")
        entries.append({"experiment": png.parent.name, "name": png.stem, "anchor": anchor("fig", key),
                        "paper": spec.get("paper"), "caption": str(spec.get("caption", "")).replace("{name}", png.stem),
                        "section": spec.get("section", FURTHER), "png": os.path.relpath(png, report_dir),
                        "svg": os.path.relpath(svg if svg.is_file() else png, report_dir)})
    return entries


def _sections(sections: list[Section | str]) -> list[Section]:
    """A paper's report sections; a plain Markdown string (the former API) becomes one untitled block."""
    out = []
    for s in sections:
        if isinstance(s, str):
            title, _, text = s.strip().partition("\n")
            s = Section(title.lstrip("# ").strip(), text)
        s.anchor = anchor("sec", s.title)[:60]
        out.append(s)
    return out


def paper_context(info: dict, evaluated: pd.DataFrame, runs: pd.DataFrame, sections: list[Section | str],
                  figures: list[Path], data_dir: Path, report_dir: Path) -> dict:
    slug = info["slug"]
    reproduction = evaluated[evaluated["mode"] != "consistency"]
    consistency = evaluated[evaluated["mode"] == "consistency"]
    figs = figure_entries(info, figures, report_dir)
    secs = _sections(sections)
    c = counts(evaluated)
    shown_statuses = [s for s in STATUSES if any(c[k][s] for k in CATEGORIES)] or ["match"]
    categories = []
    for category in CATEGORIES:
        part = reproduction[reproduction["category"] == category]
        cat_figs = [f for f in figs if f["section"] == category]
        cat_secs = [s for s in secs if s.category == category]
        if part.empty and not cat_figs and not cat_secs:
            continue
        categories.append({"title": category.capitalize(), "anchor": anchor(category),
                           "targets": _target_rows(part, data_dir, report_dir), "figures": cat_figs,
                           "sections": cat_secs})
    placed = {c["title"].lower() for c in categories}
    further = {"figures": [f for f in figs if f["section"] not in placed],
               "sections": [s for s in secs if s.category not in placed]}
    run_rows, failed_runs = [], []
    if not runs.empty:
        for experiment, group in runs.groupby("experiment"):
            simulate, analyze = commands(f"{slug}/{experiment}")
            run_rows.append({"experiment": experiment, "anchor": anchor("run", experiment), "runs": len(group),
                             "failed": int((~group["ok"].astype(bool)).sum()), "simulate": simulate,
                             "analyze": analyze, "href": os.path.relpath(data_dir / "runs" / slug / experiment,
                                                                         report_dir)})
        failed_runs = runs[~runs["ok"].astype(bool)][["experiment", "run_id", "status"]].to_dict("records")
    causes = Counter(reproduction.loc[reproduction["status"].isin(["miss", "close"]), "cause"])
    toc = [("summary", "Summary"), ("runs", "Runs and commands")]
    toc += [(c["anchor"], f"Paper vs pipeline: {c['title'].lower()}") for c in categories]
    bands = band_entries(info, evaluated)
    if bands:
        toc.append(("bands", "Sensitivity bands"))
    if not consistency.empty:
        toc.append(("self-consistency", "The paper against itself"))
    if further["figures"] or further["sections"]:
        toc.append(("further", "Further results"))
    notes = [("assumptions", "Assumptions (what the paper does not give)", info.get("assumptions") or []),
             ("errata", "Errata (misprints found, and what we run)", info.get("errata") or [])]
    toc += [(key, title.split(" (")[0]) for key, title, rows in notes if rows]
    status_counts = Counter(evaluated["status"])
    return {
        "title": f"{slug}: {info['title']}", "info": {**info, "summary": str(info.get("summary", "")).strip()},
        "toc": toc, "summary": {"statuses": shown_statuses,
                                "rows": [{"category": k, "counts": c[k]} for k in CATEGORIES if sum(c[k].values())],
                                "consistency": {s: n for s in SELF_STATUSES
                                                if (n := int((consistency["status"] == s).sum()))},
                                "causes": {k: causes[k] for k in CAUSES if causes[k]}},
        "runs": run_rows, "failed_runs": failed_runs, "categories": categories, "bands": bands,
        "consistency": _target_rows(consistency, data_dir, report_dir), "further": further, "notes": notes,
        "status_counts": [(s, status_counts[s]) for s in (*STATUSES, *SELF_STATUSES[:2]) if status_counts[s]],
        "revision": provenance.git_revision(),
    }


# -- the index ----------------------------------------------------------------------------------------------------


def _paper_row(info: dict, evaluated: pd.DataFrame, runs: pd.DataFrame) -> dict:
    c = counts(evaluated)
    live = evaluated[evaluated["mode"] != "consistency"]
    misses = live[live["status"] == "miss"]
    self_check = evaluated.loc[evaluated["mode"] == "consistency", "status"]
    return {"slug": info["slug"], "title": info["title"],
            "cells": {k: [(s, c[k][s]) for s in STATUSES if c[k][s]] for k in CATEGORIES},
            "open": int((misses["cause"] == "open").sum()), "misses": len(misses),
            "consistency": [(s, int((self_check == s).sum())) for s in SELF_STATUSES if (self_check == s).any()],
            "runs": len(runs), "failed": int((~runs["ok"].astype(bool)).sum()) if not runs.empty else 0}


def dataset_rows(data_dir: Path, report_dir: Path) -> list[dict]:
    """Every dataset under `data_dir/datasets` with its card: the LeRobot exports (`<slug>/<experiment>/`, sizes
    from meta/info.json) and the curated tables (`<slug>/`)."""
    rows = []
    root = data_dir / "datasets"
    for card in sorted([*root.glob("*/README.md"), *root.glob("*/*/README.md")]):
        folder = card.parent
        info_path = folder / "meta" / "info.json"
        info = json.loads(info_path.read_text()) if info_path.is_file() else {}
        size = sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
        rows.append({"name": folder.relative_to(root).as_posix(), "card": os.path.relpath(card, report_dir),
                     "format": f"LeRobot {info['codebase_version']}" if info else "tables (Parquet, CSV)",
                     "episodes": info.get("total_episodes"), "frames": info.get("total_frames"),
                     "fps": info.get("fps"), "size_mb": size / 1e6})
    return rows


def index_context(papers: list[tuple[dict, pd.DataFrame, pd.DataFrame]], datasets: list[dict]) -> dict:
    rows = [_paper_row(*p) for p in papers]
    total = {"cells": {k: [] for k in CATEGORIES}, "open": sum(r["open"] for r in rows),
             "misses": sum(r["misses"] for r in rows), "runs": sum(r["runs"] for r in rows),
             "failed": sum(r["failed"] for r in rows), "consistency": []}
    for k in CATEGORIES:
        n = Counter()
        for r in rows:
            n.update(dict(r["cells"][k]))
        total["cells"][k] = [(s, n[s]) for s in STATUSES if n[s]]
    n = Counter()
    for r in rows:
        n.update(dict(r["consistency"]))
    total["consistency"] = [(s, n[s]) for s in SELF_STATUSES if n[s]]
    return {"title": "Reproduction report", "papers": rows, "total": total, "categories": CATEGORIES,
            "datasets": datasets,
            "status_meaning": STATUS_MEANING, "machine": provenance.machine(), "revision": provenance.git_revision()}


# -- writing ---------------------------------------------------------------------------------------------------------


def write_paper_pages(report_dir: Path, context: dict) -> None:
    slug = context["info"]["slug"]
    files.write_text(report_dir / f"{slug}.html", render("paper.html.j2", **context))
    files.write_text(report_dir / f"{slug}.md", render("paper.md.j2", **context))


def write_index(report_dir: Path, context: dict) -> Path:
    files.write_text(report_dir / "index.html", render("index.html.j2", **context))
    files.write_text(report_dir / "index.md", render("index.md.j2", **context))
    return report_dir / "index.html"


def write_targets_csv(evaluated: list[pd.DataFrame], path: Path) -> pd.DataFrame:
    frame = pd.concat(evaluated, ignore_index=True) if evaluated else pd.DataFrame(columns=TARGETS_CSV_COLUMNS)
    frame = frame[TARGETS_CSV_COLUMNS]
    files.write_text(path, frame.to_csv(index=False))
    return frame


def write_summary(evaluated: pd.DataFrame, summary_dir: Path) -> None:
    """What DVC tracks across commits: status counts per paper as metrics, and paper vs pipeline values as plots."""
    def counts(frame: pd.DataFrame) -> dict[str, int]:
        reproduced = frame[frame["mode"] != "consistency"]["status"].value_counts()
        checks = frame[frame["mode"] == "consistency"]["status"].value_counts()
        return {**{s.replace(" ", "_"): int(reproduced.get(s, 0)) for s in STATUSES},
                "self_consistency": {s.replace(" ", "_"): int(checks.get(s, 0)) for s in SELF_STATUSES}}

    status = {slug: counts(frame) for slug, frame in evaluated.groupby("slug")}
    status["all"] = counts(evaluated)
    files.write_text(summary_dir / "status.json", json.dumps(status, indent=2) + "\n")
    numbers = evaluated.assign(paper_value=pd.to_numeric(evaluated["paper_value"], errors="coerce"),
                               pipeline_value=pd.to_numeric(evaluated["pipeline_value"], errors="coerce"))
    numbers = numbers[(numbers["mode"] != "consistency") & numbers["paper_value"].notna()
                      & numbers["pipeline_value"].notna()]
    paper = numbers["paper_value"].where(numbers["paper_value"] != 0)
    numbers = numbers.assign(target=numbers["slug"] + "/" + numbers["target_id"],
                             ratio=numbers["pipeline_value"] / paper)
    files.write_text(summary_dir / "comparison.csv", numbers[SUMMARY_COLUMNS].to_csv(index=False))

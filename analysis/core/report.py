"""The report: one summary over all papers, one page per paper, every target in one CSV.

    <data_dir>/report/index.md + index.html     papers × {trajectories, tracking errors, force errors,
                                                compute times}: targets matched / close / missed / n.r.
    <data_dir>/report/<slug>.md + .html         paper vs pipeline, figures, extra tables, assumptions, errata
    <data_dir>/report/targets.csv               slug,target_id,quantity,where,paper_value,pipeline_value,
                                                unit,mode,tolerance,status
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import pandas as pd
import yaml
from markdown_it import MarkdownIt

from analysis.core.targets import CATEGORIES, STATUSES
from pipeline.core import files, provenance

TARGETS_CSV_COLUMNS = ["slug", "target_id", "category", "quantity", "where", "paper_value", "op", "pipeline_value",
                       "deviation", "relative_deviation", "unit", "mode", "basis", "tolerance", "status", "cause",
                       "note", "experiment", "run"]
STATUS_MARK = {"match": "✅ match", "close": "🟡 close", "consistent": "🔵 consistent", "miss": "❌ miss",
               "not run": "· not run", "not-reproducible": "⚪ n.r.", "agrees": "✅ agrees",
               "disagrees": "❌ disagrees"}


def _fmt(x) -> str:
    if isinstance(x, float):
        return "" if math.isnan(x) else f"{x:.6g}"
    return str(x)


def _md_table(frame: pd.DataFrame) -> str:
    if frame.empty:
        return "_(none)_"
    return frame.map(_fmt).to_markdown(index=False)


def counts(evaluated: pd.DataFrame) -> dict[str, dict[str, int]]:
    """category -> status -> count."""
    return {cat: {s: int(((evaluated["category"] == cat) & (evaluated["status"] == s)).sum()) for s in STATUSES}
            for cat in CATEGORIES}


def _cell(c: dict[str, int]) -> str:
    if not sum(c.values()):
        return "–"
    return f"{c['match']} / {c['close']} / {c['miss']} / {c['not-reproducible']}"


def paper_page(info: dict, evaluated: pd.DataFrame, runs: pd.DataFrame, sections: list[str],
               figures: list[Path], report_dir: Path) -> str:
    c = counts(evaluated)
    lines = [f"# {info['title']}", "", f"`{info['slug']}` — {info['authors']}, *{info['venue']}*"
             + (f", doi:{info['doi']}" if info.get("doi") else ""), ""]
    if info.get("summary"):
        lines += [info["summary"].strip(), ""]
    lines += ["## Summary", "", "matched / close / missed / not reproducible", "",
              "| " + " | ".join(CATEGORIES) + " |", "|" + "---|" * len(CATEGORIES),
              "| " + " | ".join(_cell(c[k]) for k in CATEGORIES) + " |", ""]
    lines += ["## Runs", ""]
    if runs.empty:
        lines += ["No runs on disk yet: `python -m pipeline experiment=<slug>/<name>` makes them.", ""]
    else:
        table = runs.groupby("experiment").agg(runs=("run_id", "size"), failed=("ok", lambda s: int((~s).sum())))
        lines += [table.reset_index().to_markdown(index=False), ""]
        failed = runs[~runs["ok"]]
        if not failed.empty:
            lines += ["Failed runs (recorded, not hidden):", "",
                      _md_table(failed[["experiment", "run_id", "status"]]), ""]
    lines += ["## Paper vs pipeline", "",
              "Every pipeline value is computed from the runs on disk; the paper's value is copied from the paper. "
              "Tolerance rules and statuses: `analysis/core/targets.py`.", ""]
    for category in CATEGORIES:
        part = evaluated[evaluated["category"] == category]
        if part.empty:
            continue
        shown = part.assign(status=part["status"].map(STATUS_MARK))[
            ["target_id", "quantity", "where", "paper_value", "op", "pipeline_value", "unit", "mode", "tolerance",
             "status", "cause", "note"]]
        lines += [f"### {category.capitalize()}", "", _md_table(shown), ""]
    for section in sections:
        lines += [section.strip(), ""]
    if figures:
        lines += ["## Figures", ""]
        for fig in figures:
            rel = os.path.relpath(fig, report_dir)
            lines += [f"![{fig.stem}]({rel})", ""]
    for key, title in (("assumptions", "Assumptions (what the paper does not give)"),
                       ("errata", "Errata (misprints found, and what we run)")):
        items = info.get(key) or []
        if items:
            lines += [f"## {title}", "", _md_table(pd.DataFrame(items)), ""]
    return "\n".join(lines)


def index_page(papers: list[tuple[dict, pd.DataFrame, pd.DataFrame]]) -> str:
    lines = ["# Reproduction report", "",
             "Each cell: targets matched / close / missed / not reproducible. A target is one number, bound or "
             "claim the paper reports; the pipeline's value is computed from the simulated runs.", "",
             "| paper | " + " | ".join(CATEGORIES) + " | runs (failed) |", "|---|" + "---|" * (len(CATEGORIES) + 1)]
    total = {k: dict.fromkeys(STATUSES, 0) for k in CATEGORIES}
    for info, evaluated, runs in papers:
        c = counts(evaluated)
        for k in CATEGORIES:
            for s in STATUSES:
                total[k][s] += c[k][s]
        n_failed = int((~runs["ok"]).sum()) if not runs.empty else 0
        lines.append(f"| [{info['slug']}]({info['slug']}.md) | " + " | ".join(_cell(c[k]) for k in CATEGORIES)
                     + f" | {len(runs)} ({n_failed}) |")
    lines.append("| **all** | " + " | ".join(_cell(total[k]) for k in CATEGORIES) + " | |")
    m = provenance.machine()
    lines += ["", f"Code revision `{provenance.git_revision()}`. Compute times were measured on: {m['cpu']}, "
              f"{m['logical_cores']} logical cores, {m['system']}, Python {m['python']} (medians over repeats; "
              "see each paper's compute-time table).", "",
              "All targets: [targets.csv](targets.csv)."]
    return "\n".join(lines)


_CSS = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;line-height:1.4}
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0}td,th{border:1px solid #ccc;padding:2px 6px}
th{background:#f3f3f3}img{max-width:100%}code{background:#f5f5f5;padding:0 3px}"""


def to_html(markdown: str, title: str) -> str:
    body = MarkdownIt("commonmark").enable("table").render(markdown)
    body = body.replace('.md"', '.html"')
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>{title}</title><style>{_CSS}</style>"
            f"</head><body>{body}</body></html>")


def write_page(path: Path, markdown: str, title: str) -> None:
    files.write_text(path, markdown + "\n")
    files.write_text(path.with_suffix(".html"), to_html(markdown, title))


def load_paper_info(package_dir: Path) -> dict:
    return yaml.safe_load((package_dir / "paper.yaml").read_text())


def write_targets_csv(evaluated: list[pd.DataFrame], path: Path) -> pd.DataFrame:
    frame = pd.concat(evaluated, ignore_index=True) if evaluated else pd.DataFrame(columns=TARGETS_CSV_COLUMNS)
    frame = frame[TARGETS_CSV_COLUMNS]
    files.write_text(path, frame.to_csv(index=False))
    return frame

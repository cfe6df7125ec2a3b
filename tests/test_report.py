"""The report tells the truth at a glance: status rules, causes, bases, and pages whose tables hold together
(HTML escaped by construction, Markdown cells escaped)."""

from __future__ import annotations

import math
from html.parser import HTMLParser
from pathlib import Path

import pandas as pd
import pytest

from analysis.core import report
from analysis.core.sections import Section, Table
from analysis.core.stages import PAPERS_DIR, analyzed_slugs
from analysis.core.targets import (
    BAND_CAUSES,
    CATEGORIES,
    CLOSE_FACTOR,
    STATUS_MEANING,
    STATUSES,
    Tolerance,
    band_runs,
    evaluate,
    judge,
    load_targets,
    paper_value,
    self_check,
)

ROOT = Path(__file__).resolve().parents[1]
REPRODUCTION = {"match", "close", "consistent", "miss"}


class TableShape(HTMLParser):
    """Cells per row of every <table>: (header cells, [cells of each body row])."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[list[list[str]]] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self.tables[-1][-1].append(tag)


def table_shapes(html: str) -> list[list[list[str]]]:
    parser = TableShape()
    parser.feed(html)
    return parser.tables


def assert_tables_whole(html: str, where: str) -> None:
    for k, rows in enumerate(table_shapes(html)):
        header = len(rows[0])
        bad = [i for i, row in enumerate(rows) if len(row) != header]
        assert not bad, f"{where}: table {k}: rows {bad} have not {header} cells"


def markdown_rows_whole(text: str, where: str) -> None:
    """Every row of every Markdown table has as many unescaped `|` as its header."""
    block: list[str] = []
    for line in [*text.splitlines(), ""]:
        if line.startswith("|"):
            block.append(line)
            continue
        if block:
            pipes = [line.replace("\\|", "").count("|") for line in block]
            assert len(set(pipes)) == 1, f"{where}: a table row is broken: {block[pipes.index(max(pipes))][:120]}"
            block = []


# -- status rules -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("pipeline", "paper", "op", "tol", "status"), [
    (1.05, 1.0, "==", "0.1", "match"),
    (1.15, 1.0, "==", "0.1", "close"),                   # outside the tolerance, within twice it
    (1.0 + CLOSE_FACTOR * 0.1 + 1e-9, 1.0, "==", "0.1", "miss"),
    (108.9, 100.0, "==", "0.05 rel", "close"),           # relative: 8.9 % against 5 %
    (110.1, 100.0, "==", "0.05 rel", "miss"),
    (-math.pi + 1e-6, math.pi, "==", "1e-5 wrap", "match"),   # ±π are the same angle
    (0.9, 1.0, "<=", "0.2", "match"),
    (1.1, 1.0, "<=", "0.2", "close"),                    # the inequality fails by less than its margin
    (1.3, 1.0, "<=", "0.2", "miss"),
    (float("nan"), 1.0, "==", "1", "miss"),
])
def test_status_rules(pipeline, paper, op, tol, status):
    assert judge(pipeline, paper, op, Tolerance.parse(tol)) == status


def _targets(**overrides) -> pd.DataFrame:
    row = {"target_id": "x", "category": "tracking errors", "quantity": "q", "where": "Table 1", "value": "1.0",
           "unit": "m", "mode": "exact", "op": "==", "tolerance": "0.1", "basis": "simulation", "cause": "",
           "experiment": "exp", "run": "r1", "metric": "m", "band": "", "note": ""}
    return pd.DataFrame([row | overrides])


def _metrics(value: float, run: str = "r1") -> dict[str, pd.DataFrame]:
    return {"exp": pd.DataFrame([{"run_id": run, "metric": "m", "value": value, "unit": "m"}])}


def _runs(*rows: tuple[str, str]) -> pd.DataFrame:
    return pd.DataFrame([{"experiment": "exp", "run_id": r, "status": s} for r, s in rows])


def test_deviation_and_causes():
    row = evaluate("p", _targets(), _metrics(1.15), _runs(("r1", "ok"))).iloc[0]
    assert row["status"] == "close" and row["cause"] == "open"           # close without a declared cause
    assert row["deviation"] == pytest.approx(0.15) and row["relative_deviation"] == pytest.approx(0.15)
    row = evaluate("p", _targets(cause="parameter-missing"), _metrics(3.0), _runs(("r1", "ok"))).iloc[0]
    assert row["status"] == "miss" and row["cause"] == "parameter-missing"
    row = evaluate("p", _targets(cause="parameter-missing"), _metrics(1.0), _runs(("r1", "ok"))).iloc[0]
    assert row["status"] == "match" and row["cause"] == ""               # a cause shows only where it explains


def test_not_run_and_failed_runs():
    # the experiment never ran, or only a sweep of it (other run ids) is on disk: not run, never a miss
    assert evaluate("p", _targets(), {}, _runs()).iloc[0]["status"] == "not run"
    swept = evaluate("p", _targets(), _metrics(1.0, run="r1-k=2"), _runs(("r1-k=2", "ok"))).iloc[0]
    assert swept["status"] == "not run"
    # the run was made and failed: a miss that says why; so is an aggregate a failed run left without a value
    failed = evaluate("p", _targets(), {}, _runs(("r1", "failed: diverged at t = 1 s"))).iloc[0]
    assert failed["status"] == "miss" and "diverged" in failed["note"]
    runs = _runs(("r1", "ok"), ("r2", "failed: unstable"))
    aggregate = evaluate("p", _targets(run="all"), _metrics(1.0), runs).iloc[0]
    assert aggregate["status"] == "miss" and "r2 failed: unstable" in aggregate["note"]


def _interval_metrics(median: float, low: float, high: float) -> dict[str, pd.DataFrame]:
    return {"exp": pd.DataFrame([{"run_id": "r1", "metric": m, "value": v, "unit": "m"} for m, v in
                                 (("m", median), ("m.ci_low", low), ("m.ci_high", high))])}


@pytest.mark.parametrize(("low", "high", "status"), [
    (0.8, 1.3, "match"),          # the paper's 1.0 inside our interval, although the median is 1.2 (> 1.1 away)
    (1.0, 1.3, "match"),          # on the bound
    (1.05, 1.3, "miss"),          # excluded, however near: an interval has no `close`
    (0.5, 0.99, "miss"),
    (float("nan"), float("nan"), "miss"),   # no interval written: nothing supports a match
])
def test_interval_rule(low, high, status):
    """tolerance `ci`: the paper's value against the interval the analysis writes beside the metric."""
    row = evaluate("p", _targets(tolerance="ci"), _interval_metrics(1.2, low, high), _runs(("r1", "ok"))).iloc[0]
    assert row["status"] == status and row["pipeline_value"] == pytest.approx(1.2)
    assert row["tolerance"] == "95% CI" and "95 % interval" in row["note"]
    if status == "miss":
        assert row["cause"] == "open"


def test_interval_rule_judges_equality_only(tmp_path):
    path = tmp_path / "targets.csv"
    _targets(tolerance="ci", op="<=").to_csv(path, index=False)
    with pytest.raises(ValueError, match="tolerance `ci` judges `==`"):
        load_targets(path)


def test_consistency_rows_are_never_reproductions():
    agree = evaluate("p", _targets(mode="consistency", basis="paper"), _metrics(1.0), _runs(("r1", "ok"))).iloc[0]
    assert agree["status"] == "agrees"
    off = evaluate("p", _targets(mode="consistency", basis="paper"), _metrics(1.15), _runs(("r1", "ok"))).iloc[0]
    assert off["status"] == "disagrees" and off["cause"] == "paper-inconsistent"


# -- sensitivity bands ----------------------------------------------------------------------------------------------


def test_band_reads_the_target_run_and_its_sweep_runs():
    ids = pd.Series(["r1", "r1__k=2", "r1__a=0.5,b=2", "r1x", "r1-k=2", "r10__k=1", "r2__r1=1", "r1_"])
    assert band_runs(ids, "r1").tolist() == [True, True, True, False, False, False, False, False]


def _banded(default: float, swept: dict[str, float], cause: str = "parameter-missing", op: str = "==",
            status: dict[str, str] | None = None):
    """A target 1.0 ± 0.1 whose default run gives `default` and whose band experiment `sweep` gives `swept`."""
    sweep = pd.DataFrame([{"run_id": r, "metric": "m", "value": v, "unit": "m"} for r, v in swept.items()])
    runs = pd.concat([_runs(("r1", "ok")), pd.DataFrame([{"experiment": "sweep", "run_id": r,
                                                         "status": (status or {}).get(r, "ok")} for r in swept])])
    return evaluate("p", _targets(band="sweep", cause=cause, op=op), _metrics(default) | {"sweep": sweep},
                    runs).iloc[0]


def test_a_miss_whose_band_reaches_the_paper_is_consistent():
    row = _banded(1.5, {"r1__k=1": 0.8, "r1__k=2": 1.2})
    assert row["status"] == "consistent" and row["cause"] == "parameter-missing"
    assert (row["pipeline_value"], row["band_min"], row["band_max"]) == (1.5, 0.8, 1.2)  # the default stays
    assert _banded(1.15, {"r1__k=1": 0.95, "r1__k=2": 1.2})["status"] == "consistent"     # a close too
    # a match stays a match, with its band shown
    matched = _banded(1.05, {"r1__k=1": 0.5, "r1__k=2": 3.0})
    assert matched["status"] == "match" and matched["band_max"] == 3.0
    # an inequality is reached where it holds at the band's favourable end
    assert _banded(1.5, {"r1__k=1": 0.7, "r1__k=2": 1.6}, op="<")["status"] == "consistent"
    assert _banded(1.5, {"r1__k=1": 1.3, "r1__k=2": 1.6}, op="<", cause="model-limitation")["status"] == "miss"


def test_a_band_counts_only_ok_runs_of_its_own_case():
    # the run reaching the paper failed, and another case's sweep reaches it: neither counts
    row = _banded(1.5, {"r1__k=1": 1.4, "r1__k=2": 1.0, "r10__k=1": 1.0}, cause="model-limitation",
                  status={"r1__k=2": "failed: diverged"})
    assert row["status"] == "miss" and (row["band_min"], row["band_max"]) == (1.4, 1.4)
    assert row["cause"] == "model-limitation"
    # the sweep is not on disk: no band, judged as without one
    alone = evaluate("p", _targets(band="sweep", cause="parameter-missing"), _metrics(1.5), _runs(("r1", "ok")))
    assert alone.iloc[0]["status"] == "miss" and math.isnan(alone.iloc[0]["band_min"])
    assert not self_check(alone)


def test_a_band_counts_the_aggregates_of_its_sweep_points():
    """A value the analysis writes per sweep point (a fit over a map: `r1__k=2`, not a run) is part of the band;
    a failed run's rows are not."""
    sweep = pd.DataFrame([{"run_id": r, "metric": "m", "value": v, "unit": "m"}
                          for r, v in (("r1__k=1", 1.4), ("r1__k=2", 1.0), ("r1__k=3", 0.5))])
    runs = pd.concat([_runs(("r1", "ok")), pd.DataFrame([{"experiment": "sweep", "run_id": "r1__k=3",
                                                         "status": "failed: diverged"}])])
    row = evaluate("p", _targets(band="sweep", cause="parameter-missing"), _metrics(1.5) | {"sweep": sweep},
                   runs).iloc[0]
    assert row["status"] == "consistent" and (row["band_min"], row["band_max"]) == (1.0, 1.4)


def test_a_band_reaches_the_paper_within_its_tolerance():
    """1.0 ± 0.1: a band [1.08, 1.3] holds a value that would match; [1.15, 1.3] does not."""
    assert _banded(1.5, {"r1__k=1": 1.08, "r1__k=2": 1.3})["status"] == "consistent"
    assert _banded(1.5, {"r1__k=1": 1.15, "r1__k=2": 1.3}, cause="model-limitation")["status"] == "miss"


def test_a_default_without_a_value_can_be_consistent_unless_it_failed():
    """No value where the default did not fail (an aggregate with nothing to fit) is a miss a band may explain;
    a failed default run stays a miss."""
    sweep = pd.DataFrame([{"run_id": "r1__k=1", "metric": "m", "value": 1.02, "unit": "m"}])
    empty = {"exp": pd.DataFrame([{"run_id": "r1", "metric": "other", "value": 0.0, "unit": "m"}])}
    runs = pd.concat([_runs(("r0", "ok")), pd.DataFrame([{"experiment": "sweep", "run_id": "r1__k=1",
                                                         "status": "ok"}])])
    row = evaluate("p", _targets(band="sweep", cause="parameter-missing"), empty | {"sweep": sweep}, runs).iloc[0]
    assert row["status"] == "consistent" and math.isnan(row["pipeline_value"])
    failed = pd.concat([runs, _runs(("r1", "failed: diverged"))])
    row = evaluate("p", _targets(band="sweep", cause="paper-inconsistent"), {"sweep": sweep}, failed).iloc[0]
    assert row["status"] == "miss" and "diverged" in row["note"]


def test_self_check_refuses_a_missing_parameter_its_band_cannot_explain():
    bad = _banded(1.5, {"r1__k=1": 1.4, "r1__k=2": 1.6})                  # parameter-missing, band misses
    assert bad["status"] == "miss"
    problems = self_check(pd.DataFrame([bad]))
    assert len(problems) == 1 and "p:x" in problems[0] and "parameter-missing" in problems[0]
    assert all(cause in problems[0] for cause in BAND_CAUSES)
    assert self_check(pd.DataFrame([_banded(1.5, {"r1__k=1": 1.4}, cause="")]))             # `open` neither
    for cause in BAND_CAUSES:
        assert not self_check(pd.DataFrame([_banded(1.5, {"r1__k=1": 1.4, "r1__k=2": 1.6}, cause=cause)]))
    assert not self_check(pd.DataFrame([_banded(1.5, {"r1__k=1": 0.8, "r1__k=2": 1.2})]))   # consistent


def test_the_report_stage_fails_its_self_check(tmp_path, monkeypatch, capsys):
    """A banded target declared `parameter-missing` whose band cannot reach the paper: the report is still
    written, every problem is named, and the stage exits 1 (so `dvc repro` stops)."""
    from analysis.core import stages
    from analysis.core.metrics import write_metrics

    load = stages.load_targets

    def with_band(path):
        targets = load(path)
        targets.loc[0, ["band", "cause"]] = ["tables-sweep", "parameter-missing"]
        return targets

    monkeypatch.setattr(stages, "analyzed_slugs", lambda: ["ur5-ik-fsm"])
    monkeypatch.setattr(stages, "load_targets", with_band)
    first = with_band(PAPERS_DIR / "ur5_ik_fsm" / "targets.csv").iloc[0]
    metrics = tmp_path / "metrics" / "ur5-ik-fsm"
    metrics.mkdir(parents=True)
    for name, ids in (("tables", [first["run"]]), ("tables-sweep", [f"{first['run']}__k=1", f"{first['run']}__k=2"])):
        write_metrics(pd.DataFrame([{"run_id": r, "metric": first["metric"], "value": float(first["value"]) + 1 + k,
                                     "unit": first["unit"]} for k, r in enumerate(ids)]), metrics / f"{name}.parquet")
        pd.DataFrame({"run_id": ids, "status": "ok", "ok": True}).to_csv(metrics / f"{name}.runs.csv", index=False)
    assert stages.run(tmp_path, None, "report") == 1
    err = capsys.readouterr().err
    assert f"ur5-ik-fsm:{first['target_id']}: miss with cause `parameter-missing`" in err
    assert "band tables-sweep is named in targets.csv but not declared in paper.yaml" in err
    assert (tmp_path / "report" / "ur5-ik-fsm.html").is_file()


def test_a_band_belongs_to_a_reproduction_target(tmp_path):
    path = tmp_path / "targets.csv"
    _targets(mode="consistency", basis="paper", band="sweep").to_csv(path, index=False)
    with pytest.raises(ValueError, match="a band belongs to a reproduction target"):
        load_targets(path)


def test_a_paper_basis_goes_only_with_consistency(tmp_path):
    path = tmp_path / "targets.csv"
    _targets(basis="paper").to_csv(path, index=False)
    with pytest.raises(ValueError, match="basis `paper` goes with mode `consistency`"):
        load_targets(path)


def test_every_status_is_defined_in_one_sentence():
    assert set(STATUSES) | {"agrees", "disagrees"} == set(STATUS_MEANING)
    assert all(text.count(". ") == 0 and text.endswith(".") for text in STATUS_MEANING.values())


@pytest.mark.parametrize("slug", analyzed_slugs())
def test_paper_declarations(slug):
    """targets.csv loads (bases, modes, causes valid); paper.yaml declares its figures with a known section; no
    note or page text cites the spec (what a page relies on lives in the paper's own paper.yaml)."""
    package = PAPERS_DIR / slug.replace("-", "_")
    targets = load_targets(package / "targets.csv")
    info = report.load_paper_info(package)
    for key, spec in (info.get("figures") or {}).items():
        assert "/" in key and spec.get("caption") and "paper" in spec, f"{slug}: figure {key}"
        assert spec.get("section") in (*CATEGORIES, report.FURTHER), f"{slug}: figure {key}: section"
    text = (package / "paper.yaml").read_text() + "".join(targets["note"]) + "".join(
        p.read_text() for p in package.glob("*.py"))
    assert "spec §" not in text
    # every band is justified in paper.yaml and is a disclosed sweep (`-m`) in its DVC stages
    bands = {b["experiment"]: b for b in info.get("bands") or []}
    assert set(targets["band"]) - {""} <= set(bands), f"{slug}: bands not declared in paper.yaml"
    sweeps = report.simulate_args()
    for name, b in bands.items():
        assert all(str(b.get(k, "")).strip() for k in ("parameter", "range", "why")), f"{slug}: band {name}"
        assert sweeps.get(f"{slug}/{name}", "").startswith("-m "), f"{slug}: band {name} is not a -m sweep"


def test_paper_values_are_read_from_targets():
    assert paper_value("gripper-force-control", "F9.max") == 1.27
    assert paper_value("gripper-force-control", "F8.friction", "fraction") == pytest.approx(0.15)


# -- pages ------------------------------------------------------------------------------------------------------


def test_cells_with_pipes_and_markup_cannot_break_a_page(tmp_path):
    evaluated = evaluate("ur5-ik-fsm", _targets(quantity="max |τ1| <b>bold</b>", note="a | b\nc"),
                         _metrics(1.15), _runs(("r1", "ok")))
    info = {"slug": "ur5-ik-fsm", "title": "T | itle", "authors": "A", "venue": "V", "doi": "10.1/x",
            "summary": "S", "assumptions": [{"what": "|w|", "choice": "c", "config": ""}], "errata": []}
    section = Section("Extra |τ|", "prose with |x|", Table(pd.DataFrame({"|a|": [1.0, float("nan")], "b": ["|", "x"]})),
                      category="tracking errors")
    runs = pd.DataFrame([{"experiment": "exp", "run_id": "r1", "status": "ok", "ok": True}])
    context = report.paper_context(info, evaluated, runs, [section], [], tmp_path, tmp_path / "report")
    html = report.render("paper.html.j2", **context)
    assert "<b>bold</b>" not in html and "&lt;b&gt;bold&lt;/b&gt;" in html
    assert 'href="https://doi.org/10.1/x"' in html and "close" in html
    assert_tables_whole(html, "paper.html")
    markdown_rows_whole(report.render("paper.md.j2", **context), "paper.md")
    # a band beside the default value, and the bands listed with their justification
    banded = pd.concat([evaluated, pd.DataFrame([_banded(1.5, {"r1__k=1": 0.8, "r1__k=2": 1.2})])
                        .assign(target_id="y", slug="ur5-ik-fsm")], ignore_index=True)
    info["bands"] = [{"experiment": "sweep", "parameter": "k | gain", "range": "0.8-1.2", "why": "datasheet"}]
    context = report.paper_context(info, banded, runs, [section], [], tmp_path, tmp_path / "report")
    html = report.render("paper.html.j2", **context)
    assert "band [0.8, 1.2]" in html and 'id="band-sweep"' in html and "datasheet" in html
    assert_tables_whole(html, "paper.html (bands)")
    markdown_rows_whole(report.render("paper.md.j2", **context), "paper.md (bands)")
    assert not report.undeclared_bands(info, banded) and report.undeclared_bands({**info, "bands": []}, banded)
    for datasets in ([], [{"name": "ur5-ik-fsm/random-paths", "card": "../datasets/ur5-ik-fsm/random-paths/README.md",
                           "format": "LeRobot v3.0", "episodes": 2, "frames": 10, "fps": 5, "size_mb": 0.1},
                          {"name": "gripper-review", "card": "../datasets/gripper-review/README.md",
                           "format": "tables (Parquet, CSV)", "episodes": None, "frames": None, "fps": None,
                           "size_mb": 0.2}]):
        index = report.index_context([(info, evaluated, runs)], datasets)
        html = report.render("index.html.j2", **index)
        assert_tables_whole(html, "index.html")
        markdown_rows_whole(report.render("index.md.j2", **index), "index.md")
        assert all(f'href="{d["card"]}"' in html for d in datasets)


# -- a full report (after `python -m dvc repro`) --------------------------------------------------------------------


FULL = ROOT / "data" / "report" / "targets.csv"


@pytest.mark.skipif(not FULL.is_file(), reason="no full report in data/report (python -m dvc repro makes it)")
def test_full_report_is_honest():
    """Every miss and close has a declared cause, no close is farther than CLOSE_FACTOR × its tolerance, and no
    `paper`-basis row carries a reproduction status."""
    t = pd.read_csv(FULL, keep_default_na=False)
    declared = pd.concat([load_targets(PAPERS_DIR / s.replace("-", "_") / "targets.csv").assign(slug=s)
                          for s in analyzed_slugs()]).set_index(["slug", "target_id"])["cause"]
    off = t[t["status"].isin(["miss", "close"])]
    undeclared = [f"{r.slug}:{r.target_id}" for r in off.itertuples() if not declared.get((r.slug, r.target_id))]
    assert not undeclared, f"misses/closes without a declared cause: {undeclared}"
    assert not set(t.loc[t["basis"] == "paper", "status"]) & REPRODUCTION
    close = t[(t["status"] == "close") & (t["op"] == "==")]
    for r in close.itertuples():
        tol = Tolerance.parse(r.tolerance.replace("(mod 2π)", "wrap"))
        allowed = tol.value * (abs(float(r.paper_value)) if tol.relative else 1.0)
        assert abs(float(r.deviation)) <= CLOSE_FACTOR * allowed * (1 + 1e-9), r.target_id


def test_a_caption_may_hold_braces(tmp_path):
    png = tmp_path / "figures/x/plot-a.png"
    png.parent.mkdir(parents=True)
    png.write_bytes(b"")
    info = {"slug": "x", "figures": {"x/*": {"caption": "Set {q | q > 0} of case {name}", "section": "S"}}}
    [entry] = report.figure_entries(info, [png], tmp_path)
    assert entry["caption"] == "Set {q | q > 0} of case plot-a"

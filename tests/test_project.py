"""Consistency of the project's own data: DVC stages, targets files, report rules."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from analysis.core.report import simulate_args, stage_vars
from analysis.core.stages import PAPERS_DIR, analyzed_slugs, paper_package
from analysis.core.targets import Tolerance, judge, load_targets
from analysis.core.units import convert
from pipeline.core.experiment import available_experiments, experiment_descriptions, module_name, paper_module

from .conftest import ROOT


def test_every_experiment_is_a_dvc_stage_and_has_code():
    papers = stage_vars()   # one stages/<slug>/ per paper: its dvc.yaml links to the shared stage definitions
    assert set(papers) == set(analyzed_slugs()) == {e.split("/")[0] for e in available_experiments()}
    for slug, values in papers.items():
        assert values["slug"] == slug and values["module"] == module_name(slug)
        link = ROOT / "stages" / slug / "dvc.yaml"
        assert link.is_symlink() and link.resolve() == (ROOT / "stages" / "paper-stages.yaml").resolve()
    assert set(simulate_args()) == set(available_experiments())
    for experiment in available_experiments():
        slug, name = experiment.split("/")
        assert name in paper_module(slug).EXPERIMENTS
        assert name in paper_package(slug).ANALYSES
    # `--help` lists every experiment with its one-line description
    for experiment, text in experiment_descriptions().items():
        assert text != "(no description)" and "\n" not in text and len(text) <= 140, experiment



def test_dvc_reads_every_paper_s_stages():
    """DVC itself resolves the linked stage files with each paper's vars: one simulate stage per experiment, one
    analyze stage per paper, one export stage per paper with datasets, and the report."""
    import subprocess
    import sys

    listed = subprocess.run([sys.executable, "-m", "dvc", "stage", "list", "--all", "--name-only"], cwd=ROOT,
                            capture_output=True, text=True, check=True).stdout.split()
    expected = {"report"}
    for slug, values in stage_vars().items():
        stages = f"stages/{slug}/dvc.yaml"
        expected |= {f"{stages}:simulate@{name}" for name in values["experiments"]} | {f"{stages}:analyze"}
        expected |= {f"{stages}:export@{key}" for key in values["datasets"]}
    assert sorted(listed) == sorted(expected)

@pytest.mark.parametrize("slug", analyzed_slugs())
def test_targets_files_are_valid_and_point_at_real_experiments(slug):
    targets = load_targets(PAPERS_DIR / module_name(slug) / "targets.csv")
    live = targets[targets["mode"] != "not reproducible"]
    assert set(live["experiment"]) <= {e.split("/")[1] for e in available_experiments() if e.startswith(slug)}
    assert (live["metric"] != "").all() and (live["value"] != "").all()
    info = yaml.safe_load((PAPERS_DIR / module_name(slug) / "paper.yaml").read_text())
    assert info["slug"] == slug and info["assumptions"] and "errata" in info


def test_judge_rules():
    assert judge(1.00004, 1.0, "==", Tolerance(5e-5)) == "match"
    assert judge(1.00009, 1.0, "==", Tolerance(5e-5)) == "close"
    assert judge(1.0004, 1.0, "==", Tolerance(5e-5)) == "miss"
    assert judge(1.01, 1.0, "==", Tolerance(5e-5)) == "miss"
    assert judge(-math.pi + 1e-6, math.pi, "==", Tolerance(5e-5, wrap=True)) == "match"
    assert judge(1.00005e7, 1e7, "==", Tolerance(1e-4, relative=True)) == "match"
    assert judge(0.5, 1.0, "<", Tolerance()) == "match"
    assert judge(1.05, 1.0, "<", Tolerance(0.1)) == "close"
    assert judge(float("nan"), 1.0, "==", Tolerance(1.0)) == "miss"


def test_units():
    assert convert(1e-9, "m^3", "mm^3") == pytest.approx(1.0)
    assert convert(2e-6, "s", "us") == pytest.approx(2.0)
    with pytest.raises(ValueError):
        convert(1.0, "m", "s")


def test_tolerance_parse():
    assert Tolerance.parse("1e-4 rel") == Tolerance(1e-4, relative=True)
    assert Tolerance.parse("5e-5 wrap") == Tolerance(5e-5, wrap=True)
    assert Tolerance.parse("") == Tolerance()


def test_code_is_ruff_clean():
    ruff = pytest.importorskip("ruff")
    import subprocess
    import sys

    assert ruff
    proc = subprocess.run([sys.executable, "-m", "ruff", "check", "."], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout


def test_error_stats_closed_form():
    from analysis.core.errors import error_stats, force_error_stats

    t = np.linspace(0.0, 1.0, 1001)
    s = error_stats(t, np.sin(2 * np.pi * t), "e", "m")
    assert s["e.max"][0] == pytest.approx(1.0, abs=1e-5) and s["e.rms"][0] == pytest.approx(2 ** -0.5, rel=1e-3)
    assert s["e.ise"][0] == pytest.approx(0.5, rel=1e-5) and s["e.mean"][0] == pytest.approx(2 / np.pi, rel=2e-3)
    f = force_error_stats(t, np.full_like(t, 9.0), np.full_like(t, 10.0))
    assert f["force_error.max"][0] == pytest.approx(1.0) and f["force_error.sag"][0] == pytest.approx(0.1)


def test_a_target_of_a_failed_run_says_why():
    import pandas as pd

    from analysis.core.targets import evaluate

    targets = pd.DataFrame([{"target_id": "x", "category": "tracking errors", "quantity": "q", "where": "T1",
                             "value": "1", "unit": "m", "mode": "exact", "op": "==", "tolerance": "0.1",
                             "basis": "simulation", "cause": "",
                             "experiment": "e", "run": "r", "metric": "m", "note": ""}])
    runs = pd.DataFrame([{"experiment": "e", "run_id": "r", "status": "failed: diverged at t = 1 s", "ok": False}])
    row = evaluate("s", targets, {"e": pd.DataFrame(columns=["run_id", "metric", "value", "unit"])}, runs).iloc[0]
    assert row["status"] == "miss" and "failed: diverged at t = 1 s" in row["note"] and row["cause"] == "open"
    never_ran = evaluate("s", targets, {}, runs.assign(experiment="other")).iloc[0]
    assert never_ran["status"] == "not run"

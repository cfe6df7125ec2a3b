"""dyad-triad-synthesis end to end through the CLIs (the worked example, the Exudyn four-bar, the report built
from them), the runs' MCAP contract, and bad input refused before anything runs."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pipeline.core.checks import BadInput, compose_config, preflight
from pipeline.core.runlog import SimulationFailed, read_runs
from pipeline.papers.dyad_triad_synthesis import experiments
from pipeline.papers.dyad_triad_synthesis.compatibility import synthesize
from pipeline.papers.dyad_triad_synthesis.standard_form import dyad

from .conftest import run_cli

SLUG = "dyad-triad-synthesis"


@pytest.mark.slow
def test_worked_example_and_four_bar_to_report(data_dir):
    # the default sizes (the targets name the default runs): both take ~2 s of CPU
    for name in ("table5", "four-bar"):
        proc = run_cli("pipeline", f"experiment={SLUG}/{name}", f"data_dir={data_dir}", "progress=false")
        assert proc.returncode == 0, proc.stderr
    for name in ("table5", "four-bar"):
        proc = run_cli("analysis", f"experiment={SLUG}/{name}", f"data_dir={data_dir}", "stage=analyze")
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}", "stage=report")
    assert proc.returncode == 0, proc.stderr

    runs = {r.run_id: r for r in read_runs(data_dir / "runs" / SLUG / "four-bar")}
    assert set(runs) == {"defects", "replay-1to5", "servo-2to5-computed-torque", "servo-2to5-pd"}
    assert all(r.ok for r in runs.values())
    replay = runs["replay-1to5"]
    assert {"/joint_state", "/reference", "/tracking_error", "/tf", "/markers"} <= set(replay.topic_names)
    assert list(replay["/joint_state"].filter(like="position.").columns) == [
        "position.crank_A", "position.coupler", "position.rocker_B"]
    assert "model.yaml" in replay.attachments
    markers = replay["/markers"]
    assert markers.filter(like="cylinders").shape[1] > 0 and markers.filter(like="lines").shape[1] > 0
    ids = markers.filter(regex=r"^entities\.\d+\.id$").iloc[0].tolist()
    assert len(ids) == len(set(ids))                   # Foxglove replaces an entity by a later one of the same id
    assert {"/command", "/passage"} <= set(runs["servo-2to5-computed-torque"].topic_names)

    targets = pd.read_csv(data_dir / "report" / "targets.csv").set_index("target_id")
    for target in ("T5.delta1.re", "T5.delta3p.im", "S2.5.alignment", "S2.5.parallelogram.im", "S2.5.dyads",
                   "S2.3.six_sets", "S2.3.special", "F14.position", "F14.angle"):
        assert targets.loc[target, "status"] == "match", target
    assert targets.loc["S2.5.delta_loop_limits", "status"] == "miss"     # the paper's statement, refuted
    assert (targets.loc[["C5.eq13", "C5.eq19", "C5.alignment"], "status"] == "agrees").all()
    assert targets.loc["T1.triad_sets", "status"] == "not run"           # round-trips not run here
    metrics = pd.read_parquet(data_dir / "metrics" / SLUG / "four-bar.parquet").set_index(["run_id", "metric"])
    assert metrics.loc[("replay-1to5", "positions.max_error"), "value"] < 1e-10
    assert metrics.loc[("servo-2to5-computed-torque", "tracking.max"), "value"] < 1e-3
    assert (data_dir / "figures" / SLUG / "four-bar" / "fig14-four-bar.png").is_file()
    assert (data_dir / "report" / f"{SLUG}.html").is_file()


@pytest.mark.parametrize("override", [
    "scenario.four_bars=1000000000", "scenario.triads=0", "system.search.grid=5", "scenario.newton_starts=1e12",
    "system.linkage.line_density=-1", "scenario.controllers=[bogus]", "execute.servo_dt=0",
    "scenario.leg_duration=1e9", "system.table4.alpha_deg=[0,1,2,3,nan]",
    "system.table4.points=[[1,2],[3,4]]", "system.table4.points=[[1,2,3],[1,2],[1,2],[1,2],[1,2]]",  # shapes
    "execute.servo_dt=0.01",                                                        # coarser than the servo
])
def test_bad_input_is_refused_in_one_line(override):
    experiment = {"four_bars": "round-trips", "triads": "round-trips", "newton_starts": "round-trips"}.get(
        override.split("=")[0].rsplit(".", 1)[-1], "four-bar")
    with pytest.raises(BadInput) as err:
        preflight([f"experiment={SLUG}/{experiment}", override])
    message = str(err.value)
    assert "\n" not in message and len(message) < 300 and override.split("=")[0].split("[")[0] in message


def test_refusal_from_the_cli_writes_nothing(data_dir):
    proc = run_cli("pipeline", f"experiment={SLUG}/round-trips", f"data_dir={data_dir}", "scenario.count_problems=1e9")
    assert proc.returncode == 2 and "scenario.count_problems" in proc.stderr and not data_dir.exists()


def test_five_positions_without_two_dyads_is_a_failed_run_not_a_crash():
    """Positions with no real dyad (a third of random problems) leave no four-bar to build: the run fails with
    its reason and the pipeline goes on."""
    rng = np.random.default_rng(0)
    while True:
        points = rng.uniform(-20, 20, 5) + 1j * rng.uniform(-20, 20, 5)
        alpha = np.concatenate([[0], np.cumsum(rng.uniform(3, 45, 4))])
        if not any(f.label == "solution" for f in synthesize(dyad(points * 0.01, np.radians(alpha)))):
            break
    rows = [[round(float(p.real), 3), round(float(p.imag), 3)] for p in points]
    cfg = compose_config([f"experiment={SLUG}/four-bar", f"system.table4.points={rows}",
                          f"system.table4.alpha_deg={[round(float(a), 3) for a in alpha]}"])
    case = next(c for c in experiments.four_bar(cfg) if c.id == "replay-1to5")
    with pytest.raises(SimulationFailed, match="gives 0 dyads"):
        case.simulate(None)

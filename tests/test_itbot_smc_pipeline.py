"""itbot-smc end to end through the CLIs on shortened runs (a 2.5 s exercise): every
experiment simulates, analyses and reports; the runs keep the MCAP contract; bad input is refused in one line
before anything is written."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pipeline.core.checks import BadInput, preflight
from pipeline.core.runlog import read_runs

from .conftest import run_cli

SLUG = "itbot-smc"
SHORT = ["system.reference.period=2.5", "progress=false"]


@pytest.mark.slow
def test_every_experiment_to_the_report(data_dir):
    one_load = ["system.hand.support=1", "scenario.paper_model_laws=[smerl]"]   # with the bare model
    for experiment, extra in (("tracking", SHORT), ("load-support", [*SHORT, *one_load]),
                              ("smc-sweep", [*SHORT, "system.control.smc.boundary_layer=0.5"]),
                              ("reaching-time", ["progress=false"])):
        proc = run_cli("pipeline", f"experiment={SLUG}/{experiment}", f"data_dir={data_dir}", *extra)
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    runs = {r.metadata["case"]: r for r in read_runs(data_dir / "runs" / SLUG / "tracking")}
    assert {f"{law}-{group}" for law in ("nsmerl", "smerl", "smc") for group in ("analytic", "mujoco", "hall")} \
        | {"nsmerl-ms"} == set(runs)
    run = runs["smc-mujoco"]
    assert run.ok
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/wrench", "/compute_time", "/tf",
            "/markers", "/sliding_variable"} <= set(run.topic_names)
    assert {"model.xml", "config.yaml", "robot.urdf"} <= set(run.attachments)   # the arm drawn from its model
    assert {"/robot_description", "/joint_states", "/tf/robot"} <= set(run.topic_names)
    arrow = run["/markers"].filter(like="arrows.0.")                     # the hand's force at 5 mm/N
    drawn = (arrow.filter(like="shaft_length").iloc[:, 0] + arrow.filter(like="head_length").iloc[:, 0]) / 0.005
    wrench = run["/wrench"].reindex(drawn.index)
    assert len(drawn) > 100 and np.allclose(drawn, np.hypot(wrench["force_x.hand"], wrench["force_y.hand"]))
    assert {"position.joint1", "position.joint2"} <= set(run["/joint_state"].columns)
    assert len(run["/command"]) == 2500                                   # every tick of the 2.5 s exercise
    assert {"transforms.link2.translation.x", "transforms.hand.translation.x"} <= set(run["/tf"].columns)

    targets = pd.read_csv(data_dir / "report" / "targets.csv").set_index("target_id")
    targets = targets[targets["slug"] == SLUG]
    assert targets.loc["reach.eq7", "status"] == "match"                  # the reaching study ran unchanged
    assert targets.loc["reach.threshold", "status"] == "match"
    assert targets.loc["reach.eq14", "status"] == "miss"                  # p = 0.5 breaks the bound
    assert targets.loc["hw.traces", "status"] == "not-reproducible"
    assert targets.loc["err.nsmerl", "status"] == "not run"   # its run is the full exercise, not this shortened one
    metrics = pd.read_parquet(data_dir / "metrics" / SLUG / "tracking.parquet")
    claims = metrics[metrics["run_id"] == "analytic__system.reference.period=2.5"]   # the shortened runs' own
    assert set(claims["metric"]) >= {"claim.tracks_better_than_smc", "claim.less_chattering_than_smc"}
    agreement = metrics[metrics["metric"] == "agreement.e.rms"]["value"]
    assert len(agreement) == 3 and (agreement < 0.1).all()               # the two plants track alike
    assert (data_dir / "figures" / SLUG / "tracking" / "fig10-torques.png").is_file()
    assert "The three controllers" in (data_dir / "report" / f"{SLUG}.md").read_text()


@pytest.mark.parametrize("override", ["system.hand.support=1.5", "system.reference.cycles=1000",
                                      "scenario.laws=[pid]", "system.sensing.model=magic",
                                      "system.control.rate_hz=0", "system.control.phi=[0.1,1.5]",
                                      "scenario.groups.ms.omega_rate=-1"])
def test_bad_input_is_refused_in_one_line(override):
    with pytest.raises(BadInput) as refused:
        preflight([f"experiment={SLUG}/tracking", override])
    message = str(refused.value)
    assert "\n" not in message and len(message) < 300 and override.split("=")[0] in message


def test_the_cli_refuses_before_writing(data_dir):
    proc = run_cli("pipeline", f"experiment={SLUG}/load-support", f"data_dir={data_dir}", "system.hand.damping=-5")
    assert proc.returncode == 2 and "system.hand.damping" in proc.stderr and len(proc.stderr.strip()) < 300
    assert not data_dir.exists()

"""cobot-6r-ik end to end on a temporary data_dir with reduced sizes: the four experiments, analysis and
report, the statuses the reproduction reaches, what the runs hold, and bad input refused."""

from __future__ import annotations

import pandas as pd

from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli

REDUCED = {   # tables as configured: its targets read the default runs
    "tables": [],
    "completeness": ["scenario.poses=60", "scenario.reference_poses=4", "scenario.reference_starts=100"],
    "compute-time": ["scenario.poses=40", "scenario.warmup=5", "scenario.batch_repeats=1", "scenario.batch_chunk=10",
                     "scenario.peer_poses=2", "scenario.peer_starts=5"],
    "trajectory": ["scenario.cases=[circle]", "scenario.duration=1.0", "scenario.ik_dt=0.01", "execute.settle=0.1"],
}


def test_cobot_6r_ik_end_to_end(data_dir):
    for name, overrides in REDUCED.items():
        proc = run_cli("pipeline", f"experiment=cobot-6r-ik/{name}", f"data_dir={data_dir}", "progress=false",
                       *overrides)
        assert proc.returncode == 0, proc.stderr
    proc = run_cli("analysis", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr

    targets = pd.read_csv(data_dir / "report/targets.csv")
    ours = targets[targets["slug"] == "cobot-6r-ik"].set_index("target_id")
    tables = ours[ours["experiment"] == "tables"]
    assert (tables["status"] != "not run").all()
    # the genuine rows of Table 3 and all of Table 2's roots but the two the paper misprints
    genuine = [f"T3.{r}.q{j}" for r in (3, 4, 5, 6, 7, 8, 15, 16) for j in range(1, 7)]
    assert (ours.loc[genuine, "status"] == "match").all(), ours.loc[genuine, ["pipeline_value", "status"]]
    roots = ours[ours.index.str.match(r"T2\.root\d\d\.re")]
    assert (roots.drop(["T2.root03.re", "T2.root07.re"])["status"] == "match").all()
    assert ours.loc["claim.minimum_degree", "status"] == "miss" and ours.loc["L.real_roots", "status"] == "match"
    assert ours.loc["solutions.count", "pipeline_value"] == 8
    assert (ours.loc[[f"T3.{r}.consistency" for r in (1, 2, 13, 14)], "status"] == "disagrees").all()
    # every miss or close says why
    assert (ours.loc[ours["status"].isin(["miss", "close"]), "cause"].fillna("") != "").all()
    page = (data_dir / "report/cobot-6r-ik.md").read_text()
    assert "Compute time beside the peers" in page and "Measured in one run on" in page

    run = read_run(run_files(data_dir / "runs/cobot-6r-ik/trajectory")[0])
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/tracking_error/flange", "/tf",
            "/ik/samples"} <= set(run.topic_names)
    assert "model.xml" in run.attachments
    assert set(run["/joint_state"].filter(like="position.").columns) == {f"position.joint{i}" for i in range(1, 7)}
    assert run["/ik/samples"]["fk_error_position"].max() < 1e-9
    ct = read_run(run_files(data_dir / "runs/cobot-6r-ik/compute-time")[0])["/compute_time"]
    assert {"seconds.lambda16", "seconds.lambda16_batch", "seconds.octic", "seconds.octic_batch"} <= set(ct.columns)


def test_bad_input_is_refused_in_one_line(data_dir):
    for experiment, override in (("completeness", "scenario.poses=1e9"), ("trajectory", "scenario.cases=[spiral]"),
                                 ("tables", "scenario.q_deg=[90,0]")):          # a joint vector needs 6 angles
        proc = run_cli("pipeline", f"experiment=cobot-6r-ik/{experiment}", f"data_dir={data_dir}", override)
        lines = proc.stderr.strip().splitlines()
        assert proc.returncode == 2 and len(lines) == 1 and override.split("=")[0] in lines[0], proc.stderr
    assert not data_dir.exists()

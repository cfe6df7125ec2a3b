"""kinematic-graph end to end, shortened: simulate -> analyze -> report on a temporary data_dir, the statuses the
reproduction reaches, the runs' topics and the 3-D replay."""

from __future__ import annotations

import pandas as pd
import pytest

from pipeline.core.runlog import read_run

from .conftest import simulate_experiment

# fewer queries and a coarser spatial grid than the defaults; the run ids stay the defaults' so the targets find them
SHORT = {
    "table1": [],
    "search": ["search.pairs=6"],
    "spatial": ["search.pairs=3", "graph.c_res_deg=10"],
}


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    from analysis.core.stages import analyze, write_report

    data_dir = tmp_path_factory.mktemp("kinematic-graph") / "data"
    for name, overrides in SHORT.items():
        simulate_experiment(data_dir, f"kinematic-graph/{name}", overrides)
        assert analyze(f"kinematic-graph/{name}", data_dir) is not None
    write_report(data_dir)
    return data_dir


def test_report_statuses(data):
    targets = pd.read_csv(data / "report" / "targets.csv")
    targets = targets[targets["slug"] == "kinematic-graph"].set_index("target_id")
    status = targets["status"]
    table1 = status[status.index.str.match(r"T1\.C.*\.(vertices|edges|vertex_ratio)$")]
    assert len(table1) == 36 and (table1 == "match").all()
    assert (status[status.index.str.match(r"T1\.C0\.5_.*\.edge_ratio$")] == "miss").all()
    assert status["EC.C0.5"] == "miss" and targets.loc["EC.C0.5", "cause"] == "paper-inconsistent"
    assert status["EC.C1"] == "match" and status["b.dim6"] == "miss" and status["b.dim3"] == "match"
    assert status["eq7.C0.5"] == "disagrees" and status["eq7.C2"] == "agrees" and status["eq5.dim6"] == "disagrees"
    assert (status[status.index.str.endswith("printed_denominator")] == "agrees").all()
    assert status["Sec3.4.tonly"] == "match"            # Fig. 4: T-space information alone hits the obstacle
    assert status["Sec3.3.admissible"] == "miss"        # eq. (12) overestimates
    assert status["Sec3.2.search.2d"] == "match" and status["Sec3.2.search.3d"] == "match"
    live = targets[~targets["status"].isin(["not-reproducible", "not run"])]
    assert live["pipeline_value"].notna().all()
    page = (data / "report" / "kinematic-graph.md").read_text()
    assert "Table 1 recomputed" in page and "Search benchmark" in page and "Errata" in page
    for name in ("table1/table1-sizes", "search/fig2-free", "search/fig4-obstacle", "search/fig5-searched-kg",
                 "spatial/fig6-spatial", "search/execution-obstacle"):
        assert (data / "figures" / "kinematic-graph" / f"{name}.png").is_file(), name


def test_runs_carry_the_replay(data, tmp_path):
    from analysis.view import convert

    run = read_run(data / "runs" / "kinematic-graph" / "search" / "obstacle-manipulability.mcap")
    assert {"/joint_state", "/reference", "/command", "/tracking_error", "/tf", "/markers", "/clearance",
            "/kg/path", "/kg/vertices"} <= set(run.topic_names)
    assert "model.xml" in run.attachments and run.status == "ok"
    # the arm and the obstacle are drawn from the attached model: its URDF, moved by the logged joints
    assert {"/robot_description", "/joint_states", "/tf/robot"} <= set(run.topic_names)
    urdf = run.attachments["robot.urdf"].decode()
    assert urdf.count("<box ") == 1 and 'name="joint1"' in urdf and 'name="joint2"' in urdf
    bench = read_run(data / "runs" / "kinematic-graph" / "search" / "benchmark-obstacle.mcap")
    assert bench["/markers"].filter(like="cubes.0.size.x").iloc[0].tolist() == pytest.approx([0.1])
    assert run["/markers"].filter(like="cubes.0.size.x").iloc[0].tolist() == pytest.approx([0.1])  # and beside the arm
    assert list(run["/joint_state"].filter(like="position.").columns) == ["position.joint1", "position.joint2"]
    assert run["/clearance"]["value.executed.min"].min() > -0.01   # the KG plan passes the obstacle
    tonly = read_run(data / "runs" / "kinematic-graph" / "search" / "obstacle-tspace-only.mcap")
    assert tonly["/clearance"]["value.reference.min"].min() < 0    # the T-space-only plan does not
    spatial = read_run(data / "runs" / "kinematic-graph" / "spatial" / "tspace.mcap")
    assert spatial["/joint_state"].filter(like="position.").shape[1] == 6
    assert convert(spatial.path, tmp_path / "tspace.rrd").stat().st_size > 50_000

"""The dataset generator: runs exported as LeRobot v3.0 datasets (read back by Hugging Face `datasets`),
their values and units, the card, randomized episodes in one process, and bad input refused."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import yaml

from analysis.core import report
from pipeline.core import stages
from pipeline.core.checks import BadInput, preflight
from pipeline.core.runlog import RunWriter, read_run, read_runs, run_files

from .conftest import run_cli

datasets = pytest.importorskip("datasets")


def _load(root):
    frames = datasets.load_dataset("parquet", data_files=str(root / "data/*/*.parquet"), split="train")
    episodes = datasets.load_dataset("parquet", data_files=str(root / "meta/episodes/*/*.parquet"), split="train")
    return frames, episodes


def test_an_experiment_exports_to_a_lerobot_dataset_with_units_and_a_card(data_dir):
    proc = run_cli("pipeline", "experiment=ur5-ik-fsm/singular-paths", "scenario.paths=[wrist]",
                   "scenario.duration=0.5", f"data_dir={data_dir}", "progress=false")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("pipeline.dataset", "ur5-ik-fsm/singular-paths", "--data-dir", str(data_dir), "--fps", "100")
    assert proc.returncode == 0, proc.stderr
    journal = {e["stage"]: e for e in stages.read(data_dir)}   # both stages' times, for the benchmark
    assert set(journal) == {"simulate", "export"} and journal["export"]["experiment"] == "ur5-ik-fsm"
    assert journal["export"]["wall_s"] > 0 and journal["simulate"]["first_step_s"] > 0
    root = data_dir / "datasets/ur5-ik-fsm/singular-paths"
    info = json.loads((root / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0" and info["fps"] == 100 and info["total_episodes"] == 4
    assert info["data_path"] == "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
    state, action = info["features"]["observation.state"], info["features"]["action"]
    assert state["names"][:2] == ["joint1.pos", "joint2.pos"] and state["names"][6] == "joint1.vel"
    assert state["units"][0] == "rad" and state["units"][6] == "rad/s" and state["shape"] == [12]
    assert action["kind"] == "torque" and set(action["units"]) == {"N*m"}
    assert info["features"]["tracking_error.flange"]["units"] == ["m", "m", "m", "rad", "m"]
    assert all(len(f["units"]) == f["shape"][0] and all(f["units"]) for f in info["features"].values())

    frames, episodes = _load(root)
    assert frames.num_rows == info["total_frames"] == sum(episodes["length"])
    # the report's index lists it, with its card
    (listed,) = report.dataset_rows(data_dir, data_dir / "report")
    assert listed["name"] == "ur5-ik-fsm/singular-paths"
    assert listed["card"] == "../datasets/ur5-ik-fsm/singular-paths/README.md"
    assert (listed["episodes"], listed["frames"], listed["fps"]) == (4, info["total_frames"], 100)
    assert episodes["dataset_from_index"][1:] == episodes["dataset_to_index"][:-1]
    assert frames.features["observation.state"].length == 12
    table = frames.to_pandas()
    # each frame is the run's own sample at t0 + k/fps: 100 fps falls on every 5th sample of the 500 Hz log
    for k, run_id in enumerate(episodes["run_id"]):
        run = read_run(data_dir / f"runs/ur5-ik-fsm/singular-paths/{run_id}.mcap")
        ours = table[table["episode_index"] == k]
        js = run["/joint_state"]
        t = js.index.to_numpy()[0] + ours["frame_index"].to_numpy() / info["fps"]
        logged = js.loc[np.isin(np.round(js.index, 9), np.round(t, 9)), [c for c in js.columns
                                                                        if c.startswith("position.")]]
        assert len(logged) == len(ours)
        assert np.allclose(np.stack(ours["observation.state"])[:, :6], logged.to_numpy(), atol=1e-6)
        command = run["/command"].filter(like="value.").to_numpy()
        assert np.allclose(np.stack(ours["action"])[-1], command[-1], rtol=1e-6)   # held: the last command
    stats = json.loads((root / "meta/stats.json").read_text())
    assert np.allclose(stats["observation.state"]["mean"], np.stack(table["observation.state"]).mean(axis=0),
                       rtol=1e-5, atol=1e-7)
    assert set(stats["action"]) >= {"min", "max", "mean", "std", "count", "q01", "q50", "q99"}
    tasks = pd.read_parquet(root / "meta/tasks.parquet")
    assert list(tasks.index) == ["Our extension: flange paths through the wrist, shoulder and elbow singularities, "
                                 "executed in MuJoCo"]

    card = (root / "README.md").read_text()
    header = yaml.safe_load(card.split("---")[1])
    assert header["task_categories"] == ["robotics"] and "LeRobot" in header["tags"] and header["license"]
    assert header["configs"][0]["data_files"] == "data/*/*.parquet"
    assert "Singularity Analysis and Complete Methods" in card and "| `joint1.vel` | rad/s |" in card
    assert run.metadata["git_revision"] in card


def test_randomized_episodes_in_one_process(data_dir):
    args = ["experiment=ur5-ik-fsm/random-paths", "episodes.count=4", "scenario.duration=0.4",
            "execute.log_dt=0.004", f"data_dir={data_dir}", "progress=false"]
    proc = run_cli("pipeline", *args, "workers=2")
    assert proc.returncode == 0, proc.stderr
    runs = read_runs(data_dir / "runs/ur5-ik-fsm/random-paths")
    table = runs.table()
    assert len(runs) == 4 and list(table["episode"]) == [0, 1, 2, 3] and table["status"].eq("ok").all()
    gains = table["execute.bandwidth_hz"]
    assert gains.dtype.kind == "f" and gains.between(4, 16).all() and gains.nunique() == 4
    assert table["scenario.near_gap"].between(1e-5, 1e-3).all()
    meta = runs[0].metadata
    assert json.loads(meta["randomized"])["execute.bandwidth_hz"] == "uniform [4.0, 16.0]"
    assert runs[0].config["execute"]["bandwidth_hz"] == pytest.approx(gains[0])   # the episode's own config
    # the same episodes on one worker: the draws depend on (seed, episode) only, and the runs are identical
    again = data_dir.parent / "again"
    proc = run_cli("pipeline", *args[:-2], f"data_dir={again}", "progress=false", "workers=1")
    assert proc.returncode == 0, proc.stderr
    twin = read_runs(again / "runs/ur5-ik-fsm/random-paths")
    for a, b in zip(runs, twin, strict=True):
        assert a.params == b.params and a.metadata["case"] == b.metadata["case"]
        pd.testing.assert_frame_equal(a["/joint_state"], b["/joint_state"])
    # and they export as one dataset, each episode with what was drawn for it
    proc = run_cli("pipeline.dataset", "ur5-ik-fsm/random-paths", "--data-dir", str(data_dir))
    assert proc.returncode == 0, proc.stderr
    _, episodes = _load(data_dir / "datasets/ur5-ik-fsm/random-paths")
    assert episodes["parameters/execute.bandwidth_hz"] == pytest.approx(list(gains))
    assert "default + uniform" in (data_dir / "datasets/ur5-ik-fsm/random-paths/README.md").read_text()


@pytest.mark.parametrize(("args", "says"), [
    (["episodes.count=1000000"], "episodes.count=1e+06 is out of range"),
    (["episodes.count=100000", "scenario.duration=60"], "episodes would need about"),
    (["episodes.count=2", "scenario.algorithms=[alg1,alg2]", "~episodes.randomize.scenario.algorithms"],
     "would make 2 runs"),
    # every distinct draw of the choices is made, however late it first comes (here in episode 29 of 40)
    (["episodes.count=40", "seed=2", "~episodes.randomize.scenario.algorithms",
      "+episodes.randomize.scenario.algorithms={choice:[" + "[alg2]," * 10 + "[alg1,alg2]]}"],
     "episode 29 would make 2 runs"),
    (["episodes.count=2", "~episodes.randomize.execute.bandwidth_hz",
      "+episodes.randomize.execute.bandwidth_hz={normal:[8,2]}"], "a normal needs clip"),
    (["episodes.count=2", "episodes.randomize.execute.bandwidth_hz={normal:[8,2]}"], "to replace a distribution"),
    (["episodes.count=2", "~episodes.randomize.scenario.paths", "+episodes.randomize.scenario.paths={choice:[[knee]]}"],
     "scenario.paths='knee' is not allowed"),
    (["episodes.count=2", "episodes.randomize.execute.bandwidth_hz.uniform=[4,400]"],
     "is out of range: must be > 0 and <= 100"),
    (["episodes.count=2", "+episodes.randomize.execute.bandwith_hz={uniform:[4,8]}"],
     "did you mean 'execute.bandwidth_hz'"),
    (["episodes.count=2", "+episodes.randomize.execute.log_dt={uniform:[0.001]}"], "must be [a, b]"),
])
def test_bad_episodes_are_refused_before_anything_runs(args, says):
    with pytest.raises(BadInput, match=says.replace("(", r"\(").replace("+", r"\+").replace("[", r"\[")):
        preflight(["experiment=ur5-ik-fsm/random-paths", *args])


def test_bad_exports_are_refused_in_one_line(data_dir):
    proc = run_cli("pipeline.dataset", "ur5-ik-fsm/singular-pahts", "--data-dir", str(data_dir))
    assert proc.returncode == 2 and "did you mean 'ur5-ik-fsm/singular-paths'" in proc.stderr
    proc = run_cli("pipeline.dataset", "ur5-ik-fsm/singular-paths", "--data-dir", str(data_dir))
    assert proc.returncode == 2 and "python -m pipeline experiment=ur5-ik-fsm/singular-paths" in proc.stderr
    assert run_cli("pipeline", "experiment=ur5-ik-fsm/tables", f"data_dir={data_dir}", "progress=false").returncode == 0
    proc = run_cli("pipeline.dataset", "ur5-ik-fsm/tables", "--data-dir", str(data_dir))
    assert proc.returncode == 2 and "has a trajectory" in proc.stderr and len(proc.stderr.splitlines()) == 1
    assert not (data_dir / "datasets").exists()


def _two_robots(tmp_path):
    """Runs of a one-link and a two-link chain, exported: one dataset per shape."""
    from pipeline.dataset import Source, export

    runs = tmp_path / "runs"
    for n in (1, 1, 2):
        index = len(run_files(runs)) if runs.exists() else 0
        with RunWriter(runs / f"r{index}.mcap", {"run_id": f"r{index}", "slug": "demo", "experiment": "e",
                                                  "case": f"n{n}", "values": {"links": n}}) as w:
            t = np.arange(11) * 0.1
            names = [f"q{i}" for i in range(n)]
            w.log_series("/joint_state", t, units="rad", name=names, position=np.tile(t[:, None], (1, n)),
                         velocity=np.ones((11, n)))
            w.log_series("/command", t, units="rad", kind="torque", name=names, value=np.zeros((11, n)))
            w.close("ok")
    written = export([Source(runs)], tmp_path / "out", fps=10)
    assert sorted(p.name for p in written) == ["state2-action1", "state4-action2"]
    return written


def test_runs_of_different_robots_make_one_dataset_each(tmp_path):
    """A sweep over chain lengths cannot share one LeRobot feature shape: one dataset per shape."""
    _two_robots(tmp_path)
    frames, episodes = _load(tmp_path / "out/state2-action1")
    assert episodes["run_id"] == ["r0", "r1"] and frames.num_rows == 22
    assert np.allclose(frames["observation.state"][10], [1.0, 1.0])   # q0 = t, its velocity 1 at t = 1 s


def test_the_official_lerobot_class_loads_the_export(tmp_path):
    """Runs where `lerobot` is installed (it pins torch and an older rerun-sdk: `make lerobot-check` builds
    its own virtual environment)."""
    lerobot = pytest.importorskip("lerobot.datasets.lerobot_dataset")
    _two_robots(tmp_path)
    root = tmp_path / "out/state2-action1"
    dataset = lerobot.LeRobotDataset("local/demo", root=root)
    info = json.loads((root / "meta/info.json").read_text())
    assert len(dataset) == info["total_frames"] == 22 and dataset.num_episodes == 2 and dataset.fps == 10
    frame = dataset[12]   # the second episode's second frame
    assert int(frame["episode_index"]) == 1 and int(frame["frame_index"]) == 1
    assert np.allclose(frame["observation.state"].numpy(), [0.1, 1.0], atol=1e-6)


def test_every_export_stage_exports_an_experiment_of_the_pipeline():
    from analysis.core.report import simulate_args, stage_vars

    exports = {slug: v["datasets"] for slug, v in stage_vars().items() if v["datasets"]}
    assert exports
    for slug, datasets in exports.items():   # at most one export stage per paper, of its own experiments
        assert list(datasets) == ["lerobot"]
        assert all(e in simulate_args() and e.startswith(f"{slug}/") for e in datasets["lerobot"].split())

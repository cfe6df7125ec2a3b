"""The two stage CLIs as a user meets them: bad input refused in one line with nothing written, sweeps on
the local launcher, the Ray launcher config, divergence recorded as a failed run, determinism."""

from __future__ import annotations

import pytest

from pipeline.core.runlog import read_run, run_files

from .conftest import run_cli

SHORT_PATH = ["scenario.paths=[wrist]", "scenario.crossings=[near]", "scenario.duration=0.4"]


@pytest.mark.parametrize(("args", "names"), [
    (["experiment=ur5-ik-fsm/tabels"], "unknown experiment 'ur5-ik-fsm/tabels'"),
    (["experiment=ur5-ik-fsm/tables", "scenario.tabel2=1"], "unknown config key 'scenario.tabel2'"),
    (["experiment=ur5-ik-fsm/singular-paths", "execute.dt=0"], "execute.dt=0 is out of range: must be >= 0.0001"),
    (["experiment=ur5-ik-fsm/singular-paths", "execute.dt=-0.001"], "execute.dt=-0.001 is out of range"),
    (["experiment=ur5-ik-fsm/tables", "system.geometry.a2=nan"], "system.geometry.a2=nan is not a finite number"),
    (["experiment=ur5-ik-fsm/tables", "system.geometry.d4=x"], "system.geometry.d4='x' must be a number"),
    (["experiment=ur5-ik-fsm/tables", "+scenario.extra=1"], "adding keys is not allowed"),
    (["-m", "experiment=ur5-ik-fsm/singular-paths", "execute.dt=0.001,0"], "execute.dt=0 is out of range"),
    ([], "choose an experiment"),
])
def test_bad_input_is_refused_in_one_line(data_dir, args, names):
    proc = run_cli("pipeline", *args, f"data_dir={data_dir}")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and names in lines[0]
    assert not data_dir.exists()


@pytest.mark.parametrize(("args", "names"), [
    (["experimnt=ur5-ik-fsm/tables"], "unknown key 'experimnt'"),
    (["experiment=nope/x"], "unknown experiment 'nope/x'"),
    (["stage=draw"], "stage=draw must be one of"),
])
def test_analysis_bad_input(data_dir, args, names):
    proc = run_cli("analysis", *args, f"data_dir={data_dir}")
    assert proc.returncode == 2 and names in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert not data_dir.exists()


@pytest.mark.parametrize("module", ["pipeline", "analysis"])
def test_help_lists_every_experiment(module, data_dir):
    from pipeline.core.experiment import experiment_descriptions

    proc = run_cli(module, "--help")
    assert proc.returncode == 0, proc.stderr
    for name, text in experiment_descriptions().items():
        assert name in proc.stdout and text in proc.stdout
    assert not data_dir.exists()


@pytest.mark.parametrize(("module", "args", "shown"), [
    ("pipeline", ["experiment=ur5-ik-fsm/tables", "--cfg", "job"], "table2:"),
    ("pipeline", ["--cfg", "job", "-p", "system.geometry", "experiment=ur5-ik-fsm/tables"], "a2: 0.425"),
    ("analysis", ["stage=report", "--cfg", "job"], "stage: report"),
    ("analysis", ["--cfg", "job", "-p", "stage"], "all"),
])
def test_hydra_flags_take_their_value_after_a_space(module, args, shown, data_dir):
    proc = run_cli(module, *args, f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr
    assert shown in proc.stdout
    assert not data_dir.exists()   # printing the config runs nothing


def test_sweep_runs_one_file_per_point_in_parallel(data_dir):
    proc = run_cli("pipeline", "-m", "experiment=ur5-ik-fsm/singular-paths", *SHORT_PATH,
                   "scenario.algorithms=[alg2]", "execute.bandwidth_hz=6,10", f"data_dir={data_dir}")
    assert proc.returncode == 0, proc.stderr
    assert "LokyBackend with 2 concurrent workers" in proc.stderr  # joblib: parallel processes
    (sweep,) = (data_dir / "sweeps").iterdir()                       # its own folder, named by its start time
    assert not (data_dir / "runs").exists()
    runs = [read_run(p) for p in run_files(sweep / "runs/ur5-ik-fsm/singular-paths")]
    assert sorted(r.params["execute.bandwidth_hz"] for r in runs) == [6, 10]
    assert all(r.ok for r in runs) and len({r.run_id for r in runs}) == 2


def test_a_sweep_on_two_local_ray_workers(data_dir):
    pytest.importorskip("hydra_plugins.hydra_ray_launcher", reason="the [ray] extra is not installed")
    proc = run_cli("pipeline", "-m", "experiment=ur5-ik-fsm/singular-paths", *SHORT_PATH, "scenario.algorithms=[alg2]",
                   "execute.bandwidth_hz=6,10", "hydra/launcher=ray", "+hydra.launcher.ray.init.num_cpus=2",
                   f"data_dir={data_dir}", f"sweep_dir={data_dir}/sweeps/ray", timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "is validated against ConfigStore schema" not in proc.stderr  # no deprecation noise from our config
    runs = [read_run(p) for p in run_files(data_dir / "sweeps/ray/runs/ur5-ik-fsm/singular-paths")]
    assert sorted(r.params["execute.bandwidth_hz"] for r in runs) == [6, 10] and all(r.ok for r in runs)


def test_divergence_is_a_failed_run_and_the_stage_goes_on(data_dir):
    # a 20 ms step under a 200 Hz servo with no torque limit blows up
    proc = run_cli("pipeline", "experiment=ur5-ik-fsm/singular-paths", *SHORT_PATH, "execute.dt=0.02",
                   "scenario.ik_dt=0.02", "execute.log_dt=0.02", "execute.bandwidth_hz=100",
                   "system.dynamics.torque_limit=[1e9,1e9,1e9,1e9,1e9,1e9]",
                   f"data_dir={data_dir}")
    assert proc.returncode == 0
    runs = [read_run(p) for p in run_files(data_dir / "runs/ur5-ik-fsm/singular-paths")]
    assert len(runs) == 2
    assert all(r.status.startswith("failed: MuJoCo BADQACC") for r in runs)


def test_same_config_twice_gives_identical_messages(tmp_path):
    frames = []
    for k in range(2):
        d = tmp_path / f"d{k}"
        proc = run_cli("pipeline", "experiment=ur5-ik-fsm/singular-paths", *SHORT_PATH, f"data_dir={d}")
        assert proc.returncode == 0, proc.stderr
        frames.append([read_run(p).topics for p in run_files(d / "runs/ur5-ik-fsm/singular-paths")])
    for a, b in zip(*frames, strict=True):
        assert a.keys() == b.keys()
        for topic in a:
            assert a[topic].equals(b[topic]), topic


def test_choice_parameters_are_checked():
    from omegaconf import OmegaConf

    from pipeline.core.checks import BadInput, check_config
    from pipeline.core.experiment import Length, OneOf

    defaults = OmegaConf.create({"mode": "x", "joints": ["p", "q"]})
    limits = {"mode": OneOf(("x", "y")), "joints": (Length(1, 2), OneOf(("p", "q")))}
    check_config(OmegaConf.create({"mode": "y", "joints": ["q"]}), defaults, limits)
    with pytest.raises(BadInput, match=r"mode='z' is not allowed: must be one of x, y"):
        check_config(OmegaConf.create({"mode": "z", "joints": ["p"]}), defaults, limits)
    with pytest.raises(BadInput, match=r"joints\[1\]='r' is not allowed"):
        check_config(OmegaConf.create({"mode": "x", "joints": ["p", "r"]}), defaults, limits)

"""Nothing lost, nothing half-done: bad input refused up front, concurrent writers, interrupts, orphans,
divergence, damaged run files, atomic outputs. One test (or one parametrized row) per defect found."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf

from pipeline.core import files
from pipeline.core.checks import (
    BadInput,
    _leaves,
    check_config,
    check_rules,
    compose_config,
    compose_with_defaults,
    declared,
    preflight,
)
from pipeline.core.experiment import OneOf, Text, available_experiments, resolve
from pipeline.core.runlog import RunWriter, SimulationFailed, read_run, run_files

from .conftest import ENV, ROOT, run_cli

UR5_SHORT = ["scenario.paths=[wrist]", "scenario.crossings=[near]", "scenario.duration=0.4"]

# -- bad input: every kind the issue lists (and the earlier ones), refused before anything runs ------------

BAD_INPUT = [
    # unknown or misspelled names, wrong types, non-finite values, added keys
    (["experiment=ur5-ik-fsm/tabels"], "unknown experiment 'ur5-ik-fsm/tabels' (did you mean"),
    (["experiment=ur5-ik-fsm/singular-paths", "execute.dtt=0"], "unknown config key 'execute.dtt'"),
    (["experiment=ur5-ik-fsm/tables", "system.geometry.a2=nan"], "not a finite number"),
    (["experiment=ur5-ik-fsm/tables", "system.geometry.d4=x"], "must be a number"),
    (["experiment=ur5-ik-fsm/tables", "+scenario.extra=1"], "adding keys is not allowed"),
    # out of range, zero and negative steps
    (["experiment=ur5-ik-fsm/singular-paths", "execute.dt=0"], "execute.dt=0 is out of range"),
    (["experiment=ur5-ik-fsm/singular-paths", "execute.dt=-0.001"], "out of range"),
    # paths escaping data_dir through case names
    (["experiment=ur5-ik-fsm/tables", "scenario.cases=[../../../../../escape/evil]"], "is not allowed"),
    # divergence settings that used to be stored as ok
    (["experiment=partial-lagrangian/one-link", "system.simulation.dt=2.0", "system.simulation.integrator=rk4"],
     "system.simulation.dt=2 is out of range"),
    (["experiment=curve-discretization/snake-gait", "control.physics_dt=0.05"], "control.physics_dt"),
    # upper bounds: sizes, counts, durations, rates
    (["experiment=curve-discretization/snake-gait", "scenario.joints=10000000"], "scenario.joints=1e+07 is out"),
    (["experiment=ur5-ik-fsm/singular-paths", "scenario.duration=1e9"], "scenario.duration=1e+09 is out of range"),
    (["experiment=ur5-ik-fsm/singular-paths", "scenario.duration=1e7"], "out of range"),
    (["experiment=ur5-ik-fsm/singular-paths", "scenario.ik_dt=1e-9"], "scenario.ik_dt=1e-09 is out of range"),
    (["experiment=gripper-force-control/steady-state", "scenario.grasps=1000000000"], "scenario.grasps=1e+09"),
    (["experiment=ur5-ik-fsm/compute-time", "scenario.poses=1000000000"], "scenario.poses=1e+09 is out of range"),
    (["experiment=ur5-ik-fsm/singular-paths", "scenario.duration=60", "execute.dt=0.0001", "scenario.ik_dt=0.0001",
      "execute.log_dt=0.0001"], "more than the budget"),
    # choices and shapes
    (["experiment=scara-half-derivative/table2", "execute.plant=foo"], "execute.plant='foo' is not allowed"),
    (["experiment=ur5-ik-fsm/singular-paths", "execute.dt=[0.001,0.002]"], "must be a single value"),
    (["experiment=ur5-ik-fsm/singular-paths", "scenario.paths=wrist"], "must be a list, e.g. scenario.paths=[wrist]"),
    (["experiment=ur5-ik-fsm/tables", "system.fk_form=bogus"], "system.fk_form='bogus' is not allowed"),
    (["experiment=partial-lagrangian/two-link", "scenario.initial=[0.0]"], "scenario.initial has 1 elements"),
    # settings inconsistent with each other
    (["experiment=scara-half-derivative/table2", "execute.dt=0.05"], "must divide the control period"),
    (["experiment=spherical-terrain/physics-check", "system.physics.timestep=0.2"], "out of range"),
    (["experiment=spherical-terrain/physics-check", "system.physics.timestep=0.003"], "must divide"),
    # meaningless values
    (["experiment=curve-discretization/timing-fig3", "scenario.angle_batch=0"], "scenario.angle_batch=0 is out"),
    (["experiment=ur5-ik-fsm/singular-paths", "execute.log_dt=100"], "execute.log_dt=100 is out of range"),
    (["experiment=src-joint/joint-model", "scenario.log_dt=5"], "fewer than 10 samples"),
    (["experiment=ur5-ik-fsm/tables", "scenario.cases=[]"], "scenario.cases has 0 elements"),
    (["experiment=ur5-ik-fsm/tables", "scenario.cases=[independent,independent]"], "names two runs"),
    # sweeps: every swept value is checked, and the size of the grid
    (["-m", "experiment=ur5-ik-fsm/singular-paths", "execute.dt=0.001,0"], "execute.dt=0 is out of range"),
    (["-m", "experiment=ur5-ik-fsm/tables", "seed=range(0,200)", "system.geometry.d1=range(1,100)"],
     "more than 10000"),
    # data_dir
    (["experiment=ur5-ik-fsm/tables", "data_dir="], "data_dir is empty"),
    (["experiment=ur5-ik-fsm/tables", "data_dir=/proc/x"], "cannot be written"),
    (["experiment=ur5-ik-fsm/tables", f"data_dir={ROOT / 'README.md'}"], "is a file, not a directory"),
    ([], "choose an experiment"),
]


@pytest.mark.parametrize(("args", "says"), BAD_INPUT, ids=[" ".join(a)[:60] for a, _ in BAD_INPUT])
def test_bad_input_is_refused_before_anything_runs(args, says):
    with pytest.raises(BadInput) as refused:
        preflight(args)
    message = str(refused.value)
    assert says in message and "\n" not in message and len(message) < 300, message


@pytest.mark.parametrize(("args", "says"), [
    (["experiment=ur5-ik-fsm/singular-paths", "scenario.paths=wrist"], "must be a list"),
    (["experiment=curve-discretization/snake-gait", "scenario.joints=10000000"], "out of range"),
    (["experiment=ur5-ik-fsm/tables", "scenario.cases=[../../../../../escape/evil]"], "is not allowed"),
])
def test_the_cli_refuses_in_one_line_and_writes_nothing(tmp_path, args, says):
    data_dir = tmp_path / "data"
    proc = run_cli("pipeline", *args, f"data_dir={data_dir}")
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and says in lines[0] and "Traceback" not in proc.stderr
    assert not data_dir.exists() and not (tmp_path / "escape").exists()


SIZE = re.compile(r"(^|_)(duration|joints|samples|poses|grasps|repeats|moves|trials|count|steps|links|horizon|"
                  r"states|batch|iterations|restarts|grid|warmup|t1|settle|iter)($|_)")
STEP = re.compile(r"(^|_)(dt|timestep|step)($|_)")


@pytest.mark.parametrize("experiment_id", available_experiments())
def test_every_size_step_and_choice_is_declared(experiment_id):
    """Each size, count or duration 10^4 times its default, and each time step 10^-4 times it, is refused by
    what the experiment declares (a range, a rule or its budget), and every string is a choice or free text."""
    experiment = resolve(experiment_id)
    defaults = compose_config([f"experiment={experiment_id}"])
    unguarded = []
    for key, value in _leaves(defaults):
        if key.startswith("hydra") or key in ("data_dir", "sweep_dir", "seed", "progress", "description"):
            continue
        last = re.sub(r"\[\d+\]", "", key).rsplit(".", 1)[-1]
        if isinstance(value, str):
            if not any(isinstance(x, OneOf | Text) for x in declared(experiment.limits, key)):
                unguarded.append(f"{key}={value!r} (no OneOf or Text)")
            continue
        if isinstance(value, bool) or not isinstance(value, int | float):
            continue
        probe = value * 1e4 if SIZE.search(last) else value * 1e-4 if STEP.search(last) else None
        if probe is None:
            continue
        cfg = defaults.copy()
        OmegaConf.update(cfg, key, type(value)(probe) if value else 10**6, merge=False)
        try:
            check_config(cfg, defaults, experiment.limits)
            check_rules(cfg, experiment)
        except BadInput:
            continue
        unguarded.append(f"{key}={probe:g} accepted")
    assert not unguarded, f"{experiment_id}: {unguarded}"


def test_every_default_config_passes_its_own_checks():
    for experiment_id in available_experiments():
        preflight([f"experiment={experiment_id}"])


def test_one_composition_gives_the_config_and_the_defaults_it_is_checked_against():
    """preflight composes once: the config just before Hydra applies the overrides' values is what composing
    the experiment alone gives; an override that chooses a config group gets no such defaults."""
    for experiment_id in {e.split("/")[0]: e for e in available_experiments()}.values():  # one per paper
        composed, defaults = compose_with_defaults(["progress=false", f"experiment={experiment_id}", "seed=3"])
        assert OmegaConf.to_yaml(defaults) == OmegaConf.to_yaml(compose_config([f"experiment={experiment_id}"]))
        assert composed.seed == 3 and composed.progress is False and "hydra" in composed
    composed, defaults = compose_with_defaults(["experiment=ur5-ik-fsm/tables", "system=cobot-6r-ik"])
    assert defaults is None and composed.hydra.runtime.choices.system == "cobot-6r-ik"


# -- concurrent writers ------------------------------------------------------------------------------------


def test_a_run_another_process_is_writing_is_refused(tmp_path):
    data_dir = tmp_path / "data"
    with files.Locks(data_dir, ["ur5-ik-fsm/tables/sequential"]):
        proc = run_cli("pipeline", "experiment=ur5-ik-fsm/tables", f"data_dir={data_dir}")
    assert proc.returncode == 2 and "another process is writing run ur5-ik-fsm/tables/sequential" in proc.stderr
    assert run_files(data_dir / "runs/ur5-ik-fsm/tables") == []


def test_two_processes_into_one_data_dir_leave_only_complete_runs(tmp_path):
    data_dir = tmp_path / "data"
    cmd = [sys.executable, "-m", "pipeline", "experiment=ur5-ik-fsm/singular-paths", *UR5_SHORT,
           f"data_dir={data_dir}", "progress=false"]
    procs = [subprocess.Popen(cmd, cwd=ROOT, env=ENV, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    codes = [p.wait(timeout=300) for p in procs]
    assert sorted(codes) in ([0, 0], [0, 2])  # the second one either ran after or refused, never half
    paths = run_files(data_dir / "runs/ur5-ik-fsm/singular-paths")
    assert len(paths) == 2 and all(read_run(p).verify().ok for p in paths)
    assert not list((data_dir / "runs").rglob("*.partial"))


def test_runs_in_parallel_processes_equal_runs_in_one(tmp_path):
    """An experiment's cases run one per core: the files hold the same records as when run one by one."""
    frames = {}
    for workers in (1, 2):
        data_dir = tmp_path / f"w{workers}"
        proc = run_cli("pipeline", "experiment=ur5-ik-fsm/singular-paths", "scenario.paths=[wrist,shoulder]",
                       "scenario.crossings=[near]", "scenario.duration=0.4", f"data_dir={data_dir}",
                       f"workers={workers}", "progress=false")
        assert proc.returncode == 0, proc.stderr
        runs = [read_run(p) for p in run_files(data_dir / "runs/ur5-ik-fsm/singular-paths")]
        assert len(runs) == 4 and all(r.ok for r in runs)  # two paths, two algorithms
        assert {r.metadata["parallel_runs"] for r in runs} == {str(workers)}
        frames[workers] = {r.run_id: r["/joint_state"] for r in runs}
    assert frames[1].keys() == frames[2].keys()
    for rid, frame in frames[1].items():
        assert frame.equals(frames[2][rid]), rid


def test_a_timed_experiment_runs_its_cases_alone(tmp_path):
    """Its runs one after another, also as a sweep (whose local launcher would otherwise run one job per core)."""
    proc = run_cli("pipeline", "-m", "experiment=curve-discretization/timing-fig3", "scenario.joint_counts.last=6",
                   "scenario.repeats=2", "scenario.warmup=1", "seed=0,1", f"data_dir={tmp_path}",
                   f"sweep_dir={tmp_path}",
                   "progress=false")
    assert proc.returncode == 0, proc.stderr
    assert "n_jobs=1" in proc.stdout + proc.stderr
    paths = run_files(tmp_path / "runs/curve-discretization/timing-fig3")
    assert len(paths) == 4 and {read_run(p).metadata["parallel_runs"] for p in paths} == {"1"}


def test_temporary_names_are_unique_and_publishing_is_all_or_nothing(tmp_path):
    out = tmp_path / "x.txt"
    assert len({files.temporary_name(out) for _ in range(50)}) == 50
    files.write_text(out, "old")
    with pytest.raises(RuntimeError), files.atomic_path(out) as tmp:
        tmp.write_text("half")
        raise RuntimeError("writer died")
    assert out.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.endswith(files.PARTIAL_SUFFIX)) == ["x.txt"]


# -- interrupts --------------------------------------------------------------------------------------------


def test_an_interrupt_swallowed_by_a_simulator_is_still_an_interrupt(tmp_path):
    """Exudyn turns the KeyboardInterrupt raised in its callback into its own error: the run must not be
    recorded as failed, the previous run file must stay, and the stage must exit 130."""
    (tmp_path / "x.mcap").write_bytes(b"previous complete run")
    code = textwrap.dedent(f"""
        import os, signal, sys
        from pathlib import Path
        from pipeline.core import interrupts
        from pipeline.core.experiment import Case
        from pipeline.core.runner import _run_case
        from pipeline.core.runlog import SimulationFailed

        def swallowing(log):
            log.log("/joint_state", 0.0, units="rad", name=["a"], position=[0.0])
            try:
                os.kill(os.getpid(), signal.SIGINT)
            except KeyboardInterrupt:
                raise SimulationFailed("Exudyn failed at t = 0 s: user interrupt") from None

        interrupts.install()
        try:
            _run_case(Case("x", swallowing), "x", Path({str(tmp_path)!r}), "", {{"run_id": "x"}})
        except KeyboardInterrupt as err:
            sys.exit(interrupts.exit_code(err))
    """)
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=ENV, capture_output=True, timeout=120)
    assert proc.returncode == 130, proc.stderr
    assert (tmp_path / "x.mcap").read_bytes() == b"previous complete run"
    assert [p.name for p in tmp_path.iterdir()] == ["x.mcap"]


def test_ctrl_c_during_an_exudyn_run_stops_the_stage(tmp_path):
    data_dir = tmp_path / "data"
    out = data_dir / "runs/scara-half-derivative/table2"
    proc = subprocess.Popen([sys.executable, "-m", "pipeline", "experiment=scara-half-derivative/table2",
                             "scenario.k_xyz=[80000]", "scenario.duration=6", f"data_dir={data_dir}", "progress=false"],
                            cwd=ROOT, env=ENV, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not run_files(out) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    time.sleep(0.3)  # inside the next case's Exudyn integration
    proc.send_signal(signal.SIGINT)
    stderr = proc.communicate(timeout=120)[1]
    assert proc.returncode == 130, stderr
    runs = [read_run(p) for p in run_files(out)]
    assert 1 <= len(runs) < 3 and all(r.ok for r in runs), [r.status for r in runs]
    assert not list(out.glob(f"*{files.PARTIAL_SUFFIX}"))  # the runs its workers had open are dropped
    assert "interrupted" in stderr


def test_killing_a_sweep_leaves_no_orphan(tmp_path):
    data_dir = tmp_path / "data"
    proc = subprocess.Popen([sys.executable, "-m", "pipeline", "-m", "experiment=ur5-ik-fsm/singular-paths",
                             "execute.bandwidth_hz=4,6,8,10", f"data_dir={data_dir}", f"sweep_dir={data_dir}",
                             "progress=false"],
                            cwd=ROOT, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    out = data_dir / "runs/ur5-ik-fsm/singular-paths"
    while not run_files(out) and time.monotonic() < deadline:
        time.sleep(0.1)
    workers = [pid for pid in _children(proc.pid)]
    assert workers, "the sweep started no worker process"
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 15
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(pid) for pid in workers)
    assert len(run_files(out)) < 48  # the sweep did not go on to finish without its parent


def _children(pid: int) -> list[int]:
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


# -- divergence --------------------------------------------------------------------------------------------


def test_a_non_finite_state_fails_the_run_at_its_time(tmp_path):
    with RunWriter(tmp_path / "x.mcap", {}) as w:
        q = np.zeros((5, 2))
        q[3, 1] = np.nan
        with pytest.raises(SimulationFailed, match=r"non-finite /joint_state position at t = 0.3 s"):
            w.log_series("/joint_state", np.arange(5) * 0.1, units="rad", name=["a", "b"], position=q)
        with pytest.raises(SimulationFailed, match="non-finite /wrench"):
            w.log("/wrench/contact", 1.0, frame_id="world", name=["c"], force_x=[np.inf])


def test_a_run_that_simulates_nothing_is_failed(tmp_path):
    code = textwrap.dedent(f"""
        from pathlib import Path
        from pipeline.core.experiment import Case
        from pipeline.core.runner import _run_case
        print(_run_case(Case("x", lambda log: None), "x", Path({str(tmp_path)!r}), "", {{"run_id": "x"}})[0])
    """)
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=ENV, capture_output=True, text=True)
    assert proc.stdout.strip() == "failed: nothing was simulated (no message was logged)", proc.stderr
    assert read_run(tmp_path / "x.mcap").status.startswith("failed: nothing was simulated")


# -- analysis: damaged files, missing data_dir, atomic outputs ---------------------------------------------


@pytest.fixture(scope="module")
def analysed(tmp_path_factory):
    """A data_dir with good runs, five damaged files and another experiment's run, analysed once."""
    data_dir = tmp_path_factory.mktemp("bad-files") / "data"
    for args in (["experiment=ur5-ik-fsm/singular-paths", *UR5_SHORT], ["experiment=ur5-ik-fsm/tables"]):
        assert run_cli("pipeline", *args, f"data_dir={data_dir}", "progress=false").returncode == 0
    paths = data_dir / "runs/ur5-ik-fsm/singular-paths"
    good = run_files(paths)[0].read_bytes()
    (paths / "truncated.mcap").write_bytes(good[: len(good) // 2])
    flipped = bytearray(good)
    flipped[len(good) // 3] ^= 0xFF
    (paths / "flipped.mcap").write_bytes(bytes(flipped))
    (paths / "empty.mcap").write_bytes(b"")
    (paths / "text.mcap").write_text("not a run\n")
    (paths / "foreign.mcap").write_bytes(run_files(data_dir / "runs/ur5-ik-fsm/tables")[0].read_bytes())
    (data_dir / "runs/ur5-ik-fsm/tables/garbage.mcap").write_text("x")
    proc = run_cli("analysis", f"data_dir={data_dir}")
    return data_dir, proc


def test_damaged_run_files_are_listed_and_the_rest_analysed(analysed):
    import pandas as pd

    data_dir, proc = analysed
    assert proc.returncode == 0, proc.stderr
    runs = pd.read_csv(data_dir / "metrics/ur5-ik-fsm/singular-paths.runs.csv").set_index("run_id")["status"]
    for name in ("truncated", "flipped", "empty", "text"):
        assert runs[name].startswith("unreadable: "), runs[name]
    assert runs["foreign"] == "foreign: a run of ur5-ik-fsm/tables"
    assert (runs == "ok").sum() == 2
    assert (data_dir / "metrics/ur5-ik-fsm/tables.parquet").is_file()  # the next experiment was analysed too
    assert (data_dir / "report/index.html").is_file()


def test_outputs_leave_no_temporary_files(analysed):
    data_dir, _ = analysed
    assert not [p for p in data_dir.rglob(f"*{files.PARTIAL_SUFFIX}")]


@pytest.mark.parametrize(("args", "code", "says"), [
    (["data_dir=/nonexistent/data"], 2, "does not exist"),
    (["data_dir="], 2, "data_dir is empty"),
    (["data_dir=/proc/x"], 2, "cannot be written"),
    ([f"data_dir={ROOT / 'README.md'}"], 2, "is a file, not a directory"),
    (["experiment=nope/x"], 2, "unknown experiment 'nope/x'"),
])
def test_analysis_refuses_a_bad_data_dir_in_one_line(args, code, says):
    proc = run_cli("analysis", *args)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == code and len(lines) == 1 and says in lines[0], proc.stderr


def test_analysis_of_an_empty_data_dir_says_what_to_do_and_writes_nothing(tmp_path):
    proc = run_cli("analysis", f"data_dir={tmp_path}")
    assert proc.returncode == 1 and "no runs under" in proc.stderr and "python -m pipeline" in proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_documented_viewer_commands_keep_analytics_off():
    readme = (ROOT / "README.md").read_text()
    for line in readme.splitlines():
        if re.search(r"`rerun \S+\.mcap", line):
            pytest.fail(f"a documented rerun command without CI=1: {line.strip()}")
    assert 'os.environ.setdefault("CI", "1")' in (ROOT / "analysis/view.py").read_text()

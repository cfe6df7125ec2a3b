"""Speed of `ur5-ik-fsm`: the MuJoCo execution against bare stepping, IK per call (with the compiled
`ur-analytic-ik` as a peer when the [bench] extra is installed), and the dataset generator (1,000 randomized
episodes simulated, logged and exported; goal ≤ 2 minutes on 2 cores)."""

from __future__ import annotations

import itertools
import tempfile
import time
from math import pi
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import MODEL_ATTACHMENT, RunWriter, read_run, run_files
from pipeline.core.timing import best_of, time_calls, time_interleaved
from pipeline.papers.ur5_ik_fsm import experiments as ex
from pipeline.papers.ur5_ik_fsm import ik
from pipeline.robotics import dh as dhk
from pipeline.robotics.mjcf import _SERVOS, compiled, servo_rollout
from pipeline.robotics.urdf import describe


def execution(rows: list[dict]) -> None:
    import mujoco

    cfg = compose_config(["experiment=ur5-ik-fsm/singular-paths"])
    g = ex.geometry(cfg)
    ik_times, poses, q_ik, _ = ex.solve_path(cfg, "wrist", "near", "alg2")
    times, q_ref, qd_ref = ex.servo_references(q_ik, ik_times, cfg.execute.dt, True, cfg.system.dynamics.velocity_limit)
    xml = ex.arm_model(cfg, g, q_ref[0])
    steps, sim_seconds = len(times), float(times[-1])

    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def bare() -> None:
        mujoco.mj_resetData(model, data)
        data.qpos[:] = q_ref[0]
        step = mujoco.mj_step
        for _ in range(steps):
            step(model, data)

    def servo() -> None:  # a run's control, as in a stage: gains tuned at its start, set on the servo model
        servo_rollout(ex.arm_model(cfg, g, q_ref[0]), q_ref, qd_ref, times)

    def servo_model() -> None:  # what a stage's first run adds: the zero-gain model and its two gain probes
        _SERVOS.clear()
        ex.arm_model(cfg, g, q_ref[0])

    states, sensors = servo_rollout(xml, q_ref, qd_ref, times)
    system = "MuJoCo UR5, wrist path (4 s, 1 kHz)"
    rows += [{"what": system, "measure": "servo model (three compiles), once per stage",
              "value": best_of(servo_model, 5) * 1e3, "unit": "ms"},
             {"what": system, "measure": "robot description (URDF), once per process",
              "value": best_of(lambda: describe(compiled(xml)), 5) * 1e3, "unit": "ms"}]
    with tempfile.TemporaryDirectory() as tmp:
        files = (Path(tmp) / f"{k}.mcap" for k in itertools.count())
        path = next(files)
        for log_dt, label in ((cfg.execute.log_dt, "default"), (cfg.execute.dt, "every step")):
            cfg.execute.log_dt = log_dt

            # As ex.execute logs: the model attached, so the robot is drawn too. Its description is made once
            # per process (timed above), as in a stage: its runs' models differ only in their servo gains.
            def logging_only() -> None:
                nonlocal path
                path = next(files)  # a new file, as each run of a stage writes its own
                with RunWriter(path, {"run_id": "b"}) as log:
                    log.attach(MODEL_ATTACHMENT, xml, "application/xml")
                    ex.log_execution(log, cfg, g, times, q_ref, qd_ref, states, sensors, ik_times, poses)
                    log.close("ok")

            def full() -> None:
                servo()
                logging_only()

            # bare stepping and whole runs in turn, 15 rounds: medians, in wall and in this process's CPU time
            calls = {"bare": (bare, (), 1), "servo": (servo, (), 1), "logging": (logging_only, (), 1),
                     "full": (full, (), 1)}
            wall, cpu = (time_interleaved(calls, warmup=2, repeats=15, clock=clock, collect=True)
                         for clock in (time.perf_counter_ns, time.process_time_ns))
            run = read_run(path)
            messages = sum(run.message_count(t) for t in run.topic_names)
            samples = run.message_count("/joint_state")
            rate = f"log_dt = {log_dt * 1e3:g} ms ({label})"
            if label == "default":
                rows += [{"what": system, "measure": "bare mj_step loop", "value": wall["bare"].median / steps * 1e6,
                          "unit": "µs/step"},
                         {"what": system, "measure": "servoed run (gains tuned, rollout with the servo in C)",
                          "value": wall["servo"].median / steps * 1e6, "unit": "µs/step"}]
            rows += [
                {"what": system, "measure": f"messages per run (every topic, the robot drawing included), {rate}",
                 "value": messages, "unit": ""},
                {"what": system, "measure": f"messages per logged sample, {rate}", "value": messages / samples,
                 "unit": ""},
                {"what": system, "measure": f"logging, {rate}", "value": wall["logging"].median / steps * 1e6,
                 "unit": "µs/step"},
                {"what": system, "measure": f"servo + logging over bare mj_step (wall), {rate}",
                 "value": wall["full"].median / wall["bare"].median, "unit": "×", "goal": "≤ 2"},
                {"what": system, "measure": f"the same in CPU time (this process), {rate}",
                 "value": cpu["full"].median / cpu["bare"].median, "unit": "×", "goal": "≤ 2"},
                {"what": system, "measure": f"simulated seconds per wall second, {rate}",
                 "value": sim_seconds / wall["full"].median, "unit": "s/s"},
            ]


def ik_per_call(rows: list[dict]) -> None:
    rng = np.random.default_rng(0)
    n = 10_000
    q = rng.uniform(-pi, pi, (n, 6))
    poses = dhk.fk(dhk.DH.from_config(ik.UR5.dh), q)
    previous = rng.uniform(-pi, pi, (n, 6))
    inputs = list(zip(poses, previous, strict=True))
    for name, fn, goal in (("Algorithm 1 (scalar)", ik.min_displacement, "≤ 35"),
                           ("Algorithm 2 (scalar)", ik.fsm, "≤ 35")):
        s = time_calls(name, fn, inputs, warmup=500).summary_us()
        rows.append({"what": name, "measure": "per call, median (p95)", "value": s["median_us"],
                     "p95": s["p95_us"], "unit": "µs", "goal": goal, "paper": "not reported"})
    for alg in ("alg1", "alg2"):
        s = time_calls(alg, lambda a=alg: ik.solve_batch(poses, previous, a), [()], warmup=2, repeats=20,
                       items_per_call=n).summary_us()
        rows.append({"what": f"Algorithm {alg[-1]} (batched, {n} poses)", "measure": "per pose, median (p95)",
                     "value": s["median_us"], "p95": s["p95_us"], "unit": "µs", "goal": "≤ 2"})
    try:
        from ur_analytic_ik import ur5
    except ImportError:
        rows.append({"what": "ur-analytic-ik (C++ peer)", "measure": "not installed: pip install -e '.[bench]'",
                     "value": float("nan"), "unit": ""})
        return
    # the peer uses UR's own DH values: time it on poses of its own model
    peer_poses = [np.ascontiguousarray(ur5.forward_kinematics(*x)) for x in q]
    for name, fn, args in (("ur-analytic-ik all solutions (C++ peer)", ur5.inverse_kinematics,
                            [(T,) for T in peer_poses]),
                           ("ur-analytic-ik closest (C++ peer)", ur5.inverse_kinematics_closest,
                            [(T, *p) for T, p in zip(peer_poses, previous, strict=True)])):
        s = time_calls(name, fn, args, warmup=500).summary_us()
        rows.append({"what": name, "measure": "per call, median (p95)", "value": s["median_us"], "p95": s["p95_us"],
                     "unit": "µs"})


def benchmark() -> list[dict]:
    rows: list[dict] = []
    execution(rows)
    ik_per_call(rows)
    dataset(rows)
    return rows


def reader(rows: list[dict], paths: list[Path], repeats: int = 5) -> None:
    """Reading every topic of `paths` back into DataFrames: the reader's default (fixed-layout series as one
    record view, every other topic column by column in NumPy) against decoding each message with protobuf;
    messages per second, median of `repeats` in this one process, over all topics and per topic."""
    import time

    from pipeline.core.decoding import read_topics

    topics = read_run(paths[0]).topic_names
    counts = {t: sum(read_run(p).message_count(t) for p in paths) for t in topics}
    what = f"reader: every topic of {len(paths)} random-paths runs ({sum(counts.values())} messages)"

    def rate(selection: list[str], arrays: bool) -> float:
        seconds = []
        for _ in range(repeats):
            start = time.perf_counter()
            for p in paths:
                read_topics(p, selection, arrays=arrays)
            seconds.append(time.perf_counter() - start)
        return sum(counts[t] for t in selection) / float(np.median(seconds))

    slow, fast = rate(topics, False), rate(topics, True)
    rows += [{"what": what, "measure": "message by message (protobuf)", "value": slow, "unit": "messages/s"},
             {"what": what, "measure": "column by column (NumPy)", "value": fast, "unit": "messages/s",
              "goal": "≥ 670000 (10 × the 15 µs/message of issue 19)"},
             {"what": what, "measure": "column by column over protobuf", "value": fast / slow, "unit": "×"}]
    for topic in topics:
        rows += [{"what": f"reader: {topic} of {len(paths)} runs ({counts[topic]} messages)", "measure": measure,
                  "value": rate([topic], arrays), "unit": "messages/s"}
                 for arrays, measure in ((True, "column by column (NumPy)"), (False, "message by message (protobuf)"))]


def dataset(rows: list[dict], episodes: int = 1000) -> None:
    """The dataset generator end to end, as a user runs it: `episodes` randomized paths (random-paths) simulated
    and logged in one process over the cores, then exported as a LeRobot dataset; and where one episode's time
    goes, measured in this process on a few episodes."""
    import subprocess
    import sys

    import yaml
    from omegaconf import OmegaConf

    from pipeline.core import episodes as ep
    from pipeline.core import parallel
    from pipeline.core.experiment import resolve
    from pipeline.core.runner import _run_case

    what = f"dataset generator: {episodes} random-paths episodes"
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pipeline", "experiment=ur5-ik-fsm/random-paths",
                        f"episodes.count={episodes}", f"data_dir={tmp}", "progress=false"], check=True,
                       capture_output=True)
        simulated = time.perf_counter() - start
        subprocess.run([sys.executable, "-m", "pipeline.dataset", "ur5-ik-fsm/random-paths", "--data-dir", tmp],
                       check=True, capture_output=True)
        total = time.perf_counter() - start
        size = sum(p.stat().st_size for p in (Path(tmp) / "datasets").rglob("*") if p.is_file())
        reader(rows, run_files(Path(tmp) / "runs/ur5-ik-fsm/random-paths")[:40])
    workers = parallel.workers_for(0, episodes)
    rows += [
        {"what": what, "measure": f"simulate + log ({workers} workers, one process start)", "value": simulated,
         "unit": "s"},
        {"what": what, "measure": "export to LeRobot v3.0 (one process)", "value": total - simulated, "unit": "s"},
        {"what": what, "measure": "simulated, logged and exported", "value": total, "unit": "s", "goal": "≤ 120"},
        {"what": what, "measure": "episodes per second", "value": episodes / total, "unit": "1/s"},
        {"what": what, "measure": "dataset size", "value": size / 1e6, "unit": "MB"},
    ]
    # one episode's parts (one core): drawing the config, the IK along the path, MuJoCo, logging + writing
    cfg = compose_config(["experiment=ur5-ik-fsm/random-paths"])
    experiment = resolve("ur5-ik-fsm/random-paths")
    base = OmegaConf.to_container(cfg, resolve=True)
    draw = ep.sampler(cfg)
    parts: dict[str, list[float]] = {"config": [], "IK along the path (2001 scalar calls)": [],
                                     "MuJoCo servo (rollout)": [], "logging + MCAP write": [], "episode": []}
    with tempfile.TemporaryDirectory() as tmp:
        for index in range(12):
            t0 = time.perf_counter()
            plain = ep.apply(base, draw(index), ep.seed_of(cfg, index))
            episode_cfg = OmegaConf.create(plain)
            case = experiment.fn(episode_cfg)[0]
            config_yaml = yaml.safe_dump(plain, sort_keys=False)
            t1 = time.perf_counter()
            path, crossing, algorithm = case.id.split("-")
            ik_times, _, q_ik, _ = ex.solve_path(episode_cfg, path, crossing, algorithm)
            t2 = time.perf_counter()
            times, q_ref, qd_ref = ex.servo_references(q_ik, ik_times, episode_cfg.execute.dt, True,
                                                       episode_cfg.system.dynamics.velocity_limit)
            servo_rollout(ex.arm_model(episode_cfg, ex.geometry(episode_cfg), q_ref[0]), q_ref, qd_ref, times)
            t3 = time.perf_counter()
            _run_case(case, f"e{index}", Path(tmp), config_yaml, {"run_id": f"e{index}"})
            t4 = time.perf_counter()
            if index:  # the first one warms caches
                full = t4 - t3
                parts["config"].append(t1 - t0)
                parts["IK along the path (2001 scalar calls)"].append(t2 - t1)
                parts["MuJoCo servo (rollout)"].append(t3 - t2)
                parts["logging + MCAP write"].append(full - (t3 - t1))
                parts["episode"].append(full + t1 - t0)
    for part, values in parts.items():
        rows.append({"what": "one random-paths episode (median of 11)", "measure": part,
                     "value": float(np.median(values)) * 1e3, "unit": "ms"})

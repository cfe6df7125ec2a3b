"""Speed of `curve-discretization`: the algorithm per call at 100 joints against the paper's < 35 ms and our
≤ 1 ms goal (compiled, and the same code interpreted), and the MuJoCo snake against bare stepping."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from pipeline.core.checks import compose_config
from pipeline.core.runlog import MODEL_ATTACHMENT, RunWriter, read_run
from pipeline.core.timing import best_of, time_calls
from pipeline.papers.curve_discretization import algorithm as dc
from pipeline.papers.curve_discretization import experiments as ex
from pipeline.papers.curve_discretization import snake as sn

PAPER_100 = "< 35 ms total (MATLAB 7.1, 2008 Mac Pro)"
# The same stages with numba switched off, in a child process (the switch is read at import).
INTERPRETED = """
import json, sys
from pipeline.core.checks import compose_config
from pipeline.core.timing import time_calls
from pipeline.papers.curve_discretization import algorithm as dc
from pipeline.papers.curve_discretization import experiments as ex
cfg = compose_config(["experiment=curve-discretization/timing-fig3"])
curve, chain = ex.paper_curve(cfg), dc.Chain.uniform(100, cfg.scenario.chain_length / 50)
t = time_calls("total", dc.discretize, [(curve, chain, cfg.system.theta_x0, *ex.search_args(cfg))], warmup=1, repeats=5)
print(json.dumps(t.summary_us()))
"""



def algorithm_per_call(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=curve-discretization/timing-fig3"])
    curve, (dt, tol), roll = ex.paper_curve(cfg), ex.search_args(cfg), cfg.system.theta_x0
    for joints in (30, 100):
        chain = dc.Chain.uniform(joints, cfg.scenario.chain_length / (joints // 2))
        search = dc.joint_parameters(curve, chain, dt, tol)
        for name, fn, args in (("search", dc.joint_parameters, (curve, chain, dt, tol)),
                               ("angles", dc.joint_angles, (search.points, roll, joints)),
                               ("total", dc.discretize, (curve, chain, roll, dt, tol))):
            s = time_calls(name, fn, [args], warmup=200, repeats=1000).summary_us()
            total_100 = name == "total" and joints == 100
            rows.append({"what": f"Bézier (19), {joints} joints: {name}", "measure": "per call, median (p95)",
                         "value": s["median_us"], "p95": s["p95_us"], "unit": "µs",
                         "goal": "≤ 1000" if total_100 else "", "paper": PAPER_100 if total_100 else ""})
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    root = Path(__file__).resolve().parents[3]
    proc = subprocess.run([sys.executable, "-c", INTERPRETED], cwd=root, env=env, capture_output=True, text=True,
                          check=True)
    s = json.loads(proc.stdout.strip().splitlines()[-1])
    rows.append({"what": "Bézier (19), 100 joints: total, interpreted (NUMBA_DISABLE_JIT=1)",
                 "measure": "per call, median (p95)", "value": s["median_us"], "p95": s["p95_us"], "unit": "µs",
                 "paper": PAPER_100})


def snake_speed(rows: list[dict]) -> None:
    import mujoco

    cfg = compose_config(["experiment=curve-discretization/snake-gait"])
    sc, ctl = cfg.scenario, cfg.control
    chain, body = dc.Chain.uniform(sc.joints, sc.segment_length), ex.snake_body(cfg)
    xml = sn.snake_mjcf(chain, body, timestep=ctl.physics_dt, kp=ctl.kp, kv=ctl.kv)
    gait = ex.gait_curve(sc["lateral-undulation"], sc.curve_length)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    substeps = round(ctl.dt / ctl.physics_dt)

    def controlled(compare_warm_cold: bool = False) -> sn.GaitRun:
        return sn.run_gait(chain, body, gait, sc.theta_x0, *ex.search_args(cfg), xml, control_dt=ctl.dt,
                           duration=sc.duration, warm_start=ctl.warm_start, compare_warm_cold=compare_warm_cold)

    run = controlled(compare_warm_cold=True)  # logged as the experiment logs it
    steps = len(run.times) * substeps

    def bare() -> None:  # the same motion (the run's servo references played back), so the same contacts
        mujoco.mj_resetData(model, data)
        data.qpos[:] = run.qpos[0]
        n = run.q_ref.shape[1]
        for q_ref, qd_ref in zip(run.q_ref, run.qd_ref, strict=True):
            data.ctrl[:n], data.ctrl[n:] = q_ref, qd_ref
            mujoco.mj_step(model, data, nstep=substeps)

    with tempfile.TemporaryDirectory() as tmp:
        def logging_only() -> None:
            with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                log.attach(MODEL_ATTACHMENT, xml, "application/xml")  # as the experiment does: the robot drawn
                ex.log_gait(log, run, chain, xml, ctl.tf_dt)
                log.close("ok")

        t_bare, t_run, t_log = best_of(bare), best_of(controlled), best_of(logging_only)
        t_with_replay = best_of(lambda: controlled(compare_warm_cold=True))
        cpu = {fn: best_of(fn, clock=time.process_time) for fn in (bare, controlled, logging_only)}
        written = read_run(Path(tmp) / "b.mcap")
        messages = sum(written.message_count(t) for t in written.topic_names)
        samples = written.message_count("/joint_state")
    system = f"MuJoCo snake, {sc.joints} joints, lateral undulation ({sc.duration:g} s, 1 kHz, algorithm at 100 Hz)"
    rows += [
        {"what": system, "measure": "bare mj_step", "value": t_bare / steps * 1e6, "unit": "µs/step"},
        {"what": system, "measure": "controlled run (algorithm every control period, servo)",
         "value": t_run / steps * 1e6, "unit": "µs/step"},
        {"what": system, "measure": "the same, then Sec. IV-D's warm/cold search timing (an experiment, not control)",
         "value": t_with_replay / steps * 1e6, "unit": "µs/step"},
        {"what": system, "measure": "logging", "value": t_log / steps * 1e6, "unit": "µs/step"},
        {"what": system, "measure": "messages per run (every topic, the robot drawing included)",
         "value": messages, "unit": ""},
        {"what": system, "measure": "messages per logged sample", "value": messages / samples, "unit": ""},
        {"what": system, "measure": "run + logging over bare mj_step", "value": (t_run + t_log) / t_bare, "unit": "×",
         "goal": "≤ 2"},
        {"what": system, "measure": "the same in CPU time (this process)",
         "value": (cpu[controlled] + cpu[logging_only]) / cpu[bare], "unit": "×", "goal": "≤ 2"},
        {"what": system, "measure": "simulated seconds per wall second", "value": sc.duration / (t_run + t_log),
         "unit": "s/s"},
    ]


def benchmark() -> list[dict]:
    rows: list[dict] = []
    algorithm_per_call(rows)
    snake_speed(rows)
    return rows

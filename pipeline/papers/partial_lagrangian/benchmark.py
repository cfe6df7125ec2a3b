"""Speed of `partial-lagrangian`: whole runs (AD rollout in CasADi, logging) against MuJoCo stepping the same
chain, and the per-call time of one dynamics evaluation beside the paper's (which prints none)."""

from __future__ import annotations

import tempfile
from functools import partial
from pathlib import Path

import casadi as ca
import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import best_of, time_interleaved
from pipeline.papers.partial_lagrangian import experiments as ex
from pipeline.papers.partial_lagrangian import lagrangian as lg
from pipeline.papers.partial_lagrangian.rollout import Gains, simulate


def runs(rows: list[dict]) -> None:
    import mujoco

    cfg = compose_config(["experiment=partial-lagrangian/ten-link"])
    chain = ex.chain_of(cfg, 10)
    dt, duration = cfg.system.simulation.dt, cfg.scenario.free.duration
    q0, free = np.zeros(chain.n), Gains.free(chain.n)
    steps = round(duration / dt)
    model = mujoco.MjModel.from_xml_string(ex.chain_model(chain, dt))
    data = mujoco.MjData(model)

    def bare_mujoco() -> None:
        mujoco.mj_resetData(model, data)
        for _ in range(steps):
            mujoco.mj_step(model, data)

    traj = simulate(chain, q0, q0, free, dt, duration)
    t_ad = best_of(lambda: simulate(chain, q0, q0, free, dt, duration))
    with tempfile.TemporaryDirectory() as tmp:
        def logging_only() -> None:
            with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                ex.log_trajectory(log, cfg, chain, traj, free)
                log.close("ok")

        t_log = best_of(logging_only)
    t_mj = best_of(bare_mujoco)
    what = f"10-link chain, {duration:g} s at dt = {dt * 1e3:g} ms"
    rows += [
        {"what": what, "measure": "AD rollout (graph built + CasADi mapaccum), simulated s per wall s",
         "value": duration / t_ad, "unit": "s/s"},
        {"what": what, "measure": "logging at log_dt over the AD rollout", "value": t_log / t_ad, "unit": "×",
         "goal": "≤ 0.5"},
        {"what": what, "measure": "bare MuJoCo mj_step loop (Python), simulated s per wall s",
         "value": duration / t_mj, "unit": "s/s"},
    ]


def per_call(rows: list[dict]) -> None:
    import mujoco

    cfg = compose_config(["experiment=partial-lagrangian/compute-time"])
    rng = np.random.default_rng(0)
    calls = {}
    for n in (3, 10):
        chain = ex.chain_of(cfg, n)
        q, qd, tau = ex.random_states(rng, n, 1)
        for form in lg.FORMS:
            f = lg.dynamics(chain, form).forward
            calls[f"AD {form} Lagrangian, n = {n}"] = (f, tuple(ca.DM(x[0]) for x in (q, qd, tau)), 1)
        model = mujoco.MjModel.from_xml_string(ex.chain_model(chain, cfg.system.simulation.dt))
        data = mujoco.MjData(model)
        data.qpos[:], data.qvel[:] = q[0], qd[0]
        calls[f"MuJoCo mj_forward, n = {n}"] = (partial(mujoco.mj_forward, model, data), (), 1)
    for name, timing in time_interleaved(calls, warmup=100, repeats=3000).items():
        s = timing.summary_us()
        rows.append({"what": f"q̈ of the chain: {name}", "measure": "per call from Python, median (p95)",
                     "value": s["median_us"], "p95": s["p95_us"], "unit": "µs",
                     "paper": "Fig. 5b (image only; PyTorch, i5-10400)"})


def benchmark() -> list[dict]:
    rows: list[dict] = []
    runs(rows)
    per_call(rows)
    return rows

"""Speed of `itbot-smc`: both plants bare and under the 1 kHz controller, the cost of logging, and each
controller per call (the paper reports no compute time)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import best_of, time_calls
from pipeline.papers.itbot_smc import experiments as ex
from pipeline.papers.itbot_smc.closed_loop import run_closed_loop
from pipeline.papers.itbot_smc.model import gravity_torque

LAWS = {"nsmerl": "nSMERL, eqs. (5)-(6)", "smerl": "SMERL (ERL)", "smc": "conventional SMC"}


def plants(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=itbot-smc/tracking"])
    setup = ex.Setup.of(cfg.system)
    simulated = setup.reference.duration
    ticks = round(simulated / setup.period)
    hold = gravity_torque(setup.links.with_point_mass(setup.load.mass), setup.initial_state()[0])
    for kind, what in (("analytic", "analytic plant (eqs. A7-A12, RK4 at 1 ms)"), ("mujoco", "MuJoCo plant (1 ms)")):
        def bare(kind=kind) -> None:
            plant = setup.plant(kind, 1)
            for _ in range(ticks):
                plant.advance(hold)

        def closed(kind=kind):
            return run_closed_loop(setup.plant(kind, 1), setup.controller("nsmerl"), setup.sensor(), setup.reference,
                                   setup.period, setup.drive.torque_limit)

        t_bare, t_closed = best_of(bare), best_of(closed)
        run = closed()
        with tempfile.TemporaryDirectory() as tmp:
            def logging_only(run=run) -> None:
                with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                    ex.log_run(log, setup, cfg.execute, "nsmerl", run)
                    log.close("ok")

            t_log = best_of(logging_only)
        rows += [
            {"what": what, "measure": "bare plant, gravity torque held per 1 ms tick", "value": simulated / t_bare,
             "unit": "sim s / wall s"},
            {"what": what, "measure": "nSMERL closed loop, exact states (one Python step per tick)",
             "value": simulated / t_closed, "unit": "sim s / wall s"},
            {"what": what, "measure": "controller + loop over bare plant", "value": t_closed / t_bare, "unit": "×"},
            {"what": what, "measure": "logging (every tick: τ, F, v, time; 5 ms: states)", "value": t_log / t_closed,
             "unit": "× of the run", "goal": "≤ 0.3"},
        ]


def controllers(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=itbot-smc/tracking"])
    setup = ex.Setup.of(cfg.system)
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 10.0, 5000)
    q_d, qd_d, qdd_d = setup.reference(t)
    q, qd = q_d + rng.normal(0, 0.002, q_d.shape), qd_d + rng.normal(0, 0.01, qd_d.shape)
    # Python floats, as the closed loop passes them
    inputs = list(zip(t.tolist(), *(map(tuple, x.tolist()) for x in (q, qd, q_d, qd_d, qdd_d)), strict=True))
    for law, label in LAWS.items():
        s = time_calls(label, setup.controller(law), inputs, warmup=500, repeats=2).summary_us()
        rows.append({"what": label, "measure": "per control step, median (p95)", "value": s["median_us"],
                     "p95": s["p95_us"], "unit": "µs", "goal": "≪ 1000 (1 kHz)", "paper": "not reported"})


def benchmark() -> list[dict]:
    rows: list[dict] = []
    plants(rows)
    controllers(rows)
    return rows

"""Speed of `scara-half-derivative`: both plants bare and under the 5 ms controller, the cost of logging,
and the controller per call (KD vs KDHD)."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import time_calls
from pipeline.papers.scara_half_derivative import experiments as ex
from pipeline.papers.scara_half_derivative.closed_loop import PlantSettings, make_plant, run_closed_loop
from pipeline.papers.scara_half_derivative.controller import CartesianController

SIMULATED = 15.6   # s: the whole set-point motion


def _seconds(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def plants(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=scara-half-derivative/table2"])
    arm, q0 = ex.arm_of(cfg), ex.home(cfg)
    motion = ex.motion_of(cfg, arm)
    period = cfg.system.control.dt
    periods = round(SIMULATED / period)
    _, g = ex.gains(cfg, 8e4, 2500.0, 23600.0)   # KDHD, the intermediate tuning
    for kind in ("exudyn", "lagrange"):
        settings = PlantSettings(kind, 1e-3, cfg.execute.spectral_radius, cfg.execute.newton_tolerance)
        what = f"{'Exudyn closed chain' if kind == 'exudyn' else 'reduced Lagrangian (RK4)'}, 1 ms steps, 15.6 s"

        def bare(s=settings) -> None:
            plant = make_plant(s, arm, q0, np.zeros(4), period, periods)
            hold = np.zeros(4)
            for _ in range(periods):
                plant.advance(hold)

        def closed(s=settings):
            plant = make_plant(s, arm, q0, np.zeros(4), period, periods)
            return run_closed_loop(plant, CartesianController(arm, g, period, 10), motion, SIMULATED, period)

        t_bare = _seconds(bare)
        run = closed()
        t_closed = _seconds(closed)
        cfg.execute.log_dt = 1e-3
        with tempfile.TemporaryDirectory() as tmp:
            def logging_only(run=run) -> None:
                with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                    ex.log_closed_loop(log, cfg, arm, motion, run, "kdhd")
                    log.close("ok")

            t_log = _seconds(logging_only)
        rows += [
            {"what": what, "measure": "bare plant, zero torque held per period", "value": SIMULATED / t_bare,
             "unit": "sim s / wall s"},
            {"what": what, "measure": "KDHD closed loop (one Python call per 5 ms)", "value": SIMULATED / t_closed,
             "unit": "sim s / wall s"},
            {"what": what, "measure": "controller + loop over bare plant", "value": t_closed / t_bare, "unit": "×",
             "goal": "≤ 1.5"},
            {"what": what, "measure": "logging at 1 ms (+ frames at 20 ms)", "value": t_log / t_closed,
             "unit": "× of the run", "goal": "≤ 0.3"},
        ]


def controller_per_call(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=scara-half-derivative/table2"])
    arm, q0 = ex.arm_of(cfg), ex.home(cfg)
    rng = np.random.default_rng(0)
    inputs = [(q0 + rng.normal(0, 0.05, 4), rng.normal(0, 0.3, 4), ex.motion_of(cfg, arm).home, np.zeros(4))
              for _ in range(5000)]
    for label, d, hd in (("KD, eq. (11)", 5000.0, 0.0), ("KDHD, eq. (17)", 2500.0, 23600.0)):
        _, g = ex.gains(cfg, 8e4, d, hd)
        controller = CartesianController(arm, g, cfg.system.control.dt, cfg.system.control.gl_terms)
        s = time_calls(label, controller, inputs, warmup=500).summary_us()
        rows.append({"what": label, "measure": "per control step, median (p95)", "value": s["median_us"],
                     "p95": s["p95_us"], "unit": "µs", "paper": "not reported"})


def benchmark() -> list[dict]:
    rows: list[dict] = []
    plants(rows)
    controller_per_call(rows)
    return rows

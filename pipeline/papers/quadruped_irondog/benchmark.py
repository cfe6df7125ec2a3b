"""Speed of `quadruped-irondog`: the MuJoCo trot against bare stepping of the same motion, the cost of the
controller and of logging, and per-call times of the gait's pieces (control step, leg IK, Bezier point)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import best_of, time_calls
from pipeline.papers.quadruped_irondog import experiments as ex
from pipeline.papers.quadruped_irondog import kinematics as kin
from pipeline.papers.quadruped_irondog.control import TrotController
from pipeline.papers.quadruped_irondog.gait import bezier
from pipeline.papers.quadruped_irondog.model import Scene
from pipeline.papers.quadruped_irondog.simulation import Plant, simulate


def _setup():
    cfg = compose_config(["experiment=quadruped-irondog/trot"])
    robot = ex.robot_of(cfg)
    q_stand = ex.table5_pose(cfg)
    gait = ex.trot_of(cfg, robot)
    sc = cfg.scenario
    controller = TrotController(robot.leg, gait, q_stand, sc.settle, sc.rise, sc.ramp_cycles * gait.period,
                                cfg.system.gait.stride_scale)
    return cfg, robot, q_stand, controller, controller.start + sc.cycles * gait.period


def trot(rows: list[dict]) -> None:
    import mujoco

    cfg, robot, q_stand, controller, duration = _setup()
    control_dt, log_dt = 1.0 / cfg.system.control.rate_hz, 1.0 / cfg.system.log.rate_hz
    plant = Plant(robot, Scene())

    def run():
        plant.place(q_stand)
        return simulate(plant, controller, duration, control_dt, log_dt, ex.fall_of(cfg))

    trace = run()
    # the same servo commands replayed with nothing else in the loop: the simulator's own cost
    steps_per_control = round(control_dt / plant.model.opt.timestep)
    commands = trace.q_cmd[::round(control_dt / log_dt)]
    model, data = plant.model, plant.data

    def bare() -> None:
        plant.place(q_stand)
        for command in commands:
            data.ctrl[:12] = command
            mujoco.mj_step(model, data, nstep=steps_per_control)

    def logging_only() -> None:
        with tempfile.TemporaryDirectory() as tmp, RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
            ex.log_trace(log, plant, trace, cfg)
            log.close("ok")

    t_bare, t_run, t_log = best_of(bare, 3), best_of(run, 3), best_of(logging_only, 3)
    what = f"MuJoCo trot, {duration:g} s simulated at {1 / plant.model.opt.timestep:g} Hz"
    rows += [
        {"what": what, "measure": "bare mj_step, same servo commands", "value": duration / t_bare, "unit": "s/s"},
        {"what": what, "measure": "closed loop (controller + sampling)", "value": duration / t_run, "unit": "s/s"},
        {"what": what, "measure": "closed loop over bare stepping", "value": t_run / t_bare, "unit": "×",
         "goal": "≤ 2"},
        {"what": what, "measure": "logging the run to MCAP", "value": t_log, "unit": "s"},
        {"what": what, "measure": "closed loop + logging, simulated seconds per wall second",
         "value": duration / (t_run + t_log), "unit": "s/s"},
    ]


def per_call(rows: list[dict]) -> None:
    _, robot, _, controller, duration = _setup()
    times = np.linspace(controller.start, duration, 500)
    rpy = np.zeros(3)
    point = kin.fk(robot.leg, np.radians([0.0, -30.0, 60.0]))
    for name, fn, args, items in (
            ("trot control step: gait + IK of 4 legs", controller, [(t, rpy) for t in times], 1),
            ("IK of one leg, eqs. (38)-(40)", kin.ik, [(robot.leg, point)], 1),
            ("IK of 4 legs in one call, per leg", kin.ik, [(robot.leg, np.tile(point, (4, 1)))], 4),
            ("Bezier point, eqs. (41)-(44)", bezier, [(controller.trot.control_points, 0.37)], 1)):
        s = time_calls(name, fn, args, warmup=200, repeats=2000 // len(args) or 1, items_per_call=items).summary_us()
        rows.append({"what": name, "measure": "per call, median (p95)", "value": s["median_us"], "p95": s["p95_us"],
                     "unit": "µs", "paper": "not reported"})


def benchmark() -> list[dict]:
    rows: list[dict] = []
    trot(rows)
    per_call(rows)
    return rows

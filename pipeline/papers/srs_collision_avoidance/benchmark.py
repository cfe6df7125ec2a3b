"""Speed of `srs-collision-avoidance`: Algorithm 1 per iteration (IK + avoidance + filter) beside the paper's
3.68 ms, the IK alone (per call and batched), and the MuJoCo replay against bare stepping."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import best_of, time_calls
from pipeline.papers.srs_collision_avoidance import experiments as ex
from pipeline.papers.srs_collision_avoidance import planner
from pipeline.papers.srs_collision_avoidance.kinematics import ik

PAPER = "3.68 ms (3.68 s / 1000, MATLAB R2021a, i7 2.7 GHz)"


def algorithm(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=srs-collision-avoidance/compute-time"])
    _, poses = ex.task(cfg)
    _, start, end, radius = ex.obstacles(cfg, ex.humans(cfg))
    inputs = [(T, a, b, radius) for T, a, b in zip(poses, start, end, strict=True)]
    n = len(poses)
    for case in ("avoid", "avoid-exact", "avoid-capsules"):
        s = ex.settings(cfg, case)
        timing = time_calls(case, planner.Online(s).step, inputs, warmup=200, repeats=3).summary_us()
        rows.append({"what": f"Algorithm 1 online ({case})", "measure": "per iteration, median (p95)",
                     "value": timing["median_us"] / 1e3, "p95": timing["p95_us"] / 1e3, "unit": "ms",
                     "goal": "≤ 3.68", "paper": PAPER})
        batch = time_calls(f"{case} batch", lambda s=s: planner.plan(poses, start, end, radius, s), [()], warmup=2,
                           repeats=20, items_per_call=n).summary_us()
        rows.append({"what": f"Algorithm 1 batch ({case}, {n} samples)", "measure": "per sample, median (p95)",
                     "value": batch["median_us"] / 1e3, "p95": batch["p95_us"] / 1e3, "unit": "ms"})
    scalar = time_calls("ik", lambda T: ik(T, 0.3), [(T,) for T in poses], warmup=200).summary_us()
    rows.append({"what": "IK at a given α (one pose)", "measure": "per call, median (p95)",
                 "value": scalar["median_us"], "p95": scalar["p95_us"], "unit": "µs", "paper": "not reported"})
    batched = time_calls("ik batch", lambda: ik(poses, 0.3), [()], warmup=2, repeats=50,
                         items_per_call=n).summary_us()
    rows.append({"what": f"IK at a given α (batch of {n})", "measure": "per pose, median (p95)",
                 "value": batched["median_us"], "p95": batched["p95_us"], "unit": "µs"})


def replay(rows: list[dict]) -> None:
    import mujoco
    from scipy.interpolate import CubicSpline

    from pipeline.robotics.mjcf import servo_rollout

    cfg = compose_config(["experiment=srs-collision-avoidance/circle"])
    times, plan, points, capsules = ex.plan_case(cfg, "avoid")
    arms = ex.humans(cfg)
    spline = CubicSpline(times, plan.q, axis=0)
    t = np.arange(round(times[-1] / cfg.replay.dt) + 1) * cfg.replay.dt
    q_ref, qd_ref = spline(t), spline(t, 1)
    xml = ex.replay_model(cfg, arms, q_ref[0])
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def bare() -> None:
        mujoco.mj_resetData(model, data)
        data.qpos[:] = q_ref[0]
        for _ in range(len(t)):
            mujoco.mj_step(model, data)

    t_bare = best_of(bare, 3)
    t_servo = best_of(lambda: servo_rollout(xml, q_ref, qd_ref, t, moving_start=True), 3)
    with tempfile.TemporaryDirectory() as tmp:
        def whole_case() -> None:
            with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                ex.log_plan(log, cfg, times, plan, points, capsules, arms)
                ex.replay(log, cfg, times, plan, capsules, arms)
                log.close("ok")

        t_case = best_of(whole_case, 3)
    system = f"MuJoCo SRS arm, circle task ({times[-1]:.0f} s at {1 / cfg.replay.dt:.0f} Hz)"
    rows += [
        {"what": system, "measure": "bare mj_step loop", "value": t_bare / len(t) * 1e6, "unit": "µs/step"},
        {"what": system, "measure": "servoed replay (rollout, servo in C)", "value": t_servo / len(t) * 1e6,
         "unit": "µs/step"},
        {"what": system, "measure": "one case: logging + replay + MuJoCo distance audit", "value": t_case,
         "unit": "s"},
        {"what": system, "measure": "simulated seconds per wall second, whole case", "value": times[-1] / t_case,
         "unit": "s/s"},
    ]


def benchmark() -> list[dict]:
    rows: list[dict] = []
    algorithm(rows)
    replay(rows)
    return rows

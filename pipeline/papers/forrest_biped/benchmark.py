"""Speed of `forrest-biped`: the MuJoCo walk against bare stepping (simulated seconds per wall second), the
controller's time per 1 ms cycle (median, p95), the wrench QP alone, the generators and the LIP check."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import best_of, time_calls
from pipeline.papers.forrest_biped import experiments as ex
from pipeline.papers.forrest_biped import lipm, walking
from pipeline.papers.forrest_biped.model import build
from pipeline.papers.forrest_biped.support import support_polygons


def benchmark() -> list[dict]:
    import mujoco

    cfg = compose_config(["experiment=forrest-biped/walking"])
    system = ex.system_dict(cfg)
    biped, control = build(system), build(system, plant=False)
    pattern = ex.make_pattern(cfg, "extended")
    sim_seconds = float(pattern.t[-1])
    tf_every = 10
    logs: list[walking.WalkLog] = []

    def walk() -> None:
        logs.append(walking.walk(biped, control, pattern, system, tf_every))

    t_walk = best_of(walk, 3)
    w = logs[-1]
    model = mujoco.MjModel.from_xml_string(biped.xml)
    data = mujoco.MjData(model)
    q0 = walking.standing_pose(model, data, pattern.com[0], pattern.feet[:, 0])
    substeps = round(cfg.system.controller.dt / model.opt.timestep)

    def bare() -> None:               # the same physics, the recorded torques replayed open loop
        mujoco.mj_resetData(model, data)
        data.qpos[:] = q0
        for tau in w.tau:
            data.ctrl[:] = tau
            mujoco.mj_step(model, data, substeps)

    t_bare = best_of(bare, 3)
    with tempfile.TemporaryDirectory() as tmp:
        def logging_only() -> None:
            with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                ex.log_walk(log, pattern, w, biped, tf_every)
                log.close("ok")

        t_log = best_of(logging_only, 3)
    system_name = "MuJoCo FORREST, 4 s walk (0.1 ms physics, 1 ms controller)"
    steps = len(w.t) * substeps
    ctl, qp, upd = (w.compute[:, k] * 1e6 for k in range(3))
    rows = [
        {"what": system_name, "measure": "bare mj_step (recorded torques replayed)", "value": t_bare / steps * 1e6,
         "unit": "µs/step"},
        {"what": system_name, "measure": "simulated seconds per wall second, closed loop",
         "value": sim_seconds / t_walk, "unit": "s/s"},
        {"what": system_name, "measure": "simulated seconds per wall second, closed loop + logging",
         "value": sim_seconds / (t_walk + t_log), "unit": "s/s"},
        {"what": system_name, "measure": "closed loop over bare stepping", "value": t_walk / t_bare, "unit": "×"},
        {"what": system_name, "measure": "logging (MCAP) per cycle", "value": t_log / len(w.t) * 1e6, "unit": "µs"},
        {"what": "Sec. 6 controller cycle (CP + PD + QP + ID)", "measure": "per cycle, median (p95)",
         "value": float(np.median(ctl)), "p95": float(np.percentile(ctl, 95)), "unit": "µs", "goal": "≤ 1000",
         "paper": "1 ms cycle, no time reported"},
        {"what": "  in it: wrench QP (DAQP)", "measure": "per cycle, median (p95)", "value": float(np.median(qp)),
         "p95": float(np.percentile(qp, 95)), "unit": "µs"},
        {"what": "  in it: model update (MuJoCo)", "measure": "per cycle, median (p95)",
         "value": float(np.median(upd)), "p95": float(np.percentile(upd, 95)), "unit": "µs"},
    ]
    for kind in ("extended", "traditional"):
        s = time_calls(kind, lambda k=kind: ex.make_pattern(cfg, k), [()], warmup=2, repeats=20).summary_us()
        rows.append({"what": f"{kind} generator, 4 s at 1 ms", "measure": "per call, median (p95)",
                     "value": s["median_us"] / 1e3, "p95": s["p95_us"] / 1e3, "unit": "ms"})
    polygons = support_polygons(pattern, biped.foot_half, cfg.system.controller.polygon_margin)
    s = time_calls("lipm", lambda: lipm.simulate(pattern, cfg.system.controller.cp_gain, polygons, 1e-3), [()],
                   warmup=1, repeats=10).summary_us()
    rows.append({"what": "LIP closed loop, 4 s at 1 ms", "measure": "per run, median (p95)",
                 "value": s["median_us"] / 1e3, "p95": s["p95_us"] / 1e3, "unit": "ms"})
    return rows

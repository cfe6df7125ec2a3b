"""Speed of `dyad-triad-synthesis`: the three solvers of the dyad in five positions and the triad in seven
positions per call, and the Exudyn four-bar bare and under the rocker servo, with the cost of logging."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.runlog import RunWriter
from pipeline.core.timing import time_calls, time_interleaved
from pipeline.papers.dyad_triad_synthesis import experiments as ex
from pipeline.papers.dyad_triad_synthesis import multibody, synthetic
from pipeline.papers.dyad_triad_synthesis.compatibility import Compatibility
from pipeline.papers.dyad_triad_synthesis.standard_form import triad


def _seconds(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def solvers(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=dyad-triad-synthesis/compute-time"])
    points, alpha = ex.table4(cfg)
    timings = time_interleaved({name: (fn, (points, alpha), 1) for name, fn in ex.solvers(cfg).items()},
                               warmup=2, repeats=15)
    for name, timing in timings.items():
        s = timing.summary_us()
        rows.append({"what": f"dyad in 5 PP, Table 4: {name.replace('_', ' ')}", "measure": "per solve, median",
                     "value": s["median_us"] / 1e3, "p95": s["p95_us"] / 1e3, "unit": "ms", "paper": "not reported"})
    t = synthetic.random_triad(np.random.default_rng(0), 7, ungrounded=False)
    compat = Compatibility(triad(t.points, t.alpha, t.gamma, t.h))
    grid = cfg.system.search.grid_2d
    s = time_calls("triad7", lambda: compat.roots(grid_2d=grid), [()], warmup=1, repeats=5).summary_us()
    rows.append({"what": f"triad in 7 PP: {grid}² grid + Newton", "measure": "per solve, median",
                 "value": s["median_us"] / 1e3, "p95": s["p95_us"] / 1e3, "unit": "ms"})


def four_bar(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=dyad-triad-synthesis/four-bar"])
    fb, poses, points, alpha = ex.paper_four_bar(cfg)
    sc, exe = cfg.scenario, cfg.execute
    simulated = sc.move_duration + sc.hold_duration
    what = f"Exudyn four-bar, {exe.servo_dt * 1e3:g} ms steps, {exe.control_dt * 1e3:g} ms control, {simulated:g} s"

    run = ex.servo_2to5(cfg, fb, poses, "computed-torque")

    def bare() -> None:
        """The same motion open loop: the servo's torques played back, no state read, no control law (a
        motionless system would converge in fewer Newton iterations and flatter the ratio)."""
        model = multibody.ExudynFourBar(fb, cfg.system.linkage.line_density, exe.servo_dt, exe.control_dt,
                                        exe.spectral_radius, exe.newton_tolerance,
                                        start=fb.solve("B", run.reference["position"][0, 0], run.branch))
        for torque in run.torque:
            model.advance(torque=torque)
        model.finish()

    t_bare = min(_seconds(bare) for _ in range(3))
    t_servo = min(_seconds(lambda: ex.servo_2to5(cfg, fb, poses, "computed-torque")) for _ in range(3))
    with tempfile.TemporaryDirectory() as tmp:
        def logging_only() -> None:
            with RunWriter(Path(tmp) / "b.mcap", {"run_id": "b"}) as log:
                ex.log_servo(log, cfg, run, points, alpha)
                log.close("ok")

        t_log = min(_seconds(logging_only) for _ in range(3))
    rows += [
        {"what": what, "measure": "bare loop, the servo's torques played back", "value": simulated / t_bare,
         "unit": "sim s / wall s"},
        {"what": what, "measure": "computed-torque servo (one Python call per period)", "value": simulated / t_servo,
         "unit": "sim s / wall s"},
        {"what": what, "measure": "servo over bare loop", "value": t_servo / t_bare, "unit": "×", "goal": "≤ 1.5"},
        {"what": what, "measure": f"logging (every {exe.log_dt * 1e3:g} ms, frames every {exe.tf_dt * 1e3:g} ms)",
         "value": t_log / t_servo, "unit": "× of the run", "goal": "≤ 0.3"},
    ]



def benchmark() -> list[dict]:
    rows: list[dict] = []
    solvers(rows)
    four_bar(rows)
    return rows

"""Speed of `kinematic-graph`: KG construction (Algorithm 1, per stage), A* per query on the KG against the same A*
on the plain C-grid, mapping the obstacles into each graph (Sec. 3.4), and the MuJoCo execution."""

from __future__ import annotations

import math

import numpy as np

from pipeline.core.checks import compose_config
from pipeline.core.timing import best_of, time_calls, time_interleaved
from pipeline.papers.kinematic_graph import execution as ex
from pipeline.papers.kinematic_graph import experiments as kx
from pipeline.papers.kinematic_graph import graph as kgraph
from pipeline.robotics.mjcf import servo_rollout

REPEATS = 5
QUERIES = 40


def construction(rows: list[dict]) -> None:
    cfg = compose_config(["experiment=kinematic-graph/table1"])
    arm = kx.arm_of(cfg, "planar")
    for c_deg, t_res in ((1.0, 0.05), (0.5, 0.01)):
        graphs: list[kgraph.KinematicGraph] = []

        def build(c=c_deg, t=t_res, out=graphs) -> None:
            out.append(kgraph.build(arm, math.radians(c), t))

        timing = time_calls(f"KG {c_deg:g}°/{t_res:g} m", build, [()], warmup=1, repeats=REPEATS)
        s = timing.summary_us()
        what = f"planar 2R KG, {c_deg:g}°/{t_res:g} m ({graphs[-1].grid_nodes} nodes -> {graphs[-1].size} vertices)"
        rows.append({"what": what, "measure": "Algorithm 1, whole", "value": s["median_us"] / 1e3,
                     "p95": s["p95_us"] / 1e3, "unit": "ms", "paper": "not reported"})
        stages = {k: np.median([g.seconds[k] for g in graphs]) for k in graphs[-1].seconds}
        for stage, seconds in stages.items():
            rows.append({"what": what, "measure": f"stage {stage}", "value": seconds * 1e3, "unit": "ms"})


def searches(rows: list[dict], experiment: str, arm_name: str, boxes) -> None:
    cfg = compose_config([f"experiment=kinematic-graph/{experiment}"])
    world = kx.world_of(cfg, arm_name)
    scene = kx.scene_of(cfg, world, boxes, arm_name)
    queries = kx.random_queries(cfg, world, scene, QUERIES, cfg.seed)
    label = f"{experiment} ({world.kg.size} KG vertices, {world.grid.size} grid nodes)"
    for metric in ("cspace", "tspace", "manipulability"):
        for name, planner, blocked in (("KG", world.kg_planner, scene.blocked_kg),
                                       ("C-grid", world.grid_planner, scene.blocked_grid)):
            s = time_calls(name, lambda q, p=planner, b=blocked, m=metric: p.plan(m, q, b), [(q,) for q in queries],
                           warmup=3).summary_us()
            rows.append({"what": f"A* on the {name}, {metric}", "measure": f"per query, {label}",
                         "value": s["median_us"] / 1e3, "p95": s["p95_us"] / 1e3, "unit": "ms",
                         "paper": "not reported"})
    timings = time_interleaved({
        "KG": (lambda: scene.checker.blocked(world.kg, scene.margin), (), world.kg.size),
        "C-grid": (lambda: scene.checker.blocked(world.grid, scene.margin), (), world.grid.size)}, repeats=3)
    for name, t in timings.items():
        rows.append({"what": f"obstacles mapped into the {name} ({type(scene.checker).__name__})",
                     "measure": f"per vertex, {label}", "value": t.summary_us()["median_us"], "unit": "µs",
                     "goal": "KG total < grid total (Sec. 3.4)"})


def execution(rows: list[dict]) -> None:
    import mujoco

    cfg = compose_config(["experiment=kinematic-graph/spatial"])
    world = kx.world_of(cfg, "puma")
    boxes = kx.boxes_of(cfg.scenario.obstacles)
    scene = kx.scene_of(cfg, world, boxes, "puma")
    query = kx.showcase_query(cfg.scenario.showcase)
    _, joints, _, _ = kx.showcase_plan(world, scene, "tspace", query)
    e = cfg.execute
    ref = ex.timed_reference(joints, e.dt, e.speed, e.accel_fraction, e.settle)
    xml = ex.arm_xml("puma", world.node, boxes, joints[0], e.dt, e.bandwidth_hz, e.damping_ratio)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def bare() -> None:
        mujoco.mj_resetData(model, data)
        for _ in range(len(ref.times)):
            mujoco.mj_step(model, data)

    q_ref, qd_ref = ex.padded(ref, model.njnt)
    t_bare, t_servo = best_of(bare, 3), best_of(lambda: servo_rollout(xml, q_ref, qd_ref, ref.times), 3)
    what = f"MuJoCo PUMA 560, showcase plan ({ref.times[-1]:.1f} s at 1 kHz)"
    rows += [{"what": what, "measure": "bare mj_step loop", "value": t_bare / len(ref.times) * 1e6, "unit": "µs/step"},
             {"what": what, "measure": "servoed run (rollout)", "value": t_servo / len(ref.times) * 1e6,
              "unit": "µs/step"},
             {"what": what, "measure": "simulated seconds per wall second", "value": ref.times[-1] / t_servo,
              "unit": "s/s"}]


def benchmark() -> list[dict]:
    rows: list[dict] = []
    construction(rows)
    planar = compose_config(["experiment=kinematic-graph/search"])
    searches(rows, "search", "planar", kx.boxes_of(planar.scenario.obstacles))
    spatial = compose_config(["experiment=kinematic-graph/spatial"])
    searches(rows, "spatial", "puma", kx.boxes_of(spatial.scenario.obstacles))
    execution(rows)
    return rows

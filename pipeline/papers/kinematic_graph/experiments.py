"""Simulate stage of `kinematic-graph`: Table 1 and Sec. 3.2 (graph sizes), the A* searches of Secs. 3.3-3.4 on
the planar 2R (Figs. 2-5) against the plain C-grid A* and a T-space-only planner, and the spatial graph of Sec. 4.1
on a PUMA 560 in a cluttered MuJoCo scene (Fig. 6). Showcase plans are executed by a MuJoCo arm under a joint
servo. Every run logs what the analysis needs; the graphs themselves are rebuilt from the config in seconds."""

from __future__ import annotations

import functools
import itertools
import math
import time
from dataclasses import dataclass
from functools import cache

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import Timing, log_timings
from pipeline.papers.kinematic_graph import execution as ex
from pipeline.papers.kinematic_graph import graph as kgraph
from pipeline.papers.kinematic_graph.arms import RegionalArm
from pipeline.papers.kinematic_graph.collision import Boxes, MujocoChecker, PlanarChecker
from pipeline.papers.kinematic_graph.search import Plan, Planner, Query, Space, TaskSpacePlanner
from pipeline.robotics.mjcf import servo_rollout

KgSize = schemas.define(
    "KgSize", "One kinematic graph (Table 1): resolutions, C-grid and KG sizes, occupied voxels holding k clusters "
    "(clusters_per_voxel[k]); its construction time per stage is on /compute_time at the same log time.",
    c_res_rad="double rad", t_res_m="double m", jv="int64[] 1", grid_nodes="int64 1", grid_edges="int64 1",
    grid_edges_closed_form="int64 1", vertices="int64 1", edges="int64 1", occupied_voxels="int64 1",
    kg_components="int64 1", clusters_per_voxel="int64[] 1",
)
KgSearch = schemas.define(
    "KgSearch", "One A* query on one graph (kg, grid: the plain C-grid, tonly: the T-space voxels only). μ is in "
    "m^dims (dims = 2 planar: m^2, 3 spatial: m^3; declared where logged); costs in the metric's own unit (cspace: "
    "rad, tspace: m, manipulability: m^(2+dims), manipulability-admissible: m^(1+dims)); h_start: the heuristic "
    "at the start, optimal_cost: the cheapest path's cost (Dijkstra, KG only); lengths of the vertex path (q_i "
    "first) in m (task) and rad (joint); min_base_distance_m: closest approach of P_w to the base axis (z); "
    "collision_free: the joint path interpolated every dense_step is clear of every obstacle.",
    query="int64 1", graph="string", metric="string", found="bool", reason="string", vertices="int64 1",
    expanded="int64 1", met="int64 1", expansions="int64 1", explored_pct="double %", path_vertices="int64 1",
    cost="double metric's unit", h_start="double metric's unit", optimal_cost="double metric's unit",
    t_length_m="double m", c_length_rad="double rad", max_step_rad="double rad", min_mu="double q",
    mean_mu="double q", min_base_distance_m="double m", collision_free="bool", min_clearance_m="double m",
    seconds="double s",
)
MAX_QUERY_TRIES = 1000   # random start/goal draws per wanted pair before the scene is declared too cluttered


# -- config -> objects ---------------------------------------------------------------------------------------------


def arm_node(cfg: DictConfig, name: str) -> dict:
    return OmegaConf.to_container(cfg.system[name], resolve=True)


def arm_of(cfg: DictConfig, name: str) -> RegionalArm:
    return RegionalArm.from_config(name, arm_node(cfg, name))


def boxes_of(node) -> Boxes:
    return Boxes.from_config(OmegaConf.to_container(node, resolve=True))


@dataclass
class World:
    """The graphs of one arm at one resolution, with their planners; built once per experiment."""

    arm: RegionalArm
    node: dict
    kg: kgraph.KinematicGraph
    grid: kgraph.GridGraph
    kg_planner: Planner
    grid_planner: Planner
    tonly: TaskSpacePlanner
    mu_max: float
    build_seconds: float


@cache
def _world(arm_name: str, node_yaml: str, c_res: float, t_res: float, limit_factor: float) -> World:
    import yaml

    node = yaml.safe_load(node_yaml)
    arm = RegionalArm.from_config(arm_name, node)
    start = time.perf_counter()
    cgrid = kgraph.sample(arm, c_res)
    kg = kgraph.build(arm, c_res, t_res, cgrid)
    build_seconds = time.perf_counter() - start
    grid = kgraph.grid_graph(arm, c_res, t_res, cgrid)
    mu_max = float(grid.manipulability().max())   # μ_max of eqs. (11)-(12): the largest μ on the C-grid
    return World(arm, node, kg, grid, Planner(Space.of(kg, mu_max), limit_factor), Planner(Space.of(grid, mu_max),
                 limit_factor), TaskSpacePlanner(kg, limit_factor), mu_max, build_seconds)


def world_of(cfg: DictConfig, arm_name: str) -> World:
    import yaml

    return _world(arm_name, yaml.safe_dump(arm_node(cfg, arm_name)), math.radians(cfg.graph.c_res_deg),
                  float(cfg.graph.t_res), float(cfg.search.limit_factor))


class Scene:
    """Obstacles mapped into the graphs (Fig. 5: colliding vertices are removed before the search). The grid's
    mask, which costs one check per C-grid node, is made only when a benchmark asks for it."""

    def __init__(self, world: World, boxes: Boxes, checker: PlanarChecker | MujocoChecker, margin: float):
        self.world, self.boxes, self.checker, self.margin = world, boxes, checker, margin
        self.check_seconds: dict[str, float] = {}
        self.blocked_kg = self._timed("kg", lambda: checker.blocked(world.kg, margin))
        self.blocked_tonly = world.tonly.blocked(boxes, margin)

    def _timed(self, name: str, check) -> np.ndarray:
        start = time.perf_counter()
        mask = check()
        self.check_seconds[name] = time.perf_counter() - start
        return mask

    @functools.cached_property
    def blocked_grid(self) -> np.ndarray:
        return self._timed("grid", lambda: self.checker.blocked(self.world.grid, self.margin))


_SCENES: dict[tuple, Scene] = {}


def scene_of(cfg: DictConfig, world: World, boxes: Boxes, arm_name: str) -> Scene:
    """The scene of `boxes` in `world`, made once per process (the showcases share the benchmark's)."""
    key = (id(world), boxes.names, boxes.centre.tobytes(), boxes.half.tobytes(), float(cfg.search.margin))
    if key not in _SCENES:
        if world.arm.task_dims == 2:
            checker = PlanarChecker(world.arm, boxes)
        else:
            xml = ex.arm_xml(arm_name, world.node, boxes, np.zeros(world.arm.n), cfg.execute.dt,
                             cfg.execute.bandwidth_hz, cfg.execute.damping_ratio)
            checker = MujocoChecker(xml, ex.checked_links(world.node))
        _SCENES[key] = Scene(world, boxes, checker, float(cfg.search.margin))
    return _SCENES[key]


def random_queries(cfg: DictConfig, world: World, scene: Scene, count: int, seed: int) -> list[Query]:
    """Seeded start configurations and goal positions, both reached by a collision-free configuration, the goal in
    another voxel than the start."""
    rng = np.random.default_rng(seed)
    arm, queries = world.arm, []
    margin = float(cfg.search.margin)
    for _ in range(MAX_QUERY_TRIES * count):
        if len(queries) == count:
            return queries
        q = rng.uniform(arm.lower, arm.upper, (2, arm.n))
        if (scene.checker.min_clearance(q, margin) < margin).any():
            continue
        p = arm.position(q)
        voxels = kgraph.voxel_index(p, world.kg.t_res)
        if (voxels[0] == voxels[1]).all():
            continue
        queries.append(Query(q[0], p[1]))
    raise SimulationFailed(f"found only {len(queries)} collision-free start/goal pairs of {count} in "
                           f"{MAX_QUERY_TRIES * count} draws: the scene leaves too little free space")


# -- path evaluation ----------------------------------------------------------------------------------------------


def dense(path: np.ndarray, step: float) -> np.ndarray:
    """The joint path interpolated linearly with at most `step` (rad) between samples."""
    if len(path) < 2:
        return path
    pieces = [path[:1]]
    for a, b in itertools.pairwise(path):
        k = max(1, math.ceil(np.abs(b - a).max() / step))
        pieces.append(a + (b - a) * (np.arange(1, k + 1) / k)[:, None])
    return np.concatenate(pieces)


def joint_path(q_start: np.ndarray, plan: Plan, q: np.ndarray) -> np.ndarray:
    """q_i followed by the path vertices' configurations."""
    return np.vstack([q_start[None], q[plan.path]])


def path_record(world: World, scene: Scene, joints: np.ndarray | None, plan: Plan, graph: str, size: int,
                query_index: int, step: float, optimal_cost: float = float("nan")) -> dict:
    nan = float("nan")
    record = dict(query=query_index, graph=graph, metric=plan.metric, found=plan.found, reason=plan.reason,
                  vertices=size, expanded=plan.expanded, met=plan.met, expansions=plan.expansions,
                  explored_pct=plan.explored_pct(size), path_vertices=len(plan.path), cost=plan.cost,
                  h_start=plan.h_start, optimal_cost=optimal_cost, t_length_m=nan, c_length_rad=nan, max_step_rad=nan,
                  min_mu=nan, mean_mu=nan, min_base_distance_m=nan, collision_free=False, min_clearance_m=nan,
                  seconds=plan.seconds)
    if joints is None or not plan.found:
        return record
    arm = world.arm
    steps = np.diff(joints, axis=0)
    mu = arm.manipulability(joints[1:])
    # the path's clearance to the obstacles (NaN without obstacles): the dense joint path, not only its vertices
    clearance = float(scene.checker.min_clearance(dense(joints, step), 1.0).min()) if len(scene.boxes) else nan
    positions = arm.position(joints)
    record.update(t_length_m=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
                  min_base_distance_m=float(np.linalg.norm(positions[:, :2], axis=1).min()),
                  c_length_rad=float(np.linalg.norm(steps, axis=1).sum()),
                  max_step_rad=float(np.abs(steps).max()) if len(steps) else 0.0, min_mu=float(mu.min()),
                  mean_mu=float(mu.mean()), min_clearance_m=clearance, collision_free=not clearance < 0.0)
    return record


def mu_unit(arm: RegionalArm) -> str:
    """The unit of μ = sqrt(|J Jᵀ|) of the positional Jacobian (m per rad in each of `task_dims` rows)."""
    return f"m^{arm.task_dims}"


def log_records(log: RunWriter, topic: str, records: list[dict], arm: RegionalArm, spacing: float = 1e-3) -> None:
    """One KgSearch message per record, `spacing` s apart on the log's time axis (queries are a sequence)."""
    columns = {k: np.array([r[k] for r in records]) for k in records[0]}
    log.log_series(topic, np.arange(len(records)) * spacing, KgSearch,
                   field_units={"min_mu": mu_unit(arm), "mean_mu": mu_unit(arm)}, **columns)


# -- E1: Table 1 and Sec. 3.2 ------------------------------------------------------------------------------------


def table1(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    arm = arm_of(cfg, "planar")
    for c_deg in sc.c_res_deg:   # a grid too large for memory is refused before anything runs
        kgraph.check_size(arm, math.radians(c_deg))

    def simulate(log: RunWriter) -> None:
        records, stages = [], []
        for c_deg in sc.c_res_deg:
            c_res = math.radians(c_deg)
            sampled = kgraph.sample(arm, c_res)
            for t_res in sc.t_res:
                graph = kgraph.build(arm, c_res, t_res, sampled)
                components = kgraph.components(graph.size, graph.edges)
                histogram = np.bincount(graph.clusters_per_voxel())
                records.append(dict(
                    c_res_rad=c_res, t_res_m=float(t_res), jv=graph.jv, grid_nodes=graph.grid_nodes,
                    grid_edges=graph.grid_edges, grid_edges_closed_form=kgraph.grid_edge_count(graph.jv[0]),
                    vertices=graph.size, edges=len(graph.edges), occupied_voxels=graph.occupied_voxels,
                    kg_components=components, clusters_per_voxel=histogram.tolist()))
                stages.append(graph.seconds)
        for k, (record, seconds) in enumerate(zip(records, stages, strict=True)):
            t = k * 1e-3   # cell k of Table 1 at k ms: the cells are a sequence, not a trajectory
            log.log("/kg/size", t, KgSize, **record)
            log.log("/compute_time", t, name=list(seconds), seconds=list(seconds.values()), calls=[1] * len(seconds))
        # Sec. 3.2.1: the branching factor of the Moore grid, counted on a 3^dim grid, and |jv| at C_res = π
        dims = list(sc.branching_dims)
        degree = [int(np.bincount(kgraph.moore_edges((3,) * d).ravel()).max()) for d in dims]
        log.log("/kg/branching", 0.0, schemas.Scalars, units="1", name=[f"b.dim{d}" for d in dims] + ["jv.c_res_pi"],
                value=[*degree, len(kgraph.joint_values(-math.pi, math.pi, math.pi))])

    return [Case("table1", simulate)]


# -- E2, E3: searches (benchmarks) ---------------------------------------------------------------------------------


def _scene_record(world: World, scene: Scene) -> tuple[list[str], list[float], list[str]]:
    # the grid's mask is made (and timed) when first asked for, before its time is read
    values = {"kg.vertices": world.kg.size, "kg.edges": len(world.kg.edges), "kg.blocked": scene.blocked_kg.sum(),
              "kg.components": kgraph.components(world.kg.size, world.kg.edges),
              "grid.nodes": world.grid.size, "grid.edges": len(world.grid.edges),
              "grid.blocked": scene.blocked_grid.sum(), "tonly.voxels": world.tonly.space.size,
              "tonly.blocked": scene.blocked_tonly.sum(), "kg.build_seconds": world.build_seconds,
              "kg.check_seconds": scene.check_seconds["kg"], "grid.check_seconds": scene.check_seconds["grid"],
              "mu_max": world.mu_max}
    units = ["s" if name.endswith("_seconds") else mu_unit(world.arm) if name == "mu_max" else "1" for name in values]
    return list(values), [float(v) for v in values.values()], units


def benchmark_case(cfg: DictConfig, arm_name: str, boxes: Boxes, seed: int):
    """Seeded start/goal pairs; every metric on the KG and on the C-grid, and the T-space-only planner."""
    sc = cfg.search
    step = math.radians(sc.dense_step_deg)

    def simulate(log: RunWriter) -> None:
        world = world_of(cfg, arm_name)
        scene = scene_of(cfg, world, boxes, arm_name)
        names, values, units = _scene_record(world, scene)
        log.log("/kg/scene", 0.0, schemas.Scalars, units=units, name=names, value=values)
        queries = random_queries(cfg, world, scene, int(sc.pairs), seed)
        graphs = {"kg": (world.kg_planner, scene.blocked_kg, world.kg.q, list(sc.metrics)),
                  "grid": (world.grid_planner, scene.blocked_grid, world.grid.q, list(sc.baseline))}
        for planner, blocked, _, metrics in graphs.values():   # warm-up: load the compiled A*, build the edge costs
            for metric in metrics:
                planner.plan(metric, queries[0], blocked)
        records = []
        for k, query in enumerate(queries):
            for graph, (planner, blocked, q, metrics) in graphs.items():
                for metric in metrics:
                    plan = planner.plan(metric, query, blocked)
                    joints = joint_path(query.q_start, plan, q) if plan.found else None
                    optimal = planner.plan(metric, query, blocked, dijkstra=True).cost if graph == "kg" else np.nan
                    records.append(path_record(world, scene, joints, plan, graph, planner.space.size, k, step, optimal))
            if sc.tspace_only:
                plan, joints = world.tonly.plan(query, scene.blocked_tonly)
                records.append(path_record(world, scene, joints, plan, "tonly", world.tonly.space.size, k, step))
        log_records(log, "/kg/search", records, world.arm)
        n = world.arm.n
        names = [f"q_start.joint{j + 1}" for j in range(n)] + [f"goal.{a}" for a in "xyz"[: world.arm.task_dims]]
        log.log_series("/kg/query", np.arange(len(queries)) * 1e-3, schemas.Scalars, name=names,
                       units=["rad"] * n + ["m"] * world.arm.task_dims,
                       value=np.array([np.r_[q.q_start, q.goal] for q in queries]))
        seconds: dict[str, list[float]] = {}
        for r in records:
            seconds.setdefault(f"{r['graph']}.{r['metric']}", []).append(r["seconds"])
        log_timings(log, [Timing(name, np.array(s)) for name, s in seconds.items()])
        if len(boxes):
            log.write("/markers", 0, schemas.SceneUpdate(entities=ex.obstacle_geoms(boxes)))

    return simulate


# -- showcase plans, executed in MuJoCo ---------------------------------------------------------------------------

VERTEX_STATES = {"unvisited": 0, "queued": 1, "expanded": 2, "path": 3, "colliding": 4}   # the colours of Fig. 5


def showcase_plan(world: World, scene: Scene, metric: str, query: Query) -> tuple[Plan, np.ndarray, str, int]:
    """(plan, joint path q_i … vertices, graph name, graph size) of the KG planner, or of the T-space-only
    planner for metric `tspace-only`."""
    if metric == "tspace-only":
        plan, joints = world.tonly.plan(query, scene.blocked_tonly)
        if joints is None:
            raise SimulationFailed(f"the T-space-only plan failed: {plan.reason}")
        return plan, joints, "tonly", world.tonly.space.size
    plan = world.kg_planner.plan(metric, query, scene.blocked_kg, keep_masks=True)
    if not plan.found:
        raise SimulationFailed(f"no {metric} path on the KG: {plan.reason}")
    return plan, joint_path(query.q_start, plan, world.kg.q), "kg", world.kg.size


def showcase_case(cfg: DictConfig, arm_name: str, boxes: Boxes, query: Query, metric: str):
    """One query planned with one metric, post-processed and executed by the MuJoCo arm."""
    e = cfg.execute

    def simulate(log: RunWriter) -> None:
        world = world_of(cfg, arm_name)
        scene = scene_of(cfg, world, boxes, arm_name)
        arm, node = world.arm, world.node
        world.kg_planner.plan(metric if metric != "tspace-only" else "tspace", query, scene.blocked_kg)   # warm-up
        plan, joints, graph, size = showcase_plan(world, scene, metric, query)
        q_goal, reached = ex.ik_newton(arm, joints[-1], query.goal)
        waypoints = np.vstack([joints, q_goal[None]]) if reached else joints
        record = path_record(world, scene, joints, plan, graph, size, 0, math.radians(cfg.search.dense_step_deg))
        log_records(log, "/kg/search", [record], arm)
        log.log("/kg/goal", 0.0, schemas.Scalars, name=["ik_reached", "ik_error_m", "mu_max"],
                units=["bool", "m", mu_unit(arm)],
                value=[float(reached), float(np.linalg.norm(arm.position(q_goal) - query.goal)), world.mu_max])

        ref = ex.timed_reference(waypoints, e.dt, e.speed, e.accel_fraction, e.settle)
        xml = ex.arm_xml(arm_name, node, boxes, waypoints[0], e.dt, e.bandwidth_hz, e.damping_ratio)
        log.attach("model.xml", xml, "application/xml")
        states, sensors = servo_rollout(xml, *ex.padded(ref, len(node["dh"]["a"])), ref.times)
        log_execution(log, cfg, world, MujocoChecker(xml, ex.checked_links(node)) if len(boxes) else None, node, ref,
                      states, sensors, query)

        path_q = joints[1:]
        t_path = ref.arrival[1: len(joints)]
        dims = arm.task_dims
        vertex_ids = plan.path if graph == "kg" else np.arange(len(path_q))
        log.log_series("/kg/path", t_path, schemas.Scalars,
                       units=["1", *["rad"] * arm.n, *["m"] * dims, mu_unit(arm)],
                       name=["vertex", *(f"q.joint{j + 1}" for j in range(arm.n)), *(f"pos.{a}" for a in "xyz"[:dims]),
                             "mu"],
                       value=np.column_stack([vertex_ids, path_q, arm.position(path_q), arm.manipulability(path_q)]))
        if graph == "kg":
            state = np.zeros(world.kg.size)
            state[plan.met_mask] = VERTEX_STATES["queued"]
            state[plan.expanded_mask] = VERTEX_STATES["expanded"]
            state[plan.path] = VERTEX_STATES["path"]
            state[scene.blocked_kg] = VERTEX_STATES["colliding"]
            kg = world.kg
            log.log_series("/kg/vertices", np.zeros(kg.size), schemas.Scalars,
                           units=[*["m"] * dims, *["rad"] * arm.n, mu_unit(arm), "1", "1"],
                           name=[*(f"pos.{a}" for a in "xyz"[:dims]), *(f"q.joint{j + 1}" for j in range(arm.n)),
                                 "mu", "members", "state"],
                           value=np.column_stack([kg.pos, kg.q, world.kg_planner.space.mu, kg.members, state]))
        planned = arm.points(waypoints)[:, -1]
        # the arm is the attached model's (robot.urdf, drawn from /joint_state); the obstacles, world geoms of that
        # model, are scene entities too, as in the benchmark runs
        log.write("/markers", 0, schemas.SceneUpdate(entities=[
            markers.line_strip("plan", planned, thickness=0.006, color=(0.85, 0.1, 0.1, 1.0)),
            *markers.spheres(["goal"], [0.02], [(0.1, 0.7, 0.2, 1.0)]),
            *(ex.obstacle_geoms(boxes) if len(boxes) else [])]))

    return simulate


def log_execution(log: RunWriter, cfg: DictConfig, world: World, checker: MujocoChecker | None, node: dict,
                  ref: ex.Reference, states: np.ndarray, sensors: np.ndarray, query: Query) -> None:
    """The servoed run every `execute.log_dt`: joints, reference, torque, joint and P_w errors, /tf, and the
    clearance of the executed and the reference motion to each obstacle, measured by MuJoCo (mj_geomDistance)."""
    from pipeline.robotics import dh as dhk

    e, arm = cfg.execute, world.arm
    n_all = len(node["dh"]["a"])
    names = [f"joint{j + 1}" for j in range(n_all)]
    every = slice(None, None, max(1, round(e.log_dt / e.dt)))
    times = (ref.times + e.dt)[every]           # rollout returns the state after each step
    q = states[every, 1: 1 + n_all]
    qd = states[every, 1 + n_all: 1 + 2 * n_all]
    tau = sensors[every, :n_all]
    q_ref, qd_ref = (x[every] for x in ex.padded(ref, n_all))
    if not np.isfinite(q).all():
        raise SimulationFailed("the servoed arm's state is not finite")
    # every joint of the DH arms is revolute
    log.log_series("/joint_state", times, units="rad", name=names, position=q, velocity=qd, effort=tau)
    log.log_series("/reference", times, units="rad", name=names, position=q_ref, velocity=qd_ref)
    log.log_series("/command", times, units="rad", kind="torque", name=names, value=tau)
    err = q_ref - q
    log.log_series("/tracking_error", times, units="rad", name=names, error=err, norm=np.linalg.norm(err, axis=1))
    axes = list("xyz"[: arm.task_dims])
    p_err = arm.position(q_ref[:, : arm.n]) - arm.position(q[:, : arm.n])
    log.log_series("/tracking_error/pw", times, units="m", name=axes, error=p_err, norm=np.linalg.norm(p_err, axis=1))
    if checker is not None:
        executed = checker.clearance(q[:, : arm.n])
        reference = checker.clearance(q_ref[:, : arm.n])
        labels = [f"{kind}.{o}" for kind in ("executed", "reference") for o in checker.obstacle_names]
        log.log_series("/clearance", times, schemas.Scalars, units="m", name=[*labels, "executed.min", "reference.min"],
                       value=np.column_stack([executed, reference, executed.min(axis=1), reference.min(axis=1)]))
    tf = slice(None, None, max(1, round(e.tf_dt / e.dt)))
    t_tf = (ref.times + e.dt)[tf]
    frames = dhk.frames(dhk.DH.from_config(node["dh"]), states[tf, 1: 1 + n_all])[:, 1:]
    pw = np.tile(np.eye(4), (len(t_tf), 1, 1))
    pw[:, :3, 3] = arm.points(states[tf, 1: 1 + arm.n])[:, -1]
    goal = np.tile(np.eye(4), (len(t_tf), 1, 1))
    goal[:, : arm.task_dims, 3] = query.goal
    log.log_transforms(t_tf, "world", [*(f"link{i + 1}" for i in range(n_all)), "pw", "goal"],
                       np.concatenate([frames, pw[:, None], goal[:, None]], axis=1))


def showcase_query(node) -> Query:
    return Query(np.radians(np.asarray(node.q_start_deg, dtype=float)), np.asarray(node.goal, dtype=float))


def search(cfg: DictConfig) -> list[Case]:
    """Secs. 3.3-3.4, Figs. 2-5, on the planar 2R."""
    sc = cfg.scenario
    kgraph.check_size(arm_of(cfg, "planar"), math.radians(cfg.graph.c_res_deg))
    cases = []
    for k, scene_name in enumerate(sc.scenes):
        boxes = boxes_of(sc.obstacles) if scene_name == "obstacle" else Boxes.none()
        cases.append(Case(f"benchmark-{scene_name}", benchmark_case(cfg, "planar", boxes, cfg.seed + k)))
        if scene_name in sc.showcase:
            query = showcase_query(sc.showcase[scene_name])
            metrics = [*sc.showcase_metrics] + (["tspace-only"] if len(boxes) and cfg.search.tspace_only else [])
            cases += [Case(f"{scene_name}-{m}", showcase_case(cfg, "planar", boxes, query, m)) for m in metrics]
    return cases


def spatial(cfg: DictConfig) -> list[Case]:
    """Sec. 4.1, Fig. 6: the regional structure of a PUMA 560 in a cluttered cell, collisions by MuJoCo."""
    sc = cfg.scenario
    kgraph.check_size(arm_of(cfg, "puma"), math.radians(cfg.graph.c_res_deg))
    boxes = boxes_of(sc.obstacles)
    cases = [Case("benchmark", benchmark_case(cfg, "puma", boxes, cfg.seed))]
    query = showcase_query(sc.showcase)
    cases += [Case(m, showcase_case(cfg, "puma", boxes, query, m)) for m in sc.showcase_metrics]
    return cases

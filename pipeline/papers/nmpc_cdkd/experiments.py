"""Simulate stage of `nmpc-cdkd`: Table 3 (compute time), Fig. 3 (tracking), Figs. 4-5 (fixed obstacles) and
Figs. 6-7 (moving obstacles). Every run logs the joints, references, errors, obstacle clearances and one record
per OCP solve (wall time, IPOPT iterations and status), so the analysis can rebuild the paper's tables and figures."""

from __future__ import annotations

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import MODEL_ATTACHMENT, RunWriter, seconds_to_ns
from pipeline.core.timing import log_timings, time_calls
from pipeline.papers.nmpc_cdkd import kinematics as kin
from pipeline.papers.nmpc_cdkd import planning
from pipeline.papers.nmpc_cdkd.kinematics import JOINTS, Arm
from pipeline.papers.nmpc_cdkd.nmpc import Nmpc, OcpSettings
from pipeline.papers.nmpc_cdkd.plant import KinematicPlant, MujocoPlant, model_xml
from pipeline.papers.nmpc_cdkd.simulation import Controller, Move, Obstacles, Start, Trajectory, closed_loop, run

XYZ = ["x", "y", "z"]
OBSTACLE_RGBA = (0.85, 0.25, 0.2, 0.6)
PLANNING_REPEATS = 20

NmpcSolve = schemas.define(
    "NmpcSolve", "One OCP solve of an NMPC: wall time, CasADi's own total, IPOPT iterations, status and cost; "
    "the move it belongs to and whether it is in the timing statistic (a probe's first solve is not).",
    model="string", seconds="double s", solver_seconds="double s", iterations="uint32 1", success="bool",
    status="string", cost="double 1", move="uint32 1", timed="bool",
)


# -- config -> objects -------------------------------------------------------------------------------------


def arm_of(cfg: DictConfig) -> Arm:
    return Arm.from_config(OmegaConf.to_container(cfg.system, resolve=True))


def controller_of(cfg: DictConfig) -> Controller:
    s = cfg.system
    return Controller(dt=s.dt, control_steps=s.nmpc.control_steps, gain=np.asarray(s.orientation.gain, dtype=float),
                      desired_from=s.orientation.desired_from, warm_start=s.nmpc.warm_start,
                      obstacle_prediction=s.nmpc.obstacle_prediction, on_failure=s.nmpc.on_failure,
                      initial_state=s.nmpc.initial_state,
                      sample_dt=s.planning.sample_dt, wrist_band=s.planning.wrist_band)


_SOLVERS: dict[tuple, Nmpc] = {}   # built NLPs by (settings, arm): the jobs of a sweep that a worker process
#                                   runs one after another (Table 3's seeds) reuse them (~5 s for all twelve)


def nmpc_of(cfg: DictConfig, arm: Arm, model: str, horizon_steps: int, obstacles: int, band: bool) -> Nmpc:
    s = cfg.system
    settings = OcpSettings(
        model=model, horizon_steps=horizon_steps, dt=s.dt, mu=tuple(s.nmpc.mu), length_unit=s.nmpc.length_unit,
        acceleration=s.joint_limits.acceleration, jerk=s.joint_limits.jerk, obstacles=obstacles, height_band=band,
        integrator=s.nmpc.integrator, cost_quadrature=s.nmpc.cost_quadrature,
        orientation_lever=s.full.orientation_lever, tol=s.nmpc.tol,
        acceptable_obj_change_tol=s.nmpc.acceptable_obj_change_tol, max_iter=s.nmpc.max_iter)
    key = (settings, b"".join(np.asarray(a, dtype=float).tobytes() for a in (
        arm.dh.a, arm.dh.alpha, arm.dh.d, arm.dh.theta_offset, arm.wrist_dh.a, arm.wrist_dh.d, arm.base, arm.tool,
        arm.lower, arm.upper, arm.velocity)))
    if key not in _SOLVERS:
        _SOLVERS[key] = Nmpc(arm, settings)
    return _SOLVERS[key]


def tool_pose(cfg: DictConfig, position) -> np.ndarray:
    """Tool pose at `position` with the scene's orientation (tool pointing down)."""
    T = np.eye(4)
    T[:3, :3] = np.diag(cfg.system.scene.tool_axes)
    T[:3, 3] = position
    return T


def scene_obstacles(cfg: DictConfig, velocities) -> Obstacles:
    sc = cfg.system.scene
    radii = np.asarray(sc.obstacles.radii, dtype=float)
    xy = np.asarray(sc.obstacles.xy, dtype=float)
    return Obstacles(np.column_stack([xy, sc.ground_z + radii]), np.asarray(velocities, dtype=float), radii)


def plant_factory(cfg: DictConfig, arm: Arm, obstacles: Obstacles, log: RunWriter | None):
    """q0 -> plant; the MuJoCo model (generated at q0) is attached to the run."""
    p = cfg.system.plant

    def make(q0: np.ndarray):
        if p.kind == "kinematic":
            return KinematicPlant(q0)
        xml = model_xml(arm, p, cfg.system.dt, q0, obstacles.radii)
        if log is not None:
            log.attach("model.xml", xml, "application/xml")
        return MujocoPlant(xml, cfg.system.dt, q0, len(obstacles))

    return make


# -- logging -----------------------------------------------------------------------------------------------


def _segment_clearance(wrist: np.ndarray, tip: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(n, ν) distance from the tool segment [wrist point, tool tip] to each sphere's surface."""
    d = (tip - wrist)[:, None, :]
    s = np.clip(np.sum((centres - wrist[:, None, :]) * d, axis=-1) / np.sum(d * d, axis=-1), 0.0, 1.0)
    closest = wrist[:, None, :] + s[..., None] * d
    return np.linalg.norm(centres - closest, axis=-1) - radii


def log_trajectory(log: RunWriter, arm: Arm, tr: Trajectory, model: str, obstacles: Obstacles,
                   names: list[str], offset: float = 0.0, move: int = 0, untimed: int = 0) -> None:
    """Write one closed-loop move (or a probe of one); `offset` (s) places it after earlier ones of the same
    run; the first `untimed` solves are left out of the timing statistic."""
    t = tr.t + offset
    efforts = {"effort": tr.effort} if np.isfinite(tr.effort).all() else {}  # a kinematic plant has none
    log.log_series("/joint_state", t, units="rad", name=JOINTS, position=tr.q, velocity=tr.qd, **efforts)
    log.log_series("/command", t, units="rad", kind="position", name=JOINTS, value=tr.q_cmd)
    log.log_series("/command/velocity", t, units="rad", kind="velocity", name=JOINTS, value=tr.qd_cmd)
    log.log_series("/reference", t, units="rad", name=JOINTS, position=tr.q_ref, velocity=tr.qd_ref)
    F, F_ref = kin.frames(arm, tr.q), kin.frames(arm, tr.q_ref)
    tip, tip_ref = (F @ arm.tool)[:, -1, :3, 3], (F_ref @ arm.tool)[:, -1, :3, 3]
    wrist, wrist_ref = F[:, 4, :3, 3], F_ref[:, 4, :3, 3]
    log.log_series("/reference/tool", t, units="m", name=XYZ, position=tip_ref)
    log.log_series("/reference/wrist", t, units="m", name=XYZ, position=wrist_ref)
    for topic, err, unit in (("/tracking_error", tip_ref - tip, "m"), ("/tracking_error/wrist", wrist_ref - wrist, "m"),
                             ("/tracking_error/orientation", tr.orientation_error, "rad")):
        log.log_series(topic, t, units=unit, name=XYZ, error=err, norm=np.linalg.norm(err, axis=1))
    seconds = np.array([s.seconds for s in tr.solves])
    timed = np.arange(len(seconds)) >= untimed
    log.log_series("/compute_time", tr.solve_t[timed] + offset, name=[model], calls=[1],
                   seconds=seconds[timed, None])
    log.log_series("/nmpc/solve", tr.solve_t + offset, NmpcSolve, model=model, seconds=seconds,
                   solver_seconds=np.array([s.solver_seconds for s in tr.solves]),
                   iterations=np.array([s.iterations for s in tr.solves]),
                   success=np.array([s.success for s in tr.solves]),
                   status=np.array([s.status for s in tr.solves]), cost=np.array([s.cost for s in tr.solves]),
                   move=np.full(len(seconds), move), timed=timed)
    sel = tr.selection
    log.log("/planning", float(t[0]), schemas.Scalars, units=["s", "rad", "1", "1"],
            name=["seconds", "margin", "candidates", "jump_free"],
            value=[tr.planning_seconds, sel.margin, sel.candidates, sel.jump_free])
    frames = [F[:, i] for i in range(1, 7)] + [F[:, 6] @ arm.tool]
    children = [f"link{i}" for i in range(1, 7)] + ["tool"]
    if len(obstacles):
        centres = tr.centres
        safety = obstacles.radii + arm.safety_radius
        margin = np.linalg.norm(wrist[:, None, :] - centres, axis=-1) - safety
        commanded = np.linalg.norm(kin.wrist_point(arm, tr.q_cmd[:, :3])[:, None, :] - centres, axis=-1) - safety
        columns = [margin, commanded, _segment_clearance(wrist, tip, centres, obstacles.radii)]
        labels = [f"{kind}.{n}" for kind in ("margin", "command_margin", "tool") for n in names]
        if tr.tool_distance is not None:
            columns.append(tr.tool_distance)
            labels += [f"mujoco.{n}" for n in names]
        log.log_series("/clearance", t, schemas.Scalars, units="m", name=labels, value=np.concatenate(columns, axis=1))
        log.log_series("/obstacles", t, schemas.Scalars, units="m", name=[f"{n}.{a}" for n in names for a in XYZ],
                       value=centres.reshape(len(t), -1))
        poses = np.tile(np.eye(4), (len(t), len(names), 1, 1))
        poses[..., :3, 3] = centres
        frames += [poses[:, i] for i in range(len(names))]
        children += [f"obstacle/{n}" for n in names]
        log.write("/markers", seconds_to_ns(t[0]), schemas.SceneUpdate(entities=markers.spheres(
            [f"obstacle/{n}" for n in names], obstacles.radii, [OBSTACLE_RGBA] * len(names))))
    log.log_transforms(t, "world", children, np.stack(frames, axis=1))
    if log.model_xml is not None:  # the MuJoCo plant: draw the arm and its mocap obstacles as simulated
        log.log_robot(t, tr.q, mocap_pos=tr.centres if len(obstacles) else None)


# -- E2-E4: the scene of Figs. 2-7 ------------------------------------------------------------------------


def _scene_case(cfg: DictConfig, model: str, obstacles: Obstacles, band: tuple[float, float] | None):
    sc = cfg.scenario
    arm = arm_of(cfg)
    move = Move(tool_pose(cfg, sc.start), tool_pose(cfg, sc.goal), sc.t0, sc.t1 - sc.t0, sc.duration, obstacles, band)
    names = list(cfg.system.scene.obstacles.names)[:len(obstacles)]

    def simulate(log: RunWriter) -> None:
        # what this case simulated (a case may change the experiment's config, e.g. the rod length)
        log.attach("case_config.yaml", OmegaConf.to_yaml(cfg, resolve=True), "application/yaml")
        nmpc = nmpc_of(cfg, arm, model, cfg.system.nmpc.horizon_steps, len(obstacles), band is not None)
        ctl = controller_of(cfg)
        tr = run(arm, nmpc, ctl, move, plant_factory(cfg, arm, obstacles, log))
        log_trajectory(log, arm, tr, model, obstacles, names)
        # Sec. 4.2 times the planning ("approximately 1 ms"): warm, repeated, like every compute time here
        plan = time_calls("planning", planning.select_configuration,
                          [(arm, move.T_start, move.T_goal, round(move.T / ctl.sample_dt) + 1, ctl.wrist_band)],
                          warmup=3, repeats=PLANNING_REPEATS)
        log_timings(log, [plan])

    return simulate


def tracking(cfg: DictConfig) -> list[Case]:
    cases = []
    z_e = np.diag(cfg.system.scene.tool_axes)[:, 2]
    for d_e in cfg.scenario.tool_lengths:
        # another rod length moves the tool points along the tool axis, so the wrist path stays the same
        shift = -(cfg.system.dh.tool_d - d_e) * z_e
        tool_cfg = OmegaConf.merge(cfg, {"system": {"dh": {"tool_d": d_e}},
                                         "scenario": {"start": (np.asarray(cfg.scenario.start) + shift).tolist(),
                                                      "goal": (np.asarray(cfg.scenario.goal) + shift).tolist()}})
        suffix = "" if d_e == cfg.system.dh.tool_d else f"-de{d_e * 1e3:g}mm"
        cases += [Case(model + suffix, _scene_case(tool_cfg, model, Obstacles.none(), None))
                  for model in cfg.scenario.models]
    return cases


def fixed_obstacles(cfg: DictConfig) -> list[Case]:
    lower, upper = cfg.system.scene.band
    obstacles = scene_obstacles(cfg, np.zeros((len(cfg.system.scene.obstacles.radii), 3)))
    bands = {"a": (lower, np.inf), "b": (lower, upper)}
    return [Case(case, _scene_case(cfg, "decomposed", obstacles, bands[case])) for case in cfg.scenario.cases]


def moving_obstacles(cfg: DictConfig) -> list[Case]:
    band = tuple(cfg.system.scene.band)
    return [Case(case, _scene_case(cfg, "decomposed", scene_obstacles(cfg, cfg.scenario.velocity[case]), band))
            for case in cfg.scenario.cases]


# -- E1: Table 3 -------------------------------------------------------------------------------------------


def random_moves(cfg: DictConfig, arm: Arm) -> list[dict]:
    """The seeded point-to-point moves of E1, each with its obstacle and height band (same for every run)."""
    sc, rng = cfg.scenario, np.random.default_rng(cfg.seed)
    samples = lambda T: round(T / cfg.system.planning.sample_dt) + 1  # noqa: E731 (jump-check samples)
    limits = cfg.system.joint_limits
    safety = sc.obstacle.radius + arm.safety_radius
    moves = []
    while len(moves) < sc.moves:
        z = rng.uniform(*sc.tool_z)
        phi = rng.uniform(-np.pi, np.pi)
        phi_goal = phi + rng.choice([-1, 1]) * rng.uniform(*sc.azimuth_change)
        ends = [tool_pose(cfg, [0, 0, z]) for _ in range(2)]
        for T, a in zip(ends, (phi, phi_goal), strict=True):
            rho = rng.uniform(*sc.wrist_radius)
            T[:2, 3] = rho * np.cos(a), rho * np.sin(a)
        try:
            sel = planning.select_configuration(arm, ends[0], ends[1], samples(sc.min_transition_time),
                                                cfg.system.planning.wrist_band)
        except ValueError:
            continue
        T = planning.transition_time(sel.q_start, sel.q_goal, arm.velocity, limits.acceleration, limits.jerk,
                                     cfg.system.planning.limit_margin, sc.min_transition_time)
        mid = kin.wrist_point(arm, planning.JointPolynomial(sel.q_start, sel.q_goal, 0.0, T)(np.array([T / 2]))[0, :3])
        inward = -np.r_[mid[:2], 0.0] / np.linalg.norm(mid[:2])
        centre = mid + safety * (sc.obstacle.offset * inward - np.array([0, 0, sc.obstacle.drop]))
        ends_wrist = np.array([kin.wrist_target(arm, T_end) for T_end in ends])
        if np.linalg.norm(ends_wrist - centre, axis=1).min() < safety + sc.obstacle.clearance:
            continue
        z_wrist = ends_wrist[0, 2]
        moves.append({"T_start": ends[0], "T_goal": ends[1], "T": T, "selection": sel, "centre": centre,
                      "band": (z_wrist + sc.height_band[0], z_wrist + sc.height_band[1])})
    return moves


def _case_setup(cfg: DictConfig, m: dict, case: str) -> tuple[Obstacles, tuple[float, float] | None]:
    """The obstacle and height band of a Table 3 case for move `m`."""
    with_obstacle, with_band = case != "no-obstacle", case == "obstacle-height"
    obstacles = (Obstacles(m["centre"][None], np.zeros((1, 3)), np.array([cfg.scenario.obstacle.radius]))
                 if with_obstacle else Obstacles.none())
    return obstacles, m["band"] if with_band else None


def _move_of(cfg: DictConfig, m: dict, case: str) -> Move:
    sc = cfg.scenario
    obstacles, band = _case_setup(cfg, m, case)
    return Move(m["T_start"], m["T_goal"], sc.t0, m["T"], sc.t0 + m["T"] + sc.settle, obstacles, band)


def feasible_path(arm: Arm, q_ref: np.ndarray, obstacles: Obstacles, band: tuple[float, float] | None,
                  inside: float) -> np.ndarray:
    """(n, 6) joints that follow the reference γ but keep the wrist point `inside` (m) within the constraints of
    a Table 3 case: the wrist height clipped into the band (10g), then pushed out of the obstacle's safety
    sphere (10f): radially without a band; with one, up as far as the band allows, then horizontally; the tool
    keeps the reference's orientation (IK branch of the reference). Where a closed loop would be when its
    reference runs into a constraint, so the OCPs sampled on it meet their constraints active, as in the loop."""
    wrist_ref = kin.wrist_point(arm, q_ref[:, :3])
    wrist = wrist_ref.copy()
    if band is not None:
        wrist[:, 2] = np.clip(wrist[:, 2], band[0] + inside, band[1] - inside)
    for centre, radius in zip(obstacles.centres, obstacles.radii + arm.safety_radius + inside, strict=True):
        away = wrist - centre
        if band is None:
            distance = np.linalg.norm(away, axis=1)
            push = distance < radius
            wrist[push] = centre + away[push] * (radius / distance[push])[:, None]
        else:
            inside_sphere = np.linalg.norm(away, axis=1) < radius
            top = band[1] - inside
            wrist[inside_sphere, 2] = np.maximum(wrist[inside_sphere, 2], min(top, centre[2] + radius))
            away = wrist - centre
            horizontal = np.linalg.norm(away[:, :2], axis=1)
            reach = np.sqrt(np.maximum(radius ** 2 - away[:, 2] ** 2, 0.0))
            push = horizontal < reach
            wrist[push, :2] = centre[:2] + away[push, :2] * (reach[push] / horizontal[push])[:, None]
    q = q_ref.copy()
    moved = np.flatnonzero(np.linalg.norm(wrist - wrist_ref, axis=1) > 0)
    tool = kin.tool_pose(arm, q_ref[moved])
    for i, T, p in zip(moved, tool, wrist[moved], strict=True):
        T = T.copy()
        T[:3, 3] += p - kin.wrist_target(arm, T)          # the same tool orientation, its wrist point at p
        branches = kin.ik(arm, T)
        gap = np.abs(kin.wrap(branches - q_ref[i])).max(axis=1)
        if np.isfinite(gap).any():                          # else out of reach: the reference stays
            q[i] = q_ref[i] + kin.wrap(branches[np.nanargmin(gap)] - q_ref[i])
    return q


def _probe_start(cfg: DictConfig, arm: Arm, m: dict, case: str, k: int, tick: int) -> Start:
    """The state at robot update `tick` on the feasible path of move `m` (two updates before, k after)."""
    sc, dt = cfg.scenario, cfg.system.dt
    move = _move_of(cfg, m, case)
    poly = planning.JointPolynomial(m["selection"].q_start, m["selection"].q_goal, sc.t0, m["T"])
    ticks = np.arange(tick - 2, tick + k + 1)
    path = feasible_path(arm, poly(np.maximum(ticks, 0) * dt), move.obstacles, move.band, sc.probe_inside)
    rates = np.diff(path, axis=0) / dt                     # rates[i]: from update ticks[i] to ticks[i + 1]
    return Start(tick=tick, q=path[2], u_prev=rates[[1, 0]], guess_q=path[2:], guess_u=rates[2:])


def _moves_loop(cfg: DictConfig, arm: Arm, moves: list[dict], model: str, case: str, k: int):
    """One (model, case, horizon) over all moves, pausing after every OCP solve; returns (move index,
    trajectory, obstacles, untimed solves). `scenario.sampling=closed-loop`: every OCP of every move's closed
    loop; `states`: at `scenario.samples_per_move` updates drawn along each move, the OCP the closed loop solves
    there, timed after a probe of `scenario.probe_solves - 1` OCPs that starts that many control horizons
    earlier on the feasible path (the first cold, guessed from that path; each next one from the previous
    plan's prediction, guessed from its solution shifted, as in the loop)."""
    sc = cfg.scenario
    obstacles_of = lambda m: _case_setup(cfg, m, case)[0]  # noqa: E731
    nmpc = nmpc_of(cfg, arm, model, k, int(case != "no-obstacle"), case == "obstacle-height")
    ctl = controller_of(cfg)
    trajectories = []
    for index, m in enumerate(moves):
        move, plant = _move_of(cfg, m, case), plant_factory(cfg, arm, obstacles_of(m), None)
        if sc.sampling == "closed-loop":
            tr = yield from closed_loop(arm, nmpc, ctl, move, plant, m["selection"])
            trajectories.append((index, tr, move.obstacles, 0))
            continue
        for tick in m["ticks"]:   # the probe starts `probe_solves - 1` OCPs before the timed one
            first = max(0, tick - (sc.probe_solves - 1) * ctl.control_steps)
            start = _probe_start(cfg, arm, m, case, k, first)
            solves = (tick - first) // ctl.control_steps + 1
            tr = yield from closed_loop(arm, nmpc, ctl, move, plant, m["selection"], start, solves=solves)
            trajectories.append((index, tr, move.obstacles, solves - 1))
    return trajectories


def compute_time(cfg: DictConfig) -> list[Case]:
    """One run per (model, case, horizon). All of them are simulated together, on the first run's turn: the
    closed loops advance one OCP solve each in turn (like `time_interleaved`), so a change of load on a shared
    machine falls on every combination alike and the ratios of Table 3 stay fair. Every combination sees the
    same moves and, with `scenario.sampling=states`, the same sampled updates (a paired design)."""
    sc = cfg.scenario
    arm = arm_of(cfg)
    combos = [(model, case, k) for model in sc.models for case in sc.cases for k in sc.horizons]
    results: dict[tuple, list] = {}

    def simulate_all() -> None:
        moves = random_moves(cfg, arm)
        cs = cfg.system.nmpc.control_steps
        for index, m in enumerate(moves):   # the OCP updates of the move's closed loop, sampled
            updates = np.arange(0, round((sc.t0 + m["T"] + sc.settle) / cfg.system.dt) - cs, cs)
            rng = np.random.default_rng([cfg.seed, index])
            m["ticks"] = np.sort(rng.choice(updates, size=min(sc.samples_per_move, len(updates)), replace=False))
        active = {combo: _moves_loop(cfg, arm, moves, *combo) for combo in combos}
        while active:
            for combo, loop in list(active.items()):
                try:
                    next(loop)
                except StopIteration as done:
                    results[combo] = done.value
                    del active[combo]

    def simulate(log: RunWriter, combo: tuple) -> None:
        if not results:
            simulate_all()
        model, case, k = combo
        dimensions = nmpc_of(cfg, arm, model, k, int(case != "no-obstacle"), case == "obstacle-height").dimensions()
        log.log("/nmpc/problem", 0.0, schemas.Scalars, units="1", name=list(dimensions),
                value=[float(v) for v in dimensions.values()])
        _, first, obstacles, _ = results[combo][0]  # the arm drawn (moves of a case have the same obstacles)
        log.attach(MODEL_ATTACHMENT, model_xml(arm, cfg.system.plant, cfg.system.dt, first.q[0], obstacles.radii),
                   "application/xml")
        offset = 0.0
        for index, tr, obstacles, untimed in results[combo]:
            log_trajectory(log, arm, tr, combo[0], obstacles, ["obstacle"], offset - float(tr.t[0]), index, untimed)
            offset += float(tr.t[-1] - tr.t[0]) + cfg.system.dt

    return [Case(f"{model}-{case}-k{k}", lambda log, c=(model, case, k): simulate(log, c), shares_work=True)
            for model, case, k in combos]

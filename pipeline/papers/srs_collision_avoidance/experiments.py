"""Simulate stage of `srs-collision-avoidance`: the circle task of Sec. 5 with and without avoidance and the
printed/exact/unfiltered variants, each replayed in MuJoCo (`circle`); the filter pole swept (`ablation`, planned
motion drawn without a replay); the per-iteration compute time of Algorithm 1 (`compute-time`)."""

from __future__ import annotations

import dataclasses

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import log_timings, time_calls
from pipeline.papers.srs_collision_avoidance import clearance, mujoco_replay, planner, swivel_filter
from pipeline.papers.srs_collision_avoidance.avoidance import CASES, Forms, SafetyVolume
from pipeline.papers.srs_collision_avoidance.humans import HumanArms
from pipeline.papers.srs_collision_avoidance.kinematics import JOINTS, Geometry, Unreachable, fk, ik, link_frames, pose
from pipeline.robotics.transforms import rotation_angle

LINK_FRAMES = [*(f"link{i}" for i in range(1, 8)), "tool"]
WORLD_BASE = pose(mujoco_replay.R_WORLD_BASE, np.zeros(3))   # the paper's y-up base in the z-up world
XYZ = ["x", "y", "z"]
# what each case of `scenario.cases` changes in the configured algorithm
VARIANTS = {
    "no-avoid": {"avoidance": False},
    "avoid": {},
    "avoid-unfiltered": {"filter": None},
    "avoid-printed": {"forms": {"link_checks": "elseif", "d_m2": "printed", "sphere_distance": "printed"}},
    "avoid-exact": {"forms": {"alpha_c": "exact"}},
    "avoid-capsules": {"obstacle": "capsules"},
}

Avoidance = schemas.define(
    "SrsAvoidance", "Algorithm 1 at one sample: the nearest obstacle point P_c, the point of the chain under "
    "imminent collision P_col (NaN if none) and the distances, all in the base frame (y up), at the α = 0 posture.",
    case="string", find="bool", d_mc_m="double m", actual_distance_m="double m", side_g_m3="double m^3",
    p_c_m="double[] m", p_col_m="double[] m", obstacle_distance_m="double m", obstacle_capsule="uint32 1",
)
Swivel = schemas.define(
    "SrsSwivel", "The swivel angle of Algorithm 1 at one sample: computed α_c, filtered α_f, and α_f's first and "
    "second differences over T (the paper's Figs. 8-9).",
    alpha_c_rad="double rad", alpha_f_rad="double rad", alpha_f_rate_rad_s="double rad/s",
    alpha_f_acceleration_rad_s2="double rad/s^2",
)
Distances = schemas.define(
    "SrsDistances", "Signed distances per named pair (m): negative inside the safety volume, or overlapping.",
    name="string[]", distance_m="double[] m",
)
Points = schemas.define(
    "SrsPoints", "Named points in the arm's base frame (m; y_b up, as in the paper).",
    name="string[]", x_m="double[] m", y_m="double[] m", z_m="double[] m",
)


# -- configuration ------------------------------------------------------------------------------------------------


def geometry(cfg: DictConfig) -> Geometry:
    return Geometry(**cfg.system.geometry)


def humans(cfg: DictConfig) -> HumanArms:
    h = OmegaConf.to_container(cfg.system.humans)
    arrays = {k: np.asarray(h[k], dtype=float) for k in ("base", "base_radius", "base_turns", "shoulder_range",
                                                         "shoulder_offset", "shoulder_turns", "elbow_range",
                                                         "elbow_offset", "elbow_turns", "radius")}
    return HumanArms(**arrays, upper_length=h["upper_length"], fore_length=h["fore_length"], plane=h["plane"],
                     range_is=h["range_is"])


def settings(cfg: DictConfig, case: str = "avoid") -> planner.Settings:
    s = cfg.system
    a = s.algorithm
    forms = Forms(link_checks=a.link_checks, d_m2=a.d_m2, sphere_distance=a.sphere_distance, alpha_c=a.alpha_c)
    base = planner.Settings(
        geometry=geometry(cfg), volume=SafetyVolume(s.safety.d_cmin, s.safety.d_cmax), forms=forms,
        filter=swivel_filter.Coefficients.zoh(s.filter.p, s.filter.dt), avoidance=True, obstacle=a.obstacle,
        initial_alpha=s.filter.initial_alpha, shoulder_sign=s.ik.shoulder_sign, wrist_sign=s.ik.wrist_sign)
    change = dict(VARIANTS[case])
    if "forms" in change:
        change["forms"] = dataclasses.replace(forms, **change["forms"])
    return dataclasses.replace(base, **change)


def task(cfg: DictConfig) -> tuple[np.ndarray, np.ndarray]:
    """(times (N,), desired tool poses (N, 4, 4)) of Sec. 5's circle, one sample every T."""
    t = cfg.system.task
    poses = planner.circle_poses(t.centre, t.radius, t.rides, t.samples, t.start_phase, t.direction, t.tool_axis)
    return np.arange(t.samples) * cfg.system.filter.dt, poses


def obstacles(cfg: DictConfig, arms: HumanArms) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(shoulder/elbow/hand points (N, k, 3, 3), capsule starts, ends (N, 2k, 3), radii (2k,)) at every sample."""
    samples = cfg.system.task.samples
    points = arms.points(np.arange(samples), samples)
    return (points, *arms.capsules(points))


def plan_case(cfg: DictConfig, case: str):
    """Everything one case needs: (times, plan, human points, capsules (start, end, radius))."""
    times, poses = task(cfg)
    arms = humans(cfg)
    points, start, end, radius = obstacles(cfg, arms)
    try:
        plan = planner.plan(poses, start, end, radius, settings(cfg, case))
    except Unreachable as err:
        raise SimulationFailed(str(err)) from None
    if not np.isfinite(plan.q).all():
        bad = int(np.argmax(~np.isfinite(plan.q).all(axis=1)))
        raise SimulationFailed(f"IK at α_f = {plan.alpha_f[bad]:.4g} rad failed at sample {bad}")
    return times, plan, points, (start, end, radius)


# -- logging ----------------------------------------------------------------------------------------------------


def _frames_along(start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """(..., 4, 4) frames at `start` whose z axis points to `end` (where the human capsules are drawn)."""
    z = (end - start) / np.linalg.norm(end - start, axis=-1, keepdims=True)
    helper = np.broadcast_to([0.0, 0.0, 1.0], z.shape)
    x = np.cross(helper, z)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    return pose(np.stack([x, np.cross(z, x), z], axis=-1), start)


def human_frame_names(arms: HumanArms) -> list[str]:
    return [f"human{k + 1}/{part}" for k in range(len(arms.base)) for part in ("upper", "fore")]


def log_scene(log: RunWriter, cfg: DictConfig, g: Geometry) -> None:
    """One `/markers` message at t = 0: the arm's safety volume (translucent cones and the elbow sphere), locked
    to its /tf frames (the arm and the human arms are drawn from the replay model's URDF); and the fixed
    world -> base turn."""
    vol = cfg.system.safety
    safety = (0.2, 0.6, 1.0, 0.18)
    entities = [markers.cone("safety/upper_arm", "link3", [0, 0, 0], [g.a1, 0, 0], vol.d_cmin, vol.d_cmax, safety),
                markers.cone("safety/forearm", "link5", [0, 0, 0], [g.a2, 0, 0], vol.d_cmax, vol.d_cmin, safety),
                *markers.spheres(["link4"], [vol.d_cmax], [safety])]
    log.write("/markers", 0, schemas.SceneUpdate(entities=entities))
    log.log_transforms(np.zeros(1), "world", ["base"], WORLD_BASE[None, None])


def _ball(name: str, position, radius: float, color, lifetime_ns: int) -> schemas.SceneEntity:
    entity = schemas.SceneEntity(frame_id="base", id=name, spheres=[schemas.SpherePrimitive(
        pose=schemas.Pose(position=schemas.Vector3(x=position[0], y=position[1], z=position[2]),
                          orientation=schemas.Quaternion(w=1.0)),
        size=schemas.Vector3(x=2 * radius, y=2 * radius, z=2 * radius),
        color=schemas.Color(r=color[0], g=color[1], b=color[2], a=color[3]))])
    entity.lifetime.FromNanoseconds(lifetime_ns)
    return entity


def log_collision_points(log: RunWriter, times: np.ndarray, plan: planner.Plan, dt: float) -> None:
    """P_c (red while a collision is imminent, as in the paper's Fig. 5, green otherwise) and P_col (purple) per
    sample on `/markers`, each living one sample period."""
    sel, life = plan.selection, round(dt * 1e9)
    for t, P_c, P_col, find in zip(times.tolist(), plan.P_c.tolist(), sel.P_col.tolist(), sel.find.tolist(),
                                   strict=True):
        entities = [_ball("p_c", P_c, 0.025, (0.9, 0.1, 0.1, 1.0) if find else (0.2, 0.75, 0.2, 1.0), life)]
        if find:
            entities.append(_ball("p_col", P_col, 0.02, (0.55, 0.1, 0.8, 1.0), life))
        log.write("/markers", round(t * 1e9), schemas.SceneUpdate(entities=entities))


def log_plan(log: RunWriter, cfg: DictConfig, times: np.ndarray, plan: planner.Plan, points: np.ndarray,
             capsules: tuple, arms: HumanArms) -> None:
    """What Algorithm 1 computed, every sample: swivel signals, the collision test, the human points, clearances
    (safety volume and bodies), the IK's tool error, and the joints at α_f and at α = 0."""
    s, g, dt = cfg.system, geometry(cfg), cfg.system.filter.dt
    rate = np.r_[0.0, np.diff(plan.alpha_f)] / dt                               # Fig. 8: first difference / T
    acceleration = np.r_[0.0, np.diff(rate)] / dt                               # Fig. 9
    log.log_series("/swivel", times, Swivel, alpha_c_rad=plan.alpha_c, alpha_f_rad=plan.alpha_f,
                   alpha_f_rate_rad_s=rate, alpha_f_acceleration_rad_s2=acceleration)
    sel = plan.selection
    log.log_series("/avoidance", times, Avoidance, case=np.array(CASES)[sel.case], find=sel.find, d_mc_m=sel.d_mc,
                   actual_distance_m=sel.actual, side_g_m3=plan.g, p_c_m=plan.P_c, p_col_m=sel.P_col,
                   obstacle_distance_m=plan.obstacle_distance, obstacle_capsule=plan.obstacle_owner.astype(np.uint32))
    volume = SafetyVolume(s.safety.d_cmin, s.safety.d_cmax)
    flat = points.reshape(len(points), -1, 3)
    names = [f"human{k + 1}/{p}" for k in range(points.shape[1]) for p in ("shoulder", "elbow", "hand")]
    log.log_series("/humans", times, Points, name=names, x_m=flat[..., 0], y_m=flat[..., 1], z_m=flat[..., 2])
    log.log_series("/clearance/volume", times, Distances, name=names,
                   distance_m=clearance.volume_margins(volume, flat, plan.points))
    log.log_series("/clearance/volume_alpha0", times, Distances, name=names,
                   distance_m=clearance.volume_margins(volume, flat, plan.points0))
    T = fk(plan.q, g)
    start, end, radius = capsules
    pairs = clearance.capsule_clearance(*clearance.link_segments(plan.points, T[:, :3, 3]),
                                        s.dynamics.link_radius, start, end, radius)
    log.log_series("/clearance/capsules", times, Distances, name=pair_names(arms),
                   distance_m=pairs.reshape(len(times), -1))
    dp = T[:, :3, 3] - plan.poses[:, :3, 3]
    log.log_series("/ik/tool_error", times, schemas.TrackingError, units=["m", "m", "m", "rad"],
                   field_units={"norm": "m"}, name=[*XYZ, "rotation"],
                   error=np.column_stack([dp, rotation_angle(T[:, :3, :3], plan.poses[:, :3, :3])]),
                   norm=np.linalg.norm(dp, axis=1))
    log.log_series("/ik/joints", times, schemas.JointState, units="rad", name=JOINTS, position=plan.q)
    log.log_series("/ik/alpha0", times, schemas.JointState, units="rad", name=JOINTS, position=plan.q0)


def pair_names(arms: HumanArms) -> list[str]:
    return [f"{h}-{link}" for h in human_frame_names(arms) for link in mujoco_replay.ROBOT_LINKS]


def log_frames(log: RunWriter, times: np.ndarray, q: np.ndarray, g: Geometry, targets: np.ndarray,
               start: np.ndarray, end: np.ndarray, arms: HumanArms) -> None:
    """Link, target and human frames in `world` (z up; every viewer then agrees, whatever it makes of parents)."""
    frames = np.concatenate([link_frames(q, g), targets[:, None], _frames_along(start, end)], axis=1)
    log.log_transforms(times, "world", [*LINK_FRAMES, "target", *human_frame_names(arms)], WORLD_BASE @ frames)


# -- the MuJoCo replay ----------------------------------------------------------------------------------------


def dynamics(cfg: DictConfig) -> mujoco_replay.Dynamics:
    d = cfg.system.dynamics
    return mujoco_replay.Dynamics(masses=tuple(d.masses), link_radius=d.link_radius, armature=tuple(d.armature),
                                  damping=tuple(d.damping), torque_limit=tuple(d.torque_limit))


def _model(cfg: DictConfig, arms: HumanArms, timestep: float, kp: np.ndarray, kv: np.ndarray) -> str:
    lengths = np.tile([arms.upper_length, arms.fore_length], len(arms.base))
    radii = np.tile(arms.radius, len(arms.base))
    return mujoco_replay.model_xml(geometry(cfg), dynamics(cfg), radii, lengths, timestep=timestep, kp=kp, kv=kv)


def replay_model(cfg: DictConfig, arms: HumanArms, q0: np.ndarray) -> str:
    from pipeline.robotics.mjcf import with_servo_gains

    rp = cfg.replay
    return with_servo_gains(lambda kp, kv: _model(cfg, arms, rp.dt, kp, kv), q0, rp.bandwidth_hz, rp.damping_ratio)


def drawing_model(cfg: DictConfig, arms: HumanArms) -> str:
    """The replay model without its servo (zero gains): what draws a run that is planned, not replayed. Its
    URDF is the replay's, since a URDF carries no actuators."""
    zero = np.zeros(len(JOINTS))
    return _model(cfg, arms, cfg.system.filter.dt, zero, zero)


def replay(log: RunWriter, cfg: DictConfig, times: np.ndarray, plan: planner.Plan, capsules: tuple,
           arms: HumanArms) -> np.ndarray:
    """Execute the planned joints under the model's joint servo, log what the arm did, and audit the planned
    clearance with MuJoCo's distance query (at the planned and at the executed joints). Returns the executed
    joints at the planning samples (N, 7)."""
    from scipy.interpolate import CubicSpline
    from scipy.spatial.transform import Rotation

    from pipeline.robotics.mjcf import servo_rollout

    rp, g = cfg.replay, geometry(cfg)
    spline = CubicSpline(times, plan.q, axis=0)
    steps = round(times[-1] / rp.dt)
    t = np.arange(steps + 1) * rp.dt
    q_ref, qd_ref = spline(t), spline(t, 1)
    xml = replay_model(cfg, arms, q_ref[0])
    log.attach("model.xml", xml, "application/xml")
    states, sensors = servo_rollout(xml, q_ref, qd_ref, t, moving_start=True)   # a replay joins the motion
    every = max(1, round(rp.log_dt / rp.dt))
    t_state = (t + rp.dt)[::every]                    # rollout returns the state after each step
    q, qd, tau = states[::every, 1:8], states[::every, 8:15], sensors[::every, :7]
    log.log_series("/reference", t[::every], units="rad", name=JOINTS, position=q_ref[::every],
                   velocity=qd_ref[::every],
                   acceleration=spline(t[::every], 2))
    log.log_series("/joint_state", t_state, units="rad", name=JOINTS, position=q, velocity=qd, effort=tau)
    log.log_series("/command", t_state, units="rad", kind="torque", name=JOINTS, value=tau)
    err = q_ref[::every] - q
    log.log_series("/tracking_error", t_state, units="rad", name=JOINTS, error=err, norm=np.linalg.norm(err, axis=1))
    # the tool as MuJoCo measured it, against the desired pose sampled at the same instants
    R_bw = mujoco_replay.R_WORLD_BASE.T
    p_tool = sensors[::every, 7:10] @ R_bw.T
    R_tool = R_bw @ Rotation.from_quat(sensors[::every, 10:14], scalar_first=True).as_matrix()
    desired = fk(spline(t_state), g)    # the planned tool pose between samples (exact at the samples)
    dp = desired[:, :3, 3] - p_tool
    log.log_series("/tracking_error/tool", t_state, units=["m", "m", "m", "rad"], field_units={"norm": "m"},
                   name=[*XYZ, "rotation"],
                   error=np.column_stack([dp, rotation_angle(desired[:, :3, :3], R_tool)]),
                   norm=np.linalg.norm(dp, axis=1))
    # MuJoCo's distance query on the same capsules: at the planned joints and at the executed ones
    executed = states[np.clip(np.rint(times / rp.dt).astype(int) - 1, 0, len(states) - 1), 1:8]
    start, end, _ = capsules
    names = pair_names(arms)
    planned = mujoco_replay.capsule_distances(xml, plan.q, start, end)
    log.log_series("/clearance/capsules_mujoco", times, Distances, name=names,
                   distance_m=planned.reshape(len(times), -1))
    log.log_series("/clearance/capsules_replay", times, Distances, name=names,
                   distance_m=mujoco_replay.capsule_distances(xml, executed, start, end).reshape(len(times), -1))
    return executed


def _simulate(log: RunWriter, cfg: DictConfig, case: str, replayed: bool) -> None:
    """One case: Algorithm 1 over the task, logged; then either the MuJoCo replay or, for the ablation's many
    runs, the planned joints alone. Either way the scene is drawn: the arm and the human arms from the replay
    model's URDF (at the executed or the planned joints), the safety volume and the collision points."""
    times, plan, points, capsules = plan_case(cfg, case)
    arms, g = humans(cfg), geometry(cfg)
    log_plan(log, cfg, times, plan, points, capsules, arms)
    log.log_series("/reference/tool", times, schemas.Reference, units="m", name=XYZ, position=plan.poses[:, :3, 3])
    log_scene(log, cfg, g)
    log_collision_points(log, times, plan, cfg.system.filter.dt)
    if replayed:
        q, model = replay(log, cfg, times, plan, capsules, arms), None   # drawn from the attached model.xml
    else:
        q, model = plan.q, drawing_model(cfg, arms)
        log.log_series("/joint_state", times, units="rad", name=JOINTS, position=q,
                       velocity=np.gradient(q, times, axis=0))
    start, end, _ = capsules
    log_frames(log, times, q, g, plan.poses, start, end, arms)
    log.log_robot(times, q, *mujoco_replay.mocap_poses(start, end), model=model)   # the humans: mocap bodies


def circle(cfg: DictConfig) -> list[Case]:
    return [Case(case, lambda log, c=case: _simulate(log, cfg, c, True)) for case in cfg.scenario.cases]


def ablation(cfg: DictConfig) -> list[Case]:
    return [Case(case, lambda log, c=case: _simulate(log, cfg, c, False)) for case in cfg.scenario.cases]


def compute_time(cfg: DictConfig) -> list[Case]:
    """Algorithm 1 one iteration at a time (`planner.Online`), every iteration timed, `scenario.repeats` passes
    over the task after `scenario.warmup` untimed iterations; the IK alone and the whole-run batch form timed
    beside it; and the online joints checked against the batch plan."""
    sc = cfg.scenario

    def simulate(log: RunWriter) -> None:
        _, poses = task(cfg)
        _, start, end, radius = obstacles(cfg, humans(cfg))
        s = settings(cfg, "avoid")
        batch = planner.plan(poses, start, end, radius, s)
        inputs = [(T, a, b, radius) for T, a, b in zip(poses, start, end, strict=True)]
        online = planner.Online(s)
        q = np.array([online.step(*args) for args in inputs])
        gap = np.abs(np.angle(np.exp(1j * (q - batch.q)))).max()
        log.log("/online_vs_batch", 0.0, schemas.Scalars, units="rad", name=["max_joint_difference_rad"],
                value=[float(gap)])
        timings = [
            time_calls("algorithm1", planner.Online(s).step, inputs, warmup=sc.warmup, repeats=sc.repeats),
            time_calls("ik", lambda T: ik(T, 0.3, s.geometry), [(T,) for T in poses], warmup=sc.warmup),
            time_calls("algorithm1_batch", lambda: planner.plan(poses, start, end, radius, s), [()], warmup=1,
                       repeats=sc.batch_repeats, items_per_call=len(poses)),
        ]
        log_timings(log, timings)

    return [Case("algorithm1", simulate)]

"""Simulate stage of `ur5-ik-fsm`: the Table 2 tests, singular flange paths executed in MuJoCo, and
compute time. Every run logs what the analysis stage needs to rebuild the paper's tables."""

from __future__ import annotations

import re
from math import pi

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import time_calls
from pipeline.papers.ur5_ik_fsm import ik
from pipeline.papers.ur5_ik_fsm.kinematics import Geometry, det_j, fk, shoulder_term
from pipeline.robotics import dh as dhk
from pipeline.robotics.mjcf import servo_rollout
from pipeline.robotics.profiles import interpolate
from pipeline.robotics.transforms import rotation_angle

JOINTS = [f"joint{i}" for i in range(1, 7)]
ALGORITHMS = {"alg1": ik.min_displacement, "alg2": ik.fsm}

IkSelection = schemas.define(
    "Ur5IkSelection", "One IK call of the UR5 paper: the selected set and what it took to find it.",
    name="string[]", position="double[] q", previous="double[] q", found="bool", branch="int64 1",
    sets_evaluated="uint32 1", valid_sets="uint32 1", trace="string", det_j="double m^3", diff="double rad",
    fk_error_position="double m", fk_error_rotation="double rad",
)


def geometry(cfg: DictConfig) -> Geometry:
    return Geometry(**cfg.system.geometry)


def conventions(cfg: DictConfig) -> ik.Conventions:
    return ik.Conventions(**OmegaConf.to_container(cfg.system.conventions))


_PI_EXPR = re.compile(r"^\s*(-)?\s*(?:(\d+)\s*\*\s*)?pi\s*(?:/\s*(\d+))?\s*$")


def angle(value) -> float:
    """A Table 2 entry: a number, or `[-][k*]pi[/m]` evaluated in MATLAB's order ((k*pi)/m)."""
    if isinstance(value, int | float):
        return float(value)
    m = _PI_EXPR.match(str(value))
    if not m:
        raise ValueError(f"cannot read angle {value!r}: write a number or [-][k*]pi[/m]")
    sign, k, div = m.groups()
    x = (int(k) * pi if k else pi) / (int(div) if div else 1)
    return -x if sign else x


def _selection_record(sel: ik.Selection, T: np.ndarray, previous, g: Geometry) -> dict:
    if sel.q is None:
        nan = float("nan")
        return dict(name=JOINTS, position=[nan] * 6, previous=list(previous), found=False, branch=-1,
                    sets_evaluated=sel.sets_evaluated, valid_sets=sel.valid_sets, trace=sel.trace,
                    det_j=nan, diff=nan, fk_error_position=nan, fk_error_rotation=nan)
    q = np.array(sel.q)
    T_q = fk(q, g)
    return dict(name=JOINTS, position=sel.q, previous=list(previous), found=True, branch=sel.branch,
                sets_evaluated=sel.sets_evaluated, valid_sets=sel.valid_sets, trace=sel.trace,
                det_j=float(det_j(q, g)), diff=float(np.linalg.norm(np.asarray(previous) - q)),  # eq. (48)
                fk_error_position=float(np.linalg.norm(T_q[:3, 3] - T[:3, 3])),
                fk_error_rotation=float(rotation_angle(T_q[:3, :3], T[:3, :3])))


# -- E1: Tables 3-6 --------------------------------------------------------------------------------


def tables(cfg: DictConfig) -> list[Case]:
    g, c = geometry(cfg), conventions(cfg)
    printed = cfg.system.fk_form == "printed"
    generating = np.array([[angle(x) for x in row] for row in cfg.scenario.table2])
    poses = [fk(q, g, printed=printed) for q in generating]
    dh = dhk.DH.from_config(g.dh)

    def simulate(log: RunWriter, sequential: bool) -> None:
        previous = {name: np.zeros(6) for name in ALGORITHMS}
        for k, T in enumerate(poses, start=1):
            t = float(k)  # test k is logged at t = k s: the tests are a sequence, not a trajectory
            log.log("/ik/generating", t, schemas.Reference, units="rad", name=JOINTS,
                    position=generating[k - 1].tolist())
            frames = [T]
            for name, solve in ALGORITHMS.items():
                sel = solve(T, previous[name], g, c)
                log.log(f"/ik/{name}", t, IkSelection, units="rad", **_selection_record(sel, T, previous[name], g))
                if sel.q is not None:
                    frames.append(dhk.fk(dh, np.array(sel.q)))
                    if sequential:
                        previous[name] = np.array(sel.q)
                else:
                    frames.append(np.eye(4))
            log.log_transforms(np.array([t]), "base", ["target", "alg1/flange", "alg2/flange"],
                               np.array(frames)[None])

    return [Case(case, lambda log, s=(case == "sequential"): simulate(log, s)) for case in cfg.scenario.cases]


# -- E2: singular flange paths executed in MuJoCo -------------------------------------------------------


def _min_jerk(x: np.ndarray) -> np.ndarray:
    return x ** 3 * (10 - 15 * x + 6 * x ** 2)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def flange_path(kind: str, spec: DictConfig, g: Geometry, times: np.ndarray, duration: float,
                gap: float) -> np.ndarray:
    """(N, 4, 4) flange poses at `times`, constant orientation. The path passes `gap` metres from a
    singular pose at mid-time: gap = 0 puts a sample exactly on it."""
    q_mid = np.array([np.nan if x is None else float(x) for x in spec.q_mid])
    if kind == "shoulder":  # solve theta2 so that the shoulder factor of eq. (46) vanishes
        grid = np.linspace(-pi, pi, 721)
        qs = np.tile(q_mid, (len(grid), 1))
        qs[:, 1] = grid
        f = shoulder_term(qs, g)
        i = int(np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))[0])
        from scipy.optimize import brentq  # only this path needs SciPy's optimizers (slow to import)

        q_mid[1] = brentq(lambda x: float(shoulder_term(np.r_[q_mid[0], x, q_mid[2:]], g)), grid[i], grid[i + 1],
                          xtol=1e-15)
    F = dhk.frames(dhk.DH.from_config(g.dh), q_mid)
    T_mid = F[-1]
    tau = times / duration
    if kind == "elbow":  # radial in the arm plane (frame-1 to frame-3 origin), to full stretch and back
        direction = _unit(F[3, :3, 3] - F[1, :3, 3])
        offset = -gap - spec.length * (1.0 - (1.0 - np.cos(2 * pi * tau)) / 2.0)
    else:  # straight line, horizontal, perpendicular to the radial of the frame-5 origin
        p5 = F[5, :3, 3]
        direction = _unit(np.cross([0.0, 0.0, 1.0], [p5[0], p5[1], 0.0]))
        offset = spec.length * (_min_jerk(tau) - 0.5) + gap
    poses = np.tile(T_mid, (len(times), 1, 1))
    poses[:, :3, 3] += offset[:, None] * direction
    return poses


def servo_references(q_ik: np.ndarray, ik_times: np.ndarray, dt: float, unwrap: bool, velocity_limit: float):
    """IK samples -> servo references at every physics step: (times, q_ref, q̇_ref)."""
    held = q_ik.copy()
    for k in range(1, len(held)):  # a rejected sample keeps the last reference
        if np.isnan(held[k]).any():
            held[k] = held[k - 1]
    if unwrap:
        held = np.unwrap(held, axis=0)
    times = np.arange(round(ik_times[-1] / dt) + 1) * dt
    q_ref = np.stack([np.interp(times, ik_times, held[:, j]) for j in range(6)], axis=1)
    qd_ref = np.clip(np.gradient(q_ref, dt, axis=0), -velocity_limit, velocity_limit)
    return times, q_ref, qd_ref


def arm_model(cfg: DictConfig, g: Geometry, q0: np.ndarray) -> str:
    """MJCF of the UR5 of Table 1 with the assumed dynamics and servo gains tuned at q0."""
    from pipeline.robotics.mjcf import ArmDynamics, serial_arm, with_servo_gains

    ex, dyn_cfg = cfg.execute, cfg.system.dynamics
    dyn = ArmDynamics(masses=list(dyn_cfg.masses), link_radius=dyn_cfg.link_radius, armature=list(dyn_cfg.armature),
                      damping=list(dyn_cfg.damping), torque_limit=list(dyn_cfg.torque_limit))
    dh = dhk.DH.from_config(g.dh)

    def build(kp, kv) -> str:
        return serial_arm("ur5_paper_dh", dh, dyn, timestep=ex.dt, kp=list(kp), kv=list(kv))

    return with_servo_gains(build, q0, ex.bandwidth_hz, ex.damping_ratio)


def log_execution(log: RunWriter, cfg: DictConfig, g: Geometry, times, q_ref, qd_ref, states, sensors,
                  ik_times, poses) -> None:
    """Log the servoed run every `execute.log_dt` (and link frames every `execute.tf_dt`)."""
    dt = cfg.execute.dt
    every = slice(None, None, max(1, round(cfg.execute.log_dt / dt)))
    dh = dhk.DH.from_config(g.dh)
    t_state = (times + dt)[every]  # rollout returns the state after each step
    q, qd, tau = states[every, 1:7], states[every, 7:13], sensors[every, :6]
    q_ref, qd_ref = q_ref[every], qd_ref[every]
    log.log_series("/reference", times[every], units="rad", name=JOINTS, position=q_ref, velocity=qd_ref)
    log.log_series("/joint_state", t_state, units="rad", name=JOINTS, position=q, velocity=qd, effort=tau)
    log.log_series("/command", t_state, units="rad", kind="torque", name=JOINTS, value=tau)
    err = q_ref - q
    log.log_series("/tracking_error", t_state, units="rad", name=JOINTS, error=err, norm=np.linalg.norm(err, axis=1))
    # flange error of the executed motion against the desired path
    T_des = interpolate(t_state, ik_times, poses)
    link_frames = dhk.frames(dh, q)
    T_act = link_frames[:, -1]
    dp = T_des[:, :3, 3] - T_act[:, :3, 3]
    rot = rotation_angle(T_des[:, :3, :3], T_act[:, :3, :3])
    log.log_series("/tracking_error/flange", t_state, units=["m", "m", "m", "rad"], field_units={"norm": "m"},
                   name=["x", "y", "z", "rotation"],
                   error=np.column_stack([dp, rot]), norm=np.linalg.norm(dp, axis=1))
    tf = slice(None, None, max(1, round(cfg.execute.tf_dt / dt)))
    t_tf = (times + dt)[tf]
    logged = tf.step % every.step == 0  # the frames' samples are logged samples: their frames are computed
    frames = (link_frames[::tf.step // every.step] if logged else dhk.frames(dh, states[tf, 1:7]))[:, 1:]
    target = poses[np.searchsorted(ik_times, t_tf).clip(max=len(poses) - 1)]
    log.log_transforms(t_tf, "base", [*(f"link{i}" for i in range(1, 7)), "target"],
                       np.concatenate([frames, target[:, None]], axis=1))


def execute(log: RunWriter, cfg: DictConfig, q_ik: np.ndarray, ik_times: np.ndarray, poses: np.ndarray,
            g: Geometry) -> None:
    """Drive the MuJoCo UR5 along the IK references and log what it did."""
    times, q_ref, qd_ref = servo_references(q_ik, ik_times, cfg.execute.dt, cfg.execute.unwrap,
                                            cfg.system.dynamics.velocity_limit)
    xml = arm_model(cfg, g, q_ref[0])
    log.attach("model.xml", xml, "application/xml")
    states, sensors = servo_rollout(xml, q_ref, qd_ref, times)
    log_execution(log, cfg, g, times, q_ref, qd_ref, states, sensors, ik_times, poses)


def solve_path(cfg: DictConfig, path: str, crossing: str, algorithm: str):
    """IK of one singular path, sample by sample with previous = last selection:
    (ik_times, poses, q_ik with NaN rows where rejected, per-sample records)."""
    g, c, sc = geometry(cfg), conventions(cfg), cfg.scenario
    ik_times = np.arange(round(sc.duration / sc.ik_dt) + 1) * sc.ik_dt
    gap = sc.near_gap if crossing == "near" else 0.0
    poses = flange_path(path, sc[path], g, ik_times, sc.duration, gap)
    solve = ALGORITHMS[algorithm]
    q_ik = np.full((len(poses), 6), np.nan)
    selections, previous_sets = [], np.empty((len(poses), 6))
    previous = None
    for k, T in enumerate(poses):
        if previous is None:  # start on the set closest to zero, as the paper's tests do
            start = ik.min_displacement(T, np.zeros(6), g, c)
            previous = np.zeros(6) if start.q is None else np.array(start.q)
        sel = solve(T, previous, g, c)
        selections.append(sel)
        previous_sets[k] = previous
        if sel.q is not None:
            q_ik[k] = sel.q
            previous = q_ik[k]
    return ik_times, poses, q_ik, _selection_records(selections, q_ik, previous_sets, poses, g)


def _selection_records(selections: list[ik.Selection], q: np.ndarray, previous: np.ndarray, poses: np.ndarray,
                       g: Geometry) -> dict:
    """The columns of a path's /ik records, computed for all samples at once (FK by the DH product, equal to
    eqs. (2)-(13) to 1e-16 m); NaN where no set was found."""
    found = ~np.isnan(q).any(axis=1)
    T_q = dhk.fk(dhk.DH.from_config(g.dh), np.where(found[:, None], q, 0.0))
    nan = np.full(len(q), np.nan)
    return dict(name=JOINTS, position=q, previous=previous, found=found,
                branch=np.array([s.branch if s.q is not None else -1 for s in selections], dtype=np.int64),
                sets_evaluated=np.array([s.sets_evaluated for s in selections], dtype=np.uint32),
                valid_sets=np.array([s.valid_sets for s in selections], dtype=np.uint32),
                trace=np.array([s.trace for s in selections]),
                det_j=np.where(found, det_j(q, g), nan),
                diff=np.where(found, np.linalg.norm(previous - q, axis=1), nan),  # eq. (48)
                fk_error_position=np.where(found, np.linalg.norm(T_q[:, :3, 3] - poses[:, :3, 3], axis=1), nan),
                fk_error_rotation=np.where(found, rotation_angle(T_q[:, :3, :3], poses[:, :3, :3]), nan))


def singular_paths(cfg: DictConfig) -> list[Case]:
    g = geometry(cfg)

    def simulate(log: RunWriter, path: str, crossing: str, algorithm: str) -> None:
        ik_times, poses, q_ik, records = solve_path(cfg, path, crossing, algorithm)
        if np.isnan(q_ik[0]).any():
            raise SimulationFailed(f"no valid IK set at the start of the {path} path")
        log.log_series(f"/ik/{algorithm}", ik_times, IkSelection, units="rad", **records)
        sing = np.column_stack([np.sin(q_ik[:, 2]), np.sin(q_ik[:, 4]), shoulder_term(q_ik, g), det_j(q_ik, g)])
        log.log_series("/singularity", ik_times, schemas.Scalars, name=["s3", "s5", "shoulder", "det_j"], value=sing,
                       units=["1", "1", "m", "m^3"])  # sin θ3, sin θ5, eq. (46)'s shoulder factor, det J
        execute(log, cfg, q_ik, ik_times, poses, g)

    sc = cfg.scenario
    return [Case(f"{path}-{crossing}-{alg}", lambda log, p=path, x=crossing, a=alg: simulate(log, p, x, a))
            for path in sc.paths for crossing in sc.crossings for alg in sc.algorithms]


# -- E3: compute time ---------------------------------------------------------------------------------


def compute_time(cfg: DictConfig) -> list[Case]:
    g, c = geometry(cfg), conventions(cfg)
    sc = cfg.scenario

    def simulate(log: RunWriter) -> None:
        rng = np.random.default_rng(cfg.seed)
        q = rng.uniform(-pi, pi, (sc.poses, 6))
        poses = dhk.fk(dhk.DH.from_config(g.dh), q)
        previous = rng.uniform(-pi, pi, (sc.poses, 6)) if sc.previous == "random" else np.zeros((sc.poses, 6))
        scalar = {name: time_calls(name, lambda T, p, f=fn: f(T, p, g, c), list(zip(poses, previous, strict=True)),
                                   warmup=sc.warmup) for name, fn in ALGORITHMS.items()}
        counts = np.empty((sc.poses, 3))
        for k, (T, p) in enumerate(zip(poses, previous, strict=True)):
            s1, s2 = (ALGORITHMS[a](T, p, g, c) for a in ALGORITHMS)
            counts[k] = s1.sets_evaluated, s2.sets_evaluated, s1.valid_sets
        sample_t = np.arange(sc.poses) * 1e-3  # one sample per pose, 1 ms apart on the log's time axis
        log.log_series("/compute_time", sample_t, name=list(ALGORITHMS), calls=[1, 1],
                       seconds=np.column_stack([scalar[a].seconds for a in ALGORITHMS]))
        log.log_series("/ik/counts", sample_t, schemas.Scalars, value=counts, units="1",
                       name=["alg1_sets_evaluated", "alg2_sets_evaluated", "valid_sets"])

        def batched(algorithm: str):
            return ik.solve_batch(poses, previous, algorithm, g, c)

        t_batch = sc.poses * 1e-3
        for k, name in enumerate(ALGORITHMS):
            timing = time_calls(f"{name}_batch", batched, [(name,)], warmup=2, repeats=sc.batch_repeats,
                                items_per_call=sc.poses)
            times = t_batch + (k * sc.batch_repeats + np.arange(sc.batch_repeats)) * 1e-3
            log.log_series("/compute_time", times, name=[f"{name}_batch"], calls=[sc.poses],
                           seconds=timing.seconds[:, None])

    return [Case("random-poses", simulate)]

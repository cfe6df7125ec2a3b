"""Simulate stage of `curve-discretization`: the Fig. 2 example, the Fig. 3 timing sweep, and a MuJoCo snake
whose body follows a travelling wave through joint references the algorithm computes at every control step."""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
from omegaconf import DictConfig

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import MODEL_ATTACHMENT, RunWriter, SimulationFailed
from pipeline.core.timing import log_timings, time_interleaved
from pipeline.papers.curve_discretization import algorithm as dc
from pipeline.papers.curve_discretization import snake as sn

CurvePoints = schemas.define(
    "CurvePoints", "Points of a space curve or of a chain's joints: curve parameter and position.",
    name="string[]", parameter="double[] 1", x="double[] m", y="double[] m", z="double[] m",
)


def paper_curve(cfg: DictConfig) -> dc.Curve:
    return dc.bezier(cfg.system.curve.control_points)


def search_args(cfg: DictConfig) -> tuple[float, float]:
    return cfg.system.search.dt, cfg.system.search.tol


def _log_points(log: RunWriter, topic: str, points: np.ndarray, names: list[str] | None = None,
                parameter: np.ndarray | None = None) -> None:
    fields = {"x": points[:, 0].tolist(), "y": points[:, 1].tolist(), "z": points[:, 2].tolist()}
    if names is not None:
        fields["name"] = names
    if parameter is not None:
        fields["parameter"] = np.asarray(parameter).tolist()
    log.log(topic, 0.0, CurvePoints, **fields)


def _solve(curve: dc.Curve, chain: dc.Chain, theta_x0: float, cfg: DictConfig) -> tuple[dc.Search, dc.Angles]:
    try:
        return dc.discretize(curve, chain, theta_x0, *search_args(cfg))
    except dc.CurveTooShort as err:
        raise SimulationFailed(str(err)) from None


# -- E1: Fig. 2, the 30-joint Bézier example --------------------------------------------------------------

CURVE_RGBA = (0.85, 0.15, 0.1, 1.0)


def bezier_fig2(cfg: DictConfig) -> list[Case]:
    curve = paper_curve(cfg)
    chain = dc.Chain.uniform(cfg.system.chain.joints, cfg.system.chain.link_length)
    names = [f"joint{m}" for m in range(1, chain.joints + 1)]
    if cfg.system.twist_hat not in ("corrected", "printed"):
        raise ValueError(f"system.twist_hat={cfg.system.twist_hat!r} must be corrected or printed")
    printed = cfg.system.twist_hat == "printed"
    xml = sn.chain_mjcf(chain)

    def simulate(log: RunWriter, theta_x0: float) -> None:
        log.attach(MODEL_ATTACHMENT, xml, "application/xml")
        search, angles = _solve(curve, chain, theta_x0, cfg)
        qpos = sn.configuration(search.points, angles.R_w1, angles.theta)
        P = dc.joint_positions(search.points, chain.joints)
        samples = np.linspace(curve.t_start, curve.t_end, cfg.scenario.curve_samples)
        on_curve = curve(samples)
        _log_points(log, "/curve", on_curve, parameter=samples)
        log.write("/markers", 0, schemas.SceneUpdate(entities=[   # Fig. 2's curve beside the chain drawn
            markers.line_strip("curve", on_curve, thickness=0.3 * sn.CHAIN_RADIUS * chain.segment_lengths.min(),
                               color=CURVE_RGBA)]))
        _log_points(log, "/chain/curve", P, names, dc.joint_positions(search.t[:, None], chain.joints)[:, 0])
        frames = dc.forward_kinematics(search.points[0], angles.R_w1, angles.theta, chain)
        _log_points(log, "/chain/fk", frames[:, :3, 3], names)
        poe = dc.poe_forward_kinematics(search.points[0], angles.theta_z0, angles.theta_y0, theta_x0, angles.theta,
                                        chain, printed)
        _log_points(log, "/chain/poe", poe[:, :3, 3], names)
        # the chain's joint points by MuJoCo's kinematics of the model drawn, at the solved angles
        _log_points(log, "/chain/mujoco", dc.joint_positions(sn.segment_frames(xml, qpos, chain)[1][0], chain.joints),
                    names)
        log.log("/joint_state", 0.0, units="rad", name=names, position=angles.theta.tolist())
        log.log("/chain/first_frame", 0.0, schemas.Scalars, units=["rad", "rad", "rad", "1"],
                name=["theta_z0", "theta_y0", "theta_x0", "evaluations"],
                value=[angles.theta_z0, angles.theta_y0, theta_x0, search.evaluations])
        log.log_transforms(np.zeros(1), "world", names, frames[None])
        log.log_robot(np.zeros(1), qpos[None])   # drawn: link segment{i + 1} in /tf frame joint{2i + 1}

    rolls = [("paper", cfg.system.theta_x0)] + [(f"roll-{r:g}", r) for r in cfg.scenario.roll_variants]
    return [Case(name, lambda log, r=roll: simulate(log, r)) for name, roll in rolls]


# -- E2: Fig. 3, time against the number of joints ---------------------------------------------------------


def joint_counts(cfg: DictConfig) -> list[int]:
    grid = cfg.scenario.joint_counts
    return list(range(grid.first, grid.last + 1, grid.step))


def _batched(fn, calls: int):
    def run(*args) -> None:
        for _ in range(calls):
            fn(*args)

    return run


def timing_fig3(cfg: DictConfig) -> list[Case]:
    curve, sc = paper_curve(cfg), cfg.scenario
    dt, tol = search_args(cfg)
    theta_x0 = cfg.system.theta_x0
    # the paper gives no link lengths for the sweep: the chain's total length is fixed (spec §6)
    chains = {n: dc.Chain.uniform(n, sc.chain_length / (n // 2)) for n in joint_counts(cfg)}

    @functools.cache
    def measure() -> tuple[dict, dict]:
        """Every joint count and stage timed in rounds (one call of each per round), so a burst of load on a
        shared machine falls on all of them alike instead of on a block of consecutive counts."""
        searches = {n: _solve(curve, chain, theta_x0, cfg)[0] for n, chain in chains.items()}
        calls = {}
        for n, chain in chains.items():
            calls[f"search@{n}"] = (dc.joint_parameters, (curve, chain, dt, tol), 1)
            # a few µs per call, near the clock's own cost: each sample times a batch of calls
            calls[f"angles@{n}"] = (_batched(dc.joint_angles, sc.angle_batch), (searches[n].points, theta_x0, n),
                                    sc.angle_batch)
            calls[f"total@{n}"] = (dc.discretize, (curve, chain, theta_x0, dt, tol), 1)
        return searches, time_interleaved(calls, warmup=sc.warmup, repeats=sc.repeats)

    def simulate(log: RunWriter, joints: int) -> None:
        searches, timings = measure()
        search, chain = searches[joints], chains[joints]
        log_timings(log, [dataclasses.replace(timings[f"{stage}@{joints}"], name=stage)
                          for stage in ("search", "angles", "total")])
        log.log("/chain/search", 0.0, schemas.Scalars, units=["1", "1", "m", "1"],
                name=["joints", "segments", "segment_length", "evaluations"],
                value=[joints, chain.segments, chain.segment_lengths[0], search.evaluations])
        _log_points(log, "/chain/curve", search.points, sn.point_names(chain), search.t)

    return [Case(f"joints-{n:03d}", lambda log, n=n: simulate(log, n)) for n in joint_counts(cfg)]


# -- E3: the snake robot in MuJoCo ---------------------------------------------------------------------------


def gait_curve(spec: DictConfig, length: float):
    """The travelling wave of a gait as a function of time."""
    a_y, a_z, wavelength, frequency, phase_z = (float(spec[k]) for k in (  # read once, not at every control step
        "amplitude_y", "amplitude_z", "wavelength", "frequency", "phase_z"))

    def at(t: float) -> dc.Curve:
        return dc.travelling_wave(a_y, a_z, wavelength, 2 * math.pi * frequency * t, phase_z, length)
    return at


def snake_body(cfg: DictConfig) -> sn.SnakeBody:
    return sn.SnakeBody(**cfg.snake)


def snake_gait(cfg: DictConfig) -> list[Case]:
    sc, ctl = cfg.scenario, cfg.control
    chain = dc.Chain.uniform(sc.joints, sc.segment_length)
    body = snake_body(cfg)
    xml = sn.snake_mjcf(chain, body, timestep=ctl.physics_dt, kp=ctl.kp, kv=ctl.kv)
    dt, tol = search_args(cfg)

    def simulate(log: RunWriter, gait: str) -> None:
        log.attach(MODEL_ATTACHMENT, xml, "application/xml")
        try:
            run = sn.run_gait(chain, body, gait_curve(sc[gait], sc.curve_length), sc.theta_x0, dt, tol, xml,
                              control_dt=ctl.dt, duration=sc.duration, warm_start=ctl.warm_start)
        except dc.CurveTooShort as err:
            raise SimulationFailed(str(err)) from None
        log_gait(log, run, chain, xml, ctl.tf_dt)

    return [Case(gait, lambda log, g=gait: simulate(log, g)) for gait in sc.gaits]


def log_gait(log: RunWriter, run: sn.GaitRun, chain: dc.Chain, xml: str, tf_dt: float) -> None:
    t = run.times
    joints, points = sn.joint_names(chain), sn.point_names(chain)
    log.log_series("/reference", t, units="rad", name=joints, position=run.q_ref, velocity=run.qd_ref)
    log.log_series("/joint_state", t, units="rad", name=joints, position=run.q, velocity=run.qd, effort=run.tau)
    log.log_series("/command", t, units="rad", kind="torque", name=joints, value=run.tau)
    error = run.q_ref - run.q
    log.log_series("/tracking_error", t, units="rad", name=joints, error=error, norm=np.linalg.norm(error, axis=1))
    # shape: each joint point of the body against the curve's, the curve placed on the body by the best rigid fit
    placed, distance = sn.shape_fit(run.body, run.target)
    log.log_series("/tracking_error/shape", t, units="m", name=points, error=distance,
                   norm=np.linalg.norm(distance, axis=1))
    log.log_series("/compute_time", t, name=list(run.seconds), calls=[1] * len(run.seconds),
                   seconds=np.column_stack(list(run.seconds.values())))
    comparison = run.warm_vs_cold  # steps 1 … K−1, each logged at the instant of its curve
    log.log_series("/compute_time", t[1:], name=[x.name for x in comparison.timings], calls=[1, 1],
                   seconds=np.column_stack([x.seconds for x in comparison.timings]))
    log.log_series("/search", t[1:], schemas.Scalars, units=["1", "1", "1"],  # the gap is in curve parameter
                   name=["evaluations_warm", "evaluations_cold", "warm_cold_gap"],
                   value=np.column_stack([*comparison.evaluations.values(), comparison.gap]))
    every = slice(None, None, max(1, round(tf_dt / (t[1] - t[0]))))
    frames, body = sn.segment_frames(xml, run.qpos[every], chain)
    tip = frames[:, -1:].copy()
    tip[:, 0, :3, 3] = body[:, -1]
    curve = np.tile(np.eye(4), (*placed[every].shape[:2], 1, 1))
    curve[..., :3, 3] = placed[every]
    log.log_transforms(t[every], "world", [*(f"segment{i + 1}" for i in range(chain.segments)), "tip",
                                           *(f"curve/{p}" for p in points)],
                       np.concatenate([frames, tip, curve], axis=1))
    log.log_robot(t[every], run.qpos[every])

"""Simulate stage of `scara-half-derivative`: the set-point motion (Figs. 4-5), Table 2 with Figs. 8-10
(KD, KDHD, KHD on the Exudyn closed chain), the ICE/ISE maps of Fig. 6 (one run per grid point, swept with
Hydra `-m`) and the equal-ICE path of Fig. 7. Every closed-loop run logs what the analysis needs."""

from __future__ import annotations

import numpy as np
import yaml
from omegaconf import DictConfig, OmegaConf

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter
from pipeline.papers.scara_half_derivative.arm import EXTERNAL, JOINTS, LINKS, Arm, fk, ik, jacobian, link_frames
from pipeline.papers.scara_half_derivative.closed_loop import ClosedLoopRun, PlantSettings, make_plant, run_closed_loop
from pipeline.papers.scara_half_derivative.controller import CartesianController, Gains
from pipeline.papers.scara_half_derivative.setpoint import Motion

EXTERNAL_UNITS = ["m", "m", "m", "rad"]   # x, y, z of E and its heading theta


def arm_of(cfg: DictConfig) -> Arm:
    return Arm.from_config(cfg.system)


def home(cfg: DictConfig) -> np.ndarray:
    return np.deg2rad(np.asarray(cfg.system.home_deg, dtype=float))


def motion_of(cfg: DictConfig, arm: Arm) -> Motion:
    return Motion.from_config(cfg.system.motion, fk(arm, home(cfg)))


def gains(cfg: DictConfig, k_xyz: float, d_xyz: float, hd_xyz: float) -> tuple[str, Gains]:
    """(law, gains) of a translational tuning: hd_xyz = 0 is the KD law (eq. 11) with KD's rotational gains,
    anything else KDHD (eq. 17) with KDHD's (Sec. 5); KHD is KDHD with d_xyz = 0."""
    control = cfg.system.control
    law = "kd" if hd_xyz == 0 else "kdhd"
    rotation = control.rotation[law]
    return law, Gains(k_xyz=k_xyz, k_theta=control.k_theta, d_xyz=d_xyz, d_theta=rotation.d_theta, hd_xyz=hd_xyz,
                      hd_theta=rotation.hd_theta)


def _frames_with_end_effector(arm: Arm, q: np.ndarray, x_d: np.ndarray) -> np.ndarray:
    """(N, 8, 4, 4): the six links, E and the set-point (E's orientation, the set-point's position)."""
    frames = link_frames(arm, q)
    e_frame = frames[:, 5].copy()
    e_frame[:, :3, 3] = fk(arm, q)[:, :3]
    target = e_frame.copy()
    target[:, :3, 3] = x_d[:, :3]
    return np.concatenate([frames, e_frame[:, None], target[:, None]], axis=1)


def _plain(value):
    """Tuples (of tuples) as lists, for YAML."""
    return [_plain(v) for v in value] if isinstance(value, tuple | list) else value


def _stride(log_dt: float, dt: float, what: str) -> int:
    stride = round(log_dt / dt)
    if stride < 1 or abs(stride * dt - log_dt) > 1e-9 * log_dt:
        raise ValueError(f"{what}={log_dt} s must be a whole multiple of the integration step {dt} s")
    return stride


def log_closed_loop(log: RunWriter, cfg: DictConfig, arm: Arm, motion: Motion, run: ClosedLoopRun, law: str) -> None:
    """Fine-step signals every `execute.log_dt`, torques and controller times every control period, link
    frames every `execute.tf_dt`, and Exudyn's loop-closure gap."""
    ex = cfg.execute
    dt = float(run.t[1] - run.t[0])
    fine = slice(None, None, _stride(ex.log_dt, dt, "execute.log_dt"))
    t, q, qd = run.t[fine], run.q[fine], run.qd[fine]
    x_d, xd_d, xdd_d = motion(t)
    period = cfg.system.control.dt
    held = run.tau[np.minimum((t / period + 1e-9).astype(int), len(run.tau) - 1)]
    error = x_d - fk(arm, q)
    log.log_series("/reference", t, units=EXTERNAL_UNITS, name=list(EXTERNAL), position=x_d, velocity=xd_d,
                   acceleration=xdd_d)
    log.log_series("/joint_state", t, units="rad", name=list(JOINTS), position=q, velocity=qd, effort=held)
    log.log_series("/tracking_error", t, units=EXTERNAL_UNITS, field_units={"norm": "m"}, name=list(EXTERNAL),
                   error=error, norm=np.linalg.norm(error[:, :3], axis=1))
    log.log_series("/command", run.t_control, units="rad", kind="torque", name=list(JOINTS), value=run.tau)
    log.log_series("/compute_time", run.t_control, name=[law], seconds=run.controller_s[:, None], calls=[1])
    if run.loop_residual is not None:
        log.log_series("/loop_closure", run.t_control, schemas.Scalars, name=["gap"], units="m",
                       value=run.loop_residual[:, None])
    tf = slice(None, None, _stride(ex.tf_dt, dt, "execute.tf_dt"))
    log.log_transforms(run.t[tf], "base", [*LINKS, "E", "setpoint"],
                       _frames_with_end_effector(arm, run.q[tf], motion(run.t[tf])[0]))


def simulate_tuning(log: RunWriter, cfg: DictConfig, k_xyz: float, d_xyz: float, hd_xyz: float) -> None:
    """One closed-loop run of the set-point motion with the tuning (k_xyz, d_xyz, hd_xyz)."""
    arm = arm_of(cfg)
    motion = motion_of(cfg, arm)
    control, ex = cfg.system.control, cfg.execute
    law, g = gains(cfg, k_xyz, d_xyz, hd_xyz)
    plant_settings = PlantSettings(kind=ex.plant, dt=ex.dt, spectral_radius=ex.spectral_radius,
                                   newton_tolerance=ex.newton_tolerance)
    periods = round(cfg.scenario.duration / control.dt)
    model = {"arm": {k: _plain(v) for k, v in vars(arm).items()}, "gains": vars(g), "law": law,
             "plant": vars(plant_settings), "control": OmegaConf.to_container(control, resolve=True)}
    log.attach("model.yaml", yaml.safe_dump(model, sort_keys=False), "application/yaml")
    plant = make_plant(plant_settings, arm, home(cfg), np.zeros(4), control.dt, periods)
    controller = CartesianController(arm, g, control.dt, control.gl_terms, control.compensate_stiffness)
    run = run_closed_loop(plant, controller, motion, cfg.scenario.duration, control.dt)
    log_closed_loop(log, cfg, arm, motion, run, law)


# -- E1: the set-point motion, Figs. 4-5 ------------------------------------------------------------------


def setpoint(cfg: DictConfig) -> list[Case]:
    def simulate(log: RunWriter) -> None:
        arm = arm_of(cfg)
        motion = motion_of(cfg, arm)
        t = np.arange(round(cfg.scenario.duration / cfg.scenario.dt) + 1) * cfg.scenario.dt
        x_d, xd_d, xdd_d = motion(t)
        q_d = ik(arm, x_d)
        qd_d = np.linalg.solve(jacobian(arm, q_d), xd_d[..., None])[..., 0]
        log.log_series("/reference", t, units=EXTERNAL_UNITS, name=list(EXTERNAL), position=x_d, velocity=xd_d,
                       acceleration=xdd_d)
        log.log_series("/reference/joints", t, schemas.Reference, units="rad", name=list(JOINTS), position=q_d,
                       velocity=qd_d)
        log.log_series("/setpoint/check", t, schemas.Scalars, name=["fk_ik_error"], units="m & rad",
                       value=np.abs(fk(arm, q_d) - x_d).max(axis=1)[:, None])
        tf = slice(None, None, max(1, round(cfg.scenario.tf_dt / cfg.scenario.dt)))
        log.log_transforms(t[tf], "base", [*LINKS, "E", "setpoint"], _frames_with_end_effector(arm, q_d[tf], x_d[tf]))

    return [Case("setpoint", simulate)]


# -- E2: Table 2 and Figs. 8-10 -----------------------------------------------------------------------------


def table2(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    return [Case(f"{name}-k{k:g}", lambda log, k=float(k), t=sc.tunings[name]:
                 simulate_tuning(log, cfg, k, float(t.d_xyz), float(t.hd_xyz)))
            for k in sc.k_xyz for name in sc.controllers]


# -- E3: one grid point of the Fig. 6 maps (sweep with -m) --------------------------------------------------


def maps(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    k, d, hd = float(sc.k_xyz), float(sc.d_xyz), float(sc.hd_xyz)
    return [Case(f"k{k:g}-d{d:g}-hd{hd:g}", lambda log: simulate_tuning(log, cfg, k, d, hd))]


# -- E4: along the equal-ICE line, Fig. 7 -------------------------------------------------------------------


def locus(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    line = sc.line
    return [Case(f"k{k:g}-d{d:g}", lambda log, k=float(k), d=float(d):
                 simulate_tuning(log, cfg, k, d, max(0.0, round(line.intercept + line.slope * d, 6))))   # eq. (20)
            for k in sc.k_xyz for d in sc.d_xyz]

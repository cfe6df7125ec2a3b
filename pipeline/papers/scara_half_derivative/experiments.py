"""Simulate stage of `scara-half-derivative`: the set-point motion (Figs. 4-5), Table 2 with Figs. 8-10
(KD, KDHD, KHD on the Exudyn closed chain), the ICE/ISE maps of Fig. 6 (one run per grid point) and the
equal-ICE path of Fig. 7. On the reduced plant the runs of an experiment are simulated together (batch.py);
the sensitivity experiments are the same cases swept (Hydra `-m`) over what the paper does not give. Every
closed-loop run logs what the analysis needs."""

from __future__ import annotations

import numpy as np
import yaml
from omegaconf import DictConfig, ListConfig, OmegaConf

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.papers.scara_half_derivative import batch
from pipeline.papers.scara_half_derivative.arm import EXTERNAL, JOINTS, LINKS, Arm, fk, ik, jacobian, link_frames
from pipeline.papers.scara_half_derivative.closed_loop import ClosedLoopRun, PlantSettings, make_plant, run_closed_loop
from pipeline.papers.scara_half_derivative.controller import CartesianController, Gains
from pipeline.papers.scara_half_derivative.mujoco_model import model_xml, qpos
from pipeline.papers.scara_half_derivative.setpoint import Motion

EXTERNAL_UNITS = ["m", "m", "m", "rad"]   # x, y, z of E and its heading theta


Indexes = schemas.define(
    "ClosedLoopIndexes", "Table 2's indexes and eqs. (18)-(19) of one closed-loop run over [0, T_sim], on every "
    "integration step: max and mean |e| of x, y, z in that order (m), ISE = ∫(e_x² + e_y² + e_z²) dt "
    "(trapezoid, m²s), ICE = Σ_i ∫τ_i² dt of the applied torques (N²m²s), max |τ_i| of joints 1-4 (N m).",
    e_max_m="double[] m", e_mean_m="double[] m", ise_m2s="double m^2 s", ice_N2m2s="double N^2 m^2 s",
    tau_max_Nm="double[] N m",
)


def indexes(arm: Arm, motion: Motion, run: ClosedLoopRun, period: float) -> dict:
    """The fields of `Indexes` from the run's integration steps: the analysis reads these instead of decoding
    every logged sample (a map sweep has hundreds of runs)."""
    e = motion(run.t)[0][:, :3] - fk(arm, run.q)[:, :3]
    if run.tau_fine is None:
        tau, step = run.tau, period
    else:
        tau, step = run.tau_fine, float(run.t[1] - run.t[0])
    return {"e_max_m": np.abs(e).max(axis=0).tolist(),
            "e_mean_m": np.abs(e).mean(axis=0).tolist(), "ise_m2s": float(np.trapezoid((e ** 2).sum(axis=1), run.t)),
            "ice_N2m2s": float((tau ** 2).sum() * step), "tau_max_Nm": np.abs(tau).max(axis=0).tolist()}


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


def log_arm(log: RunWriter, arm: Arm, t: np.ndarray, q: np.ndarray) -> None:
    """The arm drawn: its MuJoCo model attached as model.xml, its URDF, joint states and link frames
    (mujoco_model: the closed chain's spanning tree, with the parallelogram's passive joints), and the paper's
    base frame placed at the world origin."""
    log.attach("model.xml", model_xml(arm), "application/xml")
    log.log_robot(t, qpos(q))
    log.log_transforms(t[:1], "world", ["base"], np.eye(4)[None, None])


def _plain(value):
    """Tuples (of tuples) as lists, for YAML."""
    return [_plain(v) for v in value] if isinstance(value, tuple | list) else value


def _stride(log_dt: float, dt: float, what: str) -> int:
    stride = round(log_dt / dt)
    if stride < 1 or abs(stride * dt - log_dt) > 1e-9 * log_dt:
        raise ValueError(f"{what}={log_dt} s must be a whole multiple of the integration step {dt} s")
    return stride


def log_closed_loop(log: RunWriter, cfg: DictConfig, arm: Arm, motion: Motion, run: ClosedLoopRun, law: str) -> None:
    """Fine-step signals every `execute.log_dt`, the torques (held over each control period, or at every
    integration step when they vary within it; every `execute.log_dt` when that is longer), controller times,
    link frames every `execute.tf_dt`, and Exudyn's loop-closure gap."""
    ex = cfg.execute
    dt = float(run.t[1] - run.t[0])
    fine = slice(None, None, _stride(ex.log_dt, dt, "execute.log_dt"))
    t, q, qd = run.t[fine], run.q[fine], run.qd[fine]
    x_d, xd_d, xdd_d = motion(t)
    if run.tau_fine is None:
        t_tau, tau = run.t_control, run.tau
    else:
        t_tau, tau = run.t[:-1], run.tau_fine
    step = float(t_tau[1] - t_tau[0]) if len(t_tau) > 1 else dt
    held = tau[np.minimum((t / step + 1e-9).astype(int), len(tau) - 1)]
    command = slice(None, None, max(1, round(ex.log_dt / step)))   # a sweep's runs are logged to look at
    error = x_d - fk(arm, q)
    log.log_series("/reference", t, units=EXTERNAL_UNITS, name=list(EXTERNAL), position=x_d, velocity=xd_d,
                   acceleration=xdd_d)
    log.log_series("/joint_state", t, units="rad", name=list(JOINTS), position=q, velocity=qd, effort=held)
    log.log_series("/tracking_error", t, units=EXTERNAL_UNITS, field_units={"norm": "m"}, name=list(EXTERNAL),
                   error=error, norm=np.linalg.norm(error[:, :3], axis=1))
    log.log_series("/command", t_tau[command], units="rad", kind="torque", name=list(JOINTS), value=tau[command])
    log.log("/closed_loop/indexes", float(run.t[-1]), Indexes, **indexes(arm, motion, run, cfg.system.control.dt))
    if np.isfinite(run.controller_s).all():   # a batch times no single controller
        log.log_series("/compute_time", run.t_control, name=[law], seconds=run.controller_s[:, None], calls=[1])
    if run.loop_residual is not None:
        log.log_series("/loop_closure", run.t_control, schemas.Scalars, name=["gap"], units="m",
                       value=run.loop_residual[:, None])
    tf = slice(None, None, _stride(ex.tf_dt, dt, "execute.tf_dt"))
    log.log_transforms(run.t[tf], "base", [*LINKS, "E", "setpoint"],
                       _frames_with_end_effector(arm, run.q[tf], motion(run.t[tf])[0]))
    log_arm(log, arm, run.t[tf], run.q[tf])


def _model_yaml(cfg: DictConfig, arm: Arm, law: str, g: Gains) -> str:
    control, ex = cfg.system.control, cfg.execute
    plant = {"kind": ex.plant, "dt": ex.dt, "spectral_radius": ex.spectral_radius,
             "newton_tolerance": ex.newton_tolerance}
    model = {"arm": {k: _plain(v) for k, v in vars(arm).items()}, "gains": vars(g), "law": law, "plant": plant,
             "control": OmegaConf.to_container(control, resolve=True)}
    return yaml.safe_dump(model, sort_keys=False)


def simulate_tuning(log: RunWriter, cfg: DictConfig, k_xyz: float, d_xyz: float, hd_xyz: float) -> None:
    """One closed-loop run of the set-point motion with the tuning (k_xyz, d_xyz, hd_xyz), alone."""
    arm = arm_of(cfg)
    motion = motion_of(cfg, arm)
    control, ex = cfg.system.control, cfg.execute
    law, g = gains(cfg, k_xyz, d_xyz, hd_xyz)
    plant_settings = PlantSettings(kind=ex.plant, dt=ex.dt, spectral_radius=ex.spectral_radius,
                                   newton_tolerance=ex.newton_tolerance)
    periods = round(cfg.scenario.duration / control.dt)
    log.attach("model.yaml", _model_yaml(cfg, arm, law, g), "application/yaml")
    plant = make_plant(plant_settings, arm, home(cfg), np.zeros(4), control.dt, periods)
    controller = CartesianController(arm, g, control.dt, control.gl_terms, control.compensate_stiffness,
                                     difference=control.implementation == "sampled-difference")
    run = run_closed_loop(plant, controller, motion, cfg.scenario.duration, control.dt)
    log_closed_loop(log, cfg, arm, motion, run, law)


def tuning_cases(cfg: DictConfig, tunings: list[tuple[str, float, float, float]]) -> list[Case]:
    """One case per (case id, k_xyz, d_xyz, hd_xyz). On the reduced plant all of them are simulated together
    on the first case's turn (batch.py); on Exudyn each case runs alone when its turn comes."""
    if cfg.execute.plant != "lagrange":
        return [Case(cid, lambda log, t=(k, d, hd): simulate_tuning(log, cfg, *t)) for cid, k, d, hd in tunings]
    results: dict[str, tuple] = {}

    def simulate_all() -> None:
        arm = arm_of(cfg)
        control = cfg.system.control
        laws = [gains(cfg, k, d, hd) for _, k, d, hd in tunings]
        out = batch.simulate(arm, [g for _, g in laws], motion_of(cfg, arm), home(cfg), cfg.scenario.duration,
                             control.dt, round(control.dt / cfg.execute.dt), control.gl_terms,
                             control.implementation, control.compensate_stiffness)
        for (cid, *_), (law, g), run, failure in zip(tunings, laws, out.runs, out.failures, strict=True):
            results[cid] = (arm, law, g, run, failure)

    def simulate(log: RunWriter, cid: str) -> None:
        if not results:
            simulate_all()
        arm, law, g, run, failure = results.pop(cid)
        log.attach("model.yaml", _model_yaml(cfg, arm, law, g), "application/yaml")
        if failure:
            raise SimulationFailed(failure)
        log_closed_loop(log, cfg, arm, motion_of(cfg, arm), run, law)

    return [Case(cid, lambda log, c=cid: simulate(log, c), shares_work=True) for cid, *_ in tunings]


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
        log_arm(log, arm, t[tf], q_d[tf])

    return [Case("setpoint", simulate)]


# -- E2: Table 2 and Figs. 8-10 -----------------------------------------------------------------------------


def table2(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    return tuning_cases(cfg, [(f"{name}-k{k:g}", float(k), float(sc.tunings[name].d_xyz),
                               float(sc.tunings[name].hd_xyz)) for k in sc.k_xyz for name in sc.controllers])


# -- E3: the Fig. 6 maps, one run per grid point ------------------------------------------------------------


def maps(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    stiffnesses = sc.k_xyz if isinstance(sc.k_xyz, ListConfig) else [sc.k_xyz]
    return tuning_cases(cfg, [(f"k{k:g}-d{d:g}-hd{hd:g}", float(k), float(d), float(hd))
                              for k in stiffnesses for hd in sc.hd_xyz for d in sc.d_xyz])


# -- E4: along the equal-ICE line, Fig. 7 -------------------------------------------------------------------


def locus(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    line = sc.line
    return tuning_cases(cfg, [(f"k{k:g}-d{d:g}", float(k), float(d),
                               max(0.0, round(line.intercept + line.slope * d, 6)))   # eq. (20)
                              for k in sc.k_xyz for d in sc.d_xyz])

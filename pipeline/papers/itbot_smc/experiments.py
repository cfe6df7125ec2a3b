"""Simulate stage of `itbot-smc`: the passive multi-joint exercise under nSMERL, SMERL and conventional SMC on
both plants (Figs. 6-11), the conventional SMC's gain and boundary layer (a Hydra sweep), the share of the
load the subject carries (the force comparison), and the reaching-time study of Proposition 1."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, robot, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, seconds_to_ns
from pipeline.papers.itbot_smc import SYSTEM_ATTACHMENT, reaching
from pipeline.papers.itbot_smc.closed_loop import ClosedLoopRun, Reference, run_closed_loop
from pipeline.papers.itbot_smc.controller import JointSensor, SlidingModeController
from pipeline.papers.itbot_smc.model import JOINTS, Links, fk, mdh_frames
from pipeline.papers.itbot_smc.mujoco_arm import BASE_QUAT, MujocoPlant, arm_mjcf, base_position, rotation
from pipeline.papers.itbot_smc.plants import AnalyticPlant, Drive, HandLoad
from pipeline.papers.itbot_smc.reaching import LawGains

HAND_AXES = ("x", "y")
TF_FRAMES = ("base", "link1", "link2", "hand", "hand_reference")
FORCE_RGBA, FORCE_SCALE = (0.95, 0.5, 0.1, 1.0), 0.005  # the hand's force drawn at 5 mm/N


@dataclass(frozen=True)
class Setup:
    """Everything one closed-loop run is built from, resolved from `system` (with a case's changes)."""

    system: DictConfig
    links: Links
    drive: Drive
    load: HandLoad
    reference: Reference
    period: float

    @classmethod
    def of(cls, system: DictConfig) -> Setup:
        return cls(system, Links.from_config(system), Drive.from_config(system.drive),
                   HandLoad.from_config(system.hand), Reference.from_config(system.reference),
                   1.0 / float(system.control.rate_hz))

    def mjcf(self, joint_limits: bool = True) -> str:
        s = self.system
        return arm_mjcf(self.links, self.drive, self.load, configuration=s.configuration, drawing=s.drawing,
                        z2=float(s.links.z2), joint_limits=tuple(s.joint_limits_deg) if joint_limits else None,
                        timestep=self.period, gravity=float(s.gravity))

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        q_d, qd_d, _ = self.reference(np.zeros(1))
        return q_d[0] + np.radians(list(self.system.reference.initial_error_deg)), qd_d[0]

    def plant(self, kind: str, substeps: int):
        q0, qd0 = self.initial_state()
        if kind == "mujoco":
            return MujocoPlant(self.mjcf(), self.links, self.load, self.system.configuration, self.period, q0, qd0)
        return AnalyticPlant(self.links, self.drive, self.load, self.period, substeps, q0, qd0)

    def controller(self, law: str) -> SlidingModeController:
        control = self.system.control
        model, known = control.model, self.load if control.model.hand_load else None
        links = self.links.with_point_mass(known.mass if known else 0.0).scaled(float(model.mass_scale))
        support = known.support * known.mass * self.links.gravity if known else 0.0
        return SlidingModeController(law, LawGains.from_config(control), list(control["lambda"]), links,
                                     armature=self.drive.armature if model.armature else (0.0, 0.0),
                                     friction=list(model.friction), hand_support=support)

    def sensor(self) -> JointSensor:
        s = self.system.sensing
        if s.model == "ideal":
            return JointSensor(0.0, "exact", float(s.velocity_cutoff_hz), self.period)
        return JointSensor(math.radians(float(s.resolution_deg)), s.velocity, float(s.velocity_cutoff_hz),
                           self.period, qd0=self.initial_state()[1])


def _stride(log_dt: float, period: float) -> int:
    """Ticks between logged samples: `log_dt` rounded to whole control periods (at least one)."""
    return max(1, round(log_dt / period))


def world_from_base(configuration: str, drawing) -> np.ndarray:
    """4×4 pose of frame 0 in the world (the MJCF's `base` body)."""
    T = np.eye(4)
    T[:3, :3] = rotation(BASE_QUAT[configuration])
    T[:3, 3] = base_position(configuration, drawing)
    return T


def log_run(log: RunWriter, setup: Setup, execute: DictConfig, law: str, run: ClosedLoopRun) -> None:
    """Every tick: torques, the hand force, the sliding variable, the controller's time; every `log_dt`:
    states, references, errors; every `tf_dt`: the link frames."""
    links = setup.links
    fine = slice(None, None, _stride(execute.log_dt, setup.period))
    t, q, qd = run.t[fine], run.q[fine], run.qd[fine]
    q_d, qd_d, qdd_d = setup.reference(t)
    joints = list(JOINTS)
    log.log_series("/joint_state", t, units="rad", name=joints, position=q, velocity=qd, effort=run.tau[fine])
    log.log_series("/joint_state/measured", t, units="rad", name=joints, position=run.q_measured[fine],
                   velocity=run.qd_measured[fine])
    log.log_series("/reference", t, units="rad", name=joints, position=q_d, velocity=qd_d, acceleration=qdd_d)
    error = q_d - q
    log.log_series("/tracking_error", t, units="rad", name=joints, error=error, norm=np.linalg.norm(error, axis=1))
    hand_d, hand = fk(links, q_d), fk(links, q)
    log.log_series("/reference/hand", t, units="m", name=list(HAND_AXES), position=hand_d)
    hand_error = hand_d - hand
    log.log_series("/tracking_error/hand", t, units="m", name=list(HAND_AXES), error=hand_error,
                   norm=np.linalg.norm(hand_error, axis=1))
    force, zeros = run.hand_force, np.zeros((len(run.t), 1))
    log.log_series("/wrench", run.t, frame_id="base", name=["hand"], force_x=force[:, :1], force_y=force[:, 1:],
                   force_z=zeros, torque_x=zeros, torque_y=zeros, torque_z=zeros)
    log.log_series("/command", run.t, units="rad", kind="torque", name=joints, value=run.tau)
    log.log_series("/sliding_variable", run.t, schemas.Scalars, units="rad/s", name=joints, value=run.v)  # v = ė + λe
    log.log_series("/compute_time", run.t, name=[law], seconds=run.controller_s[:, None], calls=[1])
    tf = slice(None, None, _stride(execute.tf_dt, setup.period))
    frames = frames_in_world(setup, run.q[tf], run.t[tf])
    log.log_transforms(run.t[tf], "world", list(TF_FRAMES), frames)
    log_force_arrows(log, run.t[tf], frames, force[tf])


def log_force_arrows(log: RunWriter, t: np.ndarray, frames: np.ndarray, force_base: np.ndarray) -> None:
    """The hand's force on the handle (N, in frame 0) as an arrow from the /tf frame `hand`, thinned to the
    viewers' rate: the robot itself is drawn from the attached model (robot.urdf, from /joint_state)."""
    keep = robot.thinned(t)
    world_from_hand, world_from_base = frames[keep, 3, :3, :3], frames[keep, 0, :3, :3]
    f_base = np.column_stack([force_base[keep], np.zeros(len(keep))])
    f_hand = np.einsum("nji,njk,nk->ni", world_from_hand, world_from_base, f_base)
    for t_k, f_k in zip(t[keep], f_hand, strict=True):
        log.write("/markers", seconds_to_ns(t_k), schemas.SceneUpdate(entities=[markers.arrow(
            "hand_force", "hand", f_k, FORCE_RGBA, scale=FORCE_SCALE)]))


def frames_in_world(setup: Setup, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(N, 5, 4, 4): base, link1, link2, hand and the hand's reference point, in the world."""
    world = world_from_base(setup.system.configuration, setup.system.drawing)
    frames = mdh_frames(setup.links, q)
    target = frames[:, 2].copy()
    target[:, :2, 3] = fk(setup.links, setup.reference(t)[0])
    local = np.concatenate([np.broadcast_to(np.eye(4), (len(q), 1, 4, 4)), frames, target[:, None]], axis=1)
    return world @ local


def simulate_case(log: RunWriter, system: DictConfig, execute: DictConfig, law: str, plant_kind: str) -> None:
    setup = Setup.of(system)
    xml = setup.mjcf()
    log.attach("model.xml", xml, "application/xml")
    log.attach(SYSTEM_ATTACHMENT, OmegaConf.to_yaml(system, resolve=True), "application/yaml")
    plant = setup.plant(plant_kind, int(execute.substeps))
    run = run_closed_loop(plant, setup.controller(law), setup.sensor(), setup.reference, setup.period,
                          setup.drive.torque_limit)
    if plant_kind == "mujoco":
        plant.check(np.concatenate([run.q, run.qd], axis=1), run.t)
    log_run(log, setup, execute, law, run)


def _with(system: DictConfig, changes: dict) -> DictConfig:
    out = OmegaConf.create(OmegaConf.to_container(system, resolve=True))
    for key, value in changes.items():
        OmegaConf.update(out, key, value, merge=False)
    return out


# -- the exercise under the three controllers, Figs. 6-11 ---------------------------------------------------


def tracking(cfg: DictConfig) -> list[Case]:
    """Each law (or the group's own `laws`) in each group of `scenario.groups` (a plant, a sensing model and
    the time rate of nSMERL's ω): `<law>-<group>`."""
    sc, ex = cfg.scenario, cfg.execute

    def system(group: DictConfig) -> DictConfig:
        return _with(cfg.system, {"sensing.model": group.sensing, "control.omega_rate": float(group.omega_rate)})

    return [Case(f"{law}-{name}", lambda log, law=law, g=group: simulate_case(log, system(g), ex, law, g.plant))
            for name, group in sc.groups.items() for law in (group.laws or sc.laws)]


# -- conventional SMC: gain and boundary layer (one grid point; the grid is a Hydra sweep) ------------------


def smc_sweep(cfg: DictConfig) -> list[Case]:
    """The tracking experiment's `smc-<plant>` run at one grid point: its sweep runs `smc-<plant>__<overrides>`
    are the band of the SMC targets."""
    plant = cfg.scenario.plant
    return [Case(f"smc-{plant}", lambda log: simulate_case(log, cfg.system, cfg.execute, "smc", plant))]


# -- the share of the load the subject carries: the force comparison (a Hydra sweep of system.hand.support) -----


def load_support(cfg: DictConfig) -> list[Case]:
    """The tracking experiment's `<law>-<plant>` run with the subject carrying the share system.hand.support of
    the load (the controller's model knows it, as the handle's force sensor reads it at rest): its sweep runs
    `<law>-<plant>__system.hand.support=s` are the band of the force targets. Where the subject carries all of
    it (support 1), also the paper's bare model (A8)-(A10), without the load, under each law
    (`paper-model-<law>`): only the load's inertia is then unknown to the controller."""
    sc, ex = cfg.scenario, cfg.execute
    cases = [Case(f"{sc.law}-{sc.plant}", lambda log: simulate_case(log, cfg.system, ex, sc.law, sc.plant))]
    if float(cfg.system.hand.support) == 1.0:
        bare = _with(cfg.system, {"control.model.hand_load": False})
        cases += [Case(f"paper-model-{law}", lambda log, law=law: simulate_case(log, bare, ex, law, sc.plant))
                  for law in sc.paper_model_laws]
    return cases


# -- reaching time against |v(0)|, Proposition 1 -------------------------------------------------------------


STUDY_FIELDS = ("v0", "smc", "smerl", "nsmerl", "nsmerl_no_switching", "eq7", "eq14", "eq13", "eq21")


def reaching_time(cfg: DictConfig) -> list[Case]:
    """Per joint of Table 3 and per α (Table 3's and the limit α → ∞ in which eq. (27) is exact): the reaching
    time of each law from |v(0)| on a log grid, by integration, beside the paper's closed forms (eq. 13 at
    ω = ω(0) = 1, eq. 21 at ω → 0 as the proof takes it)."""
    sc = cfg.scenario
    gains = LawGains.from_config(cfg.system.control)

    def simulate(log: RunWriter, joint: int, alpha: float) -> None:
        g = replace(gains.joint(joint), alpha=alpha, smc_K=float(gains.K[joint]), boundary_layer=0.0)
        K, phi, p, power = g.K, g.phi, g.p, g.power
        rows = []
        for v0 in np.geomspace(float(sc.v0_min), float(sc.v0_max), int(sc.points)):
            times = reaching.reaching_times(float(v0), g)
            rows.append([v0, times["smc"], times["smerl"], times["nsmerl"], times["nsmerl_no_switching"],
                         reaching.erl_reaching_time(v0, K, phi, alpha, p), reaching.erl_bound(v0, K, phi, alpha, p),
                         reaching.nsmerl_time_eq13(v0, K, phi, alpha, p, power, 1.0),
                         reaching.nsmerl_time_eq21(v0, K, phi, power, 0.0)])
        # one record per |v(0)|, 1 ms apart on the log's time axis (a study, not a trajectory)
        log.log_series("/reaching_time", np.arange(len(rows)) * 1e-3, schemas.Scalars, name=list(STUDY_FIELDS),
                       units=["rad/s"] + ["s"] * (len(STUDY_FIELDS) - 1), value=np.array(rows))
        bracket = (float(sc.v0_min), float(sc.v0_max))
        # the threshold (27) and the crossovers are values of |v(0)|; α scales |v|^p in exp(−α|v|^p)
        log.log("/reaching_time/summary", 0.0, schemas.Scalars,
                units=["rad/s", "rad/s", "rad/s", "rad/s^2", "1", f"(rad/s)^-{p:g}", "1", "1"],
                name=["threshold", "crossover", "crossover_no_switching", "K", "phi", "alpha", "p", "power"],
                value=[reaching.proposition_threshold(power), reaching.crossover(g, bracket, switching=True),
                       reaching.crossover(g, bracket, switching=False), K, phi, alpha, p, power])

    return [Case(f"joint{j}-alpha{a:g}", lambda log, j=int(j) - 1, a=float(a): simulate(log, j, a))
            for j in sc.joints for a in sc.alphas]

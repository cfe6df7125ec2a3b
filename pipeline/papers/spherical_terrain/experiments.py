"""Simulate stage of `spherical-terrain`: the four robot classes on the circle and the diamond (Figs. 6-12),
as corrected and as printed, a gain/start sweep, and a MuJoCo physics check of the no-slip model.

One experiment simulates all its robots together (one batch, `tracking.simulate`); each case logs one
robot's run."""

from __future__ import annotations

import numpy as np
from omegaconf import DictConfig
from scipy.spatial.transform import Rotation

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.papers.spherical_terrain.kinematics import CosineTerrain, tangent_rotation
from pipeline.papers.spherical_terrain.tracking import (
    GainTable,
    Model,
    Trajectory,
    controls,
    references,
    simulate,
    start_states,
)

# /joint_state: the robot's own angles (θ, φ, ψ; α instead of θ for RS) and their applied rates
ANGLES = {"3r": ["theta", "phi", "psi"], "2r": ["theta", "phi", "psi"], "rt": ["theta", "phi", "psi"],
          "rs": ["alpha", "phi", "psi"]}
# /command: the rates each class actuates (Sec. 5)
ACTUATED = {"3r": ["theta_dot", "phi_dot", "psi_dot"], "2r": ["theta_dot", "phi_dot"],
            "rt": ["theta_dot", "psi_dot"], "rs": ["alpha_dot", "phi_dot"]}
XYZ = ["x", "y", "z"]
PURSUIT = ["zeta", "g", "v_d", "tilt_saturated"]


def terrain(cfg: DictConfig) -> CosineTerrain:
    return CosineTerrain(cfg.system.terrain.amplitude, cfg.system.terrain.frequency)


def check_assumptions(cfg: DictConfig) -> None:
    """Assumption 3 of Sec. 2: the surface's radius of curvature is never smaller than R."""
    kappa = terrain(cfg).max_curvature
    if kappa * cfg.system.radius > 1.0:
        raise SimulationFailed(f"the terrain's smallest radius of curvature 1/(aω²) = {1 / kappa:.3g} m is below "
                               f"R = {cfg.system.radius:g} m: single-point contact (Sec. 2, assumption 3) fails")


def model(cfg: DictConfig, classes: list[str]) -> Model:
    s = cfg.system
    gains = GainTable.build(classes, s.controller, s.controller.gain_scale, s.form.eq58)
    return Model(terrain(cfg), s.radius, s.controller.k_e, s.tilt_limit, gains, s.form.eq25)


def robots(cfg: DictConfig) -> list[tuple[str, str]]:
    """(class, path) of every case, in case order."""
    return [(c, p) for c in cfg.scenario.classes for p in cfg.scenario.paths]


def run_batch(cfg: DictConfig) -> tuple[Model, list[tuple[str, str]], Trajectory]:
    """All robots of the experiment, integrated together, sampled every log_dt."""
    s = cfg.system
    pairs = robots(cfg)
    m = model(cfg, [c for c, _ in pairs])
    start = start_states(m.terrain, len(pairs), s.start.x, s.start.y, s.start.heading)
    t = np.arange(round(s.duration / s.dt) + 1) * s.dt
    p_d, p_d_dot = references(m, [p for _, p in pairs], t, s.paths, s.form.eq60)
    traj = simulate(m, s.dt, p_d, p_d_dot, start, max(1, round(s.log_dt / s.dt)))
    return m, pairs, traj


def shell_angular_velocity(c: dict, radius: float) -> np.ndarray:
    """World angular velocity of the shell from the rates of `controls`, (..., 3): its tangential part rolls
    the sphere as ^L V = (u, v) (ω × R n̂ = R(ω_l ĥ − ω_h l̂)); its normal part is the turning rate ψ̇ (eq. 46
    for RS), which moves the contact point in neither the paper's model nor rigid rolling."""
    h, lat, n = (np.stack(v, axis=-1) for v in (c["h"], c["l"], c["n"]))
    return ((c["u"] / radius)[..., None] * lat - (c["v"] / radius)[..., None] * h
            + np.asarray(c["turn"])[..., None] * n)


def shell_orientation(t: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """(N, 3, 3) shell attitude from its world angular velocity (N, 3) sampled at t, one exponential step
    per sample (for the 3-D replay only)."""
    steps = Rotation.from_rotvec(omega[:-1] * np.diff(t)[:, None]).as_quat().tolist()   # (x, y, z, w)
    x, y, z, w = 0.0, 0.0, 0.0, 1.0
    attitude = [(x, y, z, w)]
    for bx, by, bz, bw in steps:  # q ← step ⊗ q (world-frame increments), plain floats: 20x faster than Rotation
        x, y, z, w = (bw * x + bx * w + by * z - bz * y, bw * y - bx * z + by * w + bz * x,
                      bw * z + bx * y - by * x + bz * w, bw * w - bx * x - by * y - bz * z)
        attitude.append((x, y, z, w))
    return Rotation.from_quat(attitude).as_matrix()


SHELL_COLOR, GHOST_COLOR = (0.9, 0.6, 0.2, 0.8), (0.2, 0.5, 0.9, 0.35)


def log_scene(log: RunWriter, terrain: CosineTerrain, radius: float, spheres: dict[str, tuple],
              half_extent: float = 3.0, spacing: float = 0.1) -> None:
    """`/markers` for the 3-D replay: a sphere of radius R at each named /tf frame, and the terrain surface."""
    axis = np.linspace(-half_extent, half_extent, round(2 * half_extent / spacing) + 1)
    x, y = np.meshgrid(axis, axis)
    entities = [*markers.spheres(list(spheres), [radius] * len(spheres), list(spheres.values())),
                markers.height_field("terrain", axis, axis, terrain.height(x, y))]
    log.write("/markers", 0, schemas.SceneUpdate(entities=entities))


def robot_model(m: Model, k: int) -> Model:
    """The batch model restricted to robot k."""
    gains = GainTable(**{f: getattr(m.gains, f)[k:k + 1] for f in GainTable.__dataclass_fields__})
    return Model(m.terrain, m.radius, m.k_e, m.tilt_limit, gains, m.heading)


def log_robot(log: RunWriter, m: Model, robot: str, traj: Trajectory, k: int, tf_every: int) -> None:
    """Write robot k of the batch as one run."""
    state, p_d, p_d_dot = traj.state[:, k], traj.p_d[:, k], traj.p_d_dot[:, k]
    bad = ~np.isfinite(state).all(axis=1)
    if bad.any():
        raise SimulationFailed(f"state not finite at t = {traj.t[np.argmax(bad)]:.4g} s")
    v_d = np.linalg.norm(p_d_dot, axis=-1)
    c = controls(robot_model(m, k), state, p_d, v_d)
    t = traj.t
    error = np.column_stack(c["error"])
    log.log_series("/reference", t, units="m", name=XYZ, position=p_d, velocity=p_d_dot)
    log.log_series("/tracking_error", t, units="m", name=XYZ, error=error, norm=np.linalg.norm(error, axis=1))
    rates = np.column_stack([c["roll"], c["tilt"], c["turn"]])
    log.log_series("/joint_state", t, units="rad", name=ANGLES[robot], position=state[:, [5, 4, 3]], velocity=rates)
    asked = {"theta_dot": c["roll"], "alpha_dot": c["roll"], "phi_dot": c["tilt_command"], "psi_dot": c["turn"]}
    log.log_series("/command", t, units="rad", kind="velocity", name=ACTUATED[robot],
                   value=np.column_stack([asked[a] for a in ACTUATED[robot]]))
    saturated = (np.abs(state[:, 4]) >= m.tilt_limit - 1e-12) & bool(m.gains.steering[k])
    log.log_series("/pursuit", t, schemas.Scalars, name=PURSUIT, units=["rad", "1", "m/s", "1"],
                   value=np.column_stack([c["zeta"], c["g"], v_d, saturated.astype(float)]))
    # 3-D replay: contact frame [ĥ l̂ n̂] at P0, the shell at O_Sp (eq. 51), the target on the surface
    h, lat, n = (np.column_stack(v) for v in (c["h"], c["l"], c["n"]))
    omega = shell_angular_velocity(c, m.radius)
    every = slice(None, None, tf_every)
    frames = np.zeros((len(t), 3, 4, 4))
    frames[:, :, 3, 3] = 1.0
    frames[:, 0, :3, :3] = np.stack([h, lat, n], axis=-1)
    frames[:, 0, :3, 3] = state[:, :3]
    frames[:, 1, :3, :3] = shell_orientation(t, omega)
    frames[:, 1, :3, 3] = state[:, :3] + m.radius * n
    frames[:, 2, :3, :3] = tangent_rotation(*m.terrain.gradient(p_d[:, 0], p_d[:, 1]))
    frames[:, 2, :3, 3] = p_d
    log.log_transforms(t[every], "world", ["contact", "sphere", "target"], frames[every])
    log_scene(log, m.terrain, m.radius, {"sphere": SHELL_COLOR})


def tracking(cfg: DictConfig) -> list[Case]:
    """`paths`, `printed` and `sweep`: one case per (class, path)."""
    batch: dict = {}

    def simulate_case(log: RunWriter, k: int) -> None:
        check_assumptions(cfg)
        if "result" not in batch:
            batch["result"] = run_batch(cfg)
        m, pairs, traj = batch["result"]
        log_robot(log, m, pairs[k][0], traj, k, max(1, round(cfg.system.tf_dt / cfg.system.log_dt)))

    return [Case(f"{c}-{p}", lambda log, k=k: simulate_case(log, k)) for k, (c, p) in enumerate(robots(cfg))]

"""Physics check (not in the paper): does a rigid ball on the terrain move the way the no-slip model says?

Each robot becomes a free ball (the paper's R, an assumed mass) on a MuJoCo height field sampled from
eq. (59), with Coulomb friction. The paper's controller runs in closed loop on the ball: every control step
it reads the ball's contact point, keeps the robot's internal angles (ψ, and φ for RS) by integrating its own
commands as the kinematic model does, and asks for the shell angular velocity ω that eq. (31) needs;
three torque-limited velocity actuators (the internal drive) turn the ball. Gravity, contact softness, slip,
inertia, the drive's limits and the field's facets are what physics adds.

At every step the ball's contact-point velocity is compared with what two models make of the ball's own
measured ω: (a) the paper's, eq. (31): ṗ = ω × R n̂, and (b) exact rigid rolling without slip: the centre
moves at ω × R n̂, so ṗ_xy = (I + R ∂n̂_xy/∂(x, y))⁻¹ (ω × R n̂)_xy — the curvature term the paper drops
(spec §10-A8). The same controller on the kinematic model (same step) runs beside it.
"""

from __future__ import annotations

import numpy as np
from omegaconf import DictConfig
from scipy.spatial.transform import Rotation

from pipeline.core import schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.papers.spherical_terrain.experiments import (
    GHOST_COLOR,
    SHELL_COLOR,
    XYZ,
    check_assumptions,
    log_scene,
    model,
    robots,
    run_batch,
    shell_angular_velocity,
)
from pipeline.papers.spherical_terrain.kinematics import CosineTerrain, contact_xy_velocity, normal
from pipeline.papers.spherical_terrain.tracking import Model, controls, references, start_states

CONJUGATE = np.array([1.0, -1.0, -1.0, -1.0])
CONTACT_SCALE = 0.01   # m/N: the 2 kg ball's ~20 N ground force drawn 20 cm long
# /physics: contact-point speed of the ball and of the paper's model for the ball's own ω, how far the
# ball's contact velocity is from the paper's and from rigid rolling, slip speed, gap, drive error |ω − ω_cmd|
PHYSICS = ["actual_speed", "paper_speed", "paper_model_error", "rigid_model_error", "slip_speed", "gap",
           "omega_error"]
PHYSICS_UNITS = ["m/s", "m/s", "m/s", "m/s", "m/s", "m", "rad/s"]


def terrain_mjcf(terrain: CosineTerrain, radius: float, p: DictConfig, centers: np.ndarray) -> str:
    """MJCF: the height field of eq. (59) on [−L, L]² and one free ball per robot (balls do not collide
    with each other), each turned by three velocity actuators about its body axes (the control loop gives
    them the body-frame components of the world ω it wants), limited to ±torque_limit like a real drive."""
    count = round(2 * p.half_extent / p.grid) + 1
    axis = np.linspace(-p.half_extent, p.half_extent, count)
    x, y = np.meshgrid(axis, axis)                      # rows along y
    height = terrain.height(x, y)
    span = max(float(np.ptp(height)), 1e-3)   # a flat field still needs a positive elevation range
    low = float(height.max()) - span
    # MuJoCo reads `elevation` top row (+y) first and divides it by its maximum: rows reversed, maximum 1
    rows = (height - low) / span
    elevation = "\n".join(" ".join(f"{v:.7f}" for v in row) for row in rows[::-1])
    balls, actuators = [], []
    for k, c in enumerate(centers):
        balls.append(f"""    <body name="ball{k}" pos="{c[0]:.17g} {c[1]:.17g} {c[2]:.17g}">
      <freejoint/>
      <geom name="ball{k}" type="sphere" size="{radius:.17g}" mass="{p.mass:.17g}" contype="2" conaffinity="1"/>
      <site name="center{k}"/>
    </body>""")
        for name, gear in (("x", "0 0 0 1 0 0"), ("y", "0 0 0 0 1 0"), ("z", "0 0 0 0 0 1")):
            actuators.append(f'    <velocity name="omega{k}_{name}" site="center{k}" gear="{gear}" '
                             f'kv="{p.servo_gain:.17g}" forcelimited="true" '
                             f'forcerange="{-p.torque_limit:.17g} {p.torque_limit:.17g}"/>')
    return f"""<mujoco model="spherical_terrain">
  <compiler angle="radian"/>
  <option timestep="{p.timestep:.17g}" integrator="implicitfast" cone="elliptic" impratio="10"/>
  <default>
    <geom friction="{p.friction:.17g} 0 0" condim="3"/>
  </default>
  <asset>
    <hfield name="terrain" nrow="{count}" ncol="{count}"
            size="{p.half_extent:.17g} {p.half_extent:.17g} {span:.17g} 0.2" elevation="{elevation}"/>
  </asset>
  <worldbody>
    <geom name="terrain" type="hfield" hfield="terrain" pos="0 0 {low:.17g}" contype="1" conaffinity="2"/>
{chr(10).join(balls)}
  </worldbody>
  <actuator>
{chr(10).join(actuators)}
  </actuator>
</mujoco>
"""


def contact_point(terrain: CosineTerrain, center: np.ndarray, radius: float, guess: np.ndarray | None = None,
                  iterations: int = 6) -> np.ndarray:
    """p on z = f(x, y) with c = p + R n̂(p), (..., 3): the fixed point p_xy = c_xy + R s_n ∇f(p_xy), a
    contraction by R κ ≤ 0.16 per iteration here (assumption 3 of the paper: R κ < 1)."""
    xy = (center[..., :2] if guess is None else guess[..., :2]).copy()
    for _ in range(iterations):
        fx, fy = terrain.gradient(xy[..., 0], xy[..., 1])
        s_n = radius / np.sqrt(1.0 + fx * fx + fy * fy)
        xy[..., 0], xy[..., 1] = center[..., 0] + s_n * fx, center[..., 1] + s_n * fy
    return np.concatenate([xy, terrain.height(xy[..., 0], xy[..., 1])[..., None]], axis=-1)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis (np.cross costs 10x more on small batches)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def lift(terrain: CosineTerrain, p: np.ndarray, velocity_xy: np.ndarray) -> np.ndarray:
    """A planar velocity at p made tangent to the surface: ż = f_x ẋ + f_y ẏ."""
    fx, fy = terrain.gradient(p[..., 0], p[..., 1])
    return np.concatenate([velocity_xy, (fx * velocity_xy[..., 0] + fy * velocity_xy[..., 1])[..., None]], axis=-1)


def closed_loop(cfg: DictConfig, m: Model, paths: list[str]) -> dict[str, np.ndarray]:
    """The controller of eqs. (55)-(58) driving MuJoCo balls, every control step (system.dt) recorded:
    ball centre, linear velocity, attitude (w, x, y, z), body angular velocity, and the commanded world ω; and
    every system.tf_dt each ball's terrain contact (ground_contacts)."""
    import mujoco

    from pipeline.robotics.mjcf import check_mujoco

    s, p = cfg.system, cfg.system.physics
    dt, radius, substeps = float(s.dt), float(s.radius), round(s.dt / p.timestep)
    if substeps < 1 or abs(substeps * p.timestep - dt) > 1e-12:
        raise SimulationFailed(f"system.dt = {dt:g} s must be a multiple of physics.timestep = {p.timestep:g} s")
    k, steps = len(paths), round(s.duration / dt)
    t = np.arange(steps + 1) * dt
    p_d, p_d_dot = references(m, paths, t, s.paths, s.form.eq60)
    v_d = np.linalg.norm(p_d_dot, axis=-1)
    state = start_states(m.terrain, k, s.start.x, s.start.y, s.start.heading)   # [p (from MuJoCo), ψ, φ, θ]
    centers = state[:, :3] + radius * normal(*m.terrain.gradient(state[:, 0], state[:, 1]))
    xml = terrain_mjcf(m.terrain, radius, p, centers)
    mj_model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(mj_model)
    mujoco.mj_forward(mj_model, data)
    qpos, qvel = data.qpos.reshape(k, 7), data.qvel.reshape(k, 6)   # views, updated in place by mj_step
    out = {name: np.empty((steps + 1, k, size)) for name, size in
           (("center", 3), ("velocity", 3), ("quat", 4), ("omega_body", 3), ("omega_command", 3),
            ("contact_point", 3), ("contact_force", 3))}
    ball_of_geom = {mj_model.geom(f"ball{b}").id: b for b in range(k)}
    contacts_every = max(1, round(s.tf_dt / dt))   # drawn at the /tf rate: recorded there only (NaN between)
    out["contact_point"][:], out["contact_force"][:] = np.nan, np.nan
    steer = m.gains.steering
    for i in range(steps + 1):
        out["center"][i], out["velocity"][i], out["quat"][i], out["omega_body"][i] = \
            qpos[:, :3], qvel[:, :3], qpos[:, 3:], qvel[:, 3:]
        if i % contacts_every == 0:
            out["contact_point"][i], out["contact_force"][i] = ground_contacts(mj_model, data, ball_of_geom)
        state[:, :3] = contact_point(m.terrain, qpos[:, :3], radius, state[:, :3], iterations=3)
        c = controls(m, state, p_d[i], v_d[i])
        omega = shell_angular_velocity(c, radius)
        out["omega_command"][i] = omega
        if i == steps:
            break
        for _ in range(substeps):  # the drive turns the world ω into the ball's body axes every physics step
            data.ctrl[:] = _rotate(qpos[:, 3:] * CONJUGATE, omega).ravel()
            mujoco.mj_step(mj_model, data)
        state[:, 3:] += dt * np.stack([c["turn"], c["tilt"], c["roll"]], axis=-1)   # the robot's own angles
        state[steer, 4] = np.clip(state[steer, 4], -m.tilt_limit, m.tilt_limit)
    check_mujoco(data, out["center"].reshape(len(t), -1), t)
    return out | {"t": t, "p_d": p_d, "p_d_dot": p_d_dot, "xml": xml}


def ground_contacts(mj_model, data, ball_of_geom: dict[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Per ball, MuJoCo's terrain contact: the mean contact position and the total force on the ball (world
    frame, N); NaN position and zero force for a ball in the air."""
    import mujoco

    k = len(ball_of_geom)
    points, forces, count = np.zeros((k, 3)), np.zeros((k, 3)), np.zeros(k)
    wrench = np.zeros(6)
    for i in range(data.ncon):
        con = data.contact[i]
        ball = ball_of_geom.get(con.geom2, ball_of_geom.get(con.geom1))
        if ball is None or con.efc_address < 0:
            continue
        mujoco.mj_contactForce(mj_model, data, i, wrench)
        f = con.frame.reshape(3, 3).T @ wrench[:3]   # on geom2, along the normal from geom1 to geom2
        forces[ball] += f if con.geom2 in ball_of_geom else -f
        points[ball] += con.pos
        count[ball] += 1
    with np.errstate(invalid="ignore", divide="ignore"):
        return points / count[:, None], forces


def rolling_check(terrain: CosineTerrain, ball: dict, radius: float) -> dict[str, np.ndarray]:
    """At every recorded step, from the ball's own state: its contact point p, the contact-point velocity it
    actually has, and what the paper's model (eq. 31: ω × R n̂) and exact rigid rolling predict from its
    measured ω; the slip speed of the contact and the ball-surface gap along n̂ (< 0: penetration)."""
    center, velocity = ball["center"], ball["velocity"]
    p = contact_point(terrain, center, radius)
    n = normal(*terrain.gradient(p[..., 0], p[..., 1]))
    omega = _rotate(ball["quat"], ball["omega_body"])               # free joint: ω in the body frame
    rolling = radius * cross(omega, n)                               # ċ of rolling without slip
    actual = lift(terrain, p, contact_xy_velocity(terrain, p[..., 0], p[..., 1], velocity, radius))
    return {"contact": p, "omega": omega, "actual": actual, "paper": rolling,
            "rigid": lift(terrain, p, contact_xy_velocity(terrain, p[..., 0], p[..., 1], rolling, radius)),
            "slip": np.linalg.norm(velocity - rolling, axis=-1),
            "gap": np.sum((center - p) * n, axis=-1) - radius}


def _rotate(quat_wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors v (..., 3) by unit quaternions (..., 4) (w, x, y, z)."""
    w, u = quat_wxyz[..., :1], quat_wxyz[..., 1:]
    return v + 2.0 * cross(u, cross(u, v) + w * v)


def physics_check(cfg: DictConfig) -> list[Case]:
    s = cfg.system
    pairs = robots(cfg)
    shared: dict = {}

    def simulate_case(log: RunWriter, k: int) -> None:
        check_assumptions(cfg)
        if "result" not in shared:
            m = model(cfg, [c for c, _ in pairs])
            ball = closed_loop(cfg, m, [q for _, q in pairs])
            shared["result"] = (m, ball, rolling_check(m.terrain, ball, s.radius), run_batch(cfg)[2])
        m, ball, rolling, kinematic = shared["result"]
        log.attach("model.xml", ball["xml"], "application/xml")
        every = slice(None, None, max(1, round(s.log_dt / s.dt)))
        t, p_d = ball["t"][every], ball["p_d"][every, k]
        r = {name: value[every, k] for name, value in rolling.items()}
        center = ball["center"][every, k]
        if not np.isfinite(center).all() or np.abs(center[:, :2]).max() > s.physics.half_extent:
            raise SimulationFailed("the ball left the height field")
        log.log_series("/reference", t, units="m", name=XYZ, position=p_d, velocity=ball["p_d_dot"][every, k])
        for topic, actual in (("/tracking_error", r["contact"]),
                              ("/tracking_error/kinematic_model", kinematic.state[:, k, :3])):
            error = p_d - actual
            log.log_series(topic, t, units="m", name=XYZ, error=error, norm=np.linalg.norm(error, axis=1))
        command = ball["omega_command"][every, k]
        log.log_series("/command", t, units="rad", kind="angular_velocity", name=["omega_x", "omega_y", "omega_z"],
                       value=command)
        norm = np.linalg.norm
        log.log_series("/physics", t, schemas.Scalars, name=PHYSICS, units=PHYSICS_UNITS, value=np.column_stack([
            norm(r["actual"], axis=1), norm(r["paper"], axis=1), norm(r["actual"] - r["paper"], axis=1),
            norm(r["actual"] - r["rigid"], axis=1), r["slip"], r["gap"], norm(r["omega"] - command, axis=1)]))
        tf = slice(None, None, max(1, round(s.tf_dt / s.dt)))
        kinematic_tf = kinematic.state[:, k, :3][::max(1, round(s.tf_dt / s.log_dt))]
        frames = np.tile(np.eye(4), (len(ball["t"][tf]), 3, 1, 1))
        frames[:, 0, :3, :3] = Rotation.from_quat(ball["quat"][tf, k], scalar_first=True).as_matrix()
        frames[:, 0, :3, 3] = ball["center"][tf, k]
        frames[:, 1, :3, 3] = kinematic_tf + s.radius * normal(*m.terrain.gradient(kinematic_tf[:, 0],
                                                                                    kinematic_tf[:, 1]))
        frames[:, 2, :3, 3] = ball["p_d"][tf, k]
        log.log_transforms(ball["t"][tf], "world", ["sphere", "kinematic_model/sphere", "target"], frames)
        qpos = np.concatenate([ball["center"][tf], ball["quat"][tf]], axis=-1)  # every ball's free joint
        log.log_robot(ball["t"][tf], qpos.reshape(len(qpos), -1))
        touching = np.isfinite(ball["contact_point"][tf, k]).all(axis=1)
        log.log_contacts(ball["t"][tf], [p[None] if c else np.zeros((0, 3)) for p, c in
                                         zip(ball["contact_point"][tf, k], touching, strict=True)],
                         [f[None] if c else np.zeros((0, 3)) for f, c in
                          zip(ball["contact_force"][tf, k], touching, strict=True)], CONTACT_SCALE, diameter=0.01)
        log_scene(log, m.terrain, s.radius, {"sphere": SHELL_COLOR, "kinematic_model/sphere": GHOST_COLOR})

    return [Case(f"{c}-{q}", lambda log, k=k: simulate_case(log, k)) for k, (c, q) in enumerate(pairs)]

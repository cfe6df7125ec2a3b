"""Simulate stage of `src-joint`: the joint model against physics (E1), reaching poses A and B (E2), the
floor under A and B over every model form and reading (E2'), and reaching C between two bars (E3). Every run
logs what the analysis needs to redraw Figs. 8-10, 13-14, 16-17 and a 3-D replay (/tf frames of the spheres,
/markers to draw them)."""

from __future__ import annotations

import numpy as np
from omegaconf import DictConfig, OmegaConf

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.papers.src_joint import reachability as reach
from pipeline.papers.src_joint import revolute
from pipeline.papers.src_joint import trolley as tr
from pipeline.papers.src_joint.ik import Bars, Damper, DamperQP, IkGains, IkResult, solve_ik
from pipeline.papers.src_joint.manipulator import (
    SENSING,
    Controller,
    Defects,
    FreeBotArm,
    Trace,
    position_mode,
    velocity_mode,
)
from pipeline.papers.src_joint.model import CONVENTIONS, Chain, ModelForm, qlog, quaternion_of, rotation
from pipeline.papers.src_joint.physics import (
    ContactPhysics,
    JointRecording,
    contact_paths,
    roll_exactly,
    roll_in_mujoco,
)
from pipeline.papers.src_joint.rolling import RollingChain, exp_so3
from pipeline.robotics.transforms import quaternion_wxyz

# scipy.spatial.transform is imported where it is used: 0.15 s to import, and reach-floor never needs it

AXES = ["x", "y", "z"]
CONTACT_SCALE = 0.01   # m/N: the joint's normal force drawn 1 cm per newton
SIX_UNITS = ["rad/s", "rad/s", "rad/s", "m/s", "m/s", "m/s"]   # wx, wy, wz, vx, vy, vz
TARGET_UNITS = ["m", "m", "m", "1", "1", "1", "1"]             # x, y, z and a unit quaternion
EULER = ["X", "Y", "Z"]   # intrinsic XYZ Euler angles (MATLAB rotm2eul(·, 'XYZ'), the paper's Figs. 9, 13, 14)


# -- shared pieces ------------------------------------------------------------------------------------------


def model_form(cfg: DictConfig, **overrides) -> ModelForm:
    return ModelForm(**{**OmegaConf.to_container(cfg.system.model), **overrides})


def freebot(cfg: DictConfig) -> tr.FreeBot:
    f = cfg.system.freebot
    return tr.FreeBot(r_in=f.r_in, r_out=f.r_out, wheel_radius=f.wheel_radius, wheel_interval=f.wheel_interval)


def ik_gains(cfg: DictConfig) -> IkGains:
    k = cfg.system.ik
    return IkGains(xi=k.xi, lambda_max=k.lambda_max, kp=k.kp, ka=k.ka)


def controller(cfg: DictConfig) -> Controller:
    s = cfg.system
    return Controller(bot=freebot(cfg), radius=s.freebot.radius, form=model_form(cfg),
                      gains=tr.Gains(k_s=s.trolley.k_s, k_phi1=s.trolley.k_phi1, k_phi2=s.trolley.k_phi2),
                      ik=ik_gains(cfg), steer_tol=s.trolley.steer_tol, azimuth=s.trolley.azimuth,
                      min_rate=s.trolley.min_rate, min_arc=s.trolley.min_arc, dt=s.control.dt)


def unit_quaternion(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    return q / np.linalg.norm(q)


def euler_xyz(R: np.ndarray) -> np.ndarray:
    """Intrinsic XYZ Euler angles (rad) of rotation matrices (..., 3, 3)."""
    from scipy.spatial.transform import Rotation
    return Rotation.from_matrix(R.reshape(-1, 3, 3)).as_euler("XYZ").reshape(*R.shape[:-2], 3)


def angle_of(R: np.ndarray) -> np.ndarray:
    """Rotation angle (rad) of rotation matrices (..., 3, 3), accurate near 0 (unlike acos of the trace)."""
    from scipy.spatial.transform import Rotation
    return Rotation.from_matrix(R.reshape(-1, 3, 3)).magnitude().reshape(R.shape[:-2])


def poses(positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    T = np.zeros((*positions.shape[:-1], 4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = rotations, positions, 1.0
    return T


def log_spheres(log: RunWriter, bodies: list[str], radii, colors: list[tuple]) -> None:
    """One `/markers` message at t = 0: a sphere of each radius in each body's /tf frame."""
    log.write("/markers", 0, schemas.SceneUpdate(entities=markers.spheres(bodies, radii, colors)))


GHOST_COLOR, LITERAL_COLOR = (0.2, 0.5, 0.9, 0.35), (0.7, 0.2, 0.8, 0.35)   # the model; eq. (5) read literally


# -- E1: the joint model against physics (Sec. V-A, Figs. 8-10) -----------------------------------------------


def contact_physics(cfg: DictConfig) -> ContactPhysics:
    return ContactPhysics(**OmegaConf.to_container(cfg.physics))


def model_beside(plant: JointRecording, lower: float, upper: float, form: ModelForm) -> dict[str, np.ndarray]:
    """The paper's model driven by the Ω^B the plant realised: rotation R(q_i) (eq. 6), joint velocity by
    eq. (1) and spatial velocity Φ_i w by eq. (8), at the plant's log times."""
    chain = Chain([lower, upper], form)
    dt = plant.times[1] - plant.times[0]
    count = len(plant.times)
    rotation_m, w, nu, tangent = (np.zeros((count, 3, 3)), np.zeros((count, 3)), np.zeros((count, 6)),
                                  np.zeros((count, 3, 3)))
    for j in range(count):
        F = chain.tangent_frames()
        rotation_m[j], tangent[j] = rotation(chain.joint_quaternions())[0], F[0]
        w[j, :2] = plant.rates[j, :2] / chain.k_b[0]                    # eq. (1)
        nu[j] = chain.free_modes(F)[0] @ w[j, :2]                       # eq. (8)
        if j < count - 1:
            chain.roll(plant.interval_rates[j:j + 1], dt)
    return {"rotation": rotation_m, "joint_velocity": w, "spatial_velocity": nu, "tangent": tangent}


def _joint_pose_frames(plant: JointRecording, model: dict, lower: float, upper: float) -> np.ndarray:
    """(N, 4, 4, 4): B_{i-1}, B_i (plant), B_i (model) and the tangent plane P_i at the contact point."""
    n = len(plant.times)
    span = lower + upper
    frames = np.zeros((n, 4, 4, 4))
    frames[:, 0] = np.eye(4)
    frames[:, 1] = poses(span * plant.tangent[:, :, 2], plant.rotation)
    frames[:, 2] = poses(span * model["tangent"][:, :, 2], model["rotation"])
    frames[:, 3] = poses(lower * plant.tangent[:, :, 2], plant.tangent)
    return frames


def joint_model(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    lower, upper, command = sc.lower_radius, sc.upper_radius, np.asarray(sc.command, dtype=float)
    plants: dict[str, tuple[JointRecording, str | None]] = {}

    def plant_run(name: str) -> tuple[JointRecording, str | None]:
        if name not in plants:  # one physics run serves every model variant
            if name == "mujoco":
                plants[name] = roll_in_mujoco(lower, upper, command, sc.duration, sc.log_dt, contact_physics(cfg))
            elif name == "exact":
                plants[name] = roll_exactly(lower, upper, command, sc.duration, sc.log_dt), None
            else:
                raise SimulationFailed(f"unknown plant {name!r}: mujoco | exact")
        return plants[name]

    forms = {variant: model_form(cfg, **OmegaConf.to_container(sc.variants[variant])) for variant in sc.variants}

    def simulate(log: RunWriter, plant_name: str, variant: str) -> None:
        from scipy.spatial.transform import Rotation
        plant, xml = plant_run(plant_name)
        if xml:
            log.attach("model.xml", xml, "application/xml")
        model = model_beside(plant, lower, upper, forms[variant])
        t = plant.times
        log.log_series("/reference", t, units="rad", name=["x", "y"], velocity=np.tile(command, (len(t), 1)))
        log.log_series("/tangent_rate", t, schemas.Scalars, units="rad/s", name=AXES, value=plant.rates)
        rotvec = Rotation.from_matrix(plant.rotation).as_rotvec()
        log.log_series("/joint_state", t, units="rad", name=AXES, position=rotvec, velocity=plant.joint_velocity)
        log.log_series("/joint_state/model", t, units="rad", name=AXES,
                       position=Rotation.from_matrix(model["rotation"]).as_rotvec(),
                       velocity=model["joint_velocity"])
        six = ["wx", "wy", "wz", "vx", "vy", "vz"]
        log.log_series("/spatial_velocity", t, schemas.Scalars, units=SIX_UNITS, name=six, value=plant.spatial_velocity)
        log.log_series("/spatial_velocity/model", t, schemas.Scalars, units=SIX_UNITS, name=six,
                       value=model["spatial_velocity"])
        error = np.swapaxes(model["rotation"], -1, -2) @ plant.rotation     # R_modelᵀ R_plant (Fig. 9)
        log.log_series("/tracking_error", t, units="rad", name=EULER, error=euler_xyz(error), norm=angle_of(error))
        dw = model["joint_velocity"] - plant.joint_velocity
        log.log_series("/tracking_error/joint_velocity", t, units="rad/s", name=AXES, error=dw,
                       norm=np.linalg.norm(dw, axis=1))
        dnu = model["spatial_velocity"] - plant.spatial_velocity
        log.log_series("/tracking_error/spatial_velocity", t, units=SIX_UNITS, field_units={"norm": "rad/s & m/s"},
                       name=six, error=dnu, norm=np.linalg.norm(dnu, axis=1))
        on_lower, on_upper = contact_paths(lower, upper, plant.tangent, plant.rotation)
        log.log_series("/contact_path", t, schemas.Scalars, units="m", name=["lower", "upper"],
                       value=np.column_stack([on_lower, on_upper]))
        if plant.torque is not None:
            log.log_series("/command", t, units="rad", kind="torque", name=AXES, value=plant.torque)
            log.log_series("/contact", t, schemas.Scalars, value=plant.contact, units=["m", "N", "N"],
                           name=["penetration", "normal_force", "friction_force"])
        frames = _joint_pose_frames(plant, model, lower, upper)
        log.log_transforms(t, "world", ["B0", "B1", "B1_model", "P1"], frames)
        # the plant drawn as a robot, the model's B1 beside it
        if xml:  # the simulated pair from its MuJoCo model, B1 on its free joint
            log.log_robot(t, np.concatenate([frames[:, 1, :3, 3], quaternion_wxyz(frames[:, 1, :3, :3])], axis=1))
            normal_force = plant.contact[:, 1]
            log.log_contacts(t, frames[:, 3, None, :3, 3], (normal_force[:, None] * frames[:, 3, :3, 2])[:, None],
                             CONTACT_SCALE, diameter=0.002)
        else:  # exact rolling by the hinges of its relative state (revolute.py)
            radii = np.array([lower, upper])
            log.attach("model.xml", revolute.chain_xml(radii, "src-joint"), "application/xml")
            log.log_robot(t, revolute.hinge_angles(plant.tangent[:, None], plant.rotation[:, None], radii))
        log_spheres(log, ["B1_model"], [upper], [GHOST_COLOR])

    return [Case(f"{plant}-{variant}", lambda log, p=plant, v=variant: simulate(log, p, v))
            for plant in sc.plants for variant in sc.variants]


# -- the manipulator runs (E2, E3): what both log ---------------------------------------------------------------


def joint_names(n: int, fields) -> list[str]:
    return [f"j{i + 1}.{f}" for i in range(n) for f in fields]


def log_chain(log: RunWriter, t: np.ndarray, frames: np.ndarray, tangent: np.ndarray, relative: np.ndarray,
              radii: np.ndarray, target: np.ndarray) -> None:
    """The chain in 3-D: the paper's frames B_0 … B_n and the target on /tf, and the robot drawn from its
    four-hinge MJCF (model.xml, revolute.py) by the hinge angles of the rolling states ^{B_{i-1}}R_{P_i}
    `tangent` and ^{B_{i-1}}R_{B_i} `relative` (each (N, n, 3, 3))."""
    bodies = [f"B{i}" for i in range(len(radii))]
    log.log_transforms(t, "world", [*bodies, "target"],
                       np.concatenate([frames, np.broadcast_to(target, (len(t), 1, 4, 4))], axis=1))
    log.attach("model.xml", revolute.chain_xml(radii), "application/xml")
    log.log_robot(t, revolute.hinge_angles(tangent, relative, radii))


def log_manipulator(log: RunWriter, trace: Trace, r_desired: np.ndarray, q_desired: np.ndarray,
                    sphere_radius: float) -> dict[str, np.ndarray]:
    """Joint, trolley and wheel states, end-effector errors and the chain in 3-D of one run; returns the
    arrays."""
    a = trace.arrays()
    t, frames = a["times"], a["frames"]
    n = frames.shape[1] - 1
    joints = quaternion_of(a["relative"])                     # q_i, η ≥ 0
    joint_rot = qlog(joints)
    w = np.concatenate([a["joint_velocity"], np.zeros((len(t), n, 1))], axis=-1)
    log.log_series("/joint_state", t, units="rad", name=joint_names(n, AXES), position=joint_rot.reshape(len(t), -1),
                   velocity=w.reshape(len(t), -1))
    log.log_series("/src_state", t, schemas.Scalars, units="1",   # unit quaternions and unit normals
                   name=joint_names(n, ["qw", "qx", "qy", "qz", "nx", "ny", "nz"]),
                   value=np.concatenate([joints, a["tangent"][..., 2]], axis=-1).reshape(len(t), -1))
    log.log_series("/trolley", t, schemas.Scalars, units=["rad", "m", "m/s", "rad/s"] * n,
                   name=joint_names(n, ["heading", "arc", "u_forward", "u_steer"]),
                   value=np.stack([a["heading"], a["arc"], a["u_forward"], a["u_steer"]], axis=-1).reshape(len(t), -1))
    log.log_series("/command", t, units="rad", kind="wheel speed", name=joint_names(n, ["right", "left"]),
                   value=a["wheels"].reshape(len(t), -1))
    e_p = r_desired - frames[:, -1, :3, 3]
    log.log_series("/tracking_error", t, units="m", name=AXES, error=e_p, norm=np.linalg.norm(e_p, axis=1))
    R_err = rotation(q_desired) @ np.swapaxes(frames[:, -1, :3, :3], -1, -2)     # R_d Rᵀ
    log.log_series("/tracking_error/orientation", t, units="rad", name=EULER, error=euler_xyz(R_err),
                   norm=angle_of(R_err))
    log_chain(log, t, frames, a["tangent"], a["relative"], np.full(n + 1, sphere_radius),
              poses(r_desired, rotation(q_desired)))
    return a


# -- E2: reaching poses A and B (Sec. V-B, Figs. 11-14) ---------------------------------------------------------


def random_targets(cfg: DictConfig, radii: np.ndarray, form: ModelForm) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Poses reachable by construction: FK of configurations rolled from the start, each contact normal
    tilted by an angle in `scenario.random_tilt` towards a random azimuth."""
    sc = cfg.scenario
    rng = np.random.default_rng(cfg.seed)
    lower, upper = radii[:-1], radii[1:]
    out = {}
    for k in range(sc.random_targets):
        tilt = rng.uniform(*sc.random_tilt, sc.joints)
        azimuth = rng.uniform(-np.pi, np.pi, sc.joints)
        chain = Chain(radii, form)
        # one straight roll of 1 s per joint: the contact normal turns at l_i/(l_i + l_{i-1}) |w|
        chain.move((tilt * (lower + upper) / upper)[:, None] * np.stack([-np.sin(azimuth), np.cos(azimuth)], -1), 1.0)
        pos, _ = chain.frames()
        out[f"random{k + 1}"] = pos[-1], chain.orientation()
    return out


def log_ik(log: RunWriter, ik: IkResult) -> None:
    """The IK's convergence and per-iteration compute time, on the IK's own time axis (from t = 0)."""
    log.log_series("/ik", ik.times, schemas.Scalars, units=["m", "rad", "m & 1"],  # J mixes m/rad and 1
                   name=["position_error", "orientation_error", "sigma_min"],
                   value=np.column_stack([np.linalg.norm(ik.position_error, axis=1),
                                          np.linalg.norm(ik.orientation_error, axis=1), ik.sigma_min]))
    log.log_series("/compute_time", ik.times, name=["ik_iteration"], calls=[1], seconds=ik.seconds[:, None])
    solution = ik.chain.joint_quaternions()
    names = [*joint_names(ik.chain.n, ["qw", "qx", "qy", "qz"]), "converged"]
    log.log("/ik/solution", 0.0, schemas.Scalars, name=names, units="1",
            value=[*np.where(solution[:, :1] < 0, -solution, solution).ravel(), float(ik.converged)])


def reach_poses(cfg: DictConfig) -> list[Case]:
    sc, s = cfg.scenario, cfg.system
    n, c = sc.joints, controller(cfg)
    radii = c.radii(n)
    targets = {name: (np.asarray(t.position, dtype=float), unit_quaternion(t.quaternion))
               for name, t in sc.targets.items()}
    targets |= random_targets(cfg, radii, c.form)
    solutions: dict[str, IkResult] = {}

    def ik_for(name: str) -> IkResult:
        if name not in solutions:  # one IK serves every plant variant of a target
            k = s.ik
            solutions[name] = solve_ik(Chain(radii, c.form), *targets[name], c.ik, k.dt, k.duration,
                                       k.tol_position, k.tol_orientation, k.stall_time, k.stall_change)
        return solutions[name]

    def simulate(log: RunWriter, target: str, plant_name: str) -> None:
        r_desired, q_desired = targets[target]
        ik = ik_for(target)
        log_ik(log, ik)
        plant = sc.plants[plant_name]
        defects = Defects(radius_offset=plant.radius_offset, slip=plant.slip)
        arm = FreeBotArm(n, c.bot, s.freebot.radius, s.trolley.heading0, defects)
        trace = position_mode(arm, c, ik.chain.tangent_frames(), sc.duration, plant.sensing)
        a = log_manipulator(log, trace, r_desired, q_desired, s.freebot.radius + defects.radius_offset)
        log.log_series("/reference", a["times"], units=["m", "rad"] * n, name=joint_names(n, ["arc_left", "heading"]),
                       position=a["reference"].reshape(len(a["times"]), -1))
        log.log("/target", 0.0, schemas.Scalars, name=["x", "y", "z", "qw", "qx", "qy", "qz"],
                value=[*r_desired, *q_desired], units=TARGET_UNITS)

    for name, plant in sc.plants.items():
        if plant.sensing not in SENSING:
            raise ValueError(f"scenario.plants.{name}.sensing={plant.sensing!r}: must be one of {SENSING}")
    cases = [(name, "nominal") for name in targets]
    cases += [(name, plant) for name in sc.hardware_targets for plant in sc.plants if plant != "nominal"]
    return [Case(f"{name}-{plant}", lambda log, t=name, p=plant: simulate(log, t, p)) for name, plant in cases]


# -- E2': the floor under A and B, and eq. (5)'s literal update (Sec. V-B, eqs. 5, 66-67) -----------------------

FloorRow = schemas.define(
    "SrcReachFloor", "The closest a 3-joint equal-sphere chain comes to a target pose: one joint-update mode, one "
    "reading of the target quaternion, one weighting of orientation against position (m per rad), and the most the "
    "closed-form kinematics differs from the paper's model (every model form) at that configuration (m).",
    mode="string", reading="string", weight_m_per_rad="double m/rad", position_error_m="double m",
    orientation_error_rad="double rad", model_difference_m="double m",
)


def _model_difference(r: np.ndarray, radii: np.ndarray, position: np.ndarray, R: np.ndarray) -> float:
    """The largest difference between the closed form and the paper's Chain (every model form) at one
    configuration: end-effector position (m) and rotation matrix entries."""
    q1, q2 = reach.model_state(r)
    worst = 0.0
    for radius_convention in CONVENTIONS:
        for free_mode_sign in CONVENTIONS:
            chain = Chain(radii, ModelForm(radius_convention, free_mode_sign), q1, q2)
            pos, _ = chain.frames()
            worst = max(worst, float(np.abs(pos[-1] - position).max()),
                        float(np.abs(rotation(chain.orientation()) - R).max()))
    return worst


def reach_floor(cfg: DictConfig) -> list[Case]:
    sc, s = cfg.scenario, cfg.system
    n, radius, f = sc.joints, s.freebot.radius, sc.floor
    radii = np.full(n + 1, radius)

    def simulate_target(log: RunWriter, name: str) -> None:
        target = sc.targets[name]
        r_desired, printed = np.asarray(target.position, dtype=float), np.asarray(target.quaternion, dtype=float)
        t = 0.0
        best = None
        for mode in f.modes:
            for reading in f.readings:
                R_desired = rotation(reach.read_quaternion(printed, reading))
                found = reach.floors(r_desired, R_desired, radius, n, mode, f.weights, f.starts, f.iterations,
                                     np.random.default_rng(cfg.seed))
                for fl in found:
                    pos, R = (a[0, -1] for a in reach.fk(fl.rotvecs[None], radius))
                    log.log("/reach/floor", t, FloorRow, mode=mode, reading=reading, weight_m_per_rad=fl.weight,
                            position_error_m=fl.position_error, orientation_error_rad=fl.orientation_error,
                            model_difference_m=_model_difference(fl.rotvecs, radii, pos, R))
                    t += 1e-3   # one row per millisecond: a table, not a trajectory
                if (mode, reading) == ("incremental", "printed"):
                    best = found[-1]
        # the paper's own IK (Sec. III-B) in each joint-update mode, from the identity
        k, ik = s.ik, ik_gains(cfg)
        rows = []
        for mode in f.modes:
            result = solve_ik(Chain(radii, model_form(cfg, joint_update=mode)), r_desired, unit_quaternion(printed),
                              ik, k.dt, k.duration, k.tol_position, k.tol_orientation, k.stall_time, k.stall_change)
            rows += [np.linalg.norm(result.position_error[-1]), np.linalg.norm(result.orientation_error[-1]),
                     float(result.converged), np.abs(result.chain.joint_quaternions()[:, 3]).max()]
        log.log("/reach/ik", 0.0, schemas.Scalars, units=["m", "rad", "1", "1"] * len(f.modes),
                name=[f"{m}.{x}" for m in f.modes for x in ("position_error", "orientation_error", "converged",
                                                           "eps_z_max")], value=rows)
        if best is not None:   # the closest exact-rolling pose, to look at beside the target
            pos, rot = reach.fk(best.rotvecs[None], radius)
            log_chain(log, np.zeros(1), poses(pos, rot), exp_so3(best.rotvecs[None]), exp_so3(2 * best.rotvecs[None]),
                      radii, poses(r_desired, rotation(unit_quaternion(printed))))
            log.log("/joint_state", 0.0, units="rad", name=joint_names(n, AXES),
                    position=best.rotvecs.ravel().tolist())

    def simulate_loop(log: RunWriter) -> None:
        """One joint rolled round a closed square of Ω^B (+x, +y, −x, −y): the model in both joint-update
        modes beside exact rolling; exact rolling never twists (ε_z = 0), eq. (5) read literally does."""
        lp, dt = sc.loop, s.control.dt
        steps = round(lp.side / dt)
        sides = np.repeat(np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]) * lp.rate, steps, axis=0)
        chains = {mode: Chain(radii[:2], model_form(cfg, joint_update=mode)) for mode in reach.MODES}
        plant = RollingChain(radii[:2])
        count = len(sides) + 1
        quaternions = np.zeros((count, 3, 4))
        tangent, relative = np.zeros((count, 1, 3, 3)), np.zeros((count, 1, 3, 3))
        frames = np.zeros((count, 4, 4, 4))   # B_0, B_1 of the plant, B_1 of the model in each mode
        frames[:, 0] = np.eye(4)
        for j in range(count):
            quaternions[j] = [*(c.joint_quaternions()[0] for c in chains.values()), quaternion_of(plant.relative[0])]
            tangent[j], relative[j] = plant.tangent, plant.relative
            frames[j, 1:] = [poses(*(a[1] for a in body.frames())) for body in (plant, *chains.values())]
            if j < count - 1:
                for c in chains.values():
                    c.roll(sides[j:j + 1], dt)
                plant.roll(sides[j:j + 1], dt)
        quaternions *= np.where(quaternions[..., :1] < 0, -1.0, 1.0)
        t = np.arange(len(sides) + 1) * dt
        log.log_series("/joint_state", t, units="rad", name=[f"{m}.{a}" for m in (*reach.MODES, "plant") for a in AXES],
                       position=qlog(quaternions).reshape(len(t), -1))
        log.log_series("/eq5/joint_quaternion", t, schemas.Scalars, units="1",
                       name=[f"{m}.{c}" for m in (*reach.MODES, "plant") for c in ("qw", "qx", "qy", "qz")],
                       value=quaternions.reshape(len(t), -1))
        log.log_series("/reference", t[:-1], units="rad", name=["x", "y"], velocity=sides)   # Ω^B, rad/s
        # the plant drawn as a robot (revolute.py), B_1 of the model in each mode beside it
        ghosts = [f"B1_{mode}" for mode in chains]
        log.log_transforms(t, "world", ["B0", "B1", *ghosts], frames)
        log.attach("model.xml", revolute.chain_xml(radii[:2], "src-joint"), "application/xml")
        log.log_robot(t, revolute.hinge_angles(tangent, relative, radii[:2]))
        log_spheres(log, ghosts, [radius] * len(ghosts), [GHOST_COLOR, LITERAL_COLOR])

    cases = [Case(name, lambda log, x=name: simulate_target(log, x)) for name in sc.targets]
    return [*cases, Case("eq5-loop", simulate_loop)]


# -- E3: reaching C between two bars (Sec. V-C, Figs. 15-17) ----------------------------------------------------


def bar_markers(log: RunWriter, bars: Bars, half_length: float) -> None:
    """The bars as cylinders in `world` (Foxglove cylinders stand along their local z)."""
    from scipy.spatial.transform import Rotation
    z = np.array([0.0, 0.0, 1.0])
    turn = Rotation.align_vectors([bars.axis], [z])[0].as_quat()   # x, y, z, w: takes z onto the bar axis
    cylinders = [schemas.CylinderPrimitive(
        pose=schemas.Pose(position=schemas.Vector3(x=p[0], y=p[1], z=p[2]),
                          orientation=schemas.Quaternion(x=turn[0], y=turn[1], z=turn[2], w=turn[3])),
        size=schemas.Vector3(x=2 * bars.radius, y=2 * bars.radius, z=2 * half_length),
        bottom_scale=1.0, top_scale=1.0, color=schemas.Color(r=0.3, g=0.3, b=0.3, a=1.0)) for p in bars.points]
    log.write("/markers", 0, schemas.SceneUpdate(entities=[schemas.SceneEntity(frame_id="world", id="bars",
                                                                               cylinders=cylinders)]))


def avoid_obstacles(cfg: DictConfig) -> list[Case]:
    from pipeline.papers.src_joint.physics import mujoco_clearance, scene_xml

    sc, s = cfg.scenario, cfg.system
    n, c = sc.joints, controller(cfg)
    radii = c.radii(n)
    r_desired, q_desired = np.asarray(sc.target.position, dtype=float), unit_quaternion(sc.target.quaternion)
    axis = np.asarray(sc.bars.axis, dtype=float)
    bars = Bars(np.asarray(sc.bars.points, dtype=float), axis / np.linalg.norm(axis), sc.bars.radius)
    damper = Damper(**OmegaConf.to_container(sc.damper))
    bar_names = [f"bar{k + 1}" for k in range(len(bars.points))]
    pairs = [f"B{j + 1}.{b}" for j in range(n) for b in bar_names]

    def simulate(log: RunWriter, case: str) -> None:
        if case not in ("avoid", "unconstrained"):
            raise SimulationFailed(f"unknown case {case!r}: avoid | unconstrained")
        qp = DamperQP(2 * n, n * len(bars.points), damper)
        arm = FreeBotArm(n, c.bot, s.freebot.radius, s.trolley.heading0)
        trace = velocity_mode(arm, c, r_desired, q_desired, bars, qp, sc.duration, avoid=case == "avoid")
        a = log_manipulator(log, trace, r_desired, q_desired, s.freebot.radius)
        t = a["times"]
        log.log_series("/reference", t, units="rad", name=joint_names(n, ["x", "y"]),
                       velocity=a["reference"].reshape(len(t), -1))
        centres = a["frames"][:, 1:, :3, 3]
        clearance, _ = bars.clearance(centres.reshape(-1, 3), np.tile(radii[1:], len(t)))
        log.log_series("/clearance", t, schemas.Scalars, units="m", name=pairs, value=clearance.reshape(len(t), -1))
        xml = scene_xml(radii, bars.points, bars.axis, bars.radius, sc.bars.half_length)
        log.attach("scene.xml", xml, "application/xml")
        log.log_series("/clearance/mujoco", t, schemas.Scalars, units="m", name=pairs,
                       value=mujoco_clearance(xml, np.concatenate([np.zeros((len(t), 1, 3)), centres], axis=1))[:, 1:]
                       .reshape(len(t), -1))
        log.log_series("/compute_time", t, name=["model", "qp"], calls=[1, 1],
                       seconds=np.column_stack([a["model_seconds"], a["qp_seconds"]]))
        log.log_series("/qp", t, schemas.Scalars, name=["slack"], value=a["slack"][:, None], units="m/s")
        log.log("/target", 0.0, schemas.Scalars, name=["x", "y", "z", "qw", "qx", "qy", "qz"],
                value=[*r_desired, *q_desired], units=TARGET_UNITS)
        bar_markers(log, bars, sc.bars.half_length)

    return [Case(case, lambda log, x=case: simulate(log, x)) for case in sc.cases]

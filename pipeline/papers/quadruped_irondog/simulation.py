"""The closed loop of every MuJoCo experiment: a controller turns the time and the IMU's roll/pitch into servo
references every control period (20 ms, the paper's sensor period), the servos hold them in between, and the run
is sampled every log period. A trunk that drops too low or tilts too far is a fall: the run stops there, keeps
what it recorded, and says why."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pipeline.papers.quadruped_irondog.kinematics import JOINT_NAMES
from pipeline.papers.quadruped_irondog.model import Indices, Robot, Scene, mjcf

# A controller: (t, trunk roll/pitch/yaw from the IMU) -> (4, 3) joint references (rad)
Controller = Callable[[float, np.ndarray], np.ndarray]


def quat_rpy(quat) -> np.ndarray:
    """(..., 3) roll, pitch, yaw (rad) of unit quaternions (..., 4) in MuJoCo's (w, x, y, z) order."""
    w, x, y, z = np.moveaxis(np.asarray(quat, dtype=float), -1, 0)
    return np.stack([np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
                     np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0)),
                     np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))], axis=-1)


def _roll_pitch(w: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """`quat_rpy` of one quaternion in plain floats: the control loop's IMU, at a tenth of NumPy's cost."""
    return (math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
            math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x)))),
            math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


@dataclass(frozen=True)
class Fall:
    """When a run counts as fallen."""

    min_height: float    # m, trunk centre above the ground plane it started on
    max_tilt: float      # rad, |roll| or |pitch|


@dataclass
class Trace:
    """A run sampled every log period (index k ↔ t[k]); `failure` says why it stopped early, if it did."""

    t: np.ndarray
    qpos: np.ndarray            # (N, nq) the full configuration (trunk pose, legs, bench)
    q: np.ndarray               # (N, 12) leg joints, rad
    qd: np.ndarray              # (N, 12) rad/s
    tau: np.ndarray             # (N, 12) servo output torque, N·m: motor torque minus back-EMF damping
    tau_motor: np.ndarray       # (N, 12) the actuator's (saturating) part, N·m, |·| ≤ stall torque
    q_cmd: np.ndarray           # (N, 12) servo references in force
    trunk_velocity: np.ndarray  # (N, 6) linear (world, m/s) and angular (trunk frame, rad/s)
    contact_force: np.ndarray   # (N, 4, 3) ground reaction on each foot, world frame, N
    contact: np.ndarray         # (N, 4) 1 where the foot touches something
    control_t: np.ndarray       # (M,) control instants
    control_seconds: np.ndarray  # (M,) wall time of each controller call
    failure: str | None = None

    @property
    def rpy(self) -> np.ndarray:
        return quat_rpy(self.qpos[:, 3:7])


class Plant:
    """The compiled model and its state."""

    def __init__(self, robot: Robot, scene: Scene):
        import mujoco

        self.mj = mujoco
        self.robot, self.scene = robot, scene
        self.xml = mjcf(robot, scene)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self.idx = Indices.of(self.model)

    def place(self, q_legs: np.ndarray, clearance: float = 5e-4) -> None:
        """At rest with the legs at q_legs (4, 3) and the lowest foot `clearance` above the ground (z = 0)."""
        m, d = self.model, self.data
        self.mj.mj_resetData(m, d)
        d.qpos[3] = 1.0
        d.qpos[self.idx.qpos] = np.ravel(q_legs)
        d.ctrl[:12] = np.ravel(q_legs)
        self.mj.mj_kinematics(m, d)
        lowest = (d.site_xpos[self.idx.feet, 2] - d.qpos[2]).min() - self.robot.foot_radius
        d.qpos[2] = -lowest + clearance
        self.mj.mj_forward(m, d)

    def poses(self, qpos: np.ndarray) -> np.ndarray:
        """(N, nbody − 1, 4, 4) world poses of every body at the configurations qpos (N, nq)."""
        m, d = self.model, self.mj.MjData(self.model)
        out = np.tile(np.eye(4), (len(qpos), m.nbody - 1, 1, 1))
        for k, x in enumerate(qpos):
            d.qpos[:] = x
            self.mj.mj_kinematics(m, d)
            out[k, :, :3, :3] = d.xmat[1:].reshape(-1, 3, 3)
            out[k, :, :3, 3] = d.xpos[1:]
        return out


def _events(duration: float, dt: float, step: float) -> np.ndarray:
    return np.round(np.arange(round(duration / dt) + 1) * dt / step).astype(int)


def simulate(plant: Plant, controller: Controller, duration: float, control_dt: float, log_dt: float,
             fall: Fall, platform: Callable[[float], np.ndarray] | None = None) -> Trace:
    """Run from the plant's current state for `duration` s. `platform(t)` gives the bench's (pitch, roll) (rad)."""
    mj, m, d, idx = plant.mj, plant.model, plant.data, plant.idx
    h = m.opt.timestep
    log_steps, control_steps = _events(duration, log_dt, h), _events(duration, control_dt, h)
    events = np.union1d(log_steps, control_steps)
    is_log, is_control = np.isin(events, log_steps), np.isin(events, control_steps)
    n = len(log_steps)
    rec = {key: np.zeros((n, *shape)) for key, shape in (
        ("qpos", (m.nq,)), ("q", (12,)), ("qd", (12,)), ("tau", (12,)), ("tau_motor", (12,)), ("q_cmd", (12,)),
        ("vel", (6,)), ("force", (12,)), ("contact", (4,)))}
    control_seconds = np.zeros(len(control_steps))
    force_cols = (idx.contact[:, None] + np.arange(1, 4)).ravel()
    damping = m.dof_damping[idx.dof]
    failure = None
    k = c = 0
    clock = time.perf_counter_ns
    for j, step in enumerate(events):
        if j:
            mj.mj_step(m, d, nstep=int(step - events[j - 1]))
        t = step * h
        rpy = np.array(_roll_pitch(*d.qpos[3:7].tolist()))
        if is_control[j]:
            if platform is not None:
                d.ctrl[idx.platform_ctrl] = platform(t)
            begin = clock()
            command = np.ravel(controller(t, rpy))
            control_seconds[c] = (clock() - begin) * 1e-9
            c += 1
            if not np.isfinite(command).all():
                legs = sorted({JOINT_NAMES[i].split("_")[0] for i in np.flatnonzero(~np.isfinite(command))})
                failure = f"no IK solution at t = {t:.2f} s: the feet of {', '.join(legs)} are out of reach"
                break
            d.ctrl[:12] = command
        if is_log[j]:
            mj.mj_forward(m, d)
            rec["qpos"][k] = d.qpos
            rec["q"][k], rec["qd"][k] = d.qpos[idx.qpos], d.qvel[idx.dof]
            rec["tau_motor"][k] = d.actuator_force[:12]
            rec["tau"][k] = d.actuator_force[:12] - damping * d.qvel[idx.dof]
            rec["q_cmd"][k] = d.ctrl[:12]
            rec["vel"][k, :3], rec["vel"][k, 3:] = d.qvel[:3], d.qvel[3:6]
            rec["force"][k] = d.sensordata[force_cols]
            rec["contact"][k] = d.sensordata[idx.contact] > 0
            k += 1
            height = d.qpos[2] - _support_height(plant, d)
            if not np.isfinite(d.qpos).all():
                failure = f"state not finite at t = {t:.3f} s"
            elif d.sensordata[idx.trunk_contact] > 0:
                failure = f"fell at t = {t:.2f} s: the trunk touched the ground"
            elif height < fall.min_height:
                failure = f"fell at t = {t:.2f} s: trunk {height * 1e3:.0f} mm above the ground"
            elif max(abs(rpy[0]), abs(rpy[1])) > fall.max_tilt:
                axis = "roll" if abs(rpy[0]) >= abs(rpy[1]) else "pitch"
                failure = f"fell at t = {t:.2f} s: trunk {axis} {np.degrees(rpy[0 if axis == 'roll' else 1]):.0f}°"
            if failure:
                saturated = [JOINT_NAMES[i] for i in np.flatnonzero(np.abs(d.actuator_force[:12])
                                                                     >= 0.999 * plant.robot.stall_torque)]
                if saturated:
                    failure += f" (servos at their {plant.robot.stall_torque:.2f} N·m limit: {', '.join(saturated)})"
                break
    if failure is None:
        from pipeline.core.runlog import SimulationFailed
        from pipeline.robotics.mjcf import check_mujoco

        try:
            check_mujoco(d, rec["qpos"][:k], log_steps[:k] * h)
        except SimulationFailed as err:   # keep the trace, say why
            failure = str(err)
    return Trace(t=log_steps[:k] * h, qpos=rec["qpos"][:k], q=rec["q"][:k], qd=rec["qd"][:k], tau=rec["tau"][:k],
                 tau_motor=rec["tau_motor"][:k], q_cmd=rec["q_cmd"][:k], trunk_velocity=rec["vel"][:k],
                 contact_force=rec["force"][:k].reshape(-1, 4, 3), contact=rec["contact"][:k],
                 control_t=control_steps[:c] * h, control_seconds=control_seconds[:c], failure=failure)


def _support_height(plant: Plant, d) -> float:
    """The height of the surface under the trunk (0 on flat ground; the bench's top under its centre)."""
    if not len(plant.idx.platform_qpos):
        return 0.0
    pitch, roll = d.qpos[plant.idx.platform_qpos]
    x, y = d.qpos[0], d.qpos[1]
    return float(-x * np.tan(pitch) + y * np.tan(roll))

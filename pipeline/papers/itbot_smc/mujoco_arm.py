"""The same arm in MuJoCo, generated from the paper's parameters: the independent second plant.

Bodies (frame 0 of the paper = body `base`; in the vertical configuration it is turned so that y0 points up):

    base            the aluminium base block and joint 1's motor (drawing only)
      link1         hinge joint1 about z; body x along the link (MDH frame 1: θ1 + π/2); CoG X1 = lc1
        link2       hinge joint2 about z at x = l1; body x along the link (MDH frame 2: θ2 + π); CoG (X2, 0, Z2)
          hand      welded at x = l2: the handle, its force sensor, and the hand load (the 11 lb weight and
                    the forearm) as a point mass; the subject's damping and support act on it

Masses, CoGs and inertias are set explicitly (`inertial`), so the geoms only draw the arm: sized from the
paper's dimensions (l1, l2) and the stated drawing assumptions (`system.drawing`). The drives are joint
`armature` (N² J_r) and `frictionloss` (Coulomb c, MuJoCo's own dry-friction model), motors are `motor`
actuators with the torque limit as their control range. The force sensor at the handle reads the force
between link 2 and the hand body, like the end-effector force sensor of the hardware.
"""

from __future__ import annotations

import math

import numpy as np

from pipeline.papers.itbot_smc.model import JOINTS, Links
from pipeline.papers.itbot_smc.plants import Drive, HandLoad
from pipeline.robotics.mjcf import check_mujoco

POINT_INERTIA = 1e-10    # kg m², rotational inertia of the point masses (MuJoCo wants > 0)
# frame 0 in the world: vertical = turned +90° about x (y0 up, z0 towards −y); horizontal = the world frame
BASE_QUAT = {"vertical": (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0), "horizontal": (1.0, 0.0, 0.0, 0.0)}


def rotation(wxyz: tuple[float, float, float, float]) -> np.ndarray:
    """3×3 rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = wxyz
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def base_position(configuration: str, drawing) -> tuple[float, float, float]:
    """Where frame 0 sits in the world: on top of the base block (vertical), or on the table (horizontal)."""
    return (0.0, 0.0, float(drawing.base_size[1]) + 0.02 if configuration == "vertical" else 0.0)


def _f(*values: float) -> str:
    return " ".join(f"{v:.12g}" for v in values)


def arm_mjcf(links: Links, drive: Drive, load: HandLoad, *, configuration: str, drawing, z2: float,
             joint_limits: tuple[float, float] | None, timestep: float, gravity: float,
             integrator: str = "implicitfast") -> str:
    """MJCF of the iTbot with the hand load. `gravity` is g (m/s²) along −z of the world; `joint_limits` (deg,
    ±) become joint ranges (None: unlimited); `z2` is link 2's CoG offset along its joint axis (Table 1).
    `MujocoPlant` steps with `mj_step1`/`mj_step2`, which need an Euler-type integrator (the default)."""
    w, t = drawing.link_width, drawing.link_thickness
    base_x, base_y, base_z = drawing.base_size
    motor_r, motor_l = drawing.motor_radius, drawing.motor_length
    handle_r, handle_l = drawing.handle_radius, drawing.handle_length
    weight_r = drawing.weight_radius
    ja1, ja2 = drive.armature
    ranges = ["", ""] if joint_limits is None else \
        [f' range="{_f(-math.radians(x), math.radians(x))}"' for x in joint_limits]
    quat = BASE_QUAT[configuration]
    # rod-like inertias: I_z of the paper about z (and y), a thin plate's about the link axis
    ix1, ix2 = links.m1 * (w * w + t * t) / 12, links.m2 * (w * w + t * t) / 12
    return f"""<mujoco model="itbot">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{timestep:.12g}" gravity="0 0 {-gravity:.12g}" integrator="{integrator}">
    <flag contact="disable"/>
  </option>
  <default>
    <geom contype="0" conaffinity="0" rgba="0.75 0.77 0.8 1"/>
  </default>
  <worldbody>
    <light pos="0 -1.5 1.5" dir="0 1 -1"/>
    <body name="base" pos="{_f(*base_position(configuration, drawing))}" quat="{_f(*quat)}">
      <geom name="base_block" type="box" size="{_f(base_x / 2, base_y / 2, base_z / 2)}"
            pos="{_f(0, -base_y / 2 - 0.02, -t - base_z / 2)}" rgba="0.55 0.57 0.6 1"/>
      <geom name="motor1" type="cylinder" size="{_f(motor_r, motor_l / 2)}" pos="{_f(0, 0, -t - motor_l / 2)}"
            rgba="0.15 0.15 0.17 1"/>
      <body name="link1" quat="{_f(math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4))}">
        <joint name="{JOINTS[0]}" type="hinge" axis="0 0 1"{ranges[0]} armature="{ja1:.12g}"
               frictionloss="{drive.friction[0]:.12g}"/>
        <inertial pos="{_f(links.lc1, 0, 0)}" mass="{links.m1:.12g}" diaginertia="{_f(ix1, links.iz1, links.iz1)}"/>
        <geom name="link1" type="box" size="{_f(links.l1 / 2, w / 2, t / 2)}" pos="{_f(links.l1 / 2, 0, 0)}"/>
        <geom name="joint1_hub" type="cylinder" size="{_f(w / 2, t / 2)}"/>
        <body name="link2" pos="{_f(links.l1, 0, 0)}" quat="0 0 0 1">
          <joint name="{JOINTS[1]}" type="hinge" axis="0 0 1"{ranges[1]} armature="{ja2:.12g}"
                 frictionloss="{drive.friction[1]:.12g}"/>
          <inertial pos="{_f(links.lc2, 0, z2)}" mass="{links.m2:.12g}"
                    diaginertia="{_f(ix2, links.iz2, links.iz2)}"/>
          <geom name="link2" type="box" size="{_f(links.l2 / 2, w / 2, t / 2)}" pos="{_f(links.l2 / 2, 0, t)}"
                rgba="0.7 0.72 0.76 1"/>
          <geom name="motor2" type="cylinder" size="{_f(motor_r, motor_l / 2)}" pos="{_f(0, 0, -t / 2 - motor_l / 2)}"
                rgba="0.15 0.15 0.17 1"/>
          <body name="hand" pos="{_f(links.l2, 0, 0)}">
            <inertial pos="0 0 0" mass="{max(load.mass, POINT_INERTIA):.12g}"
                      diaginertia="{_f(POINT_INERTIA, POINT_INERTIA, POINT_INERTIA)}"/>
            <site name="handle" size="0.01"/>
            <geom name="force_sensor" type="cylinder" size="{_f(handle_r * 1.6, 0.01)}" pos="{_f(0, 0, 1.5 * t)}"
                  rgba="0.2 0.25 0.3 1"/>
            <geom name="handle" type="cylinder" size="{_f(handle_r, handle_l / 2)}"
                  pos="{_f(0, 0, 1.5 * t + 0.01 + handle_l / 2)}" rgba="0.95 0.95 0.92 1"/>
            <geom name="weight" type="sphere" size="{weight_r:.12g}" pos="{_f(0, 0, 1.5 * t + 0.01 + handle_l / 2)}"
                  rgba="0.2 0.35 0.7 0.6"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="motor1" joint="{JOINTS[0]}" ctrlrange="{_f(-drive.torque_limit[0], drive.torque_limit[0])}"/>
    <motor name="motor2" joint="{JOINTS[1]}" ctrlrange="{_f(-drive.torque_limit[1], drive.torque_limit[1])}"/>
  </actuator>
  <sensor>
    <force name="handle_force" site="handle"/>
    <framelinvel name="handle_velocity" objtype="site" objname="handle"/>
  </sensor>
</mujoco>
"""


class MujocoPlant:
    """The MuJoCo arm behind the closed loop's plant interface. Each control period: `mj_step1` (positions,
    velocities), the subject's damping and support as an applied force on the hand body, the held torque, then
    `mj_step2` (the force sensor is read there, at the tick, with the tick's torque) and the remaining steps."""

    name = "mujoco"

    def __init__(self, xml: str, links: Links, load: HandLoad, configuration: str, period: float, q0, qd0):
        import mujoco

        self._mj = mujoco
        self.xml = xml
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        steps = period / self.model.opt.timestep
        self.steps = round(steps)
        if self.steps < 1 or abs(steps - self.steps) > 1e-9:
            raise ValueError(f"the control period {period} s must be a whole number of MuJoCo steps "
                             f"({self.model.opt.timestep} s)")
        self.data.qpos[:] = q0
        self.data.qvel[:] = qd0
        mujoco.mj_forward(self.model, self.data)
        self.damping, self.support = load.damping, load.support * load.mass * links.gravity
        self.R0 = rotation(BASE_QUAT[configuration])    # frame 0 in the world
        self.hand = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, "hand")
        self.site = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, "handle")
        self._force = slice(*self._sensor_span("handle_force"))
        self._velocity = slice(*self._sensor_span("handle_velocity"))
        self._lift = self.R0[:, 1] * self.support     # the subject's support, world frame
        self._readings: list[np.ndarray] = []         # per tick: the sensor's force (site frame), the site's axes

    def _sensor_span(self, name: str) -> tuple[int, int]:
        sensor = self.model.sensor(name)
        return int(sensor.adr[0]), int(sensor.adr[0] + sensor.dim[0])

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        return self.data.qpos.copy(), self.data.qvel.copy()

    def advance(self, tau: np.ndarray) -> None:
        mj, m, d = self._mj, self.model, self.data
        mj.mj_step1(m, d)
        d.xfrc_applied[self.hand, :3] = self._lift - self.damping * d.sensordata[self._velocity]   # world frame
        d.ctrl[:] = tau
        mj.mj_step2(m, d)
        self._readings.append(np.concatenate([d.sensordata[self._force], d.site_xmat[self.site]]))
        if self.steps > 1:
            mj.mj_step(m, d, nstep=self.steps - 1)

    def hand_forces(self, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """(K, 2) the force sensor's reading at every tick so far, in frame 0: the sensor reads the force of
        link 2 on the hand body (in the site's frame); the hand pushes back on the handle."""
        readings = np.array(self._readings).reshape(-1, 12)
        in_world = np.einsum("kij,kj->ki", readings[:, 3:].reshape(-1, 3, 3), readings[:, :3])
        return -(in_world @ self.R0)[:, :2]

    def check(self, states: np.ndarray, times: np.ndarray) -> None:
        check_mujoco(self.data, states, times)

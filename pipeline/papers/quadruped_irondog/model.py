"""The MuJoCo Iron Dog Mini, generated from the paper's dimensions and masses (Table 2, spec §6).

A floating trunk and four serial legs (coxa roll, femur and tibia pitch: the paper's URDF, which leaves out the
Watt six-bar, Fig. 17), each joint driven by an SPT5535LV servo: a position actuator whose torque saturates at the
stall torque, and the motor's back-EMF as joint damping b = τ_stall / ω_no-load, so a saturated joint cannot turn
faster than the no-load speed. Every body carries geoms of the Table 2 sizes with their lumped masses, so the
model draws as the robot and its inertias follow from the shapes. At zero joint angles the legs hang straight down
(Table 5, ideal state); body frames are aligned with the trunk there, so a URDF can be written from the same
description. Only the feet and the trunk touch the ground.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from pipeline.papers.quadruped_irondog.kinematics import JOINTS, LEGS, SIDE, Layout, Leg

GRAVITY = 9.81


def _f(*values: float) -> str:
    return " ".join(f"{v:.10g}" for v in values)


@dataclass(frozen=True)
class Robot:
    """Everything the model is built from (conf/system/quadruped-irondog.yaml)."""

    leg: Leg
    layout: Layout
    height: float                        # m, trunk
    link_width: float                    # m, femur and tibia fore-aft width
    link_thickness: float                # m, femur and tibia lateral thickness
    foot_radius: float                   # m
    trunk_masses: Mapping[str, float]    # kg, Table 2 parts lumped into the trunk
    coxa_mass: float                     # kg per leg
    femur_mass: float
    tibia_mass: float
    stall_torque: float                  # N·m
    no_load_speed: float                 # rad/s
    kp: float                            # N·m/rad
    armature: float                      # kg·m²
    ranges: np.ndarray                   # (3, 2) rad: coxa, femur, tibia
    friction: float
    timestep: float                      # s

    @classmethod
    def from_config(cls, system: Mapping) -> Robot:
        leg, body, masses, servo = system["leg"], system["body"], system["masses"], system["servo"]
        return cls(
            leg=Leg(leg["L1"], leg["L2"], leg["L3"], printed=leg["ik_form"] == "printed"),
            layout=Layout(body["length"], body["hip_width"]), height=body["height"],
            link_width=body["link_width"], link_thickness=body["link_thickness"], foot_radius=body["foot_radius"],
            trunk_masses=dict(masses["trunk"]), coxa_mass=masses["coxa"], femur_mass=masses["femur"],
            tibia_mass=masses["tibia"], stall_torque=servo["stall_torque"], no_load_speed=servo["no_load_speed"],
            kp=servo["kp"], armature=servo["armature"],
            ranges=np.radians([servo["range_deg"][j] for j in JOINTS]),
            friction=system["physics"]["friction"], timestep=system["physics"]["timestep"])

    @property
    def damping(self) -> float:
        """N·m·s/rad: the back-EMF of a motor whose torque-speed line runs from stall to no-load speed."""
        return self.stall_torque / self.no_load_speed

    @property
    def trunk_mass(self) -> float:
        return float(sum(self.trunk_masses.values()))

    @property
    def mass(self) -> float:
        """kg, the whole robot (Table 2's 2572.2 g with the paper's masses)."""
        return self.trunk_mass + 4 * (self.coxa_mass + self.femur_mass + self.tibia_mass)


@dataclass(frozen=True)
class Scene:
    """What the robot stands on: flat ground, or a tilting bench (a platform on a pitch and a roll hinge at the
    origin, top face at z = 0, driven by stiff position servos); and an optional payload on the trunk."""

    platform: bool = False
    payload: float = 0.0                 # kg, a box on top of the trunk
    platform_size: tuple[float, float] = (0.7, 0.5)   # m
    floor_depth: float = 0.3             # m, the floor under the bench


@dataclass(frozen=True)
class Part:
    """A box of the model: full `size` centred at `pos` in its body's frame."""

    name: str
    pos: tuple[float, float, float]
    size: tuple[float, float, float]
    mass: float
    rgba: str
    cls: str = "visual"        # visual: drawn only; trunk: also touches the ground

    def xml(self) -> str:
        half = np.asarray(self.size, dtype=float) / 2
        return (f'<geom name="{self.name}" class="{self.cls}" type="box" pos="{_f(*self.pos)}" size="{_f(*half)}" '
                f'mass="{self.mass:.10g}" rgba="{self.rgba}"/>')


TRUNK_RGBA, SERVO_RGBA, LINK_RGBA, FOOT_RGBA = "0.85 0.55 0.15 1", "0.15 0.15 0.15 1", "0.9 0.9 0.88 1", "0.1 0.1 0.1 1"
MOUNT = 0.056   # m, the side pitch mount's 5.6 cm (12 × 5.6 cm, one per end)


def trunk_parts(robot: Robot) -> list[Part]:
    """The Table 2 parts of the trunk as boxes of their printed sizes (trunk frame: centre of the four hips)."""
    m, length, width, h = robot.trunk_masses, robot.layout.length, robot.layout.width, robot.height
    return [
        # two base plates 30 × 6 cm side by side under everything
        *(Part(f"base_{side}", (0, sign * width / 4, -h / 2 + 0.002), (length, width / 2, 0.004), m["base"] / 2,
               TRUNK_RGBA, "trunk") for side, sign in (("left", 1), ("right", -1))),
        # the pitch mounts hold the coxa servos at the hips
        *(Part(f"pitch_mount_{end}", (sign * (length / 2 - MOUNT / 2), 0, 0), (MOUNT, width, h - 0.008),
               (m["pitch_mounts"] + m["coxa_servos"]) / 2, SERVO_RGBA, "trunk") for end, sign in (("front", 1),
                                                                                                  ("back", -1))),
        Part("head", (length / 2 + 0.003, 0, 0), (0.006, width, 0.07), m["head"], TRUNK_RGBA),
        Part("back_shell", (-length / 2 - 0.003, 0, 0), (0.006, width, 0.07), m["back_shell"], TRUNK_RGBA),
        Part("battery", (0, 0, -h / 2 + 0.013), (0.105, 0.034, 0.018), m["battery"], "0.2 0.3 0.6 1"),
        Part("deck", (0, 0, h / 2 - 0.008), (length - 2 * MOUNT, width, 0.01), m["other"] + m["screws"],
             "0.2 0.5 0.25 1"),
    ]


def payload_part(robot: Robot, mass: float) -> Part:
    return Part("payload", (0, 0, robot.height / 2 + 0.025), (0.2, 0.1, 0.05), mass, "0.5 0.5 0.5 1", "trunk")


def trunk_com(robot: Robot, payload: float = 0.0) -> np.ndarray:
    """(3,) centre of mass of the trunk's parts (and payload) in the trunk frame."""
    parts = trunk_parts(robot) + ([payload_part(robot, payload)] if payload else [])
    masses = np.array([p.mass for p in parts])
    return masses @ np.array([p.pos for p in parts]) / masses.sum()


def _leg_xml(robot: Robot, i: int, pad: str) -> str:
    name, side = LEGS[i], SIDE[i]
    L1, L2, L3 = robot.leg.L1, robot.leg.L2, robot.leg.L3
    w, t = robot.link_width, robot.link_thickness
    (c_lo, c_hi), (f_lo, f_hi), (t_lo, t_hi) = robot.ranges
    hip = robot.layout.hips[i]
    # θ1 > 0 swings the foot outward: about +x on a left leg, −x on a right leg (the mirror image); θ2, θ3 > 0
    # swing it forward, about −y on both sides
    return f"""{pad}<body name="{name}_coxa" pos="{_f(*hip)}">
{pad}  <joint name="{name}_coxa" axis="{_f(side, 0, 0)}" range="{_f(c_lo, c_hi)}"/>
{pad}  {Part(f"{name}_coxa", (0, side * L1 / 2, 0), (MOUNT, L1, 0.04), robot.coxa_mass, SERVO_RGBA).xml()}
{pad}  <body name="{name}_femur" pos="{_f(0, side * L1, 0)}">
{pad}    <joint name="{name}_femur" axis="0 -1 0" range="{_f(f_lo, f_hi)}"/>
{pad}    {Part(f"{name}_femur", (0, 0, -L2 / 2), (w, t, L2), robot.femur_mass, LINK_RGBA).xml()}
{pad}    <body name="{name}_tibia" pos="{_f(0, 0, -L2)}">
{pad}      <joint name="{name}_tibia" axis="0 -1 0" range="{_f(t_lo, t_hi)}"/>
{pad}      {Part(f"{name}_tibia", (0, 0, -L3 / 2), (w * 0.8, t, L3), robot.tibia_mass, LINK_RGBA).xml()}
{pad}      <geom name="{name}_foot" class="foot" pos="{_f(0, 0, -L3)}"/>
{pad}      <site name="{name}_foot" pos="{_f(0, 0, -L3)}" size="0.005"/>
{pad}    </body>
{pad}  </body>
{pad}</body>"""


def mjcf(robot: Robot, scene: Scene = Scene()) -> str:
    """The MJCF text. Joints: the trunk's free joint, then FR, FL, BR, BL × (coxa, femur, tibia) (then the bench's
    pitch and roll hinges); actuators in the same leg order (then the bench's)."""
    legs = "\n".join(_leg_xml(robot, i, "      ") for i in range(4))
    parts = trunk_parts(robot) + ([payload_part(robot, scene.payload)] if scene.payload else [])
    trunk = "\n      ".join(p.xml() for p in parts)
    lo, hi = -robot.stall_torque, robot.stall_torque
    actuators = [f'    <position name="{n}" joint="{n}" kp="{robot.kp:.10g}" forcerange="{_f(lo, hi)}" '
                 f'ctrlrange="{_f(*robot.ranges[k % 3])}"/>'
                 for k, n in enumerate(f"{leg}_{j}" for leg in LEGS for j in JOINTS)]
    sensors = [f'    <contact name="{leg}_contact" geom2="{leg}_foot" data="found force" reduce="netforce"/>'
               for leg in LEGS]
    sensors.append('    <contact name="trunk_contact" body1="trunk" data="found"/>')
    if scene.platform:
        length, width = scene.platform_size
        bench = Part("platform", (0, 0, -0.01), (length, width, 0.02), 5.0, "0.55 0.6 0.65 1", "ground")
        ground = (f'<geom name="floor" class="ground" type="plane" size="2 2 0.05" pos="0 0 {-scene.floor_depth}"/>\n'
                  f'    <body name="platform">\n'
                  f'      <joint name="platform_pitch" axis="0 1 0" range="-0.5 0.5" damping="50"/>\n'
                  f'      <joint name="platform_roll" axis="1 0 0" range="-0.5 0.5" damping="50"/>\n'
                  f'      {bench.xml()}\n'
                  f'    </body>')
        actuators += ['    <position name="platform_pitch" joint="platform_pitch" kp="20000" kv="500"/>',
                      '    <position name="platform_roll" joint="platform_roll" kp="20000" kv="500"/>']
    else:
        ground = '<geom name="floor" class="ground" type="plane" size="0 0 0.05"/>'
    stand_height = robot.leg.L2 + robot.leg.L3 + robot.foot_radius
    return f"""<mujoco model="iron_dog_mini">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{robot.timestep:.10g}" integrator="implicitfast"/>
  <default>
    <joint type="hinge" damping="{robot.damping:.10g}" armature="{robot.armature:.10g}"/>
    <geom contype="0" conaffinity="0"/>
    <default class="visual"><geom type="box"/></default>
    <default class="trunk"><geom type="box" contype="1" conaffinity="0"/></default>
    <default class="foot">
      <geom type="sphere" size="{robot.foot_radius:.10g}" mass="0" contype="1" conaffinity="0"
            friction="{robot.friction:.10g} 0.005 0.0001" rgba="{FOOT_RGBA}"/>
    </default>
    <default class="ground">
      <geom contype="0" conaffinity="1" friction="{robot.friction:.10g} 0.005 0.0001" rgba="0.8 0.8 0.76 1"/>
    </default>
  </default>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1" directional="true"/>
    <body name="trunk" pos="0 0 {stand_height:.10g}">
      <freejoint name="trunk"/>
      <site name="imu" size="0.01"/>
      {trunk}
{legs}
    </body>
    {ground}
  </worldbody>
  <actuator>
{chr(10).join(actuators)}
  </actuator>
  <sensor>
{chr(10).join(sensors)}
  </sensor>
</mujoco>
"""


@dataclass
class Indices:
    """Addresses into a compiled model's arrays, looked up by name once."""

    qpos: np.ndarray = field(default_factory=lambda: np.zeros(0, int))    # (12,) leg joint qpos
    dof: np.ndarray = field(default_factory=lambda: np.zeros(0, int))     # (12,) leg joint dofs
    contact: np.ndarray = field(default_factory=lambda: np.zeros(0, int))  # (4,) sensordata start of each foot
    trunk_contact: int = -1                                                  # sensordata of the trunk's contact
    feet: np.ndarray = field(default_factory=lambda: np.zeros(0, int))    # (4,) foot sites
    bodies: list[str] = field(default_factory=list)                        # every body but the world
    platform_qpos: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    platform_ctrl: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    @classmethod
    def of(cls, model) -> Indices:
        import mujoco

        def ids(kind, names):
            return np.array([mujoco.mj_name2id(model, kind, n) for n in names])

        obj = mujoco.mjtObj
        names = [f"{leg}_{j}" for leg in LEGS for j in JOINTS]
        joints = ids(obj.mjOBJ_JOINT, names)
        idx = cls(qpos=model.jnt_qposadr[joints], dof=model.jnt_dofadr[joints],
                  contact=model.sensor_adr[ids(obj.mjOBJ_SENSOR, [f"{leg}_contact" for leg in LEGS])],
                  trunk_contact=int(model.sensor_adr[ids(obj.mjOBJ_SENSOR, ["trunk_contact"])[0]]),
                  feet=ids(obj.mjOBJ_SITE, [f"{leg}_foot" for leg in LEGS]),
                  bodies=[mujoco.mj_id2name(model, obj.mjOBJ_BODY, b) for b in range(1, model.nbody)])
        if mujoco.mj_name2id(model, obj.mjOBJ_JOINT, "platform_pitch") >= 0:
            platform = ids(obj.mjOBJ_JOINT, ["platform_pitch", "platform_roll"])
            idx.platform_qpos = model.jnt_qposadr[platform]
            idx.platform_ctrl = ids(obj.mjOBJ_ACTUATOR, ["platform_pitch", "platform_roll"])
        return idx

"""FORREST as a MuJoCo model, generated from Table 4 (never downloaded).

Table 4 is a floating-base tree: link i sits at the fixed transform T_i^p in its parent and rotates about its own
z. Links 1-6 are the floating base (3 translations, 3 rotations), 7-12 the left leg, 13-18 the right leg. The
rotations are composed as printed; the translations are read as zero-pose (world) offsets, because in the parent
frame they would lie along the hip-pitch axis (paper.yaml, erratum T4-1). The composed joint axes are, per leg,
hip yaw (z), hip roll (x), hip pitch (y), knee (y), ankle pitch (y), ankle roll (−x).

Every MJCF body frame is world-aligned at the zero pose (straight legs), so a body's CoM and inertia are Table 4's
r and I_d rotated into the world by the composed link rotation; the joint axis is the link's z in the world. The
same `Biped` description feeds a URDF generator later (one source). Geoms sized from Tables 1 and 4 draw the
robot; only the four corner spheres under each foot plate touch the ground (Sec. 6.3).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

LEGS = ("l", "r")
LEG_JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
JOINTS = tuple(f"{leg}_{j}" for leg in LEGS for j in LEG_JOINTS)
FIRST_LINK = {"l": 7, "r": 13}          # Table 4 link id of each leg's first joint
CORNERS = ("front_left", "front_right", "back_left", "back_right")
MIN_INERTIA = 1e-5                      # kg m², see _inertial


def _rotation(axis: str, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return {"rotx": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "roty": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "rotz": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


@dataclass(frozen=True)
class Link:
    """One Table 4 link in the world at the zero pose."""

    id: int
    parent: int
    rotation: np.ndarray      # (3, 3) composed rotation of the link frame
    origin: np.ndarray        # (3,) frame origin relative to the base (link 6) origin, m
    mass: float
    com: np.ndarray           # (3,) CoM relative to the link origin, world axes, m
    inertia: np.ndarray       # (3, 3) about the CoM, world axes, kg m²

    @property
    def axis(self) -> np.ndarray:
        return self.rotation[:, 2]


def table4_links(table: Mapping[str, Sequence], inertia_about: str = "com", link16_inertia: str = "mirror",
                 mass_scale: float = 1.0) -> dict[int, Link]:
    """Compose Table 4 (columns link, parent, T, mass, com, inertia) into links 6-18 at the zero pose.

    `inertia_about`: I_d about the CoM (`com`) or about the link origin (`origin`, legs only, shifted to the CoM
    by the parallel-axis theorem). `link16_inertia`: `mirror` uses link 10's I_d for link 16 (a typo in the
    table), `printed` the printed [0 0.01 0.01]. `mass_scale` multiplies every mass and inertia."""
    rows = {int(i): k for k, i in enumerate(table["link"])}
    rotation: dict[int, np.ndarray] = {0: np.eye(3)}
    origin: dict[int, np.ndarray] = {0: np.zeros(3)}
    links: dict[int, Link] = {}
    for i in sorted(rows):
        k = rows[i]
        p = int(table["parent"][k])
        R, t = rotation[p].copy(), np.zeros(3)
        for kind, value in table["T"][k]:
            if kind == "trans":
                t = t + np.asarray(value, dtype=float)   # world (zero-pose) offset: see the module doc
            else:
                R = R @ _rotation(kind, float(value))
        rotation[i], origin[i] = R, origin[p] + t
        if i < 6:
            continue
        I_d = table["inertia"][rows[10] if i == 16 and link16_inertia == "mirror" else k]
        m = float(table["mass"][k]) * mass_scale
        c = R @ np.asarray(table["com"][k], dtype=float)
        inertia = R @ np.diag(np.asarray(I_d, dtype=float) * mass_scale) @ R.T
        if inertia_about == "origin" and i > 6:
            inertia = inertia - m * (c @ c * np.eye(3) - np.outer(c, c))
        links[i] = Link(i, p, R, origin[i] - origin[6], m, c, inertia)
    return links


@dataclass(frozen=True)
class Biped:
    """The generated model and what the controller needs to know about it."""

    xml: str
    links: dict[int, Link]
    mass: float                  # kg, total
    hip_height: float            # m, hip line above the sole with straight legs
    foot_half: tuple[float, float]   # m, half length (x) and half width (y) of the plate
    torque_limit: np.ndarray     # (12,) N m, in JOINTS order
    body_names: tuple[str, ...]  # MuJoCo bodies of the robot (base first)


def _fmt(v) -> str:
    return " ".join(f"{x:.10g}" for x in np.atleast_1d(v))


def _inertial(link: Link) -> str:
    """<inertial> at the CoM. Table 4's zero entries (links 10, 11) get a floor of MIN_INERTIA: MuJoCo needs a
    positive inertia, and a real link has one."""
    inertia = link.inertia + np.diag(np.maximum(MIN_INERTIA - np.diag(link.inertia), 0.0))
    full = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
    return f'<inertial pos="{_fmt(link.com)}" mass="{link.mass:.10g}" fullinertia="{_fmt(full)}"/>'


def build(system: Mapping[str, Any], plant: bool = True) -> Biped:
    """MJCF of FORREST from the system config (conf/system/forrest-biped.yaml): the simulated robot (`plant`:
    Table 4 changed by `system.plant`, on the ground) or the controller's model (Table 4 read as
    `system.model` says, no ground)."""
    m = system["model"]
    reading = system["plant"] if plant else m
    links = table4_links(system["table4"], reading["inertia_about"], m["link16_inertia"],
                         system["plant"]["mass_scale"] if plant else 1.0)
    thigh = -links[10].origin[2] + links[9].origin[2]
    calf = -links[11].origin[2] + links[10].origin[2]
    sole = float(m["sole_depth"])
    hip_height = thigh + calf + sole
    half = (m["foot_length"] / 2, m["foot_width"] / 2)
    rc = float(m["corner_radius"])
    limits = np.tile(np.asarray(m["torque_limit"], dtype=float), 2)
    base = links[6]
    grey, dark, blue = "0.62 0.65 0.7 1", "0.3 0.32 0.36 1", "0.25 0.45 0.75 1"

    def leg(side: str) -> str:
        first = FIRST_LINK[side]
        xml, close = [], []
        pad = "      "
        for k, name in enumerate(LEG_JOINTS):
            link = links[first + k]
            pos = link.origin - (links[first + k - 1].origin if k else 0.0)
            joint = f"{side}_{name}"
            xml.append(f'{pad}<body name="{side}_link{first + k}" pos="{_fmt(pos)}">')
            xml.append(f'{pad}  <joint name="{joint}" axis="{_fmt(np.round(link.axis, 12))}"/>')
            xml.append(f"{pad}  {_inertial(link)}")
            if name == "hip_yaw":      # the bracket reaching forward to the yaw link's CoM
                xml.append(f'{pad}  <geom type="capsule" fromto="0 0 0 {_fmt(link.com)}" size="0.035" rgba="{dark}"/>')
            elif name == "hip_roll":
                xml.append(f'{pad}  <geom type="sphere" size="0.06" rgba="{dark}"/>')
            elif name == "hip_pitch":  # thigh, Table 1: 405 mm
                xml.append(f'{pad}  <geom type="capsule" fromto="0 0 0 0 0 {-thigh:.10g}" size="0.05" rgba="{grey}"/>')
            elif name == "knee":       # calf
                xml.append(f'{pad}  <geom type="capsule" fromto="0 0 0 0 0 {-calf:.10g}" size="0.04" rgba="{grey}"/>')
            elif name == "ankle_pitch":
                xml.append(f'{pad}  <geom type="sphere" size="0.03" rgba="{dark}"/>')
            else:                      # foot: the link to the plate, the plate, its corner contacts
                ax = float(m["ankle_x"])
                xml.append(f'{pad}  <geom type="capsule" fromto="0 0 0 {ax:.10g} 0 {-sole + 0.02:.10g}" size="0.025" '
                           f'rgba="{dark}"/>')
                xml.append(f'{pad}  <geom name="{side}_plate" type="box" pos="{ax:.10g} 0 {-sole + 0.01:.10g}" '
                           f'size="{half[0]:.10g} {half[1]:.10g} 0.01" rgba="{blue}"/>')
                xml.append(f'{pad}  <site name="{side}_sole" pos="{ax:.10g} 0 {-sole:.10g}" size="0.01"/>')
                for corner in CORNERS:
                    sx = 1 if corner.startswith("front") else -1
                    sy = 1 if corner.endswith("left") else -1
                    xml.append(f'{pad}  <geom name="{side}_{corner}" class="contact" '
                               f'pos="{ax + sx * half[0]:.10g} {sy * half[1]:.10g} {-sole + rc:.10g}" '
                               f'size="{rc:.10g}"/>')
            close.append(f"{pad}</body>")
            pad += "  "
        return "\n".join(xml + close[::-1])

    actuators = "\n".join(f'    <motor name="{j}" joint="{j}" ctrlrange="{-u:.10g} {u:.10g}"/>'
                          for j, u in zip(JOINTS, limits, strict=True))
    solref = _fmt(m["contact_solref"])
    floor = (f'    <geom name="floor" type="plane" size="5 5 0.05" contype="0" conaffinity="1" condim="3" '
             f'friction="{m["friction"]:.10g} 0.005 0.0001" solref="{solref}" rgba="0.85 0.82 0.75 1"/>')
    xml = f"""<mujoco model="forrest">
  <compiler angle="radian" autolimits="true" balanceinertia="true"/>
  <option timestep="{m['physics_dt']:.10g}" gravity="0 0 {-system['gravity']:.10g}" integrator="Euler"
          cone="elliptic"/>
  <default>
    <geom contype="0" conaffinity="0" density="0"/>
    <default class="contact">
      <geom type="sphere" contype="1" conaffinity="0" condim="3" friction="{m['friction']:.10g} 0.005 0.0001"
            solref="{solref}" rgba="0.9 0.3 0.2 1"/>
    </default>
  </default>
  <visual><global offwidth="1280" offheight="720"/></visual>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
{floor if plant else ""}
    <body name="base" pos="0 0 {hip_height:.10g}">
      <freejoint name="base"/>
      {_inertial(base)}
      <geom type="box" pos="0 0 0.125" size="0.08 0.16 0.125" rgba="{grey}"/>
      <geom type="capsule" fromto="0 {-links[7].origin[1]:.10g} 0 0 {links[7].origin[1]:.10g} 0" size="0.04"
            rgba="{dark}"/>
{leg("l")}
{leg("r")}
    </body>
  </worldbody>
  <actuator>
{actuators}
  </actuator>
</mujoco>
"""
    mass = sum(link.mass for link in links.values())
    bodies = ("base", *(f"{side}_link{FIRST_LINK[side] + k}" for side in LEGS for k in range(6)))
    return Biped(xml=xml, links=links, mass=mass, hip_height=hip_height, foot_half=half, torque_limit=limits,
                 body_names=bodies)

"""A MuJoCo model of the SRS arm and the human arms, generated from the paper's parameters: the planned motion
is replayed under a joint servo, and MuJoCo's own distance query (`mj_geomDistance`) audits our clearance.

The paper's base frame is y-up; the model's world is z-up (MuJoCo's gravity, Foxglove's and Rerun's default
view): body `base` turns y_b onto z by Rx(+π/2). Bodies link1..link7 sit at their joints in the frames of
`kinematics.link_frames`; links are capsules of `link_radius` (the paper has no link geometry); the human
links are capsules on mocap bodies (their local z along the link). Nothing collides (contype = 0): the
replay is the arm's dynamics only, and distances are queried, not felt.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.srs_collision_avoidance.kinematics import JOINTS, Geometry

BASE_QUAT = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])   # Rx(+π/2): y_b -> z_world
R_WORLD_BASE = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
ROBOT_LINKS = ("column", "upper_arm", "forearm", "tool")   # O_b P_s, P_s P_e, P_e P_w, P_w O_e


@dataclass(frozen=True)
class Dynamics:
    """What the kinematic paper leaves out, for the replay (config `system.dynamics`)."""

    masses: tuple[float, ...]        # kg, links 1..7
    link_radius: float               # m, capsule radius of the links (drawing, inertia, clearance)
    armature: tuple[float, ...]      # kg m², per joint
    damping: tuple[float, ...]       # N m s/rad, per joint
    torque_limit: tuple[float, ...]  # N m, per joint


def _f(v) -> str:
    return " ".join(f"{x:.12g}" for x in np.atleast_1d(v))


def _inertial(mass: float, length: float, radius: float) -> str:
    """A uniform rod of `length` along x from the body origin (a sphere of `radius` if length is 0)."""
    if length == 0:
        i = 0.4 * mass * radius ** 2
        return f'<inertial pos="0 0 0" mass="{mass:.12g}" diaginertia="{_f([i, i, i])}"/>'
    axial, transverse = mass * radius ** 2 / 2, mass * (3 * radius ** 2 + length ** 2) / 12
    inertia = _f([axial, transverse, transverse])
    return f'<inertial pos="{length / 2:.12g} 0 0" mass="{mass:.12g}" diaginertia="{inertia}"/>'


def model_xml(g: Geometry, dyn: Dynamics, human_radii: np.ndarray, human_lengths: np.ndarray, *, timestep: float,
              kp: np.ndarray, kv: np.ndarray) -> str:
    """MJCF of the arm (servo controls [q_ref (7), q̇_ref (7)], gravity compensated) and the human links."""
    r = dyn.link_radius
    # (axis, position in the parent body, link length along the body's x) of links 1..7
    bodies = [("0 1 0", f"0 {g.a0:.12g} 0", 0.0), ("0 0 1", "0 0 0", 0.0), ("1 0 0", "0 0 0", g.a1),
              ("0 0 1", f"{g.a1:.12g} 0 0", 0.0), ("1 0 0", "0 0 0", g.a2), ("0 0 1", f"{g.a2:.12g} 0 0", 0.0),
              ("1 0 0", "0 0 0", g.a3)]
    geoms = {3: "upper_arm", 5: "forearm", 7: "tool"}
    lines, pad = [], "      "
    for i, (axis, pos, length) in enumerate(bodies, start=1):
        k = i - 1
        lines.append(f'{pad}<body name="link{i}" pos="{pos}" gravcomp="1">')
        lines.append(f'{pad}  <joint name="{JOINTS[k]}" axis="{axis}" armature="{dyn.armature[k]:.12g}" '
                     f'damping="{dyn.damping[k]:.12g}" actuatorfrcrange="{-dyn.torque_limit[k]:.12g} '
                     f'{dyn.torque_limit[k]:.12g}"/>')
        lines.append(f"{pad}  {_inertial(dyn.masses[k], length, r)}")
        if i in geoms:
            lines.append(f'{pad}  <geom name="{geoms[i]}" type="capsule" fromto="0 0 0 {length:.12g} 0 0" '
                         f'size="{r:.12g}"/>')
        pad += "  "
    tool_quat = _f([np.cos(g.tool_rotation_y / 2), 0.0, np.sin(g.tool_rotation_y / 2), 0.0])
    lines.append(f'{pad}<site name="tool" pos="{g.a3:.12g} 0 0" quat="{tool_quat}" size="0.01"/>')
    for _ in bodies:
        pad = pad[:-2]
        lines.append(f"{pad}</body>")
    humans = "\n".join(
        f'    <body name="human{k // 2 + 1}_{("upper", "fore")[k % 2]}" mocap="true">'
        f'<geom name="human{k // 2 + 1}_{("upper", "fore")[k % 2]}" type="capsule" fromto="0 0 0 0 0 {length:.12g}" '
        f'size="{radius:.12g}" rgba="0.85 0.55 0.4 1"/></body>'
        for k, (radius, length) in enumerate(zip(human_radii, human_lengths, strict=True)))
    actuators = "\n".join(f'    <position name="pos{i}" joint="joint{i}" kp="{kp[i - 1]:.12g}"/>' for i in range(1, 8))
    actuators += "\n" + "\n".join(f'    <velocity name="vel{i}" joint="joint{i}" kv="{kv[i - 1]:.12g}"/>'
                                  for i in range(1, 8))
    sensors = "\n".join(f'    <jointactuatorfrc name="tau{i}" joint="joint{i}"/>' for i in range(1, 8))
    return f"""<mujoco model="srs_collision_avoidance">
  <compiler angle="radian" autolimits="true" inertiafromgeom="false"/>
  <option timestep="{timestep:.12g}" integrator="implicitfast"/>
  <default>
    <joint actuatorgravcomp="true"/>
    <geom contype="0" conaffinity="0" rgba="0.9 0.5 0.1 1"/>
  </default>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="1.2 1.2 0.01" rgba="0.85 0.85 0.85 1"/>
    <body name="base" quat="{_f(BASE_QUAT)}">
      <geom name="column" type="capsule" fromto="0 0 0 0 {g.a0:.12g} 0" size="{r:.12g}" rgba="0.4 0.4 0.45 1"/>
{chr(10).join(lines)}
    </body>
{humans}
  </worldbody>
  <actuator>
{actuators}
  </actuator>
  <sensor>
{sensors}
    <framepos name="tool_pos" objtype="site" objname="tool"/>
    <framequat name="tool_quat" objtype="site" objname="tool"/>
  </sensor>
</mujoco>
"""


def mocap_poses(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World positions and quaternions (w, x, y, z) of mocap capsules along z from `start` to `end` (base frame),
    batched over leading axes."""
    a = start @ R_WORLD_BASE.T
    d = (end - start) @ R_WORLD_BASE.T
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    # half-way quaternion between z and d: (1 + d_z, z × d) normalised (d = −z never occurs: arms not vertical)
    quat = np.concatenate([1.0 + d[..., 2:3], -d[..., 1:2], d[..., 0:1], np.zeros_like(d[..., :1])], axis=-1)
    return a, quat / np.linalg.norm(quat, axis=-1, keepdims=True)


def capsule_distances(xml: str, q: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """(N, m, 4) signed distances by `mj_geomDistance` of the m human capsules to the robot's four link capsules
    (`ROBOT_LINKS`), with the arm at q (N, 7) and the humans at (start, end) (N, m, 3) in the base frame."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    human_bodies = [int(np.flatnonzero(model.body_mocapid == k)[0]) for k in range(model.nmocap)]
    human_geoms = [int(model.body_geomadr[b]) for b in human_bodies]
    robot_geoms = [model.geom(name).id for name in ROBOT_LINKS]
    positions, quats = mocap_poses(start, end)
    out = np.empty((len(q), len(human_geoms), len(robot_geoms)))
    distance = mujoco.mj_geomDistance
    for n in range(len(q)):
        data.qpos[:] = q[n]
        data.mocap_pos[:] = positions[n]
        data.mocap_quat[:] = quats[n]
        mujoco.mj_kinematics(model, data)
        for i, h in enumerate(human_geoms):
            for j, rg in enumerate(robot_geoms):
                out[n, i, j] = distance(model, data, h, rg, 10.0, None)
    return out

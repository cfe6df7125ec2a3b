"""A robot description (URDF) generated from the compiled MuJoCo model the run simulates: one source of truth.

Why not a converter from PyPI: `mjcf-urdf-simple-converter` (0.7.3) converts mesh geoms only, hinge joints only,
and writes mesh files next to the URDF; `truerig` (0.1.1) drops joint anchors and `ref` offsets, turns capsules
into bare cylinders and skips world geoms; `mjcf2urdf` (0.0.1, 2020) is unmaintained. The paper models here are
primitives (capsules, cylinders, spheres, boxes), with slide, ball, free and mocap bodies, and the URDF travels
inside the run (no files beside it), so the conversion is done here from the compiled `MjModel`, where MuJoCo
has already resolved defaults, `fromto`, frames and inertias.

Conventions (what a viewer sees):
- links are `<robot>/<body>` (robot = the MJCF model name); the root link is `world`, the frame every paper's
  `/tf` already hangs from, so the robot and the paper's frames form one tree. The prefix keeps the URDF's
  parent-child frames apart from a paper's own frames of the same bodies (e.g. `link3` in world).
- a link's frame is its MuJoCo body frame, so URDF FK equals `data.xpos`/`data.xquat`.
- joints keep their MJCF names and their MuJoCo coordinate (`ref` is folded into the origin): the joint-state
  channel carries exactly `qpos`. URDF has no ball, free or mocap joint: a ball joint becomes three revolute
  joints `<name>/rx, /ry, /rz` (intrinsic XYZ angles of its quaternion), a free joint or a mocap body six
  (`/x, /y, /z` then `/rx, /ry, /rz`); their positions are computed from `qpos` and the mocap poses.
- a closed chain is simulated in MuJoCo as a tree plus equality constraints: the URDF is that spanning tree,
  and the simulated positions of every joint (passive ones included) close the loop on screen.
- visuals are the MJCF geoms (a capsule is a cylinder with two spheres); a body without geoms (a pure inertial
  link) is drawn as rods to its children and sites with a ball at its centre of mass, sized from those lengths.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

ROOT = "world"
_GEOM_PLANE, _GEOM_HFIELD, _GEOM_SPHERE, _GEOM_CAPSULE, _GEOM_ELLIPSOID, _GEOM_CYLINDER, _GEOM_BOX, _GEOM_MESH = \
    range(8)
_FREE, _BALL, _SLIDE, _HINGE = range(4)
_AXES = np.eye(3)
_PLANE_EXTENT = 2.0      # m, half-size drawn for an infinite plane
_HIDDEN_GROUPS = 3       # MuJoCo shows geom groups 0-2 by default
_FALLBACK_RGBA = (0.55, 0.6, 0.7, 1.0)


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of (..., 4) wxyz quaternions, batched."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate (..., 3) vectors by (..., 4) wxyz quaternions."""
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    half = 0.5 * np.asarray(angle, dtype=float)[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


@dataclass(frozen=True)
class Pose:
    """A rigid transform: translation (3,) then rotation as a wxyz quaternion (4,)."""

    p: np.ndarray
    q: np.ndarray

    @staticmethod
    def identity() -> Pose:
        return Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))

    def __matmul__(self, other: Pose) -> Pose:
        # _rotate and _quat_mul's operations in their order on Python floats (the same IEEE numbers): for one
        # pose a tenth of NumPy's cost, and a URDF is described from hundreds of them
        (px, py, pz), (w, x, y, z) = (np.asarray(a, dtype=float).tolist() for a in (self.p, self.q))
        (vx, vy, vz), (bw, bx, by, bz) = (np.asarray(a, dtype=float).tolist() for a in (other.p, other.q))
        tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
        return Pose(np.array([px + (vx + w * tx + (y * tz - z * ty)), py + (vy + w * ty + (z * tx - x * tz)),
                              pz + (vz + w * tz + (x * ty - y * tx))]),
                    np.array([w * bw - x * bx - y * by - z * bz, w * bx + x * bw + y * bz - z * by,
                              w * by - x * bz + y * bw + z * bx, w * bz + x * by - y * bx + z * bw]))

    def shifted(self, p: np.ndarray) -> Pose:
        """This pose followed by a pure translation p (in this frame)."""
        return self @ Pose(np.asarray(p, dtype=float), np.array([1.0, 0.0, 0.0, 0.0]))

    def rpy(self) -> np.ndarray:
        return np.array(_rpy(np.asarray(self.q, dtype=float).tobytes()))


@functools.lru_cache(maxsize=4096)
def _rpy(wxyz: bytes) -> tuple[float, float, float]:
    """URDF's fixed-axis roll, pitch, yaw of a quaternion (its float64 bytes: -0.0 is not 0.0 to atan2),
    remembered: a model's geoms and joints repeat a few orientations (a capsule's cylinder and end spheres, the
    same arm with other servo gains), and SciPy costs tens of µs a call."""
    return tuple(_euler(np.frombuffer(wxyz, dtype=float)[None], "xyz")[0].tolist())


@dataclass(frozen=True)
class Joint:
    """One URDF joint: `child` sits at `origin` in `parent`, then moves along/about `axis` by its position."""

    name: str
    kind: str                 # revolute, continuous, prismatic or fixed
    parent: str
    child: str
    origin: Pose
    axis: np.ndarray
    limits: tuple[float, float] | None = None


@dataclass(frozen=True)
class _Source:
    """Where a movable URDF joint's position comes from: `qpos[index]`, a component of the Euler angles or
    position of a ball/free joint's or a mocap body's pose."""

    kind: str                 # qpos, euler (of qpos[index:index+4]), mocap_pos, mocap_euler
    index: int
    component: int = 0


class RobotDescription:
    """The URDF of a MuJoCo model, its joints, and the per-sample joint positions and link transforms a
    viewer needs, computed in NumPy over whole trajectories."""

    def __init__(self, name: str, joints: list[Joint], sources: list[_Source], visuals: dict[str, list[str]]):
        self.name = name
        self.joints = joints
        self.movable = [j for j in joints if j.kind != "fixed"]
        self.fixed = [j for j in joints if j.kind == "fixed"]
        self._sources = sources
        self._visuals = visuals
        self._urdf: str | None = None

    @property
    def joint_names(self) -> list[str]:
        """Names of the movable joints, in the order of `joint_positions` columns."""
        return [j.name for j in self.movable]

    @property
    def links(self) -> list[str]:
        return [ROOT, *(j.child for j in self.joints)]

    def urdf(self) -> str:
        if self._urdf is None:
            self._urdf = self._write_urdf()
        return self._urdf

    def _write_urdf(self) -> str:
        out = [f'<?xml version="1.0"?>\n<robot name={quoteattr(self.name)}>']
        for link in self.links:
            out.append(f"  <link name={quoteattr(link)}>")
            out.extend(self._visuals.get(link, []))
            out.append("  </link>")
        for j in self.joints:
            rpy = j.origin.rpy()
            out.append(f"  <joint name={quoteattr(j.name)} type=\"{j.kind}\">\n"
                       f"    <parent link={quoteattr(j.parent)}/>\n    <child link={quoteattr(j.child)}/>\n"
                       f"    <origin xyz=\"{_fmt(j.origin.p)}\" rpy=\"{_fmt(rpy)}\"/>")
            if j.kind != "fixed":
                out.append(f"    <axis xyz=\"{_fmt(j.axis)}\"/>")
            if j.kind in ("revolute", "prismatic"):
                lower, upper = j.limits or (-1e3, 1e3)
                out.append(f"    <limit lower=\"{_num(lower)}\" upper=\"{_num(upper)}\" effort=\"0\" velocity=\"0\"/>")
            out.append("  </joint>")
        out.append("</robot>\n")
        return "\n".join(out)

    def joint_positions(self, qpos: np.ndarray, mocap_pos: np.ndarray | None = None,
                        mocap_quat: np.ndarray | None = None) -> np.ndarray:
        """(N, len(joint_names)) URDF joint positions from MuJoCo `qpos` (N, nq) and, for mocap bodies, their
        world poses `mocap_pos` (N, nmocap, 3) and `mocap_quat` (N, nmocap, 4, wxyz)."""
        qpos = np.atleast_2d(np.asarray(qpos, dtype=float))
        out = np.empty((len(qpos), len(self._sources)))
        euler: dict[tuple[str, int], np.ndarray] = {}
        for column, src in enumerate(self._sources):
            if src.kind == "qpos":
                out[:, column] = qpos[:, src.index]
            elif src.kind == "mocap_pos":
                out[:, column] = _mocap(mocap_pos, src, len(qpos), 3)[:, src.component]
            else:
                key = (src.kind, src.index)
                if key not in euler:
                    quat = qpos[:, src.index:src.index + 4] if src.kind == "euler" else \
                        _mocap(mocap_quat, src, len(qpos), 4)
                    euler[key] = _euler(quat, "XYZ")  # R = Rx(a)·Ry(b)·Rz(c)
                out[:, column] = euler[key][:, src.component]
        return out

    def transforms(self, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pose of each movable joint's child link in its parent link (what robot_state_publisher sends):
        translations (N, k, 3) and wxyz quaternions (N, k, 4) for joint positions (N, k)."""
        positions = np.atleast_2d(positions)
        origins = np.array([j.origin.p for j in self.movable]).reshape(-1, 3)
        rotations = np.array([j.origin.q for j in self.movable]).reshape(-1, 4)
        axes = np.array([j.axis for j in self.movable], dtype=float).reshape(-1, 3)
        sliding = np.array([j.kind == "prismatic" for j in self.movable], dtype=bool)
        trans = origins + np.where(sliding[:, None], _rotate(rotations, axes) * positions[..., None], 0.0)
        quats = _quat_mul(rotations, _axis_angle(axes, np.where(sliding, 0.0, positions)))
        return trans, quats


def _euler(quat: np.ndarray, sequence: str) -> np.ndarray:
    """Euler angles (N, 3) of (N, 4) wxyz quaternions: "xyz", URDF's fixed-axis roll, pitch, yaw
    (R = Rz(c)·Ry(b)·Rx(a)), or "XYZ", moving axes (R = Rx(a)·Ry(b)·Rz(c)). The middle angle by atan2 keeps full
    precision near ±π/2; at gimbal lock the third angle is zero (as SciPy sets it) and the rotation is exact.
    In NumPy: SciPy would cost a stage 0.25 s to import, for a few dozen angles."""
    w, x, y, z = (np.asarray(quat, dtype=float) / np.linalg.norm(quat, axis=-1, keepdims=True)).T
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    if sequence == "xyz":
        cos_b = np.hypot(R[0, 0], R[1, 0])
        a, b, c = np.arctan2(R[2, 1], R[2, 2]), np.arctan2(-R[2, 0], cos_b), np.arctan2(R[1, 0], R[0, 0])
        locked_a = np.arctan2(-R[1, 2], R[1, 1])
    elif sequence == "XYZ":
        cos_b = np.hypot(R[0, 0], R[0, 1])
        a, b, c = np.arctan2(-R[1, 2], R[2, 2]), np.arctan2(R[0, 2], cos_b), np.arctan2(-R[0, 1], R[0, 0])
        locked_a = np.arctan2(R[2, 1], R[1, 1])
    else:
        raise ValueError(f"Euler sequence {sequence!r}: 'xyz' or 'XYZ'")
    locked = cos_b < 1e-12
    return np.column_stack([np.where(locked, locked_a, a), b, np.where(locked, 0.0, c)])


def _mocap(values: np.ndarray | None, src: _Source, n: int, width: int) -> np.ndarray:
    if values is None:
        raise ValueError("the model has mocap bodies: pass their poses (mocap_pos, mocap_quat)")
    return np.broadcast_to(np.asarray(values, dtype=float)[..., src.index, :], (n, width))


def _num(x) -> str:
    """12 significant digits (float32 colours and 1e-17 round-off would otherwise print as noise)."""
    x = float(f"{float(x):.12g}")
    return repr(x if abs(x) > 1e-12 else 0.0)


def _fmt(values) -> str:
    return " ".join(_num(x) for x in np.atleast_1d(values))


def _name(model, kind, index: int, fallback: str) -> str:
    import mujoco

    return mujoco.mj_id2name(model, kind, index) or fallback


def _material(rgba) -> str:
    return f"      <material name=\"rgba {_fmt(rgba)}\"><color rgba=\"{_fmt(rgba)}\"/></material>"


def _visual(pose: Pose, geometry: str, rgba) -> str:
    return (f"    <visual>\n      <origin xyz=\"{_fmt(pose.p)}\" rpy=\"{_fmt(pose.rpy())}\"/>\n"
            f"      <geometry>{geometry}</geometry>\n{_material(rgba)}\n    </visual>")


def _geom_visuals(model, g: int) -> list[str]:
    """URDF visuals of one MuJoCo geom, in its body's frame."""
    size, kind = model.geom_size[g], int(model.geom_type[g])
    pose = Pose(model.geom_pos[g].copy(), model.geom_quat[g].copy())
    mat = int(model.geom_matid[g])
    rgba = model.mat_rgba[mat] if mat >= 0 else model.geom_rgba[g]
    if kind == _GEOM_SPHERE:
        return [_visual(pose, f'<sphere radius="{_num(size[0])}"/>', rgba)]
    if kind == _GEOM_ELLIPSOID:  # no URDF ellipsoid: the enclosing sphere
        return [_visual(pose, f'<sphere radius="{_num(max(size))}"/>', rgba)]
    if kind in (_GEOM_CYLINDER, _GEOM_CAPSULE):
        shapes = [_visual(pose, f'<cylinder radius="{_num(size[0])}" length="{_num(2 * size[1])}"/>', rgba)]
        if kind == _GEOM_CAPSULE:  # URDF has no capsule: cylinder + hemispherical ends
            shapes += [_visual(pose.shifted([0, 0, s * size[1]]), f'<sphere radius="{_num(size[0])}"/>', rgba)
                       for s in (-1, 1)]
        return shapes
    if kind == _GEOM_BOX:
        return [_visual(pose, f'<box size="{_fmt(2 * size)}"/>', rgba)]
    if kind == _GEOM_PLANE:
        half = [s if s > 0 else _PLANE_EXTENT for s in size[:2]]
        return [_visual(pose.shifted([0, 0, -0.0005]), f'<box size="{_num(2 * half[0])} {_num(2 * half[1])} 0.001"/>',
                        rgba)]
    return []  # height fields and meshes: a paper draws its terrain as /markers


def _stick_visuals(model, b: int) -> list[str]:
    """A body without geoms: rods from its origin to its children and sites, a ball at its centre of mass."""
    ends = [model.body_pos[c] for c in range(model.nbody) if c != b and model.body_parentid[c] == b]
    ends += [model.site_pos[s] for s in range(model.nsite) if model.site_bodyid[s] == b]
    ends = [np.asarray(e, dtype=float) for e in ends if np.linalg.norm(e) > 1e-9]
    scale = max([np.linalg.norm(e) for e in ends] + [2 * np.linalg.norm(model.body_ipos[b]), 0.05])
    radius = 0.03 * scale
    out = []
    for end in ends:
        length = float(np.linalg.norm(end))
        z = end / length
        axis = np.cross([0.0, 0.0, 1.0], z)
        angle = np.arctan2(np.linalg.norm(axis), z[2])
        axis = axis / np.linalg.norm(axis) if np.linalg.norm(axis) > 1e-12 else np.array([1.0, 0.0, 0.0])
        pose = Pose(end / 2, _axis_angle(axis, angle))
        out.append(_visual(pose, f'<cylinder radius="{_num(radius)}" length="{_num(length)}"/>', _FALLBACK_RGBA))
    if model.body_mass[b] > 0:
        out.append(_visual(Pose(model.body_ipos[b].copy(), np.array([1.0, 0, 0, 0])),
                           f'<sphere radius="{_num(2 * radius)}"/>', _FALLBACK_RGBA))
    return out


_ACTUATORS = re.compile(r"<actuator>.*?</actuator>", re.DOTALL)
# MJCF text without its actuators -> (a model of that robot, its description), for a few robots
_DESCRIPTIONS: dict[str, tuple[Any, RobotDescription]] = {}


def described(xml: str) -> tuple[Any, RobotDescription]:
    """A compiled `MjModel` of the robot of an MJCF text (read-only) and its robot description, made once per
    process for each robot: actuators move nothing a drawing reads, so the runs of a stage whose models
    differ only in their servo gains share both (the model is the first of them; simulate with your own)."""
    from pipeline.robotics.mjcf import compiled

    key = _ACTUATORS.sub("", xml)
    if key not in _DESCRIPTIONS:
        if len(_DESCRIPTIONS) >= 8:
            del _DESCRIPTIONS[next(iter(_DESCRIPTIONS))]
        model = compiled(xml)
        _DESCRIPTIONS[key] = model, describe(model)
    return _DESCRIPTIONS[key]


def describe(model, name: str | None = None) -> RobotDescription:
    """The robot description of a compiled MuJoCo model (`mujoco.MjModel`)."""
    import mujoco

    robot = re.sub(r"[^\w.-]", "_", name or model.names.split(b"\0", 1)[0].decode() or "robot")
    body_name = [_name(model, mujoco.mjtObj.mjOBJ_BODY, b, f"body{b}") for b in range(model.nbody)]
    link = [ROOT] + [f"{robot}/{n}" for n in body_name[1:]]
    joints: list[Joint] = []
    sources: list[_Source] = []
    visuals: dict[str, list[str]] = {}
    for g in range(model.ngeom):
        if model.geom_group[g] < _HIDDEN_GROUPS and model.geom_rgba[g][3] > 0:
            visuals.setdefault(link[model.geom_bodyid[g]], []).extend(_geom_visuals(model, g))
    for b in range(1, model.nbody):
        parent, child = link[model.body_parentid[b]], link[b]
        if child not in visuals:
            visuals[child] = _stick_visuals(model, b)
        frame, chain, anchor = _body_joints(model, b, body_name[b])
        previous = parent
        for i, (jname, kind, axis, origin, limits, src) in enumerate(chain):
            target = child if i == len(chain) - 1 and not anchor.any() else f"{child}/{jname}"
            joints.append(Joint(jname, kind, previous, target, frame @ origin if i == 0 else origin, axis, limits))
            sources.append(src)
            previous = target
        if not chain:
            joints.append(Joint(f"{body_name[b]}/fixed", "fixed", parent, child, frame, _AXES[2]))
        elif previous != child:  # from the last joint's anchor back to the body frame
            joints.append(Joint(f"{body_name[b]}/anchor", "fixed", previous, child,
                                Pose.identity().shifted(-anchor), _AXES[2]))
    return RobotDescription(robot, joints, sources, visuals)


def _body_joints(model, b: int, body: str) -> tuple[Pose, list[tuple], np.ndarray]:
    """(the body frame at qpos0 in its parent, its URDF joints in order, the last joint's anchor in the body).

    MuJoCo moves a body by each of its joints in turn, about the joint's anchor in the body frame; the
    URDF chain reproduces that: parent -> anchor_1 -> motion_1 -> (anchor_2 - anchor_1) -> motion_2 ... ->
    back by -anchor_last to the body frame."""
    import mujoco

    identity = Pose.identity()
    frame = Pose(model.body_pos[b].copy(), model.body_quat[b].copy())
    chain: list[tuple] = []  # (name, kind, axis, origin in the previous link, limits, source)
    anchor = np.zeros(3)
    for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
        jname = _name(model, mujoco.mjtObj.mjOBJ_JOINT, j, body)
        kind, adr = int(model.jnt_type[j]), int(model.jnt_qposadr[j])
        if kind == _FREE:  # the body's world pose is qpos itself
            frame = identity
            chain += _six_dof(jname, _Source("qpos", adr), _Source("euler", adr + 3))
            continue
        step = identity.shifted(model.jnt_pos[j] - anchor)
        anchor = model.jnt_pos[j].astype(float)
        limits = tuple(float(x) for x in model.jnt_range[j]) if model.jnt_limited[j] else None
        axis, q0 = model.jnt_axis[j].astype(float), float(model.qpos0[adr])
        if kind == _HINGE:  # `ref` folded into the origin: the URDF position is qpos, as MuJoCo's
            chain.append((jname, "revolute" if limits else "continuous", axis,
                          step @ Pose(np.zeros(3), _axis_angle(axis, -q0)), limits, _Source("qpos", adr)))
        elif kind == _SLIDE:
            chain.append((jname, "prismatic", axis, step.shifted(-axis * q0), limits, _Source("qpos", adr)))
        else:  # ball: intrinsic rotations about x, y', z'' at the anchor
            chain += [(f"{jname}/r{c}", "continuous", _AXES[i], step if i == 0 else identity, None,
                       _Source("euler", adr, i)) for i, c in enumerate("xyz")]
    mocap = int(model.body_mocapid[b])
    if mocap >= 0:
        frame = identity
        chain += _six_dof(body, _Source("mocap_pos", mocap), _Source("mocap_euler", mocap))
    return frame, chain, anchor


def _six_dof(name: str, position: _Source, rotation: _Source) -> list[tuple]:
    """A free pose as joints: prismatic along the parent's x, y, z, then revolute about x, y', z''."""
    identity = Pose.identity()
    offset = 1 if position.kind == "qpos" else 0  # qpos: one coordinate each; mocap: components of one pose
    return [(f"{name}/{c}", "prismatic", _AXES[i], identity, None,
             _Source(position.kind, position.index + i * offset, i)) for i, c in enumerate("xyz")] + \
        [(f"{name}/r{c}", "continuous", _AXES[i], identity, None, _Source(rotation.kind, rotation.index, i))
         for i, c in enumerate("xyz")]

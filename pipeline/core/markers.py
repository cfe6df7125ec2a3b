"""Shapes to draw on `/markers` (Foxglove SceneUpdate): Foxglove's 3D panel renders them natively, and
`python -m analysis.view` draws them in Rerun. An entity lives in a /tf frame and moves with it; `mujoco_geoms`
draws a generated MuJoCo model from its own geoms."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pipeline.core import schemas


def _color(rgba: Sequence[float]) -> schemas.Color:
    return schemas.Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])


def spheres(frames: Sequence[str], radii: Sequence[float], colors: Sequence[Sequence[float]]) -> list:
    """A sphere of each radius centred on each /tf frame."""
    return [schemas.SceneEntity(
        frame_id=frame, id=frame, frame_locked=True,
        spheres=[schemas.SpherePrimitive(pose=schemas.Pose(orientation=schemas.Quaternion(w=1.0)),
                                         size=schemas.Vector3(x=2 * r, y=2 * r, z=2 * r), color=_color(c))])
        for frame, r, c in zip(frames, radii, colors, strict=True)]


def height_field(name: str, x: np.ndarray, y: np.ndarray, z: np.ndarray, frame: str = "world",
                 color: Sequence[float] = (0.63, 0.63, 0.59, 1.0)):
    """A surface z[i, j] over the grid (x[j], y[i]) as a triangle mesh in `frame`."""
    rows, cols = z.shape
    gx, gy = np.meshgrid(x, y)
    corner = (np.arange(rows - 1)[:, None] * cols + np.arange(cols - 1)[None, :]).ravel()
    triangles = np.concatenate([np.stack([corner, corner + 1, corner + cols], axis=1),
                                np.stack([corner + 1, corner + cols + 1, corner + cols], axis=1)])
    points = [schemas.Point3(x=a, y=b, z=c) for a, b, c in zip(gx.ravel().tolist(), gy.ravel().tolist(),
                                                                z.ravel().tolist(), strict=True)]
    mesh = schemas.TriangleListPrimitive(pose=schemas.Pose(orientation=schemas.Quaternion(w=1.0)), points=points,
                                         color=_color(color), indices=triangles.ravel().tolist())
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, triangles=[mesh])


def _z_onto(direction: np.ndarray) -> schemas.Quaternion:
    """The rotation taking +z onto `direction` (Foxglove cylinders stand along their local z)."""
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    w, (x, y, z) = 1.0 + d[2], np.cross([0.0, 0.0, 1.0], d)
    if w < 1e-12:  # pointing down: half a turn about x
        return schemas.Quaternion(x=1.0, y=0.0, z=0.0, w=0.0)
    n = np.sqrt(w * w + x * x + y * y + z * z)
    return schemas.Quaternion(x=x / n, y=y / n, z=z / n, w=w / n)


def _cylinder(start, end, radius_start: float, radius_end: float, color) -> schemas.CylinderPrimitive:
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    middle, widest = (start + end) / 2, max(radius_start, radius_end)
    return schemas.CylinderPrimitive(
        pose=schemas.Pose(position=schemas.Vector3(x=middle[0], y=middle[1], z=middle[2]),
                          orientation=_z_onto(end - start)),
        size=schemas.Vector3(x=2 * widest, y=2 * widest, z=float(np.linalg.norm(end - start))),
        bottom_scale=radius_start / widest, top_scale=radius_end / widest, color=_color(color))


def capsule(frame: str, name: str, start: Sequence[float], end: Sequence[float], radius: float,
            color: Sequence[float]):
    """A capsule (a cylinder with a sphere at each end) from `start` to `end` in /tf frame `frame`."""
    caps = [schemas.SpherePrimitive(pose=schemas.Pose(position=schemas.Vector3(x=p[0], y=p[1], z=p[2]),
                                                      orientation=schemas.Quaternion(w=1.0)),
                                    size=schemas.Vector3(x=2 * radius, y=2 * radius, z=2 * radius), color=_color(color))
            for p in (start, end)]
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True,
                               cylinders=[_cylinder(start, end, radius, radius, color)], spheres=caps)


def cone(frame: str, name: str, start: Sequence[float], end: Sequence[float], radius_start: float,
         radius_end: float, color: Sequence[float]):
    """A truncated cone from `start` (radius_start) to `end` (radius_end) in /tf frame `frame`."""
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True,
                               cylinders=[_cylinder(start, end, radius_start, radius_end, color)])
def _pose(pos: Sequence[float], quat_wxyz: Sequence[float]):
    return schemas.Pose(position=schemas.Vector3(x=pos[0], y=pos[1], z=pos[2]),
                        orientation=schemas.Quaternion(w=quat_wxyz[0], x=quat_wxyz[1], y=quat_wxyz[2], z=quat_wxyz[3]))


def mujoco_geoms(model, plane_size: float = 4.0) -> list:
    """Every geom of a compiled MuJoCo model, drawn in the /tf frame named as its body (`world` for the world
    body's): boxes as cubes, spheres, cylinders, capsules as a cylinder with two end spheres, planes as a thin
    `plane_size` square slab whose top is the plane. One entity per body; log the bodies' poses on /tf."""
    import mujoco

    entities: dict[int, schemas.SceneEntity] = {}
    box, sphere, cylinder, capsule, plane = (int(k) for k in (
        mujoco.mjtGeom.mjGEOM_BOX, mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CYLINDER,
        mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_PLANE))
    for g in range(model.ngeom):
        body = int(model.geom_bodyid[g])
        frame = "world" if body == 0 else mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
        entity = entities.setdefault(body, schemas.SceneEntity(frame_id=frame, id=f"geoms/{frame}",
                                                               frame_locked=True))
        kind, size, pos, quat = int(model.geom_type[g]), model.geom_size[g], model.geom_pos[g], model.geom_quat[g]
        color = _color(model.geom_rgba[g])
        if kind == box:
            entity.cubes.append(schemas.CubePrimitive(pose=_pose(pos, quat), color=color, size=schemas.Vector3(
                x=2 * size[0], y=2 * size[1], z=2 * size[2])))
        elif kind == sphere:
            d = 2 * size[0]
            entity.spheres.append(schemas.SpherePrimitive(pose=_pose(pos, quat), color=color,
                                                          size=schemas.Vector3(x=d, y=d, z=d)))
        elif kind in (cylinder, capsule):
            d = 2 * size[0]
            entity.cylinders.append(schemas.CylinderPrimitive(pose=_pose(pos, quat), color=color, size=schemas.Vector3(
                x=d, y=d, z=2 * size[1]), bottom_scale=1.0, top_scale=1.0))
            if kind == capsule:
                for sign in (1.0, -1.0):
                    end = pos + sign * size[1] * _z_axis(quat)
                    entity.spheres.append(schemas.SpherePrimitive(pose=_pose(end, quat), color=color,
                                                                  size=schemas.Vector3(x=d, y=d, z=d)))
        elif kind == plane:
            below = pos - 0.001 * _z_axis(quat)
            entity.cubes.append(schemas.CubePrimitive(pose=_pose(below, quat), color=color, size=schemas.Vector3(
                x=plane_size, y=plane_size, z=0.002)))
    return list(entities.values())


def _z_axis(quat_wxyz: Sequence[float]) -> np.ndarray:
    """The local z axis of a unit quaternion's frame."""
    w, x, y, z = quat_wxyz
    return np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
def _pose(position, quat_wxyz) -> schemas.Pose:
    w, x, y, z = (float(v) for v in quat_wxyz)
    return schemas.Pose(position=schemas.Vector3(x=float(position[0]), y=float(position[1]), z=float(position[2])),
                        orientation=schemas.Quaternion(w=w, x=x, y=y, z=z))


def _box(position, rotation, half, color) -> schemas.TriangleListPrimitive:
    """A box as 12 triangles (Foxglove and Rerun both draw triangle lists)."""
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    points = corners @ rotation.T + position
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
             (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return schemas.TriangleListPrimitive(
        pose=schemas.Pose(orientation=schemas.Quaternion(w=1.0)), color=_color(color),
        points=[schemas.Point3(x=a, y=b, z=c) for a, b, c in points.tolist()],
        indices=[i for face in faces for i in face])


def mujoco_bodies(model, bodies: Sequence[str]) -> list:
    """The geoms (spheres, capsules, cylinders, boxes) of the named MuJoCo bodies, one entity per body in the
    /tf frame of the same name, so a run draws the simulated robot as MuJoCo sees it."""
    import mujoco

    sphere, capsule, cylinder, box = (int(t) for t in (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CAPSULE,
                                                        mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_BOX))
    entities = []
    for name in bodies:
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        spheres, cylinders, boxes = [], [], []
        for g in np.flatnonzero(model.geom_bodyid == body):
            kind, size, pos, quat = int(model.geom_type[g]), model.geom_size[g], model.geom_pos[g], model.geom_quat[g]
            color = model.geom_rgba[g]
            if kind == sphere:
                d = 2 * size[0]
                spheres.append(schemas.SpherePrimitive(pose=_pose(pos, quat), size=schemas.Vector3(x=d, y=d, z=d),
                                                       color=_color(color)))
            elif kind in (capsule, cylinder):
                d, length = 2 * size[0], 2 * size[1]
                cylinders.append(schemas.CylinderPrimitive(pose=_pose(pos, quat), bottom_scale=1.0, top_scale=1.0,
                                                           size=schemas.Vector3(x=d, y=d, z=length),
                                                           color=_color(color)))
                if kind == capsule:
                    rotation = np.zeros(9)
                    mujoco.mju_quat2Mat(rotation, quat)
                    axis = rotation.reshape(3, 3)[:, 2] * size[1]
                    spheres += [schemas.SpherePrimitive(pose=_pose(pos + s * axis, quat),
                                                        size=schemas.Vector3(x=d, y=d, z=d), color=_color(color))
                                for s in (-1, 1)]
            elif kind == box:
                rotation = np.zeros(9)
                mujoco.mju_quat2Mat(rotation, quat)
                boxes.append(_box(pos, rotation.reshape(3, 3), size, color))
        entities.append(schemas.SceneEntity(frame_id=name, id=f"{name}/geoms", frame_locked=True, spheres=spheres,
                                            cylinders=cylinders, triangles=boxes))
    return entities

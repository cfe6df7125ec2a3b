"""Shapes to draw on `/markers` (Foxglove SceneUpdate): Foxglove's 3D panel renders them natively, and
`python -m analysis.view` draws them in Rerun. An entity lives in a /tf frame and moves with it; `from_mujoco`
turns a generated MJCF's geoms into entities in its bodies' frames."""

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


def from_mujoco(model, world_frame: str = "world") -> list:
    """The boxes, cylinders, spheres and capsules of a MuJoCo model, one entity per body, each in the /tf frame
    named like its body (world geoms in `world_frame`): a generated MJCF then draws in Foxglove as in MuJoCo."""
    import mujoco

    geom = mujoco.mjtGeom
    entities: dict[int, schemas.SceneEntity] = {}
    for g in range(model.ngeom):
        body = int(model.geom_bodyid[g])
        name = world_frame if body == 0 else model.body(body).name
        entity = entities.setdefault(body, schemas.SceneEntity(frame_id=name, id=name, frame_locked=True))
        w, x, y, z = (float(v) for v in model.geom_quat[g])
        pose = schemas.Pose(position=schemas.Vector3(**dict(zip("xyz", map(float, model.geom_pos[g]), strict=True))),
                            orientation=schemas.Quaternion(w=w, x=x, y=y, z=z))
        size, color, kind = model.geom_size[g], _color(model.geom_rgba[g]), int(model.geom_type[g])
        if kind == geom.mjGEOM_BOX:
            entity.cubes.append(schemas.CubePrimitive(pose=pose, color=color, size=schemas.Vector3(
                x=2 * size[0], y=2 * size[1], z=2 * size[2])))
        elif kind == geom.mjGEOM_SPHERE:
            d = 2 * float(size[0])
            entity.spheres.append(schemas.SpherePrimitive(pose=pose, color=color, size=schemas.Vector3(x=d, y=d, z=d)))
        elif kind in (geom.mjGEOM_CYLINDER, geom.mjGEOM_CAPSULE):
            d, length = 2 * float(size[0]), 2 * float(size[1])
            entity.cylinders.append(schemas.CylinderPrimitive(pose=pose, color=color, bottom_scale=1, top_scale=1,
                                                              size=schemas.Vector3(x=d, y=d, z=length)))
            if kind == geom.mjGEOM_CAPSULE:   # the two end caps, along the geom's z
                axis = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)]) * size[1]
                for end in (model.geom_pos[g] + axis, model.geom_pos[g] - axis):
                    entity.spheres.append(schemas.SpherePrimitive(
                        pose=schemas.Pose(position=schemas.Vector3(x=end[0], y=end[1], z=end[2]),
                                          orientation=schemas.Quaternion(w=1.0)),
                        color=color, size=schemas.Vector3(x=d, y=d, z=d)))
    return list(entities.values())

"""Shapes to draw on `/markers` (Foxglove SceneUpdate): Foxglove's 3D panel renders them natively, and
`python -m analysis.view` draws them in Rerun. An entity lives in a /tf frame and moves with it."""

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

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


def _along(a: np.ndarray, b: np.ndarray) -> schemas.Pose:
    """Pose of a cylinder from a to b: its centre at the midpoint, its z axis (Foxglove's cylinder axis) along b − a."""
    d = b - a
    z = d / np.linalg.norm(d)
    axis = np.cross([0.0, 0.0, 1.0], z)
    s, c = np.linalg.norm(axis), float(z[2])
    half = np.arctan2(s, c) / 2
    axis = axis / s if s > 1e-12 else np.array([1.0, 0.0, 0.0])
    q = np.concatenate([[np.cos(half)], np.sin(half) * axis])
    mid = (a + b) / 2
    return schemas.Pose(position=schemas.Vector3(x=mid[0], y=mid[1], z=mid[2]),
                        orientation=schemas.Quaternion(w=q[0], x=q[1], y=q[2], z=q[3]))


def rods(name: str, frame: str, segments: Sequence[tuple[Sequence[float], Sequence[float]]], radius: float,
         color: Sequence[float]):
    """Cylinders of one radius joining each (start, end) pair of points given in `frame`: the links of a
    linkage drawn in their own /tf frames."""
    cylinders = []
    for a, b in segments:
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        length = float(np.linalg.norm(b - a))
        cylinders.append(schemas.CylinderPrimitive(pose=_along(a, b), color=_color(color),
                                                   size=schemas.Vector3(x=2 * radius, y=2 * radius, z=length)))
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, cylinders=cylinders)


def line_strip(name: str, points: np.ndarray, frame: str = "world", thickness: float = 0.005,
               color: Sequence[float] = (0.2, 0.2, 0.2, 1.0)):
    """A polyline through `points` (N, 3) in `frame` (a path: of a tracer point, a foot, an end effector)."""
    line = schemas.LinePrimitive(type=schemas.LinePrimitive.LINE_STRIP, thickness=thickness, color=_color(color),
                                 pose=schemas.Pose(orientation=schemas.Quaternion(w=1.0)),
                                 points=[schemas.Point3(x=x, y=y, z=z) for x, y, z in np.asarray(points).tolist()])
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, lines=[line])


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

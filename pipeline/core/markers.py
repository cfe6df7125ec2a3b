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


def box(name: str, centre: Sequence[float], size: Sequence[float], color: Sequence[float], frame: str = "world"):
    """An axis-aligned box of edge lengths `size` centred at `centre` in `frame`."""
    pose = schemas.Pose(position=schemas.Vector3(x=centre[0], y=centre[1], z=centre[2]),
                        orientation=schemas.Quaternion(w=1.0))
    cube = schemas.CubePrimitive(pose=pose, size=schemas.Vector3(x=size[0], y=size[1], z=size[2]), color=_color(color))
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, cubes=[cube])


def line_strip(name: str, points: np.ndarray, color: Sequence[float], thickness: float = 0.005,
               frame: str = "world"):
    """A polyline through `points` (k, 3) in `frame`, `thickness` in m."""
    line = schemas.LinePrimitive(type=schemas.LinePrimitive.LINE_STRIP, pose=schemas.Pose(
        orientation=schemas.Quaternion(w=1.0)), thickness=thickness, scale_invariant=False,
        points=[schemas.Point3(x=a, y=b, z=c) for a, b, c in np.asarray(points, dtype=float).tolist()],
        color=_color(color))
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

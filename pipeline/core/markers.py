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


def arrow(name: str, frame: str, vector: Sequence[float], color: Sequence[float], scale: float = 1.0,
          diameter: float = 0.004) -> schemas.SceneEntity:
    """An arrow from the origin of /tf frame `frame` along `vector` (in that frame) times `scale` (a force in
    N drawn at `scale` m/N): Foxglove's ArrowPrimitive points along +x of its pose, so the pose turns x onto it."""
    v = np.asarray(vector, dtype=float) * scale
    length = float(np.linalg.norm(v))
    x = np.array([1.0, 0.0, 0.0])
    axis = np.cross(x, v / length) if length > 0 else np.zeros(3)
    sin, cos = float(np.linalg.norm(axis)), float(x @ v / length) if length > 0 else 1.0
    half = 0.5 * np.arctan2(sin, cos)
    axis = axis / sin if sin > 1e-12 else np.array([0.0, 0.0, 1.0])
    q = schemas.Quaternion(w=np.cos(half), x=axis[0] * np.sin(half), y=axis[1] * np.sin(half),
                           z=axis[2] * np.sin(half))
    head = min(0.3 * length, 4 * diameter)
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, arrows=[schemas.ArrowPrimitive(
        pose=schemas.Pose(orientation=q), shaft_length=length - head, shaft_diameter=diameter,
        head_length=head, head_diameter=2.5 * diameter, color=_color(color))])

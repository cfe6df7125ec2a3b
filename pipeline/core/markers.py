"""Shapes to draw on `/markers` (Foxglove SceneUpdate): Foxglove's 3D panel renders them natively, and
`python -m analysis.view` draws them in Rerun. An entity lives in a /tf frame and moves with it: spheres on
frames, cones between points, arrows (forces), contact points with their force arrows, line strips (paths) and
height fields (terrain). A robot itself is drawn from its URDF (pipeline.core.robot), not from markers."""

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


def _pose(position: Sequence[float], quat_wxyz: Sequence[float] = (1.0, 0.0, 0.0, 0.0)) -> schemas.Pose:
    w, x, y, z = (float(v) for v in quat_wxyz)
    return schemas.Pose(position=schemas.Vector3(x=float(position[0]), y=float(position[1]), z=float(position[2])),
                        orientation=schemas.Quaternion(w=w, x=x, y=y, z=z))


def _onto(axis: Sequence[float], direction: Sequence[float]) -> tuple[float, float, float, float]:
    """The shortest rotation (w, x, y, z) taking the unit `axis` onto `direction` (Foxglove cylinders stand along
    their local z, arrows along their local x); the identity for a zero direction."""
    a, d = np.asarray(axis, dtype=float), np.asarray(direction, dtype=float)
    length = np.linalg.norm(d)
    if length == 0:
        return 1.0, 0.0, 0.0, 0.0
    w, (x, y, z) = 1.0 + a @ d / length, np.cross(a, d / length)
    if w < 1e-12:  # opposite: half a turn about any axis perpendicular to `axis`
        x, y, z = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        w = 0.0
    n = np.sqrt(w * w + x * x + y * y + z * z)
    return w / n, x / n, y / n, z / n


def _cylinder(start, end, radius_start: float, radius_end: float, color) -> schemas.CylinderPrimitive:
    """A cylinder (or truncated cone) from `start` to `end`; Foxglove scales its end faces from the widest."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    widest = max(radius_start, radius_end)
    return schemas.CylinderPrimitive(
        pose=_pose((start + end) / 2, _onto((0.0, 0.0, 1.0), end - start)), color=_color(color),
        size=schemas.Vector3(x=2 * widest, y=2 * widest, z=float(np.linalg.norm(end - start))),
        bottom_scale=radius_start / widest, top_scale=radius_end / widest)


def _ball(centre, radius: float, color) -> schemas.SpherePrimitive:
    d = 2 * radius
    return schemas.SpherePrimitive(pose=_pose(centre), size=schemas.Vector3(x=d, y=d, z=d), color=_color(color))


def cone(name: str, frame: str, start: Sequence[float], end: Sequence[float], radius_start: float,
         radius_end: float, color: Sequence[float]):
    """A truncated cone from `start` (radius_start) to `end` (radius_end) in /tf frame `frame`."""
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True,
                               cylinders=[_cylinder(start, end, radius_start, radius_end, color)])


def line_strip(name: str, points: np.ndarray, frame: str = "world", thickness: float = 0.005,
               color: Sequence[float] = (0.2, 0.2, 0.2, 1.0)):
    """A polyline through `points` (N, 3) in `frame` (a path: of a tracer point, a foot, an end effector)."""
    line = schemas.LinePrimitive(type=schemas.LinePrimitive.LINE_STRIP, thickness=thickness, color=_color(color),
                                 pose=_pose((0.0, 0.0, 0.0)),
                                 points=[schemas.Point3(x=x, y=y, z=z) for x, y, z in np.asarray(points).tolist()])
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, lines=[line])


def _arrow(origin, vector, color, diameter: float) -> schemas.ArrowPrimitive:
    """Foxglove's ArrowPrimitive points along +x of its pose, so the pose turns x onto `vector`."""
    length = float(np.linalg.norm(vector))
    head = min(0.3 * length, 4 * diameter)
    return schemas.ArrowPrimitive(pose=_pose(origin, _onto((1.0, 0.0, 0.0), vector)), shaft_length=length - head,
                                  shaft_diameter=diameter, head_length=head, head_diameter=2.5 * diameter,
                                  color=_color(color))


def arrow(name: str, frame: str, vector: Sequence[float], color: Sequence[float], scale: float = 1.0,
          diameter: float = 0.004) -> schemas.SceneEntity:
    """An arrow from the origin of /tf frame `frame` along `vector` (in that frame) times `scale` (a force in
    N drawn at `scale` m/N)."""
    return schemas.SceneEntity(frame_id=frame, id=name, frame_locked=True, arrows=[
        _arrow((0.0, 0.0, 0.0), np.asarray(vector, dtype=float) * scale, color, diameter)])


CONTACT_RGBA = (0.9, 0.1, 0.1, 1.0)


def contacts(name: str, points: np.ndarray, forces: np.ndarray, scale: float, frame: str = "world",
             color: Sequence[float] = CONTACT_RGBA, diameter: float = 0.004) -> schemas.SceneEntity:
    """Contact points (c, 3) in `frame` as small balls, each with its force (c, 3; N) as an arrow from the
    point, drawn at `scale` m/N (said in the entity's metadata, `force_scale`). No contact (c = 0) gives an
    empty entity: logged under the same `name`, it replaces the previous instant's contacts."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    forces = np.asarray(forces, dtype=float).reshape(-1, 3) * scale
    return schemas.SceneEntity(
        frame_id=frame, id=name, frame_locked=True,
        metadata=[schemas.KeyValuePair(key="force_scale", value=f"{scale:g} m/N")],
        spheres=[_ball(p, diameter, color) for p in points],
        arrows=[_arrow(p, f, color, diameter) for p, f in zip(points, forces, strict=True) if f.any()])


def _cube(centre, quat_wxyz, size: Sequence[float], color) -> schemas.CubePrimitive:
    return schemas.CubePrimitive(pose=_pose(centre, quat_wxyz), color=_color(color),
                                 size=schemas.Vector3(x=float(size[0]), y=float(size[1]), z=float(size[2])))


def _z_axis(quat_wxyz: Sequence[float]) -> np.ndarray:
    """The local z axis of a unit quaternion's frame."""
    w, x, y, z = quat_wxyz
    return np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])


def mujoco_geoms(model, bodies: Sequence[str] | None = None, plane_size: float = 4.0) -> list:
    """The geoms of a compiled MuJoCo model (of the named `bodies` only, if given), one entity per body in the /tf
    frame named as the body (`world` for the world body's): boxes as cubes, spheres, cylinders, capsules as a
    cylinder with two end spheres, planes as a thin `plane_size` square slab whose top is the plane. Log the
    bodies' poses on /tf under the same names."""
    import mujoco

    box, sphere, cylinder, capsule_, plane = (int(k) for k in (
        mujoco.mjtGeom.mjGEOM_BOX, mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CYLINDER,
        mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_PLANE))
    wanted = None if bodies is None else {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in bodies}
    entities: dict[int, schemas.SceneEntity] = {}
    for g in range(model.ngeom):
        body = int(model.geom_bodyid[g])
        if wanted is not None and body not in wanted:
            continue
        frame = "world" if body == 0 else mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
        entity = entities.setdefault(body, schemas.SceneEntity(frame_id=frame, id=f"geoms/{frame}",
                                                               frame_locked=True))
        kind, size, pos, quat = int(model.geom_type[g]), model.geom_size[g], model.geom_pos[g], model.geom_quat[g]
        color = model.geom_rgba[g]
        if kind == box:
            entity.cubes.append(_cube(pos, quat, 2 * size, color))
        elif kind == sphere:
            entity.spheres.append(_ball(pos, size[0], color))
        elif kind in (cylinder, capsule_):
            half = size[1] * _z_axis(quat)
            entity.cylinders.append(_cylinder(pos - half, pos + half, size[0], size[0], color))
            if kind == capsule_:
                entity.spheres.extend(_ball(end, size[0], color) for end in (pos - half, pos + half))
        elif kind == plane:
            entity.cubes.append(_cube(pos - 0.001 * _z_axis(quat), quat, (plane_size, plane_size, 0.002), color))
    return list(entities.values())

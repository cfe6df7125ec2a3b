"""Collision checks of the arm's links against box obstacles (Sec. 3.4).

- `planar_clearance`: the planar 2R in closed form, from the stored critical points of a configuration (the
  KG's vertices keep them, so no FK is needed online): capsule links against axis-aligned rectangles.
- `MujocoChecker`: any arm in MuJoCo (the spatial scenes): the arm's capsules against the obstacle geoms by
  `mj_collision`, and exact distances by `mj_geomDistance`.

Both answer `blocked(graph, margin)` (the vertices a scene removes from the graph: "the obstacle is mapped
entirely into the KG", Fig. 5), `min_clearance(qs)` and `clearance(qs)` (per obstacle).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Boxes:
    """Axis-aligned boxes: centres and half sizes (K, 3), m."""

    centre: np.ndarray
    half: np.ndarray
    names: tuple[str, ...]

    @classmethod
    def from_config(cls, node: Mapping | None) -> Boxes:
        """From {names: [...], centre: [[x, y, z], ...], half: [[hx, hy, hz], ...]} (m); None: no obstacle."""
        if not node:
            return cls(np.zeros((0, 3)), np.zeros((0, 3)), ())
        centre = np.asarray(node["centre"], dtype=float).reshape(-1, 3)
        half = np.asarray(node["half"], dtype=float).reshape(-1, 3)
        names = tuple(str(n) for n in node["names"])
        if not len(names) == len(centre) == len(half):
            raise ValueError(f"obstacles: {len(names)} names, {len(centre)} centres and {len(half)} half sizes")
        return cls(centre, half, names)

    @classmethod
    def none(cls) -> Boxes:
        return cls.from_config(None)

    def __len__(self) -> int:
        return len(self.names)


def _point_box_distance(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(...,) distance of points (..., 2) to the rectangle [lo, hi] (0 inside)."""
    return np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0), axis=-1)


def _segment_point_distance(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    d = b - a
    t = np.clip(np.einsum("...i,...i->...", p - a, d) / np.maximum(np.einsum("...i,...i->...", d, d), 1e-300), 0, 1)
    return np.linalg.norm(a + t[..., None] * d - p, axis=-1)


def _segment_hits_box(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Liang-Barsky: does the segment a-b (..., 2) meet the rectangle [lo, hi]?"""
    d = b - a
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo - a) / d, (hi - a) / d
    near = np.where(d == 0, np.where((a >= lo) & (a <= hi), -np.inf, np.inf), np.minimum(t1, t2))
    far = np.where(d == 0, np.where((a >= lo) & (a <= hi), np.inf, -np.inf), np.maximum(t1, t2))
    enter, leave = np.maximum(near.max(axis=-1), 0.0), np.minimum(far.min(axis=-1), 1.0)
    return enter <= leave


def planar_clearance(points: np.ndarray, boxes: Boxes, link_radius: float) -> np.ndarray:
    """(N, K) clearance (m) of the planar arm to each box: the smallest distance from any link capsule (segments
    between consecutive critical points, radius `link_radius`) to the box's rectangle in the plane; < 0
    penetrates. `points` (N, m, 2 or 3) are the critical points (arms.RegionalArm.points)."""
    p = np.asarray(points, dtype=float)[..., :2]
    a, b = p[:, :-1], p[:, 1:]                                   # (N, links, 2)
    out = np.empty((len(p), len(boxes)))
    corners_unit = np.array([[-1, -1], [-1, 1], [1, -1], [1, 1]], dtype=float)
    for k in range(len(boxes)):
        lo, hi = boxes.centre[k, :2] - boxes.half[k, :2], boxes.centre[k, :2] + boxes.half[k, :2]
        # convex shapes apart: the closest pair has a vertex of one of them
        ends = np.minimum(_point_box_distance(a, lo, hi), _point_box_distance(b, lo, hi))
        corners = boxes.centre[k, :2] + corners_unit * boxes.half[k, :2]
        to_corners = np.min([_segment_point_distance(a, b, c) for c in corners], axis=0)
        distance = np.where(_segment_hits_box(a, b, lo, hi), 0.0, np.minimum(ends, to_corners))
        out[:, k] = distance.min(axis=1) - link_radius
    return out


class PlanarChecker:
    """Closed-form checks of a planar arm: online from stored critical points (a KG vertex's, no FK), or from
    configurations (FK first)."""

    def __init__(self, arm, boxes: Boxes):
        self.arm, self.boxes = arm, boxes
        self.obstacle_names = list(boxes.names)

    def blocked(self, graph, margin: float) -> np.ndarray:
        """(V,) vertices whose stored critical points come closer than `margin` to an obstacle (Sec. 3.4)."""
        if not len(self.boxes):
            return np.zeros(graph.size, dtype=bool)
        return planar_clearance(graph.points, self.boxes, self.arm.link_radius).min(axis=1) < margin

    def clearance(self, qs: np.ndarray) -> np.ndarray:
        return planar_clearance(self.arm.points(np.asarray(qs, dtype=float)), self.boxes, self.arm.link_radius)

    def min_clearance(self, qs: np.ndarray, distmax: float = np.inf) -> np.ndarray:
        if not len(self.boxes):
            return np.full(len(qs), float(distmax))
        return np.minimum(self.clearance(qs).min(axis=1), distmax)


class MujocoChecker:
    """Collision queries on a generated MuJoCo model: the arm geoms (bodies `link<i>`, i in `checked_links`)
    against the obstacle geoms (named `obstacle/<name>`); only those pairs collide."""

    def __init__(self, xml: str, checked_links: Sequence[int]):
        import mujoco

        self._mj = mujoco
        self.model = m = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(m)
        names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) or "" for g in range(m.ngeom)]
        self.obstacles = np.array([g for g in range(m.ngeom) if names[g].startswith("obstacle/")], dtype=int)
        wanted = {f"link{i}" for i in checked_links}
        self.links = np.array([g for g in range(m.ngeom)
                               if mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g])) in wanted],
                              dtype=int)
        # links: contype 1, conaffinity 0; obstacles: 0, 1. Links never touch links, obstacles never obstacles.
        m.geom_contype[:] = 0
        m.geom_conaffinity[:] = 0
        m.geom_contype[self.links] = 1
        m.geom_conaffinity[self.obstacles] = 1
        for array, geoms in ((m.body_contype, self.links), (m.body_conaffinity, self.obstacles)):  # broad phase
            array[:] = 0
            array[m.geom_bodyid[geoms]] = 1
        self.obstacle_names = [names[g].removeprefix("obstacle/") for g in self.obstacles]

    def blocked(self, graph, margin: float) -> np.ndarray:
        """(V,) vertices whose configuration C.q comes closer than `margin` to an obstacle (MuJoCo does the FK)."""
        return self.min_clearance(graph.q, margin) < margin

    def min_clearance(self, qs: np.ndarray, distmax: float = 0.0) -> np.ndarray:
        """(N,) smallest signed distance (m) between a checked link and an obstacle over configurations
        (N, ≤ nq), from `mj_collision` with the obstacles' margin at `distmax`; distmax where none is closer."""
        m, d = self.model, self.data
        m.geom_margin[self.obstacles] = distmax
        kinematics, collision = self._mj.mj_kinematics, self._mj.mj_collision
        out = np.full(len(qs), float(distmax))
        for i, q in enumerate(np.asarray(qs, dtype=float)):
            d.qpos[: len(q)] = q
            kinematics(m, d)
            collision(m, d)
            if d.ncon:
                out[i] = min(float(d.contact.dist[: d.ncon].min()), distmax)
        return out

    def clearance(self, qs: np.ndarray, distmax: float = 1.0) -> np.ndarray:
        """(N, K) signed distance (m) of the nearest checked link to each obstacle, by `mj_geomDistance`."""
        out = np.empty((len(qs), len(self.obstacles)))
        m, d = self.model, self.data
        geom_distance, fromto = self._mj.mj_geomDistance, np.zeros(6)
        for i, q in enumerate(np.asarray(qs, dtype=float)):
            d.qpos[: len(q)] = q
            self._mj.mj_kinematics(m, d)
            for k, o in enumerate(self.obstacles):
                out[i, k] = min(geom_distance(m, d, int(g), int(o), distmax, fromto) for g in self.links)
        return out

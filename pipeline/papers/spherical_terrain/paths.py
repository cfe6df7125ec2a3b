"""The desired paths of Sec. 6, projected on the terrain: z_d = f(x_d, y_d), ż_d = f_x ẋ_d + f_y ẏ_d."""

from __future__ import annotations

import numpy as np


def circle(t: np.ndarray, radius: float = 2.0, rate: float = 0.05, form: str = "corrected"):
    """eq. (60): x = r cos(ωt), y = r sin(ωt). As printed, y = r cos(ωt) (a segment of the line y = x,
    traversed back and forth; erratum 2). Returns (xy, xy_dot), each (N, 2)."""
    t = np.asarray(t, dtype=float)
    c, s = np.cos(rate * t), np.sin(rate * t)
    if form == "corrected":
        return radius * np.column_stack([c, s]), radius * rate * np.column_stack([-s, c])
    if form == "printed":  # eq. (60) as printed
        return radius * np.column_stack([c, c]), radius * rate * np.column_stack([-s, -s])
    raise ValueError(f"eq60 form {form!r}: corrected | printed")


def diamond_vertices(diagonal: float) -> np.ndarray:
    """Assumption (the paper gives only the 4 m diagonals): vertices on the axes, counter-clockwise from
    (+d/2, 0) like the circle."""
    h = diagonal / 2.0
    return np.array([[h, 0.0], [0.0, h], [-h, 0.0], [0.0, -h]])


def diamond(t: np.ndarray, diagonal: float = 4.0, speed: float = 0.1):
    """Diamond with sharp vertices and straight edges (Sec. 6), constant planar speed. (xy, xy_dot)."""
    t = np.asarray(t, dtype=float)
    vertices = diamond_vertices(diagonal)
    edges = np.roll(vertices, -1, axis=0) - vertices
    edge_length = float(np.linalg.norm(edges[0]))
    s = np.mod(speed * t, 4 * edge_length)
    k = np.minimum((s // edge_length).astype(int), 3)  # at a vertex the outgoing edge is used
    frac = (s - k * edge_length) / edge_length
    return vertices[k] + frac[:, None] * edges[k], edges[k] * (speed / edge_length)


def vertex_times(duration: float, diagonal: float = 4.0, speed: float = 0.1) -> np.ndarray:
    """Times at which the diamond's target passes a vertex, 0 ≤ t ≤ duration."""
    edge_length = diagonal / np.sqrt(2.0)
    return np.arange(0.0, duration + 1e-9, edge_length / speed)


def on_surface(terrain, xy: np.ndarray, xy_dot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lift a planar path onto z = f(x, y): (p_d, ṗ_d), each (N, 3)."""
    fx, fy = terrain.gradient(xy[:, 0], xy[:, 1])
    z = terrain.height(xy[:, 0], xy[:, 1])
    z_dot = fx * xy_dot[:, 0] + fy * xy_dot[:, 1]
    return np.column_stack([xy, z]), np.column_stack([xy_dot, z_dot])


def reference(terrain, name: str, t: np.ndarray, paths_cfg, circle_form: str = "corrected"):
    """(p_d, ṗ_d) of path `name` ('circle' | 'diamond') with the parameters of `paths_cfg` (system.paths)."""
    if name == "circle":
        c = paths_cfg.circle
        xy, xy_dot = circle(t, c.radius, c.rate, circle_form)
    elif name == "diamond":
        d = paths_cfg.diamond
        xy, xy_dot = diamond(t, d.diagonal, d.speed)
    else:
        raise ValueError(f"unknown path {name!r}: circle | diamond")
    return on_surface(terrain, xy, xy_dot)

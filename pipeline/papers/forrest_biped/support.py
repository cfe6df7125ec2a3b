"""The support polygon of every controller cycle and the projection of a ZMP into it (the clamp of eq. 50)."""

from __future__ import annotations

import numpy as np

from pipeline.papers.forrest_biped.generator import DOUBLE, LEFT, Pattern

Polygon = tuple[np.ndarray, np.ndarray]     # half-planes A p ≤ b, rows of A unit normals


def support_polygons(pattern: Pattern, half: tuple[float, float], margin: float) -> list[Polygon]:
    """Half-planes (A, b) with A p ≤ b of the support polygon at every cycle: the stance foot's plate, or the
    convex hull of both plates in double support, `margin` inside; from the planned footholds."""
    from scipy.spatial import ConvexHull

    hx, hy = half[0] - margin, half[1] - margin
    box = np.array([[hx, hy], [hx, -hy], [-hx, hy], [-hx, -hy]])
    cache: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
    out = []
    for i, state in enumerate(pattern.support):
        feet = [f for f in (0, 1) if state == DOUBLE or (state == LEFT) == (f == 0)]
        key = (int(state), *(tuple(np.round(pattern.feet[f, i, :2], 9)) for f in feet))
        if key not in cache:
            points = np.vstack([pattern.feet[f, i, :2] + box for f in feet])
            eq = ConvexHull(points).equations
            cache[key] = (eq[:, :2], -eq[:, 2])
        out.append(cache[key])
    return out


def clamp(p: np.ndarray, polygon: Polygon) -> np.ndarray:
    """p (x, y) projected into the convex polygon: onto the most violated edge, in turn (a vertex takes two)."""
    A, b = polygon
    q = np.array(p, dtype=float)
    for _ in range(4):
        out = A @ q - b
        j = int(out.argmax())
        if out[j] <= 1e-12:
            break
        q -= out[j] * A[j]
    return q

"""Burmester theory of a moving plane in precision positions (Sec. 2.10), written without cofactors, so it
checks the compatibility method independently.

Position j of the plane maps a point m, given by its offset from the precision point in position 1, to
P_j + e^{iα_j} m. A centre point C is the centre of a circle through the positions of one plane point
(a ground pivot); that point is a circle point (a moving pivot).
"""

from __future__ import annotations

import itertools

import numpy as np

from pipeline.papers.dyad_triad_synthesis.standard_form import turns


def pole(points, alpha, j: int, k: int) -> complex:
    """P_jk (1-based): the fixed point of the displacement from position j to position k."""
    p, a = np.asarray(points, dtype=complex), np.asarray(alpha, dtype=float)
    rot = np.exp(1j * (a[k - 1] - a[j - 1]))
    return complex((p[k - 1] - rot * p[j - 1]) / (1 - rot))


def image_pole(points, alpha, j: int, k: int) -> complex:
    """P'_jk: the plane point that lies on P_jk in position j, shown where it is in position 1."""
    p, a = np.asarray(points, dtype=complex), np.asarray(alpha, dtype=float)
    return complex(p[0] + np.exp(1j * (a[0] - a[j - 1])) * (pole(points, alpha, j, k) - p[j - 1]))


def poles(points, alpha) -> dict[str, complex]:
    n = len(points)
    return {f"P{j}{k}": pole(points, alpha, j, k) for j, k in itertools.combinations(range(1, n + 1), 2)}


def image_poles(points, alpha) -> dict[str, complex]:
    n = len(points)
    return {f"P'{j}{k}": image_pole(points, alpha, j, k) for j, k in itertools.combinations(range(2, n + 1), 2)}


def _line_intersection(a: complex, b: complex, c: complex, d: complex) -> complex:
    """Intersection of line ab with line cd; NaN if they are parallel (or the same line)."""
    u, v = b - a, d - c
    cross = (u.conjugate() * v).imag
    if abs(cross) < 1e-12 * abs(u) * abs(v):
        return complex(np.nan, np.nan)
    return a + u * ((c - a).conjugate() * v).imag / cross


# Eq. (23) with its misprint corrected: Π12 = P13P23 × P14P24 (printed: P13P23 × P13P23, one line twice).
PI_LINES = {"Π12": ("P13", "P23", "P14", "P24"), "Π13": ("P12", "P23", "P14", "P34"),
            "Π14": ("P12", "P24", "P13", "P34"), "Π23": ("P12", "P13", "P24", "P34"),
            "Π24": ("P12", "P14", "P23", "P34"), "Π34": ("P13", "P14", "P23", "P24")}
PI_LINES_PRINTED = {**PI_LINES, "Π12": ("P13", "P23", "P13", "P23")}
# Eq. (24): the image Π-points, with the image poles of positions 2-4
PI_IMAGE_LINES = {"Π'12": ("P13", "P'23", "P14", "P'24"), "Π'13": ("P12", "P'23", "P14", "P'34"),
                  "Π'14": ("P12", "P'24", "P13", "P'34"), "Π'23": ("P12", "P13", "P'24", "P'34"),
                  "Π'24": ("P12", "P14", "P'23", "P'34"), "Π'34": ("P13", "P14", "P'23", "P'24")}


def pi_points(points, alpha, lines: dict[str, tuple[str, str, str, str]] = PI_LINES) -> dict[str, complex]:
    """Opposite-pole-quadrilateral points of four positions (eqs. 23, 24)."""
    named = poles(points[:4], alpha[:4]) | image_poles(points[:4], alpha[:4])
    return {name: _line_intersection(*(named[x] for x in ends)) for name, ends in lines.items()}


def center_point_condition(points, alpha, c) -> np.ndarray:
    """A cubic that vanishes exactly on the centre-point curve of four positions: the 3×3 consistency
    determinant of |P_j + e^{iα_j} m − C|² = |P_1 + m − C|², j = 2..4, which is linear in m; divided by
    (size of the positions + distance of C from them)⁴, so it is dimensionless (0 at a pole, where a row
    vanishes)."""
    p, a = np.asarray(points[:4], dtype=complex), np.asarray(alpha[:4], dtype=float)
    c = np.asarray(c, dtype=complex)[..., None]
    u = np.conj(p[1:] - c) * np.exp(1j * a[1:]) - np.conj(p[0] - c)                  # (…, 3)
    rhs = np.abs(p[0] - c) ** 2 - np.abs(p[1:] - c) ** 2
    rows = np.stack([2 * u.real, -2 * u.imag, rhs], axis=-1)                          # (…, 3, 3)
    size = np.abs(p - p.mean()).max() + np.abs(c[..., 0] - p.mean())
    return np.linalg.det(rows) / size ** 4


def circle_point_condition(points, alpha, m1) -> np.ndarray:
    """Vanishes exactly on the circle-point curve of four positions: the concyclicity determinant of the four
    positions z_j of the plane point that is at m1 in position 1 (rows |z|², x, y, 1), divided by their
    size⁴ (0 where two positions coincide, as at a pole: three points always lie on a circle)."""
    p, a = np.asarray(points[:4], dtype=complex), np.asarray(alpha[:4], dtype=float)
    z = p + turns(a - a[0]) * (np.asarray(m1, dtype=complex)[..., None] - p[0])       # (…, 4)
    z = z - z.mean(axis=-1, keepdims=True)
    rows = np.stack([np.abs(z) ** 2, z.real, z.imag, np.ones_like(z.real)], axis=-1)   # (…, 4, 4)
    size = np.abs(z).max(axis=-1) + np.abs(p - p.mean()).max()
    return np.linalg.det(rows) / size ** 4


def _circle_residuals(x: np.ndarray, p: np.ndarray, rot: np.ndarray, scale: float) -> np.ndarray:
    m, c = complex(x[0], x[1]), complex(x[2], x[3])
    d = np.abs(p + rot * m - c) ** 2
    return (d[1:] - d[0]) / scale ** 2


def least_squares_dyads(points, alpha, starts: int, rng: np.random.Generator, box: float = 10.0,
                        same: float = 1e-6) -> list[tuple[complex, complex]]:
    """Finite dyads (W, Z) of five positions solved directly from the circle-point condition (|P_j +
    e^{iα_j} m − C| equal for all j) by least squares from random starts in a box `box` times the size of the
    precision points around their centre; distinct converged solutions only."""
    from scipy.optimize import least_squares  # 0.3 s to import: only this solver needs it

    p, rot = np.asarray(points, dtype=complex), turns(np.asarray(alpha, dtype=float) - alpha[0])
    centre = p.mean()
    scale = max(float(np.abs(p - centre).max()), 1e-9)
    found: list[tuple[complex, complex]] = []
    for x0 in rng.uniform(-box, box, (starts, 4)) * scale + [centre.real, centre.imag] * 2:
        sol = least_squares(_circle_residuals, x0, args=(p, rot, scale), xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            method="lm")
        m, c = complex(sol.x[0], sol.x[1]), complex(sol.x[2], sol.x[3])
        if np.abs(sol.fun).max() > 1e-12 or abs(m) > 1e3 * box * scale:
            continue
        z, w = -m, (p[0] + m) - c                                  # Z: pivot -> point; W: ground -> pivot
        if all(abs(z - z0) + abs(w - w0) > same * scale for w0, z0 in found):
            found.append((w, z))
    return found

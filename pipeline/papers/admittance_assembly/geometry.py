"""Square peg in a square hole, frictionless and rigid: poses, contact candidates, unit contact wrenches,
the error line vector d, and the chart of the two-point contact state (spec §3, §6).

Frames (SI): the world origin is the centre of the hole entrance, z up; the hole is |x| < Bx, |y| < By,
z < 0 (B = b + clearance, b the peg half-width). The body frame is the peg's: z along its axis, origin on
the axis `ref_height` above the tip centre; the admittance A, twists v = [v_o; ω] (v_o the velocity of the
body origin) and wrenches w = [f; m] (m about the body origin) are all expressed in it (paper eq. 1:
"w ... measured in the body frame"). The selected point of the error measure is on the axis
`selected_height` above the tip centre (default: the tip centre); it is mated when the peg is upright and
its tip centre at (0, 0, -depth).

The planar case is the x-z section: the peg moves in (x, z, rotation about y); its twists keep the
components `PLANAR_DOFS` = (v_x, v_z, ω_y) of the spatial ones, so one code path serves both.

Candidate contacts (every single-point principal contact the insertion can meet):
  - a tip vertex of the peg on a hole wall (vertex-face);
  - planar: a rim corner of the hole on a side face of the peg (face-vertex);
  - spatial: a vertical edge of the peg across a rim edge of the hole (edge-edge). With clearance, the
    rim's corners lie outside the peg's faces, so the rim touches the peg only across its edges.
Each gives a signed gap (> 0 apart), the contact point and the unit normal pointing into the peg.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

PLANAR_DOFS = np.array([0, 2, 4])
SPATIAL_DOFS = np.arange(6)
TRANSLATION = np.array([True, True, True, False, False, False])


@dataclass(frozen=True)
class PegInHole:
    """Geometry of one case. `clearance` is per side (m); `half_width` is the peg's (bx, by) (m)."""

    planar: bool
    half_width: tuple[float, float]
    length: float
    ref_height: float
    clearance: tuple[float, float]
    depth: float
    selected_height: float = 0.0
    names: list[str] = field(init=False, compare=False)
    _kinds: dict = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        candidates = _candidates(self)
        object.__setattr__(self, "names", [c.name for c in candidates])
        kinds = {}
        for kind in ("vertex-wall", "rim-face", "edge-edge"):
            idx = [k for k, c in enumerate(candidates) if c.kind == kind]
            if idx:
                kinds[kind] = (np.array(idx), np.array([candidates[k].body for k in idx]),
                               np.array([candidates[k].world for k in idx]),
                               np.array([candidates[k].axis for k in idx]), np.array([candidates[k].side for k in idx]))
        object.__setattr__(self, "_kinds", kinds)

    @property
    def dofs(self) -> np.ndarray:
        return PLANAR_DOFS if self.planar else SPATIAL_DOFS

    @property
    def n(self) -> int:
        return len(self.dofs)

    @property
    def selected_point(self) -> np.ndarray:
        """The point of the error measure, on the axis `selected_height` above the tip centre (body frame)."""
        return np.array([0.0, 0.0, self.selected_height - self.ref_height])

    @property
    def mated_point(self) -> np.ndarray:
        """Where the selected point is when the peg is upright and inserted to `depth` (world)."""
        return np.array([0.0, 0.0, self.selected_height - self.depth])

    def hole_half_width(self, clearance_x: np.ndarray | float | None = None) -> np.ndarray:
        """(..., 2) hole half-widths (Bx, By); `clearance_x` overrides the x clearance (the chart's box)."""
        cx = np.asarray(self.clearance[0] if clearance_x is None else clearance_x, dtype=float)
        return np.stack(np.broadcast_arrays(self.half_width[0] + cx, self.half_width[1] + self.clearance[1]), -1)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis (np.cross costs several times more on the small arrays of one pose)."""
    a, b = np.broadcast_arrays(a, b)
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def rotation(tilt, tilt_x=0.0, twist=0.0) -> np.ndarray:
    """(..., 3, 3) R = Rz(twist)·Ry(tilt)·Rx(tilt_x): tilt > 0 leans the peg's top towards +x."""
    angles = np.stack(np.broadcast_arrays(np.asarray(twist, float), np.asarray(tilt, float),
                                          np.asarray(tilt_x, float)), -1)
    return Rotation.from_euler("ZYX", angles.reshape(-1, 3)).as_matrix().reshape(*angles.shape[:-1], 3, 3)


# -- contact candidates ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Candidate:
    name: str
    kind: str                 # vertex-wall | rim-face | edge-edge
    body: np.ndarray          # body point: the vertex, the face's outward normal (rim-face), the edge's base
    world: np.ndarray         # vertex-wall: the wall's normal, into the hole (zeros for the other kinds)
    axis: int                 # hole axis of the wall / rim (0: x, 1: y)
    side: float               # +1 or -1: which wall / rim along `axis`


def _candidates(g: PegInHole) -> list[_Candidate]:
    bx, by = g.half_width
    h = g.ref_height
    out = []
    sides = [(0, s) for s in (-1.0, 1.0)] + ([] if g.planar else [(1, s) for s in (-1.0, 1.0)])
    corners = [(sx, 0.0) for sx in (-1.0, 1.0)] if g.planar else [(sx, sy) for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)]
    label = "xy"
    for axis, s in sides:
        wall = f"wall{'+' if s > 0 else '-'}{label[axis]}"
        normal = np.zeros(3)
        normal[axis] = -s  # into the hole
        for sx, sy in corners:
            vertex = np.array([sx * bx, sy * by, -h])
            if (sx, sy)[axis] != s:  # only the vertices on the wall's side can reach it
                continue
            out.append(_Candidate(f"tip({sx:+.0f},{sy:+.0f})/{wall}", "vertex-wall", vertex, normal, axis, s))
        rim = f"rim{'+' if s > 0 else '-'}{label[axis]}"
        if g.planar:
            face_normal = np.array([s, 0.0, 0.0])
            out.append(_Candidate(f"{rim}/face{'+' if s > 0 else '-'}x", "rim-face", face_normal, np.zeros(3), axis, s))
        else:
            for sx, sy in corners:
                if (sx, sy)[axis] != s:
                    continue
                base = np.array([sx * bx, sy * by, -h])
                out.append(_Candidate(f"edge({sx:+.0f},{sy:+.0f})/{rim}", "edge-edge", base, np.zeros(3), axis, s))
    return out


@dataclass
class Contacts:
    """Every candidate at N poses: gap (N, K), point (N, K, 3) and normal (N, K, 3) in the world,
    `valid` (N, K): the closest features lie on the bodies (else the gap means nothing)."""

    names: list[str]
    gap: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    valid: np.ndarray


def contacts(g: PegInHole, R: np.ndarray, p: np.ndarray, clearance_x=None) -> Contacts:
    """Gaps, points and normals of every candidate at poses (R (N,3,3), p (N,3)), one vectorised pass per
    kind of contact."""
    R, p = np.asarray(R, float).reshape(-1, 3, 3), np.asarray(p, float).reshape(-1, 3)
    B = np.broadcast_to(g.hole_half_width(clearance_x), (len(R), 2))
    N, K = len(R), len(g.names)
    gap, valid = np.empty((N, K)), np.empty((N, K), bool)
    point, normal = np.empty((N, K, 3)), np.empty((N, K, 3))
    for kind, (idx, body, n_wall, axis, side) in g._kinds.items():
        half = B[:, axis]                                                   # (N, k)
        if kind == "vertex-wall":
            x = np.einsum("nij,kj->nki", R, body) + p[:, None]
            gap[:, idx] = np.einsum("nki,ki->nk", x, n_wall) + half
            point[:, idx], normal[:, idx] = x, n_wall
            valid[:, idx] = x[..., 2] <= 0.0  # below the rim, where the wall is
        elif kind == "rim-face":  # planar: rim corner (side·Bx, 0, 0) against the face of outward normal m
            rim = np.zeros((N, len(idx), 3))
            rim[..., 0] = side * half
            m_world = np.einsum("nij,kj->nki", R, body)
            local = np.einsum("nji,nkj->nki", R, rim - p[:, None])  # rim corner in the body frame
            gap[:, idx] = np.einsum("nki,ki->nk", local, body) - g.half_width[0]
            normal[:, idx] = -m_world
            point[:, idx] = rim - gap[:, idx, None] * m_world
            valid[:, idx] = (local[..., 2] >= -g.ref_height) & (local[..., 2] <= g.length - g.ref_height)
        else:  # edge-edge: peg edge base + s·(R z), s in [0, length]; rim edge start + t·b, t in [0, 2B]
            other = 1 - axis
            b = np.eye(3)[other]                                            # (k, 3)
            start = np.zeros((N, len(idx), 3))
            start[:, np.arange(len(idx)), axis] = side * half
            start[:, np.arange(len(idx)), other] = -B[:, other]
            a = np.broadcast_to(R[:, None, :, 2], start.shape)
            base = np.einsum("nij,kj->nki", R, body) + p[:, None]
            n = cross(a, b)
            n /= np.linalg.norm(n, axis=-1, keepdims=True)
            outward = np.zeros((len(idx), 3))  # away from the rim's solid corner: into the hole and up
            outward[np.arange(len(idx)), axis], outward[:, 2] = -side, 1.0
            n *= np.sign(np.einsum("nki,ki->nk", n, outward))[..., None]
            w0 = base - start
            ab, aw, bw = np.einsum("nki,ki->nk", a, b), np.einsum("nki,nki->nk", a, w0), np.einsum("nki,ki->nk", w0, b)
            denom = 1.0 - ab ** 2
            s_body, t_rim = (ab * bw - aw) / denom, (bw - ab * aw) / denom
            gap[:, idx] = np.einsum("nki,nki->nk", n, w0)
            point[:, idx], normal[:, idx] = base + s_body[..., None] * a, n
            valid[:, idx] = (s_body >= 0.0) & (s_body <= g.length) & (t_rim >= 0.0) & (t_rim <= 2 * B[:, other])
    return Contacts(g.names, gap, point, normal, valid)


def unit_wrenches(g: PegInHole, R: np.ndarray, p: np.ndarray, point: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """(N, n, K) body-frame unit wrenches [f; c × f] of contacts at world `point`s with normals into the peg,
    reduced to the case's dofs: the columns of W in w = W λ."""
    R, p = np.asarray(R, float).reshape(-1, 3, 3), np.asarray(p, float).reshape(-1, 3)
    f = np.einsum("nji,nkj->nki", R, normal)
    c = np.einsum("nji,nkj->nki", R, point - p[:, None])
    w = np.concatenate([f, cross(c, f)], axis=-1)
    return np.swapaxes(w[..., g.dofs], -1, -2)


def error_vector(g: PegInHole, R: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(N, 3) δ = the selected point − its mated position, world frame."""
    R, p = np.asarray(R, float).reshape(-1, 3, 3), np.asarray(p, float).reshape(-1, 3)
    return R @ g.selected_point + p - g.mated_point


def line_vector(g: PegInHole, R: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(N, n) d of eq. (2) in the body frame: [δ_b; p_sel × δ_b], so that dᵀv = δ·ṗ_sel = ½ d‖δ‖²/dt."""
    R = np.asarray(R, float).reshape(-1, 3, 3)
    delta_b = np.einsum("nji,nj->ni", R, error_vector(g, R, p))
    d = np.concatenate([delta_b, cross(g.selected_point, delta_b)], axis=-1)
    return d[:, g.dofs]


def nominal_twist(g: PegInHole, R: np.ndarray, speed: float) -> np.ndarray:
    """(N, n) v0: translation straight down the hole (world -z) at `speed`, in the body frame."""
    R = np.asarray(R, float).reshape(-1, 3, 3)
    v = np.zeros((len(R), 6))
    v[:, :3] = -speed * R[:, 2, :]  # Rᵀ(0, 0, -speed)
    return v[:, g.dofs]


# -- the two-point contact state and its chart ------------------------------------------------------------


def designated_pair(g: PegInHole) -> tuple[int, int]:
    """Indices of the two contacts of the assembly's two-point state: the tip vertex on the -x wall and the
    +x rim against the peg (planar: its +x face; spatial: its (+x, -y) edge, the one a positive twist turns
    towards the rim)."""
    first = "tip(-1,+0)/wall-x" if g.planar else "tip(-1,+1)/wall-x"
    second = "rim+x/face+x" if g.planar else "edge(+1,-1)/rim+x"
    return g.names.index(first), g.names.index(second)


def feature_of(name: str) -> str:
    """The hole feature (wall or rim) a candidate touches: contacts on one feature make one principal contact
    when several touch at once (a peg face flat on a wall), and only their sum is unique in a rigid model."""
    return next(part for part in name.split("/") if part.startswith(("wall", "rim")))


def forces_by_feature(g: PegInHole, forces: np.ndarray, order: list[int]) -> tuple[list[str], np.ndarray]:
    """Per-candidate forces (N, K, 3) summed per hole feature: (features, (N, F, 3)), the features of the
    candidates `order` first, then the others that carry force, in candidate order."""
    features = [feature_of(n) for n in g.names]
    loaded = [features[k] for k in order] + [features[k] for k in np.flatnonzero(np.abs(forces).sum(axis=(0, 2)) > 0)]
    names = list(dict.fromkeys(loaded))
    grouped = np.zeros((forces.shape[0], len(names), 3))
    for k, f in enumerate(features):
        if f in names:
            grouped[:, names.index(f)] += forces[:, k]
    return names, grouped


CHART = {True: ("tilt", "clearance"), False: ("tilt", "tilt_x", "twist", "lateral", "clearance")}


def chart_poses(g: PegInHole, coords: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poses of the two-point state at chart coordinates (N, m), columns as in `CHART[g.planar]`
    (rad, rad, rad, m, m): the orientation, the free lateral position (spatial) and the x clearance are
    given; the x and z positions put both designated contacts exactly at zero gap. Returns (R, p, clearance_x).

    For a fixed orientation every gap is affine in p with gradient = its normal, so one 2x2 solve is exact.
    Letting the clearance vary makes the box a superset of any one hole's configurations, in the spirit of
    the paper's decoupled coordinates (Sec. I, last paragraph)."""
    coords = np.atleast_2d(np.asarray(coords, float))
    col = dict(zip(CHART[g.planar], coords.T, strict=True))
    R = rotation(col["tilt"], col.get("tilt_x", 0.0), col.get("twist", 0.0))
    p = np.zeros((len(coords), 3))
    p[:, 1] = col.get("lateral", 0.0)
    i, j = designated_pair(g)
    c = contacts(g, R, p, col["clearance"])
    lhs = np.stack([c.normal[:, i][:, [0, 2]], c.normal[:, j][:, [0, 2]]], axis=1)
    step = np.linalg.solve(lhs, -np.stack([c.gap[:, i], c.gap[:, j]], axis=1)[..., None])[..., 0]
    p[:, [0, 2]] += step
    return R, p, col["clearance"]


def box_corners(bounds: np.ndarray) -> np.ndarray:
    """(2^m', m) vertices of the box `bounds` (m, 2); dimensions of zero width count once."""
    bounds = np.asarray(bounds, float)
    axes = [np.unique(b) for b in bounds]
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(bounds))


def se3_step(R: np.ndarray, p: np.ndarray, twist: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Pose after moving with the constant body twist [v_o; ω] (6,) for dt: T·exp(dt·twist^)."""
    v, w = twist[:3] * dt, twist[3:] * dt
    angle = float(np.sqrt(w @ w))
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if angle < 1e-4:  # series of the coefficients: the closed forms cancel catastrophically for small angles
        a, b, c = 1.0 - angle ** 2 / 6, 0.5 - angle ** 2 / 24, 1.0 / 6 - angle ** 2 / 120
    else:
        a, b, c = np.sin(angle) / angle, (1 - np.cos(angle)) / angle ** 2, (angle - np.sin(angle)) / angle ** 3
    K2 = K @ K
    exp_r = np.eye(3) + a * K + b * K2
    V = np.eye(3) + b * K + c * K2
    return R @ exp_r, p + R @ (V @ v)


def full_twist(g: PegInHole, v: np.ndarray) -> np.ndarray:
    """A reduced twist (n,) as the spatial 6-vector."""
    out = np.zeros(6)
    out[g.dofs] = v
    return out

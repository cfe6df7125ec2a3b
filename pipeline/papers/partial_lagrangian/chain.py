"""The paper's system: a planar serial chain with one point mass at the tip of each link (Sect. 3).

Angles follow the paper: θ1 is measured from the +x axis, θk (k ≥ 2) relative to link k−1 (link 2 uses
e(θ1+θ2), eq. 17), y is up, so θ1 = −90° hangs. A joint is revolute (θk is the coordinate, lk fixed) or
prismatic (lk is the coordinate, θk fixed: the slider of Sect. 3.3). Everything here is plain NumPy: the
closed forms the AD dynamics are checked against, and what the logs need (tip positions, energies).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

REVOLUTE, PRISMATIC = "revolute", "prismatic"
DAMPING_MODELS = ("cartesian", "joint")
PER_LINK = ("mass", "length", "damping", "stiffness", "joints", "angle")


@dataclass(frozen=True)
class Chain:
    """n links; link i carries mass m_i at its tip, spring k_i to the origin (eq. 16) and damping d_i."""

    mass: tuple[float, ...]           # kg
    length: tuple[float, ...]         # m (unused for a prismatic joint, whose length is its coordinate)
    damping: tuple[float, ...]        # N·s/m on the tip velocity (cartesian) or N·m·s/rad on the joint rate (joint)
    stiffness: tuple[float, ...]      # N/m, P_i = ½ k_i |p_i|² (eq. 16)
    joints: tuple[str, ...]           # revolute | prismatic, per link
    angle: tuple[float, ...]          # rad, fixed θ of a prismatic joint (unused for a revolute one)
    gravity: float = 9.8              # m/s², Listing A1
    damping_model: str = "cartesian"  # Rayleigh R_i = ½ d_i |ṗ_i|² (Listing A1) | ½ d_i q̇_i² per joint

    def __post_init__(self) -> None:
        n = len(self.mass)
        for name in PER_LINK:
            if len(getattr(self, name)) != n:
                raise ValueError(f"chain: {name} has {len(getattr(self, name))} entries for {n} links")
        if set(self.joints) - {REVOLUTE, PRISMATIC}:
            raise ValueError(f"chain: joints must be {REVOLUTE} or {PRISMATIC}, got {self.joints}")
        if self.damping_model not in DAMPING_MODELS:
            raise ValueError(f"chain: damping_model must be one of {DAMPING_MODELS}")

    @property
    def n(self) -> int:
        return len(self.mass)

    @property
    def revolute(self) -> np.ndarray:
        return np.array([j == REVOLUTE for j in self.joints])

    def joint_names(self) -> list[str]:
        return [f"{'theta' if j == REVOLUTE else 'l'}{i + 1}" for i, j in enumerate(self.joints)]

    def undamped(self) -> Chain:
        return replace(self, damping=(0.0,) * self.n)

    def prefix(self, n: int) -> Chain:
        """The first n links: the chain before an extension (eq. 6)."""
        return replace(self, **{name: getattr(self, name)[:n] for name in PER_LINK})


def planar_chain(n: int, mass: Sequence[float], length: Sequence[float], damping: Sequence[float],
                 stiffness: Sequence[float], gravity: float, damping_model: str = "cartesian",
                 joints: Sequence[str] | None = None, angle: Sequence[float] | None = None) -> Chain:
    """The first n links of the configured parameter lists; all joints revolute unless `joints` says."""
    if n > len(mass):
        raise ValueError(f"chain of {n} links needs {n} masses, the config lists {len(mass)}")
    joints = tuple(joints) if joints is not None else (REVOLUTE,) * n
    angle = tuple(float(a) for a in angle) if angle is not None else (0.0,) * n
    take = lambda xs: tuple(float(x) for x in xs[:n])  # noqa: E731
    return Chain(take(mass), take(length), take(damping), take(stiffness), joints, angle, float(gravity),
                 damping_model)


def from_config(system, n: int, joints: Sequence[str] | None = None, angle: Sequence[float] | None = None) -> Chain:
    """The chain of n links from a run's `system` config (a DictConfig or the plain dict of a run file)."""
    links = system["links"]
    return planar_chain(n, links["mass"], links["length"], links["damping"], links["stiffness"], system["gravity"],
                        system["damping_model"], joints, angle)


# -- NumPy kinematics and energies (batched over leading axes of q) ---------------------------------------


def link_geometry(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(absolute link angles φ_j = Σ_{k≤j} θ_k, link lengths) for coordinates q (..., n)."""
    q = np.asarray(q, dtype=float)
    rev = chain.revolute
    theta = np.where(rev, q, np.asarray(chain.angle))
    lengths = np.where(rev, np.asarray(chain.length), q)
    return np.cumsum(theta, axis=-1), lengths


def tip_positions(chain: Chain, q: np.ndarray) -> np.ndarray:
    """(..., n, 2) positions p_i of the point masses, p_i = Σ_{j≤i} l_j e(φ_j) (eqs. 11, 17)."""
    phi, lengths = link_geometry(chain, q)
    steps = lengths[..., None] * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    return np.cumsum(steps, axis=-2)


def tip_jacobians(chain: Chain, q: np.ndarray) -> np.ndarray:
    """(..., n, 2, n) ∂p_i/∂q: column j of tip i is nonzero for j ≤ i only (L_i holds q_1..q_i, eq. 5)."""
    q = np.asarray(q, dtype=float)
    phi, _ = link_geometry(chain, q)
    n = chain.n
    e = np.stack([np.cos(phi), np.sin(phi)], axis=-1)             # (..., n, 2) link directions
    p = tip_positions(chain, q)
    J = np.zeros((*q.shape[:-1], n, 2, n))
    for j in range(n):
        base = p[..., j - 1, :] if j > 0 else np.zeros_like(p[..., 0, :])
        for i in range(j, n):
            if chain.joints[j] == REVOLUTE:   # rotating joint j turns everything beyond it about its origin
                r = p[..., i, :] - base
                J[..., i, :, j] = np.stack([-r[..., 1], r[..., 0]], axis=-1)
            else:                               # sliding joint j moves everything beyond it along e(φ_j)
                J[..., i, :, j] = e[..., j, :]
    return J


def energies(chain: Chain, q: np.ndarray, qd: np.ndarray) -> dict[str, np.ndarray]:
    """Kinetic K = Σ½m|ṗ|² (eq. 15), potential P = Σ(½k|p|² + m g y) (eq. 16) and Rayleigh R, per sample."""
    p = tip_positions(chain, q)
    v = np.einsum("...icj,...j->...ic", tip_jacobians(chain, q), np.asarray(qd, dtype=float))
    m, k = np.asarray(chain.mass), np.asarray(chain.stiffness)
    speed2 = (v * v).sum(-1)
    kinetic = 0.5 * (m * speed2).sum(-1)
    potential = (0.5 * k * (p * p).sum(-1) + m * chain.gravity * p[..., 1]).sum(-1)
    d = np.asarray(chain.damping)
    rayleigh = 0.5 * (d * (speed2 if chain.damping_model == "cartesian" else np.asarray(qd) ** 2)).sum(-1)
    return {"kinetic": kinetic, "potential": potential, "total": kinetic + potential, "rayleigh": rayleigh}


def gravity_torque(chain: Chain, q: np.ndarray) -> np.ndarray:
    """∂P/∂q by statics, independent of any AD: joint k carries the weight of every mass beyond it
    (moment arm = horizontal distance for a revolute joint, the link's sine for a slider)."""
    J = tip_jacobians(chain, q)
    weight = np.asarray(chain.mass) * chain.gravity
    springs = np.asarray(chain.stiffness)[:, None] * tip_positions(chain, q)
    return np.einsum("...icj,...ic->...j", J, springs) + np.einsum("...ij,i->...j", J[..., :, 1, :], weight)


def double_pendulum(chain: Chain, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form (M, b) of the two-link chain, eqs. (17)-(24) with the misprints of eqs. (19)-(20)
    corrected (cross terms 2 l1 l2 cos θ2; spec §3.1); no springs, no damping. τ = M q̈ + b."""
    (m1, m2), (l1, l2), g = chain.mass, chain.length, chain.gravity
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    m11 = m1 * l1 ** 2 + m2 * (l1 ** 2 + l2 ** 2 + 2 * l1 * l2 * c2)
    m12 = m2 * (l2 ** 2 + l1 * l2 * c2)
    m22 = m2 * l2 ** 2
    h = m2 * l1 * l2 * s2
    g2 = m2 * g * l2 * np.cos(q[0] + q[1])
    b1 = -h * (2 * qd[0] * qd[1] + qd[1] ** 2) + (m1 + m2) * g * l1 * np.cos(q[0]) + g2
    b2 = h * qd[0] ** 2 + g2
    return np.array([[m11, m12], [m12, m22]]), np.array([b1, b2])


def pose_matrices(chain: Chain, q: np.ndarray) -> np.ndarray:
    """(N, n, 4, 4) poses of the link tips for /tf: the paper's plane (x, y) drawn as world (x, z), so
    gravity points down in a 3-D viewer; each frame's x axis along its link."""
    q = np.atleast_2d(q)
    phi, _ = link_geometry(chain, q)
    p = tip_positions(chain, q)
    T = np.zeros((*q.shape, 4, 4))
    c, s = np.cos(phi), np.sin(phi)
    T[..., 0, 0], T[..., 0, 2], T[..., 2, 0], T[..., 2, 2] = c, -s, s, c   # rotation about −y by φ
    T[..., 1, 1] = T[..., 3, 3] = 1.0
    T[..., 0, 3], T[..., 2, 3] = p[..., 0], p[..., 1]
    return T

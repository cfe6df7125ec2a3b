"""The RRFbR SCARA-like arm of Table 1: kinematics (eqs. 3-7), inverse kinematics, gravity compensation
(eqs. 12-13), and the pose and velocity of each of its six moving links.

Joint coordinates θ = [θ1 θ2 θ3 θ4] (eq. 1), external coordinates x = [x y z θ] (eq. 2). Angles in rad.
Everything is vectorized over leading axes of θ.

The link geometry the paper leaves out (spec §2): link 1 lies at height l1 (the top of link 0); the
actuated bar 3 and the passive bar 4 pivot on the joint-2 axis, bar 4 a height `h` above bar 3; the
coupler 5 stays vertical (the parallelogram keeps it parallel to link 2) and carries joint 4; E lies on
the joint-4 axis l4 below the distal pivot of bar 3. Links 2, 5 and 6 have their centres of mass on the
joint-2 / joint-4 axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from omegaconf import DictConfig

LINKS = ("link1", "link2", "link3", "link4", "link5", "link6")
JOINTS = ("theta1", "theta2", "theta3", "theta4")
EXTERNAL = ("x", "y", "z", "theta")
Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Arm:
    """Table 1 plus the stated assumptions (conf/system/scara-half-derivative.yaml), SI units."""

    l1: float
    l2: float
    l3: float
    l4: float
    lG1: float
    lG3: float
    lG4: float
    h: float                        # vertical spacing of the two bars' pivots (assumption; no dynamic effect)
    masses: tuple[float, ...]       # m1..m6
    inertia: tuple[tuple[float, float, float], ...]  # principal inertias of links 1..6 about their CoM, link axes
    gravity: float
    k3: float
    theta3p: float                  # rad, neutral angle of the balancing spring

    @classmethod
    def from_config(cls, system: DictConfig) -> Arm:
        g = system.geometry
        masses = tuple(float(m) for m in system.masses)
        moment = gravity_moment(g.lG3, g.lG4, g.l3, masses)
        theta3p = (np.deg2rad(system.spring.theta3p_deg) if system.spring.theta3p_deg is not None
                   else balanced_theta3p(moment, system.gravity, system.spring.k3))
        scale = float(system.get("inertia_scale", 1.0))
        return cls(l1=g.l1, l2=g.l2, l3=g.l3, l4=g.l4, lG1=g.lG1, lG3=g.lG3, lG4=g.lG4, h=g.h, masses=masses,
                   inertia=tuple(tuple(scale * float(v) for v in row) for row in system.inertia),
                   gravity=system.gravity,
                   k3=system.spring.k3, theta3p=float(theta3p))

    @property
    def moment(self) -> float:
        """m3 lG3 + m4 lG4 + l3 (m5 + m6) [kg m]: the static moment of links 3-6 about joint 3."""
        return gravity_moment(self.lG3, self.lG4, self.l3, self.masses)

    @property
    def com_offsets(self) -> np.ndarray:
        """(6, 3) centre of mass of each link in its own frame (see `link_frames`)."""
        return np.array([[self.lG1, 0, 0], [0, 0, 0], [self.lG3, 0, 0], [self.lG4, 0, 0], [0, 0, 0],
                         [0, 0, -self.l4 / 2]])


def gravity_moment(lG3: float, lG4: float, l3: float, masses) -> float:
    m = masses
    return m[2] * lG3 + m[3] * lG4 + l3 * (m[4] + m[5])


def balanced_theta3p(moment: float, gravity: float, k3: float) -> float:
    """Eq. (13): the spring's neutral angle that balances gravity exactly at θ3 = 0."""
    return -moment * gravity / k3


def gravity_torque(arm: Arm, theta3) -> np.ndarray:
    """Eq. (12): τ_g,3, the joint-3 torque that holds the arm against gravity and the spring."""
    return -arm.moment * arm.gravity * np.cos(theta3) + arm.k3 * (np.asarray(theta3) - arm.theta3p)


def potential_energy(arm: Arm, theta3) -> np.ndarray:
    """Gravity + spring energy (zero gravity energy with links 3-4 horizontal); dV/dθ3 = τ_g,3 (eq. 12)."""
    theta3 = np.asarray(theta3)
    return -arm.moment * arm.gravity * np.sin(theta3) + 0.5 * arm.k3 * (theta3 - arm.theta3p) ** 2


# -- eqs. (3)-(7) ----------------------------------------------------------------------------------------


def fk(arm: Arm, q) -> np.ndarray:
    """Eqs. (3)-(6): x = [x, y, z, θ] of E."""
    q = np.asarray(q, dtype=float)
    t1, t2, t3, t4 = np.moveaxis(q, -1, 0)
    r = arm.l3 * np.cos(t3)
    return np.stack([arm.l2 * np.cos(t1) + r * np.cos(t1 + t2), arm.l2 * np.sin(t1) + r * np.sin(t1 + t2),
                     arm.l1 - arm.l3 * np.sin(t3) - arm.l4, t1 + t2 + t4], axis=-1)


def jacobian(arm: Arm, q) -> np.ndarray:
    """Eq. (7): ẋ = J θ̇, shape (..., 4, 4)."""
    q = np.asarray(q, dtype=float)
    t1, t2, t3, _ = np.moveaxis(q, -1, 0)
    s1, c1, s3, c3 = np.sin(t1), np.cos(t1), np.sin(t3), np.cos(t3)
    s12, c12 = np.sin(t1 + t2), np.cos(t1 + t2)
    l2, l3 = arm.l2, arm.l3
    zero, one = np.zeros_like(t1), np.ones_like(t1)
    rows = [[-l2 * s1 - l3 * c3 * s12, -l3 * c3 * s12, -l3 * s3 * c12, zero],
            [l2 * c1 + l3 * c3 * c12, l3 * c3 * c12, -l3 * s3 * s12, zero],
            [zero, zero, -l3 * c3, zero],
            [one, one, zero, one]]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def fk_jacobian(arm: Arm, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. (3)-(7) for one pose, (x, J): the controller's per-period call (scalar math is 5x faster than the
    batched forms above for a single pose; tests check they agree)."""
    t1, t2, t3, t4 = (float(v) for v in q)
    s1, c1, s3, c3 = math.sin(t1), math.cos(t1), math.sin(t3), math.cos(t3)
    s12, c12 = math.sin(t1 + t2), math.cos(t1 + t2)
    l2, l3 = arm.l2, arm.l3
    r = l3 * c3
    x = np.array([l2 * c1 + r * c12, l2 * s1 + r * s12, arm.l1 - l3 * s3 - arm.l4, t1 + t2 + t4])
    J = np.array([[-l2 * s1 - r * s12, -r * s12, -l3 * s3 * c12, 0.0],
                  [l2 * c1 + r * c12, r * c12, -l3 * s3 * s12, 0.0],
                  [0.0, 0.0, -r, 0.0],
                  [1.0, 1.0, 0.0, 1.0]])
    return x, J


def ik(arm: Arm, x) -> np.ndarray:
    """Inverse of eqs. (3)-(6) on the θ2 > 0 branch (the reference pose has θ2 = +90°), |θ3| < 90°."""
    x = np.asarray(x, dtype=float)
    px, py, pz, theta = np.moveaxis(x, -1, 0)
    t3 = np.arcsin((arm.l1 - arm.l4 - pz) / arm.l3)
    r = arm.l3 * np.cos(t3)
    c2 = (px ** 2 + py ** 2 - arm.l2 ** 2 - r ** 2) / (2 * arm.l2 * r)
    t2 = np.arccos(np.clip(c2, -1.0, 1.0))
    t1 = np.arctan2(py, px) - np.arctan2(r * np.sin(t2), arm.l2 + r * np.cos(t2))
    return np.stack([t1, t2, t3, theta - t1 - t2], axis=-1)


# -- the links as rigid bodies ------------------------------------------------------------------------


def _rot_z(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, -s, zero], -1), np.stack([s, c, zero], -1), np.stack([zero, zero, one], -1)], -2)


def _rot_y(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, zero, s], -1), np.stack([zero, one, zero], -1), np.stack([-s, zero, c], -1)], -2)


def link_frames(arm: Arm, q) -> np.ndarray:
    """(..., 6, 4, 4) poses of links 1-6 in the base frame, composed joint by joint (independent of eqs. 3-6).

    Link 1: origin on the joint-1 axis at height l1, x along the link. Link 2: origin on the joint-2 axis,
    x along the arm's direction θ1+θ2. Bars 3 and 4: origin at their pivot, x along the bar, y the joint-3
    axis (rotating +θ3 about it lowers the bar). Coupler 5: origin at the distal pivot of bar 3, axes
    parallel to link 2's. Link 6: origin on the joint-4 axis (same point), turned by θ4."""
    q = np.asarray(q, dtype=float)
    t1, t2, t3, t4 = np.moveaxis(q, -1, 0)
    R1, R2 = _rot_z(t1), _rot_z(t1 + t2)
    R3 = R2 @ _rot_y(t3)
    R6 = _rot_z(t1 + t2 + t4)
    o1 = np.broadcast_to(np.array([0.0, 0.0, arm.l1]), R1.shape[:-1])
    o2 = o1 + arm.l2 * R1[..., :, 0]
    o4 = o2 + arm.h * Z
    o5 = o2 + arm.l3 * R3[..., :, 0]
    poses = np.zeros((*q.shape[:-1], 6, 4, 4))
    poses[..., 3, 3] = 1.0
    for i, (R, o) in enumerate(((R1, o1), (R2, o2), (R3, o2), (R3, o4), (R2, o5), (R6, o5))):
        poses[..., i, :3, :3] = R
        poses[..., i, :3, 3] = o
    return poses


def end_effector(arm: Arm, frames: np.ndarray) -> np.ndarray:
    """E from the link frames: l4 below the link-6 origin."""
    return frames[..., 5, :3, 3] - arm.l4 * Z


# The open tree behind the parallelogram, one revolute joint per link: (parent link, joint coordinate, rate
# factor, axis = column of the link's own frame). Bar 4 turns with θ3 (the parallelogram), the coupler turns
# back by −θ3 relative to bar 3; each joint sits at its link's frame origin.
TREE = ((-1, 0, 1.0, 2), (0, 1, 1.0, 2), (1, 2, 1.0, 1), (1, 2, 1.0, 1), (2, 2, -1.0, 1), (4, 3, 1.0, 2))


def link_jacobians(arm: Arm, q) -> np.ndarray:
    """(6, 6, 4) geometric Jacobians [v_CoM; ω] = J_i θ̇ of the six links (base frame), single q."""
    frames = link_frames(arm, q)
    com = np.einsum("lij,lj->li", frames[:, :3, :3], arm.com_offsets) + frames[:, :3, 3]
    J = np.zeros((6, 6, 4))
    for link in range(6):
        joint = link
        while joint >= 0:  # every joint between the base and this link moves it
            parent, coord, factor, column = TREE[joint]
            axis, point = frames[joint, :3, column], frames[joint, :3, 3]
            J[link, :3, coord] += factor * np.cross(axis, com[link] - point)
            J[link, 3:, coord] += factor * axis
            joint = parent
    return J


def link_inertia_world(arm: Arm, q) -> np.ndarray:
    """(6, 3, 3) inertia tensors about the CoM in base axes."""
    R = link_frames(arm, q)[:, :3, :3]
    return np.einsum("lij,lj,lkj->lik", R, np.asarray(arm.inertia), R)


def mass_matrix_from_links(arm: Arm, q) -> np.ndarray:
    """M(θ) = Σ m J_vᵀ J_v + J_ωᵀ I J_ω over the links: the kinetic energy is ½ θ̇ᵀ M θ̇."""
    J = link_jacobians(arm, q)
    inertia = link_inertia_world(arm, q)
    m = np.asarray(arm.masses)
    return (np.einsum("l,lki,lkj->ij", m, J[:, :3], J[:, :3])
            + np.einsum("lki,lkm,lmj->ij", J[:, 3:], inertia, J[:, 3:]))

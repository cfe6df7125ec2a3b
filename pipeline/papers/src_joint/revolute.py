"""The SRC joint chain as revolute joints: an MJCF (hence a URDF, pipeline.robotics.urdf) that draws the rolling
manipulator exactly, and the hinge angles of a rolling state.

Why four hinges are exact. Eq. (10) puts the tangent plane P_i at ^{B_{i-1}}R_{P_i} = R(q_{i-1,2})ᵀ, eq. (7) puts
B_i's centre (l_{i-1} + l_i) along P_i's normal, and eq. (6) turns B_i by ^{P_i}R_{B_i} = R(q_{i,1}): B_{i-1} ->
a turn about B_{i-1}'s centre -> a translation along the normal -> a turn about B_i's centre. Rolling from the
aligned start by θ about an axis ê = Rz(φ) e_x of the tangent plane gives q_{i,1} = exp(θ ê) and, by eq. (5)
with its radii corrected (erratum 1: the same arc on both spheres), q_{i-1,2} = exp(−(l_i/l_{i-1}) θ ê). With
Rz(φ) Rx(a) Rz(−φ) = Exp(a ê), and Rz commuting with the translation along z, the joint is

    ^{B_{i-1}}T_{B_i} = Rz(φ) · Rx(α) · Tz(l_{i-1} + l_i) · Rx(β) · Rz(ψ),   α = (l_i/l_{i-1}) β,  ψ = −φ,

four hinges: the azimuth of the rolling axis, the roll's share on B_{i-1}'s side (the contact normal's tilt),
on B_i's side, and the azimuth back; for equal spheres the roll is halved, α = β = Θ/2 of the joint's turn Θ.
It holds for every state the manipulator runs reach: rolling without spin between equal spheres is integrable
(any path ends in such a state: pipeline.papers.src_joint.reachability), and between unequal spheres a
straight roll does (rolling.py: P_i turns l_i/(l_{i-1}+l_i) of B_i's turn); `hinge_angles` checks it.

All four hinges are published (no URDF `mimic`): a viewer that ignores mimic joints (Rerun's URDF tree does not
expose them, rerun-io/rerun#12646; yourdfpy leaves them out of the actuated joints) would draw them at zero,
and a joint-state consumer sees every joint's position as drawn. The azimuth jumps where the contact normal
passes through B_{i-1}'s pole (α = 0, any φ draws the same pose); the drawing does not.
The MJCF bodies are the paper's B_0 … B_n (the names of the run's /tf frames) and C_i, a frame at the contact
point with z the common normal and x the rolling axis ê, drawn as a thin disc.
"""

from __future__ import annotations

import numpy as np

from pipeline.papers.src_joint.rolling import exp_so3

HINGES = ("azimuth", "roll_lower", "roll_upper", "azimuth_back")
BASE_COLOR, LINK_COLOR, CONTACT_COLOR = (0.55, 0.6, 0.7, 1.0), (0.9, 0.6, 0.2, 1.0), (0.15, 0.15, 0.15, 1.0)
_DISC = (0.35, 0.0008)   # contact disc: radius as a share of the smaller sphere's, half-thickness (m)
_TOLERANCE = 1e-9        # rad: the largest departure of a state from the four-hinge form it may have


def hinge_names(n: int) -> list[str]:
    """The MJCF (and URDF) joint names of n SRC joints, in qpos order."""
    return [f"j{i + 1}.{h}" for i in range(n) for h in HINGES]


def chain_xml(radii) -> str:
    """MJCF of spheres l_0 … l_n (`radii`) on a fixed base B_0, joined by four hinges per SRC joint."""
    radii = np.asarray(radii, dtype=float)
    n = len(radii) - 1

    def body(i: int) -> str:
        if i > n:
            return ""
        lower, upper = radii[i - 1], radii[i]
        disc = f'{_DISC[0] * min(lower, upper):.17g} {_DISC[1]:.17g}'
        return (f'<body name="C{i}" pos="0 0 {lower:.17g}">'
                f'<joint name="j{i}.azimuth" axis="0 0 1" pos="0 0 {-lower:.17g}"/>'
                f'<joint name="j{i}.roll_lower" axis="1 0 0" pos="0 0 {-lower:.17g}"/>'
                f'<geom type="cylinder" size="{disc}" rgba="{_rgba(CONTACT_COLOR)}"/>'
                f'<body name="B{i}" pos="0 0 {upper:.17g}">'
                f'<joint name="j{i}.roll_upper" axis="1 0 0"/><joint name="j{i}.azimuth_back" axis="0 0 1"/>'
                f'<geom type="sphere" size="{upper:.17g}" rgba="{_rgba(LINK_COLOR)}"/>{body(i + 1)}</body></body>')

    base = f'<geom type="sphere" size="{radii[0]:.17g}" rgba="{_rgba(BASE_COLOR)}"/>'
    return f'<mujoco model="src-manipulator"><worldbody><body name="B0">{base}{body(1)}</body></worldbody></mujoco>\n'


def _rgba(color: tuple) -> str:
    return " ".join(f"{c:g}" for c in color)


def hinge_angles(tangent: np.ndarray, relative: np.ndarray, radii) -> np.ndarray:
    """qpos of `chain_xml` for rolling states ^{B_{i-1}}R_{P_i} `tangent` and ^{B_{i-1}}R_{B_i} `relative`: (4n,)
    for states (n, 3, 3), (N, 4n) for a trajectory (N, n, 3, 3), whose azimuths are unwrapped in time. The azimuth
    and the lower roll are the contact normal's polar angles in B_{i-1}; the upper roll follows by the radius
    ratio (module docstring). Only P_i's normal counts: its turn about the normal (a trolley's frame carried
    round a loop) moves no body. Raises ValueError for a state the four hinges cannot draw."""
    radii = np.asarray(radii, dtype=float)
    normal = tangent[..., :, 2]                           # Rz(φ) Rx(α) e_z = (sin α sin φ, −sin α cos φ, cos α)
    sin_alpha = np.hypot(normal[..., 0], normal[..., 1])
    alpha = np.arctan2(sin_alpha, normal[..., 2])
    phi = np.where(sin_alpha > 0, np.arctan2(normal[..., 0], -normal[..., 1]), 0.0)   # at the pole: any φ
    if phi.ndim > 1:   # a trajectory: no 2π steps in the plotted azimuths
        phi = np.unwrap(phi, axis=0)
    beta = alpha * radii[:-1] / radii[1:]                 # α = (l_i / l_{i-1}) β
    axis = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)], axis=-1)
    departure = np.abs(exp_so3((alpha + beta)[..., None] * axis) - relative).max(initial=0.0)
    if departure > _TOLERANCE:
        raise ValueError(f"a rolling state departs by {departure:.3g} from the four-hinge form (twisted contact or "
                         "unequal spheres off a straight roll): it cannot be drawn by chain_xml")
    return np.stack([phi, alpha, beta, -phi], axis=-1).reshape(*phi.shape[:-1], -1)

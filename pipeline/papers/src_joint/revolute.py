"""The SRC joint chain as revolute joints: an MJCF (hence a URDF, pipeline.robotics.urdf) that draws the rolling
spheres exactly in any relative state, and the hinge angles of a rolling state.

The general form. Any relative state of B_i on B_{i-1} is the contact normal's direction in B_{i-1} (azimuth φ,
polar angle α), the shift (l_{i-1} + l_i) along it (eq. 7), and B_i's orientation in the frame so reached:

    ^{B_{i-1}}T_{B_i} = Rz(φ) · Rx(α) · Tz(l_{i-1} + l_i) · Rx(β) · Ry(γ) · Rz(ψ),

five hinges: the azimuth, the roll on B_{i-1}'s side (the normal's tilt), then intrinsic X-Y-Z angles of B_i
(`roll_upper`, `lean_upper`, `azimuth_back`). X-Y-Z is chosen for where its singularity lies (γ = ±π/2, B_i's z
axis along the rolling axis ê = Rz(φ) e_x): a straight roll, and every state of equal spheres, has γ = 0, as far
from it as can be; γ grows only with the twist about the normal that rolling unequal spheres round a curve
leaves (the holonomy). At the singularity, as at B_{i-1}'s pole (α = 0, any φ), the angles are still exact;
only their continuity is lost.

Equal spheres need four. Eq. (10) puts the tangent plane P_i at ^{B_{i-1}}R_{P_i} = R(q_{i-1,2})ᵀ and eq. (6)
turns B_i by ^{P_i}R_{B_i} = R(q_{i,1}). Rolling from the aligned start by θ about an axis ê = Rz(φ) e_x of the
tangent plane gives q_{i,1} = exp(θ ê) and, by eq. (5) with its radii corrected (erratum 1: the same arc on both
spheres), q_{i-1,2} = exp(−(l_i/l_{i-1}) θ ê). With Rz(φ) Rx(a) Rz(−φ) = Exp(a ê), the joint is the general
form with γ = 0, ψ = −φ and α = (l_i/l_{i-1}) β: for equal spheres the roll is halved, α = β = Θ/2 of the joint's
turn Θ. Rolling without spin between equal spheres is integrable, so every path ends in such a state
(pipeline.papers.src_joint.reachability) and `chain_xml` gives a joint of equal spheres four hinges (no
`lean_upper`); `hinge_angles` refuses a state they cannot draw. Between unequal spheres only a straight roll
keeps γ = 0 (rolling.py: P_i turns l_i/(l_{i-1}+l_i) of B_i's turn); their joints carry all five.

All hinges are published (no URDF `mimic`): a viewer that ignores mimic joints (Rerun's URDF tree does not
expose them, rerun-io/rerun#12646; yourdfpy leaves them out of the actuated joints) would draw them at zero,
and a joint-state consumer sees every joint's position as drawn. Over a trajectory the angles are continuous:
where the contact normal passes through B_{i-1}'s pole the azimuth keeps its value and the tilt changes sign,
and the angles are unwrapped in time.
The MJCF bodies are the paper's B_0 … B_n (the names of the run's /tf frames) and C_i, a frame at the contact
point with z the common normal and x the rolling axis ê, drawn as a thin disc.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

HINGES = ("azimuth", "roll_lower", "roll_upper", "lean_upper", "azimuth_back")   # the general form, in qpos order
EQUAL_HINGES = tuple(h for h in HINGES if h != "lean_upper")                     # equal spheres
BASE_COLOR, LINK_COLOR, CONTACT_COLOR = (0.55, 0.6, 0.7, 1.0), (0.9, 0.6, 0.2, 1.0), (0.15, 0.15, 0.15, 1.0)
_DISC = (0.35, 0.0008)   # contact disc: radius as a share of the smaller sphere's, half-thickness (m)
_TOLERANCE = 1e-9        # rad: the largest lean a joint of equal spheres may have (it has no hinge for it)
_POLE = 1e-12            # sin α below which the contact normal is at B_{i-1}'s pole (its azimuth undefined)


def joint_hinges(lower: float, upper: float) -> tuple[str, ...]:
    """The hinges of one SRC joint of spheres l_{i-1} = `lower`, l_i = `upper` (module docstring)."""
    return EQUAL_HINGES if lower == upper else HINGES


def hinge_names(radii) -> list[str]:
    """The MJCF (and URDF) joint names of the chain of spheres l_0 … l_n (`radii`), in qpos order."""
    return [f"j{i + 1}.{h}" for i, (a, b) in enumerate(pairwise(radii))
            for h in joint_hinges(a, b)]


def chain_xml(radii, name: str = "src-manipulator") -> str:
    """MJCF of spheres l_0 … l_n (`radii`) on a fixed base B_0, joined by the hinges of each SRC joint."""
    radii = np.asarray(radii, dtype=float)
    n = len(radii) - 1
    axes = {"roll_upper": "1 0 0", "lean_upper": "0 1 0", "azimuth_back": "0 0 1"}

    def body(i: int) -> str:
        if i > n:
            return ""
        lower, upper = radii[i - 1], radii[i]
        disc = f'{_DISC[0] * min(lower, upper):.17g} {_DISC[1]:.17g}'
        own = "".join(f'<joint name="j{i}.{h}" axis="{axes[h]}"/>' for h in joint_hinges(lower, upper)[2:])
        return (f'<body name="C{i}" pos="0 0 {lower:.17g}">'
                f'<joint name="j{i}.azimuth" axis="0 0 1" pos="0 0 {-lower:.17g}"/>'
                f'<joint name="j{i}.roll_lower" axis="1 0 0" pos="0 0 {-lower:.17g}"/>'
                f'<geom type="cylinder" size="{disc}" rgba="{_rgba(CONTACT_COLOR)}"/>'
                f'<body name="B{i}" pos="0 0 {upper:.17g}">{own}'
                f'<geom type="sphere" size="{upper:.17g}" rgba="{_rgba(LINK_COLOR)}"/>{body(i + 1)}</body></body>')

    base = f'<geom type="sphere" size="{radii[0]:.17g}" rgba="{_rgba(BASE_COLOR)}"/>'
    return f'<mujoco model="{name}"><worldbody><body name="B0">{base}{body(1)}</body></worldbody></mujoco>\n'


def _rgba(color: tuple) -> str:
    return " ".join(f"{c:g}" for c in color)


def hinge_angles(tangent: np.ndarray, relative: np.ndarray, radii) -> np.ndarray:
    """qpos of `chain_xml` for rolling states ^{B_{i-1}}R_{P_i} `tangent` and ^{B_{i-1}}R_{B_i} `relative`: one
    row for states (n, 3, 3), (N, ·) for a trajectory (N, n, 3, 3), continuous in time (module docstring). The
    azimuth and the lower roll are the contact normal's polar angles in B_{i-1}; B_i's X-Y-Z angles are taken
    in the frame they reach. Only P_i's normal counts: its turn about the normal (a trolley's frame carried
    round a loop) moves no body. Raises ValueError for a joint of equal spheres that leans (a twisted contact,
    which no rolling reaches): its four hinges cannot draw it."""
    radii = np.asarray(radii, dtype=float)
    phi, alpha = _contact_direction(tangent[..., :, 2])
    c, s, ca, sa = np.cos(phi), np.sin(phi), np.cos(alpha), np.sin(alpha)
    zero = np.zeros_like(phi)
    contact = np.stack([c, -s * ca, s * sa, s, c * ca, -c * sa, zero, sa, ca], axis=-1)   # Rz(φ) Rx(α)
    own = np.swapaxes(contact.reshape(*phi.shape, 3, 3), -1, -2) @ relative
    roll = np.arctan2(-own[..., 1, 2], own[..., 2, 2])        # own = Rx(β) Ry(γ) Rz(ψ)
    lean = np.arctan2(own[..., 0, 2], np.hypot(own[..., 1, 2], own[..., 2, 2]))
    back = np.arctan2(-own[..., 0, 1], own[..., 0, 0])
    if phi.ndim > 1:
        roll, back = np.unwrap(roll, axis=0), np.unwrap(back, axis=0)
    equal = radii[:-1] == radii[1:]
    departure = np.abs(lean[..., equal]).max(initial=0.0)
    if departure > _TOLERANCE:
        raise ValueError(f"a joint of equal spheres leans by {departure:.3g} rad (twisted about its contact normal, "
                         "which rolling never does): its four hinges in chain_xml cannot draw it")
    keep = np.ones((len(equal), len(HINGES)), dtype=bool)
    keep[equal, HINGES.index("lean_upper")] = False
    return np.stack([phi, alpha, roll, lean, back], axis=-1)[..., keep]


def _contact_direction(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth φ and polar angle α of contact normals (..., n, 3), n = Rz(φ) Rx(α) e_z. Over a trajectory
    (N, n, 3) both are continuous: at the pole the azimuth holds its neighbours' value, and through it the
    normal keeps its azimuth and tilts the other way (α < 0) instead of turning by π."""
    sin_alpha = np.hypot(normal[..., 0], normal[..., 1])
    alpha = np.arctan2(sin_alpha, normal[..., 2])
    defined = sin_alpha > _POLE
    phi = np.where(defined, np.arctan2(normal[..., 0], -normal[..., 1]), 0.0)
    if normal.ndim < 3:
        return phi, alpha
    steps = np.arange(len(phi))[:, None]
    held = np.maximum.accumulate(np.where(defined, steps, -1), axis=0)        # the last defined sample
    held = np.where(held < 0, defined.argmax(axis=0), held)   # before the first: the first (none: φ = 0)
    phi = np.take_along_axis(phi, held, axis=0)
    turned = np.unwrap(phi, period=np.pi, axis=0)
    flipped = np.round((turned - phi) / np.pi) % 2 == 1                      # (φ + π, −α) is the same normal
    return turned, np.where(flipped, -alpha, alpha)

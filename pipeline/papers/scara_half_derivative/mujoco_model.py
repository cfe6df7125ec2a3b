"""The arm as a MuJoCo model (MJCF) generated from the same `Arm` as the Exudyn plant: what a run attaches as
`model.xml` and draws (its URDF, joint states and link frames; pipeline.core.robot). The Exudyn closed chain
stays the plant; this model is the same open tree (multibody.TREE_PARENTS: θ1, θ2, θ3, φ4, φ5, θ4 at the link
frames of arm.link_frames) with the same masses, centres of mass, inertias, gravity and balancing spring, and
the parallelogram closed by an equality constraint, so MuJoCo could simulate it too.

Drawn sizes (radii of the rods and columns) are not in the paper: they only make the links visible.
"""

from __future__ import annotations

import functools

import numpy as np

from pipeline.papers.scara_half_derivative.arm import Arm
from pipeline.papers.scara_half_derivative.multibody import LOOP

TREE_JOINTS = ("theta1", "theta2", "theta3", "phi4", "phi5", "theta4")   # multibody.LOOP's rows
QPOS_JOINTS = ("theta1", "theta2", "theta3", "phi5", "theta4", "phi4")   # MuJoCo's order: bar 3's subtree first
_QPOS_ROWS = [TREE_JOINTS.index(name) for name in QPOS_JOINTS]
_COLUMN, _ARM, _BAR, _TOOL = 0.05, 0.03, 0.015, 0.012   # m, drawn radii (not in the paper)
_LINK_RGBA, _BAR_RGBA, _BASE_RGBA = ".85 .55 .2 1", ".3 .45 .75 1", ".5 .5 .55 1"


def _fmt(v) -> str:
    return " ".join(f"{x:.12g}" for x in np.atleast_1d(v))


def _body(name: str, pos, joint: str, axis: str, arm: Arm, link: int, geoms: str, inner: str = "",
          extra: str = "") -> str:
    return (f'<body name="{name}" pos="{_fmt(pos)}"><joint name="{joint}" axis="{axis}"{extra}/>'
            f'<inertial pos="{_fmt(arm.com_offsets[link])}" mass="{arm.masses[link]:.12g}" '
            f'diaginertia="{_fmt(arm.inertia[link])}"/>{geoms}{inner}</body>')


@functools.cache
def model_xml(arm: Arm) -> str:
    """MJCF of the arm (bodies link1-link6 as in arm.LINKS, joints QPOS_JOINTS, site E on the tool)."""
    l1, l2, l3, l4, h = arm.l1, arm.l2, arm.l3, arm.l4, arm.h

    def rod(a, b, radius: float, rgba: str, kind: str = "capsule") -> str:
        return f'<geom type="{kind}" fromto="{_fmt([*a, *b])}" size="{radius:.12g}" rgba="{rgba}" mass="0"/>'

    tool = _body("link6", [0, 0, 0], "theta4", "0 0 1", arm, 5,
                 rod([0, 0, 0], [0, 0, -l4], _TOOL, _LINK_RGBA) + f'<site name="E" pos="0 0 {-l4:.12g}"/>')
    coupler = _body("link5", [l3, 0, 0], "phi5", "0 1 0", arm, 4,
                    rod([0, 0, -0.02], [0, 0, h + 0.02], _BAR, _BAR_RGBA, "cylinder"), tool)
    bar3 = _body("link3", [0, 0, 0], "theta3", "0 1 0", arm, 2, rod([0, 0, 0], [l3, 0, 0], _BAR, _BAR_RGBA), coupler,
                 extra=f' stiffness="{arm.k3:.12g}" springref="{arm.theta3p:.12g}"')   # eq. (10)
    bar4 = _body("link4", [0, 0, h], "phi4", "0 1 0", arm, 3, rod([0, 0, 0], [l3, 0, 0], _BAR, _BAR_RGBA))
    link2 = _body("link2", [l2, 0, 0], "theta2", "0 0 1", arm, 1,
                  rod([0, 0, -0.03], [0, 0, h + 0.03], _ARM, _LINK_RGBA, "cylinder"), bar3 + bar4)
    link1 = _body("link1", [0, 0, l1], "theta1", "0 0 1", arm, 0, rod([0, 0, 0], [l2, 0, 0], _ARM, _LINK_RGBA), link2)
    return f"""<mujoco model="scara">
  <compiler angle="radian"/>
  <option gravity="0 0 {-arm.gravity:.12g}"/>
  <worldbody>
    {rod([0, 0, 0], [0, 0, l1], _COLUMN, _BASE_RGBA, "cylinder")}
    {link1}
  </worldbody>
  <equality><connect body1="link4" body2="link5" anchor="{l3:.12g} 0 0"/></equality>
</mujoco>
"""


def qpos(q: np.ndarray) -> np.ndarray:
    """MuJoCo qpos (..., 6) of the model from the joint coordinates θ (..., 4): the parallelogram's φ4 = θ3,
    φ5 = −θ3 (the closed chain's own map, multibody.LOOP)."""
    return np.asarray(q, dtype=float) @ LOOP[_QPOS_ROWS].T

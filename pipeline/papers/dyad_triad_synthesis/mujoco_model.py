"""The Exudyn four-bar as a MuJoCo model (MJCF) generated from the same bodies (multibody.Body): what a run
attaches as `model.xml` and draws (its URDF, joint states and link frames; pipeline.core.robot). Exudyn stays
the plant. The linkage lies in the world x-y plane in position 1; crank and coupler form a chain from the
ground pivot a0 (joints a0, a1), the rocker hangs from b0 (joint b0), and the loop is closed at b1 by an
equality constraint. Body frames sit at each link's first pivot, turned by the link's rotation from position
1: the frames the run logs on /tf (crank_A, coupler, rocker_B).

Drawn radii are the config's `linkage.link_radius`; masses, centres of mass and inertias about z are the
Exudyn bodies' (the inertia about the in-plane axes, which no planar motion uses, is set equal to it).
"""

from __future__ import annotations

import numpy as np

from pipeline.papers.dyad_triad_synthesis.fourbar import FourBar
from pipeline.papers.dyad_triad_synthesis.multibody import Body

JOINTS = ("a0", "a1", "b0")   # MJCF hinges, in qpos order: crank on ground, coupler on crank, rocker on ground


def _xyz(z: complex) -> str:
    return f"{z.real:.12g} {z.imag:.12g} 0"


def model_xml(fourbar: FourBar, bodies: list[Body], link_radius: float) -> str:
    """MJCF of the four-bar: bodies crank_A, coupler, rocker_B (multibody's order), hinges JOINTS about z."""
    f = fourbar
    crank, coupler, rocker = bodies

    def body(name: str, b: Body, origin: complex, rods: list[tuple[complex, complex]], rgba: str, joint: str,
             inner: str = "", parent: complex = 0j) -> str:
        """A link with its first pivot at `origin` (world, position 1), placed in its parent's frame."""
        geoms = "".join(f'<geom type="capsule" fromto="{_xyz(a - origin)} {_xyz(c - origin)}" '
                        f'size="{link_radius:.12g}" rgba="{rgba}" mass="0"/>' for a, c in rods)
        return (f'<body name="{name}" pos="{_xyz(origin - parent)}"><joint name="{joint}" axis="0 0 1"/>'
                f'<inertial pos="{_xyz(b.com - origin)}" mass="{b.mass:.12g}" '
                f'diaginertia="{b.inertia:.12g} {b.inertia:.12g} {b.inertia:.12g}"/>{geoms}{inner}</body>')

    coupler_xml = body("coupler", coupler, f.a1, [(f.a1, f.b1), (f.a1, f.p), (f.b1, f.p)], ".2 .45 .75 1", "a1",
                       parent=f.a0)
    crank_xml = body("crank_A", crank, f.a0, [(f.a0, f.a1)], ".85 .33 .1 1", "a0", coupler_xml)
    rocker_xml = body("rocker_B", rocker, f.b0, [(f.b0, f.b1)], ".3 .65 .3 1", "b0")
    return f"""<mujoco model="four_bar">
  <option gravity="0 0 0"/>
  <worldbody>
    <geom type="capsule" fromto="{_xyz(f.a0)} {_xyz(f.b0)}" size="{link_radius / 2:.12g}" rgba=".4 .4 .4 1"/>
    {crank_xml}
    {rocker_xml}
  </worldbody>
  <equality><connect body1="coupler" body2="rocker_B" anchor="{_xyz(f.b1 - f.a1)}"/></equality>
</mujoco>
"""


def qpos(rotations: np.ndarray) -> np.ndarray:
    """MuJoCo qpos (..., 3) from the links' rotations from position 1 (..., 3: crank, coupler, rocker): the
    coupler's hinge turns it relative to the crank."""
    rotations = np.asarray(rotations, dtype=float)
    return np.stack([rotations[..., 0], rotations[..., 1] - rotations[..., 0], rotations[..., 2]], axis=-1)

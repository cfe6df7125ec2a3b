"""MuJoCo cross-check (spec §6): the same peg and hole with soft frictionless contacts (condim 1), the
admittance realised as a bank of dampers on the peg.

The law v = v0 + A·w is what a damper B = A⁻¹ pulling the peg towards the nominal twist does when the
peg's inertia is negligible: m·v̇ = B(v0 - v) + w  ->  v = v0 + A·w as m -> 0. B = Σ_j b_j g_j g_jᵀ is built
from one `general` actuator per eigen-direction g_j of B, on a site at the body origin (site transmission:
gear = [force; torque] in the body frame, actuator velocity = gᵀv): force b_j·(g_jᵀv0 − g_jᵀv) is
ctrl_j − b_j·velocity with ctrl_j = b_j·g_jᵀv0. v0 is the world-fixed insertion twist, so ctrl follows the
peg's orientation every step. The peg keeps a small mass (its time constant m/b is then far below the
step), so the `discrete` integrator is used: it solves the contacts and the damping in one implicit step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.admittance_assembly import geometry
from pipeline.papers.admittance_assembly.geometry import PegInHole
from pipeline.robotics.transforms import quaternion_wxyz


@dataclass(frozen=True)
class MujocoSettings:
    timestep: float            # s
    mass: float                # kg, the peg with whatever the admittance device moves with it
    solref: tuple[float, float]
    solimp: tuple[float, float, float, float, float]
    integrator: str = "discrete"
    hole_depth_margin: float = 0.01  # m, the walls reach this far below the mated depth


def _fmt(v) -> str:
    return " ".join(f"{x:.17g}" for x in np.atleast_1d(v))


def damper_bank(g: PegInHole, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(gears (n, 6), b (n,)) with Σ b_j g_j g_jᵀ = A⁻¹ on the case's dofs. The eigen-decomposition is done
    in length-scaled units (design.scaling) so the directions do not mix metres and radians arbitrarily."""
    s = np.where(geometry.TRANSLATION[g.dofs], 1.0, 1.0 / g.length)
    A_scaled = A / np.outer(s, s)
    alpha, E = np.linalg.eigh(A_scaled)
    gears = np.zeros((g.n, 6))
    gears[:, g.dofs] = (E / s[:, None]).T  # g_j = S⁻¹ e_j
    return gears, 1.0 / alpha


def model_xml(g: PegInHole, A: np.ndarray, s: MujocoSettings) -> str:
    bx, by = g.half_width
    Bx, By = g.hole_half_width()
    thick = 0.02
    bottom = -(g.depth + s.hole_depth_margin)
    zc, hz = bottom / 2, -bottom / 2
    walls = [("wall-x", (-Bx - thick / 2, 0.0, zc), (thick / 2, By + thick, hz)),
             ("wall+x", (Bx + thick / 2, 0.0, zc), (thick / 2, By + thick, hz))]
    if not g.planar:
        walls += [("wall-y", (0.0, -By - thick / 2, zc), (Bx, thick / 2, hz)),
                  ("wall+y", (0.0, By + thick / 2, zc), (Bx, thick / 2, hz))]
    else:  # the planar slot is open along y: its walls only need to be longer than the peg
        walls = [(n, c, (h[0], by + thick, h[2])) for n, c, h in walls]
    wall_xml = "\n".join(f'    <geom name="{n}" type="box" pos="{_fmt(c)}" size="{_fmt(h)}" rgba=".5 .5 .55 1"/>'
                         for n, c, h in walls)
    joints = ('<joint name="x" type="slide" axis="1 0 0"/><joint name="z" type="slide" axis="0 0 1"/>'
              '<joint name="ry" type="hinge" axis="0 1 0"/>') if g.planar else '<freejoint name="peg"/>'
    # inertia of the peg box for the given mass, about the body origin's axes at the box centre
    hx, hy, hz_peg = bx, by, g.length / 2
    inertia = s.mass / 3 * np.array([hy ** 2 + hz_peg ** 2, hx ** 2 + hz_peg ** 2, hx ** 2 + hy ** 2])
    gears, b = damper_bank(g, A)
    actuators = "\n".join(f'    <general name="damper{j}" site="admittance" gear="{_fmt(gears[j])}" '
                          f'gainprm="1" biastype="affine" biasprm="0 0 {-b[j]:.17g}"/>' for j in range(len(b)))
    return f"""<mujoco model="admittance_assembly_{'planar' if g.planar else 'spatial'}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{s.timestep:.17g}" integrator="{s.integrator}" gravity="0 0 0"/>
  <default>
    <geom condim="1" solref="{_fmt(s.solref)}" solimp="{_fmt(s.solimp)}" friction="0 0 0"/>
  </default>
  <worldbody>
{wall_xml}
    <body name="peg">
      {joints}
      <inertial pos="0 0 {hz_peg - g.ref_height:.17g}" mass="{s.mass:.17g}" diaginertia="{_fmt(inertia)}"/>
      <geom name="peg" type="box" pos="0 0 {hz_peg - g.ref_height:.17g}" size="{_fmt([hx, hy, hz_peg])}"
            mass="0" rgba=".8 .6 .2 1"/>
      <site name="admittance" size="0.002"/>
    </body>
  </worldbody>
  <actuator>
{actuators}
  </actuator>
</mujoco>
"""


def drawing(g: PegInHole, A: np.ndarray) -> list:
    """The peg (in /tf frame `peg`) and the hole's walls (in `world`) of this model as /markers entities: what
    draws a quasi-static run, which has no MuJoCo model of its own. Only the geometry is drawn, so the contact
    and time settings are MuJoCo's defaults."""
    import mujoco

    from pipeline.core import markers

    geometry_only = MujocoSettings(timestep=0.002, mass=1.0, solref=(0.02, 1.0), solimp=(0.9, 0.95, 0.001, 0.5, 2))
    return markers.mujoco_geoms(mujoco.MjModel.from_xml_string(model_xml(g, A, geometry_only)))


class PegSim:
    """The model and its state, with the pose, the body twist and the contact wrench in our conventions."""

    def __init__(self, g: PegInHole, A: np.ndarray, settings: MujocoSettings):
        import mujoco

        self.mj = mujoco
        self.g = g
        self.xml = model_xml(g, A, settings)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self.gears, self.b = damper_bank(g, A)
        self.peg_geom = self.model.geom("peg").id
        self.peg_body = self.model.body("peg").id
        self.site = self.model.site("admittance").id
        self._force = np.zeros(6)
        self._twist = np.zeros(6)

    def set_pose(self, R: np.ndarray, p: np.ndarray) -> None:
        if self.g.planar:
            self.data.qpos[:] = [p[0], p[2], np.arctan2(R[0, 2], R[0, 0])]
        else:
            self.data.qpos[:3], self.data.qpos[3:7] = p, quaternion_wxyz(R)
        self.data.qvel[:] = 0.0
        self.mj.mj_forward(self.model, self.data)

    def pose(self) -> tuple[np.ndarray, np.ndarray]:
        return self.data.xmat[self.peg_body].reshape(3, 3).copy(), self.data.xpos[self.peg_body].copy()

    def twist(self) -> np.ndarray:
        """Body twist [v_o; ω] in the body frame, reduced to the case's dofs (of the site at the body origin:
        a body's own velocity in MuJoCo is its centre of mass's)."""
        self.mj.mj_objectVelocity(self.model, self.data, self.mj.mjtObj.mjOBJ_SITE, self.site, self._twist, 1)
        return np.r_[self._twist[3:], self._twist[:3]][self.g.dofs]

    def set_nominal(self, v0_body: np.ndarray) -> None:
        """ctrl_j = b_j·g_jᵀv0 (v0 reduced, body frame)."""
        self.data.ctrl[:] = self.b * (self.gears[:, self.g.dofs] @ v0_body)

    def contact_forces(self) -> tuple[np.ndarray, np.ndarray]:
        """(points (c, 3), forces (c, 3)) on the peg, world frame, of every active contact."""
        d = self.data
        points, forces = [], []
        for i in range(d.ncon):
            con = d.contact[i]
            if con.efc_address < 0 or self.peg_geom not in (con.geom1, con.geom2):
                continue
            self.mj.mj_contactForce(self.model, d, i, self._force)
            f = con.frame.reshape(3, 3).T @ self._force[:3]  # normal from geom1 to geom2: force on geom2
            forces.append(f if con.geom2 == self.peg_geom else -f)
            points.append(con.pos.copy())
        return np.array(points).reshape(-1, 3), np.array(forces).reshape(-1, 3)

    def contact_wrench(self) -> np.ndarray:
        """The total contact wrench on the peg, body frame, about the body origin, reduced."""
        R, p = self.pose()
        points, forces = self.contact_forces()
        f_b = forces @ R
        c_b = (points - p) @ R
        return np.r_[f_b.sum(axis=0), np.cross(c_b, f_b).sum(axis=0)][self.g.dofs]

    def step(self) -> None:
        self.mj.mj_step(self.model, self.data)

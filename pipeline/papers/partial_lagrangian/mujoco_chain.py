"""The same chain in MuJoCo: an independent model for the AD dynamics to agree with, and the timing
baseline of Fig. 5b (our extension; the paper times no other method).

The paper's plane (x, y) is MuJoCo's (x, z), gravity −z; a hinge turns about −y so that θ is measured
from +x towards +z, as in the paper. Each link is a body whose point mass sits at the link tip (a tiny
rotational inertia, MuJoCo needs one). A slider is a slide joint along its link, whose body frame is turned
by the fixed angle. Damping is applied as a generalized force through MuJoCo's own Jacobians
(Cartesian: −Σ d_i J_iᵀ J_i q̇; joint: −d q̇), so MuJoCo's Euler step integrates it explicitly, exactly like
our semi-implicit Euler.
"""

from __future__ import annotations

import numpy as np

from pipeline.papers.partial_lagrangian.chain import REVOLUTE, Chain

POINT_INERTIA = 1e-10   # kg·m², rotational inertia of each point mass (MuJoCo requires > 0)


def chain_model(chain: Chain, dt: float) -> str:
    """MJCF of the chain (joint i = coordinate i, site tip<i> at mass i)."""
    bodies, closing, offset = [], [], 0.0
    for i in range(chain.n):
        pad = "  " * (i + 2)
        if chain.joints[i] == REVOLUTE:
            bodies += [f'{pad}<body name="link{i + 1}" pos="{offset:.17g} 0 0">',
                       f'{pad}  <joint name="joint{i + 1}" type="hinge" axis="0 -1 0"/>']
            tip = chain.length[i]
        else:  # a slide along the link, turned by its fixed angle; qpos is the link length
            bodies += [f'{pad}<body name="link{i + 1}" pos="{offset:.17g} 0 0" '
                       f'axisangle="0 -1 0 {chain.angle[i]:.17g}">',
                       f'{pad}  <joint name="joint{i + 1}" type="slide" axis="1 0 0"/>']
            tip = 0.0
        bodies += [f'{pad}  <inertial pos="{tip:.17g} 0 0" mass="{chain.mass[i]:.17g}" '
                   f'diaginertia="{POINT_INERTIA} {POINT_INERTIA} {POINT_INERTIA}"/>',
                   f'{pad}  <site name="tip{i + 1}" pos="{tip:.17g} 0 0" size="0.05"/>']
        closing.append(f"{pad}</body>")
        offset = tip
    return f"""<mujoco model="planar_chain_{chain.n}">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option timestep="{dt:.17g}" gravity="0 0 {-chain.gravity:.17g}" integrator="Euler">
    <flag contact="disable"/>
  </option>
  <worldbody>
{chr(10).join(bodies)}
{chr(10).join(reversed(closing))}
  </worldbody>
</mujoco>
"""


class MujocoChain:
    """MuJoCo's dynamics of a chain: mass matrix, bias forces, forward dynamics, free rollouts."""

    def __init__(self, chain: Chain, dt: float = 1e-3):
        import mujoco

        self._mj = mujoco
        self.chain = chain
        self.xml = chain_model(chain, dt)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self._jac = np.zeros((3, chain.n))
        self._sites = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, f"tip{i + 1}") for i in range(chain.n)]

    def _set(self, q, qd) -> None:
        self.data.qpos[:] = q
        self.data.qvel[:] = qd

    def damping_force(self) -> np.ndarray:
        """Generalized damping force at the current state (positions must be current)."""
        d = np.asarray(self.chain.damping)
        qd = self.data.qvel
        if self.chain.damping_model == "joint":
            return -d * qd
        force = np.zeros(self.chain.n)
        for i, site in enumerate(self._sites):
            if d[i]:
                self._mj.mj_jacSite(self.model, self.data, self._jac, None, site)
                force -= d[i] * self._jac.T @ (self._jac @ qd)
        return force

    def mass_bias(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """(M, b) with τ = M q̈ + b, b = Coriolis + gravity − damping force."""
        mj = self._mj
        self._set(q, qd)
        mj.mj_forward(self.model, self.data)
        M = np.zeros((self.chain.n, self.chain.n))
        mj.mj_fullM(self.model, self.data, M)
        return M, self.data.qfrc_bias.copy() - self.damping_force()

    def forward(self, q, qd, tau) -> np.ndarray:
        """q̈ from MuJoCo's own forward dynamics with τ and the damping force applied."""
        mj = self._mj
        self._set(q, qd)
        mj.mj_kinematics(self.model, self.data)
        mj.mj_comPos(self.model, self.data)
        self.data.qfrc_applied[:] = np.asarray(tau) + self.damping_force()
        mj.mj_forward(self.model, self.data)
        return self.data.qacc.copy()

    def rollout(self, q0, qd0, steps: int) -> tuple[np.ndarray, np.ndarray]:
        """Unforced motion, MuJoCo's Euler step (q̇ += h q̈, q += h q̇): (q, q̇) after each step."""
        mj = self._mj
        mj.mj_resetData(self.model, self.data)
        self._set(q0, qd0)
        q, qd = np.empty((steps, self.chain.n)), np.empty((steps, self.chain.n))
        for k in range(steps):
            mj.mj_kinematics(self.model, self.data)
            mj.mj_comPos(self.model, self.data)
            self.data.qfrc_applied[:] = self.damping_force()
            mj.mj_step(self.model, self.data)
            q[k], qd[k] = self.data.qpos, self.data.qvel
        return q, qd

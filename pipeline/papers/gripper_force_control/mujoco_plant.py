"""The MuJoCo plant: motors, gearbox constraints, a finger with a soft pad and a grasped object, generated
from the paper's parameters. The grasp force is measured from the contact (the paper measured it with a
motor holding the Finger's gear, eq. 19), independent of the lumped model's formula.

Bodies, joints and tendons (world z up, the gripper axis through the origin):

    gripper    hinge gripper (z) bearing friction; carries the object and a fixed jaw
      finger   hinge finger (y)  the Finger's gear; φ_f = 0 when the unloaded pad touches the object
        pad    slide pad (x)     the soft pad: joint spring k_c and damper c_c
    tendon m1 = k_g·gripper + g_f·finger    M1's shaft angle φ_1 (eqs. 5-6, 8): armature J_M1, shaft friction
    tendon m2 = −g_c·gripper                M2's shaft angle φ_2 (eq. 7): armature J_M2

The gearbox is exact: each motor is a fixed tendon (a linear combination of joint angles) carrying the
motor's inertia as tendon armature and driven by a motor actuator on that tendon, so the mass matrix is
J_M1 ∇φ_1 ∇φ_1ᵀ + J_M2 ∇φ_2 ∇φ_2ᵀ, as in the lumped model, with no soft gear constraint to leak. (Motor
joints tied to the gripper by equality constraints were tried first: with the paper's massless gripper
parts MuJoCo's soft equalities let the gears slip by centiradians under the grasp load.)

Every moving body is near massless (the paper lumps all inertia into J_M1 and J_M2); gravity is off (it is
not in the paper's model). One moving finger presses the object against a fixed jaw, so that the contact
force is the F_f of eqs. (8) and (19): the Finger's-gear torque over l_f.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from omegaconf import DictConfig

from pipeline.papers.gripper_force_control.drive import Drive, Schedule
from pipeline.papers.gripper_force_control.lumped import TRACE_FIELDS, Start, Trace
from pipeline.papers.gripper_force_control.model import Gripper

PAD_THICKNESS = 0.005    # m
JAW_THICKNESS = 0.006    # m
MOTOR_HEIGHT = 0.35      # m, where the frame-mounted motors are drawn
TINY_MASS = 1e-5         # kg, and a matching inertia: "massless" moving bodies
# the pad-object contact as stiff as the step allows (MuJoCo's floor on timeconst is 2 steps): the pad's
# spring, not the contact, is the compliance
CONTACT_SOLIMP = "0.99 0.999 0.0005"
FRAMES = ("gripper", "finger", "pad", "object")


@dataclass(frozen=True)
class Layout:
    """Where the parts are: the finger hinge sits so that the unloaded pad touches the object at φ_f = 0."""

    object_radius: float
    hinge_x: float
    hinge_z: float      # below the flange: h_g, eq. (2)
    l_f: float

    @property
    def object_z(self) -> float:
        return self.hinge_z - self.l_f


def layout(p: Gripper, contact: DictConfig) -> Layout:
    return Layout(object_radius=contact.object_radius, hinge_x=contact.object_radius + PAD_THICKNESS,
                  hinge_z=-p.gear.h_g, l_f=p.l_f)


def _tiny() -> str:
    return f'<inertial pos="0 0 0" mass="{TINY_MASS}" diaginertia="{TINY_MASS * 1e-4} {TINY_MASS * 1e-4} ' \
           f'{TINY_MASS * 1e-4}"/>'


def mjcf(p: Gripper, contact: DictConfig, open_stop: float | None = None) -> str:
    """MJCF of the gripper with the friction of `p` (zero friction = the ideal case); `open_stop` (rad, < 0)
    puts a mechanical stop where the finger is fully open."""
    g, lay = p.gear, layout(p, contact)
    timeconst = 2 * p.dt
    r, lf = lay.object_radius, p.l_f
    m_obj = contact.object_mass
    i_obj = 0.4 * m_obj * r * r
    jaw_x = -r - JAW_THICKNESS / 2
    finger_range = "" if open_stop is None else f' range="{open_stop:.17g} {np.pi / 2:.17g}"'
    return f"""<mujoco model="gripper_force_control">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{p.dt:.17g}" integrator="implicitfast" gravity="0 0 0"/>
  <default>
    <geom contype="0" conaffinity="0" rgba="0.7 0.72 0.75 1"/>
  </default>
  <worldbody>
    <light pos="0 -0.4 0.6" dir="0 0.5 -1"/>
    <geom name="flange" type="cylinder" size="0.05 0.005" pos="0 0 0.01" rgba="0.3 0.3 0.3 1"/>
    <geom name="m1" type="cylinder" size="0.03 0.04" pos="0 0 {MOTOR_HEIGHT}" rgba="0.2 0.3 0.6 1"/>
    <geom name="m2" type="cylinder" size="0.03 0.04" pos="{g.l_a:.17g} 0 {MOTOR_HEIGHT}" rgba="0.6 0.3 0.2 1"/>
    <body name="gripper">
      {_tiny()}
      <joint name="gripper" type="hinge" axis="0 0 1" frictionloss="{p.tau_cg:.17g}" damping="{p.b_g:.17g}"
             solreffriction="{timeconst:.17g} 1"/>
      <geom type="cylinder" size="0.035 {-lay.hinge_z / 2:.17g}" pos="0 0 {lay.hinge_z / 2:.17g}"/>
      <geom name="jaw" type="box" size="{JAW_THICKNESS / 2} 0.012 0.015" pos="{jaw_x:.17g} 0 {lay.object_z:.17g}"
            rgba="0.25 0.25 0.25 1"/>
      <geom type="capsule" size="0.004" rgba="0.25 0.25 0.25 1"
            fromto="{jaw_x:.17g} 0 {lay.object_z:.17g} {jaw_x:.17g} 0 {lay.hinge_z:.17g}"/>
      <body name="object" pos="0 0 {lay.object_z:.17g}">
        <inertial pos="0 0 0" mass="{m_obj:.17g}" diaginertia="{i_obj:.17g} {i_obj:.17g} {i_obj:.17g}"/>
        <geom name="object" type="sphere" size="{r:.17g}" rgba="0.85 0.15 0.1 1"/>
      </body>
      <body name="finger" pos="{lay.hinge_x:.17g} 0 {lay.hinge_z:.17g}">
        {_tiny()}
        <joint name="finger" type="hinge" axis="0 1 0"{finger_range}/>
        <geom type="capsule" fromto="0 0 0 0 0 {-lf:.17g}" size="0.004"/>
        <body name="pad" pos="0 0 {-lf:.17g}">
          <joint name="pad" type="slide" axis="1 0 0" stiffness="{p.k_c:.17g}" damping="{p.c_c:.17g}"/>
          <inertial pos="{-PAD_THICKNESS / 2} 0 0" mass="{contact.pad_mass:.17g}" diaginertia="1e-8 1e-8 1e-8"/>
          <geom name="pad" type="box" size="{PAD_THICKNESS / 2} 0.012 0.012" pos="{-PAD_THICKNESS / 2} 0 0"
                rgba="0.1 0.1 0.1 1"/>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="m1" armature="{p.J_1:.17g}" frictionloss="{p.tau_c1:.17g}" damping="{p.b_1:.17g}"
           solreffriction="{timeconst:.17g} 1">
      <joint joint="gripper" coef="{g.k_g:.17g}"/>
      <joint joint="finger" coef="{g.g_f:.17g}"/>
    </fixed>
    <fixed name="m2" armature="{p.J_2:.17g}">
      <joint joint="gripper" coef="{-g.g_c:.17g}"/>
    </fixed>
  </tendon>
  <contact>
    <pair name="grasp" geom1="pad" geom2="object" condim="1" solref="{timeconst:.17g} 1" solimp="{CONTACT_SOLIMP}"/>
  </contact>
  <actuator>
    <motor name="m1" tendon="m1"/>
    <motor name="m2" tendon="m2" gear="-1"/>  <!-- the drive counts M2 backwards: eq. (14) is negative feedback -->
  </actuator>
</mujoco>
"""


class MujocoGripper:
    """A compiled model with its joint addresses; `simulate` runs the drive on it."""

    def __init__(self, p: Gripper, contact: DictConfig, open_stop: float | None = None):
        import mujoco

        self.p, self.xml, self.layout = p, mjcf(p, contact, open_stop), layout(p, contact)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self.qpos = {j: int(self.model.joint(j).qposadr[0]) for j in ("gripper", "finger", "pad")}
        self.states: list[np.ndarray] = []  # qpos at the /tf samples of the last simulate()
        self.motor = {t: self.model.tendon(t).id for t in ("m1", "m2")}
        self.pad_geom = self.model.geom("pad").id
        self.bodies = [self.model.body(b).id for b in FRAMES]

    def configuration(self, phi_g: float | np.ndarray, phi_f: float | np.ndarray) -> np.ndarray:
        """qpos (..., nq) of the lumped plant's coordinates (gear constraints hold by construction):
        joint `gripper` (hinge about z, rad) = φ_g, the gripper's turn; joint `finger` (hinge about y, rad) =
        φ_f, the Finger's-gear angle, 0 where the unloaded pad touches the object; joint `pad` (slide along
        x, m) = the pad's compression δ = l_f φ_f while it presses (lumped.contact_force), else 0. The motors
        are tendons of these: φ_1 = k_g φ_g + g_f φ_f, φ_2 = −g_c φ_g."""
        phi_g, phi_f = np.broadcast_arrays(np.asarray(phi_g, dtype=float), np.asarray(phi_f, dtype=float))
        qpos = np.zeros((*phi_g.shape, self.model.nq))
        qpos[..., self.qpos["gripper"]] = phi_g
        qpos[..., self.qpos["finger"]] = phi_f
        qpos[..., self.qpos["pad"]] = np.maximum(self.p.l_f * phi_f, 0.0)
        return qpos

    def place(self, start: Start) -> None:
        """Put the mechanism at rest in the configuration of `start`, gear constraints satisfied."""
        import mujoco

        d = self.data
        mujoco.mj_resetData(self.model, d)
        d.qpos[:] = self.configuration(start.phi_g, start.phi_f)
        mujoco.mj_forward(self.model, d)

    def drawn(self, phi_g: np.ndarray, phi_f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The lumped plant's states (K,) drawn on this model: qpos (K, nq) and the (K, len(FRAMES), 4, 4)
        world poses of its bodies, by MuJoCo's kinematics."""
        import mujoco

        qpos = self.configuration(phi_g, phi_f)
        poses = np.empty((len(qpos), len(self.bodies), 4, 4))
        for k, q in enumerate(qpos):
            self.data.qpos[:] = q
            mujoco.mj_kinematics(self.model, self.data)
            poses[k] = self.poses()
        return qpos, poses

    def grasp_force(self) -> float:
        """Normal force of the pad-object contact (0 when they do not touch)."""
        import mujoco

        d, wrench, total = self.data, np.zeros(6), 0.0
        for i in range(d.ncon):
            c = d.contact[i]
            if self.pad_geom in (c.geom1, c.geom2):
                mujoco.mj_contactForce(self.model, d, i, wrench)
                total += wrench[0]
        return total

    def poses(self) -> np.ndarray:
        """(len(FRAMES), 4, 4) world poses of the gripper, finger, pad and object."""
        out = np.zeros((len(self.bodies), 4, 4))
        out[:, 3, 3] = 1.0
        out[:, :3, :3] = self.data.xmat[self.bodies].reshape(-1, 3, 3)
        out[:, :3, 3] = self.data.xpos[self.bodies]
        return out

    def simulate(self, s: Schedule, start: Start, log_every: int, settle: float = 0.0,
                 tf_every: int = 0) -> tuple[Trace, np.ndarray]:
        """Run the drive on the model over the schedule from `start`; sample every `log_every` ticks and the
        body poses (and `states`, qpos) every `tf_every` ticks. The first `settle` s (not logged, time starts
        after them) hold the schedule's first set points with friction off: the soft contact finds its
        equilibrium, as the lumped plant's exact `start` already is."""
        import mujoco

        from pipeline.robotics.mjcf import check_mujoco

        p, m, d = self.p, self.model, self.data
        self.place(start)
        pre = round(settle / p.dt / p.position_every) * p.position_every   # keep the loops' phase
        drive = Drive(p, _hold_first(s, pre), start.I_1, start.I_2, start.phi_g)
        friction = m.dof_frictionloss.copy(), m.tendon_frictionloss.copy()
        m.dof_frictionloss[:], m.tendon_frictionloss[:] = 0.0, 0.0
        rec = np.empty((len(range(0, s.ticks, log_every)), len(TRACE_FIELDS)))
        frames, self.states = [], []
        qp, qv, ctrl = d.qpos, d.qvel, d.ctrl
        i_g, i_f = self.qpos["gripper"], self.qpos["finger"]
        k_g, g_f, j, step = p.gear.k_g, p.gear.g_f, 0, mujoco.mj_step
        for k in range(pre + s.ticks):
            if k == pre:
                m.dof_frictionloss[:], m.tendon_frictionloss[:] = friction
            # the encoders: M1's shaft (tendon m1) and M2's, which gives the gripper angle by eq. (7)
            phi_g, omega_g = float(qp[i_g]), float(qv[i_g])
            omega_1 = k_g * omega_g + g_f * float(qv[i_f])
            log = k >= pre and (k - pre) % log_every == 0
            if log:
                I_1, I_2 = drive.I_1, drive.I_2
            ctrl[0], ctrl[1] = drive.step(k, omega_1, phi_g, omega_g)
            if log:
                rec[j] = (k_g * phi_g + g_f * qp[i_f], omega_1, phi_g, omega_g, qp[i_f], qv[i_f], self.grasp_force(),
                          I_1, I_2,
                          drive.I_ref_1, drive.I_ref_2, drive.U_1, drive.U_2)
                j += 1
            if tf_every and k >= pre and (k - pre) % tf_every == 0:
                frames.append(self.poses())
                self.states.append(qp.copy())
            step(m, d)
        check_mujoco(d, rec, s.t[::log_every])
        return Trace(s.t[::log_every], {name: rec[:, i] for i, name in enumerate(TRACE_FIELDS)}), np.array(frames)


def _hold_first(s: Schedule, ticks: int) -> Schedule:
    """The schedule with its first set points held for `ticks` more ticks in front."""
    def pad(a: np.ndarray, value: float | None = None) -> np.ndarray:
        return np.concatenate([np.full(ticks, a[0] if value is None else value), a])

    dt = s.t[1] - s.t[0]
    return Schedule(np.arange(ticks + s.ticks) * dt, pad(s.force), pad(s.current), pad(s.phi_sr),
                    pad(s.omega_sr, 0.0), pad(s.epsilon_sr, 0.0))

"""MuJoCo models generated from a paper's parameters (never downloaded).

`serial_arm` turns a standard-DH table plus link masses into an MJCF arm whose body frames are the DH
frames: body i carries joint i about its local z (the DH z_{i-1} axis), and body i+1 sits at
Tz(d_i)·Tx(a_i)·Rx(α_i) in it. The flange is a site at the last DH frame, so `mj_jacSite` on it is the
geometric Jacobian of the DH model.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from pipeline.core.experiment import Rule
from pipeline.robotics.dh import DH


def _fmt(v) -> str:
    return " ".join(f"{x:.17g}" for x in np.atleast_1d(v))


@dataclass(frozen=True)
class ArmDynamics:
    """What the DH table leaves out, as stated assumptions of the paper's config."""

    masses: Sequence[float]           # kg, one per link, placed at the midpoint of the DH segment
    link_radius: float                # m, radius of the capsule used for inertia and drawing
    armature: Sequence[float]         # kg·m², reflected rotor inertia per joint
    damping: Sequence[float]          # N·m·s/rad, joint viscous friction
    torque_limit: Sequence[float]     # N·m, per joint


def serial_arm(name: str, dh: DH, dyn: ArmDynamics, *, timestep: float, kp: Sequence[float],
               kv: Sequence[float], gravity_compensation: bool = True, base_pos: Sequence[float] = (0.0, 0.0, 0.0),
               flange_xml: str = "", world_xml: str = "", radii: Sequence[float] | None = None,
               dh_segments: bool = False) -> str:
    """MJCF of a DH arm driven by a joint PD servo per joint, evaluated every physics step.

    Controls are [q_ref (n), q̇_ref (n)]: a position actuator (gain kp) and a velocity actuator
    (gain kv) per joint, so the joint torque is kp·(q_ref − q) + kv·(q̇_ref − q̇) (+ gravity
    compensation), clamped to ±torque_limit at the joint. `base_pos` places DH frame 0 in the world;
    `flange_xml` adds elements in the last DH frame (a tool), `world_xml` in the world body (obstacles).
    `radii` gives each link its own capsule radius (default: `dyn.link_radius`); `dh_segments` draws a link
    with both d and a as two capsules along z (d) then x (a), the L the DH table describes, instead of one
    straight capsule between the two origins (the link's mass is split by length).
    """
    n = dh.n
    for label, seq in (("masses", dyn.masses), ("armature", dyn.armature), ("damping", dyn.damping),
                       ("torque_limit", dyn.torque_limit), ("kp", kp), ("kv", kv)):
        if len(seq) != n:
            raise ValueError(f"{label} needs {n} values, got {len(seq)}")
    gravcomp = ' gravcomp="1"' if gravity_compensation else ""
    body_xml: list[str] = []
    indent = "    "
    for i in range(n):
        seg = np.array([dh.a[i], 0.0, dh.d[i]])  # to the next DH origin, in this (rotated) body frame
        length = float(np.linalg.norm(seg))
        ca, sa = np.cos(dh.alpha[i] / 2), np.sin(dh.alpha[i] / 2)
        pad = indent * (i + 2)
        body_xml.append(f'{pad}<body name="link{i + 1}"{gravcomp}>')
        body_xml.append(
            f'{pad}  <joint name="joint{i + 1}" axis="0 0 1" armature="{dyn.armature[i]:.17g}" '
            f'damping="{dyn.damping[i]:.17g}" actuatorfrcrange="{-dyn.torque_limit[i]:.17g} '
            f'{dyn.torque_limit[i]:.17g}" ref="{-dh.theta_offset[i]:.17g}"/>')
        radius = dyn.link_radius if radii is None else radii[i]
        if dh_segments and abs(dh.a[i]) > 1e-9 and abs(dh.d[i]) > 1e-9:
            corner = np.array([0.0, 0.0, dh.d[i]])
            share = abs(dh.d[i]) / (abs(dh.d[i]) + abs(dh.a[i]))
            body_xml.append(f'{pad}  <geom type="capsule" fromto="0 0 0 {_fmt(corner)}" size="{radius}" '
                            f'mass="{dyn.masses[i] * share:.17g}"/>')
            body_xml.append(f'{pad}  <geom type="capsule" fromto="{_fmt(corner)} {_fmt(seg)}" size="{radius}" '
                            f'mass="{dyn.masses[i] * (1 - share):.17g}"/>')
        elif length > 1e-9:
            body_xml.append(f'{pad}  <geom type="capsule" fromto="0 0 0 {_fmt(seg)}" size="{radius}" '
                            f'mass="{dyn.masses[i]:.17g}"/>')
        else:
            body_xml.append(f'{pad}  <geom type="sphere" size="{radius}" mass="{dyn.masses[i]:.17g}"/>')
        # child frame: Tz(d) Tx(a) Rx(alpha)
        body_xml.append(f'{pad}  <frame pos="{_fmt(seg)}" quat="{ca:.17g} {sa:.17g} 0 0">')
        if i == n - 1:
            body_xml.append(f'{pad}    <site name="flange" size="0.01"/>{flange_xml}')
    closing = [f"{indent * (i + 2)}  </frame>\n{indent * (i + 2)}</body>" for i in reversed(range(n))]
    actuators = "\n".join(
        f'    <position name="pos{i + 1}" joint="joint{i + 1}" kp="{kp[i]:.17g}"/>' for i in range(n)) + "\n" + \
        "\n".join(f'    <velocity name="vel{i + 1}" joint="joint{i + 1}" kv="{kv[i]:.17g}"/>' for i in range(n))
    sensors = "\n".join(f'    <jointactuatorfrc name="tau{i + 1}" joint="joint{i + 1}"/>' for i in range(n))
    joint_opts = ' actuatorgravcomp="true"' if gravity_compensation else ""
    base = f' pos="{_fmt(base_pos)}"' if any(base_pos) else ""
    return f"""<mujoco model="{name}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{timestep:.17g}" integrator="implicitfast"/>
  <default>
    <joint{joint_opts}/>
    <geom contype="0" conaffinity="0" rgba="0.6 0.65 0.7 1"/>
  </default>
  <worldbody>
    <geom type="cylinder" size="0.06 0.01" pos="0 0 -0.01" rgba="0.3 0.3 0.3 1"/>
    <body name="base"{base}>
{chr(10).join(body_xml)}
{chr(10).join(closing)}
    </body>{world_xml}
  </worldbody>
  <actuator>
{actuators}
  </actuator>
  <sensor>
{sensors}
    <framepos name="flange_pos" objtype="site" objname="flange"/>
    <framequat name="flange_quat" objtype="site" objname="flange"/>
  </sensor>
</mujoco>
"""


class ServoMJCF(str):
    """An MJCF text from `with_servo_gains`: the text itself (attached to runs, compiled by whoever needs the
    model) that also knows its zero-gain text and its gains, so `servo_rollout` sets the gains on the stage's
    one servo model instead of compiling the text again."""

    zero: str
    kp: np.ndarray
    kv: np.ndarray


def with_servo_gains(build: Callable[[np.ndarray, np.ndarray], str], q0: np.ndarray, bandwidth_hz: float,
                     damping_ratio: float) -> ServoMJCF:
    """The MJCF `build(kp, kv)` makes, with each joint servo tuned to a natural frequency and damping ratio at
    q0: kp = m·ω², kv = 2ζ·m·ω, m the diagonal of the joint-space inertia (armature included) at q0."""
    import mujoco

    zero = build(np.zeros(len(q0)), np.zeros(len(q0)))  # the same for every run of a stage
    servo = _servo(zero, build)
    servo.data.qpos[:] = q0
    mujoco.mj_forward(servo.model, servo.data)  # the inertia does not depend on the gains the model holds
    inertia = np.zeros((servo.model.nv, servo.model.nv))
    mujoco.mj_fullM(servo.model, servo.data, inertia)
    m, w = np.diag(inertia), 2 * np.pi * bandwidth_hz
    kp, kv = m * w * w, 2 * damping_ratio * m * w
    xml = ServoMJCF(build(kp, kv))
    xml.zero, xml.kp, xml.kv = zero, kp, kv
    return xml


@dataclass
class _Servo:
    """A stage's servo model (its own, mutable: each run sets its gains), its data, and how the gains enter
    the actuators: (gainprm, biasprm) = zero + per_kp · kp[dof] + per_kv · kv[dof], from the zero-gain model
    and two probe compiles (MJCF's position and velocity servos are linear in kp and kv). `linear` is False
    when the probes differ in anything else; runs then compile their own text."""

    model: object
    data: object
    dof: np.ndarray  # the joint dof each actuator drives
    zero: np.ndarray  # (2, nu, 10): gainprm and biasprm at zero gains
    per_kp: np.ndarray
    per_kv: np.ndarray
    linear: bool

    def with_gains(self, kp: np.ndarray, kv: np.ndarray):
        import mujoco

        gains = self.zero + self.per_kp * kp[self.dof, None] + self.per_kv * kv[self.dof, None]
        self.model.actuator_gainprm[:], self.model.actuator_biasprm[:] = gains
        mujoco.mj_resetData(self.model, self.data)
        return self.model, self.data


_SERVOS: dict[str, _Servo] = {}


def _servo(zero: str, build: Callable[[np.ndarray, np.ndarray], str]) -> _Servo:
    """The servo model of a zero-gain MJCF text, made once per process (a few stages' worth are kept)."""
    import mujoco

    servo = _SERVOS.get(zero)
    if servo is None:
        model = mujoco.MjModel.from_xml_string(zero)
        n = model.nv
        probes = [mujoco.MjModel.from_xml_string(build(np.full(n, p), np.full(n, v))) for p, v in ((1.0, 0.0),
                                                                                                   (0.0, 1.0))]
        zero_gains, kp_gains, kv_gains = (np.stack([m.actuator_gainprm, m.actuator_biasprm])
                                          for m in (model, *probes))
        for probe in probes:  # with the zero model's gains, a probe must be the zero model byte for byte
            probe.actuator_gainprm[:], probe.actuator_biasprm[:] = zero_gains
        linear = ((model.actuator_trntype == mujoco.mjtTrn.mjTRN_JOINT).all()
                  and all(np.array_equal(_saved(probe), _saved(model)) for probe in probes))
        servo = _Servo(model, mujoco.MjData(model), model.jnt_dofadr[model.actuator_trnid[:, 0]], zero_gains,
                       kp_gains - zero_gains, kv_gains - zero_gains, bool(linear))
        if len(_SERVOS) >= 8:
            del _SERVOS[next(iter(_SERVOS))]
        _SERVOS[zero] = servo
    return servo


def _saved(model) -> np.ndarray:
    """A model as MuJoCo saves it (MJB): every array and name, to compare two models at once."""
    import mujoco

    buffer = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer


# What a config of an IK-then-servo experiment (servo_rollout) must satisfy between its time steps.
SERVO_RULES = (
    Rule(("execute.dt", "scenario.ik_dt"), lambda dt, ik_dt: dt <= ik_dt,
         "execute.dt={0:g} s must not exceed scenario.ik_dt={1:g} s: the servo runs at least as often as the IK"),
    Rule(("execute.log_dt", "execute.dt"), lambda log_dt, dt: log_dt >= dt,
         "execute.log_dt={0:g} s is shorter than the physics step execute.dt={1:g} s"),
    Rule(("execute.log_dt", "scenario.duration"), lambda log_dt, T: log_dt <= T / 10,
         "execute.log_dt={0:g} s leaves fewer than 10 samples of the {1:g} s path"),
)


@functools.lru_cache(maxsize=8)
def compiled(xml: str):
    """The `MjModel` of an MJCF text, compiled once per process. Read-only: whoever needs to change a model
    compiles their own."""
    import mujoco

    return mujoco.MjModel.from_xml_string(xml)


def servo_rollout(xml: str, q_ref: np.ndarray, qd_ref: np.ndarray, times: np.ndarray, *, moving_start: bool = False
                  ) -> tuple[np.ndarray, np.ndarray]:
    """A whole servoed run in one C call: the model's actuators are the joint servo (controls [q_ref, q̇_ref],
    as `serial_arm` builds them), started on q_ref[0], at rest or (`moving_start`) already at q̇_ref[0].
    Returns (states, sensors), one row per step, each the state after the step (full physics state: time,
    qpos, qvel, …)."""
    import mujoco
    from mujoco import rollout

    servo = _SERVOS.get(xml.zero) if isinstance(xml, ServoMJCF) else None
    if servo is not None and servo.linear:  # the stage's servo model with this run's gains: no compile
        model, data = servo.with_gains(xml.kp, xml.kv)
    else:
        model = compiled(xml)
        data = mujoco.MjData(model)
    data.qpos[:] = q_ref[0]
    if moving_start:
        data.qvel[:] = qd_ref[0]
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    states, sensors = rollout.rollout(model, data, state0, np.concatenate([q_ref, qd_ref], axis=1)[None])
    check_mujoco(data, states[0], times)
    return states[0], sensors[0]


# MuJoCo does not return NaN when a simulation blows up: it warns and resets the state. These warnings
# therefore mark a run as failed.
_UNSTABLE = ("mjWARN_BADQACC", "mjWARN_BADQVEL", "mjWARN_BADQPOS", "mjWARN_BADCTRL")


def check_mujoco(data, states: np.ndarray, times: np.ndarray) -> None:
    """Raise SimulationFailed if a rollout went non-finite or MuJoCo flagged it unstable."""
    import mujoco

    from pipeline.core.runlog import SimulationFailed

    if not np.isfinite(states).all():
        bad = int(np.argmax(~np.isfinite(states).all(axis=1)))
        raise SimulationFailed(f"state not finite at t = {times[bad]:.4g} s")
    for name in _UNSTABLE:
        warning = data.warning[int(getattr(mujoco.mjtWarning, name))]
        if warning.number:
            raise SimulationFailed(f"MuJoCo {name.removeprefix('mjWARN_')} ({warning.number}×): the simulation "
                                   "diverged (time step too large for the gains?)")


def qpos_units(model) -> list[str]:
    """The unit of each qpos coordinate of a MuJoCo model (what `/joint_state` needs): rad for a hinge, m for a
    slide, m and a unit quaternion (1) for a free joint's position and orientation, 1 for a ball's quaternion."""
    import mujoco

    per_type = {mujoco.mjtJoint.mjJNT_HINGE: ["rad"], mujoco.mjtJoint.mjJNT_SLIDE: ["m"],
                mujoco.mjtJoint.mjJNT_BALL: ["1"] * 4, mujoco.mjtJoint.mjJNT_FREE: ["m"] * 3 + ["1"] * 4}
    return [u for kind in model.jnt_type for u in per_type[mujoco.mjtJoint(kind)]]

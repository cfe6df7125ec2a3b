"""MuJoCo: the independent physics of an SRC joint (Sec. V-A), and clearance by MuJoCo's own geometry.

The joint: B_{i-1} is fixed at the origin; B_i is a free sphere on top of it, held by an attraction force
towards B_{i-1}'s centre (the magnet; its line passes through the contact point and both centres) and by
frictional contact with sliding and torsional friction (condim 4) and MuJoCo's no-slip pass, so slip and
spin are suppressed as far as the soft contact allows. The trolley is a torque on B_i, tangent to the
contact plane, from a PI servo that holds the measured rate of B_i relative to the tangent plane, Ω^B, at
the command. Ω^B is measured the way the paper defines it: the tangent frame P_i is carried along the
measured contact normal without spin (parallel transport), and Ω^B = R_Pᵀ(ω − n × ṅ).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.src_joint.model import cross


def _fmt(v) -> str:
    return " ".join(f"{x:.17g}" for x in np.atleast_1d(v))


@dataclass(frozen=True)
class ContactPhysics:
    """What the paper's Simscape model has but does not state (all assumptions)."""

    dt: float                  # s, MuJoCo step (= servo period)
    mass: float                # kg, mass of B_i (solid-sphere inertia)
    magnet_force: float        # N, attraction of B_i towards B_{i-1}
    friction: list[float]      # [sliding, torsional (m), rolling (m)] coefficients of the contact
    solref: list[float]        # MuJoCo contact stiffness/damping: [time constant (s), damping ratio]
    solimp: list[float]        # MuJoCo contact impedance [d0, dwidth, width (m)]
    noslip_iterations: int     # MuJoCo's post-solve pass that removes slip
    noslip_tolerance: float    # and its convergence tolerance (also the main solver's)
    gravity: list[float]       # m/s², in ΣI (= ΣB_{i-1})
    servo_bandwidth_hz: float  # PI servo on Ω^B
    settle_time: float         # s the magnet holds B_i at rest before the drive starts (t = 0 after it)


def joint_xml(lower: float, upper: float, p: ContactPhysics) -> str:
    """MJCF of the Sec. V-A joint: fixed sphere l_{i-1} = lower at the origin, free sphere l_i = upper on it."""
    contact = (f'condim="4" friction="{_fmt(p.friction)}" solref="{_fmt(p.solref)}" '
               f'solimp="{_fmt(p.solimp)}"')
    return f"""<mujoco model="src-joint">
  <option timestep="{p.dt:.17g}" gravity="{_fmt(p.gravity)}" cone="elliptic" integrator="implicitfast"
          noslip_iterations="{p.noslip_iterations}" noslip_tolerance="{p.noslip_tolerance:.17g}"
          tolerance="{p.noslip_tolerance:.17g}"/>
  <worldbody>
    <geom name="B0" type="sphere" size="{lower:.17g}" {contact} rgba="0.55 0.6 0.7 1"/>
    <body name="B1" pos="0 0 {lower + upper:.17g}">
      <freejoint/>
      <geom name="B1" type="sphere" size="{upper:.17g}" mass="{p.mass:.17g}" {contact} rgba="0.9 0.6 0.2 1"/>
    </body>
  </worldbody>
</mujoco>
"""


@dataclass
class JointRecording:
    """What a plant measured at the log times (N + 1 samples), and the rate that drove each interval (N)."""

    times: np.ndarray             # (N+1,) s
    interval_rates: np.ndarray    # (N, 2) Ω^B, mean over each log interval
    rates: np.ndarray             # (N+1, 3) Ω^B at the log times (z: spin relative to P)
    rotation: np.ndarray          # (N+1, 3, 3) ^{B_{i-1}}R_{B_i}
    tangent: np.ndarray           # (N+1, 3, 3) ^{B_{i-1}}R_{P_i}
    joint_velocity: np.ndarray    # (N+1, 3) ^{B_{i-1}}ω_{B_i} expressed in P_i
    spatial_velocity: np.ndarray  # (N+1, 6) [ω; v] of B_i relative to B_{i-1}, in B_{i-1}
    torque: np.ndarray | None = None      # (N+1, 3) servo torque on B_i (N·m), ΣI
    contact: np.ndarray | None = None     # (N+1, 3) penetration (m), normal force (N), friction force (N)


def roll_in_mujoco(lower: float, upper: float, command: np.ndarray, duration: float, log_dt: float,
                   p: ContactPhysics) -> tuple[JointRecording, str]:
    """Drive B_i at Ω^B = command (2,) on the fixed B_{i-1} for `duration`; (recording, MJCF)."""
    import mujoco

    from pipeline.robotics.mjcf import check_mujoco

    xml = joint_xml(lower, upper, p)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    for _ in range(round(p.settle_time / p.dt)):   # the contact takes up the magnet's force, no drive yet
        data.xfrc_applied[1, :3] = -p.magnet_force * data.qpos[:3] / np.linalg.norm(data.qpos[:3])
        mujoco.mj_step(model, data)
    steps, every = round(duration / p.dt), round(log_dt / p.dt)
    n_log = steps // every
    inertia = 0.4 * p.mass * upper ** 2 + p.mass * upper ** 2      # about the contact point
    w_b = 2 * np.pi * p.servo_bandwidth_hz
    kp, ki = 2.0 * w_b * inertia, w_b ** 2 * inertia                  # critically damped PI on Ω^B
    command = np.asarray(command, dtype=float)

    rec = JointRecording(
        times=np.arange(n_log + 1) * log_dt, interval_rates=np.zeros((n_log, 2)), rates=np.zeros((n_log + 1, 3)),
        rotation=np.zeros((n_log + 1, 3, 3)), tangent=np.zeros((n_log + 1, 3, 3)),
        joint_velocity=np.zeros((n_log + 1, 3)), spatial_velocity=np.zeros((n_log + 1, 6)),
        torque=np.zeros((n_log + 1, 3)), contact=np.zeros((n_log + 1, 3)))
    # MuJoCo's own 3-vector and quaternion routines: this runs every step, and NumPy's per-call cost dominates
    plane = np.array([1.0, 0.0, 0.0, 0.0])        # orientation of P_i (quaternion), carried without spin
    R_P, body = np.eye(3), np.eye(3)               # body from qpos: after mj_step, data.xmat is a step old
    normal, n_new, turn, c = np.array([0.0, 0.0, 1.0]), np.zeros(3), np.zeros(4), np.zeros(3)
    omega, omega_p, rates = np.zeros(3), np.zeros(3), np.zeros(3)
    integral = np.zeros(2)
    torque = np.zeros(3)
    qpos, qvel, xfrc = data.qpos, data.qvel, data.xfrc_applied
    force6 = np.zeros(6)
    states = np.zeros((n_log + 1, 13))

    def measure() -> None:
        """Ω^B (in P), ω and the contact normal of the current state; carries P along the normal."""
        mujoco.mju_quat2Mat(body.reshape(9), qpos[3:7])
        dist = mujoco.mju_norm3(qpos[:3])
        n_new[:] = qpos[:3] / dist
        # the smallest rotation taking the old normal to the new one: q ∝ [1 + a·b, a × b]
        mujoco.mju_cross(c, normal, n_new)
        turn[0], turn[1:] = 1.0 + normal @ n_new, c
        mujoco.mju_normalize4(turn)
        mujoco.mju_mulQuat(plane, turn, plane.copy())
        mujoco.mju_quat2Mat(R_P.reshape(9), plane)
        normal[:] = n_new
        mujoco.mju_mulMatVec(omega, body, qvel[3:6])   # the free joint's ω is in the body frame
        v = qvel[:3]
        mujoco.mju_cross(omega_p, normal, (v - (v @ normal) * normal) / dist)   # n × ṅ
        mujoco.mju_mulMatTVec(rates, R_P, omega - omega_p)

    def record(j: int) -> None:
        rec.rates[j], rec.rotation[j], rec.tangent[j] = rates, body, R_P
        rec.joint_velocity[j] = R_P.T @ omega
        rec.spatial_velocity[j] = np.r_[omega, qvel[:3]]
        rec.torque[j] = torque
        normal_force = friction = 0.0
        for c in range(data.ncon):
            mujoco.mj_contactForce(model, data, c, force6)
            normal_force += force6[0]
            friction += np.hypot(force6[1], force6[2])
        penetration = np.sqrt(qpos[:3] @ qpos[:3]) - (lower + upper)
        rec.contact[j] = penetration, normal_force, friction
        states[j, :7], states[j, 7:] = qpos, qvel

    measure()
    record(0)
    interval_sum = np.zeros(2)
    for k in range(steps):
        error = command - rates[:2]
        integral += error * p.dt
        torque = R_P[:, :2] @ (kp * error + ki * integral)
        xfrc[1, :3] = -p.magnet_force * normal
        xfrc[1, 3:] = torque
        mujoco.mj_step(model, data)
        # semi-implicit Euler: the new velocity is the one that moved the bodies during this step
        measure()
        interval_sum += rates[:2]
        if (k + 1) % every == 0:
            j = (k + 1) // every
            rec.interval_rates[j - 1] = interval_sum / every
            interval_sum[:] = 0.0
            record(j)
    check_mujoco(data, states, rec.times)
    return rec, xml


def contact_paths(lower: float, upper: float, tangent: np.ndarray, rotation_: np.ndarray) -> tuple[np.ndarray,
                                                                                                  np.ndarray]:
    """Length of the path the contact point has traced on B_{i-1} and on B_i (each in its own body frame) up to
    each sample, from the tangent frames (N, 3, 3) and relative rotations (N, 3, 3): equal when nothing slips."""
    normal = tangent[:, :, 2]
    on_lower = lower * normal
    on_upper = -upper * np.einsum("nji,nj->ni", rotation_, normal)
    return tuple(np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))] for p in (on_lower, on_upper))


def roll_exactly(lower: float, upper: float, command: np.ndarray, duration: float,
                 log_dt: float) -> JointRecording:
    """The same joint in the exact rolling integrator (module `rolling`), Ω^B = command throughout."""
    from pipeline.papers.src_joint.rolling import RollingChain

    plant = RollingChain([lower, upper])
    n_log = round(duration / log_dt)
    rates = np.tile(np.asarray(command, dtype=float), (n_log, 1))
    rotation, tangent = np.zeros((n_log + 1, 3, 3)), np.zeros((n_log + 1, 3, 3))
    omega = np.zeros((n_log + 1, 3))
    for j in range(n_log + 1):
        rotation[j], tangent[j] = plant.relative[0], plant.tangent[0]
        omega[j] = plant.relative_velocity(rates[:1])[0]
        if j < n_log:
            plant.roll(rates[j:j + 1], log_dt)
    normal = tangent[:, :, 2]
    v = upper * cross(omega, normal)                       # the contact point of B_i is at rest
    return JointRecording(
        times=np.arange(n_log + 1) * log_dt, interval_rates=rates, rates=np.c_[np.vstack([rates, rates[-1:]]),
                                                                                np.zeros(n_log + 1)],
        rotation=rotation, tangent=tangent, joint_velocity=np.einsum("nji,nj->ni", tangent, omega),
        spatial_velocity=np.c_[omega, v])


# -- clearance by MuJoCo geometry (Sec. V-C check) ---------------------------------------------------------


def scene_xml(radii: np.ndarray, bar_points: np.ndarray, bar_axis: np.ndarray, bar_radius: float,
              bar_half_length: float) -> str:
    """Spheres as mocap bodies and the bars as capsules: a model for `mj_geomDistance` and for drawing."""
    axis = np.asarray(bar_axis, dtype=float) / np.linalg.norm(bar_axis)
    spheres = "\n".join(f'    <body name="B{i}" mocap="true"><geom name="B{i}" type="sphere" size="{r:.17g}"/></body>'
                        for i, r in enumerate(radii))
    bars = []
    for k, point in enumerate(bar_points):
        ends = np.r_[point - bar_half_length * axis, point + bar_half_length * axis]
        bars.append(f'    <geom name="bar{k + 1}" type="capsule" size="{bar_radius:.17g}" fromto="{_fmt(ends)}"/>')
    return f"""<mujoco model="src-manipulator-scene">
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
{spheres}
{chr(10).join(bars)}
  </worldbody>
</mujoco>
"""


def mujoco_clearance(xml: str, centres: np.ndarray) -> np.ndarray:
    """(T, k, m) signed distances of the k spheres to the m bars, by `mj_geomDistance`, for the sphere
    centres (T, k, 3) of a replayed run."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    spheres = [model.geom(f"B{i}").id for i in range(centres.shape[1])]
    bars = [g for g in range(model.ngeom) if model.geom(g).name.startswith("bar")]
    out = np.zeros((len(centres), len(spheres), len(bars)))
    for t, frame in enumerate(centres):
        data.mocap_pos[:] = frame
        mujoco.mj_kinematics(model, data)
        for i, s in enumerate(spheres):
            for j, b in enumerate(bars):
                out[t, i, j] = mujoco.mj_geomDistance(model, data, s, b, 1.0, None)
    return out

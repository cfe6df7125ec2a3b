"""The paper's motivating application: a snake robot of 2-DOF joints whose body takes the shape of a moving
curve, its joint references computed by the algorithm at every control step.

The MuJoCo model is generated from a `Chain`: segment i is a capsule along its body's x axis from Q_i to
Q_{i+1}; the head (segment 1, the paper's frame 1) is a free body; each internal 2-DOF joint is two hinges in
one body, about y (even joint 2i) then about z (odd joint 2i + 1), the order of eq. (10) and Thm 4.2. Joint 1
(θ_1 = 0) and a tip joint without a following segment are not in the model.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pipeline.core.timing import Timing, time_calls
from pipeline.papers.curve_discretization.algorithm import Chain, Curve, joint_angles, joint_parameters
from pipeline.robotics.transforms import quaternion_wxyz

WARMUP_CALLS = 20  # untimed calls of the algorithm before the control loop
CHAIN_RADIUS = 0.08  # of the segment length: a drawn chain's capsules (Fig. 2 draws the chain as a line)


@dataclass(frozen=True)
class SnakeBody:
    """What the paper leaves out: the snake's physical build (assumptions of the experiment config)."""

    radius: float          # m, capsule radius
    segment_mass: float    # kg per segment
    armature: float        # kg·m², reflected rotor inertia per hinge
    damping: float         # N·m·s/rad, hinge viscous friction
    torque_limit: float    # N·m per hinge
    friction: float        # sliding friction coefficient against the ground


def joint_names(chain: Chain) -> list[str]:
    """The actuated joints 2 … 2n − 1 (the 2-DOF joints at Q_1 … Q_{n−1})."""
    return [f"joint{m}" for m in range(2, 2 * chain.segments)]


def point_names(chain: Chain) -> list[str]:
    """The distinct joint points Q_0 … Q_n, named by their first joint: joint1, joint2, joint4, …, joint2n."""
    return ["joint1", *(f"joint{2 * i}" for i in range(1, chain.segments + 1))]


def snake_mjcf(chain: Chain, body: SnakeBody, *, timestep: float, kp: float, kv: float, floor: bool = True) -> str:
    """MJCF of the snake on a floor (or in the air), driven per hinge by kp·(q_ref − q) + kv·(q̇_ref − q̇),
    clamped to the torque limit. Controls: [q_ref (J), q̇_ref (J)] in the order of `joint_names`."""
    lengths = chain.segment_lengths
    names = joint_names(chain)
    parts: list[str] = []
    for i, length in enumerate(lengths):
        pad = "    " * (i + 2)
        if i == 0:
            parts.append(f'{pad}<body name="segment1">\n{pad}  <freejoint name="head"/>')
        else:
            parts.append(f'{pad}<body name="segment{i + 1}" pos="{lengths[i - 1]:.17g} 0 0">')
            parts.append(f'{pad}  <joint name="joint{2 * i}" axis="0 1 0"/>')
            parts.append(f'{pad}  <joint name="joint{2 * i + 1}" axis="0 0 1"/>')
        parts.append(f'{pad}  <geom fromto="0 0 0 {length:.17g} 0 0"/>')
    parts.append(f'{"    " * (len(lengths) + 1)}  <site name="tip" pos="{lengths[-1]:.17g} 0 0"/>')
    closing = [f'{"    " * (i + 2)}</body>' for i in reversed(range(len(lengths)))]
    actuators = [f'    <position joint="{j}" kp="{kp:.17g}"/>' for j in names]
    actuators += [f'    <velocity joint="{j}" kv="{kv:.17g}"/>' for j in names]
    ground = """    <light pos="0 0 4" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="0 0 0.1" contype="0" conaffinity="1" rgba="0.8 0.8 0.8 1"/>
""" if floor else ""
    return f"""<mujoco model="snake_{chain.joints}_joints">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{timestep:.17g}" integrator="implicitfast"/>
  <default>
    <joint type="hinge" armature="{body.armature:.17g}" damping="{body.damping:.17g}"
           actuatorfrcrange="{-body.torque_limit:.17g} {body.torque_limit:.17g}"/>
    <geom type="capsule" size="{body.radius:.17g}" mass="{body.segment_mass:.17g}" contype="1" conaffinity="0"
          friction="{body.friction:.17g} 0.005 0.0001" rgba="0.35 0.55 0.3 1"/>
  </default>
  <worldbody>
{ground}{chr(10).join(parts)}
{chr(10).join(closing)}
  </worldbody>
  <actuator>
{chr(10).join(actuators)}
  </actuator>
</mujoco>
"""


def chain_mjcf(chain: Chain) -> str:
    """The chain alone, as the snake's body in the air (no floor, no physics of interest): what the Fig. 2
    runs check their kinematics on and draw. Segment i + 1's frame is the paper's frame 2i + 1 (θ_1 = 0), its
    origin Q_i; the capsules' radius is a drawing choice, CHAIN_RADIUS of the shortest segment."""
    body = SnakeBody(radius=CHAIN_RADIUS * float(chain.segment_lengths.min()), segment_mass=1.0, armature=0.0,
                     damping=0.0, torque_limit=1.0, friction=1.0)
    return snake_mjcf(chain, body, timestep=1e-3, kp=1.0, kv=0.0, floor=False)


def configuration(points: np.ndarray, R_w1: np.ndarray, theta: np.ndarray, offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    """qpos putting the head at Q_0 + offset with orientation R_w1 and the hinges at θ_2 … θ_{2n−1}."""
    hinges = theta[1:2 * (len(points) - 1) - 1]
    return np.concatenate([points[0] + np.asarray(offset), quaternion_wxyz(R_w1), hinges])


@dataclass(frozen=True)
class GaitRun:
    """One gait in MuJoCo, sampled at the control instants."""

    times: np.ndarray           # (K,) s
    q_ref: np.ndarray           # (K, J) rad: the algorithm's joint angles for the curve at times[k]
    qd_ref: np.ndarray          # (K, J) rad/s: backward difference of q_ref over the control period
    q: np.ndarray               # (K, J) measured hinge angles at times[k]
    qd: np.ndarray              # (K, J) rad/s
    tau: np.ndarray             # (K, J) N·m, actuator torque of the last physics step before times[k]
    qpos: np.ndarray            # (K, nq) full configuration (head pose + hinges)
    body: np.ndarray            # (K, n+1, 3) the body's joint points in the world
    target: np.ndarray          # (K, n+1, 3) the curve's joint points in the algorithm's frame 1
    seconds: dict[str, np.ndarray]  # (K,) per control step, as the controller ran them: search, angles
    warm_vs_cold: WarmVsCold | None  # the searches of steps 1 … K−1 again, warm-started and from scratch


@dataclass(frozen=True)
class WarmVsCold:
    """Sec. IV-D's suggestion measured: each step's search warm-started from the previous step's solution and
    from scratch, timed alike (time_calls: warm-up, gc off, one call per step)."""

    timings: list[Timing]            # search_warm, search_cold
    evaluations: dict[str, np.ndarray]
    gap: np.ndarray                  # max |t_warm − t_cold| per step: both must find the same crossings


def warm_vs_cold(chain: Chain, curves: list[Curve], parameters: list[np.ndarray], dt: float,
                 tol: float) -> WarmVsCold:
    """`parameters[k]` is the solution of `curves[k]`; step k ≥ 1 is warm-started from step k − 1's."""
    warm = [(curve, chain, dt, tol, np.diff(previous)) for curve, previous in zip(curves[1:], parameters[:-1],
                                                                                   strict=True)]
    cold = [args[:4] for args in warm]
    timings = [time_calls("search_warm", joint_parameters, warm, warmup=WARMUP_CALLS),
               time_calls("search_cold", joint_parameters, cold, warmup=WARMUP_CALLS)]
    results = {"search_warm": [joint_parameters(*args) for args in warm],
               "search_cold": [joint_parameters(*args) for args in cold]}
    evaluations = {name: np.array([r.evaluations for r in rs]) for name, rs in results.items()}
    gap = np.array([np.abs(w.t - c.t).max() for w, c in zip(*results.values(), strict=True)])
    return WarmVsCold(timings, evaluations, gap)


def run_gait(chain: Chain, body: SnakeBody, curve_at: Callable[[float], Curve], theta_x0: float, dt_search: float,
             tol: float, xml: str, *, control_dt: float, duration: float, warm_start: bool,
             compare_warm_cold: bool = True) -> GaitRun:
    """At every control step solve the curve of that instant (each stage timed), then hold the references for
    the control period. The snake starts at rest in the shape of the curve at t = 0, lying on the floor.
    The algorithm is warmed up on that curve first (numba loads its compiled code at the first call).
    Afterwards (`compare_warm_cold`) the searches are timed again warm-started and from scratch."""
    import mujoco

    from pipeline.robotics.mjcf import check_mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    segment_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"segment{i + 1}")
                   for i in range(chain.segments)]
    tip = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip")
    substeps = round(control_dt / model.opt.timestep)
    steps = round(duration / control_dt) + 1
    n = len(joint_names(chain))
    seconds = {name: np.empty(steps) for name in ("search", "angles")}
    q_ref, qd_ref, q, qd, tau = (np.zeros((steps, n)) for _ in range(5))
    body_pts, target = np.empty((steps, chain.segments + 1, 3)), np.empty((steps, chain.segments + 1, 3))
    qpos = np.empty((steps, model.nq))
    curves: list[Curve] = []
    parameters: list[np.ndarray] = []
    clock = time.perf_counter_ns
    for _ in range(WARMUP_CALLS):
        joint_angles(joint_parameters(curve_at(0.0), chain, dt_search, tol).points, theta_x0, chain.joints)
    enabled = gc.isenabled()
    gc.disable()  # as in time_calls: no collector pauses inside the timed calls
    try:
        for k in range(steps):
            curve = curve_at(k * control_dt)
            # Sec. IV-D: the previous solution initializes the next search
            increments = np.diff(parameters[-1]) if warm_start and parameters else None
            start = clock()
            search = joint_parameters(curve, chain, dt_search, tol, increments)
            middle = clock()
            angles = joint_angles(search.points, theta_x0, chain.joints)
            end = clock()
            seconds["search"][k], seconds["angles"][k] = (middle - start) * 1e-9, (end - middle) * 1e-9
            curves.append(curve)
            parameters.append(search.t)
            points = search.points
            q_ref[k] = angles.theta[1:n + 1]
            if k:
                qd_ref[k] = (q_ref[k] - q_ref[k - 1]) / control_dt
            data.ctrl[:n], data.ctrl[n:] = q_ref[k], qd_ref[k]
            if k == 0:  # at rest in the curve's shape, its lowest point on the floor
                lift = body.radius - points[:, 2].min() + 1e-4
                data.qpos[:] = configuration(points, angles.R_w1, angles.theta, (0.0, 0.0, lift))
                mujoco.mj_forward(model, data)
            target[k] = (points - points[0]) @ angles.R_w1
            q[k], qd[k], qpos[k], tau[k] = data.qpos[7:], data.qvel[6:], data.qpos, data.qfrc_actuator[6:]
            body_pts[k, :-1], body_pts[k, -1] = data.xpos[segment_ids], data.site_xpos[tip]
            mujoco.mj_step(model, data, nstep=substeps)
    finally:
        if enabled:
            gc.enable()
    times = np.arange(steps) * control_dt
    check_mujoco(data, qpos, times)
    return GaitRun(times, q_ref, qd_ref, q, qd, tau, qpos, body_pts, target, seconds,
                   warm_vs_cold(chain, curves, parameters, dt_search, tol) if compare_warm_cold else None)


def shape_fit(body: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The curve's joint points placed on the body by the best rigid motion (Kabsch, least squares), batched:
    (K, n+1, 3) placed points in the world and (K, n+1) the distance of each body point from its curve point.
    The shape error does not depend on where the snake is or which segment serves as reference."""
    body_c = body - body.mean(axis=1, keepdims=True)
    target_c = target - target.mean(axis=1, keepdims=True)
    U, _, Vt = np.linalg.svd(np.einsum("kpi,kpj->kij", target_c, body_c))
    d = np.sign(np.linalg.det(U @ Vt))  # no reflections
    Vt[:, -1] *= d[:, None]
    R = np.swapaxes(U @ Vt, 1, 2)
    placed = np.einsum("kij,kpj->kpi", R, target_c) + body.mean(axis=1, keepdims=True)
    return placed, np.linalg.norm(placed - body, axis=2)


def segment_frames(xml: str, qpos: np.ndarray, chain: Chain) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's own kinematics at each configuration: (K, n, 4, 4) segment frames in the world and (K, n+1, 3)
    the body's joint points (segment origins and the tip)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"segment{i + 1}") for i in range(chain.segments)]
    qpos = np.atleast_2d(qpos)
    frames = np.tile(np.eye(4), (len(qpos), chain.segments, 1, 1))
    points = np.empty((len(qpos), chain.segments + 1, 3))
    for k, configuration_k in enumerate(qpos):
        data.qpos[:] = configuration_k
        mujoco.mj_kinematics(model, data)
        frames[k, :, :3, :3] = data.xmat[ids].reshape(-1, 3, 3)
        frames[k, :, :3, 3] = data.xpos[ids]
        points[k] = np.vstack([data.xpos[ids], data.site("tip").xpos])
    return frames, points

"""A planned path executed by a MuJoCo model of the arm under a joint servo (our extension).

Post-processing (Secs. 3.5.2, 4.2.5): the joint path is q_i, the C.q of the path's vertices, and the goal
configuration found by a numerical IK started at the last vertex (the plan is its "perfect initial guess"). It is
interpolated linearly in joint space (large C-space steps occur near singularities) and timed by one trapezoidal
velocity profile over its joint-space arc length. The MuJoCo arm (generated from the DH table) follows it under
the joint PD servo of `pipeline.robotics.mjcf` at every physics step (`mjcf.servo_rollout`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from pipeline.papers.kinematic_graph.arms import RegionalArm
from pipeline.papers.kinematic_graph.collision import Boxes
from pipeline.robotics.dh import DH
from pipeline.robotics.profiles import trapezoid


def obstacles_xml(boxes: Boxes) -> str:
    """Box obstacles as world geoms named `obstacle/<name>` (they collide with nothing in the simulation; the
    checkers switch their collisions on)."""
    return "".join(
        f'\n    <geom name="obstacle/{n}" type="box" pos="{c[0]:.17g} {c[1]:.17g} {c[2]:.17g}" '
        f'size="{h[0]:.17g} {h[1]:.17g} {h[2]:.17g}" contype="0" conaffinity="0" rgba="0.8 0.45 0.2 0.6"/>'
        for n, c, h in zip(boxes.names, boxes.centre, boxes.half, strict=True))


def arm_xml(name: str, node: Mapping, boxes: Boxes, q0: np.ndarray, timestep: float, bandwidth_hz: float,
            damping_ratio: float) -> str:
    """MJCF of the whole arm of a `system.<arm>` node (every DH row; the wrist joints of a 6R are held by the
    servo), the obstacles, and a site `pw` at P_w (the flange: d6 = 0 for a spherical wrist, the tip of a 2R);
    servo gains tuned at q0."""
    from pipeline.robotics.mjcf import ArmDynamics, serial_arm, with_servo_gains

    dh = DH.from_config(node["dh"])
    dyn = ArmDynamics(masses=list(node["masses"]), link_radius=float(node["link_radius"]),
                      armature=list(node["armature"]), damping=list(node["damping"]),
                      torque_limit=list(node["torque_limit"]))
    full_q0 = np.zeros(dh.n)
    full_q0[: len(q0)] = q0

    def build(kp, kv) -> str:
        return serial_arm(name, dh, dyn, timestep=timestep, kp=list(kp), kv=list(kv),
                          gravity_compensation=True, world_xml=obstacles_xml(boxes))

    return with_servo_gains(build, full_q0, bandwidth_hz, damping_ratio)


def checked_links(node: Mapping) -> list[int]:
    """Links whose collisions are checked: all but a first link that lies along its own joint axis (a1 = 0:
    the base column of a 6R turns in place, its collision state never changes)."""
    n = len(node["dh"]["a"])
    first = 1 if float(node["dh"]["a"][0]) == 0.0 else 0
    return list(range(1 + first, n + 1))


def ik_newton(arm: RegionalArm, q0: np.ndarray, goal: np.ndarray, iterations: int = 100, tol: float = 1e-9,
              damping: float = 1e-3, max_step: float = 0.2) -> tuple[np.ndarray, bool]:
    """Damped least squares from q0 to P_w = goal (Sec. 4.2.5), steps of at most `max_step` rad (so that it stays
    on q0's branch), kept inside the joint limits."""
    q = np.array(q0, dtype=float)
    regularise = damping ** 2 * np.eye(len(goal))
    for _ in range(iterations):
        p, J = arm.position_jacobian(q)
        e = goal - p
        if np.linalg.norm(e) < tol:
            return q, True
        step = J.T @ np.linalg.solve(J @ J.T + regularise, e)
        q = np.clip(q + step * min(1.0, max_step / np.abs(step).max()), arm.lower, arm.upper)
    return q, bool(np.linalg.norm(goal - arm.position(q)) < 1e-6)


@dataclass
class Reference:
    """The timed joint reference of one path."""

    waypoints: np.ndarray     # (W, n) joint path: q_i, the vertices' C.q, the IK goal
    arrival: np.ndarray       # (W,) s, when the reference passes each waypoint
    times: np.ndarray         # (N,) s, every physics step
    q: np.ndarray             # (N, n)
    qd: np.ndarray            # (N, n)


def timed_reference(waypoints: np.ndarray, dt: float, speed: float, accel_fraction: float,
                    settle: float) -> Reference:
    """Linear interpolation in joint space, timed by one trapezoid over the arc length: peak joint-space speed
    `speed` (rad/s), then `settle` s at rest on the goal."""
    steps = np.linalg.norm(np.diff(waypoints, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(steps)])
    length = float(arc[-1])
    duration = max(length / (speed * (1.0 - accel_fraction)), 10 * dt) if length > 0 else 10 * dt
    times = np.arange(round((duration + settle) / dt) + 1) * dt
    s, v, _ = trapezoid(times, length, duration, accel_fraction) if length > 0 else (0 * times,) * 3
    q = np.stack([np.interp(s, arc, waypoints[:, j]) for j in range(waypoints.shape[1])], axis=1)
    direction = np.diff(waypoints, axis=0) / np.maximum(steps, 1e-300)[:, None]
    segment = np.clip(np.searchsorted(arc, s, side="right") - 1, 0, max(len(steps) - 1, 0))
    qd = direction[segment] * v[:, None] if len(steps) else np.zeros_like(q)
    # the time at which the profile reaches each waypoint's arc length
    arrival = np.interp(arc, s, times) if length > 0 else np.zeros(len(waypoints))
    return Reference(waypoints, arrival, times, q, qd)


def padded(ref: Reference, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(q, q̇) of the reference for all `n` joints of the arm: the wrist joints (if any) held at 0."""
    q, qd = np.zeros((len(ref.times), n)), np.zeros((len(ref.times), n))
    q[:, : ref.q.shape[1]], qd[:, : ref.qd.shape[1]] = ref.q, ref.qd
    return q, qd


def obstacle_geoms(boxes: Boxes) -> list:
    """/markers entities of the obstacles, drawn from the same MuJoCo geoms the checkers and the arm's model use."""
    import mujoco

    from pipeline.core import markers

    model = mujoco.MjModel.from_xml_string(f'<mujoco model="obstacles"><worldbody>{obstacles_xml(boxes)}'
                                           "\n  </worldbody></mujoco>")
    return markers.mujoco_geoms(model)

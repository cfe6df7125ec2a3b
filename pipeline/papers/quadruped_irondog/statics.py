"""Standing statics by hand (spec §7, §8.5): the foot loads that balance the robot's weight, and the servo torques
that hold a pose, from the lumped masses and the leg Jacobians alone, independent of the MuJoCo model.

The four vertical foot loads are the least-norm solution of the force and the two moment balances (four feet, three
equations): for a stance symmetric about the body's x axis it loads the two diagonals equally. Friction is taken
as zero (no horizontal reaction).
"""

from __future__ import annotations

import numpy as np

from pipeline.papers.quadruped_irondog.kinematics import (
    Leg,
    body_to_leg,
    feet_in_body,
    fk,
    leg_jacobian,
    leg_to_body,
    rpy_matrix,
)
from pipeline.papers.quadruped_irondog.model import GRAVITY, Robot, trunk_com


def link_legs(leg: Leg) -> list[Leg]:
    """The centres of mass of coxa, femur and tibia as the 'feet' of shorter legs (the boxes' centres)."""
    return [Leg(leg.L1 / 2, 0.0, 0.0), Leg(leg.L1, leg.L2 / 2, 0.0), Leg(leg.L1, leg.L2, leg.L3 / 2)]


def robot_com(robot: Robot, q: np.ndarray, payload: float = 0.0) -> np.ndarray:
    """(3,) centre of mass of the robot (and payload) in the body frame, joints at q (4, 3)."""
    masses = [robot.coxa_mass, robot.femur_mass, robot.tibia_mass]
    total = robot.trunk_mass + payload
    moment = trunk_com(robot, payload) * total
    for m, link in zip(masses, link_legs(robot.leg), strict=True):
        moment = moment + m * (robot.layout.hips + leg_to_body(fk(link, q))).sum(axis=0)
        total += 4 * m
    return moment / total


def foot_loads(feet_xy: np.ndarray, com_xy: np.ndarray, weight: float) -> np.ndarray:
    """(4,) vertical loads (N) on feet at feet_xy (4, 2) carrying `weight` (N) whose line of action is at com_xy."""
    A = np.vstack([np.ones(4), feet_xy[:, 0], feet_xy[:, 1]])
    return np.linalg.pinv(A) @ (weight * np.array([1.0, com_xy[0], com_xy[1]]))


def static_torques(robot: Robot, q: np.ndarray, payload: float = 0.0,
                   rpy=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Servo torques (4, 3) N·m holding pose q (4, 3) at rest with the trunk at roll/pitch/yaw `rpy`, and the foot
    loads (4,) N: τ = Σ_links m g (u·∂p_link/∂q) − f_foot (u·∂p_foot/∂q), u the world's up axis in each leg frame."""
    R = rpy_matrix(rpy)
    weight = (robot.mass + payload) * GRAVITY
    feet = feet_in_body(robot.leg, robot.layout, q) @ R.T
    loads = foot_loads(feet[:, :2], R @ robot_com(robot, q, payload), weight)
    up = body_to_leg(np.tile(R[2], (4, 1)))      # the world z axis in each leg frame: Rᵀ ẑ
    tau = -np.einsum("li,lij->lj", up, leg_jacobian(robot.leg, q)) * loads[:, None]
    for m, link in zip([robot.coxa_mass, robot.femur_mass, robot.tibia_mass], link_legs(robot.leg), strict=True):
        tau = tau + m * GRAVITY * np.einsum("li,lij->lj", up, leg_jacobian(link, q))
    return tau, loads

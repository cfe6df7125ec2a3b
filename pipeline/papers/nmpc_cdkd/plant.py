"""The robot the controllers command every `dt` with joint positions (and their velocities, as feed-forward).

- `KinematicPlant`: the ideal joint-position-controlled robot, q = q_cmd (spec §6).
- `MujocoPlant`: a MuJoCo TX2-90 generated from Table 2 with the URDF link masses, a joint PD servo with gravity
  compensation at 1 kHz (the paper's Gazebo robot is joint-position controlled), the tool rod as a capsule from
  the wrist point to the tool tip, and the obstacles as mocap spheres, so MuJoCo measures the tool-obstacle
  distance independently of our own geometry.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from pipeline.papers.nmpc_cdkd.kinematics import Arm

TOOL_RADIUS = 1e-3  # m: the rod is drawn, and measured, as a thin capsule


class KinematicPlant:
    kind = "kinematic"

    def __init__(self, q0: np.ndarray):
        self.q = np.array(q0, dtype=float)
        self.qd = np.zeros(6)

    @property
    def effort(self) -> np.ndarray:
        return np.full(6, np.nan)

    def step(self, q_cmd: np.ndarray, qd_cmd: np.ndarray, obstacle_centres: np.ndarray) -> None:
        self.q[:] = q_cmd
        self.qd[:] = qd_cmd

    def tool_distances(self) -> np.ndarray | None:
        return None

    def check(self, times: np.ndarray, states: np.ndarray) -> None:
        pass


def model_xml(arm: Arm, plant: Mapping, dt: float, q0: np.ndarray, obstacle_radii: np.ndarray) -> str:
    """MJCF of the TX2-90 with the servo gains set for q0 (`with_servo_gains`)."""
    from pipeline.robotics.mjcf import ArmDynamics, serial_arm, with_servo_gains

    dyn = ArmDynamics(masses=list(plant["masses"]), link_radius=plant["link_radius"],
                      armature=list(plant["armature"]), damping=list(plant["damping"]),
                      torque_limit=list(plant["torque_limit"]))

    d_e = float(np.hypot(arm.tool[0, 3], arm.tool[2, 3]))
    # the rod as a capsule from the wrist point (d_f behind the flange) to the tool tip, in the flange frame
    tool = (f'<geom name="tool" type="capsule" fromto="0 0 {-arm.d_f:.17g} 0 0 {d_e:.17g}" size="{TOOL_RADIUS:.17g}" '
            'mass="0" rgba="0.1 0.1 0.1 1"/>')
    ground = (f'\n    <geom name="ground" type="plane" size="1.5 1.5 0.01" pos="0 0 {arm.base[2, 3]:.17g}" '
              'rgba="0.85 0.8 0.7 1"/>')
    spheres = "".join(f'\n    <body name="obstacle{i + 1}" mocap="true" pos="0 0 {-10.0 - i:.17g}"><geom name='
                      f'"obstacle{i + 1}" type="sphere" size="{r:.17g}" rgba="0.2 0.7 0.2 0.6"/></body>'
                      for i, r in enumerate(obstacle_radii))

    def build(kp: np.ndarray, kv: np.ndarray) -> str:
        return serial_arm("tx2_90", arm.dh, dyn, timestep=plant["physics_dt"], kp=list(kp), kv=list(kv),
                          base_pos=arm.base[:3, 3], flange_xml=tool, world_xml=ground + spheres)

    return with_servo_gains(build, q0, plant["bandwidth_hz"], plant["damping_ratio"])


class MujocoPlant:
    kind = "mujoco"

    def __init__(self, xml: str, dt: float, q0: np.ndarray, n_obstacles: int):
        import mujoco

        self._mj = mujoco
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        self.data.qpos[:] = q0
        self.data.ctrl[:6] = q0
        self._last_cmd = np.array(q0, dtype=float)
        mujoco.mj_forward(self.model, self.data)
        self.substeps = max(1, round(dt / self.model.opt.timestep))
        self._tool = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "tool")
        self._obstacles = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, f"obstacle{i + 1}")
                           for i in range(n_obstacles)]

    @property
    def q(self) -> np.ndarray:
        return self.data.qpos.copy()

    @property
    def qd(self) -> np.ndarray:
        return self.data.qvel.copy()

    @property
    def effort(self) -> np.ndarray:
        """Joint torques of the servo (incl. gravity compensation), N m."""
        return self.data.qfrc_actuator.copy()

    def step(self, q_cmd: np.ndarray, qd_cmd: np.ndarray, obstacle_centres: np.ndarray) -> None:
        """One robot update: the servo reference ramps from the last command to `q_cmd` over the update (as a
        robot controller's interpolator does), with q̇_cmd as velocity feed-forward."""
        data, start = self.data, self._last_cmd
        if len(self._obstacles):
            data.mocap_pos[:] = obstacle_centres
        data.ctrl[6:] = qd_cmd
        for i in range(1, self.substeps + 1):
            data.ctrl[:6] = start + (q_cmd - start) * (i / self.substeps)
            self._mj.mj_step(self.model, data)
        self._last_cmd = np.array(q_cmd, dtype=float)

    def tool_distances(self) -> np.ndarray:
        """(ν,) MuJoCo's distance from the tool capsule (wrist point -> tool tip) to each obstacle sphere, m."""
        self._mj.mj_kinematics(self.model, self.data)
        return np.array([self._mj.mj_geomDistance(self.model, self.data, self._tool, g, 10.0, None) + TOOL_RADIUS
                         for g in self._obstacles])

    def check(self, times: np.ndarray, states: np.ndarray) -> None:
        from pipeline.robotics.mjcf import check_mujoco

        check_mujoco(self.data, states, times)

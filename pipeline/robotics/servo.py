"""Joint-servo execution of a MuJoCo arm built by `mjcf.serial_arm`: the whole run in one C call."""

from __future__ import annotations

import numpy as np


def run_servo(xml: str, q_ref: np.ndarray, qd_ref: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Roll the model out under controls [q_ref, q̇_ref] (the servo is the model's actuators), starting at
    rest at q_ref[0]: (states (N, full physics state), sensors (N, nsensordata)), each after its step.
    Raises SimulationFailed if the rollout diverged."""
    import mujoco
    from mujoco import rollout

    from pipeline.robotics.mjcf import check_mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[:] = q_ref[0]
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    states, sensors = rollout.rollout(model, data, state0, np.concatenate([q_ref, qd_ref], axis=1)[None])
    check_mujoco(data, states[0], times)
    return states[0], sensors[0]

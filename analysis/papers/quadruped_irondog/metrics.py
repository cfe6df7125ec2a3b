"""What the analyses of `quadruped-irondog` read from a run (topic columns as arrays, the robot's constants from
the run config) and the metrics they share (servo torques, windows, feet in the world).

Every metric is in SI (angles in rad); the targets convert to the paper's units. Run-wide quantities of the
MuJoCo runs are computed over a stated window: the settled stance, the held body pose, the levelled bench, the
steady trot after the stride ramp."""

from __future__ import annotations

import numpy as np
import pandas as pd

from pipeline.core.runlog import Run
from pipeline.papers.quadruped_irondog.kinematics import JOINT_NAMES, LEGS

GRAVITY = 9.81
FEET = [f"{leg}.{a}" for leg in LEGS for a in "xyz"]


def columns(frame: pd.DataFrame, prefix: str, names) -> np.ndarray:
    """(N, len(names)) the columns `<prefix>.<name>` of a topic's frame."""
    return frame[[f"{prefix}.{n}" for n in names]].to_numpy(dtype=float)


def joints(run: Run, topic: str = "/joint_state", field: str = "position") -> np.ndarray:
    """(N, 12) a joint-named field of a topic, in JOINT_NAMES order."""
    return columns(run[topic], field, JOINT_NAMES)


def body(run: Run) -> pd.DataFrame:
    """The trunk: x, y, z (m), roll, pitch, yaw (rad), vx, vy, vz (m/s), indexed by t."""
    return run["/body"]


def feet(run: Run, topic: str = "/feet", field: str = "position") -> np.ndarray:
    """(N, 4, 3) foot positions in the leg frames."""
    return columns(run[topic], field, FEET).reshape(-1, 4, 3)


def robot_mass(run: Run) -> float:
    """kg, from the run's config (Table 2's masses as lumped)."""
    masses = run.config["system"]["masses"]
    return sum(masses["trunk"].values()) + 4 * (masses["coxa"] + masses["femur"] + masses["tibia"])


def stall_torque(run: Run) -> float:
    return float(run.config["system"]["servo"]["stall_torque"])


def trot_timing(run: Run) -> dict[str, float]:
    """cycle_time, swing_time, trot_start and steady_start (s) of a trot run."""
    frame = run["/gait/timing"].iloc[0]
    return {k: float(frame[k]) for k in ("cycle_time", "swing_time", "trot_start", "steady_start")}


def torque_metrics(run: Run, window: np.ndarray) -> dict[str, tuple[float, str]]:
    """Servo output torques against the stall torque, over a window (bool mask of the log samples)."""
    tau = joints(run, field="effort")[window]
    motor = joints(run, "/joint_state/motor", "effort")[window]
    limit = stall_torque(run)
    peak = np.abs(tau).max(axis=0)
    values = {"torque.peak": (peak.max(), "N*m"), "torque.peak_ratio": (peak.max() / limit, "ratio"),
              "torque.rms_max": (np.sqrt((tau ** 2).mean(axis=0)).max(), "N*m"),
              "torque.saturated_fraction": (float((np.abs(motor) >= 0.999 * limit).mean()), "fraction")}
    for name, value in zip(JOINT_NAMES, peak, strict=True):
        values[f"torque.peak.{name}"] = (value, "N*m")
    return values


def feet_world(run: Run) -> np.ndarray:
    """(N, 4, 3) foot positions in the world from /tf (the foot frames), at the /tf samples."""
    tf = run["/tf"]
    return np.stack([columns(tf, f"transforms.{leg}_foot.translation", "xyz") for leg in LEGS], axis=1)

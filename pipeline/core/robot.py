"""What a viewer needs to draw the robot of a run, as MCAP messages (encoded whole trajectories at a time).

- `/robot_description`: the URDF (pipeline.robotics.urdf) as ROS 2 `std_msgs/msg/String` (schema encoding
  `ros2msg`, message encoding `cdr`), the form robot_state_publisher publishes and both Foxglove's URDF layer
  (source "topic") and Rerun's MCAP loader read. One message at t = 0.
- `/joint_states`: `foxglove.JointStates`, one joint per movable URDF joint with its position (rad or m): the
  schema Foxglove's 3D panel drives a URDF from (URDF layer, control mode "joint states").
- `/tf/robot`: `foxglove.FrameTransforms`, the pose of every URDF link in its parent link (what
  robot_state_publisher makes of joint states): Rerun places the URDF's geometry by these frames, and
  Foxglove can use them instead of the joint states. Fixed joints are sent once, at the first sample.

These channels are for drawing: they are thinned to at most `VIEW_RATE_HZ`; `/joint_state` keeps every sample.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

import numpy as np

from pipeline.core import encoding

ROBOT_DESCRIPTION = "/robot_description"
JOINT_STATES = "/joint_states"
ROBOT_TF = "/tf/robot"
URDF_ATTACHMENT = "robot.urdf"
VIEW_RATE_HZ = 100.0
ROS2_STRING = ("std_msgs/msg/String", "ros2msg", b"string data", "cdr")  # schema name, encoding, text, msg enc.
_CDR_LITTLE_ENDIAN = b"\x00\x01\x00\x00"


def ros2_string(text: str) -> bytes:
    """A CDR-encoded `std_msgs/msg/String`: encapsulation header, length with the NUL, the text, NUL."""
    raw = text.encode() + b"\0"
    return _CDR_LITTLE_ENDIAN + struct.pack("<I", len(raw)) + raw


def decode_ros2_string(payload: bytes) -> str:
    (length,) = struct.unpack_from("<I", payload, 4)
    return payload[8:8 + length - 1].decode()


def thinned(times: np.ndarray, rate_hz: float = VIEW_RATE_HZ) -> np.ndarray:
    """Indices of `times` (s) kept for drawing: every k-th sample so that the rate is at most `rate_hz`,
    and the last one."""
    n = len(times)
    if n < 3:
        return np.arange(n)
    dt = np.median(np.diff(times))
    step = max(1, int(np.floor(1.0 / (rate_hz * dt) + 1e-9))) if dt > 0 else 1
    keep = np.arange(0, n, step)
    return keep if keep[-1] == n - 1 else np.append(keep, n - 1)


def frame_transforms(times_ns: np.ndarray, parents: Sequence[str], children: Sequence[str],
                     translations: np.ndarray, quats_wxyz: np.ndarray) -> list[bytes]:
    """`foxglove.FrameTransforms` messages, one per time: child k at translations[:, k] (m), rotation
    quats_wxyz[:, k] in parents[k], stamped with the time."""
    n, k = len(times_ns), len(children)
    translation = encoding.doubles([1, 2, 3], np.asarray(translations, dtype=float).reshape(n, k, 3))
    rotation = encoding.doubles([1, 2, 3, 4],  # on the wire: x y z w
                                np.asarray(quats_wxyz, dtype=float).reshape(n, k, 4)[..., [1, 2, 3, 0]])
    rotation_key = np.frombuffer(encoding.delimited(5, rotation.shape[-1]), dtype=np.uint8)
    # each transform's fields after its names, one block: translation (4), rotation (5)
    pose = np.concatenate([translation, np.broadcast_to(rotation_key, (n, k, len(rotation_key))), rotation], axis=2)
    frames = [encoding.string(2, parent) + encoding.string(3, child) + encoding.delimited(4, translation.shape[-1])
              for parent, child in zip(parents, children, strict=True)]

    def layout(rows: np.ndarray, stamp: np.ndarray) -> list[encoding.Part]:
        poses = pose if len(rows) == n else pose[rows]
        timestamp = encoding.delimited(1, stamp.shape[1])
        parts: list[encoding.Part] = []
        for j, frame in enumerate(frames):
            size = len(timestamp) + stamp.shape[1] + len(frame) + pose.shape[-1]
            parts += [encoding.delimited(1, size) + timestamp, stamp, frame, poses[:, j]]
        return parts

    return encoding.stamped(times_ns, layout)


def joint_states(times_ns: np.ndarray, names: Sequence[str], positions: np.ndarray) -> list[bytes]:
    """`foxglove.JointStates` messages, one per time, with each named joint's position (rad or m)."""
    n = len(times_ns)
    positions = encoding.doubles([2], np.asarray(positions, dtype=float).reshape(n, len(names), 1))
    joints = [encoding.string(1, name) for name in names]

    def layout(rows: np.ndarray, stamp: np.ndarray) -> list[encoding.Part]:
        values = positions if len(rows) == n else positions[rows]
        parts: list[encoding.Part] = [encoding.delimited(1, stamp.shape[1]), stamp]
        for j, joint in enumerate(joints):
            parts += [encoding.delimited(2, len(joint) + values.shape[-1]) + joint, values[:, j]]
        return parts

    return encoding.stamped(times_ns, layout)

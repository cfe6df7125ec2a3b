"""Protobuf schemas of the run logs.

Poses and transforms use Foxglove's own schemas (Foxglove and Rerun visualise them natively). Every other
numeric record uses one project schema per kind, built here at import time from a field list, so no
protoc step or generated code is needed. The common topics and their schemas are fixed in `TOPICS`:
every paper logs the same kind of record under the same name.

A paper that needs a record the common schemas cannot hold declares it with `define(...)`.
"""

from __future__ import annotations

from foxglove_schemas_protobuf.ArrowPrimitive_pb2 import ArrowPrimitive
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.CylinderPrimitive_pb2 import CylinderPrimitive
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.PosesInFrame_pb2 import PosesInFrame
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.SpherePrimitive_pb2 import SpherePrimitive
from foxglove_schemas_protobuf.TriangleListPrimitive_pb2 import TriangleListPrimitive
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory, timestamp_pb2
from google.protobuf.message import Message

_F = descriptor_pb2.FieldDescriptorProto
_SCALAR_TYPES = {
    "double": _F.TYPE_DOUBLE,
    "int64": _F.TYPE_INT64,
    "uint32": _F.TYPE_UINT32,
    "bool": _F.TYPE_BOOL,
    "string": _F.TYPE_STRING,
}
PACKAGE = "repro"


def define(type_name: str, doc: str, /, **fields: str) -> type[Message]:
    """Declare project schema `repro.<type_name>`.

    Field types are `double`, `int64`, `uint32`, `bool`, `string`, each optionally followed by `[]` for a
    repeated field. Time is the message's log time (simulated time), not a field. A repeated
    `name` field labels the entries of the other repeated fields of the same length: the reader turns
    `position` + `name=["j1", "j2"]` into columns `position.j1`, `position.j2`.
    """
    fdp = descriptor_pb2.FileDescriptorProto(
        name=f"{PACKAGE}/{type_name}.proto", package=PACKAGE, syntax="proto3")
    msg = fdp.message_type.add(name=type_name)
    for number, (field, kind) in enumerate(fields.items(), start=1):
        repeated = kind.endswith("[]")
        msg.field.add(name=field, number=number, type=_SCALAR_TYPES[kind.removesuffix("[]")],
                      label=_F.LABEL_REPEATED if repeated else _F.LABEL_OPTIONAL)
    pool = descriptor_pool.Default()
    try:
        pool.Add(fdp)
    except TypeError as err:  # defined twice: allowed only if identical (module re-import)
        existing = descriptor_pb2.FileDescriptorProto()
        pool.FindFileByName(fdp.name).CopyToProto(existing)
        if existing != fdp:
            raise ValueError(f"schema {PACKAGE}.{type_name} is already defined differently") from err
    cls = message_factory.GetMessageClass(pool.FindMessageTypeByName(f"{PACKAGE}.{type_name}"))
    cls.__doc__ = doc
    return cls


JointState = define(
    "JointState", "Measured joint positions (rad or m), velocities and efforts (N·m or N).",
    name="string[]", position="double[]", velocity="double[]", effort="double[]",
)
Reference = define(
    "Reference", "Desired values a controller tracks; joint or task space, as the names say.",
    name="string[]", position="double[]", velocity="double[]", acceleration="double[]",
)
Command = define(
    "Command", "What the controller sends to the actuators; `kind` says torque, velocity, position, ….",
    kind="string", name="string[]", value="double[]",
)
TrackingError = define(
    "TrackingError", "Reference minus measurement per named coordinate, and its Euclidean norm.",
    name="string[]", error="double[]", norm="double",
)
Wrench = define(
    "Wrench", "Force (N) and torque (N·m) at a named point or contact, expressed in `frame_id`.",
    frame_id="string", name="string[]", force_x="double[]", force_y="double[]", force_z="double[]",
    torque_x="double[]", torque_y="double[]", torque_z="double[]",
)
ComputeTime = define(
    "ComputeTime", "Wall-clock time of one call (or one batch) of a named algorithm.",
    name="string[]", seconds="double[]", calls="uint32[]",
)
Scalars = define(
    "Scalars", "Named scalar signals that no common record holds (det J, clearance, …).",
    name="string[]", value="double[]",
)

TOPICS: dict[str, type[Message]] = {
    "/joint_state": JointState,
    "/reference": Reference,
    "/command": Command,
    "/tracking_error": TrackingError,
    "/wrench": Wrench,
    "/compute_time": ComputeTime,
    "/tf": FrameTransforms,
    "/poses": PosesInFrame,
    "/markers": SceneUpdate,   # shapes to draw (spheres, cylinders, arrows, …) attached to /tf frames
    "/joint_states": JointStates,  # the robot's joints for Foxglove's URDF layer (pipeline.core.robot)
}


def for_topic(topic: str) -> type[Message] | None:
    """The common schema of a topic or of its family (`/tracking_error/flange` is a `/tracking_error`)."""
    while topic:
        if topic in TOPICS:
            return TOPICS[topic]
        topic = topic.rpartition("/")[0]
    return None


__all__ = [
    "TOPICS",
    "ArrowPrimitive",
    "Color",
    "CubePrimitive",
    "CylinderPrimitive",
    "FrameTransform",
    "FrameTransforms",
    "JointStates",
    "LinePrimitive",
    "Point3",
    "Pose",
    "PosesInFrame",
    "Quaternion",
    "SceneEntity",
    "SceneUpdate",
    "SpherePrimitive",
    "TriangleListPrimitive",
    "Vector3",
    "define",
    "for_topic",
    "stamp",
]


def stamp(t_ns: int) -> timestamp_pb2.Timestamp:
    return timestamp_pb2.Timestamp(seconds=t_ns // 1_000_000_000, nanos=t_ns % 1_000_000_000)

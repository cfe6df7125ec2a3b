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
from foxglove_schemas_protobuf.KeyValuePair_pb2 import KeyValuePair
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
_NUMERIC = ("double", "int64", "uint32")
PACKAGE = "repro"
ENTRY = "q"  # in a unit template: the unit of each named entry, which the writer declares (`units=`)

# Units per field of every schema: full schema name -> field path -> unit or unit template. Units are written as
# in analysis/core/units.py: SI, `N*m`, `rad/s`, `m/s^2`; "1" is a pure number, "bool" a flag. A template holds
# ENTRY: "q" (the entry's own unit: a joint in rad or m), "q/s", "q/s^2", "effort(q)" (N*m for rad, N for m),
# "command(q)" (what a Command's `kind` makes of q: torque -> effort, velocity -> q/s, ...).
UNITS: dict[str, dict[str, str]] = {
    # Foxglove's own schemas: positions in metres, orientations as unit quaternions
    "foxglove.FrameTransforms": {"transforms.translation": "m", "transforms.rotation": "1"},
    "foxglove.PosesInFrame": {"poses.position": "m", "poses.orientation": "1"},
}
# Command kinds -> what the command of an entry in unit q is measured in
COMMAND_KINDS = {
    "torque": "effort(q)", "force": "effort(q)", "effort": "effort(q)", "torque/force": "effort(q)",
    "current": "A", "voltage": "V", "position": "q", "velocity": "q/s", "angular_velocity": "q/s", "twist": "q/s",
    "wheel speed": "q/s", "acceleration": "q/s^2",
}
_EFFORT = {"rad": "N*m", "m": "N"}


def per_second(unit: str) -> str:
    """The unit of a rate of `unit`: rad -> rad/s, m/s -> m/s^2, 1 -> 1/s."""
    if unit.endswith("/s"):
        return unit + "^2"
    if unit.endswith("/s^2"):
        return unit[:-1] + "3"
    return f"{unit}/s"


def derive(template: str, q: str | None, kind: str = "") -> str | None:
    """The unit a template gives for an entry of unit `q` (None when q is needed but unknown)."""
    if template == "command(q)":
        template = COMMAND_KINDS.get(kind, "")
        if not template:
            return None
    if ENTRY not in template.replace("effort", ""):
        return template
    if not q:
        return None
    if template == "q":
        return q
    if template == "q/s":
        return per_second(q)
    if template == "q/s^2":
        return per_second(per_second(q))
    if template == "effort(q)":
        return _EFFORT.get(q)
    raise ValueError(f"unknown unit template {template!r}")


def define(type_name: str, doc: str, /, **fields: str) -> type[Message]:
    """Declare project schema `repro.<type_name>`.

    Each field is `"<type> <unit>"`: the type is `double`, `int64`, `uint32`, `bool` or `string`, followed by `[]`
    for a repeated field; a number needs its unit (`"double[] N"`, `"uint32 1"` for a count, `"double[] q"` for
    the unit of each named entry, declared where it is logged). Time is the message's log time (simulated time),
    not a field. A repeated `name` field labels the entries of the other repeated fields of the same length: the
    reader turns `position` + `name=["j1", "j2"]` into columns `position.j1`, `position.j2`.
    """
    fdp = descriptor_pb2.FileDescriptorProto(
        name=f"{PACKAGE}/{type_name}.proto", package=PACKAGE, syntax="proto3")
    msg = fdp.message_type.add(name=type_name)
    units = {}
    for number, (field, spec) in enumerate(fields.items(), start=1):
        kind, _, unit = spec.partition(" ")
        repeated = kind.endswith("[]")
        kind = kind.removesuffix("[]")
        if kind in _NUMERIC and not unit.strip():
            raise ValueError(f"schema {PACKAGE}.{type_name}: field {field} needs a unit, e.g. {field}=\"{spec} m\" "
                             "('1' for a pure number, 'q' for the unit of each named entry)")
        if kind == "bool":
            unit = unit or "bool"
        if unit.strip():
            units[field] = unit.strip()
        msg.field.add(name=field, number=number, type=_SCALAR_TYPES[kind],
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
    UNITS[f"{PACKAGE}.{type_name}"] = units
    return cls


def units_of(cls: type[Message]) -> dict[str, str]:
    """Field -> unit (or unit template) of a schema."""
    return UNITS.get(cls.DESCRIPTOR.full_name, {})


JointState = define(
    "JointState", "Measured joint positions, velocities and efforts; each joint's unit is declared where it is "
    "logged (rad, rad/s, N*m for a revolute joint; m, m/s, N for a prismatic one).",
    name="string[]", position="double[] q", velocity="double[] q/s", effort="double[] effort(q)",
)
Reference = define(
    "Reference", "Desired values a controller tracks; joint or task space, as the names and their units say.",
    name="string[]", position="double[] q", velocity="double[] q/s", acceleration="double[] q/s^2",
)
Command = define(
    "Command", "What the controller sends to the actuators; `kind` says torque, velocity, position, … and with "
    "each entry's unit gives the command's unit (torque on a joint in rad: N*m).",
    kind="string", name="string[]", value="double[] command(q)",
)
TrackingError = define(
    "TrackingError", "Reference minus measurement per named coordinate (each in its unit), and its Euclidean norm.",
    name="string[]", error="double[] q", norm="double q",
)
Wrench = define(
    "Wrench", "Force (N) and torque (N·m) at a named point or contact, expressed in `frame_id`.",
    frame_id="string", name="string[]", force_x="double[] N", force_y="double[] N", force_z="double[] N",
    torque_x="double[] N*m", torque_y="double[] N*m", torque_z="double[] N*m",
)
ComputeTime = define(
    "ComputeTime", "Wall-clock time of one call (or one batch) of a named algorithm.",
    name="string[]", seconds="double[] s", calls="uint32[] 1",
)
Scalars = define(
    "Scalars", "Named scalar signals that no common record holds (det J, clearance, …), each in its unit.",
    name="string[]", value="double[] q",
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


__all__ = ["ENTRY", "TOPICS", "UNITS", "ArrowPrimitive", "Color", "CubePrimitive", "CylinderPrimitive",
           "FrameTransform", "FrameTransforms", "JointStates", "KeyValuePair", "LinePrimitive", "Point3", "Pose",
           "PosesInFrame", "Quaternion", "SceneEntity", "SceneUpdate", "SpherePrimitive", "TriangleListPrimitive",
           "Vector3", "define", "derive", "for_topic", "per_second", "stamp", "units_of"]


def stamp(t_ns: int) -> timestamp_pb2.Timestamp:
    return timestamp_pb2.Timestamp(seconds=t_ns // 1_000_000_000, nanos=t_ns % 1_000_000_000)

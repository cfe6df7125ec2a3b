"""One run = one MCAP file: writing it safely and reading it back as pandas DataFrames.

Log time is simulated time in nanoseconds from 0, so two runs of the same config are byte-comparable
message by message. A run is written under a unique hidden `.partial` name and renamed only when complete
(pipeline.core.files): a killed run never leaves a file that looks finished, and a re-run replaces the old
file atomically.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable, Mapping, Sequence
from itertools import chain
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml
from google.protobuf import descriptor_pb2
from google.protobuf.descriptor import Descriptor
from google.protobuf.message import Message

from pipeline.core import files, layouts, markers, robot, schemas
from pipeline.core.decoding import entry_labels, read_topics
from pipeline.core.encoding import encode_series, messages
from pipeline.core.mcap_file import McapFile
from pipeline.robotics.transforms import quaternion_wxyz

if TYPE_CHECKING:  # pandas is for reading runs; a simulate stage does not import it
    import pandas as pd

RUN_SUFFIX = ".mcap"
METADATA_NAME = "run"
CONFIG_ATTACHMENT = "config.yaml"
MODEL_ATTACHMENT = "model.xml"   # the generated MuJoCo model (MJCF) a run simulates
UNITS_KEY = "units"   # channel metadata: JSON column -> unit
# Topics that carry the simulated state: a NaN or an infinity there means the simulation diverged, and the
# run fails with the first time it happened (every paper gets this watchdog by logging these topics).
STATE_TOPICS = ("/joint_state", "/tracking_error", "/wrench", "/command")


class SimulationFailed(RuntimeError):
    """A run that cannot go on (divergence, NaN, solver breakdown); recorded as `failed: <reason>`."""


def _schema_name(kind: type[Message] | tuple) -> str:
    return kind[0] if isinstance(kind, tuple) else kind.DESCRIPTOR.full_name


def _is_state(topic: str) -> bool:
    return any(topic == t or topic.startswith(t + "/") for t in STATE_TOPICS)


def _watch(topic: str, times: np.ndarray, columns: Mapping[str, Any]) -> None:
    """Raise SimulationFailed at the first non-finite number of a state topic."""
    for field_name, values in columns.items():
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            continue  # names, strings
        bad = ~np.isfinite(array)
        if bad.any():
            first = int(np.argmax(bad.reshape(len(times), -1).any(axis=1))) if array.ndim and len(times) > 1 else 0
            raise SimulationFailed(f"diverged: non-finite {topic} {field_name} at t = {float(times[first]):.6g} s")


def seconds_to_ns(t: float | np.ndarray) -> int | np.ndarray:
    if isinstance(t, np.ndarray):
        return np.rint(t * 1e9).astype(np.int64)
    return round(t * 1e9)


@functools.cache
def _file_descriptor_set(descriptor: Descriptor) -> bytes:
    """The schema bytes MCAP wants for protobuf: the message's file and all it imports."""
    fds = descriptor_pb2.FileDescriptorSet()
    seen: set[str] = set()

    def add(file) -> None:
        if file.name in seen:
            return
        seen.add(file.name)
        for dep in file.dependencies:
            add(dep)
        file.CopyToProto(fds.file.add())

    add(descriptor.file)
    return fds.SerializeToString()


EntryUnits = str | Sequence[str] | None


def column_units(cls: type[Message], sample: Mapping[str, Any], units: EntryUnits = None,
                 field_units: Mapping[str, EntryUnits] | None = None, topic: str = "") -> dict[str, str]:
    """Column -> unit of the record `sample` (field -> value) of schema `cls`: the schema's unit of each field,
    with its entry template ("q", "q/s", ...) filled from `units` (each named entry's unit) and `field_units`
    taking precedence. Raises ValueError naming the column whose unit nobody gave."""
    declared = schemas.units_of(cls)
    field_units = dict(field_units or {})
    unknown = set(field_units) - set(cls.DESCRIPTOR.fields_by_name)
    if unknown:
        raise ValueError(f"{topic}: field_units names no field of {cls.DESCRIPTOR.full_name}: {sorted(unknown)}")
    names = sample.get("name")
    names = None if names is None or isinstance(names, str) else list(names)
    kind = sample.get("kind", "")
    kind = kind if isinstance(kind, str) else ""

    def entries(spec: EntryUnits, count: int, what: str) -> list[str | None]:
        if spec is None or isinstance(spec, str):
            return [spec] * count
        if len(spec) != count:
            raise ValueError(f"{topic}: {what} gives {len(spec)} units for {count} entries")
        return list(spec)

    result: dict[str, str] = {}
    for fd in cls.DESCRIPTOR.fields:
        field = fd.name
        if field == "name" or fd.type == fd.TYPE_STRING or (field not in sample and field not in declared):
            continue
        template = declared.get(field)
        repeated = fd.is_repeated if hasattr(fd, "is_repeated") else fd.label == fd.LABEL_REPEATED
        if repeated:
            count = int(np.size(sample.get(field, ())))
            if not count:
                continue
            labels = entry_labels(field, count, names)
            explicit = entries(field_units[field], count, f"field_units[{field!r}]") if field in field_units \
                else [None] * count
            q = entries(units, count, "units")
            found = [e or (schemas.derive(template, qi, kind) if template else None)
                     for e, qi in zip(explicit, q, strict=True)]
        else:
            labels = [field]
            common = {units} if isinstance(units, str) else set(units or [None])
            q = next(iter(common)) if len(common) == 1 else None
            spec = field_units.get(field)
            found = [spec if isinstance(spec, str) else (schemas.derive(template, q, kind) if template else None)]
        for label, unit in zip(labels, found, strict=True):
            if not unit:
                hint = (f"field_units={{'{field}': ...}}" if not repeated or template is None
                        or schemas.ENTRY not in template.replace("effort", "")
                        else "units= (each named entry's unit, e.g. units='rad')")
                raise ValueError(f"{topic}: the unit of {label} is not known: pass {hint}")
            result[label] = unit
    return result


def _joined(parts: list[list[bytes] | np.ndarray]) -> list[bytes] | np.ndarray:
    """A topic's messages in one piece: one table if every part is a table of the same width, else bytes."""
    if len(parts) == 1:
        return parts[0]
    if all(isinstance(p, np.ndarray) for p in parts) and len({p.shape[1] for p in parts}) == 1:
        return np.concatenate(parts)
    return list(chain.from_iterable(messages(p) if isinstance(p, np.ndarray) else p for p in parts))


# (topic, schema, names, kind, units given, shape of each field) -> column -> unit, for every writer of a process
_DECLARED: dict[tuple, dict[str, str]] = {}


class RunWriter:
    """Writes one run. Use as a context manager; `close(status)` publishes the file.

    Messages wait in memory per topic and are written topic by topic at close, each topic in chunks of its
    own (pipeline.core.mcap_file): a reader that wants one topic then decompresses only that topic's chunks.
    Series of doubles are encoded in one NumPy pass, and framed as MCAP records in another."""

    def __init__(self, path: Path, metadata: Mapping[str, Any]):
        self.path = Path(path)
        self._partial = files.temporary_name(self.path)
        self._file = McapFile(self._partial)
        self._open = True
        self._types: dict[str, type[Message] | tuple] = {}  # protobuf class, or robot.ROS2_STRING
        # topic -> parts of (times in ns, messages: bytes each, or the rows of an (n, w) uint8 table)
        self._pending: dict[str, list[tuple[np.ndarray, list[bytes] | np.ndarray]]] = {}
        self._units: dict[str, dict[str, str]] = {}   # topic -> column -> unit, written as channel metadata
        self._declared: set[tuple] = set()
        self.metadata = {k: v if isinstance(v, str) else json.dumps(v) for k, v in metadata.items()}
        self._model_xml: str | None = None
        self._joint_state: tuple[np.ndarray, list[str], np.ndarray] | None = None
        self.robot = None  # the RobotDescription drawn, once log_robot has run

    # -- messages ---------------------------------------------------------------------------------
    @staticmethod
    def _schema(topic: str) -> type[Message]:
        cls = schemas.for_topic(topic)
        if cls is None:
            raise KeyError(f"{topic} is not a common topic: pass its message_type")
        return cls

    def _queue(self, topic: str, message_type: type[Message] | tuple) \
            -> list[tuple[np.ndarray, list[bytes] | np.ndarray]]:
        known = self._types.get(topic)
        if known is None:
            expected = schemas.for_topic(topic)
            if expected is not None and expected is not message_type:
                raise TypeError(f"topic {topic} is reserved for {expected.DESCRIPTOR.full_name}")
            self._types[topic] = message_type
            self._pending[topic] = []
        elif known is not message_type:
            raise TypeError(f"topic {topic} carries {_schema_name(known)}, not {_schema_name(message_type)}")
        return self._pending[topic]

    def write(self, topic: str, t_ns: int, message: Message) -> None:
        """Queue a ready-made message at simulated time `t_ns`."""
        self._queue(topic, type(message)).append((np.array([t_ns], dtype=np.int64), [message.SerializeToString()]))

    def log(self, topic: str, t: float, message_type: type[Message] | None = None, *, units: EntryUnits = None,
            field_units: Mapping[str, EntryUnits] | None = None, **fields: Any) -> None:
        """Write one record at simulated time `t` (s); common topics know their schema. `units` and
        `field_units` say what the schema leaves to the writer (see `log_series`)."""
        cls = message_type or self._schema(topic)
        if _is_state(topic):
            _watch(topic, np.array([t]), {k: v for k, v in fields.items() if not isinstance(v, str)})
        self._declare(topic, cls, fields, units, field_units)
        self.write(topic, seconds_to_ns(t), cls(**fields))

    def log_series(self, topic: str, times: np.ndarray, message_type: type[Message] | None = None, *,
                   units: EntryUnits = None, field_units: Mapping[str, EntryUnits] | None = None,
                   **columns: Any) -> None:
        """Write one record per sample: a NumPy array column gives sample i its row i (a 1-D array
        fills a scalar field, a 2-D array a repeated one); anything else (names as a list, a string) is
        the same in every record.

        Every number has a unit. The schema fixes most (`/wrench` forces in N); where it says "q" (a joint's
        position, a Scalars value) the writer gives each named entry's unit: `units="rad"` for all of them, or
        one per name (`units=["rad", "rad", "m"]`); velocities, efforts and commands follow from it (rad -> rad/s,
        N*m). `field_units={"norm": "m"}` sets a field's unit (or one per entry) outright."""
        cls = message_type or self._schema(topic)
        times_ns = seconds_to_ns(np.asarray(times, dtype=float))
        per_sample = {k: v for k, v in columns.items() if isinstance(v, np.ndarray)}
        constant = {k: v for k, v in columns.items() if k not in per_sample}
        for k, v in per_sample.items():
            if len(v) != len(times_ns):
                raise ValueError(f"{topic}: column {k} has {len(v)} samples for {len(times_ns)} times")
        if _is_state(topic):
            _watch(topic, np.asarray(times, dtype=float), per_sample)
        self._declare(topic, cls, {**constant, **{k: v[0] if len(v) else v for k, v in per_sample.items()}},
                      units, field_units)
        if topic == "/joint_state" and "position" in per_sample and self._joint_state is None:
            self._joint_state = (np.asarray(times, dtype=float), list(constant.get("name", [])),
                                 np.asarray(per_sample["position"], dtype=float).reshape(len(times_ns), -1))
        encoded = encode_series(cls, constant, per_sample)
        if encoded is None:
            rows = {k: v.tolist() for k, v in per_sample.items()}
            encoded = [cls(**constant, **{k: v[i] for k, v in rows.items()}).SerializeToString()
                       for i in range(len(times_ns))]
        self._queue(topic, cls).append((times_ns, encoded))

    def _declare(self, topic: str, cls: type[Message], sample: Mapping[str, Any], units: EntryUnits,
                 field_units: Mapping[str, EntryUnits] | None) -> None:
        """Record the unit of every column one record of `topic` makes (the first time this shape is logged)."""
        names = sample.get("name")
        names = None if names is None or isinstance(names, str) else list(names)
        self._queue(topic, cls)  # the topic's schema first: a reserved topic refuses another
        key = (topic, cls, tuple(names or ()), sample.get("kind", ""),
               units if units is None or isinstance(units, str) else tuple(units),
               tuple((k, v if isinstance(v, str) else tuple(v)) for k, v in (field_units or {}).items()),
               tuple((k, np.shape(v) if isinstance(v, list | tuple | np.ndarray) else -1) for k, v in sample.items()))
        if key in self._declared:
            return
        self._declared.add(key)
        known = self._units.setdefault(topic, {})
        declared = _DECLARED.get(key)
        if declared is None:  # the same shape in every run of an experiment: its units worked out once
            declared = _DECLARED[key] = column_units(cls, sample, units, field_units, topic)
        for column, unit in declared.items():
            if known.setdefault(column, unit) != unit:
                raise ValueError(f"{topic}: column {column} was logged in {known[column]}, now in {unit}")

    def log_transforms(self, times: np.ndarray, parent: str, children: Sequence[str],
                       matrices: np.ndarray, topic: str = "/tf") -> None:
        """Foxglove FrameTransforms: `matrices` (N, k, 4, 4) are the poses of the k `children` in
        `parent` at each of the N `times` (s). Foxglove's 3D panel and Rerun draw them as a frame tree."""
        matrices = np.asarray(matrices, dtype=float)
        times_ns = seconds_to_ns(np.asarray(times, dtype=float))
        encoded = robot.frame_transforms(times_ns, [parent] * len(children), children, matrices[..., :3, 3],
                                         quaternion_wxyz(matrices[..., :3, :3]))
        self._queue(topic, schemas.FrameTransforms).append((times_ns, encoded))
        known = self._units.setdefault(topic, {})
        for c in children:
            known.update({f"transforms.{c}.translation.{a}": "m" for a in "xyz"})
            known.update({f"transforms.{c}.rotation.{a}": "1" for a in "xyzw"})

    @property
    def model_xml(self) -> str | None:
        """The MuJoCo model attached as `model.xml`, if any."""
        return self._model_xml

    def log_robot(self, times: np.ndarray, qpos: np.ndarray, mocap_pos: np.ndarray | None = None,
                  mocap_quat: np.ndarray | None = None, model=None) -> None:
        """Draw the simulated robot: its URDF on `/robot_description` (and as attachment `robot.urdf`), its
        joints on `/joint_states` and its links on `/tf/robot` (pipeline.core.robot), from MuJoCo states
        `qpos` (N, nq) at `times` (s) and the world poses of mocap bodies, `mocap_pos` (N or 1, nmocap, 3) and
        `mocap_quat` (N or 1, nmocap, 4, wxyz; default: as in the model). `model` (`MjModel` or MJCF) defaults
        to the attached `model.xml`. Call it again to append a later part of the same run; samples are
        thinned to robot.VIEW_RATE_HZ."""
        from pipeline.robotics.urdf import describe, described

        model = model if model is not None else self._model_xml
        if model is None:
            raise ValueError("log_robot: no model given and no model.xml attached")
        model, description = described(model) if isinstance(model, str) else (model, describe(model))
        times = np.atleast_1d(np.asarray(times, dtype=float))
        keep = robot.thinned(times)
        mocap_body = model.body_mocapid >= 0
        defaults = (model.body_pos[mocap_body], model.body_quat[mocap_body])
        mocap = [np.broadcast_to(default if a is None else a, (len(times), model.nmocap, default.shape[1]))[keep]
                 for a, default in zip((mocap_pos, mocap_quat), defaults, strict=True)]
        if self.robot is None:
            self.robot = description
            urdf = description.urdf()
            self.attach(robot.URDF_ATTACHMENT, urdf, "application/xml")
            first = seconds_to_ns(times[:1])
            self._queue(robot.ROBOT_DESCRIPTION, robot.ROS2_STRING).append((first, [robot.ros2_string(urdf)]))
            fixed = description.fixed
            if fixed:
                self._queue(robot.ROBOT_TF, schemas.FrameTransforms).append((first, robot.frame_transforms(
                    first, [j.parent for j in fixed], [j.child for j in fixed],
                    np.stack([j.origin.p for j in fixed])[None], np.stack([j.origin.q for j in fixed])[None])))
        elif self.robot.urdf() != description.urdf():
            raise ValueError("log_robot: a run draws one robot; this model differs from the first one")
        if not description.movable:
            return
        positions = description.joint_positions(np.atleast_2d(qpos)[keep], *mocap)
        times_ns = seconds_to_ns(times[keep])
        self._queue(robot.JOINT_STATES, schemas.JointStates).append(
            (times_ns, robot.joint_states(times_ns, description.joint_names, positions)))
        trans, quats = description.transforms(positions)
        self._queue(robot.ROBOT_TF, schemas.FrameTransforms).append((times_ns, robot.frame_transforms(
            times_ns, [j.parent for j in description.movable], [j.child for j in description.movable],
            trans, quats)))

    def log_contacts(self, times: np.ndarray, points: Sequence[np.ndarray], forces: Sequence[np.ndarray],
                     scale: float, name: str = "contacts", **style: Any) -> None:
        """Contacts on `/markers`: at each of `times` (s) the points (c, 3) and forces (c, 3; N) of that instant
        (markers.contacts, arrows at `scale` m/N), replacing the previous instant's; thinned to
        robot.VIEW_RATE_HZ like the robot."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        keep = robot.thinned(times).tolist()
        times_ns = seconds_to_ns(times[keep])
        updates = [schemas.SceneUpdate(entities=[markers.contacts(name, points[i], forces[i], scale, **style)])
                   .SerializeToString() for i in keep]
        self._queue("/markers", schemas.SceneUpdate).append((times_ns, updates))

    def _robot_from_joint_state(self) -> None:
        """A run that attached its MuJoCo model and logged `/joint_state` under the model's joint names gets
        its robot drawn without asking (joints it did not log stay at qpos0). Models with free, ball or
        mocap bodies need the full state: call `log_robot`."""
        import mujoco

        from pipeline.robotics.urdf import described

        if self.robot is not None or self._model_xml is None or self._joint_state is None:
            return
        model, _ = described(self._model_xml)
        if model.nmocap or any(int(t) in (mujoco.mjtJoint.mjJNT_FREE, mujoco.mjtJoint.mjJNT_BALL)
                               for t in model.jnt_type):
            return
        times, names, position = self._joint_state
        columns = {name: k for k, name in enumerate(names)}
        joints = [model.joint(j).name for j in range(model.njnt)]
        if not joints or not set(joints) <= set(columns):
            return
        qpos = np.tile(model.qpos0, (len(times), 1))
        for j, name in enumerate(joints):
            qpos[:, model.jnt_qposadr[j]] = position[:, columns[name]]
        self.log_robot(times, qpos, model=self._model_xml)

    def attach(self, name: str, data: bytes | str, media_type: str) -> None:
        if name == MODEL_ATTACHMENT:
            self._model_xml = data if isinstance(data, str) else data.decode()
        self._file.attach(name, media_type, data.encode() if isinstance(data, str) else data)

    @property
    def messages(self) -> int:
        """Messages logged so far."""
        return sum(len(times) for parts in self._pending.values() for times, _ in parts)

    # -- lifecycle --------------------------------------------------------------------------------
    def _flush_topics(self) -> None:
        for topic, parts in self._pending.items():
            if not parts:  # declared, but its first record failed (a bug the run's status names)
                continue
            kind = self._types[topic]
            if isinstance(kind, tuple):  # a ROS 2 message (mixed encodings in one file are part of MCAP)
                name, encoding, definition, message_encoding = kind
                schema = (name, encoding, definition)
            else:
                schema = (kind.DESCRIPTOR.full_name, "protobuf", _file_descriptor_set(kind.DESCRIPTOR))
                message_encoding = "protobuf"
            units = self._units.get(topic)
            channel = self._file.add_channel(topic, message_encoding, schema,
                                             {UNITS_KEY: json.dumps(units)} if units else None)
            times = np.concatenate([t for t, _ in parts])
            data = _joined([chunk for _, chunk in parts])
            if len(times) != len(data):
                raise ValueError(f"{topic}: {len(data)} messages for {len(times)} times")
            if len(times) > 1 and (np.diff(times) < 0).any():
                order = np.argsort(times, kind="stable")  # equal times keep their logging order
                times = times[order]
                data = data[order] if isinstance(data, np.ndarray) else [data[i] for i in order.tolist()]
            self._file.add_messages(channel, times, data)
        self._pending.clear()

    def close(self, status: str) -> Path:
        """Record the status, finish the file and publish it under its final name."""
        if status == "ok":
            self._robot_from_joint_state()
        if self._pending:
            self.attach(layouts.LAYOUT_ATTACHMENT, layouts.foxglove_layout(self._pending, self.metadata.get("slug")),
                        "application/json")
        self._flush_topics()
        self._file.add_metadata(METADATA_NAME, {**self.metadata, "status": status})
        self._file.finish()
        self._open = False
        return files.publish(self._partial, self.path)

    def abort(self) -> None:
        """Drop the unfinished file (interrupt): the previous complete run, if any, is untouched."""
        if self._open:
            self._file.close()
            self._open = False
        self._partial.unlink(missing_ok=True)

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if self._open:
            self.abort()


# ---------------------------------------------------------------------------------------------------
# Reading


class Run:
    """A run read back: metadata, resolved config, attachments, and one DataFrame per topic (indexed by
    simulated time `t` in s), decoded the first time it is asked for."""

    def __init__(self, path: str | Path):
        from mcap.reader import make_reader  # the MCAP reader: not imported by a simulate stage

        self.path = Path(path)
        with open(self.path, "rb") as f:
            reader = make_reader(f)
            self.metadata: dict[str, str] = {}
            for record in reader.iter_metadata():
                if record.name == METADATA_NAME:
                    self.metadata = dict(record.metadata)
            self.attachments: dict[str, bytes] = {a.name: a.data for a in reader.iter_attachments()}
            summary = reader.get_summary()
        if not self.metadata:
            raise ValueError(f"{self.path} has no '{METADATA_NAME}' metadata record: not a complete run file")
        channels = summary.channels.values() if summary else []
        self.topic_names = sorted({c.topic for c in channels})
        self._units = {c.topic: json.loads(c.metadata.get(UNITS_KEY, "{}")) for c in channels}
        self._schemas = {c.topic: summary.schemas[c.schema_id].name for c in channels}
        counts = summary.statistics.channel_message_counts if summary and summary.statistics else {}
        self._counts = {c.topic: counts.get(i, 0) for i, c in (summary.channels.items() if summary else [])}
        self._frames: dict[str, pd.DataFrame] = {}

    def __repr__(self) -> str:
        return f"Run({self.path.name}, status={self.status!r}, topics={self.topic_names})"

    def verify(self) -> Run:
        """Decompress every chunk and check its CRC: a damaged file fails here, not halfway through an
        analysis (C-speed decompression, no message decoding)."""
        from mcap.reader import make_reader
        from mcap.records import Chunk
        from mcap.stream_reader import ReadDataStream, get_chunk_data_stream

        with open(self.path, "rb") as f:
            summary = make_reader(f).get_summary()
            if summary is None:
                raise ValueError(f"{self.path.name} has no summary: not a complete run file")
            for index in summary.chunk_indexes:
                f.seek(index.chunk_start_offset + 9)  # past the record's opcode (1 byte) and length (8)
                get_chunk_data_stream(Chunk.read(ReadDataStream(f)), validate_crc=True)
        return self

    @property
    def run_id(self) -> str:
        return self.metadata["run_id"]

    @property
    def status(self) -> str:
        return self.metadata["status"]

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def config(self) -> dict[str, Any]:
        return yaml.safe_load(self.attachments[CONFIG_ATTACHMENT])

    @property
    def params(self) -> dict[str, Any]:
        """What distinguishes this run in a sweep or a set of episodes: its overrides and sampled values, typed
        (numbers as numbers) from the resolved config."""
        values = self.metadata.get("values")
        if values is not None:
            return json.loads(values)
        return {k: typed(v) for k, v in json.loads(self.metadata.get("params", "{}")).items()}

    def schema_name(self, topic: str) -> str:
        """The full name of a topic's schema (`repro.JointState`, `foxglove.FrameTransforms`, ...)."""
        return self._schemas[topic]

    def message_count(self, topic: str) -> int:
        return self._counts.get(topic, 0)

    def units(self, topic: str) -> dict[str, str]:
        """Column -> unit of a topic (what the writer declared; Foxglove schemas: metres, unit quaternions)."""
        if topic not in self.topic_names:
            raise KeyError(f"{self.path.name} has no topic {topic}; it has {self.topic_names}")
        return dict(self._units.get(topic, {}))

    @property
    def topics(self) -> dict[str, pd.DataFrame]:
        """Every topic as a DataFrame (decodes all of them)."""
        return {topic: self[topic] for topic in self.topic_names}

    def __getitem__(self, topic: str) -> pd.DataFrame:
        if topic not in self._frames:
            if topic not in self.topic_names:
                raise KeyError(f"{self.path.name} has no topic {topic}; it has {self.topic_names}")
            for name, frame in read_topics(self.path, [topic]).items():
                frame.attrs["units"] = self._units.get(name, {})
                self._frames[name] = frame
        return self._frames[topic]


def read_run(path: str | Path) -> Run:
    """Open one run file: metadata and attachments now, topics as they are used."""
    return Run(path)


def run_files(directory: str | Path) -> list[Path]:
    """Complete run files in a directory, sorted; unfinished `.partial` files are never listed."""
    directory = Path(directory)
    return sorted(p for p in directory.glob(f"*{RUN_SUFFIX}") if not p.name.startswith("."))


def typed(text: str) -> Any:
    """A command-line value as Hydra types it: 4 -> int, 0.5 and 1e-4 -> float, true -> bool, null -> None,
    [a,b] -> list; anything else stays a string."""
    if not isinstance(text, str):
        return text
    value = text.strip()
    lowered = value.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered == "null":
        return None
    if value.startswith("[") and value.endswith("]"):
        inner = value[1:-1].strip()
        return [typed(x) for x in inner.split(",")] if inner else []
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    return value


class Runs(list):
    """The runs of an experiment, a sweep or a set of episodes; `table()` and `frame(topic)` make tidy tables."""

    def table(self) -> pd.DataFrame:
        """One row per run: run_id, status, case, episode, seed, wall time and every parameter, typed."""
        import pandas as pd

        rows = []
        for run in self:
            meta = run.metadata
            rows.append({"run_id": run.run_id, "status": run.status, "case": meta.get("case", ""),
                         "episode": int(meta["episode"]) if "episode" in meta else pd.NA,
                         "seed": typed(meta.get("seed", "")),
                         "wall_time_s": float(meta.get("wall_time_s", "nan")), **run.params})
        return pd.DataFrame(rows)

    def frame(self, topic: str, columns: list[str] | None = None, ok_only: bool = True) -> pd.DataFrame:
        """One tidy DataFrame of `topic` over every run: run_id, the run's parameters (typed), t, then the
        topic's columns (all, or `columns`). Runs without the topic are left out; units in `.attrs["units"]`."""
        import pandas as pd

        parts, units = [], {}
        for run in self:
            if (ok_only and not run.ok) or topic not in run.topic_names:
                continue
            data = run[topic] if columns is None else run[topic][columns]
            units.update({c: u for c, u in run.units(topic).items() if c in data.columns})
            head = pd.DataFrame({"run_id": run.run_id, **{k: [v] * len(data) if isinstance(v, list) else v
                                                           for k, v in run.params.items()}}, index=data.index)
            parts.append(pd.concat([head, data], axis=1).reset_index())
        frame = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=["run_id", "t"])
        frame.attrs["units"] = units
        return frame


def read_runs(source: str | Path | Iterable[str | Path], topic: str | None = None) -> Runs | pd.DataFrame:
    """The runs of a directory (an experiment, a sweep, a set of episodes) or of a list of files/directories.

    With `topic`, one tidy DataFrame of that topic over all of them (`Runs.frame`): a whole sweep in one call,
    swept parameters as typed columns (numbers as numbers)."""
    paths: list[Path] = []
    for item in [source] if isinstance(source, str | Path) else source:
        item = Path(item)
        paths += run_files(item) if item.is_dir() else [item]
    runs = Runs(read_run(p) for p in paths)
    return runs.frame(topic) if topic is not None else runs

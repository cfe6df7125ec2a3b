"""Read a run's topics back into DataFrames, at NumPy speed where the messages allow it.

The writer logs each topic in chunks of its own, and series of doubles with one fixed byte layout
(pipeline.core.encoding). Such a chunk is an array of equal records: MCAP's message header, then the message
with its double fields at fixed offsets. One structured NumPy view reads them all, after checking every record's
header, channel, field tags and constant fields against the first message (decoded by protobuf). Anything else
(nested messages, strings that change, fields that come and go, another writer's files) is decoded message by
message. Both paths give the same columns: a repeated field labelled by the message's `name` list becomes
`field.<name>`, else `field[i]`; a repeated message becomes `field.<child_frame_id or name or i>.<subfield>`.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from google.protobuf.descriptor import Descriptor, FieldDescriptor
from google.protobuf.message import Message

from pipeline.core import robot
from pipeline.core.encoding import series_layout

if TYPE_CHECKING:  # imported where frames are built: the simulate stage never builds one (nor reads MCAP)
    import pandas as pd

MESSAGE_OPCODE = 0x05
# opcode, record length, then the Message record's channel id, sequence, log time and publish time
RECORD_HEADER = [("op", "u1"), ("length", "<u8"), ("channel", "<u2"), ("sequence", "<u4"), ("log_time", "<u8"),
                 ("publish_time", "<u8")]
HEADER_BYTES = np.dtype(RECORD_HEADER).itemsize
CONTENT_HEADER_BYTES = HEADER_BYTES - 9  # what the record length counts before the message


def _is_repeated(fd: FieldDescriptor) -> bool:
    return fd.is_repeated if hasattr(fd, "is_repeated") else fd.label == FieldDescriptor.LABEL_REPEATED


@functools.cache
def _plan(descriptor: Descriptor) -> tuple[bool, tuple[tuple[str, bool, bool, bool], ...]]:
    """(labels entries by `name`, [(field, repeated, is_message, optional scalar)]) without the timestamp."""
    name = descriptor.fields_by_name.get("name")
    labelled = name is not None and _is_repeated(name)
    fields = tuple((fd.name, _is_repeated(fd), fd.message_type is not None,
                    fd.message_type is None and not _is_repeated(fd) and fd.has_presence) for fd in descriptor.fields
                   if not (fd.message_type is not None and fd.message_type.full_name == "google.protobuf.Timestamp")
                   and not (labelled and fd.name == "name"))
    return labelled, fields


def flatten(message: Message, prefix: str, row: dict[str, Any]) -> None:
    """Message -> flat columns. Repeated scalars are labelled by the message's `name` list if it has
    one of the same length (`position.shoulder`), else by index (`position[0]`); repeated messages by
    their `child_frame_id`/`name` if they carry one."""
    labelled, fields = _plan(message.DESCRIPTOR)
    names = list(message.name) if labelled else None
    for field_name, repeated, is_message, optional in fields:
        if optional and not message.HasField(field_name):
            continue  # an optional field left out (a joint's velocity) is no column, not a zero
        value = getattr(message, field_name)
        key = prefix + field_name
        if repeated and is_message:
            for i, item in enumerate(value):
                label = getattr(item, "child_frame_id", "") or getattr(item, "name", "") or str(i)
                flatten(item, f"{key}.{label}.", row)
        elif repeated:
            if names is not None and len(names) == len(value):
                row.update(zip([f"{key}.{n}" for n in names], value, strict=True))
            else:
                row.update((f"{key}[{i}]", v) for i, v in enumerate(value))
        elif is_message:
            flatten(value, key + ".", row)
        else:
            row[key] = value


def entry_labels(field: str, count: int, names: list[str] | None) -> list[str]:
    """The column names of a repeated field's entries (what `flatten` makes of them)."""
    if names is not None and len(names) == count:
        return [f"{field}.{n}" for n in names]
    return [f"{field}[{i}]" for i in range(count)]


def _walk(data: bytes, channel: int, first_only: bool = False) -> tuple[int, list[tuple[int, bytes]]]:
    """(offset of the channel's first message record or -1, [(log time, payload)] of its messages): the general,
    record-by-record walk of a chunk."""
    pos, first, found = 0, -1, []
    view = memoryview(data)
    while pos + 9 <= len(data):
        length = int.from_bytes(view[pos + 1:pos + 9], "little")
        if data[pos] == MESSAGE_OPCODE and int.from_bytes(view[pos + 9:pos + 11], "little") == channel:
            if first < 0:
                first = pos
            found.append((int.from_bytes(view[pos + 15:pos + 23], "little"),
                          bytes(view[pos + 9 + CONTENT_HEADER_BYTES:pos + 9 + length])))
            if first_only:
                break
        pos += 9 + length
    return first, found


class _Layout:
    """The fixed layout of a flat message, learnt from its first instance, as a record dtype."""

    def __init__(self, cls: type[Message], first: Message, payload: bytes):
        self.ok = False
        _, fields = _plan(cls.DESCRIPTOR)
        if any(is_message or optional for _, _, is_message, optional in fields):
            return
        by_name = cls.DESCRIPTOR.fields_by_name
        doubles = {f for f, *_ in fields if by_name[f].type == FieldDescriptor.TYPE_DOUBLE}
        constant = {f: getattr(first, f) for f in by_name if f not in doubles and _has(first, by_name[f])}
        repeated = {f: list(getattr(first, f)) for f in doubles if _is_repeated(by_name[f]) and getattr(first, f)}
        scalars = {f: getattr(first, f) for f in doubles if not _is_repeated(by_name[f])}
        # proto3 leaves a zero scalar out (protobuf's own encoder), the series encoder writes it: try both
        for kept in (scalars, {f: v for f, v in scalars.items() if v != 0.0}):
            per_sample = {f: np.asarray([v], dtype=float) for f, v in {**repeated, **kept}.items()}
            layout = series_layout(cls, constant, per_sample)
            if layout is None:
                return
            dtype, fill = layout
            if dtype.itemsize != len(payload):
                continue
            record = np.empty(1, dtype=dtype)
            for key, value in fill.items():
                record[key] = np.void(value) if isinstance(value, bytes) else value
            if record.tobytes() == payload:
                self.ok = True
                self.message = dtype
                self.record = np.dtype(RECORD_HEADER + [(n, *dtype.fields[n][:1]) for n in dtype.names])
                self.fixed = [n for n in dtype.names if n.startswith(("c_", "h_"))]
                self.doubles = [f for f, *_ in fields if f in per_sample]
                return

    def read(self, data: bytes, start: int, channel: int, reference: np.ndarray | None) -> np.ndarray | None:
        """The records of one chunk from `start` as one array, or None if they are not all this layout."""
        stride = self.record.itemsize
        if (len(data) - start) % stride:
            return None
        records = np.frombuffer(data, dtype=self.record, offset=start, count=(len(data) - start) // stride)
        if not ((records["op"] == MESSAGE_OPCODE).all() and (records["length"] == stride - 9).all()
                and (records["channel"] == channel).all()):
            return None
        reference = records[:1] if reference is None else reference
        for name in self.fixed:  # tags, lengths and constant fields: the same bytes in every record
            if not (records[name] == reference[name][0]).all():
                return None
        return records


def _has(message: Message, fd: FieldDescriptor) -> bool:
    value = getattr(message, fd.name)
    return len(value) > 0 if _is_repeated(fd) else value != fd.default_value


def _chunks(f, summary, channel: int) -> Iterable[bytes]:
    from mcap.records import Chunk
    from mcap.stream_reader import ReadDataStream, get_chunk_data_stream

    for index in sorted(summary.chunk_indexes, key=lambda i: i.chunk_start_offset):
        if channel in index.message_index_offsets:
            f.seek(index.chunk_start_offset + 9)  # past the record's opcode (1 byte) and length (8)
            stream, length = get_chunk_data_stream(Chunk.read(ReadDataStream(f)))
            yield stream.read(length)


def _frame(times: np.ndarray, rows: dict[str, Any]) -> pd.DataFrame:
    import pandas as pd

    index = pd.Index(times.astype(np.int64) / 1e9, name="t")
    return pd.DataFrame(rows, index=index).sort_index(kind="stable")


def _read_topic(f, summary, channel_id: int, decode, arrays: bool = True) -> pd.DataFrame | None:
    import pandas as pd

    chunks = list(_chunks(f, summary, channel_id))
    starts = [_walk(data, channel_id, first_only=True) for data in chunks]
    payload = next((found[0][1] for _, found in starts if found), None)
    if payload is None:
        return None
    first = decode(payload)
    layout = _Layout(type(first), first, payload) if arrays and isinstance(first, Message) else None
    if layout is not None and layout.ok:
        blocks, reference = [], None
        for data, (start, _) in zip(chunks, starts, strict=True):
            block = layout.read(data, start, channel_id, reference) if start >= 0 else None
            if block is None:
                break
            reference = block[:1] if reference is None else reference
            blocks.append(block)
        else:
            return _fast_frame(np.concatenate(blocks), layout, first)
    messages = [m for data in chunks for m in _walk(data, channel_id)[1]]
    rows = []
    for _, data in messages:
        decoded, row = decode(data), {}
        if isinstance(decoded, dict):
            row.update(decoded)
        else:
            flatten(decoded, "", row)
        rows.append(row)
    index = pd.Index(np.array([t for t, _ in messages], dtype=np.int64) / 1e9, name="t")
    return pd.DataFrame.from_records(rows, index=index).sort_index(kind="stable")


def _fast_frame(records: np.ndarray, layout: _Layout, first: Message) -> pd.DataFrame:

    row0: dict[str, Any] = {}
    flatten(first, "", row0)
    labelled, _ = _plan(first.DESCRIPTOR)
    names = list(first.name) if labelled else None
    columns: dict[str, Any] = {}
    n = len(records)
    doubles = set(layout.doubles)
    for column, value in row0.items():
        field = column.split(".", 1)[0].split("[", 1)[0]
        if field not in doubles:
            columns[column] = np.full(n, value) if not isinstance(value, str) else [value] * n
    for field in layout.doubles:
        values = records[field]
        if values.ndim == 1:
            columns[field] = values.astype(float, copy=True)
        else:
            for i, label in enumerate(entry_labels(field, values.shape[1], names)):
                columns[label] = values[:, i].astype(float, copy=True)
    ordered = {c: columns[c] for c in row0 if c in columns}
    return _frame(records["log_time"], ordered)


class _Ros2StringDecoder:
    """Decodes the ROS 2 `std_msgs/msg/String` channels (`/robot_description`) as a one-field message."""

    def decoder_for(self, message_encoding: str, schema):
        if message_encoding == "cdr" and schema is not None and schema.name == robot.ROS2_STRING[0]:
            return lambda payload: {"data": robot.decode_ros2_string(payload)}
        return None


def read_topics(path: str | Path, topics: Iterable[str], arrays: bool = True) -> dict[str, pd.DataFrame]:
    """Topic -> DataFrame indexed by simulated time `t` (s), for each of `topics` the file has. `arrays=False`
    decodes every message with protobuf (the general path; the benchmark compares the two)."""
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory

    wanted = set(topics)
    frames: dict[str, pd.DataFrame] = {}
    factories = (DecoderFactory(), _Ros2StringDecoder())
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
        if summary is None:
            raise ValueError(f"{Path(path).name} has no summary: not a complete run file")
        for channel_id, channel in summary.channels.items():
            if channel.topic not in wanted:
                continue
            schema = summary.schemas[channel.schema_id]
            decode = next(d for d in (f.decoder_for(channel.message_encoding, schema) for f in factories) if d)
            frame = _read_topic(f, summary, channel_id, decode, arrays)
            if frame is not None:
                frames[channel.topic] = frame
    return frames

"""Read a run's topics back into DataFrames, column by column in NumPy where the messages allow it.

A topic's messages are located through each chunk's message index (or, in a file without one, by walking the
chunk's records), then read by the first of three paths that applies:
- a series of doubles with one fixed byte layout (pipeline.core.encoding), every message checked byte for byte
  against the first one's tags, lengths and constant fields, is one structured NumPy view of the chunk;
- any other protobuf topic of at least MIN_COLUMNAR messages is decoded field by field over all messages at
  once (pipeline.core.wire), and its columns must equal protobuf's on the messages where they first appear
  and on the last one;
- anything else (fields out of order, unknown fields, another writer's quirks, a damaged message) is decoded
  message by message with protobuf, which is also the reference the tests hold the fast paths to.
All paths give the same columns: a repeated field labelled by the message's `name` list becomes `field.<name>`,
else `field[i]`; a repeated message becomes `field.<child_frame_id or name or i>.<subfield>`; an optional scalar
left out is no column.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from google.protobuf.descriptor import Descriptor, FieldDescriptor
from google.protobuf.message import Message

from pipeline.core import robot, wire
from pipeline.core.encoding import series_layout

if TYPE_CHECKING:  # imported where frames are built: the simulate stage never builds one (nor reads MCAP)
    import pandas as pd

MESSAGE_OPCODE = 0x05
MESSAGE_INDEX_OPCODE = 0x07
MAX_FIRST_ROWS = 64  # columns that first appear in more messages than this: decoded message by message
MIN_COLUMNAR = 32  # fewer messages than this: protobuf decodes them faster than NumPy steps per field
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


def _chunk_data(f, index) -> bytes:
    from mcap.records import Chunk
    from mcap.stream_reader import ReadDataStream, get_chunk_data_stream

    f.seek(index.chunk_start_offset + 9)  # past the record's opcode (1 byte) and length (8)
    chunk = Chunk.read(ReadDataStream(f))
    if chunk.compression == "lz4":  # the writer's: decompressed straight into one bytes object
        import lz4.frame

        data = lz4.frame.decompress(chunk.data)
    else:
        stream, length = get_chunk_data_stream(chunk)
        data = stream.read(length)
    if len(data) != chunk.uncompressed_size:
        raise ValueError(f"a chunk decompresses to {len(data)} bytes, its record says {chunk.uncompressed_size}")
    return data


def _indexed_offsets(f, index, channel: int) -> np.ndarray | None:
    """Offsets of the channel's message records in a chunk, from the chunk's message index (None if it has none)."""
    offset = index.message_index_offsets.get(channel)
    if offset is None:
        return None
    f.seek(offset)
    head = f.read(15)  # opcode, record length, channel id, byte length of the (log time, offset) array
    if len(head) < 15 or head[0] != MESSAGE_INDEX_OPCODE or int.from_bytes(head[9:11], "little") != channel:
        return None
    entries = np.frombuffer(f.read(int.from_bytes(head[11:15], "little")), dtype=[("t", "<u8"), ("offset", "<u8")])
    return np.sort(entries["offset"]).astype(np.int64)


def _walked_offsets(data: bytes, channel: int) -> np.ndarray:
    """Offsets of the channel's message records in a chunk, record by record (a file without message indexes)."""
    pos, found = 0, []
    view = memoryview(data)
    while pos + 9 <= len(data):
        if data[pos] == MESSAGE_OPCODE and int.from_bytes(view[pos + 9:pos + 11], "little") == channel:
            found.append(pos)
        pos += 9 + int.from_bytes(view[pos + 1:pos + 9], "little")
    return np.array(found, dtype=np.int64)


def _messages(f, summary, channel: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(bytes of the chunks, payload starts, payload ends, log times) of a channel's messages in file order."""
    parts, starts, ends, times = [], [], [], []
    base = 0
    for index in sorted(summary.chunk_indexes, key=lambda i: i.chunk_start_offset):
        if index.message_index_offsets and channel not in index.message_index_offsets:
            continue  # a chunk without message indexes may hold any channel: it is walked
        offsets = _indexed_offsets(f, index, channel)
        data = _chunk_data(f, index)
        if offsets is None:
            offsets = _walked_offsets(data, channel)
        chunk = np.frombuffer(data, dtype=np.uint8)
        if len(offsets) and offsets[-1] + HEADER_BYTES > len(chunk):
            raise ValueError(f"message index points past the end of a chunk of channel {channel}")
        head = np.ndarray((len(chunk) - HEADER_BYTES + 1,), dtype=RECORD_HEADER, buffer=chunk, strides=(1,))[offsets]
        stop = offsets + 9 + head["length"].astype(np.int64)
        if not ((head["op"] == MESSAGE_OPCODE).all() and (head["channel"] == channel).all()
                and (head["length"] >= CONTENT_HEADER_BYTES).all() and (stop <= len(chunk)).all()):
            raise ValueError(f"a chunk's message records of channel {channel} do not match its message index")
        parts.append(data)
        starts.append(base + offsets + HEADER_BYTES)
        ends.append(base + stop)
        times.append(head["log_time"])
        base += len(data)
    buf = np.frombuffer(b"".join([*parts, bytes(wire.PAD)]), dtype=np.uint8)
    empty = np.zeros(0, np.int64)
    return (buf, np.concatenate(starts) if starts else empty, np.concatenate(ends) if ends else empty,
            np.concatenate(times).astype(np.int64) if times else empty)


class _Layout:
    """The fixed byte layout of a flat series of doubles (pipeline.core.encoding), learnt from its first message
    and checked byte for byte against it."""

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
                self.fixed = [n for n in dtype.names if n.startswith(("c_", "h_"))]
                self.doubles = [f for f, *_ in fields if f in per_sample]
                return

    def read(self, buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray | None:
        """The messages as one record array (views of the chunks' equal, back-to-back records), or None if
        they are not all of this layout."""
        size = self.message.itemsize
        if (ends - starts != size).any():
            return None
        breaks = np.flatnonzero(np.diff(starts) != size + HEADER_BYTES) + 1  # chunk boundaries
        if len(breaks) > len(starts) // 16:  # records of other channels in between (another writer's chunks)
            return None
        blocks = [np.ndarray((b - a,), dtype=self.message, buffer=buf, offset=int(starts[a]),
                             strides=(size + HEADER_BYTES,))
                  for a, b in zip([0, *breaks.tolist()], [*breaks.tolist(), len(starts)], strict=True)]
        for name in self.fixed:  # tags, lengths and constant fields: the same bytes in every message
            if not all((block[name] == blocks[0][name][0]).all() for block in blocks):
                return None
        return blocks[0] if len(blocks) == 1 else np.concatenate(blocks)


def _has(message: Message, fd: FieldDescriptor) -> bool:
    value = getattr(message, fd.name)
    return len(value) > 0 if _is_repeated(fd) else value != fd.default_value


def _series(first: Message, buf: np.ndarray, starts: np.ndarray, ends: np.ndarray,
            times: np.ndarray) -> pd.DataFrame | None:
    """A flat series of doubles of one fixed layout read as one record array, or None."""
    layout = _Layout(type(first), first, buf[starts[0]:ends[0]].tobytes())
    records = layout.read(buf, starts, ends) if layout.ok else None
    if records is None:
        return None
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
            columns[column] = _values(wire.Column(column, None, wire.Texts(np.zeros(n, np.int64), np.array(
                [value], dtype=object))), n) if isinstance(value, str) else np.full(n, value)
    for field in layout.doubles:
        values = records[field]
        if values.ndim == 1:
            columns[field] = values.astype(float, copy=True)
        else:
            for i, label in enumerate(entry_labels(field, values.shape[1], names)):
                columns[label] = values[:, i].astype(float, copy=True)
    return _frame(times, {c: columns[c] for c in row0 if c in columns})


def _frame(times: np.ndarray, columns: dict[str, Any]) -> pd.DataFrame:
    import pandas as pd

    index = pd.Index(times.astype(np.int64) / 1e9, name="t")
    values = list(columns.values())
    if values and all(isinstance(v, np.ndarray) and v.dtype == np.float64 for v in values):
        frame = pd.DataFrame(np.stack(values).T, columns=list(columns), index=index, copy=False)  # one block
    else:
        frame = pd.DataFrame(columns, index=index)
    return frame if index.is_monotonic_increasing else frame.sort_index(kind="stable")


@functools.cache
def _text_dtype() -> Any:
    """The dtype pandas gives a column of Python strings (pandas 3: `str`, stored in Arrow)."""
    import pandas as pd

    return pd.Series(["a"]).dtype


@functools.lru_cache(maxsize=1024)
def _constant_text(text: str, n: int) -> Any:
    """n times `text` as a pandas string array (never modified: pandas copies on write)."""
    import pandas as pd
    import pyarrow as pa

    return pd.array(pa.array([text], pa.large_string()).take(pa.array(np.zeros(n, np.int32))), dtype=_text_dtype())


def _values(column: wire.Column, n: int) -> Any:
    """A column over all n rows: NaN where a message has no value, as pandas makes of protobuf's rows."""
    values = column.values
    dense = column.rows is None or len(column.rows) == n
    if isinstance(values, wire.Texts):
        unique = values.unique.tolist()
        if getattr(_text_dtype(), "storage", None) == "pyarrow" and all(isinstance(u, str) for u in unique):
            if dense and len(unique) == 1:  # a frame id, a joint's name: the same column in every file
                return _constant_text(unique[0], n)
            import pandas as pd
            import pyarrow as pa

            codes = values.codes.astype(np.int32)
            if not dense:
                codes = np.full(n, -1, np.int32)
                codes[column.rows] = values.codes
            texts = pa.DictionaryArray.from_arrays(pa.array(codes, mask=codes < 0), pa.array(unique, pa.large_string()))
            return pd.array(texts.dictionary_decode(), dtype=_text_dtype())  # no Python string per row; NaN where none
        values = values.objects()
    if dense:
        return values
    full = np.full(n, np.nan, dtype=float if values.dtype.kind in "fiu" else object)
    full[column.rows] = values
    return full


def _same(a: Any, b: Any) -> bool:
    return a == b or (isinstance(a, float) and isinstance(b, float) and a != a and b != b)


def _columnar(cls: type[Message], buf: np.ndarray, starts: np.ndarray, ends: np.ndarray,
              times: np.ndarray) -> pd.DataFrame | None:
    """The topic decoded column by column (pipeline.core.wire), or None where that does not apply.

    The columns are ordered as pandas orders protobuf's rows (first appearance), read off the first message
    in which each column appears; those messages and the last one are also decoded by protobuf and must hold
    exactly the same values."""
    try:
        found = wire.columns(cls.DESCRIPTOR, buf, starts, ends)
    except wire.Irregular:
        return None
    n = len(starts)
    columns = {c.name: c for c in found if c.rows is None or len(c.rows)}
    if len(columns) != len([c for c in found if c.rows is None or len(c.rows)]):
        return None  # two fields flatten to one name: protobuf's rows say which wins

    dense = {name for name, c in columns.items() if c.rows is None or len(c.rows) == n}
    sparse = {name: c for name, c in columns.items() if name not in dense}

    def value(column: wire.Column, row: int) -> Any:
        values = column.values
        return values.unique[values.codes[row]] if isinstance(values, wire.Texts) else values[row].item()

    first = {name: 0 if c.rows is None else int(c.rows[0]) for name, c in columns.items()}
    rows = sorted(set(first.values()))
    if len(rows) > MAX_FIRST_ROWS:
        return None
    checked = np.array([*rows, n - 1])
    where, by_rows = {}, {}  # sparse column -> (index of each checked row in its rows, or -1)
    for name, c in sparse.items():
        if id(c.rows) not in by_rows:  # the subfields of one repeated entry share their rows
            at = np.minimum(np.searchsorted(c.rows, checked), len(c.rows) - 1)
            by_rows[id(c.rows)] = np.where(c.rows[at] == checked, at, -1).tolist()
        where[name] = by_rows[id(c.rows)]
    order: dict[str, None] = {}
    for i, row in enumerate(checked.tolist()):
        expected: dict[str, Any] = {}
        flatten(cls.FromString(buf[starts[row]:ends[row]].tobytes()), "", expected)
        at = {name: w[i] for name, w in where.items() if w[i] >= 0}
        if len(expected) != len(dense) + len(at) or not all(
                (k in dense or k in at) and _same(value(columns[k], at.get(k, row)), v) for k, v in expected.items()):
            return None
        order.update(dict.fromkeys(expected))
    if len(order) != len(columns):
        return None
    return _frame(times, {name: _values(columns[name], n) for name in order})


def _read_topic(f, summary, channel_id: int, decode, arrays: bool = True) -> pd.DataFrame | None:
    import pandas as pd

    buf, starts, ends, times = _messages(f, summary, channel_id)
    if not len(starts):
        return None
    first = decode(buf[starts[0]:ends[0]].tobytes())
    if arrays and isinstance(first, Message):
        frame = _series(first, buf, starts, ends, times)
        if frame is None and len(starts) >= MIN_COLUMNAR:
            frame = _columnar(type(first), buf, starts, ends, times)
        if frame is not None:
            return frame
    rows = []
    for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
        decoded, row = decode(buf[a:b].tobytes()), {}
        if isinstance(decoded, dict):
            row.update(decoded)
        else:
            flatten(decoded, "", row)
        rows.append(row)
    index = pd.Index(times / 1e9, name="t")
    return pd.DataFrame.from_records(rows, index=index).sort_index(kind="stable")


class _Ros2StringDecoder:
    """Decodes the ROS 2 `std_msgs/msg/String` channels (`/robot_description`) as a one-field message."""

    def decoder_for(self, message_encoding: str, schema):
        if message_encoding == "cdr" and schema is not None and schema.name == robot.ROS2_STRING[0]:
            return lambda payload: {"data": robot.decode_ros2_string(payload)}
        return None


_DECODERS: dict[tuple, Callable[[bytes], Any]] = {}   # (message encoding, schema name, encoding, data) -> decode


def read_topics(path: str | Path, topics: Iterable[str], arrays: bool = True) -> dict[str, pd.DataFrame]:
    """Topic -> DataFrame indexed by simulated time `t` (s), for each of `topics` the file has. `arrays=False`
    decodes every message with protobuf (the general path; the benchmark compares the two)."""
    from mcap.reader import make_reader  # imported where read: a simulate stage never reads MCAP
    from mcap_protobuf.decoder import DecoderFactory

    wanted = set(topics)
    frames: dict[str, pd.DataFrame] = {}
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
        if summary is None:
            raise ValueError(f"{Path(path).name} has no summary: not a complete run file")
        for channel_id, channel in summary.channels.items():
            if channel.topic not in wanted:
                continue
            schema = summary.schemas[channel.schema_id]
            key = (channel.message_encoding, schema.name, schema.encoding, schema.data)
            if key not in _DECODERS:  # a schema's message classes are built once per process, not once per file
                factories = (DecoderFactory(), _Ros2StringDecoder())
                _DECODERS[key] = next(d for d in (f.decoder_for(channel.message_encoding, schema)
                                                  for f in factories) if d)
            decode = _DECODERS[key]
            frame = _read_topic(f, summary, channel_id, decode, arrays)
            if frame is not None:
                frames[channel.topic] = frame
    return frames

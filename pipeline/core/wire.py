"""Decode a whole series of protobuf messages column by column in NumPy: the reader's fast path.

Protobuf writers (upb, prost, this project's encoders) write a message's fields in field-number order, so the n
messages of a topic can be parsed in lock step. For each field of the schema, in order, one NumPy step reads
the tag at every message's current position; the messages that carry the field read its value and move on. A
repeated field takes one step per entry, a nested message is parsed the same way over its byte ranges. What
comes out is what `decoding.flatten` makes of each message, as columns.

Anything this does not expect (fields out of order or split, unknown fields, a wire type the schema does not
give, a varint or length running past its message, labels that repeat within a message) raises `Irregular`,
and the caller decodes the series with protobuf instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from google.protobuf.descriptor import Descriptor, FieldDescriptor

PAD = 16  # zero bytes after the last message: a varint read near the end never indexes past the buffer
MAX_DEPTH = 32

_T = FieldDescriptor
# field type -> NumPy dtype of its fixed-width value
_FIXED = {_T.TYPE_DOUBLE: "<f8", _T.TYPE_FIXED64: "<u8", _T.TYPE_SFIXED64: "<i8", _T.TYPE_FLOAT: "<f4",
          _T.TYPE_FIXED32: "<u4", _T.TYPE_SFIXED32: "<i4"}
_VARINT = {_T.TYPE_INT64, _T.TYPE_UINT64, _T.TYPE_INT32, _T.TYPE_UINT32, _T.TYPE_SINT32, _T.TYPE_SINT64,
           _T.TYPE_BOOL, _T.TYPE_ENUM}
_BYTES = {_T.TYPE_STRING, _T.TYPE_BYTES}
_3, _7 = np.uint64(3), np.uint64(7)


def _wire(fd: FieldDescriptor) -> int:
    if fd.message_type is not None or fd.type in _BYTES:
        return 2
    if fd.type in _FIXED:
        return 1 if np.dtype(_FIXED[fd.type]).itemsize == 8 else 5
    return 0


def _dtype(fd: FieldDescriptor) -> type:
    """The column dtype of a scalar field (what pandas makes of protobuf's Python values)."""
    if fd.type in (_T.TYPE_DOUBLE, _T.TYPE_FLOAT):
        return np.float64
    if fd.type == _T.TYPE_BOOL:
        return np.bool_
    return object if fd.type in _BYTES else np.int64


class Irregular(Exception):
    """The series is not one this decoder reads exactly: decode it with protobuf."""


@dataclass
class Texts:
    """Strings (or bytes) as codes into their distinct values: labels and equality stay integer work."""

    codes: np.ndarray
    unique: np.ndarray  # object array

    def __len__(self) -> int:
        return len(self.codes)

    def __getitem__(self, selection: np.ndarray) -> Texts:
        return Texts(self.codes[selection], self.unique)

    def objects(self) -> np.ndarray:
        return self.unique[self.codes]

    def code_of(self, text: str | bytes) -> int:
        """The code of `text`, -1 if no value is `text`."""
        hits = [i for i, value in enumerate(self.unique.tolist()) if value == text]
        return hits[0] if hits else -1


@dataclass
class Column:
    """Values of one flat column over a set of messages: `rows` (indices into the set, ascending) or None for
    every message of the set."""

    name: str
    rows: np.ndarray | None
    values: np.ndarray | Texts


def _varint(buf: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Base-128 varints at `pos`: (values as uint64, bytes each)."""
    byte = buf[pos]
    value = (byte & 0x7F).astype(np.uint64)
    size = np.ones(len(pos), dtype=np.int64)
    more = np.flatnonzero(byte & 0x80)
    shift = 7
    while len(more):
        if shift > 63:
            raise Irregular("varint longer than 10 bytes")
        byte = buf[pos[more] + size[more]]
        value[more] |= (byte & 0x7F).astype(np.uint64) << np.uint64(shift)
        size[more] += 1
        more = more[(byte & 0x80) != 0]
        shift += 7
    return value, size


def _fixed(buf: np.ndarray, pos: np.ndarray, dtype: str) -> np.ndarray:
    """Fixed-width values starting at byte offsets `pos`: one gather through a view whose elements start at
    every byte (NumPy reads unaligned values)."""
    width = np.dtype(dtype).itemsize
    return np.ndarray((len(buf) - width + 1,), dtype=dtype, buffer=buf, strides=(1,))[pos]


def _scalars(fd: FieldDescriptor, buf: np.ndarray, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Values of numeric field `fd` at `pos` and the bytes each takes."""
    if fd.type in _FIXED:
        dtype = _FIXED[fd.type]
        values = _fixed(buf, pos, dtype)
        if dtype == "<u8" and (values >> np.uint64(63)).any():
            raise Irregular("fixed64 beyond int64")
        return values.astype(float if dtype[1] == "f" else np.int64), np.dtype(dtype).itemsize
    if fd.type in _VARINT:
        raw, size = _varint(buf, pos)
        if fd.type == _T.TYPE_BOOL:
            return raw != 0, size
        if fd.type in (_T.TYPE_SINT32, _T.TYPE_SINT64):
            return (raw >> np.uint64(1)).astype(np.int64) ^ -(raw & np.uint64(1)).astype(np.int64), size
        if fd.type in (_T.TYPE_UINT64, _T.TYPE_UINT32) and (raw >> np.uint64(63)).any():
            raise Irregular("uint64 beyond int64")
        values = raw.view(np.int64)
        return (values.astype(np.int32).astype(np.int64) if fd.type == _T.TYPE_INT32 else values), size
    raise Irregular(f"field type {fd.type}")


def _texts(buf: np.ndarray, start: np.ndarray, length: np.ndarray, decode: bool) -> Texts:
    """Strings (or bytes) at `start`: grouped by their bytes (compared 8 at a time), each distinct value made
    into a Python object once."""
    if not len(start):
        return Texts(np.zeros(0, np.int64), np.zeros(0, dtype=object))
    last = len(buf) - 8
    words = []
    for j in range(0, int(length.max()), 8):
        left = np.clip(length - j, 0, 8).astype(np.uint64)
        mask = np.where(left == 8, ~np.uint64(0), (np.uint64(1) << (left * np.uint64(8))) - np.uint64(1))
        words.append(_fixed(buf, np.minimum(start + j, last), "<u8") & mask)
    keys = np.stack([length.astype(np.uint64), *words], axis=1)
    if (keys == keys[0]).all():  # most often one value: a frame id, a name
        codes, first = np.zeros(len(start), np.int64), np.zeros(1, np.int64)
    else:
        import pandas as pd

        digest = keys[:, 0]
        for j in range(1, keys.shape[1]):
            digest = digest * np.uint64(0x100000001B3) ^ keys[:, j]  # wraps around: a hash, checked below
        codes, _ = pd.factorize(digest)  # numbered by first appearance
        first = np.flatnonzero(codes > np.maximum.accumulate(np.concatenate([[-1], codes[:-1]])))
        if not (keys == keys[first[codes]]).all():
            raise Irregular("two strings with one hash")
    unique = np.empty(len(first), dtype=object)
    for i, row in enumerate(first.tolist()):
        raw = buf[start[row]:start[row] + length[row]].tobytes()
        try:
            unique[i] = raw.decode() if decode else raw
        except UnicodeDecodeError as err:
            raise Irregular("invalid UTF-8 in a string field") from err
    return Texts(codes, unique)


def _is_timestamp(fd: FieldDescriptor) -> bool:
    return fd.message_type is not None and fd.message_type.full_name == "google.protobuf.Timestamp"


def _repeated(fd: FieldDescriptor) -> bool:
    return fd.is_repeated if hasattr(fd, "is_repeated") else fd.label == _T.LABEL_REPEATED


def _packed(fd: FieldDescriptor, buf: np.ndarray, start: np.ndarray, length: np.ndarray) \
        -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The elements of packed segments (start, length): (segment of each element, index in it, values)."""
    if fd.type in _FIXED:
        width = np.dtype(_FIXED[fd.type]).itemsize
        if (length % width).any():
            raise Irregular("packed field length")
        count = length // width
    else:
        if fd.type not in _VARINT:
            raise Irregular("packed field type")
        first = np.repeat(start - np.cumsum(length) + length, length)  # every byte of every segment
        at = first + np.arange(len(first))
        ends = buf[at] < 0x80
        owner = np.repeat(np.arange(len(start)), length)
        if len(start) and (buf[start + length - 1] >= 0x80)[length > 0].any():
            raise Irregular("packed varint runs past its field")
        count = np.bincount(owner[ends], minlength=len(start))
    segment = np.repeat(np.arange(len(start)), count)
    k = np.arange(len(segment)) - np.repeat(np.cumsum(count) - count, count)
    if fd.type in _FIXED:
        values, _ = _scalars(fd, buf, start[segment] + k * width)
    else:
        starts = np.concatenate([[0], np.flatnonzero(ends)[:-1] + 1]) if len(segment) else np.zeros(0, np.int64)
        values, _ = _scalars(fd, buf, at[starts])
    return segment, k, values


def _joined(parts: list[Texts]) -> Texts:
    """The strings of several steps as one."""
    if len(parts) == 1:
        return parts[0]
    unique = list(dict.fromkeys(v for p in parts for v in p.unique.tolist()))
    where = {v: i for i, v in enumerate(unique)}
    codes = [np.array([where[v] for v in p.unique.tolist()], dtype=np.int64)[p.codes] for p in parts]
    values = np.empty(len(unique), dtype=object)
    values[:] = unique
    return Texts(np.concatenate(codes) if codes else np.zeros(0, np.int64), values)


def _tags(buf: np.ndarray, pos: np.ndarray, live: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tag (0 where the message has ended, `live` false) and its size at each position."""
    if live.all():
        return _varint(buf, pos)
    tag, size = np.zeros(len(pos), np.uint64), np.zeros(len(pos), np.int64)
    tag[live], size[live] = _varint(buf, pos[live])
    return tag, size


def columns(desc: Descriptor, buf: np.ndarray, start: np.ndarray, end: np.ndarray, depth: int = 0) -> list[Column]:
    """The flat columns of the messages of type `desc` at byte ranges [start, end) of `buf`."""
    if depth > MAX_DEPTH:
        raise Irregular("nesting too deep")
    m = len(start)
    pos = start.copy()
    tag, size = _tags(buf, pos, pos < end)  # at each message's position
    name_fd = desc.fields_by_name.get("name")
    labelled = name_fd is not None and _repeated(name_fd)
    if labelled and name_fd.type != _T.TYPE_STRING:
        raise Irregular(f"{desc.full_name}: names that are not strings")
    out: list[Column] = []
    repeated_scalars: list[tuple[FieldDescriptor, tuple]] = []
    names: tuple | None = None
    for fd in sorted(desc.fields, key=lambda f: f.number):
        repeated, delimited = _repeated(fd), fd.message_type is not None or fd.type in _BYTES
        packable = repeated and not delimited
        expected, packed_tag = fd.number << 3 | _wire(fd), fd.number << 3 | 2
        # a tag of this field with another wire type is not read: it stays, and the message ends irregular
        owners, ks, found = [], [], []  # per step: the messages that carry the field, entry index, values
        count = np.zeros(m, np.int64)
        while True:
            hit = tag == expected
            if packable:
                packed = tag == packed_tag
                hit |= packed
            at = np.flatnonzero(hit)
            if not len(at):
                break
            sel = slice(None) if len(at) == m else at  # every message: views instead of gathers
            value_pos = pos[sel] + size[sel]
            k = count[at] if repeated else None
            if delimited or (packable and packed[sel].any()):
                if packable and not packed[sel].all():
                    raise Irregular(f"{fd.full_name} packed in some messages only")
                length, lsize = _varint(buf, value_pos)
                value_pos += lsize
                stop = value_pos + length.astype(np.int64)
                if fd.message_type is not None:
                    values = np.stack([value_pos, stop], axis=1)
                elif delimited:  # per step: the strings of one step are most often all one value
                    values = _texts(buf, value_pos, stop - value_pos, fd.type == _T.TYPE_STRING)
                else:  # a packed segment
                    segment, k_in, values = _packed(fd, buf, value_pos, stop - value_pos)
                    count[sel] += np.bincount(segment, minlength=len(at)) - 1
                    k = k[segment] + k_in
                    at = at[segment]
            else:
                values, vsize = _scalars(fd, buf, value_pos)
                stop = value_pos + vsize
            if repeated:
                count[sel] += 1
            owners.append(at)
            ks.append(k)
            found.append(values)
            left = end[sel] - stop
            if (left < 0).any():
                raise Irregular(f"{fd.full_name} runs past its message")
            pos[sel] = stop
            tag[sel], size[sel] = _tags(buf, stop, left > 0)
            if not repeated:
                break
        if _is_timestamp(fd):
            continue
        owner = np.concatenate(owners) if owners else np.zeros(0, np.int64)
        k = np.concatenate(ks) if repeated and ks else np.zeros(0, np.int64)
        if fd.message_type is not None:
            ranges = np.concatenate(found) if found else np.zeros((0, 2), np.int64)
            if repeated:
                out += _repeated_messages(fd, buf, m, owner, k, ranges, depth)
            else:  # an absent message reads as its defaults: an empty range
                sub_start, sub_end = np.zeros(m, np.int64), np.zeros(m, np.int64)
                sub_start[owner], sub_end[owner] = ranges[:, 0], ranges[:, 1]
                out += [Column(f"{fd.name}.{c.name}", c.rows, c.values)
                        for c in columns(fd.message_type, buf, sub_start, sub_end, depth + 1)]
            continue
        values = _joined(found) if delimited else np.concatenate(found) if found else np.zeros(0, _dtype(fd))
        if repeated:
            entries = (owner, k, values, _per_entry(found, count, m))
            if labelled and fd.name == "name":
                names = entries
            else:
                repeated_scalars.append((fd, entries))
        elif fd.has_presence:  # an optional field left out is no column
            out.append(Column(fd.name, owner, values))
        elif isinstance(values, Texts):  # proto3 leaves out an empty string: the default
            unique = np.append(values.unique, np.array([fd.default_value], dtype=object))
            codes = np.full(m, len(unique) - 1)
            codes[owner] = values.codes
            out.append(Column(fd.name, None, Texts(codes, unique)))
        else:  # and a zero, false
            dense = np.full(m, fd.default_value, dtype=_dtype(fd))
            dense[owner] = values
            out.append(Column(fd.name, None, dense))
    if (pos != end).any():
        raise Irregular(f"{desc.full_name}: fields out of order, repeated or unknown")
    for fd, entries in repeated_scalars:
        out += _labelled_entries(fd.name, m, entries, names, labelled)
    return out


def _per_entry(found: list, count: np.ndarray, m: int) -> list | None:
    """A repeated field's values as one array per entry index, if every message has as many entries."""
    c = int(count[0]) if m else 0
    if not c or (count != c).any():
        return None
    if len(found) == c and all(len(v) == m for v in found):  # one step per entry
        return found
    if len(found) == 1 and not isinstance(found[0], Texts):  # one packed segment per message
        return list(found[0].reshape(m, c).T)
    return None


def _labelled_entries(field: str, m: int, entries: tuple, names: tuple | None, labelled: bool) -> list[Column]:
    """Columns of a repeated scalar field: `field.<name>` where the message's names are as many as its
    entries, else `field[i]` (decoding.entry_labels)."""
    owner, k, values, per_entry = entries
    if per_entry is not None:  # as many entries in every message, and names (if any) alike in every one
        same_names = None
        if not labelled or not len(names[0]):
            same_names = []
        elif names[3] is not None and all(len(t.unique) == 1 for t in names[3]):
            same_names = [t.unique[0] for t in names[3]]
        if same_names is not None and len(set(same_names)) == len(same_names):
            labels = [f".{n}" for n in same_names] if len(same_names) == len(per_entry) else \
                [f"[{j}]" for j in range(len(per_entry))]
            return [Column(field + label, None, v) for label, v in zip(labels, per_entry, strict=True)]
    codes, texts = -(k + 1), []  # codes below 0: the index; from 0: the code of a name
    if labelled and len(owner):
        name_owner, name_k, name_texts, _ = names
        named = (np.bincount(name_owner, minlength=m) == np.bincount(owner, minlength=m))[owner]
        if named.any():
            table = np.full((m, int(name_k.max()) + 1), -1)
            table[name_owner, name_k] = name_texts.codes
            codes = np.where(named, table[owner, np.minimum(k, table.shape[1] - 1)], codes)
        texts = name_texts.unique.tolist()
    return _group(field, m, owner, k, codes, lambda c: f".{texts[c]}" if c >= 0 else f"[{-c - 1}]", values)


def _group(field: str, m: int, owner: np.ndarray, k: np.ndarray, codes: np.ndarray, label, values) -> list[Column]:
    """One column per distinct label (`label(code)`) of the entries (owner, k); a label twice in one message is
    irregular."""
    if not len(codes):
        return []
    count = len(owner) // m
    if count * m == len(owner) and (np.bincount(owner, minlength=m) == count).all():
        at = np.empty((m, count), np.int64)  # every message has `count` entries: at[message, k] is where
        at[owner, k] = np.arange(len(owner))
        per_entry = codes[at]
        if (per_entry == per_entry[0]).all():  # ... labelled alike in every message (joints, frames)
            labels = [label(c) for c in per_entry[0].tolist()]
            if len(set(labels)) == len(labels):
                return [Column(f"{field}{text}", None, values[at[:, j]]) for j, text in enumerate(labels)]
    unique, inverse = np.unique(codes, return_inverse=True)
    labels = [label(c) for c in unique.tolist()]
    distinct, merged = np.unique(np.array(labels, dtype=object).astype(str), return_inverse=True)
    inverse = merged.reshape(-1)[inverse.reshape(-1)]
    out = []
    for i, text in enumerate(distinct.tolist()):
        sel = np.flatnonzero(inverse == i)
        rows, sel = _ascending(owner[sel], sel)
        if (np.diff(rows) == 0).any():
            raise Irregular(f"{field}: label {text} repeats within one message")
        out.append(Column(f"{field}{text}", rows, values[sel]))
    return out


def _ascending(rows: np.ndarray, values):
    """(rows, values) ordered by row."""
    if (np.diff(rows) < 0).any():
        order = np.argsort(rows, kind="stable")
        return rows[order], values[order]
    return rows, values


def _repeated_messages(fd: FieldDescriptor, buf: np.ndarray, m: int, owner: np.ndarray, k: np.ndarray,
                       ranges: np.ndarray, depth: int) -> list[Column]:
    """Columns `field.<child_frame_id or name or i>.<subfield>` of a repeated message field."""
    children = columns(fd.message_type, buf, ranges[:, 0], ranges[:, 1], depth + 1)
    codes = -(k + 1)  # below 0: the index; then the codes of names, then those of child frame ids
    texts: list[str] = []
    for label_field in ("name", "child_frame_id"):  # the later one wins where it is set (decoding.flatten)
        label_fd = fd.message_type.fields_by_name.get(label_field)
        if label_fd is None:
            continue
        if label_fd.type != _T.TYPE_STRING or _repeated(label_fd) or label_fd.has_presence:
            raise Irregular(f"{fd.full_name}: label field {label_field}")
        text = next(c.values for c in children if c.name == label_field)
        codes = np.where(text.codes != text.code_of(""), text.codes + len(texts), codes)
        texts += text.unique.tolist()
    groups = _group(fd.name, m, owner, k, codes, lambda c: f".{texts[c]}." if c >= 0 else f".{-c - 1}.",
                    np.arange(len(owner)))
    out = []
    for group in groups:
        entries = group.values  # the entries with this label, by message
        inside = np.full(len(owner), -1)
        inside[entries] = np.arange(len(entries))
        for child in children:
            if child.rows is None:
                out.append(Column(group.name + child.name, group.rows, child.values[entries]))
            else:
                at = inside[child.rows]
                keep = np.flatnonzero(at >= 0)
                rows = at[keep] if group.rows is None else group.rows[at[keep]]
                rows, values = _ascending(rows, child.values[keep])
                out.append(Column(group.name + child.name, rows, values))
    return out

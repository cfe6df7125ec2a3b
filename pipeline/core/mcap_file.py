"""An MCAP file written a topic at a time, each topic's messages framed in one NumPy pass.

A run's messages are whole series by the time it closes (pipeline.core.runlog), so a topic's message records
are built at once: the records of equal-size messages (series encoded by pipeline.core.encoding) are one
structured array, others are joined with their headers in one `bytes.join`. They are cut into LZ4 chunks of
about CHUNK_BYTES, each with its message index. (The Foxglove SDK's writer takes one message per call, 0.7 µs
each: half of a UR5 run's logging cost, which this saves most of.) Every other record is the `mcap`
package's, and the file carries what a seeking reader, Foxglove and Rerun use: chunk and message indexes,
attachment and metadata indexes, statistics and summary offsets, with the CRCs of chunks, attachments and the
summary (the data section's own CRC is left out, as the `mcap` package's writer does by default).
"""

from __future__ import annotations

import itertools
import struct
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import BinaryIO

import lz4.frame
import numpy as np
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

MAGIC = b"\x89MCAP0\r\n"
CHUNK_BYTES = 1024 * 1024
LIBRARY = "robotics-repro (pipeline.core.mcap_file)"
_MESSAGE = np.dtype([("opcode", "u1"), ("length", "<u8"), ("channel", "<u2"), ("sequence", "<u4"),
                     ("log_time", "<u8"), ("publish_time", "<u8")])  # packed: the 31 bytes before each payload
_MESSAGE_FIELDS = _MESSAGE.descr
_CONTENT = _MESSAGE.itemsize - 9  # a record's length counts what follows its opcode and length
_CHUNK_HEAD = struct.Struct("<BQQQQI")  # opcode, length, start and end times, uncompressed size and CRC
_INDEX_HEAD = struct.Struct("<BQHI")  # opcode, length, channel, byte length of its (log time, offset) pairs

Messages = np.ndarray | Sequence[bytes]  # (n, w) uint8: n payloads of w bytes; or n payloads as bytes


def _records(channel: int, first_sequence: int, times_ns: np.ndarray,
             messages: Messages) -> tuple[memoryview, np.ndarray]:
    """The message records of one channel back to back, and where each starts."""
    n = len(times_ns)
    fixed = isinstance(messages, np.ndarray) and messages.shape[1] > 0
    if fixed:
        width = messages.shape[1]
        records = np.empty(n, dtype=np.dtype([*_MESSAGE_FIELDS, ("data", "u1", (width,))]))
        records["data"] = messages
        starts = np.arange(n, dtype=np.uint64) * np.uint64(records.dtype.itemsize)
        sizes = np.full(n, width, dtype=np.uint64)
    else:
        if isinstance(messages, np.ndarray):
            messages = [b""] * n
        records = np.empty(n, dtype=_MESSAGE)
        sizes = np.fromiter(map(len, messages), dtype=np.uint64, count=n)
        starts = np.zeros(n, dtype=np.uint64)
        np.cumsum(sizes[:-1] + np.uint64(_MESSAGE.itemsize), out=starts[1:])
    records["opcode"] = Opcode.MESSAGE
    records["length"] = sizes + np.uint64(_CONTENT)
    records["channel"] = channel
    records["sequence"] = np.arange(first_sequence, first_sequence + n)  # per channel, from 1
    records["log_time"] = records["publish_time"] = times_ns
    if fixed:
        return memoryview(records).cast("B"), starts
    heads = records.tobytes()
    parts: list[bytes] = [b""] * (2 * n)
    parts[0::2] = [heads[i:i + _MESSAGE.itemsize] for i in range(0, n * _MESSAGE.itemsize, _MESSAGE.itemsize)]
    parts[1::2] = messages
    return memoryview(b"".join(parts)), starts


class McapFile:
    """Write one MCAP file: `attach`, `add_channel`, `add_messages` (one call per topic, in log-time order),
    `add_metadata`, then `finish`. `close` without `finish` leaves an unfinished file (no summary)."""

    def __init__(self, path: str | Path, chunk_bytes: int = CHUNK_BYTES):
        self._file: BinaryIO = open(path, "wb")  # closed by finish or close
        self._offset = 0
        self._chunk_bytes = chunk_bytes
        self._schemas: dict[tuple[str, str, bytes], Schema] = {}
        self._channels: dict[int, Channel] = {}
        self._chunk_indexes: list[ChunkIndex] = []
        self._attachment_indexes: list[AttachmentIndex] = []
        self._metadata_indexes: list[MetadataIndex] = []
        self._statistics = Statistics(attachment_count=0, channel_count=0, channel_message_counts={}, chunk_count=0,
                                      message_count=0, metadata_count=0, message_start_time=0, message_end_time=0,
                                      schema_count=0)
        self._write(MAGIC)
        self._write_record(Header(profile="", library=LIBRARY))

    def _write(self, data: bytes | memoryview) -> int:
        """Append `data`; returns the offset it starts at."""
        start = self._offset
        self._file.write(data)
        self._offset += len(data)
        return start

    def _write_record(self, record) -> tuple[int, int]:
        builder = RecordBuilder()
        record.write(builder)
        data = builder.end()
        return self._write(data), len(data)

    def attach(self, name: str, media_type: str, data: bytes, log_time: int = 0, create_time: int = 0) -> None:
        offset, length = self._write_record(Attachment(create_time=create_time, log_time=log_time, name=name,
                                                       media_type=media_type, data=data))
        self._attachment_indexes.append(AttachmentIndex(offset=offset, length=length, log_time=log_time,
                                                        create_time=create_time, data_size=len(data), name=name,
                                                        media_type=media_type))
        self._statistics.attachment_count += 1

    def add_metadata(self, name: str, values: Mapping[str, str]) -> None:
        offset, length = self._write_record(Metadata(name=name, metadata=dict(values)))
        self._metadata_indexes.append(MetadataIndex(offset=offset, length=length, name=name))
        self._statistics.metadata_count += 1

    def add_channel(self, topic: str, message_encoding: str, schema: tuple[str, str, bytes] | None,
                    metadata: Mapping[str, str] | None = None) -> int:
        """A new channel (id from 1); `schema` is (name, encoding, data), written once however many use it."""
        schema_id = 0
        if schema is not None:
            known = self._schemas.get(schema)
            if known is None:
                name, encoding, data = schema
                known = self._schemas[schema] = Schema(id=len(self._schemas) + 1, name=name, encoding=encoding,
                                                       data=data)
                self._write_record(known)
            schema_id = known.id
        channel = Channel(id=len(self._channels) + 1, topic=topic, message_encoding=message_encoding,
                          schema_id=schema_id, metadata=dict(metadata or {}))
        self._channels[channel.id] = channel
        self._write_record(channel)
        return channel.id

    def add_messages(self, channel: int, times_ns: np.ndarray, messages: Messages) -> None:
        """Messages of `channel` in log-time order, log (and publish) time `times_ns` each, in chunks of their
        own; another call for the channel goes on with its sequence numbers."""
        if channel not in self._channels:
            raise ValueError(f"channel {channel} was not added (add_channel gives its id)")
        times_ns = np.asarray(times_ns, dtype=np.int64)
        if len(times_ns) != len(messages):
            raise ValueError(f"channel {channel}: {len(messages)} messages for {len(times_ns)} times")
        if not len(times_ns):
            return
        if (np.diff(times_ns) < 0).any() or times_ns[0] < 0:
            raise ValueError(f"channel {channel}: log times must be non-negative and in order")
        data, starts = _records(channel, self._statistics.channel_message_counts.get(channel, 0) + 1, times_ns,
                                messages)
        cuts = [0, *(np.flatnonzero(np.diff(starts // np.uint64(self._chunk_bytes))) + 1).tolist(), len(starts)]
        for first, stop in itertools.pairwise(cuts):
            begin = int(starts[first])
            end = int(starts[stop]) if stop < len(starts) else len(data)
            self._chunk(channel, times_ns[first:stop], starts[first:stop] - np.uint64(begin), data[begin:end])
        stats = self._statistics
        stats.message_start_time = int(times_ns[0]) if not stats.message_count \
            else min(stats.message_start_time, int(times_ns[0]))
        stats.message_end_time = max(stats.message_end_time, int(times_ns[-1]))
        stats.message_count += len(times_ns)
        stats.channel_message_counts[channel] = stats.channel_message_counts.get(channel, 0) + len(times_ns)

    def _chunk(self, channel: int, times_ns: np.ndarray, starts: np.ndarray, data: memoryview) -> None:
        compressed = lz4.frame.compress(data)
        compression = b"lz4"
        head = _CHUNK_HEAD.pack(Opcode.CHUNK, 8 * 3 + 4 + 4 + len(compression) + 8 + len(compressed),
                                int(times_ns[0]), int(times_ns[-1]), len(data), zlib.crc32(data))
        chunk_start = self._write(head + struct.pack("<I", len(compression)) + compression
                                  + struct.pack("<Q", len(compressed)))
        self._write(compressed)
        index = np.empty((len(times_ns), 2), dtype="<u8")
        index[:, 0], index[:, 1] = times_ns, starts
        index_start = self._write(_INDEX_HEAD.pack(Opcode.MESSAGE_INDEX, 2 + 4 + index.nbytes, channel, index.nbytes))
        self._write(memoryview(index).cast("B"))
        self._chunk_indexes.append(ChunkIndex(
            message_start_time=int(times_ns[0]), message_end_time=int(times_ns[-1]), chunk_start_offset=chunk_start,
            chunk_length=index_start - chunk_start, message_index_offsets={channel: index_start},
            message_index_length=self._offset - index_start, compression="lz4", compressed_size=len(compressed),
            uncompressed_size=len(data)))
        self._statistics.chunk_count += 1

    def finish(self) -> None:
        """Write the summary (schemas, channels, statistics, indexes, their offsets) and the footer; close."""
        self._write_record(DataEnd(data_section_crc=0))
        stats = self._statistics
        stats.schema_count, stats.channel_count = len(self._schemas), len(self._channels)
        summary_start = self._offset
        builder = RecordBuilder()
        offsets: list[SummaryOffset] = []
        for opcode, group in ((Opcode.SCHEMA, list(self._schemas.values())),
                              (Opcode.CHANNEL, list(self._channels.values())), (Opcode.STATISTICS, [stats]),
                              (Opcode.CHUNK_INDEX, self._chunk_indexes),
                              (Opcode.ATTACHMENT_INDEX, self._attachment_indexes),
                              (Opcode.METADATA_INDEX, self._metadata_indexes)):
            if not group:
                continue
            start = builder.count
            for record in group:
                record.write(builder)
            offsets.append(SummaryOffset(group_opcode=opcode, group_start=summary_start + start,
                                         group_length=builder.count - start))
        summary_offset_start = summary_start + builder.count
        for offset in offsets:
            offset.write(builder)
        summary = builder.end()
        footer_head = struct.pack("<BQQQ", Opcode.FOOTER, 8 + 8 + 4, summary_start, summary_offset_start)
        self._write(summary)
        self._write_record(Footer(summary_start=summary_start, summary_offset_start=summary_offset_start,
                                  summary_crc=zlib.crc32(footer_head, zlib.crc32(summary))))
        self._write(MAGIC)
        self._file.close()

    def close(self) -> None:
        self._file.close()

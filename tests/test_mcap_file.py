"""The MCAP writer of runs (pipeline.core.mcap_file) against the `mcap` package: its readers (indexed, and
streamed with every CRC checked) read back what was written, and its own writer, given the same content,
makes a file they read the same."""

from __future__ import annotations

import struct
import zlib

import lz4.frame
import numpy as np
import pytest
from mcap.reader import make_reader
from mcap.records import Chunk, Footer, Message
from mcap.stream_reader import ReadDataStream, StreamReader
from mcap.writer import CompressionType, Writer

from pipeline.core.mcap_file import McapFile

SCHEMA = ("demo.Sample", "protobuf", b"\x0a\x03abc")


def _content(rng: np.random.Generator) -> list[tuple[str, tuple | None, np.ndarray, np.ndarray | list[bytes]]]:
    """(topic, schema, times in ns, messages): a table of equal payloads, payloads of every length (empty
    ones too), a table of zero-width rows, and a second topic of the first one's schema."""
    table = rng.integers(0, 256, (300, 13), dtype=np.uint8)
    varied = [rng.bytes(int(k)) for k in rng.integers(0, 90, 120)]
    return [("/a", SCHEMA, np.arange(300) * 1_000_000, table),
            ("/b", ("demo.Blob", "ros2msg", b"string data"), np.sort(rng.integers(0, 10**9, 120)), varied),
            ("/empty", None, np.array([5, 5, 9]), np.zeros((3, 0), dtype=np.uint8)),
            ("/a2", SCHEMA, np.array([0, 10**10]), table[:2])]


def _payloads(messages) -> list[bytes]:
    return [bytes(row) for row in messages] if isinstance(messages, np.ndarray) else list(messages)


def _write_ours(path, content, chunk_bytes: int) -> None:
    out = McapFile(path, chunk_bytes=chunk_bytes)
    out.attach("config.yaml", "application/yaml", b"a: 1\n")
    for topic, schema, times, messages in content:
        channel = out.add_channel(topic, "protobuf", schema, {"units": '{"x": "m"}'})
        out.add_messages(channel, times, messages)
    out.attach("model.xml", "application/xml", b"<mujoco/>")
    out.add_metadata("run", {"status": "ok"})
    out.finish()


def _write_theirs(path, content) -> None:
    with open(path, "wb") as f:
        out = Writer(f, compression=CompressionType.LZ4)
        out.start()
        out.add_attachment(0, 0, "config.yaml", "application/yaml", b"a: 1\n")
        schemas: dict[tuple, int] = {}
        for topic, schema, times, messages in content:
            if schema is not None and schema not in schemas:
                schemas[schema] = out.register_schema(*schema)
            schema_id = 0 if schema is None else schemas[schema]
            channel = out.register_channel(topic, "protobuf", schema_id, {"units": '{"x": "m"}'})
            for k, (t, data) in enumerate(zip(times.tolist(), _payloads(messages), strict=True)):
                out.add_message(channel, t, data, t, sequence=k + 1)
        out.add_attachment(0, 0, "model.xml", "application/xml", b"<mujoco/>")
        out.add_metadata("run", {"status": "ok"})
        out.finish()


def _read(path) -> dict:
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        messages = [(channel.topic, schema.name if schema else None, channel.metadata, m.sequence, m.log_time,
                     m.publish_time, m.data) for schema, channel, m in reader.iter_messages(log_time_order=False)]
        return {"messages": sorted(messages, key=lambda m: (m[0], m[4], m[3])),
                "attachments": [(a.name, a.media_type, a.data) for a in reader.iter_attachments()],
                "metadata": [(m.name, m.metadata) for m in reader.iter_metadata()],
                "counts": {summary.channels[c].topic: n for c, n in summary.statistics.channel_message_counts.items()},
                "times": (summary.statistics.message_start_time, summary.statistics.message_end_time),
                "schemas": sorted(s.name for s in summary.schemas.values()), "chunks": summary.chunk_indexes}


@pytest.mark.parametrize("chunk_bytes", [1 << 20, 500])
def test_runs_read_back_as_the_mcap_package_writes_them(tmp_path, chunk_bytes):
    content = _content(np.random.default_rng(3))
    _write_ours(tmp_path / "ours.mcap", content, chunk_bytes)
    _write_theirs(tmp_path / "theirs.mcap", content)
    ours, theirs = _read(tmp_path / "ours.mcap"), _read(tmp_path / "theirs.mcap")
    for key in ("messages", "attachments", "metadata", "counts", "times", "schemas"):
        assert ours[key] == theirs[key], key
    expected = [(topic, k + 1, t, data) for topic, _, times, messages in content
                for k, (t, data) in enumerate(zip(times.tolist(), _payloads(messages), strict=True))]
    assert sorted(m[:1] + m[3:5] + m[6:] for m in ours["messages"]) == sorted(expected)
    assert len(ours["schemas"]) == 2  # /a and /a2 share theirs
    # every chunk holds one topic, and at most one record more than the chunk size
    assert all(len(index.message_index_offsets) == 1 for index in ours["chunks"])
    assert max(index.uncompressed_size for index in ours["chunks"]) < chunk_bytes + 31 + 90
    assert len(ours["chunks"]) == 4 if chunk_bytes > 10**5 else len(ours["chunks"]) > 12


def test_every_crc_and_index_checks_out(tmp_path):
    path = tmp_path / "ours.mcap"
    content = _content(np.random.default_rng(5))
    _write_ours(path, content, chunk_bytes=700)
    records = list(StreamReader(str(path), validate_crcs=True).records)  # chunk and attachment CRCs checked
    assert sum(isinstance(r, Message) for r in records) == sum(len(times) for _, _, times, _ in content)
    raw = path.read_bytes()
    footer = next(r for r in records if isinstance(r, Footer))
    footer_start = len(raw) - 8 - (1 + 8 + 8 + 8 + 4)
    assert raw[footer_start] == 0x02 and struct.unpack_from("<QQI", raw, footer_start + 9) == \
        (footer.summary_start, footer.summary_offset_start, footer.summary_crc)
    assert zlib.crc32(raw[footer.summary_start:footer_start + 1 + 8 + 8 + 8]) == footer.summary_crc
    # each chunk's CRC is its data's, and its message index points at its records, in log-time order
    with open(path, "rb") as f:
        indexes = make_reader(f).get_summary().chunk_indexes
        assert len(indexes) > 4
        for index in indexes:
            (channel, offset), = index.message_index_offsets.items()
            f.seek(offset + 1 + 8 + 2)
            (length,) = struct.unpack("<I", f.read(4))
            pairs = np.frombuffer(f.read(length), dtype="<u8").reshape(-1, 2)
            f.seek(index.chunk_start_offset + 9)
            chunk = Chunk.read(ReadDataStream(f))
            data = lz4.frame.decompress(chunk.data)
            assert zlib.crc32(data) == chunk.uncompressed_crc and len(data) == index.uncompressed_size
            assert (np.diff(pairs[:, 0].astype(np.int64)) >= 0).all()
            for t, start in pairs.tolist():
                assert data[start] == 0x05
                (size,) = struct.unpack_from("<Q", data, start + 1)
                channel_id, _, log_time = struct.unpack_from("<HIQ", data, start + 9)
                assert (channel_id, log_time) == (channel, t) and start + 9 + size <= len(data)


def test_a_channel_written_in_parts_goes_on_with_its_sequence(tmp_path):
    out = McapFile(tmp_path / "parts.mcap")
    channel = out.add_channel("/a", "protobuf", SCHEMA)
    out.add_messages(channel, np.array([1, 2]), [b"x", b"y"])
    out.add_messages(channel, np.array([3]), np.frombuffer(b"z", dtype=np.uint8)[None])
    out.finish()
    with open(tmp_path / "parts.mcap", "rb") as f:
        assert [(m.sequence, m.log_time, m.data) for _, _, m in make_reader(f, validate_crcs=True).iter_messages()] \
            == [(1, 1, b"x"), (2, 2, b"y"), (3, 3, b"z")]


def test_bad_series_are_refused(tmp_path):
    out = McapFile(tmp_path / "bad.mcap")
    channel = out.add_channel("/a", "protobuf", SCHEMA)
    with pytest.raises(ValueError, match="not added"):
        out.add_messages(channel + 1, np.array([1]), [b"x"])
    with pytest.raises(ValueError, match="in order"):
        out.add_messages(channel, np.array([2, 1]), [b"x", b"y"])
    with pytest.raises(ValueError, match="2 messages for 3 times"):
        out.add_messages(channel, np.array([1, 2, 3]), [b"x", b"y"])
    out.close()

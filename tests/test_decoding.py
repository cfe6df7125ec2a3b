"""The reader's fast paths (a fixed-layout series as one record view, any other protobuf topic decoded column by
column in NumPy) give exactly what protobuf's message-by-message decode gives: values, NaN, times, column names and
order, dtypes. Runs of several papers, every kind of message the writer makes, and odd or damaged files (another
writer, no message index, fields out of order, unknown fields, a length past the end) fall back cleanly."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointState_pb2 import JointState
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from google.protobuf.message import DecodeError
from mcap.writer import CompressionType, IndexType, Writer

from pipeline.core import decoding, schemas
from pipeline.core.runlog import RunWriter, read_run, run_files

from .conftest import run_cli

Probe = schemas.define("ReaderProbe", "every scalar kind the reader decodes column by column",
                       label="string", count="int64 1", index="uint32 1", flag="bool", value="double m",
                       name="string[]", values="double[] q", counts="uint32[] 1")


@pytest.fixture
def paths_taken(monkeypatch) -> dict[str, list[bool]]:
    """topic schema -> whether each read took a fast path."""
    taken: dict[str, list[bool]] = {}
    series, columnar = decoding._series, decoding._columnar

    def spy_series(first, *args):
        frame = series(first, *args)
        if frame is not None:
            taken.setdefault(first.DESCRIPTOR.full_name, []).append(True)
        return frame

    def spy_columnar(cls, *args):
        frame = columnar(cls, *args)
        taken.setdefault(cls.DESCRIPTOR.full_name, []).append(frame is not None)
        return frame

    monkeypatch.setattr(decoding, "_series", spy_series)
    monkeypatch.setattr(decoding, "_columnar", spy_columnar)
    return taken


def assert_reads_alike(path, topics=None) -> dict[str, pd.DataFrame]:
    topics = read_run(path).topic_names if topics is None else topics
    fast = decoding.read_topics(path, topics)
    slow = decoding.read_topics(path, topics, arrays=False)
    assert set(fast) == set(slow)
    for topic in slow:
        pd.testing.assert_frame_equal(fast[topic], slow[topic], check_dtype=True, check_exact=True, obj=topic)
    return fast


def test_runs_of_several_papers_read_as_protobuf_reads_them(tmp_path, paths_taken):
    data_dir = tmp_path / "data"
    for experiment, *overrides in (("ur5-ik-fsm/random-paths", "episodes.count=2"),
                                   ("gripper-force-control/pick-and-place",), ("quadruped-irondog/stand",)):
        proc = run_cli("pipeline", f"experiment={experiment}", f"data_dir={data_dir}", "progress=false", *overrides)
        assert proc.returncode == 0, proc.stderr
    paths = [p for d in sorted((data_dir / "runs").glob("*/*")) for p in run_files(d)]
    assert len(paths) == 6
    for path in paths:
        assert_reads_alike(path)
    # every schema with enough messages took a fast path: frames, robot joints, markers, IK selections, series
    assert {"foxglove.FrameTransforms", "foxglove.JointStates", "foxglove.SceneUpdate", "repro.Ur5IkSelection",
            "repro.JointState", "repro.Wrench"} <= set(paths_taken)
    assert all(all(taken) for taken in paths_taken.values()), paths_taken


def test_every_kind_of_field_reads_as_protobuf_reads_it(tmp_path, paths_taken):
    """Zeros protobuf leaves out, optional fields in some messages only, frames and names that change, NaN,
    negative and large integers, strings that vary, contacts that come and go."""
    n = 80
    t = np.arange(n) * 0.01
    rng = np.random.default_rng(3)
    with RunWriter(tmp_path / "r.mcap", {"run_id": "r"}) as w:
        values = rng.normal(size=(n, 2))
        values[::7, 1] = np.nan
        w.log_series("/probe/series", t, schemas.Scalars, units="1", name=["a", "b"], value=values)
        matrices = np.tile(np.eye(4), (n, 2, 1, 1))
        matrices[:, :, :3, 3] = rng.normal(size=(n, 2, 3))
        w.log_transforms(t, "world", ["a", "b"], matrices)
        for k in range(n):
            ns = round(float(t[k]) * 1e9)
            joints = [JointState(name=f"j{i}", position=float(k + i)) for i in range(1 + k % 3)]
            if k % 2:
                joints[0].velocity = 0.0  # present, and zero
            w.write("/joint_states", ns, JointStates(joints=joints))
            frames = FrameTransforms()
            for child in (["x", "y"] if k % 4 else ["y", "z", ""]):
                frames.transforms.add(parent_frame_id="world", child_frame_id=child).translation.x = k
            w.write("/tf/changing", ns, frames)
            w.log("/probe", float(t[k]), Probe, units="rad", label=["", "left", "right"][k % 3], count=-k * 10 ** 9,
                  index=2 ** 32 - 1 - k, flag=bool(k % 2), value=float(k % 2), name=["p", "q"][: k % 3],
                  values=[0.0, -1.5][: k % 3], counts=[k, 300][: 1 + k % 2])
            if k % 5 == 0:  # a name twice: the later entry wins, as in protobuf's rows
                w.log("/probe/twice", float(t[k]), schemas.Scalars, units="1", name=["a", "a"], value=[1.0, 2.0])
        w.log_contacts(t, [rng.normal(size=(k % 3, 3)) for k in range(n)],
                       [rng.normal(size=(k % 3, 3)) for k in range(n)], scale=0.01)
        w.close("ok")
    frames = assert_reads_alike(tmp_path / "r.mcap")
    for schema in ("repro.Scalars", "foxglove.FrameTransforms", "foxglove.JointStates", "repro.ReaderProbe",
                   "foxglove.SceneUpdate"):
        assert paths_taken[schema] and all(paths_taken[schema]), (schema, paths_taken)
    changing = frames["/tf/changing"]
    assert changing["transforms.z.translation.x"].isna().sum() == n - n // 4  # only in every fourth message
    assert "transforms.2.translation.x" in changing  # an empty child frame id: labelled by its index
    assert frames["/probe"]["count"].dtype == np.int64 and frames["/probe"]["index"].max() == 2 ** 32 - 1


def _odd_file(path, messages: list[tuple[str, int, bytes]], compression=CompressionType.ZSTD,
              index_types=IndexType.ALL) -> None:
    """A file from mcap's own writer: both channels in one chunk, zstd, optionally without message indexes."""
    from pipeline.core.runlog import _file_descriptor_set

    with open(path, "wb") as f:
        writer = Writer(f, compression=compression, index_types=index_types)
        writer.start()
        schema = writer.register_schema("foxglove.JointStates", "protobuf",
                                        _file_descriptor_set(JointStates.DESCRIPTOR))
        channels = {topic: writer.register_channel(topic, "protobuf", schema) for topic in ("/a", "/b")}
        for topic, time, data in messages:
            writer.add_message(channels[topic], log_time=time, publish_time=time, data=data)
        writer.finish()


def _states(k: int) -> bytes:
    return JointStates(joints=[JointState(name="a", position=k, effort=-k), JointState(name="b")]).SerializeToString()


@pytest.mark.parametrize("index_types", [IndexType.ALL, IndexType.CHUNK])
def test_another_writers_file_reads_alike(tmp_path, paths_taken, index_types):
    messages = [(("/a", "/b")[k % 2], (k * 7919) % 100, _states(k)) for k in range(200)]  # times out of order
    _odd_file(tmp_path / "o.mcap", messages, index_types=index_types)
    frames = assert_reads_alike(tmp_path / "o.mcap", ["/a", "/b"])
    assert len(frames["/a"]) == len(frames["/b"]) == 100 and frames["/a"].index.is_monotonic_increasing
    assert all(paths_taken["foxglove.JointStates"])


def test_fields_out_of_order_or_unknown_fall_back_to_protobuf(tmp_path, paths_taken):
    regular = [_states(k) for k in range(40)]
    joint = JointState(name="c", position=1.0).SerializeToString()  # name (3 bytes), then position (9 bytes)
    out_of_order = b"\x12" + bytes([len(joint)]) + joint[3:] + joint[:3]  # valid protobuf, fields not in order
    unknown = regular[1] + b"\x48\x05"  # field 9 (varint 5): no field of JointStates
    for extra in (out_of_order, unknown):
        _odd_file(tmp_path / "o.mcap", [("/a", k, data) for k, data in enumerate([*regular, extra])])
        assert JointStates.FromString(extra).joints[0].name in ("c", "a")
        assert_reads_alike(tmp_path / "o.mcap", ["/a"])
    assert paths_taken["foxglove.JointStates"] == [False, False]


def test_a_damaged_message_fails_as_protobuf_fails(tmp_path):
    damaged = bytearray(_states(3))
    damaged[1] += 40  # the first joint's length now runs past the message
    _odd_file(tmp_path / "d.mcap", [("/a", k, _states(k)) for k in range(40)] + [("/a", 50, bytes(damaged))])
    for arrays in (True, False):
        with pytest.raises(DecodeError):
            decoding.read_topics(tmp_path / "d.mcap", ["/a"], arrays=arrays)

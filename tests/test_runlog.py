"""The MCAP contract: schemas on every channel, simulated log time, metadata and attachments, the reader's
DataFrames, atomic publication, and that Rerun and Foxglove tooling can read the files."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pandas as pd
import pytest
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from mcap.reader import make_reader

from pipeline.core import schemas
from pipeline.core.decoding import read_topics
from pipeline.core.runlog import RunWriter, read_run, read_runs, run_files, typed

from .conftest import ENV, ROOT

NAMES = ["j1", "j2", "j3"]


def write_sample(path):
    t = np.arange(5) * 0.001
    with RunWriter(path, {"slug": "demo", "experiment": "e", "run_id": path.stem, "case": "c", "seed": "0",
                          "params": {"a.b": "1"}}) as w:
        w.attach("config.yaml", "x: 1\n", "application/yaml")
        w.log_series("/joint_state", t, units=["rad", "rad", "m"], name=NAMES, position=np.arange(15.0).reshape(5, 3),
                     velocity=np.ones((5, 3)), effort=np.zeros((5, 3)))
        w.log("/wrench", 0.002, frame_id="tool", name=["c"], force_x=[1.0], force_y=[2.0], force_z=[3.0],
              torque_x=[0.0], torque_y=[0.0], torque_z=[0.5])
        w.log_series("/compute_time", t, name=["solver"], calls=[1], seconds=np.full((5, 1), 1e-6))
        T = np.tile(np.eye(4), (5, 2, 1, 1))
        T[:, 1, 0, 3] = t
        w.log_transforms(t, "world", ["base", "tool"], T)
        w.close("ok")
    return t


def test_round_trip(tmp_path):
    t = write_sample(tmp_path / "r.mcap")
    run = read_run(tmp_path / "r.mcap")
    assert run.ok and run.run_id == "r" and run.params == {"a.b": 1}   # typed, as Hydra reads the override
    assert run.attachments["config.yaml"] == b"x: 1\n"
    js = run["/joint_state"]
    assert np.allclose(js.index, t) and js.index.name == "t"
    assert np.allclose(js[["position.j1", "position.j2", "position.j3"]].to_numpy(), np.arange(15.0).reshape(5, 3))
    assert run["/wrench"]["torque_z.c"].iloc[0] == 0.5
    assert np.allclose(run["/tf"]["transforms.tool.translation.x"], t)
    assert set(run.topic_names) == {"/joint_state", "/wrench", "/compute_time", "/tf"}


def test_every_channel_has_a_decodable_schema_and_simulated_log_time(tmp_path):
    write_sample(tmp_path / "r.mcap")
    with open(tmp_path / "r.mcap", "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        for channel in summary.channels.values():
            schema = summary.schemas[channel.schema_id]
            assert channel.message_encoding == "protobuf" and schema.encoding == "protobuf"
            fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
            pool = descriptor_pool.DescriptorPool()
            for fd in fds.file:
                pool.Add(fd)
            message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
        assert summary.schemas[next(c.schema_id for c in summary.channels.values() if c.topic == "/tf")].name \
            == "foxglove.FrameTransforms"  # Foxglove's own schema: its 3D panel draws it
        times = [m.log_time for _, _, m in reader.iter_messages()]
    assert min(times) == 0 and max(times) == 4_000_000


def test_topic_schema_is_enforced(tmp_path):
    with RunWriter(tmp_path / "x.mcap", {}) as w, pytest.raises(TypeError):
        w.log("/joint_state", 0.0, schemas.Scalars, name=["a"], value=[1.0])


def test_unfinished_run_is_never_listed(tmp_path):
    code = textwrap.dedent(f"""
        import os, signal
        import numpy as np
        from pipeline.core.runlog import RunWriter
        w = RunWriter({str(tmp_path / "killed.mcap")!r}, {{"run_id": "killed"}})
        w.log_series("/joint_state", np.arange(1000) * 1e-3, units="rad", name=["a"], position=np.zeros((1000, 1)))
        os.kill(os.getpid(), signal.SIGKILL)
    """)
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=ENV)
    assert proc.returncode == -signal.SIGKILL
    assert run_files(tmp_path) == []
    [left] = tmp_path.iterdir()  # a hidden temporary under a unique name, never a run file
    assert left.name.startswith(".killed.mcap.") and left.name.endswith(".partial")


def test_interrupt_keeps_the_previous_complete_run(tmp_path):
    write_sample(tmp_path / "r.mcap")
    before = (tmp_path / "r.mcap").read_bytes()
    with pytest.raises(KeyboardInterrupt), RunWriter(tmp_path / "r.mcap", {"run_id": "r"}) as w:
        w.log("/joint_state", 0.0, units="rad", name=["a"], position=[1.0])
        raise KeyboardInterrupt
    assert (tmp_path / "r.mcap").read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["r.mcap"]


@pytest.mark.skipif(shutil.which("rerun") is None, reason="rerun CLI (rerun-sdk) not on PATH")
def test_rerun_reads_the_run(tmp_path):
    write_sample(tmp_path / "r.mcap")
    out = tmp_path / "r.rrd"
    subprocess.run(["rerun", "mcap", "convert", str(tmp_path / "r.mcap"), "-o", str(out), "--timeline-type",
                    "duration"], check=True, env=ENV, capture_output=True, timeout=120)
    printed = subprocess.run(["rerun", "rrd", "print", str(out)], check=True, env=ENV, capture_output=True,
                             text=True, timeout=120).stdout
    assert "Transform3D" in printed  # /tf became Rerun transforms
    assert "repro.JointState" in printed  # project schemas decoded by reflection


def test_no_partial_left_after_normal_close(tmp_path):
    write_sample(tmp_path / "r.mcap")
    assert os.listdir(tmp_path) == ["r.mcap"]


def test_every_column_has_its_unit(tmp_path):
    write_sample(tmp_path / "r.mcap")
    run = read_run(tmp_path / "r.mcap")
    joints = run.units("/joint_state")
    assert joints["position.j1"] == "rad" and joints["velocity.j1"] == "rad/s" and joints["effort.j1"] == "N*m"
    assert joints["position.j3"] == "m" and joints["velocity.j3"] == "m/s" and joints["effort.j3"] == "N"
    assert set(joints) == set(run["/joint_state"].columns)
    assert run["/joint_state"].attrs["units"] == joints
    assert run.units("/wrench")["force_x.c"] == "N" and run.units("/wrench")["torque_z.c"] == "N*m"
    assert run.units("/compute_time") == {"seconds.solver": "s", "calls.solver": "1"}
    assert run.units("/tf")["transforms.tool.translation.x"] == "m"


def test_a_number_without_a_unit_is_refused(tmp_path):
    with RunWriter(tmp_path / "x.mcap", {}) as w:
        with pytest.raises(ValueError, match=r"unit of position.a is not known: pass units="):
            w.log("/joint_state", 0.0, name=["a"], position=[1.0])
        with pytest.raises(ValueError, match=r"unit of norm is not known: pass field_units"):
            w.log("/tracking_error", 0.0, units=["m", "rad"], name=["x", "r"], error=[1.0, 0.1], norm=1.0)
        with pytest.raises(ValueError, match="gives 1 units for 2 entries"):
            w.log("/reference", 0.0, units=["m"], name=["x", "y"], position=[1.0, 2.0])
        w.log("/command", 0.0, units="m", kind="force", name=["x"], value=[1.0])
        with pytest.raises(ValueError, match="was logged in N, now in N\\*m"):
            w.log("/command", 0.1, units="rad", kind="torque", name=["x"], value=[1.0])
    with pytest.raises(ValueError, match="field x needs a unit"):
        schemas.define("NoUnit", "a field without its unit", x="double")


def test_the_fast_reader_equals_protobuf_decoding(tmp_path):
    """Series of doubles are read as one NumPy view; messages whose layout changes (a string that varies, a
    field that comes and goes, a zero scalar protobuf leaves out) fall back to message-by-message decoding."""
    n = 50
    t = np.arange(n) * 0.01
    with RunWriter(tmp_path / "m.mcap", {"run_id": "m"}) as w:
        w.log_series("/joint_state", t, units="rad", name=NAMES, position=np.random.default_rng(0).normal(size=(n, 3)),
                     velocity=np.ones((n, 3)))
        w.log_series("/tracking_error", t, units="m", name=["x"], error=np.zeros((n, 1)), norm=np.zeros(n))
        w.log_series("/command", t, units="rad", kind="torque", name=NAMES, value=np.ones((n, 3)))
        for k in range(n):  # per-record calls: the norm is 0 (left out by protobuf) in some records only
            w.log("/tracking_error/flange", float(t[k]), units="m", name=["x"], error=[k % 3], norm=float(k % 3))
            w.log("/probe", float(t[k]), schemas.Scalars, units="1", name=["a", "b"][: 1 + k % 2],
                  value=[1.0, 2.0][: 1 + k % 2])
        w.close("ok")
    topics = ["/joint_state", "/tracking_error", "/command", "/tracking_error/flange", "/probe"]
    fast = read_topics(tmp_path / "m.mcap", topics)
    slow = read_topics(tmp_path / "m.mcap", topics, arrays=False)
    for topic in topics:
        pd.testing.assert_frame_equal(fast[topic], slow[topic], check_dtype=False)
    assert list(fast["/command"].columns) == ["kind", "value.j1", "value.j2", "value.j3"]
    assert fast["/probe"]["value.b"].isna().sum() == n // 2


def test_typed_values_and_a_sweep_in_one_frame(tmp_path):
    assert typed("4") == 4 and typed("0.5") == 0.5 and typed("1e-4") == 1e-4 and typed("true") is True
    assert typed("[wrist,1]") == ["wrist", 1] and typed("null") is None and typed("alg2") == "alg2"
    for k, gain in enumerate((2.0, 8.0)):
        with RunWriter(tmp_path / f"r{k}.mcap", {"run_id": f"r{k}", "params": {"execute.gain": str(gain)},
                                                 "values": {"execute.gain": gain}}) as w:
            w.log_series("/tracking_error", np.arange(3) * 0.1, units="rad", name=["a"], error=np.full((3, 1), gain),
                         norm=np.full(3, gain))
            w.close("ok")
    frame = read_runs(tmp_path, "/tracking_error")
    assert list(frame.columns[:3]) == ["t", "run_id", "execute.gain"] and len(frame) == 6
    assert frame["execute.gain"].dtype.kind == "f" and (frame["error.a"] == frame["execute.gain"]).all()
    assert frame.attrs["units"]["norm"] == "rad"
    table = read_runs(tmp_path).table()
    assert table["execute.gain"].tolist() == [2.0, 8.0]


def test_series_encoded_in_numpy_equal_protobufs_byte_for_byte():
    """Rows of several varint layouts (timestamps and names of different lengths, interleaved) come out in
    row order and byte for byte as protobuf serializes them; so do fixed-layout series."""
    from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms

    from pipeline.core import robot
    from pipeline.core.encoding import encode_series, messages

    rng = np.random.default_rng(4)
    times_ns = np.array([1_000_000_001, 300 * 10**9 + 999, 2_000_000_000 + 10**8, 5 * 10**9 + 7, 1_500_000_000])
    children = ["a", "b" * 200]
    trans, quats = rng.uniform(0.1, 1, (5, 2, 3)), rng.uniform(0.1, 1, (5, 2, 4))  # no zeros: proto3 omits them
    expected = [FrameTransforms(transforms=[
        {"timestamp": {"seconds": int(t // 10**9), "nanos": int(t % 10**9)}, "parent_frame_id": "world",
         "child_frame_id": c, "translation": dict(zip("xyz", trans[i, k], strict=True)),
         "rotation": dict(zip("wxyz", quats[i, k], strict=True))} for k, c in enumerate(children)]).SerializeToString()
        for i, t in enumerate(times_ns)]
    assert robot.frame_transforms(times_ns, ["world"] * 2, children, trans, quats) == expected
    position = rng.uniform(0.1, 1, (5, 3))
    position[:, -1] = 0.0  # messages that end in zero bytes keep them
    assert messages(encode_series(schemas.JointState, {"name": NAMES}, {"position": position})) == \
        [schemas.JointState(name=NAMES, position=p).SerializeToString() for p in position]
    from foxglove_schemas_protobuf.JointStates_pb2 import JointStates

    drawn = rng.uniform(0.1, 1, (5, 2))
    assert robot.joint_states(times_ns, children, drawn) == [JointStates(
        timestamp={"seconds": int(t // 10**9), "nanos": int(t % 10**9)},
        joints=[{"name": c, "position": p} for c, p in zip(children, row, strict=True)]).SerializeToString()
        for t, row in zip(times_ns, drawn, strict=True)]


def test_quaternions_equal_scipys_bit_for_bit():
    from scipy.spatial.transform import Rotation

    from pipeline.robotics import dh
    from pipeline.robotics.transforms import quaternion_wxyz

    def scipy(R):
        return Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat(scalar_first=True).reshape(*R.shape[:-2], 4)

    rng = np.random.default_rng(5)
    axes = np.eye(3)[rng.integers(0, 3, 300)]  # half turns and quarter turns about the axes: every branch, ties
    special = Rotation.from_rotvec(axes * rng.choice([0.0, np.pi / 2, np.pi, -np.pi / 2], 300)[:, None]).as_matrix()
    ur5 = dh.DH(np.array([np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0]), np.array([0, -0.425, -0.392, 0, 0, 0]),
                np.array([0.089, 0, 0, 0.109, 0.095, 0.082]), np.zeros(6))
    for R in (Rotation.random(20_000, random_state=6).as_matrix(), special,
              dh.frames(ur5, rng.uniform(-np.pi, np.pi, (500, 6)))[:, :, :3, :3]):
        assert np.array_equal(quaternion_wxyz(R).view(np.int64), scipy(R).view(np.int64))
    skewed = Rotation.random(3, random_state=7).as_matrix() * (1 + 1e-9)  # SciPy projects it onto a rotation
    assert np.array_equal(quaternion_wxyz(skewed), scipy(skewed))
    with pytest.raises(ValueError, match="determinant"):
        quaternion_wxyz(np.diag([1.0, 1.0, -1.0]))

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
import pytest
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from mcap.reader import make_reader

from pipeline.core import schemas
from pipeline.core.runlog import RunWriter, read_run, run_files

from .conftest import ENV, ROOT

NAMES = ["j1", "j2", "j3"]


def write_sample(path):
    t = np.arange(5) * 0.001
    with RunWriter(path, {"slug": "demo", "experiment": "e", "run_id": path.stem, "case": "c", "seed": "0",
                          "params": {"a.b": "1"}}) as w:
        w.attach("config.yaml", "x: 1\n", "application/yaml")
        w.log_series("/joint_state", t, name=NAMES, position=np.arange(15.0).reshape(5, 3),
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
    assert run.ok and run.run_id == "r" and run.params == {"a.b": "1"}
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
        w.log_series("/joint_state", np.arange(1000) * 1e-3, name=["a"], position=np.zeros((1000, 1)))
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
        w.log("/joint_state", 0.0, name=["a"], position=[1.0])
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

"""Open a run in Rerun with plots and a 3-D replay.

    python -m analysis.view data/runs/<slug>/<experiment>/<run>.mcap            writes <run>.rrd beside it
    python -m analysis.view <run>.mcap --spawn                                  and opens the Rerun viewer

Rerun also opens the .mcap directly (`rerun <run>.mcap`): it draws /tf and decodes every other channel as
queryable fields. This converter adds what reflection cannot: every numeric column as a time series on a
`sim_time` timeline, the /tf frames as a 3-D skeleton (frames joined in the order they are logged), and the
spheres, cylinders and cubes of `/markers` (Foxglove SceneUpdate) drawn in the /tf frame each entity names.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np
import rerun as rr
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from pipeline.core.runlog import read_run

TIMELINE = "sim_time"
MARKERS = "/markers"


def _frames(tf) -> dict[str, np.ndarray]:
    """child frame -> (N, 7) [x y z qx qy qz qw]."""
    out = {}
    for col in tf.columns:
        if col.endswith(".translation.x"):
            child = col.removeprefix("transforms.").removesuffix(".translation.x")
            prefix = f"transforms.{child}."
            out[child] = tf[[prefix + k for k in ("translation.x", "translation.y", "translation.z",
                                                   "rotation.x", "rotation.y", "rotation.z", "rotation.w")]].to_numpy()
    return out


def _rgba(color) -> list[float]:
    return [color.r, color.g, color.b, color.a]


def _log_markers(rec: rr.RecordingStream, run_path: Path) -> None:
    """SceneUpdate spheres, cylinders, cubes and triangle meshes under world/<frame_id>/<entity id>: they move with
    that /tf frame."""
    with open(run_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, _channel, message, update in reader.iter_decoded_messages(topics=[MARKERS]):
            rec.set_time(TIMELINE, duration=message.log_time / 1e9)
            for entity in update.entities:
                path = "/".join(("world", *(p for p in (entity.frame_id, entity.id) if p != "world")))
                if entity.spheres:
                    rec.log(f"{path}/spheres", rr.Ellipsoids3D(
                        centers=[[s.pose.position.x, s.pose.position.y, s.pose.position.z] for s in entity.spheres],
                        half_sizes=[[s.size.x / 2, s.size.y / 2, s.size.z / 2] for s in entity.spheres],
                        colors=[_rgba(s.color) for s in entity.spheres]))
                if entity.cylinders:
                    c = entity.cylinders
                    rec.log(f"{path}/cylinders", rr.Cylinders3D(
                        lengths=[x.size.z for x in c], radii=[x.size.x / 2 for x in c],
                        centers=[[x.pose.position.x, x.pose.position.y, x.pose.position.z] for x in c],
                        quaternions=[[x.pose.orientation.x, x.pose.orientation.y, x.pose.orientation.z,
                                      x.pose.orientation.w] for x in c],
                        colors=[_rgba(x.color) for x in c]))
                if entity.cubes:
                    c = entity.cubes
                    rec.log(f"{path}/cubes", rr.Boxes3D(
                        half_sizes=[[x.size.x / 2, x.size.y / 2, x.size.z / 2] for x in c],
                        centers=[[x.pose.position.x, x.pose.position.y, x.pose.position.z] for x in c],
                        quaternions=[[x.pose.orientation.x, x.pose.orientation.y, x.pose.orientation.z,
                                      x.pose.orientation.w] for x in c],
                        colors=[_rgba(x.color) for x in c], fill_mode="solid"))
                for k, mesh in enumerate(entity.triangles):
                    rec.log(f"{path}/triangles{k}", rr.Mesh3D(
                        vertex_positions=[[p.x, p.y, p.z] for p in mesh.points],
                        triangle_indices=np.asarray(mesh.indices, dtype=np.uint32).reshape(-1, 3),
                        albedo_factor=_rgba(mesh.color)))


def convert(run_path: Path, out: Path | None = None, spawn: bool = False) -> Path:
    run = read_run(run_path)
    out = out or run_path.with_suffix(".rrd")
    rec = rr.RecordingStream(f"repro-{run.metadata.get('slug', 'run')}", recording_id=run.run_id)
    if spawn:
        os.environ.setdefault("CI", "1")  # the viewer sends no usage analytics where CI is set (re_analytics)
        rec.spawn()
    rec.save(out)
    rec.log("run", rr.TextDocument("\n".join(f"{k}: {v}" for k, v in run.metadata.items())), static=True)
    for topic in run.topic_names:
        frame = run[topic]
        time = rr.TimeColumn(TIMELINE, duration=frame.index.to_numpy())
        if topic == MARKERS:
            _log_markers(rec, run_path)
            continue
        if topic == "/tf" or topic.startswith("/tf/"):
            frames = _frames(frame)
            for child, pose in frames.items():
                rec.send_columns(f"world/{child}", indexes=[time],
                                 columns=rr.Transform3D.columns(translation=pose[:, :3], quaternion=pose[:, 3:]))
            if len(frames) > 1:  # a skeleton through the frame origins, in logging order
                origins = np.stack([pose[:, :3] for pose in frames.values()], axis=1)
                rec.send_columns("world/skeleton", indexes=[time],
                                 columns=rr.LineStrips3D.columns(strips=list(origins)).partition([1] * len(origins)))
            continue
        for column in frame.columns:
            values = frame[column]
            if values.dtype.kind in "fiub":
                rec.send_columns(f"{topic.strip('/')}/{column}", indexes=[time],
                                 columns=rr.Scalars.columns(scalars=values.to_numpy(dtype=float)))
    rec.flush()
    return out


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m analysis.view", description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a run file (.mcap)")
    parser.add_argument("--out", type=Path, help="where to write the .rrd (default: beside the run)")
    parser.add_argument("--spawn", action="store_true", help="also open the Rerun viewer")
    args = parser.parse_args(argv)
    if not args.run.is_file():
        print(f"error: no run file {args.run}", file=sys.stderr)
        return 2
    print(f"wrote {convert(args.run, args.out, args.spawn)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""Open a run in Rerun with plots and a 3-D replay.

    python -m analysis.view data/runs/<slug>/<experiment>/<run>.mcap            writes <run>.rrd beside it
    python -m analysis.view <run>.mcap --spawn                                  and opens the Rerun viewer

Rerun also opens the .mcap directly (`rerun <run>.mcap`): it draws /tf and decodes every other channel as
queryable fields. This converter adds what reflection cannot: every numeric column as a time series on a
`sim_time` timeline, and the /tf frames as a 3-D skeleton (frames joined in the order they are logged).

A run may attach `view.json` to draw bodies the frames alone do not show:

    {"shapes": {"<tf child frame>": {"sphere": radius}},                 moves with that frame
     "surfaces": {"<name>": {"x": [x0, x1], "y": [y0, y1], "z": rows}}}   static height field z[i][j] at
                                                                          (x0 + j·dx, y0 + i·dy) in the world
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import rerun as rr

from pipeline.core.runlog import read_run

TIMELINE = "sim_time"
VIEW_ATTACHMENT = "view.json"


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


def _height_field_mesh(x: list[float], y: list[float], z) -> rr.Mesh3D:
    z = np.asarray(z, dtype=float)
    rows, cols = z.shape
    gx, gy = np.meshgrid(np.linspace(x[0], x[1], cols), np.linspace(y[0], y[1], rows))
    corner = (np.arange(rows - 1)[:, None] * cols + np.arange(cols - 1)[None, :]).ravel()
    triangles = np.concatenate([np.stack([corner, corner + 1, corner + cols], axis=1),
                                np.stack([corner + 1, corner + cols + 1, corner + cols], axis=1)])
    return rr.Mesh3D(vertex_positions=np.column_stack([gx.ravel(), gy.ravel(), z.ravel()]),
                     triangle_indices=triangles, albedo_factor=[160, 160, 150, 255])


def _log_view(rec: rr.RecordingStream, attachment: bytes) -> None:
    """Shapes and surfaces of the run's `view.json` (static; shapes follow their /tf frames)."""
    view = json.loads(attachment)
    for frame, shape in (view.get("shapes") or {}).items():
        if "sphere" in shape:
            r = float(shape["sphere"])
            rec.log(f"world/{frame}/shape", rr.Ellipsoids3D(
                half_sizes=[[r, r, r]], fill_mode=rr.components.FillMode.MajorWireframe), static=True)
    for name, surface in (view.get("surfaces") or {}).items():
        rec.log(f"world/{name}", _height_field_mesh(surface["x"], surface["y"], surface["z"]), static=True)


def convert(run_path: Path, out: Path | None = None, spawn: bool = False) -> Path:
    run = read_run(run_path)
    out = out or run_path.with_suffix(".rrd")
    rec = rr.RecordingStream(f"repro-{run.metadata.get('slug', 'run')}", recording_id=run.run_id)
    if spawn:
        rec.spawn()
    rec.save(out)
    rec.log("run", rr.TextDocument("\n".join(f"{k}: {v}" for k, v in run.metadata.items())), static=True)
    if VIEW_ATTACHMENT in run.attachments:
        _log_view(rec, run.attachments[VIEW_ATTACHMENT])
    for topic in run.topic_names:
        frame = run[topic]
        time = rr.TimeColumn(TIMELINE, duration=frame.index.to_numpy())
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

"""Open a run in Rerun: the robot moving in 3-D beside the paper's key plots.

    python -m analysis.view data/runs/<slug>/<experiment>/<run>.mcap            writes data/views/<slug>/…/<run>.rrd
    python -m analysis.view <run>.mcap --spawn                                  and opens the Rerun viewer

Rerun also opens the .mcap directly (`CI=1 rerun <run>.mcap`): its MCAP loader draws the URDF of
`/robot_description` moved by the `/tf/robot` frames and decodes every other channel as queryable fields.
This converter adds what that loader does not: the `/markers` scene (Foxglove SceneUpdate: spheres, cubes,
cylinders, arrows for forces, lines, triangle meshes such as terrain) as Rerun archetypes in their /tf frames,
every numeric column as a time series on a `sim_time` timeline, and a blueprint: the 3-D view beside the key
plots (pipeline.core.layouts). Transforms are Rerun named frames (parent/child frame ids, as in the MCAP), so
the URDF, the paper's /tf frames and the markers share one frame tree rooted at `world`.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from pipeline.core import layouts, robot
from pipeline.core.runlog import Run, read_run

TIMELINE = "sim_time"
MARKERS = "/markers"
ROBOT_ENTITY = "robot"


def default_output(run_path: Path) -> Path:
    """data/views/<slug>/<experiment>/<run>.rrd for a run under <data_dir>/runs/…, else a temporary file:
    never beside the runs."""
    parts = run_path.resolve().parts
    if len(parts) > 4 and parts[-4] == "runs":
        return Path(*parts[:-4], "views", *parts[-3:-1], run_path.stem + ".rrd")
    return Path(tempfile.mkdtemp(prefix="repro-view-")) / (run_path.stem + ".rrd")


def _rgba(color) -> list[float]:
    return [color.r, color.g, color.b, color.a]


def _xyz(v) -> list[float]:
    return [v.x, v.y, v.z]


def _xyzw(q) -> list[float]:
    return [q.x, q.y, q.z, q.w]


def _arrow_vectors(arrows) -> tuple[list, list]:
    """Foxglove arrows point along +x of their pose, shaft + head long."""
    origins, vectors = [], []
    for a in arrows:
        q = np.array([a.pose.orientation.w, a.pose.orientation.x, a.pose.orientation.y, a.pose.orientation.z])
        w, u = q[0], q[1:]
        x = np.array([1.0, 0.0, 0.0])
        t = 2 * np.cross(u, x)
        direction = x + w * t + np.cross(u, t)
        origins.append(_xyz(a.pose.position))
        vectors.append(((a.shaft_length + a.head_length) * direction).tolist())
    return origins, vectors


_PRIMITIVES = ("spheres", "cubes", "cylinders", "arrows", "lines", "texts")


def _log_entity(rec: rr.RecordingStream, entity, drawn: dict[str, set[str]]) -> None:
    """One SceneEntity as Rerun archetypes under markers/<id>, placed in its /tf frame. An entity replaces the
    one of the same id (Foxglove's rule): the kinds of primitive it no longer has (contacts gone) are cleared."""
    path = f"markers/{entity.id or entity.frame_id}"
    # every archetype carries the frame itself: a child entity does not inherit its parent's CoordinateFrame,
    # and geometry without one hangs off no named frame (Rerun then draws nothing)
    frame = rr.CoordinateFrame(entity.frame_id or "world")
    if entity.metadata and path not in drawn:   # e.g. the scale of force arrows (m/N), shown with the entity
        rec.log(path, rr.AnyValues(**{kv.key: kv.value for kv in entity.metadata}), static=True)
    present = {kind for kind in _PRIMITIVES if getattr(entity, kind)}
    for kind in drawn.get(path, set()) - present:
        rec.log(f"{path}/{kind}", rr.Clear(recursive=False))
    drawn[path] = present
    if entity.spheres:
        rec.log(f"{path}/spheres", rr.Ellipsoids3D(
            centers=[_xyz(s.pose.position) for s in entity.spheres],
            half_sizes=[[s.size.x / 2, s.size.y / 2, s.size.z / 2] for s in entity.spheres],
            quaternions=[_xyzw(s.pose.orientation) for s in entity.spheres],
            colors=[_rgba(s.color) for s in entity.spheres], fill_mode="solid"), frame)
    if entity.cubes:
        rec.log(f"{path}/cubes", rr.Boxes3D(
            centers=[_xyz(c.pose.position) for c in entity.cubes], sizes=[_xyz(c.size) for c in entity.cubes],
            quaternions=[_xyzw(c.pose.orientation) for c in entity.cubes],
            colors=[_rgba(c.color) for c in entity.cubes], fill_mode="solid"), frame)
    if entity.cylinders:
        c = entity.cylinders
        rec.log(f"{path}/cylinders", rr.Cylinders3D(
            lengths=[x.size.z for x in c], radii=[x.size.x / 2 for x in c],
            centers=[_xyz(x.pose.position) for x in c], quaternions=[_xyzw(x.pose.orientation) for x in c],
            colors=[_rgba(x.color) for x in c], fill_mode="solid"), frame)
    if entity.arrows:
        origins, vectors = _arrow_vectors(entity.arrows)
        rec.log(f"{path}/arrows", rr.Arrows3D(origins=origins, vectors=vectors,
                                              radii=[a.shaft_diameter / 2 for a in entity.arrows],
                                              colors=[_rgba(a.color) for a in entity.arrows]), frame)
    if entity.lines:
        rec.log(f"{path}/lines", rr.LineStrips3D([[_xyz(p) for p in line.points] for line in entity.lines],
                                                 radii=[line.thickness / 2 for line in entity.lines],
                                                 colors=[_rgba(line.color) for line in entity.lines]), frame)
    for k, mesh in enumerate(entity.triangles):
        rec.log(f"{path}/triangles{k}", rr.Mesh3D(
            vertex_positions=[_xyz(p) for p in mesh.points],
            triangle_indices=np.asarray(mesh.indices, dtype=np.uint32).reshape(-1, 3),
            albedo_factor=_rgba(mesh.color)), frame)
    if entity.texts:
        rec.log(f"{path}/texts", rr.Points3D([_xyz(x.pose.position) for x in entity.texts],
                                             labels=[x.text for x in entity.texts], radii=0.0), frame)


def _log_markers(rec: rr.RecordingStream, run_path: Path) -> None:
    with open(run_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        drawn: dict[str, set[str]] = {}
        for _schema, _channel, message, update in reader.iter_decoded_messages(topics=[MARKERS]):
            rec.set_time(TIMELINE, duration=message.log_time / 1e9)
            for deletion in update.deletions:
                rec.log(f"markers/{deletion.id}", rr.Clear(recursive=True))
                drawn.pop(f"markers/{deletion.id}", None)
            for entity in update.entities:
                _log_entity(rec, entity, drawn)


def _log_transforms(rec: rr.RecordingStream, topic: str, frame) -> None:
    """A FrameTransforms topic as named-frame Transform3D columns, one entity per child frame."""
    for col in frame.columns:
        if not col.endswith(".translation.x"):
            continue
        key = col.removesuffix(".translation.x")
        rows = frame[f"{key}.translation.x"].notna().to_numpy()
        if not rows.any():
            continue
        pose = frame.loc[rows, [f"{key}.{k}" for k in ("translation.x", "translation.y", "translation.z",
                                                        "rotation.x", "rotation.y", "rotation.z", "rotation.w")]]
        child = key.removeprefix("transforms.")
        parent = frame.loc[rows, f"{key}.parent_frame_id"].to_numpy()
        times = frame.index.to_numpy()[rows]  # a frame sent once (a fixed joint) has one row
        rec.send_columns(f"{topic.strip('/')}/{child}", indexes=[rr.TimeColumn(TIMELINE, duration=times)],
                         columns=rr.Transform3D.columns(translation=pose.iloc[:, :3].to_numpy(),
                                                        quaternion=pose.iloc[:, 3:].to_numpy(),
                                                        parent_frame=parent.tolist(),
                                                        child_frame=[child] * int(rows.sum())))


def _blueprint(run: Run, plotted: dict[str, list[str]]) -> rrb.Blueprint:
    """The 3-D scene beside the key plots (the same choice as the Foxglove layout)."""
    views = []
    for plot in layouts.key_plots(run.topic_names, run.metadata.get("slug")):
        entities = [e for path in plot.paths for e in plotted.get(path, [])]
        if entities:
            views.append(rrb.TimeSeriesView(name=plot.title, origin="/", contents=entities))
    scene = rrb.Spatial3DView(name="robot", origin="/", contents=["+ /**", *(f"- /{t.strip('/')}/**"
                                                                             for t in run.topic_names
                                                                             if not t.startswith(("/tf", MARKERS)))])
    return rrb.Blueprint(rrb.Horizontal(scene, rrb.Vertical(*views), column_shares=[2, 1]) if views else scene,
                         rrb.TimePanel(state="collapsed"), collapse_panels=True)


def convert(run_path: Path, out: Path | None = None, spawn: bool = False) -> Path:
    run = read_run(run_path)
    out = out or default_output(run_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    rec = rr.RecordingStream(f"repro-{run.metadata.get('slug', 'run')}", recording_id=run.run_id)
    if spawn:
        os.environ.setdefault("CI", "1")  # the viewer sends no usage analytics where CI is set (re_analytics)
        rec.spawn()
    rec.save(out)
    rec.log("run", rr.TextDocument("\n".join(f"{k}: {v}" for k, v in run.metadata.items())), static=True)
    if robot.URDF_ATTACHMENT in run.attachments:  # Rerun's URDF loader: geometry in frames named by the links
        rec.log_file_from_contents(robot.URDF_ATTACHMENT, run.attachments[robot.URDF_ATTACHMENT],
                                   entity_path_prefix=ROBOT_ENTITY, static=True)
    plotted: dict[str, list[str]] = {}
    for topic in run.topic_names:
        if topic == MARKERS:
            _log_markers(rec, run_path)
            continue
        if topic == robot.ROBOT_DESCRIPTION:
            continue
        frame = run[topic]
        if topic == "/tf" or topic.startswith("/tf/"):
            _log_transforms(rec, topic, frame)
            continue
        time = rr.TimeColumn(TIMELINE, duration=frame.index.to_numpy())
        for column in frame.columns:
            values = frame[column]
            if values.dtype.kind in "fiub":
                entity = f"{topic.strip('/')}/{column}"
                rec.send_columns(entity, indexes=[time],
                                 columns=rr.Scalars.columns(scalars=values.to_numpy(dtype=float)))
                field = column.split(".", 1)[0]
                plotted.setdefault(f"{topic}.{column}", []).append(f"/{entity}")
                plotted.setdefault(f"{topic}.{field}[:]", []).append(f"/{entity}")
    rec.send_blueprint(_blueprint(run, plotted))
    rec.flush()
    return out


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m analysis.view", description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a run file (.mcap)")
    parser.add_argument("--out", type=Path, help="where to write the .rrd (default: data/views/<slug>/<experiment>/)")
    parser.add_argument("--spawn", action="store_true", help="also open the Rerun viewer")
    parser.add_argument("--foxglove-layout", type=Path, metavar="JSON",
                        help="also write the run's Foxglove layout there (Foxglove: Layouts → Import from file)")
    args = parser.parse_args(argv)
    if not args.run.is_file():
        print(f"error: no run file {args.run}", file=sys.stderr)
        return 2
    print(f"wrote {convert(args.run, args.out, args.spawn)}", file=sys.stderr)
    if args.foxglove_layout:
        run = read_run(args.run)
        layout = run.attachments.get(layouts.LAYOUT_ATTACHMENT) or \
            layouts.foxglove_layout(run.topic_names, run.metadata.get("slug")).encode()
        args.foxglove_layout.write_bytes(layout)
        print(f"wrote {args.foxglove_layout}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

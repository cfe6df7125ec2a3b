"""Default views of a run: which plots sit beside the 3-D scene, as a Foxglove layout and (analysis.view) a
Rerun blueprint, so that opening a run shows the robot moving beside its tracking error without clicking.

The plots are chosen from the run's topics: each tracking error's norm, clearances, contact/grasp forces;
a paper may name its own in `VIEW_PLOTS` (a list of `topic.field` paths) in `pipeline/papers/<module>`.
The Foxglove layout is built with `foxglove.layouts` (the SDK's typed model of Foxglove's layout schema, so
a field Foxglove does not know cannot be written) and attached to every run as `foxglove-layout.json`:
Foxglove → Layouts → Import from file, then open the run.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pipeline.core import robot

if TYPE_CHECKING:  # the layout model is imported when a run is closed, not when the stage starts
    import foxglove.layouts as fl

LAYOUT_ATTACHMENT = "foxglove-layout.json"
MAX_PLOTS = 4


@dataclass(frozen=True)
class Plot:
    """One plot: a title and the `topic.field` paths it draws (`field[:]`: every entry, Foxglove's slice)."""

    title: str
    paths: tuple[str, ...]


def paper_plots(slug: str | None) -> list[str] | None:
    if not slug:
        return None
    try:
        module = importlib.import_module(f"pipeline.papers.{slug.replace('-', '_')}")
    except ImportError:
        return None
    return getattr(module, "VIEW_PLOTS", None)


def key_plots(topics: Iterable[str], slug: str | None = None) -> list[Plot]:
    """The plots shown beside the robot: the paper's `VIEW_PLOTS`, else every tracking error's norm, the
    clearances and the wrenches the run has, else its joint positions."""
    topics = sorted(topics)
    declared = paper_plots(slug)
    if declared:
        return [Plot(path, (path,)) for path in declared if path.rsplit(".", 1)[0] in topics][:MAX_PLOTS]
    plots = [Plot(f"{t} (norm)", (f"{t}.norm",)) for t in topics if t.startswith("/tracking_error")]
    plots += [Plot(t, (f"{t}.value[:]",)) for t in topics if t.startswith("/clearance")]
    plots += [Plot(f"{t} (force)", (f"{t}.force_x[:]", f"{t}.force_y[:]", f"{t}.force_z[:]"))
              for t in topics if t == "/wrench"]
    if not plots and "/joint_state" in topics:
        plots.append(Plot("/joint_state (position)", ("/joint_state.position[:]",)))
    return plots[:MAX_PLOTS]


def _three_d(topics: set[str]) -> fl.ThreeDeePanel:
    import foxglove.layouts as fl

    layers = {}
    if robot.ROBOT_DESCRIPTION in topics:
        layers["robot"] = fl.BaseRendererUrdfLayerSettings(
            instance_id="robot", layer_id="foxglove.Urdf", label="robot (URDF)", source_type="topic",
            topic=robot.ROBOT_DESCRIPTION, display_mode="visual",
            control_mode="jointStates" if robot.JOINT_STATES in topics else "transforms",
            joint_states_topic=robot.JOINT_STATES if robot.JOINT_STATES in topics else None)
    layers["grid"] = fl.BaseRendererGridLayerSettings(instance_id="grid", layer_id="foxglove.Grid", label="grid",
                                                      frame_id="world", size=4, divisions=40)
    return fl.ThreeDeePanel(title="robot", config=fl.ThreeDeeConfig(follow_tf="world", layers=layers))


def _plot(plot: Plot) -> fl.PlotPanel:
    import foxglove.layouts as fl

    return fl.PlotPanel(title=plot.title, config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=path, label=path.rsplit(".", 1)[-1]) for path in plot.paths], show_legend=True))


def foxglove_layout(topics: Iterable[str], slug: str | None = None) -> str:
    """The Foxglove layout (JSON) of a run with these topics: the 3-D scene (URDF driven by the joint
    states, /tf frames, /markers) beside the key plots."""
    return _foxglove_layout(frozenset(topics), slug)


@functools.lru_cache(maxsize=64)  # the runs of an experiment share their topics: one layout, made once
def _foxglove_layout(topics: frozenset[str], slug: str | None) -> str:
    import foxglove.layouts as fl

    plots = [fl.SplitItem(content=_plot(p)) for p in key_plots(topics, slug)]
    scene = fl.SplitItem(proportion=2 if plots else 1, content=_three_d(topics))
    right = [fl.SplitItem(content=fl.SplitContainer(direction="column", items=plots))] if plots else []
    return fl.Layout(content=fl.SplitContainer(direction="row", items=[scene, *right])).to_json()

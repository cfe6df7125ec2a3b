"""One run -> one episode: which topics become which features, and their resampling to a fixed rate.

    observation.state    /joint_state positions then velocities (`<joint>.pos`, `<joint>.vel`)
    observation.effort   /joint_state efforts (`<joint>.effort`), when logged
    action               /command: what the controller sent (`<entry>`), its `kind` in the feature's metadata
    <topic>              every other trajectory signal, named after its topic (`/tracking_error/flange` ->
                         `tracking_error.flange`, `/wrench` -> `wrench`): the families of /joint_state,
                         /command, /reference, /tracking_error, /wrench and the papers' Scalars topics

Wall-clock records (/compute_time), frames and markers (/tf, /markers: the viewer's), one-off records and
the papers' own record kinds are not frame signals and stay in the MCAP files. Every feature keeps the unit of
each of its entries (from the run file's channel metadata).

Resampling: frames at t_k = t_0 + k/fps over the span of the primary topic (/joint_state, else /command,
else the first state topic), k = 0 … ⌊(t_end − t_0)·fps⌋. Signals are linearly interpolated between logged
samples (numpy.interp; no anti-alias filter); the action is held (zero-order hold: the command in force at
t_k), as an actuator holds it. A signal that does not cover the primary span is not exported.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from pipeline.core import schemas
from pipeline.core.runlog import CONFIG_ATTACHMENT, Run

FAMILIES = ("/joint_state", "/command", "/reference", "/tracking_error", "/wrench")
EXPORTED_SCHEMAS = {schemas.JointState.DESCRIPTOR.full_name, schemas.Reference.DESCRIPTOR.full_name,
                    schemas.Command.DESCRIPTOR.full_name, schemas.TrackingError.DESCRIPTOR.full_name,
                    schemas.Wrench.DESCRIPTOR.full_name, schemas.Scalars.DESCRIPTOR.full_name}
RESAMPLING = ("linear interpolation between logged samples at t_k = t_0 + k/fps (numpy.interp, no anti-alias "
              "filter); the action by zero-order hold (the command in force at t_k)")
MEANING = {
    "observation.state": "joint positions, then joint velocities",
    "observation.effort": "joint efforts: torques of revolute joints, forces of prismatic ones",
    "action": "what the controller sent to the actuators",
    "/joint_state": "joint state of a second model or plant",
    "/command": "a further command channel",
    "/reference": "what the controller tracks (desired positions, velocities, accelerations)",
    "/tracking_error": "reference minus measurement per coordinate, and its Euclidean norm",
    "/wrench": "forces (N) and torques (N*m) at a named point or contact",
}
SPAN_TOLERANCE = 0.5   # of a frame: how far a signal may stop short of the primary span's ends


@dataclass
class Feature:
    """A float feature of an episode: (frames, entries) values, one name and unit per entry."""

    key: str
    names: list[str]
    units: list[str]
    topic: str
    meaning: str
    values: np.ndarray = field(repr=False)
    extra: dict = field(default_factory=dict)   # e.g. the command's kind

    def signature(self) -> tuple:
        return self.key, tuple(self.names), tuple(self.units)


@dataclass
class Episode:
    """One run's frames, with what the card and the episode table need of the run (no MCAP handle)."""

    run_id: str
    metadata: dict[str, str]
    params: dict
    config: str                # the resolved config the run was made with (YAML)
    times: np.ndarray          # simulated time of each frame (s)
    features: dict[str, Feature]
    dropped: dict[str, str]    # topic -> why it is not a feature


def feature_key(topic: str) -> str:
    return topic.strip("/").replace("/", ".")


def meaning_of(topic: str) -> str:
    family = next((f for f in FAMILIES if topic == f or topic.startswith(f + "/")), None)
    return MEANING.get(family, "") if family else "a signal of the paper's own (Scalars)"


def trajectory_topics(run: Run) -> list[str]:
    """The run's topics that hold a frame signal (see the module's docstring), sampled more than once."""
    out = []
    for topic in run.topic_names:
        if run.schema_name(topic) in EXPORTED_SCHEMAS and run.message_count(topic) > 1:
            out.append(topic)
    return out


def has_trajectory(run: Run) -> bool:
    """A run with a time series of the simulated state (the watchdog's state topics)."""
    return any(t.split("/")[1] in ("joint_state", "command", "tracking_error", "wrench")
               for t in trajectory_topics(run))


def _numeric(frame: pd.DataFrame, units: dict[str, str]) -> tuple[list[str], list[str]]:
    columns = [c for c in frame.columns if frame[c].dtype.kind in "fiub"]
    return columns, [units.get(c, "") for c in columns]


def primary_topic(topics: list[str]) -> str | None:
    for wanted in ("/joint_state", "/command"):
        if wanted in topics:
            return wanted
    return next((t for t in topics if t.split("/")[1] in ("tracking_error", "wrench", "reference")), None)


def frame_times(run: Run, fps: int) -> np.ndarray:
    topics = trajectory_topics(run)
    primary = primary_topic(topics)
    if primary is None:
        return np.zeros(0)
    t = run[primary].index.to_numpy()
    count = int(np.floor((t[-1] - t[0]) * fps + 1e-9)) + 1
    return t[0] + np.arange(count) / fps


def _interpolate(frame: pd.DataFrame, columns: list[str], times: np.ndarray, hold: bool) -> np.ndarray:
    t = frame.index.to_numpy()
    data = frame[columns].to_numpy(dtype=float)
    if len(t) > 1 and (np.diff(t) <= 0).any():  # repeated times (a restart): keep the last record of each
        keep = np.r_[np.diff(t) > 0, True]
        t, data = t[keep], data[keep]
    if hold:
        index = np.clip(np.searchsorted(t, times + 1e-12, side="right") - 1, 0, len(t) - 1)
        return data[index]
    return np.column_stack([np.interp(times, t, data[:, j]) for j in range(data.shape[1])])


def episode(run: Run, fps: int) -> Episode:
    """The features of one run at `fps` frames per second."""
    times = frame_times(run, fps)
    topics = trajectory_topics(run)
    features: dict[str, Feature] = {}
    dropped: dict[str, str] = {}
    half = SPAN_TOLERANCE / fps
    for topic in topics:
        frame, units = run[topic], run.units(topic)
        t = frame.index.to_numpy()
        if t[0] > times[0] + half or t[-1] < times[-1] - half:
            dropped[topic] = f"spans {t[0]:.4g}-{t[-1]:.4g} s, not the episode's {times[0]:.4g}-{times[-1]:.4g} s"
            continue
        columns, column_units = _numeric(frame, units)
        if topic == "/joint_state":
            for part, key, suffix in (("position.", "observation.state", "pos"), ("velocity.", None, "vel"),
                                      ("effort.", "observation.effort", "effort")):
                chosen = [c for c in columns if c.startswith(part)]
                if not chosen:
                    continue
                values = _interpolate(frame, chosen, times, hold=False)
                names = [f"{c[len(part):]}.{suffix}" for c in chosen]
                feature_units = [units.get(c, "") for c in chosen]
                if key is None:   # velocities join the positions in observation.state
                    state = features["observation.state"]
                    state.values = np.hstack([state.values, values])
                    state.names += names
                    state.units += feature_units
                    continue
                features[key] = Feature(key, names, feature_units, topic, MEANING[key], values)
        elif topic == "/command":
            kind = str(frame["kind"].iloc[0]) if "kind" in frame.columns else ""
            values = _interpolate(frame, columns, times, hold=True)
            names = [c.removeprefix("value.") for c in columns]
            features["action"] = Feature("action", names, column_units, topic, MEANING["action"], values,
                                         {"kind": kind})
        else:
            key = feature_key(topic)
            values = _interpolate(frame, columns, times, hold=False)
            features[key] = Feature(key, columns, column_units, topic, meaning_of(topic), values)
    config = run.attachments.get(CONFIG_ATTACHMENT, b"").decode()
    return Episode(run.run_id, dict(run.metadata), run.params, config, times, features, dropped)

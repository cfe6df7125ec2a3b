"""Episodes -> a LeRobot v3.0 dataset folder (checked against lerobot 0.4.4, `lerobot.datasets`):

    meta/info.json                        codebase_version v3.0, fps, features (dtype, shape, names; ours add
                                          `units`, `description`, `topic`), path templates, totals, splits
    meta/stats.json                       per feature: min, max, mean, std, count, q01 q10 q50 q90 q99
    meta/tasks.parquet                    task string (index) -> task_index
    meta/episodes/chunk-000/file-000.parquet   per episode: episode_index, tasks, length, data/chunk_index,
                                          data/file_index, dataset_from_index, dataset_to_index,
                                          meta/episodes/chunk_index, meta/episodes/file_index, stats/<feature>/<stat>,
                                          and ours: run_id, case, parameters (JSON), parameters/<key> (numbers)
    data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet   frames of many episodes (≤ 100 MB a file)

Frames are float32 like LeRobot's own datasets (a feature of one entry is a plain column, of n a fixed-size
list); timestamp is float32 k/fps from each episode's start; index counts frames over the whole dataset.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from pipeline.dataset.features import Episode, Feature

CODEBASE_VERSION = "v3.0"
CHUNK_SIZE = 1000                 # files per chunk directory
DATA_FILE_MB = 100
VIDEO_FILE_MB = 200
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
EPISODES_PATH = "meta/episodes/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)
INDEX_FEATURES = {
    "timestamp": {"dtype": "float32", "shape": [1], "names": None, "units": ["s"],
                  "description": "time of the frame from the episode's start"},
    "frame_index": {"dtype": "int64", "shape": [1], "names": None, "units": ["1"],
                    "description": "frame number within the episode"},
    "episode_index": {"dtype": "int64", "shape": [1], "names": None, "units": ["1"],
                      "description": "episode number (one episode per run)"},
    "index": {"dtype": "int64", "shape": [1], "names": None, "units": ["1"],
              "description": "frame number within the dataset"},
    "task_index": {"dtype": "int64", "shape": [1], "names": None, "units": ["1"],
                   "description": "row of meta/tasks.parquet"},
}


def stats(values: np.ndarray) -> dict[str, list]:
    """LeRobot's statistics of a (frames, entries) array, per entry."""
    values = np.asarray(values, dtype=np.float64).reshape(len(values), -1)
    out = {"min": values.min(axis=0), "max": values.max(axis=0), "mean": values.mean(axis=0),
           "std": values.std(axis=0)}
    quantiles = np.quantile(values, QUANTILES, axis=0)
    out |= {f"q{round(q * 100):02d}": quantiles[i] for i, q in enumerate(QUANTILES)}
    return {k: v.tolist() for k, v in out.items()} | {"count": [len(values)]}


def feature_spec(feature: Feature) -> dict:
    spec = {"dtype": "float32", "shape": [len(feature.names)], "names": feature.names, "units": feature.units,
            "description": feature.meaning, "topic": feature.topic}
    return spec | feature.extra


def _column(values: np.ndarray, dtype) -> pa.Array:
    values = np.ascontiguousarray(values, dtype=dtype)
    if values.ndim == 1 or values.shape[1] == 1:
        return pa.array(values.reshape(-1))
    return pa.FixedSizeListArray.from_arrays(pa.array(values.reshape(-1)), values.shape[1])


def write(episodes: Sequence[Episode], root: Path, fps: int, task_of: Callable[[Episode], str],
          robot_type: str, episode_columns: Callable[[Episode], dict]) -> dict:
    """Write the dataset under `root` (an empty directory); returns info.json's content."""
    keys = list(episodes[0].features)
    specs = {k: feature_spec(episodes[0].features[k]) for k in keys}
    tasks: list[str] = []
    for ep in episodes:
        task = task_of(ep)
        if task not in tasks:
            tasks.append(task)
    floats_per_frame = sum(len(s["names"]) for s in specs.values())
    frames_per_file = max(1, int(DATA_FILE_MB * 1024 * 1024 / (4 * floats_per_frame + 8 * 4 + 4)))

    all_values = {k: [] for k in [*keys, *INDEX_FEATURES]}
    rows, batch, file_number, file_frames, start = [], [], 0, 0, 0

    def flush(batch: list[dict]) -> None:
        if not batch:
            return
        chunk, index = divmod(file_number, CHUNK_SIZE)
        columns = {k: pa.concat_arrays([b[k] for b in batch]) for k in batch[0]}
        path = root / DATA_PATH.format(chunk_index=chunk, file_index=index)
        path.parent.mkdir(parents=True, exist_ok=True)
        pq.write_table(pa.table(columns), path, compression="snappy")

    for episode_index, ep in enumerate(episodes):
        length = len(ep.times)
        if batch and file_frames + length > frames_per_file:
            flush(batch)
            batch, file_number, file_frames = [], file_number + 1, 0
        index_values = {
            "timestamp": (np.arange(length) / fps).astype(np.float32),
            "frame_index": np.arange(length, dtype=np.int64),
            "episode_index": np.full(length, episode_index, dtype=np.int64),
            "index": np.arange(start, start + length, dtype=np.int64),
            "task_index": np.full(length, tasks.index(task_of(ep)), dtype=np.int64),
        }
        columns = {k: _column(ep.features[k].values, np.float32) for k in keys}
        columns |= {k: pa.array(v) for k, v in index_values.items()}
        batch.append(columns)
        episode_stats = {}
        for k in keys:
            values = ep.features[k].values.astype(np.float32)
            all_values[k].append(values)
            episode_stats[k] = stats(values)
        for k, v in index_values.items():
            all_values[k].append(v)
            episode_stats[k] = stats(v)
        chunk, index = divmod(file_number, CHUNK_SIZE)
        row = {"episode_index": episode_index, "tasks": [task_of(ep)], "length": length,
               "data/chunk_index": chunk, "data/file_index": index,
               "dataset_from_index": start, "dataset_to_index": start + length,
               "meta/episodes/chunk_index": 0, "meta/episodes/file_index": 0}
        row |= {f"stats/{k}/{s}": v for k, st in episode_stats.items() for s, v in st.items()}
        rows.append(row | episode_columns(ep))
        start += length
        file_frames += length
    flush(batch)

    episodes_path = root / EPISODES_PATH.format(chunk_index=0, file_index=0)
    episodes_path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.Table.from_pandas(pd.DataFrame(rows), preserve_index=False), episodes_path,
                   compression="snappy")
    tasks_path = root / "meta" / "tasks.parquet"
    pd.DataFrame({"task_index": range(len(tasks))}, index=tasks).to_parquet(tasks_path)
    global_stats = {k: stats(np.concatenate(v)) for k, v in all_values.items()}
    (root / "meta" / "stats.json").write_text(json.dumps(global_stats, indent=4))
    info = {
        "codebase_version": CODEBASE_VERSION, "robot_type": robot_type, "total_episodes": len(episodes),
        "total_frames": start, "total_tasks": len(tasks), "chunks_size": CHUNK_SIZE,
        "data_files_size_in_mb": DATA_FILE_MB, "video_files_size_in_mb": VIDEO_FILE_MB, "fps": fps,
        "splits": {"train": f"0:{len(episodes)}"}, "data_path": DATA_PATH, "video_path": None,
        "features": {**specs, **INDEX_FEATURES},
    }
    (root / "meta" / "info.json").write_text(json.dumps(info, indent=4, ensure_ascii=False))
    return info

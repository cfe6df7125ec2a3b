"""Runs -> LeRobot datasets with a card: the runs of an experiment, of a sweep, of randomized episodes, or of
several experiments (one task each) become one dataset, one episode per run.

A LeRobot dataset holds one robot: every episode has the same features. Runs whose state or action differ
(a sweep over chain lengths, a planar and a spatial peg) are written as one dataset per kind, in
sub-folders named after their shapes (`state4-action2`, ...), under the one output folder. Features that
only some runs of a kind have are left out of that kind's dataset and named in its card.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import yaml
from jinja2 import Environment, FileSystemLoader, StrictUndefined

from pipeline.core import files, parallel
from pipeline.core.experiment import CONF_DIR, experiment_descriptions, module_name
from pipeline.core.runlog import Run, read_run, run_files
from pipeline.dataset import features, lerobot
from pipeline.dataset.features import RESAMPLING, Episode

DEFAULT_FPS = 50        # frames per second at most (LeRobot's datasets run at 10-50); never above the log rate
MAX_FPS = 10_000
DEFAULT_LICENSE = "cc-by-4.0"
ANALYSIS_PAPERS = CONF_DIR.parent / "analysis" / "papers"
TEMPLATES = Path(__file__).parent / "templates"


class ExportError(ValueError):
    """Nothing sensible to export; the message is the one line shown to the user."""


@dataclass(frozen=True)
class Source:
    """Runs to export: a directory of run files, and the experiment they belong to (None: read from the runs)."""

    runs: Path
    experiment: str | None = None


def experiment_source(experiment_id: str, data_dir: Path) -> Source:
    slug, _, name = experiment_id.partition("/")
    return Source(data_dir / "runs" / slug / name, experiment_id)


def _episode(path: Path, fps: int) -> Episode:
    return features.episode(read_run(path), fps)


def native_rate(run: Run) -> float:
    """Samples per second of the run's primary trajectory topic."""
    topics = features.trajectory_topics(run)
    primary = features.primary_topic(topics)
    t = run[primary].index.to_numpy()
    return (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 and t[-1] > t[0] else 1.0


def _shape_name(signature: tuple) -> str:
    parts = [f"{key.split('.')[-1]}{len(names)}" for key, names, _ in signature]
    return "-".join(parts) or "signals"


def _groups(episodes: list[Episode]) -> dict[str, list[Episode]]:
    """Episodes of one robot together: same state, effort and action entries."""
    core = ("observation.state", "observation.effort", "action")
    by_signature: dict[tuple, list[Episode]] = {}
    for ep in episodes:
        signature = tuple(ep.features[k].signature() for k in core if k in ep.features)
        by_signature.setdefault(signature, []).append(ep)
    if len(by_signature) == 1:
        return {"": next(iter(by_signature.values()))}
    names = {}
    for signature, group in by_signature.items():
        name = _shape_name(signature)
        while name in names:
            name += "+"
        names[name] = group
    return names


def _common_features(group: list[Episode]) -> dict[str, str]:
    """Keep the features every episode has with the same entries; return what was left out, and why."""
    counts: dict[tuple, int] = {}
    for ep in group:
        for f in ep.features.values():
            counts[f.signature()] = counts.get(f.signature(), 0) + 1
    keep = {sig[0] for sig, n in counts.items() if n == len(group)}
    left_out = {}
    for ep in group:
        for key in list(ep.features):
            if key not in keep:
                left_out[ep.features[key].topic] = "not in every run of this dataset (or with other entries)"
                del ep.features[key]
        order = ["observation.state", "observation.effort", "action"]
        ep.features = dict(sorted(ep.features.items(), key=lambda kv: (order.index(kv[0]) if kv[0] in order
                                                                       else len(order), kv[0])))
    return left_out


@cache
def paper_info(slug: str) -> dict:
    path = ANALYSIS_PAPERS / module_name(slug) / "paper.yaml"
    info = yaml.safe_load(path.read_text()) if path.is_file() else {}
    return {"slug": slug, "title": info.get("title", slug), "authors": info.get("authors", ""),
            "venue": info.get("venue", ""), "doi": info.get("doi", "")}


def _experiment_of(ep: Episode) -> str:
    return f"{ep.metadata.get('slug', '')}/{ep.metadata.get('experiment', '')}"


def _episode_columns(ep: Episode) -> dict:
    row = {"run_id": ep.run_id, "case": ep.metadata.get("case", ""),
           "parameters": json.dumps(ep.params, sort_keys=True)}
    row |= {f"parameters/{k}": float(v) for k, v in ep.params.items()
            if isinstance(v, int | float) and not isinstance(v, bool)}
    return row


def _variation(group: list[Episode]) -> tuple[str, dict, str]:
    """(how the episodes differ, the randomized keys -> distribution, the seed of the randomization)."""
    first = group[0].metadata
    randomized = json.loads(first.get("randomized", "{}"))
    if randomized:
        return (f"{len(group)} randomized episodes, parameters drawn per episode from the distributions below",
                randomized, first.get("episodes_seed", ""))
    swept = sorted({k for ep in group for k in ep.params})
    cases = sorted({ep.metadata.get("case", "") for ep in group})
    text = f"{len(cases)} case{'s' if len(cases) > 1 else ''} of the experiment ({', '.join(cases[:12])}"
    text += ", …)" if len(cases) > 12 else ")"
    if swept:
        text += f"; a sweep over {', '.join(f'`{k}`' for k in swept)}"
    return text, {}, ""


def _render_card(group: list[Episode], info: dict, experiments: list[str], path: Path, dropped: dict,
                 license: str, native: str) -> str:
    slug = experiments[0].split("/")[0]
    paper = paper_info(slug)
    descriptions = experiment_descriptions()
    variation, randomized, seed = _variation(group)
    first = group[0].metadata
    versions = json.loads(first.get("package_versions", "{}"))
    frames = [{"key": k, "shape": f"{spec['shape'][0]}", "dtype": spec["dtype"], "description": spec["description"],
               "topic": spec.get("topic", ""), "kind": spec.get("kind", ""),
               "names": spec["names"] is not None,
               "entries": list(zip(spec["names"] or [], spec["units"], strict=False))}
              for k, spec in info["features"].items() if spec["names"] is not None]
    frames += [{"key": k, "shape": "1", "dtype": spec["dtype"], "description": f"{spec['description']} "
                f"({spec['units'][0]})", "topic": "", "kind": "", "names": False, "entries": []}
               for k, spec in info["features"].items() if spec["names"] is None]
    header = yaml.safe_dump({
        "license": license, "task_categories": ["robotics"], "pretty_name": f"{slug}: {', '.join(experiments)}",
        "tags": ["LeRobot", "simulation", slug, *sorted({e.split('/')[1] for e in experiments})],
        "configs": [{"config_name": "default", "data_files": "data/*/*.parquet"}],
    }, sort_keys=False, allow_unicode=True).strip()
    episodes_text = "Each episode is one run: " + ", ".join(f"`{ep.run_id}`" for ep in group[:8])
    episodes_text += ", …" if len(group) > 8 else ""
    env = Environment(loader=FileSystemLoader(TEMPLATES), undefined=StrictUndefined, keep_trailing_newline=True)
    return env.get_template("card.md.j2").render(
        header=header, title=f"{slug}: {', '.join(e.split('/')[1] for e in experiments)}", paper=paper,
        experiments=[{"id": e, "description": descriptions.get(e, "")} for e in experiments], info=info,
        duration=sum(len(ep.times) for ep in group) / info["fps"], native=native, resampling=RESAMPLING,
        variation=variation, randomized=randomized, seed=seed,
        revisions=", ".join(sorted({ep.metadata.get("git_revision", "unknown") for ep in group})),
        packages=", ".join(f"{k} {v}" for k, v in versions.items()), license=license, features=frames,
        dropped=dropped, episodes_text=episodes_text, config=group[0].config, path=path.as_posix(),
        repo_id=f"local/{slug}-{'+'.join(e.split('/')[1] for e in experiments)}",
        command=" && ".join([f"`python -m pipeline experiment={e}`" for e in experiments]
                            + [f"`python -m pipeline.dataset {' '.join(experiments)}`"]))


def export(sources: Sequence[Source], out: Path, fps: int | None = None, license: str = DEFAULT_LICENSE,
           workers: int = 0) -> list[Path]:
    """Write the LeRobot dataset(s) of the sources' runs under `out` (replaced whole); returns their folders."""
    paths = [p for s in sources for p in run_files(s.runs)]
    if not paths:
        where = ", ".join(str(s.runs) for s in sources)
        hint = "; run it first: python -m pipeline experiment=" + sources[0].experiment \
            if sources and sources[0].experiment else ""
        raise ExportError(f"no runs under {where}{hint}")
    runs, skipped = [], 0
    for path in paths:
        try:
            run = read_run(path)
        except ValueError:
            skipped += 1
            continue
        if run.ok and features.has_trajectory(run):
            runs.append(run)
    if not runs:
        raise ExportError(f"none of the {len(paths)} runs under {sources[0].runs} has a trajectory to export "
                          "(a time series on /joint_state, /command, /tracking_error or /wrench) that ran ok")
    native = native_rate(runs[0])
    fps = fps or max(1, min(DEFAULT_FPS, math.floor(native + 1e-9)))
    episodes = list(parallel.imap(lambda p: _episode(p, fps), [r.path for r in runs], workers))
    experiments = list(dict.fromkeys(_experiment_of(ep) for ep in episodes))
    descriptions = experiment_descriptions()
    groups = _groups(episodes)
    written = []
    with files.atomic_dir(out) as tmp:
        for name, group in groups.items():
            root = tmp / name if name else tmp
            root.mkdir(parents=True, exist_ok=True)
            dropped = {**{t: w for ep in group for t, w in ep.dropped.items()}, **_common_features(group)}
            slug = experiments[0].split("/")[0]
            info = lerobot.write(group, root, fps,
                                 lambda ep: descriptions.get(_experiment_of(ep), _experiment_of(ep)),
                                 f"{slug} (simulated)", _episode_columns)
            target = out / name if name else out
            (root / "README.md").write_text(_render_card(group, info, experiments, target, dropped, license,
                                                         f"{native:.4g} Hz"))
            written.append(target)
    return written


def stats_of(dataset: Path) -> dict:
    """meta/info.json of a written dataset (for a caller's message)."""
    return json.loads((dataset / "meta" / "info.json").read_text())


__all__ = ["DEFAULT_FPS", "DEFAULT_LICENSE", "ExportError", "Source", "experiment_source", "export", "native_rate"]

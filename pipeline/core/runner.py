"""The simulate stage: one experiment config -> one MCAP file per case under <data_dir>/runs/<slug>/<name>/."""

from __future__ import annotations

import datetime as dt
import hashlib
import re
import sys
import time
import traceback
from pathlib import Path

import yaml
from omegaconf import DictConfig, ListConfig, OmegaConf
from tqdm import tqdm

from pipeline.core import episodes, interrupts, parallel, provenance, stages
from pipeline.core.checks import BadInput, check_cases
from pipeline.core.experiment import resolve
from pipeline.core.files import Busy, Locks, stale_partials
from pipeline.core.runlog import CONFIG_ATTACHMENT, RunWriter, SimulationFailed, typed

# Overrides that do not change what is simulated, so they do not name a run.
NOT_PARAMS = ("experiment", "data_dir", "sweep_dir", "progress", "workers", "episodes.count")
MAX_ID = 120


def run_params(overrides: list[str]) -> dict[str, str]:
    """Command-line overrides that define a run of a sweep (recorded, and part of the run id)."""
    params = {}
    for o in overrides:
        key, _, value = o.lstrip("+~").partition("=")
        if key not in NOT_PARAMS and not key.startswith("hydra"):
            params[key] = value
    return params


def run_values(cfg: DictConfig, params: dict[str, str]) -> dict:
    """The overrides' values as the resolved config holds them: typed (numbers as numbers, lists as lists)."""
    values = {}
    for key in params:
        value = OmegaConf.select(cfg, key, default=None, throw_on_missing=False)
        value = OmegaConf.to_container(value, resolve=True) if isinstance(value, DictConfig | ListConfig) else value
        values[key] = typed(params[key]) if value is None else value
    return values


def run_id(case: str, params: dict[str, str]) -> str:
    """`<case>` or `<case>__k=v,k=v`: readable, filesystem-safe, and stable for the same overrides."""
    if not params:
        return case
    suffix = ",".join(f"{k}={v}" for k, v in sorted(params.items()))
    suffix = re.sub(r"[^\w.=,+-]", "_", re.sub(r"[\[\]\"' ]", "", suffix))
    if len(suffix) > MAX_ID:
        suffix = hashlib.sha1(suffix.encode()).hexdigest()[:12]
    return f"{case}__{suffix}"


def simulate(cfg: DictConfig, experiment_id: str, overrides: list[str] | None = None) -> int:
    """Run every case of an experiment; returns the number of runs that failed unexpectedly (bugs).

    A case that raises SimulationFailed is recorded as `failed: <reason>` and the next case runs.
    Any other exception is recorded the same way, printed, and counted, so the caller can exit != 0.
    An interrupt (SIGINT, SIGTERM) is never a status: the open run is dropped, earlier complete files stay,
    and Interrupted propagates, even when a simulator swallowed the KeyboardInterrupt it raised.
    Raises BadInput before anything is written if the cases' names are unsafe or another process is
    writing one of the same runs.
    """
    experiment = resolve(experiment_id)
    slug, name = experiment.slug, experiment.name
    params = run_params(overrides or [])
    data_dir = Path(cfg.data_dir)
    out_dir = data_dir / "runs" / slug / name
    config_yaml = OmegaConf.to_yaml(cfg, resolve=True)
    cases = check_cases(cfg, experiment)
    names = [f"episode-{i:06d}" for i in range(cfg.episodes.count)] or [case.id for case in cases]
    ids = [run_id(name, params) for name in names]
    interrupts.install()
    locks = Locks(data_dir, [f"{slug}/{name}/{rid}" for rid in ids])
    try:
        locks.acquire()
    except Busy as busy:
        raise BadInput(f"another process is writing run {busy} under {data_dir}: wait for it, or use another "
                       "data_dir") from None
    errors = 0
    try:
        for rid in ids:  # left by writers that died: nobody else can hold these names now
            for stale in stale_partials(out_dir / f"{rid}.mcap"):
                stale.unlink(missing_ok=True)
        bar = tqdm(total=len(ids), desc=experiment_id, unit="run", disable=None if cfg.progress else True,
                   leave=False, file=sys.stderr)
        alone = experiment.timed or any(case.shares_work for case in cases)
        workers = 1 if alone else parallel.workers_for(cfg.workers, len(ids))
        stages.mark("first_step")
        for rid, status, bug in _runs(cfg, experiment, cases, ids, out_dir, config_yaml, workers, {
                "slug": slug, "experiment": name, "params": params, "values": run_values(cfg, params),
                "git_revision": provenance.git_revision(), "package_versions": provenance.package_versions(),
                "machine": provenance.machine(), "parallel_runs": str(workers)}):  # beside a logged compute time
            bar.update()
            errors += bug
            tqdm.write(f"{experiment_id} {rid}: {status}" if status != "ok" else f"wrote {out_dir / rid}.mcap",
                       file=sys.stderr)
        bar.close()
    finally:
        for rid in ids:  # what workers stopped by an interrupt left unfinished
            for stale in stale_partials(out_dir / f"{rid}.mcap"):
                stale.unlink(missing_ok=True)
        locks.release()
    return errors


def _runs(cfg: DictConfig, experiment, cases, ids: list[str], out_dir: Path, config_yaml: str, workers: int,
          metadata: dict):
    """(run id, status, bug) of every run, on `workers` processes: the experiment's cases, or its episodes.

    A TIMED experiment, or one whose cases share work, runs on one: its runs one after another, alone (DVC
    runs one stage at a time)."""
    if not cfg.episodes.count:
        def run(index: int) -> tuple[str, str, bool]:
            case, rid = cases[index], ids[index]
            return rid, *_run_case(case, rid, out_dir, config_yaml, {
                **metadata, "run_id": rid, "case": case.id, "seed": str(cfg.seed)})

        yield from parallel.imap(run, range(len(cases)), workers)
        return
    described = {key: episodes.describe(dist) for key, dist in episodes.randomized(cfg).items()}
    base = OmegaConf.to_container(cfg, resolve=True)
    draw = episodes.sampler(cfg)

    def episode(index: int) -> tuple[str, str, bool]:
        values = draw(index)
        plain = episodes.apply(base, values, episodes.seed_of(cfg, index))
        case = experiment.fn(OmegaConf.create(plain))[0]
        status, bug = _run_case(case, ids[index], out_dir, yaml.safe_dump(plain, sort_keys=False), {
            **metadata, "run_id": ids[index], "case": case.id, "seed": str(plain["seed"]), "episode": str(index),
            "episodes_seed": str(cfg.seed), "randomized": described, "values": {**metadata["values"], **values}})
        return ids[index], status, bug

    yield from parallel.imap(episode, range(cfg.episodes.count), workers)


def _run_case(case, rid: str, out_dir: Path, config_yaml: str, metadata: dict) -> tuple[str, bool]:
    """Simulate one case into its run file; (status, whether a bug rather than physics failed it)."""
    bug = False
    metadata = {**metadata, "created": dt.datetime.now(dt.UTC).isoformat(timespec="seconds")}
    with RunWriter(out_dir / f"{rid}.mcap", metadata) as writer:
        writer.attach(CONFIG_ATTACHMENT, config_yaml, "application/yaml")
        start = time.perf_counter()
        try:
            case.simulate(writer)
            status = "ok" if writer.messages else "failed: nothing was simulated (no message was logged)"
        except SimulationFailed as err:
            interrupts.raise_if_received()  # a simulator that turned Ctrl-C into its own failure
            status = f"failed: {err}"
        except Exception as err:  # a bug, not physics: keep the record, but make it loud
            interrupts.raise_if_received()
            status, bug = f"failed: {type(err).__name__}: {err}", True
            traceback.print_exc()
        interrupts.raise_if_received()  # swallowed entirely: the run may be cut short, do not publish it
        writer.metadata["wall_time_s"] = f"{time.perf_counter() - start:.3f}"
        writer.close(status)
    return status, bug

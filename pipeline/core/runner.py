"""The simulate stage: one experiment config -> one MCAP file per case under <data_dir>/runs/<slug>/<name>/."""

from __future__ import annotations

import datetime as dt
import hashlib
import re
import sys
import time
import traceback
from pathlib import Path

from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from pipeline.core import provenance
from pipeline.core.experiment import resolve
from pipeline.core.runlog import CONFIG_ATTACHMENT, RunWriter, SimulationFailed

# Overrides that do not change what is simulated, so they do not name a run.
NOT_PARAMS = ("experiment", "data_dir", "progress")
MAX_ID = 120


def run_params(overrides: list[str]) -> dict[str, str]:
    """Command-line overrides that define a run of a sweep (recorded, and part of the run id)."""
    params = {}
    for o in overrides:
        key, _, value = o.lstrip("+~").partition("=")
        if key not in NOT_PARAMS and not key.startswith("hydra"):
            params[key] = value
    return params


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
    """
    slug, name, experiment, _ = resolve(experiment_id)
    params = run_params(overrides or [])
    out_dir = Path(cfg.data_dir) / "runs" / slug / name
    config_yaml = OmegaConf.to_yaml(cfg, resolve=True)
    cases = experiment(cfg)
    errors = 0
    bar = tqdm(cases, desc=experiment_id, unit="run", disable=None if cfg.progress else True,
               leave=False, file=sys.stderr)
    for case in bar:
        rid = run_id(case.id, params)
        bar.set_postfix_str(rid)
        metadata = {
            "slug": slug, "experiment": name, "run_id": rid, "case": case.id, "seed": str(cfg.seed),
            "params": params, "git_revision": provenance.git_revision(),
            "package_versions": provenance.package_versions(), "machine": provenance.machine(),
            "created": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
        }
        with RunWriter(out_dir / f"{rid}.mcap", metadata) as writer:
            writer.attach(CONFIG_ATTACHMENT, config_yaml, "application/yaml")
            start = time.perf_counter()
            try:
                case.simulate(writer)
                status = "ok"
            except SimulationFailed as err:
                status = f"failed: {err}"
            except Exception as err:  # a bug, not physics: keep the record, but make it loud
                errors += 1
                status = f"failed: {type(err).__name__}: {err}"
                traceback.print_exc()
            writer.metadata["wall_time_s"] = f"{time.perf_counter() - start:.3f}"
            path = writer.close(status)
        if status != "ok":
            tqdm.write(f"{experiment_id} {rid}: {status}", file=sys.stderr)
        else:
            tqdm.write(f"wrote {path}", file=sys.stderr)
    return errors

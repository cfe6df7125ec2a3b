"""A Submitit launcher (SLURM, or local processes to try it) that runs several sweep points per job.

A cluster schedules jobs in seconds and caps job arrays (SLURM's MaxArraySize, often 1001 to 10⁴), while a
run of a small paper takes a fraction of a second: one job per point would spend its time queueing. Here the
sweep's N points are cut into ⌈N / configs_per_job⌉ chunks, submitted as one job array (at most
`array_parallelism` running at a time); each array task runs its points one after the other through Hydra
(each with its own composed config, as a one-point job would). The launching process shows one progress bar
for the whole sweep, advanced as chunks finish.

Configured by conf/hydra/launcher/slurm.yaml and slurm_local.yaml (`executor`: slurm | local, `configs_per_job`,
and the Submitit plugin's own keys, passed through). Needs the [slurm] extra (hydra-submitit-launcher); this
module imports it only when a sweep is launched, so Hydra's plugin scan stays cheap and quiet without it.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hydra.core.singleton import Singleton
from hydra.core.utils import JobReturn, JobStatus
from hydra.plugins.launcher import Launcher
from hydra.types import HydraContext, TaskFunction
from omegaconf import DictConfig, OmegaConf

log = logging.getLogger(__name__)

EXECUTORS = ("slurm", "local")
POLL_S = {"slurm": 10.0, "local": 0.5}   # how often finished chunks are looked for (sacct is not for hammering)


class SubmititChunks(Launcher):
    def __init__(self, executor: str, configs_per_job: int, **params: Any) -> None:
        if executor not in EXECUTORS:
            raise ValueError(f"hydra.launcher.executor={executor} must be one of {', '.join(EXECUTORS)}")
        if int(configs_per_job) < 1:
            raise ValueError(f"hydra.launcher.configs_per_job={configs_per_job} must be >= 1")
        self.executor = executor
        self.configs_per_job = int(configs_per_job)
        self.params = {k: OmegaConf.to_container(v, resolve=True) if OmegaConf.is_config(v) else v
                       for k, v in params.items()}
        self.plugin: Any = None
        self.config: DictConfig | None = None

    def setup(self, *, hydra_context: HydraContext, task_function: TaskFunction, config: DictConfig) -> None:
        try:
            from hydra_plugins.hydra_submitit_launcher import submitit_launcher
        except ImportError:
            raise ImportError("hydra/launcher=slurm needs the Submitit launcher: pip install -e '.[slurm]'") from None
        plugin = {"slurm": submitit_launcher.SlurmLauncher, "local": submitit_launcher.LocalLauncher}[self.executor]
        self.plugin = plugin(**self.params)   # runs one point, exactly as the plugin would in a job of its own
        self.plugin.setup(hydra_context=hydra_context, task_function=task_function, config=config)
        self.config = config

    def __call__(self, chunk: list[tuple[int, list[str]]], singleton_state: dict) -> list[JobReturn]:
        """In the job: every point of the chunk, one after the other; one failing does not stop the others."""
        returns = []
        for num, overrides in chunk:
            try:
                ret = self.plugin(overrides, "hydra.sweep.dir", num, f"job_id_for_{num}", singleton_state)
            except SystemExit as stop:   # the task's own exit status (a run failed by a bug, bad input)
                if not stop.code:
                    raise
                ret = JobReturn(overrides=overrides, status=JobStatus.FAILED)
                ret.return_value = RuntimeError(f"sweep point {num} ({' '.join(overrides)}) exited {stop.code}")
            returns.append(ret)
        return returns

    def launch(self, job_overrides: Sequence[Sequence[str]], initial_job_idx: int) -> Sequence[JobReturn]:
        import submitit
        from tqdm import tqdm

        assert self.config is not None, "setup() first"
        points = [(initial_job_idx + i, list(o)) for i, o in enumerate(job_overrides)]
        chunks = [points[i:i + self.configs_per_job] for i in range(0, len(points), self.configs_per_job)]
        sweep_dir = Path(str(self.config.hydra.sweep.dir))
        sweep_dir.mkdir(parents=True, exist_ok=True)
        log.info(f"Submitit {self.executor}: {len(points)} sweep points in {len(chunks)} jobs of up to "
                 f"{self.configs_per_job}; logs under {sweep_dir}")
        jobs = self._executor(submitit).map_array(self, chunks, [Singleton.get_state()] * len(chunks))
        size = {job.job_id: len(chunk) for job, chunk in zip(jobs, chunks, strict=True)}
        show = OmegaConf.select(self.config, "progress", default=True)
        with tqdm(total=len(points), desc="sweep", unit="point", disable=None if show else True) as bar:
            for job in submitit.helpers.as_completed(jobs, poll_frequency=POLL_S[self.executor]):
                bar.update(size[job.job_id])
        return [ret for job in jobs for ret in job.results()[0]]

    def _executor(self, submitit: Any) -> Any:
        """The plugin's keys as Submitit takes them: its generic ones bare, the rest prefixed with the cluster."""
        from hydra_plugins.hydra_submitit_launcher.config import BaseQueueConf

        params = dict(self.params)
        init = {"folder": params.pop("submitit_folder")}
        if "max_num_timeout" in params:
            init[f"{self.executor}_max_num_timeout"] = params.pop("max_num_timeout")
        executor = submitit.AutoExecutor(cluster=self.executor, **init)
        generic = set(OmegaConf.structured(BaseQueueConf).keys())
        executor.update_parameters(**{k if k in generic else f"{self.executor}_{k}": v for k, v in params.items()})
        return executor

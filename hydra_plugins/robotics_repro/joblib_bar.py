"""The default sweep launcher: Hydra's joblib launcher (processes on this machine) with one progress bar for the
whole sweep in the launching process; the jobs draw none (pipeline/__main__.py turns theirs off in a sweep)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from hydra.core.singleton import Singleton
from hydra.core.utils import JobReturn, configure_log, setup_globals
from hydra_plugins.hydra_joblib_launcher.joblib_launcher import JoblibLauncher
from omegaconf import OmegaConf


class JoblibBar(JoblibLauncher):
    def launch(self, job_overrides: Sequence[Sequence[str]], initial_job_idx: int) -> Sequence[JobReturn]:
        from hydra_plugins.hydra_joblib_launcher._core import execute_job, process_joblib_cfg
        from joblib import Parallel, delayed
        from tqdm import tqdm

        assert self.config is not None and self.hydra_context is not None, "setup() first"
        setup_globals()
        configure_log(self.config.hydra.hydra_logging, self.config.hydra.verbose)
        Path(str(self.config.hydra.sweep.dir)).mkdir(parents=True, exist_ok=True)
        options = {**self.joblib, "backend": "loky", "return_as": "generator"}  # loky: threads break Hydra
        process_joblib_cfg(options)
        state = Singleton.get_state()
        results = Parallel(**options)(
            delayed(execute_job)(initial_job_idx + i, overrides, self.hydra_context, self.config, self.task_function,
                                 state) for i, overrides in enumerate(job_overrides))
        show = OmegaConf.select(self.config, "progress", default=True)
        return list(tqdm(results, total=len(job_overrides), desc="sweep", unit="point", disable=None if show else True))

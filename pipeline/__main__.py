"""Simulate stage CLI (a Hydra app: `--help` lists every experiment, `--cfg job`, `-p KEY`, `-m` as documented).

    python -m pipeline experiment=<slug>/<name> [key=value ...]       one experiment, one MCAP per case
    python -m pipeline -m experiment=<slug>/<name> key=a,b,c           a sweep, run in parallel (joblib), into
                                                                       <data_dir>/sweeps/<time>/ (sweep_dir=...)
    python -m pipeline --help                                          every experiment, one line each
    python -m pipeline experiment=<slug>/<name> --cfg job              the resolved config, nothing run

A single run (no flag, no sweep, no `hydra` override) runs on the config the input checks composed, through
Hydra's own job runner: composing it again in `@hydra.main` (twice: once for its mode) cost 0.15 s a stage.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from omegaconf import DictConfig

# One BLAS thread per process: the pipeline runs one process per core, and compute times are single-threaded.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
# No OpenGL: the pipeline never renders with MuJoCo, and `import mujoco` loading GLFW cost every stage 50 ms.
os.environ.setdefault("MUJOCO_GL", "disable")


def main() -> None:
    from pipeline.core.checks import BadInput, preflight
    from pipeline.core.cli import register_help_resolver, runs_nothing, split_args

    # Hydra wants its flags before all overrides; accept them anywhere (a DVC stage appends -m).
    flags, overrides = split_args(sys.argv[1:])
    sys.argv[1:] = flags + overrides

    composed = None
    if not runs_nothing(flags):
        try:
            composed = preflight(overrides)
        except BadInput as err:
            print(f"error: {err}", file=sys.stderr)
            sys.exit(2)
    if _timed_sweep_on_this_machine(flags, overrides):  # its jobs one after another: no timing shares a core
        sys.argv.append("hydra.launcher.n_jobs=1")

    from hydra.core.hydra_config import HydraConfig
    from hydra.types import RunMode
    from omegaconf import open_dict

    from pipeline.core import interrupts
    from pipeline.core.runner import simulate

    register_help_resolver()
    stage_pid = os.getpid()

    def task(cfg: DictConfig) -> None:
        worker = os.getpid() != stage_pid
        if worker:  # a sweep worker must not outlive the stage that started it
            interrupts.die_with_parent()
        hc = HydraConfig.get()
        if hc.mode == RunMode.MULTIRUN:   # the sweep's own folder; its launcher draws the one progress bar
            with open_dict(cfg):          # and runs one job per core, so each job runs its cases itself
                sweep_dir = cfg.sweep_dir   # resolved before data_dir, which it names, changes
                cfg.data_dir, cfg.sweep_dir, cfg.progress, cfg.workers = sweep_dir, sweep_dir, False, 1
        try:
            errors = simulate(cfg, hc.runtime.choices["experiment"], list(hc.overrides.task))
        except BadInput as err:
            print(f"error: {err}", file=sys.stderr)
            raise SystemExit(2) from None
        except KeyboardInterrupt as err:
            if worker:  # the open run is already dropped; a worker pool would start the next job
                os._exit(interrupts.exit_code(err))
            raise
        if errors:
            raise SystemExit(1)

    from pipeline.core import stages

    interrupts.install()
    code: int | str | None = 0
    try:
        if composed is not None and not flags and not any(o.lstrip("+~").startswith("hydra") for o in overrides):
            _run_job(task, composed)   # one run of the config preflight composed: no need to compose it twice more
        else:
            _hydra_main(task)
    except KeyboardInterrupt as err:  # Ctrl-C or SIGTERM: the open run was dropped, finished ones stay
        print("interrupted: the run in progress was dropped; finished runs are kept", file=sys.stderr)
        code = interrupts.exit_code(err)
    except SystemExit as exit_:
        code = exit_.code
    if code == 0 and not runs_nothing(flags):
        stages.record(stages.argument(overrides, "data_dir", "data"), "simulate",
                      stages.argument(overrides, "experiment"), sweep="-m" in flags or "--multirun" in flags)
    sys.exit(code)


def _run_job(task: Callable[[DictConfig], None], cfg: DictConfig) -> None:
    """What `@hydra.main` does for a single run (Hydra.run) once the config is composed: Hydra's logging, its
    job runtime (HydraConfig, the run dir, env_set, callbacks) and its error report."""
    from hydra._internal.callbacks import Callbacks
    from hydra._internal.utils import run_and_report
    from hydra.core.utils import configure_log, run_job
    from hydra.types import HydraContext

    def run() -> None:
        configure_log(cfg.hydra.hydra_logging, cfg.hydra.verbose)
        callbacks = Callbacks(cfg)
        callbacks.on_run_start(config=cfg, config_name="config")
        ret = run_job(hydra_context=HydraContext(config_loader=None, callbacks=callbacks), task_function=task,
                      config=cfg, job_dir_key="hydra.run.dir", job_subdir_key=None)
        callbacks.on_run_end(config=cfg, config_name="config", job_return=ret)
        _ = ret.return_value   # raises what the task raised

    run_and_report(run)


def _hydra_main(task: Callable[[DictConfig], None]) -> None:
    """Hydra's own command line: sweeps and their launchers, --cfg, --help, --info."""
    import hydra
    from hydra.core.plugins import Plugins

    from hydra_plugins.robotics_repro.joblib_bar import JoblibBar
    from hydra_plugins.robotics_repro.submitit_chunks import SubmititChunks
    from pipeline.core.experiment import CONF_DIR

    # Hydra 1.3 cannot scan an editable install's hydra_plugins: our launchers are registered by hand
    for plugin in (JoblibBar, SubmititChunks):
        Plugins.instance().register(plugin)
    hydra.main(config_path=str(CONF_DIR), config_name="config", version_base=None)(task)()


def _timed_sweep_on_this_machine(flags: list[str], overrides: list[str]) -> bool:
    from pipeline.core import stages
    from pipeline.core.experiment import resolve

    experiment = stages.argument(overrides, "experiment")
    local = stages.argument(overrides, "hydra/launcher") in (None, "local", "joblib")
    return bool({"-m", "--multirun"} & set(flags)) and local and experiment is not None and resolve(experiment).timed


if __name__ == "__main__":
    main()

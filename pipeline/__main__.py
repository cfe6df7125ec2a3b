"""Simulate stage CLI.

    python -m pipeline experiment=<slug>/<name> [key=value ...]       one experiment, one MCAP per case
    python -m pipeline -m experiment=<slug>/<name> key=a,b,c           a sweep, run in parallel (joblib)
    python -m pipeline all                                             every configured experiment
"""

from __future__ import annotations

import sys


def _run_all() -> int:
    import subprocess

    from pipeline.core.experiment import available_experiments

    failed = []
    for experiment_id in available_experiments():
        print(f"== {experiment_id}", file=sys.stderr, flush=True)
        code = subprocess.call([sys.executable, "-m", "pipeline", f"experiment={experiment_id}", *sys.argv[2:]])
        if code:
            failed.append(experiment_id)
    if failed:
        print(f"error: experiments with errors: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


def main() -> None:
    if sys.argv[1:2] == ["all"]:
        sys.exit(_run_all())

    from pipeline.core.checks import BadInput, preflight

    try:
        preflight(sys.argv[1:])
    except BadInput as err:
        print(f"error: {err}", file=sys.stderr)
        sys.exit(2)

    import hydra
    from hydra.core.hydra_config import HydraConfig
    from omegaconf import DictConfig

    from pipeline.core.experiment import CONF_DIR
    from pipeline.core.runner import simulate

    @hydra.main(config_path=str(CONF_DIR), config_name="config", version_base=None)
    def task(cfg: DictConfig) -> None:
        hc = HydraConfig.get()
        errors = simulate(cfg, hc.runtime.choices["experiment"], list(hc.overrides.task))
        if errors:
            raise SystemExit(1)

    task()


if __name__ == "__main__":
    main()

"""Analyze and report stages CLI (a Hydra app: `--help` lists every experiment, `--cfg job` prints the config).

    python -m analysis                                   every experiment with runs on disk, then the report
    python -m analysis experiment=<slug>/<name>          one experiment's metrics and figures, then the report
    python -m analysis experiment=<slug>                 every experiment of one paper (a DVC analyze stage)
    python -m analysis stage=report                      only the report, from the metrics on disk
    python -m analysis data_dir=/elsewhere ...           where runs are read and outputs written (default data)

Bad input is refused in one line before Hydra starts (exit 2, nothing written).
"""

from __future__ import annotations

import difflib
import logging
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from omegaconf import DictConfig

KEYS = {"experiment": None, "data_dir": "data", "stage": "all", "workers": "0"}
STAGES = ("all", "analyze", "report")
CONF_DIR = Path(__file__).resolve().parent / "conf"
PLAIN = re.compile(r"[\w./~+@:-]*")   # a value Hydra's override grammar reads as this very string


def parse(overrides: list[str]) -> dict[str, str | None]:
    """Check the overrides: known keys, a known experiment, a known stage."""
    from pipeline.core.experiment import available_experiments

    args = dict(KEYS)
    for arg in overrides:
        key, eq, value = arg.partition("=")
        if not eq:
            raise ValueError(f"expected key=value, got '{arg}' (keys: {', '.join(KEYS)})")
        if key not in KEYS:
            hint = difflib.get_close_matches(key, KEYS, n=1)
            raise ValueError(f"unknown key '{key}'" + (f" (did you mean '{hint[0]}'?)" if hint else
                                                       f"; keys: {', '.join(KEYS)}"))
        args[key] = None if value == "null" else value
    if not (args["workers"] or "").isdigit() or int(args["workers"]) > 64:
        raise ValueError(f"workers={args['workers']} must be a whole number from 0 (one per core) to 64")
    if args["stage"] not in STAGES:
        raise ValueError(f"stage={args['stage']} must be one of {', '.join(STAGES)}")
    known = available_experiments()
    known += sorted({e.split("/")[0] for e in known})  # a paper: all its experiments
    if args["experiment"] is not None and args["experiment"] not in known:
        hint = difflib.get_close_matches(args["experiment"], known, n=1)
        raise ValueError(f"unknown experiment '{args['experiment']}'"
                         + (f" (did you mean '{hint[0]}'?)" if hint else f"; one of {', '.join(known)}"))
    from pipeline.core.checks import BadInput, check_data_dir

    try:
        data_dir = check_data_dir(args["data_dir"])
    except BadInput as err:
        raise ValueError(str(err)) from None
    if not data_dir.is_dir():
        raise ValueError(f"data_dir={args['data_dir']} does not exist: the simulate stage writes it "
                         f"(python -m pipeline experiment={args['experiment'] or '<slug>/<name>'} "
                         f"data_dir={args['data_dir']})")
    return args


def main() -> None:
    from pipeline.core.cli import runs_nothing, split_args

    flags, overrides = split_args(sys.argv[1:])
    sys.argv[1:] = flags + overrides
    args = None
    if not runs_nothing(flags):
        try:
            args = parse(overrides)
        except ValueError as err:
            print(f"error: {err}", file=sys.stderr)
            sys.exit(2)

    from pipeline.core import interrupts, stages

    def task(cfg: DictConfig | dict) -> None:
        from analysis.core.stages import run

        code = run(Path(cfg["data_dir"]), cfg["experiment"], cfg["stage"], int(cfg["workers"]))
        if code:
            raise SystemExit(code)

    interrupts.install()
    code: int | str | None = 0
    try:
        if args is not None and not flags and all(PLAIN.fullmatch(v or "") for v in args.values()):
            # the checked keys, read by Hydra's grammar as these very strings: no config to compose; the
            # logging Hydra would set up (hydra/job_logging=stdout, conf/analysis.yaml)
            logging.basicConfig(level=logging.INFO, stream=sys.stdout, format="%(message)s", force=True)
            task(args)
        else:
            _hydra_main(task)
    except KeyboardInterrupt as err:  # every output is published whole, so nothing half-written is left
        print("interrupted", file=sys.stderr)
        code = interrupts.exit_code(err)
    except SystemExit as exit_:
        code = exit_.code
    if code == 0 and not runs_nothing(flags):
        stages.record(stages.argument(overrides, "data_dir", "data"), stages.argument(overrides, "stage", "all"),
                      stages.argument(overrides, "experiment"))
    sys.exit(code)


def _hydra_main(task: Callable[[DictConfig], None]) -> None:
    """Hydra's own command line: --help, --cfg job, --info, and values in Hydra's override grammar."""
    import hydra

    from pipeline.core.cli import register_help_resolver

    register_help_resolver()
    hydra.main(config_path=str(CONF_DIR), config_name="analysis", version_base=None)(task)()


if __name__ == "__main__":
    main()

"""What the two Hydra CLIs (`python -m pipeline`, `python -m analysis`) share: telling Hydra's own flags from
the overrides, so that the one-line input checks see only overrides (`--cfg job`, `-p KEY` take a value after a
space, as Hydra documents), and the experiment list their `--help` prints."""

from __future__ import annotations

# Hydra flags followed by a value (`--info` by an optional one), and flags with which Hydra runs nothing.
VALUE_FLAGS = {"--cfg", "-c", "--package", "-p", "--config-path", "-cp", "--config-name", "-cn", "--config-dir",
               "-cd", "--experimental-rerun", "--shell-completion", "-sc"}
INFO_TOPICS = {"all", "config", "defaults", "defaults-tree", "plugins", "searchpath"}
NOTHING_RUNS = {"--help", "-h", "--hydra-help", "--cfg", "-c", "--info", "-i", "--shell-completion", "-sc",
                "--version"}


def split_args(argv: list[str]) -> tuple[list[str], list[str]]:
    """(Hydra flags with their values, overrides)."""
    flags, overrides = [], []
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg.startswith("-") and "=" in arg and arg.split("=", 1)[0] in VALUE_FLAGS:   # --cfg=job
            flags.append(arg)
        elif arg in VALUE_FLAGS and i + 1 < len(argv):
            flags += argv[i:i + 2]
            i += 1
        elif arg in ("--info", "-i") and i + 1 < len(argv) and argv[i + 1] in INFO_TOPICS:
            flags += argv[i:i + 2]
            i += 1
        elif arg.startswith("-"):
            flags.append(arg)
        else:
            overrides.append(arg)
        i += 1
    return flags, overrides


def runs_nothing(flags: list[str]) -> bool:
    """Help, config printing, info: Hydra shows something and runs no job."""
    return any(f.split("=", 1)[0] in NOTHING_RUNS for f in flags)


def register_help_resolver() -> None:
    """`${experiments:}` in a help template: every experiment with its one-line description."""
    from omegaconf import OmegaConf

    from pipeline.core.experiment import experiment_list

    if not OmegaConf.has_resolver("experiments"):
        OmegaConf.register_new_resolver("experiments", experiment_list)

"""What a paper's simulate stage provides, and how the pipeline finds it by slug.

A paper package `pipeline.papers.<slug with _>` exports

    EXPERIMENTS: dict[str, Callable[[DictConfig], list[Case]]]   # one entry per conf/experiment/<slug>/<name>.yaml
    LIMITS: dict[str, Range | OneOf]                             # physical ranges / allowed choices (optional)

An experiment turns its resolved config into cases; each case is one run, one MCAP file.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from omegaconf import DictConfig

if TYPE_CHECKING:  # the run-file machinery (pandas, MCAP) is not needed to find an experiment
    from pipeline.core.runlog import RunWriter

CONF_DIR = Path(__file__).resolve().parents[2] / "conf"


@dataclass(frozen=True)
class Case:
    """One run of an experiment: `simulate` writes its records into the open run file."""

    id: str
    simulate: Callable[[RunWriter], None]


ExperimentFn = Callable[[DictConfig], list[Case]]


@dataclass(frozen=True)
class Range:
    """An allowed interval for a parameter (each element, for a list)."""

    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None

    def __contains__(self, x: float) -> bool:
        return not ((self.gt is not None and not x > self.gt) or (self.ge is not None and not x >= self.ge)
                    or (self.lt is not None and not x < self.lt) or (self.le is not None and not x <= self.le))

    def __str__(self) -> str:
        parts = [f"{op} {v:g}" for op, v in ((">", self.gt), (">=", self.ge), ("<", self.lt), ("<=", self.le))
                 if v is not None]
        return " and ".join(parts)


@dataclass(frozen=True)
class OneOf:
    """The allowed values of a choice parameter (each element, for a list)."""

    values: tuple[str | int, ...]

    def __contains__(self, x: object) -> bool:
        return x in self.values

    def __str__(self) -> str:
        return "one of " + ", ".join(map(str, self.values))


POSITIVE = Range(gt=0)
NON_NEGATIVE = Range(ge=0)
PROBABILITY = Range(ge=0, le=1)
ANGLE = Range(ge=-2 * math.pi, le=2 * math.pi)

# Parameters named like this must be > 0 in every paper (the last key segment is matched).
POSITIVE_NAMES = ("dt", "duration", "mass", "masses", "inertia", "rate_hz", "repeats", "samples")


def module_name(slug: str) -> str:
    return slug.replace("-", "_")


def paper_module(slug: str) -> ModuleType:
    return importlib.import_module(f"pipeline.papers.{module_name(slug)}")


def available_experiments() -> list[str]:
    """Every `<slug>/<name>` that has a config file."""
    root = CONF_DIR / "experiment"
    return sorted(str(p.relative_to(root).with_suffix("")) for p in root.glob("*/*.yaml"))


def resolve(experiment_id: str) -> tuple[str, str, ExperimentFn, dict[str, Range | OneOf]]:
    """`<slug>/<name>` -> (slug, name, experiment function, parameter limits)."""
    slug, _, name = experiment_id.partition("/")
    module = paper_module(slug)
    try:
        fn = module.EXPERIMENTS[name]
    except KeyError:
        raise KeyError(f"pipeline.papers.{module_name(slug)} has no experiment '{name}'") from None
    return slug, name, fn, getattr(module, "LIMITS", {})

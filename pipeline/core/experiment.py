"""What a paper's simulate stage provides, and how the pipeline finds it by slug.

A paper package `pipeline.papers.<slug with _>` exports

    EXPERIMENTS: dict[str, Callable[[DictConfig], list[Case]]]   # one entry per conf/experiment/<slug>/<name>.yaml
    LIMITS: dict[str, Limit | tuple[Limit, ...]]   # per dotted key: ranges, choices, list lengths, free text
    RULES: list[Rule]                              # constraints between parameters (optional)
    BUDGETS: dict[str, Budget]                     # experiment name -> cost estimate and its limit (optional)
    TIMED: frozenset[str]                          # experiments whose compute times the paper's are compared with

An experiment turns its resolved config into cases; each case is one run, one MCAP file. The cases of an
experiment run in parallel, one process per core, unless it is TIMED: then they run one after another, alone
on the machine (DVC runs one stage at a time), so no other run shares a core with a measurement. Every run
records how many ran beside it (`parallel_runs`), for the compute times other experiments log in passing.

Everything declared here is checked before anything runs (pipeline.core.checks): the declarations sit beside
the experiments they guard, and tests/test_reliability.py checks that every choice, size, count, duration and
time step of every experiment is covered.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the run-file machinery (pandas, MCAP), and OmegaConf, are not needed to find an experiment
    from omegaconf import DictConfig

    from pipeline.core.runlog import RunWriter

CONF_DIR = Path(__file__).resolve().parents[2] / "conf"


@dataclass(frozen=True)
class Case:
    """One run of an experiment: `simulate` writes its records into the open run file. A case whose
    simulation `shares_work` with the experiment's other cases (all simulated together on the first one's
    turn) keeps them in one process."""

    id: str
    simulate: Callable[[RunWriter], None]
    shares_work: bool = False


ExperimentFn = Callable[["DictConfig"], list[Case]]


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


@dataclass(frozen=True)
class Length:
    """A list that may hold another number of elements than its default (which it must keep otherwise)."""

    min: int = 1
    max: int = 100

    def __contains__(self, n: int) -> bool:
        return self.min <= n <= self.max

    def __str__(self) -> str:
        return f"a list of {self.min} to {self.max} elements"


@dataclass(frozen=True)
class Text:
    """A free string (a label or a name) rather than a choice."""

    max_chars: int = 200


Limit = Range | OneOf | Length | Text


@dataclass(frozen=True)
class Rule:
    """A constraint between parameters, checked before anything runs.

    `holds` gets the values of `keys` in order; `message` says what must hold, formatted with those values
    as {0}, {1}, … A rule whose keys are not all in an experiment's config does not apply to it."""

    keys: tuple[str, ...]
    holds: Callable[..., bool]
    message: str


@dataclass(frozen=True)
class Budget:
    """A preflight cost estimate: a config whose work exceeds `limit` is refused (sizes multiply, so
    bounding each parameter alone does not bound a run)."""

    what: str                                  # the unit of work: "simulation steps", "IK calls", …
    estimate: Callable[[DictConfig], float]
    limit: float
    hint: str = ""                             # which keys to lower


@dataclass(frozen=True)
class Experiment:
    slug: str
    name: str
    fn: ExperimentFn
    limits: dict[str, Limit | tuple[Limit, ...]] = field(default_factory=dict)
    rules: tuple[Rule, ...] = ()
    budget: Budget | None = None
    timed: bool = False

    @property
    def id(self) -> str:
        return f"{self.slug}/{self.name}"


POSITIVE = Range(gt=0)
NON_NEGATIVE = Range(ge=0)
PROBABILITY = Range(ge=0, le=1)
ANGLE = Range(ge=-2 * math.pi, le=2 * math.pi)

# Bounds every paper shares, by the last segment of a key; a paper's LIMITS entry for the key replaces them.
NAMED_LIMITS: dict[str, Range] = {
    **dict.fromkeys(("dt", "mass", "masses", "inertia", "rate_hz"), POSITIVE),
    "duration": Range(gt=0, le=3600), "repeats": Range(ge=1, le=100_000), "samples": Range(ge=1, le=1_000_000),
    "log_dt": Range(ge=1e-4, le=10), "tf_dt": Range(ge=1e-4, le=10), "workers": Range(ge=0, le=64),
}
MAX_CASES = 1000  # runs one experiment may make in one process
# The root config's own keys (conf/config.yaml), declared for every experiment
ROOT_LIMITS: dict[str, Limit | tuple[Limit, ...]] = {
    "episodes.count": Range(ge=0, le=100_000),
    "episodes.randomize": Text(),   # distributions: checked episode by episode (pipeline.core.checks)
}


def module_name(slug: str) -> str:
    return slug.replace("-", "_")


def paper_module(slug: str) -> ModuleType:
    return importlib.import_module(f"pipeline.papers.{module_name(slug)}")


def available_experiments() -> list[str]:
    """Every `<slug>/<name>` that has a config file."""
    root = CONF_DIR / "experiment"
    return sorted(str(p.relative_to(root).with_suffix("")) for p in root.glob("*/*.yaml"))


def experiment_descriptions() -> dict[str, str]:
    """`<slug>/<name>` -> the one-line `description:` of its config file (what `--help` lists)."""
    import yaml

    root = CONF_DIR / "experiment"
    return {name: (yaml.safe_load((root / f"{name}.yaml").read_text()) or {}).get("description", "(no description)")
            for name in available_experiments()}


def experiment_list() -> str:
    """Every experiment with its description, one per line (for the CLIs' --help)."""
    described = experiment_descriptions()
    width = max(map(len, described), default=0)
    return "\n".join(f"  {name:<{width}}  {text}" for name, text in described.items())


def resolve(experiment_id: str) -> Experiment:
    """`<slug>/<name>` -> the experiment function and everything declared to check its config."""
    slug, _, name = experiment_id.partition("/")
    module = paper_module(slug)
    try:
        fn = module.EXPERIMENTS[name]
    except KeyError:
        raise KeyError(f"pipeline.papers.{module_name(slug)} has no experiment '{name}'") from None
    return Experiment(slug, name, fn, {**ROOT_LIMITS, **getattr(module, "LIMITS", {})},
                      tuple(getattr(module, "RULES", ())), getattr(module, "BUDGETS", {}).get(name),
                      name in getattr(module, "TIMED", ()))

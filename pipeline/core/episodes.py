"""N randomized episodes of an experiment in one process: parameters drawn per episode from distributions
declared in its config, one run file per episode, over the cores.

    episodes:
      count: 1000          # 0: the experiment's own cases; N > 0: N episodes
      workers: 0           # processes (0: one per core)
      randomize:           # the config's own layout; a distribution where a value was
        execute:
          bandwidth_hz: {uniform: [4, 16]}
        scenario:
          wrist:
            q_mid: {uniform: [-0.2, 0.2], add: true}     # each element: default + U(-0.2, 0.2)
          paths: {choice: [[wrist], [shoulder], [elbow]]}
        system:
          dynamics:
            masses: {normal: [1.0, 0.05], clip: [0.9, 1.1], scale: true}   # default × N(1, 0.05)

On the command line: `+episodes.randomize.execute.damping_ratio={uniform:[0.7,1.2]}` adds one,
`~episodes.randomize.scenario.paths` removes one (replace one by removing it and adding the new one).

Distributions: uniform [lo, hi], loguniform [lo, hi], integers [lo, hi] (inclusive), normal [mean, std] (with
clip [lo, hi]: a sample must stay in its range), choice [options]. A list-valued key draws each element (lo and
hi may be lists of its length); `add: true` adds the draw to the default, `scale: true` multiplies it.
Episode i draws from numpy's generator seeded with (`seed`, i): the same config makes the same episodes in any
order, on any number of workers, and one episode can be made again alone. Each episode must be one run of the
experiment (fix or randomize the lists that would make several). Its sampled values are in its run's metadata
(`values`, read back typed by `Run.params`), the distributions in `randomized`.

Before anything runs every episode's values are drawn and checked like any other config: ranges and choices
(the experiment's LIMITS), its RULES, and the experiment's BUDGET summed over the episodes.
"""

from __future__ import annotations

import copy
import json
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from omegaconf import DictConfig, ListConfig, OmegaConf

DISTRIBUTIONS = ("uniform", "loguniform", "integers", "normal", "choice")
MAX_EPISODES = 100_000


class BadDistribution(ValueError):
    """A distribution that cannot be drawn from; the message names the key."""


def _plain(value: Any) -> Any:
    return OmegaConf.to_container(value, resolve=True) if isinstance(value, DictConfig | ListConfig) else value


def _is_distribution(node: Any) -> bool:
    return not isinstance(node, Mapping) or any(k in node for k in (*DISTRIBUTIONS, "clip", "add", "scale"))


def randomized(cfg: DictConfig) -> dict[str, Any]:
    """Dotted config key -> its distribution (plain dicts), in key order."""
    found: dict[str, Any] = {}

    def walk(node: Any, prefix: str) -> None:
        if prefix and _is_distribution(node):
            found[prefix] = node
            return
        for key, child in node.items():
            walk(child, f"{prefix}.{key}" if prefix else str(key))

    walk(_plain(OmegaConf.select(cfg, "episodes.randomize", default=None)) or {}, "")
    return dict(sorted(found.items()))


def describe(dist: Mapping) -> str:
    """One line for the card: `uniform [4, 16]`, `default + uniform [-0.2, 0.2]`."""
    kind = next(k for k in DISTRIBUTIONS if k in dist)
    text = f"{kind} {json.dumps(dist[kind])}"
    if "clip" in dist:
        text += f" clipped to {json.dumps(dist['clip'])}"
    if dist.get("add"):
        text = f"default + {text}"
    elif dist.get("scale"):
        text = f"default × {text}"
    return text


def check_distribution(key: str, dist: Any, default: Any) -> None:
    if not isinstance(dist, Mapping):
        raise BadDistribution(f"episodes.randomize.{key} must be a distribution, e.g. {{uniform: [0, 1]}}")
    kinds = [k for k in DISTRIBUTIONS if k in dist]
    unknown = set(dist) - {*DISTRIBUTIONS, "clip", "add", "scale"}
    if len(kinds) != 1 or unknown:
        raise BadDistribution(f"episodes.randomize.{key} needs exactly one of {', '.join(DISTRIBUTIONS)} "
                              f"(and optionally clip, add, scale); got {sorted(dist)} (to replace one: "
                              f"~episodes.randomize.{key} +episodes.randomize.{key}=...)")
    kind = kinds[0]
    args = dist[kind]
    if kind == "choice":
        if not isinstance(args, list) or not args:
            raise BadDistribution(f"episodes.randomize.{key}.choice must be a non-empty list of values")
        return
    if not (isinstance(args, list) and len(args) == 2):
        raise BadDistribution(f"episodes.randomize.{key}.{kind} must be [a, b]")
    if kind == "normal" and "clip" not in dist:
        raise BadDistribution(f"episodes.randomize.{key}: a normal needs clip: [lo, hi] to keep every episode in "
                              "its allowed range")
    if (dist.get("add") or dist.get("scale")) and default is None:
        raise BadDistribution(f"episodes.randomize.{key}: add/scale need a default value")


def _draw(rng: np.random.Generator, dist: Mapping, default: Any) -> Any:
    kind = next(k for k in DISTRIBUTIONS if k in dist)
    args = dist[kind]
    if kind == "choice":
        return copy.deepcopy(args[int(rng.integers(len(args)))])
    shape = np.shape(default) if isinstance(default, list) else ()
    lo, hi = (np.broadcast_to(np.asarray(a, dtype=float), shape) for a in args)
    if kind == "uniform":
        x = rng.uniform(lo, hi)
    elif kind == "loguniform":
        x = np.exp(rng.uniform(np.log(lo), np.log(hi)))
    elif kind == "integers":
        x = rng.integers(lo.astype(int), hi.astype(int) + 1)
    else:  # normal
        x = rng.normal(lo, hi)
    if "clip" in dist:
        x = np.clip(x, *dist["clip"])
    if dist.get("add") or dist.get("scale"):
        base = np.array([np.nan if v is None else v for v in default], dtype=float) if shape else float(default)
        x = base + x if dist.get("add") else base * x
        if shape:  # a null element (solved for at run time) stays null
            return [None if d is None else float(v) for d, v in zip(default, np.atleast_1d(x), strict=True)]
    if kind == "integers":
        return x.tolist() if shape else int(x)
    return np.asarray(x, dtype=float).tolist() if shape else float(x)


def sampler(cfg: DictConfig) -> Callable[[int], dict[str, Any]]:
    """`draw(index)`: the values of episode `index`, key -> value (plain Python, typed like the defaults). The
    distributions and their defaults are read from the config once, not once per episode."""
    seed, distributions = int(cfg.seed), randomized(cfg)
    defaults = {key: _plain(OmegaConf.select(cfg, key, default=None)) for key in distributions}

    def draw(index: int) -> dict[str, Any]:
        rng = np.random.default_rng([seed, index])
        return {key: _draw(rng, dist, defaults[key]) for key, dist in distributions.items()}

    return draw


def apply(base: dict, values: Mapping[str, Any], seed: int) -> dict:
    """A copy of the plain config `base` with an episode's values and seed, and no episodes of its own."""
    episode = copy.deepcopy(base)
    set_values(episode, values)
    episode["episodes"]["count"] = 0
    episode["seed"] = seed
    return episode


def set_values(plain: dict, values: Mapping[str, Any]) -> None:
    """Write an episode's values into the plain config `plain`, in place."""
    for key, value in values.items():
        *parents, last = key.split(".")
        node = plain
        for part in parents:
            node = node[part]
        node[last] = value


def seed_of(cfg: DictConfig, index: int) -> int:
    """An episode's own seed (for a simulation's internal randomness), from the episodes' seed and its index."""
    return int(np.random.SeedSequence([int(cfg.seed), index]).generate_state(1)[0])

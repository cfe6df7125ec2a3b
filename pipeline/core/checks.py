"""Bad input is refused before anything runs, with one line that names the key and what is allowed.

`preflight(argv)` composes the config exactly as Hydra will (each swept value once), then checks it:
unknown experiment or key, a value whose type differs from its default, NaN/inf, and out-of-range physical
parameters (`POSITIVE_NAMES` everywhere, plus the paper's own `LIMITS`).
"""

from __future__ import annotations

import difflib
import importlib.util
import math
from collections.abc import Iterator
from typing import Any

from hydra import compose, initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from hydra.core.override_parser.overrides_parser import OverridesParser
from omegaconf import DictConfig, ListConfig

from pipeline.core.experiment import CONF_DIR, POSITIVE, POSITIVE_NAMES, OneOf, Range, available_experiments, resolve

NO_PREFLIGHT_FLAGS = {"--help", "-h", "--hydra-help", "--info", "-i", "--shell-completion", "-sc"}
SWEEP_LIMIT = 10_000


class BadInput(ValueError):
    """Refused input; the message is the one line shown to the user."""


def _leaves(node: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    if isinstance(node, DictConfig):
        for key in node:
            yield from _leaves(node._get_node(key), f"{prefix}{key}.")
    elif isinstance(node, ListConfig):
        for i in range(len(node)):
            yield from _leaves(node._get_node(i), f"{prefix[:-1]}[{i}].")
    else:
        yield prefix[:-1], node._value() if hasattr(node, "_value") else node


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def check_config(cfg: DictConfig, defaults: DictConfig, limits: dict[str, Range | OneOf]) -> None:
    """Raise BadInput for the first value that is not a finite number where a number belongs, has the
    wrong type, lies outside its range, or is not one of a choice's values."""
    default_values = dict(_leaves(defaults))
    for key, value in _leaves(cfg):
        if key.startswith("hydra."):
            continue
        choice = limits.get(key.split("[")[0])
        if isinstance(choice, OneOf) and value not in choice:
            raise BadInput(f"{key}={value!r} is not allowed: must be {choice}")
        default = default_values.get(key)
        if _is_number(default) and not _is_number(value):
            raise BadInput(f"{key}={value!r} must be a number (default {default})")
        if isinstance(default, bool) and not isinstance(value, bool):
            raise BadInput(f"{key}={value!r} must be true or false")
        if not _is_number(value):
            continue
        if not math.isfinite(value):
            raise BadInput(f"{key}={value} is not a finite number")
        base = key.split("[")[0]
        allowed = limits.get(base) or (POSITIVE if base.rsplit(".", 1)[-1] in POSITIVE_NAMES else None)
        if allowed is not None and value not in allowed:
            raise BadInput(f"{key}={value:g} is out of range: must be {allowed}")


def _variants(overrides: list[str]) -> list[tuple[str | None, list[str]]]:
    """(experiment, overrides) to compose and check. Every check is on one value at a time, so a sweep
    needs each swept value once (beside the fixed overrides), not every combination: 1 + Σk, not Πk."""
    parsed = OverridesParser.create().parse_overrides(overrides)
    fixed, swept = [], {}
    for o in parsed:
        if o.is_sweep_override():
            key = o.get_key_element()
            swept[key] = [f"{key}={v}" for v in o.sweep_string_iterator()]
        else:
            fixed.append(o.input_line)
    runs = 1
    for values in swept.values():
        runs *= len(values)
    if runs > SWEEP_LIMIT:
        raise BadInput(f"the sweep has {runs} runs, more than {SWEEP_LIMIT}; split it")
    chosen = [o.split("=", 1)[1] for o in fixed if o.startswith("experiment=")]
    experiments = [v.split("=", 1)[1] for v in swept.pop("experiment", [])] or chosen or [None]
    base = [o for o in fixed if not o.startswith("experiment=")]
    variants = []
    for experiment in experiments:
        variants.append((experiment, base))
        variants += [(experiment, [*base, value]) for values in swept.values() for value in values]
    return variants


def _one_line(err: Exception, overrides: list[str], valid_keys: list[str]) -> str:
    """Hydra's multi-line composition errors, cut to the line a user needs."""
    root: BaseException = err
    while root.__cause__ is not None:
        root = root.__cause__
    text = str(err)
    if "not in struct" in str(root) or "Could not override" in text or "Could not append" in text:
        key = text.split("'")[1] if "'" in text else str(root)
        hint = difflib.get_close_matches(key, valid_keys, n=1)
        return f"unknown config key '{key}'" + (f" (did you mean '{hint[0]}'?)" if hint else "")
    if "Could not find" in text or "Could not load" in text:
        return text.splitlines()[0]
    return f"{text.splitlines()[0]} ({' '.join(overrides)})"


def compose_config(overrides: list[str]) -> DictConfig:
    """The config Hydra would build for these overrides (no sweep syntax)."""
    GlobalHydra.instance().clear()
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base=None):
        return compose(config_name="config", overrides=overrides)


def preflight(argv: list[str]) -> None:
    """Refuse bad input before Hydra launches anything."""
    if NO_PREFLIGHT_FLAGS.intersection(argv):
        return
    overrides = [a for a in argv if not a.startswith("-")]
    try:
        variants = _variants(overrides)
    except BadInput:
        raise
    except Exception as err:  # the override syntax itself
        raise BadInput(f"cannot parse the overrides: {str(err).splitlines()[0]}") from None

    known = available_experiments()
    checked_defaults: dict[str, tuple[DictConfig, list[str], dict]] = {}
    for experiment, extra in variants:
        if experiment is None:
            raise BadInput("choose an experiment: experiment=<slug>/<name>, one of " + ", ".join(known))
        if experiment not in known:
            hint = difflib.get_close_matches(experiment, known, n=1)
            raise BadInput(f"unknown experiment '{experiment}'"
                           + (f" (did you mean '{hint[0]}'?)" if hint else f"; one of {', '.join(known)}"))
        if any(o.replace(" ", "") == "hydra/launcher=ray" for o in extra) and \
                importlib.util.find_spec("hydra_plugins.hydra_ray_launcher") is None:
            raise BadInput("hydra/launcher=ray needs the Ray launcher: pip install -e '.[ray]'")
        for o in extra:
            if o.startswith("+") and not o.startswith("+hydra"):
                raise BadInput(f"adding keys is not allowed ('{o}'): every parameter has a default in conf/")
        if experiment not in checked_defaults:
            defaults = compose_config([f"experiment={experiment}"])
            checked_defaults[experiment] = (defaults, [k for k, _ in _leaves(defaults)], resolve(experiment)[3])
        defaults, valid_keys, limits = checked_defaults[experiment]
        job_overrides = [f"experiment={experiment}", *(o for o in extra if not o.lstrip("+~").startswith("hydra"))]
        try:
            cfg = compose_config(job_overrides)
        except Exception as err:
            raise BadInput(_one_line(err, job_overrides, valid_keys)) from None
        check_config(cfg, defaults, limits)
    GlobalHydra.instance().clear()

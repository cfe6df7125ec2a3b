"""Bad input is refused before anything runs, with one line that names the key and what is allowed.

`preflight(argv)` composes the config exactly as Hydra will (every combination of a sweep), then checks
it: unknown experiment or key, a value whose type differs from its default, NaN/inf, and out-of-range
physical parameters (`POSITIVE_NAMES` everywhere, plus the paper's own `LIMITS`).
"""

from __future__ import annotations

import difflib
import importlib.util
import itertools
import math
from collections.abc import Iterator
from typing import Any

from hydra import compose, initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from hydra.core.override_parser.overrides_parser import OverridesParser
from omegaconf import DictConfig, ListConfig, OmegaConf

from pipeline.core.experiment import CONF_DIR, POSITIVE, POSITIVE_NAMES, Range, available_experiments, resolve

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


def check_config(cfg: DictConfig, defaults: DictConfig, limits: dict[str, Range]) -> None:
    """Raise BadInput for the first value that is not a finite number where a number belongs, has the
    wrong type, or lies outside its range."""
    default_values = dict(_leaves(defaults))
    for key, value in _leaves(cfg):
        if key.startswith("hydra."):
            continue
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


def _expand(overrides: list[str]) -> list[list[str]]:
    """Every combination of a sweep, as plain override lists."""
    parsed = OverridesParser.create().parse_overrides(overrides)
    choices = []
    for o in parsed:
        if o.is_sweep_override():
            key = o.get_key_element()
            choices.append([f"{key}={v}" for v in o.sweep_string_iterator()])
        else:
            choices.append([o.input_line])
    combos = [list(c) for c in itertools.islice(itertools.product(*choices), SWEEP_LIMIT + 1)]
    if len(combos) > SWEEP_LIMIT:
        raise BadInput(f"the sweep has more than {SWEEP_LIMIT} runs; split it")
    return combos


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
        combos = _expand(overrides)
    except BadInput:
        raise
    except Exception as err:  # a parse error of the override syntax
        raise BadInput(f"cannot parse the overrides: {str(err).splitlines()[0]}") from None

    known = available_experiments()
    reference: dict[str, tuple[DictConfig, list[str], dict[str, Range]]] = {}  # per experiment, not per run
    for combo in combos:
        experiment = next((o.split("=", 1)[1] for o in combo if o.startswith("experiment=")), None)
        if experiment is None:
            raise BadInput("choose an experiment: experiment=<slug>/<name>, one of " + ", ".join(known))
        if experiment not in known:
            hint = difflib.get_close_matches(experiment, known, n=1)
            raise BadInput(f"unknown experiment '{experiment}'"
                           + (f" (did you mean '{hint[0]}'?)" if hint else f"; one of {', '.join(known)}"))
        if any(o.replace(" ", "") in ("hydra/launcher=ray",) for o in combo) and \
                importlib.util.find_spec("hydra_plugins.hydra_ray_launcher") is None:
            raise BadInput("hydra/launcher=ray needs the Ray launcher: pip install -e '.[ray]'")
        for o in combo:
            if o.startswith("+") and not o.startswith("+hydra"):
                raise BadInput(f"adding keys is not allowed ('{o}'): every parameter has a default in conf/")

        if experiment not in reference:
            defaults = compose_config([f"experiment={experiment}"])
            reference[experiment] = (defaults, [k for k, _ in _leaves(defaults)], resolve(experiment)[3])
        defaults, valid_keys, limits = reference[experiment]
        job_overrides = [o for o in combo if not o.lstrip("+~").startswith("hydra")]
        try:
            cfg = compose_config(job_overrides)
        except Exception as err:
            raise BadInput(_one_line(err, job_overrides, valid_keys)) from None
        check_config(cfg, defaults, limits)
    GlobalHydra.instance().clear()


def selected_experiment(cfg: DictConfig) -> str:
    """`<slug>/<name>` of a composed config (from Hydra's record of the group choice)."""
    from hydra.core.hydra_config import HydraConfig

    return HydraConfig.get().runtime.choices["experiment"]


def to_yaml(cfg: DictConfig) -> str:
    return OmegaConf.to_yaml(cfg, resolve=True)

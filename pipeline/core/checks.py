"""Bad input is refused before anything runs, with one line that names the key and what is allowed.

`preflight(argv)` composes the config exactly as Hydra will (each swept value once), then checks it against
what the experiment declares (pipeline.core.experiment): the shape of every value (a list stays a list of the
default's length unless its LIMITS entry is a `Length`; a single value stays single), its type, NaN/inf, its
range or choices (the paper's LIMITS, then NAMED_LIMITS), the RULES between parameters, the experiment's
cost BUDGET, the cases it makes (at least one, at most MAX_CASES, names that are safe file names), and the
data_dir every output goes under.
"""

from __future__ import annotations

import copy
import difflib
import importlib.util
import math
import os
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, ListConfig, OmegaConf, open_dict

from pipeline.core.experiment import (
    CONF_DIR,
    MAX_CASES,
    NAMED_LIMITS,
    Case,
    Experiment,
    Length,
    Limit,
    OneOf,
    Range,
    Text,
    available_experiments,
    resolve,
)

NO_PREFLIGHT_FLAGS = {"--help", "-h", "--hydra-help", "--info", "-i", "--shell-completion", "-sc"}
SWEEP_LIMIT = 10_000
# launchers that need an optional extra: the plugin module it installs, and the extra's name
LAUNCHER_EXTRAS = {"ray": ("hydra_plugins.hydra_ray_launcher", "ray"),
                   "slurm": ("hydra_plugins.hydra_submitit_launcher", "slurm"),
                   "slurm_local": ("hydra_plugins.hydra_submitit_launcher", "slurm")}
SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._=,+-]{0,199}")


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


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def declared(limits: dict[str, Limit | tuple[Limit, ...]], key: str) -> tuple[Limit, ...]:
    """The limits declared for a key (a list's elements share their list's entry; `Text` on a key covers
    everything under it: a table of the paper's data)."""
    plain = re.sub(r"\[\d+\]", "", key)
    found = limits.get(plain)
    if found is None:
        parts = plain.split(".")
        if any(isinstance(limits.get(".".join(parts[:i])), Text) for i in range(1, len(parts))):
            return (Text(),)
        named = NAMED_LIMITS.get(parts[-1])
        return (named,) if named else ()
    return found if isinstance(found, tuple) else (found,)


def _of(kind: type, limits: tuple[Limit, ...]) -> Any:
    return next((x for x in limits if isinstance(x, kind)), None)


def _check_shape(value: Any, default: Any, key: str, limits: dict) -> None:
    """A list stays a list (of its default's length, unless declared `Length`), a single value single."""
    if key == "episodes.randomize":
        return   # distributions, each checked against the key it draws (check_episodes)
    if isinstance(default, DictConfig):
        for k in default:
            if k in value and not (not key and k == "hydra"):
                _check_shape(value._get_node(k), default._get_node(k), f"{key}.{k}" if key else str(k), limits)
        return
    if isinstance(default, ListConfig):
        if not isinstance(value, ListConfig):
            shown = OmegaConf.to_object(value) if isinstance(value, DictConfig) else value._value()
            raise BadInput(f"{key}={_short(shown)} must be a list, e.g. {key}=[{shown}] "
                           f"(default {_short(OmegaConf.to_object(default))})")
        length = _of(Length, declared(limits, key))
        if length is not None and len(value) not in length:
            raise BadInput(f"{key} has {len(value)} elements: must be {length}")
        if length is None and len(value) != len(default):
            raise BadInput(f"{key} has {len(value)} elements: must have {len(default)}, like its default "
                           f"{_short(OmegaConf.to_object(default))}")
        if len(default):
            for i in range(len(value)):
                _check_shape(value._get_node(i), default._get_node(min(i, len(default) - 1)), f"{key}[{i}]", limits)
        return
    if isinstance(value, ListConfig | DictConfig):
        raise BadInput(f"{key}={_short(OmegaConf.to_object(value))} must be a single value like "
                       f"{_short(default._value())}")
    if _of(Text, declared(limits, key)) is None:  # free text may stand where a number is (`pi/2`)
        _check_type(value._value(), default._value(), key)


def _check_type(value: Any, default: Any, key: str) -> None:
    if default is None:
        return
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise BadInput(f"{key}={_short(value)} must be true or false")
    elif _is_number(default):
        if not _is_number(value):
            raise BadInput(f"{key}={_short(value)} must be a number (default {default})")
    elif isinstance(default, str) and not isinstance(value, str):
        raise BadInput(f"{key}={_short(value)} must be a string like {default!r}")


def check_config(cfg: DictConfig, defaults: DictConfig, limits: dict[str, Limit | tuple[Limit, ...]]) -> None:
    """Raise BadInput for the first value whose shape or type differs from its default's, that is not a
    finite number where a number belongs, lies outside its range, or is not one of its choices."""
    _check_shape(cfg, defaults, "", limits)
    for key, value in _leaves(cfg):
        if key.startswith("hydra.") or key in ("data_dir",):
            continue
        allowed = declared(limits, key)
        choice, text, interval = _of(OneOf, allowed), _of(Text, allowed), _of(Range, allowed)
        if choice is not None and value not in choice:
            hint = difflib.get_close_matches(str(value), [str(v) for v in choice.values], n=1)
            raise BadInput(f"{key}={_short(value)} is not allowed: must be {choice}"
                           + (f" (did you mean '{hint[0]}'?)" if hint else ""))
        if text is not None and isinstance(value, str) and len(value) > text.max_chars:
            raise BadInput(f"{key} is {len(value)} characters long: at most {text.max_chars}")
        if not _is_number(value):
            continue
        if not math.isfinite(value):
            raise BadInput(f"{key}={value} is not a finite number")
        if interval is not None and value not in interval:
            raise BadInput(f"{key}={value:g} is out of range: must be {interval}")


def _select(cfg: DictConfig, key: str) -> Any:
    value = OmegaConf.select(cfg, key, throw_on_missing=False)
    return OmegaConf.to_object(value) if isinstance(value, DictConfig | ListConfig) else value


def check_rules(cfg: DictConfig, experiment: Experiment) -> None:
    """The constraints between parameters, then the cost estimate."""
    for rule in experiment.rules:
        values = [_select(cfg, k) for k in rule.keys]
        if any(v is None for v in values):
            continue
        if not rule.holds(*values):
            raise BadInput(rule.message.format(*values))
    budget = experiment.budget
    if budget is not None:
        cost = budget.estimate(cfg)
        if not cost <= budget.limit:
            raise BadInput(f"{experiment.id} would need about {cost:.3g} {budget.what}, more than the budget of "
                           f"{budget.limit:.3g}" + (f": {budget.hint}" if budget.hint else ""))


def check_cases(cfg: DictConfig, experiment: Experiment) -> list[Case]:
    """The experiment's cases for this config: at least one, at most MAX_CASES, unique safe names."""
    try:
        cases = experiment.fn(cfg)
    except (ValueError, KeyError, TypeError, IndexError) as err:
        raise BadInput(f"{experiment.id}: {str(err).splitlines()[0] if str(err) else type(err).__name__}") from None
    if not cases:
        raise BadInput(f"{experiment.id} makes no run with this config: check the lists in `scenario`")
    if len(cases) > MAX_CASES:
        raise BadInput(f"{experiment.id} would make {len(cases)} runs in one process, more than {MAX_CASES}: "
                       "split it with a sweep (-m)")
    ids = [case.id for case in cases]
    for case_id in ids:
        if not SAFE_NAME.fullmatch(case_id):
            raise BadInput(f"{experiment.id}: run name {_short(case_id)} is not a safe file name "
                           "(letters, digits and ._=,+- only, 200 at most)")
    dupes = sorted({i for i in ids if ids.count(i) > 1})
    if dupes:
        raise BadInput(f"{experiment.id}: the config names two runs {dupes[0]!r}: list each case once")
    return cases


def check_episodes(cfg: DictConfig, experiment: Experiment) -> None:
    """Randomized episodes: every distribution well formed and on a real key; every episode's drawn values in
    their ranges and choices, its rules holding, and one run each; the budget summed over the episodes."""
    from pipeline.core import episodes

    count = int(OmegaConf.select(cfg, "episodes.count", default=0) or 0)
    specs = episodes.randomized(cfg)
    if not count:
        return
    known = [k for k, _ in _leaves(cfg) if not k.startswith(("hydra", "episodes"))]
    for key, dist in specs.items():
        plain = re.sub(r"\[\d+\]", "", key)
        if key not in known and not any(k.startswith(plain + "[") for k in known):
            hint = difflib.get_close_matches(key, known, n=1)
            raise BadInput(f"episodes.randomize.{key}: no such config key" + (f" (did you mean '{hint[0]}'?)"
                                                                             if hint else ""))
        try:
            episodes.check_distribution(key, dist, _select(cfg, key))
        except episodes.BadDistribution as err:
            raise BadInput(str(err)) from None
    # Every episode sets the same keys: one plain config takes each episode's values in turn. How many runs an
    # episode makes depends on its lists and counts, not on its real numbers: the experiment makes its runs (on
    # one DictConfig, set likewise) for each of the first 16 distinct draws of its choices and integers.
    work = episodes.apply(OmegaConf.to_container(cfg, resolve=True), {}, 0)
    defaults = {key: _select(cfg, key) for key in specs}
    draw = episodes.sampler(cfg)
    discrete = [key for key, dist in specs.items() if "choice" in dist or "integers" in dist]
    counted: set[str] = set()
    episode_cfg: DictConfig | None = None
    total = 0.0
    budget = experiment.budget
    for index in range(count):   # plain dicts: about 0.2 ms an episode, 100,000 in 20 s
        values = draw(index)
        episodes.set_values(work, values)
        for key, value in values.items():
            try:
                _check_values(key, value, defaults[key], experiment)
            except BadInput as err:
                raise BadInput(f"episode {index}: {err}") from None
        for rule in experiment.rules:
            found = [_lookup(work, k) for k in rule.keys]
            if all(v is not None for v in found) and not rule.holds(*found):
                raise BadInput(f"episode {index}: {rule.message.format(*found)}")
        signature = repr([values[key] for key in discrete])
        if signature not in counted and len(counted) < 16:
            counted.add(signature)
            if episode_cfg is None:
                episode_cfg = OmegaConf.create(work)
            for key, value in values.items():
                OmegaConf.update(episode_cfg, key, value, merge=False)
            made = experiment.fn(episode_cfg)
            if len(made) != 1:
                raise BadInput(f"{experiment.id}: episode {index} would make {len(made)} runs ("
                               f"{', '.join(c.id for c in made[:3])}, ...): an episode is one run; fix or "
                               "randomize the lists that multiply it")
        total += budget.estimate(_Attributes(work)) if budget is not None else 0.0
        if budget is not None and not total <= budget.limit:   # said as soon as it is known
            total *= count / (index + 1)
            raise BadInput(f"{experiment.id}: {count} episodes would need about {total:.3g} {budget.what}, more "
                           f"than the budget of {budget.limit:.3g}: fewer episodes"
                           + (f", {budget.hint}" if budget.hint else ""))


class _Attributes(dict):
    """A plain config read like a DictConfig (`c.scenario.duration`), for cost estimates."""

    def __getattr__(self, name: str) -> Any:
        try:
            value = self[name]
        except KeyError:
            raise AttributeError(name) from None
        return _Attributes(value) if isinstance(value, dict) else value


def _lookup(plain: dict, key: str) -> Any:
    node: Any = plain
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _check_values(key: str, value: Any, default: Any, experiment: Experiment) -> None:
    """One drawn value against its key's declared shape, range and choices."""
    allowed = declared(experiment.limits, key)
    elements = value if isinstance(value, list) else [value]
    if isinstance(default, list) != isinstance(value, list):
        raise BadInput(f"{key}={_short(value)} must be {'a list' if isinstance(default, list) else 'one value'} "
                       f"like its default {_short(default)}")
    length = _of(Length, allowed)
    if isinstance(value, list) and (len(value) not in length if length else len(value) != len(default)):
        raise BadInput(f"{key} has {len(value)} elements: must be {length or len(default)}")
    choice, interval = _of(OneOf, allowed), _of(Range, allowed)
    for x in elements:
        if choice is not None and x not in choice:
            raise BadInput(f"{key}={_short(x)} is not allowed: must be {choice}")
        if _is_number(x) and (not math.isfinite(x) or (interval is not None and x not in interval)):
            raise BadInput(f"{key}={x:g} is out of range: must be {interval}")


def check_data_dir(value: Any) -> Path:
    """Where every output goes: a directory this process can create or write."""
    if value is None or not str(value).strip():
        raise BadInput("data_dir is empty: give a directory, e.g. data_dir=data")
    path = Path(str(value)).expanduser()
    if path.exists() and not path.is_dir():
        raise BadInput(f"data_dir={value} is a file, not a directory")
    existing = next(p for p in (path.absolute(), *path.absolute().parents) if p.exists())
    try:  # a real probe: permission bits say nothing to root, or on /proc and read-only mounts
        os.rmdir(tempfile.mkdtemp(dir=existing, prefix=".probe-"))
    except OSError:
        raise BadInput(f"data_dir={value} cannot be written ({existing} is not a writable directory)") from None
    return path


def _variants(overrides: list[str]) -> tuple[list[tuple[str | None, list[str]]], bool]:
    """(experiment, overrides) to compose and check, and whether anything is swept. Every check is on one value
    at a time, so a sweep needs each swept value once (beside the fixed overrides), not every combination:
    1 + Σk, not Πk."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

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
    sweep = bool(swept)
    chosen = [o.split("=", 1)[1] for o in fixed if o.startswith("experiment=")]
    experiments = [v.split("=", 1)[1] for v in swept.pop("experiment", [])] or chosen or [None]
    base = [o for o in fixed if not o.startswith("experiment=")]
    variants = []
    for experiment in experiments:
        variants.append((experiment, base))
        variants += [(experiment, [*base, value]) for values in swept.values() for value in values]
    return variants, sweep or len(experiments) > 1


def _one_line(err: Exception, overrides: list[str], valid_keys: list[str]) -> str:
    """Hydra's multi-line composition errors, cut to the line a user needs."""
    root: BaseException = err
    while root.__cause__ is not None:
        root = root.__cause__
    text = str(err)
    if "not in struct" in str(root) or "Could not override" in text or "Could not append" in text:
        key = text.split("'")[1] if "'" in text else str(root)
        if key.startswith("episodes.randomize."):   # struct mode: a distribution is replaced, not merged
            return (f"{key}: to replace a distribution, remove it and add the new one: ~{key} "
                    f"'+{key}={{uniform:[a,b]}}'")
        hint = difflib.get_close_matches(key, valid_keys, n=1)
        return f"unknown config key '{key}'" + (f" (did you mean '{hint[0]}'?)" if hint else "")
    if "Could not find" in text or "Could not load" in text:
        return text.splitlines()[0]
    return f"{text.splitlines()[0]} ({' '.join(overrides)})"[:280]


def _listing(known: list[str]) -> str:
    return f"{len(known)} exist, e.g. {', '.join(known[:2])} (all: ls conf/experiment/*)"


def compose_config(overrides: list[str], with_hydra: bool = False) -> DictConfig:
    """The config Hydra would build for these overrides (no sweep syntax); `with_hydra`: with its `hydra` node,
    as Hydra hands it to a job (pipeline/__main__.py runs a single run on it without composing it again)."""
    from hydra import compose, initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    GlobalHydra.instance().clear()   # job name: the one @hydra.main gives `python -m pipeline`
    with initialize_config_dir(config_dir=str(CONF_DIR), job_name="__main__", version_base=None):
        return compose(config_name="config", overrides=overrides, return_hydra_config=with_hydra)


def _without_hydra(cfg: DictConfig) -> DictConfig:
    """The job's config, as Hydra's run_job makes it: a copy without the `hydra` node."""
    job = copy.deepcopy(cfg)
    with open_dict(job):
        del job["hydra"]
    return job


def compose_with_defaults(overrides: list[str]) -> tuple[DictConfig, DictConfig | None]:
    """The config Hydra composes for `overrides` (with its `hydra` node), and the experiment's defaults: the
    same composition just before Hydra applies the overrides' values, when every override but `experiment=` is
    a value (none chooses a config group; else None). One composition where the checks would need two."""
    from hydra._internal.config_loader_impl import ConfigLoaderImpl

    apply = ConfigLoaderImpl._apply_overrides_to_config
    before: list[tuple[int, DictConfig]] = []

    def recording(values: list, cfg: DictConfig) -> None:
        before.append((len(values), _without_hydra(cfg)))
        apply(values, cfg)

    ConfigLoaderImpl._apply_overrides_to_config = staticmethod(recording)
    try:
        composed = compose_config(overrides, with_hydra=True)
    finally:
        ConfigLoaderImpl._apply_overrides_to_config = staticmethod(apply)
    values_only = len(before) == 1 and before[0][0] == len(overrides) - 1
    return composed, before[0][1] if values_only else None


def preflight(argv: list[str]) -> DictConfig | None:
    """Refuse bad input before Hydra launches anything. Returns the checked config, with its `hydra` node, when
    `argv` makes one job (no sweep), so that it need not be composed again."""
    if NO_PREFLIGHT_FLAGS.intersection(argv):
        return None
    overrides = [a for a in argv if not a.startswith("-")]
    try:
        variants, sweep = _variants(overrides)
    except BadInput:
        raise
    except Exception as err:  # the override syntax itself
        raise BadInput(f"cannot parse the overrides: {str(err).splitlines()[0]}") from None

    known = available_experiments()
    checked: dict[str, tuple[DictConfig, Experiment]] = {}
    for experiment_id, extra in variants:
        if experiment_id is None:
            raise BadInput(f"choose an experiment: experiment=<slug>/<name>; {_listing(known)}")
        if experiment_id not in known:
            hint = difflib.get_close_matches(experiment_id, known, n=1)
            raise BadInput(f"unknown experiment '{experiment_id}'"
                           + (f" (did you mean '{hint[0]}'?)" if hint else f"; {_listing(known)}"))
        for launcher, (plugin, extra_name) in LAUNCHER_EXTRAS.items():
            if any(o.replace(" ", "") == f"hydra/launcher={launcher}" for o in extra) and \
                    importlib.util.find_spec(plugin) is None:
                raise BadInput(f"hydra/launcher={launcher} needs its extra: pip install -e '.[{extra_name}]'")
        for o in extra:
            if o.startswith("+") and not o.startswith(("+hydra", "+episodes.randomize.")):
                raise BadInput(f"adding keys is not allowed ('{o}'): every parameter has a default in conf/ "
                               "(only distributions are added: +episodes.randomize.<key>={uniform:[a,b]})")
        job_overrides = [f"experiment={experiment_id}", *(o for o in extra if not o.lstrip("+~").startswith("hydra"))]
        if not sweep:   # in the order given: Hydra records them (hydra.overrides.task)
            job_overrides = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
        try:   # one job: composed as @hydra.main composes a single run (it adds hydra.mode=RUN)
            composed, defaults = compose_with_defaults(job_overrides + ([] if sweep else ["hydra.mode=RUN"]))
        except Exception as err:
            defaults = compose_config([f"experiment={experiment_id}"])
            raise BadInput(_one_line(err, job_overrides, [k for k, _ in _leaves(defaults)])) from None
        cfg = _without_hydra(composed)
        if experiment_id not in checked:
            checked[experiment_id] = (defaults or compose_config([f"experiment={experiment_id}"]),
                                      resolve(experiment_id))
        defaults, experiment = checked[experiment_id]
        check_data_dir(cfg.data_dir)
        check_config(cfg, defaults, experiment.limits)
        check_rules(cfg, experiment)
        check_cases(cfg, experiment)
        check_episodes(cfg, experiment)
    return None if sweep else composed   # (each composition leaves Hydra uninitialised, as it found it)

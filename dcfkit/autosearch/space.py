"""Search specs: a base config, the space of changes to it, the folds, the budget and the
trackers to beat (docs/search.md). Every choice is resolved against the base when the spec
is read, so a wrong key or value fails before anything runs."""
from __future__ import annotations

import collections
import dataclasses
import itertools
import math
import os
from pathlib import Path
from typing import Any, Mapping

from optuna.distributions import BaseDistribution, CategoricalDistribution, FloatDistribution, IntDistribution

from dcfkit.ablation.experiment import check_experiment
from dcfkit.ablation.spec import load_spec_config
from dcfkit.ablation.spec_keys import as_mapping, check_keys, parse_datasets, pooled_sequences
from dcfkit.autosearch.halving import Halving, parse_halving
from dcfkit.config import load_config, shipped_config_dir
from dcfkit.config.bounded_yaml import read_yaml
from dcfkit.datasets import load_dataset
from dcfkit.datasets.base import sequence_names
from dcfkit.errors import ConfigError, DcfkitError, clip, shown
from dcfkit.params import coerce

SPEC_KEYS = ("name", "description", "dataset", "sequences", "base", "space", "experiments", "folds",
             "trials", "startup_trials", "seed", "baselines", "warm_start", "halving", "final_study")
FINAL_STUDY = ("always", "if_it_wins")  # run the final study always, or only if the folds beat every baseline
KINDS = ("choice", "float", "int")
PARAMETER_KEYS = (*KINDS, "log", "when")
# configs resolved per group of related dimensions when a spec is read (some 4 ms each)
MAX_STRUCTURES = 1024


@dataclasses.dataclass(frozen=True)
class Parameter:
    """One dimension of the space: a dotted config key, its Optuna distribution, the value
    each choice label stands for (``choices``; empty for numbers), and ``when``: the
    (key, label) pairs that must hold for it to be sampled (a component's own parameter)."""

    key: str
    distribution: BaseDistribution
    choices: dict = dataclasses.field(default_factory=dict)
    when: tuple = ()

    def suggest(self, trial) -> Any:
        """The value an Optuna ``trial`` samples for this parameter."""
        d = self.distribution
        if isinstance(d, CategoricalDistribution):
            return trial.suggest_categorical(self.key, d.choices)
        if isinstance(d, IntDistribution):
            return trial.suggest_int(self.key, d.low, d.high, log=d.log)
        return trial.suggest_float(self.key, d.low, d.high, log=d.log)

    def value(self, sampled: Any) -> Any:
        """The config value for a sampled value (a choice's label stands for its value)."""
        return self.choices[sampled] if self.choices else sampled


@dataclasses.dataclass(frozen=True)
class SearchSpec:
    """A parsed search spec (docs/search.md)."""

    path: Path
    name: str
    description: str
    dataset: str
    root: Path | None
    root_origin: str
    sequences: tuple | None
    base: dict
    base_source: str
    parameters: tuple
    experiments: tuple
    folds: int
    trials: int
    startup_trials: int
    seed: int
    baselines: dict  # name -> resolved config
    pool: tuple = ()  # pooled datasets: (name, root, origin) of each, ``dataset`` their names joined by "+"
    max_frames: int | None = None  # a quick try (--max-frames): each sequence's first frames only
    warm_start: bool = True  # trial 0 of every study is the base config
    halving: Halving | None = None  # multi-fidelity: successive halving on the sequence count
    final_study: str = "always"  # FINAL_STUDY: "if_it_wins" skips it when the held-out folds lose

    def load_sequences(self) -> list:
        """The spec's sequences (of every pooled dataset), each cut to ``max_frames`` if given."""
        if self.pool:
            found = pooled_sequences(self)
        elif self.root is None:
            raise ConfigError(f"{self.path}: no dataset root: give dataset.root in the spec or --root")
        else:
            found = load_dataset(self.dataset, self.root, None if self.sequences is None else list(self.sequences))
        return [s.head(self.max_frames) for s in found]

    def config(self, params: Mapping[str, Any]) -> dict:
        """The base config with the sampled ``params`` (key -> sampled value) applied."""
        return resolve(self.base, self.parameters, params)


def find_search_spec(source: str | os.PathLike) -> Path:
    """A spec file, or a shipped one by name (``configs/searches/<name>.yaml``)."""
    path = Path(source)
    if os.path.isfile(path):
        return path.resolve()
    folder = shipped_config_dir() / "searches"
    for candidate in (folder / path, folder / f"{path}.yaml"):
        if os.path.isfile(candidate):
            return candidate.resolve()
    shipped = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
    raise ConfigError(f"search spec not found: {clip(str(source))}"
                      + (f"; shipped: {', '.join(shipped)}" if shipped else ""))


def load_search_spec(source: str | os.PathLike, root=None) -> SearchSpec:
    """Read and validate a search spec; ``root`` (a folder, or a list of them to pool) replaces
    its dataset roots (:func:`~dcfkit.ablation.spec_keys.parse_datasets`). Errors name the file
    and the key."""
    path = find_search_spec(source)
    data = read_yaml(path)
    check_keys(data, SPEC_KEYS, str(path))
    dataset, root_path, origin, pool = parse_datasets(path, data.get("dataset"), root)
    if "base" not in data:
        raise ConfigError(f"{path}: base: missing (the config every trial changes, e.g. ../dr2track.yaml)")
    base, base_source = load_spec_config(path, data["base"], {}, "base", "base")
    parameters = _parse_space(path, data.get("space"), base)
    experiments = data.get("experiments", ["ope"])
    if isinstance(experiments, str):
        experiments = [experiments]
    if not isinstance(experiments, list) or not experiments:
        raise ConfigError(f"{path}: experiments: expected a list such as [ope, tre], got {shown(experiments)}")
    experiments = check_experiments(experiments, f"{path}: experiments")
    baselines = _parse_baselines(path, data.get("baselines"))
    sequences = data.get("sequences")
    if sequences is not None:
        sequences = sequence_names(sequences, f"{path}: sequences", ConfigError)
    name = _names([data.get("name") or path.stem], f"{path}: name", "name")[0]
    return SearchSpec(
        path=path, name=name, description=str(data.get("description") or ""),
        dataset=dataset, root=root_path, root_origin=origin,
        sequences=tuple(sequences) if sequences is not None else None, base=base, base_source=base_source,
        parameters=parameters, experiments=experiments, folds=_whole(path, data, "folds", 4, 2),
        trials=_whole(path, data, "trials", 30, 1), startup_trials=_whole(path, data, "startup_trials", 10, 1),
        seed=_whole(path, data, "seed", 0, 0), baselines=baselines, pool=pool,
        warm_start=coerce(data.get("warm_start", True), bool, f"{path}: warm_start"),
        halving=parse_halving(path, data.get("halving")), final_study=_final_study(path, data))


def _parse_baselines(path: Path, raw: Any) -> dict:
    """Baseline name -> resolved config; a name is shown in summary.md and keys summary.json."""
    baselines = as_mapping(raw, f"{path}: baselines", "a mapping {name: config file}")
    for name in baselines:
        if name is None or str(name).strip() == "":
            raise ConfigError(f"{path}: baselines: {shown(name)} is not a name: give each baseline a name")
    names = _names(list(baselines), f"{path}: baselines", "baseline name")
    return {name: load_spec_config(path, cfg, {}, f"baselines.{clip(name)}", f"baselines.{clip(name)}")[0]
            for name, cfg in zip(names, baselines.values())}


def _names(keys: list, where: str, what: str) -> list[str]:
    """``keys`` as the names they stand for (``str``): each one line of printable text (they are
    written into summary.md), no two that read the same (YAML keys ``1`` and ``'1'``)."""
    names = [str(k) for k in keys]
    for name in names:
        if not name.isprintable():
            raise ConfigError(f"{where}: the {what} {shown(name)} has a line break or control character: "
                              f"give one line of printable text")
    if len(set(names)) < len(names):
        raise ConfigError(f"{where}: two {what}s read as {shown(_repeated(names))}: give distinct {what}s")
    return names


def _whole(path: Path, data: Mapping, key: str, default: int, least: int) -> int:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ConfigError(f"{path}: {key}: expected a whole number >= {least}, got {shown(value)}")
    return value


def _final_study(path: Path, data: Mapping) -> str:
    value = data.get("final_study", "always")
    if value not in FINAL_STUDY:
        raise ConfigError(f"{path}: final_study: expected one of {', '.join(FINAL_STUDY)}, got {shown(value)}")
    return value


def _parse_space(path: Path, raw: Any, base: dict) -> tuple:
    space = as_mapping(raw, f"{path}: space", "a mapping {dotted.key: {choice|float|int: ...}}")
    if not space:
        raise ConfigError(f"{path}: space: missing or empty: nothing to search")
    params: dict[str, Parameter] = {}
    for key, entry in space.items():
        where = f"{path}: space.{clip(str(key))}"
        params[str(key)] = _parse_parameter(where, str(key), entry, params)
    groups = _groups(tuple(params.values()))
    for group in groups:  # first: a parameter's contexts are combinations of its group's choices
        _check_count(path, group)
    contexts: dict[str, list[dict]] = {}
    for p in params.values():
        contexts[p.key] = _contexts(f"{path}: space.{clip(p.key)}", p, contexts)
        _check_values(f"{path}: space.{clip(p.key)}", base, p, params, contexts[p.key])
    for group in groups:
        _check_structures(path, base, group)
    return tuple(params.values())


def _parse_parameter(where: str, key: str, entry: Any, earlier: Mapping[str, Parameter]) -> Parameter:
    entry = as_mapping(entry, where, "a mapping such as {float: [5, 30], log: true} or {choice: [a, b]}")
    check_keys(entry, PARAMETER_KEYS, where)
    kinds = [k for k in KINDS if k in entry]
    if len(kinds) != 1:
        raise ConfigError(f"{where}: give exactly one of {', '.join(KINDS)}, got {shown(sorted(entry))}")
    kind, values = kinds[0], entry[kinds[0]]
    when = _parse_when(where, entry.get("when"), earlier)
    if kind == "choice":
        choices = values if isinstance(values, Mapping) else \
            {_label(v): v for v in values} if isinstance(values, list) else None
        if isinstance(values, list) and choices is not None and len(choices) < len(values):
            repeated = _repeated([_label(v) for v in values])
            raise ConfigError(f"{where}.choice: two values have the label {shown(repeated)}: give a mapping "
                              f"label -> value")
        if not choices or len(choices) < 2:
            raise ConfigError(f"{where}.choice: expected at least two values (a list, or a mapping label -> value), "
                              f"got {shown(values)}")
        if "log" in entry:
            raise ConfigError(f"{where}.log: only for float and int ranges")
        labels = _names(list(choices), f"{where}.choice", "label")  # YAML keys 1 and '1' are one label here
        return Parameter(key, CategoricalDistribution(labels), dict(zip(labels, choices.values())), when)
    if not (isinstance(values, list) and len(values) == 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values)
            and values[0] < values[1]):
        raise ConfigError(f"{where}.{kind}: expected [low, high] with low < high, got {shown(values)}")
    log = entry.get("log", False)
    if not isinstance(log, bool) or (log and values[0] <= 0):
        raise ConfigError(f"{where}.log: expected true or false (true needs low > 0), got {shown(log)}")
    if kind == "int":
        if not all(isinstance(v, int) for v in values):
            raise ConfigError(f"{where}.int: expected whole numbers, got {shown(values)}")
        return Parameter(key, IntDistribution(values[0], values[1], log=log), when=when)
    return Parameter(key, FloatDistribution(float(values[0]), float(values[1]), log=log), when=when)


def check_experiments(names: list, where: str) -> tuple[str, ...]:
    """The objective's experiments: each one an ablation can run, repeats dropped."""
    return tuple(dict.fromkeys(check_experiment(e, where) for e in names))


def _label(value: Any) -> str:
    if isinstance(value, Mapping) and isinstance(value.get("name"), str):
        return value["name"]
    return str(value)


def _repeated(labels: list[str]) -> str:
    return next(label for label, count in collections.Counter(labels).items() if count > 1)


def _parse_when(where: str, raw: Any, earlier: Mapping[str, Parameter]) -> tuple:
    when = as_mapping(raw, f"{where}.when", "a mapping {choice key: label or [labels]}")
    out = []
    for key, labels in when.items():
        labels = labels if isinstance(labels, list) else [labels]
        choice = earlier.get(str(key))
        if choice is None or not choice.choices:
            raise ConfigError(f"{where}.when: {shown(key)} is not a choice listed before it in space")
        unknown = [x for x in labels if str(x) not in choice.choices]
        if unknown:
            raise ConfigError(f"{where}.when: {shown(unknown[0])} is not one of {key}'s labels "
                              f"({', '.join(choice.choices)})")
        out.append((str(key), tuple(str(x) for x in labels)))
    return tuple(out)


def active(parameter: Parameter, params: Mapping[str, Any]) -> bool:
    """Whether ``parameter`` is sampled, given the values sampled before it."""
    return all(params.get(key) in labels for key, labels in parameter.when)


def _contexts(where: str, parameter: Parameter, earlier: Mapping[str, list[dict]]) -> list[dict]:
    """Every way ``parameter``'s ``when`` can hold: choice key -> label for the choices it names
    and those their own ``when`` names (``earlier``: each earlier parameter's contexts)."""
    contexts: list[dict] = [{}]
    for key, labels in parameter.when:
        contexts = [{**c, **up, key: label} for c in contexts for up in earlier[key] for label in labels
                    if _agree(c, {**up, key: label})]
    if not contexts:
        raise ConfigError(f"{where}.when: never holds (the choices it names are sampled under other labels)")
    return [dict(t) for t in dict.fromkeys(tuple(c.items()) for c in contexts)]


def _agree(a: Mapping, b: Mapping) -> bool:
    return all(a[k] == v for k, v in b.items() if k in a)


def _check_values(where: str, base: dict, parameter: Parameter, params: Mapping[str, Parameter],
                  contexts: list[dict]) -> None:
    """Resolve the base with each choice, or each end of a range, under each of its ``contexts``
    (:func:`_contexts`), so a wrong key or value is an error now, not in trial 17."""
    d = parameter.distribution
    values = list(parameter.choices.values()) if parameter.choices else [d.low, d.high]
    for context in contexts:
        chosen = {key: params[key].value(context[key]) for key in params if key in context}  # in space order
        under = f" under {_sampled(context)}" if context else ""
        for value in values:
            try:
                load_config(base, {**chosen, parameter.key: value})
            except DcfkitError as exc:
                raise ConfigError(f"{where}: with the value {shown(value)}{under}: {exc}") from None


def resolve(base: dict, parameters: tuple, sampled: Mapping[str, Any]) -> dict:
    """The base config with the ``sampled`` values (key -> sampled value) of ``parameters`` applied."""
    return load_config(base, {p.key: p.value(sampled[p.key]) for p in parameters if p.key in sampled})


def _related(a: Parameter, b: Parameter) -> bool:
    """Whether one's key lies inside the other's (``label`` and ``label.mu``) or one is sampled
    only under the other (``when``): then only the two together show a config is valid."""
    return (a.key.startswith(b.key + ".") or b.key.startswith(a.key + ".")
            or any(k == b.key for k, _ in a.when) or any(k == a.key for k, _ in b.when))


def _groups(parameters: tuple) -> list[list[Parameter]]:
    """The dimensions in groups of (transitively) related ones, each group in space order."""
    groups: list[list[Parameter]] = []
    for p in parameters:
        linked = [g for g in groups if any(_related(p, q) for q in g)]
        groups = [g for g in groups if all(g is not h for h in linked)] + [[q for g in linked for q in g] + [p]]
    order = {p.key: i for i, p in enumerate(parameters)}
    return [sorted(g, key=lambda p: order[p.key]) for g in groups]


def _check_count(path: Path, group: list[Parameter]) -> None:
    """Refuse a group with more than :data:`MAX_STRUCTURES` combinations of its choices."""
    choices = [p for p in group if p.choices]
    count = math.prod(len(p.choices) for p in choices)
    if count > MAX_STRUCTURES:
        raise ConfigError(f"{path}: space: the related choices {clip(', '.join(p.key for p in choices))} make "
                          f"{count} combinations, more than the {MAX_STRUCTURES} checked when a spec is read")


def _check_structures(path: Path, base: dict, group: list[Parameter]) -> None:
    """Resolve the base with every combination of the group's choices, each with the dimensions
    sampled under it at the :func:`_points` of their ranges: every config the space can make, as
    far as its structure goes, so a dimension that only some choices take (no ``when``) fails now."""
    choices = [p for p in group if p.choices]
    checked = set()
    for labels in itertools.product(*(p.choices for p in choices)):
        for point in range(3):
            sampled = _structure(group, dict(zip((p.key for p in choices), labels)), point)
            if (mark := repr(sampled)) in checked:
                continue
            checked.add(mark)
            try:
                resolve(base, tuple(group), sampled)
            except DcfkitError as exc:
                raise ConfigError(f"{path}: {_described(sampled)}: {exc}") from None


def _structure(group: list[Parameter], labels: Mapping[str, str], point: int) -> dict[str, Any]:
    """The sampled values of one config of the group: each choice sampled under ``labels`` at
    its label, each range sampled under them at one of its :func:`_points`."""
    sampled: dict[str, Any] = {}
    for p in group:
        if active(p, sampled):
            sampled[p.key] = labels[p.key] if p.choices else _points(p.distribution)[point]
    return sampled


def _points(d: BaseDistribution) -> tuple:
    """A range's ends and a point inside, off any round number: a whole-number key given a
    float range, ``{float: [1, 3]}``, takes both ends but not 1.76."""
    if isinstance(d, IntDistribution):
        return d.low, (d.low + d.high) // 2, d.high
    inside = d.low * (d.high / d.low) ** 0.382 if d.log else d.low + 0.382 * (d.high - d.low)
    return d.low, min(max(inside, d.low), d.high), d.high


def _described(sampled: Mapping[str, Any]) -> str:
    """Where a config of the space is wrong: ``space.key: with the value v`` for one dimension,
    else the values together, with the way out (a dimension only some choices take needs when)."""
    if len(sampled) == 1:
        (key, value), = sampled.items()
        return f"space.{clip(key)}: with the value {shown(value)}"
    return (f"space: {_sampled(sampled)} together give no valid config (a dimension that only some choices "
            f"take needs when)")


def _sampled(sampled: Mapping[str, Any]) -> str:
    return clip(", ".join(f"{key}={shown(value)}" for key, value in sampled.items()))

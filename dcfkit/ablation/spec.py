"""Ablation specs: named variants and parameter grids of tracker configs, validated and
expanded to jobs."""
from __future__ import annotations

import contextlib
import dataclasses
import itertools
import math
import os
from pathlib import Path
from typing import Any, Iterable, Mapping

import yaml

from dcfkit import limits
from dcfkit.ablation.experiment import check_experiment
from dcfkit.ablation.published import parse_published
from dcfkit.ablation.spec_keys import as_mapping, check_keys, check_root, parse_datasets, pooled_sequences
from dcfkit.config import load_config, shipped_config, shipped_config_dir
from dcfkit.config.bounded_yaml import read_yaml
from dcfkit.datasets import load_dataset
from dcfkit.datasets.base import sequence_names
from dcfkit.errors import ConfigError, DcfkitError, clip, shown
from dcfkit.store.provenance import dcfkit_version, run_key

SPEC_KEYS = ("name", "description", "dataset", "sequences", "experiment", "variants", "grid", "published")
VARIANT_KEYS = ("config", "overrides", "description")
GRID_KEYS = ("base", "overrides", "mode", "parameters")
GRID_MODES = ("sweep", "product")
# named and grid variants in one spec, each resolved when the spec is read (some 4 ms; 15 ms on a
# busy machine): the default of $DCFKIT_MAX_VARIANTS and `dcfkit ablate --max-variants`
MAX_VARIANTS = 1000
RAISE_VARIANTS = f"dcfkit ablate --max-variants N, ${limits.VARIANTS_VARIABLE} or dcfkit.ablation.spec.MAX_VARIANTS raise it"


@dataclasses.dataclass(frozen=True)
class Variant:
    """One row of the ablation table: ``config`` is the fully resolved config dict;
    ``values`` holds the grid parameter values that define it (empty for a named variant)."""

    name: str
    config: dict
    source: str
    overrides: dict = dataclasses.field(default_factory=dict)
    values: dict = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class Grid:
    """A parameter grid around ``base`` (a variant name or a config): ``parameters`` maps a
    dotted key to ``(label, values)``; ``mode`` is ``sweep`` (one at a time) or ``product``."""

    base: str
    mode: str
    parameters: dict
    base_config: dict


@dataclasses.dataclass(frozen=True)
class AblationSpec:
    """A validated spec (:func:`load_spec`): every variant's config already resolved."""

    path: Path
    name: str
    description: str
    dataset: str              # canonical dataset name
    root: Path | None         # absolute; None when neither the spec nor --root gives one
    root_origin: str          # where root came from, for error messages
    sequences: tuple | None   # None: every sequence present under root
    variants: tuple           # of Variant: named variants first, then the grid's, in spec order
    grid: Grid | None
    max_frames: int | None = None  # a smoke run: each sequence's first frames only
    experiment: str = "ope"  # the runs of each sequence: one of ablation_experiments()
    published: tuple = ()  # (name, folder) of result files scored beside the variants, never run
    pool: tuple = ()  # pooled datasets: (name, root, origin) of each, ``dataset`` their names joined by "+"

    def load_sequences(self) -> list:
        """The :class:`dcfkit.datasets.Sequence` objects to run: the spec's subset, else all under root."""
        if self.pool:
            return [s.head(self.max_frames) for s in pooled_sequences(self)]
        check_root(self.path, self.dataset, self.root, self.root_origin)
        found = load_dataset(self.dataset, self.root, list(self.sequences) if self.sequences is not None else None)
        return [s.head(self.max_frames) for s in found]


@dataclasses.dataclass(frozen=True)
class Job:
    """One tracker run to do: ``variant`` on ``sequence`` with the resolved ``config``;
    ``key`` names the run's result folder (:func:`dcfkit.store.provenance.run_key`)."""

    variant: str
    config: dict
    sequence: str
    key: str


def variant_names(jobs: Iterable[Job]) -> dict[str, list[str]]:
    """key -> the names of the variants that share that run, in spec order."""
    names: dict[str, list[str]] = {}
    for job in jobs:
        if job.variant not in names.setdefault(job.key, []):
            names[job.key].append(job.variant)
    return names


def _find_spec(source: str | os.PathLike) -> Path:
    path = Path(source)
    if os.path.isfile(path):  # os.path: a name too long for the file system is no file (Path.is_file raises)
        return path.resolve()
    folder = shipped_config_dir() / "ablations"
    for candidate in (folder / path, folder / f"{path}.yaml"):
        if os.path.isfile(candidate) and candidate.suffix in (".yaml", ".yml"):
            return candidate.resolve()
    shipped = [p.stem for p in sorted(folder.glob("*.yaml")) if _is_spec_file(p)] if folder.is_dir() else []
    raise ConfigError(f"ablation spec not found: {clip(str(source))}"
                      + (f"; shipped specs: {', '.join(shipped)}" if shipped else ""))


def _is_spec_file(path: Path) -> bool:
    with contextlib.suppress(ConfigError):
        data = read_yaml(path)
        return "variants" in data or "grid" in data
    return False


def _overrides(value: Any, where: str) -> dict:
    out = as_mapping(value, where, "a mapping of dotted keys to values, e.g. {label.mu: 0.3}")
    for key in out:
        if not isinstance(key, str) or not key.strip():
            raise ConfigError(f"{where}: keys must be dotted config keys such as label.mu, got {shown(key)}")
    return out


def load_spec_config(spec_path: Path, config: Any, overrides: Mapping, where: str, key: str) -> tuple[dict, str]:
    """Resolve ``config`` (relative to the spec file, else a shipped name) with ``overrides``.

    ``where`` names the spec entry in errors, ``key`` the spec key holding ``config``."""
    if not isinstance(config, str) or not config.strip():
        raise ConfigError(f"{spec_path}: {key}: expected a config file or shipped name "
                          f"(e.g. ../dr2track.yaml or dr2track), got {shown(config)}")
    local = spec_path.parent / config
    found = local if os.path.isfile(local) else shipped_config(config)  # never the working directory
    if found is None:
        raise ConfigError(f"{spec_path}: {where}: config '{clip(config)}' not found (looked for "
                          f"{clip(str(local))} and for a shipped config of that name)")
    source = str(found)
    try:
        return load_config(source, overrides), source
    except DcfkitError as exc:
        try:
            load_config(source)
        except DcfkitError:
            raise ConfigError(f"{spec_path}: {where}: {exc}") from None
        raise ConfigError(f"{spec_path}: {where} overrides ({clip(', '.join(overrides))}): {exc}") from None


def format_value(value: Any) -> str:
    """A grid value as written in variant names and plot ticks."""
    if isinstance(value, str):
        return value
    return yaml.safe_dump(value, default_flow_style=True, width=10**6).strip().removesuffix("...").strip()


def _parse_grid(spec_path: Path, data: Any, named: dict[str, Variant], limit: int) -> tuple[Grid, list[Variant]]:
    grid = as_mapping(data, f"{spec_path}: grid", "a mapping with base, mode and parameters")
    check_keys(grid, GRID_KEYS, f"{spec_path}: grid")
    mode = grid.get("mode", "sweep")
    if mode not in GRID_MODES:
        raise ConfigError(f"{spec_path}: grid.mode: expected one of {', '.join(GRID_MODES)}, got {shown(mode)}")
    base = grid.get("base")
    if base is None:
        raise ConfigError(f"{spec_path}: grid.base: missing; name a variant or a config (e.g. dr2track)")
    extra = _overrides(grid.get("overrides"), f"{spec_path}: grid.overrides")
    if isinstance(base, str) and base in named:
        base_source = named[base].source
        base_overrides = {**named[base].overrides, **extra}
    else:
        base_source, base_overrides = base, extra
    base_config, base_source = load_spec_config(spec_path, base_source, base_overrides, "grid.base", "grid.base")

    params = as_mapping(grid.get("parameters"), f"{spec_path}: grid.parameters",
                      "a mapping of dotted keys to value lists, e.g. {label.mu: [0, 0.1, 0.25]}")
    if not params:
        raise ConfigError(f"{spec_path}: grid.parameters: empty; give at least one dotted key with a list of values")
    parsed = _parse_parameters(spec_path, params)
    variants = []
    for point in _grid_points(spec_path, parsed, mode, len(named), limit):
        name = ", ".join(f"{parsed[k][0]}={format_value(v)}" for k, v in point.items())
        where = clip("grid (" + ", ".join(f"{k}={format_value(v)}" for k, v in point.items()) + ")")
        config, _ = load_spec_config(spec_path, base_source, {**base_overrides, **point}, where, "grid.base")
        variants.append(Variant(name, config, base_source, {**base_overrides, **point}, dict(point)))
    return Grid(str(base), mode, parsed, base_config), variants


def _parse_parameters(spec_path: Path, params: Mapping) -> dict[str, tuple[str, list]]:
    """``grid.parameters`` as dotted key -> (label, values), each value and label once."""
    parsed: dict[str, tuple[str, list]] = {}
    for key, entry in params.items():
        where = f"{spec_path}: grid.parameters.{clip(str(key))}"
        label = key
        if isinstance(entry, Mapping):
            check_keys(entry, ("values", "label"), where)
            label = str(entry.get("label") or key)
            entry = entry.get("values")
        if not isinstance(entry, list) or not entry:
            raise ConfigError(f"{where}: expected a non-empty list of values (or {{label: ..., values: [...]}}), "
                              f"got {shown(entry)}")
        dup = _first_repeat(format_value(v) for v in entry)
        if dup is not None:
            raise ConfigError(f"{where}: value {clip(dup)} is listed twice")
        parsed[str(key)] = (label, list(entry))
    dup = _first_repeat(label for label, _ in parsed.values())
    if dup is not None:
        raise ConfigError(f"{spec_path}: grid.parameters: two parameters share the label {shown(dup)}")
    return parsed


def _first_repeat(items: Iterable) -> Any:
    """The first item seen a second time, or None (in linear time: a grid may list many values)."""
    seen = set()
    for item in items:
        if item in seen:
            return item
        seen.add(item)
    return None


def _grid_points(spec_path: Path, parsed: Mapping, mode: str, named: int, limit: int) -> list[dict]:
    """The grid's points (dotted key -> value), counted before they are made: a product of a few
    long lists is more variants than can be resolved, or held."""
    lengths = [len(values) for _, values in parsed.values()]
    count = sum(lengths) if mode == "sweep" else math.prod(lengths)
    if named + count > limit:
        raise ConfigError(f"{spec_path}: grid.parameters: {count} grid points ({mode}) and {named} named variants; "
                          f"a spec has at most {limit} variants ({RAISE_VARIANTS})")
    if mode == "sweep":
        return [{key: value} for key, (_, values) in parsed.items() for value in values]
    keys = list(parsed)
    return [dict(zip(keys, combo)) for combo in itertools.product(*(parsed[k][1] for k in keys))]


def variant_limit(given: int | None = None) -> int:
    """The most variants a spec may have: ``given`` (``dcfkit ablate --max-variants``), else
    ``$DCFKIT_MAX_VARIANTS``, else :data:`MAX_VARIANTS`."""
    if given is None:
        return limits.max_variants(MAX_VARIANTS)
    if isinstance(given, bool) or not isinstance(given, int) or given < 1:
        raise ConfigError(f"max_variants must be a whole number >= 1, got {shown(given)}")
    return given


def load_spec(source: str | os.PathLike, root=None,
              sequences: Iterable[str] | str | None = None, max_variants: int | None = None) -> AblationSpec:
    """Read and validate an ablation spec (a path, or a shipped name such as ``table3``).

    ``root`` (a folder, or a list of them to pool) replaces the spec's ``dataset.root``
    (relative to the working directory; :func:`~dcfkit.ablation.spec_keys.parse_datasets`);
    the spec's own root is relative to the spec file. ``sequences`` (names, or one
    comma-separated string) replaces the spec's subset. Every variant's config is resolved
    here, so a wrong key or value fails before anything runs; errors name the spec file
    and the key. A spec has at most :func:`variant_limit` variants (``max_variants``, else
    ``$DCFKIT_MAX_VARIANTS``, else :data:`MAX_VARIANTS`).
    """
    limit = variant_limit(max_variants)
    path = _find_spec(source)
    data = read_yaml(path)
    check_keys(data, SPEC_KEYS, str(path))
    for key in ("name", "description"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise ConfigError(f"{path}: {key}: expected a string, got {shown(data[key])}")
    dataset_name, root_path, origin, pool = parse_datasets(path, data.get("dataset"), root)
    named = _parse_variants(path, data.get("variants"), limit)
    grid, grid_variants = None, []
    if data.get("grid") is not None:
        grid, grid_variants = _parse_grid(path, data["grid"], named, limit)
    for v in grid_variants:
        if v.name in named:
            raise ConfigError(f"{path}: grid point {shown(v.name)} has the same name as variants.{clip(v.name)}; "
                              f"rename the variant")
    if not named and not grid_variants:
        raise ConfigError(f"{path}: no variants and no grid: nothing to run")
    return AblationSpec(path=path, name=str(data.get("name") or path.stem),
                        description=str(data.get("description") or ""), dataset=dataset_name,
                        root=root_path, root_origin=origin, sequences=_parse_sequences(path, data, sequences),
                        variants=tuple(named.values()) + tuple(grid_variants), grid=grid,
                        experiment=(experiment := check_experiment(data.get("experiment", "ope"), f"{path}: experiment")),
                        published=parse_published(path, data.get("published"), [*named, *(v.name for v in grid_variants)],
                                                  experiment),
                        pool=pool)


def _parse_sequences(path: Path, data: Mapping, sequences) -> tuple | None:
    """The spec's sequence subset, or ``sequences`` (from --sequences) instead."""
    where = f"{path}: sequences"
    if sequences is None:
        sequences = data.get("sequences")
    else:
        where = "--sequences (replacing the spec's sequences)"
    if sequences is None:
        return None
    return tuple(sequence_names(sequences, where, ConfigError))


def _parse_variants(path: Path, raw: Any, limit: int) -> dict[str, Variant]:
    """The named variants, each config resolved with its overrides."""
    raw_variants = as_mapping(raw, f"{path}: variants", "a mapping of variant names to {config: ..., overrides: {...}}")
    if len(raw_variants) > limit:
        raise ConfigError(f"{path}: variants: {len(raw_variants)} variants; a spec has at most {limit} "
                          f"({RAISE_VARIANTS})")
    named: dict[str, Variant] = {}
    for name, entry in raw_variants.items():
        where = f"variants.{clip(str(name))}"
        if str(name) in named:  # YAML keys 1 and "1" (or true and "True") are one name here
            raise ConfigError(f"{path}: {where}: variant names must be unique, and {shown(name)} is given twice")
        if isinstance(entry, str):
            entry = {"config": entry}
        entry = as_mapping(entry, f"{path}: {where}", "{config: path-or-name, overrides: {dotted.key: value}}")
        check_keys(entry, VARIANT_KEYS, f"{path}: {where}")
        if "config" not in entry:
            raise ConfigError(f"{path}: {where}.config: missing (a config file relative to the spec, "
                              f"or a shipped name such as dr2track)")
        overrides = _overrides(entry.get("overrides"), f"{path}: {where}.overrides")
        config, src = load_spec_config(path, entry["config"], overrides, where, f"{where}.config")
        named[str(name)] = Variant(str(name), config, src, overrides)
    return named


def expand(spec: AblationSpec, sequences: Iterable | None = None, version: str | None = None) -> list[Job]:
    """The job list: every variant (spec order) on every sequence (dataset or given order).

    ``sequences`` are names or :class:`dcfkit.datasets.Sequence` objects; default: the
    spec's subset, else every sequence under the spec's root.
    """
    if sequences is None:
        sequences = spec.sequences if spec.sequences is not None else spec.load_sequences()
    names = [s if isinstance(s, str) else s.name for s in sequences]
    version = version if version is not None else dcfkit_version()
    keys = {v.name: run_key(v.config, version) for v in spec.variants}
    return [Job(v.name, v.config, seq, keys[v.name]) for v in spec.variants for seq in names]

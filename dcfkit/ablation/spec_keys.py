"""A spec's YAML read key by key (the checks every spec, ablation or search, goes through) and
its ``dataset``: one benchmark and root, or a list of them pooled into one set of sequences."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping

from dcfkit.datasets import DatasetError, canonical_name, load_datasets
from dcfkit.errors import ConfigError, clip, shown
from dcfkit.params import closest
from dcfkit.store.provenance import shared_path


def as_mapping(value: Any, where: str, what: str) -> dict:
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}: expected {what}, got {type(value).__name__} {shown(value)}")
    return dict(value)


def check_keys(data: Mapping, valid: tuple, where: str) -> None:
    for key in data:
        if key not in valid:
            raise ConfigError(f"{where}: unknown key {shown(key)}{closest(key, valid)}; valid keys: {', '.join(valid)}")


def parse_datasets(path: Path, dataset: Any, roots) -> tuple[str, Path | None, str, tuple]:
    """(dataset, root, origin, pool) of a spec's ``dataset`` (one, or a list to pool) with the
    ``--root`` folders ``roots`` (None, one, or a list) replacing the spec's roots: one --root per
    listed dataset in order, or any number for one dataset. One dataset and root: as
    :func:`parse_dataset`, ``pool`` empty; several: ``dataset`` their names joined by "+" (the
    results' folder ``OUT/jobs/<dataset>/``), ``root`` None, ``pool`` the (name, root, origin) of each."""
    roots = [] if roots is None else [roots] if isinstance(roots, (str, os.PathLike)) else list(roots)
    if not isinstance(dataset, list) and len(roots) <= 1:
        return (*parse_dataset(path, dataset, roots[0] if roots else None), ())
    entries = dataset if isinstance(dataset, list) else [dataset]
    if not entries:
        raise ConfigError(f"{path}: dataset: an empty list; name at least one dataset")
    parsed = [parse_dataset(path, entry, None, f"dataset[{i}]" if isinstance(dataset, list) else "dataset")
              for i, entry in enumerate(entries)]
    if roots:
        if len(parsed) not in (1, len(roots)):
            raise ConfigError(f"{path}: dataset lists {len(parsed)} datasets but {len(roots)} --root were given: "
                              f"give one --root per listed dataset, in the spec's order")
        names = [name for name, _, _ in parsed] * (len(roots) if len(parsed) == 1 else 1)
        parsed = [(name, Path(root).expanduser().resolve(), "--root") for name, root in zip(names, roots)]
    if len(parsed) == 1:
        return (*parsed[0], ())
    return "+".join(dict.fromkeys(name for name, _, _ in parsed)), None, "pooled", tuple(parsed)


def parse_dataset(path: Path, dataset: Any, root, key: str = "dataset") -> tuple[str, Path | None, str]:
    """(canonical dataset name, absolute root or None, where the root came from) of the spec's
    ``key`` (``dataset``, or an item of its list)."""
    if isinstance(dataset, str):
        dataset = {"name": dataset}
    dataset = as_mapping(dataset, f"{path}: {key}", "a mapping {name: uav123_10fps, root: path} (or a list of them)")
    check_keys(dataset, ("name", "root"), f"{path}: {key}")
    if not dataset.get("name"):
        raise ConfigError(f"{path}: {key}.name: missing (e.g. uav123_10fps, dtb70, uavdt, otb)")
    if not isinstance(dataset["name"], str):
        raise ConfigError(f"{path}: {key}.name: expected a name such as uav123_10fps, got {shown(dataset['name'])}")
    try:
        name = canonical_name(dataset["name"])
    except DatasetError as exc:
        raise ConfigError(f"{path}: {key}.name: {exc}") from None
    if root is not None:
        return name, Path(root).expanduser().resolve(), "--root"
    if dataset.get("root"):
        return (name, (path.parent / Path(str(dataset["root"])).expanduser()).resolve(),
                f"{key}.root {shown(dataset['root'])} relative to the spec")
    return name, None, "not given"


def check_root(path: Path, dataset: str, root: Path | None, origin: str) -> None:
    """A :class:`ConfigError` naming the spec unless ``root`` (from ``origin``) is a folder."""
    if root is None:
        raise ConfigError(f"{path}: dataset.root is not given; pass --root DIR "
                          f"(the {dataset} benchmark folder)")
    if not os.path.isdir(root):
        hint = "" if origin == "--root" else f"; pass --root DIR (the {dataset} benchmark folder)"
        raise ConfigError(f"{path}: dataset root {clip(str(root))} ({origin}) is not a folder{hint}")


def pooled_sequences(spec) -> list:
    """The sequences of a spec whose ``dataset`` lists several (:func:`dcfkit.datasets.load_datasets`)."""
    for name, root, origin in spec.pool:
        check_root(spec.path, name, root, origin)
    return load_datasets([n for n, _, _ in spec.pool], [r for _, r, _ in spec.pool],
                         list(spec.sequences) if spec.sequences is not None else None)


def _root(root, base) -> str | None:
    """``root`` as a file in folder ``base`` names it (:func:`shared_path`); None stays None."""
    return None if root is None else shared_path(root, base)


def data_record(spec, base=None) -> dict:
    """``dataset`` and ``root`` as a summary in folder ``base`` records them: a name and a folder
    (relative to ``base``), or for pooled datasets a list of each."""
    if not spec.pool:
        return {"dataset": spec.dataset, "root": _root(spec.root, base)}
    return {"dataset": [n for n, _, _ in spec.pool], "root": [_root(r, base) for _, r, _ in spec.pool]}


def data_text(spec, base=None) -> str:
    """``uav123_10fps at ROOT``, one such item per pooled dataset, roots relative to ``base``."""
    pool = spec.pool or ((spec.dataset, spec.root, ""),)
    return ", ".join(f"{n} at {_root(r, base) or 'no root'}" for n, r, _ in pool)


def roots_text(spec) -> str:
    """The spec's root, or its pooled roots separated by commas."""
    return ", ".join(str(r) for _, r, _ in spec.pool) or str(spec.root)

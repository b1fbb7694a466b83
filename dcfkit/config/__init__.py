"""Tracker configs: YAML files with inheritance, dotted overrides and validation.

A config names one component per slot (``features`` is a list) plus the tracker's geometry::

    name: dr2track
    base: strcf.yaml            # optional: inherit, then override (mappings merge, lists replace)
    tracker: {search_area_scale: 5, cell_size: 4, ...}
    features: [{name: gray}, {name: fhog}, {name: colornames}]
    label: {name: distractor_repressed, top_n: 30, mu: 0.25}
    regularizers: {spatial: {name: box}, temporal: {name: temporal, theta: 12}}
    solver: {name: admm_strcf, iterations: 4}
    search: {name: motion_aware}
    scale: {name: dsst}

Overrides are dotted keys (``label.mu=0.3``, ``features.0.name=gray``); a value ``null``
removes an optional slot (``regularizers.temporal=null``; ``regularizers=null`` both roles).
Naming another component (``label.name=gaussian``, or ``label: {name: gaussian}`` in a child
file) drops the old component's parameters. ``base`` cannot be overridden: it is read with
the file.
"""
from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import Any, Mapping

from dcfkit.config.bounded_yaml import check_value, read_yaml, unshared
from dcfkit.config.overrides import merge, parse_overrides, parse_value, set_dotted
from dcfkit.config.slots import KINDS, SLOTS, TOP_LEVEL, Slot, components, resolve
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.errors import ConfigError, DcfkitError, clip, shown

__all__ = ["KINDS", "MAX_BASE_CHAIN", "SLOTS", "Slot", "TOP_LEVEL", "TrackerParams", "check_value", "components",
           "load_config", "merge", "parse_overrides", "parse_value", "read_yaml", "resolve", "set_dotted",
           "shipped_config", "shipped_config_dir"]

MAX_BASE_CHAIN = 32  # files in one 'base:' chain


def shipped_config_dir() -> Path:
    """The shipped configs: ``configs/`` of a checkout, or ``dcfkit/configs`` when installed."""
    package = Path(__file__).resolve().parents[1]
    checkout = package.parent / "configs"
    return checkout if (checkout / "dr2track.yaml").is_file() else package / "configs"


def _load_file(path: Path, chain: tuple[Path, ...] = ()) -> tuple[dict, tuple[Path, ...]]:
    """The file merged over its ``base`` chain, and the files read (this one first)."""
    path = path.resolve()
    if path in chain:
        raise ConfigError(f"{path}: circular 'base' chain: {' -> '.join(map(str, chain + (path,)))}")
    if len(chain) >= MAX_BASE_CHAIN:  # each file is a level of recursion here and in merge()
        raise ConfigError(f"{chain[0]}: the 'base' chain is longer than {MAX_BASE_CHAIN} files "
                          f"(dcfkit.config.MAX_BASE_CHAIN): {chain[0]} -> {chain[1]} -> ... -> {path}")
    data = read_yaml(path)
    base = data.pop("base", None)
    if base is None:
        return data, (path,)
    if not isinstance(base, str):
        raise ConfigError(f"{path}: 'base' must be a file name, got {shown(base)}")
    base_path = path.parent / base
    if not os.path.isfile(base_path):  # a shipped config by name ('dr2track' or 'dr2track.yaml')
        shipped = shipped_config(base) if Path(base).name == base else None
        if shipped is None:
            raise ConfigError(f"{path}: base config '{clip(base)}' not found (looked for {clip(str(base_path))} "
                              f"and for a shipped config of that name)")
        base_path = shipped
    inherited, files = _load_file(base_path, chain + (path,))
    return merge(inherited, data), (path,) + files


def load_config(source: str | Path | Mapping, overrides: Mapping[str, Any] | None = None) -> dict:
    """Read a config (path, or a dict), apply dotted overrides, validate, fill in defaults.

    A bare name such as 'dr2track' finds ``configs/dr2track.yaml``. Returns the fully
    resolved config: every component with all its parameters. An error in a config with a
    ``base`` lists the files it was merged from (the key may sit in any of them).
    """
    files: tuple[Path, ...] = ()
    if not isinstance(source, (str, os.PathLike, Mapping)):
        raise ConfigError(f"a config is a file path, a shipped config name or a mapping, got {type(source).__name__}")
    if isinstance(source, Mapping):
        origin = "<config dict>"
        check_value(source, origin)  # before deepcopy and merge walk it
        data = unshared(copy.deepcopy(dict(source)))
        base = data.pop("base", None)
        if base is not None:
            if not isinstance(base, (str, os.PathLike)):
                raise ConfigError(f"{origin}: 'base' must be a file name, got {shown(base)}")
            inherited, files = _load_file(_find(base))
            data = merge(inherited, data)
    else:
        path = _find(source)
        data, files = _load_file(path)
        origin = str(path)
    for key, value in (overrides or {}).items():
        if not isinstance(key, str):
            raise ConfigError(f"override keys are dotted strings such as 'label.mu', got {shown(key)}")
        if key.split(".")[0].strip() == "base":  # set_dotted would set a key that nothing reads any more
            raise ConfigError(f"override '{clip(key)}': a config's base is read with its file, before overrides "
                              f"apply; give that config instead (its shipped name or file), or write a file whose "
                              f"base: names it")
        check_value(value, f"override '{clip(key)}'")
        set_dotted(data, key, copy.deepcopy(value))  # a later dotted key must not write into the caller's value
    check_value(data, origin)  # dotted keys nest values deeper; merged files add up
    try:
        return resolve(data, origin)
    except DcfkitError as exc:
        chain = [origin] * isinstance(source, Mapping) + [str(f) for f in files]
        if len(chain) < 2:
            raise
        raise type(exc)(f"{exc} (config merged from {' <- '.join(chain)})") from None


def shipped_config(name: str | Path) -> Path | None:
    """The shipped config called ``name`` ('dr2track' or 'dr2track.yaml'), or None."""
    folder = shipped_config_dir()
    return next((c for c in (folder / name, folder / f"{name}.yaml") if os.path.isfile(c)), None)


def _find(source: str | Path) -> Path:
    path = Path(source)
    if os.path.isfile(path):  # os.path: a name too long for the file system is no file (Path.is_file raises)
        return path
    found = shipped_config(path)
    if found is not None:
        return found
    folder = shipped_config_dir()
    shipped = sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []
    raise ConfigError(f"config not found: {clip(str(source))}"
                      + (f"; shipped configs: {', '.join(shipped)}" if shipped else ""))

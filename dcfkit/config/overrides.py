"""Changes to a config given as text: ``--set key.path=value``, and the merge of a ``base:``."""
from __future__ import annotations

import copy
from typing import Any, Mapping

import yaml

from dcfkit.config.bounded_yaml import OverLimit, load_yaml
from dcfkit.errors import ConfigError, clip, shown


def merge(base: Mapping, override: Mapping) -> dict:
    """Deep merge: mappings merge key by key, anything else (lists included) is replaced.

    A component mapping that names a different component replaces the old one whole (its
    parameters would not fit the new component)."""
    out = copy.deepcopy(dict(base))
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping) and \
                value.get("name", out[key].get("name")) == out[key].get("name"):
            out[key] = merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def parse_value(text: str, where: str = "--set value") -> Any:
    """A CLI override value: YAML scalars/lists ('0.3', 'true', '[1, 2]', 'null'); text that is
    not YAML stays text. A value over the bounds of a config is a ConfigError naming ``where``."""
    try:
        return load_yaml(text)
    except OverLimit as exc:
        raise ConfigError(f"{where}: {exc.describe()}") from None
    except yaml.YAMLError:
        return text


def parse_overrides(items) -> dict:
    """``["label.mu=0.3", "name=x"]`` -> ``{"label.mu": 0.3, "name": "x"}`` (CLI ``--set`` values)."""
    out = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"--set expects KEY=VALUE (e.g. label.mu=0.3), got {shown(item)}")
        out[key.strip()] = parse_value(value, f"--set {clip(key.strip())}") if value.strip() else ""
    return out


def get_dotted(config: Any, key: str) -> Any:
    """The value at dotted ``key`` of ``config`` (list items by index), or None."""
    node = config
    for part in key.split("."):
        if isinstance(node, list) and part.lstrip("-").isdigit() and -len(node) <= int(part) < len(node):
            node = node[int(part)]
        elif isinstance(node, Mapping) and part in node:
            node = node[part]
        else:
            return None
    return node


def set_dotted(config: dict, key: str, value: Any) -> None:
    """Set ``a.b.0.c`` in nested dicts/lists; list indices are integers."""
    parts = key.split(".")
    node: Any = config
    for i, part in enumerate(parts[:-1]):
        if isinstance(node, list):
            node = node[_index(node, part, ".".join(parts[: i + 1]))]
        elif isinstance(node, dict):
            if not isinstance(node.get(part), (dict, list)):
                node[part] = {}
            node = node[part]
        else:
            raise ConfigError(f"override '{clip(key)}': '{clip('.'.join(parts[: i + 1]))}' is not a mapping")
    last = parts[-1]
    if isinstance(node, list):
        node[_index(node, last, key)] = value
    else:
        if last == "name" and len(parts) > 1 and node.get("name") not in (None, value):
            node.clear()  # another component: the old one's parameters do not apply
        node[last] = value


def _index(items: list, part: str, where: str) -> int:
    try:
        i = int(part)
    except ValueError:
        raise ConfigError(f"override '{clip(where)}': this is a list; use an index 0..{len(items) - 1}") from None
    if not -len(items) <= i < len(items):
        raise ConfigError(f"override '{clip(where)}': index {shown(i)} out of range 0..{len(items) - 1}")
    return i

"""A config's slots, each resolved to a component spec the registry has checked."""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Mapping

from dcfkit.config.tracker_params import TrackerParams
from dcfkit.errors import ConfigError, clip, shown
from dcfkit.params import closest, parse_params
from dcfkit.registry import get_registry

SLOTS = ("features", "label", "regularizers", "solver", "search", "scale")


KINDS = ("feature", "label", "regularizer", "solver", "search", "scale")  # of the components each slot takes


TOP_LEVEL = ("name", "description", "base", "tracker") + SLOTS


REGULARIZER_ROLES = ("spatial", "temporal")


def components(config: Mapping) -> list[tuple[str, str]]:
    """The ``(kind, name)`` of every component a resolved config uses."""
    def name(spec):
        return spec.get("name") if isinstance(spec, Mapping) else None

    features, regularizers = config.get("features"), config.get("regularizers")
    found = [("feature", name(f)) for f in features] if isinstance(features, (list, tuple)) else []
    found += [("regularizer", name(r)) for r in regularizers.values()] if isinstance(regularizers, Mapping) else []
    found += [(kind, name(config.get(slot))) for kind, slot in
              (("label", "label"), ("solver", "solver"), ("search", "search"), ("scale", "scale"))]
    return [(kind, n) for kind, n in found if isinstance(n, str)]


def _component(registry, kind: str, spec: Any, where: str) -> dict:
    instance = registry.build(kind, spec, where)
    return {"name": type(instance).name, **dataclasses.asdict(instance.params)}


def resolve(data: Mapping, origin: str) -> dict:
    """Validate every key of ``data`` and return it with all defaults filled in."""
    registry = get_registry()
    unknown = [k for k in data if k not in TOP_LEVEL]
    if unknown:
        raise ConfigError(f"{origin}: unknown key {shown(unknown[0])}{closest(unknown[0], TOP_LEVEL)}; "
                          f"valid keys: {', '.join(TOP_LEVEL)}")
    missing = [k for k in ("features", "label", "solver") if k not in data]
    if missing:
        raise ConfigError(f"{origin}: missing required key '{missing[0]}'")
    for key in ("name", "description"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise ConfigError(f"{origin}: {key}: expected a string, got {shown(data[key])}")
    out: dict[str, Any] = {"name": data.get("name") or Path(origin).stem}
    if data.get("description"):
        out["description"] = str(data["description"])
    tracker = parse_params(TrackerParams, data.get("tracker"), f"{origin}: tracker")
    out["tracker"] = dataclasses.asdict(tracker)
    features = data["features"]
    if not isinstance(features, list) or not features:
        raise ConfigError(f"{origin}: features must be a non-empty list, e.g. [{{name: fhog}}]")
    out["features"] = [_component(registry, "feature", f, f"{origin}: features[{i}]") for i, f in enumerate(features)]
    out["label"] = _component(registry, "label", data["label"], f"{origin}: label")
    regs = data.get("regularizers")
    regs = {} if regs is None else regs  # not `or {}`: [], '' or false stood for "none" unnoticed
    if not isinstance(regs, Mapping):
        raise ConfigError(f"{origin}: regularizers: expected a mapping of roles ({', '.join(REGULARIZER_ROLES)}) to "
                          f"components, got {shown(regs)} (null: none; regularizers.temporal: null drops one role)")
    out["regularizers"] = {}
    for role in regs:
        if role not in REGULARIZER_ROLES:
            raise ConfigError(f"{origin}: regularizers.{clip(str(role))}: unknown role"
                              f"{closest(role, REGULARIZER_ROLES)}; valid: {', '.join(REGULARIZER_ROLES)}")
    for role in REGULARIZER_ROLES:
        spec = regs.get(role)
        if spec is None:
            out["regularizers"][role] = None
            continue
        where = f"{origin}: regularizers.{role}"
        resolved = _component(registry, "regularizer", spec, where)
        cls = registry.entry("regularizer", resolved["name"]).cls
        if getattr(cls, "role", None) != role:
            valid = [n for n in registry.names("regularizer")
                     if getattr(registry.entry("regularizer", n).cls, "role", None) == role]
            raise ConfigError(f"{where}: '{resolved['name']}' is a {getattr(cls, 'role', '?')} regularizer; "
                              f"{role} ones: {', '.join(valid)}")
        out["regularizers"][role] = resolved
    out["solver"] = _component(registry, "solver", data["solver"], f"{origin}: solver")
    out["search"] = _component(registry, "search", data.get("search", "fixed"), f"{origin}: search")
    out["scale"] = _component(registry, "scale", data.get("scale", "pyramid"), f"{origin}: scale")
    return out

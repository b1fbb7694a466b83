"""The one table of a config's component slots (:data:`SLOTS`), and what reads it.

A :class:`Slot` says where a config names components, of which kind, one or a list, required
or else what an absent slot takes. Config resolution (:func:`resolve`: each spec checked, no
component built), the tracker (:func:`build`: each component built once), provenance
(:func:`components`), ``dcfkit components`` and docs/configs.md all read this table.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Mapping

from dcfkit.components.base import Component
from dcfkit.config.tracker_params import TrackerParams
from dcfkit.errors import ConfigError, clip, shown
from dcfkit.params import closest, parse_params
from dcfkit.registry import Registry, get_registry


@dataclasses.dataclass(frozen=True)
class Slot:
    """``name``: the tracker's attribute holding what is built; ``kind``: of its components;
    ``key``: where a config gives them (``label``, or ``regularizers.spatial``: one role of a
    group, whose component's ``role`` must match); ``many``: a non-empty list of them;
    ``required``, or ``default``: the component an absent slot takes (None: none);
    ``help``: its line in docs/configs.md."""

    name: str
    kind: str
    key: str
    many: bool = False
    required: bool = False
    default: str | None = None
    help: str = ""

    @property
    def top(self) -> str:
        """The config's top-level key holding the slot."""
        return self.key.partition(".")[0]

    @property
    def role(self) -> str | None:
        """The slot's role in its group (``spatial`` of ``regularizers.spatial``), or None."""
        return self.key.partition(".")[2] or None


SLOTS = (
    Slot("features", "feature", "features", many=True, required=True,
         help="a list of one or more features, their channels stacked"),
    Slot("label", "label", "label", required=True, help="the regression target"),
    Slot("spatial", "regularizer", "regularizers.spatial"),
    Slot("temporal", "regularizer", "regularizers.temporal"),
    Slot("solver", "solver", "solver", required=True, help="how the filter is trained"),
    Slot("search", "search", "search", default="fixed", help="where the next frame is searched"),
    Slot("scale_estimator", "scale", "scale", default="pyramid", help="how the scale is estimated"),
    Slot("memory", "memory", "memory", help="the training samples kept and their weights (absent: none; "
         "the continuous loop's solvers need one)"),
    Slot("schedule", "schedule", "schedule", help="on which frames the filter is trained (absent: every frame)"),
    Slot("mask", "mask", "mask", help="a spatial mask learnt each frame, outside which the filter is zero"),
    Slot("channel_weights", "channel_weights", "channel_weights",
         help="how much each feature channel's response counts at detection"),
    Slot("reliability", "reliability", "reliability", help="how sure each detection is (its score is the presence "
         "score written per frame; absent: the response's peak, nothing judged)"),
    Slot("redetect", "redetect", "redetect", help="where to search on a frame the reliability component judges "
         "lost, and which candidate to take (needs reliability)"),
)

KINDS = tuple(dict.fromkeys(s.kind for s in SLOTS))  # the kinds of the components the slots take

TOP_LEVEL = ("name", "description", "base", "tracker") + tuple(dict.fromkeys(s.top for s in SLOTS))


def roles(group: str) -> tuple[str, ...]:
    """The roles of a group of slots (``regularizers``: spatial, temporal)."""
    return tuple(s.role for s in SLOTS if s.top == group and s.role is not None)


def specs(slot: Slot, config: Mapping) -> list:
    """The specs ``slot`` holds in a resolved ``config`` (none where it holds none)."""
    value = config.get(slot.top)
    if slot.role is not None:
        value = value.get(slot.role) if isinstance(value, Mapping) else None
    if slot.many:
        return list(value) if isinstance(value, (list, tuple)) else []
    return [] if value is None else [value]


def components(config: Mapping) -> list[tuple[str, str]]:
    """The ``(kind, name)`` of every component a resolved config uses."""
    return [(slot.kind, spec["name"]) for slot in SLOTS for spec in specs(slot, config)
            if isinstance(spec, Mapping) and isinstance(spec.get("name"), str)]


def build(slot: Slot, registry: Registry, config: Mapping, tracker: str) -> list[Component] | Component | None:
    """What ``slot`` holds in the resolved ``config`` of ``tracker``, each component built once:
    a list (``many``), one, or None (an absent role)."""
    where, found = f"{tracker}: {slot.key}", specs(slot, config)
    if not found and slot.role is None and (slot.required or slot.default is not None):
        raise ConfigError(f"{where}: missing (a Tracker takes a config that dcfkit.load_config resolved)")
    if slot.many:
        return [registry.build(slot.kind, spec, f"{where}[{i}]") for i, spec in enumerate(found)]
    return registry.build(slot.kind, found[0], where) if found else None


def _spec(registry: Registry, slot: Slot, raw: Any, where: str) -> dict:
    """``raw`` resolved: its component's name and every parameter, checked, nothing built."""
    entry, params = registry.resolve(slot.kind, raw, where)
    role = getattr(entry.cls, "role", None)
    if slot.role is not None and role != slot.role:
        valid = [n for n in registry.names(slot.kind) if getattr(registry.entry(slot.kind, n).cls, "role", None)
                 == slot.role]
        raise ConfigError(f"{where}: '{entry.cls.name}' is a {role or '?'} {slot.kind}; "
                          f"{slot.role} ones: {', '.join(valid)}")
    return {"name": entry.cls.name, **dataclasses.asdict(params)}


def _group(data: Mapping, group: str, origin: str) -> Mapping:
    """The roles a config gives ``group`` (``regularizers``), checked."""
    valid = roles(group)
    given = data.get(group)
    given = {} if given is None else given  # not `or {}`: [], '' or false stood for "none" unnoticed
    if not isinstance(given, Mapping):
        raise ConfigError(f"{origin}: {group}: expected a mapping of roles ({', '.join(valid)}) to components, "
                          f"got {shown(given)} (null: none; {group}.{valid[-1]}: null drops one role)")
    for role in given:
        if role not in valid:
            raise ConfigError(f"{origin}: {group}.{clip(str(role))}: unknown role{closest(role, valid)}; "
                              f"valid: {', '.join(valid)}")
    return given


def _resolve_slot(registry: Registry, slot: Slot, data: Mapping, origin: str) -> list | dict | None:
    """The resolved spec of ``slot`` in ``data``: a list (``many``), one, or None (no role given)."""
    where = f"{origin}: {slot.key}"
    if slot.role is not None:
        raw = _group(data, slot.top, origin).get(slot.role)
        return None if raw is None else _spec(registry, slot, raw, where)
    raw = data.get(slot.key, slot.default)
    if raw is None and not slot.required and slot.default is None:  # an optional slot left empty
        return None
    if not slot.many:
        return _spec(registry, slot, raw, where)
    if not isinstance(raw, list) or not raw:
        raise ConfigError(f"{where} must be a non-empty list, e.g. [{{name: NAME}}]; {slot.kind}s: "
                          f"{', '.join(registry.names(slot.kind))}")
    return [_spec(registry, slot, spec, f"{where}[{i}]") for i, spec in enumerate(raw)]


def resolve(data: Mapping, origin: str) -> dict:
    """Validate every key of ``data`` and return it with all defaults filled in."""
    registry = get_registry()
    unknown = [k for k in data if k not in TOP_LEVEL]
    if unknown:
        raise ConfigError(f"{origin}: unknown key {shown(unknown[0])}{closest(unknown[0], TOP_LEVEL)}; "
                          f"valid keys: {', '.join(TOP_LEVEL)}")
    missing = [s.key for s in SLOTS if s.required and s.key not in data]
    if missing:
        raise ConfigError(f"{origin}: missing required key '{missing[0]}'")
    for key in ("name", "description"):
        if data.get(key) is not None and not isinstance(data[key], str):
            raise ConfigError(f"{origin}: {key}: expected a string, got {shown(data[key])}")
    out: dict[str, Any] = {"name": data.get("name") or Path(origin).stem}
    if data.get("description"):
        out["description"] = str(data["description"])
    out["tracker"] = dataclasses.asdict(parse_params(TrackerParams, data.get("tracker"), f"{origin}: tracker"))
    for slot in SLOTS:
        spec = _resolve_slot(registry, slot, data, origin)
        if spec is None and slot.role is None:  # an optional slot left empty: absent, as configs before it
            continue
        if slot.role is None:
            if spec is not None or slot.required or slot.default is not None:  # an empty optional slot: no key
                out[slot.key] = spec
        else:
            out.setdefault(slot.top, {})[slot.role] = spec
    return out

"""Component registry over pluggy.

Every component, built-in or third-party, is registered through one hook,
``dcfkit_register_components(registry)``, in which a plugin calls
``registry.register(SomeComponent)``. Built-ins live in :mod:`dcfkit.builtin` and are
registered exactly like plugins found through the ``dcfkit`` entry-point group.
Set ``DCFKIT_DISABLE_PLUGINS=1`` to load built-ins only. Nothing happens at import time:
the registry is built on first use of :func:`get_registry`.
"""
from __future__ import annotations

import dataclasses
import importlib
import importlib.metadata
import os
import warnings
from typing import Any, Mapping

import pluggy

from .errors import RegistryError
from .params import NoParams, closest, parse_params

PROJECT = "dcfkit"
KINDS = ("feature", "label", "regularizer", "solver", "search", "scale")
DISABLE_ENV = "DCFKIT_DISABLE_PLUGINS"

hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


class HookSpecs:
    @hookspec
    def dcfkit_register_components(self, registry: "Registry") -> None:
        """Register components by calling ``registry.register(cls)`` for each."""


class Component:
    """Base of all components: a ``kind``, a ``name`` and a ``Params`` schema."""

    kind: str = ""
    name: str = ""
    Params: type = NoParams

    def __init__(self, params: Any = None):
        self.params = params if params is not None else self.Params()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.params})"


@dataclasses.dataclass(frozen=True)
class Entry:
    cls: type
    provider: str


class Registry:
    """Component classes by (kind, name), with the plugin that provided each."""

    def __init__(self):
        self._entries: dict[str, dict[str, Entry]] = {k: {} for k in KINDS}
        self._provider = "?"
        self.failures: list[str] = []

    def register(self, cls: type) -> type:
        """Register a component class; its ``kind`` and ``name`` must be set and new."""
        kind, name = getattr(cls, "kind", ""), getattr(cls, "name", "")
        if kind not in KINDS:
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): kind {kind!r} is not one of "
                                f"{', '.join(KINDS)}")
        if not name or not isinstance(name, str):
            raise RegistryError(f"{cls.__qualname__} (from {self._provider}): component has no name")
        if not dataclasses.is_dataclass(cls.Params):
            raise RegistryError(f"{kind} '{name}' (from {self._provider}): Params must be a dataclass")
        existing = self._entries[kind].get(name)
        if existing is not None:
            raise RegistryError(f"{kind} '{name}' from {self._provider} is already registered by "
                                f"{existing.provider}")
        self._entries[kind][name] = Entry(cls, self._provider)
        return cls

    def names(self, kind: str) -> list[str]:
        return sorted(self._check_kind(kind))

    def entry(self, kind: str, name: str) -> Entry:
        entries = self._check_kind(kind)
        if name not in entries:
            skipped = f"; skipped plugins: {' | '.join(self.failures)}" if self.failures else ""
            raise RegistryError(f"unknown {kind} '{name}'{closest(name, entries)}; "
                                f"registered {kind}s: {', '.join(sorted(entries)) or 'none'}{skipped}")
        return entries[name]

    def build(self, kind: str, spec: Mapping[str, Any] | str, where: str) -> Component:
        """Instantiate a component from ``{'name': ..., **params}`` (or a bare name)."""
        if isinstance(spec, str):
            spec = {"name": spec}
        if not isinstance(spec, Mapping) or not isinstance(spec.get("name"), str):
            raise RegistryError(f"{where}: expected a mapping with a 'name' key "
                                f"(one of {', '.join(self.names(kind))}), got {spec!r}")
        values = dict(spec)
        name = values.pop("name")
        try:
            cls = self.entry(kind, name).cls
        except RegistryError as exc:
            raise RegistryError(f"{where}.name: {exc}") from None
        return cls(parse_params(cls.Params, values, f"{where} ({kind} '{name}')"))

    def _check_kind(self, kind: str) -> dict[str, Entry]:
        if kind not in self._entries:
            raise RegistryError(f"unknown component kind {kind!r}{closest(kind, KINDS)}; kinds: {', '.join(KINDS)}")
        return self._entries[kind]

    def _run_plugin(self, pm: pluggy.PluginManager, plugin: Any, provider: str) -> None:
        """Register one plugin's components; on failure undo them and remember why."""
        before = {k: dict(v) for k, v in self._entries.items()}
        self._provider = provider
        try:
            pm.register(plugin, name=provider)
            pm.check_pending()  # catches misspelt hook names
            others = [p for p in pm.get_plugins() if p is not plugin]
            pm.subset_hook_caller("dcfkit_register_components", remove_plugins=others)(registry=self)
        except Exception as exc:  # a broken plugin must not break dcfkit
            self._entries = before
            if pm.is_registered(plugin):
                pm.unregister(plugin)
            message = f"dcfkit plugin '{provider}' failed and was skipped: {exc}"
            self.failures.append(message)
            warnings.warn(message, RuntimeWarning, stacklevel=3)
        finally:
            self._provider = "?"


_REGISTRY: Registry | None = None


def plugins_disabled() -> bool:
    return os.environ.get(DISABLE_ENV, "").strip().lower() not in ("", "0", "false", "no")


def get_registry() -> Registry:
    """The process-wide registry, built on first call."""
    global _REGISTRY
    if _REGISTRY is None:
        _REGISTRY = build_registry(external=not plugins_disabled())
    return _REGISTRY


def build_registry(external: bool = True) -> Registry:
    """Build a fresh registry: built-ins, then every ``dcfkit`` entry point (if ``external``)."""
    pm = pluggy.PluginManager(PROJECT)
    pm.add_hookspecs(HookSpecs)
    registry = Registry()
    registry._run_plugin(pm, importlib.import_module("dcfkit.builtin"), "dcfkit")
    if external:
        for ep in sorted(importlib.metadata.entry_points(group=PROJECT), key=lambda e: e.name):
            if ep.value.split(":")[0] == "dcfkit.builtin":
                continue
            provider = f"{ep.name} ({ep.value})"
            try:
                plugin = ep.load()
            except Exception as exc:
                message = f"dcfkit plugin '{provider}' could not be imported and was skipped: {exc!r}"
                registry.failures.append(message)
                warnings.warn(message, RuntimeWarning, stacklevel=2)
                continue
            registry._run_plugin(pm, plugin, provider)
    return registry

"""The registry of benchmark layouts: what :func:`load_dataset` and :func:`detect_dataset` know.

Each layout registers its name (and aliases), its loader ``(root, sequences=None) ->
list[Sequence]``, a one-line description of its folders (shown in error messages) and a
``detect(root)`` that says how specifically ``root`` looks like it. The built-in layouts
register themselves when :mod:`dcfkit.datasets` is imported, and a script calls
:func:`register_layout` the same way. A plugin package registers its layouts in its dcfkit
hook with ``registry.register_dataset(...)`` (:mod:`dcfkit.registry`, docs/plugins.md);
they are looked up after these, the plugins loaded on first need.
"""
from __future__ import annotations

import contextlib
import dataclasses
import enum
import warnings
from pathlib import Path
from typing import Callable, Iterable, Iterator, Mapping

from ..errors import RegistryError, describe_error, shown
from ..protocols import DEFAULT, PROTOCOLS
from ..registry import PluginWarning, get_registry
from .base import DatasetError, Sequence, require_root

Loader = Callable[..., list[Sequence]]  # (root, sequences=None) -> list[Sequence]
Detector = Callable[[Path], int]  # root -> Evidence (or bool)


class Evidence(enum.IntEnum):
    """How specifically a folder looks like one layout; detection picks the most specific.

    ``detect`` may also return a bool: True counts as :attr:`FOLDERS`.
    """

    NONE = 0
    FOLDERS = 1  # the folder structure fits, and other benchmarks share it
    FILES = 2  # file names or counts fit this benchmark
    NAME = 3  # a folder is named after this benchmark


# How the candidates fit, in the error when several fit equally well (not read from docstrings,
# which python -OO strips).
_EVIDENCE_TEXT = {
    Evidence.FOLDERS: "by the folder structure only",
    Evidence.FILES: "by file names or counts",
    Evidence.NAME: "by folder names",
}


@dataclasses.dataclass(frozen=True)
class Layout:
    """One registered benchmark layout (see :func:`register_layout`)."""

    name: str
    load: Loader
    description: str
    detect: Detector | None = None
    aliases: tuple[str, ...] = ()
    provider: str = ""  # the plugin that registered it; "" for dcfkit's and those registered in code
    protocol: str = ""  # the scoring protocol of the benchmark's own toolkit; "" for the OTB toolkit's

    def __str__(self) -> str:
        also = f" (also {', '.join(self.aliases)})" if self.aliases else ""
        source = f" [plugin {self.provider}]" if self.provider else ""
        return f"{self.name}{also}: {self.description}{source}"


_LAYOUTS: dict[str, Layout] = {}  # canonical name -> layout, in registration order
_NAMES: dict[str, str] = {}  # every name and alias -> canonical name


def _key(name: str) -> str:
    """The one spelling of a name: case-insensitive, and ``-`` read as ``_`` (``uav123-20l``)."""
    return str(name).strip().lower().replace("-", "_")


def register_layout(name: str, load: Loader, description: str, *,
                    detect: Detector | None = None, aliases: Iterable[str] = (), protocol: str = "") -> Layout:
    """Make ``name`` and its ``aliases`` loadable by :func:`load_dataset` (case-insensitive, ``-``
    read as ``_``).

    ``load(root, sequences=None)`` returns the :class:`Sequence` list; ``description`` is
    one line saying what is on disk (``ROOT/<seq>/img/%05d.jpg, ...``); ``detect(root)``
    returns an :class:`Evidence` (or a bool) for :func:`detect_dataset`, which skips layouts
    without one. ``protocol`` names the scoring protocol of the toolkit that published the
    benchmark's tables (:mod:`dcfkit.protocols`), which scores its sequences unless
    ``--protocol`` says otherwise; by default the OTB toolkit's. A name or alias that is
    already registered is a :class:`RegistryError`.
    """
    layout = new_layout(name, load, description, detect=detect, aliases=aliases, protocol=protocol)
    _LAYOUTS[layout.name] = layout
    _NAMES.update(dict.fromkeys((layout.name,) + layout.aliases, layout.name))
    return layout


def new_layout(name: str, load: Loader, description: str, *, detect: Detector | None = None,
               aliases: Iterable[str] = (), provider: str = "", protocol: str = "") -> Layout:
    """A checked :class:`Layout`, not yet registered (:func:`register_layout` registers it here, a
    plugin's ``registry.register_dataset`` in :mod:`dcfkit.registry`); a :class:`RegistryError`
    if it is malformed or a name is taken here."""
    layout = Layout(_key(name), load, str(description).strip(), detect,
                    tuple(dict.fromkeys(_key(a) for a in aliases if _key(a) != _key(name))), provider,
                    str(protocol or ""))
    _check_new_layout(layout)
    return layout


def _check_new_layout(layout: Layout) -> None:
    where = f"dataset layout {layout.name!r}" + (f" (from {layout.provider})" if layout.provider else "")
    if not layout.name:
        raise RegistryError(f"dataset layout {shown(layout.description)}: the name is empty")
    if "auto" in (layout.name,) + layout.aliases:
        raise RegistryError(f"{where}: 'auto' cannot be a name: load_dataset('auto', root) detects the dataset")
    for taken in (n for n in (layout.name,) + layout.aliases if n in _NAMES):
        owner = _NAMES[taken]
        also = "" if owner == taken else f" (as a name of {owner!r})"
        fix = "give the plugin's layout another name" if layout.provider else \
            f"unregister_layout({owner!r}) first to replace it"
        raise RegistryError(f"{where}: the name {taken!r} is already registered{also}; {fix}")
    if not callable(layout.load) or not (layout.detect is None or callable(layout.detect)):
        raise RegistryError(f"{where}: load and detect must be functions")
    if layout.protocol and layout.protocol not in PROTOCOLS:
        raise RegistryError(f"{where}: unknown protocol {shown(layout.protocol)}; protocols: {', '.join(PROTOCOLS)}")
    if not layout.description or "\n" in layout.description:
        raise RegistryError(f"{where}: the description must be one non-empty line, "
                            f"got {shown(layout.description)}")


def unregister_layout(name: str) -> Layout:
    """Remove the layout called ``name`` (or one of its aliases) with all its names; a plugin's
    cannot be (uninstall the plugin, or set DCFKIT_DISABLE_PLUGINS)."""
    if _key(name) not in _NAMES:
        raise DatasetError(f"no dataset layout {shown(name)} registered in code; layouts: {', '.join(_LAYOUTS)}")
    layout = _LAYOUTS.pop(_NAMES[_key(name)])
    for n in (layout.name,) + layout.aliases:
        del _NAMES[n]
    return layout


@contextlib.contextmanager
def registered_layout(name: str, load: Loader, description: str, *,
                      detect: Detector | None = None, aliases: Iterable[str] = (),
                      protocol: str = "") -> Iterator[Layout]:
    """:func:`register_layout` for the duration of a ``with`` block (tests, experiments)."""
    layout = register_layout(name, load, description, detect=detect, aliases=aliases, protocol=protocol)
    try:
        yield layout
    finally:
        unregister_layout(layout.name)


def layouts() -> tuple[Layout, ...]:
    """Every registered layout: dcfkit's and those registered in code, in registration order,
    then the plugins' (one whose name was since registered in code is shadowed by it)."""
    return tuple(_LAYOUTS.values()) + tuple(p for p in get_registry().datasets() if p.name not in _NAMES)


def _find(name: str) -> Layout | None:
    """The layout called ``name`` (or an alias): one registered here first, then a plugin's;
    None if there is none; a RegistryError if two plugins register the name."""
    key = _key(name)
    if key in _NAMES:
        return _LAYOUTS[_NAMES[key]]
    return get_registry().dataset(key)


class _Loaders(Mapping):
    """Canonical name -> loader of every registered layout; read-only, always current."""

    def __getitem__(self, name: str) -> Loader:
        return {layout.name: layout for layout in layouts()}[name].load

    def __iter__(self) -> Iterator[str]:
        return iter([layout.name for layout in layouts()])

    def __len__(self) -> int:
        return len(layouts())

    def __repr__(self) -> str:
        return f"DATASETS({', '.join(self)})"


DATASETS: Mapping[str, Loader] = _Loaders()


# --------------------------------------------------------------------------- lookup and loading


def _known_layouts() -> str:
    return "\n".join(f"  {layout}" for layout in layouts())


def canonical_name(name: str) -> str:
    """Canonical dataset name for ``name`` (case-insensitive, ``-``/``@`` accepted)."""
    return get_layout(name).name


def get_layout(name: str) -> Layout:
    """The layout registered as ``name`` or an alias; :class:`DatasetError` listing them otherwise
    (and the plugins that were skipped, whose layouts may be the one meant)."""
    found = _find(name)
    if found is None:
        failures = get_registry().failures
        skipped = f"\nSkipped plugins: {' | '.join(failures)}" if failures else ""
        raise DatasetError(f"unknown dataset {shown(name)}; valid names: {', '.join(DATASETS)} "
                           f"(case-insensitive). Their layouts:\n{_known_layouts()}{skipped}")
    return found


def load_dataset(name: str | None, root, sequences: Iterable[str] | str | None = None) -> list[Sequence]:
    """Sequences of dataset ``name`` under ``root`` (all present ones, or those named).

    ``name`` is case-insensitive; ``None`` or ``"auto"`` uses :func:`detect_dataset`.
    ``sequences`` may be a list of names or one comma-separated string.
    """
    if name is None or str(name).lower() == "auto":
        name = detect_dataset(root)
    layout = get_layout(name)
    loaded = layout.load(root, sequences)
    if not loaded:
        raise DatasetError(f"no {layout.name} sequences under {root}; expected {layout.description}")
    return loaded


def detect_dataset(root) -> str:
    """The dataset whose layout ``root`` fits most specifically; :class:`DatasetError` when
    none fits or several fit equally well (the message lists them: pass the name instead)."""
    root = require_root(root, "dataset")
    known = {layout.name: layout for layout in layouts()}
    evidence = {name: _evidence(layout, root) for name, layout in known.items() if layout.detect is not None}
    best = max(evidence.values(), default=Evidence.NONE)
    if best == Evidence.NONE:
        raise DatasetError(f"no known benchmark layout under {root}; expected one of:\n{_known_layouts()}")
    found = [name for name, level in evidence.items() if level == best]
    if len(found) > 1:
        candidates = "\n".join(f"  {known[name]}" for name in found)
        raise DatasetError(
            f"cannot tell which dataset {root} holds: {', '.join(found)} fit equally well "
            f"({_EVIDENCE_TEXT[best]}); pass the dataset name ({' or '.join(found)}). "
            f"Their layouts:\n{candidates}")
    return found[0]


def _evidence(layout: Layout, root: Path) -> Evidence:
    try:
        level = layout.detect(root)
    except Exception as exc:  # a plugin's bug must not stop detection of every other benchmark
        if not layout.provider:
            raise
        warnings.warn(f"dataset layout {layout.name!r} of dcfkit plugin '{layout.provider}' was left out of "
                      f"detection: detect({root}) raised {describe_error(exc)}", PluginWarning, stacklevel=3)
        return Evidence.NONE
    try:
        return Evidence(int(level))
    except (TypeError, ValueError):
        raise RegistryError(f"dataset layout {layout.name!r}: detect({root}) returned {shown(level)}, "
                            f"not an Evidence level (0..{int(Evidence.NAME)}) or a bool") from None


def benchmark_protocol(sequences: Iterable[Sequence]) -> str:
    """The protocol that scored the published tables of the benchmark ``sequences`` come from:
    their layout's ``protocol`` (LaSOT's toolkit for LaSOT, GOT-10k's for GOT-10k), else the
    OTB toolkit's (:data:`dcfkit.protocols.DEFAULT`), also for sequences of several benchmarks
    that disagree."""
    found = set()
    for name in {s.dataset for s in sequences}:
        layout = _find(name) if name else None
        found.add(layout.protocol if layout is not None and layout.protocol else DEFAULT)
    return found.pop() if len(found) == 1 else DEFAULT

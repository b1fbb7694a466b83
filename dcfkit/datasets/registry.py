"""The registry of benchmark layouts: what :func:`load_dataset` and :func:`detect_dataset` know.

Each layout registers its name (and aliases), its loader ``(root, sequences=None) ->
list[Sequence]``, a one-line description of its folders (shown in error messages) and a
``detect(root)`` that says how specifically ``root`` looks like it. The built-in layouts
register themselves when :mod:`dcfkit.datasets` is imported; a plugin calls
:func:`register_layout` the same way.
"""
from __future__ import annotations

import contextlib
import dataclasses
import enum
from pathlib import Path
from typing import Callable, Iterable, Iterator, Mapping

from ..errors import RegistryError, shown
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

    def __str__(self) -> str:
        also = f" (also {', '.join(self.aliases)})" if self.aliases else ""
        return f"{self.name}{also}: {self.description}"


_LAYOUTS: dict[str, Layout] = {}  # canonical name -> layout, in registration order
_NAMES: dict[str, str] = {}  # every name and alias -> canonical name


def _key(name: str) -> str:
    """The one spelling of a name: case-insensitive, and ``-`` read as ``_`` (``uav123-20l``)."""
    return str(name).strip().lower().replace("-", "_")


def register_layout(name: str, load: Loader, description: str, *,
                    detect: Detector | None = None, aliases: Iterable[str] = ()) -> Layout:
    """Make ``name`` and its ``aliases`` loadable by :func:`load_dataset` (case-insensitive, ``-``
    read as ``_``).

    ``load(root, sequences=None)`` returns the :class:`Sequence` list; ``description`` is
    one line saying what is on disk (``ROOT/<seq>/img/%05d.jpg, ...``); ``detect(root)``
    returns an :class:`Evidence` (or a bool) for :func:`detect_dataset`, which skips layouts
    without one. A name or alias that is already registered is a :class:`RegistryError`.
    """
    layout = Layout(_key(name), load, str(description).strip(), detect,
                    tuple(dict.fromkeys(_key(a) for a in aliases if _key(a) != _key(name))))
    _check_new_layout(layout)
    _LAYOUTS[layout.name] = layout
    _NAMES.update(dict.fromkeys((layout.name,) + layout.aliases, layout.name))
    return layout


def _check_new_layout(layout: Layout) -> None:
    where = f"dataset layout {layout.name!r}"
    if not layout.name:
        raise RegistryError(f"dataset layout {shown(layout.description)}: the name is empty")
    if "auto" in (layout.name,) + layout.aliases:
        raise RegistryError(f"{where}: 'auto' cannot be a name: load_dataset('auto', root) detects the dataset")
    for taken in (n for n in (layout.name,) + layout.aliases if n in _NAMES):
        owner = _NAMES[taken]
        also = "" if owner == taken else f" (as a name of {owner!r})"
        raise RegistryError(f"{where}: the name {taken!r} is already registered{also}; "
                            f"unregister_layout({owner!r}) first to replace it")
    if not callable(layout.load) or not (layout.detect is None or callable(layout.detect)):
        raise RegistryError(f"{where}: load and detect must be functions")
    if not layout.description or "\n" in layout.description:
        raise RegistryError(f"{where}: the description must be one non-empty line, "
                            f"got {shown(layout.description)}")


def unregister_layout(name: str) -> Layout:
    """Remove the layout called ``name`` (or one of its aliases) with all its names."""
    layout = _LAYOUTS.pop(canonical_name(name))
    for n in (layout.name,) + layout.aliases:
        del _NAMES[n]
    return layout


@contextlib.contextmanager
def registered_layout(name: str, load: Loader, description: str, *,
                      detect: Detector | None = None,
                      aliases: Iterable[str] = ()) -> Iterator[Layout]:
    """:func:`register_layout` for the duration of a ``with`` block (tests, experiments)."""
    layout = register_layout(name, load, description, detect=detect, aliases=aliases)
    try:
        yield layout
    finally:
        unregister_layout(layout.name)


def layouts() -> tuple[Layout, ...]:
    """Every registered layout, in registration order."""
    return tuple(_LAYOUTS.values())


class _Loaders(Mapping):
    """Canonical name -> loader of every registered layout; read-only, always current."""

    def __getitem__(self, name: str) -> Loader:
        return _LAYOUTS[name].load

    def __iter__(self) -> Iterator[str]:
        return iter(_LAYOUTS)

    def __len__(self) -> int:
        return len(_LAYOUTS)

    def __repr__(self) -> str:
        return f"DATASETS({', '.join(_LAYOUTS)})"


DATASETS: Mapping[str, Loader] = _Loaders()


# --------------------------------------------------------------------------- lookup and loading


def _known_layouts() -> str:
    return "\n".join(f"  {layout}" for layout in _LAYOUTS.values())


def canonical_name(name: str) -> str:
    """Canonical dataset name for ``name`` (case-insensitive, ``-``/``@`` accepted)."""
    found = _NAMES.get(_key(name))
    if found is None:
        raise DatasetError(f"unknown dataset {shown(name)}; valid names: {', '.join(_LAYOUTS)} "
                           f"(case-insensitive). Their layouts:\n{_known_layouts()}")
    return found


def get_layout(name: str) -> Layout:
    """The layout registered as ``name`` or an alias; :class:`DatasetError` listing them otherwise."""
    return _LAYOUTS[canonical_name(name)]


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
    evidence = {layout.name: _evidence(layout, root) for layout in _LAYOUTS.values()
                if layout.detect is not None}
    best = max(evidence.values(), default=Evidence.NONE)
    if best == Evidence.NONE:
        raise DatasetError(f"no known benchmark layout under {root}; expected one of:\n{_known_layouts()}")
    found = [name for name, level in evidence.items() if level == best]
    if len(found) > 1:
        candidates = "\n".join(f"  {_LAYOUTS[name]}" for name in found)
        raise DatasetError(
            f"cannot tell which dataset {root} holds: {', '.join(found)} fit equally well "
            f"({_EVIDENCE_TEXT[best]}); pass the dataset name ({' or '.join(found)}). "
            f"Their layouts:\n{candidates}")
    return found[0]


def _evidence(layout: Layout, root: Path) -> Evidence:
    level = layout.detect(root)
    try:
        return Evidence(int(level))
    except (TypeError, ValueError):
        raise RegistryError(f"dataset layout {layout.name!r}: detect({root}) returned {shown(level)}, "
                            f"not an Evidence level (0..{int(Evidence.NAME)}) or a bool") from None

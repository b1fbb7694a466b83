"""A benchmark layout: its names, loader, detector and protocol, checked when it is registered.

Built-in layouts register here when :mod:`dcfkit.datasets` is imported, as a script does with
:func:`register_layout`; a plugin's go through ``registry.register_dataset`` (:mod:`dcfkit.registry`),
which makes them with :func:`new_layout`. Lookups are in :mod:`dcfkit.datasets.catalog`.

Every layout's loader is a :class:`CheckedLoader`: the sequences it returns must have names
that are one safe file name each (:func:`sequence_name_problem`) and unique, since results,
exports and reports are files named after them.
"""
from __future__ import annotations

import contextlib
import dataclasses
import enum
import unicodedata
from pathlib import Path
from typing import Callable, Iterable, Iterator

from dcfkit.datasets.base import DatasetError, Sequence
from dcfkit.errors import RegistryError, clip, shown
from dcfkit.protocols import PROTOCOLS

Loader = Callable[..., list[Sequence]]  # (root, sequences=None) -> list[Sequence]
#: Unicode categories no name may hold: controls (line breaks, tab, NUL), format characters,
#: line and paragraph separators, surrogates (bytes that were not UTF-8), unassigned code points;
#: a no-break or ideographic space is a name's own (str.isprintable refuses those too)
UNPRINTABLE = frozenset({"Cc", "Cf", "Zl", "Zp", "Cs", "Cn"})
NAME_BYTES = 200  # the longest sequence name in UTF-8: a result's file name adds 30 bytes, a file name holds 255
Detector = Callable[[Path], int]  # root -> Evidence (or bool)


class Evidence(enum.IntEnum):
    """How specifically a folder looks like one layout; detection picks the most specific.

    ``detect`` may also return a bool: True counts as :attr:`FOLDERS`.
    """

    NONE = 0
    FOLDERS = 1  # the folder structure fits, and other benchmarks share it
    FILES = 2  # file names or counts fit this benchmark
    NAME = 3  # a folder is named after this benchmark


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


def layout_key(name: str) -> str:
    """The one spelling of a name: case-insensitive, and ``-`` read as ``_`` (``uav123-20l``)."""
    return str(name).strip().lower().replace("-", "_")


def layouts_in_code() -> tuple[Layout, ...]:
    """The layouts registered in code (dcfkit's own first), in registration order."""
    return tuple(_LAYOUTS.values())


def layout_in_code(name: str) -> Layout | None:
    """The layout registered in code as ``name`` or one of its aliases, or None."""
    key = layout_key(name)
    return _LAYOUTS[_NAMES[key]] if key in _NAMES else None


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
    layout = Layout(layout_key(name), load, str(description).strip(), detect,
                    tuple(dict.fromkeys(layout_key(a) for a in aliases if layout_key(a) != layout_key(name))), provider,
                    str(protocol or ""))
    _check_new_layout(layout)
    return dataclasses.replace(layout, load=CheckedLoader(load, _where(layout)))


def _where(layout: Layout) -> str:
    return f"dataset layout {layout.name!r}" + (f" (from {layout.provider})" if layout.provider else "")


def _escaped(text: str) -> str:
    """``text`` with the bytes of a name that is not UTF-8 (Python's surrogate escapes) shown as
    ``\\xff``: printable and writable whatever the terminal's encoding."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def _shown_name(name) -> str:
    """``name`` as :func:`shown` shows it, a name that is not UTF-8 as its bytes (``b'seq\\xff'``)."""
    try:
        name.encode("utf-8")
    except (AttributeError, UnicodeEncodeError):
        return shown(name.encode("utf-8", "surrogateescape") if isinstance(name, str) else name)
    return shown(name)


def sequence_name_problem(name) -> str | None:
    """Why ``name`` cannot name a sequence, or None: it must be one file name on every system
    (not empty, no leading ``.``; no ``/``, ``\\`` or ``:``), UTF-8, printable (no line break,
    tab or NUL), without spaces at either end (list files strip them) and at most
    :data:`NAME_BYTES` bytes long."""
    if not isinstance(name, str):
        return f"is a {type(name).__name__}, not a string"
    try:
        size = len(name.encode("utf-8"))
    except UnicodeEncodeError:
        return "is not valid UTF-8 (its bytes are shown escaped): rename its folder or files to a UTF-8 name"
    if name in ("", ".", ".."):
        return "is not a file name"
    if any(c in name for c in "/\\:"):
        return "holds / \\ or :, which would make its result files' path leave the results folder"
    if name.startswith("."):
        return "starts with '.', which hides its files and is how dcfkit names files in progress"
    if any(unicodedata.category(c) in UNPRINTABLE for c in name):  # isprintable() refuses a no-break space too
        return "holds a line break, tab, NUL or other unprintable character"
    if name != name.strip():
        return "starts or ends with a space, which list files drop"
    if size > NAME_BYTES:
        return f"is {size} bytes long in UTF-8; at most {NAME_BYTES} leave room for its result files' endings"
    return None


class CheckedLoader:
    """A layout's loader as dcfkit calls it: the original, then a check of what it returned, a
    list of :class:`Sequence` with unique, safe names (:func:`sequence_name_problem`); a
    :class:`DatasetError` naming the layout and the sequence otherwise."""

    def __init__(self, original: Loader, where: str):
        self.original, self.where = original, where

    def __call__(self, *args, **kwargs) -> list[Sequence]:
        loaded = self.original(*args, **kwargs)
        if not isinstance(loaded, (list, tuple)) or not all(isinstance(s, Sequence) for s in loaded):
            raise DatasetError(f"{self.where}: load() returned {shown(loaded)}, expected a list of "
                               f"dcfkit.datasets.Sequence")
        seen: dict[str, str] = {}
        for seq in loaded:
            problem = sequence_name_problem(seq.name)
            if problem is None and seq.name.lower() in seen:
                problem = (f"is also the name of sequence {seen[seq.name.lower()]!r} (names must differ in "
                           f"more than case: their result files would be one on a case-insensitive disk)")
            if problem is not None:
                found = f" ({clip(_escaped(str(seq.annotation)))})" if seq.annotation else ""
                raise DatasetError(f"{self.where}: sequence name {_shown_name(seq.name)}{found} {problem}")
            seen[seq.name.lower()] = seq.name
        return list(loaded)


def _check_new_layout(layout: Layout) -> None:
    where = _where(layout)
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
    if layout_key(name) not in _NAMES:
        raise DatasetError(f"no dataset layout {shown(name)} registered in code; layouts: {', '.join(_LAYOUTS)}")
    layout = _LAYOUTS.pop(_NAMES[layout_key(name)])
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

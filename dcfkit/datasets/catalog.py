"""Finding a benchmark layout: by name for :func:`load_dataset`, by its folders for
:func:`detect_dataset`. Layouts registered in code (:mod:`dcfkit.datasets.layout`) come first,
then the plugins' (``registry.register_dataset``, docs/plugins.md), loaded on first need.
"""
from __future__ import annotations

import warnings
from pathlib import Path
from typing import Iterable, Iterator, Mapping

from dcfkit.datasets.base import DatasetError, Sequence, require_root
from dcfkit.datasets.layout import Evidence, Layout, Loader, layout_in_code, layout_key, layouts_in_code
from dcfkit.errors import RegistryError, describe_error, shown
from dcfkit.protocols import DEFAULT
from dcfkit.registry import PluginWarning, get_registry

# How the candidates fit, in the error when several fit equally well (not read from docstrings,
# which python -OO strips).
_EVIDENCE_TEXT = {
    Evidence.FOLDERS: "by the folder structure only",
    Evidence.FILES: "by file names or counts",
    Evidence.NAME: "by folder names",
}


def layouts() -> tuple[Layout, ...]:
    """Every registered layout: dcfkit's and those registered in code, in registration order,
    then the plugins' (one whose name was since registered in code is shadowed by it)."""
    return layouts_in_code() + tuple(p for p in get_registry().datasets() if layout_in_code(p.name) is None)


def _find(name: str) -> Layout | None:
    """The layout called ``name`` (or an alias): one registered here first, then a plugin's;
    None if there is none; a RegistryError if two plugins register the name."""
    found = layout_in_code(name)
    return found if found is not None else get_registry().dataset(layout_key(name))


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
    OTB toolkit's (:data:`dcfkit.protocols.DEFAULT`). Sequences of benchmarks scored by
    different rules (pooled roots) are a :class:`DatasetError`: the protocol must be named."""
    found: dict[str, list[str]] = {}
    for name in dict.fromkeys(s.dataset for s in sequences):
        layout = _find(name) if name else None
        found.setdefault(layout.protocol if layout is not None and layout.protocol else DEFAULT, []).append(
            name or "unnamed")
    if len(found) > 1:
        rules = "; ".join(f"{', '.join(names)}: {protocol}" for protocol, names in found.items())
        raise DatasetError(f"the sequences come from benchmarks whose tables are scored by different rules ({rules}): "
                           f"name the protocol that scores them all (--protocol, or protocol= in Python)")
    return next(iter(found), DEFAULT)

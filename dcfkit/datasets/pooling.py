"""Several benchmark roots as one set of sequences (``--root A --root B``), scored and tested as
one: a table, its means and its paired tests over all their sequences (docs/evaluation.md,
'Pooling datasets')."""
from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Iterable

from dcfkit.datasets.base import DatasetError, Sequence, select_sequences
from dcfkit.datasets.catalog import load_dataset
from dcfkit.datasets.images import DatasetWarning
from dcfkit.errors import clip

AUTO = "auto"


def _as_list(value) -> list:
    if value is None:
        return []
    return [value] if isinstance(value, (str, os.PathLike)) else list(value)


def pair_roots(names, roots, names_option: str = "--dataset", roots_option: str = "--root") -> list[tuple[str, Path]]:
    """(dataset name, root) for each root: ``names`` none (detect each), one (for every root), or
    one per root in the same order; a :class:`DatasetError` naming both options otherwise. A root
    given twice counts once, with a :class:`DatasetWarning` (its sequences would count twice)."""
    names, roots = [str(n) for n in _as_list(names)], [Path(r).expanduser() for r in _as_list(roots)]
    if not roots:
        raise DatasetError(f"no {roots_option} given: name the benchmark root folder")
    if len(names) > 1 and len(names) != len(roots):
        raise DatasetError(f"{len(names)} {names_option} for {len(roots)} {roots_option}: give one {names_option} "
                           f"for every root, or one per {roots_option} in the same order (or none: each detected)")
    names = names * len(roots) if len(names) == 1 else names or [AUTO] * len(roots)
    pairs: dict[str, tuple[str, Path]] = {}
    for name, root in zip(names, roots):
        key = os.path.normcase(os.path.realpath(root))
        if key in pairs:
            warnings.warn(f"{roots_option} {clip(str(root))} given more than once: its sequences count once",
                          DatasetWarning, stacklevel=2)
        else:
            pairs[key] = (name, root)
    return list(pairs.values())


def load_datasets(names, roots, sequences: Iterable[str] | str | None = None) -> list[Sequence]:
    """The sequences of every root in order (:func:`pair_roots` pairs ``names`` with ``roots``),
    as :func:`~dcfkit.datasets.load_dataset` loads one; one root is exactly that call.

    Results are files named after the sequence (``OUT/<tracker>/<sequence>.txt``), so two roots
    holding a sequence of one name are a :class:`DatasetError` naming both. ``sequences`` (names,
    or one comma-separated string) selects across all roots; a name in none is an error naming
    the roots.
    """
    pairs = pair_roots(names, roots)
    if len(pairs) == 1:
        return load_dataset(*pairs[0], sequences)
    pooled: dict[str, Sequence] = {}
    first: dict[str, tuple[str, Path]] = {}  # lower-case name -> (name, root) that holds it first
    for name, root in pairs:
        for seq in load_dataset(name, root, None):
            # lower case: the two result files would be one on Windows and macOS
            clash, where = first.setdefault(seq.name.lower(), (seq.name, root))
            if where != root:
                raise DatasetError(
                    f"sequence {clash!r} is under two roots, {where} ({pooled[clash].dataset}) and {root} "
                    f"({seq.dataset}): results are named after the sequence (OUT/<tracker>/<sequence>.txt), so "
                    f"pooled sequences need distinct names; leave one of the roots out")
            pooled[seq.name] = seq
    if sequences is None:
        return list(pooled.values())
    where = "the roots " + ", ".join(f"{clip(str(root))} ({name})" for name, root in pairs)
    return [pooled[n] for n in select_sequences(list(pooled), sequences, where)]

"""The one store layout of the commands that make runs: ``OUT/<name>/`` holds a config's runs,
``OUT/<name>/<experiment>/`` but for one pass (``eval``'s tracker folders, ``ablate``'s
variants, ``search``'s trials and baselines; docs/evaluation.md, "Running"), which ``report``,
``compare`` and the toolkits read. A name is a folder ``report`` lists: :func:`folder_problem`
says why one is not, and :func:`folder_names` makes usable, distinct names of labels."""
from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import Iterable

from dcfkit.experiments import Experiment, get_experiment

MAX_NAME_BYTES = 100  # a folder name, in UTF-8: file systems take 255, and the run's file names go inside
_UNSAFE = re.compile(r"\s*[/\\:,]+\s*")  # path separators, a drive's colon, report --trackers' comma


def store_folder(out, name: str, experiment: str | Experiment = "ope") -> Path:
    """Where ``name``'s runs of ``experiment`` go: ``OUT/<name>/``, or ``OUT/<name>/<experiment>/``."""
    sub = get_experiment(experiment).folder
    return Path(out) / name / sub if sub else Path(out) / name


def folder_problem(name: str) -> str | None:
    """Why ``name`` cannot be a folder that ``report`` lists and ``--trackers`` names, or None."""
    if not isinstance(name, str) or not name.strip():
        return "is empty"
    if name.startswith(".") or name != name.strip() or not name.isprintable() or _UNSAFE.search(name):
        return ("must be usable as a folder name that report lists (no / \\ : or comma, no leading dot, no leading "
                "or trailing space, no control character such as a null byte or a line break)")
    if len(name.encode("utf-8")) > MAX_NAME_BYTES:
        return f"is over {MAX_NAME_BYTES} bytes, too long for a folder name"
    return None


def folder_names(labels: Iterable[str], reserved: Iterable[str] = ()) -> dict[str, str]:
    """label -> a distinct folder name (:func:`folder_problem`), case aside as some file systems
    have it: the label itself where it is usable and not ``reserved``; else the label with each
    run of unusable characters as ``_``, cut to fit, and followed by ``-`` and 8 hex digits of
    the label's SHA-256 where that name is taken. The names depend on the set of labels only."""
    labels = list(dict.fromkeys(labels))
    taken = {name.casefold() for name in reserved}
    names = {}
    for label in sorted(labels):  # usable labels first (an unusable one never takes their names), sorted
        if folder_problem(label) is None and label.casefold() not in taken:
            names[label] = label
            taken.add(label.casefold())
    for label in sorted(labels):
        if label in names:
            continue
        name = _usable(label)
        if name.casefold() in taken:
            name = f"{_cut(name, MAX_NAME_BYTES - 9)}-{hashlib.sha256(label.encode('utf-8', 'surrogatepass')).hexdigest()[:8]}"
        names[label] = name
        taken.add(name.casefold())
    return {label: names[label] for label in labels}


def _usable(label: str) -> str:
    """``label`` as a usable folder name: unusable characters as ``_``, no leading dot, cut to fit."""
    text = "".join(c if c.isprintable() else "_" for c in _UNSAFE.sub("_", str(label).strip()))
    return _cut(text.lstrip("."), MAX_NAME_BYTES).strip() or "_"


def _cut(text: str, size: int) -> str:
    """``text`` cut to at most ``size`` UTF-8 bytes, between characters."""
    return text.encode("utf-8", "surrogatepass")[:size].decode("utf-8", "ignore")

"""Published results in an ablation spec: folders of result files scored beside the variants,
never run (``published: {NAME: FOLDER}``, FOLDER relative to the spec)."""
from __future__ import annotations

import logging
from pathlib import Path
from typing import Any, Iterable, Mapping

from dcfkit.analysis.report import read_folder
from dcfkit.datasets import Sequence
from dcfkit.errors import ConfigError, clip, shown
from dcfkit.experiments import get_experiment

log = logging.getLogger(__name__)

STATUS = "published"  # a published entry's status and key in the summary's rows


def parse_published(spec_path: Path, raw: Any, variants: Iterable[str], experiment: str) -> tuple:
    """``((name, folder), ...)`` of the spec's ``published`` mapping, each folder checked to exist."""
    if raw is None:
        return ()
    if not isinstance(raw, Mapping) or not raw:
        raise ConfigError(f"{spec_path}: published: expected a mapping of names to result folders, got {shown(raw)}")
    if get_experiment(experiment).folder:  # runs of their own, which published one-pass results do not have
        raise ConfigError(f"{spec_path}: published: published results are one-pass results; the spec's experiment "
                          f"is {experiment}, whose runs they do not have")
    taken, found = set(variants), []
    for name, folder in raw.items():
        where = f"{spec_path}: published.{clip(str(name))}"
        if not isinstance(name, str) or not name.strip() or not name.isprintable():
            raise ConfigError(f"{spec_path}: published: a name must be printable text, got {shown(name)}")
        if name in taken:
            raise ConfigError(f"{where}: a variant has that name; give the published results another")
        if not isinstance(folder, str) or not folder:
            raise ConfigError(f"{where}: expected a folder of <sequence>.txt result files, got {shown(folder)}")
        path = (spec_path.parent / Path(folder).expanduser()).resolve()
        if not path.is_dir():
            raise ConfigError(f"{where}: {clip(str(path))} is not a folder (relative paths are the spec's)")
        taken.add(name)
        found.append((name, path))
    return tuple(found)


def read_published(published: Iterable[tuple[str, Path]], sequences: list[Sequence]) -> dict[str, dict]:
    """name -> sequence -> result of each published folder (:func:`dcfkit.analysis.report.read_folder`);
    a sequence without a file is said here, and scored as a failure."""
    results = {}
    for name, folder in published:
        results[name] = read_folder(folder, sequences)
        lacking = [s.name for s in sequences if s.name not in results[name]]
        if lacking:
            log.warning("published %r (%s) has no result for %d sequence(s), scored as failures: %s", name, folder,
                        len(lacking), ", ".join(lacking[:10]))
    return results

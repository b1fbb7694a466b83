"""Result files written whole or not at all: atomic writes, locks, and the text formats of
boxes, confidences and times."""
from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import logging
import os
import tempfile
from pathlib import Path
from typing import Iterable

import numpy as np

from dcfkit.errors import DcfkitError, clip

log = logging.getLogger(__name__)


@functools.lru_cache(maxsize=1)
def _file_mode() -> int:
    """The mode open() would give a new file (mkstemp's are owner-only)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


class StoreError(DcfkitError):
    """Results could not be written: the run stops (writing the next run would fail too)."""


def atomic_write(path: Path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` via a temporary file in the same folder + ``os.replace``;
    a :class:`StoreError` naming the file if it cannot be written."""
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as exc:
        raise StoreError(f"cannot write {clip(str(path))}: {exc.strerror}") from None
    try:
        os.fchmod(fd, _file_mode())
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode("utf-8") if isinstance(data, str) else data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise StoreError(f"cannot write {clip(str(path))}: {exc.strerror or exc}") from None
        raise


def make_dir(folder: Path) -> Path:
    """``mkdir -p``, with a :class:`StoreError` naming the folder (e.g. a file is in the way)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise StoreError(f"cannot create the folder {clip(str(folder))}: {exc.strerror}") from None
    return folder


def ensure_writable(folder: Path, names: Iterable[str] = (), what: str = "results") -> None:
    """Create ``folder`` if needed and raise a :class:`StoreError` now, before any work, if it
    cannot take ``what`` (a probe file is written and removed) or if a file to be written
    there, ``folder/<name>``, is a folder."""
    make_dir(folder)
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".write-probe.")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise StoreError(f"cannot write {what} to {clip(str(folder))}: {exc.strerror}") from None
    blocked = [name for name in names if (folder / name).is_dir()]
    if blocked:
        raise StoreError(f"cannot write {what} to {folder}: {', '.join(blocked)} "
                         f"{'is a folder; move it' if len(blocked) == 1 else 'are folders; move them'} away")


def remove_temporary_files(folder: Path, names: Iterable[str]) -> None:
    """Remove what a killed run left of writing ``folder/<name>`` (never read): the
    ``.<name>.<random>.tmp`` files of :func:`atomic_write`, the folder listed once."""
    names = set(names)
    with contextlib.suppress(OSError):
        with os.scandir(folder) as found:
            stale = [entry.path for entry in found if entry.name.startswith(".") and entry.name.endswith(".tmp")
                     and entry.name[1:-4].rpartition(".")[0] in names]
        for path in stale:
            with contextlib.suppress(OSError):
                os.unlink(path)


@contextlib.contextmanager
def exclusive(lock: Path, command: str, what: str):
    """Hold the file lock ``lock`` so two runs never write the same results (released on any
    exit). Where no lock can be taken (not POSIX, a file system without flock) the run goes
    on unlocked, with a warning."""
    try:
        import fcntl  # POSIX only: elsewhere the run goes on unlocked

        handle = open(lock, "a+")
    except (ImportError, OSError) as exc:
        if not isinstance(exc, ImportError):
            log.warning("cannot create the lock %s (%s): running without it", lock, exc.strerror)
        yield
        return
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise DcfkitError(f"another `{command}` is writing {what} (it holds {lock}); "
                              f"wait for it or write elsewhere") from None
        except OSError as exc:
            log.warning("cannot lock %s (%s): running without the lock", lock, exc.strerror)
        yield


def read_json(path: Path) -> dict | None:
    """The JSON object in ``path``, or None if it is missing, unreadable or not an object."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def format_boxes(boxes: np.ndarray, offset: float = 1.0) -> str:
    """0-based ``(N, 4)`` boxes as ``%.3f`` ``x,y,w,h`` lines, ``offset`` added to x and y: 1 for
    the 1-based lines of a result file, 0 for ``dcfkit track --out`` without ``--one-based``."""
    shifted = np.asarray(boxes, dtype=np.float64) + np.array([offset, offset, 0.0, 0.0])
    return "".join("%.3f,%.3f,%.3f,%.3f\n" % tuple(b) for b in shifted)


def format_confidence(confidence: np.ndarray) -> str:
    """``(N, 3)`` ``(peak, apce, score)`` rows (:mod:`dcfkit.tracker.confidence`) as
    ``peak,apce,score`` lines, ``%.6g``; NaN as ``nan``."""
    rows = np.asarray(confidence, dtype=np.float64).reshape(-1, 3)
    return "".join("%.6g,%.6g,%.6g\n" % tuple(row) for row in rows)


def format_times(times: np.ndarray) -> str:
    """Seconds per frame, one ``%.8f`` a line (the OTB and GOT-10k toolkits' ``_time.txt``)."""
    return "".join("%.8f\n" % t for t in np.asarray(times, dtype=np.float64).reshape(-1))


def checksum(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()

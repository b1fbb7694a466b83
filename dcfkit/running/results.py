"""The results store: one folder of per-sequence result files that cannot be silently damaged.

``FOLDER/<sequence>.txt``
    one ``x,y,w,h`` line per frame, ``%.3f``, **1-based** (1 is added to x and y), so the
    MATLAB OTB/UAV123 toolkit and pysot read it unchanged. Frame 1 holds the initial
    ground-truth box; a lost target is ``nan,nan,nan,nan``.
``FOLDER/<sequence>.time``
    tracker seconds per frame, one ``%.8f`` a line (decoding excluded; frame 1 is ``init``),
    as the OTB and GOT-10k toolkits' ``_time.txt`` files hold them.
``FOLDER/<sequence>.confidence``
    one ``peak,apce`` line per frame (:mod:`dcfkit.tracker.confidence`), ``%.6g``; ``nan,nan`` for
    frame 1 (``init``: no response), frames held as blank, and trackers without a confidence.
``FOLDER/<sequence>.json``
    sidecar: the run key (:func:`run_key`), the SHA-256 of the ``.txt`` as written (and of
    the time and confidence files), per-frame tracker seconds, fps, the config, the dcfkit
    and plugin versions. Written last: it marks the sequence as done.
``FOLDER/<sequence>.error``
    instead, when the tracker raised: frame (1-based), error, traceback, as JSON.

Each kind of file has its own ending, and only boxes end in ``.txt``: any sequence name has
files of its own (were ``car``'s time file ``car_time.txt``, it would be the boxes file of a
sequence ``car_time``).

Every file is written to a temporary file in the same folder and moved into place with
``os.replace``. A result is used only when its sidecar is well formed and its ``.txt``
still has the recorded checksum (:meth:`ResultStore.problem`): a file cut short or edited
is never scored by ``report``, ``compare`` or the ablation summary, and ``eval``/``ablate``
recompute it (they also require the run key of the config they run). Every write failure
is a :class:`StoreError` naming the file.
"""
from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import functools
import glob
import hashlib
import json
import logging
import os
import platform
import re
import shlex
import sys
import tempfile
import traceback
from datetime import datetime, timezone
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from dcfkit import __version__
from dcfkit.config.slots import components
from dcfkit.datasets import DatasetError, Sequence, read_boxes
from dcfkit.errors import DcfkitError, clip, shown
from dcfkit.running.platforms import cpu_model
from dcfkit.registry import get_registry

log = logging.getLogger(__name__)

LABEL_KEYS = ("name", "description")  # config keys that never change a box
# the endings of a sequence's files in a store; none is an ending of another
BOXES_END, SIDECAR_END, ERROR_END, TIME_END, CONFIDENCE_END = ".txt", ".json", ".error", ".time", ".confidence"
TOOLKIT_TIME_SUFFIX, TOOLKIT_CONFIDENCE_SUFFIX = "_time", "_confidence"  # <sequence>_time.txt, as toolkits write


# --------------------------------------------------------------------------- identity


def dcfkit_version() -> str:
    """``dcfkit.__version__`` (part of every run key)."""
    return __version__


def json_default(obj):
    """``json.dumps`` fallback for numpy values, dataclasses and sets."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return dataclasses.asdict(obj)
    if isinstance(obj, (set, frozenset)):
        return sorted(obj)
    return str(obj)


def plugin_versions(config: Mapping) -> list[str]:
    """``"package version"`` of each installed plugin whose components ``config`` uses."""
    used = components(config)
    return get_registry().plugin_versions(used) if used else []  # e.g. an OpenCV baseline: no registry


def run_key(config: Mapping, version: str | None = None) -> str:
    """The identity of a run: 16 hex digits of SHA-256 over the canonical JSON (sorted keys)
    of ``config`` without its ``name`` and ``description`` (they change no box), the dcfkit
    version and the versions of the plugins whose components the config uses (a plugin's
    new release gives new results; configs of built-ins only keep their keys)."""
    payload = {"config": {k: v for k, v in config.items() if k not in LABEL_KEYS},
               "dcfkit": version if version is not None else dcfkit_version()}
    plugins = plugin_versions(config)
    if plugins:
        payload["plugins"] = plugins
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), default=json_default)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


_COMMAND: contextvars.ContextVar[list | None] = contextvars.ContextVar("dcfkit_command", default=None)


@contextlib.contextmanager
def running_command(argv: list[str]):
    """Within: :func:`invocation` says ``argv`` (the CLI's ``dcfkit ...`` when its ``main`` is
    called with arguments, as tests and scripts do, rather than their own process's)."""
    token = _COMMAND.set(list(argv))
    try:
        yield
    finally:
        _COMMAND.reset(token)


def invocation() -> dict:
    """How this command was given: ``{"command": argv, "cwd": working directory}``. The
    process's ``sys.argv`` (with ``python -m PACKAGE`` as the first words when it was run so:
    ``sys.argv[0]`` is then the path of ``__main__.py``, which does not run alone) unless
    :func:`running_command` says otherwise. Result sidecars record the client's."""
    argv = _COMMAND.get()
    if argv is None:
        argv = list(sys.argv)
        spec = getattr(sys.modules.get("__main__"), "__spec__", None)
        if spec is not None and spec.name.endswith(".__main__"):
            argv[:1] = ["python", "-m", spec.name.removesuffix(".__main__")]
        elif argv:
            argv[0] = os.path.basename(argv[0]) or argv[0]
    return {"command": argv, "cwd": os.getcwd()}


def command_line(record: Mapping) -> str | None:
    """A sidecar's or :func:`invocation`'s command as one shell line, or None if not recorded."""
    argv = record.get("command")
    if not isinstance(argv, list) or not all(isinstance(a, str) for a in argv):
        return None
    return shlex.join(argv)


@functools.lru_cache(maxsize=1)
def machine() -> dict:
    """The machine this process runs on: host name, OS, CPU model, cores, Python version."""
    return {"host": platform.node(), "system": platform.platform(terse=True), "cpu": cpu_model(),
            "cores": os.cpu_count(), "python": platform.python_version()}


# --------------------------------------------------------------------------- files


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
    """Remove what a killed run left of writing ``folder/<name>`` (never read)."""
    for name in names:
        for stale in folder.glob(f".{glob.escape(name)}.*.tmp"):
            with contextlib.suppress(OSError):
                stale.unlink()


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
    """``(N, 2)`` ``(peak, apce)`` rows as ``peak,apce`` lines, ``%.6g``; NaN as ``nan``."""
    return "".join("%.6g,%.6g\n" % (p, a) for p, a in np.asarray(confidence, dtype=np.float64).reshape(-1, 2))


def format_times(times: np.ndarray) -> str:
    """Seconds per frame, one ``%.8f`` a line (the OTB and GOT-10k toolkits' ``_time.txt``)."""
    return "".join("%.8f\n" % t for t in np.asarray(times, dtype=np.float64).reshape(-1))


def checksum(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# --------------------------------------------------------------------------- the store


@dataclasses.dataclass(frozen=True, eq=False)
class SequenceResult:
    """A tracker's result on one sequence: ``boxes`` ``(N, 4) float64`` 0-based;
    ``times`` ``(N,) float64`` seconds per frame and ``fps`` when known (None for imports);
    ``platform`` the :func:`dcfkit.running.platforms.record` of the run when its sidecar has one."""

    boxes: np.ndarray
    times: np.ndarray | None = None
    fps: float | None = None
    run_key: str | None = None
    platform: dict | None = None


class ResultStore:
    """The result files of one tracker configuration: ``folder/<sequence>.{txt,json,time,confidence,error}``."""

    def __init__(self, folder):
        self.folder = Path(folder)

    def boxes_path(self, name: str) -> Path:
        return self.folder / f"{name}{BOXES_END}"

    def sidecar_path(self, name: str) -> Path:
        return self.folder / f"{name}{SIDECAR_END}"

    def error_path(self, name: str) -> Path:
        return self.folder / f"{name}{ERROR_END}"

    def time_path(self, name: str) -> Path:
        return self.folder / f"{name}{TIME_END}"

    def confidence_path(self, name: str) -> Path:
        return self.folder / f"{name}{CONFIDENCE_END}"

    def _written(self, name: str) -> tuple[Path, ...]:
        """The files a finished run writes besides its sidecar."""
        return self.boxes_path(name), self.time_path(name), self.confidence_path(name)

    def file_names(self, name: str) -> list[str]:
        return [p.name for p in (*self._written(name), self.sidecar_path(name), self.error_path(name))]

    def sidecar(self, name: str) -> dict | None:
        return read_json(self.sidecar_path(name))

    def status(self, seq: Sequence, key: str, meta: dict | None = None) -> str:
        """``done`` (complete, intact, from run ``key`` started at ``seq``'s current first
        box), ``damaged`` (its sidecar is ``key``'s but the sidecar or the boxes file is not
        what was written), ``failed`` (``key`` raised) or ``missing``. ``meta``: the sidecar,
        if read."""
        meta = self.sidecar(seq.name) if meta is None else meta
        if meta is not None and meta.get("run_key") == key:
            if meta.get("init_box") != [float(v) for v in seq.init_box]:
                return "missing"  # a corrected annotation: run again
            return "done" if self.problem(seq.name, meta, len(seq)) is None else "damaged"
        error = read_json(self.error_path(seq.name))
        return "failed" if error is not None and error.get("run_key") == key else "missing"

    def is_done(self, seq: Sequence, key: str) -> bool:
        return self.status(seq, key) == "done"

    def problem(self, name: str, meta: dict, frames: int | None = None) -> str | None:
        """Why the stored result of sequence ``name`` (sidecar ``meta``; ``frames`` long, if
        known) cannot be used, or None. Results written by dcfkit < 0.4 have no checksum:
        their lines are checked against the format dcfkit wrote instead."""
        try:
            _check_sidecar(meta)
        except (TypeError, ValueError) as exc:
            return f"{self.sidecar_path(name)} is malformed ({exc})"
        path = self.boxes_path(name)
        try:
            data = path.read_bytes()
        except OSError as exc:
            return f"cannot read {path} ({exc.strerror})"
        frames = meta["frames"] if frames is None else frames
        if "sha256" in meta:
            if meta["sha256"] == checksum(data) and meta["frames"] == frames:
                return None
            return f"{path} is not the file its run wrote (cut short or edited)"
        lines = data.splitlines(keepends=True)
        if len(lines) == frames and all(_RESULT_LINE.fullmatch(line) for line in lines):
            return None
        return f"{path} (written by dcfkit < 0.4, without a checksum) is not as its run wrote it"

    def write(self, seq: Sequence, boxes: np.ndarray, meta: dict, times: np.ndarray | None = None,
              confidence: np.ndarray | None = None) -> None:
        """Store a finished run: boxes, the ``times`` and ``confidence`` files (each left out,
        and any older one removed, when None), then the sidecar (``meta`` plus the checksums)."""
        text = format_boxes(boxes)
        with contextlib.suppress(FileNotFoundError):
            self.sidecar_path(seq.name).unlink()  # an older sidecar must never describe new boxes
        atomic_write(self.boxes_path(seq.name), text)
        meta = {**meta, "frames": len(boxes), "sha256": checksum(text.encode())}
        for field, path, data, form in (("time_sha256", self.time_path(seq.name), times, format_times),
                                        ("confidence_sha256", self.confidence_path(seq.name), confidence,
                                         format_confidence)):
            meta.pop(field, None)
            if data is None:
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
                continue
            extra = form(data)
            atomic_write(path, extra)
            meta[field] = checksum(extra.encode())
        atomic_write(self.sidecar_path(seq.name), json.dumps(meta, indent=1, default=json_default) + "\n")
        with contextlib.suppress(FileNotFoundError):
            self.error_path(seq.name).unlink()

    def write_failure(self, seq: Sequence, record: dict, exc: BaseException) -> None:
        """Store a failed run (removing any results, which another config may have left)."""
        record = {**record, "sequence": seq.name, "dataset": seq.dataset, "type": type(exc).__name__,
                  "traceback": "".join(traceback.format_exception(exc)), "time": now()}
        for stale in (self.sidecar_path(seq.name), *self._written(seq.name)):
            with contextlib.suppress(FileNotFoundError):
                stale.unlink()
        make_dir(self.folder)
        atomic_write(self.error_path(seq.name), json.dumps(record, indent=1, default=json_default) + "\n")

    def load(self, sequences: Iterable[Sequence | str]) -> dict[str, SequenceResult]:
        """Intact results for ``sequences`` (names or :class:`Sequence`); others (not run,
        failed, damaged, malformed: each of the last two is logged) are left out. A
        :class:`DatasetError` if the intact results come from different configs."""
        results, keys = {}, {}
        for seq in sequences:
            name = seq if isinstance(seq, str) else seq.name
            meta = self.sidecar(name)
            if meta is None or not self.boxes_path(name).is_file():
                continue
            problem = self.problem(name, meta, None if isinstance(seq, str) else len(seq))
            if problem is not None:
                log.warning("%s: left out; run it again to recompute %r", problem, name)
                continue
            key = meta.get("run_key", meta.get("config_hash"))  # config_hash: dcfkit < 0.4
            results[name] = SequenceResult(read_boxes(self.boxes_path(name)), _times(meta),
                                           None if meta.get("fps") is None else float(meta["fps"]), key,
                                           meta.get("platform") if isinstance(meta.get("platform"), dict) else None)
            keys.setdefault(key, []).append(name)
        if len(keys) > 1:
            detail = "; ".join(f"{k}: {', '.join(v[:5])}{' ...' if len(v) > 5 else ''}" for k, v in keys.items())
            raise DatasetError(
                f"results in {self.folder} mix {len(keys)} configurations ({detail}); rerun "
                f"`dcfkit eval` with one config, or give the other config a different 'name'")
        return results


_NUMBER = rb"(?:nan|-?\d+\.\d{3})"
_RESULT_LINE = re.compile(_NUMBER + rb"(?:," + _NUMBER + rb"){3}\n")  # format_boxes's %.3f lines


def _check_sidecar(meta: dict) -> None:
    """A :class:`ValueError` or :class:`TypeError` naming the first field of a results
    sidecar that has the wrong type."""
    checks = {"frames": lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0,
              "sha256": lambda v: isinstance(v, str), "time_sha256": lambda v: isinstance(v, str),
              "confidence_sha256": lambda v: isinstance(v, str),
              "run_key": lambda v: isinstance(v, str), "config_hash": lambda v: isinstance(v, str),
              "fps": lambda v: v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)),
              "times": lambda v: isinstance(v, list) and all(isinstance(t, (int, float)) for t in v)}
    if not isinstance(meta.get("frames"), int):
        raise ValueError("no frame count")
    for field, ok in checks.items():
        if field in meta and not ok(meta[field]):
            raise TypeError(f"{field} is {meta[field]!r:.60}")


def _times(meta: dict) -> np.ndarray | None:
    times = np.asarray(meta.get("times", []), dtype=np.float64).reshape(-1)
    return times if times.size else None


def load_results(out_dir, tracker_name: str, sequences: Iterable[Sequence | str]) -> dict[str, SequenceResult]:
    """Intact results of ``tracker_name`` under ``out_dir`` (:meth:`ResultStore.load`)."""
    folder = Path(out_dir) / tracker_name
    if not folder.is_dir():
        raise DatasetError(f"no results folder for tracker {shown(tracker_name)}: {clip(str(folder))}")
    return ResultStore(folder).load(sequences)


def result_files(folder) -> dict[str, Path]:
    """``{sequence: folder/<sequence>.txt}``; a ``*_time.txt`` or ``*_confidence.txt`` (the
    timings and confidences of some toolkits and of dcfkit < 0.7) is left out unless a dcfkit
    sidecar says it is a sequence's boxes. A :class:`DatasetError` if ``folder`` is not a folder."""
    folder = Path(folder)
    if not folder.is_dir():
        raise DatasetError(f"results folder not found: {clip(str(folder))}")
    return {p.stem: p for p in sorted(folder.glob(f"*{BOXES_END}"))
            if not p.stem.endswith((TOOLKIT_TIME_SUFFIX, TOOLKIT_CONFIDENCE_SUFFIX))
            or p.with_suffix(SIDECAR_END).is_file()}


def import_results(folder) -> dict[str, SequenceResult]:
    """Per-sequence result files of another tracker: ``folder/<sequence>.txt``, 1-based
    ``x,y,w,h`` separated by commas, tabs or spaces. Returns 0-based boxes, no timings."""
    return {name: SequenceResult(read_boxes(path)) for name, path in result_files(folder).items()}

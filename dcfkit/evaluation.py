"""One-pass evaluation (OPE) runner, result files, and OpenCV baseline trackers.

A tracker is any object with ``init(image, box)`` and ``update(image) -> box``; images
are ``(H, W, 3) uint8`` **BGR** (as ``cv2.imread`` returns them) and boxes are
``(x, y, w, h)`` floats, **0-based**. Trackers come from a factory
``make_tracker(config) -> tracker``, called once per sequence; the default is
:func:`dcfkit.load_tracker`.

Output layout of :func:`run_one_pass` (``OUT/<tracker name>/``):

``<sequence>.txt``
    one ``x,y,w,h`` line per frame, ``%.3f``, **1-based** (1 is added to x and y), so the
    MATLAB OTB/UAV123 toolkit and pysot read it unchanged. Frame 0 holds the initial
    ground-truth box. A lost target is written as ``nan,nan,nan,nan``.
``<sequence>.json``
    sidecar: per-frame tracker time in seconds (``init`` for frame 0, ``update`` after;
    image decoding excluded; before its first sequence of a dcfkit config, a process runs a
    throw-away copy of the tracker on the first frame, untimed, so one-time loading of
    compiled code is not counted), ``fps`` = frames / total tracker time, the config, its
    hash, the dcfkit version and the plugin packages the config uses. Written last, so it
    marks the sequence as done.
``<sequence>.error.json``
    written instead when the tracker raised: frame, error and traceback.

Every file is written to a temporary file in the same folder and moved into place with
``os.replace``, so an interrupted run never leaves a half-written file. On rerun a
sequence is skipped when its sidecar has the same config hash and its ``.txt`` has one
line per frame; failed sequences are retried.

The same result files serve :mod:`dcfkit.ablation`, which uses this module's
:func:`track_sequence`, :func:`is_done`, :func:`atomic_write` and worker set-up
(:func:`worker_init`, :func:`single_threaded_env`).
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import functools
import hashlib
import json
import logging
import multiprocessing
import os
import signal
import sys
import tempfile
import time
import traceback
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

import numpy as np

from .datasets import DatasetError, Sequence, read_boxes
from .errors import ConfigError, DcfkitError
from .report import add_protocol_argument, evaluate, score_line

__all__ = [
    "OpenCVTracker",
    "OpenCVUnavailable",
    "SequenceResult",
    "add_eval_arguments",
    "available_opencv_trackers",
    "cmd_eval",
    "config_hash",
    "dcfkit_version",
    "import_results",
    "load_results",
    "opencv_tracker",
    "run_one_pass",
]

log = logging.getLogger(__name__)

_THREAD_VARS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")


# --------------------------------------------------------------------------- identity


def dcfkit_version() -> str:
    """``dcfkit.__version__``, else the installed distribution's version, else ``"unknown"``."""
    import dcfkit

    version = getattr(dcfkit, "__version__", None)
    if version:
        return str(version)
    try:
        import importlib.metadata

        return importlib.metadata.version("dcfkit")
    except Exception:
        return "unknown"


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
    from .config import components
    from .registry import get_registry

    used = components(config)
    return get_registry().plugin_versions(used) if used else []  # e.g. an OpenCV baseline: no registry


def config_hash(config: Mapping, version: str | None = None) -> str:
    """16 hex digits of SHA-256 over the canonical JSON (sorted keys) of config + dcfkit version,
    and the versions of the plugins whose components the config uses (so a plugin's new
    release gives new results, while configs of built-ins only keep their hashes)."""
    payload = {"config": config, "dcfkit": version if version is not None else dcfkit_version()}
    plugins = plugin_versions(config)
    if plugins:
        payload["plugins"] = plugins
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), default=json_default)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _tracker_name(config: Mapping) -> str:
    name = config.get("name") if isinstance(config, Mapping) else None
    if not isinstance(name, str) or not name.strip():
        raise ConfigError("config has no top-level 'name' (the tracker name used for the output folder)")
    if name in (".", "..") or any(c in name for c in "/\\:"):
        raise ConfigError(f"config 'name' {name!r} must be usable as a folder name (no / \\ :)")
    return name


# --------------------------------------------------------------------------- files


@functools.lru_cache(maxsize=1)
def _file_mode() -> int:
    """The mode open() would give a new file (mkstemp's are owner-only)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def atomic_write(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` via a temporary file in the same folder + ``os.replace``."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, _file_mode())
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _format_boxes(boxes: np.ndarray) -> str:
    one_based = boxes + np.array([1.0, 1.0, 0.0, 0.0])
    return "".join("%.3f,%.3f,%.3f,%.3f\n" % tuple(b) for b in one_based)


def _count_lines(path: Path) -> int:
    with open(path, "rb") as f:
        return sum(1 for line in f if line.strip())


def _paths(tracker_dir: Path, name: str) -> tuple[Path, Path, Path]:
    return (tracker_dir / f"{name}.txt", tracker_dir / f"{name}.json",
            tracker_dir / f"{name}.error.json")


def make_dir(folder: Path) -> Path:
    """``mkdir -p``, with a :class:`DcfkitError` naming the folder (e.g. a file is in the way)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise DcfkitError(f"cannot create the folder {folder}: {exc.strerror}") from None
    return folder


@contextlib.contextmanager
def exclusive(lock: Path, command: str, what: str):
    """Hold the file lock ``lock`` so two runs never write the same results (released on any
    exit). Where no lock can be taken (not POSIX, a read-only folder, a file system without
    flock) the run goes on unlocked, with a warning."""
    try:
        import fcntl

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
                              f"wait for it or use another --out") from None
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


def is_done(tracker_dir: Path, seq: Sequence, chash: str) -> bool:
    """Whether ``seq`` has complete results in ``tracker_dir`` from the config with hash ``chash``,
    started from ``seq``'s current initial box (a corrected annotation is run again)."""
    txt, side, _ = _paths(tracker_dir, seq.name)
    return _complete(read_json(side), txt, seq, chash)


def _complete(meta: dict | None, txt: Path, seq: Sequence, chash: str) -> bool:
    """:func:`is_done` given the sequence's sidecar ``meta`` (None: missing) and result file."""
    init = [float(v) for v in seq.init_box]
    return (meta is not None and meta.get("config_hash") == chash
            and meta.get("init_box", init) == init  # (sidecars older than the field: trusted)
            and txt.is_file() and _count_lines(txt) == len(seq))


# --------------------------------------------------------------------------- tracking one sequence


class _TrackerFailure(Exception):
    def __init__(self, frame: int, message: str):
        super().__init__(message)
        self.frame = frame


def _as_box(value, frame: int, seq: Sequence, method: str) -> np.ndarray:
    try:
        box = np.asarray(value, dtype=np.float64).reshape(4)
    except (TypeError, ValueError):
        raise _TrackerFailure(
            frame, f"sequence {seq.name!r}, frame {frame} ({seq.frames[frame].name}): "
                   f"{method} returned {value!r}, expected 4 numbers (x, y, w, h)") from None
    return box


def _default_factory(config):
    from dcfkit import load_tracker  # lazy: the core is not needed to score results

    return load_tracker(config)


_warmed_up: set[str] = set()  # config hashes this process has run once, untimed


def _warm_up(config: Mapping, chash: str, image: np.ndarray, box: np.ndarray) -> None:
    """Run a throw-away dcfkit tracker for one init and update, once per process and config, so
    that one-time loading (numba's compiled loops, the CN table) is not charged to the fps of
    whichever sequence comes first. A failure here is left to the timed run to report."""
    if chash in _warmed_up:
        return
    _warmed_up.add(chash)
    with contextlib.suppress(Exception):
        tracker = _default_factory(dict(config))
        tracker.init(image, box)
        tracker.update(image)


def track_sequence(config: Mapping, seq: Sequence, tracker_dir: Path, make_tracker,
                   chash: str, version: str, on_frame: Callable[[], None] | None = None) -> dict:
    """Run one sequence and write its files; returns ``{"sequence", "status", ...}``."""
    txt, side, err_file = _paths(tracker_dir, seq.name)
    factory = make_tracker or _default_factory
    boxes = np.full((len(seq), 4), np.nan)
    times = np.zeros(len(seq))
    frame = -1
    try:
        tracker = factory(dict(config))
        for frame in range(len(seq)):
            image = seq.frame(frame)  # decoding is not timed
            if frame == 0 and make_tracker is None:
                _warm_up(config, chash, image, seq.init_box)
            t0 = time.perf_counter()
            try:
                if frame == 0:
                    tracker.init(image, seq.init_box)
                else:
                    out = tracker.update(image)
            except Exception as exc:
                raise _TrackerFailure(
                    frame, f"sequence {seq.name!r}, frame {frame} ({seq.frames[frame].name}): "
                           f"{'init' if frame == 0 else 'update'} raised "
                           f"{type(exc).__name__}: {exc}") from exc
            times[frame] = time.perf_counter() - t0
            boxes[frame] = seq.init_box if frame == 0 else _as_box(out, frame, seq, "update()")
            if on_frame is not None:
                on_frame()
    except Exception as exc:
        frame_no = exc.frame if isinstance(exc, _TrackerFailure) else frame
        if isinstance(exc, (_TrackerFailure, DcfkitError)):
            message = str(exc)
        elif frame_no < 0:
            message = f"sequence {seq.name!r}: creating the tracker raised {type(exc).__name__}: {exc}"
        else:
            message = f"sequence {seq.name!r}, frame {frame_no}: {type(exc).__name__}: {exc}"
        cause = exc.__cause__ if isinstance(exc, _TrackerFailure) and exc.__cause__ else exc
        return record_failure(tracker_dir, seq, config.get("name"), message, cause, chash, version,
                              frame_no if frame_no >= 0 else None)

    total = float(times.sum())
    meta = {
        "sequence": seq.name, "dataset": seq.dataset, "tracker": config["name"],
        "init_box": [float(v) for v in seq.init_box],
        "frames": len(seq), "fps": len(seq) / total if total > 0 else None,
        "total_time": total, "config_hash": chash, "dcfkit_version": version, "plugins": plugin_versions(config),
        "time": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "config": config, "times": times.tolist(),
    }
    with contextlib.suppress(FileNotFoundError):
        side.unlink()  # an older config's sidecar must never describe the new boxes
    atomic_write(txt, _format_boxes(boxes))
    atomic_write(side, json.dumps(meta, indent=1, default=json_default) + "\n")  # marks done
    with contextlib.suppress(FileNotFoundError):
        err_file.unlink()
    return {"sequence": seq.name, "status": "done", "fps": meta["fps"], "frames": len(seq)}


def record_failure(tracker_dir: Path, seq: Sequence, tracker: str | None, message: str, exc: BaseException,
                   chash: str, version: str, frame: int | None = None) -> dict:
    """Write ``<sequence>.error.json`` (removing any results, which another config may have left)
    and return the failed-sequence summary ``{"sequence", "status", "error", "frames"}``."""
    txt, side, err_file = _paths(tracker_dir, seq.name)
    record = {
        "sequence": seq.name, "dataset": seq.dataset, "tracker": tracker,
        "frame": frame, "frame_file": str(seq.frames[frame]) if frame is not None else None,
        "error": message, "type": type(exc).__name__, "traceback": "".join(traceback.format_exception(exc)),
        "config_hash": chash, "dcfkit_version": version,
        "time": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }
    for stale in (side, txt):
        with contextlib.suppress(FileNotFoundError):
            stale.unlink()
    try:
        tracker_dir.mkdir(parents=True, exist_ok=True)
        atomic_write(err_file, json.dumps(record, indent=1, default=json_default) + "\n")
    except OSError as write_error:  # the returned summary still reports the failure
        log.warning("could not write %s: %s", err_file, write_error)
    return {"sequence": seq.name, "status": "failed", "error": message, "frames": len(seq)}


# --------------------------------------------------------------------------- runner


@contextlib.contextmanager
def single_threaded_env():
    """Set the BLAS/OpenMP thread variables to 1 (inherited by spawned workers), then restore."""
    saved = {k: os.environ.get(k) for k in _THREAD_VARS}
    os.environ.update({k: "1" for k in _THREAD_VARS})
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def worker_init(parent_pid: int | None = None):
    """A worker process: one BLAS/OpenMP/OpenCV thread. With ``parent_pid`` (a pool worker of
    :func:`run_pool`) it dies with the parent and ignores SIGINT: Ctrl-C reaches the whole
    process group, and a worker interrupted mid-protocol would leave the parent waiting for it
    forever; the parent stops its workers itself."""
    from .registry import PluginWarning

    os.environ.update({k: "1" for k in _THREAD_VARS})
    warnings.simplefilter("ignore", PluginWarning)  # the parent said it
    with contextlib.suppress(Exception):
        import cv2

        cv2.setNumThreads(1)
    if parent_pid is not None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        _die_with_parent(parent_pid)


def crash_message(seq: Sequence, exc: BaseException) -> str:
    """What to say of a sequence whose worker failed outside the tracker."""
    if isinstance(exc, BrokenProcessPool):
        return (f"sequence {seq.name!r}: a worker process died (killed, out of memory, or it could not start: "
                "a script that runs this with jobs > 1 needs an `if __name__ == '__main__':` guard); "
                "rerun to retry")
    return f"sequence {seq.name!r}: the worker failed: {type(exc).__name__}: {exc}"


def run_pool(calls: Mapping[Any, tuple], jobs: int, on_result: Callable[[Any, Any], None],
             on_crash: Callable[[Any, BaseException], Any]) -> None:
    """Run ``fn(*args)`` for every ``key: (fn, *args)`` of ``calls`` in ``jobs`` spawned,
    single-threaded worker processes; ``on_result(key, result)`` as each finishes.

    A call whose worker raised outside ``fn``'s own handling, or died (killed, out of memory:
    the pool then fails every call not yet finished), gets ``on_crash(key, exc)`` as its
    result. Ctrl-C or any error in the caller terminates the workers at once."""
    with single_threaded_env():  # workers are spawned on submit and inherit it
        pool = ProcessPoolExecutor(max_workers=min(jobs, len(calls)), mp_context=multiprocessing.get_context("spawn"),
                                   initializer=worker_init, initargs=(os.getpid(),))
        try:
            futures = {pool.submit(*call): key for key, call in calls.items()}
            for future in as_completed(futures):
                key = futures[future]
                try:
                    result = future.result()
                except Exception as exc:
                    result = on_crash(key, exc)
                on_result(key, result)
        except BaseException:
            for process in list((getattr(pool, "_processes", None) or {}).values()):
                process.terminate()  # results are written atomically: nothing half-written stays
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


def _die_with_parent(parent_pid: int) -> None:
    """Linux: have the kernel kill this worker when the parent dies, even by SIGKILL
    (a pool worker would otherwise wait forever on its task queue)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    if os.getppid() != parent_pid:  # the parent died before prctl
        os._exit(1)


def run_one_pass(config: Mapping, sequences: Iterable[Sequence], out_dir, make_tracker=None,
                 jobs: int = 1, progress: bool = True) -> dict:
    """One-pass evaluation of the tracker described by ``config`` on ``sequences``.

    Each sequence starts from a fresh tracker (``make_tracker(config)``, default
    :func:`dcfkit.load_tracker`) initialised on frame 0's ground truth. Results go to
    ``out_dir/<config['name']>/`` (see the module docstring). Sequences already done with
    the same config hash are skipped. A tracker exception fails only its sequence.
    ``jobs > 1`` runs sequences in a spawned process pool with one BLAS/OpenMP thread per
    worker; ``make_tracker`` must then be picklable (a module-level function or class).

    Returns a plain dict: ``tracker``, ``dir``, ``config_hash``, ``done`` (computed now),
    ``skipped`` (already done), ``failed`` (sequence -> message).
    """
    name = _tracker_name(config)
    config = dict(config)
    sequences = list(sequences)
    bad = [s.name + (f" (first box in {s.annotation})" if s.annotation else "") for s in sequences
           if not (np.isfinite(s.ground_truth[0]).all() and (s.ground_truth[0, 2:] > 0).all())]
    if bad:
        raise DatasetError(
            f"one-pass evaluation initialises on frame 0's ground truth, which is NaN or "
            f"empty in sequence(s): {', '.join(bad)}")
    version = dcfkit_version()
    chash = config_hash(config, version)
    tracker_dir = Path(out_dir) / name
    make_dir(tracker_dir)

    with contextlib.ExitStack() as locks:  # a run on other sequences of this folder may go on alongside
        lock_dir = tracker_dir / ".locks"
        with contextlib.suppress(OSError):  # e.g. read-only results: exclusive() then runs unlocked
            lock_dir.mkdir(exist_ok=True)
        for seq in sequences:
            locks.enter_context(exclusive(lock_dir / f"{seq.name}.lock", "dcfkit eval",
                                          f"{name}'s results of sequence {seq.name!r} to {tracker_dir}"))
        metas = {s.name: read_json(_paths(tracker_dir, s.name)[1]) for s in sequences}  # each read once
        todo = [s for s in sequences if not _complete(metas[s.name], _paths(tracker_dir, s.name)[0], s, chash)]
        old = {s.name: metas[s.name] or {} for s in todo}
        for seq in todo:  # OUT/<tracker>/<sequence> has no benchmark level: never mix two benchmarks there
            if old[seq.name].get("dataset") and seq.dataset and old[seq.name]["dataset"] != seq.dataset:
                raise DatasetError(
                    f"{_paths(tracker_dir, seq.name)[1]} holds results on dataset {old[seq.name]['dataset']!r}, and "
                    f"this run is on {seq.dataset!r}: use a separate --out for each benchmark")
        same = json.dumps(config, sort_keys=True, default=json_default)

        def other_config(seq: Sequence) -> bool:  # not merely another dcfkit version of this config
            meta = old[seq.name]
            return (meta.get("config_hash") not in (None, chash)
                    and json.dumps(meta.get("config"), sort_keys=True, default=json_default) != same)

        replaced = [s.name for s in todo if other_config(s)]
        if replaced:
            log.warning("%s: replacing the results of another config named %r for %d sequence(s): %s (give this "
                        "config another name to keep both)", tracker_dir, name, len(replaced), ", ".join(replaced[:10]))
        summary = {"tracker": name, "dir": tracker_dir, "config_hash": chash,
                   "done": [], "skipped": [s.name for s in sequences if s not in todo], "failed": {}}

        def record(result):
            if result["status"] == "done":
                summary["done"].append(result["sequence"])
            else:
                summary["failed"][result["sequence"]] = result["error"]
                log.warning("%s: %s", name, result["error"])

        from tqdm.auto import tqdm

        bar = tqdm(total=sum(len(s) for s in todo), unit="frame", desc=name,
                   disable=not progress or not todo, dynamic_ncols=True)
        try:
            if jobs <= 1 or len(todo) <= 1:
                for seq in todo:
                    bar.set_postfix_str(seq.name, refresh=False)
                    start = bar.n
                    record(track_sequence(config, seq, tracker_dir, make_tracker, chash, version,
                                          on_frame=lambda: bar.update(1)))
                    bar.update(start + len(seq) - bar.n)  # a failed sequence skips its rest
            else:
                def finished(seq, result):
                    record(result)
                    bar.set_postfix_str(seq.name, refresh=False)
                    bar.update(result["frames"])

                def crashed(seq, exc):
                    return record_failure(tracker_dir, seq, name, crash_message(seq, exc), exc, chash, version)

                calls = {seq: (track_sequence, config, seq, tracker_dir, make_tracker, chash, version) for seq in todo}
                run_pool(calls, jobs, finished, crashed)
        finally:
            bar.close()
        order = {s.name: i for i, s in enumerate(sequences)}
        summary["done"].sort(key=order.get)
        return summary


# --------------------------------------------------------------------------- reading results


@dataclasses.dataclass(frozen=True, eq=False)
class SequenceResult:
    """A tracker's result on one sequence: ``boxes`` ``(N, 4) float64`` 0-based;
    ``times`` ``(N,) float64`` seconds per frame and ``fps`` when known (None for imports)."""

    boxes: np.ndarray
    times: np.ndarray | None = None
    fps: float | None = None
    config_hash: str | None = None


def load_results(out_dir, tracker_name: str, sequences: Iterable[Sequence | str]) -> dict[str, SequenceResult]:
    """Completed results of ``tracker_name`` under ``out_dir`` for ``sequences``.

    A sequence counts as completed when it has both ``.txt`` and ``.json`` sidecar;
    others (not run, failed, interrupted) are left out of the returned dict. Raises
    :class:`DatasetError` if the completed sequences come from different configs or a
    file has the wrong number of lines.
    """
    tracker_dir = Path(out_dir) / tracker_name
    if not tracker_dir.is_dir():
        raise DatasetError(f"no results folder for tracker {tracker_name!r}: {tracker_dir}")
    results, hashes = {}, {}
    for seq in sequences:
        name = seq if isinstance(seq, str) else seq.name
        txt, side, _ = _paths(tracker_dir, name)
        meta = read_json(side)
        if meta is None or not txt.is_file():
            continue
        boxes = read_boxes(txt)
        if not isinstance(seq, str) and len(boxes) != len(seq):
            raise DatasetError(f"{txt}: {len(boxes)} lines but sequence {name!r} has {len(seq)} frames")
        try:
            times = np.asarray(meta.get("times", []), dtype=np.float64).reshape(-1)
            fps = meta.get("fps")
            fps = float(fps) if fps is not None else None
            if not isinstance(meta.get("config_hash"), (str, type(None))):
                raise TypeError(f"config_hash is {meta['config_hash']!r}")
        except (TypeError, ValueError) as exc:
            raise DatasetError(f"{side}: malformed results sidecar ({exc}); delete it and run again to "
                               f"recompute {name!r}") from None
        results[name] = SequenceResult(boxes, times if times.size else None, fps, meta.get("config_hash"))
        hashes.setdefault(meta.get("config_hash"), []).append(name)
    if len(hashes) > 1:
        detail = "; ".join(f"{h}: {', '.join(v[:5])}{' ...' if len(v) > 5 else ''}" for h, v in hashes.items())
        raise DatasetError(
            f"results in {tracker_dir} mix {len(hashes)} configurations ({detail}); rerun "
            f"`dcfkit eval` with one config, or give the other config a different 'name'")
    return results


def result_files(folder) -> dict[str, Path]:
    """``{sequence: folder/<sequence>.txt}``, leaving out ``*_time.txt`` (timings written by
    some toolkits); a :class:`DatasetError` if ``folder`` is not a folder."""
    folder = Path(folder)
    if not folder.is_dir():
        raise DatasetError(f"results folder not found: {folder}")
    return {p.stem: p for p in sorted(folder.glob("*.txt")) if not p.stem.endswith("_time")}


def import_results(folder) -> dict[str, SequenceResult]:
    """Per-sequence result files of another tracker: ``folder/<sequence>.txt``, 1-based
    ``x,y,w,h`` separated by commas, tabs or spaces. Returns 0-based boxes, no timings.
    Files ending in ``_time.txt`` (timings written by some toolkits) are ignored."""
    return {name: SequenceResult(read_boxes(path)) for name, path in result_files(folder).items()}


# --------------------------------------------------------------------------- OpenCV baselines

# Preferred constructor first: legacy trackers take and return float boxes (Rect2d).
_OPENCV_CONSTRUCTORS = {
    "CSRT": ("legacy.TrackerCSRT_create", "TrackerCSRT_create"),
    "KCF": ("legacy.TrackerKCF_create", "TrackerKCF_create"),
    "MOSSE": ("legacy.TrackerMOSSE_create",),
}


class OpenCVUnavailable(DcfkitError, LookupError):
    """The requested OpenCV tracker is not in this OpenCV build."""


def _opencv_constructor(name: str):
    import cv2

    for dotted in _OPENCV_CONSTRUCTORS[name]:
        obj = cv2
        for part in dotted.split("."):
            obj = getattr(obj, part, None)
            if obj is None:
                break
        if obj is not None:
            return obj, dotted.startswith("legacy.")
    return None, False


def available_opencv_trackers() -> list[str]:
    """Names of the OpenCV baselines this OpenCV build provides (subset of CSRT, KCF, MOSSE)."""
    try:
        return [n for n in _OPENCV_CONSTRUCTORS if _opencv_constructor(n)[0] is not None]
    except ImportError:
        return []


class OpenCVTracker:
    """An OpenCV tracker behind the dcfkit protocol (float ``(x, y, w, h)`` 0-based boxes).

    When OpenCV reports a failure (``ok`` false) the previous box is returned, as the
    tracker keeps no other estimate.
    """

    def __init__(self, name: str):
        self.name = name
        self._tracker = None
        self._box = None

    def init(self, image: np.ndarray, box) -> None:
        create, legacy = _opencv_constructor(self.name)
        self._tracker = create()
        box = np.asarray(box, dtype=np.float64)
        rect = tuple(float(v) for v in box) if legacy else (
            int(round(box[0])), int(round(box[1])), max(1, int(round(box[2]))), max(1, int(round(box[3]))))
        self._tracker.init(image, rect)
        self._box = box.copy()

    def update(self, image: np.ndarray) -> np.ndarray:
        ok, rect = self._tracker.update(image)
        rect = np.asarray(rect, dtype=np.float64)
        if ok and np.isfinite(rect).all() and rect[2] > 0 and rect[3] > 0:
            self._box = rect
        return self._box.copy()


class _OpenCVFactory:
    """Picklable ``make_tracker`` for :func:`run_one_pass` (``jobs > 1``)."""

    def __init__(self, name: str):
        self.name = name

    def __call__(self, config=None) -> OpenCVTracker:
        return OpenCVTracker(self.name)

    def __repr__(self):
        return f"opencv_tracker({self.name!r})"


def opencv_tracker(name: str) -> Callable[[Any], OpenCVTracker]:
    """``make_tracker`` factory for OpenCV's CSRT, KCF or MOSSE (case-insensitive).

    Raises :class:`OpenCVUnavailable` naming the available ones if this build lacks it.
    Use with a config such as ``{"name": "opencv-kcf"}``.
    """
    key = str(name).upper()
    if key not in _OPENCV_CONSTRUCTORS:
        raise OpenCVUnavailable(f"unknown OpenCV tracker {name!r}; choose from {', '.join(_OPENCV_CONSTRUCTORS)}")
    if key not in available_opencv_trackers():
        raise OpenCVUnavailable(
            f"OpenCV tracker {key} is not in this OpenCV build (available: "
            f"{', '.join(available_opencv_trackers()) or 'none'}); install opencv-contrib-python-headless")
    return _OpenCVFactory(key)


# --------------------------------------------------------------------------- CLI


def add_eval_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Arguments of ``dcfkit eval``."""
    parser.add_argument("configs", nargs="+", metavar="CONFIG",
                        help="tracker config YAML file(s) or shipped config names (strcf, bacf, dr2track); "
                             "'opencv:CSRT', 'opencv:KCF' or 'opencv:MOSSE' runs an OpenCV baseline")
    parser.add_argument("--dataset", default="auto",
                        help="uav123, uav123_10fps, uav123_20l, dtb70, uavdt, otb (default: detect)")
    parser.add_argument("--root", required=True, type=Path, help="benchmark root folder")
    parser.add_argument("--out", required=True, type=Path, help="results folder (OUT/<tracker>/)")
    parser.add_argument("--sequences", default=None, help="comma-separated sequence names (default: all)")
    parser.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a config value (repeatable), e.g. --set solver.iterations=3")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_protocol_argument(parser)
    return parser


def _resolve_config(spec: str, overrides: Mapping[str, Any]) -> tuple[dict, Callable | None]:
    """(config, make_tracker) for a CONFIG argument of ``dcfkit eval``."""
    if spec.lower().startswith("opencv:"):
        kind = spec.split(":", 1)[1]
        factory = opencv_tracker(kind)
        return {"name": f"opencv-{factory.name.lower()}", "opencv": factory.name, **overrides}, factory
    from dcfkit.config import load_config  # lazy: only needed to run dcfkit trackers

    return dict(load_config(spec, overrides)), None


def _distinct_names(specs: list[str], resolved: list[tuple[dict, Callable | None]]
                    ) -> list[tuple[dict, Callable | None]]:
    """All configs checked before any runs: a config given twice runs once; two different
    configs with the same name (one output folder) are a :class:`ConfigError`."""
    seen: dict[str, tuple[str, dict]] = {}
    out = []
    for spec, (config, factory) in zip(specs, resolved):
        name = _tracker_name(config)
        if name not in seen:
            seen[name] = (spec, config)
            out.append((config, factory))
        elif seen[name][1] != config:
            raise ConfigError(
                f"configs {seen[name][0]!r} and {spec!r} are both named {name!r} and would write to the "
                f"same results folder; give one of them another 'name:' (--set name=... renames every CONFIG)")
    return out


def cmd_eval(args: argparse.Namespace) -> int:
    """``dcfkit eval``: run each config on the dataset; exit status 1 if any sequence failed."""
    from .datasets import load_dataset

    sequences = load_dataset(args.dataset, args.root, args.sequences)
    from .config import parse_overrides

    overrides = parse_overrides(args.overrides)
    resolved = _distinct_names(args.configs, [_resolve_config(spec, overrides) for spec in args.configs])
    status = 0
    for config, factory in resolved:
        summary = run_one_pass(config, sequences, args.out, make_tracker=factory,
                               jobs=args.jobs, progress=not args.no_progress)
        print(f"{summary['tracker']}: {len(summary['done'])} run, {len(summary['skipped'])} "
              f"already done, {len(summary['failed'])} failed -> {summary['dir']}")
        scores = evaluate({summary["tracker"]: load_results(args.out, summary["tracker"], sequences)},
                          sequences, protocol=args.protocol)
        print(f"  {score_line(scores['overall'][0], args.protocol)}")
        for seq, message in summary["failed"].items():
            print(f"  FAILED {message}")
        status = status or (1 if summary["failed"] else 0)
    return status

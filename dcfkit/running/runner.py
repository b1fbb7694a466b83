"""One run into its result store, and the process pool and dask cluster that run many:
:func:`dcfkit.running.execute.execute` runs them all, the runs of a sequence that share its
frames (TRE's, SRE's) together (:mod:`dcfkit.running.lockstep`). ``dcfkit eval``
(:mod:`dcfkit.running.evaluation`) and ``dcfkit ablate`` (:mod:`dcfkit.ablation`) differ only
in which runs they ask for.

Each run is tracked as its experiment says (:meth:`dcfkit.experiments.base.Experiment.track`)
from a fresh tracker, and written to a :class:`dcfkit.store.results.ResultStore`; a tracker
exception fails only its run (an ``.error`` naming the 1-based frame and its file). Workers
have one BLAS/OpenMP/OpenCV thread each and die with the parent.
"""
from __future__ import annotations

import contextlib
import dataclasses
import logging
import multiprocessing
import os
import signal
import sys
import uuid
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

import cv2
import numpy as np

from dcfkit.datasets import Sequence
from dcfkit.errors import DcfkitError
from dcfkit.experiments import EXPERIMENTS, Experiment
from dcfkit.experiments.loop import TrackerFailure
from dcfkit.registry import PluginWarning
from dcfkit.store import platforms
from dcfkit.store.code_state import box_code
from dcfkit.store.provenance import (
    dcfkit_version,
    invocation,
    machine,
    now,
    plugin_versions,
    run_key,
    sources,
    without_home,
)
from dcfkit.store.results import ResultStore
from dcfkit.running.scheduler import connect as connect_scheduler, import_distributed
from dcfkit.store.timing import timing_record

log = logging.getLogger(__name__)

_THREAD_VARS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")


@dataclasses.dataclass(frozen=True)
class RunTask:
    """One run to do: ``config`` on ``seq`` into the store at ``folder`` under ``key``, tracked as
    ``experiment`` tracks its runs (bound to its rule, if it has one); ``alone``: timed alone,
    not in lockstep (:mod:`dcfkit.running.lockstep`), since its twin in another experiment
    (OPE's run, TRE's first) is copied with its timing.
    ``make_tracker(config)`` builds the tracker (None: :func:`dcfkit.load_tracker`)."""

    config: dict
    seq: Sequence
    folder: Path
    key: str
    make_tracker: Callable | None = None
    experiment: Experiment = EXPERIMENTS["ope"]
    alone: bool = False


# --------------------------------------------------------------------------- one run


def load_dcfkit_tracker(config):
    from dcfkit.tracker.tracker import load_tracker  # lazy: scoring results needs no tracker core

    return load_tracker(config)


_warmed_up: set[str] = set()  # run keys this process has run once, untimed


def _warm_up(task: RunTask) -> None:
    """Run a throw-away dcfkit tracker for one init and update, once per process and config, so
    that one-time loading (numba's compiled loops, the CN table) is not charged to the fps of
    whichever sequence comes first. A failure here is left to the timed run to report."""
    if task.make_tracker is not None or task.key in _warmed_up:
        return
    _warmed_up.add(task.key)
    with contextlib.suppress(Exception):
        image = task.seq.frame(0)
        tracker = load_dcfkit_tracker(dict(task.config))
        tracker.init(image, task.seq.init_box)
        tracker.update(image)


def warm_up_compiled(tasks: Iterable[RunTask]) -> None:
    """Before a progress bar starts: one throw-away run (:func:`_warm_up`) per solver among
    ``tasks``, in this process, so that numba compiles its kernels (and caches them for the
    workers) here, not inside the first timed runs, whose slowness made the first estimate of
    the time left ten times too long."""
    seen = set()
    for task in tasks:
        solver = task.config.get("solver")
        name = solver.get("name") if isinstance(solver, dict) else None
        if task.make_tracker is None and name not in seen:
            seen.add(name)
            _warm_up(task)


def make_tracker(task: RunTask):
    """A fresh tracker for ``task``: its ``make_tracker``, else dcfkit's for its config."""
    return (task.make_tracker or load_dcfkit_tracker)(dict(task.config))


def run_sequence(task: RunTask, version: str, on_frame: Callable[[], None] | None = None,
                 origin: Mapping | None = None, timing: Mapping | None = None) -> dict:
    """Run ``task`` and store its boxes or its failure; returns ``{"sequence", "status",
    "frames", "error" (failed) or "fps" (done)}``. ``origin``: the client's
    :func:`~dcfkit.store.provenance.invocation` (default: this process's), recorded in the sidecar
    with the machine that ran it; ``timing``: how its speed was measured
    (:func:`dcfkit.store.timing.timing_record`; default: alone, in this process)."""
    seq = task.seq
    _warm_up(task)
    reading = [0]  # the 1-based number of the frame being read, for errors in decoding

    def read(i: int):
        reading[0] = i + 1
        return seq.frame(i)

    def make():
        return make_tracker(task)

    tracker = None
    try:
        tracker = make()
        run = task.experiment.track(tracker, make, seq, read, on_frame)
    except Exception as exc:
        frame = exc.frame if isinstance(exc, TrackerFailure) else reading[0] or None
        return record_failure(task, version, failure_message(seq, exc, tracker is None, frame), exc, frame)
    return store_run(task, run, version, origin, timing)


def store_run(task: RunTask, run, version: str, origin: Mapping | None, timing: Mapping | None) -> dict:
    """Write ``task``'s finished :class:`~dcfkit.experiments.loop.Track` ``run`` with its
    sidecar (:func:`run_sequence`'s ``origin`` and ``timing``); returns the run's summary."""
    seq, store = task.seq, ResultStore(task.folder)
    plugins = plugin_versions(task.config)
    meta = {"sequence": seq.name, "dataset": seq.dataset, "tracker": task.config.get("name"),
            "init_box": [float(v) for v in seq.init_box], "fps": run.fps,
            "timing": dict(timing or timing_record("local", 1)),
            "total_time": float(np.nansum(run.times)),
            "run_key": task.key, "dcfkit_version": version, "plugins": plugins, "source": sources(plugins),
            "time": now(), **(origin or invocation()), "machine": machine(), "platform": platforms.record(),
            "config": task.config,
            "times": run.times.tolist(), **task.experiment.record(run)}
    store.write(seq, run.boxes, meta, run.times, run.confidence)
    return {"sequence": seq.name, "status": "done", "fps": run.fps, "frames": len(seq)}


def failure_message(seq: Sequence, exc: Exception, creating: bool, frame: int | None) -> str:
    """What to say of a failed run, naming the sequence and the 1-based frame and its file."""
    if isinstance(exc, DcfkitError) and not isinstance(exc, TrackerFailure) and f"sequence {seq.name!r}" in str(exc):
        return str(exc)  # e.g. an unreadable frame: its message names the sequence and the frame
    if creating:
        return f"sequence {seq.name!r}: creating the tracker raised {type(exc).__name__}: {exc}"
    where = f"frame {frame} of {len(seq)} ({seq.frames[frame - 1].name})" if frame else "before its first frame"
    detail = exc.detail if isinstance(exc, TrackerFailure) else f"{type(exc).__name__}: {exc}"
    return f"sequence {seq.name!r}, {where}: {detail}"


def record_failure(task: RunTask, version: str, message: str, exc: BaseException, frame: int | None = None) -> dict:
    """Store ``task``'s failure (on ``frame``, 1-based, if known) and return the failed-run summary."""
    cause = exc.__cause__ if isinstance(exc, TrackerFailure) and exc.__cause__ else exc
    ResultStore(task.folder).write_failure(task.seq, {
        "tracker": task.config.get("name"), "frame": frame,
        "frame_file": without_home(str(task.seq.frames[frame - 1])) if frame else None,
        "error": without_home(message), "run_key": task.key, "dcfkit_version": version}, cause)
    return {"sequence": task.seq.name, "status": "failed", "error": message, "frames": len(task.seq)}


# --------------------------------------------------------------------------- worker processes


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
    """A worker process: one BLAS/OpenMP/OpenCV thread. With ``parent_pid`` (a pool worker) it
    dies with the parent and ignores SIGINT: Ctrl-C reaches the whole process group, and a
    worker interrupted mid-protocol would leave the parent waiting for it forever; the parent
    stops its workers itself."""
    os.environ.update({k: "1" for k in _THREAD_VARS})
    warnings.simplefilter("ignore", PluginWarning)  # the parent said it
    cv2.setNumThreads(1)
    if parent_pid is not None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        _die_with_parent(parent_pid)


def _die_with_parent(parent_pid: int) -> None:
    """Linux: have the kernel kill this worker when the parent dies, even by SIGKILL
    (a pool worker would otherwise wait forever on its task queue)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes  # Linux only

            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    if os.getppid() != parent_pid:  # the parent died before prctl
        os._exit(1)


_worker_ready = False


def check_worker(task: RunTask, version: str) -> None:
    """Set a worker up once, and refuse to run where its dcfkit or plugins are not the client's."""
    global _worker_ready
    if not _worker_ready:  # dask workers have no initializer: one OpenCV thread each
        worker_init()
        _worker_ready = True
    if dcfkit_version() != version:
        raise DcfkitError(f"this worker runs dcfkit {dcfkit_version()}, the client {version}; "
                          f"install the same version on every worker")
    if task.make_tracker is None and run_key(task.config, version, task.experiment.rule) != task.key:
        plugins = ", ".join(plugin_versions(task.config)) or "none"
        raise DcfkitError(f"this worker's dcfkit code ({box_code()}) or plugins ({plugins}) are not the client's: "
                          f"install the same dcfkit source and plugin versions on every worker")


def crash_message(seq: Sequence, exc: BaseException) -> str:
    """What to say of a run whose worker failed outside the tracker."""
    if isinstance(exc, BrokenProcessPool):
        return (f"sequence {seq.name!r}: a worker process died (killed, out of memory, or it could not start: "
                "a script that runs this with jobs > 1 needs an `if __name__ == '__main__':` guard); "
                "rerun to retry")
    return f"sequence {seq.name!r}: the worker failed: {type(exc).__name__}: {exc}"


def run_pool(calls: Mapping[Any, tuple], jobs: int, on_result: Callable[[Any, Any], None],
             on_crash: Callable[[Any, BaseException], Any]) -> None:
    """Run ``fn(*args)`` for every ``key: (fn, *args)`` of ``calls`` in ``jobs`` spawned,
    single-threaded worker processes (at most one a usable core: :func:`worker_count`);
    ``on_result(key, result)`` as each finishes.

    A call whose worker raised outside ``fn``'s own handling, or died (killed, out of memory:
    the pool then fails every call not yet finished), gets ``on_crash(key, exc)`` as its
    result. Ctrl-C or any error in the caller terminates the workers at once."""
    with single_threaded_env():  # workers are spawned on submit and inherit it
        pool = ProcessPoolExecutor(max_workers=worker_count(jobs, len(calls)),
                                   mp_context=multiprocessing.get_context("spawn"),
                                   initializer=worker_init, initargs=(os.getpid(),))
        try:
            futures = {pool.submit(*call): key for key, call in calls.items()}
            _deliver(as_completed(futures), futures.__getitem__, on_result, on_crash)
        except BaseException:
            for process in list((getattr(pool, "_processes", None) or {}).values()):
                process.terminate()  # results are written atomically: nothing half-written stays
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


def _deliver(finished: Iterable, key_of: Callable, on_result: Callable, on_crash: Callable) -> None:
    """``on_result(key, result)`` for each future as it finishes; a future that raised gets
    ``on_crash(key, exc)`` as its result."""
    for future in finished:
        key = key_of(future)
        try:
            result = future.result()
        except Exception as exc:
            result = on_crash(key, exc)
        on_result(key, result)


@contextlib.contextmanager
def dask_client(scheduler: str | None, workers: int | None):
    """A dask.distributed client of the scheduler at ``scheduler``, or else of a ``LocalCluster``
    of ``workers`` single-threaded worker processes (:func:`worker_count` says how many)."""
    distributed = import_distributed()
    with contextlib.ExitStack() as stack:
        if scheduler:
            yield stack.enter_context(connect_scheduler(scheduler))
            return
        with single_threaded_env():  # inherited by the worker processes
            cluster = stack.enter_context(distributed.LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None))
        yield stack.enter_context(distributed.Client(cluster))


def dask_threads(client, jobs: int) -> int:
    """The worker threads to plan a scheduler's work for: those of the workers it has, or
    ``jobs`` if more (workers may still be joining), with a warning when none has joined."""
    threads = sum(client.nthreads().values())
    if threads == 0:
        log.warning("no worker has joined the dask scheduler yet: the runs are planned for %d worker thread%s "
                    "(--jobs)", jobs, "" if jobs == 1 else "s")
    return max(jobs, threads)


def run_dask(client, calls: Mapping[Any, tuple], on_result: Callable[[Any, Any], None],
             on_crash: Callable[[Any, BaseException], Any]) -> None:
    """Run ``fn(*args)`` for every ``key: (fn, *args)`` of ``calls`` on ``client``'s cluster;
    ``on_result`` and ``on_crash`` as for :func:`run_pool`. Each task is named for its key and
    this command (dask's name for it), so two clients' calls are never one task to a shared
    scheduler."""
    distributed = import_distributed()
    command = uuid.uuid4().hex[:12]
    futures = {client.submit(*call, pure=False, key=f"dcfkit-{key}-{command}"): key for key, call in calls.items()}
    try:
        _deliver(distributed.as_completed(futures), futures.__getitem__, on_result, on_crash)
    except BaseException:
        client.cancel(list(futures))
        raise


def usable_cores() -> int:
    with contextlib.suppress(AttributeError):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def pool_size(jobs: int, tasks: int) -> int:
    """Local worker processes for ``tasks`` tasks at ``jobs``: at most one a task and one a usable core."""
    return min(max(1, min(jobs, tasks)), usable_cores())


def worker_count(jobs: int, tasks: int) -> int:
    """:func:`pool_size`, with a warning when ``jobs`` asks for more than the usable cores (more
    would only share them and multiply the memory)."""
    if max(1, min(jobs, tasks)) > usable_cores():
        log.warning("--jobs %d: running %d worker processes, one per usable core (more would only share them "
                    "and multiply the memory)", jobs, usable_cores())
    return pool_size(jobs, tasks)

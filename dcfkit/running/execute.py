"""Running many (config, sequence) runs: in this process, in a local process pool or on
dask.distributed (:mod:`dcfkit.running.runner`), the runs that share their frames tracked
together (:mod:`dcfkit.running.lockstep`). ``dcfkit eval`` and ``dcfkit ablate`` and ``dcfkit
search`` go through :func:`execute` (:mod:`dcfkit.running.plan` says which runs)."""
from __future__ import annotations

from typing import Callable, Iterable, Mapping

from dcfkit.errors import DcfkitError, shown
from dcfkit.running.lockstep import groups, run_group
from dcfkit.running import runner  # its functions looked up when called, as tests replace them
from dcfkit.running.runner import RunTask
from dcfkit.store.files import StoreError
from dcfkit.store.provenance import dcfkit_version, invocation
from dcfkit.store.results import ResultStore
from dcfkit.store.timing import timing_record


def run_unit_in_worker(unit: list[RunTask], version: str, origin: Mapping | None = None,
                       timing: Mapping | None = None) -> list[dict]:
    """:func:`dcfkit.running.lockstep.run_group` in a pool or dask worker, which must run the
    client's dcfkit and plugins (:func:`~dcfkit.running.runner.check_worker`)."""
    runner.check_worker(unit[0], version)
    return run_group(unit, version, origin=origin, timing=timing)


def execute(tasks: Iterable[RunTask], on_result: Callable[[RunTask, dict], None], jobs: int = 1,
            executor: str = "local", scheduler: str | None = None, version: str | None = None,
            on_frame: Callable[[], None] | None = None) -> None:
    """Run every task, calling ``on_result(task, summary)`` as each finishes (in this process).

    ``executor="local"``: the tasks as units of :func:`dcfkit.running.lockstep.groups` (runs
    sharing their frames tracked together), in this process when ``jobs == 1`` or there is one
    unit (then ``on_frame()`` is called after every frame of every run), else in ``jobs``
    spawned worker processes, at most one a usable core (tasks and their ``make_tracker`` must
    be picklable). ``"dask"``: the units as tasks of the scheduler at ``scheduler``
    (:func:`dcfkit.running.scheduler.connect`: a bad address, or one that is not a Dask
    scheduler, is one line in bounded time), or of a ``LocalCluster`` of ``jobs``
    single-threaded workers when ``scheduler`` is None."""
    tasks = list(tasks)
    version = version if version is not None else dcfkit_version()
    origin = invocation()  # the client's command, whichever process or machine runs a task
    if executor not in ("local", "dask"):
        raise DcfkitError(f"executor must be 'local' or 'dask', got {shown(executor)}")
    if jobs < 1:
        raise DcfkitError(f"jobs must be >= 1, got {jobs}")

    def crashed(task: RunTask, exc: BaseException) -> dict:
        if isinstance(exc, StoreError):  # as in this process: writing the next run would fail too
            raise exc
        return runner.record_failure(task, version, runner.crash_message(task.seq, exc), exc)

    if not tasks:
        return
    if executor == "dask":
        _run_on_dask(tasks, jobs, scheduler, version, origin, on_result, crashed)
        return
    units = groups(tasks, 1 if jobs == 1 else runner.pool_size(jobs, len(tasks)))
    if jobs == 1 or len(units) == 1:
        for unit in units:
            for task, result in zip(unit, run_group(unit, version, on_frame, origin, timing_record("local", 1))):
                on_result(task, result)
        return
    timing = timing_record("local", runner.pool_size(jobs, len(units)))
    runner.run_pool(_calls(units, version, origin, timing), jobs, *_deliveries(units, on_result, crashed))


def _run_on_dask(tasks: list[RunTask], jobs: int, scheduler: str | None, version: str, origin: Mapping,
                 on_result: Callable, crashed: Callable) -> None:
    """The units as dask tasks: split for the scheduler's worker threads
    (:func:`~dcfkit.running.runner.dask_threads`), or, without a scheduler, as for the local pool
    and run on a ``LocalCluster`` of as many workers."""
    local = None if scheduler else groups(tasks, runner.pool_size(jobs, len(tasks)))
    workers = None if local is None else runner.worker_count(jobs, len(local))
    with runner.dask_client(scheduler, workers) as client:
        units = local if local is not None else groups(tasks, runner.dask_threads(client, jobs))
        runner.run_dask(client, _calls(units, version, origin, timing_record("dask", workers)),
                        *_deliveries(units, on_result, crashed))


def _calls(units: list[list[RunTask]], version: str, origin: Mapping, timing: Mapping) -> dict[int, tuple]:
    """Each unit's call of :func:`run_unit_in_worker`, keyed by the unit's index."""
    return {i: (run_unit_in_worker, unit, version, origin, timing) for i, unit in enumerate(units)}


def _deliveries(units: list[list[RunTask]], on_result: Callable, crashed: Callable) -> tuple[Callable, Callable]:
    """``on_result`` and ``on_crash`` for :func:`_calls`' keys: a unit's results each to its run,
    and a unit whose worker failed failing each run it had not stored."""
    def finished(i: int, results: list[dict]) -> None:
        for task, result in zip(units[i], results):
            on_result(task, result)

    def died(i: int, exc: BaseException) -> list[dict]:
        return [_stored(task) or crashed(task, exc) for task in units[i]]

    return finished, died


def _stored(task: RunTask) -> dict | None:
    """The summary of ``task``'s run if its unit stored it before the unit's worker died (a
    unit's runs end together, and are stored one after another), else None: a run stored now
    was to do when the command began, so this command made it."""
    store = ResultStore(task.folder)
    meta = store.sidecar(task.seq.name)
    if store.status(task.seq, task.key, meta) != "done":
        return None
    return {"sequence": task.seq.name, "status": "done", "fps": meta.get("fps"), "frames": len(task.seq)}

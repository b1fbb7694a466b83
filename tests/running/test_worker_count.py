"""--jobs is capped at the usable cores, with a warning: more workers only share the cores and
multiply the memory (issue 37)."""
from __future__ import annotations

import os
import types
from pathlib import Path

import numpy as np
import pytest

from dcfkit.datasets import Sequence
from dcfkit.running import runner
from dcfkit.running.execute import execute
from dcfkit.running.runner import RunTask


def test_a_pool_never_has_more_workers_than_usable_cores(monkeypatch, caplog):
    monkeypatch.setattr(runner, "usable_cores", lambda: 1)
    pids = {}
    runner.run_pool({k: (os.getpid,) for k in range(3)}, 8, pids.__setitem__, lambda k, exc: exc)
    assert len(pids) == 3 and len(set(pids.values())) == 1 and os.getpid() not in pids.values()
    assert "--jobs 8: running 1 worker processes, one per usable core" in caplog.text


def test_the_cap_counts_the_tasks_and_warns_only_when_it_cuts(monkeypatch, caplog):
    monkeypatch.setattr(runner, "usable_cores", lambda: 2)
    assert runner.worker_count(8, 1) == 1 and runner.worker_count(2, 5) == 2 and runner.worker_count(8, 2) == 2
    assert caplog.text == ""
    assert runner.worker_count(8, 5) == 2 and "--jobs 8: running 2 worker processes" in caplog.text


def test_a_local_dask_cluster_is_capped_too(monkeypatch):
    made = {}

    class Enough(Exception):
        pass

    def local_cluster(**options):
        made.update(options)
        raise Enough  # no cluster needed: its size is the point

    monkeypatch.setattr(runner, "import_distributed", lambda: types.SimpleNamespace(LocalCluster=local_cluster))
    monkeypatch.setattr(runner, "usable_cores", lambda: 2)
    with pytest.raises(Enough):
        execute([RunTask({"name": "kcf"}, Sequence(f"s{i}", (Path(f"s{i}.png"),), np.ones((1, 4)), {}, "synthetic"),
                         Path("unused"), "k") for i in range(5)], print, jobs=8, executor="dask")
    assert made["n_workers"] == 2


def test_a_scheduler_is_planned_for_its_worker_threads_or_jobs_if_more(caplog):
    """Before its workers join, a scheduler has no threads: the runs are split for --jobs, with a warning."""
    threads = lambda *counts: types.SimpleNamespace(nthreads=lambda: dict(enumerate(counts)))  # noqa: E731
    assert runner.dask_threads(threads(4, 4), 2) == 8 and runner.dask_threads(threads(1), 3) == 3
    assert caplog.text == ""
    assert runner.dask_threads(threads(), 6) == 6 and "no worker has joined the dask scheduler yet" in caplog.text
